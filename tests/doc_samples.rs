//! The sample outputs in README.md and docs/*.md are this build's: every ```text block with
//! lines `$ polhode …` is run again, and each line shown under a command must appear in what
//! it prints, in order, with the same words and the same numbers. Lines may be left out
//! (`...`), and columns may be realigned. Timings are the exception, marked by their form:
//! a number directly followed by `s wall` or, in `compare`'s table, written `0.32s`; they
//! are compared only in shape.
//!
//! After an intended change, regenerate the samples from this build (the lines shown are
//! replaced by the lines printed, timings included) and review the diff:
//!
//! ```sh
//! POLHODE_BLESS=1 cargo test --release --test doc_samples
//! ```

use std::path::{Path, PathBuf};
use std::process::Command;

/// One `$ polhode …` line of a sample block and the lines shown under it.
struct Sample {
    /// The markdown file and the command's line (1-based).
    file: PathBuf,
    line: usize,
    /// The arguments after `polhode`.
    args: Vec<String>,
    /// (line index in the file, text) of each output line shown, `...` left out.
    shown: Vec<(usize, String)>,
}

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn documents() -> Vec<PathBuf> {
    let root = repository();
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

fn samples(file: &Path, text: &str) -> Vec<Sample> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim_end() != "```text" {
            i += 1;
            continue;
        }
        i += 1;
        let mut current: Option<Sample> = None;
        while i < lines.len() && lines[i].trim_end() != "```" {
            let l = lines[i];
            if let Some(command) = l.strip_prefix("$ polhode ") {
                out.extend(current.take());
                let command = command.split(" #").next().unwrap_or("");
                current = Some(Sample {
                    file: file.to_path_buf(),
                    line: i + 1,
                    args: command.split_whitespace().map(String::from).collect(),
                    shown: Vec::new(),
                });
            } else if let Some(s) = current.as_mut()
                && !l.trim().is_empty()
                && l.trim() != "..."
            {
                s.shown.push((i, l.to_string()));
            }
            i += 1;
        }
        out.extend(current.take());
        i += 1;
    }
    out
}

/// A line's pieces: words (whitespace runs made one space) and numbers.
#[derive(Debug, PartialEq)]
enum Piece {
    Text(String),
    Number(String),
    Timing,
}

fn pieces(line: &str) -> Vec<Piece> {
    let chars: Vec<char> = line.trim().chars().collect();
    let mut out = Vec::new();
    let mut text = String::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let starts_number = c.is_ascii_digit()
            && (i == 0 || !(chars[i - 1].is_alphabetic() || chars[i - 1] == '_'))
            || ((c == '-' || c == '+')
                && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit())
                && (i == 0 || chars[i - 1].is_whitespace() || "([,".contains(chars[i - 1])));
        if !starts_number {
            if c.is_whitespace() {
                if !text.ends_with(' ') {
                    text.push(' ');
                }
            } else {
                text.push(c);
            }
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
            i += 1;
        }
        if i + 1 < chars.len()
            && chars[i] == 'e'
            && (chars[i + 1].is_ascii_digit()
                || ("+-".contains(chars[i + 1])
                    && chars.get(i + 2).is_some_and(|d| d.is_ascii_digit())))
        {
            i += 2;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
            }
        }
        let number: String = chars[start..i].iter().collect();
        let rest: String = chars[i..].iter().collect();
        let timing = rest.starts_with(" s wall")
            || (rest.starts_with('s') && rest[1..].chars().next().is_none_or(char::is_whitespace));
        if !text.is_empty() {
            out.push(Piece::Text(std::mem::take(&mut text)));
        }
        out.push(if timing {
            Piece::Timing
        } else {
            Piece::Number(number)
        });
    }
    if !text.is_empty() {
        out.push(Piece::Text(text));
    }
    out
}

/// The same words and the same kinds of pieces.
fn same_shape(a: &[Piece], b: &[Piece]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| match (x, y) {
            (Piece::Text(p), Piece::Text(q)) => p == q,
            (Piece::Number(_), Piece::Number(_)) | (Piece::Timing, Piece::Timing) => true,
            _ => false,
        })
}

/// Runs a sample's command in a scratch directory whose `scenarios` is the repository's (so
/// that its logs go there, not into the repository), and returns what it printed.
fn run(sample: &Sample, scratch: &Path) -> Vec<String> {
    let output = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args(&sample.args)
        .current_dir(scratch)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}:{}: `polhode {}` failed: {}",
        sample.file.display(),
        sample.line,
        sample.args.join(" "),
        String::from_utf8_lossy(&output.stderr)
    );
    let mut text = String::from_utf8_lossy(&output.stdout).into_owned();
    text += &String::from_utf8_lossy(&output.stderr);
    text.lines().map(String::from).collect()
}

#[test]
fn the_documents_show_what_this_build_prints() {
    let bless = std::env::var_os("POLHODE_BLESS").is_some();
    let scratch = std::env::temp_dir().join(format!("polhode-doc-samples-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    let link = scratch.join("scenarios");
    if !link.exists() {
        std::os::unix::fs::symlink(repository().join("scenarios"), &link).unwrap();
    }
    let mut failures = Vec::new();
    let mut count = 0;
    for file in documents() {
        let text = std::fs::read_to_string(&file).unwrap();
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        let mut changed = false;
        for sample in samples(&file, &text) {
            count += 1;
            let printed = run(&sample, &scratch);
            let mut from = 0;
            for (index, shown) in &sample.shown {
                let want = pieces(shown);
                let found =
                    (from..printed.len()).find(|&k| same_shape(&pieces(&printed[k]), &want));
                let Some(k) = found else {
                    failures.push(format!(
                        "{}:{}: `polhode {}` printed no line like `{}` (after line {from} of \
                         its output)",
                        file.display(),
                        index + 1,
                        sample.args.join(" "),
                        shown.trim()
                    ));
                    continue;
                };
                from = k + 1;
                if pieces(&printed[k]) != want {
                    if bless {
                        lines[*index] = printed[k].clone();
                        changed = true;
                    } else {
                        failures.push(format!(
                            "{}:{}: shown   `{}`\n    printed `{}`",
                            file.display(),
                            index + 1,
                            shown.trim(),
                            printed[k].trim()
                        ));
                    }
                } else if bless && printed[k] != *shown {
                    // A timing or the alignment: refreshed with the rest.
                    lines[*index] = printed[k].clone();
                    changed = true;
                }
            }
        }
        if changed {
            let mut new = lines.join("\n");
            new.push('\n');
            std::fs::write(&file, new).unwrap();
        }
    }
    std::fs::remove_dir_all(&scratch).ok();
    assert!(
        count >= 6,
        "only {count} samples found: the parser lost them"
    );
    assert!(
        failures.is_empty(),
        "{} sample line(s) differ from this build (if intended, regenerate with \
         POLHODE_BLESS=1 cargo test --release --test doc_samples and review the diff):\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn numbers_and_timings_are_told_apart() {
    let p = pieces("  work: 33 steps (9 rejected), 596 RHS evaluations, 0.067 s wall");
    assert_eq!(p.last(), Some(&Piece::Text(" s wall".into())));
    assert!(p.contains(&Piece::Timing));
    assert!(p.contains(&Piece::Number("596".into())));
    let row = pieces("explorer1-pydy  4 × hinged_rod  27  40.75 s  -1.5e-3  90.072°  0.32s");
    assert!(row.contains(&Piece::Number("40.75".into())));
    assert!(row.contains(&Piece::Number("-1.5e-3".into())));
    assert_eq!(
        row[row.len() - 2..],
        [Piece::Timing, Piece::Text("s".into())]
    );
    // A changed number is a different line; a changed timing or alignment is not.
    assert_ne!(pieces("t = 1.151254498 s"), pieces("t = 1.151254499 s"));
    assert_eq!(pieces("a   0.32s"), pieces("a 0.41s"));
    assert!(same_shape(&pieces("t = 1 s"), &pieces("t =  2 s")));
}
