//! `polhode run`: one scenario into its log, tables and summary.

use super::summary::{print_summary, summary_json};
use super::{EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_IO, load, probe_writable};
use crate::log::live::LiveServer;
use crate::log::pacing::Pacing;
use crate::log::{McapLogger, write_atomically};
use crate::scenario::Overrides;
use crate::sim::{self, Control, NullSink, Sink, Status};
use std::io::IsTerminal;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// What `polhode run` writes besides its text.
pub(super) struct RunOutputs<'a> {
    /// No MCAP log.
    pub(super) no_log: bool,
    /// The JSON summary.
    pub(super) summary: Option<&'a Path>,
    /// The sampled telemetry as CSV.
    pub(super) csv: Option<&'a Path>,
    /// The sampled telemetry as Parquet.
    pub(super) parquet: Option<&'a Path>,
    /// The live view (`--live`), if asked for.
    pub(super) live: Option<LiveOptions>,
}

/// `--live` and its options.
pub(super) struct LiveOptions {
    /// Port to serve on (0: any free port).
    pub(super) port: u16,
    /// `--realtime X`: X seconds of sim time per wall-clock second; none: full speed.
    pub(super) realtime: Option<f64>,
    /// `--live-linger S`: seconds the server stays up after the run; none: until Ctrl-C.
    pub(super) linger: Option<f64>,
}

/// Runs the scenario at `path` with `overrides`, writing `outputs`; returns the exit code.
pub(super) fn run(path: &Path, overrides: &Overrides, outputs: &RunOutputs, quiet: bool) -> i32 {
    let no_log = outputs.no_log;
    // `--summary -` prints the JSON summary on standard output, in place of the printed one.
    let summary_to_stdout = outputs.summary == Some(Path::new("-"));
    let summary_path = outputs.summary.filter(|_| !summary_to_stdout);
    let s = match load(path, overrides) {
        Ok(s) => s,
        Err(c) => return c,
    };
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    // No output may be the scenario or another output (nothing is written otherwise).
    let mut plan = crate::outputs::Plan::new();
    plan.input("the scenario", path);
    for (what, p) in [
        ("--summary", summary_path),
        ("--csv", outputs.csv),
        ("--parquet", outputs.parquet),
        ("the log", (!no_log).then_some(s.mcap_path.as_path())),
    ] {
        if let Some(p) = p {
            plan.output(what, p);
        }
    }
    if let Err(e) = plan.check() {
        eprintln!("error: {e}");
        return EXIT_BAD_INPUT;
    }
    if let Some(p) = summary_path
        && let Err(e) = probe_writable(p)
    {
        eprintln!("error: cannot write the summary to {}: {e}", p.display());
        return EXIT_BAD_INPUT;
    }
    if let Some(live) = &outputs.live {
        for (flag, value, least) in [
            ("--realtime", live.realtime, "greater than 0"),
            ("--live-linger", live.linger, "0 or more"),
        ] {
            if let Some(v) = value
                && !(v.is_finite() && (v > 0.0 || (v == 0.0 && flag == "--live-linger")))
            {
                eprintln!("error: {flag} {v}: expected a finite number of seconds {least}");
                return EXIT_BAD_INPUT;
            }
        }
    }
    // The server first: a port that cannot be bound stops the run before any file is made.
    let server = match &outputs.live {
        Some(live) => match LiveServer::start(live.port) {
            Ok(server) => {
                if !quiet {
                    eprintln!(
                        "live view: {} (Foxglove: Open connection → Foxglove WebSocket)",
                        server.url()
                    );
                }
                Some(Arc::new(server))
            }
            Err(e) => {
                eprintln!("error: {e}; choose another port with --port");
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    let mut table = if outputs.csv.is_some() || outputs.parquet.is_some() {
        match crate::log::samples::SampleTable::create(
            &s.spacecraft,
            s.orbit.as_deref(),
            outputs.csv,
            outputs.parquet,
        ) {
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
    let mut logger = if no_log && server.is_none() {
        None
    } else {
        let file = (!no_log).then_some(s.mcap_path.as_path());
        match McapLogger::create_with_live(file, server.clone(), &s, s.omega0.norm()) {
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
    if let Some(l) = logger.as_mut().filter(|l| l.final_path().is_some()) {
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
    let (mut both, mut null);
    let sink: &mut dyn Sink = match (logger.as_mut(), table.as_mut()) {
        (Some(l), Some(t)) => {
            both = crate::log::samples::Both(l, t);
            &mut both
        }
        (Some(l), None) => l,
        (None, Some(t)) => t,
        (None, None) => {
            null = NullSink;
            &mut null
        }
    };
    let result = match outputs.live.as_ref().and_then(|l| l.realtime) {
        Some(speed) => sim::run(&s, &mut Pacing::new(sink, speed), ctl),
        None => sim::run(&s, sink, ctl),
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let outcome = match result {
        Ok(o) => o,
        Err(e) => {
            // Name what was being written: the log, the tables, or both.
            let tables: Vec<String> = outputs
                .csv
                .into_iter()
                .chain(outputs.parquet)
                .map(|p| p.display().to_string())
                .collect();
            let (what, kept) = match (logger.is_some(), tables.is_empty()) {
                (true, true) => (
                    format!("the log {}", s.mcap_path.display()),
                    "no log was kept",
                ),
                (false, _) => (
                    format!("the sampled telemetry {}", tables.join(" / ")),
                    "no table was kept",
                ),
                (true, false) => (
                    format!(
                        "the log {} or the sampled telemetry {}",
                        s.mcap_path.display(),
                        tables.join(" / ")
                    ),
                    "no log was kept, nor any table",
                ),
            };
            eprintln!("error: writing {what} failed: {e}; {kept}");
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
    if let Some(mut l) = logger.take_if(|l| l.final_path().is_none()) {
        // A live view alone: it only gets the run's end on `/log`.
        if let Err(e) = l.end_run(&outcome) {
            eprintln!("warning: the live view did not get the run's end: {e}");
        }
    }
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
    if summary_to_stdout {
        print!("{}", summary_json(&s, &outcome, written.as_deref()));
    } else if !quiet {
        print_summary(&s, &outcome, written.as_deref());
        for p in &tables {
            println!("  table: {}", p.display());
        }
    }
    for w in &outcome.warnings {
        eprintln!("warning: {}", w.message);
    }
    if let (Some(server), Some(live)) = (server, &outputs.live)
        && !matches!(outcome.status, Status::Interrupted)
    {
        linger(server, live.linger, &interrupt, quiet);
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

/// Keeps the live view up after the run, so that a viewer can look back over it: for
/// `seconds`, or until Ctrl-C when none; then stops the server.
fn linger(server: Arc<LiveServer>, seconds: Option<f64>, interrupt: &AtomicBool, quiet: bool) {
    if !quiet {
        match seconds {
            Some(t) if t > 0.0 => eprintln!(
                "the run is over; the live view stays up at {} for {t} s (Ctrl-C ends it)",
                server.url()
            ),
            Some(_) => {}
            None => eprintln!(
                "the run is over; the live view stays up at {} until Ctrl-C",
                server.url()
            ),
        }
    }
    let end = seconds.map(|t| Instant::now() + Duration::from_secs_f64(t));
    while !interrupt.load(Ordering::SeqCst) && end.is_none_or(|end| Instant::now() < end) {
        std::thread::sleep(Duration::from_millis(50));
    }
    // The log, the only other holder, is finished by now.
    if let Ok(server) = Arc::try_unwrap(server) {
        server.stop();
    }
}
