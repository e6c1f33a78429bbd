//! A sink that hands what a run produces to another thread, so that the run and the sink that
//! writes it (an MCAP logger, say) proceed in parallel.

use super::{EventRecord, Outcome, Reference, Sink, Warning};
use crate::model::Observation;
use std::io;
use std::sync::mpsc::{Receiver, SyncSender};

/// What a run handed its sink, kept to be replayed into another sink.
#[derive(Debug, Clone)]
pub enum Record {
    /// [`Sink::sample`]'s arguments.
    Sample(Observation, Vec<f64>, Reference),
    /// [`Sink::event`]'s arguments.
    Event(EventRecord, Observation),
    /// [`Sink::warning`]'s argument.
    Warning(Warning),
}

/// One message down a [`Relay`]'s channel.
#[derive(Debug)]
pub enum Relayed {
    /// Records, in the order the run produced them.
    Records(Vec<Record>),
    /// The run's end: what [`super::run`] returned.
    Finished(Box<io::Result<Outcome>>),
}

/// Records handed on together: one channel message per batch, not per sample.
const BATCH: usize = 256;

/// A [`Sink`] that sends what a run hands it, in batches and in order, down a channel, and
/// then the run's result ([`Relay::finish`]); the receiving thread hands them on to the sink
/// that does the work ([`receive_run`]). A send that fails (the receiver has gone, after an
/// error of its own) fails the run with [`io::ErrorKind::BrokenPipe`].
pub struct Relay {
    batch: Vec<Record>,
    to: SyncSender<Relayed>,
}

impl Relay {
    /// A relay sending down `to`.
    pub fn new(to: SyncSender<Relayed>) -> Self {
        Relay {
            batch: Vec::with_capacity(BATCH),
            to,
        }
    }

    /// Sends the records not yet sent, then the run's result `outcome`. Returns whether the
    /// receiver took them.
    pub fn finish(mut self, outcome: io::Result<Outcome>) -> bool {
        self.flush().is_ok() && self.to.send(Relayed::Finished(Box::new(outcome))).is_ok()
    }

    fn flush(&mut self) -> io::Result<()> {
        if self.batch.is_empty() {
            return Ok(());
        }
        let batch = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH));
        self.to
            .send(Relayed::Records(batch))
            .map_err(|_| io::Error::new(io::ErrorKind::BrokenPipe, "the writer stopped"))
    }

    fn push(&mut self, record: Record) -> io::Result<()> {
        self.batch.push(record);
        if self.batch.len() >= BATCH {
            self.flush()?;
        }
        Ok(())
    }
}

impl Sink for Relay {
    fn sample(&mut self, o: &Observation, y: &[f64], inv: &Reference) -> io::Result<()> {
        self.push(Record::Sample(o.clone(), y.to_vec(), *inv))
    }

    fn event(&mut self, e: &EventRecord, o: &Observation) -> io::Result<()> {
        self.push(Record::Event(e.clone(), o.clone()))
    }

    fn warning(&mut self, w: &Warning) -> io::Result<()> {
        self.push(Record::Warning(w.clone()))
    }
}

/// Hands one run's records, received from a [`Relay`] on `from`, to `sink` in order, and
/// returns the run's result; an error of `sink`'s is returned at once (the caller drops `from`
/// to stop the run), and a relay that stops without finishing is a
/// [`io::ErrorKind::BrokenPipe`].
pub fn receive_run(from: &Receiver<Relayed>, sink: &mut dyn Sink) -> io::Result<Outcome> {
    loop {
        let message = from.recv().map_err(|_| {
            io::Error::new(
                io::ErrorKind::BrokenPipe,
                "the run stopped without a result",
            )
        })?;
        match message {
            Relayed::Records(records) => {
                for record in &records {
                    match record {
                        Record::Sample(o, y, inv) => sink.sample(o, y, inv)?,
                        Record::Event(e, o) => sink.event(e, o)?,
                        Record::Warning(w) => sink.warning(w)?,
                    }
                }
            }
            Relayed::Finished(outcome) => return *outcome,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{self, Overrides, Scenario};
    use crate::sim::{Control, Memory, Status, run};
    use std::path::Path;
    use std::sync::atomic::AtomicBool;
    use std::sync::mpsc::sync_channel;

    /// A short scene with events (the nutation angle crosses 45° and 80°) and many samples.
    fn scene() -> Scenario {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/montecarlo-sink.yaml");
        scenario::load(&path, &Overrides::default()).unwrap()
    }

    /// The run on a thread of its own, relayed into `sink` on this one.
    fn relayed(sc: &Scenario, interrupt: &AtomicBool, sink: &mut dyn Sink) -> io::Result<Outcome> {
        std::thread::scope(|scope| {
            let (to, from) = sync_channel(2);
            scope.spawn(move || {
                let mut relay = Relay::new(to);
                let outcome = run(
                    sc,
                    &mut relay,
                    Control {
                        interrupt,
                        progress: None,
                    },
                );
                relay.finish(outcome);
            });
            receive_run(&from, sink)
        })
    }

    #[test]
    fn a_relayed_run_hands_on_what_a_direct_one_receives_in_the_same_order() {
        let sc = scene();
        let mut direct = Memory::with_states();
        let mut direct_outcome = run(&sc, &mut direct, Control::uninterrupted()).unwrap();
        let mut through = Memory::with_states();
        let mut outcome = relayed(&sc, &AtomicBool::new(false), &mut through).unwrap();
        // The wall-clock time is the one thing allowed to differ.
        (direct_outcome.wall_time, outcome.wall_time) = (0.0, 0.0);
        assert!(direct.samples.len() > 2 * BATCH, "several batches");
        assert_eq!(direct.events.len(), 2, "both events");
        assert_eq!(format!("{direct:?}"), format!("{through:?}"));
        assert_eq!(format!("{direct_outcome:?}"), format!("{outcome:?}"));
    }

    #[test]
    fn an_interrupted_run_is_reported_through_the_relay() {
        let outcome = relayed(&scene(), &AtomicBool::new(true), &mut Memory::new()).unwrap();
        assert_eq!(outcome.status, Status::Interrupted);
    }

    /// A sink that fails at its `limit`-th sample.
    struct Failing {
        samples: usize,
        limit: usize,
    }

    impl Sink for Failing {
        fn sample(&mut self, _: &Observation, _: &[f64], _: &Reference) -> io::Result<()> {
            self.samples += 1;
            if self.samples == self.limit {
                return Err(io::Error::other("disk full"));
            }
            Ok(())
        }
        fn event(&mut self, _: &EventRecord, _: &Observation) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_failing_writer_stops_the_run_instead_of_waiting_for_it() {
        let sc = scene();
        let mut failing = Failing {
            samples: 0,
            limit: BATCH + 10,
        };
        let (to, from) = sync_channel(1);
        let runner = std::thread::spawn(move || {
            let mut relay = Relay::new(to);
            let outcome = run(&sc, &mut relay, Control::uninterrupted());
            let kind = outcome.as_ref().err().map(io::Error::kind);
            relay.finish(outcome);
            kind
        });
        let error = receive_run(&from, &mut failing).unwrap_err();
        assert_eq!(error.to_string(), "disk full");
        drop(from);
        assert_eq!(runner.join().unwrap(), Some(io::ErrorKind::BrokenPipe));
    }
}
