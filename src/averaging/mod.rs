//! Averaged (secular) propagation: the slow evolution of a slowly dissipating spinner, from
//! its rates averaged over one period of the exact torque-free motion (first-order
//! averaging; Sanders, Verhulst & Murdock, *Averaging Methods in Nonlinear Dynamical
//! Systems*). Equations, treatment of the separatrix, validity and accuracy:
//! `docs/averaging.md`.
//!
//! - [`motion`]: the torque-free motion at a slow state (|H|, T) in closed form: its
//!   circulation, period, mean precession rate and second moments ⟨ω ωᵀ⟩.
//! - [`stepper`]: the slow system stepped by DOP853, and the full state rebuilt from the exact
//!   solution for sampling, events and logs.

pub mod eddy;
pub mod field_moments;
pub mod forced;
pub mod motion;
pub mod stepper;

pub use stepper::{AveragedStepper, refusal};

/// Largest ratio ε of the fast period to the dissipation time at which the averaged method
/// runs (dimensionless): its error in the slow variables is O(ε).
pub const MAX_EPSILON: f64 = 1e-2;

/// Largest ratio of the fast period to the period of an orbit-driven forcing (the orbit
/// period, for eddy currents in the geomagnetic field) at which the averaged method averages
/// the two independently (dimensionless).
pub const MAX_FAST_TO_FORCING: f64 = 1e-2;

/// Within 1 − m < this of the separatrix the polhode period (which diverges there) is left out
/// of ε (dimensionless).
pub const SEPARATRIX_LAYER: f64 = 1e-2;

#[cfg(test)]
mod tests;
