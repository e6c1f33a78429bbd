//! Where polhode writes, and what it never overwrites (docs/cli.md): no output may be an input
//! or another output (by path, `..`, symlink or hard link), a directory of outputs is taken
//! only when new, empty or polhode's, one writer at a time, and a name from user text stays
//! inside its directory. Every refusal exits 2 and writes nothing.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const CAMPAIGN: &str = "tests/data/montecarlo-sink.yaml";

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
    common::Scratch::new("polhode-outputs", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn run(args: &[&str]) -> Output {
    polhode().args(args).output().unwrap()
}

/// The names in `dir`, sorted (hidden ones too).
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Checks a refusal: exit code 2, a message holding each of `expect`.
fn assert_refused(what: &str, o: &Output, expect: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    for e in expect {
        assert!(err.contains(e), "{what}: `{e}` missing from: {err}");
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const GOOD: &str = "name: good
body:
  principal: [1.0, 2.0, 3.0]
initial:
  omega: [0.1, 0.0, 1.0]
duration: 2.0
output: {rate: 10}
";

/// Before: `polhode run t.yaml --out t.yaml` (and `--csv`, `--parquet`, `--summary`,
/// `compare --csv`, `linearize --json`) exited 0 with the scenario replaced by the output.
#[test]
fn an_output_that_is_the_input_is_refused_however_it_is_named() {
    let dir = scratch("input");
    let scenario = dir.join("t.yaml");
    std::fs::write(&scenario, GOOD).unwrap();
    std::fs::create_dir(dir.join("sub")).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&scenario, dir.join("link.yaml")).unwrap();
        std::fs::hard_link(&scenario, dir.join("hard.yaml")).unwrap();
    }
    let mut aliases = vec![
        scenario.clone(),
        dir.join("sub/../t.yaml"),
        dir.join("missing/../t.yaml"),
    ];
    if cfg!(unix) {
        aliases.push(dir.join("link.yaml"));
        aliases.push(dir.join("hard.yaml"));
    }
    let t = s(&scenario);
    for alias in &aliases {
        let a = s(alias);
        let cases: [Vec<&str>; 7] = [
            vec!["run", t, "-q", "--out", a],
            vec!["run", t, "-q", "--no-log", "--csv", a],
            vec!["run", t, "-q", "--no-log", "--parquet", a],
            vec!["run", t, "-q", "--no-log", "--summary", a],
            vec!["compare", t, "--csv", a],
            vec!["compare", t, "--chart", a],
            vec!["linearize", t, "--json", a],
        ];
        for args in cases {
            let o = run(&args);
            assert_refused(&format!("{args:?}"), &o, &[a, "the scenario"]);
            assert_eq!(
                std::fs::read_to_string(&scenario).unwrap(),
                GOOD,
                "{args:?} changed the scenario"
            );
        }
    }
    let mut left = names(&dir);
    left.retain(|n| !["t.yaml", "sub", "link.yaml", "hard.yaml"].contains(&n.as_str()));
    assert!(left.is_empty(), "written: {left:?}");
}

/// Before: `compare --chart X --csv X` exited 0 and one of the two outputs was lost.
#[test]
fn two_outputs_of_one_command_on_one_file_are_refused() {
    let dir = scratch("two");
    let scenario = dir.join("t.yaml");
    std::fs::write(&scenario, GOOD).unwrap();
    let x = dir.join("x.out");
    let x_dotted = dir.join("sub/../x.out");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let t = s(&scenario);
    let cases: [Vec<&str>; 4] = [
        vec!["compare", t, "--chart", s(&x), "--csv", s(&x)],
        vec!["compare", t, "--csv", s(&x), "--json", s(&x_dotted)],
        vec![
            "run",
            t,
            "-q",
            "--no-log",
            "--csv",
            s(&x),
            "--parquet",
            s(&x),
        ],
        vec!["run", t, "-q", "--out", s(&x), "--summary", s(&x_dotted)],
    ];
    for args in cases {
        let o = run(&args);
        assert_refused(&format!("{args:?}"), &o, &["x.out", "both name"]);
        assert!(!x.exists(), "{args:?} wrote {}", x.display());
    }
}

/// Before: a campaign run from DIR/scenario.yaml with `--out DIR` wrote its tables beside its
/// input (and a kill removed the input), and an input named `runs.csv` was replaced by the
/// table.
#[test]
fn a_campaign_never_writes_into_the_directory_of_its_input() {
    let dir = scratch("beside");
    let text = std::fs::read_to_string(root().join(CAMPAIGN)).unwrap();
    for name in ["scenario.yaml", "runs.csv"] {
        let input = dir.join(name);
        std::fs::write(&input, &text).unwrap();
        let o = run(&[
            "montecarlo",
            s(&input),
            "--runs",
            "2",
            "-q",
            "--out",
            s(&dir),
        ]);
        assert_refused(name, &o, &[s(&dir), "holds the scenario"]);
        assert_eq!(std::fs::read_to_string(&input).unwrap(), text, "{name}");
        assert_eq!(names(&dir), vec![name.to_string()]);
        std::fs::remove_file(&input).unwrap();
    }
}

/// Before: `montecarlo --out DIR` into a directory of the user's files removed and replaced
/// them (a user's `t_x_histogram.png` was deleted), and `--out /` was accepted.
#[test]
fn a_campaign_takes_only_a_new_empty_or_polhode_directory() {
    let dir = scratch("users");
    let users = dir.join("mine");
    std::fs::create_dir(&users).unwrap();
    for f in ["t_x_histogram.png", "summary.txt", "notes.md"] {
        std::fs::write(users.join(f), "mine").unwrap();
    }
    for out in [users.as_path(), Path::new("/")] {
        let o = run(&["montecarlo", CAMPAIGN, "--runs", "2", "-q", "--out", s(out)]);
        assert_refused(s(out), &o, &[s(out), "polhode did not write"]);
    }
    assert_eq!(
        names(&users),
        vec!["notes.md", "summary.txt", "t_x_histogram.png"]
    );
    for f in names(&users) {
        assert_eq!(std::fs::read(users.join(&f)).unwrap(), b"mine", "{f}");
    }

    // A new directory is taken, then taken again: the second campaign's files replace the
    // first's, a file of the user's that no campaign writes stays, and one of a name a
    // campaign writes refuses the directory.
    let out = dir.join("new/deeper");
    let o = run(&[
        "montecarlo",
        CAMPAIGN,
        "--runs",
        "4",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(names(&out).contains(&".polhode-outputs".to_string()));
    std::fs::write(out.join("notes.md"), "mine").unwrap();
    let o = run(&[
        "montecarlo",
        CAMPAIGN,
        "--runs",
        "4",
        "--shard",
        "1/2",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let left = names(&out);
    assert!(left.contains(&"notes.md".to_string()), "{left:?}");
    assert!(
        !left.iter().any(|n| n.ends_with(".png")),
        "the whole campaign's charts were kept beside the shard's files: {left:?}"
    );
    std::fs::write(out.join("t_y_cdf.svg"), "mine").unwrap();
    let o = run(&[
        "montecarlo",
        CAMPAIGN,
        "--runs",
        "4",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_refused(
        "a user's chart",
        &o,
        &["t_y_cdf.svg", "not written by polhode"],
    );
    assert_eq!(std::fs::read(out.join("t_y_cdf.svg")).unwrap(), b"mine");
    assert_eq!(std::fs::read(out.join("notes.md")).unwrap(), b"mine");
    assert!(
        out.join("campaign.json").exists(),
        "the refusal removed files"
    );
}

/// Before: `merge --out S` with S one of the shards removed that shard's files.
#[test]
fn merge_into_one_of_its_shards_is_refused() {
    let dir = scratch("merge");
    let shards: Vec<PathBuf> = (1..=2).map(|k| dir.join(format!("s{k}"))).collect();
    for (k, d) in shards.iter().enumerate() {
        let spec = format!("{}/2", k + 1);
        let o = run(&[
            "montecarlo",
            CAMPAIGN,
            "--runs",
            "4",
            "--shard",
            &spec,
            "-q",
            "--out",
            s(d),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let before = std::fs::read(shards[0].join("runs.csv")).unwrap();
    let listed = names(&shards[0]);
    for out in [shards[0].clone(), shards[0].join("../s1"), dir.clone()] {
        let o = run(&[
            "merge",
            s(&shards[0]),
            s(&shards[1]),
            "-q",
            "--out",
            s(&out),
        ]);
        assert_refused(s(&out), &o, &["--out"]);
        assert_eq!(names(&shards[0]), listed);
        assert_eq!(std::fs::read(shards[0].join("runs.csv")).unwrap(), before);
    }
    let merged = dir.join("s1/merged");
    let o = run(&[
        "merge",
        s(&shards[0]),
        s(&shards[1]),
        "-q",
        "--out",
        s(&merged),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// Before: two campaigns writing the same `--out` both exited 0 and left a mixed directory.
#[test]
fn a_second_campaign_into_a_directory_being_written_is_refused() {
    let dir = scratch("concurrent");
    let out = dir.join("out");
    let mut first = polhode()
        .args(["montecarlo", CAMPAIGN, "--runs", "100000", "--threads", "1"])
        .args(["--seed", "1", "-q", "--out", s(&out)])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while !out.join("runs.csv").exists()
        && !names_or_empty(&out).iter().any(|n| n.ends_with(".tmp"))
    {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the first campaign never started"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = run(&[
        "montecarlo",
        CAMPAIGN,
        "--runs",
        "4",
        "--seed",
        "2",
        "-q",
        "--out",
        s(&out),
    ]);
    let still_running = first.try_wait().unwrap().is_none();
    first.kill().unwrap();
    first.wait().unwrap();
    assert!(
        still_running,
        "the first campaign ended before the second started"
    );
    assert_refused(
        "the second campaign",
        &o,
        &["another polhode process", s(&out)],
    );
    assert!(
        !out.join("campaign.json").exists(),
        "the second campaign wrote its manifest into the first's directory"
    );
    // Once the first is gone, the directory is free again.
    let o = run(&[
        "montecarlo",
        CAMPAIGN,
        "--runs",
        "4",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        names(&out).iter().all(|n| !n.ends_with(".tmp")),
        "{:?}",
        names(&out)
    );
}

fn names_or_empty(dir: &Path) -> Vec<String> {
    if dir.is_dir() { names(dir) } else { Vec::new() }
}

/// Before: the default campaign directory was `logs/<name>-montecarlo` with the name as
/// written, so `name: ../../victim/evil` wrote outside `logs/`.
#[test]
fn a_scenario_name_never_leads_outside_logs() {
    let dir = scratch("name");
    let work = dir.join("a/b");
    std::fs::create_dir_all(&work).unwrap();
    let text = std::fs::read_to_string(root().join(CAMPAIGN))
        .unwrap()
        .replace("name: montecarlo-sink", "name: ../../victim/evil");
    std::fs::write(work.join("s.yaml"), text).unwrap();
    let o = polhode()
        .args(["montecarlo", "s.yaml", "--runs", "2", "-q"])
        .current_dir(&work)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!dir.join("victim").exists(), "wrote outside logs/");
    assert_eq!(names(&dir.join("a")), vec!["b"]);
    assert_eq!(names(&work), vec!["logs", "s.yaml"]);
    let inside = names(&work.join("logs"));
    assert_eq!(inside.len(), 1, "{inside:?}");
    assert!(!inside[0].contains(".."), "{inside:?}");
    assert!(
        work.join("logs")
            .join(&inside[0])
            .join("campaign.json")
            .exists()
    );
}

/// `plot --out DIR` takes the directory as a campaign does: a user's chart is not replaced.
#[test]
fn plot_takes_only_a_new_empty_or_polhode_directory() {
    let dir = scratch("plot");
    let scenario = dir.join("t.yaml");
    std::fs::write(&scenario, GOOD).unwrap();
    let log = dir.join("t.mcap");
    let o = run(&["run", s(&scenario), "-q", "--out", s(&log)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let users = dir.join("mine");
    std::fs::create_dir(&users).unwrap();
    std::fs::write(users.join("omega.png"), "mine").unwrap();
    let o = run(&["plot", s(&log), "-q", "--out", s(&users)]);
    assert_refused(
        "a user's directory",
        &o,
        &[s(&users), "polhode did not write"],
    );
    assert_eq!(names(&users), vec!["omega.png"]);
    let o = run(&["plot", s(&log), "-q", "--out", s(&dir)]);
    assert_refused("the log's directory", &o, &["holds the log"]);
    let charts = dir.join("charts");
    for _ in 0..2 {
        let o = run(&["plot", s(&log), "-q", "--out", s(&charts)]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    assert!(names(&charts).contains(&"omega.png".to_string()));
}
