//! `polhode montecarlo` and `polhode merge`: campaigns, whole or in shards.

use super::{EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_IO};
use crate::lanes::ensemble::Engine;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

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

/// The options of `polhode montecarlo`.
pub(super) struct Options<'a> {
    pub(super) runs: Option<u64>,
    pub(super) seed: Option<u64>,
    pub(super) threads: Option<usize>,
    pub(super) shard: Option<&'a str>,
    pub(super) out: Option<PathBuf>,
    pub(super) method: Option<String>,
    /// Lanes where the scene has a lane form (`--no-lanes` clears it).
    pub(super) lanes: bool,
    /// `--lane-width`: "1", "4" or "8" (checked by the parser); None: the widest.
    pub(super) lane_width: Option<String>,
    pub(super) quiet: bool,
}

/// Runs a campaign (or one shard of it) and writes its outputs into `out`.
pub(super) fn montecarlo_cmd(path: &Path, options: Options) -> i32 {
    use crate::montecarlo;
    let Options {
        runs,
        seed,
        threads,
        shard,
        out,
        method,
        lanes,
        lane_width,
        quiet,
    } = options;
    let engine = match lane_width.as_deref() {
        Some("1") => Engine::Scalar,
        Some("4") => Engine::Avx2,
        Some(_) => Engine::Avx512,
        None => Engine::Auto,
    };
    let prep = match montecarlo::load_with_method(path, runs, seed, method) {
        Ok(p) => p.with_lane_engine(engine).with_integration(lanes),
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
    let threads = match montecarlo::thread_count(threads, "--threads") {
        Ok((t, note)) => {
            if let Some(note) = note {
                eprintln!("warning: {note}");
            }
            t
        }
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let range = match shard {
        Some([k, n]) => montecarlo::shard_range(prep.campaign.runs, k, n),
        None => 0..prep.campaign.runs,
    };
    let dir = out.unwrap_or_else(|| {
        // The scenario's name is user text: one plain component, whatever it holds.
        let suffix = "-montecarlo";
        let name = crate::outputs::sanitize(&prep.scenario.name, suffix.len());
        let base = PathBuf::from("logs").join(format!("{name}{suffix}"));
        match shard {
            Some([k, _]) => base.join(format!("shard-{k}")),
            None => base,
        }
    });
    // Nothing is written unless the directory may hold the outputs: not the scenario's,
    // new, empty or polhode's, and no other campaign writing into it.
    let owned = crate::outputs::Plan::new()
        .input("the scenario", path)
        .output_dir("--out", &dir)
        .check()
        .and_then(|()| montecarlo::output::claim(&dir));
    let owned = match owned {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    // The tables are written as the runs finish.
    let mut writer = match montecarlo::output::CampaignWriter::create(owned, &prep, shard) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    writer.use_threads(threads);
    let interrupt = campaign_interrupt();
    let total = range.end - range.start;
    if !quiet {
        eprintln!(
            "{}: {} runs{} on {threads} thread(s), seed {} → {}\n  integrated {}",
            prep.scenario.name,
            total,
            shard.map_or(String::new(), |[k, n]| format!(" (shard {k} of {n})")),
            prep.campaign.seed,
            dir.display(),
            prep.integration.describe()
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
    let result = prep.execute_streaming(range, threads, &interrupt, &on_row, &mut |row| {
        writer.push(row)
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let partial = match result {
        Ok(p) => p,
        Err(e) => {
            eprintln!(
                "error: {e}; nothing was kept (a re-run with the same seed writes the same result)"
            );
            return EXIT_IO;
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let rows = writer.rows();
    if rows == 0 && partial {
        eprintln!("interrupted before any run finished; nothing was written");
        return EXIT_INTERRUPTED;
    }
    WRITING_OUTPUTS.store(true, Ordering::SeqCst);
    let written = match writer.finish(partial, &interrupt) {
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
            "{rows} runs in {seconds:.2} s ({:.2} runs/s on {threads} thread(s){memory}) → {}",
            rows as f64 / seconds.max(1e-9),
            dir.display()
        );
    }
    if partial {
        eprintln!(
            "interrupted: {rows} of {total} runs finished; the result in {} is marked partial \
             (no campaign.mcap)",
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

/// Combines the shards' outputs in `dirs` into the whole campaign's, in `out`.
pub(super) fn merge_cmd(dirs: &[PathBuf], out: &Path, quiet: bool) -> i32 {
    use crate::montecarlo;
    let shards = match montecarlo::output::check_shards(dirs) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let mut plan = crate::outputs::Plan::new();
    for d in dirs {
        plan.input("the shard", d);
    }
    let owned = match plan
        .output_dir("--out", out)
        .check()
        .and_then(|()| montecarlo::output::claim(out))
    {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let interrupt = campaign_interrupt();
    WRITING_OUTPUTS.store(true, Ordering::SeqCst);
    let (written, rows) = match shards.write(owned, &interrupt) {
        Ok(x) => x,
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
            rows,
            out.display()
        );
    }
    0
}

/// Peak resident memory of this process (MiB), from Linux's `/proc/self/status` (`VmHWM`).
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
