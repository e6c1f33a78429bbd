//! Writing a file whole or not at all: under a temporary name in the destination directory,
//! unique to the writer (process id and a process-wide counter, so threads and processes
//! writing the same target never share one), synced, then renamed over the target.

use super::inputs::check_not_input;
use std::fs::File;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary files made by this process so far (the counter in their names).
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A fresh temporary name beside `target`: `.<name>.<pid>.<n>.tmp` in its directory
/// (`name` is its file name, or `default_name`).
pub fn temporary_path(target: &Path, default_name: &str) -> PathBuf {
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = target
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| default_name.into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Whether `name` is a temporary name that [`temporary_path`] gives for the file `of`.
pub fn is_temporary_of(name: &str, of: &str) -> bool {
    let Some(rest) = name
        .strip_prefix('.')
        .and_then(|n| n.strip_suffix(".tmp"))
        .and_then(|n| n.strip_prefix(of))
        .and_then(|n| n.strip_prefix('.'))
    else {
        return false;
    };
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    matches!(rest.split_once('.'), Some((pid, n)) if digits(pid) && digits(n))
}

/// A temporary file that is removed when dropped (on errors and panics alike) unless it was
/// kept by renaming it to its final name.
pub struct TempFile {
    path: PathBuf,
    keep: bool,
}

impl TempFile {
    /// Creates a fresh temporary file ([`temporary_path`]) beside `target`, whose directory
    /// must exist. The name is new: an existing file is never opened.
    pub fn beside(target: &Path, default_name: &str) -> io::Result<(TempFile, File)> {
        let path = temporary_path(target, default_name);
        let file = File::options().write(true).create_new(true).open(&path)?;
        Ok((TempFile { path, keep: false }, file))
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames it to `to` (never onto an input of this process: [`check_not_input`]).
    pub fn persist(mut self, to: &Path) -> io::Result<()> {
        check_not_input(to)?;
        std::fs::rename(&self.path, to)?;
        self.keep = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.keep {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Writes `bytes` to `path` through a temporary file and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    check_replaceable(path)?;
    check_not_input(path)?;
    let result = (|| {
        let (temp, mut f) = TempFile::beside(path, "out")?;
        f.write_all(bytes)?;
        f.sync_all()?;
        temp.persist(path)
    })();
    result.map_err(crate::log::with_hint)
}

/// Refuses to replace anything but a regular file: outputs are renamed into place, which
/// would swap a device (`/dev/null`, `/dev/full`), FIFO or socket for a plain file.
pub fn check_replaceable(path: &Path) -> io::Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} exists and is not a regular file (a directory, device, FIFO or socket); \
                 outputs replace files by renaming, so give a file path",
                path.display()
            ),
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_are_unique_per_writer_and_recognised() {
        let target = Path::new("/some/dir/runs.csv");
        let a = temporary_path(target, "x");
        let b = temporary_path(target, "x");
        assert_ne!(a, b);
        assert_eq!(a.parent(), target.parent());
        let name = a.file_name().unwrap().to_str().unwrap();
        assert!(is_temporary_of(name, "runs.csv"), "{name}");
        assert!(!is_temporary_of(name, "runs"));
        assert!(!is_temporary_of(".runs.csv.12.tmp", "runs.csv"));
        assert!(!is_temporary_of("runs.csv", "runs.csv"));
    }

    #[test]
    fn threads_writing_one_target_leave_one_whole_file() {
        let dir = std::env::temp_dir().join(format!("polhode-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.bin");
        std::thread::scope(|s| {
            for k in 0..8u8 {
                let target = &target;
                s.spawn(move || {
                    for _ in 0..20 {
                        write_atomically(target, &vec![k; 100_000]).unwrap();
                    }
                });
            }
        });
        let bytes = std::fs::read(&target).unwrap();
        assert_eq!(bytes.len(), 100_000);
        assert!(bytes.iter().all(|b| *b == bytes[0]));
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "no temporary left"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
