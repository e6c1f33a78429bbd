//! The sign convention of `body.inertia`'s off-diagonal entries (docs/conventions.md, "Inertia
//! tensor and products of inertia"): the matrix is the inertia tensor J with
//! J_xy = −∫x y dm, used as given in H = J ω; products of inertia P_xy = +∫x y dm must be
//! entered with their sign changed. The expected values below are derived by hand.

mod common;

use common::{run, scenario};
use nalgebra::Vector3;
use polhode::scenario::{self as sc, Overrides};
use std::path::Path;

fn body_yaml(inertia: &str) -> String {
    format!(
        "name: t\nbody: {{inertia: {inertia}}}\ninitial: {{omega: [1.0, 0.0, 0.0]}}\n\
         duration: 1.0\nintegrator: {{method: dopri5, rtol: 1.0e-12, atol: 1.0e-14}}\n\
         output: {{rate: 10}}\n"
    )
}

/// A body whose mass lies more along x = y than along x = −y: J_xx = J_yy = 3, J_zz = 5 kg m²,
/// P_xy = ∫x y dm = +1 kg m², so the tensor entry is J_xy = −1.
///
/// By hand: the x–y block [[3, −1], [−1, 3]] has eigenvalues 3 ∓ 1, with eigenvectors
/// (1, 1)/√2 for 3 − 1 = 2 and (1, −1)/√2 for 3 + 1 = 4; z is principal with 5. So
/// I = (2, 4, 5) kg m², the least inertia about (1, 1, 0)/√2, the line the mass lies along.
/// Spin ω = (1, 0, 0) rad/s gives H = J ω = (3, −1, 0) N m s and T = ½ ωᵀ J ω = 1.5 J.
#[test]
fn a_negative_off_diagonal_entry_is_a_positive_product_of_inertia() {
    let s = scenario(&body_yaml("[[3, -1, 0], [-1, 3, 0], [0, 0, 5]]"));
    let hub = &s.spacecraft.hub;
    let moments = hub.principal_moments;
    for (got, want) in moments.iter().zip([2.0, 4.0, 5.0]) {
        assert!((got - want).abs() < 1e-12, "principal moments {moments:?}");
    }
    let axes = hub.principal_axes;
    let along = |col: usize, v: Vector3<f64>| {
        (axes.column(col).dot(&v.normalize()).abs() - 1.0).abs() < 1e-12
    };
    assert!(
        along(0, Vector3::new(1.0, 1.0, 0.0)),
        "I1 axis {:?}",
        axes.column(0)
    );
    assert!(
        along(1, Vector3::new(1.0, -1.0, 0.0)),
        "I2 axis {:?}",
        axes.column(1)
    );
    assert!(along(2, Vector3::z()), "I3 axis {:?}", axes.column(2));

    // The matrix is used as given in H = J ω (through the whole run path).
    let (out, _) = run(&s);
    let h = out.initial_observation.h_body;
    assert!(
        (h - Vector3::new(3.0, -1.0, 0.0)).norm() < 1e-12,
        "H = {h:?}"
    );
    assert!((out.initial_observation.kinetic_energy - 1.5).abs() < 1e-12);

    // Entering the product +1 instead gives the mirrored body: the same moments, but the
    // least inertia about (1, −1, 0)/√2, across the mass.
    let mirrored = scenario(&body_yaml("[[3, 1, 0], [1, 3, 0], [0, 0, 5]]"));
    let m_axes = mirrored.spacecraft.hub.principal_axes;
    let m = m_axes
        .column(0)
        .dot(&Vector3::new(1.0, -1.0, 0.0).normalize())
        .abs();
    assert!((m - 1.0).abs() < 1e-12, "{:?}", m_axes.column(0));
}

/// Three equal products: a dumbbell along (1, 1, 1) (P_xy = P_yz = P_zx = +1 kg m²) on a
/// spherical core, J_xx = J_yy = J_zz = 3 kg m².
///
/// By hand: J = 4·1 − 𝟙 (𝟙 the all-ones matrix, whose eigenvalues are 3 along (1, 1, 1) and
/// 0 twice across it), so the moments are 4 − 3 = 1 about (1, 1, 1)/√3 and 4 twice. With the
/// products entered unchanged the matrix is 2·1 + 𝟙: moments 2, 2, 5, which violates the
/// triangle inequality (2 + 2 < 5), so no body has it and polhode refuses it.
#[test]
fn three_products_change_the_moments_and_the_wrong_sign_is_refused() {
    let s = scenario(&body_yaml("[[3, -1, -1], [-1, 3, -1], [-1, -1, 3]]"));
    let hub = &s.spacecraft.hub;
    for (got, want) in hub.principal_moments.iter().zip([1.0, 4.0, 4.0]) {
        assert!((got - want).abs() < 1e-12, "{:?}", hub.principal_moments);
    }
    let d = hub
        .principal_axes
        .column(0)
        .dot(&Vector3::new(1.0, 1.0, 1.0).normalize());
    assert!((d.abs() - 1.0).abs() < 1e-12);

    let wrong = sc::parse(
        Path::new("t.yaml"),
        body_yaml("[[3, 1, 1], [1, 3, 1], [1, 1, 3]]"),
        &Overrides::default(),
    );
    let Err(err) = wrong else {
        panic!("the +products matrix must be refused");
    };
    let err = err.to_string();
    assert!(err.contains("body.inertia"), "{err}");
}
