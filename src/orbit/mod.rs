//! The spacecraft's orbit, as a model-level input for environment effectors (gravity
//! gradient, magnetic field, drag, solar pressure): an analytic, stateless function of the
//! simulation time `t` (s since the scenario epoch), cheap enough to be called many times
//! per step. See `docs/environment.md`, section "Orbit".
//!
//! Conventions:
//! - ECI: an inertial frame with z along the body's rotation axis and x toward the vernal
//!   equinox (taken as the GCRS/J2000 axes; precession and nutation are not modelled).
//!   Positions in m, velocities in m/s, angles in rad, times in s.
//! - Elements: classical `(a, e, i, Ω, ω, ν₀)` at `t = 0` ([`Elements`]).
//! - Two-body motion (Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed.,
//!   §2.2–2.3 and Algorithm 10 COE2RV; Curtis, *Orbital Mechanics for Engineering
//!   Students*, ch. 3–4): `M = M₀ + Ṁ t`, Kepler's equation `E − e sin E = M` ([`kepler`]),
//!   perifocal position `a(cos E − e) P̂ + a√(1−e²) sin E Q̂`, velocity
//!   `(√(μa)/r)(−sin E P̂ + √(1−e²) cos E Q̂)`, `r = a(1 − e cos E)`, with the perifocal axes
//!   `[P̂ Q̂ Ŵ] = R3(−Ω) R1(−i) R3(−ω)`. `cos E − e` and `1 − e cos E` are formed as
//!   `(1 − e) − (1 − cos E)` and `(1 − e) + e(1 − cos E)` with `1 − cos E = 2 sin²(E/2)`,
//!   which keep their digits as `e → 1` near perigee, where `cos E` rounds to 1.
//! - Optional secular J2 drift ([`Orbit::new`] with `j2_secular`): Ω, ω and M advance at
//!   the first-order secular rates (Vallado §9.6), and the state is formed from the
//!   drifted elements as in Vallado's PKEPLER algorithm (§9.6). The velocity is then the
//!   two-body velocity of the current elements (as for osculating elements), which differs
//!   from the time derivative of the position by the secular rates (≈ |Ω̇| r, a few m/s in
//!   LEO). No short-period terms, no drag.
//! - LVLH ([`Lvlh`]): `o3 = −r̂` (nadir), `o2 = −ĥ` (negative orbit normal),
//!   `o1 = o2 × o3` (along track for a circular orbit).

mod body;
mod earth;
mod elements;
pub mod field_table;
pub mod igrf;
pub mod kepler;
pub mod magnetic;
pub mod recent;

pub use body::CentralBody;
pub use earth::{earth_rotation_angle, gmst_iau82};
pub use elements::Elements;
pub use magnetic::GeomagneticField;

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use std::f64::consts::TAU;

/// Secular rates of the elements (rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SecularRates {
    /// dΩ/dt: `−(3/2) n J2 (R/p)² cos i` with J2, else 0.
    pub raan: f64,
    /// dω/dt: `(3/4) n J2 (R/p)² (5 cos² i − 1)` with J2, else 0.
    pub arg_perigee: f64,
    /// dM/dt: `n [1 + (3/4) J2 (R/p)² √(1−e²) (3 cos² i − 1)]` with J2, else `n`.
    pub mean_anomaly: f64,
}

/// The LVLH (orbit) frame at one instant, and its motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lvlh {
    /// Direction cosine matrix whose ROWS are `o1, o2, o3` in ECI components: it maps ECI
    /// components to LVLH components, `v_O = C_ON v_N`.
    pub eci_to_lvlh: Matrix3<f64>,
    /// Angular velocity ω_ON of the LVLH frame relative to ECI, in ECI components (rad/s):
    /// `Ω̇ ẑ + (ω̇ + ν̇) ĥ` with `ĥ = −o2` and `ν̇ = Ṁ (a/r)² √(1−e²)` (`= |h|/r²` for a
    /// Keplerian orbit).
    pub omega: Vector3<f64>,
    /// Time derivative of [`Lvlh::omega`] (rad/s², ECI components; the same vector as the
    /// derivative taken in the LVLH frame, since `ω × ω = 0`):
    /// `ν̈ ĥ + (ω̇ + ν̇) Ω̇ (ẑ × ĥ)`, `ν̈ = −2 ν̇ ṙ/r`.
    pub omega_dot: Vector3<f64>,
}

impl Lvlh {
    /// Along-track axis `o1` in ECI.
    pub fn o1(&self) -> Vector3<f64> {
        self.eci_to_lvlh.row(0).transpose()
    }
    /// Negative orbit normal `o2` in ECI.
    pub fn o2(&self) -> Vector3<f64> {
        self.eci_to_lvlh.row(1).transpose()
    }
    /// Nadir `o3` in ECI.
    pub fn o3(&self) -> Vector3<f64> {
        self.eci_to_lvlh.row(2).transpose()
    }
    /// The attitude of the LVLH frame as a quaternion `q_NO` in the crate's convention (it
    /// maps LVLH components to ECI components, `v_N = q_NO · v_O`, like the body attitude
    /// maps body to inertial): the rotation whose matrix is `eci_to_lvlhᵀ`.
    pub fn lvlh_to_eci(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            self.eci_to_lvlh.transpose(),
        ))
    }
    /// [`Lvlh::omega`] in LVLH components.
    pub fn omega_in_lvlh(&self) -> Vector3<f64> {
        self.eci_to_lvlh * self.omega
    }
}

/// An orbit about a central body: two-body motion, optionally with the secular J2 drift of
/// the node, perigee and mean anomaly. Stateless: every query depends on `t` alone.
///
/// The fields are private because the constructor caches derived quantities (mean motion,
/// rates, perifocal axes); read them with [`Orbit::body`], [`Orbit::elements`] and
/// [`Orbit::j2_secular`].
#[derive(Debug, Clone)]
pub struct Orbit {
    /// This orbit's identity ([`recent::next_id`]; a clone keeps it), for the field values
    /// kept per thread; not part of its equality.
    id: u64,
    body: CentralBody,
    elements: Elements,
    j2_secular: bool,
    /// Keplerian mean motion (rad/s).
    n: f64,
    rates: SecularRates,
    /// Mean anomaly at t = 0 (rad).
    m0: f64,
    /// √(1 − e²).
    eta: f64,
    /// Semi-minor axis a√(1 − e²) (m).
    b: f64,
    /// √(μ a) (m²/s).
    sqrt_mu_a: f64,
    cos_i: f64,
    sin_i: f64,
    /// Perifocal axes at t = 0 (fixed without J2).
    axes0: [Vector3<f64>; 3],
    /// μ/a³ (1/s²): μ/r³ at every instant of a circular orbit.
    mu_over_a3: f64,
}

/// The Kepler solution at one instant.
struct Phase {
    sin_e: f64,
    cos_e: f64,
    /// `cos E − e`, as `(1 − e) − (1 − cos E)`: no cancellation as `e → 1` near perigee,
    /// where `cos E` and `e` both round to about 1 and their difference to noise.
    cos_e_minus_e: f64,
    /// Orbit radius (m).
    r: f64,
    /// Perifocal axes P̂, Q̂, Ŵ in ECI.
    axes: [Vector3<f64>; 3],
}

impl PartialEq for Orbit {
    /// Equal elements about the same body with the same secular rates: the same motion
    /// (whatever the identities).
    fn eq(&self, other: &Orbit) -> bool {
        let Orbit {
            id: _,
            body,
            elements,
            j2_secular,
            ..
        } = self;
        // The rest is derived from these three.
        *body == other.body && *elements == other.elements && *j2_secular == other.j2_secular
    }
}

impl Orbit {
    /// This orbit's identity: a number no other orbit built in the process has (its clones
    /// share it).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// An orbit from validated elements (see [`Elements::validate`]).
    pub fn new(body: CentralBody, elements: Elements, j2_secular: bool) -> Result<Orbit, String> {
        elements.validate(&body)?;
        let Elements {
            semi_major_axis: a,
            eccentricity: e,
            inclination: i,
            ..
        } = elements;
        let n = (body.mu / (a * a * a)).sqrt();
        let eta = ((1.0 - e) * (1.0 + e)).sqrt();
        let (sin_i, cos_i) = i.sin_cos();
        let rates = if j2_secular {
            let p = a * eta * eta;
            let k = body.j2 * (body.radius / p).powi(2);
            let c2 = cos_i * cos_i;
            SecularRates {
                raan: -1.5 * n * k * cos_i,
                arg_perigee: 0.75 * n * k * (5.0 * c2 - 1.0),
                mean_anomaly: n * (1.0 + 0.75 * k * eta * (3.0 * c2 - 1.0)),
            }
        } else {
            SecularRates {
                raan: 0.0,
                arg_perigee: 0.0,
                mean_anomaly: n,
            }
        };
        let (sn, cn) = elements.true_anomaly.sin_cos();
        let e0 = (eta * sn).atan2(e + cn);
        let m0 = kepler::mean_from_eccentric(e0, e);
        Ok(Orbit {
            id: recent::next_id(),
            body,
            elements,
            j2_secular,
            n,
            rates,
            m0,
            eta,
            b: a * eta,
            sqrt_mu_a: (body.mu * a).sqrt(),
            cos_i,
            sin_i,
            axes0: perifocal_axes(elements.raan, cos_i, sin_i, elements.arg_perigee),
            mu_over_a3: body.mu / (a * a * a),
        })
    }

    /// The central body.
    pub fn body(&self) -> &CentralBody {
        &self.body
    }

    /// The elements at t = 0.
    pub fn elements(&self) -> &Elements {
        &self.elements
    }

    /// Whether the secular J2 drift is applied.
    pub fn j2_secular(&self) -> bool {
        self.j2_secular
    }

    /// Keplerian mean motion `n = √(μ/a³)` (rad/s).
    pub fn mean_motion(&self) -> f64 {
        self.n
    }

    /// Keplerian period `2π/n` (s). With the secular J2 drift, the anomalistic period
    /// (perigee to perigee) is `2π/Ṁ` and the nodal period `2π/(Ṁ + ω̇)`, from
    /// [`Orbit::secular_rates`].
    pub fn period(&self) -> f64 {
        TAU / self.n
    }

    /// The rates of Ω, ω and M.
    pub fn secular_rates(&self) -> SecularRates {
        self.rates
    }

    /// Ω at time t (rad, not wrapped).
    pub fn raan(&self, t: f64) -> f64 {
        self.elements.raan + self.rates.raan * t
    }

    /// ω at time t (rad, not wrapped).
    pub fn arg_perigee(&self, t: f64) -> f64 {
        self.elements.arg_perigee + self.rates.arg_perigee * t
    }

    /// Mean anomaly at time t (rad, not wrapped).
    pub fn mean_anomaly(&self, t: f64) -> f64 {
        self.m0 + self.rates.mean_anomaly * t
    }

    fn phase(&self, t: f64) -> Phase {
        let e = self.elements.eccentricity;
        let m = self.mean_anomaly(t);
        let (sin_e, cos_e, one_minus_cos_e) = if e == 0.0 {
            // Circular: E = M, no Kepler solve; the table-driven sin/cos (a few ulps).
            let (s, c) = crate::sincos::sin_cos(m);
            (s, c, 1.0 - c)
        } else {
            let s = kepler::solve(m, e);
            (s.sin_e, s.cos_e, s.one_minus_cos_e)
        };
        let axes = if self.j2_secular {
            perifocal_axes(self.raan(t), self.cos_i, self.sin_i, self.arg_perigee(t))
        } else {
            self.axes0
        };
        Phase {
            sin_e,
            cos_e,
            cos_e_minus_e: if e == 0.0 {
                cos_e
            } else {
                (1.0 - e) - one_minus_cos_e
            },
            r: if e == 0.0 {
                self.elements.semi_major_axis
            } else {
                self.elements.semi_major_axis * ((1.0 - e) + e * one_minus_cos_e)
            },
            axes,
        }
    }

    /// Position (m) and velocity (m/s) in ECI at time t (s since the epoch).
    pub fn state(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let ph = self.phase(t);
        let a = self.elements.semi_major_axis;
        let [p, q, _] = ph.axes;
        let r = p * (a * ph.cos_e_minus_e) + q * (self.b * ph.sin_e);
        let k = self.sqrt_mu_a / ph.r;
        let v = p * (-k * ph.sin_e) + q * (k * self.eta * ph.cos_e);
        (r, v)
    }

    /// The unit vector from the body's centre to the spacecraft (ECI) and the distance (m) at
    /// time t: what the environment torques need, without the velocity. Equal to
    /// [`Orbit::state`]'s position over its norm.
    #[inline(always)]
    pub fn direction(&self, t: f64) -> (Vector3<f64>, f64) {
        if self.elements.eccentricity == 0.0 && !self.j2_secular {
            // Circular with fixed axes: a (P̂ cos M + Q̂ sin M), nothing else to form.
            let (sin_m, cos_m) = crate::sincos::sin_cos(self.mean_anomaly(t));
            let [p, q, _] = &self.axes0;
            return (p * cos_m + q * sin_m, self.elements.semi_major_axis);
        }
        let ph = self.phase(t);
        let (a, e) = (self.elements.semi_major_axis, self.elements.eccentricity);
        let [p, q, _] = ph.axes;
        if e == 0.0 {
            // Circular: r = a, and the position is a (P̂ cos E + Q̂ sin E) exactly.
            return (p * ph.cos_e + q * ph.sin_e, a);
        }
        let r = p * (a * ph.cos_e_minus_e) + q * (self.b * ph.sin_e);
        (r / ph.r, ph.r)
    }

    /// The unit vector from the body's centre to the spacecraft (ECI) and μ/r³ (1/s²) at time
    /// t: what the gravity gradient needs. For a circular orbit μ/r³ is the constant μ/a³,
    /// with no division per call.
    #[inline(always)]
    pub fn tidal_direction(&self, t: f64) -> (Vector3<f64>, f64) {
        let (r_hat, radius) = self.direction(t);
        let mu_over_r3 = if self.elements.eccentricity == 0.0 {
            self.mu_over_a3
        } else {
            self.body.mu / (radius * radius * radius)
        };
        (r_hat, mu_over_r3)
    }

    /// Distance from the body's centre (m).
    pub fn radius(&self, t: f64) -> f64 {
        self.phase(t).r
    }

    /// Altitude above the sphere of the equatorial radius R (m); not geodetic.
    pub fn altitude(&self, t: f64) -> f64 {
        self.radius(t) - self.body.radius
    }

    /// True anomaly ν (rad, in `(−π, π]`).
    pub fn true_anomaly(&self, t: f64) -> f64 {
        let ph = self.phase(t);
        (self.eta * ph.sin_e).atan2(ph.cos_e_minus_e)
    }

    /// Argument of latitude `u = ω + ν` (rad, in `[0, 2π)`): the angle from the ascending
    /// node to the spacecraft, in the direction of motion.
    pub fn argument_of_latitude(&self, t: f64) -> f64 {
        (self.arg_perigee(t) + self.true_anomaly(t)).rem_euclid(TAU)
    }

    /// The LVLH frame at time t, with its angular velocity and acceleration (see [`Lvlh`]).
    pub fn lvlh(&self, t: f64) -> Lvlh {
        let ph = self.phase(t);
        let (a, e) = (self.elements.semi_major_axis, self.elements.eccentricity);
        let [p, q, w] = ph.axes;
        // Normalised by the length of the perifocal position itself (not by r from
        // a(1 − e cos E)), so that cos²ν + sin²ν = 1 to rounding for any e.
        let (x, y) = (a * ph.cos_e_minus_e, self.b * ph.sin_e);
        let rho = (x * x + y * y).sqrt();
        let (cos_nu, sin_nu) = (x / rho, y / rho);
        let r_hat = p * cos_nu + q * sin_nu;
        let o1 = q * cos_nu - p * sin_nu; // ĥ × r̂
        let o2 = -w;
        let o3 = -r_hat;
        let eci_to_lvlh = Matrix3::from_rows(&[o1.transpose(), o2.transpose(), o3.transpose()]);
        let m_dot = self.rates.mean_anomaly;
        let a_r = a / ph.r;
        let nu_dot = m_dot * a_r * a_r * self.eta;
        let r_dot = a_r * a * e * ph.sin_e * m_dot;
        let nu_ddot = -2.0 * nu_dot * r_dot / ph.r;
        let u_dot = self.rates.arg_perigee + nu_dot;
        let z_cross_w = Vector3::new(-w.y, w.x, 0.0);
        let omega = Vector3::z() * self.rates.raan + w * u_dot;
        let omega_dot = w * nu_ddot + z_cross_w * (u_dot * self.rates.raan);
        Lvlh {
            eci_to_lvlh,
            omega,
            omega_dot,
        }
    }
}

/// Perifocal axes `P̂, Q̂, Ŵ` in ECI: the columns of `R3(−Ω) R1(−i) R3(−ω)` (Vallado,
/// 4th ed., §2.6, algorithm COE2RV; Curtis, §4.6, the transpose of the ECI-to-perifocal
/// matrix `R3(ω) R1(i) R3(Ω)`).
fn perifocal_axes(raan: f64, cos_i: f64, sin_i: f64, arg_perigee: f64) -> [Vector3<f64>; 3] {
    let (so, co) = raan.sin_cos();
    let (sw, cw) = arg_perigee.sin_cos();
    [
        Vector3::new(
            co * cw - so * sw * cos_i,
            so * cw + co * sw * cos_i,
            sw * sin_i,
        ),
        Vector3::new(
            -co * sw - so * cw * cos_i,
            -so * sw + co * cw * cos_i,
            cw * sin_i,
        ),
        Vector3::new(so * sin_i, -co * sin_i, cos_i),
    ]
}

#[cfg(test)]
mod tests;
