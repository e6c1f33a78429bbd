//! The time grid shared by the fixed-step methods.

/// Step n of a fixed-step method ends at `t0 + n·dt`, computed afresh rather than accumulated
/// (so the integrated time never drifts from the label), and a step that would end past
/// `t_end`, or within 1e-9·dt of it, ends exactly there. A step shortened to an earlier `t_end`
/// does not advance the grid: the next one ends on the grid point it fell short of, so no
/// step exceeds `dt`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedGrid {
    t0: f64,
    dt: f64,
    /// Grid steps completed.
    n: u64,
}

impl FixedGrid {
    /// The grid from `t0` (s) with step `dt` (s, > 0).
    pub fn new(t0: f64, dt: f64) -> Self {
        FixedGrid { t0, dt, n: 0 }
    }

    /// The nominal step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Where the next step ends, never past `t_end`, and whether that is a grid point.
    pub fn next(&self, t_end: f64) -> (f64, bool) {
        let grid = self.t0 + (self.n + 1) as f64 * self.dt;
        if grid >= t_end - 1e-9 * self.dt {
            (t_end, grid <= t_end + 1e-9 * self.dt)
        } else {
            (grid, true)
        }
    }

    /// Records a completed step that [`FixedGrid::next`] said ended `on_grid`.
    pub fn advance(&mut self, on_grid: bool) {
        if on_grid {
            self.n += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::FixedGrid;

    #[test]
    fn a_shortened_step_does_not_move_the_grid() {
        let mut g = FixedGrid::new(0.0, 0.3);
        assert_eq!(g.next(10.0), (0.3, true));
        g.advance(true);
        // An earlier end cuts the step short…
        let (t, on) = g.next(0.4);
        assert_eq!((t, on), (0.4, false));
        g.advance(on);
        // …and the next step ends on the grid point it fell short of.
        assert_eq!(g.next(10.0), (0.6, true));
        // Landing within 1e-9·dt of the end counts as the end, on the grid.
        assert_eq!(g.next(0.6 + 1e-12), (0.6 + 1e-12, true));
    }
}
