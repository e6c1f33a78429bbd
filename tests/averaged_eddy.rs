//! `method: averaged` with eddy currents (docs/averaging.md, "Eddy currents") against
//! references it did not produce: the full integration with dop853 in the Earth's field over
//! days, for a tumbling cylinder (an axisymmetric stage with a cylindrical shell on its axis)
//! and for a spherical shell in a triaxial body; the energy-sink closed form that holds when
//! H lies along a uniform field; and the refusals.

mod common;

use common::{run, scenario};
use nalgebra::{Matrix3, Vector3};
use polhode::effectors::EddyCurrents;
use polhode::effectors::eddy_currents::AmbientField;
use polhode::sim::Status;

/// A low orbit and an epoch inside the field model's years.
const ORBIT: &str = "epoch: 2016-03-01T00:00:00Z
orbit: {semi_major_axis_km: 7018.137, inclination_deg: 71.0, raan_deg: 30.0, j2_secular: true, magnetic_field: dipole}
";

/// The scene with `body`, `omega` and `effector` under `integrator` for `days`.
fn scene(body: &str, omega: &str, effector: &str, integrator: &str, days: f64) -> String {
    format!(
        "name: eddy-avg
{ORBIT}body: {body}
initial: {{omega: {omega}}}
duration: {}
integrator: {integrator}
output: {{rate: 0.001}}
effectors:
  - eddy_currents: {effector}
",
        days * 86_400.0
    )
}

/// |H|, T at the end of the full run and the averaged run, and the wall times.
fn compare(body: &str, omega: &str, effector: &str, days: f64) -> [(f64, f64); 3] {
    let full = scene(
        body,
        omega,
        effector,
        "{method: dop853, rtol: 1.0e-10, atol: 1.0e-12}",
        days,
    );
    let avg = scene(
        body,
        omega,
        effector,
        "{method: averaged, rtol: 1.0e-10}",
        days,
    );
    let (out_f, rec_f) = run(&scenario(&full));
    let (out_a, rec_a) = run(&scenario(&avg));
    assert_eq!(out_f.status, Status::Complete);
    assert_eq!(out_a.status, Status::Complete, "{:?}", out_a.status);
    let (f0, f1) = (&rec_f.samples[0], rec_f.samples.last().unwrap());
    let a1 = rec_a.samples.last().unwrap();
    assert_eq!(f1.t, a1.t);
    [
        (f0.h_norm, f0.kinetic_energy),
        (f1.h_norm, f1.kinetic_energy),
        (a1.h_norm, a1.kinetic_energy),
    ]
}

/// Checks the averaged end state against the full one: |H| and T within 1 %, and the losses
/// of |H| and T within `loss` of the full run's.
fn check(what: &str, r: [(f64, f64); 3], loss: f64) {
    let [(h0, t0), (hf, tf), (ha, ta)] = r;
    let (dh, dt) = ((ha - hf) / hf, (ta - tf) / tf);
    let (lh, lt) = (((h0 - ha) / (h0 - hf) - 1.0), ((t0 - ta) / (t0 - tf) - 1.0));
    eprintln!(
        "{what}: full |H| {hf:.6e} T {tf:.6e} (lost {:.3} %, {:.3} %); averaged |H| {ha:.6e} T \
         {ta:.6e}: off by {dh:.2e}, {dt:.2e}; losses off by {lh:.2e}, {lt:.2e}",
        100.0 * (1.0 - hf / h0),
        100.0 * (1.0 - tf / t0)
    );
    assert!(dh.abs() < 0.01 && dt.abs() < 0.01, "{what}");
    assert!(lh.abs() < loss && lt.abs() < loss, "{what}");
    // It must have lost something worth comparing.
    assert!(1.0 - tf / t0 > 0.02, "{what}");
}

/// An axisymmetric stage (a thin aluminium cylinder on its symmetry axis) tumbling near
/// end over end, four days in the dipole field: the averaged method against dop853.
#[test]
fn a_tumbling_cylinder_agrees_with_the_full_integration() {
    let r = compare(
        "{principal: [1200, 1200, 300]}",
        "[0.5, 0.15, 0.6]",
        "{conductivity: 3.5e7, shape: {cylindrical_shell: {radius: 0.6, length: 4.0, \
         thickness: 0.0015, axis: [0, 0, 1]}}}",
        4.0,
    );
    check("cylinder", r, 0.02);
}

/// A spherical shell in a triaxial body (isotropic tensor), four days: the averaged method
/// against dop853.
#[test]
fn a_spherical_shell_in_a_triaxial_body_agrees_with_the_full_integration() {
    let r = compare(
        "{principal: [300, 420, 500]}",
        "[0.3, -0.4, 0.5]",
        "{conductivity: 3.5e7, shape: {spherical_shell: {radius: 0.8, thickness: 0.001}}}",
        4.0,
    );
    check("spherical shell", r, 0.02);
}

/// H along a uniform field B with an isotropic tensor μ: the torque −μ|B|² ω⊥ is then the
/// energy sink's with c = μ|B|² about H (it has no part along H, so H stays along B), and an
/// axisymmetric body's nutation follows tan θ = tan θ₀ e^{t/τ}, 1/τ = c (I_t − I_s)/(I_s I_t)
/// (Thomson & Reiter), for the full motion as for the averaged one.
#[test]
fn along_a_uniform_field_it_is_the_energy_sink_closed_form() {
    let (i_s, i_t) = (0.5, 1.0);
    let omega = Vector3::new(0.3, 0.0, 2.0);
    let h = Vector3::new(i_t * omega.x, 0.0, i_s * omega.z);
    let b = h.normalize() * 4e-5;
    // c (I_t − I_s)/(I_s I_t) = 1e-4 /s: τ = 1e4 s, and ε well below the limit.
    let c = 1e-4 * i_s * i_t / (i_t - i_s);
    let mu = c / b.norm_squared();
    let yaml = common::rigid_yaml(
        [i_t, i_t, i_s],
        [omega.x, omega.y, omega.z],
        20_000.0,
        "{method: averaged, rtol: 1.0e-12}",
        "",
    );
    let mut s = scenario(&yaml);
    s.simulation
        .spacecraft
        .add_effector(Box::new(EddyCurrents {
            name: "eddy".into(),
            field: AmbientField::Uniform(b),
            tensor: Matrix3::identity() * mu,
            material: None,
        }))
        .unwrap();
    let (out, rec) = run(&s);
    assert_eq!(out.status, Status::Complete, "{:?}", out.status);
    let tau = i_s * i_t / (c * (i_t - i_s));
    let tan0 = (i_t * omega.x / (i_s * omega.z)).abs();
    let mut worst: f64 = 0.0;
    for o in &rec.samples {
        // θ between H and the symmetry axis (body z).
        let hb = o.h_body;
        let theta = (hb.xy().norm()).atan2(hb.z.abs());
        let expected = (tan0 * (o.t / tau).exp()).atan();
        worst = worst.max((theta - expected).abs());
        assert!((o.h_norm / h.norm() - 1.0).abs() < 1e-9, "|H| changed");
        assert!(o.h_inertial.normalize().cross(&b.normalize()).norm() < 1e-9);
    }
    eprintln!("worst nutation error {worst:e} rad");
    assert!(worst < 1e-7, "{worst:e}");
}

/// A triaxial body with an anisotropic tensor is refused at load, naming the effector.
#[test]
fn an_anisotropic_tensor_on_a_triaxial_body_is_refused() {
    let yaml = scene(
        "{principal: [300, 420, 500]}",
        "[0.3, -0.4, 0.5]",
        "{conductivity: 3.5e7, shape: {cylindrical_shell: {radius: 0.6, length: 4.0, \
         thickness: 0.0015, axis: [0, 0, 1]}}}",
        "{method: averaged}",
        1.0,
    );
    let Err(err) = polhode::scenario::parse(
        std::path::Path::new("t.yaml"),
        yaml,
        &polhode::scenario::Overrides::default(),
    ) else {
        panic!("not refused");
    };
    let msg = err.to_string();
    assert!(
        msg.contains("eddy_currents") && msg.contains("not axisymmetric"),
        "{msg}"
    );
}

/// A body spinning too slowly against the orbit is refused before the first step.
#[test]
fn a_slow_spin_against_the_orbit_is_refused() {
    let yaml = scene(
        "{principal: [1200, 1200, 300]}",
        "[0.005, 0.0015, 0.006]",
        "{conductivity: 3.5e7, shape: {cylindrical_shell: {radius: 0.6, length: 4.0, \
         thickness: 0.0015, axis: [0, 0, 1]}}}",
        "{method: averaged}",
        1.0,
    );
    let (out, _) = run(&scenario(&yaml));
    match out.status {
        Status::Failed { diagnosis } => {
            assert!(diagnosis.contains("of the orbit period"), "{diagnosis}")
        }
        s => panic!("not refused: {s:?}"),
    }
}
