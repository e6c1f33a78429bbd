//! A sink that keeps a run's samples and events in memory.

use super::{EventRecord, Reference, Sink, Warning};
use crate::model::Observation;

/// Keeps every output sample's observation (and, if asked, its full state vector), every event
/// and every warning, in time order.
#[derive(Debug, Default)]
pub struct Memory {
    /// The observation at each output sample.
    pub samples: Vec<Observation>,
    /// The state vector at each output sample, when built with [`Memory::with_states`].
    pub states: Vec<Vec<f64>>,
    /// Events at their located times.
    pub events: Vec<EventRecord>,
    /// Warnings the run went on from.
    pub warnings: Vec<Warning>,
    /// Whether to keep the state vectors.
    keep_states: bool,
}

impl Memory {
    /// Keeps observations, events and warnings.
    pub fn new() -> Self {
        Memory::default()
    }

    /// Also keeps each sample's full state vector (hub, then effector states).
    pub fn with_states() -> Self {
        Memory {
            keep_states: true,
            ..Memory::default()
        }
    }
}

impl Sink for Memory {
    fn sample(&mut self, o: &Observation, y: &[f64], _: &Reference) -> std::io::Result<()> {
        self.samples.push(o.clone());
        if self.keep_states {
            self.states.push(y.to_vec());
        }
        Ok(())
    }

    fn event(&mut self, e: &EventRecord, _: &Observation) -> std::io::Result<()> {
        self.events.push(e.clone());
        Ok(())
    }

    fn warning(&mut self, w: &Warning) -> std::io::Result<()> {
        self.warnings.push(w.clone());
        Ok(())
    }
}
