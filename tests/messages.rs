//! Messages (issue 35 §4): each bad input is reported at its own field, in plain words, with
//! short numbers. One scan runs over a battery of bad inputs (the corpus's and the cases
//! below) and refuses Debug text, runs of spaces and numbers printed as long decimals.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn polhode() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-messages", name)
}

const BASE: &str = "name: b
body: {mass: 10.0, principal: [1.0, 2.0, 3.0]}
initial: {omega: [0.1, 0.0, 1.0]}
duration: 2.0
integrator: {method: dopri5}
output: {rate: 10}
";

/// (case, YAML, the field the message must name, words it must hold)
fn cases() -> Vec<(&'static str, String, &'static str, &'static str)> {
    vec![
        (
            "inclination",
            format!("{BASE}orbit: {{semi_major_axis_km: 7000, inclination_deg: 400}}\n"),
            "orbit.inclination_deg",
            "expected an inclination from 0 to 180 degrees, got 400",
        ),
        (
            "duplicate-names",
            format!(
                "{BASE}effectors:\n  - {{wheel: {{name: w, axial_inertia: 0.01, axis: [0,0,1]}}}}\n  \
                 - {{wheel: {{name: w, axial_inertia: 0.01, axis: [1,0,0]}}}}\n"
            ),
            "effectors[1]",
            "two effectors are named `w`",
        ),
        (
            "copies-negative-flow",
            format!(
                "{BASE}effectors:\n  - {{wheel: {{name: w, axial_inertia: 0.01, axis: [0,0,1], \
                 copies: {{count: -1, about: [0,0,1]}}}}}}\n"
            ),
            "effectors[0].wheel.copies.count",
            "expected a whole number from 0 to 4294967295, got `-1`",
        ),
        (
            "copies-negative-block",
            format!(
                "{BASE}effectors:\n  - wheel:\n      name: w\n      axial_inertia: 0.01\n      \
                 axis: [0,0,1]\n      copies:\n        count: -1\n        about: [0,0,1]\n"
            ),
            "effectors[0].wheel.copies.count",
            "expected a whole number from 0 to 4294967295, got `-1`",
        ),
        (
            "quoted-on",
            format!("{BASE}orbit: {{semi_major_axis_km: 7000, j2_secular: 'on'}}\n"),
            "orbit.j2_secular",
            "expected `true` or `false`",
        ),
        (
            "quoted-y",
            format!("{BASE}orbit: {{semi_major_axis_km: 7000, j2_secular: 'y'}}\n"),
            "orbit.j2_secular",
            "expected `true` or `false`",
        ),
        (
            "plain-off",
            format!("{BASE}orbit: {{semi_major_axis_km: 7000, j2_secular: off}}\n"),
            "orbit.j2_secular",
            "expected `true` or `false`",
        ),
        (
            "huge-number",
            BASE.replace("duration: 2.0", "duration: 1e300"),
            "",
            "",
        ),
        (
            "omega-ten-values",
            BASE.replace("[0.1, 0.0, 1.0]", "[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]"),
            "initial.omega",
            "expected a list of 3 values, got more than 3",
        ),
        (
            // 85 000 table rows are 255 000 YAML nodes, past the reader's 250 000.
            "too-many-nodes",
            format!(
                "{BASE}effectors:\n  - wheel:\n      axial_inertia: 0.01\n      axis: [0,0,1]\n      \
                 motor: {{torque: {{steps: [{}]}}}}\n",
                vec!["[1,0]"; 85_000].join(",")
            ),
            "",
            "past the reader's limit",
        ),
        (
            "assembly-law",
            format!(
                "{BASE}effectors:\n  - wheel:\n      name: a\n      axial_inertia: 0.01\n      \
                 axis: [0,0,1]\n      motor: {{rate_damping: {{gain: 0.5, sample_rate: 10.0}}}}\n  \
                 - wheel:\n      name: b\n      axial_inertia: 0.01\n      axis: [1,0,0]\n      \
                 motor: {{rate_damping: {{gain: 0.1, sample_rate: 3.0}}}}\n"
            ),
            "effectors[1].wheel.motor.rate_damping",
            "one assembly with one law",
        ),
    ]
}

/// What no message may hold: Rust Debug text, runs of spaces, 22+ digit numerals, the
/// parser's type names.
fn unreadable(message: &str) -> Option<String> {
    if message.contains("  ") {
        return Some("a run of spaces".into());
    }
    for debug in [
        "Some(",
        "None",
        "Ok(",
        "Err(",
        " { ",
        "invalid u32",
        "invalid u64",
        "invalid i64",
    ] {
        if message.contains(debug) {
            return Some(format!("Debug or parser text `{debug}`"));
        }
    }
    let mut run = 0;
    for c in message.chars() {
        if c.is_ascii_digit() {
            run += 1;
            if run > 21 {
                return Some("a numeral of more than 21 digits".into());
            }
        } else if c != '.' {
            run = 0;
        }
    }
    None
}

fn check(file: &Path) -> (Option<i32>, String) {
    let out = polhode().arg("check").arg(file).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Each case is refused (exit 2), at its own field, with what was expected.
#[test]
fn bad_inputs_are_reported_at_their_field() {
    let dir = scratch("cases");
    for (name, yaml, field, words) in cases() {
        let file = dir.join(format!("{name}.yaml"));
        std::fs::write(&file, yaml).unwrap();
        let (code, err) = check(&file);
        assert_eq!(code, Some(2), "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.yaml:")),
            "{name}: no file and line: {err}"
        );
        if !field.is_empty() {
            assert!(err.contains(&format!("field `{field}`")), "{name}: {err}");
        }
        assert!(err.contains(words), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The scan: every message of the battery (the cases above and every file of
/// tests/corpus/bad) is free of Debug text, runs of spaces and long decimals.
#[test]
fn no_message_holds_debug_text_runs_of_spaces_or_long_numbers() {
    let dir = scratch("scan");
    let mut files: Vec<PathBuf> = cases()
        .into_iter()
        .map(|(name, yaml, _, _)| {
            let file = dir.join(format!("{name}.yaml"));
            std::fs::write(&file, yaml).unwrap();
            file
        })
        .collect();
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus/bad");
    let mut listed: Vec<PathBuf> = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    listed.sort();
    files.extend(listed);
    let mut found = Vec::new();
    for file in &files {
        let (_, err) = check(file);
        if let Some(why) = unreadable(&err) {
            found.push(format!("{}: {why}: {err}", file.display()));
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// An unstable sampled loop (gain 300 N m s at 10 Hz on 9 kg m²) is blamed on the controller,
/// not on a vanishing inertia.
#[test]
fn an_unstable_sampled_loop_is_blamed_on_the_controller() {
    let dir = scratch("loop");
    let file = dir.join("loop.yaml");
    let yaml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/rwa-rate-damping.yaml"
    ))
    .unwrap()
    .replace(
        "gain: 0.5, sample_rate: 10.0",
        "gain: 300.0, sample_rate: 10.0",
    )
    .lines()
    .filter(|l| !l.contains("max_torque") && !l.contains("max_speed"))
    .collect::<Vec<_>>()
    .join("\n");
    std::fs::write(&file, yaml).unwrap();
    let out = polhode()
        .args(["run", file.to_str().unwrap(), "--no-log", "-q"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains(
            "the discrete rate-damping loop is unstable: gain 300 N m s sampled every 0.1 s"
        ),
        "{err}"
    );
    assert!(!err.contains("vanishing inertia"), "{err}");
    assert!(unreadable(&err).is_none(), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A full disk while writing `--csv` with `--no-log` names the table, not the log (before:
/// "writing the log failed"). RLIMIT_FSIZE makes writes past 20 kB fail as on a full disk.
#[test]
fn a_full_disk_under_csv_alone_names_the_table() {
    use std::os::unix::process::CommandExt;
    let dir = scratch("csv-full");
    let csv = dir.join("t.csv");
    let mut cmd = polhode();
    cmd.args([
        "run",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/rwa-rate-damping.yaml"
        ),
        "--no-log",
        "-q",
        "--csv",
    ])
    .arg(&csv);
    // SAFETY: setrlimit is async-signal-safe and touches only the child being started.
    unsafe {
        cmd.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 20_000,
                rlim_max: 20_000,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("writing the sampled telemetry"), "{err}");
    assert!(err.contains("t.csv"), "{err}");
    assert!(!err.contains("the log"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A NaN in `probability_by` is a non-finite number at its field, not "text that reads as a
/// number".
#[test]
fn a_nan_in_probability_by_is_called_not_finite() {
    let dir = scratch("nan");
    let file = dir.join("nan.yaml");
    let yaml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/explorer1-energy-sink.yaml"
    ))
    .unwrap()
    .replace(
        "probability_by: [3600, 6888, 14400]",
        "probability_by: [3600, .nan]",
    );
    std::fs::write(&file, yaml).unwrap();
    let out = polhode()
        .args(["montecarlo", file.to_str().unwrap(), "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("field `montecarlo.probability_by`: expected a finite number, got `.nan`"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A name `check` accepts is one `montecarlo` can write its directory under: the longest
/// name of multi-byte characters gives a campaign directory within the file-name limit.
#[test]
fn check_and_montecarlo_agree_on_a_long_name() {
    let dir = scratch("long-name");
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cubesat-detumble.yaml"),
    )
    .unwrap();
    let long = "é".repeat(200);
    let yaml: String = source
        .lines()
        .map(|l| {
            if l.starts_with("name:") {
                format!("name: {long}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let file = dir.join("long.yaml");
    std::fs::write(&file, yaml).unwrap();
    let (code, err) = check(&file);
    assert_eq!(code, Some(0), "{err}");
    let out = polhode()
        .current_dir(&dir)
        .args(["montecarlo", "--runs", "2"])
        .arg(&file)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let campaign = std::fs::read_dir(dir.join("logs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.join("runs.csv").exists())
        .expect("a campaign directory with runs.csv");
    assert!(campaign.file_name().unwrap().len() <= 255);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A hand-typed quaternion (four digits, norm 0.99999) is normalised with a located warning;
/// one off by more than a thousandth is refused.
#[test]
fn a_hand_typed_quaternion_is_normalised_with_a_warning() {
    let typed = BASE.replace(
        "initial: {omega: [0.1, 0.0, 1.0]}",
        "initial: {omega: [0.1, 0.0, 1.0], attitude: {w: 0.7071, x: 0, y: 0.7071, z: 0}}",
    );
    let s = polhode::scenario::parse(Path::new("q.yaml"), typed, &Default::default()).unwrap();
    let q = s.attitude0;
    assert!(
        (q.w - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15,
        "{q:?}"
    );
    let w: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("q.yaml:3:45: field `initial.attitude`: the quaternion's norm is 0.99999")
            && w[0].contains("normalised to {w: 0.707106781, x: 0.000000000, y: 0.707106781"),
        "{w:?}"
    );
    let off = BASE.replace(
        "initial: {omega: [0.1, 0.0, 1.0]}",
        "initial: {omega: [0.1, 0.0, 1.0], attitude: {w: 0.7, x: 0, y: 0.7, z: 0}}",
    );
    let Err(e) = polhode::scenario::parse(Path::new("q.yaml"), off, &Default::default()) else {
        panic!("a quaternion of norm 0.99 is refused");
    };
    let e = e.to_string();
    assert!(
        e.contains("field `initial.attitude`: expected a unit quaternion {w, x, y, z} (norm within 1e-3 of 1, then normalised), got norm 0.989949"),
        "{e}"
    );
}
