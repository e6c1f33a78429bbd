//! `polhode plot LOG.mcap`: charts of one run read back from its MCAP log, without a viewer.
//!
//! The log is read with the `mcap` crate; each `polhode.*` message (`/telemetry`,
//! `/effectors/<name>`) is decoded with the field names of the schema embedded in the file
//! (a protobuf `FileDescriptorSet` of doubles), so any log polhode wrote can be plotted, and
//! the units come from the channels' `units` metadata. The charts are drawn by
//! [`crate::plot`], the writer of the benchmark and campaign charts.

use crate::plot::{Chart, Series, Style};
use prost::Message as _;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One channel's samples: the field names in schema order and a column per field.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Channel {
    /// Field names (`sim_time` first).
    pub fields: Vec<String>,
    /// Units by field name (`""` when unknown).
    pub units: BTreeMap<String, String>,
    /// One column of values per field, a value per message.
    pub columns: Vec<Vec<f64>>,
}

impl Channel {
    /// The column of `field`, if the channel has it.
    pub fn column(&self, field: &str) -> Option<&[f64]> {
        let k = self.fields.iter().position(|f| f == field)?;
        Some(&self.columns[k])
    }
}

/// What a run's log holds for charts: `/telemetry` and each `/effectors/<name>` by name, in
/// channel order.
#[derive(Debug, Clone, Default)]
pub struct RunLog {
    /// The scenario's name (metadata `polhode.scenario`), or the file's stem.
    pub name: String,
    /// `/telemetry`.
    pub telemetry: Channel,
    /// `/effectors/<name>`, in channel order.
    pub effectors: Vec<(String, Channel)>,
}

/// The field names of a `FileDescriptorSet` of one message of doubles, in number order.
fn schema_fields(data: &[u8]) -> Result<Vec<String>, String> {
    let set = prost_types::FileDescriptorSet::decode(data)
        .map_err(|e| format!("cannot decode the schema: {e}"))?;
    let message = set
        .file
        .first()
        .and_then(|f| f.message_type.first())
        .ok_or("the schema describes no message")?;
    let mut fields: Vec<(i32, String)> = message
        .field
        .iter()
        .map(|f| (f.number(), f.name().to_string()))
        .collect();
    fields.sort();
    Ok(fields.into_iter().map(|(_, n)| n).collect())
}

/// Decodes a protobuf message of doubles (fields 1..=n, wire type 1) into `out` (n values;
/// absent fields are proto3's 0).
fn decode_doubles(data: &[u8], out: &mut [f64]) -> Result<(), String> {
    out.fill(0.0);
    let mut i = 0;
    while i < data.len() {
        let mut key = 0u64;
        let mut shift = 0;
        loop {
            let b = *data.get(i).ok_or("a message ends inside a field key")?;
            i += 1;
            key |= u64::from(b & 0x7f) << shift;
            if b < 0x80 {
                break;
            }
            shift += 7;
            if shift > 63 {
                return Err("a field key is too long".into());
            }
        }
        if key & 7 != 1 {
            return Err(format!("field {} is not a double", key >> 3));
        }
        let bytes = data.get(i..i + 8).ok_or("a message ends inside a double")?;
        i += 8;
        let number = (key >> 3) as usize;
        if number >= 1 && number <= out.len() {
            out[number - 1] = f64::from_le_bytes(bytes.try_into().expect("8 bytes"));
        }
    }
    Ok(())
}

/// Reads the telemetry and effector channels of the log at `path`.
pub fn read(path: &Path) -> Result<RunLog, String> {
    crate::outputs::note_input(path);
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let not_a_log = |e: mcap::McapError| {
        format!(
            "{} is not a readable MCAP log ({e}); expected a log written by `polhode run`",
            path.display()
        )
    };
    let mut channels: BTreeMap<u16, (String, Channel)> = BTreeMap::new();
    let mut row = Vec::new();
    for message in mcap::MessageStream::new(&bytes).map_err(not_a_log)? {
        let message = message.map_err(not_a_log)?;
        let topic = &message.channel.topic;
        if topic != "/telemetry" && !topic.starts_with("/effectors/") {
            continue;
        }
        let id = message.channel.id;
        if let std::collections::btree_map::Entry::Vacant(slot) = channels.entry(id) {
            let schema = message
                .channel
                .schema
                .as_ref()
                .ok_or_else(|| format!("{}: channel {topic} has no schema", path.display()))?;
            let fields = schema_fields(&schema.data)
                .map_err(|e| format!("{}: channel {topic}: {e}", path.display()))?;
            let units = message
                .channel
                .metadata
                .get("units")
                .and_then(|u| serde_json::from_str::<BTreeMap<String, String>>(u).ok())
                .unwrap_or_default();
            let columns = vec![Vec::new(); fields.len()];
            slot.insert((
                topic.clone(),
                Channel {
                    fields,
                    units,
                    columns,
                },
            ));
        }
        let (_, channel) = channels.get_mut(&id).expect("inserted above");
        row.resize(channel.fields.len(), 0.0);
        decode_doubles(&message.data, &mut row)
            .map_err(|e| format!("{}: a {topic} message: {e}", path.display()))?;
        for (column, v) in channel.columns.iter_mut().zip(&row) {
            column.push(*v);
        }
    }
    // The scenario's name from the metadata record `polhode`, when the summary has it.
    let scenario = mcap::read::Summary::read(&bytes)
        .ok()
        .flatten()
        .and_then(|summary| {
            summary
                .metadata_indexes
                .iter()
                .filter(|i| i.name == "polhode")
                .find_map(|i| mcap::read::metadata(&bytes, i).ok())
        })
        .and_then(|m| m.metadata.get("scenario").cloned());
    let mut log = RunLog {
        name: scenario.unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        }),
        ..RunLog::default()
    };
    let mut found = false;
    for (_, (topic, channel)) in channels {
        if topic == "/telemetry" {
            log.telemetry = channel;
            found = true;
        } else {
            let name = topic.trim_start_matches("/effectors/").to_string();
            log.effectors.push((name, channel));
        }
    }
    if !found || log.telemetry.columns.first().is_none_or(|c| c.is_empty()) {
        return Err(format!(
            "{} has no /telemetry samples; expected a log written by `polhode run`",
            path.display()
        ));
    }
    Ok(log)
}

fn series(t: &[f64], y: &[f64], name: &str) -> Series {
    Series::new(
        name,
        t.iter().copied().zip(y.iter().copied()).collect(),
        Style::Line,
    )
}

fn unit_label(what: &str, unit: &str) -> String {
    if unit.is_empty() || unit == "1" {
        what.to_string()
    } else {
        format!("{what} ({unit})")
    }
}

/// The charts of a run: ω, the nutation angle, the energies, and each effector's coordinates
/// (its fields in the unit of its first field), with their file stems.
pub fn charts(log: &RunLog) -> Vec<(String, Chart)> {
    let tel = &log.telemetry;
    let t = tel.column("sim_time").unwrap_or(&[]);
    let mut out = Vec::new();
    let x_label = "t (s)";

    let mut omega = Chart::new(format!("{}: body rates", log.name), x_label, "ω (rad/s)");
    for (field, name) in [("omega_x", "ω_x"), ("omega_y", "ω_y"), ("omega_z", "ω_z")] {
        if let Some(y) = tel.column(field) {
            omega.series.push(series(t, y, name));
        }
    }
    out.push(("omega".to_string(), omega));

    let mut nutation = Chart::new(
        format!("{}: nutation angle", log.name),
        x_label,
        "nutation angle (deg)",
    );
    if let Some(y) = tel.column("nutation_angle_deg") {
        nutation.series.push(series(t, y, ""));
    }
    out.push(("nutation".to_string(), nutation));

    let mut energy = Chart::new(format!("{}: energies", log.name), x_label, "energy (J)");
    for (field, name) in [
        ("kinetic_energy", "kinetic"),
        ("elastic_energy", "elastic"),
        ("dissipated_energy", "dissipated"),
    ] {
        if let Some(y) = tel.column(field) {
            energy.series.push(series(t, y, name));
        }
    }
    out.push(("energy".to_string(), energy));

    for (name, channel) in &log.effectors {
        let t = channel.column("sim_time").unwrap_or(&[]);
        let Some(first) = channel.fields.iter().find(|f| *f != "sim_time") else {
            continue;
        };
        let unit = channel.units.get(first).cloned().unwrap_or_default();
        let mut chart = Chart::new(
            format!("{}: {name}", log.name),
            x_label,
            unit_label("coordinates", &unit),
        );
        for (k, field) in channel.fields.iter().enumerate() {
            if field != "sim_time" && channel.units.get(field).cloned().unwrap_or_default() == unit
            {
                chart
                    .series
                    .push(series(t, &channel.columns[k], field.as_str()));
            }
        }
        let stem: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        out.push((format!("effector_{stem}"), chart));
    }
    out
}

/// Whether `plot` may write a file named `name` (a chart: SVG or PNG).
pub fn may_write(name: &str) -> bool {
    name.ends_with(".svg") || name.ends_with(".png")
}

/// Writes the charts of `log` as SVG and PNG into `owned` (claimed with [`may_write`]);
/// returns the files written.
pub fn write(log: &RunLog, mut owned: crate::outputs::OwnedDir) -> Result<Vec<PathBuf>, String> {
    let dir = owned.dir().to_path_buf();
    let mut written = Vec::new();
    for (stem, chart) in charts(log) {
        let stem = crate::outputs::sanitize(&stem, ".svg".len());
        owned.file(&format!("{stem}.svg"))?;
        owned.file(&format!("{stem}.png"))?;
        written.extend(crate::plot::svg_and_png(&chart, &dir.join(stem))?);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doubles_decode_as_encoded() {
        let values = [0.0, -1.5, 3.25e-300, f64::MAX, 7.0];
        let mut buf = Vec::new();
        crate::log::telemetry::encode_doubles(&values, &mut buf);
        let mut out = [9.0; 5];
        decode_doubles(&buf, &mut out).unwrap();
        assert_eq!(out, values);
        assert!(decode_doubles(&buf[..buf.len() - 1], &mut out).is_err());
        assert!(decode_doubles(&[0x08, 0x01], &mut out).is_err());
    }
}
