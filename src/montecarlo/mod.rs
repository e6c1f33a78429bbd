//! Monte Carlo campaigns over perturbed scenarios (`polhode montecarlo`, `polhode merge`;
//! documented in `docs/montecarlo.md` and `docs/cluster.md`).
//!
//! Run i draws from the ChaCha8 stream (seed, i): its draws depend on nothing else, so a
//! campaign gives the same table whatever the thread count, the order of the runs or the way
//! it is split into shards. Runs are independent and single-threaded; rayon spreads them over
//! the cores, a block of runs at a time, and the finished rows go to the writers in run order:
//! a campaign's memory does not grow with its number of runs.

mod covariance;
mod dispersion;
pub mod output;
pub mod runs;
mod second_moments;
mod select;
mod spec;
mod summary;
pub mod table;

pub use crate::scenario::campaign::CampaignFile;
pub use dispersion::{Dispersion, Distribution, Target, erfc, normal_mass};
pub use spec::{Campaign, InvalidDraws, MAX_DRAWS_PER_RUN, MAX_RUNS};
pub use summary::{percentile, wilson95};
pub use table::{Row, RunStatus};

use crate::lanes::ensemble::Engine;
use crate::log::telemetry;
use crate::model::Observation;
use crate::scenario::{self, Overrides, Quantity, Scenario, ScenarioError};
use crate::sim::{self, Control, EventRecord, Reference, Sink, Status};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::ops::Range;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Runs a campaign runs in parallel before their rows are written: the most rows it holds.
/// Each block ends when its slowest run does, which costs at most about one run's time per
/// thread and block.
pub const BLOCK_RUNS: u64 = 4096;

/// Most runs per thread in a block for which the runs are ordered by their expected cost
/// (see `Prepared::longest_first`).
pub const ORDERED_RUNS_PER_THREAD: usize = 32;

/// Most runs integrated together in one lockstep of lanes (a chunk), and the most runs of a
/// block ordered by their expected cost when the campaign runs in lanes, whatever the thread
/// count: a chunk's lanes idle from the moment its last run starts until its longest
/// remaining run ends, so its runs are best many and longest first.
pub const LANE_CHUNK_RUNS: usize = 128;

/// Worker threads allowed per logical core: a campaign asking for more threads than
/// [`max_threads`] gets that many. Threads beyond the cores only add contention (rayon's own
/// default is one per logical core), and a pool of 10⁵ threads takes minutes to start, during
/// which nothing answers Ctrl-C or SIGTERM.
pub const THREADS_PER_CORE: usize = 4;

/// The logical cores of this machine (1 when unknown).
pub fn logical_cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}

/// The most worker threads a campaign uses: [`THREADS_PER_CORE`] × the logical cores.
pub fn max_threads() -> usize {
    THREADS_PER_CORE * logical_cores()
}

/// The worker threads for a requested count (`None`: one per logical core), with a note when
/// the request was above [`max_threads`] and was capped; `what` names the option in messages
/// (`--threads`, `threads`). `Err` for 0.
pub fn thread_count(
    requested: Option<usize>,
    what: &str,
) -> Result<(usize, Option<String>), String> {
    let cap = max_threads();
    match requested {
        None => Ok((logical_cores(), None)),
        Some(0) => Err(format!("{what}: expected at least 1, got 0")),
        Some(t) if t > cap => Ok((
            cap,
            Some(format!(
                "{what} {t}: capped at {cap} ({THREADS_PER_CORE} × {} logical cores); more \
                 threads than cores only add contention",
                logical_cores()
            )),
        )),
        Some(t) => Ok((t, None)),
    }
}

/// A run as [`Prepared::build_run`] builds it.
type Built = Result<(Scenario, Vec<f64>), InvalidDraw>;

/// A campaign ready to run: the nominal scenario, its tree, the checked campaign and the
/// table's columns.
#[derive(Debug)]
pub struct Prepared {
    /// The nominal scenario.
    pub scenario: Scenario,
    /// The campaign settings.
    pub campaign: Campaign,
    /// The scenario as a JSON tree without its `montecarlo` block.
    tree: Value,
    /// Columns after `run`, `status`, `message`.
    pub columns: Vec<String>,
    /// Hex SHA-256 of the scenario file's text.
    pub scenario_sha256: String,
    /// The scenario file as named on the command line (recorded, and used in messages).
    pub scenario_file: String,
    /// Column of the event that stands for the flat spin (charts, ranking), if any.
    pub primary_event: Option<usize>,
    /// Column of the initial transverse rate.
    pub transverse_column: usize,
    /// The conditions of the event columns.
    pub event_conditions: Vec<String>,
    /// First event column (the event columns follow in the order of `event_conditions`).
    pub event_start: usize,
    /// Column of the largest nutation.
    max_nutation_column: usize,
    /// The method every run uses instead of the scenario's (`--method`), if any.
    pub method: Option<String>,
    /// Column counting the draws a run rejected (`redraws`), under `invalid_draws: redraw`.
    run_redraw_column: Option<usize>,
    /// Columns counting a dispersion's own redraws (`inertia_redraws`).
    redraw_columns: Vec<usize>,
    /// How the runs are integrated: in lanes where the scene has a lane form.
    pub integration: Integration,
    /// Whether lanes are wanted where the scene has a lane form (`--no-lanes` clears it).
    lanes_wanted: bool,
    /// The lane engine asked for (`--lane-width`; default the widest this processor has).
    lane_engine: Engine,
}

/// How a campaign's runs are integrated on each thread.
#[derive(Debug, Clone, PartialEq)]
pub enum Integration {
    /// Several runs at once in lockstep lanes with this engine (`crate::lanes`); a run the
    /// lanes cannot take (its perturbed scene has no lane form, or the lanes decline it
    /// part-way) takes the scalar path. Every run's row is the scalar path's.
    Lanes(Engine),
    /// One run after another, and why not in lanes.
    Scalar(String),
}

impl Integration {
    /// How the runs of `scenario` are integrated on this processor, in lanes with `engine`
    /// (or the nearest it has) where the scene has a lane form.
    pub fn of(scenario: &Scenario, engine: Engine) -> Self {
        use crate::lanes::ensemble::resolved;
        match sim::lane_form(scenario) {
            Ok(_) => Integration::Lanes(resolved(engine)),
            Err(why) => Integration::Scalar(format!("the scene has no lane form: {why}")),
        }
    }

    /// A line for the campaign's header: where the runs go and why.
    pub fn describe(&self) -> String {
        match self {
            Integration::Lanes(Engine::Avx512) => {
                "in lockstep lanes, eight runs at once per thread (AVX-512)".into()
            }
            Integration::Lanes(Engine::Avx2) => {
                "in lockstep lanes, four runs at once per thread (AVX2)".into()
            }
            Integration::Lanes(Engine::Portable4) => {
                "in lockstep lanes, four runs at once per thread (SSE2)".into()
            }
            Integration::Lanes(_) => {
                "in a lockstep lane, one run at a time per thread (this processor has no AVX2)"
                    .into()
            }
            Integration::Scalar(why) => format!("one run at a time per thread ({why})"),
        }
    }
}

/// Hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// `bytes` (a digest) in lower-case hex.
pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A column name made of letters, digits and `_`.
fn identifier(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c);
        } else if c == '.' || c == '-' {
            out.push(if c == '-' { 'm' } else { 'p' });
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_end_matches('_').to_string()
}

impl Prepared {
    /// Checks the `montecarlo:` block of `scenario` (loaded from `scenario_file`) and lays out
    /// the table. `runs` and `seed` override the block's values.
    pub fn new(
        scenario: Scenario,
        scenario_file: &str,
        runs: Option<u64>,
        seed: Option<u64>,
    ) -> Result<Self, ScenarioError> {
        let path = scenario.path.clone();
        let Some(file) = &scenario.montecarlo else {
            return Err(ScenarioError::whole_file(
                &path,
                "expected a `montecarlo:` block with `runs` and `dispersions` (see \
                 docs/montecarlo.md)",
            ));
        };
        // Runs are built from the scenario's YAML tree. The tree holds JSON values, so text
        // that reads as a number (`name: 1e2`, `name: .nan`) would come back as another text
        // or not at all: such values must be quoted.
        const QUOTE: &str = "a text value in this scenario reads as a number (e.g. `name: 1e2`, \
                             `name: 0x1F`, `name: .nan`); quote it (`name: \"1e2\"`) to run a \
                             campaign";
        let mut tree: Value =
            serde_saphyr::from_str_with_options(&scenario.source, crate::scenario::yaml_options())
                .map_err(|e| {
                    let first = e.without_snippet().to_string();
                    let first = first.lines().next().unwrap_or("").to_string();
                    let location = e.location().map(|l| (l.line() as u32, l.column() as u32));
                    // A number that is not finite (`.nan`, `.inf`) where a number is expected
                    // (`probability_by: [.nan]`) is that, not text reading as a number.
                    let line = location.and_then(|(l, _)| {
                        crate::scenario::yaml_line(&scenario.source, l).map(|t| (l, t))
                    });
                    if let Some((l, text)) = line {
                        let lower = text.to_ascii_lowercase();
                        let key = lower
                            .split(':')
                            .next()
                            .unwrap_or("")
                            .trim()
                            .trim_start_matches("- ");
                        if key != "name"
                            && let Some(k) = [".nan", ".inf", "-.inf", "+.inf"]
                                .iter()
                                .filter_map(|w| lower.find(w))
                                .min()
                        {
                            let column = text[..k].chars().count() as u32 + 1;
                            let word: String = text[k..]
                                .chars()
                                .take_while(|c| !matches!(c, ',' | ']' | '}' | ' '))
                                .collect();
                            return ScenarioError::at(
                                &path,
                                Some((l, column)),
                                crate::scenario::field_path_at(&scenario.source, l, column),
                                format!("expected a finite number, got `{word}`"),
                            );
                        }
                    }
                    ScenarioError::at(&path, location, "", format!("{QUOTE} ({first})"))
                })?;
        if let Some(map) = tree.as_object_mut() {
            map.remove("montecarlo");
        }
        let text = serde_json::to_string(&tree).unwrap_or_default();
        let same = match scenario::parse(&path, text, &Overrides::default()) {
            Ok(back) => {
                let names = |s: &Scenario| -> Vec<String> {
                    s.spacecraft
                        .effectors()
                        .iter()
                        .map(|e| e.name().to_string())
                        .collect()
                };
                back.name == scenario.name
                    && back.description == scenario.description
                    && back.mcap_path == scenario.mcap_path
                    && back.epoch_unix_ns == scenario.epoch_unix_ns
                    && back.method.describe() == scenario.method.describe()
                    && names(&back) == names(&scenario)
            }
            Err(_) => false,
        };
        let block = crate::scenario::key_location(&scenario.source, "montecarlo");
        if !same {
            return Err(ScenarioError::at(&path, block, "montecarlo", QUOTE));
        }
        let mut campaign = Campaign::new(&path, file, &tree, scenario.duration)?;
        if let Some(r) = runs {
            if r == 0 || r > MAX_RUNS {
                return Err(ScenarioError::whole_file(
                    &path,
                    format!("--runs: expected 1 to {MAX_RUNS}, got {r}"),
                ));
            }
            campaign.runs = r;
        }
        if let Some(s) = seed {
            campaign.seed = s;
        }
        // The dispersions applied in order to the nominal tree (with throwaway draws): each
        // must still find its field when its turn comes (an `inertia` dispersion replaces
        // `body.principal` by `body.inertia`), and none may touch the conditions that name
        // the table's columns.
        let mut trial = tree.clone();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        for (k, d) in campaign.dispersions.iter().enumerate() {
            let field = format!("montecarlo.dispersions[{k}]");
            for (label, p) in d.path_targets() {
                if p.pointer.starts_with("/events/") || p.pointer.starts_with("/stop/") {
                    return Err(ScenarioError::at(
                        &path,
                        d.at,
                        format!("{field}.path"),
                        "event and stop conditions name the table's columns and cannot be \
                         dispersed",
                    ));
                }
                let shape = match trial.pointer(&p.pointer) {
                    Some(Value::Array(a)) if a.iter().all(Value::is_number) => Some(a.len()),
                    Some(Value::Number(_)) => Some(1),
                    _ => None,
                };
                if shape != Some(p.len) {
                    return Err(ScenarioError::at(
                        &path,
                        d.at,
                        format!("{field}.path"),
                        format!(
                            "`{label}` is no longer there when this dispersion applies: an \
                             earlier one replaced it (`inertia` turns `body.principal` into \
                             `body.inertia`); list this dispersion before that one"
                        ),
                    ));
                }
            }
            let mut scratch = Vec::new();
            // A failed throwaway draw says nothing about the structure; real draws report it.
            let _ = d.apply(&mut trial, &mut rng, &mut scratch);
        }
        // Each perturbed field must take a continuous value: the nominal value written as a
        // floating-point number (4 → 4.0) must still load; a count or a stage number fails.
        for (k, d) in campaign.dispersions.iter().enumerate() {
            for (label, p) in d.path_targets() {
                let mut probe = tree.clone();
                let x0 = p.nominal(&probe);
                let as_float: Vec<Value> = x0.iter().map(|x| serde_json::json!(x)).collect();
                if let Some(slot) = probe.pointer_mut(&p.pointer) {
                    *slot = if p.is_list {
                        Value::Array(as_float)
                    } else {
                        as_float[0].clone()
                    };
                }
                let text = serde_json::to_string(&probe).unwrap_or_default();
                if let Err(e) = scenario::parse(&path, text, &Overrides::default()) {
                    return Err(ScenarioError::at(
                        &path,
                        d.at,
                        format!("montecarlo.dispersions[{k}].path"),
                        format!(
                            "`{label}` does not take a continuous value ({}), so it \
                             cannot be dispersed",
                            e.message
                        ),
                    ));
                }
            }
        }
        // A field perturbed twice (a tilt, then a magnitude) records the value after each;
        // the later columns are told apart by `@k`, k the dispersion's index.
        let mut columns: Vec<String> = Vec::new();
        let mut redraw_columns = Vec::new();
        for (k, d) in campaign.dispersions.iter().enumerate() {
            for (m, c) in d.columns().into_iter().enumerate() {
                if d.redraw_column() == Some(m) {
                    redraw_columns.push(columns.len());
                }
                if columns.contains(&c) {
                    columns.push(format!("{c}@{k}"));
                } else {
                    columns.push(c);
                }
            }
        }
        // Under `invalid_draws: redraw`, the draws each run rejected before its valid one.
        let run_redraw_column = (campaign.invalid_draws == InvalidDraws::Redraw).then(|| {
            columns.push("redraws".into());
            columns.len() - 1
        });
        let transverse_column = columns.len();
        columns.push("initial_transverse_rate".into());
        let event_start = columns.len();
        let event_conditions: Vec<String> = scenario.events.iter().map(|c| c.describe()).collect();
        for c in &event_conditions {
            columns.push(format!("t_{}", identifier(c)));
        }
        let max_nutation_column = columns.len() + 1;
        columns.extend(
            [
                "final_nutation_deg",
                "max_nutation_deg",
                "final_spin_axis_x",
                "final_spin_axis_y",
                "final_spin_axis_z",
                "kinetic_energy_lost",
                "energy_dissipated",
            ]
            .map(String::from),
        );
        for &f in &campaign.final_telemetry {
            columns.push(format!("final_{}", telemetry::FIELDS[f]));
        }
        columns.extend(["end_time", "steps", "rhs_evaluations"].map(String::from));
        let mut seen = std::collections::BTreeSet::new();
        for c in &columns {
            if !seen.insert(c.as_str()) {
                return Err(ScenarioError::at(
                    &path,
                    block,
                    "montecarlo.dispersions",
                    format!(
                        "two table columns would be named `{c}`; a dispersion path must not \
                         be named like a metric column"
                    ),
                ));
            }
        }
        // The flat spin: the nutation event with the highest `above` threshold.
        let primary_event = scenario
            .events
            .iter()
            .enumerate()
            .filter(|(_, c)| c.quantity == Quantity::NutationAngleDeg && c.above)
            .max_by(|a, b| a.1.threshold.total_cmp(&b.1.threshold))
            .map(|(k, _)| event_start + k);
        Ok(Prepared {
            scenario_sha256: sha256_hex(scenario.source.as_bytes()),
            scenario_file: scenario_file.to_string(),
            scenario,
            campaign,
            tree,
            columns,
            primary_event,
            transverse_column,
            event_conditions,
            event_start,
            max_nutation_column,
            method: None,
            run_redraw_column,
            redraw_columns,
            integration: Integration::Scalar(String::new()),
            lanes_wanted: true,
            lane_engine: Engine::Auto,
        }
        .with_integration(true))
    }

    /// Runs in lanes where the nominal scene has a lane form (`lanes`), or every run on the
    /// scalar path (`!lanes`, `--no-lanes`).
    pub fn with_integration(mut self, lanes: bool) -> Self {
        self.lanes_wanted = lanes;
        self.integration = if lanes {
            Integration::of(&self.scenario, self.lane_engine)
        } else {
            Integration::Scalar("--no-lanes".into())
        };
        self
    }

    /// Lanes with `engine` (or the nearest this processor has) instead of the widest
    /// (`--lane-width`; the rows are the same).
    pub fn with_lane_engine(mut self, engine: Engine) -> Self {
        self.lane_engine = engine;
        let lanes = self.lanes_wanted;
        self.with_integration(lanes)
    }

    /// The random stream of run `i`: ChaCha8 seeded with the campaign seed, stream `i`.
    pub fn stream(&self, i: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(self.campaign.seed);
        rng.set_stream(i);
        rng
    }

    /// Every run with `method` (a method name, as `--method`) instead of the scenario's,
    /// checked on the nominal scenario (e.g. `averaged` on a scene it cannot treat).
    pub fn with_method(mut self, method: Option<String>) -> Result<Self, ScenarioError> {
        if let Some(m) = &method {
            let text = serde_json::to_string(&self.tree).unwrap_or_default();
            let ov = Overrides {
                method: Some(m.clone()),
                ..Overrides::default()
            };
            let nominal = scenario::parse(&self.scenario.path, text, &ov)?;
            self.scenario.simulation.method = nominal.simulation.method;
        }
        self.method = method;
        let lanes = self.lanes_wanted;
        Ok(self.with_integration(lanes))
    }

    /// The perturbed scenario of run `i` and the recorded inputs (the dispersions' columns,
    /// then under `invalid_draws: redraw` the number of draws rejected). Under `redraw`, a
    /// draw that is not a valid scenario is followed by the next draw of the run's own
    /// stream, up to [`MAX_DRAWS_PER_RUN`] draws: the result still depends on (seed, i)
    /// alone.
    pub fn build_run(&self, i: u64) -> Result<(Scenario, Vec<f64>), InvalidDraw> {
        let mut rng = self.stream(i);
        let redraw = self.campaign.invalid_draws == InvalidDraws::Redraw;
        let mut rejected = 0u32;
        loop {
            match self.draw_once(&mut rng) {
                Ok((sc, mut inputs)) => {
                    if redraw {
                        inputs.push(f64::from(rejected));
                    }
                    return Ok((sc, inputs));
                }
                Err(_) if redraw && rejected + 1 < MAX_DRAWS_PER_RUN => rejected += 1,
                Err(mut e) => {
                    if redraw {
                        e.message = format!(
                            "no valid draw in {MAX_DRAWS_PER_RUN} (invalid_draws: redraw); the \
                             last: {}",
                            e.message
                        );
                        e.redraws = Some(rejected + 1);
                    }
                    return Err(e);
                }
            }
        }
    }

    /// One draw of every dispersion from `rng`, and the scenario it gives.
    fn draw_once(&self, rng: &mut ChaCha8Rng) -> Result<(Scenario, Vec<f64>), InvalidDraw> {
        let mut tree = self.tree.clone();
        let mut inputs = Vec::new();
        for d in &self.campaign.dispersions {
            if let Err(message) = d.apply(&mut tree, rng, &mut inputs) {
                return Err(InvalidDraw {
                    message,
                    inputs,
                    redraws: None,
                });
            }
        }
        let parsed = serde_json::to_string(&tree)
            .map_err(|e| e.to_string())
            .and_then(|text| {
                let ov = Overrides {
                    method: self.method.clone(),
                    ..Overrides::default()
                };
                scenario::parse(&self.scenario.path, text, &ov)
                    .map_err(|e| format!("the perturbed scenario is not valid: {}", e.message))
            });
        match parsed {
            Ok(mut sc) => {
                sc.path = self.scenario_file.clone().into();
                Ok((sc, inputs))
            }
            Err(message) => Err(InvalidDraw {
                message,
                inputs,
                redraws: None,
            }),
        }
    }

    /// Runs `i` to the end; `None` if it was interrupted (it is then not part of the result).
    pub fn run_one(&self, i: u64, interrupt: &AtomicBool) -> Option<Row> {
        self.run_built(i, self.build_run(i), interrupt)
    }

    /// [`Prepared::run_one`] with run `i` already built (by [`Prepared::build_run`]).
    fn run_built(&self, i: u64, built: Built, interrupt: &AtomicBool) -> Option<Row> {
        let (sc, values) = match self.ready(i, built) {
            Ok(x) => x,
            Err(row) => return Some(*row),
        };
        self.run_scalar(i, &sc, values, interrupt)
    }

    /// Run `i` integrated on the scalar path.
    fn run_scalar(
        &self,
        i: u64,
        sc: &Scenario,
        values: Vec<Option<f64>>,
        interrupt: &AtomicBool,
    ) -> Option<Row> {
        let mut sink = Extremes::default();
        let ctl = Control {
            interrupt,
            progress: None,
        };
        let outcome = sim::run(sc, &mut sink, ctl);
        self.row(i, values, outcome, &sink)
    }

    /// The runs `chunk` (each index with its build) integrated together in lanes with
    /// `engine`; a run the lanes do not take is integrated on the scalar path. The rows are
    /// in the order of `chunk` (`None`: interrupted).
    fn run_in_lanes(
        &self,
        engine: Engine,
        chunk: Vec<(u64, Built)>,
        interrupt: &AtomicBool,
    ) -> Vec<Option<Row>> {
        let mut rows: Vec<Option<Row>> = Vec::with_capacity(chunk.len());
        let mut ready = Vec::new();
        for (k, (i, built)) in chunk.into_iter().enumerate() {
            match self.ready(i, built) {
                Ok((sc, values)) => {
                    rows.push(None);
                    ready.push((k, i, sc, values));
                }
                Err(row) => rows.push(Some(*row)),
            }
        }
        let sims: Vec<&sim::Simulation> = ready.iter().map(|r| &*r.2).collect();
        // A sink error cannot happen (the extremes sink writes nothing); if one did, the
        // scalar path would report it run by run.
        let results = sim::run_in_lanes::<Extremes>(engine, &sims, interrupt)
            .unwrap_or_else(|_| (0..sims.len()).map(|_| None).collect());
        for ((k, i, sc, values), result) in ready.into_iter().zip(results) {
            rows[k] = match result {
                Some((outcome, sink)) => self.row(i, values, Ok(outcome), &sink),
                None => self.run_scalar(i, &sc, values, interrupt),
            };
        }
        rows
    }

    /// Run `i`'s scenario, ready to integrate, and its row's values so far (the inputs and
    /// the initial transverse rate); `Err`: the row of an invalid draw.
    #[allow(clippy::result_large_err)]
    fn ready(&self, i: u64, built: Built) -> Result<(Scenario, Vec<Option<f64>>), Box<Row>> {
        let mut values = vec![None; self.columns.len()];
        let (sc, inputs) = match built {
            Ok(x) => x,
            Err(InvalidDraw {
                message,
                inputs,
                redraws,
            }) => {
                // Keep what was drawn, so the table shows which draw was invalid.
                for (k, v) in inputs.iter().enumerate() {
                    values[k] = Some(*v);
                }
                if let (Some(j), Some(n)) = (self.run_redraw_column, redraws) {
                    values[j] = Some(f64::from(n));
                }
                return Err(Box::new(Row {
                    run: i,
                    status: RunStatus::Invalid,
                    message,
                    values,
                }));
            }
        };
        for (k, v) in inputs.iter().enumerate() {
            values[k] = Some(*v);
        }
        let s = sc.spacecraft.spin_axis.normalize();
        let w = sc.omega0;
        values[self.transverse_column] = Some((w - s * w.dot(&s)).norm());
        let mut sc = sc;
        if matches!(sc.method, crate::sim::Method::Averaged(_)) {
            // The averaged method's cost is its slow steps; rebuilding the state on the output
            // grid would cost more than the run. The largest nutation is then taken at t = 0,
            // the end and the events (docs/montecarlo.md).
            sc.simulation.output_rate = 1.0 / sc.duration;
        }
        Ok((sc, values))
    }

    /// Run `i`'s row from its `values` so far, the outcome of its integration and what its
    /// sink saw.
    fn row(
        &self,
        i: u64,
        mut values: Vec<Option<f64>>,
        outcome: std::io::Result<sim::Outcome>,
        sink: &Extremes,
    ) -> Option<Row> {
        let outcome = match outcome {
            Ok(o) => o,
            Err(e) => {
                return Some(Row {
                    run: i,
                    status: RunStatus::Failed,
                    message: e.to_string(),
                    values,
                });
            }
        };
        let (status, message) = match &outcome.status {
            Status::Complete => (RunStatus::Complete, String::new()),
            Status::Stopped { condition } => (RunStatus::Stopped, condition.clone()),
            Status::Interrupted => return None,
            Status::Failed { diagnosis } => (RunStatus::Failed, diagnosis.clone()),
            Status::InvalidModel { diagnosis } => (RunStatus::InvalidModel, diagnosis.clone()),
        };
        for (k, c) in self.event_conditions.iter().enumerate() {
            values[self.event_start + k] = outcome
                .events
                .iter()
                .find(|e| &e.condition == c)
                .map(|e| e.t);
        }
        let o = &outcome.final_observation;
        let o0 = &outcome.initial_observation;
        let axis = o.omega.try_normalize(0.0).unwrap_or_default();
        let mut at = self.max_nutation_column - 1;
        for v in [
            o.nutation_angle.to_degrees(),
            sink.max_nutation.max(o.nutation_angle).to_degrees(),
            axis[0],
            axis[1],
            axis[2],
            o0.kinetic_energy - o.kinetic_energy,
            o.dissipated_energy,
        ] {
            values[at] = Some(v);
            at += 1;
        }
        let tel = telemetry::values(o, &Reference::of(o0));
        for &f in &self.campaign.final_telemetry {
            values[at] = Some(tel[f]);
            at += 1;
        }
        values[at] = Some(o.t);
        values[at + 1] = Some(outcome.stats.steps as f64);
        values[at + 2] = Some(outcome.stats.rhs_evaluations as f64);
        Some(Row {
            run: i,
            status,
            message,
            values,
        })
    }

    /// Runs `range` on `threads` threads. Calls `on_row` as each run finishes (from any
    /// thread). Returns the finished runs in run order and whether any run was skipped or cut
    /// short by `interrupt`.
    pub fn execute(
        &self,
        range: Range<u64>,
        threads: usize,
        interrupt: &AtomicBool,
        on_row: &(dyn Fn(&Row) + Sync),
    ) -> Result<(Vec<Row>, bool), String> {
        let mut rows = Vec::new();
        let partial = self.execute_streaming(range, threads, interrupt, on_row, &mut |r| {
            rows.push(r);
            Ok(())
        })?;
        Ok((rows, partial))
    }

    /// Runs `range` on `threads` threads, [`BLOCK_RUNS`] runs at a time, and hands the
    /// finished runs to `consume` in run order; holds one block's rows at most. Calls
    /// `on_row` as each run finishes (from any thread). Returns whether any run was skipped
    /// or cut short by `interrupt`; an error of `consume` ends the campaign.
    pub fn execute_streaming(
        &self,
        range: Range<u64>,
        threads: usize,
        interrupt: &AtomicBool,
        on_row: &(dyn Fn(&Row) + Sync),
        consume: &mut dyn FnMut(Row) -> Result<(), String>,
    ) -> Result<bool, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.clamp(1, max_threads()))
            .build()
            .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
        let mut partial = false;
        let mut start = range.start;
        while start < range.end {
            if interrupt.load(Ordering::Relaxed) {
                // The remaining blocks are skipped whole.
                partial = true;
                break;
            }
            let block = start..(start + BLOCK_RUNS).min(range.end);
            start = block.end;
            let n = (block.end - block.start) as usize;
            let lanes = matches!(self.integration, Integration::Lanes(_));
            let (order, built) = self.longest_first(block.clone(), &pool, lanes, interrupt);
            // A list schedule: each thread takes the next run of `order` as it finishes one,
            // so that the longest runs start first and the short ones fill in at the end (a
            // run's row does not depend on when or where it runs).
            let next = AtomicUsize::new(0);
            let slots: Vec<Mutex<Option<Row>>> = (0..n).map(|_| Mutex::new(None)).collect();
            // Lanes take a chunk of runs at a time: enough to keep the lanes full (a lane that
            // finishes takes the chunk's next run), few enough to share the block out among
            // threads (on one thread, as many as a chunk holds). The runs are dealt to the
            // chunks in turn, so that each chunk holds long and short runs, longest first
            // where the order is a prediction: its lanes idle at its end only while its
            // shortest runs finish.
            let width = match self.integration {
                Integration::Lanes(engine) => engine.width(),
                Integration::Scalar(_) => 1,
            };
            let chunk = if threads <= 1 {
                n.min(LANE_CHUNK_RUNS)
            } else {
                (n / (4 * threads)).clamp(2 * width.max(4), LANE_CHUNK_RUNS)
            };
            let chunks = if lanes {
                dealt(&order, n.div_ceil(chunk.max(1)))
            } else {
                Vec::new()
            };
            let next_chunk = AtomicUsize::new(0);
            pool.broadcast(|_| {
                while let Integration::Lanes(engine) = self.integration {
                    let c = next_chunk.fetch_add(1, Ordering::Relaxed);
                    if c >= chunks.len() || interrupt.load(Ordering::Relaxed) {
                        break;
                    }
                    let js = &chunks[c];
                    let runs = js
                        .iter()
                        .map(|&j| {
                            let i = block.start + j as u64;
                            let prebuilt = built
                                .get(j)
                                .and_then(|b| b.lock().unwrap_or_else(|e| e.into_inner()).take());
                            (i, prebuilt.unwrap_or_else(|| self.build_run(i)))
                        })
                        .collect();
                    for (&j, row) in js.iter().zip(self.run_in_lanes(engine, runs, interrupt)) {
                        if let Some(row) = row {
                            on_row(&row);
                            *slots[j].lock().unwrap_or_else(|e| e.into_inner()) = Some(row);
                        }
                    }
                }
                // One run at a time on the scalar path.
                while let Integration::Scalar(_) = self.integration {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= n || interrupt.load(Ordering::Relaxed) {
                        break;
                    }
                    let j = order[k];
                    let i = block.start + j as u64;
                    // The run as the prediction built it, if it did.
                    let prebuilt = built
                        .get(j)
                        .and_then(|b| b.lock().unwrap_or_else(|e| e.into_inner()).take());
                    let run =
                        self.run_built(i, prebuilt.unwrap_or_else(|| self.build_run(i)), interrupt);
                    if let Some(row) = run {
                        on_row(&row);
                        *slots[j].lock().unwrap_or_else(|e| e.into_inner()) = Some(row);
                    }
                }
            });
            let results = slots
                .into_iter()
                .map(|slot| slot.into_inner().unwrap_or_else(|e| e.into_inner()));
            for r in results {
                match r {
                    Some(r) => consume(r)?,
                    None => partial = true,
                }
            }
        }
        Ok(partial)
    }

    /// The runs of `range` (offsets into it), the longest expected first: by the stiffness of
    /// each run's equations at its initial state (the spectral radius of the Jacobian, which
    /// bounds an explicit method's step, times the duration), computed on `pool`. Runs
    /// whose draw is invalid keep their index order after the others; so do all runs once
    /// `interrupt` is set. In index order, without a prediction: the averaged method's runs
    /// (whose cost is their slow steps), one thread on the scalar path, and more than
    /// [`ORDERED_RUNS_PER_THREAD`] runs per thread (in `lanes`, more than that or
    /// [`LANE_CHUNK_RUNS`], whichever is larger), where the last runs' imbalance is small
    /// against the whole, and the built runs would have to be held for the whole block. In
    /// lanes the order matters on one thread too: a chunk's lanes idle while its last runs
    /// finish.
    /// Returns the order and, when it predicted, each run as it built it (taken by the runs,
    /// so that none is built twice).
    fn longest_first(
        &self,
        range: Range<u64>,
        pool: &rayon::ThreadPool,
        lanes: bool,
        interrupt: &AtomicBool,
    ) -> (Vec<usize>, Vec<Mutex<Option<Built>>>) {
        let n = (range.end - range.start) as usize;
        let averaged = matches!(
            self.scenario.simulation.method,
            crate::sim::Method::Averaged(_)
        );
        let threads = pool.current_num_threads();
        let most = if lanes {
            (ORDERED_RUNS_PER_THREAD * threads).max(LANE_CHUNK_RUNS)
        } else {
            ORDERED_RUNS_PER_THREAD * threads
        };
        if averaged || n < 2 || (threads < 2 && !lanes) || n > most {
            return ((0..n).collect(), Vec::new());
        }
        let predicted: Vec<(f64, Option<Built>)> = pool.install(|| {
            (0..n)
                .into_par_iter()
                .map(|j| {
                    if interrupt.load(Ordering::Relaxed) {
                        return (0.0, None);
                    }
                    let built = self.build_run(range.start + j as u64);
                    let cost = match &built {
                        Ok((sc, _)) => {
                            let y = sc.spacecraft.initial_state(&sc.omega0, &sc.attitude0);
                            let stiffness =
                                crate::linearize::stiffness(&sc.spacecraft, 0.0, &y, sc.duration);
                            stiffness.spectral_radius * sc.duration
                        }
                        Err(_) => 0.0,
                    };
                    (if cost.is_finite() { cost } else { 0.0 }, Some(built))
                })
                .collect()
        });
        let mut order: Vec<usize> = (0..n).collect();
        // Stable: equal expectations keep their index order.
        order.sort_by(|&a, &b| predicted[b].0.total_cmp(&predicted[a].0));
        let built = predicted.into_iter().map(|(_, b)| Mutex::new(b)).collect();
        (order, built)
    }

    /// What the campaign's summary is computed from, besides the runs.
    pub fn summary_spec(&self) -> summary::SummarySpec {
        summary::SummarySpec {
            columns: self.columns.clone(),
            events: self
                .event_conditions
                .iter()
                .enumerate()
                .map(|(k, c)| summary::EventColumn {
                    condition: c.clone(),
                    name: self.columns[self.event_start + k].clone(),
                    column: self.event_start + k,
                })
                .collect(),
            probability_by: self.campaign.probability_by.clone(),
            rank: self.rank_rule(),
            invalid_draws: summary::InvalidDrawSpec {
                policy: self.campaign.invalid_draws.label(),
                run_column: self.run_redraw_column,
                dispersion_columns: self.redraw_columns.clone(),
            },
        }
    }

    /// How runs are ranked: by the flat-spin event time (earliest is worst) or, without
    /// such an event, by the largest nutation (largest is worst).
    pub fn rank_rule(&self) -> summary::RankRule {
        match self.primary_event {
            Some(c) => summary::RankRule {
                column: c,
                name: self.columns[c].clone(),
                smaller_is_worse: true,
                missing: f64::INFINITY,
            },
            None => summary::RankRule {
                column: self.max_nutation_column,
                name: self.columns[self.max_nutation_column].clone(),
                smaller_is_worse: false,
                missing: f64::NEG_INFINITY,
            },
        }
    }
}

/// A draw that is not a valid scenario: why, and the inputs drawn up to that point.
#[derive(Debug, Clone, PartialEq)]
pub struct InvalidDraw {
    /// Why.
    pub message: String,
    /// The recorded inputs drawn before the failure.
    pub inputs: Vec<f64>,
    /// Under `invalid_draws: redraw`, the draws made in vain (the run then has no valid one).
    pub redraws: Option<u32>,
}

impl std::fmt::Display for InvalidDraw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// Loads a scenario and prepares its campaign.
pub fn load(path: &Path, runs: Option<u64>, seed: Option<u64>) -> Result<Prepared, ScenarioError> {
    let sc = scenario::load(path, &Overrides::default())?;
    Prepared::new(sc, &path.display().to_string(), runs, seed)
}

/// [`load`], with every run on `method` instead of the scenario's.
pub fn load_with_method(
    path: &Path,
    runs: Option<u64>,
    seed: Option<u64>,
    method: Option<String>,
) -> Result<Prepared, ScenarioError> {
    load(path, runs, seed)?.with_method(method)
}

/// The run range of shard `k` of `n` (1-based) of `runs` runs: contiguous, sizes differing by
/// at most one.
pub fn shard_range(runs: u64, k: u64, n: u64) -> Range<u64> {
    let at = |j: u64| ((u128::from(runs) * u128::from(j)) / u128::from(n)) as u64;
    at(k - 1)..at(k)
}

/// `order` dealt into `chunks` chunks in turn: chunk c holds `order[c]`, `order[c + chunks]`,
/// …, in that order.
fn dealt(order: &[usize], chunks: usize) -> Vec<Vec<usize>> {
    let chunks = chunks.clamp(1, order.len().max(1));
    (0..chunks)
        .map(|c| order.iter().skip(c).step_by(chunks).copied().collect())
        .collect()
}

/// Tracks the largest nutation angle seen (rad) at output samples and events.
#[derive(Debug, Default)]
struct Extremes {
    max_nutation: f64,
}

impl Extremes {
    fn keep(&mut self, nutation_angle: f64) {
        self.max_nutation = self.max_nutation.max(nutation_angle);
    }
}

impl Sink for Extremes {
    fn sample(&mut self, o: &Observation, _: &[f64], _: &Reference) -> std::io::Result<()> {
        self.keep(o.nutation_angle);
        Ok(())
    }
    fn event(&mut self, _: &EventRecord, o: &Observation) -> std::io::Result<()> {
        self.keep(o.nutation_angle);
        Ok(())
    }
    fn reads_principal_angles(&self) -> bool {
        false
    }
    fn nutation_sample(&mut self, _t: f64, nutation_angle: f64) -> Option<std::io::Result<()>> {
        self.keep(nutation_angle);
        Some(Ok(()))
    }
    fn reads_only_nutation(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests;
