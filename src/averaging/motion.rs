//! The torque-free motion at a slow state (|H|, T): its circulation, period, mean precession
//! rate and second moments ⟨ω ωᵀ⟩ over one period, in closed form (docs/averaging.md).
//!
//! Principal moments I1 ≤ I2 ≤ I3. With Δ1 = H² − 2T I1 ≥ 0, Δ3 = 2T I3 − H² ≥ 0 and
//! Δ2 = H² − 2T I2, the polhode circulates about axis 3 when Δ2 > 0 and about axis 1 when
//! Δ2 < 0 (Landau & Lifshitz, *Mechanics*, §37). In both regimes the rates on principal axes
//! are Jacobi elliptic functions of u = λ t (u = 0 where ω has no intermediate component):
//!
//! | | ω1 | ω2 | ω3 | m | λ² |
//! |---|---|---|---|---|---|
//! | about 3 | √A1 cn u | σ √A2 sn u | σ √A3 dn u | (I2−I1)Δ3 / ((I3−I2)Δ1) | (I3−I2)Δ1 / (I1 I2 I3) |
//! | about 1 | σ √A1 dn u | σ √A2' sn u | √A3 cn u | (I3−I2)Δ1 / ((I2−I1)Δ3) | (I2−I1)Δ3 / (I1 I2 I3) |
//!
//! with A1 = Δ3 / (I1 (I3−I1)), A3 = Δ1 / (I3 (I3−I1)), A2 = Δ3 / (I2 (I3−I2)),
//! A2' = Δ1 / (I2 (I2−I1)) and σ = ±1 the branch (the sign of the rate about the circulation
//! axis). Over a period 4K(m) the odd products average to zero and (Byrd & Friedman,
//! *Handbook of Elliptic Integrals*, 310–313) ⟨sn²⟩ = (K − E)/(m K), ⟨cn²⟩ = 1 − ⟨sn²⟩,
//! ⟨dn²⟩ = 1 − m ⟨sn²⟩. With K = R_F(0, 1−m, 1) and K − E = (m/3) R_D(0, 1−m, 1) (DLMF 19.25.1)
//! ⟨sn²⟩ = R_D / (3 R_F), which has no cancellation as m → 0 (where it is ½).

use crate::exact::elliptic::{carlson_rf, carlson_rj};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::FRAC_PI_2;

/// The axis the polhode circulates about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Circulation {
    /// About the axis of least inertia (H² < 2T I2).
    MinorAxis,
    /// About the axis of most inertia (H² > 2T I2).
    MajorAxis,
    /// On the separatrix (H² = 2T I2): the period is infinite.
    Separatrix,
}

/// Averages of the torque-free motion over one polhode period at a slow state.
#[derive(Debug, Clone, Copy)]
pub struct PeriodAverages {
    /// Which axis the polhode circulates about.
    pub circulation: Circulation,
    /// Elliptic parameter m (dimensionless).
    pub m: f64,
    /// 1 − m, without cancellation (dimensionless).
    pub m1: f64,
    /// Polhode period 4K/λ (s); infinite on the separatrix.
    pub period: f64,
    /// Mean rate (rad/s) at which the body turns about H: the precession per period over the
    /// period (the separatrix's limit |H|/I2 on it).
    pub precession_rate: f64,
    /// ⟨ω ωᵀ⟩ on principal axes (rad²/s²).
    pub omega_omega: Matrix3<f64>,
}

/// Principal moments I1 ≤ I2 ≤ I3 (kg m²) of a body that is not spherical, with the
/// differences the formulas divide by.
#[derive(Debug, Clone, Copy)]
pub struct Moments {
    /// I1, I2, I3 (kg m²).
    pub i: [f64; 3],
}

impl Moments {
    /// The moments `principal` (ascending, kg m²), with two that differ by at most
    /// [`crate::exact::SYMMETRY_TOLERANCE`] of the largest made equal, as the exact solution
    /// treats them; `None` for a spherical body, whose rates never change.
    pub fn new(principal: &Vector3<f64>) -> Option<Moments> {
        let [mut i1, mut i2, mut i3] = [principal.x, principal.y, principal.z];
        let tol = crate::exact::SYMMETRY_TOLERANCE * i3;
        let (eq12, eq23) = (i2 - i1 <= tol, i3 - i2 <= tol);
        if eq12 && eq23 {
            return None;
        }
        if eq12 {
            let mean = 0.5 * (i1 + i2);
            (i1, i2) = (mean, mean);
        }
        if eq23 {
            let mean = 0.5 * (i2 + i3);
            (i2, i3) = (mean, mean);
        }
        Some(Moments { i: [i1, i2, i3] })
    }

    /// The kinetic energy (J) nearest `energy` that a body with |H| = `h` (N m s) can have:
    /// T between the spin about the major axis, |H|²/(2 I3), and about the minor axis,
    /// |H|²/(2 I1). A slow state outside that band (an overshoot of the slow stepper towards a
    /// pure spin) stands for the pure spin at its edge, never for a rate larger than |H|
    /// allows.
    pub fn admissible_energy(&self, h: f64, energy: f64) -> f64 {
        let [i1, _, i3] = self.i;
        let h2 = h * h;
        energy.clamp(h2 / (2.0 * i3), h2 / (2.0 * i1))
    }

    /// Δ1 = H² − 2T I1 and Δ3 = 2T I3 − H² (T taken in the admissible band, and clamped at 0
    /// against rounding) and Δ2 = H² − 2T I2 (kg² m⁴ s⁻²), for |H| = `h` (N m s) and
    /// T = `energy` (J).
    pub fn deltas(&self, h: f64, energy: f64) -> (f64, f64, f64) {
        let [i1, i2, i3] = self.i;
        let energy = self.admissible_energy(h, energy);
        let h2 = h * h;
        let d1 = (h2 - 2.0 * energy * i1).max(0.0);
        let d3 = (2.0 * energy * i3 - h2).max(0.0);
        // As the difference of the other two, so that its sign is decided consistently.
        let d2 = ((i3 - i2) * d1 - (i2 - i1) * d3) / (i3 - i1);
        (d1, d2, d3)
    }

    /// Whether the polhode circulates about axis 3 (or is on the separatrix) for this Δ2. A
    /// body symmetric about axis 3 (I1 = I2) always does.
    fn about_major(&self, d2: f64) -> bool {
        d2 >= 0.0 || self.i[1] == self.i[0]
    }

    /// The rates on principal axes (rad/s) at u = 0 of the branch `sign` (±1): the reference
    /// point of the polhode phase, where ω2 = 0.
    pub fn reference_rates(&self, h: f64, energy: f64, sign: f64) -> Vector3<f64> {
        let [i1, _, i3] = self.i;
        let (d1, d2, d3) = self.deltas(h, energy);
        let a1 = (d3 / (i1 * (i3 - i1))).sqrt();
        let a3 = (d1 / (i3 * (i3 - i1))).sqrt();
        if self.about_major(d2) {
            Vector3::new(a1, 0.0, sign * a3)
        } else {
            Vector3::new(sign * a1, 0.0, a3)
        }
    }

    /// The polhode phase u/(4K) in [0, 1) of principal-axis rates `w` at the slow state they
    /// define, and the branch σ (the sign of the rate about the circulation axis).
    pub fn phase_of(&self, w: &Vector3<f64>) -> (f64, f64) {
        let [i1, i2, i3] = self.i;
        let h = Vector3::new(i1 * w.x, i2 * w.y, i3 * w.z).norm();
        let energy = 0.5 * (i1 * w.x * w.x + i2 * w.y * w.y + i3 * w.z * w.z);
        let (d1, d2, d3) = self.deltas(h, energy);
        let a = self.period_averages(h, energy);
        let (sign, s, c, d) = if self.about_major(d2) {
            let sign = if w.z < 0.0 { -1.0 } else { 1.0 };
            let a1 = (d3 / (i1 * (i3 - i1))).sqrt();
            let a2 = (d3 / (i2 * (i3 - i2))).sqrt();
            let a3 = (d1 / (i3 * (i3 - i1))).sqrt();
            (
                sign,
                ratio(w.y * sign, a2),
                ratio(w.x, a1),
                ratio(w.z.abs(), a3),
            )
        } else {
            let sign = if w.x < 0.0 { -1.0 } else { 1.0 };
            let a1 = (d3 / (i1 * (i3 - i1))).sqrt();
            let a2 = (d1 / (i2 * (i2 - i1))).sqrt();
            let a3 = (d1 / (i3 * (i3 - i1))).sqrt();
            (
                sign,
                ratio(w.y * sign, a2),
                ratio(w.z, a3),
                ratio(w.x.abs(), a1),
            )
        };
        if !a.period.is_finite() || (s == 0.0 && c == 0.0) {
            // On the separatrix, or in pure spin: every phase is the same state.
            return (0.0, sign);
        }
        let k = carlson_rf(0.0, a.m1, 1.0);
        let u = crate::exact::elliptic::inverse_sncndn(s, c, d.min(1.0), k);
        let phase = (u / (4.0 * k)).rem_euclid(1.0);
        (if phase >= 1.0 { 0.0 } else { phase }, sign)
    }

    /// The period averages at |H| = `h` (N m s) and T = `energy` (J).
    pub fn period_averages(&self, h: f64, energy: f64) -> PeriodAverages {
        let [i1, i2, i3] = self.i;
        let (d1, d2, d3) = self.deltas(h, energy);
        let i123 = i1 * i2 * i3;
        let a1 = d3 / (i1 * (i3 - i1));
        let a3 = d1 / (i3 * (i3 - i1));
        if d2 == 0.0 && i2 > i1 && i3 > i2 {
            // The separatrix: the body spends the infinite period at the intermediate axis.
            let w2 = h / i2;
            return PeriodAverages {
                circulation: Circulation::Separatrix,
                m: 1.0,
                m1: 0.0,
                period: f64::INFINITY,
                precession_rate: h / i2,
                omega_omega: Matrix3::from_diagonal(&Vector3::new(0.0, w2 * w2, 0.0)),
            };
        }
        // Circulation about axis c (moment I_c), the other extreme axis o (moment I_o).
        let (circulation, m, m1, lambda2, a2, i_c, i_o, nu) = if self.about_major(d2) {
            (
                Circulation::MajorAxis,
                // Symmetric about axis 3 (I1 = I2): m = 0, also in a transverse spin (Δ1 = 0).
                if i2 == i1 {
                    0.0
                } else {
                    (i2 - i1) * d3 / ((i3 - i2) * d1)
                },
                if i2 == i1 {
                    1.0
                } else {
                    (i3 - i1) * d2 / ((i3 - i2) * d1)
                },
                (i3 - i2) * d1 / i123,
                d3 / (i2 * (i3 - i2)),
                i3,
                i1,
                i3 * (i2 - i1) / (i1 * (i3 - i2)),
            )
        } else {
            (
                Circulation::MinorAxis,
                // Symmetric about axis 1 (I2 = I3): m = 0, also in the flat spin (Δ3 = 0).
                if i3 == i2 {
                    0.0
                } else {
                    (i3 - i2) * d1 / ((i2 - i1) * d3)
                },
                if i3 == i2 {
                    1.0
                } else {
                    (i3 - i1) * (-d2) / ((i2 - i1) * d3)
                },
                (i2 - i1) * d3 / i123,
                d1 / (i2 * (i2 - i1)),
                i1,
                i3,
                i1 * (i3 - i2) / (i3 * (i2 - i1)),
            )
        };
        let m = m.clamp(0.0, 1.0);
        let m1 = m1.clamp(0.0, 1.0);
        let rf = carlson_rf(0.0, m1, 1.0);
        let sn2 = carlson_rj(0.0, m1, 1.0, 1.0) / (3.0 * rf);
        let (cn2, dn2) = (1.0 - sn2, 1.0 - m * sn2);
        let diag = match circulation {
            Circulation::MajorAxis => Vector3::new(a1 * cn2, a2 * sn2, a3 * dn2),
            _ => Vector3::new(a1 * dn2, a2 * sn2, a3 * cn2),
        };
        let lambda = lambda2.sqrt();
        let period = 4.0 * rf / lambda;
        // φ̇ = H/I_c + H (1/I_o − 1/I_c) / (1 + ν sn²u), so the mean over a period is
        // H/I_c + H (1/I_o − 1/I_c) Π(−ν | m)/K (Landau & Lifshitz §37).
        let pi_over_k = pi_minus_nu(nu, m, m1) / rf;
        let precession_rate = h / i_c + h * (1.0 / i_o - 1.0 / i_c) * pi_over_k;
        PeriodAverages {
            circulation,
            m,
            m1,
            period: if lambda > 0.0 { period } else { f64::INFINITY },
            precession_rate,
            omega_omega: Matrix3::from_diagonal(&diag),
        }
    }
}

/// `x / a`, or 0 when the amplitude `a` is 0 (that rate is then 0 too).
fn ratio(x: f64, a: f64) -> f64 {
    if a > 0.0 {
        (x / a).clamp(-1.0, 1.0)
    } else {
        0.0
    }
}

/// The complete elliptic integral of the third kind Π(−ν | m) = ∫₀^K du / (1 + ν sn²u) for
/// ν ≥ 0: Π(n | m) = R_F(0, 1−m, 1) + (n/3) R_J(0, 1−m, 1, 1−n) (DLMF 19.25.2) for ν ≤ 1,
/// and for ν > 1 the form of DLMF 19.7.9 that has no cancellation.
fn pi_minus_nu(nu: f64, m: f64, m1: f64) -> f64 {
    if nu <= 1.0 {
        carlson_rf(0.0, m1, 1.0) - nu / 3.0 * carlson_rj(0.0, m1, 1.0, 1.0 + nu)
    } else {
        let x = ((1.0 + nu) * (1.0 + m / nu)).sqrt();
        m / (3.0 * nu) * carlson_rj(0.0, m1, 1.0, 1.0 + m / nu) + FRAC_PI_2 / x
    }
}
