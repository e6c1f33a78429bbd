//! Linearisation about the LVLH-fixed equilibrium of a gravity-gradient spacecraft in a
//! circular orbit: pitch and roll–yaw libration modes, their stability and the region of the
//! inertia plane they fall in.
//!
//! The equilibrium is the attitude with the spacecraft's principal axes on the LVLH axes
//! (o1 along track = roll, o2 = −orbit normal = pitch, o3 = nadir = yaw), at rest in LVLH
//! (ω_BN = −n o2), every effector at rest relative to the hub. Of the 24 such attitudes the
//! one nearest the scenario's initial attitude relative to LVLH is taken (ties go to the one
//! nearest the body axes on the LVLH axes), so a scenario started a few degrees off its
//! nominal attitude is linearised about that nominal attitude.
//!
//! The coordinates are those of the rotating LVLH frame: the small rotation α of the body
//! from the equilibrium (LVLH components: roll φ, pitch θ, yaw ψ to first order, for any
//! Euler sequence), the body's rate relative to LVLH w = ω_BO (LVLH components), and the
//! effectors' dynamic states. The Jacobian is taken by central differences of the
//! spacecraft's own right-hand side (in inertial form, at t = 0, with the orbit's LVLH frame),
//! mapped to and from these coordinates; it is compared in the tests with the closed forms of
//! Hughes (1986, ch. 9), which this module also reports for reference but does not use.

use super::{central_jacobian, dynamic_states, principal};
use crate::integrate::OdeSystem;
use crate::model::{HubState, Spacecraft};
use crate::orbit::{Lvlh, Orbit};
use nalgebra::{Complex, DMatrix, Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};
use std::f64::consts::TAU;

type C64 = Complex<f64>;

/// Effector kinds whose torque varies around the orbit in LVLH (the magnetic field, the Sun
/// direction, the co-rotating wind), so that no LVLH-fixed attitude is an equilibrium.
const FORCED: [&str; 5] = [
    "magnetic_dipole",
    "eddy_currents",
    "hysteresis_rod",
    "solar_pressure",
    "aerodynamic",
];

/// Relative step of the central differences (rad for α, n for w, 1 for effector states):
/// about ε^(1/3), where truncation and rounding errors balance (both ~1e-11 relative).
const STEP: f64 = 1e-5;

/// An eigenvalue's real part counts as zero below this fraction of n.
const ZERO: f64 = 1e-8;

/// One eigenvalue of the LVLH linearisation.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LvlhMode {
    /// Real part: growth (> 0) or decay (< 0) rate (1/s).
    pub re: f64,
    /// Imaginary part: angular frequency (rad/s).
    pub im: f64,
    /// `pitch`, `roll_yaw` or `effector`: the coordinates the eigenvector mostly lives in
    /// (angles in rad and rates in units of n weighed alike).
    pub role: String,
    /// `growing`, `decaying`, `oscillating`, `rotor` (the zero eigenvalue of a frictionless
    /// rotor, whose absolute axial momentum is conserved) or `neutral` (a further zero
    /// eigenvalue: the linearisation is degenerate).
    pub kind: String,
    /// |im| / n: the frequency as a multiple of the orbit rate.
    pub frequency_over_n: f64,
    /// 2π/|im| (s), when the mode oscillates.
    pub period: Option<f64>,
    /// 1/|re| (s), when the mode grows or decays.
    pub time_constant: Option<f64>,
}

/// The closed forms for a rigid body with principal axes on LVLH (Hughes 1986, ch. 9), with
/// the moments about the roll, pitch and yaw axes.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClosedForm {
    /// k1 = (I_pitch − I_yaw)/I_roll.
    pub k1: f64,
    /// k2 = (I_roll − I_yaw)/I_pitch.
    pub k2: f64,
    /// k3 = (I_pitch − I_roll)/I_yaw.
    pub k3: f64,
    /// ω_p² = 3 n² k2 of θ̈ + 3n²k2 θ = 0 (rad²/s²): negative when pitch diverges.
    pub pitch_omega_squared: f64,
    /// The two roots s² of s⁴ + n²(1 + 3k1 + k1k3) s² + 4n⁴k1k3 = 0 (rad²/s², complex when
    /// the discriminant is negative), as [re, im] pairs.
    pub roll_yaw_s_squared: [[f64; 2]; 2],
    /// Pitch is stable: k2 > 0 (I_roll > I_yaw).
    pub pitch_stable: bool,
    /// Roll–yaw is (linearly) stable: k1k3 > 0 and 1 + 3k1 + k1k3 > 4√(k1k3).
    pub roll_yaw_stable: bool,
    /// Where the moments fall: the Lagrange region, the DeBra–Delp region, or which
    /// condition fails.
    pub region: String,
}

/// The linearisation about the LVLH equilibrium.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LvlhLinearization {
    /// Orbit rate n (rad/s).
    pub orbit_rate: f64,
    /// Orbit period 2π/n (s).
    pub orbit_period: f64,
    /// The equilibrium attitude body → LVLH, [w, x, y, z].
    pub equilibrium_attitude: [f64; 4],
    /// The body axes (unit, body components) along roll o1, pitch o2 and yaw o3.
    pub body_axes_on_lvlh: [[f64; 3]; 3],
    /// Moments of inertia about the roll, pitch and yaw axes, I_roll, I_pitch, I_yaw
    /// (kg m²; principal moments of the whole spacecraft, effectors at rest).
    pub moments: [f64; 3],
    /// Angle from the scenario's initial attitude (relative to LVLH) to the equilibrium (deg).
    pub initial_offset_deg: f64,
    /// Names of the linearised coordinates, in the Jacobian's order.
    pub state_names: Vec<String>,
    /// Jacobian (row-major).
    pub jacobian: Vec<Vec<f64>>,
    /// Eigenvalues, largest real part first.
    pub modes: Vec<LvlhMode>,
    /// `unstable`, `asymptotically stable`, `marginally stable (oscillatory)` or
    /// `inconclusive: …` (a zero eigenvalue).
    pub verdict: String,
    /// Largest |ẋ| at the equilibrium: |α̇|/n, |ẇ|/n² and effector rates (near zero).
    pub equilibrium_residual: f64,
    /// The rigid body's closed forms for the same moments.
    pub closed_form: ClosedForm,
}

/// Whether `sc` is linearised about the LVLH equilibrium: it has a `gravity_gradient`.
pub fn applies(sc: &Spacecraft) -> bool {
    sc.effectors()
        .iter()
        .any(|e| e.kind() == "gravity_gradient")
}

/// The rigid-body closed forms (Hughes 1986, ch. 9) for moments `[I_roll, I_pitch, I_yaw]`
/// (kg m²) at orbit rate `n` (rad/s).
pub fn closed_form(moments: [f64; 3], n: f64) -> ClosedForm {
    let [ir, ip, iy] = moments;
    let k1 = (ip - iy) / ir;
    let k2 = (ir - iy) / ip;
    let k3 = (ip - ir) / iy;
    let n2 = n * n;
    let b = 1.0 + 3.0 * k1 + k1 * k3;
    let c = 4.0 * k1 * k3;
    let disc = b * b - 4.0 * c;
    let roots = if disc >= 0.0 {
        let r = disc.sqrt();
        [[n2 * (-b + r) / 2.0, 0.0], [n2 * (-b - r) / 2.0, 0.0]]
    } else {
        let r = (-disc).sqrt();
        [
            [-n2 * b / 2.0, n2 * r / 2.0],
            [-n2 * b / 2.0, -n2 * r / 2.0],
        ]
    };
    let pitch_stable = k2 > 0.0;
    let roll_yaw_stable = k1 * k3 > 0.0 && b > 4.0 * (k1 * k3).sqrt();
    let region = if ip > ir && ir > iy {
        "Lagrange region (I_pitch > I_roll > I_yaw): stable, a minimum of the Jacobi integral"
            .to_string()
    } else if pitch_stable && roll_yaw_stable {
        "DeBra–Delp region (I_roll > I_yaw > I_pitch with 1 + 3k1 + k1k3 > 4√(k1k3)): \
         linearly stable by gyroscopic coupling only, not a minimum of the Jacobi integral, \
         so energy dissipation destabilises it"
            .to_string()
    } else {
        let mut why = Vec::new();
        if !pitch_stable {
            why.push(format!("pitch diverges: I_roll ≤ I_yaw (k2 = {k2:.6} ≤ 0)"));
        }
        if k1 * k3 <= 0.0 {
            why.push(format!(
                "roll–yaw diverges: k1k3 = {:.6} ≤ 0 (a real positive root s)",
                k1 * k3
            ));
        } else if !roll_yaw_stable {
            let side = if k1 < 0.0 {
                "k1, k3 < 0 (the DeBra–Delp ordering) but outside the DeBra–Delp region: "
            } else {
                ""
            };
            why.push(format!(
                "roll–yaw is unstable: {side}1 + 3k1 + k1k3 = {b:.6} ≤ 4√(k1k3) = {:.6} \
                 (complex s²: an oscillation that grows)",
                4.0 * (k1 * k3).sqrt()
            ));
        }
        format!("unstable: {}", why.join("; "))
    };
    ClosedForm {
        k1,
        k2,
        k3,
        pitch_omega_squared: 3.0 * n2 * k2,
        roll_yaw_s_squared: roots,
        pitch_stable,
        roll_yaw_stable,
        region,
    }
}

/// The attitude body → LVLH (as C_OB, rows the body axes along o1, o2, o3) with the
/// principal axes of `inertia` on the LVLH axes, nearest `initial` (C_OB of the initial
/// attitude); ties go to the one nearest C_OB = 1.
fn nearest_equilibrium(inertia: &Matrix3<f64>, initial: &Matrix3<f64>) -> Matrix3<f64> {
    let (_, axes) = principal(inertia);
    const PERMUTATIONS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut best: Option<(f64, f64, Matrix3<f64>)> = None;
    for p in PERMUTATIONS {
        for signs in 0..8u32 {
            let row = |k: usize| {
                let s = if signs >> k & 1 == 1 { -1.0 } else { 1.0 };
                (axes.column(p[k]) * s).transpose()
            };
            let c = Matrix3::from_rows(&[row(0), row(1), row(2)]);
            if c.determinant() < 0.0 {
                continue;
            }
            let closeness = (c * initial.transpose()).trace();
            let to_body = c.trace();
            let better = match &best {
                None => true,
                Some((b, t, _)) => {
                    closeness > b + 1e-9 || (closeness > b - 1e-9 && to_body > t + 1e-9)
                }
            };
            if better {
                best = Some((closeness, to_body, c));
            }
        }
    }
    best.map(|(_, _, c)| c).unwrap_or_else(Matrix3::identity)
}

/// The spacecraft's right-hand side in LVLH coordinates at t = 0.
struct LvlhSystem<'a> {
    sc: &'a Spacecraft,
    lvlh: Lvlh,
    /// The equilibrium attitude body → LVLH.
    q0: UnitQuaternion<f64>,
    /// Positions of the effectors' dynamic states in the spacecraft's state vector.
    effector_idx: Vec<usize>,
}

impl LvlhSystem<'_> {
    /// The inertial state for LVLH coordinates x = [α, w, effector states].
    fn inertial_state(&self, x: &[f64]) -> Vec<f64> {
        let v = Vector3::new(x[0], x[1], x[2]) * 0.5;
        let dq = Quaternion::new((1.0 - v.norm_squared()).sqrt(), v.x, v.y, v.z);
        let q_ob = UnitQuaternion::new_unchecked(dq) * self.q0;
        let q_nb = self.lvlh.lvlh_to_eci() * q_ob;
        let w_on_o = self.lvlh.omega_in_lvlh();
        let w = Vector3::new(x[3], x[4], x[5]);
        let omega_b = q_ob.inverse_transform_vector(&(w + w_on_o));
        let mut y = self.sc.rest_state(&omega_b, &q_nb);
        for (k, &i) in self.effector_idx.iter().enumerate() {
            y[i] = x[6 + k];
        }
        y
    }

    /// ẋ for LVLH coordinates `x`, written into `out`, from the spacecraft's right-hand side.
    fn rhs(&self, x: &[f64], out: &mut Vec<f64>) {
        let y = self.inertial_state(x);
        let mut dy = vec![0.0; y.len()];
        self.sc.rhs(0.0, &y, &mut dy);
        let q_nb = Quaternion::new(y[3], y[4], y[5], y[6]);
        let dq_nb = Quaternion::new(dy[3], dy[4], dy[5], dy[6]);
        let q_on = self.lvlh.lvlh_to_eci().inverse().into_inner();
        let w_on_o = self.lvlh.omega_in_lvlh();
        // q_OB = q_ON ⊗ q_NB with q̇_ON = ½ (0, −ω_ON^O) ⊗ q_ON.
        let dq_on = Quaternion::from_imag(-w_on_o) * q_on * 0.5;
        let dq_ob = dq_on * q_nb + q_on * dq_nb;
        // δq = q_OB ⊗ q0⁻¹ = (√(1 − |α/2|²), α/2): α̇ = 2 vec(q̇_OB ⊗ q0⁻¹).
        let alpha_dot = (dq_ob * self.q0.inverse().into_inner()).imag() * 2.0;
        // w = C_OB ω_BN − ω_ON^O: ẇ = C_OB (ω_BO × ω_BN + ω̇_BN) − C_ON ω̇_ON.
        let q_ob = UnitQuaternion::new_normalize(q_on * q_nb);
        let omega = Vector3::new(y[0], y[1], y[2]);
        let omega_dot = Vector3::new(dy[0], dy[1], dy[2]);
        let w_bo = omega - q_ob.inverse_transform_vector(&w_on_o);
        let w_dot = q_ob.transform_vector(&(w_bo.cross(&omega) + omega_dot))
            - self.lvlh.eci_to_lvlh * self.lvlh.omega_dot;
        out.clear();
        out.extend(alpha_dot.iter().chain(w_dot.iter()));
        out.extend(self.effector_idx.iter().map(|&i| dy[i]));
    }
}

/// Refuses what has no fixed LVLH equilibrium or what this linearisation does not cover.
fn check_applicable(sc: &Spacecraft, orbit: &Orbit) -> Result<(), String> {
    if let Some(refusal) = crate::sim::linearize_refusal(sc, crate::sim::Linearisation::Lvlh) {
        return Err(refusal.to_string());
    }
    let e = orbit.elements().eccentricity;
    if e != 0.0 {
        return Err(format!(
            "the orbit's eccentricity is {e}: in an eccentric orbit the distance and the LVLH \
             frame's rate vary around the orbit, so the LVLH-fixed attitude is not an \
             equilibrium (the motion about it is periodically forced: a Floquet problem), and \
             `linearize` handles circular orbits only (eccentricity 0)"
        ));
    }
    if orbit.j2_secular() {
        return Err(
            "`orbit.j2_secular: true`: the regressing node gives the LVLH frame a rate \
             component Ω̇ ẑ that turns in LVLH around the orbit, so the LVLH-fixed attitude is \
             not an exact equilibrium; linearise with `j2_secular: false` (the change is of \
             relative order Ω̇/n, about 1e-3 in LEO)"
                .into(),
        );
    }
    for eff in sc.effectors() {
        if FORCED.contains(&eff.kind()) {
            return Err(format!(
                "effector `{}` ({}) applies a torque that varies around the orbit in LVLH \
                 (the magnetic field, the Sun direction or the co-rotating wind turn relative \
                 to the orbit frame), so the LVLH attitude is not a fixed equilibrium: its \
                 effect is a forced response, not a mode; linearise without it",
                eff.name(),
                eff.kind()
            ));
        }
        let init = eff.initial_state();
        if let Some((j, v)) = init
            .iter()
            .enumerate()
            .take(eff.num_dynamic_states())
            .find(|(_, v)| **v != 0.0)
        {
            let names = eff.state_names();
            return Err(format!(
                "effector `{}` starts away from rest ({} = {v}): the LVLH equilibrium \
                 linearised here has every effector at rest relative to the hub (a spinning \
                 rotor makes a momentum-biased equilibrium, which this does not solve for)",
                eff.name(),
                names.get(j).map(String::as_str).unwrap_or("a state")
            ));
        }
    }
    Ok(())
}

/// Linearises `sc` in the circular `orbit` about the LVLH equilibrium nearest `attitude0`
/// (body → inertial at t = 0).
pub fn linearize_lvlh(
    sc: &Spacecraft,
    orbit: &Orbit,
    attitude0: &UnitQuaternion<f64>,
) -> Result<LvlhLinearization, String> {
    check_applicable(sc, orbit)?;
    let n = orbit.mean_motion();
    let lvlh = orbit.lvlh(0.0);
    let rest = sc.rest_state(&Vector3::zeros(), &UnitQuaternion::identity());
    let inertia = sc.system_inertia(&rest);
    let q_ob_initial = lvlh.lvlh_to_eci().inverse() * attitude0;
    let initial = *q_ob_initial.to_rotation_matrix().matrix();
    let c_ob = nearest_equilibrium(&inertia, &initial);
    let q0 = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c_ob));
    let initial_offset_deg = q0.angle_to(&q_ob_initial).to_degrees();
    let body_axes: [Vector3<f64>; 3] = [0, 1, 2].map(|k| c_ob.row(k).transpose());
    let moments = body_axes.map(|a| a.dot(&(inertia * a)));

    // Torque-only effectors other than the gravity gradient must not push at the
    // equilibrium (a Rayleigh torque −Γω does, since ω_BN = −n o2 ≠ 0).
    let y_eq = {
        let omega_b = q0.inverse_transform_vector(&lvlh.omega_in_lvlh());
        sc.rest_state(&omega_b, &(lvlh.lvlh_to_eci() * q0))
    };
    let gg_scale = 3.0 * n * n * inertia.norm();
    for (k, eff) in sc.effectors().iter().enumerate() {
        if !eff.torque_only() || eff.kind() == "gravity_gradient" {
            continue;
        }
        let hub = HubState {
            t: 0.0,
            omega: Vector3::new(y_eq[0], y_eq[1], y_eq[2]),
            attitude: &y_eq[3..7],
        };
        let tau = eff.torque(&hub, sc.effector_states(k, &y_eq));
        if tau.norm() > 1e-9 * gg_scale {
            return Err(format!(
                "effector `{}` ({}) applies {:.3e} N m at the LVLH equilibrium (body at rest \
                 in LVLH, turning at the orbit rate {n:.6e} rad/s in inertial space), against \
                 a gravity-gradient scale 3n²|I| = {gg_scale:.3e} N m: the LVLH attitude is \
                 not an equilibrium with it; linearise without it",
                eff.name(),
                eff.kind(),
                tau.norm()
            ));
        }
    }

    let (effector_idx, effector_names) = dynamic_states(sc);
    let system = LvlhSystem {
        sc,
        lvlh,
        q0,
        effector_idx,
    };
    let m = 6 + system.effector_idx.len();
    let names: Vec<String> = [
        "roll",
        "pitch",
        "yaw",
        "roll_rate",
        "pitch_rate",
        "yaw_rate",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain(effector_names)
    .collect();
    let x0 = vec![0.0; m];
    let mut f0 = Vec::new();
    system.rhs(&x0, &mut f0);
    let equilibrium_residual = f0
        .iter()
        .enumerate()
        .map(|(i, v)| match i {
            0..3 => v.abs() / n,
            3..6 => v.abs() / (n * n),
            _ => v.abs(),
        })
        .fold(0.0, f64::max);
    if equilibrium_residual > 1e-9 {
        return Err(format!(
            "the LVLH attitude with the principal axes on the LVLH axes and the effectors at \
             rest is not an equilibrium of this spacecraft (residual \
             {equilibrium_residual:.3e} relative to n and n²): an effector is pushed at rest \
             (a damper's mass pulled by the tidal force, a spring preloaded), or the inertia \
             the gravity gradient acts on has other principal axes than the whole \
             spacecraft's; the equilibrium then lies elsewhere, and this linearisation does \
             not solve for it"
        ));
    }
    let step = |j: usize| match j {
        0..3 => STEP,
        3..6 => STEP * n,
        _ => STEP,
    };
    let jac = central_jacobian(&x0, &(0..m).collect::<Vec<_>>(), m, step, |x, out| {
        system.rhs(x, out)
    });
    let eig = jac.clone().complex_eigenvalues();
    let zero = ZERO * n;
    let mut modes: Vec<LvlhMode> = eig
        .iter()
        .map(|&z| {
            let kind = if z.re > zero {
                "growing"
            } else if z.re < -zero {
                "decaying"
            } else if z.im.abs() > zero {
                "oscillating"
            } else {
                "neutral"
            };
            LvlhMode {
                re: z.re,
                im: z.im,
                role: role_of(&jac, z, n).into(),
                kind: kind.into(),
                frequency_over_n: z.im.abs() / n,
                period: (z.im.abs() > zero).then(|| TAU / z.im.abs()),
                time_constant: (z.re.abs() > zero).then(|| 1.0 / z.re.abs()),
            }
        })
        .collect();
    // Each frictionless rotor's absolute axial momentum is conserved: one zero eigenvalue
    // each, the rotor's own (not a degeneracy).
    let mut free_rotors = super::rotors(sc)
        .iter()
        .filter(|r| r.damping == 0.0)
        .count();
    let mut by_size: Vec<usize> = (0..modes.len()).collect();
    by_size.sort_by(|&a, &b| {
        C64::new(modes[a].re, modes[a].im)
            .norm()
            .total_cmp(&C64::new(modes[b].re, modes[b].im).norm())
    });
    for k in by_size {
        if free_rotors > 0 && modes[k].kind == "neutral" {
            modes[k].kind = "rotor".into();
            free_rotors -= 1;
        }
    }
    modes.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    let verdict = if modes.iter().any(|m| m.kind == "growing") {
        "unstable".to_string()
    } else if modes.iter().any(|m| m.kind == "neutral") {
        "inconclusive: a zero eigenvalue (equal moments about two LVLH axes); the \
         linearisation cannot decide stability"
            .to_string()
    } else if modes
        .iter()
        .all(|m| m.kind == "decaying" || m.kind == "rotor")
    {
        "asymptotically stable".to_string()
    } else {
        "marginally stable (oscillatory)".to_string()
    };
    let q = q0.into_inner();
    Ok(LvlhLinearization {
        orbit_rate: n,
        orbit_period: TAU / n,
        equilibrium_attitude: [q.w, q.i, q.j, q.k],
        body_axes_on_lvlh: body_axes.map(|a| [a.x, a.y, a.z]),
        moments,
        initial_offset_deg,
        state_names: names,
        jacobian: (0..m)
            .map(|r| (0..m).map(|c| jac[(r, c)]).collect())
            .collect(),
        modes,
        verdict,
        equilibrium_residual,
        closed_form: closed_form(moments, n),
    })
}

/// Which coordinates the eigenvector of `jac` for eigenvalue `z` mostly lives in: `pitch`
/// (θ, pitch rate), `roll_yaw` (φ, ψ and their rates) or `effector`. Rates are weighed in
/// units of n, so an angle and its rate count alike.
fn role_of(jac: &DMatrix<f64>, z: C64, n: f64) -> &'static str {
    let m = jac.nrows();
    let shifted = DMatrix::<C64>::from_fn(m, m, |r, c| {
        C64::new(jac[(r, c)], 0.0) - if r == c { z } else { C64::new(0.0, 0.0) }
    });
    let svd = shifted.svd(false, true);
    let Some(v_t) = svd.v_t else {
        return "effector";
    };
    // The right singular vector of the smallest singular value spans the null space.
    let k = (0..svd.singular_values.len())
        .min_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]))
        .unwrap_or(0);
    let weight = |i: usize| {
        let scale = if (3..6).contains(&i) { 1.0 / n } else { 1.0 };
        (v_t[(k, i)] * scale).norm_sqr()
    };
    let pitch = weight(1) + weight(4);
    let roll_yaw = weight(0) + weight(2) + weight(3) + weight(5);
    let effector: f64 = (6..m).map(weight).sum();
    if pitch >= roll_yaw && pitch >= effector {
        "pitch"
    } else if roll_yaw >= effector {
        "roll_yaw"
    } else {
        "effector"
    }
}

impl LvlhLinearization {
    /// The human-readable report printed by `polhode linearize` (one line per item).
    pub fn report(&self, name: &str) -> String {
        let n = self.orbit_rate;
        let mut out = String::new();
        let mut line = |s: String| {
            out.push_str(&s);
            out.push('\n');
        };
        line(format!(
            "{name}: LVLH equilibrium in a circular orbit, n = {n:.9e} rad/s (period {:.3} s)",
            self.orbit_period
        ));
        let [r, p, y] = self.body_axes_on_lvlh;
        line(format!(
            "  body axes on roll (o1, along track) [{:+.4}, {:+.4}, {:+.4}], pitch (o2, −orbit \
             normal) [{:+.4}, {:+.4}, {:+.4}], yaw (o3, nadir) [{:+.4}, {:+.4}, {:+.4}]",
            r[0], r[1], r[2], p[0], p[1], p[2], y[0], y[1], y[2]
        ));
        line(format!(
            "  I_roll {:.6}, I_pitch {:.6}, I_yaw {:.6} kg m²; the initial attitude is {:.3}° \
             from this equilibrium",
            self.moments[0], self.moments[1], self.moments[2], self.initial_offset_deg
        ));
        line(format!(
            "  {:>16} {:>16}  {:<9} {:<12} {:>9} {:>14} time constant",
            "Re (1/s)", "Im (rad/s)", "role", "mode", "ω/n", "period"
        ));
        for m in &self.modes {
            let period = m
                .period
                .map(|t| format!("{t:.3} s"))
                .unwrap_or_else(|| "-".into());
            let tc = m
                .time_constant
                .map(|t| format!("{t:.6} s"))
                .unwrap_or_else(|| "-".into());
            line(format!(
                "  {:>16.9e} {:>16.9e}  {:<9} {:<12} {:>9.6} {:>14} {tc}",
                m.re, m.im, m.role, m.kind, m.frequency_over_n, period
            ));
        }
        line(format!("  verdict: {}", self.verdict));
        let c = &self.closed_form;
        line(format!(
            "  closed form (rigid body, Hughes 1986 ch. 9): k1 = {:.6}, k2 = {:.6}, k3 = {:.6}",
            c.k1, c.k2, c.k3
        ));
        let freq = |w2: f64| {
            if w2 >= 0.0 {
                let w = w2.sqrt();
                format!("{w:.9e} rad/s = {:.6} n", w / n)
            } else {
                format!("grows at {:.9e} 1/s", (-w2).sqrt())
            }
        };
        line(format!(
            "    pitch ω_p² = 3n²k2: {}",
            freq(c.pitch_omega_squared)
        ));
        let [a, b] = c.roll_yaw_s_squared;
        if a[1] == 0.0 {
            line(format!(
                "    roll–yaw s⁴ + n²(1 + 3k1 + k1k3)s² + 4n⁴k1k3 = 0: {}; {}",
                freq(-a[0]),
                freq(-b[0])
            ));
        } else {
            line(format!(
                "    roll–yaw s⁴ + n²(1 + 3k1 + k1k3)s² + 4n⁴k1k3 = 0: complex s² = \
                 {:.6e} ± {:.6e}i rad²/s² (growing oscillation)",
                a[0],
                a[1].abs()
            ));
        }
        line(format!("    {}", c.region));
        out
    }
}
