//! `hysteresis_rod`: a soft-magnetic rod along a body axis ê whose flux density B follows
//! the component H = ê·B_geo/μ₀ of the ambient field along it through a major hysteresis
//! loop and its minor loops, by the model of Flatley & Henretty ("A Magnetic Hysteresis
//! Model", NASA CP-3299, Flight Mechanics/Estimation Theory Symposium, 1995).
//!
//! The limiting (major) loop, in the rod's apparent properties (coercivity H_c, remanence
//! B_r, saturation B_s, all as measured on the rod in an applied field H, so that its shape
//! demagnetisation is folded in):
//!
//! ```text
//! B_asc(H) = (2 B_s/π) atan(k (H − H_c)),   B_desc(H) = (2 B_s/π) atan(k (H + H_c)),
//! k = tan(π B_r / (2 B_s)) / H_c
//! ```
//!
//! so that B_desc(0) = B_r, B_asc(H_c) = 0, B → ±B_s. Inside the loop the rod moves by
//!
//! ```text
//! dB/dH = q(Γ) · (2 k B_s/π) cos²(π B/(2 B_s)),     q = q₀ + (1 − q₀) Γ^p,
//! x = (H − H_desc(B)) / (2 H_c),   Γ = x for dH/dt > 0, 1 − x for dH/dt < 0 (clamped to [0, 1])
//! ```
//!
//! with H_desc(B) = tan(πB/(2B_s))/k − H_c the descending branch's H at the present B: the
//! limiting slope at the present B, scaled down by how far the state is from the branch it
//! moves towards (x = 0 on the descending branch, 1 on the ascending). On that branch q = 1
//! and the state follows it; just after a reversal q = q₀ and B recoils slowly, which draws
//! the minor loops inside the major one. q₀ and p are the model's two shape constants.
//!
//! B is the effector's dynamic state, integrated as dB/dt = (dB/dH) dH/dt, with
//! dH/dt = ê·(C(q)ᵀ Ḃ_geo − ω × B_body)/μ₀: the field's own change along the orbit (a
//! central difference of the inertial field over ±[`FIELD_STEP`] s), and the body's turn.
//!
//! The rod's moment is m = (B/μ₀ − H) V ê (its magnetisation M = B/μ₀ − H times its volume
//! V), and the torque τ = m × B_body. For a high-permeability rod B/μ₀ ≫ H (0.3 T against
//! 30 A/m is 2.4e5 against 30), so m ≈ B V/μ₀ ê, the form of Flatley & Henretty; the exact
//! magnetisation costs nothing and makes the work of the torque over a closed cycle in a
//! constant field exactly −V ∮ H dB, the loop's area times the volume: with the field fixed
//! in inertial space, τ·ω = m·dB_body/dt = μ₀ M V dH/dt, and μ₀ ∮ M dH = ∮ (B − μ₀H) dH =
//! ∮ B dH = −∮ H dB.
//!
//! The torque is external; its work W = ∫ τ·ω dt (J) is a bookkeeping state, which the
//! energy balance subtracts.

use super::eddy_currents::{AmbientField, MU_0};
use super::environment::{names, to_body};
use crate::model::{Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Validity};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Half-width (s) of the central difference that gives the geomagnetic field's rate along the
/// orbit: its relative truncation error is about (h/τ)²/6 for a harmonic of time scale τ,
/// below 1e-5 for the degree-13 terms (τ ≳ 70 s in low orbit).
pub const FIELD_STEP: f64 = 0.5;

/// The recoil slope q₀ by default (the slope just after a reversal, as a fraction of the
/// limiting slope): the value of a public restatement of the model, not checked against the
/// paper (another restatement uses 0.085 with p = 4.75; docs/effectors.md).
pub const DEFAULT_Q0: f64 = 0.0;

/// The exponent p by default (as [`DEFAULT_Q0`]).
pub const DEFAULT_P: f64 = 2.0;

/// The rod's hysteresis loop (apparent properties) and the minor-loop rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HysteresisLoop {
    /// Apparent coercivity H_c (A/m, > 0): where the ascending branch crosses B = 0.
    pub coercivity: f64,
    /// Apparent remanence B_r (T, 0 < B_r < B_s): B on the descending branch at H = 0.
    pub remanence: f64,
    /// Apparent saturation flux density B_s (T).
    pub saturation: f64,
    /// Recoil slope q₀ (0 ≤ q₀ ≤ 1; [`DEFAULT_Q0`] by default).
    pub q0: f64,
    /// Exponent p (> 0; [`DEFAULT_P`] by default).
    pub p: f64,
}

impl HysteresisLoop {
    /// A loop with the default minor-loop constants.
    pub fn new(coercivity: f64, remanence: f64, saturation: f64) -> HysteresisLoop {
        HysteresisLoop {
            coercivity,
            remanence,
            saturation,
            q0: DEFAULT_Q0,
            p: DEFAULT_P,
        }
    }

    /// k = tan(π B_r/(2 B_s)) / H_c (m/A).
    #[inline]
    pub fn k(&self) -> f64 {
        (0.5 * PI * self.remanence / self.saturation).tan() / self.coercivity
    }

    /// The limiting loop's B (T) at `h` (A/m): the ascending branch when `ascending`, else the
    /// descending one.
    pub fn limiting(&self, h: f64, ascending: bool) -> f64 {
        let shift = if ascending {
            -self.coercivity
        } else {
            self.coercivity
        };
        2.0 * self.saturation / PI * (self.k() * (h + shift)).atan()
    }

    /// dB/dH (T m/A) at the state (`b`, `h`) for H increasing (`rising`) or decreasing.
    #[inline]
    pub fn slope(&self, b: f64, h: f64, rising: bool) -> f64 {
        let k = self.k();
        // The angle πB/(2B_s), kept inside (−π/2, π/2): at saturation the slope is zero.
        let a = (0.5 * PI * b / self.saturation).clamp(-0.5 * PI, 0.5 * PI);
        let c = a.cos();
        let limit_slope = 2.0 * k * self.saturation / PI * c * c;
        if limit_slope <= 0.0 {
            return 0.0;
        }
        let h_desc = a.tan() / k - self.coercivity;
        let x = (h - h_desc) / (2.0 * self.coercivity);
        let gamma = if rising { x } else { 1.0 - x }.clamp(0.0, 1.0);
        (self.q0 + (1.0 - self.q0) * gamma.powf(self.p)) * limit_slope
    }
}

/// The demagnetising factor N (1) along the symmetry axis of a uniformly magnetised spheroid of
/// length-to-diameter ratio `m` (> 0): Osborn, "Demagnetizing factors of the general
/// ellipsoid", Phys. Rev. 67, 351 (1945). For a prolate spheroid (m > 1)
///
/// ```text
/// N = (m/√(m²−1) · ln(m + √(m²−1)) − 1) / (m² − 1)
/// ```
///
/// 1/3 for a sphere, and for an oblate one (m < 1) N = (1 − m/√(1−m²) · acos m)/(1 − m²).
/// A long rod of the same length and diameter is taken as this spheroid
/// (docs/effectors.md says what that leaves out).
pub fn demagnetising_factor(m: f64) -> f64 {
    let d = m * m - 1.0;
    if d.abs() < 1e-6 {
        // The series about the sphere: N = 1/3 − (4/15)(m − 1) + O((m − 1)²).
        return 1.0 / 3.0 - 4.0 / 15.0 * (m - 1.0);
    }
    if d > 0.0 {
        let r = d.sqrt();
        (m / r * (m + r).ln() - 1.0) / d
    } else {
        let r = (-d).sqrt();
        (1.0 - m / r * m.acos()) / -d
    }
}

/// Root of the increasing function `f` in [`lo`, `hi`] (f(lo) ≤ 0 ≤ f(hi)) by bisection, to
/// the resolution of doubles.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

impl HysteresisLoop {
    /// The apparent loop of a rod whose material has this loop (B against the field H_in inside
    /// the material) and whose demagnetising factor is `n` (0 < n < 1): the loop sheared by
    /// H = H_in + N M, M = B/μ₀ − H_in, seen as the rod's B_app = μ₀(H + M) against the
    /// applied H (so that its moment (B_app/μ₀ − H) V is M V). Its coercivity is the applied
    /// H where B_app = 0 on the ascending branch, its remanence B_app at H = 0 on the
    /// descending one (both solved on the material's branches), and its saturation the
    /// material's (the magnetisation saturates at the same M_s); the minor-loop constants
    /// are kept. For a long high-permeability rod the remanence is close to μ₀ H_c/N.
    pub fn apparent(&self, n: f64) -> HysteresisLoop {
        let m = |b: f64, h_in: f64| b / MU_0 - h_in;
        // Ascending branch: B_app = (1 + N) B − N μ₀ H_in, increasing in H_in; zero near H_c.
        let b_app = |h_in: f64| {
            let b = self.limiting(h_in, true);
            (1.0 + n) * b - n * MU_0 * h_in
        };
        let span = 4.0 * self.coercivity;
        let h_in = bisect(b_app, self.coercivity - span, self.coercivity + span);
        let coercivity = h_in + n * m(self.limiting(h_in, true), h_in);
        // Descending branch at H = 0: H_in + N M = 0, increasing in H_in, in [−H_c, 0].
        let applied = |h_in: f64| h_in + n * m(self.limiting(h_in, false), h_in);
        let h_in = bisect(applied, -self.coercivity, 0.0);
        let remanence = MU_0 * m(self.limiting(h_in, false), h_in);
        HysteresisLoop {
            coercivity,
            remanence,
            ..*self
        }
    }
}

/// The electrical conductivity of HyMu-80 (S/m): the reciprocal of its resistivity, 0.58 µΩ m
/// (Carpenter Technology's datasheet of the alloy), the default for the rod's eddy currents.
pub const HYMU80_CONDUCTIVITY: f64 = 1.0 / 0.58e-6;

/// The eddy-current field over the coercivity past which a run is warned (the measure of the
/// rod's validity).
pub const EDDY_WARN: f64 = 0.1;

/// The eddy-current field over the coercivity past which the rate-independent loop does not
/// hold: a run stops (`checks.on_validity`).
pub const EDDY_LIMIT: f64 = 1.0;

/// The conductor behind a rod's eddy currents, for its validity range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodConductor {
    /// Radius r (m).
    pub radius: f64,
    /// Electrical conductivity σ (S/m).
    pub conductivity: f64,
}

impl RodConductor {
    /// The field (A/m) the eddy currents of a flux density changing at `b_rate` (T/s) set up
    /// on the rod's axis, against the change: in a long cylinder with a uniform dB/dt along
    /// it the current density is J(ρ) = σ ρ Ḃ/2 around the axis, and the field at the axis
    /// ∫₀^r J dρ = σ r² Ḃ/4.
    pub fn eddy_field(&self, b_rate: f64) -> f64 {
        0.25 * self.conductivity * self.radius * self.radius * b_rate.abs()
    }
}

/// A hysteresis rod on the hub.
#[derive(Debug, Clone)]
pub struct HysteresisRod {
    /// Name (telemetry topic).
    pub name: String,
    /// The field it sits in.
    pub field: AmbientField,
    /// Unit axis ê of the rod (body axes).
    pub axis: Vector3<f64>,
    /// Volume V (m³).
    pub volume: f64,
    /// Its loop.
    pub hysteresis: HysteresisLoop,
    /// Its radius and conductivity, for the validity check (`None`: a rod given by its
    /// volume, unchecked).
    pub conductor: Option<RodConductor>,
}

/// What the rod sees at a hub state: the field (T, body axes), H along the rod (A/m) and its
/// rate (A/m/s).
struct Seen {
    field: Vector3<f64>,
    h: f64,
    h_rate: f64,
}

impl HysteresisRod {
    /// The field in body axes, H along the rod and dH/dt at the hub state.
    fn seen(&self, hub: &HubState) -> Seen {
        let q = hub.attitude;
        let (field, own_rate) = match &self.field {
            AmbientField::Geomagnetic { orbit, field } => {
                let b = field.field_on_orbit(orbit, hub.t);
                let ahead = field.field_on_orbit(orbit, hub.t + FIELD_STEP);
                let behind = field.field_on_orbit(orbit, hub.t - FIELD_STEP);
                (
                    to_body(q, &b),
                    to_body(q, &((ahead - behind) / (2.0 * FIELD_STEP))),
                )
            }
            AmbientField::Uniform(b) => (to_body(q, b), Vector3::zeros()),
        };
        let rate = own_rate - hub.omega.cross(&field);
        Seen {
            field,
            h: self.axis.dot(&field) / MU_0,
            h_rate: self.axis.dot(&rate) / MU_0,
        }
    }

    /// The rod's moment (A m², body axes) for flux density `b` (T) in the applied `h` (A/m).
    #[inline]
    pub fn moment(&self, b: f64, h: f64) -> Vector3<f64> {
        self.axis * ((b / MU_0 - h) * self.volume)
    }

    /// dB/dt (T/s) for flux density `b` and H, dH/dt.
    #[inline]
    fn b_rate(&self, b: f64, h: f64, h_rate: f64) -> f64 {
        self.hysteresis.slope(b, h, h_rate > 0.0) * h_rate
    }
}

/// Index of the work in the rod's states.
const WORK: usize = 1;

impl Effector for HysteresisRod {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "hysteresis_rod"
    }
    fn num_states(&self) -> usize {
        2
    }
    fn num_dynamic_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        names(&["b", "work"])
    }
    fn initial_state(&self) -> Vec<f64> {
        // A demagnetised rod; placed inside the loop at t = 0 by `at_breakpoint`.
        vec![0.0, 0.0]
    }
    fn at_breakpoint(&self, hub: &HubState, x: &mut [f64]) {
        // Called once at t = 0 (the rod has no breakpoints of its own; other effectors' calls
        // later leave it alone): a demagnetised rod, B = 0, where (H, 0) lies inside the
        // loop (|H| ≤ H_c); otherwise the nearest point of the loop, B on the branch between
        // which and H = 0 the state would lie.
        if hub.t == 0.0 {
            let h = self.seen(hub).h;
            let l = &self.hysteresis;
            x[0] = x[0].clamp(l.limiting(h, true), l.limiting(h, false));
        }
    }
    fn is_external(&self) -> bool {
        true
    }
    fn scratch_len(&self) -> usize {
        4
    }
    fn torque_only(&self) -> bool {
        true
    }
    fn torque(&self, hub: &HubState, x: &[f64]) -> Vector3<f64> {
        let s = self.seen(hub);
        self.moment(x[0], s.h).cross(&s.field)
    }
    fn couple(&self, hub: &HubState, x: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]) {
        let tau = self.torque(hub, x);
        coupling.add_torque(&tau);
        scratch[..3].copy_from_slice(tau.as_slice());
    }
    fn derivatives(
        &self,
        hub: &HubState,
        _accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        let s = self.seen(hub);
        dx[0] = self.b_rate(x[0], s.h, s.h_rate);
        dx[WORK] =
            scratch[0] * hub.omega[0] + scratch[1] * hub.omega[1] + scratch[2] * hub.omega[2];
    }
    fn has_switching(&self) -> bool {
        true
    }
    /// dH/dt: where it changes sign the slope changes branch, and dB/dt kinks.
    fn switching(&self, hub: &HubState, _x: &[f64]) -> Option<f64> {
        Some(self.seen(hub).h_rate)
    }
    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        EnergyAccount {
            work: x[WORK],
            ..EnergyAccount::default()
        }
    }
    fn validity_at(&self, hub: &HubState, x: &[f64]) -> Option<Validity> {
        let c = self.conductor?;
        let s = self.seen(hub);
        let b_rate = self.b_rate(x[0], s.h, s.h_rate);
        Some(Validity {
            value: c.eddy_field(b_rate) / self.hysteresis.coercivity,
            warn: EDDY_WARN,
            limit: EDDY_LIMIT,
        })
    }
    fn validity_report_at(&self, hub: &HubState, x: &[f64]) -> (String, String) {
        let Some(c) = self.conductor else {
            return Default::default();
        };
        let s = self.seen(hub);
        let b_rate = self.b_rate(x[0], s.h, s.h_rate);
        let field = c.eddy_field(b_rate);
        (
            format!(
                "the rod's flux density changes at {b_rate:.4e} T/s (H along it at {:.4e} \
                 A/m/s): its eddy currents (σ = {:.4e} S/m, r = {:e} m) set up σ r² |dB/dt|/4 = \
                 {field:.4e} A/m on its axis, {:.3} of the coercivity {:.4e} A/m (warning at \
                 {EDDY_WARN}, limit {EDDY_LIMIT}): the rate-independent loop of Flatley & \
                 Henretty leaves that field out, and the rod's loop widens with it",
                s.h_rate,
                c.conductivity,
                c.radius,
                field / self.hysteresis.coercivity,
                self.hysteresis.coercivity
            ),
            "a slower tumble, thinner rods, or a rate-dependent rod model (not in polhode)".into(),
        )
    }
    fn telemetry_names(&self) -> Vec<String> {
        names(&[
            "b", "h", "h_rate", "moment", "torque_x", "torque_y", "torque_z", "work",
        ])
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        let s = self.seen(hub);
        let m = self.moment(x[0], s.h);
        let tau = m.cross(&s.field);
        vec![
            x[0],
            s.h,
            s.h_rate,
            m.dot(&self.axis),
            tau[0],
            tau[1],
            tau[2],
            x[WORK],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a limiting branch, moving along it, the slope is the branch's own derivative.
    #[test]
    fn the_state_on_a_branch_follows_it() {
        let l = HysteresisLoop::new(12.0, 0.35, 0.74);
        for h in [-40.0, -5.0, 0.0, 7.0, 30.0] {
            for ascending in [true, false] {
                let b = l.limiting(h, ascending);
                let d = 1e-5;
                let numeric = (l.limiting(h + d, ascending) - l.limiting(h - d, ascending)) / 2e-5;
                let s = l.slope(b, h, ascending);
                assert!(
                    (s / numeric - 1.0).abs() < 1e-8,
                    "{h} {ascending}: {s} {numeric}"
                );
            }
        }
    }
}
