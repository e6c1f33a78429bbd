//! The command line as a user meets it: bad input, the run and its outputs, linearize, Ctrl-C.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn polhode() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-cli", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Writes `text` to `dir/name` and returns the path.
fn write_scenario(dir: &Path, name: &str, text: &str) -> PathBuf {
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    file
}

/// The `--summary` JSON written at `path`.
fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The `status` of a log's `polhode` metadata record.
fn log_status(bytes: &[u8]) -> String {
    let summary = mcap::Summary::read(bytes).unwrap().unwrap();
    let index = summary
        .metadata_indexes
        .iter()
        .find(|i| i.name == "polhode")
        .expect("metadata");
    mcap::read::metadata(bytes, index).unwrap().metadata["status"].clone()
}

const GOOD: &str = "name: good
body:
  principal: [1.0, 2.0, 3.0]
  spin_axis: [0, 0, 1]
initial:
  omega: [0.1, 0.0, 1.0]
duration: 2.0
integrator: {method: dopri5, rtol: 1.0e-10, atol: 1.0e-12}
output: {rate: 10}
";

/// Writes `yaml` to DIR/bad.yaml, runs `polhode run` on it with the log going to DIR, and
/// checks: exit code 2, one message naming file:line, the field and the expectation, no
/// panic, and nothing written in DIR.
fn assert_rejected(name: &str, yaml: &[u8], line: u32, field: &str, expect: &str) {
    assert_rejected_at(name, yaml, line, Some(field), expect)
}

/// As [`assert_rejected`]; `field` is `None` for syntax errors, where no field is certain.
fn assert_rejected_at(name: &str, yaml: &[u8], line: u32, field: Option<&str>, expect: &str) {
    let dir = scratch(name);
    let file = dir.join("bad.yaml");
    std::fs::write(&file, yaml).unwrap();
    let out = polhode()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(dir.join("out.mcap"))
        .arg("--summary")
        .arg(dir.join("summary.json"))
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{name}: {err}");
    assert!(!err.contains("panicked"), "{name}: {err}");
    let located = format!("{}:{line}:", file.display());
    assert!(
        err.contains(&located),
        "{name}: expected {located} in: {err}"
    );
    if let Some(field) = field {
        assert!(
            err.contains(&format!("field `{field}`")),
            "{name}: expected field {field} in: {err}"
        );
    }
    assert!(
        err.contains(expect),
        "{name}: expected '{expect}' in: {err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{name}: one message: {err}");
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n != "bad.yaml")
        .collect();
    assert!(left.is_empty(), "{name}: files written: {left:?}");
    // `check` agrees.
    let chk = polhode().arg("check").arg(&file).output().unwrap();
    assert_eq!(chk.status.code(), Some(2), "{name}: check");
}

#[test]
fn malformed_yaml() {
    let y = GOOD.replace("spin_axis: [0, 0, 1]", "spin_axis: [0, 0, 1");
    assert_rejected_at("malformed", y.as_bytes(), 5, None, "");
}

#[test]
fn unknown_key_suggests_the_nearest() {
    let y = GOOD.replace("spin_axis:", "spin_axs:");
    assert_rejected(
        "unknown",
        y.as_bytes(),
        4,
        "body.spin_axs",
        "did you mean `spin_axis`?",
    );
    let y = GOOD.replace("method: dopri5", "method: dopri");
    assert_rejected(
        "method",
        y.as_bytes(),
        8,
        "integrator.method",
        "did you mean `dopri5`?",
    );
}

#[test]
fn missing_keys_name_the_missing_field() {
    let y = GOOD.replace("duration: 2.0\n", "");
    assert_rejected("missing-duration", y.as_bytes(), 8, "duration", "required");
    let y = GOOD.replace(
        "  omega: [0.1, 0.0, 1.0]",
        "  omega: [0.1, 0.0, 1.0]\n  attitude: {w: 1.0, x: 0.0, y: 0.0}",
    );
    assert_rejected(
        "missing-z",
        y.as_bytes(),
        7,
        "initial.attitude.z",
        "required",
    );
}

#[test]
fn empty_file_and_non_mapping() {
    let dir = scratch("empty");
    for (name, text) in [("empty.yaml", "# nothing\n"), ("list.yaml", "- a\n- b\n")] {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let out = polhode().arg("check").arg(&file).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        assert!(
            stderr(&out).contains("expected a mapping of scenario keys"),
            "{}",
            stderr(&out)
        );
    }
}

#[test]
fn wrong_types() {
    let y = GOOD.replace("duration: 2.0", "duration: two seconds");
    assert_rejected("type-duration", y.as_bytes(), 7, "duration", "");
    let y = GOOD.replace("[1.0, 2.0, 3.0]", "[1.0, 2.0]");
    assert_rejected(
        "type-length",
        y.as_bytes(),
        3,
        "body.principal",
        "list of 3 values",
    );
}

#[test]
fn unphysical_inertia() {
    let y = GOOD.replace("[1.0, 2.0, 3.0]", "[-1.0, 2.0, 3.0]");
    assert_rejected(
        "negative",
        y.as_bytes(),
        3,
        "body.principal",
        "positive definite",
    );
    let y = GOOD.replace("[1.0, 2.0, 3.0]", "[1.0, 1.0, 3.0]");
    assert_rejected(
        "triangle",
        y.as_bytes(),
        3,
        "body.principal",
        "triangle inequality",
    );
    let y = GOOD.replace(
        "principal: [1.0, 2.0, 3.0]",
        "inertia: [[1, 0.5, 0], [0, 2, 0], [0, 0, 2]]",
    );
    assert_rejected("asymmetric", y.as_bytes(), 3, "body.inertia", "symmetric");
}

#[test]
fn non_finite_numbers() {
    let y = GOOD.replace("omega: [0.1, 0.0, 1.0]", "omega: [.nan, 0.0, 1.0]");
    assert_rejected("nan", y.as_bytes(), 6, "initial.omega", "finite");
    let y = GOOD.replace("duration: 2.0", "duration: .inf");
    assert_rejected("inf", y.as_bytes(), 7, "duration", "finite");
    let y = GOOD.replace("[1.0, 2.0, 3.0]", "[1.0, .nan, 3.0]");
    assert_rejected("nan-inertia", y.as_bytes(), 3, "body.principal", "finite");
}

#[test]
fn non_positive_duration() {
    for d in ["0", "-1.0"] {
        let y = GOOD.replace("duration: 2.0", &format!("duration: {d}"));
        assert_rejected(
            &format!("duration{d}"),
            y.as_bytes(),
            7,
            "duration",
            "positive",
        );
    }
}

#[test]
fn not_utf8() {
    let mut y = GOOD.as_bytes().to_vec();
    y.splice(0..0, b"# caf\xe9\n".iter().copied());
    let dir = scratch("utf8");
    let file = dir.join("bad.yaml");
    std::fs::write(&file, &y).unwrap();
    let out = polhode().arg("check").arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains(":1:6:"), "{}", stderr(&out));
    assert!(stderr(&out).contains("UTF-8"));
}

#[test]
fn unwritable_output_path() {
    let dir = scratch("unwritable");
    let file = write_scenario(&dir, "good.yaml", GOOD);
    // A path under a regular file can never be created, whoever runs the test.
    let blocker = dir.join("not-a-dir");
    std::fs::write(&blocker, "x").unwrap();
    let target = blocker.join("out.mcap");
    let out = polhode()
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            target.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains(&target.display().to_string()));
    assert!(!target.exists());
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn run_writes_log_and_summary() {
    let dir = scratch("run");
    let file = write_scenario(&dir, "good.yaml", GOOD);
    let mcap = dir.join("good.mcap");
    let summary = dir.join("summary.json");
    let out = polhode()
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            mcap.to_str().unwrap(),
        ])
        .args(["--summary", summary.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(mcap.exists());
    let json: serde_json::Value = read_json(&summary);
    for key in [
        "status",
        "body",
        "initial",
        "final",
        "drift",
        "steps",
        "rhs_evaluations",
        "wall_time_s",
        "events",
        "samples",
    ] {
        assert!(json.get(key).is_some(), "summary lacks {key}");
    }
    let fin = &json["final"];
    for key in [
        "omega",
        "q",
        "kinetic_energy",
        "h_norm",
        "nutation_angle_deg",
    ] {
        assert!(fin.get(key).is_some(), "summary.final lacks {key}");
    }
    assert_eq!(fin["t"].as_f64(), Some(2.0));
    assert_eq!(json["samples"].as_u64(), Some(21));
    assert!(json["drift"]["h_norm_rel"].as_f64().unwrap() < 1e-9);
    // The log holds what the summary says.
    let bytes = std::fs::read(&mcap).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let stats = summary.stats.unwrap();
    let per_channel: std::collections::HashMap<String, u64> = summary
        .channels
        .values()
        .map(|c| (c.topic.clone(), stats.channel_message_counts[&c.id]))
        .collect();
    assert_eq!(per_channel["/tf"], 21);
    assert_eq!(per_channel["/telemetry"], 21);
    assert_eq!(per_channel["/scene"], 21);
}

/// `--summary -` prints the JSON summary (in place of the printed one) and writes no file
/// named `-`.
#[test]
fn summary_dash_prints_the_json() {
    let dir = scratch("summary-dash");
    let file = write_scenario(&dir, "good.yaml", GOOD);
    let out = polhode()
        .current_dir(&dir)
        .args(["run", file.to_str().unwrap(), "--no-log", "--summary", "-"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["final"]["t"].as_f64(), Some(2.0));
    assert_eq!(json["samples"].as_u64(), Some(21));
    assert!(!dir.join("-").exists());
}

#[test]
fn overrides_from_the_command_line() {
    let dir = scratch("overrides");
    let file = write_scenario(&dir, "good.yaml", GOOD);
    let summary = dir.join("s.json");
    let out = polhode()
        .args([
            "run",
            file.to_str().unwrap(),
            "--no-log",
            "--method",
            "rk4",
            "--dt",
            "0.01",
        ])
        .args([
            "--duration",
            "3",
            "--summary",
            summary.to_str().unwrap(),
            "--quiet",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stdout.is_empty());
    let json: serde_json::Value = read_json(&summary);
    assert_eq!(json["method"], "rk4");
    assert_eq!(json["steps"].as_u64(), Some(300));
    assert_eq!(json["rhs_evaluations"].as_u64(), Some(1200));
    assert_eq!(json["final"]["t"].as_f64(), Some(3.0));
}

#[test]
fn stop_event_ends_the_run_at_the_crossing() {
    let dir = scratch("stop");
    let summary = dir.join("s.json");
    let out = polhode()
        .args(["run", "scenarios/book.yaml", "--no-log", "--quiet"])
        .args(["--summary", summary.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = read_json(&summary);
    assert_eq!(json["status"]["kind"], "stopped");
    let t = json["events"][0]["t"].as_f64().unwrap();
    assert_eq!(json["final"]["t"].as_f64(), Some(t));
    let nut = json["final"]["nutation_angle_deg"].as_f64().unwrap();
    assert!((nut - 89.0).abs() < 1e-8, "stopped at {nut}°");
}

#[test]
fn linearize_reproduces_k_for_the_tennis_racket() {
    let out = polhode()
        .args(["linearize", "scenarios/tennis-racket.yaml", "--json", "-"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let k = json["max_growth_rate"].as_f64().unwrap();
    assert!((k - 5.0).abs() < 1e-8, "k = {k}");
    assert_eq!(json["verdict"], "unstable");
    let text = polhode()
        .args(["linearize", "scenarios/tennis-racket.yaml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("time constant 0.200000 s"), "{text}");
}

#[test]
fn every_shipped_scenario_is_valid() {
    let mut files: Vec<PathBuf> = std::fs::read_dir("scenarios")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    assert!(files.len() >= 5);
    let out = polhode().arg("check").args(&files).output().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
}

/// Ctrl-C mid-run: exit 130, a valid finished MCAP of what was computed, marked partial.
#[test]
#[cfg(unix)]
fn interrupt_keeps_a_valid_partial_log() {
    let dir = scratch("sigint");
    let file = dir.join("long.yaml");
    std::fs::write(
        &file,
        GOOD.replace("duration: 2.0", "duration: 1.0e6").replace(
            "method: dopri5, rtol: 1.0e-10, atol: 1.0e-12",
            "method: rk4, dt: 1.0e-4",
        ),
    )
    .unwrap();
    let mcap = dir.join("long.mcap");
    let child = polhode()
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            mcap.to_str().unwrap(),
            // The whole 1e6 s would be a 2 GB log; it is interrupted long before.
            "--max-log-mb",
            "1e5",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the run is under way (its temporary file exists), then interrupt.
    let started = std::time::Instant::now();
    while !std::fs::read_dir(&dir)
        .unwrap()
        .any(|e| e.unwrap().file_name().to_string_lossy().ends_with(".tmp"))
    {
        assert!(started.elapsed().as_secs() < 30, "run did not start");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(500));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(stderr(&out).contains("partial"), "{}", stderr(&out));
    assert_partial_log_is_valid(&mcap);
    let leftovers = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".tmp")
        })
        .count();
    assert_eq!(leftovers, 0);
}

fn assert_partial_log_is_valid(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    let mut n = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        m.unwrap();
        n += 1;
    }
    assert!(n > 3, "only {n} messages");
    assert_eq!(log_status(&bytes), "interrupted");
}

/// An explicit method far above its stability limit: the run stops with a diagnosis (time,
/// last finite state, remedy), exit 3, and keeps a valid log marked partial, never NaNs.
#[test]
fn unstable_step_stops_with_a_diagnosis_and_a_partial_log() {
    let dir = scratch("unstable");
    let file = dir.join("unstable.yaml");
    std::fs::write(
        &file,
        GOOD.replace("omega: [0.1, 0.0, 1.0]", "omega: [30.0, 50.0, 80.0]")
            .replace("duration: 2.0", "duration: 100.0")
            .replace(
                "method: dopri5, rtol: 1.0e-10, atol: 1.0e-12",
                "method: rk4, dt: 0.5",
            ),
    )
    .unwrap();
    let mcap = dir.join("unstable.mcap");
    let summary = dir.join("s.json");
    let out = polhode()
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            mcap.to_str().unwrap(),
        ])
        .args(["--summary", summary.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let err = stderr(&out);
    // Caught as diverging while the state is still finite (the energy balance grew), with
    // the stiffness measured there against rk4's stability bound.
    assert!(err.contains("diverging"), "{err}");
    assert!(err.contains("stability bound"), "{err}");
    let json: serde_json::Value = read_json(&summary);
    assert_eq!(json["status"]["kind"], "failed");
    let w = json["final"]["omega"].as_array().unwrap();
    assert!(
        w.iter().all(|v| v.as_f64().is_some_and(f64::is_finite)),
        "{w:?}"
    );
    let bytes = std::fs::read(&mcap).unwrap();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        m.unwrap();
    }
    let s = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(log_status(&bytes), "failed");
    // The last finite state is the log's last sample: /telemetry field 1 is sim_time, a
    // protobuf double (key 0x09, then 8 bytes little-endian).
    let telemetry = s
        .channels
        .values()
        .find(|c| c.topic == "/telemetry")
        .unwrap()
        .id;
    let last = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.id == telemetry)
        .last()
        .unwrap();
    assert_eq!(last.data[0], 0x09);
    let sim_time = f64::from_le_bytes(last.data[1..9].try_into().unwrap());
    assert_eq!(Some(sim_time), json["final"]["t"].as_f64());
}

/// Errors caused by a command-line option name the option, not a line of the file.
#[test]
fn option_errors_name_the_option() {
    let dir = scratch("options");
    let file = write_scenario(&dir, "good.yaml", GOOD);
    for (args, field) in [
        (vec!["--duration", "nan"], "--duration"),
        (vec!["--method", "dopri6"], "--method"),
        (vec!["--method", "rk4", "--dt=-1"], "--dt"),
        (vec!["--duration", "1e9"], "--duration"),
    ] {
        let out = polhode()
            .args(["run", file.to_str().unwrap(), "--no-log"])
            .args(&args)
            .output()
            .unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(&format!("field `{field}`")), "{args:?}: {err}");
        let blames_a_line = err
            .split("good.yaml:")
            .nth(1)
            .is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_digit()));
        assert!(!blames_a_line, "{args:?} blames a line: {err}");
    }
}

/// Requests that would run for ever or overflow the log's time stamps are refused up front.
#[test]
fn unbounded_work_and_unstampable_times_are_refused() {
    let y = GOOD.replace(
        "method: dopri5, rtol: 1.0e-10, atol: 1.0e-12",
        "method: dopri5, max_step: 1.0e-17",
    );
    assert_rejected(
        "max-step",
        y.as_bytes(),
        8,
        "integrator.max_step",
        "limit is 1e11",
    );
    let y = format!("epoch: \"2100-01-01T00:00:00Z\"\n{}", GOOD)
        .replace("duration: 2.0", "duration: 3.0e8")
        .replace("rate: 10", "rate: 1.0e-3");
    assert_rejected("late", y.as_bytes(), 8, "duration", "2106-02-07");
}

#[test]
fn summary_and_log_must_differ() {
    let dir = scratch("same");
    let file = write_scenario(&dir, "good.yaml", GOOD);
    let target = dir.join("x.out");
    let out = polhode()
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            target.to_str().unwrap(),
        ])
        .args(["--summary", target.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!target.exists());
}

/// A spacecraft with a hinged rod and a damper, for the bad-effector cases below.
const WITH_EFFECTORS: &str = "name: fx
body:
  mass: 10.0
  principal: [1.0, 2.0, 3.0]
  spin_axis: [0, 0, 1]
  shape: {box: {size: [1.0, 1.0, 1.0]}}
effectors:
  - hinged_rod:
      mass: 0.1
      length: 0.5
      hinge: [0.5, 0.0, 0.0]
      direction: [1, 0, 0]
      axis: [0, 0, 1]
      stiffness: 1.0
      damping: 0.1
  - modal_appendage:
      length: 2.0
      bending_stiffness: 10.0
      mass_per_length: 0.2
      attachment: [0.0, 0.5, 0.0]
      direction: [0, 1, 0]
      flap_direction: [0, 0, 1]
initial:
  omega: [0.1, 0.0, 1.0]
duration: 2.0
output: {rate: 10}
";

#[test]
fn the_effector_template_is_valid() {
    let dir = scratch("fx-ok");
    let file = write_scenario(&dir, "ok.yaml", WITH_EFFECTORS);
    let out = polhode().arg("check").arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

#[test]
fn unphysical_effectors_are_located_errors() {
    let cases: [(&str, &str, &str, u32, &str, &str); 7] = [
        (
            "neg-mass",
            "      mass: 0.1",
            "      mass: -0.1",
            9,
            "effectors[0].hinged_rod.mass",
            "positive",
        ),
        (
            "nan-length",
            "      length: 0.5",
            "      length: .nan",
            10,
            "effectors[0].hinged_rod.length",
            "positive",
        ),
        (
            "outside",
            "      hinge: [0.5, 0.0, 0.0]",
            "      hinge: [0.9, 0.0, 0.0]",
            11,
            "effectors[0].hinged_rod.hinge",
            "outside the body",
        ),
        (
            "skew-axis",
            "      axis: [0, 0, 1]",
            "      axis: [1, 0, 1]",
            13,
            "effectors[0].hinged_rod.axis",
            "perpendicular",
        ),
        (
            "zero-ei",
            "      bending_stiffness: 10.0",
            "      bending_stiffness: 0.0",
            18,
            "effectors[1].modal_appendage.bending_stiffness",
            "positive",
        ),
        (
            "neg-damping",
            "      damping: 0.1",
            "      damping: -0.1",
            15,
            "effectors[0].hinged_rod.damping",
            "from 0 to 1e12",
        ),
        ("no-mass", "  mass: 10.0\n", "", 0, "body.mass", "body.mass"),
    ];
    for (name, from, to, line, field, expect) in cases {
        let y = WITH_EFFECTORS.replacen(from, to, 1);
        assert_ne!(y, WITH_EFFECTORS, "{name}: the replacement must apply");
        if line == 0 {
            // Not tied to a line of its own: the message names the field.
            let dir = scratch(name);
            let file = write_scenario(&dir, "bad.yaml", &y);
            let out = polhode().arg("check").arg(&file).output().unwrap();
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(2), "{name}: {err}");
            assert!(err.contains(field) && err.contains(expect), "{name}: {err}");
        } else {
            assert_rejected(name, y.as_bytes(), line, field, expect);
        }
    }
}

#[test]
fn compare_prints_the_fidelities_side_by_side() {
    let dir = scratch("compare");
    let rigid = write_scenario(&dir, "rigid.yaml", GOOD);
    let fx = write_scenario(&dir, "fx.yaml", WITH_EFFECTORS);
    let chart = dir.join("chart.svg");
    let json = dir.join("table.json");
    let out = polhode()
        .args(["compare"])
        .arg(&rigid)
        .arg(&fx)
        .arg("--chart")
        .arg(&chart)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("good") && text.contains("hinged_rod + modal_appendage"),
        "{text}"
    );
    let rows = read_json(&json);
    assert_eq!(rows.as_array().unwrap().len(), 2);
    assert_eq!(rows[0]["states"], 7);
    assert!(std::fs::read_to_string(&chart).unwrap().starts_with("<svg"));
}

#[test]
fn inconsistent_effector_combinations_are_refused() {
    let wheel = "  - wheel_damper: {inertia: 3.0, axis: [1, 1, 0], damping: 1.0}\n";
    let cases = [
        // 1 / (âᵀ I⁻¹ â) = 1.82 kg m² for this axis, though âᵀ I â = 5.5.
        (
            "big-wheel",
            WITH_EFFECTORS
                .replace("principal: [1.0, 2.0, 3.0]", "principal: [1.0, 10.0, 10.0]")
                .replace("effectors:\n", &format!("effectors:\n{wheel}")),
            "effectors[0].wheel_damper.inertia",
        ),
        (
            "copy-outside",
            // The hinge is on the +x face of a flattened box; turned about y, two copies
            // land 0.2 m above and below it.
            WITH_EFFECTORS
                .replace("size: [1.0, 1.0, 1.0]", "size: [1.0, 1.0, 0.6]")
                .replace(
                    "      damping: 0.1\n",
                    "      damping: 0.1\n      copies: {count: 4, about: [0, 1, 0]}\n",
                ),
            "effectors[0].hinged_rod.copies",
        ),
        (
            "sink-with-rod",
            WITH_EFFECTORS.replace(
                "effectors:\n",
                "effectors:\n  - energy_sink: {coefficient: 0.1}\n",
            ),
            "effectors[0].energy_sink",
        ),
        (
            "sink-intermediate",
            GOOD.replace("spin_axis: [0, 0, 1]", "spin_axis: [0, 1, 0]")
                .replace("omega: [0.1, 0.0, 1.0]", "omega: [0.1, 1.0, 0.0]")
                + "effectors:\n  - energy_sink: {time_constant: 10.0}\n",
            "effectors[0].energy_sink.time_constant",
        ),
        (
            "motion-start",
            WITH_EFFECTORS.replace(
                "initial:",
                "hub_motion: {spin_up: {axis: [0, 0, 1], rate: 1.0, ramp_time: 5.0}}\ninitial:",
            ),
            "initial.omega",
        ),
    ];
    for (name, yaml, field) in cases {
        let dir = scratch(name);
        let file = write_scenario(&dir, "bad.yaml", &yaml);
        let out = polhode().arg("check").arg(&file).output().unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(&format!("field `{field}`")), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}

#[test]
fn bench_point_prints_one_timed_solve_as_json() {
    let out = polhode()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "bench",
            "point",
            "scenarios/tennis-racket.yaml",
            "--method",
            "dop853",
        ])
        .args(["--rtol", "1e-9", "--duration", "2", "--repeats", "2"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["method"], "dop853");
    assert_eq!(json["duration"], 2.0);
    assert_eq!(json["final_state"].as_array().unwrap().len(), 7);
    assert_eq!(json["cpu_seconds_all"].as_array().unwrap().len(), 2);
    assert!(json["steps"].as_u64().unwrap() > 10);
    assert!(json["cpu_seconds"].as_f64().unwrap() > 0.0);
}

#[test]
fn bench_work_precision_writes_charts_and_csv() {
    let dir = scratch("work-precision");
    let out = polhode()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["bench", "work-precision", "--problems", "tennis-racket"])
        .args([
            "--methods",
            "rk4,dop853,exact",
            "--max-points",
            "2",
            "--quiet",
        ])
        .args(["--out", dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let svg = std::fs::read_to_string(dir.join("work-precision-tennis-racket.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("dop853"),
        "{svg:.200}"
    );
    let png = std::fs::read(dir.join("work-precision-tennis-racket.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let csv = std::fs::read_to_string(dir.join("work-precision.csv")).unwrap();
    // Header, two settings each for rk4 and dop853, one for exact.
    assert_eq!(csv.lines().count(), 6, "{csv}");
    assert!(csv.lines().skip(1).all(|l| l.ends_with("\"ok\"")), "{csv}");
    // Bad selections are refused before any work.
    let bad = polhode()
        .args(["bench", "work-precision", "--methods", "dop8533"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("unknown method `dop8533`"));
}

#[test]
fn auto_says_what_it_picked_and_unknown_methods_get_a_suggestion() {
    let out = polhode()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "scenarios/tennis-racket.yaml",
            "--no-log",
            "--method",
            "auto",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("auto: torque-free rigid body"), "{text}");
    let out = polhode()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "scenarios/tennis-racket.yaml",
            "--no-log",
            "--method",
            "dop85",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("did you mean `dop853`?"),
        "{}",
        stderr(&out)
    );
    // A fixed-step method needs its step.
    let out = polhode()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "scenarios/tennis-racket.yaml",
            "--no-log",
            "--method",
            "gauss",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("integrator.dt"), "{}", stderr(&out));
}

#[test]
fn methods_refuse_scenes_and_settings_they_do_not_apply_to() {
    let root = env!("CARGO_MANIFEST_DIR");
    let run = |args: &[&str]| {
        polhode()
            .current_dir(root)
            .args(["run", "--no-log"])
            .args(args)
            .output()
            .unwrap()
    };
    // A prescribed hub motion has no free flow to compose with, and no closed form.
    for (m, expect) in [
        ("splitting", "composes the free rigid-body flow"),
        ("exact", "torque-free rigid body only"),
    ] {
        let out = run(&["scenarios/spin-up.yaml", "--method", m, "--dt", "0.01"]);
        assert_eq!(out.status.code(), Some(2), "{m}: {}", stderr(&out));
        assert!(stderr(&out).contains(expect), "{m}: {}", stderr(&out));
        assert!(stderr(&out).contains("--method"), "{}", stderr(&out));
    }
    // Another method's setting is refused, naming the option.
    let out = run(&[
        "scenarios/tennis-racket.yaml",
        "--method",
        "gauss",
        "--dt",
        "0.01",
        "--order",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--order") && stderr(&out).contains("`splitting` only"),
        "{}",
        stderr(&out)
    );
    let out = run(&[
        "scenarios/tennis-racket.yaml",
        "--method",
        "gauss",
        "--dt",
        "0.01",
        "--stages",
        "3",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("expected 1 or 2, got 3"),
        "{}",
        stderr(&out)
    );
}
