//! polhode's MCAP logs read by an independent implementation: the Python `mcap` package with
//! its protobuf decoder (tests/python/read_mcap.py), in the venv that `scripts/test.sh`
//! creates. The test fails (it does not skip) when the venv is missing.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn python() -> PathBuf {
    let p = root().join(".venv/bin/python");
    assert!(
        p.exists(),
        "{} is missing: run scripts/python-venv.sh (scripts/test.sh does it for you)",
        p.display()
    );
    p
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-reader", name)
}

fn run_polhode(scenario: &Path, out: &Path, extra: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Runs the reader; returns (exit code, stdout + stderr).
fn read(file: &Path, args: &[&str]) -> (i32, String) {
    let o = Command::new(python())
        .arg(root().join("tests/python/read_mcap.py"))
        .arg(file)
        .args(args)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.code().unwrap_or(-1), text)
}

/// A pure spin about body z from the identity: the reader checks every /tf rotation against
/// (0, 0, sin(Ωt/2), cos(Ωt/2)), i.e. polhode's convention (body → world, x y z w).
#[test]
fn known_rotation_in_the_right_convention() {
    let dir = scratch("spin");
    let scenario = dir.join("spin.yaml");
    std::fs::write(
        &scenario,
        "name: z-spin\nbody: {principal: [1.0, 2.0, 3.0], spin_axis: [0, 0, 1]}\n\
         initial: {omega: [0.0, 0.0, 0.7]}\nduration: 20.0\noutput: {rate: 25}\n",
    )
    .unwrap();
    for method in [
        vec!["--method", "dopri5"],
        vec!["--method", "rk4", "--dt", "0.001"],
        vec!["--method", "exact"],
    ] {
        let out = dir.join(format!("{}.mcap", method[1]));
        run_polhode(&scenario, &out, &method);
        let (code, text) = read(&out, &["--expect-samples", "501", "--expect-spin-z", "0.7"]);
        assert_eq!(code, 0, "{method:?}: {text}");
        // The wrong sense of rotation must fail: the check can fail.
        let (code, _) = read(&out, &["--expect-spin-z", "-0.7", "--quiet"]);
        assert_eq!(code, 1, "{method:?}: the reversed rotation was accepted");
    }
}

/// Every shipped scenario's log decodes completely with the embedded schemas.
#[test]
fn every_shipped_scenario_log_decodes() {
    let dir = scratch("shipped");
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    for f in files {
        let out = dir.join(f.with_extension("mcap").file_name().unwrap());
        // Long runs are cut to 20 s: decoding is what is tested here.
        let text = std::fs::read_to_string(&f).unwrap();
        let long = text
            .lines()
            .filter_map(|l| l.strip_prefix("duration:"))
            .filter_map(|v| v.split('#').next()?.trim().parse::<f64>().ok())
            .any(|d| d > 20.0);
        run_polhode(&f, &out, if long { &["--duration", "20"] } else { &[] });
        let (code, text) = read(&out, &[]);
        assert_eq!(code, 0, "{}: {text}", f.display());
        // The reader found every field's unit in the schemas' field comments.
        let summary: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
        let units = &summary["units"];
        assert_eq!(units["polhode.Telemetry"]["omega_x"], "rad/s", "{text}");
        assert_eq!(units["polhode.Telemetry"]["h_norm"], "N m s", "{text}");
        if f.ends_with("explorer1-pydy.yaml") {
            // Four rods, one schema.
            let schemas: Vec<&String> = units.as_object().unwrap().keys().collect();
            assert_eq!(
                schemas,
                ["polhode.Telemetry", "polhode.effectors.HingedRodFlapLag"],
                "{text}"
            );
            assert_eq!(
                units["polhode.effectors.HingedRodFlapLag"]["flap_rate"],
                "rad/s"
            );
        }
    }
}

/// A truncated log is refused by the independent reader.
#[test]
fn truncated_log_is_refused() {
    let dir = scratch("truncated");
    let out = dir.join("full.mcap");
    run_polhode(&root().join("scenarios/tennis-racket.yaml"), &out, &[]);
    let bytes = std::fs::read(&out).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let (code, text) = read(&cut, &["--quiet"]);
    assert_eq!(code, 1, "{text}");
}
