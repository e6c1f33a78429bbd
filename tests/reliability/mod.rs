//! Shared by the hardening tests (tests/corpus.rs, tests/faults.rs): running the binary, and
//! recording each case's observed outcome for docs/reliability.md.
#![allow(dead_code)]

use std::io::Write;
use std::path::PathBuf;
use std::process::Command;

/// The `polhode` binary under test.
pub fn polhode() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polhode"))
}

/// A fresh, empty scratch directory for one test, removed when it passes.
pub fn scratch(name: &str) -> crate::common::Scratch {
    crate::common::Scratch::new("polhode-hard", name)
}

/// What a case did, as observed.
pub struct Observed {
    /// Exit code (`None`: no process, a library-level case).
    pub code: Option<i32>,
    /// The message the user saw (stderr, or its relevant line).
    pub message: String,
    /// What was left on disk, described.
    pub left: Vec<String>,
}

/// Appends one row to `$POLHODE_RELIABILITY_DIR/<table>.tsv` when that variable is set
/// (`scripts/reliability.sh` sets it and turns the rows into docs/reliability.md's tables).
pub fn record(table: &str, case: &str, what: &str, seen: &Observed) {
    let Some(dir) = std::env::var_os("POLHODE_RELIABILITY_DIR") else {
        return;
    };
    let dir = PathBuf::from(dir);
    std::fs::create_dir_all(&dir).unwrap();
    let clean = |s: &str| s.replace(['\t', '\n'], " ");
    let code = seen.code.map_or("—".to_string(), |c| c.to_string());
    let left = if seen.left.is_empty() {
        "nothing".to_string()
    } else {
        seen.left.join("; ")
    };
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(dir.join(format!("{table}.tsv")))
        .unwrap();
    writeln!(
        f,
        "{}\t{}\t{}\t{}\t{}",
        clean(case),
        clean(what),
        code,
        clean(&seen.message),
        clean(&left)
    )
    .unwrap();
}
