//! The scenario file: the user-facing YAML contract (documented in `docs/scenarios.md`).
//!
//! Loading has two phases: serde turns the text into [`ScenarioFile`] (syntax, unknown keys and
//! types are reported by the YAML layer with their line and column), then [`ScenarioFile::validate`]
//! checks physics and ranges, using the spans kept on every checked field, and produces a
//! [`Scenario`] ready to run.

mod body;
mod bounds;
pub mod campaign;
mod effectors;
mod error;
mod initial;
mod integrator;
mod orbit;
mod output;
mod time;

pub use body::BodySpec;
use body::ValidHub;
pub use effectors::{EffectorSpec, HubMotionSpec};
use initial::check_rate;
pub use initial::{InitialSpec, QuaternionSpec};
pub use integrator::IntegratorSpec;
use integrator::{MethodChoice, from};
pub use output::{Compression, OutputSpec};
use output::{OutputSettings, output_rate_hint};

pub use error::{ScenarioError, field_path_at, nearest};
pub use time::{LAST_LOG_SECOND, format_epoch, log_origin, parse_epoch};
// The run's own types live in `sim`; the loader builds them (re-exported for its users).
pub use crate::sim::{Adaptive, Condition, DriftLimits, Method, OnBreach, Quantity};

use crate::model::{RigidBody, Spacecraft};
use crate::sim::Simulation;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::{Path, PathBuf};

/// Largest number of output samples a run may request (duration × rate); beyond it the log
/// would be tens of gigabytes.
pub const MAX_SAMPLES: f64 = 5e7;
/// Largest scenario file accepted (bytes).
pub const MAX_FILE_BYTES: u64 = 1 << 20;
/// Largest magnitude of a physical parameter in SI units (masses, lengths, inertia moments,
/// stiffnesses, damping, ...). Far beyond any spacecraft, and small enough that energies and
/// momenta built from such values stay finite in double precision.
pub const MAX_MAGNITUDE: f64 = 1e12;
/// Smallest positive value of a parameter that must be positive (masses, lengths, inertia
/// moments, stiffnesses): below it the equations divide by numbers that round to nothing.
pub const MIN_POSITIVE: f64 = 1e-12;
/// Largest initial body rate |ω| (rad/s), about 95 000 rev/min.
pub const MAX_RATE: f64 = 1e4;
/// Shortest run (s): the log stamps time in nanoseconds.
pub const MIN_DURATION: f64 = 1e-9;
/// Default largest log (MB): a run whose log is estimated to be larger is refused before it
/// starts (`output.max_log_mb`, `--max-log-mb`).
pub const DEFAULT_MAX_LOG_MB: f64 = 2000.0;
/// Smallest ratio of the smallest principal moment to the largest.
pub const MIN_MOMENT_RATIO: f64 = 1e-9;
/// Smallest absolute tolerance: below it the scaled error norm overflows for components
/// near zero, and the error test (and radau5's Newton test) can never pass.
pub const MIN_ATOL: f64 = 1e-30;
/// Longest scenario name (characters); the name becomes the default log's file name.
pub const MAX_NAME_CHARS: usize = 200;
/// Default epoch of sim time 0: J2000, 2000-01-01T12:00:00Z.
pub const DEFAULT_EPOCH: &str = "2000-01-01T12:00:00Z";

/// The scenario as written in YAML.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Short identifier, used for the default log name.
    pub name: Spanned<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// UTC date and time of sim time 0 (RFC 3339, e.g. `2000-01-01T12:00:00Z`).
    #[serde(default)]
    pub epoch: Option<Spanned<String>>,
    /// The rigid hub.
    pub body: BodySpec,
    /// Initial state.
    pub initial: InitialSpec,
    /// Simulated time span (s).
    pub duration: Spanned<f64>,
    /// Integration method and its settings.
    #[serde(default)]
    pub integrator: Option<IntegratorSpec>,
    /// Logging.
    #[serde(default)]
    pub output: Option<OutputSpec>,
    /// Conditions that end the run, located in time.
    #[serde(default)]
    pub stop: Vec<Spanned<ConditionSpec>>,
    /// Conditions recorded every time they become true, without stopping.
    #[serde(default)]
    pub events: Vec<Spanned<ConditionSpec>>,
    /// Parts beyond the rigid hub: dampers, appendages, dissipation torques.
    #[serde(default)]
    pub effectors: Vec<Spanned<EffectorSpec>>,
    /// A prescribed hub rotation (the hub's centre of mass is then pinned).
    #[serde(default)]
    pub hub_motion: Option<HubMotionSpec>,
    /// A Monte Carlo campaign over this scenario (`polhode montecarlo`; ignored by `run`).
    #[serde(default)]
    pub montecarlo: Option<campaign::CampaignFile>,
    /// Bounds on invariant drift and what to do when one is exceeded.
    #[serde(default)]
    pub checks: Option<ChecksSpec>,
    /// The orbit of the spacecraft's centre of mass (environmental torques, LVLH).
    #[serde(default)]
    pub orbit: Option<orbit::OrbitSpec>,
}

/// `checks:` — accuracy the run must keep, checked at every step.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChecksSpec {
    /// Largest relative drift of each conserved invariant.
    #[serde(default)]
    pub max_drift: Option<DriftBoundsSpec>,
    /// `stop` (default: end the run, keep the log, exit 3) or `warn` (note it and go on).
    #[serde(default)]
    pub on_drift: Option<Spanned<String>>,
    /// When an effector leaves the range its model holds in: `stop` (default: end the run
    /// as `invalid_model` with a diagnosis) or `warn` (note it once and go on).
    #[serde(default)]
    pub on_validity: Option<Spanned<String>>,
}

/// `checks.max_drift:` bounds (dimensionless, relative to the initial value).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriftBoundsSpec {
    /// Angular momentum: max of |ΔH|/|H₀| (body |H|) and |ΔH_N|/|H₀| (inertial vector).
    #[serde(default)]
    pub momentum: Option<Spanned<f64>>,
    /// Energy balance (kinetic + elastic + dissipated): |ΔE|/E₀.
    #[serde(default)]
    pub energy: Option<Spanned<f64>>,
    /// Quaternion norm: ||q| − 1|.
    #[serde(default)]
    pub quaternion_norm: Option<Spanned<f64>>,
}

/// A shape for the 3D view, in body axes, centred on the centre of mass.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum ShapeSpec {
    /// Box with side lengths along body x, y, z (m).
    Box {
        /// Side lengths (m).
        size: [f64; 3],
    },
    /// Cylinder with its axis along a body axis.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
        /// Axis direction in body axes (default z).
        #[serde(default)]
        axis: Option<[f64; 3]>,
    },
}

/// A condition on a logged quantity, e.g. `{nutation_angle_deg: {above: 89.0}}`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum ConditionSpec {
    /// Nutation angle of the spin axis relative to H (degrees).
    NutationAngleDeg(ThresholdSpec),
    /// Angle between ω and the minimum-inertia principal axis (degrees).
    #[serde(rename = "angle_to_principal_1_deg")]
    AngleToPrincipal1Deg(ThresholdSpec),
    /// Angle between ω and the intermediate principal axis (degrees).
    #[serde(rename = "angle_to_principal_2_deg")]
    AngleToPrincipal2Deg(ThresholdSpec),
    /// Angle between ω and the maximum-inertia principal axis (degrees).
    #[serde(rename = "angle_to_principal_3_deg")]
    AngleToPrincipal3Deg(ThresholdSpec),
    /// Body rate about x (rad/s).
    OmegaX(ThresholdSpec),
    /// Body rate about y (rad/s).
    OmegaY(ThresholdSpec),
    /// Body rate about z (rad/s).
    OmegaZ(ThresholdSpec),
    /// Rotational kinetic energy (J).
    KineticEnergy(ThresholdSpec),
    /// The body's rate |ω| (deg/s): a detumbling's progress.
    RateDegS(ThresholdSpec),
    /// Angle between the `magnetic_dipole`'s moment and the local field (degrees).
    FieldAngleDeg(ThresholdSpec),
}

/// `{above: X}` or `{below: X}`: the condition holds while the quantity is above (below) X;
/// `once: true` records only its first occurrence, `for: S` asks that it hold S seconds.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ThresholdSpec {
    /// Holds while the quantity is greater than this.
    #[serde(default)]
    pub above: Option<f64>,
    /// Holds while the quantity is less than this.
    #[serde(default)]
    pub below: Option<f64>,
    /// Record only the first time the condition becomes true (default false).
    #[serde(default)]
    pub once: Option<bool>,
    /// The condition must hold continuously this long (s) before it counts; the event's
    /// time is the start of the interval that held (default 0: at once).
    #[serde(default, rename = "for")]
    pub hold: Option<f64>,
}

/// Shape drawn in viewers, validated.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Box with side lengths (m) along the columns of `axes` (body coordinates).
    Box {
        /// Side lengths (m).
        size: Vector3<f64>,
        /// Orientation of the box in the body frame.
        orientation: UnitQuaternion<f64>,
    },
    /// Cylinder whose axis is the local z of `orientation`.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
        /// Rotation taking z to the cylinder axis, in the body frame.
        orientation: UnitQuaternion<f64>,
    },
}

/// `body.composite: true`: the whole spacecraft's mass properties as given, and what polhode
/// took away to get the hub's own (kept in [`Simulation::spacecraft`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CompositeHub {
    /// The whole spacecraft's mass as given (kg), if given (it is needed only when effectors
    /// move mass).
    pub total_mass: Option<f64>,
    /// The whole spacecraft's inertia about its centre of mass as given (kg m², body axes).
    pub total_inertia: Matrix3<f64>,
    /// Mass of the effectors that move mass, at rest (kg).
    pub effector_mass: f64,
    /// The hub's centre of mass relative to the whole spacecraft's (m, body axes): the
    /// effectors' positions, given about the whole spacecraft's centre of mass, were shifted
    /// by minus this to be about the hub's.
    pub hub_offset: Vector3<f64>,
}

/// A validated scenario, ready to run.
#[derive(Debug)]
pub struct Scenario {
    /// Where it was read from.
    pub path: PathBuf,
    /// The YAML text as read (attached to logs).
    pub source: String,
    /// `name:`.
    pub name: String,
    /// The run itself: spacecraft, initial state, method, duration, sampling, conditions
    /// and checks (also reached through `Deref`, as `scenario.spacecraft`).
    pub simulation: Simulation,
    /// `description:`.
    pub description: String,
    /// Sim time 0 as Unix time (ns; negative before 1970).
    pub epoch_unix_ns: i64,
    /// Why `auto` picked [`Simulation::method`] (None when the method was named).
    pub method_choice: Option<String>,
    /// Where the MCAP log goes.
    pub mcap_path: PathBuf,
    /// Largest rate of `/scene` updates (Hz).
    pub scene_rate: f64,
    /// MCAP chunk compression.
    pub compression: Compression,
    /// Shape for viewers.
    pub shape: Shape,
    /// With `body.composite: true`, the whole spacecraft as given and the hub's remainder.
    pub composite: Option<CompositeHub>,
    /// Located warnings found while loading (e.g. a placement that could not be checked),
    /// printed by `check` and `run`.
    pub warnings: Vec<ScenarioError>,
    /// The `montecarlo:` block as written, checked by `montecarlo::Campaign::new`.
    pub montecarlo: Option<campaign::CampaignFile>,
    /// Largest log the run may write (MB), checked against an estimate before it starts.
    pub max_log_mb: f64,
    /// The orbit (`orbit:`), when the scenario has one.
    pub orbit: Option<std::sync::Arc<crate::orbit::Orbit>>,
    /// The geomagnetic field model its magnetic effectors see, in words (None without one).
    pub magnetic_field: Option<String>,
}

impl Scenario {
    /// A scenario around a [`Simulation`] built in code, so that it can be logged to MCAP
    /// like a file's: the default epoch ([`DEFAULT_EPOCH`]), no orbit, 10 scene updates per
    /// second, LZ4 chunks, a box with the hub's inertia proportions for the viewers, the log
    /// at `logs/<name>.mcap`, and no scenario attachment (there is no source text).
    pub fn from_simulation(name: &str, simulation: Simulation) -> Scenario {
        let hub = &simulation.spacecraft.hub;
        let shape = Shape::Box {
            size: hub.equivalent_box(1.0),
            orientation: UnitQuaternion::from_matrix(&hub.principal_axes),
        };
        Scenario {
            path: PathBuf::new(),
            source: String::new(),
            name: name.to_string(),
            description: String::new(),
            epoch_unix_ns: parse_epoch(DEFAULT_EPOCH).expect("the default epoch parses"),
            method_choice: None,
            mcap_path: output::default_log_path(name),
            scene_rate: 10.0,
            compression: Compression::default(),
            shape,
            composite: None,
            warnings: Vec::new(),
            montecarlo: None,
            max_log_mb: DEFAULT_MAX_LOG_MB,
            orbit: None,
            magnetic_field: None,
            simulation,
        }
    }
}

/// A scenario is a [`Simulation`] with the provenance and output settings the YAML front end
/// adds: it reads as its simulation (`scenario.spacecraft`, `sim::run(&scenario, …)`).
impl std::ops::Deref for Scenario {
    type Target = Simulation;
    fn deref(&self) -> &Simulation {
        &self.simulation
    }
}

impl std::ops::DerefMut for Scenario {
    fn deref_mut(&mut self) -> &mut Simulation {
        &mut self.simulation
    }
}

/// Overrides from the command line, applied before validation.
#[derive(Debug, Clone, Default)]
pub struct Overrides {
    /// `--method`.
    pub method: Option<String>,
    /// `--dt` (s).
    pub dt: Option<f64>,
    /// `--rtol`.
    pub rtol: Option<f64>,
    /// `--atol`.
    pub atol: Option<f64>,
    /// `--stages` (gauss).
    pub stages: Option<u32>,
    /// `--order` (splitting).
    pub order: Option<u32>,
    /// `--duration` (s).
    pub duration: Option<f64>,
    /// `--out`.
    pub mcap: Option<PathBuf>,
    /// `--max-log-mb`.
    pub max_log_mb: Option<f64>,
}

/// Reads and validates a scenario file.
pub fn load(path: &Path, overrides: &Overrides) -> Result<Scenario, ScenarioError> {
    crate::outputs::note_input(path);
    let meta = std::fs::metadata(path)
        .map_err(|e| ScenarioError::whole_file(path, format!("cannot read the file: {e}")))?;
    if meta.is_dir() {
        return Err(ScenarioError::whole_file(
            path,
            "this is a directory; expected a scenario file (YAML)",
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(ScenarioError::whole_file(
            path,
            format!(
                "the file is {} bytes; a scenario must be at most {MAX_FILE_BYTES} bytes",
                meta.len()
            ),
        ));
    }
    // Read at most one byte past the limit: a FIFO or a device (`/dev/zero`) reports no size.
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| {
            use std::io::Read;
            f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes)
        })
        .map_err(|e| ScenarioError::whole_file(path, format!("cannot read the file: {e}")))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(ScenarioError::whole_file(
            path,
            format!(
                "the input is longer than {MAX_FILE_BYTES} bytes, the largest scenario accepted"
            ),
        ));
    }
    if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        return Err(ScenarioError::at(
            path,
            Some((1, 1)),
            "",
            "the file is UTF-16 text (it starts with a UTF-16 byte-order mark); save it as \
             UTF-8",
        ));
    }
    let source = String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let before = &e.as_bytes()[..offset];
        let line = before.iter().filter(|&&b| b == b'\n').count() as u32 + 1;
        let column = (offset
            - before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1)) as u32
            + 1;
        ScenarioError::at(
            path,
            Some((line, column)),
            "",
            format!(
                "byte 0x{:02x} is not UTF-8 text; save the file as UTF-8",
                e.as_bytes()[offset]
            ),
        )
    })?;
    parse(path, source, overrides)
}

/// Line `line` (1-based) of `source`, as YAML counts lines.
pub fn yaml_line(source: &str, line: u32) -> Option<&str> {
    error::yaml_lines(source)
        .get(line.checked_sub(1)? as usize)
        .copied()
}

/// How scenario text is read: YAML 1.2 core booleans only (`true`/`false`), so that `yes`,
/// `on`, `'y'` or `'off'` are strings, as YAML 1.2 says, and a boolean key refuses them.
pub fn yaml_options() -> serde_saphyr::Options {
    serde_saphyr::options! { strict_booleans: true }
}

/// Parses and validates scenario text (`path` is used in messages and for nothing else).
pub fn parse(
    path: &Path,
    source: String,
    overrides: &Overrides,
) -> Result<Scenario, ScenarioError> {
    let file: ScenarioFile = match serde_saphyr::from_str_with_options(&source, yaml_options()) {
        Ok(f) => f,
        Err(e) => return Err(yaml_error(path, &source, &e)),
    };
    // Plausible physical bounds on every number, after the field checks (whose messages
    // say more about the fields they know).
    let bounded = bounds::check(path, &source);
    let scenario = file.validate(path, source, overrides)?;
    bounded.map(|()| scenario)
}

/// What a breach of the YAML reader's resource limits means, in the scenario's terms.
fn budget_message(breach: &serde_saphyr::budget::BudgetBreach) -> String {
    use serde_saphyr::budget::BudgetBreach as B;
    let limit = match breach {
        B::Nodes { nodes } => format!("more than {} values, lists and mappings", nodes - 1),
        B::Events { events } => format!("more than {} YAML events", events - 1),
        B::Depth { depth } => format!("nesting {depth} levels deep"),
        B::Aliases { aliases } => format!("{aliases} aliases (`*name`)"),
        B::Anchors { anchors } => format!("{anchors} anchors (`&name`)"),
        B::Documents { documents } => format!("{documents} documents"),
        B::MergeKeys { merge_keys } => format!("{merge_keys} merge keys (`<<`)"),
        B::AliasAnchorRatio { aliases, anchors } => {
            format!("{aliases} aliases of {anchors} anchors (an alias expansion bomb?)")
        }
        _ => "more text than a scenario needs".into(),
    };
    format!(
        "the YAML holds {limit}, past the reader's limit; a scenario's lists and tables are \
         short (a torque table of a few hundred points is plenty)"
    )
}

/// Turns a YAML-layer error into a located [`ScenarioError`] with a suggestion for misspelt keys.
fn yaml_error(path: &Path, source: &str, e: &serde_saphyr::Error) -> ScenarioError {
    let mut location = e.location().map(|l| (l.line() as u32, l.column() as u32));
    let rendered = e.without_snippet().to_string();
    let mut message = rendered.lines().next().unwrap_or("").trim().to_string();
    // Drop the library's own "error: line L column C:" prefix; we print the location ourselves.
    if let Some(rest) = message.strip_prefix("error: ") {
        message = rest.to_string();
    }
    if message.starts_with("line ")
        && let Some((_, rest)) = message.split_once(": ")
    {
        message = rest.to_string();
    }
    // The location is printed in front; drop the library's copy at the end.
    if let Some(i) = message.rfind(" at line ")
        && message[i..].contains(", column ")
    {
        message.truncate(i);
    }
    if message.is_empty() {
        message = "invalid YAML".into();
    }
    if let serde_saphyr::Error::Budget { breach, .. } = e.without_snippet() {
        return ScenarioError::at(path, location, "", budget_message(breach));
    }
    const TOP_LEVEL: &str = "expected a mapping of scenario keys (`name`, `body`, `initial`, \
                             `duration`, ...)";
    if source
        .trim()
        .lines()
        .all(|l| l.trim().is_empty() || l.trim().starts_with('#'))
    {
        return ScenarioError::at(path, None, "", format!("the file is empty: {TOP_LEVEL}"));
    }
    let not_a_mapping =
        message.contains("expected mapping start") && location.is_some_and(|l| l.0 == 1);
    if not_a_mapping {
        message = format!("the document is not a mapping: {TOP_LEVEL}");
    }
    // A syntax error is about the text, not about a field: say what is likely open.
    let syntax = matches!(
        e.without_snippet(),
        serde_saphyr::Error::ExternalMessage { .. } | serde_saphyr::Error::Eof { .. }
    );
    if syntax && let Some((line, _)) = location {
        if let Some(hint) = unclosed_before(source, line) {
            message = format!("{message} ({hint})");
        }
        if message.starts_with("tabs disallowed") {
            message = "a tab in the indentation: YAML indents with spaces".into();
        } else if message.contains("did not find expected key") {
            message = format!(
                "{message}: check this line's indentation against the lines above (keys of \
                 one mapping start in the same column)"
            );
        } else if message.starts_with("mapping values are not allowed") {
            message = "a `:` inside a value: quote the value (\"a: b\"), or check the \
                       indentation"
                .into();
        }
        if message.contains("\\u{0}") {
            message = "a NUL byte: YAML text may not contain control characters".into();
        }
    }
    let mut field = if syntax || not_a_mapping {
        String::new()
    } else {
        location
            .map(|(l, c)| field_path_at(source, l, c))
            .unwrap_or_default()
    };
    // The text of the offending scalar, for type errors.
    let found = location
        .and_then(|(l, c)| scalar_at(source, l, c))
        .map(|t| format!(", got `{t}`"))
        .unwrap_or_default();
    if message == "invalid floating point" || message.starts_with("invalid floating point") {
        message = format!(
            "expected a number{found} (plain numbers in SI units, no unit suffix; angles in \
             radians unless the key ends in `_deg`)"
        );
    } else if (field.starts_with("events[") || field.starts_with("stop["))
        && (message == "expected mapping start"
            || message == "expected end of mapping after enum variant value")
    {
        message = if message.starts_with("expected end") {
            "expected one condition per list item: put each `QUANTITY: {above: X}` on its own \
             `-` line"
                .into()
        } else if field.contains('.') {
            format!(
                "expected a threshold mapping `{{above: X}}` or `{{below: X}}`{found}, with \
                 optional `once: true` and `for: SECONDS`"
            )
        } else {
            format!("expected a condition such as `nutation_angle_deg: {{above: 45.0}}`{found}")
        };
    } else if message == "expected mapping start" && field.ends_with("attitude") {
        message = format!(
            "expected a quaternion as a mapping `{{w: 1.0, x: 0.0, y: 0.0, z: 0.0}}`{found} \
             (body to inertial, Hamilton); a list is refused because whether its scalar comes \
             first or last would be a guess"
        );
    } else if message == "expected sequence start" {
        message = format!("expected a list `[...]`{found}");
    } else if message == "expected string scalar" {
        let last = field.rsplit('.').next().unwrap_or("");
        let text_field = matches!(
            last,
            "name"
                | "description"
                | "epoch"
                | "mcap"
                | "method"
                | "on_drift"
                | "on_validity"
                | "freedom"
        );
        let what = location
            .and_then(|(l, c)| {
                let line = *error::yaml_lines(source).get(l.checked_sub(1)? as usize)?;
                line.chars().nth(c.checked_sub(1)? as usize)
            })
            .map_or("", |c| match c {
                '[' => ", got a list",
                '{' => ", got a mapping",
                _ => "",
            });
        message = if text_field {
            format!("expected a text string{what}")
        } else {
            format!("expected a single value{what}")
        };
    } else if message.contains("untagged enum PerAngle") {
        message = "expected a number, or a [flap, lag] pair of numbers".into();
    } else if message.contains("untagged enum") {
        message = "a value of the wrong form (see docs/scenarios.md and docs/effectors.md)".into();
    } else if message.starts_with("recursion limit exceeded") {
        message = "the YAML nests deeper than the parser allows (a scenario nests a few \
                   levels; is a bracket repeated?)"
            .into();
        field.clear();
    } else if message.starts_with("multiple YAML documents") {
        message = "a second YAML document starts here (`---`); a scenario file holds one \
                   document"
            .into();
        field.clear();
    } else if let Some(rest) = message.strip_prefix("invalid length ")
        && let Some((got, expected)) = rest.split_once(", expected ")
        && let Some(n) = expected.split_whitespace().last()
    {
        // The reader stops at the first value past the expected count, so `got` is then
        // n + 1 whatever the list's real length.
        let got = match (got.parse::<usize>(), n.parse::<usize>()) {
            (Ok(g), Ok(m)) if g == m + 1 => format!("more than {m}"),
            _ => got.to_string(),
        };
        message = format!("expected a list of {n} values, got {got}");
    } else if message.starts_with("invalid boolean") {
        message = format!(
            "expected `true` or `false`{found} (YAML 1.2: yes, no, on, off, y and n are text, \
             not booleans)"
        );
    } else if let Some(kind) = message
        .strip_prefix("invalid ")
        .filter(|k| matches!(*k, "u8" | "u16" | "u32" | "u64" | "usize"))
    {
        let max = match kind {
            "u8" => "255",
            "u16" => "65535",
            "u32" => "4294967295",
            _ => "18446744073709551615",
        };
        // The parser may point past a flow mapping's end: name the count it could not read.
        let bad = location.and_then(|(l, c)| not_a_count_before(source, l, c));
        let got = match &bad {
            Some((_, _, text, _)) => format!(", got `{text}`"),
            None => found.clone(),
        };
        if let Some((l, c, _, inline)) = bad {
            location = Some((l, c));
            // The block keys down to this line, then the inline keys to the value.
            let block = field_path_at(source, l, 1);
            field = field_path_at(source, l, c);
            if !field.ends_with(&inline) {
                field = if block.is_empty() {
                    inline
                } else {
                    format!("{block}.{inline}")
                };
            }
        }
        message = format!("expected a whole number from 0 to {max}{got}");
    } else if let Some(rest) = message.strip_prefix("duplicate mapping key: ") {
        let key = rest.split(',').next().unwrap_or(rest).trim();
        message = format!("`{key}` is given twice; a key may appear once in a mapping");
    }
    // "unknown field `x`, expected one of a, b" → suggest the nearest valid name.
    if message.starts_with("unknown")
        && let Some(unknown) = message.split('`').nth(1)
        && let Some((_, list)) = message.split_once("expected one of ")
    {
        let valid: Vec<&str> = list
            .split(',')
            .map(|s| s.trim().trim_matches('`'))
            .collect();
        if let Some(best) = nearest(unknown, valid.iter().copied()) {
            message = format!("{message}; did you mean `{best}`?");
        }
    }
    // "missing field `x`": the location is a sibling key, so the field is its parent's `x`.
    if let Some(missing) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.split('`').next())
    {
        let parent = field.rsplit_once('.').map(|(p, _)| p).unwrap_or("");
        field = if parent.is_empty() {
            missing.to_string()
        } else {
            format!("{parent}.{missing}")
        };
        message = format!("{message}: this key is required");
    }
    ScenarioError::at(path, location, field, message)
}

/// The `key: value` on `line` whose value is a number but not a whole number from 0 up (a
/// count of -1 or 2.5): the first at or after `column` (the parser points at the start of
/// the flow mapping that holds it), else the last before. Its (line, column), text and the
/// inline keys that lead to it (`wheel.copies.count`).
fn not_a_count_before(source: &str, line: u32, column: u32) -> Option<(u32, u32, String, String)> {
    let text = *error::yaml_lines(source).get(line.checked_sub(1)? as usize)?;
    let chars: Vec<char> = text.chars().collect();
    let mut best = None;
    // Keys whose values are the open `{…}` mappings, and the key just read.
    let mut open: Vec<String> = Vec::new();
    let mut key_start = 0;
    for k in 0..chars.len() {
        match chars[k] {
            '{' => {
                let before: String = chars[key_start..k].iter().collect();
                let key = before.trim().trim_end_matches(':').trim().to_string();
                open.push(key);
                key_start = k + 1;
            }
            '}' => {
                open.pop();
                key_start = k + 1;
            }
            ',' | '[' | ']' => key_start = k + 1,
            ':' => {
                let key: String = chars[key_start..k].iter().collect();
                let key = key.trim().trim_start_matches("- ").to_string();
                let mut s = k + 1;
                while s < chars.len() && chars[s] == ' ' {
                    s += 1;
                }
                let mut e = s;
                while e < chars.len() && !matches!(chars[e], ',' | '}' | ']' | ' ' | '#') {
                    e += 1;
                }
                let value: String = chars[s..e].iter().collect();
                if value.parse::<f64>().is_ok() && value.parse::<u64>().is_err() {
                    let mut path: Vec<&str> = open
                        .iter()
                        .map(String::as_str)
                        .filter(|k| !k.is_empty() && *k != "-")
                        .collect();
                    path.push(&key);
                    best = Some((line, s as u32 + 1, value, path.join(".")));
                    if s + 1 >= column as usize {
                        break;
                    }
                }
            }
            _ => {}
        }
    }
    best
}

/// Where a bracket or quote opened before `line` (1-based) is still open, for syntax errors
/// reported later than their cause (YAML flow lists and quoted text may span lines).
fn unclosed_before(source: &str, line: u32) -> Option<String> {
    let mut open: Vec<(char, u32)> = Vec::new();
    for (i, raw) in error::yaml_lines(source)
        .into_iter()
        .enumerate()
        .take(line.saturating_sub(1) as usize)
    {
        let number = i as u32 + 1;
        let mut quote: Option<char> = None;
        let mut prev = ' ';
        for c in raw.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '#') if prev == ' ' || prev == '\t' => break,
                (None, '"') => quote = Some('"'),
                (None, '\'') if prev == ' ' || prev == ':' || prev == '[' || prev == ',' => {
                    quote = Some('\'')
                }
                (None, '[' | '{') => open.push((c, number)),
                (None, ']' | '}') => {
                    open.pop();
                }
                _ => {}
            }
            prev = c;
        }
        if let Some(q) = quote {
            return Some(format!("is the `{q}` opened on line {number} closed?"));
        }
    }
    open.last()
        .map(|(c, l)| format!("is the `{c}` opened on line {l} closed?"))
}

/// The scalar text starting at (`line`, `column`), 1-based, up to a flow indicator, comment or
/// the end of the line; `None` when empty or not a plain scalar.
fn scalar_at(source: &str, line: u32, column: u32) -> Option<String> {
    let text = *error::yaml_lines(source).get(line.checked_sub(1)? as usize)?;
    let rest: String = text
        .chars()
        .skip(column.checked_sub(1)? as usize)
        .take_while(|c| !matches!(c, ',' | ']' | '}' | '#' | '[' | '{'))
        .collect();
    let rest = rest.trim();
    (!rest.is_empty() && rest.chars().count() <= 60).then(|| rest.to_string())
}

pub(crate) fn loc<T>(s: &Spanned<T>) -> Option<(u32, u32)> {
    Some((s.referenced.line() as u32, s.referenced.column() as u32))
}

/// `v` over its length, or `None` for a zero or non-finite vector. Scaled by its largest
/// component first, so that [1e200, 1e200, 0] does not overflow to an infinite length and
/// [1e-300, 1e-300, 0] does not underflow to a zero one.
pub fn unit_vector(v: &Vector3<f64>) -> Option<Vector3<f64>> {
    let m = v.amax();
    (v.iter().all(|x| x.is_finite()) && m > 0.0).then(|| (v / m).normalize())
}

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Whether `v` is a positive parameter polhode supports ([`MIN_POSITIVE`] to
/// [`MAX_MAGNITUDE`]).
pub fn in_positive_range(v: f64) -> bool {
    (MIN_POSITIVE..=MAX_MAGNITUDE).contains(&v)
}

/// `v` for a message: plain when of moderate size, in exponent form when very large or small.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Checks the `checks:` block against what the spacecraft conserves.
fn drift_limits(
    path: &Path,
    checks: Option<ChecksSpec>,
    sc: &Spacecraft,
) -> Result<DriftLimits, ScenarioError> {
    let Some(checks) = checks else {
        return Ok(DriftLimits::default());
    };
    let on_breach = |choice: &Option<Spanned<String>>, key: &str| match choice {
        None => Ok(OnBreach::Stop),
        Some(a) if a.value == "stop" => Ok(OnBreach::Stop),
        Some(a) if a.value == "warn" => Ok(OnBreach::Warn),
        Some(a) => Err(ScenarioError::at(
            path,
            loc(a),
            format!("checks.{key}"),
            format!("expected `stop` or `warn`, got `{}`", a.value),
        )),
    };
    let on_drift = on_breach(&checks.on_drift, "on_drift")?;
    let on_validity = on_breach(&checks.on_validity, "on_validity")?;
    let bounds = checks.max_drift.unwrap_or_default();
    let bound = |b: &Option<Spanned<f64>>, key: &str, conserved: bool, why: &str| match b {
        None => Ok(None),
        Some(v) if !conserved => Err(ScenarioError::at(
            path,
            loc(v),
            format!("checks.max_drift.{key}"),
            format!("this scene does not conserve it ({why}), so no drift bound applies"),
        )),
        Some(v) if v.value.is_finite() && v.value > 0.0 => Ok(Some(v.value)),
        Some(v) => Err(ScenarioError::at(
            path,
            loc(v),
            format!("checks.max_drift.{key}"),
            format!(
                "expected a positive relative drift (e.g. 1.0e-8), got {}",
                number(v.value)
            ),
        )),
    };
    Ok(DriftLimits {
        momentum: bound(
            &bounds.momentum,
            "momentum",
            sc.conserves_momentum(),
            "its hub's rotation is prescribed",
        )?,
        energy: bound(
            &bounds.energy,
            "energy",
            sc.conserves_energy(),
            if sc.expels_mass() {
                "a thruster's motor supplies energy to it"
            } else {
                "a prescribed motion does work on it"
            },
        )?,
        quaternion_norm: bound(&bounds.quaternion_norm, "quaternion_norm", true, "")?,
        on_drift,
        on_validity,
    })
}

/// Where the top-level `key:` is written (line, column), for errors about what it lacks.
pub(crate) fn key_location(source: &str, key: &str) -> Option<(u32, u32)> {
    error::yaml_lines(source)
        .into_iter()
        .position(|l| {
            l.strip_prefix(key)
                .is_some_and(|r| r.trim_start().starts_with(':'))
        })
        .map(|i| (i as u32 + 1, 1))
}

/// The (line, column) of the value of the `n`-th (0-based) `name:` key whose value is `name`
/// (plain or quoted), in block or inline style.
fn nth_name_location(source: &str, name: &str, n: usize) -> Option<(u32, u32)> {
    let mut seen = 0;
    for (i, line) in error::yaml_lines(source).into_iter().enumerate() {
        let mut from = 0;
        while let Some(k) = line[from..].find("name:") {
            let key = from + k;
            from = key + 5;
            if key > 0 && line[..key].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let rest = &line[from..];
            let value = rest.trim_start();
            let text = value
                .split([',', '}', '#'])
                .next()
                .unwrap_or("")
                .trim()
                .trim_matches(['"', '\'']);
            if text == name {
                if seen == n {
                    let byte = from + (rest.len() - value.len());
                    let column = line[..byte].chars().count() as u32 + 1;
                    return Some((i as u32 + 1, column));
                }
                seen += 1;
            }
        }
    }
    None
}

fn loc_of<T>(s: &Option<Spanned<T>>) -> Option<(u32, u32)> {
    s.as_ref().and_then(loc)
}

impl ScenarioFile {
    /// Checks physics and ranges and builds the runnable [`Scenario`].
    pub fn validate(
        self,
        path: &Path,
        source: String,
        ov: &Overrides,
    ) -> Result<Scenario, ScenarioError> {
        let err = |l: Option<(u32, u32)>, field: &str, msg: String| {
            ScenarioError::at(path, l, field, msg)
        };
        let name = self.name.value.trim().to_string();
        if name.is_empty() {
            return Err(err(
                loc(&self.name),
                "name",
                "expected a non-empty name".into(),
            ));
        }
        if name.chars().count() > MAX_NAME_CHARS {
            return Err(err(
                loc(&self.name),
                "name",
                format!(
                    "the name has {} characters; expected at most {MAX_NAME_CHARS} (it names \
                     the log file)",
                    name.chars().count()
                ),
            ));
        }

        // Body.
        let ValidHub {
            hub,
            inertia,
            location: inertia_loc,
            field: inertia_field,
        } = self.body.hub(path, &source)?;

        let (omega0, attitude0, attitude_note) = self.initial.state(path, &source)?;

        // The orbit, and the initial state given relative to its LVLH frame.
        let orbit = match &self.orbit {
            Some(spec) => Some(orbit::orbit(path, spec, key_location(&source, "orbit"))?),
            None => None,
        };
        let magnetic_model = orbit::magnetic_model(path, self.orbit.as_ref())?;
        let frame = orbit::initial_frame(path, &self.initial.frame, orbit.is_some())?;
        let (attitude0, omega0) = match (&orbit, frame) {
            (Some(o), orbit::InitialFrame::Lvlh) => orbit::from_lvlh(o, &attitude0, &omega0),
            _ => (attitude0, omega0),
        };
        if frame == orbit::InitialFrame::Lvlh {
            check_rate(&omega0)
                .map_err(|m| err(loc_of(&self.initial.frame), "initial.frame", m))?;
        }

        // Spin axis: given, or the principal axis closest to the initial angular momentum.
        let spin_axis = match &self.body.spin_axis {
            Some(s) => {
                let Some(v) = unit_vector(&Vector3::from(s.value)) else {
                    return Err(err(
                        loc(s),
                        "body.spin_axis",
                        "expected a non-zero vector of three finite numbers (body axes)".into(),
                    ));
                };
                v
            }
            None => default_spin_axis(&hub, &omega0),
        };

        // Duration.
        let duration = ov.duration.unwrap_or(self.duration.value);
        let (duration_loc, duration_field) =
            from(ov.duration, loc(&self.duration), "duration", "--duration");
        if !(duration.is_finite() && duration > 0.0) {
            return Err(err(
                duration_loc,
                duration_field,
                format!(
                    "expected a positive, finite number of seconds, got {}",
                    number(duration)
                ),
            ));
        }
        if duration < MIN_DURATION {
            return Err(err(
                duration_loc,
                duration_field,
                format!(
                    "{duration:e} s is shorter than the log's time resolution; expected at \
                     least {MIN_DURATION:e} s"
                ),
            ));
        }

        // Integrator.
        let spec = self.integrator.unwrap_or_default();
        let MethodChoice {
            method,
            auto,
            adaptive,
            location: method_l,
            field: method_field,
        } = spec.method(
            path,
            ov,
            (duration, loc(&self.duration)),
            &omega0,
            &self.output,
        )?;

        // Output.
        let out = self.output.unwrap_or_default();
        let OutputSettings {
            output_rate,
            scene_rate,
            mcap_path,
            max_log_mb,
        } = out.settings(path, ov, &name, (duration, loc(&self.duration)))?;

        // Epoch.
        let epoch_unix_ns = match &self.epoch {
            None => parse_epoch(DEFAULT_EPOCH).expect("the default epoch parses"),
            Some(e) => parse_epoch(&e.value).map_err(|m| err(loc(e), "epoch", m))?,
        };
        // The log's time stamps (epoch, or 1970 for an earlier epoch, + sim time) must fit
        // Foxglove's 32-bit seconds.
        let end_s = log_origin(epoch_unix_ns) as f64 * 1e-9 + duration;
        if end_s >= LAST_LOG_SECOND as f64 {
            return Err(err(
                duration_loc,
                duration_field,
                format!(
                    "epoch {} plus {duration:e} s ends after 2106-02-07T06:28:16Z, the last \
                     time a log can stamp; shorten the run or choose an earlier epoch",
                    format_epoch(epoch_unix_ns)
                ),
            ));
        }

        let stop = conditions(path, "stop", &self.stop)?;
        let events = conditions(path, "events", &self.events)?;

        let given_shape = match &self.body.shape {
            None => None,
            Some(s) => Some(shape(path, s)?),
        };
        let mass = match &self.body.mass {
            None => None,
            Some(m) if in_positive_range(m.value) => Some(m.value),
            Some(m) => {
                return Err(err(
                    loc(m),
                    "body.mass",
                    format!(
                        "expected a positive mass from {MIN_POSITIVE:e} to {MAX_MAGNITUDE:e} \
                         kg, got {}",
                        m.value
                    ),
                ));
            }
        };
        // The effectors as written: positions about the hub's centre of mass, or, with
        // `composite: true`, about the whole spacecraft's.
        let cx = effectors::Context {
            path,
            hub: &hub,
            shape: given_shape.as_ref(),
            spin_axis,
            omega0,
            shift: Vector3::zeros(),
            notes: std::cell::RefCell::new(Vec::new()),
            orbit: orbit.clone(),
            epoch_unix_ns,
            epoch_loc: loc_of(&self.epoch),
            duration,
            hub_mass: mass,
            magnetic_model,
            field: std::cell::RefCell::new(None),
        };
        let mut built = effectors::build(&cx, &self.effectors)?;
        let mut warnings = cx.notes.into_inner();
        let mut field = cx.field.into_inner();
        let (hub, hub_mass, spin_axis, composite_hub) =
            if self.body.composite.as_ref().is_some_and(|c| c.value) {
                let (hub, mass, offset, effector_mass) = composite_remainder(
                    path,
                    &self.body,
                    hub,
                    mass,
                    (inertia_loc, inertia_field),
                    &built,
                )?;
                let spin_axis = match &self.body.spin_axis {
                    Some(_) => spin_axis,
                    None => default_spin_axis(&hub, &omega0),
                };
                if effector_mass > 0.0 {
                    // Again, with the hub's own inertia and every position moved to be about
                    // the hub's centre of mass (placement is checked where it was written).
                    let cx = effectors::Context {
                        path,
                        hub: &hub,
                        shape: given_shape.as_ref(),
                        spin_axis,
                        omega0,
                        shift: -offset,
                        notes: std::cell::RefCell::new(Vec::new()),
                        orbit: orbit.clone(),
                        epoch_unix_ns,
                        epoch_loc: loc_of(&self.epoch),
                        duration,
                        hub_mass: mass,
                        magnetic_model,
                        field: std::cell::RefCell::new(None),
                    };
                    built = effectors::build(&cx, &self.effectors)?;
                    warnings = cx.notes.into_inner();
                    field = cx.field.into_inner();
                }
                let report = CompositeHub {
                    total_mass: self.body.mass.as_ref().map(|m| m.value),
                    total_inertia: inertia,
                    effector_mass,
                    hub_offset: offset,
                };
                (hub, mass, spin_axis, Some(report))
            } else {
                (hub, mass, spin_axis, None)
            };
        // Without `body.shape` the viewer draws a box with the inertia's proportions; nothing
        // is checked against it.
        let shape = given_shape.unwrap_or_else(|| Shape::Box {
            size: hub.equivalent_box(1.0),
            orientation: UnitQuaternion::from_matrix(&hub.principal_axes),
        });

        let mut spacecraft = Spacecraft::new(hub, spin_axis);
        spacecraft.hub_mass = hub_mass;
        for e in built {
            let name = e.name().to_string();
            let duplicate = spacecraft.effectors().iter().any(|x| x.name() == name);
            spacecraft.add_effector(e).map_err(|e| {
                // A repeated name is an error of the second `name:` that spells it (a name a
                // `copies:` block made is reported at the effectors list); anything else is
                // about the hub's mass.
                if duplicate {
                    let at = nth_name_location(&source, &name, 1)
                        .or_else(|| key_location(&source, "effectors"));
                    let field = at
                        .map(|(l, c)| error::field_path_at(&source, l, c))
                        .unwrap_or_else(|| "effectors".into());
                    err(at, &field, e.to_string())
                } else {
                    err(
                        self.body.mass.as_ref().and_then(loc),
                        "body.mass",
                        e.to_string(),
                    )
                }
            })?;
        }
        if let Some(m) = &self.hub_motion {
            let motion = effectors::motion(path, m)?;
            // The state's ω integrates the prescribed ω̇, so it must start at the motion's ω(0).
            use crate::model::HubMotion;
            let start = motion.omega(0.0);
            if (omega0 - start).norm() > 1e-12 * (1.0 + start.norm()) {
                let l = self.initial.omega.as_ref().and_then(loc).or(self
                    .initial
                    .omega_rpm
                    .as_ref()
                    .and_then(loc));
                return Err(err(
                    l,
                    "initial.omega",
                    format!(
                        "with `hub_motion` the initial rates must be the motion's at t = 0, \
                         [{}, {}, {}] rad/s",
                        start[0], start[1], start[2]
                    ),
                ));
            }
            spacecraft.set_motion(Box::new(motion));
        }
        // The method contract (src/sim/support.rs): refused here with the field located, and
        // checked again before any run's first step.
        if !auto && let Some(refusal) = method.refusal(&spacecraft, duration) {
            return Err(err(method_l, method_field, refusal.to_string()));
        }
        let (method, method_choice) = if auto {
            let (m, why) = choose_method(&spacecraft, &omega0, &attitude0, duration, adaptive);
            // The closed form steps for sampling and event bracketing: bound its work as the
            // named method's is above.
            let exact_steps = duration * output_rate.max(4.0 * omega0.norm());
            if m == Method::Exact && exact_steps > 1e11 {
                let (l, f) = if ov.duration.is_some() {
                    (None, "--duration")
                } else {
                    (loc(&self.duration), "duration")
                };
                return Err(err(
                    l,
                    f,
                    format!(
                        "`auto` picked the exact solution, which would need at least \
                         {exact_steps:.1e} evaluations; the limit is 1e11 (a shorter duration)"
                    ),
                ));
            }
            (m, Some(why))
        } else {
            (method, None)
        };

        let drift_limits = drift_limits(path, self.checks, &spacecraft)?;
        warnings.splice(0..0, attitude_note);
        // `field_angle_deg` watches a permanent magnet's angle to the field.
        if !spacecraft.has_magnet {
            for (list, specs) in [("stop", &self.stop), ("events", &self.events)] {
                for (i, s) in specs.iter().enumerate() {
                    if matches!(s.value, ConditionSpec::FieldAngleDeg(_)) {
                        return Err(err(
                            loc(s),
                            &format!("{list}[{i}].field_angle_deg"),
                            "expected a `magnetic_dipole` among the effectors: the angle is \
                             between its moment and the local field"
                                .to_string(),
                        ));
                    }
                }
            }
        }

        Ok(Scenario {
            path: path.to_path_buf(),
            source,
            name,
            description: self.description.unwrap_or_default(),
            epoch_unix_ns,
            simulation: Simulation {
                spacecraft,
                omega0,
                attitude0,
                duration,
                method,
                output_rate,
                stop,
                events,
                drift_limits,
            },
            method_choice,
            mcap_path,
            scene_rate,
            compression: out.compression.unwrap_or_default(),
            shape,
            composite: composite_hub,
            warnings,
            montecarlo: self.montecarlo,
            max_log_mb,
            orbit,
            magnetic_field: field.map(|f| f.describe()),
        })
    }
}

/// The principal axis of `hub` closest to the initial angular momentum `I ω₀`.
fn default_spin_axis(hub: &RigidBody, omega0: &Vector3<f64>) -> Vector3<f64> {
    let h = hub.inertia * omega0;
    let axes = hub.principal_axes;
    let best = (0..3)
        .max_by(|&a, &b| {
            let da = axes.column(a).dot(&h).abs();
            let db = axes.column(b).dot(&h).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(2);
    axes.column(best).into_owned()
}

/// `body.composite: true`: the hub's own mass properties, the whole spacecraft's as given
/// (`total` about its centre of mass O, `mass`) minus the mass-moving `effectors` at rest, built
/// with their positions about O. With the effectors' mass m_e, first moment s and inertia J about
/// O, the hub has mass m_h = M − m_e and, O being the centre of mass of the whole
/// (m_h c + s = 0), its centre of mass at c = −s / m_h from O; by the parallel-axis theorem its
/// inertia about O is I_h + m_h (|c|² 1 − c cᵀ), so about its own centre of mass
/// I_h = I − J − m_h (|c|² 1 − c cᵀ). Returns the hub, m_h, c and m_e; refuses a remainder
/// that is not a physical body, with the numbers.
fn composite_remainder(
    path: &Path,
    body: &BodySpec,
    total: RigidBody,
    mass: Option<f64>,
    (inertia_loc, inertia_field): (Option<(u32, u32)>, &str),
    effectors: &[Box<dyn crate::model::Effector>],
) -> Result<(RigidBody, Option<f64>, Vector3<f64>, f64), ScenarioError> {
    let (m_e, first, j) = rest_mass_properties(effectors);
    if m_e == 0.0 {
        return Ok((total, mass, Vector3::zeros(), 0.0));
    }
    // 11 significant digits: the numbers as given, without the subtraction's rounding noise.
    let short = |x: f64| number(format!("{x:.10e}").parse().unwrap_or(x));
    let Some(m_total) = mass else {
        return Err(ScenarioError::at(
            path,
            loc_of(&body.composite),
            "body.mass",
            format!(
                "with `composite: true` and effectors that move mass ({} kg of them), expected \
                 `body.mass`: the whole spacecraft's mass (kg)",
                short(m_e)
            ),
        ));
    };
    let m_h = m_total - m_e;
    if !in_positive_range(m_h) {
        return Err(ScenarioError::at(
            path,
            loc_of(&body.mass),
            "body.mass",
            format!(
                "with `composite: true` this is the whole spacecraft's mass, {} kg, and the \
                 effectors that move mass weigh {} kg, leaving {} kg for the hub: the effectors \
                 outweigh the total given (the hub's own mass must be at least {MIN_POSITIVE:e} \
                 kg)",
                short(m_total),
                short(m_e),
                short(m_h)
            ),
        ));
    }
    let c = -first / m_h;
    let taken = j + m_h * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
    let remainder = total.inertia - taken;
    let remainder = 0.5 * (remainder + remainder.transpose());
    let moments = |m: &Matrix3<f64>| {
        let mut e: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
        e.sort_by(f64::total_cmp);
        e.iter()
            .map(|x| format!("{x:.6e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let refuse = |why: String| {
        ScenarioError::at(
            path,
            inertia_loc,
            inertia_field,
            format!(
                "with `composite: true` this is the whole spacecraft's inertia (principal moments \
                 {} kg m²), and the hub's own is what remains after taking away the effectors \
                 at rest, which account for principal moments {} kg m² about the whole \
                 spacecraft's centre of mass (the hub's own centre of mass, [{}, {}, {}] m from \
                 it, included): the effectors out-inertia the total given, and the remainder \
                 {why}",
                moments(&total.inertia),
                moments(&taken),
                short(c[0]),
                short(c[1]),
                short(c[2]),
            ),
        )
    };
    let hub = RigidBody::new(remainder)
        .map_err(|e| refuse(format!("is not a physical inertia tensor: {e}")))?;
    let p = hub.principal_moments;
    if p.min() < MIN_MOMENT_RATIO * p.max() {
        return Err(refuse(format!(
            "has principal moments {:.6e}, {:.6e}, {:.6e} kg m², the smallest below \
             {MIN_MOMENT_RATIO:e} of the largest",
            p[0], p[1], p[2]
        )));
    }
    Ok((hub, Some(m_h), c, m_e))
}

/// Mass, first moment (kg m) and inertia (kg m², body axes) of the mass-moving effectors at
/// rest (every effector state zero), about the origin their positions are given from. Read
/// from each effector's own momentum, so every kind (and every copy) counts as it moves.
fn rest_mass_properties(
    effectors: &[Box<dyn crate::model::Effector>],
) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let attitude = [1.0, 0.0, 0.0, 0.0];
    let (mut mass, mut first, mut inertia) = (0.0, Vector3::zeros(), Matrix3::zeros());
    for e in effectors.iter().filter(|e| e.moves_mass()) {
        let x = vec![0.0; e.num_states()];
        let at = |omega: Vector3<f64>| {
            let hub = crate::model::HubState {
                t: 0.0,
                omega,
                attitude: &attitude,
            };
            e.momentum(&hub, &x)
        };
        let still = at(Vector3::zeros());
        mass += still.mass;
        first += still.first_moment;
        for c in 0..3 {
            let column = at(Vector3::ith(c, 1.0)).angular - still.angular;
            inertia.set_column(c, &(inertia.column(c) + column));
        }
    }
    (mass, first, inertia)
}

/// Stiffness ratio above which `auto` picks the implicit method: an explicit method's stable
/// step would be a thousandth of the motion's time scale.
pub const AUTO_STIFFNESS_RATIO: f64 = 1e3;

/// What `auto` runs: `exact` for a torque-free rigid body; otherwise `radau5` when the
/// equations are stiff at the initial state (see [`crate::linearize::Stiffness::ratio`]),
/// else `dop853`. Returns the method and the reason, printed with the run.
pub fn choose_method(
    sc: &Spacecraft,
    omega0: &Vector3<f64>,
    attitude0: &UnitQuaternion<f64>,
    duration: f64,
    adaptive: Adaptive,
) -> (Method, String) {
    if sc.effectors().is_empty() && sc.motion().is_none() {
        return (
            Method::Exact,
            "auto: torque-free rigid body, so the closed-form solution (no truncation error)"
                .into(),
        );
    }
    let y0 = sc.initial_state(omega0, attitude0);
    let st = crate::linearize::stiffness(sc, 0.0, &y0, duration);
    if !st.ratio().is_finite() {
        return (
            Method::Dop853(adaptive),
            "auto: the stiffness could not be measured at the initial state, so dop853 \
             (explicit, order 8; it diagnoses stiffness if it meets it)"
                .into(),
        );
    }
    if st.ratio() > AUTO_STIFFNESS_RATIO {
        (
            Method::Radau5(adaptive),
            format!(
                "auto: stiff (fastest eigenvalue |λ| = {:.3e} 1/s is {:.1e} times the motion's \
                 rate {:.3e} 1/s, above {AUTO_STIFFNESS_RATIO:e}), so radau5 (L-stable implicit)",
                st.spectral_radius,
                st.ratio(),
                st.motion_rate
            ),
        )
    } else {
        (
            Method::Dop853(adaptive),
            format!(
                "auto: not stiff (fastest eigenvalue |λ| = {:.3e} 1/s is {:.1e} times the \
                 motion's rate {:.3e} 1/s, below {AUTO_STIFFNESS_RATIO:e}), so dop853 (explicit, \
                 order 8)",
                st.spectral_radius,
                st.ratio(),
                st.motion_rate
            ),
        )
    }
}

/// Parses one condition written like an item of `events:` or `stop:`, e.g.
/// `{nutation_angle_deg: {above: 45.0, once: true}}` (for `polhode compare --event`), with the
/// checks and messages a scenario file gets. The error names the column in `text` and the
/// field, e.g. ``column 24: field `nutation_angle_deg.for`: expected a duration ≥ 0 s …``.
pub fn parse_condition(text: &str) -> Result<Condition, String> {
    const EXPECTED: &str = "expected one condition such as `{nutation_angle_deg: {above: 45.0}}` \
                            (an `events:` list item; see docs/scenarios.md)";
    let path = Path::new("--event");
    let render = |e: ScenarioError| {
        let mut out = String::new();
        if let Some(c) = e.column {
            out += &format!("column {c}: ");
        }
        if let Some(f) = &e.field {
            let f = f.strip_prefix("event[0].").unwrap_or(f);
            out += &format!("field `{f}`: ");
        }
        out + &e.message
    };
    if text.trim().is_empty() {
        return Err(EXPECTED.into());
    }
    let spec: Spanned<ConditionSpec> = serde_saphyr::from_str_with_options(text, yaml_options())
        .map_err(|e| {
            let err = yaml_error(path, text, &e);
            if err.message.starts_with("the document is not a mapping")
                || err.message.starts_with("the file is empty")
            {
                EXPECTED.to_string()
            } else {
                render(err)
            }
        })?;
    let mut list = conditions(path, "event", std::slice::from_ref(&spec)).map_err(render)?;
    Ok(list.remove(0))
}

fn conditions(
    path: &Path,
    field: &str,
    specs: &[Spanned<ConditionSpec>],
) -> Result<Vec<Condition>, ScenarioError> {
    specs
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (quantity, th) = match &s.value {
                ConditionSpec::NutationAngleDeg(t) => (Quantity::NutationAngleDeg, t),
                ConditionSpec::AngleToPrincipal1Deg(t) => (Quantity::AngleToPrincipalDeg(0), t),
                ConditionSpec::AngleToPrincipal2Deg(t) => (Quantity::AngleToPrincipalDeg(1), t),
                ConditionSpec::AngleToPrincipal3Deg(t) => (Quantity::AngleToPrincipalDeg(2), t),
                ConditionSpec::OmegaX(t) => (Quantity::Omega(0), t),
                ConditionSpec::OmegaY(t) => (Quantity::Omega(1), t),
                ConditionSpec::OmegaZ(t) => (Quantity::Omega(2), t),
                ConditionSpec::KineticEnergy(t) => (Quantity::KineticEnergy, t),
                ConditionSpec::RateDegS(t) => (Quantity::RateDegS, t),
                ConditionSpec::FieldAngleDeg(t) => (Quantity::FieldAngleDeg, t),
            };
            let field = format!("{field}[{i}].{}", quantity.key());
            let (threshold, above) = match (th.above, th.below) {
                (Some(a), None) => (a, true),
                (None, Some(b)) => (b, false),
                _ => {
                    return Err(ScenarioError::at(
                        path,
                        loc(s),
                        field,
                        "expected exactly one of `above: <value>` or `below: <value>`",
                    ));
                }
            };
            if !threshold.is_finite() {
                return Err(ScenarioError::at(
                    path,
                    loc(s),
                    field,
                    "expected a finite threshold",
                ));
            }
            let hold = th.hold.unwrap_or(0.0);
            if !(hold.is_finite() && hold >= 0.0) {
                return Err(ScenarioError::at(
                    path,
                    loc(s),
                    format!("{field}.for"),
                    format!(
                        "expected a duration ≥ 0 s for which the condition must hold, got {}",
                        number(hold)
                    ),
                ));
            }
            Ok(Condition {
                quantity,
                threshold,
                above,
                once: th.once.unwrap_or(false),
                hold,
            })
        })
        .collect()
}

fn shape(path: &Path, s: &Spanned<ShapeSpec>) -> Result<Shape, ScenarioError> {
    let bad = |m: &str| ScenarioError::at(path, loc(s), "body.shape", m);
    let positive = |x: f64| x.is_finite() && x > 0.0;
    match &s.value {
        ShapeSpec::Box { size } => {
            if !size.iter().all(|&x| positive(x)) {
                return Err(bad("expected three positive box side lengths (m)"));
            }
            Ok(Shape::Box {
                size: Vector3::from(*size),
                orientation: UnitQuaternion::identity(),
            })
        }
        ShapeSpec::Cylinder {
            radius,
            length,
            axis,
        } => {
            if !positive(*radius) || !positive(*length) {
                return Err(bad("expected a positive radius and length (m)"));
            }
            let Some(axis) = unit_vector(&Vector3::from(axis.unwrap_or([0.0, 0.0, 1.0]))) else {
                return Err(bad("expected a non-zero cylinder axis"));
            };
            let orientation = UnitQuaternion::rotation_between(&Vector3::z(), &axis)
                .unwrap_or_else(|| {
                    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
                });
            Ok(Shape::Cylinder {
                radius: *radius,
                length: *length,
                orientation,
            })
        }
    }
}
