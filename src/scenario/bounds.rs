//! Plausible physical bounds, applied to every number of a scenario file by one pass over its
//! text, after the field-by-field validation: a value no spacecraft could have (a semi-major
//! axis of 1e300 km, a box of 1e200 m, a wheel torque of 1e300 N m) is refused at load, with
//! its file, line and field, instead of failing at t = 0 with a non-finite state.
//!
//! The bound depends on the quantity's kind, read from the key that holds the number
//! ([`BOUNDS`]); every other number is a parameter in SI units and is held to
//! [`super::MAX_MAGNITUDE`], far beyond any spacecraft and small enough that energies and
//! momenta built from such values stay finite.

use super::error::{field_path_at, yaml_lines};
use super::{MAX_MAGNITUDE, ScenarioError};
use std::path::Path;

/// Kinds of quantity with a bound other than [`MAX_MAGNITUDE`], by the key that holds them:
/// (how the key ends, largest magnitude, unit and kind for the message). `None`: not a
/// physical quantity (a seed, a count, text).
const BOUNDS: &[(&str, Option<f64>, &str)] = &[
    // Lengths in kilometres: the same 1e12 m as any length in metres.
    ("_km", Some(MAX_MAGNITUDE / 1e3), "km"),
    ("seed", None, ""),
    ("runs", None, ""),
    ("name", None, ""),
    ("description", None, ""),
    ("path", None, ""),
    ("epoch", None, ""),
    ("mcap", None, ""),
    ("summary", None, ""),
];

/// The bound on a number held by `key` (the last key of its field path) and its unit text.
fn bound_for(key: &str) -> Option<(f64, &'static str)> {
    let key = key.split('[').next().unwrap_or(key);
    for &(suffix, bound, unit) in BOUNDS {
        if key.ends_with(suffix) {
            return bound.map(|b| (b, unit));
        }
    }
    Some((MAX_MAGNITUDE, "SI units"))
}

/// Whether `token` is a YAML 1.2 core-schema float or integer (not `.inf`/`.nan`, which the
/// field checks refuse on their own).
fn numeric(token: &str) -> Option<f64> {
    let t = token.strip_prefix(['+', '-']).unwrap_or(token);
    let first = t.chars().next()?;
    if !(first.is_ascii_digit() || first == '.') {
        return None;
    }
    if !t
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-' | '_'))
    {
        return None;
    }
    token.replace('_', "").parse::<f64>().ok()
}

/// The smallest bound of any key: a number within it is within its own.
fn smallest_bound() -> f64 {
    BOUNDS
        .iter()
        .filter_map(|b| b.1)
        .fold(MAX_MAGNITUDE, f64::min)
}

/// Checks every number of `source` against its bound; the first one out of bounds is an error
/// naming its line, column and field.
pub(super) fn check(path: &Path, source: &str) -> Result<(), ScenarioError> {
    // Inside a block scalar (`key: >` or `key: |`): the indent of its key.
    let mut block: Option<usize> = None;
    for (index, raw) in yaml_lines(source).into_iter().enumerate() {
        let line = index as u32 + 1;
        let indent = raw.len() - raw.trim_start().len();
        if let Some(key_indent) = block {
            if raw.trim().is_empty() || indent > key_indent {
                continue;
            }
            block = None;
        }
        let trimmed = raw.trim_end();
        let value_part = trimmed.rsplit_once(':').map_or("", |x| x.1).trim();
        if let Some(rest) = value_part.strip_prefix(['>', '|'])
            && rest
                .chars()
                .all(|c| c.is_ascii_digit() || c == '+' || c == '-')
        {
            block = Some(indent);
            continue;
        }
        // Tokens outside quotes and comments, with their 1-based columns.
        let chars: Vec<char> = raw.chars().collect();
        let mut k = 0;
        let mut quote: Option<char> = None;
        let mut start: Option<usize> = None;
        while k <= chars.len() {
            let c = chars.get(k).copied().unwrap_or(' ');
            if let Some(q) = quote {
                if c == q {
                    quote = None;
                }
                k += 1;
                continue;
            }
            let delimiter = c.is_whitespace() || matches!(c, '[' | ']' | '{' | '}' | ',' | ':');
            if delimiter || c == '#' || c == '"' || c == '\'' {
                if let Some(s) = start.take() {
                    let token: String = chars[s..k].iter().collect();
                    // A key is followed by ':' (then a space or the end); skip it.
                    let is_key = c == ':';
                    // A number within the smallest bound breaches none: its field (a
                    // search of the text) is looked up only for the others.
                    if !is_key
                        && let Some(v) = numeric(&token)
                        && v.abs() > smallest_bound()
                    {
                        let column = s as u32 + 1;
                        let field = field_path_at(source, line, column);
                        let key = field.rsplit('.').next().unwrap_or("");
                        if let Some((bound, unit)) = bound_for(key)
                            && v.abs() > bound
                        {
                            return Err(ScenarioError::at(
                                path,
                                Some((line, column)),
                                field,
                                format!(
                                    "{} is beyond any plausible value: expected a magnitude of \
                                     at most {} ({unit})",
                                    crate::timefmt::number(v),
                                    crate::timefmt::number(bound)
                                ),
                            ));
                        }
                    }
                }
                if c == '#' && (k == 0 || chars[k - 1].is_whitespace()) {
                    break;
                }
                if c == '"' || c == '\'' {
                    quote = Some(c);
                }
            } else if start.is_none() {
                start = Some(k);
            }
            k += 1;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(yaml: &str) -> String {
        check(Path::new("x.yaml"), yaml).unwrap_err().to_string()
    }

    #[test]
    fn absurd_sizes_are_refused_with_their_field() {
        let e = err("orbit:\n  semi_major_axis_km: 1e300\n");
        assert!(e.contains("x.yaml:2:23"), "{e}");
        assert!(e.contains("orbit.semi_major_axis_km"), "{e}");
        assert!(e.contains("1e300 is beyond any plausible value"), "{e}");
        assert!(e.contains("at most 1e9 (km)"), "{e}");
        let e = err("body:\n  shape: {box: {size: [1.0, 1e200, 2]}}\n");
        assert!(e.contains("size`"), "{e}");
        let e = err("effectors:\n  - wheel:\n      max_torque: -1.0e300 # N m\n");
        assert!(e.contains("max_torque"), "{e}");
    }

    #[test]
    fn text_seeds_and_ordinary_values_pass() {
        let ok = "name: '1e300'\ndescription: >\n  a 1e300 J thing\n  more 1e20\nseed: \
                  18446744073709551615\nbody: {principal: [1, 2, 3e3]}  # 1e99\n\
                  orbit: {semi_major_axis_km: 7000.0}\n";
        check(Path::new("x.yaml"), ok).unwrap();
    }
}
