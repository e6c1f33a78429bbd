//! Where polhode writes, and what it never overwrites (docs/cli.md). Every command that
//! writes files goes through this module:
//!
//! - [`Plan`]: before anything runs, every output is resolved (symlinks, `..`) and compared
//!   with every input and every other output, by (device, inode) for files that exist (hard
//!   links, bind mounts) and by resolved path for the rest; a conflict is refused with the
//!   path and what it conflicts with, and nothing is written.
//! - [`OwnedDir`]: a directory of outputs is taken only when new, empty or marked as
//!   polhode's, locked while written, and only the files its marker lists are removed.
//! - [`write_atomically`] and [`TempFile`]: a file is written under a temporary name unique
//!   to the writer (process id and counter), in its destination directory, then renamed.
//! - [`sanitize`] and [`check_component`]: a file name built from user text stays one plain
//!   path component.
//! - [`note_input`] and [`check_not_input`]: every file read as an input is remembered, and
//!   every write and removal above refuses it, whichever writer forgot its plan.

mod atomic;
mod identity;
mod inputs;
mod names;
mod owned_dir;

pub use atomic::{TempFile, check_replaceable, is_temporary_of, temporary_path, write_atomically};
pub use identity::Identity;
pub use inputs::{check_not_input, note_input};
pub use names::{MAX_NAME_BYTES, check_component, sanitize};
pub use owned_dir::{MARKER, OwnedDir};

use std::path::{Path, PathBuf};

/// What a path is to a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// A file or directory read.
    Input,
    /// A file written.
    Output,
    /// A directory written into ([`OwnedDir`]).
    OutputDir,
}

/// One path of a [`Plan`].
#[derive(Debug)]
struct Entry {
    kind: Kind,
    /// How the command calls it (`--csv`, `the scenario`).
    role: String,
    /// As given.
    path: PathBuf,
    identity: Identity,
}

/// The inputs and outputs of one command, checked against each other before it runs.
#[derive(Debug, Default)]
pub struct Plan {
    entries: Vec<Entry>,
    /// A path that could not be resolved, with why.
    unresolved: Option<String>,
}

impl Plan {
    /// An empty plan.
    pub fn new() -> Self {
        Self::default()
    }

    fn add(&mut self, kind: Kind, role: &str, path: &Path) -> &mut Self {
        match Identity::of(path) {
            Ok(identity) => self.entries.push(Entry {
                kind,
                role: role.to_string(),
                path: path.to_path_buf(),
                identity,
            }),
            Err(e) => {
                self.unresolved
                    .get_or_insert_with(|| format!("{role} {}: {e}", path.display()));
            }
        }
        self
    }

    /// A file (or directory) the command reads.
    pub fn input(&mut self, role: &str, path: &Path) -> &mut Self {
        self.add(Kind::Input, role, path)
    }

    /// A file the command writes.
    pub fn output(&mut self, role: &str, path: &Path) -> &mut Self {
        self.add(Kind::Output, role, path)
    }

    /// A directory the command writes files into.
    pub fn output_dir(&mut self, role: &str, path: &Path) -> &mut Self {
        self.add(Kind::OutputDir, role, path)
    }

    /// Refuses, naming both, any output that is an input or another output, any output file
    /// that exists and is not a regular file, any input inside an output directory, and any
    /// output file inside an output directory. Writes nothing.
    pub fn check(&self) -> Result<(), String> {
        if let Some(e) = &self.unresolved {
            return Err(format!("cannot resolve {e}"));
        }
        let name = |e: &Entry| format!("{} {}", e.role, e.path.display());
        let resolved = |e: &Entry| {
            if e.identity.resolved == e.path {
                String::new()
            } else {
                format!(" (resolved: {})", e.identity.resolved.display())
            }
        };
        for (i, out) in self.entries.iter().enumerate() {
            if out.kind == Kind::Output {
                check_replaceable(&out.path).map_err(|e| format!("{}: {e}", out.role))?;
            }
            if out.kind == Kind::Input {
                continue;
            }
            for (j, other) in self.entries.iter().enumerate() {
                if i == j {
                    continue;
                }
                let conflict = match (out.kind, other.kind) {
                    (Kind::Output, Kind::Input) => out.identity.same(&other.identity),
                    (Kind::Output, Kind::Output) => j > i && out.identity.same(&other.identity),
                    (Kind::OutputDir, Kind::Input | Kind::Output) => {
                        other.identity.in_dir(&out.identity)
                    }
                    (Kind::OutputDir, Kind::OutputDir) => {
                        j > i && out.identity.same(&other.identity)
                    }
                    _ => false,
                };
                if !conflict {
                    continue;
                }
                if (out.kind, other.kind) == (Kind::Output, Kind::Output) {
                    let other_path = if other.path == out.path {
                        String::new()
                    } else {
                        format!(" and {}", other.path.display())
                    };
                    return Err(format!(
                        "{} and {} both name {}{other_path}{}: give each output its own file; \
                         nothing was written",
                        out.role,
                        other.role,
                        out.path.display(),
                        resolved(out)
                    ));
                }
                let what = match (out.kind, other.kind) {
                    (Kind::Output, _) => "is the same file as",
                    (_, Kind::Input | Kind::OutputDir) if other.identity.same(&out.identity) => {
                        "is the same path as"
                    }
                    _ => "is the directory that holds",
                };
                let remedy = if other.kind == Kind::Input {
                    "polhode never writes over its inputs; give the output another place"
                } else {
                    "give each output its own place"
                };
                return Err(format!(
                    "{}{} {what} {}{}: {remedy}; nothing was written",
                    name(out),
                    resolved(out),
                    name(other),
                    resolved(other)
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_equal_to_inputs_or_each_other_are_refused() {
        let dir = std::env::temp_dir().join(format!("polhode-plan-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("t.yaml");
        std::fs::write(&input, "x").unwrap();
        let check = |f: &dyn Fn(&mut Plan)| {
            let mut p = Plan::new();
            p.input("the scenario", &input);
            f(&mut p);
            p.check()
        };
        let e = check(&|p| {
            p.output("--out", &input);
        })
        .unwrap_err();
        assert!(e.contains("--out") && e.contains("the scenario"), "{e}");
        let e = check(&|p| {
            p.output("--csv", &dir.join("a.csv"))
                .output("--parquet", &dir.join("x/../a.csv"));
        })
        .unwrap_err();
        assert!(e.contains("--csv") && e.contains("--parquet"), "{e}");
        let e = check(&|p| {
            p.output_dir("--out", &dir);
        })
        .unwrap_err();
        assert!(e.contains("holds the scenario"), "{e}");
        let e = check(&|p| {
            p.output("--chart", &dir.join("c/a.svg"))
                .output_dir("--out", &dir.join("c"));
        })
        .unwrap_err();
        assert!(e.contains("--chart"), "{e}");
        check(&|p| {
            p.output("--csv", &dir.join("a.csv"))
                .output_dir("--out", &dir.join("c"));
        })
        .unwrap();
        #[cfg(unix)]
        {
            std::fs::hard_link(&input, dir.join("hard.yaml")).unwrap();
            assert!(
                check(&|p| {
                    p.output("--summary", &dir.join("hard.yaml"));
                })
                .is_err()
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
