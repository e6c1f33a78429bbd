//! `polhode run --csv FILE --parquet FILE`: the sampled telemetry as tables, checked against
//! the run's MCAP log by an independent Python reader (tests/python/read_samples.py: the
//! `mcap` package, the schemas embedded in the log, Python's csv module and pyarrow).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-table", name)
}

fn polhode(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args(args)
        .output()
        .unwrap()
}

fn read_samples(log: &Path, csv: &Path, parquet: &Path) -> (bool, String) {
    let o = Command::new(common::venv_python())
        .arg(root().join("tests/python/read_samples.py"))
        .args([log, csv, parquet])
        .output()
        .unwrap();
    (
        o.status.success(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ),
    )
}

/// Scenes with effectors (a held wheel and a damper; coils in orbit) and without, in orbit
/// and not: the CSV and the Parquet file hold the log's samples bit for bit, with its units
/// (in orbit the attitude relative to LVLH equals the log's /orbit fields, by name); a scene
/// without an orbit has no LVLH column. A table edited by one digit fails the check.
#[test]
fn tables_equal_the_log_in_an_independent_reader() {
    let dir = scratch("equal");
    for (scene, columns) in [
        ("dual-spin", 38),
        // In orbit: 38 columns, then the attitude relative to LVLH (the /orbit fields).
        ("cubesat-detumble", 48),
        // In orbit: the 26 /telemetry fields, the gravity gradient's five, the ten LVLH ones.
        ("gravity-gradient-smallsat", 41),
        ("tennis-racket", 26),
    ] {
        let (log, csv, parquet) = (
            dir.join(format!("{scene}.mcap")),
            dir.join(format!("{scene}.csv")),
            dir.join(format!("{scene}.parquet")),
        );
        let scenario = root().join(format!("scenarios/{scene}.yaml"));
        let o = polhode(&[
            "run",
            scenario.to_str().unwrap(),
            "--duration",
            "30",
            "--quiet",
            "--out",
            log.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
            "--parquet",
            parquet.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let (ok, text) = read_samples(&log, &csv, &parquet);
        assert!(ok, "{scene}: {text}");
        assert!(
            text.contains(&format!("columns {columns} identical")),
            "{scene}: {text}"
        );
    }
    // One changed digit in the last row's ω_x is found.
    let csv = dir.join("tennis-racket.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let last = lines.pop().unwrap();
    let mut fields: Vec<String> = last.split(',').map(String::from).collect();
    let digit = fields[1].rfind(|c: char| c.is_ascii_digit()).unwrap();
    let changed = if &fields[1][digit..=digit] == "1" {
        "2"
    } else {
        "1"
    };
    fields[1].replace_range(digit..=digit, changed);
    lines.push(fields.join(","));
    std::fs::write(&csv, lines.join("\n") + "\n").unwrap();
    let (ok, text) = read_samples(
        &dir.join("tennis-racket.mcap"),
        &csv,
        &dir.join("tennis-racket.parquet"),
    );
    assert!(!ok && text.contains("CSV row"), "{text}");
}

/// Bad targets are refused before the run, with nothing written; a run without `--csv` or
/// `--parquet` writes no table.
#[test]
fn bad_table_targets_are_refused_before_the_run() {
    let dir = scratch("bad");
    let scenario = root().join("scenarios/tennis-racket.yaml");
    let s = scenario.to_str().unwrap();
    let same = dir.join("same.csv");
    let o = polhode(&[
        "run",
        s,
        "--no-log",
        "--csv",
        same.to_str().unwrap(),
        "--parquet",
        same.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--csv and --parquet both name"), "{err}");
    let missing = dir.join("no/such/dir/t.parquet");
    let o = polhode(&["run", s, "--no-log", "--parquet", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("cannot write the sampled telemetry"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none());
}

/// `polhode plot LOG.mcap`: the log read back for the charts equals the CSV table of the same
/// run (checked above against the log by the independent reader) column for column, bit for
/// bit; the charts of ω, the nutation angle, the energies and each effector are written as
/// SVG and PNG; a file that is not a log is refused with nothing written.
#[test]
fn plot_reads_the_log_and_writes_its_charts() {
    let dir = scratch("plot");
    let (log, csv) = (dir.join("run.mcap"), dir.join("run.csv"));
    let scenario = root().join("scenarios/dual-spin.yaml");
    let o = polhode(&[
        "run",
        scenario.to_str().unwrap(),
        "--duration",
        "20",
        "--quiet",
        "--out",
        log.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let run = polhode::log::charts::read(&log).unwrap();
    assert_eq!(run.name, "dual-spin");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let mut checked = 0;
    for (j, name) in header.iter().enumerate() {
        let name = name.split(" [").next().unwrap();
        let column = match name.split_once('.') {
            None => run.telemetry.column(name),
            Some((effector, field)) => run
                .effectors
                .iter()
                .find(|(n, _)| n == effector)
                .and_then(|(_, c)| c.column(field)),
        }
        .unwrap_or_else(|| panic!("{name} missing from the log read back"));
        let from_csv: Vec<f64> = rows.iter().map(|r| r[j]).collect();
        assert_eq!(column, from_csv.as_slice(), "{name}");
        checked += 1;
    }
    assert_eq!(checked, 38);

    let charts = dir.join("charts");
    let o = polhode(&[
        "plot",
        log.to_str().unwrap(),
        "--out",
        charts.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for stem in [
        "omega",
        "nutation",
        "energy",
        "effector_rotor",
        "effector_damper",
    ] {
        let png = std::fs::read(charts.join(format!("{stem}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "{stem}");
        let svg = std::fs::read_to_string(charts.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.contains("dual-spin:"), "{stem}");
    }

    let not_a_log = dir.join("charts-of-csv");
    let o = polhode(&[
        "plot",
        csv.to_str().unwrap(),
        "--out",
        not_a_log.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("is not a readable MCAP log"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!not_a_log.exists());
}
