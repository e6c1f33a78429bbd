//! MCAP logs for Foxglove and Rerun (topics and conventions in `docs/logs.md`).
//!
//! Topics: `/tf` (`foxglove.FrameTransforms`, world → body), `/scene` (`foxglove.SceneUpdate`,
//! the body and arrows for ω and H, frame-locked to `body`), `/telemetry` (`polhode.Telemetry`)
//! and `/log` (`foxglove.Log`, events and the run's end). All protobuf, schemas embedded.
//! `/effectors/<name>` channels share one schema per effector kind and field set
//! (`polhode.effectors.HingedRodFlapLag`, [`units::effector_message`]); every field of the
//! polhode schemas carries its unit as its protobuf comment ([`units::field_unit`]).
//! A scenario with an orbit adds `/orbit` (`polhode.Orbit`: position, velocity, altitude and
//! the attitude relative to LVLH), the `lvlh`, `eci` and `ecef` frames in `/tf`, and the orbit
//! view ([`orbit_scene`]: `/earth`, `/orbit_scene`); a scenario without one writes none of it.
//! Log time = scenario epoch + sim time. The file is written under a temporary name in the
//! target directory and renamed when finished, so a final name never holds a half-written log.

pub mod charts;
pub mod live;
pub mod orbit;
pub mod orbit_scene;
mod outlets;
pub mod pacing;
pub mod samples;
pub mod telemetry;
pub mod units;

use crate::model::{Drawing, HubState, Observation, Spacecraft};
use crate::scenario::{Compression, Scenario, Shape, format_epoch, log_origin};
use crate::sim::{EventRecord, Outcome, Reference, Sink};
use foxglove::Encode;
use foxglove::Schema;
use foxglove::messages as fg;
use live::LiveServer;
use nalgebra::{UnitQuaternion, Vector3};
use outlets::Outlets;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Frame names used in `/tf` and `/scene`.
pub const WORLD_FRAME: &str = "world";
/// The body frame.
pub const BODY_FRAME: &str = "body";
/// The LVLH (orbit) frame, in `/tf` only for scenarios with an orbit.
pub const LVLH_FRAME: &str = "lvlh";

/// A file attached to an MCAP log.
#[derive(Debug, Clone)]
pub struct Attachment {
    /// File name shown by readers.
    pub name: String,
    /// Media type, e.g. `application/json`.
    pub media_type: String,
    /// Contents.
    pub data: Vec<u8>,
}

/// Writes one run (or several, under topic prefixes) to an MCAP file.
pub struct McapLogger<'a> {
    spacecraft: &'a Spacecraft,
    /// `/effectors/<name>` channel of each effector, in order.
    effector_channels: Vec<u16>,
    /// The file and the live view the messages go to.
    outlets: Outlets,
    /// The file's temporary name and its final one (none for a live view alone).
    file: Option<(TempFile, PathBuf)>,
    epoch_ns: u64,
    channels: Channels,
    sequence: u32,
    scene: SceneStyle,
    /// Name of the body frame (`body`, or `<prefix>/body` when runs share a file).
    body_frame: String,
    /// The scenario's orbit, if any: `/orbit` and the LVLH frame in `/tf`.
    orbit: Option<Arc<crate::orbit::Orbit>>,
    /// Name of the LVLH frame (`lvlh`, or `<prefix>/lvlh`).
    lvlh_frame: String,
    /// The orbit view (`eci` and `ecef` in `/tf`, `/earth`, `/orbit_scene`), with an orbit.
    orbit_scene: Option<orbit_scene::OrbitScene>,
    /// The polhode schemas and channels registered so far.
    registry: Registry,
    buf: Vec<u8>,
}

/// What [`register`] has added to a file, across the runs that share it.
#[derive(Default)]
struct Registry {
    /// Fields of each effector schema (by message name) already in the file.
    effector_schemas: BTreeMap<String, Vec<String>>,
    /// Bytes of the polhode schemas and of the channel topics and metadata (each is written
    /// twice: in the data section and in the summary).
    bytes: usize,
}

struct Channels {
    tf: u16,
    scene: u16,
    telemetry: u16,
    log: u16,
    /// `/orbit`, for a scenario with an orbit.
    orbit: Option<u16>,
    /// `/earth` and `/orbit_scene`, for a scenario with an orbit.
    earth: Option<u16>,
    orbit_scene: Option<u16>,
}

pub(crate) use crate::outputs::TempFile;

/// Static drawing parameters, fixed at the start of the run.
struct SceneStyle {
    shape: Shape,
    /// Arrow length for the initial |ω| and |H| (m).
    arrow_length: f64,
    omega_ref: f64,
    h_ref: f64,
    /// Smallest sim-time interval between `/scene` updates (s).
    interval: f64,
    /// Sim time of the last `/scene` update.
    last: Option<f64>,
}

impl SceneStyle {
    fn of(scenario: &Scenario, outcome_ref_omega: f64) -> Self {
        // |H| of the whole spacecraft (hub and effectors) at t = 0.
        let sc = &scenario.spacecraft;
        let y0 = sc.initial_state(&scenario.omega0, &scenario.attitude0);
        let h0 = sc.observe(0.0, &y0).h_norm;
        let size = match &scenario.shape {
            Shape::Box { size, .. } => size.max(),
            Shape::Cylinder { radius, length, .. } => length.max(2.0 * radius),
        };
        SceneStyle {
            shape: scenario.shape.clone(),
            arrow_length: 0.9 * size,
            omega_ref: outcome_ref_omega.max(f64::MIN_POSITIVE),
            h_ref: h0.max(f64::MIN_POSITIVE),
            interval: 1.0 / scenario.scene_rate,
            last: None,
        }
    }
}

/// The body frame's name for topics under `prefix`.
fn body_frame(prefix: &str) -> String {
    frame_name(prefix, BODY_FRAME)
}

/// The name of `frame` for topics under `prefix`: `frame`, or `<prefix>/<frame>`.
fn frame_name(prefix: &str, frame: &str) -> String {
    let p = prefix.trim_matches('/');
    if p.is_empty() {
        frame.to_string()
    } else {
        format!("{p}/{frame}")
    }
}

/// The orbit view of `scenario` under `prefix`, if it has an orbit.
fn orbit_view(scenario: &Scenario, prefix: &str) -> Option<orbit_scene::OrbitScene> {
    let orbit = scenario.orbit.clone()?;
    // `world` is shared by the runs of a file (only the body and LVLH frames take the prefix),
    // and so are the Earth's frames.
    let frames = orbit_scene::Frames {
        eci: orbit_scene::ECI_FRAME.into(),
        ecef: orbit_scene::ECEF_FRAME.into(),
        world: WORLD_FRAME.into(),
        body: body_frame(prefix),
        lvlh: frame_name(prefix, LVLH_FRAME),
    };
    let epoch = scenario.epoch_unix_ns;
    let earth_angle = Box::new(move |t| crate::orbit::earth_rotation_angle(epoch, t));
    Some(orbit_scene::OrbitScene::new(orbit, earth_angle, frames))
}

/// Adds the schemas and channels of one run under `prefix`.
fn register(
    writer: &mut Outlets,
    registry: &mut Registry,
    scenario: &Scenario,
    prefix: &str,
) -> io::Result<(Channels, Vec<u16>)> {
    let prefix = prefix.trim_end_matches('/');
    let tf = add::<fg::FrameTransforms>(writer, &format!("{prefix}/tf"))?;
    let scene = add::<fg::SceneUpdate>(writer, &format!("{prefix}/scene"))?;
    let schema = telemetry::schema_bytes();
    let telemetry = add_channel(
        writer,
        registry,
        Schema::new(telemetry::SCHEMA_NAME, "protobuf", schema),
        format!("{prefix}/telemetry"),
        BTreeMap::from([(
            "units".to_string(),
            telemetry::units_metadata(units::TELEMETRY, &telemetry::FIELDS),
        )]),
    )?;
    let log = add::<fg::Log>(writer, &format!("{prefix}/log"))?;
    let mut effector_channels = Vec::new();
    for e in scenario.spacecraft.effectors() {
        let mut names = vec!["sim_time".to_string()];
        names.extend(e.telemetry_names());
        let message = effector_schema_name(registry, e.kind(), &names);
        let schema = telemetry::schema_for("polhode.effectors", &message, e.kind(), &names);
        let name = format!("polhode.effectors.{message}");
        if !registry.effector_schemas.contains_key(&message) {
            registry.bytes += name.len() + schema.len();
            registry.effector_schemas.insert(message, names.clone());
        }
        // Identical schemas (same name and fields) are written once and shared.
        effector_channels.push(add_channel(
            writer,
            registry,
            Schema::new(name, "protobuf", schema),
            format!("{prefix}/effectors/{}", e.name()),
            BTreeMap::from([
                ("kind".to_string(), e.kind().to_string()),
                (
                    "units".to_string(),
                    telemetry::units_metadata(e.kind(), &names),
                ),
            ]),
        )?);
    }
    // Only for a scenario with an orbit: a scenario without one writes the same file as before.
    let (earth, orbit_scene) = match &scenario.orbit {
        Some(_) => (
            // Written once, at the first sample: kept for viewers that join a live run later.
            Some(add_latched::<fg::SceneUpdate>(
                writer,
                &format!("{prefix}/earth"),
                true,
            )?),
            Some(add::<fg::SceneUpdate>(
                writer,
                &format!("{prefix}/orbit_scene"),
            )?),
        ),
        None => (None, None),
    };
    let orbit = match &scenario.orbit {
        Some(_) => {
            let schema = orbit::schema_bytes();
            registry.bytes += orbit::SCHEMA_NAME.len() + schema.len();
            Some(add_channel(
                writer,
                registry,
                Schema::new(orbit::SCHEMA_NAME, "protobuf", schema),
                format!("{prefix}/orbit"),
                BTreeMap::from([(
                    "units".to_string(),
                    telemetry::units_metadata(units::ORBIT, &orbit::FIELDS),
                )]),
            )?)
        }
        None => None,
    };
    Ok((
        Channels {
            tf,
            scene,
            telemetry,
            log,
            orbit,
            earth,
            orbit_scene,
        },
        effector_channels,
    ))
}

/// Adds a protobuf channel, counting its topic and metadata in `registry`.
fn add_channel(
    writer: &mut Outlets,
    registry: &mut Registry,
    schema: Schema,
    topic: String,
    metadata: BTreeMap<String, String>,
) -> io::Result<u16> {
    registry.bytes += topic.len()
        + metadata
            .iter()
            .map(|(k, v)| k.len() + v.len())
            .sum::<usize>();
    writer.add_channel(&topic, &schema, "protobuf", &metadata, false)
}

/// The message name of the schema for an effector of `kind` with `fields`: that of
/// [`units::effector_message`], unless the file already has a schema of that name with other
/// fields (a kind whose variants the name does not tell apart); then the name followed by `_`
/// and a hash of the field names, so that a name never stands for two field sets.
fn effector_schema_name(registry: &Registry, kind: &str, fields: &[String]) -> String {
    let message = units::effector_message(kind, fields);
    match registry.effector_schemas.get(&message) {
        Some(known) if known.as_slice() != fields => {
            // FNV-1a over the names, each followed by a 0 byte.
            let mut h: u32 = 0x811c_9dc5;
            for b in fields.iter().flat_map(|f| f.bytes().chain([0])) {
                h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
            }
            format!("{message}_{h:08x}")
        }
        _ => message,
    }
}

fn io_err(e: mcap::McapError) -> io::Error {
    match e {
        // Keep the operating system's error (and its kind: disk full, file too large).
        mcap::McapError::Io(e) => with_hint(e),
        other => io::Error::other(other.to_string()),
    }
}

fn add<T: Encode>(w: &mut Outlets, topic: &str) -> io::Result<u16> {
    add_latched::<T>(w, topic, false)
}

/// Adds a channel of Foxglove messages `T`; `latched`: see [`Outlets::add_channel`].
fn add_latched<T: Encode>(w: &mut Outlets, topic: &str, latched: bool) -> io::Result<u16> {
    let schema = T::get_schema().ok_or_else(|| io::Error::other("message without schema"))?;
    w.add_channel(
        topic,
        &schema,
        &T::get_message_encoding(),
        &BTreeMap::new(),
        latched,
    )
}

impl<'a> McapLogger<'a> {
    /// Creates the temporary file next to `path` and writes the header, schemas and
    /// channels. Fails before any integration if the location is not writable.
    pub fn create(path: &Path, scenario: &'a Scenario, outcome_ref_omega: f64) -> io::Result<Self> {
        Self::create_prefixed(path, scenario, outcome_ref_omega, "")
    }

    /// A log of one run to the file `path` (if any) and to the live view `live` (if any):
    /// the same channels and messages in both. With neither, the messages go nowhere.
    pub fn create_with_live(
        path: Option<&Path>,
        live: Option<Arc<LiveServer>>,
        scenario: &'a Scenario,
        outcome_ref_omega: f64,
    ) -> io::Result<Self> {
        let (file, writer) = match path {
            Some(p) => {
                let (temp, writer) = Self::open_file(p, scenario)?;
                (Some((temp, p.to_path_buf())), Some(writer))
            }
            None => (None, None),
        };
        Self::with_outlets(
            Outlets::new(writer, live),
            file,
            scenario,
            outcome_ref_omega,
            "",
        )
    }

    /// As [`McapLogger::create`], with every topic under `prefix` (e.g. `/worst`) and the
    /// body frame named `<prefix>/body` without the leading slash, so several runs can share
    /// one file ([`McapLogger::continue_with`]).
    pub fn create_prefixed(
        path: &Path,
        scenario: &'a Scenario,
        outcome_ref_omega: f64,
        prefix: &str,
    ) -> io::Result<Self> {
        let (temp, writer) = Self::open_file(path, scenario)?;
        Self::with_outlets(
            Outlets::new(Some(writer), None),
            Some((temp, path.to_path_buf())),
            scenario,
            outcome_ref_omega,
            prefix,
        )
    }

    /// Creates the temporary file beside `path` and its MCAP writer (the header).
    fn open_file(path: &Path, scenario: &Scenario) -> io::Result<(TempFile, outlets::FileWriter)> {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if path.is_dir() {
            return Err(io::Error::other(format!(
                "{} is a directory; expected a file path ending in .mcap",
                path.display()
            )));
        }
        check_replaceable(path)?;
        std::fs::create_dir_all(&dir)?;
        let (temp, file) = TempFile::beside(path, "run.mcap")?;
        let options = mcap::WriteOptions::new()
            .compression(match scenario.compression {
                Compression::Lz4 => Some(mcap::Compression::Lz4),
                Compression::Zstd => Some(mcap::Compression::Zstd),
                Compression::None => None,
            })
            .compression_threads(0)
            .profile("")
            .library(format!("polhode {}", env!("CARGO_PKG_VERSION")));
        let writer = options
            .create(BufWriter::with_capacity(1 << 16, file))
            .map_err(io_err)?;
        Ok((temp, writer))
    }

    /// Registers the channels of one run under `prefix` in `outlets`.
    fn with_outlets(
        mut outlets: Outlets,
        file: Option<(TempFile, PathBuf)>,
        scenario: &'a Scenario,
        outcome_ref_omega: f64,
        prefix: &str,
    ) -> io::Result<Self> {
        let mut registry = Registry::default();
        let (channels, effector_channels) =
            register(&mut outlets, &mut registry, scenario, prefix)?;
        Ok(McapLogger {
            spacecraft: &scenario.spacecraft,
            effector_channels,
            outlets,
            file,
            epoch_ns: log_origin(scenario.epoch_unix_ns),
            channels,
            sequence: 0,
            scene: SceneStyle::of(scenario, outcome_ref_omega),
            body_frame: body_frame(prefix),
            orbit: scenario.orbit.clone(),
            lvlh_frame: frame_name(prefix, LVLH_FRAME),
            orbit_scene: orbit_view(scenario, prefix),
            registry,
            buf: Vec::with_capacity(1024),
        })
    }

    /// Registers the topics of another run (of `scenario`, under `prefix`) in the same file;
    /// its samples follow those already written.
    pub fn continue_with<'b>(
        self,
        scenario: &'b Scenario,
        outcome_ref_omega: f64,
        prefix: &str,
    ) -> io::Result<McapLogger<'b>> {
        let McapLogger {
            mut outlets,
            file,
            sequence,
            mut registry,
            buf,
            ..
        } = self;
        let (channels, effector_channels) =
            register(&mut outlets, &mut registry, scenario, prefix)?;
        Ok(McapLogger {
            spacecraft: &scenario.spacecraft,
            effector_channels,
            outlets,
            file,
            epoch_ns: log_origin(scenario.epoch_unix_ns),
            channels,
            sequence,
            scene: SceneStyle::of(scenario, outcome_ref_omega),
            body_frame: body_frame(prefix),
            orbit: scenario.orbit.clone(),
            lvlh_frame: frame_name(prefix, LVLH_FRAME),
            orbit_scene: orbit_view(scenario, prefix),
            registry,
            buf,
        })
    }

    /// Where the finished log will be (none for a live view alone).
    pub fn final_path(&self) -> Option<&Path> {
        self.file.as_ref().map(|(_, p)| p.as_path())
    }

    /// Log time (Unix ns) of sim time `t`, from the log origin (the epoch, or 1970-01-01 for
    /// an earlier epoch). Validation keeps origin + duration below 2^32 s,
    /// so this neither overflows nor saturates for `0 ≤ t ≤ duration`.
    fn log_time(&self, t: f64) -> u64 {
        self.epoch_ns
            .saturating_add((t.max(0.0) * 1e9).round() as u64)
    }

    fn timestamp(&self, t: f64) -> fg::Timestamp {
        let ns = self.log_time(t);
        fg::Timestamp::new((ns / 1_000_000_000) as u32, (ns % 1_000_000_000) as u32)
    }

    fn write_raw(&mut self, channel: u16, log_time: u64) -> io::Result<()> {
        self.sequence = self.sequence.wrapping_add(1);
        self.outlets
            .write(channel, self.sequence, log_time, &self.buf)
    }

    fn write<T: Encode>(&mut self, channel: u16, t: f64, msg: &T) -> io::Result<()> {
        self.buf.clear();
        msg.encode(&mut self.buf)
            .map_err(|e| io::Error::other(e.to_string()))?;
        self.write_raw(channel, self.log_time(t))
    }

    /// Writes a text line to `/log` at sim time `t`.
    pub fn log_text(&mut self, t: f64, level: fg::log::Level, text: &str) -> io::Result<()> {
        let msg = fg::Log {
            timestamp: Some(self.timestamp(t)),
            level: level as i32,
            message: text.to_string(),
            name: "polhode".into(),
            file: String::new(),
            line: 0,
        };
        self.write(self.channels.log, t, &msg)
    }

    /// Writes the run's end to `/log`, its metadata and the scenario attachment, finishes the
    /// file and renames it to its final name, which it returns. A log without a file (a live
    /// view alone) takes [`McapLogger::end_run`] instead.
    pub fn finish(
        mut self,
        scenario: &Scenario,
        method: &str,
        outcome: &Outcome,
    ) -> io::Result<PathBuf> {
        self.end_run(outcome)?;
        let t_end = outcome.final_observation.t;
        let mut meta = BTreeMap::new();
        meta.insert("version".into(), env!("CARGO_PKG_VERSION").into());
        meta.insert("scenario".into(), scenario.name.clone());
        if !scenario.path.as_os_str().is_empty() {
            meta.insert("scenario_file".into(), scenario.path.display().to_string());
        }
        meta.insert("integrator".into(), method.into());
        meta.insert("epoch".into(), format_epoch(scenario.epoch_unix_ns));
        if let Some(field) = &scenario.magnetic_field {
            meta.insert("magnetic_field".into(), field.clone());
        }
        if scenario.epoch_unix_ns < 0 {
            // MCAP log times are unsigned: an epoch before 1970 is stamped from 1970.
            meta.insert("log_time_origin".into(), format_epoch(self.epoch_ns as i64));
        }
        meta.insert(
            "quaternion_convention".into(),
            "Hamilton; body to world (v_world = q v_body q*); /tf stores x,y,z,w; \
             /telemetry stores q_w,q_x,q_y,q_z"
                .into(),
        );
        meta.insert("status".into(), outcome.status.label().into());
        meta.insert("partial".into(), outcome.status.is_partial().to_string());
        meta.insert("sim_time_end".into(), format!("{t_end}"));
        meta.insert("steps".into(), outcome.stats.steps.to_string());
        meta.insert(
            "rhs_evaluations".into(),
            outcome.stats.rhs_evaluations.to_string(),
        );
        // A scenario built in code ([`Scenario::from_simulation`]) has no text to attach.
        let attachments = if scenario.source.is_empty() {
            Vec::new()
        } else {
            vec![Attachment {
                name: "scenario.yaml".into(),
                media_type: "application/yaml".into(),
                data: scenario.source.as_bytes().to_vec(),
            }]
        };
        self.finish_with("polhode", meta, attachments)
    }

    /// Writes how the current run ended to its `/log` topic.
    pub fn end_run(&mut self, outcome: &Outcome) -> io::Result<()> {
        let t_end = outcome.final_observation.t;
        let level = match outcome.status {
            crate::sim::Status::Complete | crate::sim::Status::Stopped { .. } => {
                fg::log::Level::Info
            }
            _ => fg::log::Level::Warning,
        };
        let text = match &outcome.status {
            crate::sim::Status::Complete => {
                format!("run complete at t = {}", crate::timefmt::seconds(t_end))
            }
            crate::sim::Status::Stopped { condition } => {
                format!(
                    "run stopped at t = {}: {condition}",
                    crate::timefmt::seconds(t_end)
                )
            }
            crate::sim::Status::Interrupted => {
                format!(
                    "run interrupted at t = {}; this log is partial",
                    crate::timefmt::seconds(t_end)
                )
            }
            crate::sim::Status::Failed { diagnosis } => {
                format!("run failed; this log is partial: {diagnosis}")
            }
            crate::sim::Status::InvalidModel { diagnosis } => {
                format!(
                    "run stopped outside the model's validity; this log is partial: {diagnosis}"
                )
            }
        };
        self.log_text(t_end, level, &text)
    }

    /// Writes a metadata record `name` and `attachments` (stamped at the epoch), finishes the
    /// file and renames it to its final name.
    pub fn finish_with(
        mut self,
        name: &str,
        metadata: BTreeMap<String, String>,
        attachments: Vec<Attachment>,
    ) -> io::Result<PathBuf> {
        let epoch_ns = self.epoch_ns;
        let writer = self
            .outlets
            .file_mut()
            .ok_or_else(|| io::Error::other("this log has no file to finish"))?;
        writer
            .write_metadata(&mcap::records::Metadata {
                name: name.into(),
                metadata,
            })
            .map_err(io_err)?;
        for a in attachments {
            writer
                .attach(&mcap::Attachment {
                    log_time: epoch_ns,
                    create_time: epoch_ns,
                    name: a.name,
                    media_type: a.media_type,
                    data: Cow::Owned(a.data),
                })
                .map_err(io_err)?;
        }
        let McapLogger { outlets, file, .. } = self;
        let (Some(mut writer), Some((temp, final_path))) = (outlets.into_file(), file) else {
            return Err(io::Error::other("this log has no file to finish"));
        };
        writer.finish().map_err(io_err)?;
        let file = writer
            .into_inner()
            .into_inner()
            .map_err(|e| e.into_error())?;
        file.sync_all()?;
        // On any error above, dropping `temp` removes the unfinished file.
        temp.persist(&final_path)?;
        Ok(final_path)
    }

    /// Estimated size of the finished log (bytes, before chunk compression) for `scenario`
    /// run to its end: every message of the first sample encoded as the run will encode it,
    /// times the number of samples and scene updates, plus MCAP's per-message record and index
    /// (47 bytes) and the summary, schemas (polhode's own, with their field comments, counted
    /// as registered: each written twice) and attachments, with a 10 % margin. Compression
    /// only makes the file smaller.
    pub fn estimate_bytes(&mut self, scenario: &Scenario) -> f64 {
        const PER_MESSAGE: f64 = 47.0;
        let sc = self.spacecraft;
        // A generic state: protobuf leaves zero fields out, so the initial state (often an
        // identity attitude, rates about one axis) would encode shorter than later ones.
        let mut y0 = sc.initial_state(&scenario.omega0, &scenario.attitude0);
        let spin = scenario.omega0.norm().max(1e-3);
        for w in &mut y0[0..3] {
            *w += 0.01 * spin;
        }
        y0[3..7].copy_from_slice(&[0.5; 4]);
        let o = sc.observe(0.0, &y0);
        let inv = Reference::of(&o);
        let tf = self.body_transform(&o);
        let mut per_sample = self.encoded_len(&tf) + PER_MESSAGE;
        telemetry::encode_doubles(&telemetry::values(&o, &inv), &mut self.buf);
        per_sample += self.buf.len() as f64 + PER_MESSAGE;
        if let Some(orbit) = &self.orbit {
            // Every field is written (zeros too), so any instant encodes to the same length.
            telemetry::encode_doubles(
                &orbit::values(orbit, 0.0, &o.attitude, &o.omega),
                &mut self.buf,
            );
            per_sample += self.buf.len() as f64 + PER_MESSAGE;
        }
        let hub = HubState {
            t: 0.0,
            omega: o.omega,
            attitude: &y0[3..7],
        };
        for (k, e) in sc.effectors().iter().enumerate() {
            let mut values = vec![0.0];
            values.extend(e.telemetry(&hub, sc.effector_states(k, &y0)));
            telemetry::encode_doubles(&values, &mut self.buf);
            per_sample += self.buf.len() as f64 + PER_MESSAGE;
        }
        let scene = self.scene_update(&o, &y0);
        let per_scene = self.encoded_len(&scene) + PER_MESSAGE;
        // The orbit view: `/earth` once, `/orbit_scene` at its own rate (the `eci` and `ecef`
        // transforms are in `tf` above).
        let mut orbit_view = 0.0;
        if let Some(view) = self.orbit_scene.take() {
            let ts = self.timestamp(0.0);
            orbit_view = self.encoded_len(&view.earth(ts))
                + PER_MESSAGE
                + view.updates(scenario.duration, scenario.output_rate)
                    * (self.encoded_len(&view.update(0.0, ts)) + PER_MESSAGE);
            self.orbit_scene = Some(view);
        }
        let samples = (scenario.duration * scenario.output_rate).floor() + 2.0;
        let scenes =
            (scenario.duration * scenario.scene_rate.min(scenario.output_rate)).floor() + 2.0;
        let fixed =
            64.0 * 1024.0 + 2.0 * self.registry.bytes as f64 + 2.0 * scenario.source.len() as f64;
        // Scene updates grow as appendages deflect: uncompressed logs of the shipped scenarios
        // measured 0.76–1.05 times the raw figure (docs/reliability.md); 10 % covers that.
        1.1 * (samples * per_sample + scenes * per_scene + orbit_view) + fixed
    }

    /// The `/tf` message placing the body frame in `world` at the observation's attitude,
    /// followed, for a scenario with an orbit, by the LVLH frame in `world` (at the origin,
    /// like the body, rotated by `q_NO`), then `world` in `eci` (at r(t)) and `ecef` in `eci`
    /// (rotated by the Earth rotation angle).
    fn body_transform(&self, o: &Observation) -> fg::FrameTransforms {
        let transform = |child: &str, q: &UnitQuaternion<f64>| fg::FrameTransform {
            timestamp: Some(self.timestamp(o.t)),
            parent_frame_id: WORLD_FRAME.into(),
            child_frame_id: child.to_string(),
            translation: Some(fg::Vector3 {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            }),
            rotation: Some(fg::Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            }),
        };
        let mut transforms = vec![transform(&self.body_frame, &o.attitude)];
        if let Some(orbit) = &self.orbit {
            transforms.push(transform(&self.lvlh_frame, &orbit.lvlh(o.t).lvlh_to_eci()));
        }
        if let Some(view) = &self.orbit_scene {
            transforms.extend(view.transforms(o.t, self.timestamp(o.t)));
        }
        fg::FrameTransforms { transforms }
    }

    /// For a scenario with an orbit: `/earth` at the first sample, `/orbit_scene` when due.
    fn orbit_view(&mut self, t: f64) -> io::Result<()> {
        let (Some(earth), Some(channel)) = (self.channels.earth, self.channels.orbit_scene) else {
            return Ok(());
        };
        let Some(mut view) = self.orbit_scene.take() else {
            return Ok(());
        };
        let first = view.is_first();
        let due = view.due(t);
        let timestamp = self.timestamp(t);
        let result = (|| {
            if first {
                self.write(earth, t, &view.earth(timestamp))?;
            }
            if due {
                self.write(channel, t, &view.update(t, timestamp))?;
            }
            Ok(())
        })();
        self.orbit_scene = Some(view);
        result
    }

    fn encoded_len<T: Encode>(&mut self, msg: &T) -> f64 {
        self.buf.clear();
        // Encoding into a Vec cannot fail for want of space; a failure would show as 0.
        let _ = msg.encode(&mut self.buf);
        self.buf.len() as f64
    }

    /// Removes the temporary file (after an error that leaves nothing worth keeping).
    pub fn abandon(self) {
        drop(self);
    }

    fn scene_update(&self, o: &Observation, y: &[f64]) -> fg::SceneUpdate {
        let color = |r, g, b, a| Some(fg::Color { r, g, b, a });
        let quat = |q: &UnitQuaternion<f64>| {
            Some(fg::Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            })
        };
        let origin = Some(fg::Vector3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        });
        let arrow = |v: &Vector3<f64>, reference: f64, rgb: (f64, f64, f64)| {
            let n = v.norm();
            // √ scaling keeps a tenfold drop of |ω| (a flat spin) visible: 32 % of the length.
            let length = self.scene.arrow_length * (n / reference).sqrt().min(2.0);
            let orientation =
                UnitQuaternion::rotation_between(&Vector3::x(), v).unwrap_or_else(|| {
                    if v.x < 0.0 {
                        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
                    } else {
                        UnitQuaternion::identity()
                    }
                });
            let head = (0.2 * self.scene.arrow_length).min(0.5 * length);
            fg::ArrowPrimitive {
                pose: Some(fg::Pose {
                    position: origin,
                    orientation: quat(&orientation),
                }),
                shaft_length: (length - head).max(0.0),
                shaft_diameter: 0.03 * self.scene.arrow_length,
                head_length: head,
                head_diameter: 0.08 * self.scene.arrow_length,
                color: color(rgb.0, rgb.1, rgb.2, 1.0),
            }
        };
        let body_color = color(0.75, 0.75, 0.8, 0.85);
        let (cubes, cylinders) = match &self.scene.shape {
            Shape::Box { size, orientation } => (
                vec![fg::CubePrimitive {
                    pose: Some(fg::Pose {
                        position: origin,
                        orientation: quat(orientation),
                    }),
                    size: Some(fg::Vector3 {
                        x: size[0],
                        y: size[1],
                        z: size[2],
                    }),
                    color: body_color,
                }],
                vec![],
            ),
            Shape::Cylinder {
                radius,
                length,
                orientation,
            } => (
                vec![],
                vec![fg::CylinderPrimitive {
                    pose: Some(fg::Pose {
                        position: origin,
                        orientation: quat(orientation),
                    }),
                    size: Some(fg::Vector3 {
                        x: 2.0 * radius,
                        y: 2.0 * radius,
                        z: *length,
                    }),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color: body_color,
                }],
            ),
        };
        let point = |v: &Vector3<f64>| fg::Point3 {
            x: v[0],
            y: v[1],
            z: v[2],
        };
        let mut lines = Vec::new();
        let mut spheres = Vec::new();
        let mut cylinders = cylinders;
        let effector_color = color(0.85, 0.2, 0.25, 1.0);
        for (k, e) in self.spacecraft.effectors().iter().enumerate() {
            for d in e.drawings(self.spacecraft.effector_states(k, y)) {
                match d {
                    Drawing::Line { points, thickness } => lines.push(fg::LinePrimitive {
                        r#type: fg::line_primitive::Type::LineStrip as i32,
                        pose: Some(fg::Pose {
                            position: origin,
                            orientation: quat(&UnitQuaternion::identity()),
                        }),
                        thickness,
                        scale_invariant: false,
                        points: points.iter().map(point).collect(),
                        color: effector_color,
                        colors: vec![],
                        indices: vec![],
                    }),
                    Drawing::Sphere { center, diameter } => spheres.push(fg::SpherePrimitive {
                        pose: Some(fg::Pose {
                            position: Some(fg::Vector3 {
                                x: center[0],
                                y: center[1],
                                z: center[2],
                            }),
                            orientation: quat(&UnitQuaternion::identity()),
                        }),
                        size: Some(fg::Vector3 {
                            x: diameter,
                            y: diameter,
                            z: diameter,
                        }),
                        color: effector_color,
                    }),
                    Drawing::Disc {
                        center,
                        axis,
                        diameter,
                        thickness,
                    } => {
                        let orientation = UnitQuaternion::rotation_between(&Vector3::z(), &axis)
                            .unwrap_or_else(|| {
                                UnitQuaternion::from_axis_angle(
                                    &Vector3::x_axis(),
                                    std::f64::consts::PI,
                                )
                            });
                        cylinders.push(fg::CylinderPrimitive {
                            pose: Some(fg::Pose {
                                position: Some(fg::Vector3 {
                                    x: center[0],
                                    y: center[1],
                                    z: center[2],
                                }),
                                orientation: quat(&orientation),
                            }),
                            size: Some(fg::Vector3 {
                                x: diameter,
                                y: diameter,
                                z: thickness,
                            }),
                            bottom_scale: 1.0,
                            top_scale: 1.0,
                            color: effector_color,
                        })
                    }
                }
            }
        }
        fg::SceneUpdate {
            deletions: vec![],
            entities: vec![fg::SceneEntity {
                timestamp: Some(self.timestamp(o.t)),
                frame_id: self.body_frame.clone(),
                id: "spacecraft".into(),
                lifetime: None,
                frame_locked: true,
                metadata: vec![],
                arrows: vec![
                    arrow(&o.omega, self.scene.omega_ref, (0.95, 0.55, 0.1)),
                    arrow(&o.h_body, self.scene.h_ref, (0.2, 0.5, 1.0)),
                ],
                cubes,
                spheres,
                cylinders,
                lines,
                triangles: vec![],
                texts: vec![],
                models: vec![],
            }],
        }
    }
}

impl Sink for McapLogger<'_> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> io::Result<()> {
        let tf = self.body_transform(o);
        self.write(self.channels.tf, o.t, &tf)?;
        // Allow for rounding of the sample grid so that a 10 Hz scene is not skipped at 100 Hz.
        let due = self
            .scene
            .last
            .is_none_or(|last| o.t - last >= self.scene.interval * (1.0 - 1e-9));
        if due {
            let scene = self.scene_update(o, y);
            self.write(self.channels.scene, o.t, &scene)?;
            self.scene.last = Some(o.t);
        }
        self.orbit_view(o.t)?;
        let values = telemetry::values(o, inv);
        telemetry::encode_doubles(&values, &mut self.buf);
        self.write_raw(self.channels.telemetry, self.log_time(o.t))?;
        if let (Some(channel), Some(orbit)) = (self.channels.orbit, &self.orbit) {
            let values = orbit::values(orbit, o.t, &o.attitude, &o.omega);
            telemetry::encode_doubles(&values, &mut self.buf);
            self.write_raw(channel, self.log_time(o.t))?;
        }
        if !self.effector_channels.is_empty() {
            let hub = HubState {
                t: o.t,
                omega: o.omega,
                attitude: &y[3..7],
            };
            for k in 0..self.effector_channels.len() {
                let e = &self.spacecraft.effectors()[k];
                let mut values = vec![o.t];
                values.extend(e.telemetry(&hub, self.spacecraft.effector_states(k, y)));
                telemetry::encode_doubles(&values, &mut self.buf);
                self.write_raw(self.effector_channels[k], self.log_time(o.t))?;
            }
        }
        Ok(())
    }

    fn event(&mut self, e: &EventRecord, o: &Observation) -> io::Result<()> {
        // Logged when known: with `for:`, at the end of the interval that held.
        let text = format!(
            "event at t = {}: {} (nutation {:.4}° at t = {})",
            crate::timefmt::seconds(e.t),
            e.condition,
            o.nutation_angle.to_degrees(),
            crate::timefmt::seconds(o.t)
        );
        self.log_text(e.confirmed, fg::log::Level::Info, &text)
    }

    fn warning(&mut self, w: &crate::sim::Warning) -> io::Result<()> {
        self.log_text(
            w.t,
            fg::log::Level::Warning,
            &format!("warning: {}", w.message),
        )
    }
}

pub use crate::outputs::{check_replaceable, write_atomically};

/// Adds what to do to an out-of-space error (disk full, quota, file-size limit), keeping its
/// kind.
pub fn with_hint(e: io::Error) -> io::Error {
    use io::ErrorKind::{FileTooLarge, QuotaExceeded, StorageFull};
    if matches!(e.kind(), StorageFull | FileTooLarge | QuotaExceeded) {
        io::Error::new(
            e.kind(),
            format!(
                "{e}: out of space (disk full, quota or file-size limit); free space, or lower the output rate"
            ),
        )
    } else {
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Overrides;
    use prost::Message as _;
    use prost_types::FileDescriptorSet;
    use std::sync::atomic::AtomicBool;

    fn root() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("polhode-log-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Runs `scenario` (YAML text) for `duration` s into `out`; returns the log's bytes and
    /// the size estimated before the run.
    fn run(
        text: &str,
        duration: f64,
        compression: Option<Compression>,
        out: &Path,
    ) -> (Vec<u8>, f64) {
        let overrides = Overrides {
            duration: Some(duration),
            mcap: Some(out.to_path_buf()),
            ..Default::default()
        };
        let mut s = crate::scenario::parse(Path::new("test.yaml"), text.to_string(), &overrides)
            .unwrap_or_else(|e| panic!("{e}"));
        if let Some(c) = compression {
            s.compression = c;
        }
        let mut logger = McapLogger::create(out, &s, s.omega0.norm()).unwrap();
        let estimate = logger.estimate_bytes(&s);
        let stop = AtomicBool::new(false);
        let ctl = crate::sim::Control {
            interrupt: &stop,
            progress: None,
        };
        let outcome = crate::sim::run(&s, &mut logger, ctl).unwrap();
        logger.finish(&s, "test", &outcome).unwrap();
        (std::fs::read(out).unwrap(), estimate)
    }

    fn summary(bytes: &[u8]) -> mcap::Summary {
        mcap::Summary::read(bytes).unwrap().expect("a summary")
    }

    /// The unit at the end of a field comment: ` <description> (<unit>).`
    fn unit_of(comment: &str) -> Option<&str> {
        let c = comment.trim_end().strip_suffix(").")?;
        let open = c.rfind('(')?;
        let unit = &c[open + 1..];
        (open > 0 && !unit.trim().is_empty() && !unit.contains(')')).then_some(unit)
    }

    /// Every field of every polhode schema in the log has a comment ending in a unit, the
    /// same unit as the channel's `units` metadata. Returns the number of fields checked.
    fn check_units(bytes: &[u8], what: &str) -> usize {
        let summary = summary(bytes);
        let mut checked = 0;
        for ch in summary.channels.values() {
            let schema = ch.schema.as_ref().unwrap();
            if !schema.name.starts_with("polhode.") {
                continue;
            }
            let set = FileDescriptorSet::decode(&*schema.data).unwrap();
            assert_eq!(set.file.len(), 1, "{what} {}", ch.topic);
            let file = &set.file[0];
            let msg = &file.message_type[0];
            assert_eq!(
                format!("{}.{}", file.package(), msg.name()),
                schema.name,
                "{what}"
            );
            let locations = &file.source_code_info.as_ref().unwrap().location;
            let units: serde_json::Value =
                serde_json::from_str(ch.metadata.get("units").expect("units metadata")).unwrap();
            assert_eq!(units.as_object().unwrap().len(), msg.field.len());
            for (i, f) in msg.field.iter().enumerate() {
                let loc = locations
                    .iter()
                    .find(|l| l.path == [4, 0, 2, i as i32])
                    .unwrap_or_else(|| panic!("{what} {}: no comment on {}", ch.topic, f.name()));
                let comment = loc.leading_comments();
                let unit = unit_of(comment).unwrap_or_else(|| {
                    panic!(
                        "{what} {} ({}): field {} has no unit in its comment {comment:?}",
                        ch.topic,
                        schema.name,
                        f.name()
                    )
                });
                assert_eq!(units[f.name()], unit, "{what} {} {}", ch.topic, f.name());
                checked += 1;
            }
        }
        checked
    }

    fn shipped(name: &str) -> String {
        std::fs::read_to_string(root().join("scenarios").join(name)).unwrap()
    }

    #[test]
    fn every_field_of_every_shipped_scenario_has_a_unit() {
        let dir = scratch("units");
        let mut names: Vec<String> = std::fs::read_dir(root().join("scenarios"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".yaml"))
            .collect();
        names.sort();
        for must in [
            "explorer1-pydy.yaml",
            "explorer1-pydy-modal.yaml",
            "nutation-damper.yaml",
            "wheel-damper.yaml",
            "flexible-boom.yaml",
            "spin-up.yaml",
            "tennis-racket.yaml",
        ] {
            assert!(names.iter().any(|n| n == must), "{must} is not shipped");
        }
        for name in &names {
            let (bytes, _) = run(&shipped(name), 0.05, None, &dir.join("u.mcap"));
            // /telemetry, then each effector's fields.
            assert!(
                check_units(&bytes, name) >= telemetry::FIELDS.len(),
                "{name}"
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn four_rods_share_one_schema() {
        let dir = scratch("rods");
        let (bytes, _) = run(
            &shipped("explorer1-pydy.yaml"),
            0.05,
            None,
            &dir.join("r.mcap"),
        );
        let summary = summary(&bytes);
        // /tf, /scene, /telemetry, /log and /effectors/antenna_1 … _4, as before.
        assert_eq!(summary.channels.len(), 8);
        let rods: Vec<_> = summary
            .channels
            .values()
            .filter(|c| c.topic.starts_with("/effectors/"))
            .collect();
        assert_eq!(rods.len(), 4);
        let effector_schemas: Vec<_> = summary
            .schemas
            .values()
            .filter(|s| s.name.starts_with("polhode.effectors."))
            .collect();
        assert_eq!(effector_schemas.len(), 1, "{effector_schemas:?}");
        assert_eq!(
            effector_schemas[0].name,
            "polhode.effectors.HingedRodFlapLag"
        );
        for c in &rods {
            assert_eq!(
                c.schema.as_ref().unwrap().id,
                effector_schemas[0].id,
                "{}",
                c.topic
            );
        }
        // Schema records in the file: one each for the 4 hub topics' and the rods' schema.
        let stats = summary.stats.as_ref().unwrap();
        assert_eq!((stats.schema_count, stats.channel_count), (5, 8));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Instances of one kind with different fields get different schemas, named by variant.
    #[test]
    fn each_field_set_has_its_own_schema() {
        let rod = |name: &str, freedom: &str, hinge: &str, direction: &str| {
            format!(
                "  - hinged_rod: {{name: {name}, mass: 0.1, length: 0.5, hinge: {hinge}, \
                 direction: {direction}, axis: [0, 0, 1], freedom: {freedom}, stiffness: 1.0, \
                 damping: 0.1, copies: {{count: 2, about: [0, 0, 1]}}}}\n"
            )
        };
        let beam = |name: &str, modes: u32, bending: &str, z: f64| {
            format!(
                "  - modal_appendage: {{name: {name}, length: 2.0, bending_stiffness: 40.0, \
                 mass_per_length: 0.4, tip_mass: 0.1, attachment: [0, 0, {z}], \
                 direction: [0, 0, {z}], flap_direction: [1, 0, 0], modes: {modes}, \
                 bending: {bending}}}\n"
            )
        };
        let mut text = String::from(
            "name: variants\nbody:\n  mass: 100.0\n  principal: [10.0, 12.0, 15.0]\n  \
             spin_axis: [0, 0, 1]\n  shape: {box: {size: [2.0, 2.0, 2.0]}}\neffectors:\n",
        );
        text += &rod("a", "flap", "[0, 0.5, 0]", "[0, 1, 0]");
        text += &rod("b", "lag", "[0.5, 0, 0.2]", "[1, 0, 0]");
        text += &rod("c", "flap_lag", "[0.5, 0.5, -0.2]", "[0.6, 0.8, 0]");
        text += &beam("m3", 3, "both", 1.0);
        text += &beam("m5", 5, "flap", -1.0);
        text += "  - spring_mass_damper: {name: d, mass: 1.0, position: [0.5, 0, 0], \
                 direction: [0, 0, 1], stiffness: 1.0, damping: 0.5}\n\
                 \x20 - wheel_damper: {name: w, inertia: 0.5, axis: [0, 0, 1], damping: 1.0, \
                 position: [0, 0, 0.5]}\n\
                 \x20 - rayleigh: {name: r, gamma_diagonal: [0.01, 0.01, 0.01]}\n\
                 initial: {omega: [0.01, 0.0, 0.5]}\nduration: 1.0\n";
        let dir = scratch("variants");
        let (bytes, estimate) = run(&text, 0.05, Some(Compression::None), &dir.join("v.mcap"));
        check_units(&bytes, "variants");
        let summary = summary(&bytes);
        let mut by_schema: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for c in summary.channels.values() {
            if let Some(e) = c.topic.strip_prefix("/effectors/") {
                by_schema
                    .entry(c.schema.as_ref().unwrap().name.clone())
                    .or_default()
                    .push(e.to_string());
            }
        }
        for v in by_schema.values_mut() {
            v.sort();
        }
        let expect: BTreeMap<String, Vec<String>> = [
            ("HingedRodFlap", vec!["a_1", "a_2"]),
            ("HingedRodLag", vec!["b_1", "b_2"]),
            ("HingedRodFlapLag", vec!["c_1", "c_2"]),
            ("ModalAppendageFlapLag3Modes", vec!["m3"]),
            ("ModalAppendageFlap5Modes", vec!["m5"]),
            ("SpringMassDamper", vec!["d"]),
            ("WheelDamper", vec!["w"]),
            ("Rayleigh", vec!["r"]),
        ]
        .into_iter()
        .map(|(k, v)| {
            (
                format!("polhode.effectors.{k}"),
                v.into_iter().map(String::from).collect(),
            )
        })
        .collect();
        assert_eq!(by_schema, expect);
        assert_eq!(summary.schemas.len(), 4 + expect.len());
        // A short run is all schemas and channels: the estimate must still cover them.
        assert!(
            bytes.len() as f64 <= estimate,
            "{} bytes, estimated {estimate}",
            bytes.len()
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The log-size estimate against an uncompressed log of a run with effectors.
    #[test]
    fn estimate_covers_the_log() {
        let dir = scratch("estimate");
        let (bytes, estimate) = run(
            &shipped("explorer1-pydy.yaml"),
            5.0,
            Some(Compression::None),
            &dir.join("e.mcap"),
        );
        let ratio = bytes.len() as f64 / estimate;
        assert!((0.6..=1.0).contains(&ratio), "actual / estimate = {ratio}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The estimate counts `/orbit` and the `lvlh` transform for a scenario with an orbit.
    #[test]
    fn estimate_covers_a_log_with_an_orbit() {
        let dir = scratch("estimate-orbit");
        let (bytes, estimate) = run(
            &shipped("gravity-gradient-smallsat.yaml"),
            2000.0,
            Some(Compression::None),
            &dir.join("o.mcap"),
        );
        let ratio = bytes.len() as f64 / estimate;
        assert!((0.6..=1.0).contains(&ratio), "actual / estimate = {ratio}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A name shared by two field sets (a kind whose variants the name does not tell apart)
    /// gets a hash suffix for the second.
    #[test]
    fn a_schema_name_never_stands_for_two_field_sets() {
        let mut registry = Registry::default();
        let a: Vec<String> = ["sim_time", "x"].map(String::from).to_vec();
        let b: Vec<String> = ["sim_time", "y"].map(String::from).to_vec();
        assert_eq!(effector_schema_name(&registry, "new_kind", &a), "NewKind");
        registry
            .effector_schemas
            .insert("NewKind".into(), a.clone());
        assert_eq!(effector_schema_name(&registry, "new_kind", &a), "NewKind");
        let other = effector_schema_name(&registry, "new_kind", &b);
        assert!(
            other.starts_with("NewKind_") && other.len() == 16,
            "{other}"
        );
    }
}
