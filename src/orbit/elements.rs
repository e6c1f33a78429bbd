//! Classical orbital elements and their validation.

use super::CentralBody;
use std::f64::consts::PI;

/// Classical (Keplerian) elements at the scenario epoch `t = 0`, SI units and radians.
///
/// Angles follow Vallado, *Fundamentals of Astrodynamics and Applications* (4th ed., §2.4):
/// the inclination `i ∈ [0, π]` from the ECI z axis to the orbit normal `h`, the right
/// ascension of the ascending node Ω from the ECI x axis in the equatorial plane, the
/// argument of perigee ω from the node to perigee in the orbit plane (in the direction of
/// motion), and the true anomaly ν₀ from perigee to the spacecraft. For a circular orbit
/// (`e = 0`) perigee is undefined, only `ω + ν₀` (the argument of latitude) matters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elements {
    /// Semi-major axis a (m).
    pub semi_major_axis: f64,
    /// Eccentricity e, `0 ≤ e < 1`.
    pub eccentricity: f64,
    /// Inclination i (rad), `0 ≤ i ≤ π`.
    pub inclination: f64,
    /// Right ascension of the ascending node Ω (rad).
    pub raan: f64,
    /// Argument of perigee ω (rad).
    pub arg_perigee: f64,
    /// True anomaly ν₀ at the epoch (rad).
    pub true_anomaly: f64,
}

impl Elements {
    /// Elements from `(a, e, i, Ω, ω, ν₀)`: a in m, angles in rad. Not checked here: see
    /// [`Elements::validate`] (which [`super::Orbit::new`] calls).
    pub fn new(a: f64, e: f64, i: f64, raan: f64, arg_perigee: f64, true_anomaly: f64) -> Self {
        Elements {
            semi_major_axis: a,
            eccentricity: e,
            inclination: i,
            raan,
            arg_perigee,
            true_anomaly,
        }
    }

    /// Elements from the perigee and apogee ALTITUDES above the body's equatorial radius
    /// R (m): `r_p = R + h_p`, `r_a = R + h_a`, `a = (r_p + r_a)/2`,
    /// `e = (r_a − r_p)/(r_a + r_p)`; angles in rad. Validated.
    pub fn from_altitudes(
        body: &CentralBody,
        perigee_altitude: f64,
        apogee_altitude: f64,
        inclination: f64,
        raan: f64,
        arg_perigee: f64,
        true_anomaly: f64,
    ) -> Result<Self, String> {
        finite("perigee altitude", perigee_altitude, "m")?;
        finite("apogee altitude", apogee_altitude, "m")?;
        if apogee_altitude < perigee_altitude {
            return Err(format!(
                "apogee altitude {:.3} km is below the perigee altitude {:.3} km: expected \
                 apogee ≥ perigee",
                apogee_altitude / 1e3,
                perigee_altitude / 1e3
            ));
        }
        if perigee_altitude < 0.0 {
            return Err(format!(
                "perigee altitude {:.3} km: the perigee is {:.3} km below the surface \
                 (R = {:.3} km); expected an altitude ≥ 0",
                perigee_altitude / 1e3,
                -perigee_altitude / 1e3,
                body.radius / 1e3
            ));
        }
        let rp = body.radius + perigee_altitude;
        let ra = body.radius + apogee_altitude;
        let el = Elements::new(
            0.5 * (rp + ra),
            (ra - rp) / (ra + rp),
            inclination,
            raan,
            arg_perigee,
            true_anomaly,
        );
        el.validate(body)?;
        Ok(el)
    }

    /// Checks the elements: all finite, `a > 0`, `0 ≤ e < 1`, `0 ≤ i ≤ π`, and the perigee
    /// radius `a(1 − e)` not below the body's surface (radius R). The message names the
    /// quantity and what was expected.
    pub fn validate(&self, body: &CentralBody) -> Result<(), String> {
        finite("semi-major axis", self.semi_major_axis, "m")?;
        finite("eccentricity", self.eccentricity, "")?;
        finite("inclination", self.inclination, "rad")?;
        finite("right ascension of the ascending node", self.raan, "rad")?;
        finite("argument of perigee", self.arg_perigee, "rad")?;
        finite("true anomaly", self.true_anomaly, "rad")?;
        let (a, e, i) = (self.semi_major_axis, self.eccentricity, self.inclination);
        if a <= 0.0 {
            return Err(format!(
                "semi-major axis {a} m: expected a > 0 (polhode propagates closed orbits)"
            ));
        }
        if !(0.0..1.0).contains(&e) {
            return Err(format!(
                "eccentricity {e}: polhode propagates closed orbits: 0 ≤ e < 1"
            ));
        }
        if !(0.0..=PI).contains(&i) {
            return Err(format!(
                "inclination {i} rad ({:.6}°): expected 0 ≤ i ≤ π rad (0° to 180°)",
                i.to_degrees()
            ));
        }
        let rp = a * (1.0 - e);
        if rp < body.radius {
            return Err(format!(
                "perigee radius a(1 − e) = {:.3} km: the perigee is {:.3} km below the surface \
                 (R = {:.3} km)",
                rp / 1e3,
                (body.radius - rp) / 1e3,
                body.radius / 1e3
            ));
        }
        Ok(())
    }
}

fn finite(what: &str, x: f64, unit: &str) -> Result<(), String> {
    if x.is_finite() {
        Ok(())
    } else {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        Err(format!("{what} is {x}{unit}: expected a finite number"))
    }
}
