//! polhode: spacecraft attitude dynamics with energy dissipation.
//!
//! Conventions (see `docs/conventions.md`): SI units; the attitude quaternion maps body
//! vectors to inertial vectors (`v_N = R(q) v_B`), Hamilton product, stored scalar-first
//! `(w, x, y, z)` in state vectors; `q̇ = ½ q ⊗ (0, ω_B)`.
//!
//! Layers, bottom up: [`integrate`] (methods behind one stepping interface), [`exact`] (the
//! closed-form torque-free reference), [`orbit`] (the analytic orbit and LVLH frame that
//! environment effectors read), [`model`] (hub plus effectors as an ODE system),
//! [`scenario`] (the YAML contract), [`sim`] (the run loop: sampling, events, invariants),
//! [`log`] (MCAP output), [`linearize`], and the command-line front end in [`cli`].

pub mod bench;
pub mod cli;
pub mod compare;
pub mod effectors;
pub mod exact;
pub mod integrate;
pub mod linearize;
pub mod log;
pub mod model;
pub mod montecarlo;
pub mod orbit;
pub mod plot;
pub mod scenario;
pub mod sim;
pub mod timefmt;
