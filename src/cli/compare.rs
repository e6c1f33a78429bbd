//! `polhode compare`: several fidelities of one scene side by side.

use super::{EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_IO, load};
use crate::log::write_atomically;
use crate::scenario::{self, Overrides};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Runs each scenario and writes the table, chart, series and JSON asked for.
pub(super) fn compare_cmd(
    paths: &[PathBuf],
    chart: Option<&Path>,
    csv: Option<&Path>,
    json: Option<&Path>,
    duration: Option<f64>,
    events: &[String],
    methods: &[String],
) -> i32 {
    // Each scenario with each `--method` (or its own).
    let methods: Vec<Option<String>> = if methods.is_empty() {
        vec![None]
    } else {
        methods.iter().cloned().map(Some).collect()
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
        for method in &methods {
            let overrides = Overrides {
                duration,
                method: method.clone(),
                ..Overrides::default()
            };
            match load(p, &overrides) {
                Ok(mut s) => {
                    if methods.len() > 1 {
                        // One row per method: the rows are told apart by it.
                        s.name = format!("{} [{}]", s.name, s.method.name());
                    }
                    scenarios.push(s)
                }
                Err(c) => return c,
            }
        }
    }
    // No output may be a scenario or another output (nothing runs otherwise).
    let mut plan = crate::outputs::Plan::new();
    for p in paths {
        plan.input("the scenario", p);
    }
    for (what, p) in [("--chart", chart), ("--csv", csv), ("--json", json)] {
        match p {
            Some(p) if p != Path::new("-") => {
                plan.output(what, p);
            }
            _ => {}
        }
    }
    if let Err(e) = plan.check() {
        eprintln!("error: {e}");
        return EXIT_BAD_INPUT;
    }
    // Every row keeps its (t, nutation) series until the chart is drawn: two values a sample,
    // bounded by the longest row's.
    if let Some(s) = scenarios
        .iter()
        .max_by(|a, b| (a.duration * a.output_rate).total_cmp(&(b.duration * b.output_rate)))
        && let Err(e) = crate::resources::check_sample_memory(
            &format!("{}: the compared runs' series", s.path.display()),
            s.duration,
            s.output_rate,
            2 * scenarios.len(),
        )
    {
        eprintln!("error: {e}");
        return EXIT_BAD_INPUT;
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
