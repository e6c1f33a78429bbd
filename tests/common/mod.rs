//! Helpers shared by the integration tests.
#![allow(dead_code)]

use polhode::model::Observation;
use polhode::scenario::{self, Overrides, Scenario};
use polhode::sim::{self, Control, Outcome};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// A sink that keeps every sample and event in memory.
pub type Recorder = polhode::sim::Memory;

/// Parses a scenario from YAML text.
pub fn scenario(yaml: &str) -> Scenario {
    scenario_with(yaml, &Overrides::default())
}

/// Parses a scenario from YAML text with overrides.
pub fn scenario_with(yaml: &str, ov: &Overrides) -> Scenario {
    scenario::parse(Path::new("test.yaml"), yaml.to_string(), ov)
        .unwrap_or_else(|e| panic!("test scenario invalid: {e}"))
}

/// Runs a scenario, keeping samples and events.
pub fn run(s: &Scenario) -> (Outcome, Recorder) {
    let mut rec = Recorder::default();
    let stop = AtomicBool::new(false);
    let out = sim::run(
        s,
        &mut rec,
        Control {
            interrupt: &stop,
            progress: None,
        },
    )
    .expect("in-memory sink cannot fail");
    (out, rec)
}

/// Runs a scenario, keeping samples, events and every sample's state vector.
pub fn run_with_states(s: &Scenario) -> (Outcome, Recorder) {
    let mut rec = Recorder::with_states();
    let out = sim::run(s, &mut rec, Control::uninterrupted()).expect("in-memory sink cannot fail");
    (out, rec)
}

/// A rigid-body scenario in YAML from its parts.
pub fn rigid_yaml(
    principal: [f64; 3],
    omega: [f64; 3],
    duration: f64,
    integrator: &str,
    extra: &str,
) -> String {
    format!(
        "name: t\nbody: {{principal: [{}, {}, {}]}}\ninitial: {{omega: [{:e}, {:e}, {:e}]}}\n\
         duration: {duration:e}\nintegrator: {integrator}\noutput: {{rate: 10}}\n{extra}",
        principal[0], principal[1], principal[2], omega[0], omega[1], omega[2]
    )
}

/// The energy balance's largest change from its first sample, and the kinetic energy's spread
/// (largest minus smallest), both as fractions of the first sample's kinetic energy T₀.
pub fn balance_drift_and_spread(samples: &[Observation]) -> (f64, f64) {
    let (e0, t0) = (samples[0].energy_balance(), samples[0].kinetic_energy);
    let mut worst: f64 = 0.0;
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for o in samples {
        worst = worst.max((o.energy_balance() - e0).abs() / t0);
        lo = lo.min(o.kinetic_energy);
        hi = hi.max(o.kinetic_energy);
    }
    (worst, (hi - lo) / t0)
}

/// The Python of the test venv (`.venv`, made by scripts/python-venv.sh), for the independent
/// readers in tests/python.
pub fn venv_python() -> std::path::PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    assert!(
        p.exists(),
        "{} is missing: run scripts/python-venv.sh (scripts/test.sh does it for you)",
        p.display()
    );
    p
}

/// A fresh, empty scratch directory for one test (`<temp>/<prefix>-<pid>-<name>`), removed
/// with what the test wrote there when the test ends, unless it failed: then it is kept, to be
/// looked at. Dereferences to its path.
pub struct Scratch(std::path::PathBuf);

impl Scratch {
    /// Creates it (emptied first, if a run with the same process id left it).
    pub fn new(prefix: &str, name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("{prefix}-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }
}

impl std::ops::Deref for Scratch {
    type Target = std::path::PathBuf;
    fn deref(&self) -> &std::path::PathBuf {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
