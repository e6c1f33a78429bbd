//! Watching conditions along a run: when each `stop:` or `events:` condition fires.
//!
//! A condition holds while its margin is positive. Without `for:` it fires at each up-crossing
//! of the margin (or at t = 0 when it holds there); with `for: S` it fires once it has held
//! continuously for S seconds, and the event's time is the start of that interval (it is
//! *known* S seconds later, when the run reaches it). After firing, a condition must stop
//! holding before it can fire again; with `once: true` it never fires again.

use super::Condition;

/// Where a watched condition stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Not holding.
    Idle,
    /// Holding since this time (s), not yet for its `for:` duration.
    Holding(f64),
    /// Holding, and already fired for this interval.
    Fired,
    /// Fired with `once: true`: no longer watched.
    Done,
}

/// One condition being watched.
#[derive(Debug, Clone)]
pub(super) struct Watch<'a> {
    /// The condition.
    pub condition: &'a Condition,
    /// Whether firing ends the run (`stop:`).
    pub terminal: bool,
    phase: Phase,
}

/// A condition that fired.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Firing {
    /// The event's time (s): when the condition became true.
    pub t: f64,
    /// When the run knew it (s): `t` plus the `for:` duration.
    pub confirmed: f64,
}

impl<'a> Watch<'a> {
    /// Starts watching `condition`.
    pub fn new(condition: &'a Condition, terminal: bool) -> Self {
        Watch {
            condition,
            terminal,
            phase: Phase::Idle,
        }
    }

    /// Whether it can still fire.
    pub fn active(&self) -> bool {
        self.phase != Phase::Done
    }

    /// The margin at t = 0 (`g0`): a condition that holds there starts holding at 0.
    pub fn start(&mut self, g0: f64) -> Option<Firing> {
        if g0 > 0.0 {
            self.begin(0.0, 0.0, g0)
        } else {
            None
        }
    }

    /// Advances over one check interval `[a, b]` with margins `ga`, `gb`. `locate(up)` finds
    /// the crossing inside it: upward (`true`) or downward. Called for consecutive intervals.
    pub fn advance(
        &mut self,
        a: f64,
        b: f64,
        ga: f64,
        gb: f64,
        mut locate: impl FnMut(bool) -> f64,
    ) -> Option<Firing> {
        let _ = a;
        let up = ga <= 0.0 && gb > 0.0;
        let down = ga > 0.0 && gb <= 0.0;
        match self.phase {
            Phase::Done => None,
            Phase::Idle if up => {
                let t = locate(true);
                self.begin(t, b, gb)
            }
            Phase::Idle => None,
            Phase::Holding(since) => {
                let due = since + self.condition.hold;
                if down {
                    let t_down = locate(false);
                    self.phase = Phase::Idle;
                    (t_down >= due).then(|| self.fire(since))
                } else if b >= due {
                    Some(self.fire(since))
                } else {
                    None
                }
            }
            Phase::Fired => {
                if down {
                    self.phase = Phase::Idle;
                }
                None
            }
        }
    }

    /// Whether [`Watch::advance`] over an interval ending at `b` with margins `ga`, `gb` would
    /// neither fire nor change the watch: the margin keeps its side (no crossing to locate,
    /// and `(ga > 0) == (gb > 0)` rules out NaN ends that could bracket one), and a condition
    /// holding toward its `for:` duration does not complete it by `b`.
    #[inline(always)]
    pub fn unmoved(&self, ga: f64, gb: f64, b: f64) -> bool {
        let completes = match self.phase {
            Phase::Holding(since) => b >= since + self.condition.hold,
            _ => false,
        };
        (ga > 0.0) == (gb > 0.0) && !completes
    }

    /// The condition became true at `t`; the interval checked runs to `b` with margin `gb`.
    fn begin(&mut self, t: f64, b: f64, gb: f64) -> Option<Firing> {
        if self.condition.hold == 0.0 || (gb > 0.0 && b >= t + self.condition.hold) {
            Some(self.fire(t))
        } else {
            self.phase = Phase::Holding(t);
            None
        }
    }

    fn fire(&mut self, since: f64) -> Firing {
        self.phase = if self.condition.once {
            Phase::Done
        } else {
            Phase::Fired
        };
        Firing {
            t: since,
            confirmed: since + self.condition.hold,
        }
    }
}

/// How many times a margin's change over a step (or over the step before, scaled to this
/// step's size) both of the step's ends must lie from zero for the interior checks to be
/// skipped. Over a step that resolves the motion, a margin is close to a quadratic in time,
/// whose excursion beyond the step's ends is at most half that change; 8 leaves a factor 16
/// for what the quadratic model misses.
const INTERIOR_SAFETY: f64 = 8.0;

/// Whether a margin with values `g_before`, `ga`, `gb` at the starts of the last step (size
/// `h_before`), of this step (size `h`), and at its end cannot cross zero inside this step:
/// both ends on one side, each farther from zero than [`INTERIOR_SAFETY`] times the larger
/// of the step's change and the last step's change scaled to `h`. `false` when anything is
/// unknown or not finite (then the interior points are checked).
pub(super) fn far_from_crossing(g_before: f64, ga: f64, gb: f64, h_before: f64, h: f64) -> bool {
    if !(h_before > 0.0 && g_before.is_finite() && ga.is_finite() && gb.is_finite()) {
        return false;
    }
    let change = (gb - ga).abs().max((ga - g_before).abs() * h / h_before);
    (ga > 0.0) == (gb > 0.0) && ga.abs().min(gb.abs()) > INTERIOR_SAFETY * change
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Quantity;

    /// Steps a watch over a sampled margin g(t) on a uniform grid, locating crossings by
    /// linear interpolation.
    fn run(c: &Condition, g: impl Fn(f64) -> f64, t_end: f64, h: f64) -> Vec<Firing> {
        let mut w = Watch::new(c, false);
        let mut out: Vec<Firing> = w.start(g(0.0)).into_iter().collect();
        let mut a = 0.0;
        while a < t_end {
            let b = a + h;
            let (ga, gb) = (g(a), g(b));
            let cross = |_up: bool| a + (b - a) * ga / (ga - gb);
            out.extend(w.advance(a, b, ga, gb, cross));
            a = b;
        }
        out
    }

    fn below(threshold: f64, once: bool, hold: f64) -> Condition {
        Condition {
            once,
            hold,
            ..Condition::crossing(Quantity::NutationAngleDeg, threshold, false)
        }
    }

    /// A decaying oscillation x(t) = 10 e^{−t/20} cos t crosses "|x| below 1" dozens of times.
    fn ringing(t: f64) -> f64 {
        1.0 - (10.0 * (-t / 20.0).exp() * t.cos()).abs()
    }

    /// Over steps that resolve the motion (up to 1 rad of phase per step), a margin
    /// g(t) = sin t + c that crosses zero and back inside a step, with both ends on one side,
    /// is never judged far from crossing; and far from zero the judgement saves the checks.
    #[test]
    fn interior_checks_are_kept_wherever_a_margin_crosses_twice_inside_a_step() {
        let (mut hidden, mut skipped) = (0, 0);
        for &h in &[0.05, 0.2, 0.5, 1.0] {
            for j in 0..400 {
                let c = -1.2 + 2.4 * j as f64 / 399.0;
                let g = |t: f64| t.sin() + c;
                let h_before = h * (0.6 + 0.8 * ((j * 7) % 11) as f64 / 10.0);
                let mut t0 = 0.013 * j as f64;
                while t0 < 20.0 {
                    let t1 = t0 + h;
                    let (gp, ga, gb) = (g(t0 - h_before), g(t0), g(t1));
                    let far = far_from_crossing(gp, ga, gb, h_before, h);
                    // Dense sampling of the step: does g take the other sign inside?
                    let crosses = (1..1000).any(|k| {
                        let gk = g(t0 + h * k as f64 / 1000.0);
                        (gk > 0.0) != (ga > 0.0)
                    });
                    if crosses && (ga > 0.0) == (gb > 0.0) {
                        hidden += 1;
                        assert!(!far, "h {h}, c {c}, t0 {t0}: a double crossing judged far");
                    }
                    skipped += usize::from(far);
                    t0 = t1;
                }
            }
        }
        assert!(
            hidden > 30,
            "{hidden} double crossings: the test must meet some"
        );
        assert!(skipped > 10_000, "{skipped} steps skipped");
        // Unknowns: no judgement.
        assert!(!far_from_crossing(f64::NAN, -1.0, -1.0, 1.0, 1.0));
        assert!(!far_from_crossing(-1.0, -1.0, -1.0, 0.0, 1.0));
        assert!(far_from_crossing(-1.0, -1.0, -1.0, 1.0, 1.0));
    }

    #[test]
    fn without_options_every_crossing_fires() {
        let f = run(&below(0.0, false, 0.0), ringing, 100.0, 1e-3);
        // |x| < 1 near each zero π/2 + kπ of cos t while the envelope 10 e^{−t/20} is above 1
        // (t < 20 ln 10 = 46.05 s: k = 0..14, 15 zeros), and for good after the last of them.
        assert_eq!(f.len(), 15);
        for (k, firing) in f.iter().enumerate() {
            let zero = std::f64::consts::FRAC_PI_2 + k as f64 * std::f64::consts::PI;
            // Each firing is where |x| falls through 1, just before its zero of cos t.
            assert!(ringing(firing.t).abs() < 1e-3, "{k}: {}", firing.t);
            assert!(
                firing.t < zero && zero - firing.t < std::f64::consts::FRAC_PI_2,
                "{k}: {}",
                firing.t
            );
        }
    }

    #[test]
    fn once_fires_at_the_first_crossing_only() {
        let all = run(&below(0.0, false, 0.0), ringing, 100.0, 1e-3);
        let once = run(&below(0.0, true, 0.0), ringing, 100.0, 1e-3);
        assert_eq!(once.len(), 1);
        assert_eq!(once[0], all[0]);
    }

    #[test]
    fn for_fires_at_the_start_of_the_interval_that_held() {
        // The envelope 10 e^{−t/20} falls to 1 at t* = 20 ln 10 = 46.0517 s; |x| < 1 from the
        // last zero-neighbourhood crossing before t* on. With `for: 10` only an interval of
        // 10 s qualifies: the one that starts at the last up-crossing of g, before t*.
        let f = run(&below(0.0, false, 10.0), ringing, 100.0, 1e-3);
        assert_eq!(f.len(), 1, "{f:?}");
        let all = run(&below(0.0, false, 0.0), ringing, 100.0, 1e-3);
        let last = all.last().unwrap();
        assert_eq!(f[0].t, last.t);
        assert!((f[0].confirmed - (last.t + 10.0)).abs() < 1e-12);
        assert!(f[0].t < 20.0 * 10f64.ln() && f[0].t > 40.0, "{}", f[0].t);
        // Each earlier interval of holding is shorter than π: `for: 3.2` also finds only the last.
        let short = run(&below(0.0, false, 3.2), ringing, 100.0, 1e-3);
        assert_eq!(short.len(), 1);
        assert_eq!(short[0].t, last.t);
    }

    #[test]
    fn a_condition_that_stops_holding_early_does_not_fire() {
        // Holds on [1, 3] only: `for: 2.5` never fires, `for: 1.5` fires at 1.
        let g = |t: f64| if (1.0..3.0).contains(&t) { 1.0 } else { -1.0 };
        let cross = |c: &Condition| {
            let mut w = Watch::new(c, false);
            let mut out = vec![];
            let h = 0.25;
            let mut a = 0.0;
            while a < 10.0 {
                let b = a + h;
                // Exact crossing times of the step function.
                let locate = |up: bool| if up { 1.0 } else { 3.0 };
                out.extend(w.advance(a, b, g(a), g(b), locate));
                a = b;
            }
            out
        };
        assert!(cross(&below(0.0, false, 2.5)).is_empty());
        let f = cross(&below(0.0, false, 1.5));
        assert_eq!(
            f,
            vec![Firing {
                t: 1.0,
                confirmed: 2.5
            }]
        );
    }

    /// Wherever `unmoved` says an interval changes nothing, `advance` over it neither fires,
    /// nor locates a crossing, nor changes the watch's phase; and the claim is made for the
    /// common intervals (margins on one side, nothing due), in every phase.
    #[test]
    fn an_unmoved_watch_is_what_advance_leaves_unchanged() {
        let conditions = [
            below(0.0, false, 0.0),
            below(0.0, true, 0.0),
            below(0.0, false, 2.0),
        ];
        let margins = [-1.0, -0.0, 0.0, 1e-300, 1.0, f64::NAN, f64::INFINITY];
        let (mut claimed, mut checked) = (0, 0);
        let mut phases = Vec::new();
        for c in &conditions {
            // The phases: idle; holding since 0.5 (with `for:`); fired; done (with `once`).
            let mut watches = vec![Watch::new(c, false)];
            let mut w = Watch::new(c, false);
            w.start(1.0);
            watches.push(w);
            for w in &mut watches.clone() {
                w.advance(0.0, 1.0, -1.0, 1.0, |_| 0.5);
                watches.push(w.clone());
            }
            for w in &watches {
                for &ga in &margins {
                    for &gb in &margins {
                        for b in [1.0, 2.49, 2.5, 10.0] {
                            checked += 1;
                            if !w.unmoved(ga, gb, b) {
                                continue;
                            }
                            claimed += 1;
                            let mut after = w.clone();
                            let fired = after.advance(b - 0.25, b, ga, gb, |_| {
                                panic!("a crossing located in an unmoved interval")
                            });
                            assert_eq!(fired, None, "{w:?} over ({ga}, {gb}) to {b}");
                            assert_eq!(after.phase, w.phase, "{w:?} over ({ga}, {gb}) to {b}");
                        }
                    }
                }
            }
            phases.extend(watches.iter().map(|w| w.phase));
            for w in &watches {
                assert!(w.unmoved(-1.0, -1.0, 1.0) || matches!(w.phase, Phase::Holding(_)));
                assert!(!w.unmoved(-1.0, 1.0, 1.0) && !w.unmoved(1.0, -1.0, 1.0));
            }
        }
        assert!(claimed > checked / 4, "{claimed} of {checked}");
        assert!(phases.contains(&Phase::Idle) && phases.contains(&Phase::Fired));
        assert!(phases.contains(&Phase::Done), "{phases:?}");
        assert!(
            phases.iter().any(|p| matches!(p, Phase::Holding(_))),
            "{phases:?}"
        );
    }

    #[test]
    fn holding_at_the_start_counts_from_zero() {
        let f = run(&below(0.0, false, 2.0), |_| 1.0, 5.0, 0.5);
        assert_eq!(
            f,
            vec![Firing {
                t: 0.0,
                confirmed: 2.0
            }]
        );
    }
}
