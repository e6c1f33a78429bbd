//! `/orbit` and the `lvlh` frame in the MCAP log of a scenario with an orbit, read back with
//! the `mcap` crate and decoded by hand (docs/logs.md); a scenario without an orbit has
//! neither.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Equatorial radius of the Earth (km), the sphere altitudes are measured above.
const R_EARTH_KM: f64 = 6378.137;

/// `/orbit` field numbers (field i of `polhode.Orbit` has number i + 1).
const SIM_TIME: u64 = 1;
const R_ECI: [u64; 3] = [2, 3, 4];
const V_ECI: [u64; 3] = [5, 6, 7];
const ALTITUDE: u64 = 8;
const ARG_LAT: u64 = 9;
const Q_LVLH: [u64; 4] = [10, 11, 12, 13];
const ROLL: u64 = 14;
const PITCH: u64 = 15;
const YAW: u64 = 16;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polhode-orbit-log-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs a shipped scenario for `duration` s and returns its log's bytes.
fn run(scenario: &str, duration: f64, out: &Path) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(scenario);
    let o = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(out)
        .arg("--duration")
        .arg(duration.to_string())
        .arg("-q")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(out).unwrap()
}

/// Decodes a message of flat proto3 doubles: tag (varint, number << 3 | 1), then 8 bytes
/// little-endian; absent fields are zero.
fn doubles(d: &[u8]) -> HashMap<u64, f64> {
    let mut fields = HashMap::new();
    let mut i = 0;
    while i < d.len() {
        let (mut key, mut shift) = (0u64, 0);
        loop {
            let b = d[i];
            i += 1;
            key |= u64::from(b & 0x7f) << shift;
            shift += 7;
            if b & 0x80 == 0 {
                break;
            }
        }
        assert_eq!(key & 7, 1, "only doubles");
        fields.insert(
            key >> 3,
            f64::from_le_bytes(d[i..i + 8].try_into().unwrap()),
        );
        i += 8;
    }
    fields
}

fn get(m: &HashMap<u64, f64>, k: u64) -> f64 {
    *m.get(&k).unwrap_or(&0.0)
}

// `foxglove.FrameTransforms`, declared here from the published schema.
#[derive(Clone, PartialEq, prost::Message)]
struct Quaternion {
    #[prost(double, tag = "1")]
    x: f64,
    #[prost(double, tag = "2")]
    y: f64,
    #[prost(double, tag = "3")]
    z: f64,
    #[prost(double, tag = "4")]
    w: f64,
}

#[derive(Clone, PartialEq, prost::Message)]
struct FrameTransform {
    #[prost(string, tag = "2")]
    parent_frame_id: String,
    #[prost(string, tag = "3")]
    child_frame_id: String,
    #[prost(message, optional, tag = "5")]
    rotation: Option<Quaternion>,
}

#[derive(Clone, PartialEq, prost::Message)]
struct FrameTransforms {
    #[prost(message, repeated, tag = "1")]
    transforms: Vec<FrameTransform>,
}

/// `(w, x, y, z)` Hamilton product.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The messages of `topic`, with their log times.
fn messages(bytes: &[u8], topic: &str) -> Vec<(u64, Vec<u8>)> {
    mcap::MessageStream::new(bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == topic)
        .map(|m| (m.log_time, m.data.into_owned()))
        .collect()
}

fn frames(bytes: &[u8]) -> Vec<Vec<FrameTransform>> {
    use prost::Message as _;
    messages(bytes, "/tf")
        .iter()
        .map(|(_, d)| FrameTransforms::decode(d.as_slice()).unwrap().transforms)
        .collect()
}

#[test]
fn a_scenario_with_an_orbit_logs_it_and_the_lvlh_frame() {
    let dir = scratch("gg");
    let bytes = run("gravity-gradient-smallsat.yaml", 20.0, &dir.join("gg.mcap"));

    // The channel, its schema and its units.
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let channel = summary
        .channels
        .values()
        .find(|c| c.topic == "/orbit")
        .expect("an /orbit channel");
    assert_eq!(channel.schema.as_ref().unwrap().name, "polhode.Orbit");
    let units: serde_json::Value = serde_json::from_str(&channel.metadata["units"]).unwrap();
    for (field, unit) in [
        ("sim_time", "s"),
        ("r_eci_x", "km"),
        ("v_eci_z", "km/s"),
        ("altitude", "km"),
        ("argument_of_latitude_deg", "deg"),
        ("q_lvlh_w", "1"),
        ("roll_deg", "deg"),
        ("pitch_deg", "deg"),
        ("yaw_deg", "deg"),
    ] {
        assert_eq!(units[field], unit, "{field}");
    }
    assert_eq!(units.as_object().unwrap().len(), 16);

    let orbit = messages(&bytes, "/orbit");
    let telemetry = messages(&bytes, "/telemetry");
    let tf = frames(&bytes);
    // Sampled with the telemetry: output.rate 0.5 Hz over 20 s.
    assert_eq!(orbit.len(), 11);
    let times = |m: &[(u64, Vec<u8>)]| m.iter().map(|(t, _)| *t).collect::<Vec<_>>();
    assert_eq!(times(&orbit), times(&telemetry));
    assert_eq!(tf.len(), orbit.len());

    for (k, ((_, data), transforms)) in orbit.iter().zip(&tf).enumerate() {
        let o = doubles(data);
        let t = get(&o, SIM_TIME);
        assert_eq!(t, 2.0 * k as f64);
        let r = R_ECI.map(|i| get(&o, i));
        let v = V_ECI.map(|i| get(&o, i));
        let r_norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        let v_norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(
            (r_norm - R_EARTH_KM - get(&o, ALTITUDE)).abs() < 1e-9,
            "t = {t}: |r| - R = {} km, altitude {} km",
            r_norm - R_EARTH_KM,
            get(&o, ALTITUDE)
        );
        // A circular 600 km orbit: |v| = sqrt(mu / a).
        assert!((get(&o, ALTITUDE) - 600.0).abs() < 1e-6, "{t}");
        assert!(
            (v_norm - (398_600.441_8_f64 / 6978.137).sqrt()).abs() < 1e-3,
            "{v_norm}"
        );
        let u = get(&o, ARG_LAT);
        assert!((0.0..360.0).contains(&u), "{u}");

        // /tf: the body and the LVLH frame, both children of the world frame; the body
        // attitude is the LVLH frame's times the logged attitude relative to LVLH.
        let body = transforms
            .iter()
            .find(|f| f.child_frame_id == "body")
            .expect("body frame");
        let lvlh = transforms
            .iter()
            .find(|f| f.child_frame_id == "lvlh")
            .expect("an lvlh frame in /tf");
        assert_eq!(body.parent_frame_id, "world");
        assert_eq!(lvlh.parent_frame_id, "world");
        let wxyz = |q: &Option<Quaternion>| {
            let q = q.as_ref().unwrap();
            [q.w, q.x, q.y, q.z]
        };
        let q_ob = Q_LVLH.map(|i| get(&o, i));
        assert!(q_ob[0] >= 0.0);
        let q_nb = mul(wxyz(&lvlh.rotation), q_ob);
        let dot: f64 = q_nb
            .iter()
            .zip(wxyz(&body.rotation))
            .map(|(a, b)| a * b)
            .sum();
        assert!(
            1.0 - dot.abs() < 1e-12,
            "t = {t}: q_NO q_OB != q_NB ({dot})"
        );

        if k == 0 {
            // The scenario's initial attitude, body -> LVLH, and its 3-2-1 angles.
            let expect = [0.995247, 0.043453, 0.087073, -0.003802];
            for (got, want) in q_ob.iter().zip(expect) {
                assert!(
                    (got - want).abs() < 1e-6,
                    "q_lvlh {q_ob:?}, expected {expect:?}"
                );
            }
            for (field, want) in [(ROLL, 5.0), (PITCH, 10.0), (YAW, 0.0)] {
                let got = get(&o, field);
                assert!(
                    (got - want).abs() < 1e-3,
                    "field {field}: {got} deg, expected {want}"
                );
            }
            // Starting at the ascending node.
            assert!(u.abs() < 1e-9, "{u}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scenario_without_an_orbit_has_no_orbit_channel_nor_lvlh_frame() {
    let dir = scratch("rigid");
    let bytes = run("tennis-racket.yaml", 1.0, &dir.join("tr.mcap"));
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert!(
        summary.channels.values().all(|c| c.topic != "/orbit"),
        "an /orbit channel"
    );
    assert!(summary.schemas.values().all(|s| s.name != "polhode.Orbit"));
    let tf = frames(&bytes);
    assert!(!tf.is_empty());
    for transforms in &tf {
        assert_eq!(transforms.len(), 1);
        assert_eq!(transforms[0].child_frame_id, "body");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
