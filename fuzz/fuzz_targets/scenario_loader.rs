//! Fuzz target `scenario_loader`: arbitrary bytes through the path the command line takes
//! with a scenario file.
//!
//! The bytes are written to a file and read back by `scenario::load` (size limit, UTF-8
//! check, YAML, validation) with default overrides, as `polhode run` / `check` do. A
//! scenario with a `montecarlo:` block then goes through `montecarlo::Prepared::new`, as
//! `polhode montecarlo` does (`montecarlo::load`), and the first runs of the campaign are
//! built (`Prepared::build_run`: the dispersions drawn and applied, the perturbed scenario
//! parsed again), which is everything a campaign does before integrating. With its
//! dispersions taken away, a campaign's run 0 must be the nominal scenario again (the same
//! settings, conditions, effectors and initial state, bit for bit).
//!
//! Properties:
//! - nothing panics, hangs or grows without bound (libFuzzer's -timeout and -rss_limit_mb);
//! - every error names the file: its `Display` starts with the path, its `file` field is
//!   the path, its message is not empty and carries no source snippet, and a line number it
//!   gives lies inside the text;
//! - without its dispersions, a campaign's run 0 is the nominal scenario.

#![no_main]

use libfuzzer_sys::fuzz_target;
use polhode::montecarlo::{InvalidDraws, Prepared};
use polhode::scenario::{self, Overrides, Scenario, ScenarioError};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Runs of a campaign built per input (each parses the perturbed scenario again).
const RUNS_BUILT: u64 = 3;

/// A directory of this process: `$POLHODE_FUZZ_TMP` (set by scripts/fuzz.sh), else
/// `/dev/shm` (no disk writes), else the system temporary directory.
fn scratch_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = std::env::var_os("POLHODE_FUZZ_TMP")
            .map(PathBuf::from)
            .unwrap_or_else(|| {
                let shm = PathBuf::from("/dev/shm");
                if shm.is_dir() {
                    shm
                } else {
                    std::env::temp_dir()
                }
            });
        let dir = base.join(format!("polhode-fuzz-scenario-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("cannot create the fuzzer's scratch directory");
        dir
    })
}

/// The number of lines of `text` as YAML counts them.
fn yaml_lines(text: &str) -> u32 {
    let b = text.as_bytes();
    let mut n = 1;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' || (c == b'\r' && b.get(i + 1) != Some(&b'\n')) {
            n += 1;
        }
    }
    n
}

/// Checks that an error names `path` and is located inside `text` (when `text` is known).
fn check_error(e: &ScenarioError, path: &Path, text: Option<&str>, stage: &str) {
    let shown = e.to_string();
    let name = path.display().to_string();
    assert!(
        shown.starts_with(&name),
        "{stage}: the error does not start with the file name {name:?}: {shown:?}"
    );
    assert_eq!(
        e.file, path,
        "{stage}: the error names another file: {shown:?}"
    );
    assert!(
        !e.message.trim().is_empty(),
        "{stage}: the error has no message: {shown:?}"
    );
    if let (Some(line), Some(text)) = (e.line, text) {
        // Lines are 1-based and counted as YAML does (a line break is CR LF, LF or a lone
        // CR); one past the last line is where an unterminated construct ends.
        let lines = yaml_lines(text);
        assert!(
            line >= 1 && line <= lines + 1,
            "{stage}: line {line} is outside the {lines}-line file: {shown:?}"
        );
    }
    // One message: the YAML library's source snippet (` --> <input>:L:C` and `  |` lines) is
    // dropped by scenario::parse; a snippet in the message means a path that forgot to.
    assert!(
        !e.message.contains("\n --> ") && !e.message.contains("\n  |"),
        "{stage}: the message carries the YAML library's snippet: {shown:?}"
    );
    if let Some(column) = e.column {
        assert!(column >= 1, "{stage}: column 0: {shown:?}");
    }
}

/// Asserts that two scenarios are the same as far as a run can tell.
fn same_scenario(a: &Scenario, b: &Scenario) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let state = |s: &Scenario| bits(&s.spacecraft.initial_state(&s.omega0, &s.attitude0));
    let names = |s: &Scenario| {
        s.spacecraft
            .effectors()
            .iter()
            .map(|e| e.name().to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(a.name, b.name);
    assert_eq!(a.description, b.description);
    assert_eq!(a.epoch_unix_ns, b.epoch_unix_ns);
    assert_eq!(a.duration.to_bits(), b.duration.to_bits(), "duration");
    assert_eq!(a.method, b.method, "method");
    assert_eq!(
        a.output_rate.to_bits(),
        b.output_rate.to_bits(),
        "output rate"
    );
    assert_eq!(a.scene_rate.to_bits(), b.scene_rate.to_bits(), "scene rate");
    assert_eq!(a.compression, b.compression);
    assert_eq!(a.mcap_path, b.mcap_path);
    assert_eq!(a.stop, b.stop, "stop conditions");
    assert_eq!(a.events, b.events, "events");
    assert_eq!(a.shape, b.shape, "shape");
    assert_eq!(names(a), names(b), "effectors");
    assert_eq!(state(a), state(b), "initial state");
    assert_eq!(
        bits(a.spacecraft.spin_axis.as_slice()),
        bits(b.spacecraft.spin_axis.as_slice()),
        "spin axis"
    );
    assert_eq!(
        a.spacecraft.hub_mass.map(f64::to_bits),
        b.spacecraft.hub_mass.map(f64::to_bits)
    );
    assert_eq!(
        bits(a.spacecraft.hub.inertia.as_slice()),
        bits(b.spacecraft.hub.inertia.as_slice()),
        "hub inertia"
    );
}

fuzz_target!(|data: &[u8]| {
    let path = scratch_dir().join("scenario.yaml");
    std::fs::write(&path, data).expect("cannot write the input file");
    let text = std::str::from_utf8(data).ok();
    let sc = match scenario::load(&path, &Overrides::default()) {
        Ok(sc) => sc,
        Err(e) => {
            check_error(&e, &path, text, "load");
            return;
        }
    };
    assert_eq!(
        Some(sc.source.as_str()),
        text,
        "the scenario's source is not the file"
    );
    if sc.montecarlo.is_none() {
        return;
    }
    // As montecarlo::load: the campaign is named by the path as given.
    let mut prep = match Prepared::new(sc, &path.display().to_string(), None, None) {
        Ok(p) => p,
        Err(e) => {
            check_error(&e, &path, text, "montecarlo");
            return;
        }
    };
    // What the campaign uses before it integrates: the ranking rule and the first runs.
    let rule = prep.rank_rule();
    assert!(rule.column < prep.columns.len());
    assert!(prep.transverse_column < prep.columns.len());
    for i in 0..prep.campaign.runs.min(RUNS_BUILT) {
        match prep.build_run(i) {
            Ok((run, inputs)) => {
                // run_one writes input k into column k: one input per dispersion column.
                assert_eq!(
                    inputs.len(),
                    prep.transverse_column,
                    "run {i}: {} inputs for {} dispersion columns",
                    inputs.len(),
                    prep.transverse_column
                );
                assert_eq!(run.path, path, "run {i} is named after another file");
            }
            Err(e) => assert!(
                !e.message.is_empty(),
                "run {i}: an invalid draw without a reason"
            ),
        }
    }
    // Without dispersions, a run is the nominal scenario: the campaign's way from the YAML
    // (a JSON tree, its text parsed again) must give the scenario back, or every run of the
    // campaign would be invalid (or differ from the scenario the campaign was checked on).
    let dispersions = std::mem::take(&mut prep.campaign.dispersions);
    let nominal = &prep.scenario;
    match prep.build_run(0) {
        Ok((run, inputs)) => {
            // No drawn inputs; under `invalid_draws: redraw` the run's count of redraws, 0.
            let expected: &[f64] = match prep.campaign.invalid_draws {
                InvalidDraws::Redraw => &[0.0],
                InvalidDraws::Exclude => &[],
            };
            assert_eq!(inputs, expected, "the nominal run's inputs");
            same_scenario(nominal, &run);
        }
        Err(e) => panic!(
            "the nominal scenario does not survive the campaign's YAML → JSON → scenario path: \
             {}",
            e.message
        ),
    }
    prep.campaign.dispersions = dispersions;
});
