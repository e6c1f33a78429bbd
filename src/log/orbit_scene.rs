//! The orbit view of a scenario with an orbit (docs/logs.md, "The orbit view"): the Earth to
//! scale, the orbit path, and the spacecraft marked at orbit scale.
//!
//! Frames (in `/tf`, lengths in metres like every other frame): `eci`, the Earth-centred
//! inertial frame (the root); `world` (the existing body-centred frame, ECI axes) placed in
//! `eci` at the orbital position r(t) with no rotation; `ecef`, the Earth-fixed frame,
//! rotated about z by the Earth rotation angle θ(t) (IAU 2000;
//! [`crate::orbit::earth_rotation_angle`] at the scenario epoch).
//!
//! Topics (both `foxglove.SceneUpdate`):
//! - `/earth`, one message at t = 0: entity `earth` in `ecef`, frame-locked, so it turns with
//!   the Earth: a sphere of the equatorial radius, the equator, the parallels at ±30° and ±60°,
//!   the meridians every 30° and the prime meridian highlighted. One message is enough: a
//!   viewer seeking to any time takes the last message of each topic before it.
//! - `/orbit_scene`, every period / [`UPDATES_PER_PERIOD`] of sim time: entity `orbit_path`
//!   (one Keplerian period of the propagated orbit from the current time, in `eci`),
//!   `spacecraft_marker` (a sphere at the origin of `world`, i.e. at r(t)), `body_axes`
//!   (arrows along the body axes, in `body`) and `lvlh_axes` (lines along o1, o2, o3, in
//!   `lvlh`). The marker and the axes are frame-locked, so they follow `/tf` at every sample;
//!   their sizes are fractions of the semi-major axis, not the body's (which is metres across).

use crate::orbit::Orbit;
use foxglove::messages as fg;
use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::PI;
use std::sync::Arc;

/// The Earth-centred inertial frame.
pub const ECI_FRAME: &str = "eci";
/// The Earth-fixed frame.
pub const ECEF_FRAME: &str = "ecef";
/// `/orbit_scene` updates per Keplerian period (every 30° of mean anomaly).
pub const UPDATES_PER_PERIOD: f64 = 12.0;
/// Segments of the orbit path over one period.
pub const PATH_SEGMENTS: usize = 180;
/// Graticule step along each circle (deg).
const GRATICULE_STEP_DEG: usize = 5;
/// Radius of the graticule's vertices over the Earth's (so the chords stay above the sphere:
/// a 5° chord dips by 1 − cos 2.5° = 0.095 %).
const GRATICULE_LIFT: f64 = 1.004;
/// Marker diameter, axis lengths and arrow shaft diameter, as fractions of the semi-major axis.
const MARKER_DIAMETER: f64 = 0.06;
const AXIS_LENGTH: f64 = 0.2;
const SHAFT_DIAMETER: f64 = 0.008;

/// The Earth rotation angle θ (rad) as a function of sim time (s): for a scenario,
/// [`crate::orbit::earth_rotation_angle`] at its epoch.
pub type EarthAngle = Box<dyn Fn(f64) -> f64 + Send + Sync>;

/// Names of the frames the orbit view uses, under a topic prefix.
#[derive(Debug, Clone)]
pub struct Frames {
    /// `eci`.
    pub eci: String,
    /// `ecef`.
    pub ecef: String,
    /// `world` (the body-centred frame).
    pub world: String,
    /// `body`.
    pub body: String,
    /// `lvlh`.
    pub lvlh: String,
}

/// What the orbit view needs during a run.
pub struct OrbitScene {
    orbit: Arc<Orbit>,
    /// The Earth rotation angle θ (rad) at sim time t (s).
    earth_angle: EarthAngle,
    frames: Frames,
    /// Sim-time interval between `/orbit_scene` updates (s).
    interval: f64,
    /// Sim time of the last `/orbit_scene` update.
    last: Option<f64>,
}

fn point(v: &Vector3<f64>) -> fg::Point3 {
    fg::Point3 {
        x: v[0],
        y: v[1],
        z: v[2],
    }
}

fn colour(r: f64, g: f64, b: f64, a: f64) -> Option<fg::Color> {
    Some(fg::Color { r, g, b, a })
}

fn quat(q: &UnitQuaternion<f64>) -> Option<fg::Quaternion> {
    Some(fg::Quaternion {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    })
}

fn pose(position: Vector3<f64>, q: &UnitQuaternion<f64>) -> Option<fg::Pose> {
    Some(fg::Pose {
        position: Some(fg::Vector3 {
            x: position[0],
            y: position[1],
            z: position[2],
        }),
        orientation: quat(q),
    })
}

/// A scale-invariant line strip (thickness in pixels).
fn strip(points: Vec<fg::Point3>, pixels: f64, c: Option<fg::Color>) -> fg::LinePrimitive {
    fg::LinePrimitive {
        r#type: fg::line_primitive::Type::LineStrip as i32,
        pose: pose(Vector3::zeros(), &UnitQuaternion::identity()),
        thickness: pixels,
        scale_invariant: true,
        points,
        color: c,
        colors: vec![],
        indices: vec![],
    }
}

fn entity(id: &str, frame: &str, timestamp: fg::Timestamp) -> fg::SceneEntity {
    fg::SceneEntity {
        timestamp: Some(timestamp),
        frame_id: frame.to_string(),
        id: id.into(),
        lifetime: None,
        frame_locked: true,
        metadata: vec![],
        arrows: vec![],
        cubes: vec![],
        spheres: vec![],
        cylinders: vec![],
        lines: vec![],
        triangles: vec![],
        texts: vec![],
        models: vec![],
    }
}

/// The point of a sphere of radius `r` at geocentric latitude `lat` and longitude `lon` (rad).
fn on_sphere(r: f64, lat: f64, lon: f64) -> fg::Point3 {
    let (sl, cl) = lat.sin_cos();
    let (so, co) = lon.sin_cos();
    point(&Vector3::new(r * cl * co, r * cl * so, r * sl))
}

impl OrbitScene {
    /// The orbit view of `orbit`, with the Earth rotation angle and the frame names.
    pub fn new(orbit: Arc<Orbit>, earth_angle: EarthAngle, frames: Frames) -> OrbitScene {
        let interval = orbit.period() / UPDATES_PER_PERIOD;
        OrbitScene {
            orbit,
            earth_angle,
            frames,
            interval,
            last: None,
        }
    }

    /// The transforms `eci → world` (translation r(t) in m, no rotation) and `eci → ecef`
    /// (rotation R3 by +θ about z: it maps Earth-fixed components to ECI components).
    pub fn transforms(&self, t: f64, timestamp: fg::Timestamp) -> [fg::FrameTransform; 2] {
        let (r, _) = self.orbit.state(t);
        let theta = (self.earth_angle)(t);
        let transform =
            |child: &str, translation: Vector3<f64>, q: UnitQuaternion<f64>| fg::FrameTransform {
                timestamp: Some(timestamp),
                parent_frame_id: self.frames.eci.clone(),
                child_frame_id: child.to_string(),
                translation: Some(fg::Vector3 {
                    x: translation[0],
                    y: translation[1],
                    z: translation[2],
                }),
                rotation: quat(&q),
            };
        [
            transform(&self.frames.world, r, UnitQuaternion::identity()),
            transform(
                &self.frames.ecef,
                Vector3::zeros(),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), theta),
            ),
        ]
    }

    /// Whether nothing has been written yet (the `/earth` message is due).
    pub fn is_first(&self) -> bool {
        self.last.is_none()
    }

    /// Whether `/orbit_scene` is due at sim time `t` (the first sample, then every interval,
    /// allowing for the rounding of the sample grid); marks it written if so.
    pub fn due(&mut self, t: f64) -> bool {
        let due = self
            .last
            .is_none_or(|last| t - last >= self.interval * (1.0 - 1e-9));
        if due {
            self.last = Some(t);
        }
        due
    }

    /// The `/earth` message: the Earth in `ecef`, frame-locked.
    pub fn earth(&self, timestamp: fg::Timestamp) -> fg::SceneUpdate {
        let radius = self.orbit.body().radius;
        let lifted = GRATICULE_LIFT * radius;
        let step = (GRATICULE_STEP_DEG as f64).to_radians();
        let grid = colour(0.62, 0.76, 0.95, 0.8);
        let mut e = entity("earth", &self.frames.ecef, timestamp);
        e.spheres.push(fg::SpherePrimitive {
            pose: pose(Vector3::zeros(), &UnitQuaternion::identity()),
            size: Some(fg::Vector3 {
                x: 2.0 * radius,
                y: 2.0 * radius,
                z: 2.0 * radius,
            }),
            color: colour(0.12, 0.3, 0.62, 1.0),
        });
        // Parallels (the equator thicker), closed circles.
        let around = 360 / GRATICULE_STEP_DEG;
        for lat_deg in [-60.0_f64, -30.0, 0.0, 30.0, 60.0] {
            let points = (0..=around)
                .map(|k| on_sphere(lifted, lat_deg.to_radians(), k as f64 * step))
                .collect();
            let pixels = if lat_deg == 0.0 { 2.0 } else { 1.0 };
            e.lines.push(strip(points, pixels, grid));
        }
        // Meridians, pole to pole; the prime meridian (longitude 0) highlighted.
        let half = 180 / GRATICULE_STEP_DEG;
        for k_lon in 0..12 {
            let lon = (30.0 * k_lon as f64).to_radians();
            let points = (0..=half)
                .map(|k| on_sphere(lifted, -PI / 2.0 + k as f64 * step, lon))
                .collect();
            e.lines.push(if k_lon == 0 {
                strip(points, 3.0, colour(1.0, 0.78, 0.2, 1.0))
            } else {
                strip(points, 1.0, grid)
            });
        }
        fg::SceneUpdate {
            deletions: vec![],
            entities: vec![e],
        }
    }

    /// The points of the orbit path at sim time `t`: r(t + k T / N), k = 0 … N, with T the
    /// Keplerian period and N = [`PATH_SEGMENTS`] (m, ECI).
    pub fn path(&self, t: f64) -> Vec<Vector3<f64>> {
        let period = self.orbit.period();
        (0..=PATH_SEGMENTS)
            .map(|k| {
                self.orbit
                    .state(t + period * k as f64 / PATH_SEGMENTS as f64)
                    .0
            })
            .collect()
    }

    /// The `/orbit_scene` message at sim time `t`.
    pub fn update(&self, t: f64, timestamp: fg::Timestamp) -> fg::SceneUpdate {
        let a = self.orbit.elements().semi_major_axis;
        let mut path = entity("orbit_path", &self.frames.eci, timestamp);
        // The path is drawn where it was computed, not moved with later transforms.
        path.frame_locked = false;
        path.lines.push(strip(
            self.path(t).iter().map(point).collect(),
            2.0,
            colour(0.3, 0.95, 0.95, 1.0),
        ));
        let mut marker = entity("spacecraft_marker", &self.frames.world, timestamp);
        let d = MARKER_DIAMETER * a;
        marker.spheres.push(fg::SpherePrimitive {
            pose: pose(Vector3::zeros(), &UnitQuaternion::identity()),
            size: Some(fg::Vector3 { x: d, y: d, z: d }),
            color: colour(1.0, 0.3, 0.85, 1.0),
        });
        let length = AXIS_LENGTH * a;
        let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
        let rgb = [(0.95, 0.25, 0.25), (0.3, 0.85, 0.35), (0.3, 0.55, 1.0)];
        let mut body = entity("body_axes", &self.frames.body, timestamp);
        for (axis, (r, g, b)) in axes.iter().zip(rgb) {
            let q = UnitQuaternion::rotation_between(&Vector3::x(), axis)
                .unwrap_or_else(UnitQuaternion::identity);
            let head = 0.25 * length;
            body.arrows.push(fg::ArrowPrimitive {
                pose: pose(Vector3::zeros(), &q),
                shaft_length: length - head,
                shaft_diameter: SHAFT_DIAMETER * a,
                head_length: head,
                head_diameter: 2.5 * SHAFT_DIAMETER * a,
                color: colour(r, g, b, 1.0),
            });
        }
        let mut lvlh = entity("lvlh_axes", &self.frames.lvlh, timestamp);
        for (axis, (r, g, b)) in axes.iter().zip(rgb) {
            // Lighter than the body's axes: o1 along track, o2 negative orbit normal, o3 nadir.
            let tip = axis * (1.3 * length);
            lvlh.lines.push(strip(
                vec![point(&Vector3::zeros()), point(&tip)],
                1.5,
                colour(0.5 + 0.5 * r, 0.5 + 0.5 * g, 0.5 + 0.5 * b, 0.9),
            ));
        }
        fg::SceneUpdate {
            deletions: vec![],
            entities: vec![path, marker, body, lvlh],
        }
    }

    /// The number of `/orbit_scene` updates over a run of `duration` s (at most one per
    /// sample at `output_rate` Hz), for the log-size estimate.
    pub fn updates(&self, duration: f64, output_rate: f64) -> f64 {
        (duration * (1.0 / self.interval).min(output_rate)).floor() + 2.0
    }
}
