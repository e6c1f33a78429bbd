//! Which file a path names: resolved (symlinks and `..` followed) and, for a file that
//! exists, its (device, inode), so that hard links and bind mounts compare equal.

use std::io;
use std::path::{Component, Path, PathBuf};

/// A path as the file system sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    /// The absolute path with every symlink and `..` of its existing part resolved; the part
    /// that does not exist yet is appended with `.` and `..` removed lexically.
    pub resolved: PathBuf,
    /// (device, inode) of the file when it exists.
    pub id: Option<(u64, u64)>,
}

impl Identity {
    /// Resolves `path` (relative paths against the working directory).
    pub fn of(path: &Path) -> io::Result<Identity> {
        let absolute = std::path::absolute(path)?;
        // The longest prefix that exists is canonicalised; the rest cannot hold symlinks.
        let mut tail: Vec<std::ffi::OsString> = Vec::new();
        let mut head = absolute;
        let base = loop {
            if let Ok(p) = head.canonicalize() {
                break p;
            }
            match (head.parent(), head.file_name()) {
                (Some(parent), Some(name)) => {
                    tail.push(name.to_os_string());
                    head = parent.to_path_buf();
                }
                // The root itself.
                (None, _) => break head,
                // `..` last, below a part that does not exist: resolved lexically.
                (Some(_), None) => head = lexical(&head),
            }
        };
        let mut resolved = base;
        for name in tail.iter().rev() {
            match Path::new(name).components().next() {
                Some(Component::ParentDir) => {
                    resolved.pop();
                }
                Some(Component::CurDir) | None => {}
                _ => resolved.push(name),
            }
        }
        Ok(Identity {
            id: file_id(&resolved),
            resolved,
        })
    }

    /// Whether `self` and `other` are the same file: by (device, inode) when both exist,
    /// otherwise by resolved path.
    pub fn same(&self, other: &Identity) -> bool {
        match (self.id, other.id) {
            (Some(a), Some(b)) => a == b,
            _ => self.resolved == other.resolved,
        }
    }

    /// Whether `self` is a file directly inside the directory `dir`, or `dir` itself.
    pub fn in_dir(&self, dir: &Identity) -> bool {
        if self.same(dir) {
            return true;
        }
        match self.resolved.parent() {
            Some(parent) => match (file_id(parent), dir.id) {
                (Some(a), Some(b)) => a == b,
                _ => parent == dir.resolved,
            },
            None => false,
        }
    }
}

/// `path` with `.` and `..` removed without looking at the file system.
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// (device, inode) of the file at `path` (symlinks followed), if it exists.
pub fn file_id(path: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("polhode-identity-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn symlinks_hard_links_and_dot_dot_name_the_same_file() {
        let dir = scratch("same");
        let file = dir.join("t.yaml");
        std::fs::write(&file, "x").unwrap();
        let id = Identity::of(&file).unwrap();
        std::fs::create_dir(dir.join("sub")).unwrap();
        let dotted = dir.join("sub/../t.yaml");
        assert!(Identity::of(&dotted).unwrap().same(&id));
        let missing_then_up = dir.join("nowhere/../t.yaml");
        assert!(Identity::of(&missing_then_up).unwrap().same(&id));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&file, dir.join("link.yaml")).unwrap();
            assert!(Identity::of(&dir.join("link.yaml")).unwrap().same(&id));
            std::fs::hard_link(&file, dir.join("hard.yaml")).unwrap();
            let hard = Identity::of(&dir.join("hard.yaml")).unwrap();
            assert!(hard.same(&id));
            assert_ne!(hard.resolved, id.resolved);
        }
        let other = Identity::of(&dir.join("other.yaml")).unwrap();
        assert!(!other.same(&id));
        assert!(id.in_dir(&Identity::of(&dir).unwrap()));
        assert!(!id.in_dir(&Identity::of(&dir.join("sub")).unwrap()));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
