//! A directory a command writes many files into (a campaign, a merge, `plot`): polhode takes
//! it only when it is new, empty, or carries polhode's marker file, holds an exclusive lock on
//! the marker for as long as it writes, lists in the marker every file name before writing
//! it, and removes only what a previous marker listed.

use super::atomic::is_temporary_of;
use super::inputs::check_not_input;
use super::names::check_component;
use std::fs::File;
use std::io::{Read as _, Seek as _, SeekFrom, Write as _};
use std::path::{Path, PathBuf};

/// The marker file: the format line, then one name per line of the files written here.
pub const MARKER: &str = ".polhode-outputs";

/// The marker's first line.
const FORMAT: &str = "polhode-outputs/1";

/// A directory owned, and locked, for the lifetime of this value.
#[derive(Debug)]
pub struct OwnedDir {
    dir: PathBuf,
    /// The open marker, locked (`flock`, exclusive); closing it releases the lock.
    marker: File,
    /// Names listed in the marker since it was claimed.
    names: Vec<String>,
}

/// The names in `dir`, sorted.
fn entries(dir: &Path) -> Result<Vec<String>, String> {
    let list = std::fs::read_dir(dir).map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
    let mut names: Vec<String> = list
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    Ok(names)
}

/// Takes the exclusive lock on `file` without waiting; false when another holds it.
fn try_lock(file: &File) -> std::io::Result<bool> {
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        // SAFETY: flock on a file descriptor this `File` owns and keeps open.
        let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
        if r == 0 {
            return Ok(true);
        }
        let e = std::io::Error::last_os_error();
        if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
            Ok(false)
        } else {
            Err(e)
        }
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        Ok(true)
    }
}

impl OwnedDir {
    /// Takes `dir` (created, parents too, when missing): it must be empty or carry the
    /// marker, and no other process may hold it. `may_write(name)` says whether this
    /// command may write a file of that name: such a file that the marker does not list is
    /// a user's, and the directory is refused rather than the file replaced. Then the files
    /// the marker lists (and their temporaries) are removed, and the marker starts afresh.
    pub fn claim(dir: &Path, may_write: &dyn Fn(&str) -> bool) -> Result<OwnedDir, String> {
        let d = dir.display();
        match std::fs::metadata(dir) {
            Ok(m) if !m.is_dir() => {
                return Err(format!("{d} exists and is not a directory"));
            }
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {d}: {e}"))?;
            }
            Err(e) => return Err(format!("cannot use {d}: {e}")),
        }
        let before = entries(dir)?;
        if !before.is_empty() && !before.iter().any(|n| n == MARKER) {
            return Err(foreign(dir, &before));
        }
        let marker_path = dir.join(MARKER);
        let mut options = File::options();
        options.read(true).write(true).create(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            options.custom_flags(libc::O_NOFOLLOW);
        }
        let mut marker = options
            .open(&marker_path)
            .map_err(|e| format!("cannot write {}: {e}", marker_path.display()))?;
        if !marker.metadata().is_ok_and(|m| m.is_file()) {
            return Err(format!(
                "{} is not polhode's marker file",
                marker_path.display()
            ));
        }
        match try_lock(&marker) {
            Ok(true) => {}
            Ok(false) => {
                return Err(format!(
                    "another polhode process is writing into {d} (it holds the lock on \
                     {}); wait for it to finish, or give another directory",
                    marker_path.display()
                ));
            }
            Err(e) => return Err(format!("cannot lock {}: {e}", marker_path.display())),
        }
        // Read again under the lock: another process may have written meanwhile.
        let mut text = String::new();
        marker
            .read_to_string(&mut text)
            .map_err(|e| format!("cannot read {}: {e}", marker_path.display()))?;
        let now = entries(dir)?;
        let previous: Vec<String> = match text.lines().next() {
            Some(FORMAT) => text.lines().skip(1).map(String::from).collect(),
            // Just created (by this process, or by one killed before it wrote a line).
            None if now.iter().all(|n| n == MARKER) => Vec::new(),
            _ => {
                return Err(format!(
                    "{} is not polhode's marker file (it does not start with `{FORMAT}`); \
                     give another directory",
                    marker_path.display()
                ));
            }
        };
        if let Some(bad) = previous
            .iter()
            .find(|n| check_component(n).is_err() || *n == MARKER)
        {
            return Err(format!(
                "{} lists `{}`, which polhode never writes; give another directory",
                marker_path.display(),
                bad.escape_debug()
            ));
        }
        let listed =
            |n: &str| n == MARKER || previous.iter().any(|p| p == n || is_temporary_of(n, p));
        if let Some(n) = now.iter().find(|n| !listed(n) && may_write(n)) {
            return Err(format!(
                "{} was not written by polhode (it is not listed in {}), and this command \
                 writes a file of that name there; move it away, or give another directory",
                dir.join(n).display(),
                marker_path.display()
            ));
        }
        // Remove the previous files, then their temporaries.
        let remove = |n: &str| {
            let p = dir.join(n);
            check_not_input(&p).map_err(|e| e.to_string())?;
            match std::fs::remove_file(&p) {
                Ok(()) => Ok(()),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
                Err(e) => Err(format!("cannot remove the old {}: {e}", p.display())),
            }
        };
        for n in &previous {
            remove(n)?;
        }
        for n in now
            .iter()
            .filter(|n| previous.iter().any(|p| is_temporary_of(n, p)))
        {
            remove(n)?;
        }
        let mut owned = OwnedDir {
            dir: dir.to_path_buf(),
            marker,
            names: Vec::new(),
        };
        owned.rewrite()?;
        Ok(owned)
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The marker with the format line and [`OwnedDir::names`], written in place (the lock
    /// stays on the same file).
    fn rewrite(&mut self) -> Result<(), String> {
        let mut text = format!("{FORMAT}\n");
        for n in &self.names {
            text.push_str(n);
            text.push('\n');
        }
        let path = self.dir.join(MARKER);
        (|| {
            self.marker.set_len(0)?;
            self.marker.seek(SeekFrom::Start(0))?;
            self.marker.write_all(text.as_bytes())?;
            self.marker.sync_data()
        })()
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
    }

    /// The path of the file `name` in the directory, listed in the marker before it is
    /// returned (so that a later claim removes it, and its temporaries, even if this process
    /// is killed while writing it). Refuses a name that is not one plain component, and a
    /// file of that name that polhode did not write.
    pub fn file(&mut self, name: &str) -> Result<PathBuf, String> {
        check_component(name)?;
        let path = self.dir.join(name);
        if self.names.iter().any(|n| n == name) {
            return Ok(path);
        }
        if name == MARKER || std::fs::symlink_metadata(&path).is_ok() {
            return Err(format!(
                "{} exists and was not written by polhode; it is left as it is, and the \
                 output is not written",
                path.display()
            ));
        }
        let line = format!("{name}\n");
        (|| {
            self.marker.seek(SeekFrom::End(0))?;
            self.marker.write_all(line.as_bytes())?;
            self.marker.sync_data()
        })()
        .map_err(|e| format!("cannot write {}: {e}", self.dir.join(MARKER).display()))?;
        self.names.push(name.to_string());
        Ok(path)
    }

    /// The names listed so far, in the order they were.
    pub fn names(&self) -> &[String] {
        &self.names
    }
}

/// The refusal of a directory that holds files and no marker.
fn foreign(dir: &Path, names: &[String]) -> String {
    let shown: Vec<&str> = names.iter().take(3).map(String::as_str).collect();
    format!(
        "{} holds files polhode did not write ({}{}); polhode writes only into a new or \
         empty directory, or one it wrote before (which carries its marker {MARKER}), so \
         that nothing of yours is replaced or removed: give another directory",
        dir.display(),
        shown.join(", "),
        if names.len() > 3 { ", …" } else { "" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("polhode-owned-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn any(_: &str) -> bool {
        true
    }

    #[test]
    fn a_directory_is_taken_only_new_empty_or_marked_and_one_writer_at_a_time() {
        let dir = scratch("claim");
        let mut owned = OwnedDir::claim(&dir, &any).unwrap();
        let p = owned.file("runs.csv").unwrap();
        std::fs::write(&p, "a").unwrap();
        // A second writer is refused while the first holds the directory.
        let e = OwnedDir::claim(&dir, &any).unwrap_err();
        assert!(e.contains("another polhode process"), "{e}");
        drop(owned);
        // A killed writer's temporary goes with the file the marker names; a user's file
        // that the command does not write stays.
        std::fs::write(dir.join(".runs.csv.1.2.tmp"), "t").unwrap();
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        let owned = OwnedDir::claim(&dir, &|n| n != "notes.txt").unwrap();
        assert_eq!(entries(&dir).unwrap(), vec![MARKER, "notes.txt"]);
        drop(owned);
        // A user's file of a name the command writes refuses the directory.
        std::fs::write(dir.join("summary.txt"), "mine").unwrap();
        let e = OwnedDir::claim(&dir, &|n| n != "notes.txt").unwrap_err();
        assert!(
            e.contains("summary.txt") && e.contains("not written by polhode"),
            "{e}"
        );
        assert_eq!(std::fs::read(dir.join("summary.txt")).unwrap(), b"mine");
        // A directory of files without the marker is refused, and left as it was.
        let user = scratch("user");
        std::fs::create_dir_all(&user).unwrap();
        std::fs::write(user.join("t_x_histogram.png"), "mine").unwrap();
        let e = OwnedDir::claim(&user, &any).unwrap_err();
        assert!(e.contains("holds files polhode did not write"), "{e}");
        assert_eq!(entries(&user).unwrap(), vec!["t_x_histogram.png"]);
        let mut owned = OwnedDir::claim(&dir, &|_| false).unwrap();
        let e = owned.file("summary.txt").unwrap_err();
        assert!(e.contains("not written by polhode"), "{e}");
        assert!(owned.file("../escape").is_err());
        drop(owned);
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::remove_dir_all(&user);
    }
}
