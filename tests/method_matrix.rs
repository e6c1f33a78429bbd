//! The method contract's differential check (docs/choosing-a-method.md, "What each method
//! supports"; docs/reliability.md): every shipped scenario under every method, over a
//! shortened horizon, either refused at load by the contract (src/sim/support.rs) or in
//! agreement with a tight dop853 reference within that method's own error:
//!
//! - adaptive methods at rtol 1e-9: within 1e-5 (hub rates relative to |ω₀|, and attitude in
//!   rad) over the horizon;
//! - fixed-step methods, run at h and h/2 (h from the scene's fastest eigenvalue): the h/2
//!   result within twice the distance between the two plus 1e-9. An order-p method's error at
//!   h/2 is that distance over 2^p − 1, so a method that converges passes with room, and one
//!   that ignores a feature converges to the wrong answer and fails;
//! - `exact`: within 1e-9;
//! - `averaged`: T and |H| within 1e-4 (its O(ε) error; the fast phase is not compared).
//!
//! The support table in docs/choosing-a-method.md and docs/reliability.md is generated here: `POLHODE_BLESS=1 cargo
//! test --release --test method_matrix` rewrites it (and docs/figures/method-matrix.csv, the
//! scene-by-method errors); without it the test fails when the table differs.

use polhode::bench::attitude_error;
use polhode::scenario::{self, Overrides, Scenario};
use polhode::sim::{self, Feature, Features, Linearisation, Method, Support};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A method as run here: its name on the command line, and its order or stages.
struct Setting {
    label: &'static str,
    method: &'static str,
    fixed: bool,
    order: Option<u32>,
    stages: Option<u32>,
}

const SETTINGS: [Setting; 11] = [
    adaptive("dopri5"),
    adaptive("dop853"),
    adaptive("radau5"),
    fixed("rk4", "rk4", None, None),
    fixed("gauss-1", "gauss", None, Some(1)),
    fixed("gauss-2", "gauss", None, Some(2)),
    fixed("lie", "lie", None, None),
    fixed("splitting-2", "splitting", Some(2), None),
    fixed("splitting-4", "splitting", Some(4), None),
    adaptive("exact"),
    adaptive("averaged"),
];

const fn adaptive(name: &'static str) -> Setting {
    Setting {
        label: name,
        method: name,
        fixed: false,
        order: None,
        stages: None,
    }
}

const fn fixed(
    label: &'static str,
    method: &'static str,
    order: Option<u32>,
    stages: Option<u32>,
) -> Setting {
    Setting {
        label,
        method,
        fixed: true,
        order,
        stages,
    }
}

/// Longest horizon (s) and most fixed steps per run.
const HORIZON: f64 = 10.0;
const MAX_STEPS: f64 = 4e4;

fn load(path: &Path, ov: &Overrides) -> Result<Scenario, String> {
    scenario::load(path, ov).map_err(|e| e.to_string())
}

/// Hub error of `y` against `r`: rates relative to `scale` (rad/s), attitude (rad).
fn hub_error(r: &[f64], y: &[f64], scale: f64) -> f64 {
    let dw = (0..3).map(|i| (y[i] - r[i]).powi(2)).sum::<f64>().sqrt() / scale;
    attitude_error(&r[3..7], &y[3..7]).max(dw)
}

/// What happened to one method on one scene.
enum Outcome {
    /// Refused at load or before the first step, with the reason.
    Refused(String),
    /// Ran: its error and the bound it had to meet.
    Ran { error: f64, bound: f64 },
}

struct Scene {
    name: String,
    features: Features,
    outcomes: Vec<Outcome>,
}

fn run_scene(path: &Path) -> Scene {
    let name = path.file_stem().unwrap().to_string_lossy().to_string();
    let base = load(path, &Overrides::default()).expect("a shipped scenario loads");
    let features = Features::of(&base.spacecraft, base.duration);
    let y0 = base.spacecraft.initial_state(&base.omega0, &base.attitude0);
    let rho = polhode::linearize::stiffness(&base.spacecraft, 0.0, &y0, base.duration)
        .spectral_radius
        .max(base.omega0.norm())
        .max(1e-3);
    // A step of 0.1/|λ|: inside every explicit method's stability bound (2.78 and up); and
    // short enough that neither the horizon nor the breakpoints (a controller's ticks) cut
    // the steps at h and at h/2 to the same grid, which would hide the error.
    let horizon = base.duration.min(HORIZON).min(MAX_STEPS * 0.05 / rho);
    let first_breakpoint = base
        .spacecraft
        .next_breakpoint(0.0)
        .unwrap_or(f64::INFINITY);
    let h = (0.1 / rho).min(horizon / 20.0).min(first_breakpoint / 4.0);
    let with = |method: &str, dt: Option<f64>, s: &Setting, rtol: f64| Overrides {
        method: Some(method.into()),
        dt,
        rtol: (!s.fixed && method != "exact").then_some(rtol),
        atol: (!s.fixed && method != "exact").then_some(rtol * 1e-3),
        order: s.order,
        stages: s.stages,
        duration: Some(horizon),
        ..Overrides::default()
    };
    let solve = |ov: &Overrides| -> Result<(Scenario, Vec<f64>), String> {
        let s = load(path, ov)?;
        let y = sim::integrate_only(&s, horizon)?.final_state;
        Ok((s, y))
    };
    let reference_setting = adaptive("dop853");
    let (_, reference) = solve(&with("dop853", None, &reference_setting, 1e-12))
        .unwrap_or_else(|e| panic!("{name}: the reference failed: {e}"));
    // Rates relative to the larger of |ω| at the start and the end (a spin-up starts at rest).
    let end_rate = (0..3).map(|i| reference[i].powi(2)).sum::<f64>().sqrt();
    let scale = base.omega0.norm().max(end_rate).max(1e-9);
    let mut outcomes = Vec::new();
    for s in &SETTINGS {
        let outcome = if s.fixed {
            let coarse = solve(&with(s.method, Some(h), s, 0.0));
            let fine = solve(&with(s.method, Some(h / 2.0), s, 0.0));
            match (coarse, fine) {
                (Ok((_, yc)), Ok((_, yf))) => Outcome::Ran {
                    error: hub_error(&reference, &yf, scale),
                    bound: 2.0 * hub_error(&yc, &yf, scale) + 1e-9,
                },
                (Err(e), _) | (_, Err(e)) => Outcome::Refused(e),
            }
        } else {
            match solve(&with(s.method, None, s, 1e-9)) {
                Ok((sc, y)) if s.method == "averaged" => {
                    let a = sc.spacecraft.observe(horizon, &y);
                    let r = sc.spacecraft.observe(horizon, &reference);
                    let error = ((a.kinetic_energy - r.kinetic_energy) / r.kinetic_energy)
                        .abs()
                        .max(((a.h_norm - r.h_norm) / r.h_norm).abs());
                    Outcome::Ran { error, bound: 1e-4 }
                }
                Ok((_, y)) => Outcome::Ran {
                    error: hub_error(&reference, &y, scale),
                    bound: if s.method == "exact" { 1e-9 } else { 1e-5 },
                },
                Err(e) => Outcome::Refused(e),
            }
        };
        outcomes.push(outcome);
    }
    Scene {
        name,
        features,
        outcomes,
    }
}

/// The method each setting stands for, as the contract sees it.
fn method_of(label: &str) -> Method {
    let a = polhode::sim::Adaptive {
        rtol: 1e-9,
        atol: 1e-12,
        max_step: f64::INFINITY,
    };
    match label {
        "dopri5" => Method::Dopri5(a),
        "dop853" => Method::Dop853(a),
        "radau5" => Method::Radau5(a),
        "rk4" => Method::Rk4 { dt: 0.1 },
        "gauss-1" => Method::Gauss { dt: 0.1, stages: 1 },
        "gauss-2" => Method::Gauss { dt: 0.1, stages: 2 },
        "lie" => Method::Lie { dt: 0.1 },
        "splitting-2" => Method::Splitting { dt: 0.1, order: 2 },
        "splitting-4" => Method::Splitting { dt: 0.1, order: 4 },
        "exact" => Method::Exact,
        _ => Method::Averaged(a),
    }
}

fn scenario_paths() -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(root().join("scenarios"))
        .expect("scenarios/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "yaml"))
        .collect();
    paths.sort();
    paths
}

/// The support table (markdown), from the contract and what the scenes showed.
fn support_table(scenes: &[Scene]) -> String {
    let mut t = String::from("| method |");
    for f in Feature::ALL {
        let _ = write!(t, " {} |", f.label());
    }
    t.push_str("\n|---|");
    for _ in Feature::ALL {
        t.push_str("---|");
    }
    t.push('\n');
    for (k, s) in SETTINGS.iter().enumerate() {
        let method = method_of(s.label);
        let _ = write!(t, "| `{}` |", s.label);
        for f in Feature::ALL {
            let with: Vec<&Scene> = scenes.iter().filter(|sc| sc.features.has(f)).collect();
            let ran = with
                .iter()
                .filter(|sc| matches!(sc.outcomes[k], Outcome::Ran { .. }))
                .count();
            let cell = sim::support(&method, f).cell();
            let _ = write!(t, " {cell} ({ran}/{} ran) |", with.len());
        }
        t.push('\n');
    }
    for kind in Linearisation::ALL {
        let _ = write!(t, "| {} |", kind.label());
        for f in Feature::ALL {
            let _ = write!(t, " {} |", sim::linearize_support(kind, f).cell());
        }
        t.push('\n');
    }
    t
}

/// Replaces the block between the markers in `doc` with `body`.
fn splice(doc: &str, begin: &str, end: &str, body: &str) -> String {
    let a = doc.find(begin).expect("begin marker") + begin.len();
    let b = doc.find(end).expect("end marker");
    format!("{}\n{}{}", &doc[..a], body, &doc[b..])
}

#[test]
fn every_scenario_under_every_method_agrees_with_dop853_or_is_refused_by_the_contract() {
    let scenes: Vec<Scene> = scenario_paths().iter().map(|p| run_scene(p)).collect();
    let mut failures = Vec::new();
    let mut csv = String::from("scenario");
    for s in &SETTINGS {
        let _ = write!(csv, ",{}", s.label);
    }
    csv.push('\n');
    for scene in &scenes {
        csv.push_str(&scene.name);
        for (s, outcome) in SETTINGS.iter().zip(&scene.outcomes) {
            let method = method_of(s.label);
            let contract_refuses = Feature::ALL
                .iter()
                .any(|&f| scene.features.has(f) && sim::support(&method, f) == Support::No);
            match outcome {
                Outcome::Ran { error, bound } => {
                    let _ = write!(csv, ",{error:.1e}");
                    if contract_refuses {
                        failures.push(format!(
                            "{} {}: ran, but the contract says it refuses this scene",
                            scene.name, s.label
                        ));
                    }
                    // NaN fails too.
                    if error.is_nan() || *error > *bound {
                        failures.push(format!(
                            "{} {}: error {error:.3e} beyond its bound {bound:.3e}",
                            scene.name, s.label
                        ));
                    }
                }
                Outcome::Refused(why) => {
                    csv.push_str(",refused");
                    // A refusal must come from the contract, naming the method; or be the
                    // averaged method's own ("partly" in the table: its effectors, ε, the
                    // separatrix, a periodic orbit it cannot find), refused before the
                    // first step or stopped with a diagnosis.
                    let averaged_partly = s.method == "averaged" && !contract_refuses;
                    let named = why.contains(&format!("method `{}`", s.method));
                    if !(contract_refuses && named || averaged_partly) {
                        failures.push(format!(
                            "{} {}: refused outside the contract: {why}",
                            scene.name, s.label
                        ));
                    }
                }
            }
        }
        csv.push('\n');
    }
    let table = support_table(&scenes);
    let (begin, end) = (
        "<!-- support table: generated by tests/method_matrix.rs -->",
        "<!-- end of support table -->",
    );
    let bless = std::env::var_os("POLHODE_BLESS").is_some();
    for doc in ["docs/choosing-a-method.md", "docs/reliability.md"] {
        let doc_path = root().join(doc);
        let text = std::fs::read_to_string(&doc_path).expect("the doc");
        let updated = splice(&text, begin, end, &table);
        if bless {
            std::fs::write(&doc_path, &updated).expect("write the doc");
        } else if updated != text {
            failures.push(format!(
                "{doc}'s support table is stale; regenerate it with POLHODE_BLESS=1 cargo \
                 test --release --test method_matrix. It should read:\n{table}"
            ));
        }
    }
    if bless {
        std::fs::write(root().join("docs/figures/method-matrix.csv"), &csv).expect("csv");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
