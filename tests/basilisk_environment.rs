//! The four environmental torques against Basilisk's own modules, at the fixed states of
//! `peers/results/basilisk_environment.json` (written by `peers/basilisk_environment.py`
//! with bsk 2.12.1; this test reads the committed file and needs neither Python nor
//! Basilisk): GravityGradientEffector, MagneticFieldCenteredDipole with MtbEffector,
//! ExponentialAtmosphere with ZeroWindModel and FacetDragDynamicEffector, and
//! FacetSRPDynamicEffector with Eclipse. Basilisk was given polhode's inputs where the
//! models differ (μ, the IGRF-14 dipole and the Earth rotation angle, the atmosphere band,
//! the Sun's direction and distance, the solar flux through the facet area; the script's
//! docstring and docs/peers.md list them), so what is compared is the torque computation.
//!
//! polhode's side is built here from the state's inputs alone (elements, epoch, time,
//! attitude, effector data) and evaluated through `EnvironmentTorque::environment_torque`,
//! the call the simulator makes. The inputs Basilisk was fed are checked against polhode's
//! own (orbit state, Earth rotation angle, dipole coefficients, density, Sun vector), so
//! that a disagreement is located.
//!
//! With `POLHODE_PEER_OUT=path` the polhode torques and the differences are written there as
//! JSON (`peers/run.sh` does so for the tables of docs/peers.md).
use nalgebra::{Matrix3, Vector3};
use polhode::effectors::aerodynamic::density;
use polhode::effectors::environment::EnvironmentTorque;
use polhode::effectors::solar_pressure::sun_direction;
use polhode::effectors::{Aerodynamic, GravityGradient, MagneticDipole, SolarPressure};
use polhode::model::HubState;
use polhode::orbit::magnetic::{Dipole, decimal_year};
use polhode::orbit::{CentralBody, Elements, GeomagneticField, Orbit, earth_rotation_angle};
use polhode::scenario::{Overrides, parse, parse_epoch};
use serde_json::{Value, json};
use std::path::Path;
use std::sync::Arc;

/// Relative agreement of the torques, |τ_polhode − τ_Basilisk| / |τ_Basilisk|. The same
/// formulas evaluated in a different order differ by a few ulps; measured: up to 2e-15 for
/// the gravity gradient, magnetic and solar torques, 1.5e-14 for the aerodynamic one, whose
/// density ρ₀ exp(−(h − h₀)/H) turns the last bit of the orbit radius (9e-10 m at 6800 km,
/// where polhode's Kepler solution and Basilisk's orbitalMotion round differently) into
/// 9e-10/H ≈ 1.6e-14 of ρ for H = 58 km. A wrong constant, frame, sign or band is 1e-8
/// (μ) to 5e-3 (the solar flux) or more.
const TORQUE_TOLERANCE: f64 = 1e-13;
/// Relative agreement of the inputs fed to Basilisk with polhode's own (orbit state,
/// density, wind, Sun vector and distance).
const INPUT_TOLERANCE: f64 = 1e-13;

fn results() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/peers/results/basilisk_environment.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn v3(v: &Value) -> Vector3<f64> {
    let a = v.as_array().unwrap_or_else(|| panic!("not an array: {v}"));
    assert_eq!(a.len(), 3, "{v}");
    Vector3::new(f(&a[0]), f(&a[1]), f(&a[2]))
}

fn quaternion(v: &Value) -> [f64; 4] {
    let a = v.as_array().unwrap();
    [f(&a[0]), f(&a[1]), f(&a[2]), f(&a[3])]
}

/// The hub state the environment torques see: time `t` (s) and attitude `q` (w, x, y, z);
/// they do not depend on the rates.
fn at(t: f64, q: &[f64; 4]) -> HubState<'_> {
    HubState {
        t,
        omega: Vector3::zeros(),
        attitude: q,
    }
}

/// The orbit of the JSON elements (m, degrees; two-body, no J2 drift).
fn orbit(el: &Value) -> Arc<Orbit> {
    let deg = |k: &str| f(&el[k]).to_radians();
    let elements = Elements::new(
        f(&el["a"]),
        f(&el["e"]),
        deg("i"),
        deg("raan"),
        deg("argp"),
        deg("nu"),
    );
    Arc::new(Orbit::new(CentralBody::EARTH, elements, false).unwrap())
}

fn epoch(input: &Value) -> i64 {
    parse_epoch(input["epoch"].as_str().unwrap()).unwrap()
}

fn relative(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

/// One compared state.
struct Row {
    label: String,
    basilisk: Vector3<f64>,
    polhode: Vector3<f64>,
}

/// polhode's torque at one state of `kind`, after checking the inputs Basilisk was fed.
fn polhode_torque(kind: &str, input: &Value, fed: &Value) -> Vector3<f64> {
    let label = input["label"].as_str().unwrap();
    let orbit = orbit(&input["elements"]);
    let t = f(&input["t"]);
    let q = quaternion(&input["attitude"]);
    let (r, v) = orbit.state(t);
    let r_fed = v3(&fed["r_eci"]);
    let v_fed = v3(&fed["v_eci"]);
    assert!(
        relative(&r, &r_fed) <= INPUT_TOLERANCE && relative(&v, &v_fed) <= INPUT_TOLERANCE,
        "{kind}, {label}: orbit state {r:?} {v:?} vs Basilisk's orbitalMotion {r_fed:?} {v_fed:?}"
    );
    match kind {
        "gravity_gradient" => {
            assert_eq!(f(&fed["mu"]), CentralBody::EARTH.mu, "{label}: μ fed");
            let rows = input["inertia"].as_array().unwrap();
            let inertia = Matrix3::from_fn(|i, j| f(&rows[i][j]));
            let gg = GravityGradient {
                name: "gg".into(),
                orbit,
                inertia,
            };
            gg.environment_torque(&at(t, &q))
        }
        "magnetic_dipole" => {
            let epoch_ns = epoch(input);
            let unix_s = epoch_ns as f64 * 1e-9 + t;
            let year = decimal_year(unix_s);
            assert!(
                (year - f(&fed["decimal_year"])).abs() <= 1e-12,
                "{label}: year {year} vs {}",
                fed["decimal_year"]
            );
            let d = Dipole::igrf14(year);
            for (ours, key) in [(d.g10, "g10_nT"), (d.g11, "g11_nT"), (d.h11, "h11_nT")] {
                assert!(
                    (ours - f(&fed[key])).abs() <= 1e-9,
                    "{label}: {key} {ours} vs {}",
                    fed[key]
                );
            }
            let era = earth_rotation_angle(epoch_ns, t);
            assert!(
                (era - f(&fed["earth_rotation_angle"])).abs() <= 1e-12,
                "{label}: Earth rotation angle {era} vs {}",
                fed["earth_rotation_angle"]
            );
            let md = MagneticDipole {
                name: "m".into(),
                orbit,
                field: GeomagneticField::new(epoch_ns),
                moment: v3(&input["moment"]),
            };
            let b = md.field_body(t, &q);
            let b_fed = v3(&fed["b_body"]);
            assert!(
                relative(&b, &b_fed) <= TORQUE_TOLERANCE,
                "{label}: B in body axes {b:?} vs Basilisk's {b_fed:?}"
            );
            md.environment_torque(&at(t, &q))
        }
        "aerodynamic" => {
            let h = r.norm() - CentralBody::EARTH.radius;
            let rho = density(h);
            let rho_fed = f(&fed["density"]);
            assert!(
                ((rho - rho_fed) / rho_fed).abs() <= INPUT_TOLERANCE,
                "{label}: density {rho:e} vs Basilisk's ExponentialAtmosphere {rho_fed:e} (band {})",
                fed["band"]
            );
            let aero = Aerodynamic {
                name: "a".into(),
                orbit,
                drag_coefficient: f(&input["drag_coefficient"]),
                area: f(&input["area"]),
                center_of_pressure: v3(&input["center_of_pressure"]),
            };
            let (_, wind) = aero.density_and_wind(t, &q);
            let wind_fed = v3(&fed["wind_body"]);
            assert!(
                relative(&wind, &wind_fed) <= INPUT_TOLERANCE,
                "{label}: relative wind {wind:?} vs Basilisk's {wind_fed:?}"
            );
            aero.environment_torque(&at(t, &q))
        }
        "solar_pressure" => {
            let epoch_ns = epoch(input);
            let (s, d) = sun_direction(epoch_ns as f64 * 1e-9 + t);
            let s_fed = v3(&fed["sun_eci"]);
            assert!(
                (s - s_fed).norm() <= INPUT_TOLERANCE
                    && (d - f(&fed["sun_distance_au"])).abs() <= INPUT_TOLERANCE,
                "{label}: Sun {s:?} at {d} AU vs fed {s_fed:?} at {}",
                fed["sun_distance_au"]
            );
            let sp = SolarPressure {
                name: "s".into(),
                orbit,
                epoch_unix_ns: epoch_ns,
                area: f(&input["area"]),
                normal: v3(&input["normal"]),
                center_of_pressure: v3(&input["center_of_pressure"]),
                specular: f(&input["specular"]),
                diffuse: f(&input["diffuse"]),
            };
            // The shadow: Basilisk's conical umbra (shadow factor 0 or 1 at these states,
            // chosen away from the penumbra) against polhode's cylinder.
            let lit = sp.state_at(t, &q).illuminated;
            assert_eq!(
                lit,
                f(&fed["shadow_factor"]) == 1.0,
                "{label}: illuminated {lit}, Basilisk's shadow factor {}",
                fed["shadow_factor"]
            );
            sp.environment_torque(&at(t, &q))
        }
        _ => panic!("unknown kind {kind}"),
    }
}

#[test]
fn environmental_torques_agree_with_basilisk() {
    let data = results();
    assert_eq!(
        data["basilisk"], "2.12.1",
        "the Basilisk version of the results"
    );
    let mut out = serde_json::Map::new();
    for kind in [
        "gravity_gradient",
        "magnetic_dipole",
        "aerodynamic",
        "solar_pressure",
    ] {
        let states = data["effectors"][kind]
            .as_array()
            .unwrap_or_else(|| panic!("no {kind} states"));
        assert!(states.len() >= 5, "{kind}: {} states", states.len());
        let mut rows = Vec::new();
        for s in states {
            let (input, fed) = (&s["input"], &s["basilisk"]);
            rows.push(Row {
                label: input["label"].as_str().unwrap().to_string(),
                basilisk: v3(&fed["torque"]),
                polhode: polhode_torque(kind, input, fed),
            });
        }
        let mut nonzero = 0;
        let mut worst: f64 = 0.0;
        let mut table = Vec::new();
        for row in &rows {
            let rel = if row.basilisk == Vector3::zeros() {
                assert_eq!(
                    row.polhode,
                    Vector3::zeros(),
                    "{kind}, {}: Basilisk's torque is zero",
                    row.label
                );
                0.0
            } else {
                nonzero += 1;
                relative(&row.polhode, &row.basilisk)
            };
            assert!(
                rel <= TORQUE_TOLERANCE,
                "{kind}, {}: polhode {:?} vs Basilisk {:?}: relative difference {rel:e}",
                row.label,
                row.polhode,
                row.basilisk
            );
            worst = worst.max(rel);
            table.push(json!({
                "label": row.label,
                "basilisk": row.basilisk.as_slice(),
                "polhode": row.polhode.as_slice(),
                "relative_difference": rel,
            }));
        }
        assert!(nonzero >= 4, "{kind}: only {nonzero} nonzero torques");
        eprintln!(
            "{kind}: {} states, largest relative difference {worst:.2e}",
            rows.len()
        );
        out.insert(kind.into(), Value::Array(table));
    }
    if let Ok(path) = std::env::var("POLHODE_PEER_OUT") {
        let doc = json!({"tolerance": TORQUE_TOLERANCE, "effectors": out});
        std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap() + "\n")
            .unwrap_or_else(|e| panic!("{path}: {e}"));
    }
}

/// A YAML list `[x, y, z]` of a JSON array, numbers written in full (`{:?}` round-trips).
fn yaml_list(v: &Value) -> String {
    let items: Vec<String> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| format!("{:?}", f(x)))
        .collect();
    format!("[{}]", items.join(", "))
}

/// The scenario file of one state: its epoch, inertia, orbit (km, degrees) and the one
/// effector with the state's data, as a user writes them.
fn scenario_yaml(kind: &str, input: &Value) -> String {
    let el = &input["elements"];
    let epoch = input["epoch"]
        .as_str()
        .map(|e| format!("epoch: {e}\n"))
        .unwrap_or_default();
    let body = match input.get("inertia") {
        Some(rows) => {
            let rows: Vec<String> = rows.as_array().unwrap().iter().map(yaml_list).collect();
            format!("{{inertia: [{}]}}", rows.join(", "))
        }
        None => "{principal: [1.0, 2.0, 3.0]}".to_string(),
    };
    let effector = match kind {
        "gravity_gradient" => "{}".to_string(),
        "magnetic_dipole" => format!("{{moment: {}}}", yaml_list(&input["moment"])),
        "aerodynamic" => format!(
            "{{drag_coefficient: {:?}, area: {:?}, center_of_pressure: {}}}",
            f(&input["drag_coefficient"]),
            f(&input["area"]),
            yaml_list(&input["center_of_pressure"])
        ),
        "solar_pressure" => format!(
            "{{area: {:?}, normal: {}, center_of_pressure: {}, specular: {:?}, diffuse: {:?}}}",
            f(&input["area"]),
            yaml_list(&input["normal"]),
            yaml_list(&input["center_of_pressure"]),
            f(&input["specular"]),
            f(&input["diffuse"])
        ),
        _ => panic!("unknown kind {kind}"),
    };
    format!(
        "name: basilisk-state
{epoch}body: {body}
orbit: {{semi_major_axis_km: {:?}, eccentricity: {:?}, inclination_deg: {:?}, raan_deg: {:?}, \
arg_perigee_deg: {:?}, true_anomaly_deg: {:?}, magnetic_field: dipole}}
initial: {{omega: [0.0, 0.0, 0.0]}}
duration: 1.0
effectors:
  - {kind}: {effector}
",
        f(&el["a"]) / 1e3,
        f(&el["e"]),
        f(&el["i"]),
        f(&el["raan"]),
        f(&el["argp"]),
        f(&el["nu"]),
    )
}

/// The same states through the scenario loader (the YAML a user writes: km, degrees, the
/// epoch string, `body.inertia`), evaluated by the loaded spacecraft's effector: the same
/// torques as Basilisk's. The km and degree conversions round the elements by an ulp, which
/// moves the torques by at most the conditioning noise above.
#[test]
fn the_same_states_from_scenario_files_agree_with_basilisk() {
    let data = results();
    for kind in [
        "gravity_gradient",
        "magnetic_dipole",
        "aerodynamic",
        "solar_pressure",
    ] {
        let mut worst: f64 = 0.0;
        for s in data["effectors"][kind].as_array().unwrap() {
            let (input, fed) = (&s["input"], &s["basilisk"]);
            let label = input["label"].as_str().unwrap();
            let yaml = scenario_yaml(kind, input);
            let scenario = parse(
                Path::new("basilisk-state.yaml"),
                yaml.clone(),
                &Overrides::default(),
            )
            .unwrap_or_else(|e| panic!("{kind}, {label}: {e}\n{yaml}"));
            let effectors = scenario.spacecraft.effectors();
            assert_eq!(effectors.len(), 1, "{kind}, {label}");
            let effector = &effectors[0];
            assert_eq!(effector.kind(), kind);
            let q = quaternion(&input["attitude"]);
            let hub = HubState {
                t: f(&input["t"]),
                omega: Vector3::zeros(),
                attitude: &q,
            };
            let ours = effector.torque(&hub, &effector.initial_state());
            let theirs = v3(&fed["torque"]);
            let rel = if theirs == Vector3::zeros() {
                assert_eq!(ours, Vector3::zeros(), "{kind}, {label}");
                0.0
            } else {
                relative(&ours, &theirs)
            };
            assert!(
                rel <= TORQUE_TOLERANCE,
                "{kind}, {label}: from the scenario file {ours:?} vs Basilisk {theirs:?}: {rel:e}\n{yaml}"
            );
            worst = worst.max(rel);
        }
        eprintln!("{kind} from scenario files: largest relative difference {worst:.2e}");
    }
}
