//! Memory a run will need, known before it starts, and the limit it is held to.
//!
//! A run that keeps its output samples in memory (the Python `Scenario.run`, which hands them
//! to numpy; `polhode compare`, which keeps each fidelity's nutation series) needs about
//! samples × columns × 8 bytes, with samples = ⌊duration × rate⌋ + 2. That is estimated
//! before anything is allocated and a run above [`memory_limit_bytes`] is refused with the
//! numbers, instead of letting the allocator abort the process (and a Python interpreter with
//! it). The buffers are then grown with `Vec::try_reserve`, so that an allocation failure
//! below the limit is still an error, not an abort.

use std::collections::TryReserveError;

/// Environment variable overriding the memory limit (MB, 10⁶ bytes).
pub const MAX_MEMORY_ENV: &str = "POLHODE_MAX_MEMORY_MB";

/// Limit when the physical memory cannot be read (bytes): 4 GB.
const FALLBACK_LIMIT: f64 = 4e9;

/// The physical memory of this machine (bytes), if the OS tells.
pub fn physical_memory_bytes() -> Option<f64> {
    // SAFETY: sysconf only reads system configuration values.
    let (pages, page) = unsafe {
        (
            libc::sysconf(libc::_SC_PHYS_PAGES),
            libc::sysconf(libc::_SC_PAGESIZE),
        )
    };
    (pages > 0 && page > 0).then_some(pages as f64 * page as f64)
}

/// The most memory a run's stored samples may take (bytes): `POLHODE_MAX_MEMORY_MB` when set
/// to a positive number, else half the physical memory (4 GB when that is unknown). With the
/// text saying where the limit comes from.
pub fn memory_limit() -> (f64, String) {
    if let Some(mb) = std::env::var(MAX_MEMORY_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|mb| mb.is_finite() && *mb > 0.0)
    {
        return (mb * 1e6, format!("set by {MAX_MEMORY_ENV}"));
    }
    match physical_memory_bytes() {
        Some(b) => (b / 2.0, "half this machine's memory".into()),
        None => (FALLBACK_LIMIT, "the machine's memory is unknown".into()),
    }
}

/// The memory limit in bytes ([`memory_limit`]).
pub fn memory_limit_bytes() -> f64 {
    memory_limit().0
}

/// Output samples of a run of `duration` s sampled at `rate` Hz: k / rate for k = 0, 1, … up
/// to the end, and the last instant.
pub fn sample_count(duration: f64, rate: f64) -> f64 {
    (duration * rate).floor().max(0.0) + 2.0
}

/// Bytes taken by `samples` samples of `columns` f64 values.
pub fn sample_bytes(samples: f64, columns: usize) -> f64 {
    samples * columns as f64 * 8.0
}

/// A byte count for messages: "512 kB", "11.8 GB", "3.1e6 TB".
pub fn bytes_text(bytes: f64) -> String {
    let units = [(1e12, "TB"), (1e9, "GB"), (1e6, "MB"), (1e3, "kB")];
    for (scale, unit) in units {
        if bytes >= scale {
            let v = bytes / scale;
            return if v >= 1e6 {
                format!("{} {unit}", crate::timefmt::approx(v))
            } else if v >= 100.0 {
                format!("{v:.0} {unit}")
            } else {
                format!("{v:.1} {unit}")
            };
        }
    }
    format!("{bytes:.0} bytes")
}

/// `Err` with the numbers when storing the samples of a run of `duration` s at `rate` Hz,
/// `columns` values each, would take more than the memory limit. `what` names the file and
/// what stores them (e.g. "x.yaml: the run's samples").
pub fn check_sample_memory(
    what: &str,
    duration: f64,
    rate: f64,
    columns: usize,
) -> Result<(), String> {
    let samples = sample_count(duration, rate);
    let bytes = sample_bytes(samples, columns);
    let (limit, why) = memory_limit();
    if bytes <= limit {
        return Ok(());
    }
    let n = crate::timefmt::number;
    Err(format!(
        "{what} would take about {} ({} samples = rate {} Hz × duration {} s, × {columns} \
         columns × 8 bytes), above the limit of {} ({why}); lower `output.rate`, shorten the \
         run, or raise {MAX_MEMORY_ENV}",
        bytes_text(bytes),
        crate::timefmt::approx(samples),
        n(rate),
        n(duration),
        bytes_text(limit)
    ))
}

/// The message for a failed `try_reserve` of `values` f64 values.
pub fn reserve_failed(what: &str, values: usize, e: &TryReserveError) -> String {
    format!(
        "{what}: cannot allocate {} for {} values ({e}); lower `output.rate` or shorten the run",
        bytes_text(values as f64 * 8.0),
        crate::timefmt::approx(values as f64)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_past_the_limit_is_refused_with_the_numbers() {
        let e = check_sample_memory("x.yaml: the samples", 1e9, 1e6, 30).unwrap_err();
        assert!(e.contains("240000 TB"), "{e}");
        assert!(
            e.contains("1e15 samples = rate 1e6 Hz × duration 1e9 s"),
            "{e}"
        );
        assert!(check_sample_memory("x", 10.0, 10.0, 30).is_ok());
    }

    #[test]
    fn bytes_read_as_numbers() {
        assert_eq!(bytes_text(512.0), "512 bytes");
        assert_eq!(bytes_text(1.18e10), "11.8 GB");
        assert_eq!(bytes_text(3e20), "3e8 TB");
    }
}
