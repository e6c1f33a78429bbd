//! The per-run table: one row per finished run, written as CSV (read back by `merge`) and
//! Parquet (for data tools). Numbers are written in Rust's shortest round-trip form, so a
//! table read back from CSV is bit for bit the table that was written.

use parquet::basic::{LogicalType, Repetition, Type as PhysicalType};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::io::BufRead;
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

/// Writes the table as CSV, a row at a time: the header on creation, then each row as it is
/// pushed (in run order). Holds nothing but the current line, and hashes what it writes.
pub struct CsvWriter<W: std::io::Write> {
    out: W,
    line: String,
    hash: Sha256,
}

impl<W: std::io::Write> CsvWriter<W> {
    /// Starts the table in `out` with the header of `columns`.
    pub fn new(out: W, columns: &[String]) -> std::io::Result<Self> {
        let header: Vec<String> = LEADING
            .iter()
            .map(|s| s.to_string())
            .chain(columns.iter().map(|c| quote(c)))
            .collect();
        let mut w = Self {
            out,
            line: header.join(",") + "\n",
            hash: Sha256::new(),
        };
        w.flush_line()?;
        Ok(w)
    }

    fn flush_line(&mut self) -> std::io::Result<()> {
        self.hash.update(self.line.as_bytes());
        self.out.write_all(self.line.as_bytes())?;
        self.line.clear();
        Ok(())
    }

    /// Appends `row`.
    pub fn push(&mut self, row: &Row) -> std::io::Result<()> {
        let _ = write!(
            self.line,
            "{},{},{}",
            row.run,
            row.status.label(),
            quote(&row.message)
        );
        for v in &row.values {
            self.line.push(',');
            if let Some(v) = v {
                let _ = write!(self.line, "{v:?}");
            }
        }
        self.line.push('\n');
        self.flush_line()
    }

    /// Flushes the table and returns its writer and the hex SHA-256 of everything written.
    pub fn finish(mut self) -> std::io::Result<(W, String)> {
        self.out.flush()?;
        let hex = self
            .hash
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        Ok((self.out, hex))
    }
}

/// The table as CSV text: header, then rows in run order.
pub fn to_csv(columns: &[String], rows: &[Row]) -> String {
    let write = || -> std::io::Result<Vec<u8>> {
        let mut w = CsvWriter::new(Vec::new(), columns)?;
        for r in rows {
            w.push(r)?;
        }
        Ok(w.finish()?.0)
    };
    // Writing into memory cannot fail, and the writer writes only UTF-8.
    String::from_utf8(write().unwrap_or_default()).unwrap_or_default()
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Reads CSV records (RFC 4180 quoting) one at a time: a quoted field may hold line ends.
struct Records<R: BufRead> {
    input: R,
    line: Vec<u8>,
}

impl<R: BufRead> Records<R> {
    /// The next record's fields, or `None` at the end of the input.
    fn next_record(&mut self) -> Result<Option<Vec<String>>, String> {
        let mut record = Vec::new();
        let mut field = Vec::new();
        let mut quoted = false;
        let mut at_start = true;
        let mut started = false;
        loop {
            self.line.clear();
            let n = self
                .input
                .read_until(b'\n', &mut self.line)
                .map_err(|e| format!("cannot read it: {e}"))?;
            if n == 0 {
                // A started record ends only here inside a quoted field: a line without its
                // `\n` is refused below as soon as it is read.
                return if started {
                    Err("a quoted field is not closed (the file is truncated)".into())
                } else {
                    Ok(None)
                };
            }
            started = true;
            if self.line.last() != Some(&b'\n') {
                return Err(if quoted {
                    "a quoted field is not closed (the file is truncated)".into()
                } else {
                    "the last line has no line end (the file is truncated)".into()
                });
            }
            let mut bytes = self.line.iter().copied().peekable();
            while let Some(c) = bytes.next() {
                if quoted {
                    if c == b'"' {
                        if bytes.peek() == Some(&b'"') {
                            bytes.next();
                            field.push(b'"');
                        } else {
                            quoted = false;
                        }
                    } else {
                        field.push(c);
                    }
                    continue;
                }
                match c {
                    b'"' if at_start => quoted = true,
                    b',' => {
                        record.push(utf8(std::mem::take(&mut field))?);
                        at_start = true;
                        continue;
                    }
                    b'\n' => {
                        record.push(utf8(std::mem::take(&mut field))?);
                        return Ok(Some(record));
                    }
                    b'\r' => {}
                    c => field.push(c),
                }
                at_start = false;
            }
            // Still inside a quoted field: it goes on on the next line.
        }
    }
}

fn utf8(bytes: Vec<u8>) -> Result<String, String> {
    String::from_utf8(bytes).map_err(|_| "a field is not UTF-8 text".into())
}

/// Reads a table written by [`CsvWriter`] from `input`, checking its header against
/// `columns`, and hands each row to `each` in the order of the file. Holds one row at a time.
pub fn read_csv<R: BufRead>(
    input: R,
    columns: &[String],
    mut each: impl FnMut(Row) -> Result<(), String>,
) -> Result<(), String> {
    let mut recs = Records {
        input,
        line: Vec::new(),
    };
    let header = recs.next_record()?.ok_or("the file is empty")?;
    let expected: Vec<String> = LEADING
        .iter()
        .map(|s| s.to_string())
        .chain(columns.iter().cloned())
        .collect();
    if header != expected {
        return Err("its columns differ from the campaign's".into());
    }
    let mut line = 1;
    while let Some(rec) = recs.next_record()? {
        line += 1;
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
        let mut rec = rec;
        each(Row {
            run,
            status,
            message: std::mem::take(&mut rec[2]),
            values,
        })?;
    }
    Ok(())
}

/// Reads a table written by [`to_csv`], checking its header against `columns`.
pub fn from_csv(text: &str, columns: &[String]) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    read_csv(text.as_bytes(), columns, |r| {
        rows.push(r);
        Ok(())
    })?;
    Ok(rows)
}

/// Rows per Parquet row group: the Parquet writer holds at most this many rows.
pub const PARQUET_ROWS_PER_GROUP: usize = 16_384;

/// Writes the table as Parquet (uncompressed), a row group of [`PARQUET_ROWS_PER_GROUP`]
/// rows at a time: `run` INT64, `status` and `message` strings, then one optional DOUBLE
/// per column (null where the CSV is empty).
pub struct ParquetWriter<W: std::io::Write + Send> {
    writer: SerializedFileWriter<W>,
    rows: Vec<Row>,
    rows_per_group: usize,
}

fn parquet_error(e: parquet::errors::ParquetError) -> String {
    e.to_string()
}

impl<W: std::io::Write + Send> ParquetWriter<W> {
    /// Starts the file in `out` with the schema of `columns`.
    pub fn new(out: W, columns: &[String]) -> Result<Self, String> {
        Self::with_rows_per_group(out, columns, PARQUET_ROWS_PER_GROUP)
    }

    /// [`ParquetWriter::new`] with another row-group size (at least 1).
    pub fn with_rows_per_group(
        out: W,
        columns: &[String],
        rows_per_group: usize,
    ) -> Result<Self, String> {
        let rows_per_group = rows_per_group.max(1);
        let e = parquet_error;
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
        Ok(Self {
            writer: SerializedFileWriter::new(out, schema, props).map_err(e)?,
            rows: Vec::with_capacity(rows_per_group),
            rows_per_group,
        })
    }

    /// Appends `row`; writes a row group when a group's rows are waiting.
    pub fn push(&mut self, row: Row) -> Result<(), String> {
        self.rows.push(row);
        if self.rows.len() == self.rows_per_group {
            self.write_group()?;
        }
        Ok(())
    }

    fn write_group(&mut self) -> Result<(), String> {
        let e = parquet_error;
        let rows = &self.rows;
        let mut group = self.writer.next_row_group().map_err(e)?;
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
        self.rows.clear();
        Ok(())
    }

    /// Writes the last row group (a table of no rows has one, empty) and the footer, and
    /// returns the writer.
    pub fn finish(mut self) -> Result<W, String> {
        if !self.rows.is_empty() || self.writer.flushed_row_groups().is_empty() {
            self.write_group()?;
        }
        self.writer.into_inner().map_err(parquet_error)
    }
}

/// The table as a Parquet file (see [`ParquetWriter`]).
pub fn to_parquet(columns: &[String], rows: &[Row]) -> Result<Vec<u8>, String> {
    let mut w = ParquetWriter::new(Vec::new(), columns)?;
    for r in rows {
        w.push(r.clone())?;
    }
    w.finish()
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
    fn csv_is_read_back_from_a_stream_with_line_ends_in_messages() {
        let (columns, rows) = sample();
        let text = to_csv(&columns, &rows);
        let mut back = Vec::new();
        // A one-byte buffer: records are reassembled across reads and lines.
        let input = std::io::BufReader::with_capacity(1, text.as_bytes());
        read_csv(input, &columns, |r| {
            back.push(r);
            Ok(())
        })
        .unwrap();
        assert_eq!(back, rows);
    }

    #[test]
    fn parquet_row_groups_hold_every_row_in_order() {
        use parquet::file::reader::{FileReader, SerializedFileReader};
        use parquet::record::Field;
        let columns = vec!["x".to_string()];
        let rows: Vec<Row> = (0..10)
            .map(|run| Row {
                run,
                status: if run == 4 {
                    RunStatus::Failed
                } else {
                    RunStatus::Complete
                },
                message: if run == 4 {
                    "bad".into()
                } else {
                    String::new()
                },
                values: vec![(run != 7).then_some(run as f64 * 0.5)],
            })
            .collect();
        let mut w = ParquetWriter::with_rows_per_group(Vec::new(), &columns, 3).unwrap();
        for r in &rows {
            w.push(r.clone()).unwrap();
        }
        let bytes = w.finish().unwrap();
        let path =
            std::env::temp_dir().join(format!("polhode-groups-{}.parquet", std::process::id()));
        std::fs::write(&path, &bytes).unwrap();
        let reader = SerializedFileReader::new(std::fs::File::open(&path).unwrap()).unwrap();
        assert_eq!(reader.metadata().num_row_groups(), 4);
        let read: Vec<Vec<Field>> = reader
            .get_row_iter(None)
            .unwrap()
            .map(|r| {
                r.unwrap()
                    .get_column_iter()
                    .map(|(_, f)| f.clone())
                    .collect()
            })
            .collect();
        let _ = std::fs::remove_file(&path);
        assert_eq!(read.len(), rows.len());
        for (r, f) in rows.iter().zip(&read) {
            assert_eq!(f[0], Field::Long(r.run as i64));
            assert_eq!(f[1], Field::Str(r.status.label().into()));
            let message = if r.message.is_empty() {
                Field::Null
            } else {
                Field::Str(r.message.clone())
            };
            assert_eq!(f[2], message);
            assert_eq!(f[3], r.values[0].map_or(Field::Null, Field::Double));
        }
        // Up to a group's rows, one group: the bytes of a table written whole.
        let few = &rows[..3];
        let mut w = ParquetWriter::with_rows_per_group(Vec::new(), &columns, 3).unwrap();
        few.iter().for_each(|r| w.push(r.clone()).unwrap());
        assert_eq!(w.finish().unwrap(), to_parquet(&columns, few).unwrap());
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
