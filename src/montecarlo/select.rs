//! Exact statistics in constant memory, for tables read in passes rather than held: order
//! statistics by radix selection, and correctly rounded sums. Both give the same bits as
//! sorting the values would, whatever the order the values come in, so a summary does not
//! depend on how the runs were split between threads or shards.

/// `x` as a `u64` whose unsigned order is `f64::total_cmp`'s order of `x`.
pub fn ordered_key(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 { !b } else { b | 1 << 63 }
}

/// The `f64` of an [`ordered_key`].
pub fn from_ordered_key(k: u64) -> f64 {
    f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k })
}

/// Bits resolved per pass of [`RadixSelect`].
const DIGIT_BITS: u32 = 8;
/// Passes [`RadixSelect`] needs to resolve a 64-bit key.
pub const PASSES: u32 = 64 / DIGIT_BITS;

/// Finds the keys at given ranks (0-based, in ascending order) of a multiset of `u64` keys
/// that is presented once per pass, in [`PASSES`] passes of any order, holding 256 counts
/// per distinct rank (MSD radix selection).
#[derive(Debug, Clone)]
pub struct RadixSelect {
    /// Distinct ranks asked for, ascending.
    ranks: Vec<u64>,
    /// Per rank: the high bits resolved so far (the rest zero).
    prefix: Vec<u64>,
    /// Per rank: its rank among the keys that share `prefix`.
    remaining: Vec<u64>,
    /// Distinct prefixes of this pass, ascending, and the counts of the next digit under each.
    groups: Vec<(u64, [u64; 256])>,
    pass: u32,
}

impl RadixSelect {
    /// Selection of the keys at `ranks` (each below the number of keys that will be shown).
    pub fn new(ranks: &[u64]) -> Self {
        let mut r = ranks.to_vec();
        r.sort_unstable();
        r.dedup();
        let n = r.len();
        let mut s = Self {
            remaining: r.clone(),
            ranks: r,
            prefix: vec![0; n],
            groups: Vec::new(),
            pass: 0,
        };
        s.regroup();
        s
    }

    fn regroup(&mut self) {
        let mut prefixes = self.prefix.clone();
        prefixes.dedup();
        self.groups = prefixes.into_iter().map(|p| (p, [0; 256])).collect();
    }

    /// Whether every rank is resolved.
    pub fn done(&self) -> bool {
        self.pass == PASSES || self.ranks.is_empty()
    }

    /// Counts one key in the current pass.
    #[inline]
    pub fn observe(&mut self, key: u64) {
        if self.done() {
            return;
        }
        let known = DIGIT_BITS * self.pass;
        let high = if known == 0 {
            0
        } else {
            key & !(u64::MAX >> known)
        };
        let digit = ((key >> (64 - known - DIGIT_BITS)) & 0xff) as usize;
        // The prefixes are sorted, and the ranks' prefixes form one chain of ascending
        // intervals: a key falls under at most one.
        if let Ok(g) = self.groups.binary_search_by(|(p, _)| p.cmp(&high)) {
            self.groups[g].1[digit] += 1;
        }
    }

    /// Ends a pass: resolves the next digit of every rank.
    pub fn end_pass(&mut self) {
        if self.done() {
            return;
        }
        let shift = 64 - DIGIT_BITS * (self.pass + 1);
        for i in 0..self.ranks.len() {
            let g = self
                .groups
                .binary_search_by(|(p, _)| p.cmp(&self.prefix[i]))
                .unwrap_or(0);
            let counts = &self.groups[g].1;
            let mut below = 0;
            for (d, &c) in counts.iter().enumerate() {
                if self.remaining[i] < below + c {
                    self.prefix[i] |= (d as u64) << shift;
                    self.remaining[i] -= below;
                    break;
                }
                below += c;
            }
        }
        self.pass += 1;
        self.regroup();
    }

    /// The key at `rank` (one of those given to [`RadixSelect::new`]) once [`done`].
    ///
    /// [`done`]: RadixSelect::done
    pub fn key(&self, rank: u64) -> u64 {
        self.prefix[self.index(rank)]
    }

    /// How many keys equal to [`RadixSelect::key`] come before `rank` in ascending order
    /// (0 unless the key is repeated).
    pub fn rank_among_equals(&self, rank: u64) -> u64 {
        self.remaining[self.index(rank)]
    }

    fn index(&self, rank: u64) -> usize {
        self.ranks.binary_search(&rank).unwrap_or(0)
    }
}

/// A sum of `f64` values rounded once, at the end (Shewchuk's adaptive-precision
/// expansions, 1997): the result is the exact sum correctly rounded, so it does not depend
/// on the order of the values. Finite values only.
#[derive(Debug, Clone, Default)]
pub struct ExactSum {
    /// Non-overlapping partial sums, ascending in magnitude.
    partials: Vec<f64>,
}

impl ExactSum {
    /// Adds `x`.
    pub fn add(&mut self, mut x: f64) {
        let mut kept = 0;
        for k in 0..self.partials.len() {
            let mut y = self.partials[k];
            if x.abs() < y.abs() {
                std::mem::swap(&mut x, &mut y);
            }
            let hi = x + y;
            let lo = y - (hi - x);
            if lo != 0.0 {
                self.partials[kept] = lo;
                kept += 1;
            }
            x = hi;
        }
        self.partials.truncate(kept);
        self.partials.push(x);
    }

    /// The sum, correctly rounded (to nearest, ties to even).
    pub fn value(&self) -> f64 {
        let p = &self.partials;
        let Some(mut n) = p.len().checked_sub(1) else {
            return 0.0;
        };
        let mut hi = p[n];
        let mut lo = 0.0;
        while n > 0 {
            let x = hi;
            n -= 1;
            let y = p[n];
            hi = x + y;
            lo = y - (hi - x);
            if lo != 0.0 {
                break;
            }
        }
        // Round half to even: if the rest below `lo` pushes the same way as `lo`, `hi` was
        // rounded the wrong way at a tie.
        if n > 0 && ((lo < 0.0 && p[n - 1] < 0.0) || (lo > 0.0 && p[n - 1] > 0.0)) {
            let y = lo * 2.0;
            let x = hi + y;
            if y == x - hi {
                hi = x;
            }
        }
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn select_all(keys: &[u64], ranks: &[u64]) -> RadixSelect {
        let mut s = RadixSelect::new(ranks);
        while !s.done() {
            for &k in keys {
                s.observe(k);
            }
            s.end_pass();
        }
        s
    }

    #[test]
    fn ordered_keys_sort_as_total_cmp() {
        let mut v = vec![
            -f64::NAN,
            f64::NEG_INFINITY,
            -1e300,
            -1.0,
            -5e-324,
            -0.0,
            0.0,
            5e-324,
            1.0,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ];
        let keys: Vec<u64> = v.iter().map(|&x| ordered_key(x)).collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        for (x, k) in v.iter().zip(&keys) {
            assert_eq!(from_ordered_key(*k).to_bits(), x.to_bits());
        }
        v.reverse();
        v.sort_by(f64::total_cmp);
        assert_eq!(v[0].to_bits(), (-f64::NAN).to_bits());
    }

    #[test]
    fn selection_equals_sorting_with_ties_and_both_signs() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for n in [1usize, 2, 7, 1000, 5000] {
            let mut values: Vec<f64> = (0..n)
                .map(|i| match i % 5 {
                    0 => rng.random::<f64>() * 1e3,
                    1 => -rng.random::<f64>(),
                    2 => 42.0,
                    3 => (rng.random::<f64>() - 0.5) * 1e-300,
                    _ => -0.0,
                })
                .collect();
            let keys: Vec<u64> = values.iter().map(|&x| ordered_key(x)).collect();
            values.sort_by(f64::total_cmp);
            let ranks: Vec<u64> = [0, n / 3, n / 2, n - 1, (n - 1) / 2]
                .iter()
                .map(|&r| r as u64)
                .collect();
            let s = select_all(&keys, &ranks);
            for &r in &ranks {
                let got = from_ordered_key(s.key(r));
                assert_eq!(
                    got.to_bits(),
                    values[r as usize].to_bits(),
                    "n {n} rank {r}"
                );
                let first = values.iter().position(|x| x.to_bits() == got.to_bits());
                assert_eq!(s.rank_among_equals(r), r - first.unwrap() as u64);
            }
        }
    }

    #[test]
    fn exact_sum_is_correctly_rounded_in_any_order() {
        // 1 + 1e100 + 1 - 1e100 = 2 exactly; naive summation gives 0.
        let mut s = ExactSum::default();
        for x in [1.0, 1e100, 1.0, -1e100] {
            s.add(x);
        }
        assert_eq!(s.value(), 2.0);
        // A tie: 1 + 2^-53 + 2^-106 rounds up; without the last term it rounds to even (1).
        let mut t = ExactSum::default();
        for x in [1.0, 2f64.powi(-53), 2f64.powi(-106)] {
            t.add(x);
        }
        assert_eq!(t.value(), 1.0 + f64::EPSILON);
        let mut u = ExactSum::default();
        for x in [1.0, 2f64.powi(-53)] {
            u.add(x);
        }
        assert_eq!(u.value(), 1.0);
        // Order does not matter.
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut v: Vec<f64> = (0..2000)
            .map(|_| (rng.random::<f64>() - 0.5) * 10f64.powi(rng.random_range(-20..20)))
            .collect();
        let sum = |v: &[f64]| {
            let mut s = ExactSum::default();
            v.iter().for_each(|&x| s.add(x));
            s.value()
        };
        let a = sum(&v);
        v.reverse();
        assert_eq!(sum(&v).to_bits(), a.to_bits());
        v.sort_by(f64::total_cmp);
        assert_eq!(sum(&v).to_bits(), a.to_bits());
    }
}
