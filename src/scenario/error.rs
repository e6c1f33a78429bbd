//! Scenario errors that name the file, line, column and field, and say what was expected.

use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with a scenario file, located as precisely as the input allows.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioError {
    /// The scenario file.
    pub file: PathBuf,
    /// 1-based line, when known.
    pub line: Option<u32>,
    /// 1-based column, when known.
    pub column: Option<u32>,
    /// Dotted path of the field (`body.inertia`), when known.
    pub field: Option<String>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl ScenarioError {
    /// An error at a known location.
    pub fn at(
        file: &Path,
        location: Option<(u32, u32)>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        let field = field.into();
        ScenarioError {
            file: file.to_path_buf(),
            line: location.map(|l| l.0),
            column: location.map(|l| l.1),
            field: (!field.is_empty()).then_some(field),
            message: crate::timefmt::tidy(&message.into()),
        }
    }

    /// An error about the file as a whole (unreadable, not UTF-8, …).
    pub fn whole_file(file: &Path, message: impl Into<String>) -> Self {
        Self::at(file, None, "", message)
    }
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(col) = self.column {
                write!(f, ":{col}")?;
            }
        }
        write!(f, ": ")?;
        if let Some(field) = &self.field {
            write!(f, "field `{field}`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for ScenarioError {}

/// The dotted path of the mapping keys that enclose `(line, column)` (1-based) in block-style
/// YAML, including a key of an inline `{…}` mapping on that line when the column points into
/// one. Used only to name the field in error messages.
pub fn field_path_at(source: &str, line: u32, column: u32) -> String {
    // (indent, key, index of the sequence item under the key, if it holds a sequence)
    let mut stack: Vec<(usize, String, Option<usize>)> = Vec::new();
    for (index, raw) in yaml_lines(source).into_iter().enumerate() {
        let number = index as u32 + 1;
        if number > line {
            break;
        }
        let content = raw.split(" #").next().unwrap_or("");
        let trimmed = content.trim_start();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let mut indent = content.len() - trimmed.len();
        let mut rest = trimmed;
        // A sequence item "- key: value" opens a mapping indented past the dash; it is the
        // next item of the sequence under the nearest key to its left.
        if rest.starts_with("- ") {
            while stack.last().is_some_and(|(i, _, _)| *i > indent) {
                stack.pop();
            }
            if let Some(parent) = stack.last_mut() {
                parent.2 = Some(parent.2.map_or(0, |i| i + 1));
            }
        }
        while let Some(after) = rest.strip_prefix("- ") {
            indent += 2;
            rest = after.trim_start();
        }
        let Some(key) = block_key(rest) else {
            continue;
        };
        while stack.last().is_some_and(|(i, _, _)| *i >= indent) {
            stack.pop();
        }
        if number == line && (column as usize) <= indent + 1 {
            // The error points at the key itself.
            stack.push((indent, key.to_string(), None));
            break;
        }
        stack.push((indent, key.to_string(), None));
        if number == line {
            // Inside a value on this line: find the innermost inline key up to the column,
            // including a key that starts at the column itself.
            let chars: Vec<char> = raw.chars().collect();
            let start = (column as usize).saturating_sub(1).min(chars.len());
            let mut end = start;
            while end < chars.len() && !matches!(chars[end], ':' | ',' | '}' | ']') {
                end += 1;
            }
            let take =
                if chars.get(end) == Some(&':') && !matches!(chars.get(start), Some('{' | '[')) {
                    end + 1
                } else {
                    start
                };
            let upto: String = chars[..take].iter().collect();
            let after_key = upto.split_once(':').map(|x| x.1).unwrap_or("");
            if let Some(k) = last_inline_key(after_key) {
                stack.push((usize::MAX, k, None));
            }
        }
    }
    stack
        .into_iter()
        .map(|(_, k, item)| match item {
            Some(i) => format!("{k}[{i}]"),
            None => k,
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// The lines of `source` as YAML counts them: a line ends at LF, CRLF or a lone CR (which
/// `str::lines` does not split at), so that line numbers agree with the parser's.
pub fn yaml_lines(source: &str) -> Vec<&str> {
    let bytes = source.as_bytes();
    let mut lines = Vec::new();
    let mut start = 0;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => {
                lines.push(&source[start..i]);
                start = i + 1;
            }
            b'\r' => {
                lines.push(&source[start..i]);
                if bytes.get(i + 1) == Some(&b'\n') {
                    i += 1;
                }
                start = i + 1;
            }
            _ => {}
        }
        i += 1;
    }
    if start < bytes.len() {
        lines.push(&source[start..]);
    }
    lines
}

fn block_key(s: &str) -> Option<&str> {
    let (key, _) = s.split_once(':')?;
    let key = key.trim().trim_matches(|c| c == '"' || c == '\'');
    (!key.is_empty() && !key.starts_with(['{', '[', '-']) && !key.contains(' ')).then_some(key)
}

fn last_inline_key(s: &str) -> Option<String> {
    let mut best = None;
    for (i, c) in s.char_indices() {
        if c == ':' {
            let before = &s[..i];
            let start = before.rfind(['{', ',', '[']).map(|p| p + 1).unwrap_or(0);
            let key = before[start..]
                .trim()
                .trim_matches(|c| c == '"' || c == '\'');
            if !key.is_empty() && !key.contains(' ') {
                best = Some(key.to_string());
            }
        }
    }
    best
}

/// The valid name closest to `unknown` (edit distance), if any is reasonably close.
pub fn nearest<'a>(unknown: &str, valid: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    valid
        .into_iter()
        .map(|v| (strsim::damerau_levenshtein(unknown, v), v))
        .filter(|(d, v)| *d <= 3.max(v.len() / 3))
        .min_by_key(|(d, _)| *d)
        .map(|(_, v)| v)
}

#[cfg(test)]
mod tests {
    use super::*;

    const YAML: &str = "name: x\nbody:\n  principal: [1, 2, 3]\n  spin_axs: [0, 1, 0]\n\
        initial:\n  attitude: {w: 1.0, x: 0.0, q: 0.0}\nstop:\n  - nutation_angle_deg: {above: 3}\n";

    #[test]
    fn paths_of_block_and_inline_keys() {
        assert_eq!(field_path_at(YAML, 4, 3), "body.spin_axs");
        assert_eq!(field_path_at(YAML, 3, 17), "body.principal");
        assert_eq!(field_path_at(YAML, 6, 33), "initial.attitude.q");
        // A key that starts at the column (serde-saphyr points there for missing fields).
        assert_eq!(field_path_at(YAML, 6, 23), "initial.attitude.x");
        assert_eq!(field_path_at(YAML, 8, 5), "stop[0].nutation_angle_deg");
        assert_eq!(field_path_at(YAML, 1, 1), "name");
    }

    #[test]
    fn paths_count_sequence_items() {
        let y = "effectors:\n  - rod:\n      mass: 1\n  - beam:\n      length: 2\n      \
                 EI: 3\nnext:\n- a: 1\n- b: 2\n";
        assert_eq!(field_path_at(y, 3, 7), "effectors[0].rod.mass");
        assert_eq!(field_path_at(y, 6, 7), "effectors[1].beam.EI");
        // A sequence at the key's own indent.
        assert_eq!(field_path_at(y, 9, 3), "next[1].b");
    }

    #[test]
    fn lines_end_at_lf_crlf_and_lone_cr() {
        assert_eq!(yaml_lines("a\nb\r\nc\rd"), ["a", "b", "c", "d"]);
        assert_eq!(yaml_lines("a\n"), ["a"]);
        // The field is found on the line the parser names.
        assert_eq!(
            field_path_at("x: 1\r\rbody:\r  mass: 2\r", 4, 3),
            "body.mass"
        );
    }

    #[test]
    fn suggests_the_nearest_key() {
        let keys = ["inertia", "principal", "spin_axis"];
        assert_eq!(nearest("spin_axs", keys), Some("spin_axis"));
        assert_eq!(nearest("principle", keys), Some("principal"));
        assert_eq!(nearest("colour", keys), None);
    }

    #[test]
    fn display_names_file_line_and_field() {
        let e = ScenarioError::at(Path::new("a.yaml"), Some((4, 3)), "body.x", "bad");
        assert_eq!(e.to_string(), "a.yaml:4:3: field `body.x`: bad");
    }
}
