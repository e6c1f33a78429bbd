//! The slosh analog against published numbers (`cargo test --release --test slosh_published
//! -- --nocapture` prints each comparison). Only values read from a publication's own table
//! are used here; what could not be read is listed in docs/slosh-analogs.md ("Published
//! numbers").
//!
//! **The half-full sphere.** NASTRAN's Demonstration Problem 3-3-1 ("Vibration of a liquid in
//! a half-filled rigid sphere", NASA COSMIC NASTRAN; its text is distributed with NASA's
//! NASTRAN-95 release) takes g = 10.0 ft/s² and a sphere of radius
//! R = 10.0 ft, half full of an incompressible liquid, and tabulates in its Table 1 the
//! first antisymmetric (n = 1) mode's natural frequency two ways:
//!
//! | source (Table 1, mode 1) | frequency |
//! | --- | ---: |
//! | "Reference": B. Budiansky, J. Aerospace Sci. 27(3), 1960, Table 2 (analytical) | 0.1991 Hz |
//! | NASTRAN's axisymmetric fluid finite elements | 0.1988 Hz |
//!
//! **Tolerances, from the publication's reading precision.** Both are printed to four
//! decimals of a hertz, so each stands for an interval of ±0.00005 Hz (2.5e-4 of the value;
//! 5e-4 in ω²R/g). Our Ritz solution's own error (`numerical_error`, 8e-8 at half full) is
//! negligible against that. The test asserts that our frequency rounds to NASTRAN's printed
//! value, and that our difference from Budiansky's printed value is the −0.0003 Hz (−0.15 %)
//! that the same table shows between NASTRAN and Budiansky, again to the printing's
//! ±0.00005 Hz (the interval of a difference of two rounded values is ±0.0001 Hz): our value
//! does **not** round to Budiansky's, and the test says so rather than widening the band.
//! (The Ritz κ is an upper bound on the exact eigenvalue, ω₁²R/g ≤ 1.56016, while the
//! Budiansky value read back from 0.1991 Hz is 1.5650 ± 0.0008: the published value is the
//! high one; docs/slosh-analogs.md, "Published numbers".)
//! The sloshing frequency needs no units beyond consistency (ω² = κ g with κ in 1/length), so
//! the case is run in SI with R = 3.048 m and g = 3.048 m/s².
use polhode::effectors::slosh_analog::{Liquid, Tank, slosh_analog};
use std::f64::consts::PI;

/// Water; only the Bond number (far above every threshold at this size) and the damping
/// (not compared) depend on it. The demonstration problem's liquid is inviscid.
const WATER: Liquid = Liquid {
    density: 1000.0,
    kinematic_viscosity: 1.0e-6,
    surface_tension: 0.0728,
};

/// One foot (m).
const FOOT: f64 = 0.3048;

/// Half of the last printed digit of NASTRAN's Table 1 (Hz).
const PRINTED_HALF_DIGIT: f64 = 0.5e-4;

#[test]
fn half_full_sphere_against_nastran_demonstration_problem_3_3_1() {
    let radius = 10.0 * FOOT;
    let g = 10.0 * FOOT;
    let a = slosh_analog(&Tank::Sphere { radius }, 0.5, &WATER, g).unwrap();
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
    let ours = a.frequency / (2.0 * PI);

    let budiansky = 0.1991;
    let nastran = 0.1988;
    let lambda = |f: f64| (2.0 * PI * f).powi(2) * radius / g;
    println!(
        "half-full sphere, R = 10 ft, g = 10 ft/s^2 (NASTRAN demonstration problem 3-3-1, Table 1):"
    );
    println!(
        "  ours        f1 = {ours:.6} Hz  (omega^2 R/g = {:.5}, Ritz error {:.1e})",
        a.frequency_parameter, a.numerical_error
    );
    for (name, value) in [("NASTRAN FE", nastran), ("Budiansky", budiansky)] {
        println!(
            "  {name:<11} f1 = {value:.4} Hz    (omega^2 R/g = {:.4} from the printed digits); \
             ours - it = {:+.6} Hz ({:+.3} %)",
            lambda(value),
            ours - value,
            100.0 * (ours - value) / value
        );
    }

    // The dimensionless check of the conversion itself: ω²R/g from f, R and g.
    assert!((lambda(ours) - a.frequency_parameter).abs() < 1e-12);
    // Ours rounds to NASTRAN's printed 0.1988 Hz.
    assert!(
        (ours - nastran).abs() <= PRINTED_HALF_DIGIT,
        "ours {ours:.6} Hz vs NASTRAN {nastran} Hz"
    );
    // Ours lies 0.0003 Hz below Budiansky's printed 0.1991 Hz, as NASTRAN's does; the
    // difference of two four-decimal values is known to ±0.0001 Hz.
    let below = budiansky - ours;
    assert!(
        (below - 0.0003).abs() <= 2.0 * PRINTED_HALF_DIGIT,
        "ours {ours:.6} Hz is {below:.6} Hz below Budiansky's {budiansky} Hz"
    );
    assert!(
        below > PRINTED_HALF_DIGIT,
        "ours now rounds to Budiansky's value: update docs/slosh-analogs.md"
    );
}
