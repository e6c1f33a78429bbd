//! The sample clock of a discrete controller inside the continuous simulation: it samples at
//! t_k = k Δt (k = 0, 1, 2, …) and holds its command until the next tick (a zero-order hold).
//!
//! Each tick is a breakpoint ([`crate::model::Effector::next_breakpoint`]): the integrators
//! stop exactly on it, the controller samples the state there and updates its held command,
//! and the method restarts on the far side (docs/integrators.md, "Breakpoints"). The tick at
//! t = 0 is taken when the initial state is built.

/// Ticks every `period` seconds from t = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleClock {
    /// The sample interval Δt (s, > 0).
    pub period: f64,
}

impl SampleClock {
    /// A clock ticking at `rate` (Hz, > 0).
    pub fn from_rate(rate: f64) -> SampleClock {
        SampleClock { period: 1.0 / rate }
    }

    /// The time of tick `k` (s): k Δt, computed from k so that ticks do not drift.
    #[inline]
    pub fn tick(&self, k: u64) -> f64 {
        k as f64 * self.period
    }

    /// The first tick strictly after `t` (s).
    #[inline]
    pub fn next_tick(&self, t: f64) -> f64 {
        let mut k = (t / self.period).floor().max(0.0) as u64 + 1;
        // t / Δt may round below an integer for a t that is itself a tick.
        while self.tick(k) <= t {
            k += 1;
        }
        // …or above it, skipping a tick just after t.
        while k > 1 && self.tick(k - 1) > t {
            k -= 1;
        }
        self.tick(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_next_tick_is_strictly_after_and_never_skips_one() {
        for rate in [1.0, 3.0, 7.0, 10.0, 0.3] {
            let clock = SampleClock::from_rate(rate);
            let mut t = 0.0;
            for k in 1..10_000u64 {
                let next = clock.next_tick(t);
                assert_eq!(next, clock.tick(k), "rate {rate}, tick {k}");
                t = next;
            }
            // From between ticks, the next one.
            assert_eq!(clock.next_tick(2.5 * clock.period), clock.tick(3));
            assert_eq!(clock.next_tick(0.0), clock.tick(1));
        }
    }
}
