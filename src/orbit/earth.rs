//! The Earth's rotation angle, for rotating Earth-fixed quantities (magnetic field,
//! co-rotating atmosphere) into the ECI frame.
//!
//! Time argument everywhere: the scenario epoch as Unix nanoseconds (UTC, the value
//! [`crate::scenario::parse_epoch`] returns) plus `t` seconds of simulation time. UT1 is
//! taken equal to UTC: |UT1 − UTC| < 0.9 s by definition of UTC, so the angle is off by
//! at most 0.9 s × ω_E ≈ 6.6e-5 rad (0.004°).

use std::f64::consts::TAU;

/// Unix time of J2000.0 (2000-01-01T12:00:00), in ns.
const J2000_UNIX_NS: i64 = 946_728_000_000_000_000;
const NS_PER_DAY: i64 = 86_400_000_000_000;

/// UT1 days since J2000.0 as `(whole days, fraction)`, with the whole part exact.
fn days_since_j2000(epoch_unix_ns: i64, t: f64) -> (f64, f64) {
    let d_ns = epoch_unix_ns - J2000_UNIX_NS;
    let whole = d_ns.div_euclid(NS_PER_DAY);
    let rem_ns = d_ns.rem_euclid(NS_PER_DAY);
    let frac = (rem_ns as f64 * 1e-9 + t) / 86_400.0;
    (whole as f64, frac)
}

/// Earth rotation angle θ (rad, in `[0, 2π)`) at `t` seconds after the epoch:
/// the IAU 2000 definition (IAU 2000 Resolution B1.8; IERS Conventions 2010, eq. 5.15)
/// `θ = 2π (0.7790572732640 + 1.00273781191135448 D_U)`, `D_U = JD(UT1) − 2451545.0`.
///
/// The whole days of `D_U` are dropped from the `1.0 · D_U` part before the sum (they are
/// whole turns), which keeps the full `f64` resolution of the day fraction.
///
/// Which angle to use: with ECI taken as the GCRS (J2000) axes and precession–nutation
/// neglected, rotating Earth-fixed vectors by `R3(−θ)` with θ the ERA leaves only the
/// motion of the pole (≈ 20″ per year since 2000) as error, whereas GMST
/// ([`gmst_iau82`]) also carries the accumulated precession in right ascension
/// (≈ 4612″ per century, 0.32° by 2025). Use the ERA unless matching Vallado's
/// equinox-based examples.
pub fn earth_rotation_angle(epoch_unix_ns: i64, t: f64) -> f64 {
    let (whole, frac) = days_since_j2000(epoch_unix_ns, t);
    let turns = 0.779_057_273_264_0 + frac + 0.002_737_811_911_354_48 * (whole + frac);
    TAU * turns.rem_euclid(1.0)
}

/// Greenwich mean sidereal time (rad, in `[0, 2π)`), IAU 1982 model (Vallado,
/// *Fundamentals of Astrodynamics and Applications*, 4th ed., eq. 3-47 and Algorithm 15):
/// `θ = 67310.54841 s + (876600 h + 8640184.812866 s) T + 0.093104 s T² − 6.2e-6 s T³`,
/// `T = D_U/36525` (Julian centuries of UT1 since J2000.0), converted at 240 s per degree.
///
/// `876600 h · T` is `86400 s · D_U` exactly, of which only the day fraction contributes
/// modulo one day; it is evaluated that way to keep precision.
pub fn gmst_iau82(epoch_unix_ns: i64, t: f64) -> f64 {
    let (whole, frac) = days_since_j2000(epoch_unix_ns, t);
    let tc = (whole + frac) / 36_525.0;
    let seconds = 67_310.548_41
        + 86_400.0 * frac.rem_euclid(1.0)
        + tc * (8_640_184.812_866 + tc * (0.093_104 - 6.2e-6 * tc));
    TAU * (seconds / 86_400.0).rem_euclid(1.0)
}
