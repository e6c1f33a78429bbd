//! One run's sampled telemetry as a table (`polhode run --csv FILE --parquet FILE`): a row
//! per output sample, the `/telemetry` fields then every effector's fields as
//! `<effector>.<field>`, then, for a scenario with an orbit, the attitude relative to LVLH
//! ([`orbit::ATTITUDE_FIELDS`]: `q_lvlh_*`, `roll_deg`, `pitch_deg`, `yaw_deg`,
//! `omega_lvlh_*`); the same numbers as the MCAP log's `/telemetry`, `/effectors/*` and
//! `/orbit`. Without an orbit those columns are absent and nothing is computed for them.
//!
//! - **CSV**: a header whose names carry their units, `omega_x [rad/s]`; numbers in Rust's
//!   shortest round-trip form, so the text reads back bit for bit.
//! - **Parquet**: plain column names, REQUIRED DOUBLE columns, one row group per
//!   [`ROWS_PER_GROUP`] samples; the key-value metadata `units` maps each column to its unit
//!   (JSON, as the MCAP channels' `units`).
//!
//! Both are streamed to a hidden temporary file beside the target and renamed into place
//! when the run ends, so memory stays flat and a final name never holds a half-written table.

use super::TempFile;
use super::orbit;
use super::telemetry::{self, FIELDS};
use super::units;
use crate::model::{HubState, Observation, Spacecraft};
use crate::orbit::Orbit;
use crate::sim::{EventRecord, Reference, Sink, Warning};
use parquet::basic::{Repetition, Type as PhysicalType};
use parquet::data_type::DoubleType;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Samples buffered per Parquet row group.
pub const ROWS_PER_GROUP: usize = 65_536;

/// A column: its name and unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// `omega_x`, or `<effector>.<field>` for an effector's field.
    pub name: String,
    /// Its unit (`""` when unknown).
    pub unit: String,
}

/// The columns of a run of `spacecraft`: the `/telemetry` fields, then each effector's, then
/// with an `orbit` the attitude relative to LVLH ([`orbit::ATTITUDE_FIELDS`]).
pub fn columns(spacecraft: &Spacecraft, orbit: Option<&Orbit>) -> Vec<Column> {
    let unit_of = |kind: &str, field: &str| {
        units::field_unit(kind, field)
            .map(|(_, u)| u.to_string())
            .unwrap_or_default()
    };
    let mut out: Vec<Column> = FIELDS
        .iter()
        .map(|f| Column {
            name: f.to_string(),
            unit: unit_of(units::TELEMETRY, f),
        })
        .collect();
    for e in spacecraft.effectors() {
        for f in e.telemetry_names() {
            out.push(Column {
                name: format!("{}.{f}", e.name()),
                unit: unit_of(e.kind(), &f),
            });
        }
    }
    if orbit.is_some() {
        out.extend(orbit::ATTITUDE_FIELDS.iter().map(|f| Column {
            name: f.to_string(),
            unit: unit_of(units::ORBIT, f),
        }));
    }
    out
}

/// A table being written to a temporary file beside its target.
struct Pending {
    temp: TempFile,
    target: PathBuf,
}

impl Pending {
    fn new(target: &Path) -> io::Result<(Pending, File)> {
        super::check_replaceable(target)?;
        let (temp, file) = TempFile::beside(target, "table")?;
        let target = target.to_path_buf();
        Ok((Pending { temp, target }, file))
    }

    /// Renames the table into place; returns its path.
    fn persist(self) -> io::Result<PathBuf> {
        self.temp.persist(&self.target)?;
        Ok(self.target)
    }
}

struct ParquetOut {
    pending: Pending,
    writer: SerializedFileWriter<File>,
    /// Column-major buffer of the current row group.
    buffered: Vec<Vec<f64>>,
}

/// A [`Sink`] writing the sampled telemetry to CSV and/or Parquet.
pub struct SampleTable<'a> {
    spacecraft: &'a Spacecraft,
    orbit: Option<&'a Orbit>,
    csv: Option<(Pending, BufWriter<File>)>,
    parquet: Option<ParquetOut>,
    row: Vec<f64>,
    text: String,
}

impl<'a> SampleTable<'a> {
    /// Opens the tables (either may be `None`) for a run of `spacecraft`, in `orbit` when
    /// there is one (its attitude relative to LVLH is then tabulated too). Fails before the
    /// run when a target cannot be written.
    pub fn create(
        spacecraft: &'a Spacecraft,
        orbit: Option<&'a Orbit>,
        csv: Option<&Path>,
        parquet: Option<&Path>,
    ) -> io::Result<SampleTable<'a>> {
        let cols = columns(spacecraft, orbit);
        let csv = match csv {
            None => None,
            Some(path) => {
                let (pending, file) = Pending::new(path)?;
                let mut w = BufWriter::new(file);
                let header: Vec<String> = cols
                    .iter()
                    .map(|c| {
                        let name = if c.unit.is_empty() {
                            c.name.clone()
                        } else {
                            format!("{} [{}]", c.name, c.unit)
                        };
                        if name.contains([',', '"']) {
                            format!("\"{}\"", name.replace('"', "\"\""))
                        } else {
                            name
                        }
                    })
                    .collect();
                writeln!(w, "{}", header.join(","))?;
                Some((pending, w))
            }
        };
        let parquet = match parquet {
            None => None,
            Some(path) => {
                let (pending, file) = Pending::new(path)?;
                let e = |e: parquet::errors::ParquetError| io::Error::other(e.to_string());
                let fields = cols
                    .iter()
                    .map(|c| {
                        Type::primitive_type_builder(&c.name, PhysicalType::DOUBLE)
                            .with_repetition(Repetition::REQUIRED)
                            .build()
                            .map(Arc::new)
                    })
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(e)?;
                let schema = Arc::new(
                    Type::group_type_builder("polhode_samples")
                        .with_fields(fields)
                        .build()
                        .map_err(e)?,
                );
                let units_json = format!(
                    "{{{}}}",
                    cols.iter()
                        .map(|c| format!(
                            "{}:{}",
                            serde_json::Value::from(c.name.as_str()),
                            serde_json::Value::from(c.unit.as_str())
                        ))
                        .collect::<Vec<_>>()
                        .join(",")
                );
                let props = Arc::new(
                    WriterProperties::builder()
                        .set_created_by(format!("polhode {}", env!("CARGO_PKG_VERSION")))
                        .set_key_value_metadata(Some(vec![KeyValue::new(
                            "units".to_string(),
                            units_json,
                        )]))
                        .build(),
                );
                let writer = SerializedFileWriter::new(file, schema, props).map_err(e)?;
                Some(ParquetOut {
                    pending,
                    writer,
                    buffered: vec![Vec::new(); cols.len()],
                })
            }
        };
        Ok(SampleTable {
            spacecraft,
            orbit,
            csv,
            parquet,
            row: Vec::with_capacity(cols.len()),
            text: String::new(),
        })
    }

    fn flush_group(&mut self) -> io::Result<()> {
        let Some(p) = self.parquet.as_mut() else {
            return Ok(());
        };
        if p.buffered[0].is_empty() {
            return Ok(());
        }
        let e = |e: parquet::errors::ParquetError| io::Error::other(e.to_string());
        let mut group = p.writer.next_row_group().map_err(e)?;
        let mut k = 0;
        while let Some(mut col) = group.next_column().map_err(e)? {
            col.typed::<DoubleType>()
                .write_batch(&p.buffered[k], None, None)
                .map_err(e)?;
            col.close().map_err(e)?;
            p.buffered[k].clear();
            k += 1;
        }
        group.close().map_err(e)?;
        Ok(())
    }

    /// Finishes both tables and renames them into place; returns their paths.
    pub fn finish(mut self) -> io::Result<Vec<PathBuf>> {
        self.flush_group()?;
        let mut written = Vec::new();
        if let Some((pending, w)) = self.csv.take() {
            let file = w.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            written.push(pending.persist()?);
        }
        if let Some(p) = self.parquet.take() {
            let file = p
                .writer
                .into_inner()
                .map_err(|e| io::Error::other(e.to_string()))?;
            file.sync_all()?;
            written.push(p.pending.persist()?);
        }
        Ok(written)
    }
}

/// Fills `row` with one sample's values in [`columns`] order: the `/telemetry` fields, then
/// each effector's fields, then with an `orbit` the attitude relative to LVLH (shared by the
/// tables and the Python package).
pub fn fill_row(
    row: &mut Vec<f64>,
    sc: &Spacecraft,
    orbit: Option<&Orbit>,
    o: &Observation,
    y: &[f64],
    inv: &Reference,
) {
    row.clear();
    row.extend_from_slice(&telemetry::values(o, inv));
    let hub = HubState {
        t: o.t,
        omega: o.omega,
        attitude: &y[3..7],
    };
    for (k, e) in sc.effectors().iter().enumerate() {
        row.extend(e.telemetry(&hub, sc.effector_states(k, y)));
    }
    if let Some(orbit) = orbit {
        row.extend_from_slice(&orbit::attitude_values(orbit, o.t, &o.attitude, &o.omega));
    }
}

impl Sink for SampleTable<'_> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> io::Result<()> {
        fill_row(&mut self.row, self.spacecraft, self.orbit, o, y, inv);
        if let Some((_, w)) = self.csv.as_mut() {
            use std::fmt::Write as _;
            self.text.clear();
            for (i, v) in self.row.iter().enumerate() {
                if i > 0 {
                    self.text.push(',');
                }
                let _ = write!(self.text, "{v:?}");
            }
            self.text.push('\n');
            w.write_all(self.text.as_bytes())?;
        }
        if let Some(p) = self.parquet.as_mut() {
            for (k, v) in self.row.iter().enumerate() {
                p.buffered[k].push(*v);
            }
            if p.buffered[0].len() >= ROWS_PER_GROUP {
                self.flush_group()?;
            }
        }
        Ok(())
    }
    fn event(&mut self, _e: &EventRecord, _o: &Observation) -> io::Result<()> {
        Ok(())
    }
}

/// Two sinks fed the same run.
pub struct Both<'a, A: Sink + ?Sized, B: Sink + ?Sized>(pub &'a mut A, pub &'a mut B);

impl<A: Sink + ?Sized, B: Sink + ?Sized> Sink for Both<'_, A, B> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> io::Result<()> {
        self.0.sample(o, y, inv)?;
        self.1.sample(o, y, inv)
    }
    fn event(&mut self, e: &EventRecord, o: &Observation) -> io::Result<()> {
        self.0.event(e, o)?;
        self.1.event(e, o)
    }
    fn warning(&mut self, w: &Warning) -> io::Result<()> {
        self.0.warning(w)?;
        self.1.warning(w)
    }
}
