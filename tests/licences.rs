//! Every package in the dependency graph must carry a licence from the allow-list below, and
//! polhode itself exactly `MIT OR Apache-2.0`.
//!
//! The graph comes from `cargo metadata --format-version 1 --locked --offline` (every platform
//! in Cargo.lock). When crates for other platforms were never downloaded (`cargo fetch --locked`
//! downloads them), that command fails offline, and the check falls back to the packages built
//! for this host (`--filter-platform`), saying so on stderr. Each package's `license` field is
//! an SPDX expression: `OR`, `AND`, `WITH`, parentheses, and the deprecated `/` meaning `OR`.
//! An `OR` needs one allowed side, an `AND` both; `X WITH exception` is allowed when the pair is
//! listed or `X` alone is (an exception only adds permissions). A package without an
//! expression (only a `license-file`, or nothing) fails by name: someone must read its terms.
//! See docs/licences.md.

use serde_json::Value;
use std::process::Command;

/// Permissive licences: each lets polhode be used, modified and redistributed under
/// MIT OR Apache-2.0, in source or binary form, with no obligation beyond keeping notices
/// (none is copyleft, so nothing forces polhode's own licence or source disclosure).
/// - MIT, Apache-2.0 (and its LLVM exception, which only waives the attribution of compiled
///   code), BSD-2-Clause, BSD-3-Clause, ISC, Zlib, 0BSD, BSL-1.0: the usual permissive licences
///   of the Rust ecosystem; BSD-3-Clause (tiny-skia, zstd), Zlib (slotmap, zlib-rs) and
///   BSD-2-Clause (arrayref) are the only choice some dependencies offer.
/// - CC0-1.0: a public-domain dedication (tiny-keccak's only licence).
/// - Unicode-3.0, Unicode-DFS-2016: the permissive licence of the Unicode data tables that
///   unicode-ident and unicode-properties embed (`AND`ed with MIT OR Apache-2.0).
///
/// Not listed, on purpose: GPL, LGPL, AGPL (copyleft), MPL-2.0 (file-level copyleft; no
/// dependency needs it today: add it here, with a reason, if one does), and anything unknown.
const ALLOWED: &[&str] = &[
    "MIT",
    "Apache-2.0",
    "Apache-2.0 WITH LLVM-exception",
    "BSD-2-Clause",
    "BSD-3-Clause",
    "ISC",
    "Zlib",
    "0BSD",
    "BSL-1.0",
    "CC0-1.0",
    "Unicode-3.0",
    "Unicode-DFS-2016",
];

/// The licence polhode itself must declare in Cargo.toml.
const OWN_LICENCE: &str = "MIT OR Apache-2.0";

/// A parsed SPDX licence expression.
#[derive(Debug, PartialEq)]
enum Expr {
    Licence(String),
    With(String, String),
    And(Box<Expr>, Box<Expr>),
    Or(Box<Expr>, Box<Expr>),
}

fn tokenize(s: &str) -> Vec<String> {
    let mut tokens = Vec::new();
    let mut word = String::new();
    for c in s.chars() {
        if c.is_whitespace() || c == '(' || c == ')' || c == '/' {
            if !word.is_empty() {
                tokens.push(std::mem::take(&mut word));
            }
            if !c.is_whitespace() {
                tokens.push(c.to_string());
            }
        } else {
            word.push(c);
        }
    }
    if !word.is_empty() {
        tokens.push(word);
    }
    tokens
}

struct Parser {
    tokens: Vec<String>,
    pos: usize,
}

impl Parser {
    fn peek(&self) -> Option<&str> {
        self.tokens.get(self.pos).map(String::as_str)
    }

    fn next(&mut self) -> Option<String> {
        let t = self.tokens.get(self.pos).cloned();
        self.pos += 1;
        t
    }

    fn is_op(t: &str, op: &str) -> bool {
        t.eq_ignore_ascii_case(op)
    }

    /// or := and (("OR" | "/") and)*
    fn or(&mut self) -> Result<Expr, String> {
        let mut left = self.and()?;
        while let Some(t) = self.peek() {
            if Self::is_op(t, "OR") || t == "/" {
                self.pos += 1;
                let right = self.and()?;
                left = Expr::Or(Box::new(left), Box::new(right));
            } else {
                break;
            }
        }
        Ok(left)
    }

    /// and := with ("AND" with)*
    fn and(&mut self) -> Result<Expr, String> {
        let mut left = self.with()?;
        while self.peek().is_some_and(|t| Self::is_op(t, "AND")) {
            self.pos += 1;
            let right = self.with()?;
            left = Expr::And(Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    /// with := atom ("WITH" exception)?;  atom := licence | "(" or ")"
    fn with(&mut self) -> Result<Expr, String> {
        let atom = match self.next() {
            Some(t) if t == "(" => {
                let inner = self.or()?;
                return match self.next() {
                    Some(t) if t == ")" => Ok(inner),
                    other => Err(format!("expected `)`, found {other:?}")),
                };
            }
            Some(t)
                if t == ")"
                    || t == "/"
                    || ["AND", "OR", "WITH"].iter().any(|op| Self::is_op(&t, op)) =>
            {
                return Err(format!("expected a licence, found `{t}`"));
            }
            Some(t) => Expr::Licence(t),
            None => return Err("expected a licence, found the end".into()),
        };
        if self.peek().is_some_and(|t| Self::is_op(t, "WITH")) {
            self.pos += 1;
            let Expr::Licence(id) = atom else {
                return Err("`WITH` must follow a single licence".into());
            };
            return match self.next() {
                Some(e) if e != "(" && e != ")" && e != "/" => Ok(Expr::With(id, e)),
                other => Err(format!(
                    "expected an exception after `WITH`, found {other:?}"
                )),
            };
        }
        Ok(atom)
    }
}

/// Parses an SPDX expression (operators also accepted in lower case, as some old crates write
/// them).
fn parse(expr: &str) -> Result<Expr, String> {
    let mut p = Parser {
        tokens: tokenize(expr),
        pos: 0,
    };
    let e = p.or()?;
    match p.peek() {
        None => Ok(e),
        Some(t) => Err(format!("unexpected `{t}`")),
    }
}

fn licence_allowed(id: &str) -> bool {
    // `X+` ("X or any later version") is acceptable when X is.
    let id = id.strip_suffix('+').unwrap_or(id);
    ALLOWED.contains(&id)
}

fn allowed(e: &Expr) -> bool {
    match e {
        Expr::Licence(id) => licence_allowed(id),
        Expr::With(id, exception) => {
            ALLOWED.contains(&format!("{id} WITH {exception}").as_str()) || licence_allowed(id)
        }
        Expr::And(a, b) => allowed(a) && allowed(b),
        Expr::Or(a, b) => allowed(a) || allowed(b),
    }
}

/// Whether the SPDX expression `expr` is satisfied by the allow-list (a malformed expression is
/// refused).
fn expression_allowed(expr: &str) -> Result<bool, String> {
    parse(expr).map(|e| allowed(&e))
}

fn cargo_metadata() -> Value {
    let cargo = env!("CARGO");
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let run = |extra: &[&str]| {
        Command::new(cargo)
            .args(["metadata", "--format-version", "1", "--locked", "--offline"])
            .args(["--manifest-path", manifest])
            .args(extra)
            .output()
            .expect("cannot run cargo")
    };
    let mut out = run(&[]);
    if !out.status.success() {
        let host = Command::new(cargo).arg("-vV").output().expect("cargo -vV");
        let host = String::from_utf8_lossy(&host.stdout)
            .lines()
            .find_map(|l| l.strip_prefix("host: ").map(str::to_owned))
            .expect("cargo -vV names the host");
        eprintln!(
            "note: `cargo metadata --offline` failed for the whole graph (crates for other \
             platforms not downloaded; `cargo fetch --locked` fetches them): checking only the \
             packages for {host}.\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out = run(&["--filter-platform", &host]);
    }
    assert!(
        out.status.success(),
        "cargo metadata failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON")
}

#[test]
fn every_dependency_has_an_allowed_licence() {
    let meta = cargo_metadata();
    let root = meta["resolve"]["root"].as_str().map(str::to_owned);
    let packages = meta["packages"].as_array().expect("packages");
    assert!(packages.len() > 1, "no dependencies listed");
    let mut offending = Vec::new();
    let mut own = None;
    for p in packages {
        let name = p["name"].as_str().unwrap_or("?");
        let version = p["version"].as_str().unwrap_or("?");
        let licence = p["license"].as_str();
        if root.as_deref() == p["id"].as_str() {
            own = Some(licence.map(str::to_owned));
            continue;
        }
        match licence {
            None => offending.push(format!(
                "{name} {version}: no `license` expression (license-file: {})",
                p["license_file"].as_str().unwrap_or("none")
            )),
            Some(expr) => match expression_allowed(expr) {
                Ok(true) => {}
                Ok(false) => offending.push(format!("{name} {version}: `{expr}` is not allowed")),
                Err(e) => offending.push(format!("{name} {version}: `{expr}` does not parse: {e}")),
            },
        }
    }
    let own = own.expect("polhode itself is in the metadata");
    assert_eq!(
        own.as_deref(),
        Some(OWN_LICENCE),
        "polhode's Cargo.toml must say license = \"{OWN_LICENCE}\""
    );
    assert!(
        offending.is_empty(),
        "{} package(s) with a licence outside the allow-list {ALLOWED:?} (tests/licences.rs, \
         docs/licences.md):\n  {}",
        offending.len(),
        offending.join("\n  ")
    );
}

#[test]
fn single_licences() {
    assert_eq!(expression_allowed("MIT"), Ok(true));
    assert_eq!(expression_allowed("Apache-2.0"), Ok(true));
    assert_eq!(expression_allowed("GPL-3.0-only"), Ok(false));
    assert_eq!(expression_allowed("GPL-2.0-or-later"), Ok(false));
    assert_eq!(expression_allowed("LicenseRef-Proprietary"), Ok(false));
    assert_eq!(expression_allowed("MPL-2.0"), Ok(false));
}

#[test]
fn and_needs_both_and_or_needs_one() {
    assert_eq!(expression_allowed("MIT AND GPL-2.0"), Ok(false));
    assert_eq!(expression_allowed("MIT OR GPL-3.0"), Ok(true));
    assert_eq!(expression_allowed("GPL-3.0 OR MIT"), Ok(true));
    assert_eq!(expression_allowed("GPL-3.0 OR LGPL-2.1"), Ok(false));
    assert_eq!(
        expression_allowed("MIT OR Apache-2.0 OR LGPL-2.1-or-later"),
        Ok(true)
    );
    assert_eq!(
        expression_allowed("(MIT OR Apache-2.0) AND Unicode-3.0"),
        Ok(true)
    );
    assert_eq!(
        expression_allowed("(MIT OR Apache-2.0) AND GPL-3.0"),
        Ok(false)
    );
    assert_eq!(
        expression_allowed("(MIT OR GPL-3.0) AND (BSD-3-Clause OR AGPL-3.0)"),
        Ok(true)
    );
    // AND binds tighter than OR: this is GPL-3.0 OR (MIT AND Zlib).
    assert_eq!(expression_allowed("GPL-3.0 OR MIT AND Zlib"), Ok(true));
    assert_eq!(expression_allowed("GPL-3.0 OR MIT AND GPL-2.0"), Ok(false));
}

#[test]
fn deprecated_slash_means_or() {
    assert_eq!(expression_allowed("MIT/Apache-2.0"), Ok(true));
    assert_eq!(expression_allowed("Apache-2.0 / MIT"), Ok(true));
    assert_eq!(expression_allowed("GPL-3.0/MIT"), Ok(true));
    assert_eq!(expression_allowed("GPL-3.0/LGPL-3.0"), Ok(false));
}

#[test]
fn with_exceptions() {
    assert_eq!(
        expression_allowed("Apache-2.0 WITH LLVM-exception"),
        Ok(true)
    );
    assert_eq!(
        expression_allowed("Apache-2.0 WITH LLVM-exception OR Apache-2.0 OR MIT"),
        Ok(true)
    );
    // An exception does not make a copyleft licence permissive.
    assert_eq!(
        expression_allowed("GPL-2.0 WITH Classpath-exception-2.0"),
        Ok(false)
    );
    assert_eq!(expression_allowed("MIT+"), Ok(true));
}

#[test]
fn malformed_expressions_are_refused() {
    for bad in [
        "",
        "MIT OR",
        "(MIT",
        "MIT)",
        "AND MIT",
        "MIT Apache-2.0",
        "MIT WITH",
        "(MIT) WITH X",
    ] {
        assert!(expression_allowed(bad).is_err(), "{bad:?} parsed");
    }
}
