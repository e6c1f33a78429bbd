//! Fuzz target `writers`: what polhode writes, fed with arbitrary values.
//!
//! One input is one of:
//! - `Mcap`: one to three runs logged into one file by `log::McapLogger` (`create_prefixed`,
//!   then `continue_with`, as a campaign's `campaign.mcap`), each a small valid scenario
//!   (built from a template with an arbitrary effector name, compression, epoch and scene
//!   rate) fed arbitrary samples (observations and state vectors of arbitrary doubles: NaN,
//!   ±inf, subnormals, huge), events and log lines with arbitrary strings, then finished
//!   (`finish` or `finish_with` with arbitrary metadata and attachments), abandoned, or
//!   finished onto a final name that was made unusable meanwhile. A finished file is read
//!   back with the `mcap` crate: every message (MessageStream), the summary's counts, the
//!   metadata and attachments, `/telemetry` payloads bit for bit, and every
//!   `/effectors/*` payload against the field count of its own embedded schema.
//! - `Table`: arbitrary column names and rows through `montecarlo::table::to_csv`,
//!   `from_csv` (round trip) and `to_parquet` (read back with the `parquet` crate).
//! - `CsvText`: arbitrary text through `table::from_csv` (what `merge` reads).
//! - `Outputs`: arbitrary rows of a small campaign through `montecarlo::output::write_outputs`
//!   (CSV, Parquet, summary statistics as JSON and text, charts, the worst / median / best
//!   runs' MCAP, the manifest), whole or as a shard, optionally with one output name taken
//!   by a directory; the files are read back and checked against each other.
//! - `Atomic`: `log::write_atomically` with arbitrary bytes, onto a free name or a directory.
//! - `Stats`: the public summary statistics `percentile` and `wilson95`.
//! - `Chart`: `plot::Chart::to_svg` (the campaign charts' writer) with arbitrary series,
//!   ranges, scales and reference lines; the SVG must parse (usvg).
//!
//! Properties: no panic; a writer returns Ok with a valid file, or a clean Err that leaves
//! nothing under the final name and no temporary file behind.
//!
//! The summary module (`column_stats`, `event_stats`, `rank`, `failures`, `fmt`,
//! `stats_table`) is private (`mod summary` in src/montecarlo/mod.rs); it is reached here
//! through `write_outputs`, its public caller.

#![no_main]

use arbitrary::Arbitrary;
use foxglove::messages::log::Level;
use libfuzzer_sys::fuzz_target;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use polhode::integrate::Stats;
use polhode::log::{Attachment, McapLogger, telemetry, write_atomically};
use polhode::model::Observation;
use polhode::montecarlo::output::{Manifest, write_outputs};
use polhode::montecarlo::{
    MAX_RUNS, Prepared, Row, RunStatus, percentile, sha256_hex, table, wilson95,
};
use polhode::scenario::{self, Overrides, Scenario};
use polhode::sim::{self, Control, EventRecord, NullSink, Outcome, Reference, Sink, Status};
use prost::Message as _;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::AtomicBool;

/// Bounds that keep one input fast (the input size bounds them too).
const MAX_RUNS_PER_FILE: usize = 3;
const MAX_ITEMS: usize = 128;
const MAX_COLUMNS: usize = 24;
const MAX_ROWS: usize = 64;

// ---------------------------------------------------------------------------------------
// Scratch space

/// A directory of this process: `$POLHODE_FUZZ_TMP` (set by scripts/fuzz.sh), else
/// `/dev/shm` (no disk writes, fsync is free), else the system temporary directory.
fn scratch_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = std::env::var_os("POLHODE_FUZZ_TMP")
            .map(PathBuf::from)
            .unwrap_or_else(|| {
                let shm = PathBuf::from("/dev/shm");
                if shm.is_dir() {
                    shm
                } else {
                    std::env::temp_dir()
                }
            });
        let dir = base.join(format!("polhode-fuzz-writers-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("cannot create the fuzzer's scratch directory");
        dir
    })
}

/// An empty directory for one input.
fn fresh_dir() -> PathBuf {
    let dir = scratch_dir().join("case");
    if dir.exists() {
        std::fs::remove_dir_all(&dir).expect("cannot empty the scratch directory");
    }
    std::fs::create_dir_all(&dir).expect("cannot create the scratch directory");
    dir
}

/// Names in `dir` that look like a writer's temporary file (`.NAME.PID.tmp`).
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("cannot list the scratch directory")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && n.ends_with(".tmp"))
        .collect()
}

/// Puts a directory (with a file in it) where a writer wants to put a file.
fn block_with_directory(path: &Path) {
    std::fs::create_dir_all(path).expect("cannot create the blocking directory");
    std::fs::write(path.join("keep"), b"x").expect("cannot fill the blocking directory");
}

// ---------------------------------------------------------------------------------------
// Arbitrary values

/// An observation of arbitrary doubles.
#[derive(Arbitrary, Debug, Clone)]
struct Obs {
    t: f64,
    omega: [f64; 3],
    q: [f64; 4],
    q_norm_error: f64,
    h_body: [f64; 3],
    h_inertial: [f64; 3],
    h_norm: f64,
    h_carried_out: [f64; 3],
    kinetic_energy: f64,
    elastic_energy: f64,
    dissipated_energy: f64,
    dissipation_power: f64,
    external_work: f64,
    nutation_angle: f64,
    angles_to_principal: [f64; 3],
}

impl Obs {
    fn build(&self) -> Observation {
        let [w, x, y, z] = self.q;
        Observation {
            t: self.t,
            omega: Vector3::from(self.omega),
            attitude: UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z)),
            q_norm_error: self.q_norm_error,
            h_body: Vector3::from(self.h_body),
            h_inertial: Vector3::from(self.h_inertial),
            h_norm: self.h_norm,
            h_carried_out: Vector3::from(self.h_carried_out),
            kinetic_energy: self.kinetic_energy,
            elastic_energy: self.elastic_energy,
            dissipated_energy: self.dissipated_energy,
            dissipation_power: self.dissipation_power,
            external_work: self.external_work,
            nutation_angle: self.nutation_angle,
            angles_to_principal: self.angles_to_principal,
            field_angle: f64::NAN,
        }
    }
}

/// The scenarios a log is written for: one per kind of effector, and a prescribed spin-up.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Kind {
    Rigid,
    Rayleigh,
    EnergySink,
    SpringMass,
    Wheel,
    HingedRod,
    Modal,
    SpinUp,
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Compression {
    Lz4,
    Zstd,
    None,
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Epoch {
    Default,
    Unix0,
    /// The latest epoch a 1 s scenario accepts (epoch + duration before 2106-02-07T06:28:16Z).
    Latest,
}

/// The YAML of a small valid scenario of `kind` (`name` is a YAML scalar, already quoted).
fn template(kind: Kind, name: &str, c: Compression, e: Epoch, scene_rate: Option<f64>) -> String {
    let compression = match c {
        Compression::Lz4 => "lz4",
        Compression::Zstd => "zstd",
        Compression::None => "none",
    };
    let epoch = match e {
        Epoch::Default => String::new(),
        Epoch::Unix0 => "epoch: \"1970-01-01T00:00:00Z\"\n".into(),
        Epoch::Latest => "epoch: \"2106-02-07T06:28:14Z\"\n".into(),
    };
    let scene = scene_rate.map_or(String::new(), |r| format!(", scene_rate: {r:e}"));
    let (body, effectors, extra) = match kind {
        Kind::Rigid => ("principal: [1.0, 2.0, 3.0]", String::new(), ""),
        Kind::Rayleigh => (
            "principal: [1.0, 2.0, 3.0]",
            format!("  - rayleigh: {{name: {name}, gamma_diagonal: [0.1, 0.2, 0.3]}}\n"),
            "",
        ),
        Kind::EnergySink => (
            "principal: [2.0, 2.1, 1.0]\n  spin_axis: [0, 0, 1]",
            format!("  - energy_sink: {{name: {name}, time_constant: 10.0}}\n"),
            "",
        ),
        Kind::SpringMass => (
            "mass: 5274.4\n  principal: [1375.7, 1292.5, 1402.4]\n  spin_axis: [0, 0, 1]\n  \
             shape: {cylinder: {radius: 1.1, length: 1.6, axis: [0, 0, 1]}}",
            format!(
                "  - spring_mass_damper: {{name: {name}, mass: 52.744, position: [1.0, 0.0, 0.0], \
                 direction: [0, 0, 1], stiffness: 52.744, damping: 105.49}}\n"
            ),
            "",
        ),
        Kind::Wheel => (
            "principal: [100.0, 120.0, 80.0]",
            format!(
                "  - wheel_damper: {{name: {name}, inertia: 6.0, axis: [0, 0, 1], damping: 50.0, \
                 position: [0.0, 0.0, 0.6]}}\n"
            ),
            "",
        ),
        Kind::HingedRod => (
            "mass: 13.9\n  principal: [4.9004774, 4.9004774, 0.0651632]\n  spin_axis: [0, 0, 1]\n  \
             shape: {cylinder: {radius: 0.076, length: 2.05, axis: [0, 0, 1]}}",
            format!(
                "  - hinged_rod: {{name: {name}, mass: 0.139, length: 0.56, hinge: [0.0, 0.076, 0.1], \
                 direction: [0, 1, 0], axis: [0, 0, 1], stiffness: 0.565, damping: 1.13, \
                 copies: {{count: 2, about: [0, 0, 1]}}}}\n"
            ),
            "",
        ),
        Kind::Modal => (
            "mass: 300.0\n  principal: [80.0, 95.0, 120.0]\n  spin_axis: [0, 0, 1]\n  \
             shape: {box: {size: [1.4, 1.2, 1.0]}}",
            format!(
                "  - modal_appendage: {{name: {name}, length: 6.0, bending_stiffness: 40.0, \
                 mass_per_length: 0.4, tip_mass: 1.5, attachment: [0.7, 0.0, 0.0], \
                 direction: [1, 0, 0], flap_direction: [0, 0, 1], modes: 2, \
                 damping_ratio: 0.05}}\n"
            ),
            "",
        ),
        Kind::SpinUp => (
            "mass: 100.0\n  principal: [10.0, 10.0, 10.0]\n  spin_axis: [0, 0, 1]\n  \
             shape: {box: {size: [0.4, 0.4, 0.4]}}",
            format!(
                "  - modal_appendage: {{name: {name}, length: 10.0, bending_stiffness: 1.4e4, \
                 mass_per_length: 1.2, attachment: [0.0, 0.0, 0.0], direction: [1, 0, 0], \
                 flap_direction: [0, 0, 1], bending: lag, modes: 2, damping_ratio: 0.0}}\n"
            ),
            "hub_motion:\n  spin_up: {axis: [0, 0, 1], rate: 6.0, ramp_time: 15.0}\n",
        ),
    };
    let effectors = if effectors.is_empty() {
        String::new()
    } else {
        format!("effectors:\n{effectors}")
    };
    let omega = if matches!(kind, Kind::SpinUp) {
        "[0.0, 0.0, 0.0]"
    } else {
        "[0.05, 0.05, 2.0]"
    };
    format!(
        "name: fuzz\n{epoch}body:\n  {body}\n{effectors}{extra}initial:\n  omega: {omega}\n\
         duration: 1.0\noutput: {{rate: 10, compression: {compression}{scene}}}\n"
    )
}

/// Parses the scenario of `kind` with the arbitrary parts if it validates, else without them
/// (the template itself must always validate).
fn scenario_of(r: &RunCase) -> Scenario {
    let path = Path::new("fuzz-writers.yaml");
    let name = serde_json::to_string(&r.effector_name).expect("a string serialises");
    let text = template(r.kind, &name, r.compression, r.epoch, Some(r.scene_rate));
    if let Ok(sc) = scenario::parse(path, text, &Overrides::default()) {
        return sc;
    }
    let text = template(r.kind, "part", r.compression, r.epoch, None);
    scenario::parse(path, text.clone(), &Overrides::default())
        .unwrap_or_else(|e| panic!("the writers' template does not load: {e}\n{text}"))
}

// ---------------------------------------------------------------------------------------
// MCAP

#[derive(Arbitrary, Debug)]
enum Item {
    Sample {
        o: Obs,
        reference: Obs,
        state: Vec<f64>,
    },
    Event {
        o: Obs,
        t: f64,
        condition: String,
        terminal: bool,
    },
    Text {
        t: f64,
        level: u8,
        text: String,
    },
}

#[derive(Arbitrary, Debug)]
enum EndStatus {
    Complete,
    Stopped(String),
    Interrupted,
    Failed(String),
    InvalidModel(String),
}

#[derive(Arbitrary, Debug)]
struct RunCase {
    kind: Kind,
    compression: Compression,
    epoch: Epoch,
    scene_rate: f64,
    effector_name: String,
    prefix: String,
    ref_omega: f64,
    items: Vec<Item>,
    status: EndStatus,
    final_obs: Obs,
    steps: u64,
    rhs_evaluations: u64,
    /// Whether `end_run` is called before the next run (a campaign always calls it).
    end_run: bool,
}

#[derive(Arbitrary, Debug)]
enum Ending {
    /// `finish` with the last run's scenario.
    Finish { method: String },
    /// `finish_with` arbitrary metadata and attachments.
    FinishWith {
        name: String,
        metadata: Vec<(String, String)>,
        attachments: Vec<(String, String, Vec<u8>)>,
    },
    /// `abandon`.
    Abandon,
    /// The final name becomes a directory before `finish`.
    Blocked,
}

#[derive(Arbitrary, Debug)]
struct McapCase {
    file_name: u8,
    runs: Vec<RunCase>,
    ending: Ending,
}

/// A real outcome (of the rigid template run to its end), so that this target does not
/// depend on every field of `Outcome`; the fields the logger reads are then set per input.
fn outcome_template() -> &'static Outcome {
    static OUTCOME: OnceLock<Outcome> = OnceLock::new();
    OUTCOME.get_or_init(|| {
        let text = template(Kind::Rigid, "part", Compression::None, Epoch::Default, None);
        let sc = scenario::parse(Path::new("fuzz-writers.yaml"), text, &Overrides::default())
            .expect("the rigid template loads");
        let interrupt = AtomicBool::new(false);
        let ctl = Control {
            interrupt: &interrupt,
            progress: None,
        };
        sim::run(&sc, &mut NullSink, ctl).expect("the rigid template runs")
    })
}

fn outcome_of(r: &RunCase) -> Outcome {
    let o = r.final_obs.build();
    let mut outcome = outcome_template().clone();
    outcome.status = match &r.status {
        EndStatus::Complete => Status::Complete,
        EndStatus::Stopped(c) => Status::Stopped {
            condition: c.clone(),
        },
        EndStatus::Interrupted => Status::Interrupted,
        EndStatus::Failed(d) => Status::Failed {
            diagnosis: d.clone(),
        },
        EndStatus::InvalidModel(d) => Status::InvalidModel {
            diagnosis: d.clone(),
        },
    };
    outcome.final_observation = o.clone();
    outcome.initial_observation = o;
    outcome.stats = Stats {
        steps: r.steps,
        rhs_evaluations: r.rhs_evaluations,
        ..Stats::default()
    };
    outcome
}

fn level(l: u8) -> Level {
    match l % 6 {
        0 => Level::Unknown,
        1 => Level::Debug,
        2 => Level::Info,
        3 => Level::Warning,
        4 => Level::Error,
        _ => Level::Fatal,
    }
}

/// Reads protobuf fields 1..=N of wire type 1 (doubles), in order, as `encode_doubles` writes.
fn decode_doubles(mut b: &[u8]) -> Result<Vec<f64>, String> {
    let mut out = Vec::new();
    while !b.is_empty() {
        let mut key = 0u64;
        let mut shift = 0;
        loop {
            let (&byte, rest) = b.split_first().ok_or("truncated key")?;
            b = rest;
            key |= u64::from(byte & 0x7f) << shift;
            if byte & 0x80 == 0 {
                break;
            }
            shift += 7;
            if shift > 63 {
                return Err("overlong key".into());
            }
        }
        if key & 7 != 1 {
            return Err(format!("wire type {} where a double was expected", key & 7));
        }
        if key >> 3 != out.len() as u64 + 1 {
            return Err(format!(
                "field {} where {} was expected",
                key >> 3,
                out.len() + 1
            ));
        }
        if b.len() < 8 {
            return Err("truncated double".into());
        }
        let (v, rest) = b.split_at(8);
        out.push(f64::from_le_bytes(v.try_into().expect("8 bytes")));
        b = rest;
    }
    Ok(out)
}

/// The number of fields of the first message of a `FileDescriptorSet`.
fn schema_fields(data: &[u8]) -> usize {
    let set =
        prost_types::FileDescriptorSet::decode(data).expect("an embedded schema does not decode");
    set.file[0].message_type[0].field.len()
}

fn fuzz_mcap(case: McapCase) {
    let mut runs = case.runs;
    runs.truncate(MAX_RUNS_PER_FILE);
    if runs.is_empty() {
        return;
    }
    for r in &mut runs {
        r.items.truncate(MAX_ITEMS);
    }
    let scenarios: Vec<Scenario> = runs.iter().map(scenario_of).collect();
    let dir = fresh_dir();
    let file =
        ["run.mcap", "campaign.mcap", "a b.mcap", "no-extension"][case.file_name as usize % 4];
    let path = dir.join(file);

    // What the reader must find.
    let mut expected_messages = 0u64;
    let mut expected_telemetry: Vec<[f64; 26]> = Vec::new();

    let mut logger: Option<McapLogger> = None;
    for (r, sc) in runs.iter().zip(&scenarios) {
        let mut l = match logger.take() {
            None => McapLogger::create_prefixed(&path, sc, r.ref_omega, &r.prefix),
            Some(prev) => prev.continue_with(sc, r.ref_omega, &r.prefix),
        }
        .unwrap_or_else(|e| panic!("cannot start the log in a writable directory: {e}"));
        let dim = sc.spacecraft.initial_state(&sc.omega0, &sc.attitude0).len();
        let effectors = sc.spacecraft.effectors().len() as u64;
        let interval = 1.0 / sc.scene_rate;
        let mut last_scene: Option<f64> = None;
        for item in &r.items {
            match item {
                Item::Sample {
                    o,
                    reference,
                    state,
                } => {
                    let o = o.build();
                    let inv = Reference::of(&reference.build());
                    // A state vector of the scenario's length (the run loop's contract).
                    let mut y: Vec<f64> = state.iter().copied().take(dim).collect();
                    y.resize(dim, 0.0);
                    l.sample(&o, &y, &inv).expect("a sample was refused");
                    // /tf, /telemetry, one per effector, and /scene when due (as the logger
                    // decides it).
                    expected_messages += 2 + effectors;
                    let due = last_scene.is_none_or(|last| o.t - last >= interval * (1.0 - 1e-9));
                    if due {
                        expected_messages += 1;
                        last_scene = Some(o.t);
                    }
                    expected_telemetry.push(telemetry::values(&o, &inv));
                }
                Item::Event {
                    o,
                    t,
                    condition,
                    terminal,
                } => {
                    let e = EventRecord {
                        t: *t,
                        confirmed: *t,
                        condition: condition.clone(),
                        terminal: *terminal,
                    };
                    l.event(&e, &o.build()).expect("an event was refused");
                    expected_messages += 1;
                }
                Item::Text { t, level: lv, text } => {
                    l.log_text(*t, level(*lv), text)
                        .expect("a log line was refused");
                    expected_messages += 1;
                }
            }
        }
        logger = Some(l);
        if r.end_run {
            let outcome = outcome_of(r);
            logger
                .as_mut()
                .expect("just set")
                .end_run(&outcome)
                .expect("end_run was refused");
            expected_messages += 1;
        }
    }
    let l = logger.expect("at least one run");
    let last = runs.last().expect("at least one run");
    let last_sc = scenarios.last().expect("at least one run");

    let (result, attachments) = match case.ending {
        Ending::Abandon => {
            l.abandon();
            assert!(!path.exists(), "an abandoned log left {}", path.display());
            assert!(
                temporaries(&dir).is_empty(),
                "an abandoned log left {:?}",
                temporaries(&dir)
            );
            return;
        }
        Ending::Blocked => {
            block_with_directory(&path);
            let r = l.finish(last_sc, "rk4", &outcome_of(last));
            assert!(r.is_err(), "finishing onto a directory succeeded");
            assert!(
                path.is_dir() && path.join("keep").is_file(),
                "the directory was replaced"
            );
            assert!(
                temporaries(&dir).is_empty(),
                "a failed finish left {:?}",
                temporaries(&dir)
            );
            return;
        }
        Ending::Finish { method } => {
            expected_messages += 1; // finish writes how the run ended
            (l.finish(last_sc, &method, &outcome_of(last)), 1)
        }
        Ending::FinishWith {
            name,
            metadata,
            attachments,
        } => {
            let n = attachments.len();
            let meta: BTreeMap<String, String> = metadata.into_iter().collect();
            let att = attachments
                .into_iter()
                .map(|(name, media_type, data)| Attachment {
                    name,
                    media_type,
                    data,
                })
                .collect();
            (l.finish_with(&name, meta, att), n)
        }
    };
    let written = match result {
        Ok(p) => p,
        Err(e) => {
            assert!(
                !path.exists(),
                "a failed finish ({e}) left {}",
                path.display()
            );
            assert!(
                temporaries(&dir).is_empty(),
                "a failed finish left {:?}",
                temporaries(&dir)
            );
            return;
        }
    };
    assert_eq!(written, path);
    assert!(
        temporaries(&dir).is_empty(),
        "a finished log left {:?}",
        temporaries(&dir)
    );
    let bytes = std::fs::read(&path).expect("the finished log cannot be read");

    // Every message, in the order written.
    let mut count = 0u64;
    let mut telemetry_seen = 0usize;
    for m in mcap::MessageStream::new(&bytes).expect("not an MCAP file") {
        let m = m.unwrap_or_else(|e| panic!("message {count} does not read: {e}"));
        count += 1;
        let schema = m
            .channel
            .schema
            .as_ref()
            .expect("a channel without a schema");
        if schema.name == telemetry::SCHEMA_NAME {
            let got = decode_doubles(&m.data).expect("a /telemetry message does not decode");
            let want = expected_telemetry[telemetry_seen];
            assert_eq!(
                got.len(),
                want.len(),
                "a /telemetry message has the wrong field count"
            );
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                assert_eq!(
                    g.to_bits(),
                    w.to_bits(),
                    "/telemetry message {telemetry_seen}, field {}: wrote {w:?}, read {g:?}",
                    telemetry::FIELDS[k]
                );
            }
            telemetry_seen += 1;
        } else if schema.name.starts_with("polhode.effectors.") {
            let got = decode_doubles(&m.data).expect("an /effectors message does not decode");
            let fields = schema_fields(&schema.data);
            assert_eq!(
                got.len(),
                fields,
                "{}: {} values for the {fields} fields of its schema {}",
                m.channel.topic,
                got.len(),
                schema.name
            );
        }
    }
    assert_eq!(
        count, expected_messages,
        "messages written and read back differ"
    );
    assert_eq!(telemetry_seen, expected_telemetry.len());
    let summary = mcap::Summary::read(&bytes)
        .expect("the summary does not read")
        .expect("the log has no summary section");
    let stats = summary.stats.expect("the summary has no statistics");
    assert_eq!(stats.message_count, expected_messages);
    assert_eq!(summary.metadata_indexes.len(), 1);
    assert_eq!(summary.attachment_indexes.len(), attachments);
    for m in &summary.metadata_indexes {
        mcap::read::metadata(&bytes, m).expect("the metadata does not read");
    }
    for a in &summary.attachment_indexes {
        mcap::read::attachment(&bytes, a).expect("an attachment does not read");
    }
}

// ---------------------------------------------------------------------------------------
// Tables

#[derive(Arbitrary, Debug)]
enum ArbStatus {
    Complete,
    Stopped,
    Failed,
    Invalid,
    InvalidModel,
}

impl ArbStatus {
    fn get(&self) -> RunStatus {
        match self {
            ArbStatus::Complete => RunStatus::Complete,
            ArbStatus::Stopped => RunStatus::Stopped,
            ArbStatus::Failed => RunStatus::Failed,
            ArbStatus::Invalid => RunStatus::Invalid,
            ArbStatus::InvalidModel => RunStatus::InvalidModel,
        }
    }
}

#[derive(Arbitrary, Debug)]
struct ArbRow {
    run: u64,
    status: ArbStatus,
    message: String,
    values: Vec<Option<f64>>,
}

impl ArbRow {
    fn build(&self, columns: usize) -> Row {
        let mut values = self.values.clone();
        values.resize(columns, None);
        Row {
            run: self.run,
            status: self.status.get(),
            message: self.message.clone(),
            values,
        }
    }
}

#[derive(Arbitrary, Debug)]
struct TableCase {
    columns: Vec<String>,
    rows: Vec<ArbRow>,
}

/// Equal, or both NaN (CSV writes every NaN as `NaN`: its sign and payload are not kept).
fn same(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
        _ => false,
    }
}

fn same_rows(a: &[Row], b: &[Row]) -> Result<(), String> {
    if a.len() != b.len() {
        return Err(format!("{} rows written, {} read", a.len(), b.len()));
    }
    for (x, y) in a.iter().zip(b) {
        if x.run != y.run || x.status != y.status || x.message != y.message {
            return Err(format!("row {} differs: wrote {x:?}, read {y:?}", x.run));
        }
        if x.values.len() != y.values.len()
            || x.values.iter().zip(&y.values).any(|(p, q)| !same(*p, *q))
        {
            return Err(format!(
                "row {} values differ: wrote {x:?}, read {y:?}",
                x.run
            ));
        }
    }
    Ok(())
}

/// Reads a Parquet file written by `table::to_parquet` and compares it with `rows`.
fn check_parquet(bytes: Vec<u8>, columns: &[String], rows: &[Row]) {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;
    let reader = SerializedFileReader::new(bytes::Bytes::from(bytes))
        .unwrap_or_else(|e| panic!("the Parquet file does not read: {e}"));
    let meta = reader.metadata().file_metadata();
    assert_eq!(meta.num_rows(), rows.len() as i64, "Parquet row count");
    assert_eq!(
        meta.schema_descr().num_columns(),
        3 + columns.len(),
        "Parquet column count"
    );
    let iter = reader
        .get_row_iter(None)
        .unwrap_or_else(|e| panic!("the Parquet rows do not read: {e}"));
    let mut n = 0;
    for (row, want) in iter.zip(rows) {
        let row = row.unwrap_or_else(|e| panic!("Parquet row {n} does not read: {e}"));
        let fields: Vec<&Field> = row.get_column_iter().map(|(_, f)| f).collect();
        assert_eq!(fields.len(), 3 + columns.len());
        assert_eq!(
            fields[0],
            &Field::Long(want.run as i64),
            "Parquet run of row {n}"
        );
        assert_eq!(
            fields[1],
            &Field::Str(want.status.label().into()),
            "Parquet status of row {n}"
        );
        let message = match fields[2] {
            Field::Null => String::new(),
            Field::Str(s) => s.clone(),
            f => panic!("Parquet message of row {n} is {f:?}"),
        };
        assert_eq!(message, want.message, "Parquet message of row {n}");
        for (k, v) in want.values.iter().enumerate() {
            let got = match fields[3 + k] {
                Field::Null => None,
                Field::Double(x) => Some(*x),
                f => panic!("Parquet value {k} of row {n} is {f:?}"),
            };
            assert!(
                same(got, *v),
                "Parquet value {k} of row {n}: wrote {v:?}, read {got:?}"
            );
        }
        n += 1;
    }
    assert_eq!(n, rows.len(), "Parquet rows read");
}

fn fuzz_table(case: TableCase) {
    // Column names are unique and differ from the leading ones (Prepared::new refuses a
    // table with two columns of one name; dispersion and metric columns are never `run`,
    // `status` or `message`). Parquet readers match columns by name.
    let mut columns: Vec<String> = Vec::new();
    for c in case.columns {
        if !columns.contains(&c) && !table::LEADING.contains(&c.as_str()) {
            columns.push(c);
        }
    }
    columns.truncate(MAX_COLUMNS);
    let rows: Vec<Row> = case
        .rows
        .iter()
        .take(MAX_ROWS)
        .map(|r| r.build(columns.len()))
        .collect();
    let csv = table::to_csv(&columns, &rows);
    let back = table::from_csv(&csv, &columns)
        .unwrap_or_else(|e| panic!("the CSV written does not read back: {e}\n{csv:?}"));
    if let Err(e) = same_rows(&rows, &back) {
        panic!("CSV round trip: {e}\n{csv:?}");
    }
    assert_eq!(
        table::to_csv(&columns, &back),
        csv,
        "CSV written twice differs"
    );
    if let Ok(bytes) = table::to_parquet(&columns, &rows) {
        check_parquet(bytes, &columns, &rows);
    }
}

#[derive(Arbitrary, Debug)]
struct CsvTextCase {
    text: String,
    columns: Vec<String>,
}

fn fuzz_csv_text(case: CsvTextCase) {
    let mut columns = case.columns;
    columns.truncate(MAX_COLUMNS);
    if let Ok(rows) = table::from_csv(&case.text, &columns) {
        for r in &rows {
            assert_eq!(
                r.values.len(),
                columns.len(),
                "a row read with the wrong width"
            );
        }
        let again = table::to_csv(&columns, &rows);
        let back = table::from_csv(&again, &columns)
            .unwrap_or_else(|e| panic!("a table read from CSV does not round-trip: {e}"));
        if let Err(e) = same_rows(&rows, &back) {
            panic!("CSV read, written and read again: {e}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Campaign outputs

/// A small campaign: an energy sink spinner of 2 s with two events (so the runs are ranked by
/// the flat-spin time and charted) or none (ranked by the largest nutation).
fn campaign_yaml(events: bool) -> String {
    let events = if events {
        "events:\n  - {nutation_angle_deg: {above: 1.0}}\n  - {nutation_angle_deg: {above: 2.0}}\n"
    } else {
        ""
    };
    format!(
        "name: fuzz-campaign\nbody:\n  principal: [2.0, 2.1, 1.0]\n  spin_axis: [0, 0, 1]\n\
         effectors:\n  - energy_sink: {{name: sink, time_constant: 10.0}}\n\
         initial:\n  omega: [0.05, 0.05, 2.0]\nduration: 2.0\n\
         integrator: {{method: dop853, rtol: 1.0e-6, atol: 1.0e-8}}\noutput: {{rate: 5}}\n\
         {events}montecarlo:\n  runs: 8\n  seed: 7\n  dispersions:\n\
         \x20   - {{path: initial.omega, tilt: {{sd_deg: 1.0}}}}\n\
         \x20   - {{path: \"effectors[sink].time_constant\", log_normal: {{sigma: 0.3}}}}\n\
         \x20   - {{attitude: {{sd_deg: 2.0}}}}\n\
         \x20 probability_by: [1.0, 2.0]\n  final_telemetry: [h_norm]\n"
    )
}

fn prepare(events: bool) -> Prepared {
    let path = Path::new("fuzz-campaign.yaml");
    let text = campaign_yaml(events);
    let sc = scenario::parse(path, text.clone(), &Overrides::default())
        .unwrap_or_else(|e| panic!("the campaign template does not load: {e}\n{text}"));
    Prepared::new(sc, "fuzz-campaign.yaml", None, None)
        .unwrap_or_else(|e| panic!("the campaign template does not prepare: {e}"))
}

thread_local! {
    static CAMPAIGNS: [RefCell<Prepared>; 2] = [RefCell::new(prepare(true)), RefCell::new(prepare(false))];
}

#[derive(Arbitrary, Debug)]
struct OutputsCase {
    with_events: bool,
    runs: u64,
    /// None: the whole campaign (charts, and unless partial the worst / median / best MCAP).
    shard: Option<(u64, u64)>,
    partial: bool,
    probability_by: Vec<f64>,
    rows: Vec<ArbRow>,
    /// Index into the output names of one to be taken by a directory beforehand.
    blocked: Option<u8>,
}

/// Whether whole campaigns may draw their charts (PNG rendering is slow).
fn charts_enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os("POLHODE_FUZZ_CHARTS").is_some_and(|v| v == "1"))
}

const OUTPUT_NAMES: [&str; 7] = [
    "campaign.json",
    "runs.csv",
    "runs.parquet",
    "scenario.yaml",
    "summary.json",
    "summary.txt",
    "campaign.mcap",
];

fn fuzz_outputs(case: OutputsCase) {
    CAMPAIGNS.with(|c| {
        let mut prep = c[usize::from(!case.with_events)].borrow_mut();
        // What Campaign::new and the command line guarantee: 1 ≤ runs ≤ MAX_RUNS, positive
        // finite probability times, 1 ≤ k ≤ n ≤ runs, rows of the range in run order.
        let runs = 1 + case.runs % MAX_RUNS;
        prep.campaign.runs = runs;
        let mut by: Vec<f64> = case
            .probability_by
            .iter()
            .copied()
            .filter(|t| t.is_finite() && *t > 0.0)
            .take(8)
            .collect();
        if by.is_empty() {
            by.push(prep.scenario.duration);
        }
        prep.campaign.probability_by = by;
        let shard = case.shard.map(|(k, n)| {
            let n = 1 + n % runs;
            [1 + k % n, n]
        });
        let range = match shard {
            Some([k, n]) => polhode::montecarlo::shard_range(runs, k, n),
            None => 0..runs,
        };
        let width = prep.columns.len();
        let mut rows: Vec<Row> = case
            .rows
            .iter()
            .take(MAX_ROWS)
            .filter(|_| range.end > range.start)
            .map(|r| {
                let mut row = r.build(width);
                row.run = range.start + r.run % (range.end - range.start);
                row
            })
            .collect();
        rows.sort_by_key(|r| r.run);
        rows.dedup_by_key(|r| r.run);
        let finished_all = rows.len() as u64 == range.end - range.start;
        let partial = case.partial || !finished_all;
        // A whole campaign charts every event that a usable run reached: three PNGs per
        // event rasterised by resvg, about 1.5 s each under instrumentation, which would take
        // most of the fuzzer's time for code that is not polhode's. Such inputs are written
        // as the single shard 1/1 (the same table and summary) unless POLHODE_FUZZ_CHARTS=1;
        // the charts' SVG is fuzzed on its own by the `Chart` case.
        let event_columns = prep.event_start..prep.event_start + prep.event_conditions.len();
        let charted = shard.is_none()
            && rows.iter().any(|r| {
                r.status.ok() && event_columns.clone().any(|j| r.values[j].is_some())
            });
        let shard = if charted && !charts_enabled() {
            Some([1, 1])
        } else {
            shard
        };

        let dir = fresh_dir();
        let blocked = case
            .blocked
            .map(|b| OUTPUT_NAMES[b as usize % OUTPUT_NAMES.len()]);
        if let Some(name) = blocked {
            block_with_directory(&dir.join(name));
        }
        let interrupt = AtomicBool::new(false);
        let result = write_outputs(&dir, &prep, &rows, shard, partial, &interrupt);
        let leftovers = temporaries(&dir);
        assert!(
            leftovers.is_empty(),
            "write_outputs left {leftovers:?} ({result:?})"
        );
        let written = match result {
            Ok(w) => w,
            Err(e) => {
                assert!(
                    blocked.is_some(),
                    "write_outputs failed in a writable directory: {e}"
                );
                assert!(
                    !dir.join("campaign.json").is_file(),
                    "write_outputs failed ({e}) but left a manifest"
                );
                return;
            }
        };
        assert!(
            blocked.is_none(),
            "write_outputs wrote over a directory: {written:?}"
        );
        for p in &written.files {
            assert!(
                p.is_file(),
                "{} is listed as written but is not a file",
                p.display()
            );
        }
        let read = |name: &str| {
            std::fs::read_to_string(dir.join(name))
                .unwrap_or_else(|e| panic!("{name} was not written: {e}"))
        };
        let manifest: Manifest = serde_json::from_str(&read("campaign.json"))
            .unwrap_or_else(|e| panic!("campaign.json does not parse: {e}"));
        let csv = read("runs.csv");
        assert_eq!(manifest.runs_csv_sha256, sha256_hex(csv.as_bytes()));
        assert_eq!(manifest.runs_in_table, rows.len() as u64);
        assert_eq!(manifest.runs, runs);
        assert_eq!(manifest.shard, shard);
        assert_eq!(manifest.partial, partial);
        assert_eq!(manifest.run_range, [range.start, range.end]);
        assert_eq!(manifest.columns, prep.columns);
        assert_eq!(read("scenario.yaml"), prep.scenario.source);
        let back = table::from_csv(&csv, &prep.columns)
            .unwrap_or_else(|e| panic!("runs.csv does not read back: {e}"));
        if let Err(e) = same_rows(&rows, &back) {
            panic!("runs.csv: {e}");
        }
        let parquet =
            std::fs::read(dir.join("runs.parquet")).expect("runs.parquet was not written");
        check_parquet(parquet, &prep.columns, &rows);
        let summary: serde_json::Value = serde_json::from_str(&read("summary.json"))
            .unwrap_or_else(|e| panic!("summary.json does not parse: {e}"));
        let status = &summary["status"];
        let counted: u64 = ["complete", "stopped", "failed", "invalid", "invalid_model"]
            .iter()
            .map(|k| status[k].as_u64().expect("a status count"))
            .sum();
        assert_eq!(counted, rows.len() as u64, "summary.json status counts");
        let text = read("summary.txt");
        assert!(text.starts_with("polhode "), "summary.txt: {text:?}");
        let mcap_path = dir.join("campaign.mcap");
        if mcap_path.exists() {
            let bytes = std::fs::read(&mcap_path).expect("campaign.mcap does not read");
            for m in mcap::MessageStream::new(&bytes).expect("campaign.mcap is not an MCAP file") {
                m.unwrap_or_else(|e| panic!("campaign.mcap: a message does not read: {e}"));
            }
            mcap::Summary::read(&bytes)
                .expect("campaign.mcap: the summary does not read")
                .expect("campaign.mcap has no summary");
        }
    });
}

// ---------------------------------------------------------------------------------------
// Atomic writes and statistics

#[derive(Arbitrary, Debug)]
struct AtomicCase {
    blocked: bool,
    name: u8,
    bytes: Vec<u8>,
}

fn fuzz_atomic(case: AtomicCase) {
    let dir = fresh_dir();
    let name = ["out.json", ".hidden", "a b c.txt", "x.tmp"][case.name as usize % 4];
    let path = dir.join(name);
    if case.blocked {
        block_with_directory(&path);
    }
    let result = write_atomically(&path, &case.bytes);
    assert!(
        temporaries(&dir).is_empty(),
        "write_atomically left {:?}",
        temporaries(&dir)
    );
    match result {
        Ok(()) => {
            assert!(!case.blocked, "write_atomically replaced a directory");
            assert_eq!(std::fs::read(&path).expect("written"), case.bytes);
        }
        Err(_) => {
            assert!(
                case.blocked,
                "write_atomically failed in a writable directory"
            );
            assert!(path.join("keep").is_file(), "the directory was replaced");
        }
    }
}

#[derive(Arbitrary, Debug)]
struct StatsCase {
    values: Vec<f64>,
    p: f64,
    k: u32,
    n: u32,
}

fn fuzz_stats(case: StatsCase) {
    let mut v = case.values;
    if !v.is_empty() {
        v.sort_by(f64::total_cmp);
        // Percentiles are asked between 0 and 100.
        let p = if case.p.is_finite() {
            case.p.abs() % 100.0
        } else {
            50.0
        };
        let x = percentile(&v, p);
        let finite = v.iter().all(|x| x.is_finite()) && (v[v.len() - 1] - v[0]).is_finite();
        if finite {
            let tol = 1e-12 * v[0].abs().max(v[v.len() - 1].abs()) + 1e-300;
            assert!(
                x >= v[0] - tol && x <= v[v.len() - 1] + tol,
                "percentile {p} = {x} outside [{}, {}]",
                v[0],
                v[v.len() - 1]
            );
        }
    }
    let n = case.n as usize;
    let k = if n == 0 { 0 } else { case.k as usize % (n + 1) };
    let [lo, hi] = wilson95(k, n);
    assert!(
        0.0 <= lo && lo <= hi && hi <= 1.0,
        "wilson95({k}, {n}) = [{lo}, {hi}]"
    );
}

// ---------------------------------------------------------------------------------------
// Charts (the campaign's histogram, CDF and scatter are `plot::Chart`s)

#[derive(Arbitrary, Debug)]
struct ChartCase {
    title: String,
    x_label: String,
    y_label: String,
    x_log: bool,
    y_log: bool,
    series: Vec<(String, Vec<(f64, f64)>, u8)>,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    reference_lines: Vec<(bool, f64, String)>,
    width: u16,
    height: u16,
}

fn fuzz_chart(case: ChartCase) {
    use polhode::plot::{Axis, Chart, ReferenceLine, Scale, Series, Style};
    let scale = |log| if log { Scale::Log10 } else { Scale::Linear };
    let mut chart = Chart::new(case.title, case.x_label, case.y_label);
    chart.x_scale = scale(case.x_log);
    chart.y_scale = scale(case.y_log);
    chart.x_range = case.x_range;
    chart.y_range = case.y_range;
    for (name, points, style) in case.series.into_iter().take(12) {
        let style = [
            Style::Line,
            Style::Markers,
            Style::LineMarkers,
            Style::Dashed,
        ][style as usize % 4];
        chart.series.push(Series::new(name, points, style));
    }
    for (x, value, label) in case.reference_lines.into_iter().take(8) {
        chart.reference_lines.push(ReferenceLine::new(
            if x { Axis::X } else { Axis::Y },
            value,
            label,
        ));
    }
    // Sizes from a thumbnail to the campaign charts' 900 × 600 and a little beyond.
    let width = 50 + u32::from(case.width) % 1200;
    let height = 50 + u32::from(case.height) % 900;
    let svg = chart.to_svg(width, height);
    assert!(
        svg.starts_with("<svg"),
        "not an SVG document: {:?}",
        &svg[..svg.len().min(80)]
    );
    resvg::usvg::Tree::from_str(&svg, &resvg::usvg::Options::default())
        .unwrap_or_else(|e| panic!("the chart's SVG does not parse: {e}"));
}

// ---------------------------------------------------------------------------------------

#[derive(Arbitrary, Debug)]
enum Case {
    Mcap(McapCase),
    Table(TableCase),
    CsvText(CsvTextCase),
    Outputs(OutputsCase),
    Atomic(AtomicCase),
    Stats(StatsCase),
    Chart(ChartCase),
}

fuzz_target!(|case: Case| {
    match case {
        Case::Mcap(c) => fuzz_mcap(c),
        Case::Table(c) => fuzz_table(c),
        Case::CsvText(c) => fuzz_csv_text(c),
        Case::Outputs(c) => fuzz_outputs(c),
        Case::Atomic(c) => fuzz_atomic(c),
        Case::Stats(c) => fuzz_stats(c),
        Case::Chart(c) => fuzz_chart(c),
    }
});
