//! The command line's grammar: subcommands and their options (clap derive).

use crate::scenario::Overrides;
use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "polhode",
    version,
    about = "Spacecraft attitude dynamics with energy dissipation"
)]
/// The whole command line.
pub(super) struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub(super) command: Command,
}

/// The subcommands (docs/cli.md).
#[derive(Subcommand, Debug)]
pub(super) enum Command {
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
        /// Write a JSON summary here (or print it, in place of the printed summary, with
        /// `--summary -`).
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
        /// Serve the run as it computes to Foxglove over its WebSocket protocol
        /// (ws://localhost:8765 unless --port), the same topics as the log (docs/viewing.md).
        #[arg(long)]
        live: bool,
        /// Port of the live view (0: any free port, printed on stderr).
        #[arg(long, requires = "live", default_value_t = crate::log::live::DEFAULT_PORT)]
        port: u16,
        /// Pace the run at X times wall-clock time (X s of sim time per second); without it
        /// a live run goes at full speed.
        #[arg(long, value_name = "X", requires = "live")]
        realtime: Option<f64>,
        /// Seconds the live view stays up after the run ends (default: until Ctrl-C).
        #[arg(long, value_name = "S", requires = "live")]
        live_linger: Option<f64>,
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
        /// Run every scenario with this method instead of its own; repeatable (one row per
        /// scenario and method, e.g. `--method dop853 --method averaged`).
        #[arg(long = "method", value_name = "METHOD")]
        methods: Vec<String>,
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
        /// Integration method of every run instead of the scenario's (e.g. `averaged`).
        #[arg(long)]
        method: Option<String>,
        /// Integrate one run after another on each thread even where the scene has a lane
        /// form (the rows are the same; for comparison).
        #[arg(long)]
        no_lanes: bool,
        /// Runs integrated at once per thread where the scene has a lane form: 8 (AVX-512),
        /// 4 (AVX2) or 1; default the widest this processor has, and a width it lacks falls
        /// back to the next narrower (the rows are the same; for comparison).
        #[arg(long, value_name = "W", value_parser = ["1", "4", "8"], conflicts_with = "no_lanes")]
        lane_width: Option<String>,
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
pub(super) enum BenchCommand {
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
    /// The averaged method against dop853 (rtol 1e-10) on the same scene: speed-up, event
    /// times and energies, as JSON (one line per scene).
    Averaged {
        /// Scenario YAML files.
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
        /// rtol of the averaged method (default: the scene's).
        #[arg(long)]
        rtol: Option<f64>,
        /// Times (s, on the scene's output grid) at which to compare T and |H|.
        #[arg(long, value_delimiter = ',')]
        times: Vec<f64>,
        /// Timed runs of each method; the fastest counts.
        #[arg(long, default_value_t = 5)]
        repeats: usize,
    },
    /// Long-horizon work-precision: T's error against wall time for dop853 and averaged on
    /// dissipating scenes (charts and CSV).
    LongHorizon {
        /// Scenario YAML files.
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
        /// Times (s, on each scene's output grid) at which T is compared.
        #[arg(long, value_delimiter = ',', required = true)]
        times: Vec<f64>,
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
pub(super) struct OutArgs {
    /// Directory for the charts (SVG and PNG) and CSV.
    #[arg(long, default_value = "docs/figures")]
    pub(super) out: PathBuf,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub(super) quiet: bool,
}

/// Options of a benchmark sweep over methods and settings.
#[derive(clap::Args, Debug, Clone)]
pub(super) struct SweepArgs {
    /// Methods to include (comma-separated labels; default all).
    #[arg(long, value_delimiter = ',')]
    pub(super) methods: Vec<String>,
    /// Directory for the charts (SVG and PNG) and CSV.
    #[arg(long, default_value = "docs/figures")]
    pub(super) out: PathBuf,
    /// A method's sweep stops after the first solve slower than this (s).
    #[arg(long, default_value_t = 1.0)]
    pub(super) budget: f64,
    /// Most settings tried per method.
    #[arg(long, default_value_t = 10)]
    pub(super) max_points: usize,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub(super) quiet: bool,
}

/// Method options shared by `run` and `bench point`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct MethodArgs {
    /// Integration method: rk4, dopri5, dop853, radau5, gauss, lie, splitting, exact, averaged or auto.
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
