//! Faults tried on purpose: SIGINT and SIGTERM mid-run and mid-campaign, a full disk (a
//! file-size limit), a shard killed and re-run, tampered shards, and numerical trouble
//! (non-finite state, Newton failure, a collapsed step, step-size underflow, drift beyond a
//! bound, a log too large). Each checks the outcome a user relies on: the exit code, the
//! message, and what is on disk afterwards. With `POLHODE_RELIABILITY_DIR` set, each case's
//! observed outcome is recorded for docs/reliability.md (`scripts/reliability.sh`).

#![cfg(unix)]

mod common;
mod reliability;

use reliability::{Observed, polhode, record, scratch};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const CAMPAIGN: &str = "tests/data/montecarlo-sink.yaml";

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn temporaries(dir: &Path) -> Vec<String> {
    names(dir)
        .into_iter()
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

/// Waits until `ready()` holds (at most 60 s).
fn wait_for(what: &str, mut ready: impl FnMut() -> bool) {
    let started = Instant::now();
    while !ready() {
        assert!(started.elapsed() < Duration::from_secs(60), "{what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The `polhode` metadata record of an MCAP log (after checking the file reads whole).
fn log_metadata(path: &Path) -> std::collections::BTreeMap<String, String> {
    let bytes = std::fs::read(path).unwrap();
    let mut messages = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        m.unwrap();
        messages += 1;
    }
    assert!(messages > 0, "{}: no messages", path.display());
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let index = summary
        .metadata_indexes
        .iter()
        .find(|i| i.name == "polhode")
        .expect("polhode metadata");
    mcap::read::metadata(&bytes, index).unwrap().metadata
}

const LONG_RUN: &str = "name: long
body:
  principal: [1.0, 2.0, 3.0]
  spin_axis: [0, 0, 1]
initial:
  omega: [0.1, 0.0, 1.0]
duration: 1.0e6
integrator: {method: rk4, dt: 1.0e-4}
output: {rate: 10}
";

/// SIGINT or SIGTERM while a run integrates: exit 130, a valid log of what was computed,
/// marked partial, and no temporary left.
fn signal_mid_run(sig: &str) {
    let dir = scratch(&format!("run-{sig}"));
    let file = dir.join("long.yaml");
    std::fs::write(&file, LONG_RUN).unwrap();
    let mcap = dir.join("long.mcap");
    let child = polhode()
        .args([
            "run",
            "long.yaml",
            "--out",
            "long.mcap",
            "--max-log-mb",
            "1e5",
        ])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for("the run did not start", || !temporaries(&dir).is_empty());
    std::thread::sleep(Duration::from_millis(500));
    signal(&child, sig);
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let meta = log_metadata(&mcap);
    assert_eq!(meta["status"], "interrupted", "{meta:?}");
    assert_eq!(meta["partial"], "true", "{meta:?}");
    assert!(temporaries(&dir).is_empty(), "{:?}", names(&dir));
    record(
        "faults",
        &format!("SIG{sig} mid-run"),
        "`polhode run` of a 1e6 s scenario, signalled 0.5 s in",
        &Observed {
            code: out.status.code(),
            message: err.lines().last().unwrap_or("").to_string(),
            left: vec![format!(
                "long.mcap: valid MCAP, status `{}`, ends at t = {} s",
                meta["status"], meta["sim_time_end"]
            )],
        },
    );
}

#[test]
fn sigint_mid_run_keeps_a_valid_partial_log() {
    signal_mid_run("INT");
}

#[test]
fn sigterm_mid_run_keeps_a_valid_partial_log() {
    signal_mid_run("TERM");
}

/// The manifest of a campaign directory.
fn manifest(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("campaign.json")).unwrap()).unwrap()
}

/// SIGINT or SIGTERM while a campaign runs: exit 130, every output written whole, the
/// manifest marked partial with the finished runs, no temporary left.
fn signal_mid_campaign(sig: &str) {
    let dir = scratch(&format!("campaign-{sig}"));
    let out_dir = dir.join("out");
    let child = polhode()
        .args([
            "montecarlo",
            CAMPAIGN,
            "--runs",
            "1000000",
            "--threads",
            "2",
        ])
        .arg("--out")
        .arg(&out_dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, sig);
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let m = manifest(&out_dir);
    assert_eq!(m["partial"], true);
    let finished = m["runs_in_table"].as_u64().unwrap();
    assert!(finished > 0 && finished < 1_000_000, "{finished}");
    let csv = std::fs::read_to_string(out_dir.join("runs.csv")).unwrap();
    assert_eq!(
        csv.lines().count() as u64,
        finished + 1,
        "header + one row per run"
    );
    assert!(temporaries(&out_dir).is_empty(), "{:?}", names(&out_dir));
    // A partial campaign is never merged as if it were whole.
    let merged = polhode()
        .args(["merge", "-q", "--out"])
        .arg(dir.join("merged"))
        .arg(&out_dir)
        .output()
        .unwrap();
    assert_eq!(merged.status.code(), Some(2), "{}", stderr(&merged));
    record(
        "faults",
        &format!("SIG{sig} mid-campaign"),
        "`polhode montecarlo` of 10⁶ runs on 2 threads, signalled 1.5 s in",
        &Observed {
            code: out.status.code(),
            message: err
                .lines()
                .find(|l| l.starts_with("interrupted"))
                .unwrap_or("")
                .to_string(),
            left: vec![format!(
                "every output whole; campaign.json `partial: true` with {finished} finished runs; \
                 `merge` refuses it"
            )],
        },
    );
}

#[test]
fn sigint_mid_campaign_keeps_finished_runs_marked_partial() {
    signal_mid_campaign("INT");
}

#[test]
fn sigterm_mid_campaign_keeps_finished_runs_marked_partial() {
    signal_mid_campaign("TERM");
}

/// `cmd` with a file-size limit of `bytes` (RLIMIT_FSIZE, as `ulimit -f` sets): writes beyond
/// it fail as on a full disk.
fn with_file_size_limit(cmd: &mut Command, bytes: u64) -> &mut Command {
    // SAFETY: setrlimit is async-signal-safe and touches only the child being started.
    unsafe {
        cmd.pre_exec(move || {
            let limit = libc::rlimit {
                rlim_cur: bytes,
                rlim_max: bytes,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        })
    }
}

#[test]
fn a_full_disk_during_a_run_is_a_clear_error_and_leaves_no_file() {
    let dir = scratch("fsize-run");
    // A log of about 0.6 MB against a 100 kB limit.
    let out = with_file_size_limit(
        polhode()
            .args(["run", "scenarios/minor-axis-spin.yaml", "-q", "--out"])
            .arg(dir.join("out.mcap"))
            .arg("--summary")
            .arg(dir.join("summary.json")),
        100_000,
    )
    .output()
    .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("File too large"), "{err}");
    assert!(err.contains("out of space"), "{err}");
    assert!(err.contains("no log was kept"), "{err}");
    assert_eq!(names(&dir), Vec::<String>::new(), "nothing may be left");
    record(
        "faults",
        "full disk during a run",
        "`polhode run` with a 100 kB file-size limit (RLIMIT_FSIZE) and a 0.6 MB log",
        &Observed {
            code: out.status.code(),
            message: err.trim().to_string(),
            left: vec![],
        },
    );
}

#[test]
fn a_full_disk_during_campaign_outputs_is_a_clear_error_and_no_manifest() {
    let dir = scratch("fsize-campaign");
    let out_dir = dir.join("out");
    let out = with_file_size_limit(
        polhode()
            .args(["montecarlo", CAMPAIGN, "--runs", "50", "-q", "--out"])
            .arg(&out_dir),
        20_000,
    )
    .output()
    .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("File too large"), "{err}");
    assert!(err.contains("incomplete"), "{err}");
    let left = names(&out_dir);
    assert!(!left.contains(&"campaign.json".to_string()), "{left:?}");
    assert!(temporaries(&out_dir).is_empty(), "{left:?}");
    // What was written is whole: the table parses to all 50 runs.
    if left.contains(&"runs.csv".to_string()) {
        let csv = std::fs::read_to_string(out_dir.join("runs.csv")).unwrap();
        assert_eq!(csv.lines().count(), 51);
    }
    record(
        "faults",
        "full disk while a campaign writes its outputs",
        "`polhode montecarlo` (50 runs) with a 20 kB file-size limit",
        &Observed {
            code: out.status.code(),
            message: err.trim().to_string(),
            left: vec![format!(
                "whole files only ({}); no campaign.json, so `merge` refuses the directory",
                left.join(", ")
            )],
        },
    );
}

/// Every file of a campaign directory, by name.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    names(dir)
        .into_iter()
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect()
}

#[test]
fn a_killed_shard_rerun_gives_the_identical_result() {
    let dir = scratch("killed-shard");
    let shard = |k: u32, out: &Path| {
        let mut cmd = polhode();
        // 20000 runs: a shard of 10000 lasts some 4 s in lanes on one thread, well past the
        // kill at 0.4 s.
        cmd.args(["montecarlo", CAMPAIGN, "--runs", "20000", "--seed", "9"])
            .args([
                "--threads",
                "1",
                "--shard",
                &format!("{k}/2"),
                "-q",
                "--out",
            ])
            .arg(out)
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        cmd
    };
    // Shard 1 is killed (SIGKILL: no handler runs) while it computes, then run again.
    let killed = dir.join("shard-1");
    let mut child = shard(1, &killed).spawn().unwrap();
    std::thread::sleep(Duration::from_millis(400));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the shard ended before the kill"
    );
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !killed.join("campaign.json").exists(),
        "a killed shard has no manifest, so merge would refuse it"
    );
    let finish = |k: u32, out: &Path| {
        let o = shard(k, out).output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    };
    finish(1, &killed);
    let clean = dir.join("clean-1");
    finish(1, &clean);
    assert_eq!(
        contents(&killed),
        contents(&clean),
        "re-run after a kill = clean run"
    );
    finish(2, &dir.join("shard-2"));
    let merged = dir.join("merged");
    let o = polhode()
        .args(["merge", "-q", "--out"])
        .arg(&merged)
        .arg(&killed)
        .arg(dir.join("shard-2"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let single = dir.join("single");
    let o = polhode()
        .args([
            "montecarlo",
            CAMPAIGN,
            "--runs",
            "20000",
            "--seed",
            "9",
            "-q",
        ])
        .arg("--out")
        .arg(&single)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(contents(&merged), contents(&single));
    record(
        "faults",
        "shard killed (SIGKILL) and re-run",
        "shard 1/2 of 20000 runs killed 0.4 s in, re-run into the same directory",
        &Observed {
            code: Some(0),
            message: "the re-run shard's files equal a clean run's byte for byte; the merged \
                      result equals the single-process campaign's"
                .into(),
            left: vec![],
        },
    );
}

#[test]
fn merge_refuses_truncated_and_altered_shards() {
    let dir = scratch("tampered");
    for k in 1..=2 {
        let o = polhode()
            .args(["montecarlo", CAMPAIGN, "--runs", "40", "--seed", "4"])
            .args(["--shard", &format!("{k}/2"), "-q", "--out"])
            .arg(dir.join(format!("s{k}")))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let csv = dir.join("s2/runs.csv");
    let good = std::fs::read(&csv).unwrap();
    for (case, bytes) in [
        ("truncated", good[..good.len() / 2].to_vec()),
        ("altered", {
            let mut b = good.clone();
            let i = b.len() - 5;
            b[i] = if b[i] == b'1' { b'2' } else { b'1' };
            b
        }),
    ] {
        std::fs::write(&csv, &bytes).unwrap();
        let out_dir = dir.join(format!("merged-{case}"));
        let o = polhode()
            .args(["merge", "-q", "--out"])
            .arg(&out_dir)
            .arg(dir.join("s1"))
            .arg(dir.join("s2"))
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{case}: {err}");
        assert!(err.contains("does not match its manifest"), "{case}: {err}");
        assert!(!out_dir.join("campaign.json").exists(), "{case}");
        record(
            "faults",
            &format!("merge with a {case} shard table"),
            &format!("shard 2's runs.csv {case} after it was written"),
            &Observed {
                code: o.status.code(),
                message: err.trim().to_string(),
                left: vec![],
            },
        );
    }
}

/// Runs `polhode run` on `yaml` (written to a scratch file) with `args`; returns the output and
/// the directory.
fn run_yaml(name: &str, yaml: &str, args: &[&str]) -> (Output, common::Scratch) {
    let dir = scratch(name);
    std::fs::write(dir.join("s.yaml"), yaml).unwrap();
    let out = polhode()
        .args(["run", "s.yaml", "--out", "s.mcap", "-q"])
        .args(args)
        .current_dir(&dir)
        .output()
        .unwrap();
    (out, dir)
}

/// Checks a failed integration: exit 3, a diagnosis with the time, the state and a remedy,
/// and a valid log up to the failure marked partial.
fn assert_failed_with_diagnosis(out: &Output, dir: &Path, expect: &str) -> String {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains(expect), "expected '{expect}' in: {err}");
    assert!(err.contains("state at t = "), "{err}");
    assert!(err.contains("suggested remedy"), "{err}");
    let meta = log_metadata(&dir.join("s.mcap"));
    assert_eq!(meta["status"], "failed");
    assert_eq!(meta["partial"], "true");
    assert!(temporaries(dir).is_empty());
    err.trim().to_string()
}

const RIGID: &str = "name: trouble
body:
  principal: [1.0, 2.0, 3.0]
initial:
  omega: [0.1, 1.0, 0.1]
duration: 100.0
output: {rate: 10}
";

#[test]
fn non_finite_state_stops_with_a_diagnosis() {
    // A prescribed spin-up (its energy is not conserved, so only finiteness is checked) with
    // a step far beyond rk4's stability bound.
    let (out, dir) = run_yaml(
        "nonfinite",
        // The beam's deflection passes its model's limit before the state overflows:
        // `on_validity: warn` lets the run go on to the numerical failure under test.
        &(std::fs::read_to_string("scenarios/spin-up.yaml").unwrap()
            + "checks: {on_validity: warn}\n"),
        &["--method", "rk4", "--dt", "1"],
    );
    let err = assert_failed_with_diagnosis(&out, &dir, "non-finite");
    record(
        "numerical",
        "non-finite state",
        "scenarios/spin-up.yaml (prescribed motion) with rk4, dt = 1 s",
        &Observed {
            code: out.status.code(),
            message: err,
            left: vec![
                "s.mcap: valid up to the last finite state, status `failed`, partial".into(),
            ],
        },
    );
}

#[test]
fn a_diverging_integration_stops_before_it_overflows() {
    let yaml = format!("{RIGID}integrator: {{method: rk4, dt: 20.0}}\n");
    let (out, dir) = run_yaml("diverging", &yaml, &[]);
    let err = assert_failed_with_diagnosis(&out, &dir, "the integration is diverging");
    assert!(err.contains("stability bound"), "{err}");
    record(
        "numerical",
        "diverging integration",
        "rk4 with dt = 20 s on a body spinning at 1 rad/s",
        &Observed {
            code: out.status.code(),
            message: err,
            left: vec!["s.mcap: valid, status `failed`, partial".into()],
        },
    );
}

#[test]
fn newton_failure_stops_with_a_diagnosis() {
    let (out, dir) = run_yaml(
        "newton",
        &std::fs::read_to_string("scenarios/flexible-boom.yaml").unwrap(),
        &["--method", "gauss", "--dt", "100", "--max-log-mb", "1e4"],
    );
    let err = assert_failed_with_diagnosis(&out, &dir, "Newton iteration");
    record(
        "numerical",
        "Newton failure",
        "scenarios/flexible-boom.yaml with gauss, dt = 100 s",
        &Observed {
            code: out.status.code(),
            message: err,
            left: vec!["s.mcap: valid, status `failed`, partial".into()],
        },
    );
}

#[test]
fn a_collapsed_step_size_stops_with_a_diagnosis() {
    // A hinged rod started at 90° flap: its lag angle is undefined there (the two-angle
    // coordinates are singular), and an adaptive method's steps shrink to ~1e-11 s.
    let yaml = "name: flap90
body:
  mass: 10.0
  principal: [1.0, 2.0, 3.0]
  spin_axis: [0, 0, 1]
  shape: {box: {size: [1.0, 1.0, 1.0]}}
effectors:
  - hinged_rod:
      mass: 1.0
      length: 0.5
      hinge: [0.5, 0.0, 0.0]
      direction: [1, 0, 0]
      axis: [0, 0, 1]
      stiffness: 0.0
      damping: 0.0
      initial_angles: [1.5707963267948966, 0.0]
      initial_rates: [0.0, 1.0]
initial:
  omega: [0.1, 0.0, 1.0]
duration: 20.0
output: {rate: 10}
checks: {on_validity: warn}
";
    // `on_validity: warn`: the rod starts past its model's limit (the validity check would
    // stop it at t = 0); under test is the run loop's guard against a collapsing step.
    let (out, dir) = run_yaml("collapse", yaml, &[]);
    let err = assert_failed_with_diagnosis(&out, &dir, "the step size collapsed");
    record(
        "numerical",
        "step size collapsing",
        "a hinged rod started at its 90° flap singularity, dopri5",
        &Observed {
            code: out.status.code(),
            message: err,
            left: vec!["s.mcap: valid, status `failed`, partial".into()],
        },
    );
}

#[test]
fn a_finite_time_singularity_is_a_step_size_underflow() {
    use polhode::integrate::{Dop853, OdeSystem, Stepper, Tolerances};
    /// y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
    struct BlowUp;
    impl OdeSystem for BlowUp {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
            dydt[0] = y[0] * y[0];
        }
    }
    let tol = Tolerances {
        rtol: 1e-8,
        atol: 1e-8,
    };
    let mut s = Dop853::new(0.0, &[1.0], tol, f64::INFINITY, None);
    let err = loop {
        if let Err(e) = s.step(&BlowUp, 2.0) {
            break e;
        }
    };
    let message = err.to_string();
    let t: f64 = message
        .strip_prefix("step size underflow at t = ")
        .and_then(|r| r.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{message}"));
    assert!((t - 1.0).abs() < 1e-6, "{message}");
    record(
        "numerical",
        "step-size underflow",
        "dop853 on y' = y² (blows up at t = 1), the library's stepper",
        &Observed {
            code: None,
            message,
            left: vec![
                "(library level: the run loop turns it into exit 3 with the state, as above)"
                    .into(),
            ],
        },
    );
}

#[test]
fn drift_beyond_a_bound_stops_or_warns() {
    let bounds =
        "checks:\n  max_drift: {momentum: 1.0e-6, energy: 1.0e-6, quaternion_norm: 1.0e-6}\n";
    let coarse = format!("{RIGID}integrator: {{method: rk4, dt: 0.2}}\n{bounds}");
    let (out, dir) = run_yaml("drift-stop", &coarse, &[]);
    let err = assert_failed_with_diagnosis(&out, &dir, "beyond the bound 1e-6");
    record(
        "numerical",
        "drift beyond a bound (on_drift: stop)",
        "rk4, dt = 0.2 s, checks.max_drift 1e-6 on |H|, energy and |q|",
        &Observed {
            code: out.status.code(),
            message: err,
            left: vec!["s.mcap: valid, status `failed`, partial".into()],
        },
    );
    let warn = format!("{coarse}  on_drift: warn\n");
    let (out, dir) = run_yaml("drift-warn", &warn, &[]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 3, "one per invariant: {err}");
    let meta = log_metadata(&dir.join("s.mcap"));
    assert_eq!(meta["status"], "complete");
    // The same run with a fine step stays within the bounds: the check is not always on.
    let fine = format!("{RIGID}integrator: {{method: rk4, dt: 0.01}}\n{bounds}");
    let (out, _) = run_yaml("drift-fine", &fine, &[]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"));
    record(
        "numerical",
        "drift beyond a bound (on_drift: warn)",
        "as above with `on_drift: warn`",
        &Observed {
            code: Some(0),
            message: warnings[0].to_string(),
            left: vec!["s.mcap complete, with the warnings on /log".into()],
        },
    );
}

#[test]
fn a_log_over_the_size_limit_is_refused_before_the_run() {
    let (out, dir) = run_yaml(
        "log-limit",
        &std::fs::read_to_string("scenarios/explorer1.yaml").unwrap(),
        &["--max-log-mb", "10"],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("above the limit of 10 MB"), "{err}");
    assert_eq!(names(&dir), vec!["s.yaml".to_string()]);
    record(
        "faults",
        "log larger than the limit",
        "scenarios/explorer1.yaml (a 44 MB log) with --max-log-mb 10",
        &Observed {
            code: out.status.code(),
            message: err.trim().to_string(),
            left: vec![],
        },
    );
}

#[test]
fn devices_are_neither_overwritten_nor_read_forever() {
    // An output path that is a device would be replaced by the rename that finishes a file.
    let out = polhode()
        .args([
            "run",
            "scenarios/minor-axis-spin.yaml",
            "-q",
            "--out",
            "/dev/null",
        ])
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );
    record(
        "faults",
        "output path is a device",
        "`polhode run ... --out /dev/null`",
        &Observed {
            code: out.status.code(),
            message: err.trim().to_string(),
            left: vec!["/dev/null untouched".into()],
        },
    );
    // A scenario that never ends (a device reports no size) is read only up to the limit.
    let out = polhode().args(["check", "/dev/zero"]).output().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("longer than 1048576 bytes"), "{err}");
    record(
        "faults",
        "endless scenario input",
        "`polhode check /dev/zero`",
        &Observed {
            code: out.status.code(),
            message: err.trim().to_string(),
            left: vec![],
        },
    );
}

#[test]
fn campaign_text_that_reads_as_a_number_is_refused() {
    // Found by fuzzing: runs are built from the YAML tree as JSON values, where `name: 1e2`
    // becomes 100.0 and `.nan` has no value at all.
    for name in ["1e2", "0x1F", ".nan"] {
        let yaml = format!(
            "name: {name}\nbody: {{principal: [1.0, 2.0, 3.0]}}\ninitial: {{omega: [0.1, 0, 0]}}\n\
             duration: 1.0\nmontecarlo:\n  runs: 2\n"
        );
        let dir = scratch(&format!("numeric-name-{}", name.replace('.', "")));
        std::fs::write(dir.join("s.yaml"), &yaml).unwrap();
        let out = polhode()
            .args(["montecarlo", "s.yaml", "-q", "--out", "c"])
            .current_dir(&dir)
            .output()
            .unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains("quote it"), "{name}: {err}");
        assert_eq!(names(&dir), vec!["s.yaml".to_string()], "{name}");
        // Quoted, it runs.
        std::fs::write(
            dir.join("s.yaml"),
            yaml.replace(&format!("name: {name}"), &format!("name: \"{name}\"")),
        )
        .unwrap();
        let out = polhode()
            .args(["montecarlo", "s.yaml", "-q", "--out", "c"])
            .current_dir(&dir)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name} quoted: {}",
            stderr(&out)
        );
    }
}
