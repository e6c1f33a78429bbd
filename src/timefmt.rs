//! How sim times are printed: the one format of every message, table and log text.
//!
//! Times are rounded to the nanosecond (the resolution of MCAP log times) and written without
//! trailing zeros: `9000 s`, `0.5 s`, `5756.586413516 s`. Rust's plain `{}` of an f64 prints
//! the shortest round-trip form instead (`2.1000000000000005`), which reads as noise, and
//! `{:.9}` pads (`9000.000000000`).

/// `t` (s) as text with its unit, e.g. `5756.586413516 s`.
pub fn seconds(t: f64) -> String {
    format!("{} s", seconds_value(t))
}

/// `t` (s) as a number without its unit, rounded to the nanosecond, trailing zeros dropped.
pub fn seconds_value(t: f64) -> String {
    if !t.is_finite() {
        return format!("{t}");
    }
    if t.abs() >= 1e12 {
        return format!("{t:e}");
    }
    let text = format!("{t:.9}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_rounded_to_the_nanosecond_without_padding() {
        assert_eq!(seconds(9000.0), "9000 s");
        assert_eq!(seconds(0.5), "0.5 s");
        assert_eq!(seconds(2.1000000000000005), "2.1 s");
        assert_eq!(seconds(5756.586413516), "5756.586413516 s");
        assert_eq!(seconds(1e-10), "0 s");
        assert_eq!(seconds(-1e-12), "0 s");
        assert_eq!(seconds(0.0), "0 s");
        assert_eq!(seconds(1.5e13), "1.5e13 s");
        assert_eq!(seconds(f64::NAN), "NaN s");
    }
}
