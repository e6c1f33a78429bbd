//! The energy-sink class in the lanes: a rigid hub with principal body axes and one
//! `energy_sink` torque (the scalar path's `Spacecraft` with that one effector, whose
//! right-hand side is `Spacecraft::torque_rhs` with Euler's equations in their three-term
//! form), integrated by the lockstep ensemble of [`super::ensemble`] with dop853 or dopri5.
//! Its run is [`SinkRun`]; its system in lanes, [`SinkLanes`], written with the operations
//! (and their order) of the scalar code, so each lane's steps and state are bit for bit those
//! of the scalar method on that run's `Spacecraft` (the tests at the end compare the
//! right-hand side and the observation; tests/lanes_campaign.rs whole campaigns).
//!
//! The torque is τ = −c ω⊥, ω⊥ = ω − (ω·Ĥ) Ĥ with Ĥ = Iω/|Iω| (docs/effectors.md,
//! "energy_sink"); the one state beside ω and q is the dissipated energy, Ė = c |ω⊥|².

use super::ensemble::{LaneObservation, LaneRun, LaneSystem};
use super::{Lane, LaneMask, linalg};
use crate::effectors::energy_sink::EnergySink;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// States of a run: ω (rad/s, 3), q (w, x, y, z) and the dissipated energy (J): the scalar
/// `Spacecraft`'s layout for this scene.
pub const DIM: usize = 8;

/// One run of the class.
#[derive(Debug, Clone)]
pub struct SinkRun {
    /// The hub's inertia (kg m², body axes; diagonal: principal axes).
    pub hub_inertia: Matrix3<f64>,
    /// The diagonal of the hub's inverse inertia as the scalar `RigidBody` holds it (1/(kg m²)).
    pub inverse_inertia: [f64; 3],
    /// Euler's coefficients `[(I₂−I₃)/I₁, (I₃−I₁)/I₂, (I₁−I₂)/I₃]` as the scalar
    /// `Spacecraft` holds them.
    pub euler_coefficients: [f64; 3],
    /// The energy sink.
    pub sink: EnergySink,
    /// Initial body rate ω₀ (rad/s, body axes).
    pub omega0: Vector3<f64>,
    /// Initial attitude (body to inertial).
    pub attitude0: UnitQuaternion<f64>,
    /// The scene's spin axis (body axes, unit), which the nutation angle is measured from.
    pub spin_axis: Vector3<f64>,
    /// End time (s); the run starts at t = 0.
    pub t_end: f64,
    /// Rate of the output grid (Hz; 0: none): [`LaneRun::sample_rate`].
    pub sample_rate: f64,
}

impl LaneRun<DIM> for SinkRun {
    type System<L: Lane> = SinkLanes<L>;
    fn initial_state(&self) -> [f64; DIM] {
        let (w, q) = (self.omega0, self.attitude0);
        [w.x, w.y, w.z, q.w, q.i, q.j, q.k, 0.0]
    }
    fn t_end(&self) -> f64 {
        self.t_end
    }
    fn sample_rate(&self) -> f64 {
        self.sample_rate
    }
}

/// The parameters of the class's runs in the lanes, one run per lane. Matrices by columns
/// (`m[c][r]` is row r, column c), as nalgebra stores them.
#[derive(Debug, Clone, Copy)]
pub struct SinkLanes<L: Lane> {
    hub_inertia: [[L; 3]; 3],
    inverse_inertia: [L; 3],
    euler_coefficients: [L; 3],
    /// The sink's coefficient c (N m s/rad) and the inertia its Ĥ is formed with.
    coefficient: L,
    sink_inertia: [[L; 3]; 3],
    spin_axis: [L; 3],
}

impl<L: Lane> SinkLanes<L> {
    /// ω⊥ = ω − (ω·Ĥ) Ĥ (rad/s), as `EnergySink::transverse_rate`: zero where Iω is.
    #[inline(always)]
    fn transverse_rate(&self, w: [L; 3]) -> [L; 3] {
        let zero = L::splat(0.0);
        let h = linalg::mat_vec(&self.sink_inertia, w);
        let n2 = zero + linalg::dot(h, h);
        let s = linalg::dot(w, h) / n2;
        let none = n2.equals(zero);
        linalg::each3(|k| L::select(none, zero, w[k] - h[k] * s))
    }

    /// c |ω⊥|² (W), the sink's dissipation rate.
    #[inline(always)]
    fn power(&self, perp: [L; 3]) -> L {
        self.coefficient * (L::splat(0.0) + linalg::dot(perp, perp))
    }
}

impl<L: Lane> LaneSystem<L, DIM, SinkRun> for SinkLanes<L> {
    #[inline(always)]
    fn idle() -> Self {
        let z = L::splat(0.0);
        SinkLanes {
            hub_inertia: [[z; 3]; 3],
            inverse_inertia: [z; 3],
            euler_coefficients: [z; 3],
            coefficient: z,
            sink_inertia: [[z; 3]; 3],
            spin_axis: [z; 3],
        }
    }

    #[inline(always)]
    fn load(&mut self, i: usize, run: &SinkRun) {
        let set = |x: &mut L, v: f64| *x = x.with_lane(i, v);
        set(&mut self.coefficient, run.sink.coefficient);
        for j in 0..3 {
            set(&mut self.inverse_inertia[j], run.inverse_inertia[j]);
            set(&mut self.euler_coefficients[j], run.euler_coefficients[j]);
            set(&mut self.spin_axis[j], run.spin_axis[j]);
            for c in 0..3 {
                set(&mut self.hub_inertia[c][j], run.hub_inertia[(j, c)]);
                set(&mut self.sink_inertia[c][j], run.sink.inertia[(j, c)]);
            }
        }
    }

    /// The right-hand side, as `Spacecraft::torque_rhs` with Euler's three-term form:
    /// ω̇ = (c₁ ω₂ ω₃, c₂ ω₃ ω₁, c₃ ω₁ ω₂) + I⁻¹ τ, the torque summed from zero; every lane
    /// is solved.
    #[inline(always)]
    fn rhs(&self, y: &[L], dy: &mut [L]) -> L::Mask {
        let (y, dy) = (&y[..DIM], &mut dy[..DIM]);
        let zero = L::splat(0.0);
        let w = [y[0], y[1], y[2]];
        let perp = self.transverse_rate(w);
        let minus_c = -self.coefficient;
        let torque: [L; 3] = linalg::each3(|k| zero + minus_c * perp[k]);
        let [c1, c2, c3] = self.euler_coefficients;
        let rigid = [c1 * w[1] * w[2], c2 * w[2] * w[0], c3 * w[0] * w[1]];
        let inv = self.inverse_inertia;
        let q_dot = linalg::quaternion_rate([y[3], y[4], y[5], y[6]], w);
        for k in 0..3 {
            dy[k] = rigid[k] + inv[k] * torque[k];
        }
        dy[3] = q_dot[0];
        dy[4] = q_dot[1];
        dy[5] = q_dot[2];
        dy[6] = q_dot[3];
        dy[7] = self.power(perp);
        L::Mask::splat(true)
    }

    /// The observation at state `y`, with the operations (and their order) of
    /// `observe::invariants` on a hub with this one torque: nalgebra's `I ω` and dot products,
    /// the effector's (zero) momentum and energies added to the sums, which start from zero,
    /// the 4-vector norm `(i² + k²) + (j² + w²)` and the rotation `(2 (u × v) w + u × t) + v`;
    /// then |H| and the nutation angle.
    #[inline(always)]
    fn observe(&self, y: &[L; DIM]) -> LaneObservation<L> {
        let zero = L::splat(0.0);
        let w = [y[0], y[1], y[2]];
        let iw = linalg::mat_vec(&self.hub_inertia, w);
        let h: [L; 3] = linalg::each3(|k| iw[k] + zero);
        let kinetic = L::splat(0.5) * linalg::dot(w, iw) + zero;
        let energies = [
            kinetic,
            zero + zero,
            zero + y[7],
            zero + self.power(self.transverse_rate(w)),
            zero + zero,
        ];
        LaneObservation::of_hub([y[3], y[4], y[5], y[6]], h, energies, self.spin_axis)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::F64x4;
    use crate::lanes::ensemble::assert_lanes_are_the_spacecrafts;
    use crate::model::{RigidBody, Spacecraft};

    /// A spacecraft of the class and its run, from principal moments, a coefficient and ω₀.
    fn scene(moments: [f64; 3], c: f64, omega: [f64; 3]) -> (Spacecraft, SinkRun) {
        let inertia = Matrix3::from_diagonal(&Vector3::from(moments));
        let hub = RigidBody::new(inertia).expect("a valid inertia");
        let mut sc = Spacecraft::new(hub, Vector3::new(0.1, 0.2, 1.0));
        let sink = EnergySink {
            name: "sink".into(),
            coefficient: c,
            inertia,
        };
        sc.add_effector(Box::new(sink.clone())).expect("added");
        let run = SinkRun {
            hub_inertia: inertia,
            inverse_inertia: [0, 1, 2].map(|k| sc.hub.inertia_inv[(k, k)]),
            euler_coefficients: sc.euler_coefficients().expect("principal axes"),
            sink,
            omega0: Vector3::from(omega),
            attitude0: UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1),
            spin_axis: sc.spin_axis,
            t_end: 1.0,
            sample_rate: 0.0,
        };
        (sc, run)
    }

    /// The class's right-hand side and observation, in four lanes at once, are the scalar
    /// `Spacecraft`'s bit for bit, at states spread over the rates, attitudes and energies,
    /// signed zeros included.
    #[test]
    fn the_lanes_right_hand_side_and_observation_are_the_spacecrafts() {
        let cases = [
            ([4.948, 4.948, 0.150], 3.1e-3, [0.0785, 0.0785, 78.54]),
            ([1.0, 2.0, 3.0], 0.2, [0.4, -1.3, 0.02]),
            ([2.5, 1.5, 1.2], 1e-6, [-0.0, 0.0, 3.0]),
            ([0.03, 0.04, 0.05], 4.0, [0.0, 0.0, 0.0]),
        ];
        let scenes: Vec<_> = cases.iter().map(|&(m, c, w)| scene(m, c, w)).collect();
        let mut lanes = SinkLanes::<F64x4>::idle();
        for (i, (_, run)) in scenes.iter().enumerate() {
            lanes.load(i, run);
        }
        let states: Vec<[f64; DIM]> = scenes
            .iter()
            .enumerate()
            .map(|(i, (_, run))| {
                let mut y = run.initial_state();
                y[3] *= 1.0 + 1e-9 * i as f64;
                y[7] = 0.25 * i as f64;
                y
            })
            .collect();
        let spacecraft: Vec<_> = scenes.iter().map(|(sc, _)| sc).collect();
        assert_lanes_are_the_spacecrafts::<SinkRun, DIM>(&lanes, &spacecraft, &states, "sink");
    }
}
