//! Linearisation about steady spin: eigenvalues, growth or decay rates, time constants.
//!
//! The equilibrium is spin at rate Ω about the scenario's spin axis ŝ (which must be a
//! principal axis of the hub, or no steady spin exists), with every effector at rest. The
//! Jacobian of the rate dynamics (ω and effector states; the attitude does not feed back in a
//! torque-free or internal-effector scene) is taken by central differences of the full
//! right-hand side, so it covers whatever effectors the spacecraft has. For the rigid body the
//! rate equations are quadratic, so central differences are exact up to rounding.

use crate::integrate::OdeSystem;
use crate::model::{HUB_STATES, Spacecraft};
use nalgebra::{DMatrix, UnitQuaternion, Vector3};

/// One eigenvalue of the linearisation.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Mode {
    /// Real part: growth (> 0) or decay (< 0) rate (1/s).
    pub re: f64,
    /// Imaginary part: angular frequency (rad/s).
    pub im: f64,
    /// `spin` (the neutral direction along ŝ), `growing`, `decaying`, `oscillating` or
    /// `neutral`.
    pub kind: String,
    /// 1/|re| (s), when the mode grows or decays.
    pub time_constant: Option<f64>,
}

/// The linearisation's result.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Linearization {
    /// Unit spin axis, body frame.
    pub spin_axis: [f64; 3],
    /// Spin rate Ω about it (rad/s).
    pub spin_rate: f64,
    /// Which principal axis ŝ is (1 = minimum inertia … 3 = maximum).
    pub principal_axis: usize,
    /// Principal moments, ascending (kg m²).
    pub principal_moments: [f64; 3],
    /// Jacobian (row-major) in the order of `state_names`.
    pub jacobian: Vec<Vec<f64>>,
    /// Names of the linearised states.
    pub state_names: Vec<String>,
    /// Eigenvalues, largest real part first.
    pub modes: Vec<Mode>,
    /// `unstable`, `asymptotically stable` or `marginally stable (oscillatory)`.
    pub verdict: String,
    /// Largest real part among the non-spin modes (1/s).
    pub max_growth_rate: f64,
    /// Predicted time constant of the nutation growth or decay, 1/|max_growth_rate| (s).
    pub time_constant: Option<f64>,
    /// The rigid-body closed form of physics.md for the same spin (an independent check):
    /// growth rate k for the intermediate axis, nutation frequency otherwise.
    pub rigid_body_prediction: RigidPrediction,
}

/// Closed-form small-motion prediction for a rigid body spinning about a principal axis.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RigidPrediction {
    /// Growth rate k (1/s) for the intermediate axis, 0 otherwise.
    pub growth_rate: f64,
    /// Nutation angular frequency (rad/s) for the minor or major axis, 0 otherwise.
    pub frequency: f64,
}

/// Linearises `sc` about steady spin at `spin_rate` (rad/s) about its spin axis.
pub fn linearize(sc: &Spacecraft, spin_rate: f64) -> Result<Linearization, String> {
    let s = sc.spin_axis;
    let p = sc.hub.principal_moments;
    let axes = sc.hub.principal_axes;
    let (principal, alignment) = (0..3)
        .map(|c| (c, axes.column(c).dot(&s).abs()))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((2, 0.0));
    let misalignment = (1.0 - alignment.min(1.0)).max(0.0);
    if misalignment > 1e-9 {
        let a = axes.column(principal);
        return Err(format!(
            "the spin axis [{:.6}, {:.6}, {:.6}] is not a principal axis of the body (nearest: \
             axis {} = [{:.6}, {:.6}, {:.6}], off by {:.3e}°), so no steady spin about it exists",
            s[0],
            s[1],
            s[2],
            principal + 1,
            a[0],
            a[1],
            a[2],
            (2.0 * misalignment).sqrt().to_degrees()
        ));
    }
    if !(spin_rate.is_finite() && spin_rate != 0.0) {
        return Err(format!(
            "the spin rate about the spin axis is {spin_rate} rad/s; a linearisation about \
             steady spin needs a non-zero rate"
        ));
    }

    let omega = s * spin_rate;
    let y_eq = sc.initial_state(&omega, &UnitQuaternion::identity());
    let n = sc.dim();
    // Linearised coordinates: ω and effector states (the attitude is ignorable).
    let idx: Vec<usize> = (0..3).chain(HUB_STATES..n).collect();
    let mut names: Vec<String> = ["omega_x", "omega_y", "omega_z"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for e in sc.effectors() {
        names.extend(
            e.state_names()
                .into_iter()
                .map(|s| format!("{}.{s}", e.name())),
        );
    }
    let m = idx.len();
    let mut jac = DMatrix::<f64>::zeros(m, m);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let h = 1e-6 * spin_rate.abs().max(1e-3);
    for (col, &j) in idx.iter().enumerate() {
        let mut yp = y_eq.clone();
        let mut ym = y_eq.clone();
        yp[j] += h;
        ym[j] -= h;
        sc.rhs(0.0, &yp, &mut fp);
        sc.rhs(0.0, &ym, &mut fm);
        for (row, &i) in idx.iter().enumerate() {
            jac[(row, col)] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    let eig = jac.clone().complex_eigenvalues();
    let scale = spin_rate.abs();
    let zero = 1e-9 * scale;
    // One zero eigenvalue belongs to the spin itself (a change of spin rate is steady too).
    // Further zero eigenvalues make the linearisation degenerate (e.g. a symmetric body spun
    // about a transverse axis): they are `neutral`, and the verdict says the linear theory
    // cannot decide.
    let mut spin_seen = false;
    let mut modes: Vec<Mode> = eig
        .iter()
        .map(|z| {
            let kind = if z.norm() <= zero {
                if spin_seen {
                    "neutral"
                } else {
                    spin_seen = true;
                    "spin"
                }
            } else if z.re > zero {
                "growing"
            } else if z.re < -zero {
                "decaying"
            } else if z.im.abs() > zero {
                "oscillating"
            } else {
                "neutral"
            };
            Mode {
                re: z.re,
                im: z.im,
                kind: kind.into(),
                time_constant: (z.re.abs() > zero).then(|| 1.0 / z.re.abs()),
            }
        })
        .collect();
    modes.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    let max_growth_rate = modes
        .iter()
        .filter(|m| m.kind != "spin")
        .map(|m| m.re)
        .reduce(f64::max)
        .unwrap_or(0.0);
    let degenerate = modes.iter().any(|m| m.kind == "neutral");
    let verdict = if max_growth_rate > zero {
        "unstable"
    } else if degenerate {
        "inconclusive: repeated zero eigenvalues (a symmetric body spun about a transverse \
         axis, or a sphere); the linearisation cannot decide stability"
    } else if max_growth_rate < -zero {
        "asymptotically stable"
    } else {
        "marginally stable (oscillatory)"
    };
    let (i1, i2, i3) = (p[0], p[1], p[2]);
    let w = spin_rate.abs();
    let rigid = match principal {
        1 => RigidPrediction {
            growth_rate: w * ((i3 - i2) * (i2 - i1) / (i1 * i3)).sqrt(),
            frequency: 0.0,
        },
        0 => RigidPrediction {
            growth_rate: 0.0,
            frequency: w * ((i2 - i1) * (i3 - i1) / (i2 * i3)).sqrt(),
        },
        _ => RigidPrediction {
            growth_rate: 0.0,
            frequency: w * ((i3 - i1) * (i3 - i2) / (i1 * i2)).sqrt(),
        },
    };
    Ok(Linearization {
        spin_axis: [s[0], s[1], s[2]],
        spin_rate,
        principal_axis: principal + 1,
        principal_moments: [i1, i2, i3],
        jacobian: (0..m)
            .map(|r| (0..m).map(|c| jac[(r, c)]).collect())
            .collect(),
        state_names: names,
        modes,
        verdict: verdict.into(),
        max_growth_rate,
        time_constant: (max_growth_rate.abs() > zero).then(|| 1.0 / max_growth_rate.abs()),
        rigid_body_prediction: rigid,
    })
}

/// The spin rate about the spin axis implied by the initial rates: `ω₀ · ŝ` (rad/s).
pub fn spin_rate_of(sc: &Spacecraft, omega0: &Vector3<f64>) -> f64 {
    omega0.dot(&sc.spin_axis)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::RigidBody;
    use approx::assert_relative_eq;

    #[test]
    fn tennis_racket_growth_rate_is_k() {
        // physics.md: k = Ω sqrt((I3−I2)(I2−I1)/(I1 I3)) = 10·sqrt(0.5·1.5/3) = 5 1/s.
        let sc = Spacecraft::new(
            RigidBody::from_principal([1.0, 2.5, 3.0]).unwrap(),
            Vector3::y(),
        );
        let lin = linearize(&sc, 10.0).unwrap();
        assert_eq!(lin.verdict, "unstable");
        assert_relative_eq!(lin.max_growth_rate, 5.0, max_relative = 1e-9);
        assert_relative_eq!(
            lin.rigid_body_prediction.growth_rate,
            5.0,
            max_relative = 1e-12
        );
        assert_eq!(lin.modes.iter().filter(|m| m.kind == "spin").count(), 1);
    }

    #[test]
    fn major_and_minor_axes_oscillate_at_the_nutation_frequency() {
        let body = RigidBody::from_principal([1.0, 2.0, 3.0]).unwrap();
        for (axis, expected) in [
            (Vector3::z(), 2.0 * (2.0f64 * 1.0 / 2.0).sqrt()),
            (Vector3::x(), 2.0 * (1.0f64 * 2.0 / 6.0).sqrt()),
        ] {
            let sc = Spacecraft::new(body.clone(), axis);
            let lin = linearize(&sc, 2.0).unwrap();
            assert_eq!(lin.verdict, "marginally stable (oscillatory)");
            let f = lin.modes.iter().map(|m| m.im.abs()).fold(0.0, f64::max);
            assert_relative_eq!(f, expected, max_relative = 1e-9);
            assert_relative_eq!(
                lin.rigid_body_prediction.frequency,
                expected,
                max_relative = 1e-12
            );
        }
    }

    #[test]
    fn repeated_zero_eigenvalues_are_inconclusive() {
        // I = (1, 1, 1.5) spun about x: the Jacobian is nilpotent (all eigenvalues 0).
        let sc = Spacecraft::new(
            RigidBody::from_principal([1.0, 1.0, 1.5]).unwrap(),
            Vector3::x(),
        );
        let lin = linearize(&sc, 2.0).unwrap();
        assert!(lin.verdict.starts_with("inconclusive"), "{}", lin.verdict);
        assert_eq!(lin.modes.iter().filter(|m| m.kind == "spin").count(), 1);
        assert!(lin.max_growth_rate.is_finite());
        assert_eq!(lin.time_constant, None);
    }

    #[test]
    fn refuses_a_non_principal_spin_axis() {
        let sc = Spacecraft::new(
            RigidBody::from_principal([1.0, 2.0, 3.0]).unwrap(),
            Vector3::new(1.0, 1.0, 0.0),
        );
        assert!(
            linearize(&sc, 1.0)
                .unwrap_err()
                .contains("not a principal axis")
        );
    }
}
