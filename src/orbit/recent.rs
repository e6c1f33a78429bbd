//! The last few field values asked on this thread.
//!
//! A right-hand side asks the field at the same instants once per effector that needs it: a
//! magnet at t, each hysteresis rod at t and t ± its difference step, in its torque and again
//! in its derivatives (thirteen questions for a magnet and two rods, three instants). Each
//! thread keeps the last [`KEPT`] answers under a key that names the field, the orbit and the
//! instant's bits, so that each instant is evaluated once; an answer kept is the one the field
//! gives, bit for bit.

use nalgebra::Vector3;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Answers kept per thread.
pub const KEPT: usize = 4;

/// What an answer is kept under: which field along which orbit (numbers from [`next_id`] and
/// the model's own), and the instant's bits. Key 0 in the first place is no answer.
pub type Key = [u64; 4];

/// Numbers given so far ([`next_id`]).
static GIVEN: AtomicU64 = AtomicU64::new(0);

/// A number no other call in the process returns (from 1): the identity of a table or an
/// orbit, which its clones keep (they hold the same field).
pub fn next_id() -> u64 {
    GIVEN.fetch_add(1, Ordering::Relaxed) + 1
}

struct Kept {
    entries: [(Key, [f64; 3]); KEPT],
    next: usize,
}

thread_local! {
    static KEPT_HERE: RefCell<Kept> = const {
        RefCell::new(Kept {
            entries: [([0; 4], [0.0; 3]); KEPT],
            next: 0,
        })
    };
}

/// The answer kept under `key` on this thread, or `evaluate()`, then kept in place of the
/// oldest. `key[0]` must not be 0.
#[inline]
pub fn kept(key: Key, evaluate: impl FnOnce() -> Vector3<f64>) -> Vector3<f64> {
    debug_assert_ne!(key[0], 0);
    KEPT_HERE.with_borrow_mut(|kept| {
        if let Some((_, b)) = kept.entries.iter().find(|(k, _)| *k == key) {
            return Vector3::from(*b);
        }
        let b = evaluate();
        kept.entries[kept.next] = (key, b.into());
        kept.next = (kept.next + 1) % KEPT;
        b
    })
}
