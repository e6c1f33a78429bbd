//! The nutation-damper class in the lanes: a rigid hub carrying one spring–mass damper (the
//! scalar path's `Spacecraft` with one `spring_mass_damper`, whose right-hand side is its
//! closed form, `Spacecraft::lone_rhs`), integrated by the lockstep ensemble of
//! [`super::ensemble`]. Its run is [`DamperRun`]; its system in lanes, [`DamperLanes`]: the
//! damper's closed form in [`SpringMassLanes`] and the quaternion rate in [`super::linalg`],
//! the code the scalar path runs at `f64`, so each lane's steps and state are bit for bit
//! those of the scalar `Dopri5` on that run's `Spacecraft` (tests/lanes_damper.rs compares
//! them).

use super::ensemble::{LaneObservation, LaneRun, LaneSystem};
use super::{Lane, linalg};
use crate::effectors::spring_mass::{SpringMass, SpringMassLanes};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// States of a run: ω (rad/s, 3), q (w, x, y, z), the damper's offset ρ (m), rate ρ̇ (m/s)
/// and dissipated energy (J): the scalar `Spacecraft`'s layout for this scene.
pub const DIM: usize = 10;

/// One run of the class.
#[derive(Debug, Clone)]
pub struct DamperRun {
    /// The hub's inertia about its centre of mass (kg m², body axes, symmetric).
    pub hub_inertia: Matrix3<f64>,
    /// The hub's mass (kg).
    pub hub_mass: f64,
    /// The damper (its `travel` is not checked here).
    pub damper: SpringMass,
    /// Initial body rate ω₀ (rad/s, body axes).
    pub omega0: Vector3<f64>,
    /// Initial attitude (body to inertial).
    pub attitude0: UnitQuaternion<f64>,
    /// Initial offset ρ₀ (m).
    pub offset0: f64,
    /// Initial offset rate ρ̇₀ (m/s).
    pub rate0: f64,
    /// The scene's spin axis (body axes, unit: `Spacecraft::spin_axis`), which the nutation
    /// angle is measured from.
    pub spin_axis: Vector3<f64>,
    /// End time (s); the run starts at t = 0.
    pub t_end: f64,
    /// Rate of the output grid (Hz; 0: none): [`LaneRun::sample_rate`].
    pub sample_rate: f64,
}

impl DamperRun {
    /// The initial state in the layout of [`DIM`] (the dissipated energy starts at 0).
    pub fn initial_state(&self) -> [f64; DIM] {
        let (w, q) = (self.omega0, self.attitude0);
        [
            w.x,
            w.y,
            w.z,
            q.w,
            q.i,
            q.j,
            q.k,
            self.offset0,
            self.rate0,
            0.0,
        ]
    }
}

impl LaneRun<DIM> for DamperRun {
    type System<L: Lane> = DamperLanes<L>;
    fn initial_state(&self) -> [f64; DIM] {
        DamperRun::initial_state(self)
    }
    fn t_end(&self) -> f64 {
        self.t_end
    }
    fn sample_rate(&self) -> f64 {
        self.sample_rate
    }
    /// A damper whose direction is not a unit vector is not the closed form's.
    fn admitted(&self) -> bool {
        self.damper.has_unit_direction()
    }
}

/// The parameters of the class's runs in the lanes, one run per lane.
#[derive(Debug, Clone, Copy)]
pub struct DamperLanes<L: Lane> {
    damper: SpringMassLanes<L>,
    /// The spin axis (body axes, unit).
    spin_axis: [L; 3],
    hub_inertia: [[L; 3]; 3],
    hub_mass: L,
    /// The damper's reduced mass with the hub (kg).
    reduced_mass: L,
}

impl<L: Lane> LaneSystem<L, DIM, DamperRun> for DamperLanes<L> {
    #[inline(always)]
    fn idle() -> Self {
        let z = L::splat(0.0);
        DamperLanes {
            damper: SpringMassLanes {
                mass: z,
                position: [z; 3],
                direction: [z; 3],
                stiffness: z,
                damping: z,
            },
            spin_axis: [z; 3],
            hub_inertia: [[z; 3]; 3],
            hub_mass: z,
            reduced_mass: z,
        }
    }

    #[inline(always)]
    fn load(&mut self, i: usize, run: &DamperRun) {
        let set = |x: &mut L, v: f64| *x = x.with_lane(i, v);
        let d = &mut self.damper;
        set(&mut d.mass, run.damper.mass);
        set(&mut d.stiffness, run.damper.stiffness);
        set(&mut d.damping, run.damper.damping);
        for j in 0..3 {
            set(&mut d.position[j], run.damper.position[j]);
            set(&mut d.direction[j], run.damper.direction[j]);
            set(&mut self.spin_axis[j], run.spin_axis[j]);
            for c in 0..3 {
                set(&mut self.hub_inertia[c][j], run.hub_inertia[(j, c)]);
            }
        }
        set(&mut self.hub_mass, run.hub_mass);
        let reduced_mass = run.damper.lanes().reduced_mass(run.hub_mass);
        set(&mut self.reduced_mass, reduced_mass);
    }

    /// The right-hand side (the scalar `Spacecraft::lone_rhs` of this scene), per lane;
    /// returns the lanes whose closed form was solved.
    #[inline(always)]
    fn rhs(&self, y: &[L], dy: &mut [L]) -> L::Mask {
        let (y, dy) = (&y[..DIM], &mut dy[..DIM]);
        let omega = [y[0], y[1], y[2]];
        let (offset, rate) = (y[7], y[8]);
        let a = self.damper.lone_accelerations(
            offset,
            rate,
            omega,
            &self.hub_inertia,
            self.reduced_mass,
        );
        let q_dot = linalg::quaternion_rate([y[3], y[4], y[5], y[6]], omega);
        dy[0] = a.omega_dot[0];
        dy[1] = a.omega_dot[1];
        dy[2] = a.omega_dot[2];
        dy[3] = q_dot[0];
        dy[4] = q_dot[1];
        dy[5] = q_dot[2];
        dy[6] = q_dot[3];
        dy[7] = rate;
        dy[8] = a.u_dot;
        dy[9] = self.damper.dissipation_power(rate);
        a.solved
    }

    /// The observation at state `y`, with the operations (and their order) of
    /// `observe::invariants` on a hub with this one damper: nalgebra's `I ω`, dot products
    /// `(x + y) + z`, its 4-vector norm `(i² + k²) + (j² + w²)` and its rotation
    /// `(2 (u × v) w + u × t) + v`; the damper's closed-form momentum, then the hub's
    /// translation. The sums start from zero as the scalar sums do (so −0 becomes +0). Then
    /// |H| and the nutation angle (as `Observation::from_invariants` takes them; the
    /// arctangent is [`super::elementary::half_plane_atan2`], the scalar path's too; both by
    /// [`LaneObservation::of_hub`]).
    #[inline(always)]
    fn observe(&self, y: &[L; DIM]) -> LaneObservation<L> {
        use linalg::cross;
        let zero = L::splat(0.0);
        let half = L::splat(0.5);
        let w = [y[0], y[1], y[2]];
        let i = &self.hub_inertia;
        // hub_inertia[c][r] is I(r, c).
        let iw: [L; 3] = linalg::each3(|r| i[0][r] * w[0] + i[1][r] * w[1] + i[2][r] * w[2]);
        let mut h = iw;
        let mut kinetic = half * (w[0] * iw[0] + w[1] * iw[1] + w[2] * iw[2]);
        let d = &self.damper;
        let (q, u) = (y[7], y[8]);
        let m = d.mass;
        let r: [L; 3] = linalg::each3(|k| d.position[k] + q * d.direction[k]);
        let wr = cross(w, r);
        let v: [L; 3] = linalg::each3(|k| wr[k] + u * d.direction[k]);
        let rv = cross(r, v);
        let mass = self.hub_mass + m;
        let first_moment: [L; 3] = linalg::each3(|k| zero + m * r[k]);
        let linear: [L; 3] = linalg::each3(|k| zero + m * v[k]);
        for k in 0..3 {
            h[k] += m * rv[k];
        }
        kinetic += half * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        // The hub moves at −P/M when the particles carry linear momentum.
        let moving = mass.greater_than(zero)
            & !(linear[0].equals(zero) & linear[1].equals(zero) & linear[2].equals(zero));
        let v_hub: [L; 3] = linalg::each3(|k| -linear[k] / mass);
        let c = cross(first_moment, v_hub);
        for k in 0..3 {
            h[k] = L::select(moving, h[k] + c[k], h[k]);
        }
        let lin2 = linear[0] * linear[0] + linear[1] * linear[1] + linear[2] * linear[2];
        kinetic = L::select(moving, kinetic - half * lin2 / mass, kinetic);
        let energies = [
            kinetic,
            zero + half * d.stiffness * q * q,
            zero + y[9],
            zero + d.damping * u * u,
            zero + zero,
        ];
        LaneObservation::of_hub([y[3], y[4], y[5], y[6]], h, energies, self.spin_axis)
    }
}
