//! `polhode bench …`: timing, work-precision, drift, stability and separatrix benchmarks.

use super::args::BenchCommand;
use super::{EXIT_BAD_INPUT, EXIT_FAILED, load, make_dir, report_files};
use std::path::Path;

/// Runs one benchmark command.
pub(super) fn bench_cmd(what: BenchCommand) -> i32 {
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
        BenchCommand::Averaged {
            scenarios,
            rtol,
            times,
            repeats,
        } => {
            if let Some(r) = rtol
                && !(r.is_finite() && (1e-15..1.0).contains(&r))
            {
                eprintln!("error: --rtol: expected a tolerance from 1e-15 to 1, got {r}");
                return EXIT_BAD_INPUT;
            }
            if times.iter().any(|t| !(t.is_finite() && *t >= 0.0)) {
                eprintln!("error: --times: expected non-negative times in seconds");
                return EXIT_BAD_INPUT;
            }
            for path in &scenarios {
                match crate::bench::secular::compare(path, rtol, &times, repeats) {
                    Ok(c) => println!("{}", serde_json::to_string(&c).expect("serialisable")),
                    Err(e) => {
                        eprintln!("error: {}: {e}", path.display());
                        return EXIT_FAILED;
                    }
                }
            }
            0
        }
        BenchCommand::LongHorizon {
            scenarios,
            times,
            out,
        } => {
            if times.iter().any(|t| !(t.is_finite() && *t >= 0.0)) {
                eprintln!("error: --times: expected non-negative times in seconds");
                return EXIT_BAD_INPUT;
            }
            if let Err(code) = make_dir(&out.out) {
                return code;
            }
            let mut files = Vec::new();
            for path in &scenarios {
                match crate::bench::secular::long_horizon(
                    path,
                    &times,
                    &out.out,
                    bench_progress(out.quiet),
                ) {
                    Ok(f) => files.extend(f),
                    Err(e) => return report_files(Err(e), out.quiet),
                }
            }
            report_files(Ok(files), out.quiet)
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

/// Progress lines of a benchmark on stderr, unless `quiet`.
fn bench_progress(quiet: bool) -> impl FnMut(&str) {
    move |line: &str| {
        if !quiet {
            eprintln!("{line}");
        }
    }
}
