//! The per-run table: one row per finished run, written as CSV (read back by `merge`) and
//! Parquet (for data tools). Numbers are written in Rust's shortest round-trip form, so a
//! table read back from CSV is bit for bit the table that was written.

use parquet::basic::{LogicalType, Repetition, Type as PhysicalType};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::fmt::Write as _;
use std::sync::Arc;

/// How one run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunStatus {
    /// Reached the duration.
    Complete,
    /// A `stop:` condition ended it.
    Stopped,
    /// The integration failed (diagnosis in the message).
    Failed,
    /// The draw could not be made into a valid scenario (reason in the message).
    Invalid,
    /// An effector left the range its model holds in (`checks.on_validity: stop`; diagnosis
    /// in the message).
    InvalidModel,
}

impl RunStatus {
    /// The word written in the table.
    pub fn label(self) -> &'static str {
        match self {
            RunStatus::Complete => "complete",
            RunStatus::Stopped => "stopped",
            RunStatus::Failed => "failed",
            RunStatus::Invalid => "invalid",
            RunStatus::InvalidModel => "invalid_model",
        }
    }

    /// Parses [`RunStatus::label`].
    pub fn parse(s: &str) -> Option<Self> {
        [
            Self::Complete,
            Self::Stopped,
            Self::Failed,
            Self::Invalid,
            Self::InvalidModel,
        ]
        .into_iter()
        .find(|v| v.label() == s)
    }

    /// Whether the run's metrics are usable (complete or stopped).
    pub fn ok(self) -> bool {
        matches!(self, RunStatus::Complete | RunStatus::Stopped)
    }
}

/// One run's row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Run index, 0-based.
    pub run: u64,
    /// How it ended.
    pub status: RunStatus,
    /// Diagnosis of a failed or invalid run (empty otherwise).
    pub message: String,
    /// One value per column; `None` where there is none (event never reached, run failed).
    pub values: Vec<Option<f64>>,
}

/// Names of the fixed leading columns.
pub const LEADING: [&str; 3] = ["run", "status", "message"];

/// The table as CSV text: header, then rows in run order.
pub fn to_csv(columns: &[String], rows: &[Row]) -> String {
    let mut out = String::new();
    let header: Vec<String> = LEADING
        .iter()
        .map(|s| s.to_string())
        .chain(columns.iter().map(|c| quote(c)))
        .collect();
    out.push_str(&header.join(","));
    out.push('\n');
    for r in rows {
        let _ = write!(out, "{},{},{}", r.run, r.status.label(), quote(&r.message));
        for v in &r.values {
            out.push(',');
            if let Some(v) = v {
                let _ = write!(out, "{v:?}");
            }
        }
        out.push('\n');
    }
    out
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Splits CSV text into records of fields (RFC 4180 quoting).
fn records(text: &str) -> Result<Vec<Vec<String>>, String> {
    let mut out = Vec::new();
    let mut record = Vec::new();
    let mut field = String::new();
    let mut chars = text.chars().peekable();
    let mut quoted = false;
    let mut at_start = true;
    while let Some(c) = chars.next() {
        if quoted {
            if c == '"' {
                if chars.peek() == Some(&'"') {
                    chars.next();
                    field.push('"');
                } else {
                    quoted = false;
                }
            } else {
                field.push(c);
            }
            continue;
        }
        match c {
            '"' if at_start => quoted = true,
            ',' => {
                record.push(std::mem::take(&mut field));
                at_start = true;
                continue;
            }
            '\n' => {
                record.push(std::mem::take(&mut field));
                out.push(std::mem::take(&mut record));
                at_start = true;
                continue;
            }
            '\r' => {}
            c => field.push(c),
        }
        at_start = false;
    }
    if quoted {
        return Err("a quoted field is not closed (the file is truncated)".into());
    }
    if !field.is_empty() || !record.is_empty() {
        return Err("the last line has no line end (the file is truncated)".into());
    }
    Ok(out)
}

/// Reads a table written by [`to_csv`], checking its header against `columns`.
pub fn from_csv(text: &str, columns: &[String]) -> Result<Vec<Row>, String> {
    let mut recs = records(text)?.into_iter();
    let header = recs.next().ok_or("the file is empty")?;
    let expected: Vec<String> = LEADING
        .iter()
        .map(|s| s.to_string())
        .chain(columns.iter().cloned())
        .collect();
    if header != expected {
        return Err("its columns differ from the campaign's".into());
    }
    let mut rows = Vec::new();
    for (n, rec) in recs.enumerate() {
        let line = n + 2;
        if rec.len() != expected.len() {
            return Err(format!(
                "line {line} has {} fields; expected {}",
                rec.len(),
                expected.len()
            ));
        }
        let run = rec[0]
            .parse::<u64>()
            .map_err(|_| format!("line {line}: `run` is not a run index"))?;
        let status = RunStatus::parse(&rec[1])
            .ok_or_else(|| format!("line {line}: unknown status `{}`", rec[1]))?;
        let mut values = Vec::with_capacity(columns.len());
        for (k, f) in rec[3..].iter().enumerate() {
            values.push(if f.is_empty() {
                None
            } else {
                Some(
                    f.parse::<f64>().map_err(|_| {
                        format!("line {line}: `{}` is not a number: `{f}`", columns[k])
                    })?,
                )
            });
        }
        rows.push(Row {
            run,
            status,
            message: rec[2].clone(),
            values,
        });
    }
    Ok(rows)
}

/// The table as a Parquet file (uncompressed; one row group): `run` INT64, `status` and
/// `message` strings, then one optional DOUBLE per column (null where the CSV is empty).
pub fn to_parquet(columns: &[String], rows: &[Row]) -> Result<Vec<u8>, String> {
    let e = |e: parquet::errors::ParquetError| e.to_string();
    let string = |name: &str, rep| {
        Type::primitive_type_builder(name, PhysicalType::BYTE_ARRAY)
            .with_repetition(rep)
            .with_logical_type(Some(LogicalType::String))
            .build()
    };
    let mut fields = vec![
        Arc::new(
            Type::primitive_type_builder("run", PhysicalType::INT64)
                .with_repetition(Repetition::REQUIRED)
                .build()
                .map_err(e)?,
        ),
        Arc::new(string("status", Repetition::REQUIRED).map_err(e)?),
        Arc::new(string("message", Repetition::OPTIONAL).map_err(e)?),
    ];
    for c in columns {
        fields.push(Arc::new(
            Type::primitive_type_builder(c, PhysicalType::DOUBLE)
                .with_repetition(Repetition::OPTIONAL)
                .build()
                .map_err(e)?,
        ));
    }
    let schema = Arc::new(
        Type::group_type_builder("polhode_runs")
            .with_fields(fields)
            .build()
            .map_err(e)?,
    );
    let props = Arc::new(
        WriterProperties::builder()
            .set_created_by(format!("polhode {}", env!("CARGO_PKG_VERSION")))
            .build(),
    );
    let mut buf = Vec::new();
    let mut writer = SerializedFileWriter::new(&mut buf, schema, props).map_err(e)?;
    let mut group = writer.next_row_group().map_err(e)?;
    let mut index = 0usize;
    while let Some(mut col) = group.next_column().map_err(e)? {
        match index {
            0 => {
                let runs: Vec<i64> = rows.iter().map(|r| r.run as i64).collect();
                col.typed::<Int64Type>()
                    .write_batch(&runs, None, None)
                    .map_err(e)?;
            }
            1 => {
                let s: Vec<ByteArray> = rows.iter().map(|r| r.status.label().into()).collect();
                col.typed::<ByteArrayType>()
                    .write_batch(&s, None, None)
                    .map_err(e)?;
            }
            2 => {
                let def: Vec<i16> = rows
                    .iter()
                    .map(|r| i16::from(!r.message.is_empty()))
                    .collect();
                let s: Vec<ByteArray> = rows
                    .iter()
                    .filter(|r| !r.message.is_empty())
                    .map(|r| r.message.as_str().into())
                    .collect();
                col.typed::<ByteArrayType>()
                    .write_batch(&s, Some(&def), None)
                    .map_err(e)?;
            }
            k => {
                let j = k - LEADING.len();
                let def: Vec<i16> = rows
                    .iter()
                    .map(|r| i16::from(r.values[j].is_some()))
                    .collect();
                let v: Vec<f64> = rows.iter().filter_map(|r| r.values[j]).collect();
                col.typed::<DoubleType>()
                    .write_batch(&v, Some(&def), None)
                    .map_err(e)?;
            }
        }
        col.close().map_err(e)?;
        index += 1;
    }
    group.close().map_err(e)?;
    writer.close().map_err(e)?;
    Ok(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> (Vec<String>, Vec<Row>) {
        let columns = vec!["a".to_string(), "b[0]".to_string()];
        let rows = vec![
            Row {
                run: 0,
                status: RunStatus::Complete,
                message: String::new(),
                values: vec![Some(0.1 + 0.2), None],
            },
            Row {
                run: 7,
                status: RunStatus::Failed,
                message: "step size underflow at t = 1, \"stiff\"\nsecond line".into(),
                values: vec![Some(1e-300), Some(-1.234_567_891_234_567_8e208)],
            },
        ];
        (columns, rows)
    }

    #[test]
    fn csv_round_trips_bit_for_bit() {
        let (columns, rows) = sample();
        let text = to_csv(&columns, &rows);
        let back = from_csv(&text, &columns).unwrap();
        assert_eq!(back, rows);
        assert_eq!(to_csv(&columns, &back), text);
    }

    #[test]
    fn csv_refuses_truncation_and_other_columns() {
        let (columns, rows) = sample();
        let text = to_csv(&columns, &rows);
        assert!(from_csv(&text[..text.len() - 3], &columns).is_err());
        assert!(from_csv(&text, &columns[..1]).is_err());
    }

    #[test]
    fn parquet_has_magic_and_is_deterministic() {
        let (columns, rows) = sample();
        let a = to_parquet(&columns, &rows).unwrap();
        let b = to_parquet(&columns, &rows).unwrap();
        assert_eq!(a, b);
        assert_eq!(&a[..4], b"PAR1");
        assert_eq!(&a[a.len() - 4..], b"PAR1");
    }
}
