//! The capsule tank's slosh analog (`polhode::effectors::slosh_analog`, Rayleigh–Ritz on solid
//! harmonics) against an independent solution of the same potential problem: linear finite
//! elements on a mapped grid with Richardson extrapolation, `tests/reference/slosh_capsule.py`,
//! committed as `tests/data/slosh_capsule.json` (this test needs no Python). The reference
//! checks itself against the flat-bottomed cylinder's closed forms before it writes anything;
//! its cases put the free surface in the lower dome, at the junctions, in the barrel and in
//! the upper dome of capsules with barrels of R and 3R.
use polhode::effectors::slosh_analog::{
    Liquid, SloshError, Tank, capsule_fill_range, slosh_analog,
};
use serde_json::Value;
use std::f64::consts::PI;

const WATER: Liquid = Liquid {
    density: 1000.0,
    kinematic_viscosity: 1.0e-6,
    surface_tension: 0.0728,
};

/// Fill fraction of a capsule (R = 1, barrel b) whose surface is `depth` above its bottom
/// pole: the dome caps π h²(3 − h)/3 and the barrel's π (h − 1), written out here.
fn fill_for_depth(barrel: f64, depth: f64) -> f64 {
    let cap = |h: f64| PI * h * h * (3.0 - h) / 3.0;
    let dome = 2.0 * PI / 3.0;
    let volume = if depth <= 1.0 {
        cap(depth)
    } else if depth <= 1.0 + barrel {
        dome + PI * (depth - 1.0)
    } else {
        let above = 2.0 + barrel - depth;
        2.0 * dome + PI * barrel - cap(above)
    };
    volume / (4.0 * PI / 3.0 + PI * barrel)
}

#[test]
fn capsule_analog_matches_the_finite_element_reference() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/slosh_capsule.json"
    ))
    .expect("tests/data/slosh_capsule.json");
    let doc: Value = serde_json::from_str(&text).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    assert!(cases.len() >= 10);
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for case in cases {
        let barrel = case["barrel"].as_f64().unwrap();
        let depth = case["depth"].as_f64().unwrap();
        let fill = fill_for_depth(barrel, depth);
        let tank = Tank::Capsule {
            radius: 1.0,
            barrel,
        };
        let (min, max) = capsule_fill_range(barrel);
        if !(min..=max).contains(&fill) {
            // Past the range the Ritz basis is provided for (the surface more than 0.3R up
            // the upper dome): refused, not answered.
            println!(
                "barrel {barrel} depth {depth}: fill {fill:.4} refused (range {min:.4}-{max:.4})"
            );
            assert!(matches!(
                slosh_analog(&tank, fill, &WATER, 9.81),
                Err(SloshError::FillOutOfRange { .. })
            ));
            continue;
        }
        compared += 1;
        let a = slosh_analog(&tank, fill, &WATER, 9.81).unwrap();
        assert!(
            (a.depth - depth).abs() < 1e-12,
            "depth {} vs {depth}",
            a.depth
        );
        let estimate: Vec<f64> = case["error_estimate"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        // Tolerance per quantity: three times the reference's own error estimate (the
        // disagreement of its two Richardson extrapolations, which bounded its true error on
        // the cylinder by a factor of 8 or more), plus the Ritz solution's convergence
        // estimate (`numerical_error`, relative) on the same scale.
        let ours = [
            a.frequency_parameter,
            a.slosh_mass / WATER.density,
            a.pivot_height,
        ];
        let theirs = [
            case["kappa"].as_f64().unwrap(),
            case["slosh_volume"].as_f64().unwrap(),
            case["pivot_height"].as_f64().unwrap(),
        ];
        for (k, name) in ["kappa", "slosh volume", "pivot height"].iter().enumerate() {
            let scale = theirs[k].abs().max(1.0);
            let tolerance = 3.0 * estimate[k] + a.numerical_error * scale;
            let diff = (ours[k] - theirs[k]).abs();
            println!(
                "barrel {barrel} depth {depth}: {name} {:.8} vs {:.8}, |diff| {diff:.1e} (tolerance {tolerance:.1e})",
                ours[k], theirs[k]
            );
            assert!(
                diff <= tolerance,
                "barrel {barrel}, depth {depth}: {name} {} vs reference {} (tolerance {tolerance:.1e})",
                ours[k],
                theirs[k]
            );
            worst = worst.max(diff / scale);
        }
    }
    assert!(compared >= 9, "only {compared} cases inside the range");
    println!("largest difference over {compared} cases: {worst:.1e}");
}
