//! Results a user can trust unattended: models that stop outside their validity, events that
//! answer the question asked (`once`, `for`), and one status vocabulary across outputs.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn polhode() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-trust", name)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The `polhode` metadata record of a log.
fn log_metadata(path: &Path) -> std::collections::BTreeMap<String, String> {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let index = summary
        .metadata_indexes
        .iter()
        .find(|i| i.name == "polhode")
        .expect("metadata");
    mcap::read::metadata(&bytes, index).unwrap().metadata
}

/// The texts of a log's `/log` messages.
fn log_texts(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/log")
        .map(|m| String::from_utf8_lossy(&m.data).into_owned())
        .collect()
}

fn run(dir: &Path, scenario: &str, args: &[&str]) -> Output {
    polhode()
        .arg("run")
        .arg(scenario)
        .args(["--out", "s.mcap", "--summary", "s.json"])
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(path)
        .display()
        .to_string()
}

/// Before: the floppy boom drifted to a "complete" flat spin with its tips 12 m off axis and
/// no warning. Now: a warning at δ/L = 0.1, then `invalid_model` at δ/L = 0.3 naming the boom,
/// the deflection and the remedy; the log is kept and marked partial; exit 3.
#[test]
fn a_modal_boom_past_its_small_deflection_range_stops_with_a_diagnosis() {
    let dir = scratch("boom");
    let out = run(&dir, &repo("scenarios/floppy-boom.yaml"), &["-q"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("modal_appendage `boom_1` left the range its model holds in"),
        "{err}"
    );
    for expect in [
        "δ/L = 0.30",
        "foreshortened by",
        "stiffer boom",
        "hinged_rod",
        "more modes",
    ] {
        assert!(err.contains(expect), "expected {expect:?} in {err}");
    }
    // Warned once per boom at δ/L = 0.1, before the stop.
    assert_eq!(
        err.matches("nears the edge of the range").count(),
        2,
        "{err}"
    );
    let json = read_json(&dir.join("s.json"));
    assert_eq!(json["status"]["kind"], "invalid_model");
    assert_eq!(json["warnings"].as_array().unwrap().len(), 2);
    let t_stop = json["final"]["t"].as_f64().unwrap();
    let t_warn = json["warnings"][0]["t"].as_f64().unwrap();
    assert!(t_warn > 0.0 && t_warn < t_stop, "{t_warn} {t_stop}");
    let meta = log_metadata(&dir.join("s.mcap"));
    assert_eq!(meta["status"], "invalid_model");
    assert_eq!(meta["partial"], "true");
    let logged = log_texts(&dir.join("s.mcap"));
    assert!(
        logged.iter().any(|m| m.contains("nears the edge")),
        "{logged:?}"
    );
    assert!(
        logged
            .iter()
            .any(|m| m.contains("outside the model's validity")),
        "{logged:?}"
    );
}

/// `checks: {on_validity: warn}` goes on past the limit, warning once more that the results
/// are not to be trusted.
#[test]
fn on_validity_warn_goes_on_and_says_so() {
    let dir = scratch("boom-warn");
    let yaml = std::fs::read_to_string(repo("scenarios/floppy-boom.yaml")).unwrap()
        + "checks: {on_validity: warn}\n";
    std::fs::write(dir.join("b.yaml"), yaml).unwrap();
    let out = run(&dir, "b.yaml", &["-q", "--duration", "400"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert_eq!(err.matches("not to be trusted").count(), 2, "{err}");
    let json = read_json(&dir.join("s.json"));
    assert_eq!(json["status"]["kind"], "complete");
    assert_eq!(json["warnings"].as_array().unwrap().len(), 4);
    // And `on_validity` takes only `stop` or `warn`, located.
    let bad = std::fs::read_to_string(repo("scenarios/floppy-boom.yaml")).unwrap()
        + "checks: {on_validity: ignore}\n";
    std::fs::write(dir.join("bad.yaml"), bad).unwrap();
    let out = polhode()
        .args(["check", "bad.yaml"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("checks.on_validity") && err.contains("expected `stop` or `warn`"),
        "{err}"
    );
}

/// A spring–mass damper's `travel` and a wheel's `max_speed` are limits like the beam's.
#[test]
fn damper_travel_and_wheel_speed_are_enforced() {
    let dir = scratch("travel");
    // The nutation damper's particle swings by about 0.07 m: a 5 cm travel is exceeded.
    let damper = std::fs::read_to_string(repo("scenarios/nutation-damper.yaml"))
        .unwrap()
        .replace(
            "damping: 105.49              # N s/m",
            "damping: 105.49\n      travel: 0.05",
        );
    assert!(damper.contains("travel: 0.05"));
    std::fs::write(dir.join("d.yaml"), damper).unwrap();
    let out = run(&dir, "d.yaml", &["-q"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("spring_mass_damper `damper` left the range")
            && err.contains("travel of 0.05 m"),
        "{err}"
    );
    let wheel = std::fs::read_to_string(repo("scenarios/wheel-damper.yaml")).unwrap();
    let wheel = wheel.replacen("wheel_damper:", "wheel_damper:\n      max_speed: 1.0e-9", 1);
    std::fs::write(dir.join("w.yaml"), &wheel).unwrap();
    let out = run(&dir, "w.yaml", &["-q"]);
    let err = text(&out.stderr);
    // The Kasdin–Paley wheel starts at rest relative to the body and is spun up by the
    // nutation: it passes any tiny rating at once.
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("wheel_damper `") && err.contains("rated"),
        "{err}"
    );
}

/// The sampled nutation angle of the nutation-damper scenario, (t, degrees), from its log.
fn nutation_samples(path: &Path) -> Vec<(f64, f64)> {
    let bytes = std::fs::read(path).unwrap();
    let mut out = vec![];
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic != "/telemetry" {
            continue;
        }
        // Fields are proto3 doubles numbered from 1 (sim_time = 1, nutation_angle_deg = 17):
        // tag byte (number << 3 | 1) then 8 little-endian bytes; zeros are omitted.
        let mut fields = std::collections::HashMap::new();
        let d = &m.data;
        let mut i = 0;
        while i < d.len() {
            let (mut key, mut shift) = (0u64, 0);
            loop {
                let b = d[i];
                i += 1;
                key |= u64::from(b & 0x7f) << shift;
                shift += 7;
                if b & 0x80 == 0 {
                    break;
                }
            }
            assert_eq!(key & 7, 1, "only doubles");
            fields.insert(
                key >> 3,
                f64::from_le_bytes(d[i..i + 8].try_into().unwrap()),
            );
            i += 8;
        }
        out.push((
            *fields.get(&1).unwrap_or(&0.0),
            *fields.get(&17).unwrap_or(&0.0),
        ));
    }
    out
}

/// `once` records the first crossing only; `for: 60` gives the settling time: the start of
/// the first interval of 60 s below 1°. Checked against the logged samples (20 Hz), which the
/// event machinery did not produce.
#[test]
fn once_and_for_answer_the_settling_question() {
    let dir = scratch("settle");
    let out = run(&dir, &repo("scenarios/nutation-damper.yaml"), &[]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let json = read_json(&dir.join("s.json"));
    let events = json["events"].as_array().unwrap();
    assert_eq!(events.len(), 2, "{events:?}");
    let first = &events[0];
    let settled = &events[1];
    assert_eq!(first["condition"], "nutation_angle_deg below 1 once");
    assert_eq!(settled["condition"], "nutation_angle_deg below 1 for 60 s");
    let (t_first, t_settled) = (first["t"].as_f64().unwrap(), settled["t"].as_f64().unwrap());
    assert!(t_first < t_settled, "{t_first} {t_settled}");
    assert!(
        stdout.contains("nutation_angle_deg below 1 for 60 s"),
        "{stdout}"
    );

    let samples = nutation_samples(&dir.join("s.mcap"));
    assert!(samples.len() > 10_000);
    // The first sample below 1° follows the `once` event within one sample interval.
    let first_below = samples.iter().find(|s| s.1 < 1.0).unwrap().0;
    assert!(
        first_below >= t_first && first_below - t_first <= 0.05 + 1e-9,
        "{first_below} vs {t_first}"
    );
    // Every sample in [t_settled, t_settled + 60] is below 1°, and the last sample before
    // t_settled is not.
    let window: Vec<_> = samples
        .iter()
        .filter(|s| s.0 >= t_settled && s.0 <= t_settled + 60.0)
        .collect();
    assert!(window.len() >= 1199, "{}", window.len());
    assert!(window.iter().all(|s| s.1 < 1.0));
    let before = samples.iter().rev().find(|s| s.0 < t_settled).unwrap();
    assert!(before.1 >= 1.0, "{before:?}");
    // And no earlier interval of 60 s was entirely below 1°: find the brute-force answer
    // on the samples (to the sample spacing).
    let mut start: Option<f64> = None;
    let mut brute = None;
    for s in &samples {
        if s.1 < 1.0 {
            let since = *start.get_or_insert(s.0);
            if s.0 - since >= 60.0 {
                brute = Some(since);
                break;
            }
        } else {
            start = None;
        }
    }
    let brute = brute.expect("settled within the run");
    assert!(
        brute >= t_settled && brute - t_settled <= 0.05 + 1e-9,
        "{brute} vs {t_settled}"
    );
}

/// A stop with `for:` ends the run at the end of the interval; its event keeps the start.
#[test]
fn a_stop_with_for_ends_when_the_interval_has_held() {
    let dir = scratch("stop-for");
    let yaml = std::fs::read_to_string(repo("scenarios/nutation-damper.yaml"))
        .unwrap()
        .replace(
            "events:\n",
            "stop:\n  - nutation_angle_deg: {below: 1.0, for: 30.0}\nevents:\n",
        );
    std::fs::write(dir.join("s.yaml"), yaml).unwrap();
    let out = run(&dir, "s.yaml", &["-q"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let json = read_json(&dir.join("s.json"));
    assert_eq!(json["status"]["kind"], "stopped");
    let stop = json["events"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["terminal"] == true)
        .unwrap()
        .clone();
    let t = stop["t"].as_f64().unwrap();
    let t_end = json["final"]["t"].as_f64().unwrap();
    assert!((t_end - (t + 30.0)).abs() < 1e-6, "{t} {t_end}");
    assert!(json["final"]["nutation_angle_deg"].as_f64().unwrap() < 1.0);
}

/// The text output lists 10 events and counts the rest; the summary keeps them all.
#[test]
fn text_output_prints_ten_events_then_a_count() {
    let dir = scratch("many");
    let out = run(
        &dir,
        &repo("scenarios/tennis-racket.yaml"),
        &["--duration", "100"],
    );
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0));
    let json = read_json(&dir.join("s.json"));
    let n = json["events"].as_array().unwrap().len();
    assert!(n > 12, "{n}");
    assert_eq!(stdout.matches("  event: ").count(), 10, "{stdout}");
    assert!(
        stdout.contains(&format!("… and {} more events", n - 10)),
        "{stdout}"
    );
}

/// One status word everywhere: the summary's `kind`, the text and the log metadata.
#[test]
fn one_status_vocabulary() {
    let dir = scratch("words");
    let out = run(&dir, &repo("scenarios/tennis-racket.yaml"), &[]);
    assert_eq!(out.status.code(), Some(0));
    let json = read_json(&dir.join("s.json"));
    assert_eq!(json["status"]["kind"], "complete");
    assert!(text(&out.stdout).contains("status: complete\n"));
    let meta = log_metadata(&dir.join("s.mcap"));
    assert_eq!(meta["status"], "complete");
    assert_eq!(meta["partial"], "false");
}

/// Principal axes point into the positive half of the body axis they are closest to, also
/// for a CubeSat whose moments ascend as z, y, x (before: axis 3 printed as [-1, 0, 0]).
#[test]
fn principal_axes_follow_the_documented_convention() {
    let dir = scratch("axes");
    std::fs::write(
        dir.join("c.yaml"),
        "name: cubesat\nbody: {principal: [0.035, 0.033, 0.008]}\ninitial: {omega: [0.1, 0.0, 0.0]}\nduration: 1.0\n",
    )
    .unwrap();
    let out = run(&dir, "c.yaml", &[]);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("axis 3: [+1.000000000, +0.000000000, +0.000000000]"),
        "{stdout}"
    );
    for line in stdout
        .lines()
        .filter(|l| l.trim_start().starts_with("axis "))
    {
        assert!(!line.contains('-'), "{line}");
    }
    let json = read_json(&dir.join("s.json"));
    assert_eq!(
        json["body"]["principal_axes"][2],
        serde_json::json!([1.0, 0.0, 0.0])
    );
    // Explorer 1's eigensolver leaves components of order 1e-17: they print as +0.
    let out = run(
        &dir,
        &repo("scenarios/explorer1.yaml"),
        &["--duration", "0.01"],
    );
    let stdout = text(&out.stdout);
    let axes: Vec<&str> = stdout.lines().filter(|l| l.contains("axis ")).collect();
    assert_eq!(axes.len(), 3, "{stdout}");
    assert!(axes.iter().all(|l| !l.contains('-')), "{axes:?}");
}

/// `polhode check` validates the `montecarlo:` block with `montecarlo`'s own message (before:
/// it said "ok" for `path: initial.omeg`).
#[test]
fn check_validates_the_campaign_block_like_montecarlo() {
    let dir = scratch("check-mc");
    let good = std::fs::read_to_string(repo("tests/data/montecarlo-sink.yaml")).unwrap();
    std::fs::write(dir.join("good.yaml"), &good).unwrap();
    let out = polhode()
        .args(["check", "good.yaml"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("montecarlo: "),
        "{}",
        text(&out.stdout)
    );
    let bad = good.replacen("path: initial.omega,", "path: initial.omeg,", 1);
    assert_ne!(bad, good);
    std::fs::write(dir.join("bad.yaml"), &bad).unwrap();
    let check = polhode()
        .args(["check", "bad.yaml"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let campaign = polhode()
        .args(["montecarlo", "bad.yaml", "--runs", "2", "-q", "--out", "mc"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(check.status.code(), Some(2));
    assert_eq!(campaign.status.code(), Some(2));
    let message = text(&check.stderr);
    assert!(message.contains("has no field `omeg`"), "{message}");
    assert_eq!(message, text(&campaign.stderr));
    assert!(!dir.join("mc").exists());
}

/// A mistyped subcommand gets a suggestion, transposed letters included.
#[test]
fn a_mistyped_subcommand_gets_a_suggestion() {
    for (typed, meant) in [
        ("rnu", "run"),
        ("chekc", "check"),
        ("lineraize", "linearize"),
    ] {
        let out = polhode().arg(typed).output().unwrap();
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("a similar subcommand exists: '{meant}'")),
            "{typed}: {err}"
        );
    }
    let out = polhode().arg("xyzzy").output().unwrap();
    assert!(!text(&out.stderr).contains("similar"));
}

/// `polhode check` on `yaml`: (exit code, stderr).
fn check_text(name: &str, yaml: &str) -> (Option<i32>, String) {
    let dir = scratch(name);
    std::fs::write(dir.join("s.yaml"), yaml).unwrap();
    let out = polhode()
        .args(["check", "s.yaml"])
        .current_dir(&dir)
        .output()
        .unwrap();
    (out.status.code(), text(&out.stderr))
}

const HEAD: &str = "name: x\nbody: {principal: [1, 2, 3], mass: 10}\ninitial:\n  omega: [0.1, 0, 1]\nduration: 1\n";

/// Semantic errors carry the line and column (before: the energy sink combined with a wheel
/// had neither), event errors their list index, and an attitude given as a list the form to
/// use.
#[test]
fn errors_are_located_and_say_what_to_write() {
    let cases = [
        (
            "sink",
            format!(
                "{HEAD}effectors:\n  - wheel_damper: {{inertia: 0.01, axis: [0, 0, 1], damping: 0.1}}\n  - energy_sink: {{coefficient: 0.1}}\n"
            ),
            "s.yaml:8:5: field `effectors[1].energy_sink`: an energy sink models",
        ),
        (
            "rayleigh",
            format!("{HEAD}effectors:\n  - rayleigh: {{name: r}}\n"),
            "s.yaml:7:5: field `effectors[0].rayleigh`: expected exactly one of `gamma",
        ),
        (
            "attitude",
            HEAD.replace(
                "  omega: [0.1, 0, 1]\n",
                "  omega: [0.1, 0, 1]\n  attitude: [1, 0, 0, 0]\n",
            ),
            "s.yaml:5:13: field `initial.attitude`: expected a quaternion as a mapping `{w: 1.0, x: 0.0, y: 0.0, z: 0.0}`",
        ),
        (
            "event-threshold",
            format!(
                "{HEAD}events:\n  - nutation_angle_deg: {{above: 1}}\n  - nutation_angle_deg: 5\n"
            ),
            "s.yaml:8:25: field `events[1].nutation_angle_deg`: expected a threshold mapping `{above: X}` or `{below: X}`, got `5`",
        ),
        (
            "event-two",
            format!(
                "{HEAD}stop:\n  - {{nutation_angle_deg: {{above: 1}}, omega_x: {{above: 1}}}}\n"
            ),
            "field `stop[0]`: expected one condition per list item",
        ),
        (
            "event-for",
            format!(
                "{HEAD}events:\n  - omega_z: {{above: 1}}\n  - omega_z: {{below: 1, for: -2}}\n"
            ),
            "s.yaml:8:5: field `events[1].omega_z.for`: expected a duration ≥ 0 s",
        ),
    ];
    for (name, yaml, expect) in cases {
        let (code, err) = check_text(name, &yaml);
        assert_eq!(code, Some(2), "{name}: {err}");
        assert!(err.contains(expect), "{name}: expected {expect:?} in {err}");
    }
}

/// In a campaign, runs stopped outside their model's validity get their own status, are
/// counted, and are left out of event probabilities, which say how many they exclude.
#[test]
fn campaigns_count_and_exclude_invalid_model_runs() {
    let dir = scratch("mc-invalid");
    // EI below about 5 N m² takes the floppy boom past δ/L = 0.3 within 600 s; above about 10
    // it stays inside.
    let yaml = std::fs::read_to_string(repo("scenarios/floppy-boom.yaml"))
        .unwrap()
        .replace("duration: 3600.0", "duration: 600.0")
        + "montecarlo:\n  runs: 8\n  seed: 3\n  dispersions:\n    - {path: \"effectors[boom].bending_stiffness\", uniform: {min: 1.5, max: 12.0}}\n  probability_by: [300]\n";
    std::fs::write(dir.join("mc.yaml"), yaml).unwrap();
    let out = polhode()
        .args(["montecarlo", "mc.yaml", "-q", "--out", "out"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let summary = read_json(&dir.join("out/summary.json"));
    let status = &summary["status"];
    let invalid_model = status["invalid_model"].as_u64().unwrap();
    let usable = status["complete"].as_u64().unwrap() + status["stopped"].as_u64().unwrap();
    assert!(invalid_model > 0 && usable > 0, "{status}");
    let event = &summary["events"][0];
    assert_eq!(event["runs"].as_u64().unwrap(), usable, "{event}");
    assert_eq!(event["excluded"].as_u64().unwrap(), 8 - usable, "{event}");
    assert_eq!(
        event["excluded_invalid_model"].as_u64().unwrap(),
        invalid_model
    );
    let table = std::fs::read_to_string(dir.join("out/runs.csv")).unwrap();
    assert_eq!(
        table.matches(",invalid_model,").count() as u64,
        invalid_model,
        "{table}"
    );
    let text_summary = std::fs::read_to_string(dir.join("out/summary.txt")).unwrap();
    assert!(
        text_summary.contains(&format!("{invalid_model} invalid_model")),
        "{text_summary}"
    );
    assert!(text_summary.contains("runs excluded ("), "{text_summary}");
}
