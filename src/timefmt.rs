//! How sim times are printed: the one format of every message, table and log text.
//!
//! Times are rounded to the nanosecond (the resolution of MCAP log times) and written without
//! trailing zeros: `9000 s`, `0.5 s`, `5756.586413516 s`. Rust's plain `{}` of an f64 prints
//! the shortest round-trip form instead (`2.1000000000000005`), which reads as noise, and
//! `{:.9}` pads (`9000.000000000`).

/// A number in a message: the shortest text that reads back as the same f64, in exponent
/// form past 1e±6 (`1e300`, `2.5e-7`), so that no message prints a 300-digit decimal. The one
/// number format of error messages and diagnoses.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-6..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A message made readable: runs of spaces inside a line (left by a format string broken
/// across source lines) become one, and a decimal numeral of more than 21 digits (an f64 such
/// as 1e300 or 1e-300 printed with `{}`) is rewritten by [`number`].
pub fn tidy(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    for (i, line) in message.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        let body = line.trim_start_matches(' ');
        out.push_str(&line[..line.len() - body.len()]);
        let mut last_space = false;
        let mut numeral = String::new();
        let flush = |numeral: &mut String, out: &mut String| {
            let digits = numeral.chars().filter(char::is_ascii_digit).count();
            match numeral.parse::<f64>() {
                Ok(v) if digits > 21 => out.push_str(&number(v)),
                _ => out.push_str(numeral),
            }
            numeral.clear();
        };
        for c in body.chars() {
            if c.is_ascii_digit() || (c == '.' && !numeral.is_empty()) {
                numeral.push(c);
                last_space = false;
                continue;
            }
            flush(&mut numeral, &mut out);
            if c == ' ' {
                if !last_space {
                    out.push(c);
                }
                last_space = true;
            } else {
                out.push(c);
                last_space = false;
            }
        }
        flush(&mut numeral, &mut out);
    }
    out
}

/// An estimate in a message: [`number`] of `v` rounded to four significant digits
/// (`1.000000000000002e15` reads `1e15`).
pub fn approx(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return number(v);
    }
    let text = format!("{v:.3e}");
    number(text.parse().unwrap_or(v))
}

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
    fn numbers_in_messages_are_short() {
        assert_eq!(number(1e300), "1e300");
        assert_eq!(number(-1e-300), "-1e-300");
        assert_eq!(number(0.1), "0.1");
        assert_eq!(number(123456.5), "123456.5");
        assert_eq!(number(1e6), "1e6");
        assert_eq!(number(2.5e-7), "2.5e-7");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(f64::NAN), "NaN");
        assert_eq!(approx(1.000000000000002e15), "1e15");
        assert_eq!(approx(49_000_002.0), "4.9e7");
        assert_eq!(approx(123.456), "123.5");
        assert_eq!(
            tidy("expected      gain 1.5 and  rate"),
            "expected gain 1.5 and rate"
        );
        assert_eq!(tidy(&format!("got {}", 1e300)), "got 1e300");
        assert_eq!(tidy(&format!("got -{}", 1e-300)), "got -1e-300");
        assert_eq!(
            tidy("seed 18446744073709551615\n  indented"),
            "seed 18446744073709551615\n  indented"
        );
        for v in [1e300, 1.2345678901234567e-200, 0.1 + 0.2, 5e-324] {
            assert_eq!(number(v).parse::<f64>().unwrap(), v);
        }
    }

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
