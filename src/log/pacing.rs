//! `--realtime X`: a run paced at X times wall-clock time, for the live view.

use crate::model::Observation;
use crate::sim::{EventRecord, Reference, Sink, Warning};
use std::io;
use std::time::{Duration, Instant};

/// Holds each sample back until its sim time, divided by `speed`, has passed on the wall
/// clock since the first sample (`--realtime X`: X seconds of sim time per second); passes
/// everything on to `inner`.
pub struct Pacing<'a, S: Sink + ?Sized> {
    inner: &'a mut S,
    speed: f64,
    /// Wall-clock instant and sim time of the first sample.
    start: Option<(Instant, f64)>,
}

impl<'a, S: Sink + ?Sized> Pacing<'a, S> {
    /// Paces `inner` at `speed` times wall-clock time (`speed > 0`, finite).
    pub fn new(inner: &'a mut S, speed: f64) -> Self {
        Pacing {
            inner,
            speed,
            start: None,
        }
    }
}

impl<S: Sink + ?Sized> Sink for Pacing<'_, S> {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> io::Result<()> {
        let (wall0, t0) = *self.start.get_or_insert((Instant::now(), o.t));
        let due = Duration::from_secs_f64(((o.t - t0) / self.speed).clamp(0.0, 1e9));
        let elapsed = wall0.elapsed();
        if due > elapsed {
            std::thread::sleep(due - elapsed);
        }
        self.inner.sample(o, y, inv)
    }
    fn event(&mut self, e: &EventRecord, o: &Observation) -> io::Result<()> {
        self.inner.event(e, o)
    }
    fn warning(&mut self, w: &Warning) -> io::Result<()> {
        self.inner.warning(w)
    }
}
