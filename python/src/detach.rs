//! Long work on a worker thread with the GIL released, Ctrl-C checked on the calling thread.

use crate::SIGNAL_POLL;
use pyo3::prelude::*;
use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};

/// How a detached piece of work ended: its value (or the panic that stopped it), and the
/// exception raised on the calling thread meanwhile (Ctrl-C's `KeyboardInterrupt`, or one
/// from `on_wake`), after which the work was told to stop and then waited for.
pub(crate) struct Detached<T> {
    pub(crate) value: Result<T, Box<dyn Any + Send>>,
    pub(crate) raised: Option<PyErr>,
}

/// Runs `work` on a worker thread with the GIL released, waking every [`SIGNAL_POLL`] to run
/// Python's signal handlers and then `on_wake`; on an exception from either (Ctrl-C:
/// `KeyboardInterrupt`) sets `interrupt` and waits for the worker to stop.
pub(crate) fn run_detached<T: Send>(
    py: Python<'_>,
    interrupt: &AtomicBool,
    mut on_wake: impl FnMut(Python<'_>) -> PyResult<()>,
    work: impl FnOnce() -> T + Send,
) -> Detached<T> {
    let finished = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let result = catch_unwind(AssertUnwindSafe(work));
            let (done, wake) = &finished;
            *done.lock().unwrap_or_else(|p| p.into_inner()) = true;
            wake.notify_all();
            result
        });
        let wait = || {
            let (done, wake) = &finished;
            let guard = done.lock().unwrap_or_else(|p| p.into_inner());
            let (guard, _) = wake
                .wait_timeout_while(guard, SIGNAL_POLL, |finished| !*finished)
                .unwrap_or_else(|p| p.into_inner());
            *guard
        };
        let mut raised = None;
        while !py.detach(wait) {
            if let Err(e) = py.check_signals().and_then(|()| on_wake(py)) {
                interrupt.store(true, Ordering::SeqCst);
                raised = Some(e);
                break;
            }
        }
        // The worker ends soon after the flag is set (after the current step).
        let value = py.detach(|| worker.join());
        Detached {
            value: value.unwrap_or_else(Err),
            raised,
        }
    })
}
