//! The files this process has read as inputs (scenarios, logs, shard outputs): the last
//! line of defence, checked by every write and removal of [`super::atomic`] and
//! [`super::OwnedDir`], whatever command or library call is writing, so that no writer that
//! forgot its [`super::Plan`] can replace or remove an input.

use super::identity::{Identity, file_id};
use std::io;
use std::path::Path;
use std::sync::Mutex;

/// The inputs read so far.
static INPUTS: Mutex<Vec<Identity>> = Mutex::new(Vec::new());

/// Records `path` as an input of this process (a path that cannot be resolved is skipped:
/// reading it fails anyway).
pub fn note_input(path: &Path) {
    let Ok(identity) = Identity::of(path) else {
        return;
    };
    if let Ok(mut inputs) = INPUTS.lock()
        && !inputs.contains(&identity)
    {
        inputs.push(identity);
    }
}

/// Refuses to write over, or remove, `target` when it is an input of this process: the same
/// resolved path, or the same (device, inode) as an input that is still where it was read.
pub fn check_not_input(target: &Path) -> io::Result<()> {
    let Ok(inputs) = INPUTS.lock() else {
        return Ok(());
    };
    if inputs.is_empty() {
        return Ok(());
    }
    let t = Identity::of(target)?;
    let hit = inputs.iter().find(|i| {
        i.resolved == t.resolved || (t.id.is_some() && t.id == i.id && file_id(&i.resolved) == i.id)
    });
    match hit {
        None => Ok(()),
        Some(i) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is the input {} of this run; polhode never writes over its inputs, so \
                 nothing was written there",
                target.display(),
                i.resolved.display()
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_write_or_removal_reaches_an_input() {
        let dir = std::env::temp_dir().join(format!("polhode-inputs-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("t.yaml");
        std::fs::write(&input, "x").unwrap();
        note_input(&input);
        let e = crate::outputs::write_atomically(&input, b"y").unwrap_err();
        assert!(
            e.to_string().contains("never writes over its inputs"),
            "{e}"
        );
        #[cfg(unix)]
        {
            std::fs::hard_link(&input, dir.join("hard.yaml")).unwrap();
            assert!(crate::outputs::write_atomically(&dir.join("hard.yaml"), b"y").is_err());
        }
        let (temp, _) = crate::outputs::TempFile::beside(&input, "t").unwrap();
        assert!(temp.persist(&dir.join("sub/../t.yaml")).is_err());
        assert_eq!(std::fs::read(&input).unwrap(), b"x");
        crate::outputs::write_atomically(&dir.join("other.yaml"), b"y").unwrap();
        let _ = std::fs::remove_dir_all(&dir);
    }
}
