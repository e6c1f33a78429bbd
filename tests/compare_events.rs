//! `polhode compare`'s event columns: the scenarios' own `events:` (their union), the
//! `--event` override, the 45°/80° fallback, and times identical to `polhode run`'s.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn polhode() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-cmp", name)
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A rigid body spun near its intermediate axis: it flips over and over (the tennis racket).
const FLIPPER: &str = "name: flipper
body:
  principal: [1.0, 2.0, 3.0]
  spin_axis: [0, 1, 0]
initial:
  omega: [0.01, 2.0, 0.01]
duration: 12.0
integrator: {method: dopri5, rtol: 1.0e-10, atol: 1.0e-12}
output: {rate: 20}
events:
  - nutation_angle_deg: {above: 45.0, once: true}
  - {nutation_angle_deg: {above: 90.0}}
";

/// A minor-axis spinner with an energy sink: it goes flat within a minute or two.
const SINK: &str = "name: sink
body:
  principal: [2.0, 2.1, 1.0]
  spin_axis: [0, 0, 1]
effectors:
  - energy_sink: {time_constant: 10.0}
initial:
  omega: [0.05, 0.05, 2.0]
duration: 120.0
integrator: {method: dop853, rtol: 1.0e-9, atol: 1.0e-12}
output: {rate: 10}
events:
  - nutation_angle_deg: {above: 45.0, once: true}
  - nutation_angle_deg: {above: 80.0, for: 2.0}
  - {omega_z: {below: 1.5}}
";

/// `polhode compare ARGS --json FILE` and its text output; the run must succeed.
fn compare(dir: &Path, args: &[&str]) -> (serde_json::Value, String) {
    let table = dir.join("table.json");
    let out = polhode()
        .arg("compare")
        .args(args)
        .arg("--json")
        .arg(&table)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
    (
        json(&table),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// The `events` of `polhode run SCENARIO --no-log --summary`, as (condition, t).
fn run_events(dir: &Path, scenario: &Path) -> Vec<(String, f64)> {
    let summary = dir.join("summary.json");
    let out = polhode()
        .arg("run")
        .arg(scenario)
        .args(["--no-log", "--quiet", "--summary"])
        .arg(&summary)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    json(&summary)["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["condition"].as_str().unwrap().to_string(),
                e["t"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// Every watched cell of `row` holds the first time `polhode run` records for its condition,
/// bit for bit, and an unwatched one is empty.
fn assert_times_match(row: &serde_json::Value, run: &[(String, f64)]) {
    for cell in row["events"].as_array().unwrap() {
        let condition = cell["condition"].as_str().unwrap();
        let first = run.iter().find(|(c, _)| c == condition).map(|(_, t)| *t);
        if cell["watched"] == true {
            assert_eq!(cell["t"].as_f64(), first, "{condition}");
        } else {
            assert!(cell["t"].is_null(), "{condition}");
        }
    }
}

fn conditions(row: &serde_json::Value) -> Vec<String> {
    row["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["condition"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn columns_are_the_union_of_the_scenarios_events_with_run_s_times() {
    let dir = scratch("union");
    let a = write(&dir, "flipper.yaml", FLIPPER);
    let b = write(&dir, "sink.yaml", SINK);
    let csv = dir.join("series.csv");
    let chart = dir.join("chart.svg");
    let (rows, text) = compare(
        &dir,
        &[
            a.to_str().unwrap(),
            b.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
            "--chart",
            chart.to_str().unwrap(),
        ],
    );
    let expected = [
        "nutation_angle_deg above 45 once",
        "nutation_angle_deg above 90",
        "nutation_angle_deg above 80 for 2 s",
        "omega_z below 1.5",
    ];
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        assert_eq!(conditions(r), expected);
        assert_eq!(r["event_source"], "scenarios");
    }
    let watched = |r: &serde_json::Value| -> Vec<bool> {
        r["events"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["watched"].as_bool().unwrap())
            .collect()
    };
    assert_eq!(watched(&rows[0]), [true, true, false, false]);
    assert_eq!(watched(&rows[1]), [true, false, true, true]);
    // Every watched event happens in these runs.
    for r in rows {
        for c in r["events"].as_array().unwrap() {
            assert_eq!(c["t"].is_number(), c["watched"] == true, "{c}");
        }
    }
    assert_times_match(&rows[0], &run_events(&dir, &a));
    assert_times_match(&rows[1], &run_events(&dir, &b));

    // Short titles in the table; a scenario lacking a column shows `—`.
    let header = text.lines().next().unwrap();
    for title in ["θ > 45°", "θ > 90°", "θ > 80° for 2 s", "ω_z < 1.5"] {
        assert!(header.contains(title), "{header}");
        assert_eq!(
            rows[0]["events"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|c| c["title"] == title)
                .count(),
            1
        );
    }
    assert!(
        !text.contains("showing the nutation angle passing"),
        "{text}"
    );
    let flipper_line = text.lines().find(|l| l.starts_with("flipper")).unwrap();
    assert_eq!(flipper_line.matches('—').count(), 2, "{flipper_line}");

    // The CSV marks each column's first time with its full text; the chart has a marker
    // series per column.
    let csv = std::fs::read_to_string(&csv).unwrap();
    assert!(csv.starts_with("scenario,t_s,nutation_deg,event\n"));
    for (name, r) in [("flipper", &rows[0]), ("sink", &rows[1])] {
        for c in r["events"].as_array().unwrap() {
            let Some(t) = c["t"].as_f64() else { continue };
            let condition = c["condition"].as_str().unwrap();
            let line = csv
                .lines()
                .find(|l| {
                    l.starts_with(&format!("{name},")) && l.ends_with(&format!(",{condition}"))
                })
                .unwrap_or_else(|| panic!("{name}: no CSV line for {condition}"));
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells[1].parse::<f64>().unwrap(), t, "{line}");
        }
    }
    let svg = std::fs::read_to_string(&chart).unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(
        svg.contains("ω_z &lt; 1.5") || svg.contains("ω_z < 1.5"),
        "legend"
    );
}

#[test]
fn event_options_replace_the_scenarios_events() {
    let dir = scratch("option");
    let a = write(&dir, "flipper.yaml", FLIPPER);
    let b = write(&dir, "sink.yaml", SINK);
    let (rows, text) = compare(
        &dir,
        &[
            a.to_str().unwrap(),
            b.to_str().unwrap(),
            "--event",
            "{nutation_angle_deg: {above: 45.0, once: true}}",
            "--event",
            "{omega_z: {below: 1.9}}",
            // A repeat is one column.
            "--event",
            "{nutation_angle_deg: {above: 45.0, once: true}}",
        ],
    );
    let header = text.lines().next().unwrap();
    assert!(
        header.contains("θ > 45°") && header.contains("ω_z < 1.9"),
        "{header}"
    );
    assert!(!header.contains("θ > 90°"), "{header}");
    for r in rows.as_array().unwrap() {
        assert_eq!(
            conditions(r),
            ["nutation_angle_deg above 45 once", "omega_z below 1.9"]
        );
        assert_eq!(r["event_source"], "option");
        assert!(
            r["events"]
                .as_array()
                .unwrap()
                .iter()
                .all(|c| c["watched"] == true)
        );
    }
    // Both scenarios watch the first one themselves: the same time as their own runs.
    let rows = rows.as_array().unwrap();
    for (r, s) in rows.iter().zip([&a, &b]) {
        let run = run_events(&dir, s);
        let own = run
            .iter()
            .find(|(c, _)| c == "nutation_angle_deg above 45 once");
        assert_eq!(r["events"][0]["t"].as_f64(), own.map(|x| x.1));
    }

    // A bad condition is refused with the scenario file's message, before anything runs.
    for (bad, expect) in [
        (
            "{nutation_angle_deg: {abve: 45.0}}",
            "did you mean `above`?",
        ),
        (
            "{nutation_angle_deg: {above: 45.0, for: -1}}",
            "field `nutation_angle_deg.for`: expected a duration ≥ 0 s",
        ),
        (
            "{nutation_angle_deg: {above: 1.0, below: 2.0}}",
            "expected exactly one of `above: <value>` or `below: <value>`",
        ),
        ("", "expected one condition such as"),
    ] {
        let out = polhode()
            .arg("compare")
            .arg(&a)
            .args(["--event", bad])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(stderr(&out).contains(expect), "{bad}: {}", stderr(&out));
        assert!(out.stdout.is_empty(), "{bad}: nothing runs");
    }
}

#[test]
fn without_events_the_columns_fall_back_to_45_and_80_degrees() {
    let dir = scratch("fallback");
    let bare = SINK[..SINK.find("events:").unwrap()].to_string();
    let a = write(&dir, "bare.yaml", &bare);
    let (rows, text) = compare(&dir, &[a.to_str().unwrap()]);
    let mut lines = text.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .contains("showing the nutation angle passing 45° and 80°"),
        "{text}"
    );
    let header = lines.next().unwrap();
    assert!(
        header.contains("θ > 45°") && header.contains("θ > 80°"),
        "{header}"
    );
    let row = &rows[0];
    assert_eq!(row["event_source"], "default");
    assert_eq!(
        conditions(row),
        ["nutation_angle_deg above 45", "nutation_angle_deg above 80"]
    );
    // The same times as a run that declares them.
    let declared = write(
        &dir,
        "declared.yaml",
        &format!(
            "{bare}events:\n  - {{nutation_angle_deg: {{above: 45.0}}}}\n  - {{nutation_angle_deg: {{above: 80.0}}}}\n"
        ),
    );
    let run = run_events(&dir, &declared);
    assert_eq!(run.len(), 2, "{run:?}");
    assert_times_match(row, &run);
    assert!(
        row["events"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["t"].is_number())
    );
}
