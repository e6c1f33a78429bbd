//! The closed-form period averages against quadrature over the exact solution's rates (an
//! independent path: Jacobi functions evaluated by the solution, summed numerically).

use super::motion::{Circulation, Moments};
use crate::exact::TorqueFreeSolution;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// (principal moments, initial rates on them, expected circulation).
fn cases() -> Vec<([f64; 3], [f64; 3], Circulation)> {
    vec![
        ([2.0, 3.0, 4.0], [1.0, 0.3, 0.2], Circulation::MinorAxis),
        ([2.0, 3.0, 4.0], [0.1, 0.4, 1.0], Circulation::MajorAxis),
        // Near the separatrix on both sides (m within about 1e-3 of 1).
        ([2.0, 3.0, 4.0], [0.5, 1.0, 0.3540], Circulation::MajorAxis),
        ([2.0, 3.0, 4.0], [0.5, 1.0, 0.3530], Circulation::MinorAxis),
        // Close to pure spin about axes 1 and 3.
        ([1.0, 1.5, 2.2], [3.0, 1e-4, 2e-4], Circulation::MinorAxis),
        ([1.0, 1.5, 2.2], [1e-4, 2e-4, 3.0], Circulation::MajorAxis),
        // Symmetric about the least (Explorer 1) and the largest axis.
        (
            [0.15, 4.95, 4.95],
            [78.5, 0.08, 0.05],
            Circulation::MinorAxis,
        ),
        ([3.0, 3.0, 5.0], [0.4, 0.1, 2.0], Circulation::MajorAxis),
    ]
}

/// ⟨ω ωᵀ⟩ by the trapezoidal rule over one period (spectrally accurate for a periodic
/// integrand) of the exact solution, and the solution.
fn quadrature(i: [f64; 3], w: [f64; 3], points: usize) -> (Matrix3<f64>, TorqueFreeSolution) {
    let inertia = Matrix3::from_diagonal(&Vector3::from(i));
    let sol =
        TorqueFreeSolution::new(&inertia, &Vector3::from(w), &UnitQuaternion::identity()).unwrap();
    let period = sol.polhode_period();
    let mut m = Matrix3::zeros();
    for k in 0..points {
        let omega = sol.omega_at(period * k as f64 / points as f64);
        m += omega * omega.transpose();
    }
    (m / points as f64, sol)
}

fn slow_state(i: [f64; 3], w: [f64; 3]) -> (f64, f64) {
    let h = Vector3::new(i[0] * w[0], i[1] * w[1], i[2] * w[2]).norm();
    let t = 0.5 * (i[0] * w[0] * w[0] + i[1] * w[1] * w[1] + i[2] * w[2] * w[2]);
    (h, t)
}

#[test]
fn second_moments_period_and_precession_match_the_exact_motion() {
    for (i, w, circulation) in cases() {
        let moments = Moments::new(&Vector3::from(i)).unwrap();
        let (h, t) = slow_state(i, w);
        let a = moments.period_averages(h, t);
        assert_eq!(a.circulation, circulation, "{i:?} {w:?}");
        let (m, sol) = quadrature(i, w, 40_000);
        let scale = 2.0 * t / i[0];
        let err = (a.omega_omega - m).amax() / scale;
        assert!(err < 1e-11, "{i:?} {w:?}: ⟨ωωᵀ⟩ off by {err:e}");
        let p = sol.polhode_period();
        assert!(
            ((a.period - p) / p).abs() < 1e-12,
            "{i:?} {w:?}: period {} against {p}",
            a.period
        );
        let turn = sol.precession_angle_per_period();
        let err = (a.precession_rate * a.period - turn).abs() / turn.abs();
        assert!(err < 1e-11, "{i:?} {w:?}: precession off by {err:e}");
    }
}

#[test]
fn the_phase_and_branch_of_a_state_lead_back_to_it() {
    for (i, w, _) in cases() {
        let moments = Moments::new(&Vector3::from(i)).unwrap();
        let (h, t) = slow_state(i, w);
        for sign in [1.0, -1.0] {
            let w = Vector3::from(w) * sign;
            let (phase, branch) = moments.phase_of(&w);
            assert!((0.0..1.0).contains(&phase));
            let reference = moments.reference_rates(h, t, branch);
            assert_eq!(reference.y, 0.0);
            let inertia = Matrix3::from_diagonal(&Vector3::from(i));
            let sol =
                TorqueFreeSolution::new(&inertia, &reference, &UnitQuaternion::identity()).unwrap();
            let back = sol.omega_at(phase * sol.polhode_period());
            let err = (back - w).amax() / w.amax();
            assert!(err < 1e-10, "{i:?} {w:?}: phase {phase} gives {back:?}");
        }
    }
}

#[test]
fn on_the_separatrix_the_body_sits_at_the_intermediate_axis() {
    let i = [2.0, 3.0, 4.0];
    let moments = Moments::new(&Vector3::from(i)).unwrap();
    let h = 6.0;
    let t = h * h / (2.0 * i[1]);
    let a = moments.period_averages(h, t);
    assert_eq!(a.circulation, Circulation::Separatrix);
    assert!((a.omega_omega[(1, 1)] - 4.0).abs() < 1e-15);
    assert_eq!(a.precession_rate, 2.0);
    // Approached from either side, the averages tend to it, logarithmically (the period
    // grows like ln(1/(1 − m))): closer is nearer.
    for side in [1.0, -1.0] {
        let gap = |d: f64| {
            let b = moments.period_averages(h, t * (1.0 + side * d));
            (
                (b.omega_omega[(1, 1)] - 4.0).abs(),
                (b.precession_rate - 2.0).abs(),
                b.period,
            )
        };
        let (far, near) = (gap(1e-6), gap(1e-12));
        assert!(near.0 < far.0 && near.0 < 0.3, "{side}: {far:?} {near:?}");
        assert!(near.1 < far.1 && near.1 < 0.1, "{side}: {far:?} {near:?}");
        assert!(near.2 > far.2, "{side}: {far:?} {near:?}");
    }
}

#[test]
fn a_spherical_body_has_nothing_to_average() {
    assert!(Moments::new(&Vector3::new(2.0, 2.0, 2.0)).is_none());
}
