//! The `polhode` command line, one file per command (documented in docs/cli.md): `run`,
//! `check`, `compare`, `linearize`, `bench`, `montecarlo` and `merge`, `plot`.
//!
//! Exit codes: 0 success; 2 bad input (scenario, options, unwritable output; nothing written);
//! 1 an I/O failure during the run; 3 the integration failed (the log up to the failure is
//! kept, marked partial); 130 interrupted by Ctrl-C (the log is kept, marked partial).

mod args;
mod bench;
mod check;
mod compare;
mod linearize;
mod montecarlo;
mod plot;
mod run;
mod summary;

pub use args::MethodArgs;
pub use linearize::linearize_json;
pub use summary::summary_json;

use crate::scenario::{self, Overrides, Scenario};
use args::{Cli, Command};
use clap::Parser;
use std::path::{Path, PathBuf};

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
        Command::Check { scenarios } => check::check(&scenarios),
        Command::Compare {
            scenarios,
            chart,
            csv,
            json,
            duration,
            events,
            methods,
        } => compare::compare_cmd(
            &scenarios,
            chart.as_deref(),
            csv.as_deref(),
            json.as_deref(),
            duration,
            &events,
            &methods,
        ),
        Command::Linearize { scenario, json } => {
            linearize::linearize_cmd(&scenario, json.as_deref())
        }
        Command::Montecarlo {
            scenario,
            runs,
            seed,
            threads,
            shard,
            out,
            method,
            no_lanes,
            lane_width,
            quiet,
        } => montecarlo::montecarlo_cmd(
            &scenario,
            montecarlo::Options {
                runs,
                seed,
                threads,
                shard: shard.as_deref(),
                out,
                method,
                lanes: !no_lanes,
                lane_width,
                quiet,
            },
        ),
        Command::Merge { dirs, out, quiet } => montecarlo::merge_cmd(&dirs, &out, quiet),
        Command::Plot { log, out, quiet } => plot::plot_cmd(&log, out, quiet),
        Command::Bench { what } => bench::bench_cmd(what),
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
            live,
            port,
            realtime,
            live_linger,
        } => {
            let overrides = Overrides {
                max_log_mb,
                ..method.overrides(duration, out)
            };
            let outputs = run::RunOutputs {
                no_log,
                summary: summary.as_deref(),
                csv: csv.as_deref(),
                parquet: parquet.as_deref(),
                live: live.then_some(run::LiveOptions {
                    port,
                    realtime,
                    linger: live_linger,
                }),
            };
            run::run(&scenario, &overrides, &outputs, quiet)
        }
    }
}

/// Creates `dir` and its parents, or reports why not (exit code 1).
fn make_dir(dir: &Path) -> Result<(), i32> {
    std::fs::create_dir_all(dir).map_err(|e| {
        eprintln!("error: {}: {e}", dir.display());
        EXIT_IO
    })
}

/// Lists the files a command wrote (unless `quiet`); exit code 3 with its error.
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

/// Reads and validates a scenario, printing the located error (exit code 2).
fn load(path: &Path, overrides: &Overrides) -> Result<Scenario, i32> {
    scenario::load(path, overrides).map_err(|e| {
        eprintln!("error: {e}");
        EXIT_BAD_INPUT
    })
}

/// Checks up front that a file can be created at `path` (without leaving one behind).
fn probe_writable(path: &Path) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::other("it is a directory"));
    }
    crate::log::check_replaceable(path)?;
    let (_probe, _) = crate::outputs::TempFile::beside(path, "probe")?;
    Ok(())
}
