//! `polhode.Telemetry`: one flat protobuf message of doubles per sample.
//!
//! Flat double fields plot directly in Foxglove (`/telemetry.nutation_angle_deg`) and become
//! plain columns in Rerun. The schema is a protobuf `FileDescriptorSet` built here, so readers
//! decode with the schema embedded in the file and need no generated code. Each field carries
//! its description and unit as its protobuf comment (`source_code_info`, from
//! [`super::units`]).

use super::units;
use crate::model::Observation;
use crate::sim::Reference;
use prost::Message;
use prost_types::{
    DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet, SourceCodeInfo,
    field_descriptor_proto::{Label, Type},
    source_code_info::Location,
};

/// Fully qualified schema name.
pub const SCHEMA_NAME: &str = "polhode.Telemetry";

/// Field names in field-number order (field `i` has number `i + 1`); units in [`units`] (the
/// schema's field comments) and `docs/logs.md`.
pub const FIELDS: [&str; 26] = [
    "sim_time",
    "omega_x",
    "omega_y",
    "omega_z",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "h_body_x",
    "h_body_y",
    "h_body_z",
    "h_inertial_x",
    "h_inertial_y",
    "h_inertial_z",
    "h_norm",
    "kinetic_energy",
    "nutation_angle_deg",
    "angle_to_principal_1_deg",
    "angle_to_principal_2_deg",
    "angle_to_principal_3_deg",
    "drift_h_rel",
    "drift_energy_rel",
    "q_norm_error",
    "elastic_energy",
    "dissipated_energy",
    "dissipation_power",
];

/// The serialized `FileDescriptorSet` describing [`FIELDS`] as proto3 doubles.
pub fn schema_bytes() -> Vec<u8> {
    schema_for("polhode", "Telemetry", units::TELEMETRY, &FIELDS)
}

/// A `FileDescriptorSet` for message `package.message` whose fields are the doubles `names`
/// (numbered from 1 in order), each with its description and unit (those of `kind` in
/// [`units::field_unit`]) as its leading comment.
///
/// The comments are `source_code_info` locations with path `[4, 0, 2, i]` (message 0, field
/// i) and spans as if the file were written out as
///
/// ```text
/// 0  syntax = "proto3";
/// 1
/// 2  package <package>;
/// 3
/// 4  message <message> {
/// 5    // <description> (<unit>).
/// 6    double <name> = 1;
///      …                      (field i: comment on line 5 + 2i, declaration on 6 + 2i)
///    }
/// ```
pub fn schema_for<S: AsRef<str>>(package: &str, message: &str, kind: &str, names: &[S]) -> Vec<u8> {
    let fields = names
        .iter()
        .map(|n| n.as_ref())
        .enumerate()
        .map(|(i, name)| FieldDescriptorProto {
            name: Some(name.to_string()),
            number: Some(i as i32 + 1),
            label: Some(Label::Optional as i32),
            r#type: Some(Type::Double as i32),
            json_name: Some(name.to_string()),
            ..Default::default()
        })
        .collect();
    let location = names
        .iter()
        .map(|n| n.as_ref())
        .enumerate()
        .map(|(i, name)| {
            let line = 6 + 2 * i as i32;
            let declaration = format!("double {name} = {};", i + 1);
            Location {
                path: vec![4, 0, 2, i as i32],
                span: vec![line, 2, 2 + declaration.chars().count() as i32],
                leading_comments: Some(units::field_comment(kind, name)),
                ..Default::default()
            }
        })
        .collect();
    let file = FileDescriptorProto {
        name: Some(format!("{}/{message}.proto", package.replace('.', "/"))),
        package: Some(package.into()),
        syntax: Some("proto3".into()),
        message_type: vec![DescriptorProto {
            name: Some(message.into()),
            field: fields,
            ..Default::default()
        }],
        source_code_info: Some(SourceCodeInfo { location }),
        ..Default::default()
    };
    FileDescriptorSet { file: vec![file] }.encode_to_vec()
}

/// The channel metadata `units` of a schema from [`schema_for`]: a JSON object from field
/// name to unit, in field order (`""` for a field without a known unit).
pub fn units_metadata<S: AsRef<str>>(kind: &str, names: &[S]) -> String {
    let entries: Vec<String> = names
        .iter()
        .map(|n| {
            let n = n.as_ref();
            let unit = units::field_unit(kind, n).map_or("", |(_, u)| u);
            format!(
                "{}:{}",
                serde_json::Value::from(n),
                serde_json::Value::from(unit)
            )
        })
        .collect();
    format!("{{{}}}", entries.join(","))
}

/// The values of [`FIELDS`] for one observation.
pub fn values(o: &Observation, inv: &Reference) -> [f64; 26] {
    let q = o.attitude.quaternion();
    let a = o.angles_to_principal.map(f64::to_degrees);
    [
        o.t,
        o.omega[0],
        o.omega[1],
        o.omega[2],
        q.w,
        q.i,
        q.j,
        q.k,
        o.h_body[0],
        o.h_body[1],
        o.h_body[2],
        o.h_inertial[0],
        o.h_inertial[1],
        o.h_inertial[2],
        o.h_norm,
        o.kinetic_energy,
        o.nutation_angle.to_degrees(),
        a[0],
        a[1],
        a[2],
        inv.h_rel(o),
        inv.energy_rel(o),
        o.q_norm_error,
        o.elastic_energy,
        o.dissipated_energy,
        o.dissipation_power,
    ]
}

/// Encodes doubles as protobuf fields 1..=N (wire type 1: 64-bit little-endian).
pub fn encode_doubles(values: &[f64], out: &mut Vec<u8>) {
    out.clear();
    for (i, v) in values.iter().enumerate() {
        let key = ((i as u64 + 1) << 3) | 1;
        let mut k = key;
        while k >= 0x80 {
            out.push((k as u8) | 0x80);
            k >>= 7;
        }
        out.push(k as u8);
        out.extend_from_slice(&v.to_le_bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoding_is_readable_by_prost() {
        // Decode with prost's generic wire-format reader into a dynamic structure: a message
        // with the same field numbers, declared here independently.
        #[derive(Clone, PartialEq, prost::Message)]
        struct Three {
            #[prost(double, tag = "1")]
            a: f64,
            #[prost(double, tag = "2")]
            b: f64,
            #[prost(double, tag = "16")]
            c: f64,
        }
        let mut values = vec![0.0; 16];
        values[0] = 1.5;
        values[1] = -2.25e-300;
        values[15] = f64::MAX;
        let mut buf = Vec::new();
        encode_doubles(&values, &mut buf);
        let m = Three::decode(buf.as_slice()).unwrap();
        assert_eq!((m.a, m.b, m.c), (1.5, -2.25e-300, f64::MAX));
    }

    #[test]
    fn schema_describes_every_field() {
        let set = FileDescriptorSet::decode(schema_bytes().as_slice()).unwrap();
        let msg = &set.file[0].message_type[0];
        assert_eq!(msg.field.len(), FIELDS.len());
        assert_eq!(msg.field[16].name.as_deref(), Some("nutation_angle_deg"));
        assert_eq!(msg.field[16].number, Some(17));
        let info = set.file[0].source_code_info.as_ref().unwrap();
        assert_eq!(info.location.len(), FIELDS.len());
        let loc = &info.location[1];
        assert_eq!(loc.path, [4, 0, 2, 1]);
        assert_eq!(
            loc.leading_comments.as_deref(),
            Some(" Body rate about body x (rad/s).\n")
        );
        assert_eq!(loc.span, [8, 2, 2 + "double omega_x = 2;".len() as i32]);
    }

    #[test]
    fn units_metadata_is_json_in_field_order() {
        let text = units_metadata(units::TELEMETRY, &FIELDS);
        assert!(
            text.starts_with(r#"{"sim_time":"s","omega_x":"rad/s","#),
            "{text}"
        );
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v.as_object().unwrap().len(), FIELDS.len());
        assert_eq!(v["h_norm"], "N m s");
    }
}
