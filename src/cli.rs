//! The `polhode` command line: `run`, `check`, `linearize` (stable; documented in docs/cli.md).
//!
//! Exit codes: 0 success; 2 bad input (scenario, options, unwritable output; nothing written);
//! 1 an I/O failure during the run; 3 the integration failed (the log up to the failure is
//! kept, marked partial); 130 interrupted by Ctrl-C (the log is kept, marked partial).

use crate::linearize::{Linearization, linearize, linearize_driven, spin_rate_of};
use crate::log::{McapLogger, write_atomically};
use crate::model::RigidBody;
use crate::scenario::{self, Overrides, Scenario};
use crate::sim::{self, Control, NullSink, Outcome, Status};
use clap::{Parser, Subcommand};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A write beyond the file-size limit (`ulimit -f`) raises SIGXFSZ, which by default kills the
/// process with a half-written temporary file; ignored, the write fails with EFBIG instead and
/// the run reports it like a full disk and cleans up.
fn ignore_file_size_signal() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to SIG_IGN at start-up, before any thread exists,
    // has no preconditions.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// Exit code for bad input.
pub const EXIT_BAD_INPUT: i32 = 2;
/// Exit code for an I/O failure during a run.
pub const EXIT_IO: i32 = 1;
/// Exit code for an integration failure.
pub const EXIT_FAILED: i32 = 3;
/// Exit code after Ctrl-C.
pub const EXIT_INTERRUPTED: i32 = 130;

#[derive(Parser, Debug)]
#[command(
    name = "polhode",
    version,
    about = "Spacecraft attitude dynamics with energy dissipation"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scenario, write its MCAP log and print a summary.
    Run {
        /// Scenario YAML file.
        scenario: PathBuf,
        /// MCAP output (overrides `output.mcap`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Do not write an MCAP log.
        #[arg(long, conflicts_with = "out")]
        no_log: bool,
        #[command(flatten)]
        method: MethodArgs,
        /// Simulated duration (s), overrides `duration`.
        #[arg(long)]
        duration: Option<f64>,
        /// Write a JSON summary here.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Write the sampled telemetry (every output sample, effectors' fields included) as
        /// CSV here, units in the header.
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        /// Write the sampled telemetry as Parquet here, units in the file's metadata.
        #[arg(long, value_name = "FILE")]
        parquet: Option<PathBuf>,
        /// Largest log to write (MB, 10⁶ bytes; overrides `output.max_log_mb`, default 2000):
        /// a run whose log is estimated larger is refused before it starts.
        #[arg(long, value_name = "MB")]
        max_log_mb: Option<f64>,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Validate a scenario and exit.
    Check {
        /// Scenario YAML file(s).
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
    },
    /// Run several fidelities of one scene and print them side by side (no logs written).
    Compare {
        /// Scenario YAML files.
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
        /// Write a chart of the nutation angle against time (SVG).
        #[arg(long)]
        chart: Option<PathBuf>,
        /// Write the nutation angle series (CSV).
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write the table as JSON (or print it with `--json -`).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Simulated duration for every scenario (s), overrides each `duration`.
        #[arg(long)]
        duration: Option<f64>,
        /// An event column, written like an `events:` item, e.g.
        /// `{nutation_angle_deg: {above: 45.0, once: true}}`; repeatable. Replaces the
        /// scenarios' own `events:` as the columns.
        #[arg(long = "event", value_name = "CONDITION")]
        events: Vec<String>,
    },
    /// Benchmarks of the integration methods (docs/choosing-a-method.md).
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
    /// Run the scenario's Monte Carlo campaign (its `montecarlo:` block) on all cores.
    Montecarlo {
        /// Scenario YAML file with a `montecarlo:` block.
        scenario: PathBuf,
        /// Number of runs (overrides `montecarlo.runs`).
        #[arg(long)]
        runs: Option<u64>,
        /// Seed of the random streams (overrides `montecarlo.seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Run only shard K of N (`K/N`, 1-based): a contiguous slice of the runs, to be
        /// combined with `polhode merge`.
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
        /// Output directory (default `logs/<name>-montecarlo`, or `…/shard-K` for a shard).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Charts of one run from its MCAP log (ω, nutation angle, energies, effector
    /// coordinates) as SVG and PNG, without a viewer.
    Plot {
        /// The run's MCAP log.
        log: PathBuf,
        /// Output directory (default: beside the log, `<log stem>-plots`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Combine the outputs of all shards of a campaign into the result of the whole campaign.
    Merge {
        /// Shard output directories (one per shard).
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory for the combined result.
        #[arg(long)]
        out: PathBuf,
        /// Print nothing but errors.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Eigenvalues of the linearisation about steady spin about the spin axis (with a
    /// gravity gradient in a circular orbit: about the LVLH equilibrium).
    Linearize {
        /// Scenario YAML file.
        scenario: PathBuf,
        /// Write JSON to this file (or print JSON with `--json -`).
        #[arg(long)]
        json: Option<PathBuf>,
    },
}

/// `polhode bench …`.
#[derive(Subcommand, Debug)]
enum BenchCommand {
    /// Time one solve (integration only, minimum of repeats) and print it as JSON.
    Point {
        /// Scenario YAML file.
        scenario: PathBuf,
        #[command(flatten)]
        method: MethodArgs,
        /// Simulated duration (s), overrides `duration`.
        #[arg(long)]
        duration: Option<f64>,
        /// Number of timed solves; the fastest is reported (0: as many as fit in 0.3 s, ≤ 7).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
    },
    /// Error against CPU time for every method on a problem set (charts and CSV).
    WorkPrecision {
        /// Problems (comma-separated; default all: generic-tumble, near-separatrix,
        /// tennis-racket, damper, explorer1-pydy).
        #[arg(long, value_delimiter = ',')]
        problems: Vec<String>,
        #[command(flatten)]
        sweep: SweepArgs,
    },
    /// Invariant drift of every method over a long torque-free tumble (charts and CSV).
    Drift {
        /// Simulated time (s).
        #[arg(long, default_value_t = 1e5)]
        duration: f64,
        #[command(flatten)]
        out: OutArgs,
    },
    /// Largest stable step of every method against the stiffness of a damper (chart, CSV).
    Stability {
        #[command(flatten)]
        out: OutArgs,
    },
    /// Error growth of every method near the separatrix, with the problem's conditioning.
    Separatrix {
        /// Simulated time (s).
        #[arg(long, default_value_t = 100.0)]
        duration: f64,
        #[command(flatten)]
        out: OutArgs,
    },
}

/// Where a benchmark writes, and how loudly.
#[derive(clap::Args, Debug, Clone)]
struct OutArgs {
    /// Directory for the charts (SVG and PNG) and CSV.
    #[arg(long, default_value = "docs/figures")]
    out: PathBuf,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

/// Method options shared by `run` and `bench point`.
#[derive(clap::Args, Debug, Clone)]
struct SweepArgs {
    /// Methods to include (comma-separated labels; default all).
    #[arg(long, value_delimiter = ',')]
    methods: Vec<String>,
    /// Directory for the charts (SVG and PNG) and CSV.
    #[arg(long, default_value = "docs/figures")]
    out: PathBuf,
    /// A method's sweep stops after the first solve slower than this (s).
    #[arg(long, default_value_t = 1.0)]
    budget: f64,
    /// Most settings tried per method.
    #[arg(long, default_value_t = 10)]
    max_points: usize,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}
#[derive(clap::Args, Debug, Clone, Default)]
pub struct MethodArgs {
    /// Integration method: rk4, dopri5, dop853, radau5, gauss, lie, splitting, exact or auto.
    #[arg(long)]
    pub method: Option<String>,
    /// Fixed step for rk4, gauss, lie and splitting (s).
    #[arg(long)]
    pub dt: Option<f64>,
    /// Relative tolerance for adaptive methods.
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance for adaptive methods.
    #[arg(long)]
    pub atol: Option<f64>,
    /// Stages of gauss: 1 (implicit midpoint) or 2.
    #[arg(long)]
    pub stages: Option<u32>,
    /// Order of splitting: 2 or 4.
    #[arg(long)]
    pub order: Option<u32>,
}

impl MethodArgs {
    /// The overrides these options make, with `duration` and `mcap`.
    pub fn overrides(&self, duration: Option<f64>, mcap: Option<PathBuf>) -> Overrides {
        Overrides {
            method: self.method.clone(),
            dt: self.dt,
            rtol: self.rtol,
            atol: self.atol,
            stages: self.stages,
            order: self.order,
            duration,
            mcap,
            max_log_mb: None,
        }
    }
}

/// Adds a "similar subcommand" tip where clap's own (Jaro similarity) finds none: transposed
/// letters (`rnu` → `run`) and up to two typos by Damerau–Levenshtein distance.
fn suggest_subcommand(e: &mut clap::Error) {
    use clap::CommandFactory;
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::InvalidSubcommand || e.get(ContextKind::SuggestedSubcommand).is_some()
    {
        return;
    }
    let Some(ContextValue::String(typed)) = e.get(ContextKind::InvalidSubcommand) else {
        return;
    };
    let typed = typed.clone();
    let best = Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .map(|name| (strsim::damerau_levenshtein(&typed, &name), name))
        .filter(|(d, name)| *d <= 2 && *d < name.len())
        .min();
    if let Some((_, name)) = best {
        e.insert(
            ContextKind::SuggestedSubcommand,
            ContextValue::Strings(vec![name]),
        );
    }
}

/// Runs the command line; returns the process exit code.
pub fn main() -> i32 {
    ignore_file_size_signal();
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(mut e) => {
            let code = if e.use_stderr() { EXIT_BAD_INPUT } else { 0 };
            suggest_subcommand(&mut e);
            let _ = e.print();
            return code;
        }
    };
    match cli.command {
        Command::Check { scenarios } => check(&scenarios),
        Command::Compare {
            scenarios,
            chart,
            csv,
            json,
            duration,
            events,
        } => compare_cmd(
            &scenarios,
            chart.as_deref(),
            csv.as_deref(),
            json.as_deref(),
            duration,
            &events,
        ),
        Command::Linearize { scenario, json } => linearize_cmd(&scenario, json.as_deref()),
        Command::Montecarlo {
            scenario,
            runs,
            seed,
            threads,
            shard,
            out,
            quiet,
        } => montecarlo_cmd(&scenario, runs, seed, threads, shard.as_deref(), out, quiet),
        Command::Merge { dirs, out, quiet } => merge_cmd(&dirs, &out, quiet),
        Command::Plot { log, out, quiet } => plot_cmd(&log, out, quiet),
        Command::Bench { what } => bench_cmd(what),
        Command::Run {
            scenario,
            out,
            no_log,
            method,
            duration,
            summary,
            csv,
            parquet,
            max_log_mb,
            quiet,
        } => {
            let overrides = Overrides {
                max_log_mb,
                ..method.overrides(duration, out)
            };
            let outputs = RunOutputs {
                no_log,
                summary: summary.as_deref(),
                csv: csv.as_deref(),
                parquet: parquet.as_deref(),
            };
            run(&scenario, &overrides, &outputs, quiet)
        }
    }
}

fn plot_cmd(log: &Path, out: Option<PathBuf>, quiet: bool) -> i32 {
    let dir = out.unwrap_or_else(|| {
        let stem = log
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "run".into());
        log.with_file_name(format!("{stem}-plots"))
    });
    match crate::log::charts::read(log) {
        Err(e) => {
            eprintln!("error: {e}");
            EXIT_BAD_INPUT
        }
        Ok(run) => report_files(crate::log::charts::write(&run, &dir), quiet),
    }
}

fn bench_cmd(what: BenchCommand) -> i32 {
    match what {
        BenchCommand::Point {
            scenario,
            method,
            duration,
            repeats,
        } => {
            let s = match load(&scenario, &method.overrides(duration, None)) {
                Ok(s) => s,
                Err(code) => return code,
            };
            match crate::bench::point(&s, repeats) {
                Ok(p) => {
                    println!("{}", serde_json::to_string(&p).expect("serialisable"));
                    0
                }
                Err(diagnosis) => {
                    eprintln!("error: {}: {diagnosis}", scenario.display());
                    EXIT_FAILED
                }
            }
        }
        BenchCommand::Drift { duration, out } => {
            if !(duration.is_finite() && duration > 0.0) {
                eprintln!("error: --duration: expected a positive number of seconds");
                return EXIT_BAD_INPUT;
            }
            if let Err(code) = make_dir(&out.out) {
                return code;
            }
            report_files(
                crate::bench::failure::drift(
                    Path::new("."),
                    duration,
                    &out.out,
                    bench_progress(out.quiet),
                ),
                out.quiet,
            )
        }
        BenchCommand::Stability { out } => {
            if let Err(code) = make_dir(&out.out) {
                return code;
            }
            report_files(
                crate::bench::failure::stability(&out.out, bench_progress(out.quiet)),
                out.quiet,
            )
        }
        BenchCommand::Separatrix { duration, out } => {
            if !(duration.is_finite() && duration > 0.0 && duration <= 1e4) {
                eprintln!("error: --duration: expected a positive number of seconds up to 1e4");
                return EXIT_BAD_INPUT;
            }
            if let Err(code) = make_dir(&out.out) {
                return code;
            }
            report_files(
                crate::bench::failure::separatrix(
                    Path::new("."),
                    duration,
                    &out.out,
                    bench_progress(out.quiet),
                ),
                out.quiet,
            )
        }
        BenchCommand::WorkPrecision { problems, sweep } => {
            use crate::bench::work_precision::{PROBLEMS, Problem};
            let chosen: Vec<Problem> = if problems.is_empty() {
                PROBLEMS.to_vec()
            } else {
                let mut v = Vec::new();
                for name in &problems {
                    match PROBLEMS.iter().find(|p| p.name == name) {
                        Some(p) => v.push(*p),
                        None => {
                            let names: Vec<&str> = PROBLEMS.iter().map(|p| p.name).collect();
                            eprintln!(
                                "error: --problems: unknown problem `{name}`, expected some of {}",
                                names.join(", ")
                            );
                            return EXIT_BAD_INPUT;
                        }
                    }
                }
                v
            };
            let methods = match methods_named(&sweep.methods) {
                Ok(m) => m,
                Err(code) => return code,
            };
            if let Err(code) = make_dir(&sweep.out) {
                return code;
            }
            let budget = crate::bench::Budget {
                seconds_per_point: sweep.budget,
                max_points: sweep.max_points,
            };
            report_files(
                crate::bench::work_precision::run(
                    Path::new("."),
                    &chosen,
                    &methods,
                    &budget,
                    &sweep.out,
                    bench_progress(sweep.quiet),
                ),
                sweep.quiet,
            )
        }
    }
}

/// The methods named in `labels` (all when empty), or exit code 2 for an unknown one.
fn methods_named(labels: &[String]) -> Result<Vec<crate::bench::MethodSpec>, i32> {
    use crate::bench::{METHODS, MethodSpec};
    if labels.is_empty() {
        return Ok(METHODS.to_vec());
    }
    labels
        .iter()
        .map(|l| {
            MethodSpec::by_label(l).ok_or_else(|| {
                eprintln!(
                    "error: --methods: unknown method `{l}`, expected some of {}",
                    MethodSpec::labels().join(", ")
                );
                EXIT_BAD_INPUT
            })
        })
        .collect()
}

fn bench_progress(quiet: bool) -> impl FnMut(&str) {
    move |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    }
}

fn make_dir(dir: &Path) -> Result<(), i32> {
    std::fs::create_dir_all(dir).map_err(|e| {
        eprintln!("error: {}: {e}", dir.display());
        EXIT_IO
    })
}

fn report_files(result: Result<Vec<PathBuf>, String>, quiet: bool) -> i32 {
    match result {
        Ok(files) => {
            if !quiet {
                for f in files {
                    println!("wrote {}", f.display());
                }
            }
            0
        }
        Err(e) => {
            eprintln!("error: {e}");
            EXIT_FAILED
        }
    }
}

fn load(path: &Path, overrides: &Overrides) -> Result<Scenario, i32> {
    scenario::load(path, overrides).map_err(|e| {
        eprintln!("error: {e}");
        EXIT_BAD_INPUT
    })
}

fn compare_cmd(
    paths: &[PathBuf],
    chart: Option<&Path>,
    csv: Option<&Path>,
    json: Option<&Path>,
    duration: Option<f64>,
    events: &[String],
) -> i32 {
    let overrides = Overrides {
        duration,
        ..Overrides::default()
    };
    // Validate everything before running anything.
    let mut option_events = Vec::new();
    for text in events {
        match scenario::parse_condition(text) {
            Ok(c) => option_events.push(c),
            Err(e) => {
                eprintln!("error: --event '{text}': {e}");
                return EXIT_BAD_INPUT;
            }
        }
    }
    let mut scenarios = Vec::new();
    for p in paths {
        match load(p, &overrides) {
            Ok(s) => scenarios.push(s),
            Err(c) => return c,
        }
    }
    let columns = crate::compare::Columns::new(&scenarios, &option_events);
    let interrupt = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupt.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let tty = std::io::stderr().is_terminal();
    let mut rows = Vec::new();
    let count = scenarios.len();
    for (i, s) in scenarios.into_iter().enumerate() {
        if tty {
            eprintln!("[{}/{count}] {} …", i + 1, s.name);
        }
        match crate::compare::run_one(s, &columns, &interrupt) {
            Ok(r) => rows.push(r),
            Err(e) => {
                eprintln!("error: {e}");
                return EXIT_IO;
            }
        }
        if interrupt.load(Ordering::SeqCst) {
            eprintln!("interrupted: the table holds the runs finished so far");
            break;
        }
    }
    let table = crate::compare::table(&rows, &columns);
    let title = format!(
        "Nutation angle: {}",
        rows.iter()
            .map(|r| r.name.as_str())
            .collect::<Vec<_>>()
            .join(" vs ")
    );
    let mut outputs: Vec<(&Path, String)> = Vec::new();
    if let Some(p) = chart {
        outputs.push((p, crate::compare::chart(&rows, &columns, &title)));
    }
    if let Some(p) = csv {
        outputs.push((p, crate::compare::series_csv(&rows)));
    }
    let json_text = serde_json::to_string_pretty(&rows).unwrap_or_default() + "\n";
    match json {
        Some(p) if p == Path::new("-") => print!("{json_text}"),
        Some(p) => outputs.push((p, json_text)),
        None => {}
    }
    for (p, text) in outputs {
        if let Err(e) = write_atomically(p, text.as_bytes()) {
            eprintln!("error: cannot write {}: {e}", p.display());
            return EXIT_IO;
        }
    }
    if json != Some(Path::new("-")) {
        print!("{table}");
    }
    if interrupt.load(Ordering::SeqCst) {
        EXIT_INTERRUPTED
    } else {
        0
    }
}

/// Validates whole files, `montecarlo:` block included (with `polhode montecarlo`'s own
/// checks and messages), without running anything.
fn check(paths: &[PathBuf]) -> i32 {
    let mut code = 0;
    for p in paths {
        let s = match load(p, &Overrides::default()) {
            Ok(s) => s,
            Err(c) => {
                code = c;
                continue;
            }
        };
        let campaign = if s.montecarlo.is_some() {
            match crate::montecarlo::load(p, None, None) {
                Ok(prep) => format!(
                    "; montecarlo: {} runs, {} dispersions, seed {}",
                    prep.campaign.runs,
                    prep.campaign.dispersions.len(),
                    prep.campaign.seed
                ),
                Err(e) => {
                    eprintln!("error: {e}");
                    code = EXIT_BAD_INPUT;
                    continue;
                }
            }
        } else {
            String::new()
        };
        println!(
            "{}: ok ({}; {}; {}; {} Hz to {}{campaign})",
            p.display(),
            s.name,
            crate::timefmt::seconds(s.duration),
            s.method.describe(),
            s.output_rate,
            s.mcap_path.display()
        );
        if let Some(line) = hub_remainder_line(&s) {
            println!("{line}");
        }
        for w in &s.warnings {
            eprintln!("warning: {w}");
        }
    }
    code
}

/// With `body.composite: true`, the hub's own mass properties polhode derived (the whole
/// spacecraft minus the effectors at rest), for `check` and `run`.
fn hub_remainder_line(s: &Scenario) -> Option<String> {
    let c = s.composite.as_ref()?;
    let sc = &s.spacecraft;
    let p = sc.hub.principal_moments;
    // `+ 0.0` turns −0 into 0, so no component prints as `-0.000000000e0`.
    let o = c.hub_offset.map(|x| x + 0.0);
    let mass = match (c.total_mass, sc.hub_mass) {
        (Some(total), Some(hub)) => format!(
            "mass {hub:.9e} kg (of {total} kg; effectors {:.9e} kg), ",
            c.effector_mass
        ),
        _ => String::new(),
    };
    Some(format!(
        "  hub (composite body minus the effectors at rest): {mass}centre of mass \
         [{:+.9e}, {:+.9e}, {:+.9e}] m from the whole spacecraft's, principal moments \
         {:.9e}, {:.9e}, {:.9e} kg m²",
        o[0], o[1], o[2], p[0], p[1], p[2]
    ))
}

fn linearize_cmd(path: &Path, json: Option<&Path>) -> i32 {
    let s = match load(path, &Overrides::default()) {
        Ok(s) => s,
        Err(c) => return c,
    };
    if crate::linearize::lvlh::applies(&s.spacecraft) {
        // A gravity-gradient spacecraft in orbit: about its LVLH equilibrium.
        let lin = match crate::linearize::lvlh::linearize_scenario(&s) {
            Ok(l) => l,
            Err(m) => {
                eprintln!("error: {}: {m}", path.display());
                return EXIT_BAD_INPUT;
            }
        };
        let text = serde_json::to_string_pretty(&lin).unwrap_or_default();
        match json {
            Some(p) if p == Path::new("-") => println!("{text}"),
            Some(p) => {
                if let Err(e) = write_atomically(p, text.as_bytes()) {
                    eprintln!("error: cannot write {}: {e}", p.display());
                    return EXIT_BAD_INPUT;
                }
                print!("{}", lin.report(&s.name));
            }
            None => print!("{}", lin.report(&s.name)),
        }
        return 0;
    }
    if let Some(motion) = s.spacecraft.motion() {
        // A driven hub: the effectors' modes at the rate the motion reaches at the end.
        let omega = motion.omega(s.duration);
        let lin = match linearize_driven(&s.spacecraft, &omega) {
            Ok(l) => l,
            Err(m) => {
                eprintln!("error: {}: {m}", path.display());
                return EXIT_BAD_INPUT;
            }
        };
        let text = serde_json::to_string_pretty(&lin).unwrap_or_default();
        if let Some(p) = json {
            if p == Path::new("-") {
                println!("{text}");
                return 0;
            }
            if let Err(e) = write_atomically(p, text.as_bytes()) {
                eprintln!("error: cannot write {}: {e}", p.display());
                return EXIT_BAD_INPUT;
            }
        }
        println!(
            "{}: hub driven ({}); effector modes at ω = [{:.6}, {:.6}, {:.6}] rad/s (the rate \
             at t = {})",
            s.name,
            motion.describe(),
            omega[0],
            omega[1],
            omega[2],
            crate::timefmt::seconds(s.duration)
        );
        println!(
            "  {:>16} {:>16}  {:<12} time constant",
            "Re (1/s)", "Im (rad/s)", "mode"
        );
        for m in &lin.modes {
            let tc = m
                .time_constant
                .map(|t| format!("{t:.6} s"))
                .unwrap_or_else(|| "-".into());
            println!("  {:>16.9e} {:>16.9e}  {:<12} {tc}", m.re, m.im, m.kind);
        }
        println!("  verdict: {}", lin.verdict);
        return 0;
    }
    let rate = spin_rate_of(&s.spacecraft, &s.omega0);
    let lin = match linearize(&s.spacecraft, rate) {
        Ok(l) => l,
        Err(m) => {
            eprintln!("error: {}: {m}", path.display());
            return EXIT_BAD_INPUT;
        }
    };
    let text = serde_json::to_string_pretty(&lin).unwrap_or_default();
    match json {
        Some(p) if p == Path::new("-") => println!("{text}"),
        Some(p) => {
            if let Err(e) = write_atomically(p, text.as_bytes()) {
                eprintln!("error: cannot write {}: {e}", p.display());
                return EXIT_BAD_INPUT;
            }
            print_linearization(&s, &lin);
        }
        None => print_linearization(&s, &lin),
    }
    0
}

fn print_linearization(s: &Scenario, lin: &Linearization) {
    let a = lin.spin_axis;
    println!(
        "{}: steady spin {:.6} rad/s about [{:.4}, {:.4}, {:.4}] (principal axis {} of \
         I = {:.6}, {:.6}, {:.6} kg m²)",
        s.name,
        lin.spin_rate,
        a[0],
        a[1],
        a[2],
        lin.principal_axis,
        lin.principal_moments[0],
        lin.principal_moments[1],
        lin.principal_moments[2]
    );
    println!(
        "  {:>16} {:>16}  {:<12} {:<10} time constant",
        "Re (1/s)", "Im (rad/s)", "mode", "role"
    );
    for m in &lin.modes {
        let tc = m
            .time_constant
            .map(|t| format!("{t:.6} s"))
            .unwrap_or_else(|| "-".into());
        println!(
            "  {:>16.9e} {:>16.9e}  {:<12} {:<10} {tc}",
            m.re, m.im, m.kind, m.role
        );
    }
    println!("  verdict: {}", lin.verdict);
    print_spin_decay_and_gyrostat(lin);
    if let Some(n) = &lin.nutation {
        let what = if n.rate > 0.0 { "grows" } else { "decays" };
        match n.time_constant {
            Some(tc) => println!(
                "  nutation {what} at {:.9e} 1/s (time constant {tc:.6} s), frequency {:.6e} \
                 rad/s",
                n.rate, n.frequency
            ),
            None => println!("  nutation: neutral, frequency {:.6e} rad/s", n.frequency),
        }
        if let (Some(r), Some(tc)) = (n.energy_sink_rate, n.energy_sink_time_constant) {
            println!(
                "  energy-sink estimate: {r:.9e} 1/s (time constant {tc:.6} s), {:+.1}% from \
                 the eigenvalue",
                100.0 * (r - n.rate) / n.rate.abs().max(f64::MIN_POSITIVE)
            );
        }
        if let Some(w) = &n.dual_spin_energy_sink {
            let tc = w
                .time_constant
                .map(|t| format!(" (time constant {t:.6} s)"))
                .unwrap_or_default();
            println!(
                "  weighted (dual-spin) energy-sink estimate: {:.9e} 1/s{tc}, {:+.1}% from the \
                 eigenvalue",
                w.rate,
                100.0 * w.relative_difference
            );
            for b in &w.bodies {
                println!(
                    "    nutation seen in {} (spin {:.6e} rad/s): λ = {:+.6e} rad/s",
                    if b.body == "hub" {
                        "the hub".to_string()
                    } else {
                        format!("`{}`", b.body)
                    },
                    b.spin_rate,
                    b.nutation_frequency
                );
            }
            for k in &w.sinks {
                println!(
                    "    `{}` on the {}: {:+.9e} 1/s",
                    k.effector, k.body, k.rate
                );
            }
        }
    } else if let Some(tc) = lin.time_constant {
        let what = if lin.max_growth_rate > 0.0 {
            "growth"
        } else {
            "decay"
        };
        println!(
            "  {what} rate {:.9e} 1/s, time constant {tc:.6} s",
            lin.max_growth_rate
        );
    }
    if lin.equilibrium_residual > 1e-9 {
        println!(
            "  warning: the effectors at rest are not in equilibrium under this spin (residual \
             {:.3e}); the linearisation is about a point that is not steady",
            lin.equilibrium_residual
        );
    }
    let r = &lin.rigid_body_prediction;
    let form = if lin.gyrostat.is_some() {
        "gyrostat closed form (rotors locked at their relative rates)"
    } else {
        "rigid-body closed form"
    };
    if r.growth_rate > 0.0 {
        println!("  {form}: k = {:.9e} 1/s", r.growth_rate);
    } else {
        println!("  {form}: nutation frequency {:.9e} rad/s", r.frequency);
    }
}

/// The `linearize` lines on the spin's own decay (an external torque) and on a gyrostat's
/// spinning rotors.
fn print_spin_decay_and_gyrostat(lin: &Linearization) {
    if let Some(m) = lin.modes.iter().find(|m| m.role == "spin_decay") {
        let tc = m
            .time_constant
            .map(|t| format!(" (time constant {t:.6} s)"))
            .unwrap_or_default();
        println!(
            "  spin decay: {:.9e} 1/s{tc}; an external torque drains |H|, so the spin is not \
             steady but decays (expected): the modes are those about the spin at this rate",
            m.re
        );
    }
    let Some(g) = &lin.gyrostat else { return };
    println!(
        "  gyrostat: rotor momentum h = {:.9e} N m s along the spin axis",
        g.rotor_momentum
    );
    match (g.rotor_decay_rate, g.rotor_decay_time_constant) {
        (Some(r), Some(tc)) => {
            let periods = g
                .nutation_periods_per_decay
                .map(|n| format!(", {n:.3e} nutation periods"))
                .unwrap_or_default();
            println!(
                "  {}: a damped rotor's relative rate decays at {r:.9e} 1/s (time constant \
                 {tc:.6} s{periods}); linearised about the rate frozen at its initial value",
                g.equilibrium
            );
            if g.equilibrium == "not steady" {
                println!(
                    "  warning: the rotor's relative rate decays within {} nutation periods, \
                     so the frozen-rate linearisation does not describe the motion; give the \
                     rotor less damping, or start it at rest",
                    crate::linearize::QUASI_STEADY_PERIODS
                );
            }
        }
        _ => println!("  {}: every spinning rotor is frictionless", g.equilibrium),
    }
}

/// Whether two paths name the same file (compared as absolute paths; neither need exist).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::path::absolute(a), std::path::absolute(b)) {
        (Ok(a), Ok(b)) => a == b || a.canonicalize().ok() == Some(b.clone()),
        _ => a == b,
    }
}

/// Checks up front that a file can be created at `path` (without leaving one behind).
fn probe_writable(path: &Path) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::other("it is a directory"));
    }
    crate::log::check_replaceable(path)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let tmp = dir.join(format!(".polhode-probe.{}.tmp", std::process::id()));
    std::fs::File::create(&tmp)?;
    std::fs::remove_file(&tmp)
}

/// What `polhode run` writes besides its text.
struct RunOutputs<'a> {
    /// No MCAP log.
    no_log: bool,
    /// The JSON summary.
    summary: Option<&'a Path>,
    /// The sampled telemetry as CSV.
    csv: Option<&'a Path>,
    /// The sampled telemetry as Parquet.
    parquet: Option<&'a Path>,
}

fn run(path: &Path, overrides: &Overrides, outputs: &RunOutputs, quiet: bool) -> i32 {
    let (no_log, summary_path) = (outputs.no_log, outputs.summary);
    let s = match load(path, overrides) {
        Ok(s) => s,
        Err(c) => return c,
    };
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(p) = summary_path
        && !no_log
        && same_file(p, &s.mcap_path)
    {
        eprintln!(
            "error: --summary {} is the log's own path; give the summary another name",
            p.display()
        );
        return EXIT_BAD_INPUT;
    }
    if let Some(p) = summary_path
        && let Err(e) = probe_writable(p)
    {
        eprintln!("error: cannot write the summary to {}: {e}", p.display());
        return EXIT_BAD_INPUT;
    }
    // No two outputs may be the same file.
    let named: Vec<(&str, &Path)> = [
        ("--summary", summary_path),
        ("--csv", outputs.csv),
        ("--parquet", outputs.parquet),
        ("the log", (!no_log).then_some(s.mcap_path.as_path())),
    ]
    .into_iter()
    .filter_map(|(what, p)| p.map(|p| (what, p)))
    .collect();
    for (i, (a, pa)) in named.iter().enumerate() {
        for (b, pb) in &named[i + 1..] {
            if same_file(pa, pb) {
                eprintln!(
                    "error: {a} and {b} both name {}; give each output its own file",
                    pa.display()
                );
                return EXIT_BAD_INPUT;
            }
        }
    }
    let mut table = if outputs.csv.is_some() || outputs.parquet.is_some() {
        match crate::log::samples::SampleTable::create(&s.spacecraft, outputs.csv, outputs.parquet)
        {
            Ok(t) => Some(t),
            Err(e) => {
                eprintln!(
                    "error: cannot write the sampled telemetry to {}: {e}",
                    outputs
                        .csv
                        .into_iter()
                        .chain(outputs.parquet)
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(" / ")
                );
                return EXIT_BAD_INPUT;
            }
        }
    } else {
        None
    };
    let mut logger = if no_log {
        None
    } else {
        match McapLogger::create(&s.mcap_path, &s, s.omega0.norm()) {
            Ok(l) => Some(l),
            Err(e) => {
                eprintln!(
                    "error: cannot write the log to {}: {e}",
                    s.mcap_path.display()
                );
                return EXIT_BAD_INPUT;
            }
        }
    };
    if let Some(l) = logger.as_mut() {
        let estimate_mb = l.estimate_bytes(&s) / 1e6;
        if estimate_mb > s.max_log_mb {
            eprintln!(
                "error: {}: the log would be about {} MB before compression \
                 ({:.3e} samples at {} Hz over {} s), above the limit of {} MB; lower \
                 `output.rate` (or `output.scene_rate`), shorten the run, or raise the limit \
                 with `output.max_log_mb` or --max-log-mb",
                s.path.display(),
                match estimate_mb {
                    x if x >= 100.0 => format!("{x:.0}"),
                    x if x >= 1.0 => format!("{x:.1}"),
                    x => format!("{x:.3}"),
                },
                (s.duration * s.output_rate).floor() + 1.0,
                s.output_rate,
                s.duration,
                s.max_log_mb
            );
            if let Some(l) = logger {
                l.abandon();
            }
            return EXIT_BAD_INPUT;
        }
    }

    let interrupt = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupt.clone();
        // A second Ctrl-C exits at once.
        let _ = ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                std::process::exit(EXIT_INTERRUPTED);
            }
        });
    }
    let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new((s.duration * 1000.0).ceil() as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} sim {msg} ETA {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let mut progress = |t: f64| {
        if let Some(b) = &bar {
            b.set_position((t * 1000.0) as u64);
            b.set_message(format!("{t:.3}/{} s", s.duration));
        }
    };
    let ctl = Control {
        interrupt: &interrupt,
        progress: Some(&mut progress),
    };
    let result = match (logger.as_mut(), table.as_mut()) {
        (Some(l), Some(t)) => sim::run(&s, &mut crate::log::samples::Both(l, t), ctl),
        (Some(l), None) => sim::run(&s, l, ctl),
        (None, Some(t)) => sim::run(&s, t, ctl),
        (None, None) => sim::run(&s, &mut NullSink, ctl),
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let outcome = match result {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: writing the log failed: {e}; no log was kept");
            if let Some(l) = logger {
                l.abandon();
            }
            return EXIT_IO;
        }
    };
    let mut tables = Vec::new();
    if let Some(t) = table {
        match t.finish() {
            Ok(paths) => tables = paths,
            Err(e) => {
                eprintln!("error: finishing the sampled telemetry failed: {e}; no table was kept");
                if let Some(l) = logger {
                    l.abandon();
                }
                return EXIT_IO;
            }
        }
    }
    let mut written = None;
    if let Some(l) = logger {
        match l.finish(&s, &s.method.describe(), &outcome) {
            Ok(p) => written = Some(p),
            Err(e) => {
                eprintln!(
                    "error: finishing the log {} failed: {e}; no log was kept",
                    s.mcap_path.display()
                );
                return EXIT_IO;
            }
        }
    }
    if let Some(p) = summary_path {
        let json = summary_json(&s, &outcome, written.as_deref());
        if let Err(e) = write_atomically(p, json.as_bytes()) {
            eprintln!("error: cannot write the summary {}: {e}", p.display());
            return EXIT_IO;
        }
    }
    if !quiet {
        print_summary(&s, &outcome, written.as_deref());
        for p in &tables {
            println!("  table: {}", p.display());
        }
    }
    for w in &outcome.warnings {
        eprintln!("warning: {}", w.message);
    }
    match &outcome.status {
        Status::Complete | Status::Stopped { .. } => 0,
        Status::Interrupted => {
            eprintln!(
                "interrupted at t = {}: the log holds what was computed and is marked partial",
                crate::timefmt::seconds(outcome.final_observation.t)
            );
            EXIT_INTERRUPTED
        }
        Status::Failed { diagnosis } => {
            eprintln!("error: the integration failed: {diagnosis}");
            EXIT_FAILED
        }
        Status::InvalidModel { diagnosis } => {
            eprintln!("error: the model left its validity range: {diagnosis}");
            EXIT_FAILED
        }
    }
}

/// Event lines the text summary prints; the rest are counted.
const PRINTED_EVENTS: usize = 10;

/// The `--summary` JSON document.
#[derive(serde::Serialize)]
struct Summary<'a> {
    polhode_version: &'static str,
    scenario: &'a str,
    scenario_file: String,
    method: &'static str,
    method_settings: String,
    /// Why `auto` picked the method (absent when it was named).
    #[serde(skip_serializing_if = "Option::is_none")]
    method_choice: Option<&'a str>,
    body: Body,
    status: &'a Status,
    mcap: Option<String>,
    initial: State,
    #[serde(rename = "final")]
    final_state: State,
    drift: &'a sim::Drift,
    /// Whether H_N is conserved by the model (no external torque, no prescribed motion):
    /// then `drift.h_*` measure integration error; otherwise they are physical changes.
    conserves_momentum: bool,
    effectors: Vec<EffectorInfo>,
    steps: u64,
    rejected_steps: u64,
    rhs_evaluations: u64,
    /// Newton iterations, Jacobians and LU factorisations (implicit methods).
    newton_iterations: u64,
    jacobian_evaluations: u64,
    factorizations: u64,
    samples: u64,
    wall_time_s: f64,
    events: &'a [sim::EventRecord],
    /// Events beyond the first 10 000 (logged, not listed here).
    events_not_kept: u64,
    warnings: &'a [sim::Warning],
}

/// An effector as built from the scenario.
#[derive(serde::Serialize)]
struct EffectorInfo {
    name: String,
    kind: &'static str,
    states: Vec<String>,
}

/// Mass properties as polhode computed them: the whole spacecraft, effectors locked in their
/// initial configuration, about its centre of mass.
#[derive(serde::Serialize)]
struct Body {
    /// Principal moments, ascending (kg m²).
    principal_moments: [f64; 3],
    /// Unit principal axes in body coordinates, in the order of the moments.
    principal_axes: [[f64; 3]; 3],
    /// Unit spin axis (body) whose nutation angle is reported.
    spin_axis: [f64; 3],
}

fn body(s: &Scenario) -> Body {
    let sc = &s.spacecraft;
    let (p, axes) = if sc.effectors().is_empty() {
        (sc.hub.principal_moments, sc.hub.principal_axes)
    } else {
        let y0 = sc.initial_state(&s.omega0, &s.attitude0);
        match RigidBody::new(sc.system_inertia(&y0)) {
            Ok(b) => (b.principal_moments, b.principal_axes),
            Err(_) => (sc.hub.principal_moments, sc.hub.principal_axes),
        }
    };
    let sa = s.spacecraft.spin_axis;
    Body {
        principal_moments: [p[0], p[1], p[2]],
        principal_axes: RigidBody::reported_axes(&axes),
        spin_axis: [sa[0], sa[1], sa[2]],
    }
}

#[derive(serde::Serialize)]
struct State {
    t: f64,
    omega: [f64; 3],
    q: Quat,
    kinetic_energy: f64,
    elastic_energy: f64,
    dissipated_energy: f64,
    h_norm: f64,
    h_inertial: [f64; 3],
    nutation_angle_deg: f64,
}

#[derive(serde::Serialize)]
struct Quat {
    w: f64,
    x: f64,
    y: f64,
    z: f64,
}

fn state(o: &crate::model::Observation) -> State {
    State {
        t: o.t,
        omega: [o.omega[0], o.omega[1], o.omega[2]],
        q: Quat {
            w: o.attitude.w,
            x: o.attitude.i,
            y: o.attitude.j,
            z: o.attitude.k,
        },
        kinetic_energy: o.kinetic_energy,
        elastic_energy: o.elastic_energy,
        dissipated_energy: o.dissipated_energy,
        h_norm: o.h_norm,
        h_inertial: [o.h_inertial[0], o.h_inertial[1], o.h_inertial[2]],
        nutation_angle_deg: o.nutation_angle.to_degrees(),
    }
}

/// The `run --summary` JSON document of `outcome` (pretty-printed, newline-terminated): `mcap`
/// is the log written, if any. Floats are written so that they read back bit for bit. Shared
/// with the Python package, whose `Result.summary` is this document.
pub fn summary_json(s: &Scenario, o: &Outcome, mcap: Option<&Path>) -> String {
    let summary = Summary {
        polhode_version: env!("CARGO_PKG_VERSION"),
        scenario: &s.name,
        scenario_file: s.path.display().to_string(),
        method: s.method.name(),
        method_settings: s.method.describe(),
        method_choice: s.method_choice.as_deref(),
        body: body(s),
        status: &o.status,
        mcap: mcap.map(|p| p.display().to_string()),
        initial: state(&o.initial_observation),
        final_state: state(&o.final_observation),
        drift: &o.drift,
        conserves_momentum: s.spacecraft.conserves_momentum(),
        effectors: s
            .spacecraft
            .effectors()
            .iter()
            .map(|e| EffectorInfo {
                name: e.name().to_string(),
                kind: e.kind(),
                states: e.state_names(),
            })
            .collect(),
        steps: o.stats.steps,
        rejected_steps: o.stats.rejected_steps,
        rhs_evaluations: o.stats.rhs_evaluations,
        newton_iterations: o.stats.newton_iterations,
        jacobian_evaluations: o.stats.jacobian_evaluations,
        factorizations: o.stats.factorizations,
        samples: o.samples,
        wall_time_s: o.wall_time,
        events: &o.events,
        events_not_kept: o.events_not_kept,
        warnings: &o.warnings,
    };
    serde_json::to_string_pretty(&summary).unwrap_or_default() + "\n"
}

fn print_summary(s: &Scenario, o: &Outcome, mcap: Option<&Path>) {
    let f = &o.final_observation;
    let q = f.attitude;
    println!("{} — {}", s.name, s.method.describe());
    if let Some(why) = &s.method_choice {
        println!("  {why}");
    }
    let b = body(s);
    let m = b.principal_moments;
    println!(
        "  principal moments {:.9e}, {:.9e}, {:.9e} kg m²",
        m[0], m[1], m[2]
    );
    // Rounded to the digits printed before the sign is chosen, so that a component of
    // −1e-17 from the eigensolver prints as +0, not −0.
    let digits = |v: f64| (v * 1e9).round() / 1e9 + 0.0;
    for (i, a) in b.principal_axes.iter().enumerate() {
        println!(
            "    axis {}: [{:+.9}, {:+.9}, {:+.9}]",
            i + 1,
            digits(a[0]),
            digits(a[1]),
            digits(a[2])
        );
    }
    if let Some(line) = hub_remainder_line(s) {
        println!("{line}");
    }
    println!(
        "  status: {}{}",
        o.status.label(),
        match &o.status {
            Status::Stopped { condition } => format!(" ({condition})"),
            _ => String::new(),
        }
    );
    println!("  t = {}", crate::timefmt::seconds(f.t));
    println!(
        "  ω = [{:.9e}, {:.9e}, {:.9e}] rad/s",
        f.omega[0], f.omega[1], f.omega[2]
    );
    println!(
        "  q = {{w: {:.12}, x: {:.12}, y: {:.12}, z: {:.12}}}",
        q.w, q.i, q.j, q.k
    );
    println!(
        "  T = {:.12e} J   |H| = {:.12e} N m s   nutation {:.6}°",
        f.kinetic_energy,
        f.h_norm,
        f.nutation_angle.to_degrees()
    );
    if !s.spacecraft.effectors().is_empty() {
        println!(
            "  elastic {:.6e} J   dissipated {:.6e} J   ({} effectors, {} states)",
            f.elastic_energy,
            f.dissipated_energy,
            s.spacecraft.effectors().len(),
            crate::integrate::OdeSystem::dim(&s.spacecraft)
        );
    }
    let (label, energy) = if s.spacecraft.effectors().is_empty() {
        ("T", "drift")
    } else {
        ("T+V+W", "drift")
    };
    if s.spacecraft.conserves_momentum() {
        println!(
            "  {energy}: |H| {:.3e}  H_N {:.3e}  {label} {:.3e}  |q| {:.3e}",
            o.drift.h_norm_rel, o.drift.h_inertial_rel, o.drift.energy_rel, o.drift.q_norm
        );
    } else if s.spacecraft.conserves_energy() {
        println!(
            "  change (external torque): |H| {:.3e}  H_N {:.3e}; {energy}: {label} {:.3e}  \
             |q| {:.3e}",
            o.drift.h_norm_rel, o.drift.h_inertial_rel, o.drift.energy_rel, o.drift.q_norm
        );
    } else {
        println!(
            "  prescribed hub motion: momentum and energy are not conserved; {energy}: |q| \
             {:.3e}",
            o.drift.q_norm
        );
    }
    println!(
        "  work: {} steps ({} rejected), {} RHS evaluations, {} samples, {:.3} s wall",
        o.stats.steps, o.stats.rejected_steps, o.stats.rhs_evaluations, o.samples, o.wall_time
    );
    if s.method.is_implicit() {
        println!(
            "  implicit: {} Newton iterations, {} Jacobians, {} LU factorisations",
            o.stats.newton_iterations, o.stats.jacobian_evaluations, o.stats.factorizations
        );
    }
    for e in o.events.iter().take(PRINTED_EVENTS) {
        println!(
            "  event: t = {}  {}{}",
            crate::timefmt::seconds(e.t),
            e.condition,
            if e.terminal { " (stop)" } else { "" }
        );
    }
    let more = (o.events.len() - o.events.len().min(PRINTED_EVENTS)) as u64 + o.events_not_kept;
    if more > 0 {
        println!(
            "  … and {more} more events (all are in the log and in --summary; `once: true` or \
             `for: SECONDS` on a condition records only what answers the question)"
        );
    }
    if let Some(p) = mcap {
        println!("  log: {}", p.display());
    }
}

/// Parses `K/N` (1 ≤ K ≤ N).
fn parse_shard(text: &str) -> Result<[u64; 2], String> {
    let bad = || format!("--shard {text}: expected K/N with 1 ≤ K ≤ N, e.g. 2/8");
    let (k, n) = text.split_once('/').ok_or_else(bad)?;
    let k: u64 = k.trim().parse().map_err(|_| bad())?;
    let n: u64 = n.trim().parse().map_err(|_| bad())?;
    if k == 0 || k > n {
        return Err(bad());
    }
    Ok([k, n])
}

/// Running statistics shown on the progress bar.
#[derive(Default)]
struct CampaignProgress {
    done: u64,
    reached: u64,
    time_sum: f64,
    failed: u64,
}

fn montecarlo_cmd(
    path: &Path,
    runs: Option<u64>,
    seed: Option<u64>,
    threads: Option<usize>,
    shard: Option<&str>,
    out: Option<PathBuf>,
    quiet: bool,
) -> i32 {
    use crate::montecarlo;
    let prep = match montecarlo::load(path, runs, seed) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let shard = match shard.map(parse_shard).transpose() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if let Some([_, n]) = shard
        && n > prep.campaign.runs
    {
        eprintln!(
            "error: --shard: {n} shards for {} runs would leave some empty; use at most {} shards",
            prep.campaign.runs, prep.campaign.runs
        );
        return EXIT_BAD_INPUT;
    }
    if threads == Some(0) {
        eprintln!("error: --threads: expected at least 1");
        return EXIT_BAD_INPUT;
    }
    let threads = threads.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let range = match shard {
        Some([k, n]) => montecarlo::shard_range(prep.campaign.runs, k, n),
        None => 0..prep.campaign.runs,
    };
    // The table is held in memory until the outputs are written: refuse up front a campaign
    // whose table cannot fit, rather than fail (or swap) hours later.
    let need_mib = (range.end - range.start) as f64 * TABLE_BYTES_PER_RUN / 1048576.0 + 50.0;
    if let Some(available) = available_memory_mib()
        && need_mib > 0.8 * available
    {
        eprintln!(
            "error: {}: {} runs need about {need_mib:.0} MiB for the campaign's table, and this \
             machine has {available:.0} MiB available; split the campaign into shards \
             (--shard K/N, docs/cluster.md), each holding its own runs only",
            path.display(),
            range.end - range.start
        );
        return EXIT_BAD_INPUT;
    }
    let dir = out.unwrap_or_else(|| {
        let base = PathBuf::from("logs").join(format!("{}-montecarlo", prep.scenario.name));
        match shard {
            Some([k, _]) => base.join(format!("shard-{k}")),
            None => base,
        }
    });
    if let Err(e) = std::fs::create_dir_all(&dir).and_then(|()| probe_writable(&dir.join("x"))) {
        eprintln!("error: cannot write to {}: {e}", dir.display());
        return EXIT_BAD_INPUT;
    }
    // A previous campaign's files go first, so a run that dies leaves no stale manifest.
    if let Err(e) = crate::montecarlo::output::clear_outputs(&dir) {
        eprintln!("error: {e}");
        return EXIT_BAD_INPUT;
    }
    let interrupt = campaign_interrupt();
    let total = range.end - range.start;
    if !quiet {
        eprintln!(
            "{}: {} runs{} on {threads} thread(s), seed {} → {}",
            prep.scenario.name,
            total,
            shard.map_or(String::new(), |[k, n]| format!(" (shard {k} of {n})")),
            prep.campaign.seed,
            dir.display()
        );
    }
    let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(total);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} runs, ETA {eta} | {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let stats = std::sync::Mutex::new(CampaignProgress::default());
    let primary = prep.primary_event;
    let on_row = |row: &crate::montecarlo::Row| {
        let Ok(mut s) = stats.lock() else { return };
        s.done += 1;
        if !row.status.ok() {
            s.failed += 1;
        }
        if let Some(t) = primary.and_then(|j| row.values[j]) {
            s.reached += 1;
            s.time_sum += t;
        }
        if let Some(b) = &bar {
            b.inc(1);
            let mean = match s.time_sum / s.reached.max(1) as f64 {
                _ if s.reached == 0 => String::new(),
                t if t < 120.0 => format!(", mean {t:.1} s"),
                t => format!(", mean {:.1} min", t / 60.0),
            };
            let flat = if primary.is_some() {
                format!("flat spin in {}/{}{mean}; ", s.reached, s.done)
            } else {
                String::new()
            };
            b.set_message(format!("{flat}{} failed", s.failed));
        }
    };
    let started = std::time::Instant::now();
    let result = prep.execute(range, threads, &interrupt, &on_row);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let (rows, partial) = match result {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_IO;
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    if rows.is_empty() && partial {
        eprintln!("interrupted before any run finished; nothing was written");
        return EXIT_INTERRUPTED;
    }
    WRITING_OUTPUTS.store(true, Ordering::SeqCst);
    let written =
        match montecarlo::output::write_outputs(&dir, &prep, &rows, shard, partial, &interrupt) {
            Ok(w) => w,
            Err(e) => {
                eprintln!(
                    "error: {e}; the campaign's outputs in {} are incomplete: the files written \
                     before this one are whole, but the manifest campaign.json was not written, \
                     so `merge` refuses the directory (a re-run with the same seed writes the \
                     same result)",
                    dir.display()
                );
                return EXIT_IO;
            }
        };
    if !quiet {
        if let Ok(text) = std::fs::read_to_string(dir.join("summary.txt")) {
            print!("{text}");
        }
        let memory =
            peak_memory_mib().map_or(String::new(), |m| format!(", peak memory {m:.0} MiB"));
        eprintln!(
            "{} runs in {seconds:.2} s ({:.2} runs/s on {threads} thread(s){memory}) → {}",
            rows.len(),
            rows.len() as f64 / seconds.max(1e-9),
            dir.display()
        );
    }
    if partial {
        eprintln!(
            "interrupted: {} of {total} runs finished; the result in {} is marked partial \
             (no campaign.mcap)",
            rows.len(),
            dir.display()
        );
        return EXIT_INTERRUPTED;
    }
    if written.mcap_interrupted {
        eprintln!(
            "interrupted while logging the worst, median and best runs: every run is in {}, \
             but campaign.mcap was not written",
            dir.display()
        );
        return EXIT_INTERRUPTED;
    }
    0
}

/// Set while a campaign writes its outputs: a second Ctrl-C then no longer exits at once,
/// so the outputs of the finished runs are not lost half-way.
static WRITING_OUTPUTS: AtomicBool = AtomicBool::new(false);

/// The Ctrl-C flag of `montecarlo` and `merge`: the first Ctrl-C sets it (runs under way are
/// abandoned, the MCAP's re-runs stop); a second exits at once unless outputs are being
/// written.
fn campaign_interrupt() -> Arc<AtomicBool> {
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = interrupt.clone();
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) && !WRITING_OUTPUTS.load(Ordering::SeqCst) {
            std::process::exit(EXIT_INTERRUPTED);
        }
    });
    interrupt
}

fn merge_cmd(dirs: &[PathBuf], out: &Path, quiet: bool) -> i32 {
    use crate::montecarlo;
    let (prep, rows) = match montecarlo::output::merge(dirs) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let interrupt = campaign_interrupt();
    WRITING_OUTPUTS.store(true, Ordering::SeqCst);
    let written =
        match montecarlo::output::write_outputs(out, &prep, &rows, None, false, &interrupt) {
            Ok(w) => w,
            Err(e) => {
                eprintln!(
                    "error: {e}; the merged result in {} is incomplete (no campaign.json)",
                    out.display()
                );
                return EXIT_IO;
            }
        };
    if written.mcap_interrupted {
        eprintln!(
            "interrupted: the merged result is in {}, but campaign.mcap was not written",
            out.display()
        );
        return EXIT_INTERRUPTED;
    }
    if !quiet {
        if let Ok(text) = std::fs::read_to_string(out.join("summary.txt")) {
            print!("{text}");
        }
        eprintln!(
            "merged {} shards ({} runs) → {}",
            dirs.len(),
            rows.len(),
            out.display()
        );
    }
    0
}

/// Peak resident memory of this process (MiB), from Linux's `/proc/self/status` (`VmHWM`).
/// Memory a campaign holds per run at its peak, when the table, its CSV text and its Parquet
/// bytes coexist (measured: about 1.8 kB with the test campaign's 32 columns;
/// docs/montecarlo.md).
const TABLE_BYTES_PER_RUN: f64 = 2000.0;

/// `MemAvailable` of /proc/meminfo (MiB), where there is one.
fn available_memory_mib() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
