//! The repository's documentation stands alone: no text file points at reference sheets kept
//! outside it (`physics.md`, `shared/...`, or a `validation.md` other than the repository's own
//! docs/validation.md), and every relative markdown link in README.md and docs/ resolves to a
//! file in the repository.

use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Directories of installed third-party material (npm packages, Python environments, build
/// output) that the viewer and reader scripts create next to their sources: not ours.
const THIRD_PARTY_DIRS: [&str; 4] = ["node_modules", "target", "__pycache__", "site-packages"];

/// Every file under `dir`, recursively (symbolic links are not followed), leaving out
/// hidden directories (`.venv`, …) and [`THIRD_PARTY_DIRS`].
fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() {
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') || THIRD_PARTY_DIRS.contains(&name.as_ref()) {
                continue;
            }
            files_under(&path, out);
        } else if kind.is_file() {
            out.push(path);
        }
    }
}

/// The text files to check: docs/, scenarios/, src/, tests/ (except this file), benches/,
/// scripts/ and README.md. Files that are not UTF-8 (images, binary corpora) are skipped.
fn text_files() -> Vec<(PathBuf, String)> {
    let root = root();
    let mut paths = vec![root.join("README.md")];
    for dir in ["docs", "scenarios", "src", "tests", "benches", "scripts"] {
        files_under(&root.join(dir), &mut paths);
    }
    let this = root.join(file!());
    paths.sort();
    paths
        .into_iter()
        .filter(|p| *p != this)
        .filter_map(|p| {
            let text = String::from_utf8(fs::read(&p).ok()?).ok()?;
            Some((p, text))
        })
        .collect()
}

fn rel(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}

/// Whether the `validation.md` at byte `at` of `line` refers to the repository's own
/// docs/validation.md: written as a path `docs/validation.md`, as the target of a relative
/// markdown link in a file of docs/ (`](validation.md)`, which the link check resolves), or as
/// the text of such a link (`[validation.md](…)`, whose target is checked in turn).
fn is_own_validation_md(line: &str, at: usize, in_docs: bool) -> bool {
    let before = &line[..at];
    let after = &line[at + "validation.md".len()..];
    before.ends_with("docs/")
        || (in_docs && (before.ends_with("](") || before.ends_with("](./")))
        || (before.ends_with('[') && after.starts_with("]("))
}

/// The outside references on one line of a file (`in_docs`: the file is docs/*.md).
fn outside_references(line: &str, in_docs: bool) -> Vec<String> {
    let mut found = Vec::new();
    for bad in ["shared/", "physics.md"] {
        if line.contains(bad) {
            found.push(format!("`{bad}`"));
        }
    }
    for (at, _) in line.match_indices("validation.md") {
        if !is_own_validation_md(line, at, in_docs) {
            found.push("a bare `validation.md` (write docs/validation.md or link it)".into());
        }
    }
    found
}

#[test]
fn no_references_to_sheets_outside_the_repository() {
    let files = text_files();
    assert!(files.len() > 50, "only {} text files found", files.len());
    let docs = root().join("docs");
    let mut problems = Vec::new();
    for (path, text) in &files {
        let in_docs =
            path.parent() == Some(docs.as_path()) && path.extension().is_some_and(|e| e == "md");
        for (n, line) in text.lines().enumerate() {
            for what in outside_references(line, in_docs) {
                problems.push(format!("{}:{}: {what}: {}", rel(path), n + 1, line.trim()));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "{} reference(s) to material outside the repository; cite the published source \
         instead (see docs/validation.md, docs/conventions.md):\n  {}",
        problems.len(),
        problems.join("\n  ")
    );
}

/// The relative link targets of markdown text, with their line numbers: the `path` of every
/// `](path)` outside fenced code blocks, without a `#anchor` or a title; http(s), mailto and
/// pure-anchor links left out.
fn relative_links(text: &str) -> Vec<(usize, String)> {
    let mut links = Vec::new();
    let mut fenced = false;
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        for (at, _) in line.match_indices("](") {
            let rest = &line[at + 2..];
            let Some(end) = rest.find(')') else {
                continue;
            };
            let mut target = rest[..end].trim();
            // `](<path with spaces>)` and `](path "title")`.
            if let Some(t) = target.strip_prefix('<') {
                target = t.split('>').next().unwrap_or("");
            } else {
                target = target.split_whitespace().next().unwrap_or("");
            }
            let target = target.split('#').next().unwrap_or("");
            let lower = target.to_ascii_lowercase();
            if target.is_empty()
                || lower.starts_with("http://")
                || lower.starts_with("https://")
                || lower.starts_with("mailto:")
            {
                continue;
            }
            links.push((n + 1, target.to_string()));
        }
    }
    links
}

/// Broken relative links of the markdown file `path` (relative to its directory; a leading `/`
/// means the repository root, as on GitHub).
fn broken_links(path: &Path, text: &str) -> Vec<String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    relative_links(text)
        .into_iter()
        .filter(|(_, target)| {
            let resolved = match target.strip_prefix('/') {
                Some(from_root) => root().join(from_root),
                None => dir.join(target),
            };
            !resolved.exists()
        })
        .map(|(n, target)| format!("{}:{n}: ]({target}) does not exist", rel(path)))
        .collect()
}

fn markdown_files() -> Vec<PathBuf> {
    let root = root();
    let mut files = vec![root.join("README.md")];
    for entry in fs::read_dir(root.join("docs")).expect("docs/").flatten() {
        let p = entry.path();
        if p.extension().is_some_and(|e| e == "md") {
            files.push(p);
        }
    }
    files.sort();
    files
}

#[test]
fn relative_markdown_links_resolve() {
    let files = markdown_files();
    assert!(
        files.len() > 10,
        "only {} markdown files found",
        files.len()
    );
    let mut broken = Vec::new();
    let mut checked = 0;
    for path in &files {
        let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", rel(path)));
        checked += relative_links(&text).len();
        broken.extend(broken_links(path, &text));
    }
    assert!(
        checked > 20,
        "only {checked} relative links found: is the parser broken?"
    );
    assert!(
        broken.is_empty(),
        "{} broken relative link(s):\n  {}",
        broken.len(),
        broken.join("\n  ")
    );
}

// The detectors themselves, on lines that must and must not be flagged.

#[test]
fn outside_references_are_recognised() {
    assert_eq!(
        outside_references("see shared/validation.md", false).len(),
        2
    );
    assert_eq!(outside_references("as physics.md says", true).len(), 1);
    assert_eq!(
        outside_references("the table of validation.md", true).len(),
        1
    );
    assert_eq!(
        outside_references("(validation.md: −0.010689 1/s)", false).len(),
        1
    );
    // A relative link `](validation.md)` means docs/validation.md only from inside docs/.
    assert_eq!(outside_references("[v](validation.md)", false).len(), 1);
    assert!(outside_references("[validation.md](validation.md)", true).is_empty());
    assert!(outside_references("[docs/validation.md](docs/validation.md)", false).is_empty());
    assert!(outside_references("(docs/validation.md: −0.010689 1/s)", false).is_empty());
    assert!(outside_references("`tests/validation.rs`; the machines are shared", false).is_empty());
}

#[test]
fn links_are_parsed_and_checked() {
    let text = "[a](conventions.md) ![b](figures/x.svg \"title\") [c](https://example.org/x.md)\n\
                [d](#anchor) [e](validation.md#sources)\n```\nlet x = v[0](1);\n```\n[f](<a b.md>)";
    let targets: Vec<String> = relative_links(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(
        targets,
        ["conventions.md", "figures/x.svg", "validation.md", "a b.md"]
    );
    let docs = root().join("docs").join("any.md");
    assert!(broken_links(&docs, "[ok](validation.md) [ok](../README.md)").is_empty());
    let broken = broken_links(&docs, "[x](no-such-file.md)\n[y](conventions.md)");
    assert_eq!(broken.len(), 1);
    assert!(broken[0].contains("docs/any.md:1"), "{broken:?}");
}
