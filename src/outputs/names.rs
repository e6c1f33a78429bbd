//! File names built from user text (a scenario's `name:`): made safe as one path component.

/// Longest file name Linux file systems accept (bytes, `NAME_MAX`).
pub const MAX_NAME_BYTES: usize = 255;

/// `text` as a file-name stem: anything but ASCII letters, digits, `-` and `_` becomes `-`
/// (so no `/`, `.`, NUL or control character survives), an empty result becomes `-`, and
/// it is cut to leave room for `reserve` more bytes within [`MAX_NAME_BYTES`].
pub fn sanitize(text: &str, reserve: usize) -> String {
    let mut out: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect();
    if out.is_empty() {
        out.push('-');
    }
    out.truncate(MAX_NAME_BYTES.saturating_sub(reserve).max(1));
    out
}

/// Checks that `name` is a single, ordinary path component: not empty, not `.` or `..`, no
/// `/`, `\`, NUL or control character, at most [`MAX_NAME_BYTES`] bytes.
pub fn check_component(name: &str) -> Result<(), String> {
    let bad = |why: &str| {
        Err(format!(
            "`{}` cannot be a file name: {why}",
            name.escape_debug()
        ))
    };
    if name.is_empty() {
        return bad("it is empty");
    }
    if name == "." || name == ".." {
        return bad("it names a directory");
    }
    if name.contains(['/', '\\']) {
        return bad("it holds a path separator");
    }
    if name.chars().any(char::is_control) {
        return bad("it holds a NUL or control character");
    }
    if name.len() > MAX_NAME_BYTES {
        return bad(&format!(
            "it is {} bytes long, above the limit of {MAX_NAME_BYTES}",
            name.len()
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn user_text_never_leaves_its_directory() {
        for text in [
            "../../victim/evil",
            "a/b",
            "..",
            ".",
            "",
            "x\0y",
            "tab\there",
            "é",
        ] {
            let name = sanitize(text, 0);
            check_component(&name).unwrap();
            assert!(!name.contains('.') && !name.contains('/'), "{name}");
        }
        assert_eq!(sanitize("../../victim/evil", 0), "------victim-evil");
        let long = "x".repeat(1000);
        assert_eq!(sanitize(&long, 12).len(), MAX_NAME_BYTES - 12);
        for bad in ["", ".", "..", "a/b", "a\0b", "a\nb", &"y".repeat(256)] {
            assert!(check_component(bad).is_err(), "{bad:?}");
        }
        check_component("runs.csv").unwrap();
    }
}
