//! Descriptions and units of every logged field, and the names of the effector schemas.
//!
//! This is the one table behind the field comments in the MCAP schemas
//! (`FileDescriptorProto.source_code_info`) and the channels' `units` metadata;
//! `docs/logs.md` lists the same units. A field missing here has no unit: the schema builder
//! then writes a comment without one, and the tests (`every_logged_field_has_a_unit` here,
//! `log::tests` on the shipped scenarios' logs) fail.

use std::borrow::Cow;

/// The `kind` under which [`field_unit`] knows the fields of `/telemetry`.
pub const TELEMETRY: &str = "telemetry";

/// The `kind` under which [`field_unit`] knows the fields of `/orbit`.
pub const ORBIT: &str = "orbit";

/// The unit of a dimensionless quantity (a ratio, a quaternion component).
pub const DIMENSIONLESS: &str = "1";

/// Modal coordinates of mass-normalised modes (w = Σ q φ, φ in kg^-½).
const MODAL: &str = "m kg^½";
const MODAL_RATE: &str = "m kg^½/s";

/// `/telemetry`: field, description, unit.
const TELEMETRY_FIELDS: [(&str, &str, &str); 26] = [
    ("sim_time", "Simulation time since the epoch", "s"),
    ("omega_x", "Body rate about body x", "rad/s"),
    ("omega_y", "Body rate about body y", "rad/s"),
    ("omega_z", "Body rate about body z", "rad/s"),
    (
        "q_w",
        "Attitude quaternion body to world (Hamilton, normalised), scalar part",
        DIMENSIONLESS,
    ),
    (
        "q_x",
        "Attitude quaternion body to world, x part",
        DIMENSIONLESS,
    ),
    (
        "q_y",
        "Attitude quaternion body to world, y part",
        DIMENSIONLESS,
    ),
    (
        "q_z",
        "Attitude quaternion body to world, z part",
        DIMENSIONLESS,
    ),
    (
        "h_body_x",
        "Angular momentum about the system centre of mass, body x",
        "N m s",
    ),
    (
        "h_body_y",
        "Angular momentum about the system centre of mass, body y",
        "N m s",
    ),
    (
        "h_body_z",
        "Angular momentum about the system centre of mass, body z",
        "N m s",
    ),
    (
        "h_inertial_x",
        "Angular momentum about the system centre of mass, world x",
        "N m s",
    ),
    (
        "h_inertial_y",
        "Angular momentum about the system centre of mass, world y",
        "N m s",
    ),
    (
        "h_inertial_z",
        "Angular momentum about the system centre of mass, world z",
        "N m s",
    ),
    ("h_norm", "Magnitude of the angular momentum |H|", "N m s"),
    (
        "kinetic_energy",
        "Kinetic energy of the whole spacecraft in its centre-of-mass frame",
        "J",
    ),
    (
        "nutation_angle_deg",
        "Nutation angle, between the scenario's spin axis and H",
        "deg",
    ),
    (
        "angle_to_principal_1_deg",
        "Angle between omega and the minimum-inertia principal axis",
        "deg",
    ),
    (
        "angle_to_principal_2_deg",
        "Angle between omega and the intermediate-inertia principal axis",
        "deg",
    ),
    (
        "angle_to_principal_3_deg",
        "Angle between omega and the maximum-inertia principal axis",
        "deg",
    ),
    (
        "drift_h_rel",
        "Relative change of |H| since the start, (|H| - |H0|)/|H0|; with a thruster, of |H plus \
         the angular momentum the exhaust carried out|",
        DIMENSIONLESS,
    ),
    (
        "drift_energy_rel",
        "Relative drift of the energy balance E = kinetic + elastic + dissipated, (E - E0)/E0",
        DIMENSIONLESS,
    ),
    (
        "q_norm_error",
        "Norm error |q| - 1 of the integrated quaternion",
        DIMENSIONLESS,
    ),
    (
        "elastic_energy",
        "Elastic energy stored in the effectors",
        "J",
    ),
    (
        "dissipated_energy",
        "Energy dissipated by the effectors since the start",
        "J",
    ),
    (
        "dissipation_power",
        "Power dissipated by the effectors",
        "W",
    ),
];

/// `/orbit`: field, description, unit.
const ORBIT_FIELDS: [(&str, &str, &str); 19] = [
    ("sim_time", "Simulation time since the epoch", "s"),
    ("r_eci_x", "Spacecraft position, ECI x", "km"),
    ("r_eci_y", "Spacecraft position, ECI y", "km"),
    ("r_eci_z", "Spacecraft position, ECI z", "km"),
    ("v_eci_x", "Spacecraft velocity, ECI x", "km/s"),
    ("v_eci_y", "Spacecraft velocity, ECI y", "km/s"),
    ("v_eci_z", "Spacecraft velocity, ECI z", "km/s"),
    (
        "altitude",
        "Altitude above the sphere of the central body's equatorial radius, |r| - R",
        "km",
    ),
    (
        "argument_of_latitude_deg",
        "Argument of latitude u, from the ascending node to the spacecraft, in [0, 360)",
        "deg",
    ),
    (
        "q_lvlh_w",
        "Attitude quaternion body to LVLH, q_OB = q_NO^-1 q_NB, Hamilton, sign with w >= 0, scalar part",
        DIMENSIONLESS,
    ),
    (
        "q_lvlh_x",
        "Attitude quaternion body to LVLH, x part",
        DIMENSIONLESS,
    ),
    (
        "q_lvlh_y",
        "Attitude quaternion body to LVLH, y part",
        DIMENSIONLESS,
    ),
    (
        "q_lvlh_z",
        "Attitude quaternion body to LVLH, z part",
        DIMENSIONLESS,
    ),
    (
        "roll_deg",
        "Roll, 3-2-1 Euler angle about the body 1 axis, the last rotation, in (-180, 180]",
        "deg",
    ),
    (
        "pitch_deg",
        "Pitch, 3-2-1 Euler angle about the intermediate 2 axis, in [-90, 90]",
        "deg",
    ),
    (
        "yaw_deg",
        "Yaw, 3-2-1 Euler angle about the LVLH o3 nadir axis, the first rotation, in (-180, 180]",
        "deg",
    ),
    (
        "omega_lvlh_x",
        "Body rate relative to LVLH, omega_BO = omega_BN - C_BN omega_ON, about body x",
        "rad/s",
    ),
    (
        "omega_lvlh_y",
        "Body rate relative to LVLH, about body y",
        "rad/s",
    ),
    (
        "omega_lvlh_z",
        "Body rate relative to LVLH, about body z",
        "rad/s",
    ),
];

/// Description and unit of `field` of `/telemetry` (`kind` = [`TELEMETRY`]), of `/orbit`
/// (`kind` = [`ORBIT`]) or of the
/// telemetry of an effector of `kind` (its YAML kind, e.g. `hinged_rod`; `sim_time`
/// included). `None` when the field is not known for that kind.
pub fn field_unit(kind: &str, field: &str) -> Option<(Cow<'static, str>, &'static str)> {
    if kind == TELEMETRY {
        return TELEMETRY_FIELDS
            .iter()
            .find(|(name, ..)| *name == field)
            .map(|&(_, d, u)| (Cow::Borrowed(d), u));
    }
    if kind == ORBIT {
        return ORBIT_FIELDS
            .iter()
            .find(|(name, ..)| *name == field)
            .map(|&(_, d, u)| (Cow::Borrowed(d), u));
    }
    let fixed = |d: &'static str, u: &'static str| Some((Cow::Borrowed(d), u));
    match (kind, field) {
        (_, "sim_time") => return fixed("Simulation time since the epoch", "s"),
        (
            "spring_mass_damper" | "hinged_rod" | "modal_appendage" | "slosh_pendulum",
            "elastic_energy",
        ) => {
            return fixed("Elastic energy stored in this effector", "J");
        }
        (_, "dissipated_energy") => {
            return fixed("Energy dissipated by this effector since the start", "J");
        }
        (_, "dissipation_power") => return fixed("Power dissipated by this effector", "W"),
        ("spring_mass_damper", "offset") => {
            return fixed(
                "Offset of the mass along its line from the spring's rest",
                "m",
            );
        }
        ("spring_mass_damper", "offset_rate") => return fixed("Rate of the offset", "m/s"),
        ("hinged_rod", "flap") => {
            return fixed("Flap angle, the rod tipped toward the hinge axis", "rad");
        }
        ("hinged_rod", "lag") => {
            return fixed("Lag angle, the rod turned about the hinge axis", "rad");
        }
        ("hinged_rod", "flap_rate") => return fixed("Flap angle rate", "rad/s"),
        ("hinged_rod", "lag_rate") => return fixed("Lag angle rate", "rad/s"),
        ("hinged_rod", "tip_x") => return fixed("Rod tip position, body x", "m"),
        ("hinged_rod", "tip_y") => return fixed("Rod tip position, body y", "m"),
        ("hinged_rod", "tip_z") => return fixed("Rod tip position, body z", "m"),
        ("slosh_pendulum", "phi") => {
            return fixed(
                "Pendulum angle phi, the rod turned about p3 from its rest direction",
                "rad",
            );
        }
        ("slosh_pendulum", "theta") => {
            return fixed("Pendulum angle theta, the rod tipped toward -p3", "rad");
        }
        ("slosh_pendulum", "phi_rate") => return fixed("Rate of phi", "rad/s"),
        ("slosh_pendulum", "theta_rate") => return fixed("Rate of theta", "rad/s"),
        ("slosh_pendulum", "liquid_mass") => {
            return fixed("Liquid left in the tank that a thruster drains", "kg");
        }
        ("slosh_pendulum", "fill") => {
            return fixed("Fill fraction of the drained tank, by volume", "1");
        }
        ("slosh_pendulum", "slosh_mass") => {
            return fixed("Sloshing mass of the analog at the present fill", "kg");
        }
        ("slosh_pendulum", "length") => {
            return fixed("Pendulum length of the analog at the present fill", "m");
        }
        ("slosh_pendulum", "swing_deg") => {
            return fixed("Angle between the rod and its rest direction", "deg");
        }
        ("thruster", "exhaust_momentum_x" | "exhaust_momentum_y" | "exhaust_momentum_z") => {
            return fixed(
                "Angular momentum the exhaust has carried out since the start, about the \
                 centre of mass, inertial axes",
                "N m s",
            );
        }
        ("thruster", "propellant_mass") => return fixed("Propellant left in the tank", "kg"),
        ("thruster", "thrust") => return fixed("Thrust magnitude", "N"),
        ("thruster", "mass_flow") => {
            return fixed("Mass flow leaving through the nozzle", "kg/s");
        }
        ("modal_appendage", "tip_flap") => {
            return fixed("Tip deflection along the flap direction", "m");
        }
        ("modal_appendage", "tip_lag") => {
            return fixed("Tip deflection along the lag direction", "m");
        }
        ("wheel_damper" | "wheel", "rate") => {
            return fixed("Rotor rate about its axis relative to the body", "rad/s");
        }
        ("wheel", "momentum") => {
            return fixed(
                "Rotor's angular momentum relative to the body, I_a times the rate",
                "N m s",
            );
        }
        ("wheel", "motor_torque") => {
            return fixed(
                "Motor torque on the rotor (the body takes its opposite)",
                "N m",
            );
        }
        ("wheel", "friction_torque") => {
            return fixed("Bearing friction torque opposing the rotor's rate", "N m");
        }
        ("wheel", "motor_work") => {
            return fixed("Work done by the motor since the start", "J");
        }
        ("gravity_gradient", "torque_x") => {
            return fixed("Gravity-gradient torque on the hub, body x", "N m");
        }
        ("gravity_gradient", "torque_y") => {
            return fixed("Gravity-gradient torque on the hub, body y", "N m");
        }
        ("gravity_gradient", "torque_z") => {
            return fixed("Gravity-gradient torque on the hub, body z", "N m");
        }
        ("gravity_gradient", "work") => {
            return fixed(
                "Work done by the gravity-gradient torque since the start",
                "J",
            );
        }
        ("gravity_gradient", "potential_energy") => {
            return fixed(
                "Attitude-dependent gravitational potential energy of the hub",
                "J",
            );
        }
        ("magnetic_dipole", "torque_x") => {
            return fixed("Magnetic torque m × B on the hub, body x", "N m");
        }
        ("magnetic_dipole", "torque_y") => {
            return fixed("Magnetic torque m × B on the hub, body y", "N m");
        }
        ("magnetic_dipole", "torque_z") => {
            return fixed("Magnetic torque m × B on the hub, body z", "N m");
        }
        ("eddy_currents", "torque_x") => {
            return fixed(
                "Eddy-current torque (M (ω × B)) × B on the hub, body x",
                "N m",
            );
        }
        ("eddy_currents", "torque_y") => {
            return fixed(
                "Eddy-current torque (M (ω × B)) × B on the hub, body y",
                "N m",
            );
        }
        ("eddy_currents", "torque_z") => {
            return fixed(
                "Eddy-current torque (M (ω × B)) × B on the hub, body z",
                "N m",
            );
        }
        ("eddy_currents", "b_x") => return fixed("Magnetic field at the body, body x", "T"),
        ("eddy_currents", "b_y") => return fixed("Magnetic field at the body, body y", "T"),
        ("eddy_currents", "b_z") => return fixed("Magnetic field at the body, body z", "T"),
        ("eddy_currents", "power") => {
            return fixed("Power dissipated by the eddy currents, −τ·ω", "W");
        }
        ("eddy_currents", "reynolds") => {
            return fixed(
                "Magnetic Reynolds number μ0 σ |ω| h R / 2 (NaN for a tensor given directly)",
                DIMENSIONLESS,
            );
        }
        ("eddy_currents", "work") => {
            return fixed(
                "Work done by the eddy-current torque since the start (≤ 0)",
                "J",
            );
        }
        ("hysteresis_rod", "b") => {
            return fixed(
                "Flux density of the rod along its axis (apparent loop)",
                "T",
            );
        }
        ("hysteresis_rod", "h") => {
            return fixed("Applied field along the rod, H = ê·B/μ0", "A/m");
        }
        ("hysteresis_rod", "h_rate") => {
            return fixed("Rate of the applied field along the rod, dH/dt", "A/m/s");
        }
        ("hysteresis_rod", "moment") => {
            return fixed(
                "Magnetic moment of the rod along its axis, (B/μ0 − H) V",
                "A m^2",
            );
        }
        ("hysteresis_rod", "torque_x") => {
            return fixed("Hysteresis-rod torque m × B on the hub, body x", "N m");
        }
        ("hysteresis_rod", "torque_y") => {
            return fixed("Hysteresis-rod torque m × B on the hub, body y", "N m");
        }
        ("hysteresis_rod", "torque_z") => {
            return fixed("Hysteresis-rod torque m × B on the hub, body z", "N m");
        }
        ("hysteresis_rod", "work") => {
            return fixed(
                "Work done by the hysteresis-rod torque since the start",
                "J",
            );
        }
        ("magnetorquer", "dipole_x") => {
            return fixed("Commanded coil dipole, held between ticks, body x", "A m^2");
        }
        ("magnetorquer", "dipole_y") => {
            return fixed("Commanded coil dipole, held between ticks, body y", "A m^2");
        }
        ("magnetorquer", "dipole_z") => {
            return fixed("Commanded coil dipole, held between ticks, body z", "A m^2");
        }
        ("magnetorquer", "torque_x") => {
            return fixed("Magnetic torque m × B on the hub, body x", "N m");
        }
        ("magnetorquer", "torque_y") => {
            return fixed("Magnetic torque m × B on the hub, body y", "N m");
        }
        ("magnetorquer", "torque_z") => {
            return fixed("Magnetic torque m × B on the hub, body z", "N m");
        }
        ("magnetorquer", "b_x") => return fixed("Geomagnetic field, body x", "T"),
        ("magnetorquer", "b_y") => return fixed("Geomagnetic field, body y", "T"),
        ("magnetorquer", "b_z") => return fixed("Geomagnetic field, body z", "T"),
        ("magnetorquer", "samples") => {
            return fixed(
                "Field samples the controller has taken (ticks)",
                DIMENSIONLESS,
            );
        }
        ("magnetorquer", "rotation_per_sample") => {
            return fixed(
                "Body rotation between field samples at the last tick, |omega| dt",
                "rad",
            );
        }
        ("magnetorquer", "work") => {
            return fixed("Work done by the coils' torque since the start", "J");
        }
        ("magnetic_dipole", "b_x") => return fixed("Geomagnetic field, body x", "T"),
        ("magnetic_dipole", "b_y") => return fixed("Geomagnetic field, body y", "T"),
        ("magnetic_dipole", "b_z") => return fixed("Geomagnetic field, body z", "T"),
        ("magnetic_dipole", "work") => {
            return fixed("Work done by the magnetic torque since the start", "J");
        }
        ("solar_pressure", "torque_x") => {
            return fixed("Solar pressure torque r_cp × F on the hub, body x", "N m");
        }
        ("solar_pressure", "torque_y") => {
            return fixed("Solar pressure torque r_cp × F on the hub, body y", "N m");
        }
        ("solar_pressure", "torque_z") => {
            return fixed("Solar pressure torque r_cp × F on the hub, body z", "N m");
        }
        ("solar_pressure", "sun_x") => return fixed("Unit vector to the Sun, body x", "1"),
        ("solar_pressure", "sun_y") => return fixed("Unit vector to the Sun, body y", "1"),
        ("solar_pressure", "sun_z") => return fixed("Unit vector to the Sun, body z", "1"),
        ("solar_pressure", "illuminated") => {
            return fixed("1 in sunlight, 0 in the Earth's cylindrical shadow", "1");
        }
        ("solar_pressure", "work") => {
            return fixed("Work done by the solar pressure since the start", "J");
        }
        ("aerodynamic", "torque_x") => {
            return fixed("Aerodynamic torque r_cp × F on the hub, body x", "N m");
        }
        ("aerodynamic", "torque_y") => {
            return fixed("Aerodynamic torque r_cp × F on the hub, body y", "N m");
        }
        ("aerodynamic", "torque_z") => {
            return fixed("Aerodynamic torque r_cp × F on the hub, body z", "N m");
        }
        ("aerodynamic", "density") => {
            return fixed("Atmospheric density (exponential model)", "kg/m^3");
        }
        ("aerodynamic", "wind_x") => {
            return fixed("Velocity through the co-rotating air, body x", "m/s");
        }
        ("aerodynamic", "wind_y") => {
            return fixed("Velocity through the co-rotating air, body y", "m/s");
        }
        ("aerodynamic", "wind_z") => {
            return fixed("Velocity through the co-rotating air, body z", "m/s");
        }
        ("aerodynamic", "work") => {
            return fixed("Work done by the aerodynamic torque since the start", "J");
        }
        _ => {}
    }
    if kind == "modal_appendage" {
        // `flap_<i>`, `lag_<i>` and their `_rate`.
        let (coordinate, rate) = match field.strip_suffix("_rate") {
            Some(c) => (c, true),
            None => (field, false),
        };
        let (direction, mode) = coordinate.split_once('_')?;
        let mode: u32 = mode.parse().ok().filter(|&m| m >= 1)?;
        if !matches!(direction, "flap" | "lag")
            || mode.to_string() != coordinate[direction.len() + 1..]
        {
            return None;
        }
        let what = if rate {
            "Rate of the modal coordinate"
        } else {
            "Modal coordinate"
        };
        return Some((
            Cow::Owned(format!(
                "{what} of {direction} bending mode {mode} (mass-normalised)"
            )),
            if rate { MODAL_RATE } else { MODAL },
        ));
    }
    None
}

/// The protobuf comment of a field: ` <description> (<unit>).`, or the description alone
/// for a field without a known unit (which the tests refuse).
pub fn field_comment(kind: &str, field: &str) -> String {
    match field_unit(kind, field) {
        Some((description, unit)) => format!(" {description} ({unit}).\n"),
        None => format!(" {field}\n"),
    }
}

/// The message name of the schema for an effector of `kind` with telemetry fields `fields`
/// (`sim_time` first): the kind in CamelCase, plus, for kinds whose fields vary between
/// instances, the variant: `HingedRodFlap`, `HingedRodLag`, `HingedRodFlapLag`;
/// `ModalAppendageFlap3Modes`, `ModalAppendageFlapLag5Modes`, …. Instances with the same
/// fields share the name (and so the schema); different fields give different names.
pub fn effector_message(kind: &str, fields: &[String]) -> String {
    let mut name: String = kind
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut c = w.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        })
        .collect();
    if !name.starts_with(|c: char| c.is_ascii_alphabetic()) {
        name.insert(0, 'E');
    }
    let has = |f: &str| fields.iter().any(|x| x == f);
    match kind {
        "hinged_rod" => {
            for (field, part) in [("flap", "Flap"), ("lag", "Lag")] {
                if has(field) {
                    name.push_str(part);
                }
            }
        }
        "modal_appendage" => {
            for (field, part) in [("flap_1", "Flap"), ("lag_1", "Lag")] {
                if has(field) {
                    name.push_str(part);
                }
            }
            let direction = if has("flap_1") { "flap" } else { "lag" };
            let modes = (1..)
                .take_while(|i| has(&format!("{direction}_{i}")))
                .count();
            name.push_str(&format!("{modes}Modes"));
        }
        _ => {}
    }
    name
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::telemetry::FIELDS;

    #[test]
    fn telemetry_table_follows_fields() {
        let names: Vec<&str> = TELEMETRY_FIELDS.iter().map(|(n, ..)| *n).collect();
        assert_eq!(names, FIELDS);
        for f in FIELDS {
            let (d, u) = field_unit(TELEMETRY, f).unwrap();
            assert!(!d.is_empty() && !u.is_empty(), "{f}");
        }
        assert_eq!(field_unit(TELEMETRY, "omega").map(|x| x.1), None);
    }

    #[test]
    fn orbit_table_follows_fields() {
        let names: Vec<&str> = ORBIT_FIELDS.iter().map(|(n, ..)| *n).collect();
        assert_eq!(names, crate::log::orbit::FIELDS);
        assert_eq!(field_unit(ORBIT, "altitude").unwrap().1, "km");
        assert_eq!(field_unit(ORBIT, "omega_x"), None);
    }

    #[test]
    fn modal_coordinates_are_parsed_strictly() {
        assert_eq!(field_unit("modal_appendage", "flap_3").unwrap().1, MODAL);
        assert_eq!(
            field_unit("modal_appendage", "lag_10_rate").unwrap().1,
            MODAL_RATE
        );
        for bad in [
            "flap_0",
            "flap_01",
            "flap_x",
            "twist_1",
            "flap",
            "flap_1_rate_rate",
        ] {
            assert!(field_unit("modal_appendage", bad).is_none(), "{bad}");
        }
        assert!(field_unit("hinged_rod", "flap_1").is_none());
        assert!(field_unit("rayleigh", "elastic_energy").is_none());
        assert!(field_unit("no_such_kind", "offset").is_none());
    }

    #[test]
    fn comments_carry_the_unit() {
        assert_eq!(
            field_comment(TELEMETRY, "omega_x"),
            " Body rate about body x (rad/s).\n"
        );
        assert_eq!(field_comment("hinged_rod", "tip_q"), " tip_q\n");
    }

    #[test]
    fn message_names_say_the_variant() {
        let f = |names: &[&str]| -> Vec<String> { names.iter().map(|s| s.to_string()).collect() };
        assert_eq!(
            effector_message("hinged_rod", &f(&["sim_time", "flap", "lag", "flap_rate"])),
            "HingedRodFlapLag"
        );
        assert_eq!(
            effector_message("hinged_rod", &f(&["sim_time", "lag", "lag_rate"])),
            "HingedRodLag"
        );
        assert_eq!(
            effector_message(
                "modal_appendage",
                &f(&["sim_time", "lag_1", "lag_2", "lag_1_rate"])
            ),
            "ModalAppendageLag2Modes"
        );
        assert_eq!(
            effector_message("spring_mass_damper", &f(&["sim_time", "offset"])),
            "SpringMassDamper"
        );
        assert_eq!(effector_message("9lives", &[]), "E9lives");
    }
}
