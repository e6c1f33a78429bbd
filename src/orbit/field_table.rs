//! The IGRF-14 field along an analytic orbit, tabulated once per run.
//!
//! The orbit is a known function of time, and so is the field at the spacecraft's centre of
//! mass in inertial axes, B_N(t) = R₃(−θ(t)) B_ECEF(R₃(θ(t)) r_N(t), t), θ the Earth rotation
//! angle. Rather than sum the degree-13 harmonics at every right-hand side (about 85 times a
//! dipole's cost), the run's span is cut into segments of at most an eighth of an orbit and
//! 600 s, and each component of B_N on a segment is held as the Chebyshev interpolant through
//! [`NODES`] points ([`crate::chebyshev`]). Where the field varies fastest along a low orbit
//! (degree 13 on the reference sphere, a wavelength of about 3000 km, some 400 s at 7.5 km/s)
//! a segment spans under two of its periods, and 20 points resolve that to well below a
//! picotesla. Every segment is checked at the 19 points between its nodes against the
//! harmonics themselves; a segment that misses [`TOLERANCE`] is halved until it meets it, and
//! the largest departure found is kept ([`FieldTable::max_error`]) and reported with the run.
//! The IGRF's own accuracy is of order 10–100 nT (it leaves out the crustal and external
//! fields), so the table adds nothing visible to the model's error.

use super::Orbit;
use super::earth_rotation_angle;
use super::igrf::Coefficients;
use super::magnetic::decimal_year;
use super::recent;
use crate::chebyshev::{Chebyshev, clenshaw, coefficients};
use nalgebra::Vector3;

/// Chebyshev points per segment.
pub const NODES: usize = 20;
/// Largest departure from the harmonics (T) a segment may show at its check points: 1 pT.
pub const TOLERANCE: f64 = 1e-12;
/// Longest segment (s).
const MAX_SEGMENT: f64 = 600.0;
/// Most evaluations of the harmonics a table may cost (about 2.5 µs each with the year's
/// coefficients and the orbit position: some 1.2 s of load, 90 days of a low orbit): past
/// this a run evaluates the harmonics directly instead ([`FieldTable::build`] returns
/// `None`).
pub const MAX_EVALUATIONS: usize = 500_000;

/// The IGRF-14 field (T, inertial axes) at the orbit position at time `t` (s after the epoch
/// `epoch_unix_ns`), from the harmonics; `Err` outside IGRF-14's years.
pub fn igrf_on_orbit(orbit: &Orbit, epoch_unix_ns: i64, t: f64) -> Result<Vector3<f64>, String> {
    let (r_hat, radius) = orbit.direction(t);
    igrf_eci(epoch_unix_ns, t, &(radius * r_hat))
}

/// The IGRF-14 field (T, inertial axes) at the inertial position `r` (m) at time `t` (s after
/// the epoch `epoch_unix_ns`).
pub fn igrf_eci(epoch_unix_ns: i64, t: f64, r: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    let year = decimal_year(epoch_unix_ns as f64 * 1e-9 + t);
    let c = Coefficients::igrf14(year)?;
    let (s, co) = earth_rotation_angle(epoch_unix_ns, t).sin_cos();
    let ecef = Vector3::new(co * r.x + s * r.y, -s * r.x + co * r.y, r.z);
    let b = c.field_ecef(&ecef);
    Ok(Vector3::new(co * b.x - s * b.y, s * b.x + co * b.y, b.z))
}

/// One segment: its start (s), length (s) and the three components' coefficients.
#[derive(Debug, Clone)]
struct Segment {
    start: f64,
    length: f64,
    coefficients: [[f64; NODES]; 3],
}

/// The field along one orbit over [0, end] s.
#[derive(Debug, Clone)]
pub struct FieldTable {
    segments: Vec<Segment>,
    /// Nominal segment length (s): the nominal segment k spans [k, k + 1) times it.
    nominal: f64,
    /// Index in `segments` of the first piece of each nominal segment (halving splits one
    /// into pieces).
    first: Vec<usize>,
    end: f64,
    max_error: f64,
    /// This table's identity ([`recent::next_id`]; a clone keeps it), for the answers kept
    /// per thread ([`recent`]).
    id: u64,
}

impl FieldTable {
    /// The table for `orbit` from the epoch `epoch_unix_ns` over `duration` s; `Ok(None)` when
    /// it would cost more than [`MAX_EVALUATIONS`] (a very long run), `Err` outside
    /// IGRF-14's years.
    pub fn build(
        orbit: &Orbit,
        epoch_unix_ns: i64,
        duration: f64,
    ) -> Result<Option<FieldTable>, String> {
        let nominal = (orbit.period() / 8.0).min(MAX_SEGMENT);
        let count = (duration / nominal).ceil().max(1.0) as usize;
        if count.saturating_mul(2 * NODES) > MAX_EVALUATIONS {
            return Ok(None);
        }
        let exact = |t: f64| igrf_on_orbit(orbit, epoch_unix_ns, t);
        let mut segments = Vec::with_capacity(count);
        let mut first = Vec::with_capacity(count);
        let mut max_error: f64 = 0.0;
        for k in 0..count {
            first.push(segments.len());
            let (start, stop) = (k as f64 * nominal, ((k + 1) as f64 * nominal).min(duration));
            let stop = stop.max(start + 1e-9 * nominal.max(1.0));
            // Halve until the segment meets the tolerance (a coarse one is split in two).
            let mut pending = vec![(start, stop)];
            while let Some((a, b)) = pending.pop() {
                let (segment, error) = Self::fit(&exact, a, b)?;
                if error > TOLERANCE && b - a > 1.0 {
                    let mid = 0.5 * (a + b);
                    pending.push((mid, b));
                    pending.push((a, mid));
                    continue;
                }
                max_error = max_error.max(error);
                segments.push(segment);
            }
        }
        Ok(Some(FieldTable {
            segments,
            nominal,
            first,
            end: duration,
            max_error,
            id: recent::next_id(),
        }))
    }

    /// One segment on [a, b] and its largest departure (T) at the points between its nodes.
    fn fit(
        exact: &dyn Fn(f64) -> Result<Vector3<f64>, String>,
        a: f64,
        b: f64,
    ) -> Result<(Segment, f64), String> {
        let nodes = Chebyshev::nodes(a, b, NODES);
        let samples = nodes
            .iter()
            .map(|&t| exact(t))
            .collect::<Result<Vec<_>, _>>()?;
        let mut segment = Segment {
            start: a,
            length: b - a,
            coefficients: [[0.0; NODES]; 3],
        };
        for (i, c) in segment.coefficients.iter_mut().enumerate() {
            let values: Vec<f64> = samples.iter().map(|v| v[i]).collect();
            c.copy_from_slice(&coefficients(&values));
        }
        let mut error: f64 = 0.0;
        for t in Chebyshev::nodes(a, b, NODES - 1) {
            error = error.max((segment.at(t) - exact(t)?).amax());
        }
        Ok((segment, error))
    }

    /// The field (T, inertial axes) at `t` (s), or `None` outside [0, end].
    #[inline]
    pub fn field_eci(&self, t: f64) -> Option<Vector3<f64>> {
        if !(0.0..=self.end).contains(&t) {
            return None;
        }
        // Kind 1: a table (the key names it alone: it was built for one orbit and epoch).
        Some(recent::kept([1, self.id, 0, t.to_bits()], || {
            self.evaluate(t)
        }))
    }

    /// The segments' value at `t` in [0, end] (T, inertial axes).
    #[inline]
    fn evaluate(&self, t: f64) -> Vector3<f64> {
        let nominal = ((t / self.nominal) as usize).min(self.first.len() - 1);
        let mut k = self.first[nominal];
        // The pieces of a halved segment: step to the one that holds t.
        while k + 1 < self.segments.len() && self.segments[k + 1].start <= t {
            k += 1;
        }
        self.segments[k].at(t)
    }

    /// The largest departure from the harmonics found at the check points (T).
    pub fn max_error(&self) -> f64 {
        self.max_error
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.segments.len()
    }

    /// Whether it has no segment (never: a table has at least one).
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }
}

impl Segment {
    #[inline]
    fn at(&self, t: f64) -> Vector3<f64> {
        let s = 2.0 * (t - self.start) / self.length - 1.0;
        Vector3::new(
            clenshaw(&self.coefficients[0], s),
            clenshaw(&self.coefficients[1], s),
            clenshaw(&self.coefficients[2], s),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::{CentralBody, Elements};

    fn table(true_anomaly: f64) -> FieldTable {
        let elements = Elements::new(6878.137e3, 0.0, 1.7, 0.7, 0.0, true_anomaly);
        let orbit = Orbit::new(CentralBody::EARTH, elements, true).unwrap();
        // 2027-03-01 (Unix ns), one hour.
        FieldTable::build(&orbit, 1_803_945_600_000_000_000, 3600.0)
            .unwrap()
            .unwrap()
    }

    /// The evaluations a thread keeps answer each table with its own segments' value, bit for
    /// bit: two tables of two orbits asked in turn at the same times, each time asked again
    /// before and after more times than are kept, and a clone answering as its original.
    #[test]
    fn kept_evaluations_answer_each_table_with_its_own_value() {
        let (a, b) = (table(0.3), table(2.0));
        let copy = a.clone();
        let bits = |v: Vector3<f64>| v.map(f64::to_bits);
        let times: Vec<f64> = (0..3 * recent::KEPT)
            .map(|k| 0.5 + 97.3 * k as f64)
            .collect();
        for round in 0..3 {
            for (k, &t) in times.iter().enumerate() {
                let t_again = times[k.saturating_sub(round)];
                for (table, other) in [(&a, &b), (&b, &a), (&copy, &b)] {
                    for t in [t, t_again, t] {
                        let value = table.field_eci(t).unwrap();
                        assert_eq!(bits(value), bits(table.evaluate(t)), "t = {t}");
                        assert_ne!(bits(value), bits(other.evaluate(t)), "t = {t}");
                    }
                }
            }
        }
        assert!(a.field_eci(3601.0).is_none() && a.field_eci(f64::NAN).is_none());
    }
}
