//! `/orbit` and the `lvlh` frame in the MCAP log of a scenario with an orbit, read back with
//! the `mcap` crate and decoded by hand (docs/logs.md); a scenario without an orbit has
//! neither.

mod common;

use std::collections::HashMap;
use std::path::Path;
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
const OMEGA_LVLH: [u64; 3] = [17, 18, 19];
/// `/telemetry` field numbers of ω_BN (rad/s, body axes).
const OMEGA: [u64; 3] = [2, 3, 4];

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-orbit-log", name)
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
struct Vector3 {
    #[prost(double, tag = "1")]
    x: f64,
    #[prost(double, tag = "2")]
    y: f64,
    #[prost(double, tag = "3")]
    z: f64,
}

#[derive(Clone, PartialEq, prost::Message)]
struct FrameTransform {
    #[prost(string, tag = "2")]
    parent_frame_id: String,
    #[prost(string, tag = "3")]
    child_frame_id: String,
    #[prost(message, optional, tag = "4")]
    translation: Option<Vector3>,
    #[prost(message, optional, tag = "5")]
    rotation: Option<Quaternion>,
}

// `foxglove.SceneUpdate`, the parts the orbit view uses, from the published schema.
#[derive(Clone, PartialEq, prost::Message)]
struct Pose {
    #[prost(message, optional, tag = "1")]
    position: Option<Vector3>,
    #[prost(message, optional, tag = "2")]
    orientation: Option<Quaternion>,
}

#[derive(Clone, PartialEq, prost::Message)]
struct Sphere {
    #[prost(message, optional, tag = "1")]
    pose: Option<Pose>,
    #[prost(message, optional, tag = "2")]
    size: Option<Vector3>,
}

#[derive(Clone, PartialEq, prost::Message)]
struct Arrow {
    #[prost(message, optional, tag = "1")]
    pose: Option<Pose>,
    #[prost(double, tag = "2")]
    shaft_length: f64,
    #[prost(double, tag = "4")]
    head_length: f64,
}

#[derive(Clone, PartialEq, prost::Message)]
struct Line {
    #[prost(message, optional, tag = "2")]
    pose: Option<Pose>,
    #[prost(message, repeated, tag = "5")]
    points: Vec<Vector3>,
}

#[derive(Clone, PartialEq, prost::Message)]
struct SceneEntity {
    #[prost(string, tag = "2")]
    frame_id: String,
    #[prost(string, tag = "3")]
    id: String,
    #[prost(bool, tag = "5")]
    frame_locked: bool,
    #[prost(message, repeated, tag = "7")]
    arrows: Vec<Arrow>,
    #[prost(message, repeated, tag = "9")]
    spheres: Vec<Sphere>,
    #[prost(message, repeated, tag = "11")]
    lines: Vec<Line>,
}

#[derive(Clone, PartialEq, prost::Message)]
struct SceneUpdate {
    #[prost(message, repeated, tag = "2")]
    entities: Vec<SceneEntity>,
}

fn scenes(bytes: &[u8], topic: &str) -> Vec<(u64, Vec<SceneEntity>)> {
    use prost::Message as _;
    messages(bytes, topic)
        .iter()
        .map(|(t, d)| (*t, SceneUpdate::decode(d.as_slice()).unwrap().entities))
        .collect()
}

fn xyz(v: &Option<Vector3>) -> [f64; 3] {
    v.as_ref().map_or([0.0; 3], |v| [v.x, v.y, v.z])
}

fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Perifocal P̂ (to perigee) and Ŵ (orbit normal) in ECI for Ω, i, ω (rad), from the
/// rotation R3(−Ω) R1(−i) R3(−ω) written out (Vallado, 4th ed., §2.6; Curtis, §4.6).
fn perifocal(raan: f64, inc: f64, argp: f64) -> ([f64; 3], [f64; 3]) {
    let (so, co) = raan.sin_cos();
    let (si, ci) = inc.sin_cos();
    let (sw, cw) = argp.sin_cos();
    (
        [co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si],
        [so * si, -co * si, ci],
    )
}

/// WGS-84 GM (m^3/s^2) and the semi-major axis of gravity-gradient-smallsat (m).
const MU: f64 = 3.986_004_418e14;
const A_GG: f64 = 6_978_137.0;

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
        ("omega_lvlh_x", "rad/s"),
        ("omega_lvlh_z", "rad/s"),
    ] {
        assert_eq!(units[field], unit, "{field}");
    }
    assert_eq!(units.as_object().unwrap().len(), 19);

    let orbit = messages(&bytes, "/orbit");
    let telemetry = messages(&bytes, "/telemetry");
    let tf = frames(&bytes);
    // Sampled with the telemetry: output.rate 0.5 Hz over 20 s.
    assert_eq!(orbit.len(), 11);
    let times = |m: &[(u64, Vec<u8>)]| m.iter().map(|(t, _)| *t).collect::<Vec<_>>();
    assert_eq!(times(&orbit), times(&telemetry));
    assert_eq!(tf.len(), orbit.len());

    for (k, (((_, data), transforms), (_, hub))) in
        orbit.iter().zip(&tf).zip(&telemetry).enumerate()
    {
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
        // The orbit view's frames: `world` at r(t) in `eci`, and the Earth-fixed `ecef`.
        assert_eq!(transforms.len(), 4);
        let world = &transforms[2];
        let ecef = &transforms[3];
        assert_eq!(
            (
                world.parent_frame_id.as_str(),
                world.child_frame_id.as_str()
            ),
            ("eci", "world")
        );
        assert_eq!(
            (ecef.parent_frame_id.as_str(), ecef.child_frame_id.as_str()),
            ("eci", "ecef")
        );
        let r_tf = xyz(&world.translation);
        let r_m = r.map(|x| x * 1e3);
        assert!(
            norm(sub(r_tf, r_m)) <= 1e-12 * norm(r_m),
            "t = {t}: eci -> world {r_tf:?} m, /orbit r {r_m:?} m"
        );
        // Against the circular orbit written out: u = n t from the ascending node.
        let (p_hat, w_hat) = perifocal(30f64.to_radians(), 51.6f64.to_radians(), 0.0);
        let q_hat = [
            w_hat[1] * p_hat[2] - w_hat[2] * p_hat[1],
            w_hat[2] * p_hat[0] - w_hat[0] * p_hat[2],
            w_hat[0] * p_hat[1] - w_hat[1] * p_hat[0],
        ];
        let u = (MU / A_GG.powi(3)).sqrt() * t;
        let expect: [f64; 3] =
            std::array::from_fn(|k| A_GG * (u.cos() * p_hat[k] + u.sin() * q_hat[k]));
        assert!(
            norm(sub(r_tf, expect)) <= 1e-9 * A_GG,
            "t = {t}: r {r_tf:?}, two-body {expect:?}"
        );
        // ecef: a rotation about z by the Earth rotation angle (IAU 2000, IERS Conventions
        // 2010 eq. 5.15) at the default epoch J2000.0, D_U = t / 86400.
        let era = std::f64::consts::TAU
            * (0.779_057_273_264_0 + (t + 0.002_737_811_911_354_48 * t) / 86_400.0);
        let e = wxyz(&ecef.rotation);
        let half = era / 2.0;
        let d = (e[0] * half.cos() + e[3] * half.sin()).abs();
        assert!(
            e[1] == 0.0 && e[2] == 0.0 && 1.0 - d < 1e-15,
            "t = {t}: ecef {e:?}, ERA {era}"
        );
        assert_eq!(xyz(&ecef.translation), [0.0; 3]);
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

        // The body rate relative to LVLH: ω_BO = ω_BN − C_BN ω_ON, with the frame's rate of a
        // two-body orbit ω_ON = r × v / |r|² (ECI) written out here from the logged r and v.
        let rxv = [
            r[1] * v[2] - r[2] * v[1],
            r[2] * v[0] - r[0] * v[2],
            r[0] * v[1] - r[1] * v[0],
        ];
        let r2: f64 = r.iter().map(|x| x * x).sum();
        let w_on = rxv.map(|x| x / r2);
        let q_body = wxyz(&body.rotation);
        let conj = [q_body[0], -q_body[1], -q_body[2], -q_body[3]];
        let in_body = mul(mul(conj, [0.0, w_on[0], w_on[1], w_on[2]]), q_body);
        let hub = doubles(hub);
        let expect: [f64; 3] = std::array::from_fn(|i| get(&hub, OMEGA[i]) - in_body[i + 1]);
        let got = OMEGA_LVLH.map(|i| get(&o, i));
        assert!(
            norm(sub(got, expect)) < 1e-12,
            "t = {t}: omega_lvlh {got:?} rad/s, from r, v and ω_BN {expect:?}"
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
    assert!(
        summary
            .channels
            .values()
            .all(|c| c.topic != "/earth" && c.topic != "/orbit_scene"),
        "an orbit view"
    );
    let tf = frames(&bytes);
    assert!(!tf.is_empty());
    for transforms in &tf {
        assert_eq!(transforms.len(), 1);
        assert_eq!(transforms[0].child_frame_id, "body");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `/earth` once, with the Earth to scale in the Earth-fixed frame; `/orbit_scene` every
/// twelfth of a period, with the path starting at the spacecraft and lying on the orbit's
/// circle and plane, the marker at the origin of `world` (so at r(t)) and the axes.
#[test]
fn the_orbit_view_draws_the_earth_the_path_and_the_marker() {
    let dir = scratch("view");
    let bytes = run(
        "gravity-gradient-smallsat.yaml",
        2000.0,
        &dir.join("gg.mcap"),
    );
    let tf = frames(&bytes);
    let tf_times: Vec<u64> = messages(&bytes, "/tf").iter().map(|(t, _)| *t).collect();
    let r_at = |log_time: u64| {
        let k = tf_times
            .iter()
            .position(|t| *t == log_time)
            .expect("a /tf sample");
        xyz(&tf[k][2].translation)
    };

    let earth = scenes(&bytes, "/earth");
    assert_eq!(earth.len(), 1);
    assert_eq!(earth[0].0, tf_times[0]);
    let e = &earth[0].1[0];
    assert_eq!(
        (e.id.as_str(), e.frame_id.as_str(), e.frame_locked),
        ("earth", "ecef", true)
    );
    let d = 2.0 * R_EARTH_KM * 1e3;
    assert_eq!(xyz(&e.spheres[0].size), [d, d, d]);
    // The graticule lies just above the sphere; one line (the prime meridian) at longitude 0.
    let mut prime = 0;
    for line in &e.lines {
        for p in &line.points {
            let n = norm(xyz(&Some(p.clone())));
            assert!(n > R_EARTH_KM * 1e3 && n < 1.01 * R_EARTH_KM * 1e3, "{n}");
        }
        if line
            .points
            .iter()
            .all(|p| p.y.abs() < 1e-6 * d && p.x > -1e-6 * d)
        {
            prime += 1;
        }
    }
    assert_eq!(prime, 1, "one line on the prime meridian");

    let views = scenes(&bytes, "/orbit_scene");
    // Period 2 pi sqrt(a^3/mu) = 5801.1 s, an update every 483.4 s, on the 2 s sample grid:
    // t = 0, 484, 968, 1452, 1936.
    let period = std::f64::consts::TAU * (A_GG.powi(3) / MU).sqrt();
    let sim: Vec<u64> = views.iter().map(|(t, _)| t - tf_times[0]).collect();
    let expect = [0, 484, 968, 1452, 1936].map(|s: u64| s * 1_000_000_000);
    assert_eq!(sim, expect, "period {period}");
    let (_, w_hat) = perifocal(30f64.to_radians(), 51.6f64.to_radians(), 0.0);
    for (log_time, entities) in &views {
        let by_id = |id: &str| {
            entities
                .iter()
                .find(|e| e.id == id)
                .unwrap_or_else(|| panic!("no {id}"))
        };
        let r = r_at(*log_time);
        let path = by_id("orbit_path");
        assert_eq!(path.frame_id, "eci");
        let points: Vec<[f64; 3]> = path.lines[0]
            .points
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect();
        assert_eq!(points.len(), 181);
        // Starts and ends (one period later) at the spacecraft.
        assert!(
            norm(sub(points[0], r)) <= 1e-9 * A_GG,
            "{:?} {r:?}",
            points[0]
        );
        assert!(norm(sub(points[180], r)) <= 1e-9 * A_GG);
        for p in &points {
            assert!((norm(*p) - A_GG).abs() <= 1e-9 * A_GG, "|p| = {}", norm(*p));
            assert!(
                dot(*p, w_hat).abs() <= 1e-9 * A_GG,
                "out of plane {}",
                dot(*p, w_hat)
            );
        }
        // Consecutive points 2 degrees apart.
        let step = (dot(points[0], points[1]) / (A_GG * A_GG))
            .acos()
            .to_degrees();
        assert!((step - 2.0).abs() < 1e-9, "{step}");

        let marker = by_id("spacecraft_marker");
        assert_eq!(
            (marker.frame_id.as_str(), marker.frame_locked),
            ("world", true)
        );
        assert_eq!(
            xyz(&marker.spheres[0].pose.as_ref().unwrap().position),
            [0.0; 3]
        );
        let size = xyz(&marker.spheres[0].size)[0];
        // Visible at orbit scale: 6 % of a (419 km), not the metre-sized body.
        assert!((size - 0.06 * A_GG).abs() < 1e-6, "{size}");
        let body = by_id("body_axes");
        assert_eq!((body.frame_id.as_str(), body.arrows.len()), ("body", 3));
        let lvlh = by_id("lvlh_axes");
        assert_eq!((lvlh.frame_id.as_str(), lvlh.lines.len()), ("lvlh", 3));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An eccentric, inclined orbit: every point of the path is on the ellipse with a focus at
/// the Earth's centre (the sum of the distances to both foci is 2a) and in the orbit plane.
#[test]
fn the_orbit_path_of_an_eccentric_orbit_lies_on_its_ellipse() {
    let dir = scratch("ellipse");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/gravity-gradient-smallsat.yaml"),
    )
    .unwrap();
    let start = text.find("orbit:").unwrap();
    let end = text.find("initial:").unwrap();
    let (a, e, inc, raan, argp) = (9000.0e3, 0.2, 63.4_f64, 120.0_f64, 250.0_f64);
    let orbit = format!(
        "orbit:\n  semi_major_axis_km: {}\n  eccentricity: {e}\n  inclination_deg: {inc}\n  \
         raan_deg: {raan}\n  arg_perigee_deg: {argp}\n  true_anomaly_deg: 75.0\n",
        a / 1e3
    );
    let scenario = dir.join("eccentric.yaml");
    std::fs::write(
        &scenario,
        format!("{}{orbit}{}", &text[..start], &text[end..]),
    )
    .unwrap();
    let out = dir.join("e.mcap");
    let o = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(["--duration", "10", "-q"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&out).unwrap();
    let (p_hat, w_hat) = perifocal(raan.to_radians(), inc.to_radians(), argp.to_radians());
    // The empty focus, 2 a e from the Earth's centre, away from perigee.
    let f2 = p_hat.map(|x| -2.0 * a * e * x);
    let views = scenes(&bytes, "/orbit_scene");
    assert_eq!(views.len(), 1);
    let path = views[0].1.iter().find(|e| e.id == "orbit_path").unwrap();
    let points = &path.lines[0].points;
    assert_eq!(points.len(), 181);
    let (mut r_min, mut r_max) = (f64::INFINITY, 0.0_f64);
    for p in points {
        let p = [p.x, p.y, p.z];
        let sum = norm(p) + norm(sub(p, f2));
        assert!(
            (sum - 2.0 * a).abs() <= 1e-9 * a,
            "r1 + r2 = {sum}, 2a = {}",
            2.0 * a
        );
        assert!(
            dot(p, w_hat).abs() <= 1e-9 * a,
            "out of plane {}",
            dot(p, w_hat)
        );
        r_min = r_min.min(norm(p));
        r_max = r_max.max(norm(p));
    }
    // Equal time steps: the path reaches near perigee a(1 - e) and apogee a(1 + e).
    assert!(
        r_min < 1.001 * a * (1.0 - e) && r_max > 0.999 * a * (1.0 + e),
        "{r_min} {r_max}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
