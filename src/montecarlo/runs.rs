//! The finished runs as the summary reads them: in run order, as many times as it needs.
//! A campaign in memory is read from its rows; a streamed campaign from a scratch file of
//! their values ([`RunStore`]), so that its memory does not grow with the number of runs.

use super::table::Row;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// What the summary's passes read of a run.
#[derive(Debug, Clone, Copy)]
pub struct RunView<'a> {
    /// Run index.
    pub run: u64,
    /// Whether its metrics are usable (complete or stopped).
    pub ok: bool,
    /// One value per column.
    pub values: &'a [Option<f64>],
}

/// Finished runs that can be read again, in run order.
pub trait Runs {
    /// Calls `each` on every run, in run order.
    fn scan(&self, each: &mut dyn FnMut(RunView<'_>)) -> Result<(), String>;
}

impl Runs for &[Row] {
    fn scan(&self, each: &mut dyn FnMut(RunView<'_>)) -> Result<(), String> {
        for r in self.iter() {
            each(RunView {
                run: r.run,
                ok: r.status.ok(),
                values: &r.values,
            });
        }
        Ok(())
    }
}

/// Writes the runs' values to a scratch file, a fixed-size record per run: the run index
/// (8 bytes), the usable flag (1), then per column a presence byte and the value's 8 bytes.
pub struct RunStore {
    path: PathBuf,
    out: BufWriter<File>,
    columns: usize,
    record: Vec<u8>,
}

impl RunStore {
    /// Creates the scratch file `path` (a new name) for runs with `columns` values.
    pub fn create(path: &Path, columns: usize) -> Result<Self, String> {
        let file = File::options()
            .write(true)
            .create_new(true)
            .open(path)
            .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 20, file),
            columns,
            record: Vec::with_capacity(9 + 9 * columns),
        })
    }

    /// Appends `row` (rows must come in run order).
    pub fn push(&mut self, row: &Row) -> Result<(), String> {
        let r = &mut self.record;
        r.clear();
        r.extend_from_slice(&row.run.to_le_bytes());
        r.push(u8::from(row.status.ok()));
        for v in &row.values {
            r.push(u8::from(v.is_some()));
            r.extend_from_slice(&v.unwrap_or(0.0).to_le_bytes());
        }
        self.out
            .write_all(r)
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))
    }

    /// Ends writing; the runs can then be read back.
    pub fn finish(mut self) -> Result<StoredRuns, String> {
        self.out
            .flush()
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))?;
        Ok(StoredRuns {
            path: std::mem::take(&mut self.path),
            columns: self.columns,
        })
    }
}

impl Drop for RunStore {
    fn drop(&mut self) {
        if !self.path.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// The runs of a finished [`RunStore`]; the scratch file is removed when this is dropped.
pub struct StoredRuns {
    path: PathBuf,
    columns: usize,
}

impl Runs for StoredRuns {
    fn scan(&self, each: &mut dyn FnMut(RunView<'_>)) -> Result<(), String> {
        let what = |e: std::io::Error| format!("cannot read {}: {e}", self.path.display());
        let file = File::open(&self.path).map_err(what)?;
        let mut input = BufReader::with_capacity(1 << 20, file);
        let mut record = vec![0u8; 9 + 9 * self.columns];
        let mut values = vec![None; self.columns];
        loop {
            match input.read_exact(&mut record) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(()),
                Err(e) => return Err(what(e)),
            }
            let word = |at: usize| {
                let mut b = [0u8; 8];
                b.copy_from_slice(&record[at..at + 8]);
                b
            };
            for (k, v) in values.iter_mut().enumerate() {
                let at = 9 + 9 * k;
                *v = (record[at] == 1).then(|| f64::from_le_bytes(word(at + 1)));
            }
            each(RunView {
                run: u64::from_le_bytes(word(0)),
                ok: record[8] == 1,
                values: &values,
            });
        }
    }
}

impl Drop for StoredRuns {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::montecarlo::RunStatus;

    #[test]
    fn a_store_reads_back_what_the_rows_hold() {
        let rows = vec![
            Row {
                run: 3,
                status: RunStatus::Complete,
                message: String::new(),
                values: vec![Some(-0.0), None, Some(f64::NAN)],
            },
            Row {
                run: 9,
                status: RunStatus::Failed,
                message: "x".into(),
                values: vec![None, Some(1e-310), Some(f64::INFINITY)],
            },
        ];
        let dir = std::env::temp_dir().join(format!("polhode-store-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("runs.scratch");
        let mut store = RunStore::create(&path, 3).unwrap();
        for r in &rows {
            store.push(r).unwrap();
        }
        let stored = store.finish().unwrap();
        let collect = |src: &dyn Runs| {
            let mut seen = Vec::new();
            src.scan(&mut |v| {
                let bits: Vec<Option<u64>> = v.values.iter().map(|x| x.map(f64::to_bits)).collect();
                seen.push((v.run, v.ok, bits));
            })
            .unwrap();
            seen
        };
        assert_eq!(collect(&stored), collect(&rows.as_slice()));
        drop(stored);
        assert!(!path.exists());
        let _ = std::fs::remove_dir(&dir);
    }
}
