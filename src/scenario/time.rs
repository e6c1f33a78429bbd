//! The scenario epoch: RFC 3339 UTC date-time ↔ Unix nanoseconds (MCAP log time).

/// Days from 1970-01-01 to the civil date `y-m-d` (proleptic Gregorian), by the
/// era/day-of-era decomposition described by H. Hinnant ("chrono-compatible low-level date
/// algorithms").
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146097 + doe - 719468
}

/// The civil date of a day count from 1970-01-01 (inverse of `days_from_civil`).
fn civil_from_days(z: i64) -> (i64, i64, i64) {
    let z = z + 719468;
    let era = z.div_euclid(146097);
    let doe = z - era * 146097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// First Unix second that log timestamps cannot hold: Foxglove's `Timestamp` stores seconds
/// as `u32` (2106-02-07T06:28:16Z).
pub const LAST_LOG_SECOND: u64 = 1 << 32;

/// First year an epoch may have: the environment models' tables (IGRF) start in 1900.
pub const FIRST_EPOCH_YEAR: i64 = 1900;

/// Parses `YYYY-MM-DDTHH:MM:SS[.fraction]Z` (UTC) to Unix time in nanoseconds (negative
/// before 1970), for years from `FIRST_EPOCH_YEAR` until 2106-02-07T06:28:16Z.
///
/// MCAP log times are unsigned nanoseconds since 1970: a run whose epoch precedes 1970 is
/// stamped from 1970-01-01T00:00:00Z instead (see [`log_origin`]).
pub fn parse_epoch(text: &str) -> Result<i64, String> {
    let expected = "expected a UTC date-time like `2000-01-01T12:00:00Z` (RFC 3339, ending in Z)";
    let s = text.trim();
    let bad = || format!("`{s}` is not a valid date-time: {expected}");
    let body = s
        .strip_suffix('Z')
        .or(s.strip_suffix('z'))
        .ok_or_else(bad)?;
    let (date, time) = body.split_once(['T', 't', ' ']).ok_or_else(bad)?;
    let num = |x: &str, len: usize| -> Result<i64, String> {
        if x.len() != len || !x.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad());
        }
        x.parse::<i64>().map_err(|_| bad())
    };
    let mut dparts = date.split('-');
    let (y, mo, d) = (
        num(dparts.next().unwrap_or(""), 4)?,
        num(dparts.next().unwrap_or(""), 2)?,
        num(dparts.next().unwrap_or(""), 2)?,
    );
    if dparts.next().is_some() {
        return Err(bad());
    }
    let (hms, frac) = time.split_once('.').unwrap_or((time, ""));
    let mut tparts = hms.split(':');
    let (h, mi, sec) = (
        num(tparts.next().unwrap_or(""), 2)?,
        num(tparts.next().unwrap_or(""), 2)?,
        num(tparts.next().unwrap_or(""), 2)?,
    );
    if tparts.next().is_some() || frac.len() > 9 || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return Err(bad());
    }
    let month_days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let max_day = if mo == 2 && leap {
        29
    } else {
        *month_days
            .get((mo - 1).clamp(0, 11) as usize)
            .unwrap_or(&31)
    };
    if !(1..=12).contains(&mo) || d < 1 || d > max_day || h > 23 || mi > 59 || sec > 59 {
        return Err(bad());
    }
    if y < FIRST_EPOCH_YEAR {
        return Err(format!(
            "`{s}` is before {FIRST_EPOCH_YEAR}-01-01: the environment models (the IGRF field, \
             the Earth's rotation) are tabulated from {FIRST_EPOCH_YEAR}; choose a later epoch"
        ));
    }
    let nanos: i64 = if frac.is_empty() {
        0
    } else {
        format!("{frac:0<9}").parse().map_err(|_| bad())?
    };
    let secs = days_from_civil(y, mo, d) * 86400 + h * 3600 + mi * 60 + sec;
    if secs >= LAST_LOG_SECOND as i64 {
        return Err(format!(
            "`{s}` is too late: log timestamps hold seconds in 32 bits, so the epoch plus the \
             run must stay before 2106-02-07T06:28:16Z"
        ));
    }
    Ok(secs * 1_000_000_000 + nanos)
}

/// The log time (Unix ns) of simulation time 0 for an epoch `epoch_unix_ns`: the epoch
/// itself from 1970 on; 0 (1970-01-01T00:00:00Z) for an earlier epoch, whose instants MCAP's
/// unsigned log times cannot hold. The log's metadata keeps the true epoch either way.
pub fn log_origin(epoch_unix_ns: i64) -> u64 {
    u64::try_from(epoch_unix_ns).unwrap_or(0)
}

/// Formats Unix nanoseconds (negative before 1970) as `YYYY-MM-DDTHH:MM:SS.nnnnnnnnnZ`.
pub fn format_epoch(unix_ns: i64) -> String {
    let secs = unix_ns.div_euclid(1_000_000_000);
    let nanos = unix_ns.rem_euclid(1_000_000_000);
    let (y, m, d) = civil_from_days(secs.div_euclid(86400));
    let rem = secs.rem_euclid(86400);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{nanos:09}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_instants() {
        assert_eq!(parse_epoch("1970-01-01T00:00:00Z"), Ok(0));
        // J2000 is 946 728 000 s after the Unix epoch.
        assert_eq!(
            parse_epoch("2000-01-01T12:00:00Z"),
            Ok(946_728_000_000_000_000)
        );
        assert_eq!(
            parse_epoch("2024-02-29T23:59:59.5Z"),
            Ok(1_709_251_199_500_000_000)
        );
        assert_eq!(
            format_epoch(946_728_000_000_000_000),
            "2000-01-01T12:00:00.000000000Z"
        );
        // Explorer 1's launch: 1958-01-01 is 12·365 + 3 leap days = 4383 days before
        // 1970-01-01, and February 1st 31 days after it.
        let launch = -(4383 - 31) * 86_400 + 3 * 3600 + 47 * 60 + 56;
        assert_eq!(
            parse_epoch("1958-02-01T03:47:56.25Z"),
            Ok(launch * 1_000_000_000 + 250_000_000)
        );
        assert_eq!(
            format_epoch(launch * 1_000_000_000 + 250_000_000),
            "1958-02-01T03:47:56.250000000Z"
        );
        assert_eq!(log_origin(launch * 1_000_000_000), 0);
        assert_eq!(log_origin(5), 5);
    }

    #[test]
    fn round_trip_over_many_days() {
        // Every accepted epoch: 1900-01-01 (25 567 days before 1970) to just before
        // 2106-02-07 (2^32 s).
        for day in (-25_567..49_710).step_by(37) {
            let ns = day as i64 * 86_400_000_000_000 + 12_345_678_901;
            assert_eq!(parse_epoch(&format_epoch(ns)), Ok(ns));
        }
    }

    #[test]
    fn rejects_bad_dates() {
        for s in [
            "2023-02-29T00:00:00Z",
            "2000-13-01T00:00:00Z",
            "2000-01-01",
            "2000-01-01T00:00:00",
            "1899-12-31T23:59:59Z",
            "2000-01-01T24:00:00Z",
            "2106-02-07T06:28:16Z",
        ] {
            assert!(parse_epoch(s).is_err(), "{s}");
        }
    }
}
