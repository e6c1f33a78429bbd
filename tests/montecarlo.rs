//! Monte Carlo campaigns from the command line: the same result whatever the threads and the
//! sharding, merge refusing bad shard sets, Ctrl-C keeping a valid partial result, bad
//! campaign definitions, and the Parquet table read by an independent reader.

mod common;

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const SCENARIO: &str = "tests/data/montecarlo-sink.yaml";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn polhode() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_polhode"));
    c.current_dir(root());
    c
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-mc", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn campaign(args: &[&str], out: &Path) -> Output {
    let o = polhode()
        .arg("montecarlo")
        .args(args)
        .args(["--quiet", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    o
}

fn merge(dirs: &[&Path], out: &Path) -> Output {
    polhode()
        .arg("merge")
        .args(dirs)
        .args(["--quiet", "--out", out.to_str().unwrap()])
        .output()
        .unwrap()
}

/// Every file of a result directory by name (temporary files would show up here too).
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

fn assert_same(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "{} vs {}",
        a.display(),
        b.display()
    );
    for (name, bytes) in &fa {
        assert!(
            bytes == &fb[name],
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn threads_order_and_shards_give_the_same_result_bit_for_bit() {
    let dir = scratch("repro");
    let one = dir.join("one");
    let two = dir.join("two");
    campaign(&[SCENARIO, "--runs", "60", "--threads", "1"], &one);
    campaign(&[SCENARIO, "--runs", "60", "--threads", "2"], &two);
    assert_same(&one, &two);
    let expected = [
        ".polhode-outputs",
        "campaign.json",
        "campaign.mcap",
        "flat_spin_time_cdf.png",
        "flat_spin_time_cdf.svg",
        "flat_spin_time_histogram.png",
        "flat_spin_time_histogram.svg",
        "runs.csv",
        "runs.parquet",
        "scenario.yaml",
        "summary.json",
        "summary.txt",
        "t_nutation_angle_deg_above_45_cdf.png",
        "t_nutation_angle_deg_above_45_cdf.svg",
        "t_nutation_angle_deg_above_45_histogram.png",
        "t_nutation_angle_deg_above_45_histogram.svg",
        "t_nutation_angle_deg_above_45_vs_transverse_rate.png",
        "t_nutation_angle_deg_above_45_vs_transverse_rate.svg",
        "t_nutation_angle_deg_above_80_cdf.png",
        "t_nutation_angle_deg_above_80_cdf.svg",
        "t_nutation_angle_deg_above_80_histogram.png",
        "t_nutation_angle_deg_above_80_histogram.svg",
        "t_nutation_angle_deg_above_80_vs_transverse_rate.png",
        "t_nutation_angle_deg_above_80_vs_transverse_rate.svg",
        "transverse_rate_vs_flat_spin_time.png",
        "transverse_rate_vs_flat_spin_time.svg",
    ];
    assert_eq!(files(&one).keys().cloned().collect::<Vec<_>>(), expected);

    // Four shards with uneven sizes, run in reverse order on two threads, merged in a
    // shuffled order.
    let shards: Vec<PathBuf> = (1..=4).map(|k| dir.join(format!("shard-{k}"))).collect();
    for k in (1..=4).rev() {
        let spec = format!("{k}/4");
        campaign(
            &[SCENARIO, "--runs", "60", "--shard", &spec, "--threads", "2"],
            &shards[k - 1],
        );
    }
    let shard_files = files(&shards[0]);
    assert!(
        !shard_files.contains_key("campaign.mcap"),
        "shards skip the MCAP"
    );
    let m = json(&shards[1].join("campaign.json"));
    assert_eq!(m["shard"], serde_json::json!([2, 4]));
    assert_eq!(m["run_range"], serde_json::json!([15, 30]));
    let merged = dir.join("merged");
    let o = merge(&[&shards[2], &shards[0], &shards[3], &shards[1]], &merged);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same(&one, &merged);

    let summary = json(&one.join("summary.json"));
    assert_eq!(summary["partial"], false);
    assert_eq!(summary["runs_in_table"], 60);
    assert_eq!(summary["status"]["complete"], 60);
    // Every run of this scene goes flat within 200 s.
    let by = &summary["events"][1]["by"];
    assert_eq!(by[2]["t"], 200.0);
    assert_eq!(by[2]["probability"], 1.0);

    // A shard written into a directory that held a whole campaign leaves none of its files.
    campaign(&[SCENARIO, "--runs", "60", "--shard", "1/4"], &one);
    assert_same(&one, &shards[0]);
}

#[test]
fn merge_refuses_bad_shard_sets() {
    let dir = scratch("refuse");
    let shard = |k: u32, n: u32, seed: &str, name: &str| {
        let out = dir.join(name);
        let spec = format!("{k}/{n}");
        campaign(
            &[SCENARIO, "--runs", "12", "--seed", seed, "--shard", &spec],
            &out,
        );
        out
    };
    let s1 = shard(1, 3, "5", "s1");
    let s2 = shard(2, 3, "5", "s2");
    let s3 = shard(3, 3, "5", "s3");
    let other_seed = shard(3, 3, "6", "s3-seed6");
    let other_count = shard(2, 2, "5", "s2of2");
    let out = dir.join("out");
    let refused = |dirs: &[&Path], expect: &str| {
        let o = merge(dirs, &out);
        assert_eq!(o.status.code(), Some(2), "{dirs:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(expect), "{dirs:?}: {}", stderr(&o));
        assert!(
            !out.join("campaign.json").exists(),
            "nothing may be written"
        );
    };
    refused(&[&s1, &s2], "shard(s) 3 of 3 are missing");
    refused(&[&s1, &s2, &s2, &s3], "shard 2 of 3 is given twice");
    refused(&[&s1, &s2, &other_seed], "seed 6 differs from 5");
    refused(&[&s1, &s2, &other_count], "shard count 2 differs from 3");

    // A different scenario.
    let edited = dir.join("edited.yaml");
    let text = std::fs::read_to_string(root().join(SCENARIO)).unwrap();
    std::fs::write(
        &edited,
        text.replace("time_constant: 10.0", "time_constant: 11.0"),
    )
    .unwrap();
    let s3_other = dir.join("s3-other");
    campaign(
        &[
            edited.to_str().unwrap(),
            "--runs",
            "12",
            "--seed",
            "5",
            "--shard",
            "3/3",
        ],
        &s3_other,
    );
    refused(&[&s1, &s2, &s3_other], "scenario (SHA-256)");

    // A table truncated or altered after it was written.
    let cut = dir.join("s3-cut");
    std::fs::create_dir_all(&cut).unwrap();
    for (name, bytes) in files(&s3) {
        std::fs::write(cut.join(&name), bytes).unwrap();
    }
    let csv = std::fs::read(cut.join("runs.csv")).unwrap();
    std::fs::write(cut.join("runs.csv"), &csv[..csv.len() - 10]).unwrap();
    refused(&[&s1, &s2, &cut], "truncated or altered");
    let mut altered = csv.clone();
    let i = altered.iter().rposition(|b| b.is_ascii_digit()).unwrap();
    altered[i] = if altered[i] == b'1' { b'2' } else { b'1' };
    std::fs::write(cut.join("runs.csv"), &altered).unwrap();
    refused(&[&s1, &s2, &cut], "truncated or altered");

    // Shards of another build, and manifests naming a shard or range that cannot exist.
    let other_build = dir.join("s3-build");
    std::fs::create_dir_all(&other_build).unwrap();
    for (name, bytes) in files(&s3) {
        std::fs::write(other_build.join(&name), bytes).unwrap();
    }
    let manifest = std::fs::read_to_string(other_build.join("campaign.json")).unwrap();
    let mut m: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    m["build_id"] = "0000000000000000".into();
    std::fs::write(other_build.join("campaign.json"), m.to_string()).unwrap();
    refused(&[&s1, &s2, &other_build], "polhode build");
    refused(&[&other_build, &s1, &s2], "polhode build");
    m = serde_json::from_str(&manifest).unwrap();
    m["shard"] = serde_json::json!([1, 0]);
    std::fs::write(other_build.join("campaign.json"), m.to_string()).unwrap();
    refused(&[&s1, &s2, &other_build], "which does not exist");
    m = serde_json::from_str(&manifest).unwrap();
    m["run_range"] = serde_json::json!([9, 3]);
    std::fs::write(other_build.join("campaign.json"), m.to_string()).unwrap();
    refused(&[&s1, &s2, &other_build], "impossible run range");
    // Columns of the same count that differ: the first one that differs, by name.
    m = serde_json::from_str(&manifest).unwrap();
    let second = m["columns"][1].as_str().unwrap().to_string();
    m["columns"][1] = "renamed".into();
    std::fs::write(other_build.join("campaign.json"), m.to_string()).unwrap();
    refused(
        &[&s1, &s2, &other_build],
        &format!("table column 2 `renamed` differs from `{second}`"),
    );

    // Not a campaign output at all.
    refused(
        &[&s1, &s2, &dir.join("nothing-here")],
        "no finished campaign output",
    );

    // The right set merges.
    let o = merge(&[&s1, &s2, &s3], &out);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn ctrl_c_keeps_every_finished_run_in_a_valid_partial_result() {
    let dir = scratch("sigint");
    let out = dir.join("partial");
    let mut child = polhode()
        .args([
            "montecarlo",
            SCENARIO,
            "--runs",
            "1000000",
            "--threads",
            "2",
            "--shard",
            "1/2",
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The first line on stderr announces the start; let some runs finish, then interrupt.
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    assert!(line.contains("runs"), "{line}");
    std::thread::sleep(std::time::Duration::from_millis(3000));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{rest}");
    assert!(rest.contains("marked partial"), "{rest}");

    let manifest = json(&out.join("campaign.json"));
    assert_eq!(manifest["partial"], true);
    let n = manifest["runs_in_table"].as_u64().unwrap();
    assert!(n > 0 && n < 500_000, "{n} runs finished");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["partial"], true);
    assert_eq!(summary["runs_in_table"], n);
    assert!(
        std::fs::read_to_string(out.join("summary.txt"))
            .unwrap()
            .contains("PARTIAL")
    );
    // The table is whole: every row it lists is the row a full campaign computes for that run.
    let csv = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len() as u64, n + 1);
    let full = dir.join("full");
    campaign(&[SCENARIO, "--runs", "1000000", "--shard", "1/5000"], &full);
    let full_csv = std::fs::read_to_string(full.join("runs.csv")).unwrap();
    let reference: BTreeMap<&str, &str> = full_csv
        .lines()
        .skip(1)
        .map(|l| (l.split(',').next().unwrap(), l))
        .collect();
    let mut checked = 0;
    for l in &lines[1..] {
        if let Some(r) = reference.get(l.split(',').next().unwrap()) {
            assert_eq!(l, r);
            checked += 1;
        }
    }
    assert!(
        checked > 0,
        "no run of the partial table was among the first 200"
    );
    // No temporary files are left, and a partial shard cannot be merged.
    assert!(files(&out).keys().all(|f| !f.contains(".tmp")));
    let o = merge(&[&out, &full], &dir.join("merged"));
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("partial"), "{}", stderr(&o));
}

#[test]
fn bad_campaign_definitions_are_located_errors() {
    let dir = scratch("bad");
    let base = std::fs::read_to_string(root().join(SCENARIO)).unwrap();
    let case = |name: &str, from: &str, to: &str, expect: &[&str]| {
        let file = dir.join(format!("{name}.yaml"));
        assert!(base.contains(from), "{from}");
        std::fs::write(&file, base.replace(from, to)).unwrap();
        let out = dir.join(name);
        let o = polhode()
            .args([
                "montecarlo",
                file.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        for e in expect {
            assert!(
                stderr(&o).contains(e),
                "{name}: expected `{e}` in {}",
                stderr(&o)
            );
        }
        assert!(
            !out.join("campaign.json").exists(),
            "{name}: nothing may be written"
        );
        assert!(!stderr(&o).contains("panicked"));
    };
    case(
        "unknown-field",
        "path: \"effectors[sink].time_constant\"",
        "path: \"effectors[sink].time_konstant\"",
        &[
            "montecarlo.dispersions[2].path",
            ":25:14:",
            "did you mean `time_constant`",
        ],
    );
    case(
        "unknown-entry",
        "effectors[sink]",
        "effectors[damper]",
        &["no entry named `damper`", "names: sink"],
    );
    case(
        "two-distributions",
        "log_normal: {sigma: 0.3}",
        "log_normal: {sigma: 0.3}, normal: {sd: 1.0}",
        &["exactly one of", "normal, log_normal"],
    );
    case(
        "wrong-length",
        "path: initial.omega, tilt: {sd_deg: 1.0}",
        "path: initial.omega, normal: {sd: [1.0, 2.0]}",
        &["one number or 3"],
    );
    case(
        "zero-runs",
        "runs: 40",
        "runs: 0",
        &["montecarlo.runs", "from 1 to"],
    );
    case(
        "unknown-key",
        "probability_by:",
        "probability_bye:",
        &["montecarlo", "did you mean `probability_by`"],
    );
    case(
        "not-numeric",
        "path: initial.omega, tilt",
        "path: name, tilt",
        &["not a number or a list of numbers"],
    );
    case(
        "narrow-truncation",
        "min: 1.8, max: 2.3",
        "min: 3.0, max: 3.1",
        &["keep too little of the distribution"],
    );
    case(
        "after-inertia",
        "    - {attitude: {sd_deg: 2.0}}\n",
        "    - {attitude: {sd_deg: 2.0}}\n    - {path: \"body.principal[0]\", normal: {sd: 0.01}}\n",
        &[
            "montecarlo.dispersions[6].path",
            "no longer there",
            "list this dispersion before",
        ],
    );
    case(
        "event-threshold",
        "path: initial.omega, tilt: {sd_deg: 1.0}",
        "path: \"events[1].nutation_angle_deg.above\", normal: {sd: 1.0}",
        &["cannot be dispersed"],
    );
    case(
        "telemetry",
        "final_telemetry: [h_norm]",
        "final_telemetry: [h_nrom]",
        &["unknown telemetry field `h_nrom`", "did you mean `h_norm`"],
    );
    let pair = "paths: [\"initial.omega[0]\", \"initial.omega[1]\"]";
    let last = "path: \"initial.omega[0]\", normal: {sd: 0.01}";
    case(
        "covariance-asymmetric",
        last,
        &format!("{pair}, normal: {{covariance: [[1.0e-4, 0.5e-4], [0.4e-4, 1.0e-4]]}}"),
        &[
            "montecarlo.dispersions[6].normal.covariance",
            ":29:",
            "symmetric",
            "[0][1] is 0.00005",
        ],
    );
    case(
        "covariance-not-semidefinite",
        last,
        &format!("{pair}, normal: {{covariance: [[1.0e-4, 2.0e-4], [2.0e-4, 1.0e-4]]}}"),
        &[
            "montecarlo.dispersions[6].normal.covariance",
            "positive semidefinite",
            "eigenvalue -1.0",
        ],
    );
    case(
        "covariance-size",
        last,
        &format!("{pair}, normal: {{covariance: [[1.0e-4]]}}"),
        &[
            "expected 2 rows of 2 numbers",
            "initial.omega[0], initial.omega[1]",
        ],
    );
    case(
        "sd-and-covariance",
        last,
        &format!("{pair}, normal: {{sd: 0.01, covariance: [[1.0, 0.0], [0.0, 1.0]]}}"),
        &["montecarlo.dispersions[6]", "not both"],
    );
    case(
        "paths-of-different-sizes",
        last,
        "paths: [initial.omega, duration], normal: {sd: 0.01}",
        &["same size", "`initial.omega` has 3", "`duration` has 1"],
    );
    case(
        "paths-truncated",
        last,
        &format!("{pair}, truncated_normal: {{sd: 0.01, min: 0.0}}"),
        &["cannot share one draw"],
    );
    case(
        "paths-unknown",
        last,
        "paths: [\"initial.omega[0]\", \"initial.omegga[1]\"], normal: {sd: 0.01}",
        &["montecarlo.dispersions[6].paths[1]", "did you mean `omega`"],
    );
    case(
        "physical-inertia-sd",
        "{inertia: {sd: 0.01}}",
        "{physical_inertia: {sd: [0.01, 0.02]}}",
        &["montecarlo.dispersions[4]", "expected one number or 3"],
    );
    case(
        "invalid-draws-policy",
        "  probability_by:",
        "  invalid_draws: sometimes\n  probability_by:",
        &[
            "montecarlo.invalid_draws",
            "expected `redraw` or `exclude`, got `sometimes`",
        ],
    );
    // A whole-number field cannot be dispersed.
    let rods = root().join("scenarios/explorer1-pydy.yaml");
    let text = std::fs::read_to_string(&rods).unwrap();
    let text = text.split("\nmontecarlo:").next().unwrap().to_string() + "\n";
    let file = dir.join("count.yaml");
    std::fs::write(
        &file,
        format!(
            "{text}montecarlo:\n  runs: 2\n  dispersions:\n    - {{path: \"effectors[0].copies.count\", normal: {{sd: 1.0}}}}\n"
        ),
    )
    .unwrap();
    let o = polhode()
        .args([
            "montecarlo",
            file.to_str().unwrap(),
            "--out",
            dir.join("c").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot be dispersed"), "{}", stderr(&o));
    // Options.
    for (args, expect) in [
        (vec!["--shard", "0/3"], "expected K/N"),
        (vec!["--shard", "4/3"], "expected K/N"),
        (vec!["--shard", "1/41"], "at most 40 shards"),
        (vec!["--threads", "0"], "at least 1"),
        (vec!["--runs", "0"], "--runs"),
    ] {
        let o = polhode()
            .args(["montecarlo", SCENARIO])
            .args(&args)
            .args(["--out", dir.join("opt").to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(expect), "{args:?}: {}", stderr(&o));
    }
    // A scenario without a campaign.
    let o = polhode()
        .args([
            "montecarlo",
            "scenarios/tennis-racket.yaml",
            "--out",
            dir.join("none").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("expected a `montecarlo:` block"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn invalid_draws_are_recorded_with_what_was_drawn() {
    let dir = scratch("invalid");
    let text = std::fs::read_to_string(root().join(SCENARIO))
        .unwrap()
        .replace("log_normal: {sigma: 0.3}", "normal: {sd: 10.0}");
    let file = dir.join("invalid.yaml");
    std::fs::write(
        &file,
        text.replace(
            "  probability_by:",
            "  invalid_draws: exclude\n  probability_by:",
        ),
    )
    .unwrap();
    let out = dir.join("out");
    campaign(&[file.to_str().unwrap(), "--runs", "30"], &out);
    let summary = json(&out.join("summary.json"));
    let invalid = summary["status"]["invalid"].as_u64().unwrap();
    // A time constant drawn from N(10, 10²) is not positive in about 16 % of the runs.
    assert!((1..15).contains(&invalid), "{invalid} invalid runs");
    let table = polhode::montecarlo::table::from_csv(
        &std::fs::read_to_string(out.join("runs.csv")).unwrap(),
        &json(&out.join("campaign.json"))["columns"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap().to_string())
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let columns = json(&out.join("campaign.json"))["columns"].clone();
    let j = columns
        .as_array()
        .unwrap()
        .iter()
        .position(|c| c == "effectors[sink].time_constant")
        .unwrap();
    let mut seen = 0;
    for row in table.iter().filter(|r| r.status.label() == "invalid") {
        assert!(
            row.message.contains("expected a positive"),
            "{}",
            row.message
        );
        // The draw that made it invalid is in the table.
        assert!(row.values[j].unwrap() <= 0.0, "{row:?}");
        seen += 1;
    }
    assert_eq!(seen, invalid);
    assert_eq!(summary["invalid_draws"]["policy"], "exclude");
    assert_eq!(summary["invalid_draws"]["invalid_runs"], invalid);
    let text = std::fs::read_to_string(out.join("summary.txt")).unwrap();
    assert!(text.contains("invalid draws (exclude)"), "{text}");
    assert!(
        text.contains(&format!("with the {invalid} excluded runs")),
        "{text}"
    );

    // The same campaign redrawing: the runs whose first draw was valid are the same runs,
    // and each invalid one is drawn again from its own stream. So the redrawn campaign's
    // probabilities lie within the range `exclude` gives for each (the excluded runs
    // counted as without and with the event).
    std::fs::write(&file, text_with_redraw(&dir)).unwrap();
    let again = dir.join("redraw");
    campaign(&[file.to_str().unwrap(), "--runs", "30"], &again);
    let redrawn = json(&again.join("summary.json"));
    assert_eq!(redrawn["status"]["invalid"], 0);
    assert_eq!(redrawn["invalid_draws"]["policy"], "redraw");
    let columns: Vec<String> = json(&again.join("campaign.json"))["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    let rows = polhode::montecarlo::table::from_csv(
        &std::fs::read_to_string(again.join("runs.csv")).unwrap(),
        &columns,
    )
    .unwrap();
    let r = columns.iter().position(|c| c == "redraws").unwrap();
    let counts: Vec<f64> = rows.iter().map(|row| row.values[r].unwrap()).collect();
    let count = &redrawn["invalid_draws"]["redrawn"][0];
    assert_eq!(count["column"], "redraws");
    assert_eq!(
        count["rejected"].as_f64().unwrap(),
        counts.iter().sum::<f64>()
    );
    assert_eq!(
        count["runs"].as_u64().unwrap(),
        invalid,
        "the runs redrawn are the runs `exclude` left out"
    );
    let mut compared = 0;
    for (e, f) in summary["events"]
        .as_array()
        .unwrap()
        .iter()
        .zip(redrawn["events"].as_array().unwrap())
    {
        for (b, c) in e["by"]
            .as_array()
            .unwrap()
            .iter()
            .zip(f["by"].as_array().unwrap())
        {
            let (lo, hi) = (
                b["with_excluded"][0].as_f64().unwrap(),
                b["with_excluded"][1].as_f64().unwrap(),
            );
            let p = c["probability"].as_f64().unwrap();
            assert!(lo <= p && p <= hi, "{p} outside [{lo}, {hi}]");
            assert!(hi - lo > 0.0);
            compared += 1;
        }
    }
    assert!(compared >= 6);
}

/// The invalid-draw scenario of [`invalid_draws_are_recorded_with_what_was_drawn`] under
/// the default `invalid_draws` (redraw).
fn text_with_redraw(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("invalid.yaml"))
        .unwrap()
        .replace("  invalid_draws: exclude\n", "")
}

#[test]
fn parquet_table_matches_the_csv_in_an_independent_reader() {
    let dir = scratch("parquet");
    let out = dir.join("out");
    campaign(&[SCENARIO, "--runs", "25"], &out);
    let python = root().join(".venv/bin/python");
    assert!(
        python.exists(),
        "{} is missing: run scripts/python-venv.sh (scripts/test.sh does it for you)",
        python.display()
    );
    let o = Command::new(python)
        .arg(root().join("tests/python/read_parquet.py"))
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}{}", stderr(&o));
    // 32 columns, and `redraws` (the default `invalid_draws: redraw`).
    assert!(text.contains("rows 25 columns 33 identical"), "{text}");
}

#[test]
fn every_shipped_campaign_is_valid() {
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.contains("\nmontecarlo:") {
            continue;
        }
        let sc = polhode::scenario::load(&path, &Default::default()).unwrap();
        let p = polhode::montecarlo::Prepared::new(sc, "x", None, None)
            .unwrap_or_else(|e| panic!("{e}"));
        // The first draws build valid scenarios.
        for i in 0..20 {
            p.build_run(i)
                .unwrap_or_else(|e| panic!("{}: run {i}: {e}", path.display()));
        }
    }
}

/// Width and height of a PNG file, after checking its signature and that it ends with IEND.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    assert_eq!(&bytes[12..16], b"IHDR");
    assert!(bytes.ends_with(&[0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82]));
    let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn every_event_gets_its_own_charts() {
    let dir = scratch("event-charts");
    // Two events of different kinds: the first crossing of 45°, and 80° held for 5 s (the
    // flat spin: the nutation event with the highest `above`).
    let text = std::fs::read_to_string(root().join(SCENARIO)).unwrap();
    let two = text.replace(
        "  - {nutation_angle_deg: {above: 45.0}}\n  - {nutation_angle_deg: {above: 80.0}}\n",
        "  - {nutation_angle_deg: {above: 45.0, once: true}}\n  - {nutation_angle_deg: {above: 80.0, for: 5.0}}\n",
    );
    assert_ne!(two, text);
    let scenario = dir.join("two-events.yaml");
    std::fs::write(&scenario, &two).unwrap();
    let out = dir.join("out");
    campaign(&[scenario.to_str().unwrap(), "--runs", "24"], &out);

    let summary = json(&out.join("summary.json"));
    let charts = summary["charts"].as_array().unwrap();
    assert_eq!(charts.len(), 2, "{charts:?}");
    let columns = [
        "t_nutation_angle_deg_above_45_once",
        "t_nutation_angle_deg_above_80_for_5_s",
    ];
    let text_summary = std::fs::read_to_string(out.join("summary.txt")).unwrap();
    let mut svgs = Vec::new();
    for (c, column) in charts.iter().zip(columns) {
        assert_eq!(c["column"], column);
        let files: Vec<&str> = c["files"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        let expected: Vec<String> = ["histogram", "cdf", "vs_transverse_rate"]
            .iter()
            .flat_map(|k| [format!("{column}_{k}.svg"), format!("{column}_{k}.png")])
            .collect();
        assert_eq!(files, expected);
        for f in &files {
            let bytes = std::fs::read(out.join(f)).unwrap();
            if f.ends_with(".svg") {
                let svg = String::from_utf8(bytes).unwrap();
                assert!(
                    svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
                    "{f}"
                );
                svgs.push(svg);
            } else {
                assert_eq!(png_size(&bytes), (1350, 900), "{f}");
            }
            assert!(text_summary.contains(&f.replace(".svg", ".svg/png")) || f.ends_with(".png"));
        }
    }
    // The two events' charts differ (their times and titles), chart by chart.
    for k in 0..3 {
        assert_ne!(svgs[k], svgs[3 + k], "chart {k}");
        assert!(svgs[3 + k].contains("flat spin"), "chart {k}");
        assert!(
            svgs[k].contains("nutation_angle_deg above 45 once"),
            "chart {k}"
        );
    }
    // The flat spin's charts keep their historical names, the same bytes as its own.
    let flat = charts[1]["flat_spin_files"].as_array().unwrap();
    assert_eq!(flat.len(), 6);
    assert_eq!(charts[0]["flat_spin_files"], serde_json::json!([]));
    for (old, new) in flat.iter().zip(charts[1]["files"].as_array().unwrap()) {
        let (old, new) = (old.as_str().unwrap(), new.as_str().unwrap());
        assert_eq!(
            std::fs::read(out.join(old)).unwrap(),
            std::fs::read(out.join(new)).unwrap(),
            "{old} vs {new}"
        );
    }

    // A campaign with one event written into the same directory leaves no chart of the
    // other; a shard writes none and lists none.
    let one = text.replace("  - {nutation_angle_deg: {above: 45.0}}\n", "");
    let single = dir.join("one-event.yaml");
    std::fs::write(&single, &one).unwrap();
    campaign(&[single.to_str().unwrap(), "--runs", "8"], &out);
    let names: Vec<String> = files(&out)
        .into_keys()
        .filter(|n| n.starts_with("t_"))
        .collect();
    assert_eq!(names.len(), 6, "{names:?}");
    assert!(
        names
            .iter()
            .all(|n| n.starts_with("t_nutation_angle_deg_above_80_")),
        "{names:?}"
    );
    campaign(
        &[single.to_str().unwrap(), "--runs", "8", "--shard", "1/2"],
        &out,
    );
    assert!(
        files(&out)
            .keys()
            .all(|n| !n.ends_with(".svg") && !n.ends_with(".png"))
    );
    assert_eq!(
        json(&out.join("summary.json"))["charts"],
        serde_json::json!([])
    );
}

/// Orbit elements disperse like any numeric field: each run's drawn inclination, size and
/// eccentricity, written into a plain scenario and run alone, give the campaign's final |H|
/// and h_inertial exactly (the pitch rate at rest in LVLH is the orbit's rate, so |H| tells
/// the orbits apart).
#[test]
fn orbit_elements_disperse_like_any_numeric_field() {
    let dir = scratch("orbit");
    let base = "name: mc-orbit
body: {principal: [6.0, 8.0, 2.0]}
orbit: {semi_major_axis_km: 6978.137, inclination_deg: 51.6, eccentricity: 0.0}
initial:
  frame: lvlh
  omega: [0.0, 0.0, 0.0]
  attitude: {w: 0.9990482215818578, x: 0.0, y: 0.043619387365336, z: 0.0}
duration: 600
integrator: {method: dop853, rtol: 1.0e-9, atol: 1.0e-12}
output: {rate: 0.1}
effectors:
  - gravity_gradient: {}
";
    let yaml = format!(
        "{base}montecarlo:
  runs: 4
  seed: 3
  dispersions:
    - {{path: \"orbit.inclination_deg\", normal: {{sd: 5.0}}}}
    - {{path: \"orbit.semi_major_axis_km\", normal: {{sd: 100.0}}}}
    - {{path: \"orbit.eccentricity\", uniform: {{min: 0.0, max: 0.05}}}}
  final_telemetry: [h_norm]
"
    );
    let scenario = dir.join("campaign.yaml");
    std::fs::write(&scenario, yaml).unwrap();
    let out = dir.join("out");
    campaign(&[scenario.to_str().unwrap()], &out);
    let csv = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut norms = Vec::new();
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        let (i, a, e) = (
            cells[col("orbit.inclination_deg")],
            cells[col("orbit.semi_major_axis_km")],
            cells[col("orbit.eccentricity")],
        );
        let single = base.replace(
            "orbit: {semi_major_axis_km: 6978.137, inclination_deg: 51.6, eccentricity: 0.0}",
            &format!("orbit: {{semi_major_axis_km: {a}, inclination_deg: {i}, eccentricity: {e}}}"),
        );
        let path = dir.join("single.yaml");
        std::fs::write(&path, single).unwrap();
        let summary = dir.join("single.json");
        let o = polhode()
            .args([
                "run",
                path.to_str().unwrap(),
                "--no-log",
                "--quiet",
                "--summary",
            ])
            .arg(&summary)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        let expected = json(&summary)["final"]["h_norm"].as_f64().unwrap();
        let got: f64 = cells[col("final_h_norm")].parse().unwrap();
        assert_eq!(got, expected, "{line}");
        norms.push(got);
    }
    assert_eq!(norms.len(), 4);
    // Different orbits: different rates, so different |H|.
    norms.sort_by(f64::total_cmp);
    assert!(
        norms.windows(2).all(|w| w[1] > w[0] * (1.0 + 1e-6)),
        "{norms:?}"
    );
}

/// A campaign larger than a block of runs (`BLOCK_RUNS`), than the CDF's exact staircase and
/// than the scatter's points streams the same files as its shards merged, and its summary
/// equals the statistics of its table computed here by sorting.
#[test]
fn a_campaign_of_many_blocks_streams_the_result_of_its_shards() {
    let dir = scratch("blocks");
    let scene = "scenarios/explorer1-energy-sink.yaml";
    let runs = "9000";
    let whole = dir.join("whole");
    let common = ["--method", "averaged", "--runs", runs, "--threads", "2"];
    campaign(&[&[scene][..], &common[..]].concat(), &whole);
    let shards: Vec<PathBuf> = (1..=2).map(|k| dir.join(format!("shard-{k}"))).collect();
    for (k, s) in shards.iter().enumerate() {
        let spec = format!("{}/2", k + 1);
        campaign(
            &[&[scene][..], &common[..], &["--shard", &spec]].concat(),
            s,
        );
    }
    let merged = dir.join("merged");
    let o = merge(&[&shards[1], &shards[0]], &merged);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_same(&whole, &merged);

    let manifest = json(&whole.join("campaign.json"));
    let columns: Vec<String> = manifest["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    let table = polhode::montecarlo::table::from_csv(
        &std::fs::read_to_string(whole.join("runs.csv")).unwrap(),
        &columns,
    )
    .unwrap();
    assert_eq!(table.len(), 9000);
    let summary = json(&whole.join("summary.json"));
    for stats in summary["columns"].as_array().unwrap() {
        let name = stats["column"].as_str().unwrap();
        let j = columns.iter().position(|c| c == name).unwrap();
        let mut v: Vec<f64> = table
            .iter()
            .filter(|r| r.status.ok())
            .filter_map(|r| r.values[j])
            .filter(|x| x.is_finite())
            .collect();
        v.sort_by(f64::total_cmp);
        assert_eq!(stats["count"], v.len(), "{name}");
        assert_eq!(stats["min"].as_f64().unwrap(), v[0], "{name}");
        assert_eq!(stats["max"].as_f64().unwrap(), v[v.len() - 1], "{name}");
        for (k, p) in [1.0, 5.0, 25.0, 50.0, 75.0, 95.0, 99.0].iter().enumerate() {
            let expected = polhode::montecarlo::percentile(&v, *p);
            assert_eq!(
                stats["percentiles"][k].as_f64().unwrap(),
                expected,
                "{name} p{p}"
            );
        }
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let got = stats["mean"].as_f64().unwrap();
        assert!(
            (got - mean).abs() <= 1e-12 * mean.abs().max(1e-300),
            "{name}: {got} {mean}"
        );
    }
    // More flat spins than the scatter shows: it says which share it draws.
    let scatter =
        std::fs::read_to_string(whole.join("t_nutation_angle_deg_above_45_vs_transverse_rate.svg"))
            .unwrap();
    assert!(
        scatter.contains("1 in 2 of"),
        "the scatter's title names its thinning"
    );
}

/// Every lane width the processor has (and the scalar path) writes the same campaign
/// directory; the header names the engine; a width that is not 1, 4 or 8, or one given with
/// `--no-lanes`, is refused before anything is written.
#[test]
fn every_lane_width_writes_the_same_campaign() {
    let dir = scratch("widths");
    let scenario = "scenarios/nutation-damper.yaml";
    let base = [scenario, "--runs", "24", "--threads", "2"];
    let scalar = dir.join("scalar");
    campaign(&[&base[..], &["--no-lanes"]].concat(), &scalar);
    for width in ["1", "4", "8"] {
        let out = dir.join(format!("w{width}"));
        campaign(&[&base[..], &["--lane-width", width]].concat(), &out);
        assert_same(&scalar, &out);
    }
    let o = polhode()
        .args([
            "montecarlo",
            scenario,
            "--runs",
            "8",
            "--lane-width",
            "8",
            "--out",
        ])
        .arg(dir.join("header"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let header = String::from_utf8_lossy(&o.stdout).into_owned() + &stderr(&o);
    assert!(
        header.contains("integrated in lockstep lane"),
        "the header names the lanes: {header}"
    );
    for bad in [
        vec!["--lane-width", "3"],
        vec!["--lane-width", "4", "--no-lanes"],
    ] {
        let out = dir.join("refused");
        let o = polhode()
            .args(["montecarlo", scenario, "--runs", "8"])
            .args(&bad)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("--lane-width"),
            "{bad:?}: {}",
            stderr(&o)
        );
        assert!(!out.exists(), "{bad:?}: nothing written");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
