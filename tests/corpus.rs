//! The bad-input corpus (tests/corpus/): every malformed, mistyped, unphysical or absurd
//! scenario must be refused by `run`, `check` and `montecarlo` alike with exactly the message
//! in tests/corpus/expected.tsv (file, line, column, field and what was expected), exit code
//! 2, no panic, and nothing written.
//!
//! Cases too big to commit (deep nesting, a 2 MiB file, a 900 000-character name, ...) are
//! generated here. With `POLHODE_RELIABILITY_DIR` set, the observed outcome of every case is
//! written there for docs/reliability.md (`scripts/reliability.sh`).

mod common;
mod reliability;

use reliability::{Observed, polhode, record, scratch};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const CORPUS: &str = "tests/corpus/bad";
const EXPECTED: &str = "tests/corpus/expected.tsv";

/// One expectation: what the case tries, and the exact error line.
struct Expected {
    what: String,
    message: String,
}

fn expectations() -> BTreeMap<String, Expected> {
    let text = std::fs::read_to_string(EXPECTED).expect("tests/corpus/expected.tsv");
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        let mut cols = line.splitn(3, '\t');
        let (Some(case), Some(what), Some(message)) = (cols.next(), cols.next(), cols.next())
        else {
            panic!("{EXPECTED}:{}: expected case<TAB>what<TAB>message", i + 1);
        };
        let previous = out.insert(
            case.to_string(),
            Expected {
                what: what.to_string(),
                message: message.to_string(),
            },
        );
        assert!(previous.is_none(), "{EXPECTED}: {case} twice");
    }
    out
}

/// The base scenario the generated cases start from (valid as it stands).
const BASE: &str = "name: corpus
body:
  principal: [1.0, 2.0, 3.0]
  spin_axis: [0, 0, 1]
initial:
  omega: [0.1, 0.0, 1.0]
duration: 2.0
integrator: {method: dopri5, rtol: 1.0e-10, atol: 1.0e-12}
output: {rate: 10}
";

/// Cases too large (or too odd) to keep as files: name → bytes.
fn generated() -> Vec<(&'static str, Vec<u8>)> {
    let nest = 100_000;
    let deep = BASE.replace(
        "omega: [0.1, 0.0, 1.0]",
        &format!("omega: {}{}", "[".repeat(nest), "]".repeat(nest)),
    );
    let mut huge = BASE.to_string();
    huge.push_str(&format!("# {}\n", "x".repeat(2 << 20)));
    let long_name = BASE.replace("name: corpus", &format!("name: {}", "n".repeat(900_000)));
    let long_list = BASE.replace(
        "omega: [0.1, 0.0, 1.0]",
        &format!("omega: [{}]", vec!["0.1"; 200_000].join(",")),
    );
    // Ten levels of ten aliases each: 10^10 nodes if expanded.
    let mut bomb = String::from("name: corpus\ndescription: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n");
    for i in 1..10 {
        bomb.push_str(&format!(
            "a{i}: &a{i} [{}]\n",
            vec![format!("*a{}", i - 1); 10].join(", ")
        ));
    }
    bomb.push_str(&BASE.replacen("name: corpus\n", "", 1));
    let two_docs = format!("{BASE}---\n{BASE}");
    vec![
        ("generated/deep-nesting.yaml", deep.into_bytes()),
        ("generated/huge-file.yaml", huge.into_bytes()),
        ("generated/long-name.yaml", long_name.into_bytes()),
        ("generated/long-list.yaml", long_list.into_bytes()),
        ("generated/alias-bomb.yaml", bomb.into_bytes()),
        ("generated/two-documents.yaml", two_docs.into_bytes()),
    ]
}

/// Runs `args` on `file` (relative to `dir`) and checks exit 2, the exact message, no panic
/// and that `dir` holds nothing but the inputs afterwards.
fn assert_refused(dir: &Path, file: &str, args: &[&str], expected: &str) -> Observed {
    let before = listing(dir);
    let mut cmd = polhode();
    cmd.current_dir(dir).arg(args[0]).arg(file).args(&args[1..]);
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let label = format!("{file} ({})", args[0]);
    assert!(!err.contains("panicked"), "{label}: panic: {err}");
    assert_eq!(out.status.code(), Some(2), "{label}: {err}");
    assert_eq!(err.trim_end(), format!("error: {expected}"), "{label}");
    assert_eq!(listing(dir), before, "{label}: something was written");
    Observed {
        code: out.status.code(),
        message: err.trim_end().to_string(),
        left: vec![],
    }
}

fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut all = vec![];
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p.clone());
            }
            all.push(p);
        }
    }
    all.sort();
    all
}

#[test]
fn every_bad_scenario_is_refused_with_its_exact_message() {
    let expected = expectations();
    let mut cases: Vec<(String, Vec<u8>)> = vec![];
    for e in std::fs::read_dir(CORPUS).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        cases.push((name, std::fs::read(&p).unwrap()));
    }
    for (name, bytes) in generated() {
        cases.push((name.to_string(), bytes));
    }
    cases.sort();
    let named: Vec<&String> = cases.iter().map(|c| &c.0).collect();
    for k in expected.keys() {
        if !k.starts_with("special/") {
            assert!(
                named.contains(&k),
                "{EXPECTED} lists {k}, which is not in the corpus"
            );
        }
    }
    let dir = scratch("corpus");
    for (name, bytes) in &cases {
        let e = expected
            .get(name)
            .unwrap_or_else(|| panic!("{name}: no expected message in {EXPECTED}"));
        let file = Path::new(name).file_name().unwrap().to_string_lossy();
        let case_dir = dir.join(file.trim_end_matches(".yaml"));
        std::fs::create_dir_all(&case_dir).unwrap();
        std::fs::write(case_dir.join(&*file), bytes).unwrap();
        let message = e.message.replace("{file}", &file);
        let seen = assert_refused(
            &case_dir,
            &file,
            &["run", "--out", "out.mcap", "--summary", "s.json"],
            &message,
        );
        assert_refused(&case_dir, &file, &["check"], &message);
        assert_refused(
            &case_dir,
            &file,
            &["montecarlo", "--out", "campaign"],
            &message,
        );
        record("corpus", name, &e.what, &seen);
    }
}

#[test]
fn missing_files_and_directories_are_refused() {
    let expected = expectations();
    let dir = scratch("corpus-special");
    std::fs::create_dir_all(dir.join("a-directory.yaml")).unwrap();
    for (case, file) in [
        ("special/missing-file", "no-such-file.yaml"),
        ("special/a-directory", "a-directory.yaml"),
    ] {
        let e = &expected[case];
        let message = e.message.replace("{file}", file);
        let seen = assert_refused(&dir, file, &["run"], &message);
        assert_refused(&dir, file, &["check"], &message);
        record("corpus", case, &e.what, &seen);
    }
}
