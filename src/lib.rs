//! polhode: spacecraft attitude dynamics with energy dissipation.
//!
//! Conventions (see `docs/conventions.md`): SI units; the attitude quaternion maps body
//! vectors to inertial vectors (`v_N = R(q) v_B`), Hamilton product, stored scalar-first
//! `(w, x, y, z)` in state vectors; `q̇ = ½ q ⊗ (0, ω_B)`.
//!
//! # The front door
//!
//! A run is a [`sim::Simulation`]: a [`model::Spacecraft`] (a rigid hub plus
//! [`model::Effector`]s such as [`effectors::energy_sink::EnergySink`]), its initial rates and
//! attitude, a [`sim::Method`], a duration, the output rate, the [`sim::Condition`]s that stop
//! or mark the run, and the drift checks. [`sim::run`] integrates it into any [`sim::Sink`]:
//! [`sim::Memory`] keeps the samples, [`log::McapLogger`] writes the MCAP log,
//! [`log::samples::SampleTable`] the CSV and Parquet tables. Front ends build a `Simulation`:
//! code directly, the YAML loader ([`scenario::load`], whose [`scenario::Scenario`] is a
//! `Simulation` with its provenance and output settings), the command line ([`cli`]) and the
//! Python package (`python/`) over the loader.
//!
//! ## A body built in code
//!
//! A body spun about its axis of least inertia, with an energy sink (Thomson & Reiter 1960)
//! draining its kinetic energy at fixed |H|: it ends in a flat spin about the axis of most
//! inertia, the fate of Explorer 1.
//!
//! ```
//! use nalgebra::{Matrix3, UnitQuaternion, Vector3};
//! use polhode::effectors::energy_sink::EnergySink;
//! use polhode::model::{RigidBody, Spacecraft};
//! use polhode::sim::{self, Adaptive, Condition, Control, Memory, Method, Quantity, Simulation};
//!
//! let inertia = Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 14.0)); // kg m²
//! let mut spacecraft = Spacecraft::new(RigidBody::new(inertia)?, Vector3::x());
//! let sink = EnergySink { name: "sink".into(), coefficient: 0.5, inertia };
//! spacecraft.add_effector(Box::new(sink)).map_err(|e| e.to_string())?;
//!
//! let tolerances = Adaptive { rtol: 1e-9, atol: 1e-12, max_step: f64::INFINITY };
//! let omega0 = Vector3::new(2.0, 0.02, 0.0); // rad/s, body frame
//! let mut run = Simulation::new(
//!     spacecraft,
//!     omega0,
//!     UnitQuaternion::identity(),
//!     2000.0, // s
//!     Method::Dop853(tolerances),
//! );
//! run.events.push(Condition::crossing(Quantity::NutationAngleDeg, 80.0, true));
//!
//! let mut memory = Memory::new();
//! let outcome = sim::run(&run, &mut memory, Control::uninterrupted())?;
//! let flat_spin = &memory.events[0];
//! assert!(flat_spin.t > 0.0 && flat_spin.t < 2000.0);
//! // The sink keeps |H|; the energy balance T + W holds to the integration error.
//! assert!(outcome.drift.h_norm_rel.abs() < 1e-8);
//! assert!(outcome.drift.energy_rel.abs() < 1e-8);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## The same run logged to MCAP
//!
//! [`scenario::Scenario::from_simulation`] gives a code-built run the log settings a file
//! would have had (default epoch, no orbit, a box for the viewers); the log opens in Foxglove
//! and Rerun like the command line's.
//!
//! ```
//! use nalgebra::{Matrix3, UnitQuaternion, Vector3};
//! use polhode::log::McapLogger;
//! use polhode::model::{RigidBody, Spacecraft};
//! use polhode::scenario::Scenario;
//! use polhode::sim::{self, Adaptive, Control, Method, Simulation};
//!
//! let inertia = Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 14.0)); // kg m²
//! let spacecraft = Spacecraft::new(RigidBody::new(inertia)?, Vector3::x());
//! let tolerances = Adaptive { rtol: 1e-9, atol: 1e-12, max_step: f64::INFINITY };
//! let run = Simulation::new(
//!     spacecraft,
//!     Vector3::new(0.02, 1.0, 0.02), // rad/s: near the intermediate axis, so it tumbles
//!     UnitQuaternion::identity(),
//!     60.0, // s
//!     Method::Dop853(tolerances),
//! );
//! let scene = Scenario::from_simulation("intermediate axis", run);
//! let path = std::env::temp_dir().join("polhode-doc-intermediate-axis.mcap");
//! let mut logger = McapLogger::create(&path, &scene, scene.omega0.norm())?;
//! let outcome = sim::run(&scene, &mut logger, Control::uninterrupted())?;
//! let written = logger.finish(&scene, &scene.method.describe(), &outcome)?;
//! assert!(std::fs::metadata(&written)?.len() > 0);
//! # std::fs::remove_file(&written)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## A scenario file
//!
//! ```
//! use polhode::scenario::{self, Overrides};
//! use polhode::sim::{self, Control, Memory};
//! use std::path::Path;
//!
//! let racket = scenario::load(Path::new("scenarios/tennis-racket.yaml"), &Overrides::default())?;
//! let mut memory = Memory::new();
//! let outcome = sim::run(&racket, &mut memory, Control::uninterrupted())?;
//! // The intermediate-axis spin flips: its nutation angle passes 90° (Landau & Lifshitz §37).
//! assert!(!outcome.events.is_empty());
//! assert_eq!(memory.samples.last().map(|o| o.t), Some(racket.duration));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Layers
//!
//! Bottom up: [`integrate`] (methods behind one stepping interface), [`exact`] (the
//! closed-form torque-free reference), [`orbit`] (the analytic orbit and LVLH frame that
//! environment effectors read), [`model`] (hub plus effectors as an ODE system),
//! [`effectors`], [`sim`] (the run loop: sampling, events, invariants), [`scenario`] (the YAML
//! front end), [`log`] (MCAP output and tables), [`linearize`], [`montecarlo`], [`compare`],
//! [`bench`](mod@bench), and the command line in [`cli`]. `sim` knows nothing of YAML.

#![deny(missing_docs)]

pub mod averaging;
pub mod bench;
pub mod chebyshev;
pub mod cli;
pub mod compare;
pub mod cpu;
pub mod effectors;
pub mod exact;
pub mod integrate;
pub mod lanes;
pub mod linearize;
pub mod log;
pub mod model;
pub mod montecarlo;
pub mod orbit;
pub mod outputs;
pub mod plot;
pub mod resources;
pub mod scenario;
pub mod sim;
pub mod sincos;
pub mod timefmt;

/// The README's Rust example: through this item `cargo test --doc` compiles and runs every
/// `rust` block of README.md (its other blocks are tagged `sh`, `python`, `text`, `yaml` and
/// are not compiled), so the code shown on the front page cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeExamples;
