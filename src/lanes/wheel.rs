//! The driven-wheel class in the lanes: a rigid hub carrying one `wheel` whose motor holds a
//! torque command between breakpoints, with viscous bearing friction (the scalar path's
//! `Spacecraft` with that one effector, whose right-hand side couples it and solves the hub's
//! rotational equations, `Spacecraft::takes_rotational_solve`). The command is a stepped
//! torque profile (`motor: {torque: {steps: …}}`), changing at its steps, or a rate-damping
//! law (`motor: {rate_damping: …}`), which samples ω at its clock's ticks and holds u = g·ω
//! until the next. Each lane's steps end exactly on its run's breakpoints, where the held
//! torque takes its new value and the lane restarts ([`super::ensemble`]).
//!
//! The equations are the wheel's (docs/actuators.md): with the rotor's axial inertia I_a on
//! the unit axis â, its rate Ω relative to the hub and g = u − f(Ω),
//! (I − I_a â âᵀ) ω̇ = −ω × (I ω + I_a Ω â) − g â and Ω̇ = g / I_a − â·ω̇; the motor's work
//! W' = u Ω and the friction's dissipation D' = f Ω, f = c Ω. The run is [`WheelRun`]; its
//! system in lanes, [`WheelLanes`], written with the operations (and their order) of the
//! scalar code, so each lane's steps and state are bit for bit those of the scalar method on
//! that run's `Spacecraft` (the tests at the end compare the right-hand side and the
//! observation; tests/lanes_campaign.rs whole campaigns).
//!
//! The rotational block I − I_a â âᵀ is constant, so its cofactor inverse (the scalar solve's,
//! from the same numbers) is formed once per run, not at every right-hand side: the same bits.
//! A run whose block is not positive definite to rounding (the scalar solve would fall back
//! to a general inverse) is not admitted: it takes the scalar path.

use super::ensemble::{LaneObservation, LaneRun, LaneSystem};
use super::{Lane, LaneMask, linalg};
use crate::effectors::motor::{MotorMode, RateDamping, TorqueProfile};
use crate::effectors::motor_wheel::MotorWheel;
use crate::model::Spacecraft;
use nalgebra::{Matrix3, Vector3};
use std::any::Any;

/// The hub's states: ω (rad/s, 3) and q (w, x, y, z).
const HUB_STATES: usize = 7;

/// States of a run: the hub's, then the wheel's relative rate Ω (rad/s), its held motor
/// torque (N m), the motor's work (J) and the friction's dissipated energy (J): the scalar
/// `Spacecraft`'s layout for this scene.
pub const DIM: usize = HUB_STATES + 4;

/// One run of the class.
#[derive(Debug, Clone)]
pub struct WheelRun {
    /// The hub's inertia, the rotor included as if locked (kg m², body axes, symmetric).
    pub hub_inertia: Matrix3<f64>,
    /// The rotor's axial inertia I_a (kg m²).
    pub axial_inertia: f64,
    /// The rotor's unit axis â (body axes).
    pub axis: Vector3<f64>,
    /// Largest motor torque |u| (N m); infinite for none (clamping to ±∞ changes nothing).
    pub max_torque: f64,
    /// The bearing's viscous friction coefficient c (N m s/rad).
    pub viscous: f64,
    /// What the motor's held torque follows.
    pub command: HeldCommand,
    /// The inverse of the rotational block I − I_a â âᵀ by columns, as the scalar solve forms
    /// it at every call; `None` where it is not positive definite to rounding.
    pub block_inverse: Option<[[f64; 3]; 3]>,
    /// The initial state.
    pub initial_state: [f64; DIM],
    /// The scene's spin axis (body axes, unit), which the nutation angle is measured from.
    pub spin_axis: Vector3<f64>,
    /// End time (s); the run starts at t = 0.
    pub t_end: f64,
    /// Rate of the output grid (Hz; 0: none): [`LaneRun::sample_rate`].
    pub sample_rate: f64,
}

/// What a driven wheel's held torque command follows.
#[derive(Debug, Clone)]
pub enum HeldCommand {
    /// A stepped profile: the command changes at its steps.
    Steps(TorqueProfile),
    /// A rate-damping law: at each tick of its clock the command becomes g·ω.
    RateDamping(RateDamping),
}

impl WheelRun {
    /// The run of `sc` from the state `y0` (its layout) to `t_end` (s) with an output grid of
    /// `sample_rate` (Hz), or why `sc` is not of the class (a sentence fragment).
    pub fn new(
        sc: &Spacecraft,
        y0: &[f64],
        t_end: f64,
        sample_rate: f64,
    ) -> Result<WheelRun, String> {
        let [effector] = sc.effectors() else {
            return Err("it has more than one effector".into());
        };
        let any: &dyn Any = effector.as_ref();
        let Some(wheel) = any.downcast_ref::<MotorWheel>() else {
            return Err(format!(
                "its effector `{}` ({}) is not a wheel",
                effector.name(),
                effector.kind()
            ));
        };
        let command = match &wheel.mode {
            MotorMode::Torque(profile @ TorqueProfile::Steps(_)) => {
                HeldCommand::Steps(profile.clone())
            }
            MotorMode::RateDamping(law) => HeldCommand::RateDamping(*law),
            _ => {
                return Err(
                    "its wheel's motor holds no command (the lanes take `motor: {torque: \
                     {steps: …}}` and `motor: {rate_damping: …}`)"
                        .into(),
                );
            }
        };
        if wheel.friction.coulomb != 0.0 {
            return Err("its wheel's bearing has Coulomb friction (the lanes take viscous)".into());
        }
        if !sc.takes_rotational_solve() {
            return Err("its right-hand side is not the hub's rotational equations".into());
        }
        let initial_state = <[f64; DIM]>::try_from(y0).map_err(|_| {
            "its state is not laid out as the lanes' (ω, q, Ω, held torque, work, dissipated \
             energy)"
                .to_string()
        })?;
        // The block as the scalar coupling forms it: the hub's inertia less (I_a â) âᵀ.
        let (i, a, ia) = (
            &sc.hub.inertia,
            wheel.axis,
            wheel.axial_inertia * wheel.axis,
        );
        let block = |r: usize, c: usize| i[(r, c)] - ia[r] * a[c];
        let (inverse, ok) = linalg::spd_inverse3(
            block(0, 0),
            block(1, 0),
            block(2, 0),
            block(1, 1),
            block(2, 1),
            block(2, 2),
        );
        Ok(WheelRun {
            hub_inertia: *i,
            axial_inertia: wheel.axial_inertia,
            axis: wheel.axis,
            max_torque: wheel.max_torque.unwrap_or(f64::INFINITY),
            viscous: wheel.friction.viscous,
            command,
            block_inverse: ok.then_some(inverse),
            initial_state,
            spin_axis: sc.spin_axis,
            t_end,
            sample_rate,
        })
    }
}

impl LaneRun<DIM> for WheelRun {
    type System<L: Lane> = WheelLanes<L>;
    const BREAKPOINTS: bool = true;
    fn initial_state(&self) -> [f64; DIM] {
        self.initial_state
    }
    fn t_end(&self) -> f64 {
        self.t_end
    }
    fn sample_rate(&self) -> f64 {
        self.sample_rate
    }
    /// A rotational block that is not positive definite takes the scalar path's general
    /// inverse.
    fn admitted(&self) -> bool {
        self.block_inverse.is_some()
    }
    fn next_stop(&self, t: f64) -> f64 {
        match &self.command {
            HeldCommand::Steps(profile) => {
                crate::sim::next_stop_of(|t| profile.next_breakpoint(t), t, self.t_end)
            }
            HeldCommand::RateDamping(law) => {
                crate::sim::next_stop_of(|t| Some(law.clock.next_tick(t)), t, self.t_end)
            }
        }
    }
    /// The held torque takes its new value (`MotorWheel::at_breakpoint`): the profile's at
    /// `t`, or the law's g·ω.
    fn at_breakpoint(&self, t: f64, y: &mut [f64; DIM]) {
        y[HUB_STATES + 1] = match &self.command {
            HeldCommand::Steps(profile) => profile.at(t),
            HeldCommand::RateDamping(law) => law.gains.dot(&Vector3::new(y[0], y[1], y[2])),
        };
    }
}

/// The parameters of the class's runs in the lanes, one run per lane. Matrices by columns
/// (`m[c][r]` is row r, column c), as nalgebra stores them.
#[derive(Debug, Clone, Copy)]
pub struct WheelLanes<L: Lane> {
    hub_inertia: [[L; 3]; 3],
    block_inverse: [[L; 3]; 3],
    axial_inertia: L,
    axis: [L; 3],
    max_torque: L,
    viscous: L,
    spin_axis: [L; 3],
}

impl<L: Lane> WheelLanes<L> {
    /// The motor torque u (N m): the held command clamped to ±`max_torque` as `f64::clamp`
    /// does (a NaN stays NaN).
    #[inline(always)]
    fn motor_torque(&self, held: L) -> L {
        let low = -self.max_torque;
        let u = L::select(held.less_than(low), low, held);
        L::select(u.greater_than(self.max_torque), self.max_torque, u)
    }

    /// The friction torque f(Ω) = c Ω + 0 (N m), as `Friction::torque` adds its zero Coulomb
    /// part.
    #[inline(always)]
    fn friction(&self, rate: L) -> L {
        self.viscous * rate + L::splat(0.0)
    }
}

impl<L: Lane> LaneSystem<L, DIM, WheelRun> for WheelLanes<L> {
    #[inline(always)]
    fn idle() -> Self {
        let z = L::splat(0.0);
        WheelLanes {
            hub_inertia: [[z; 3]; 3],
            block_inverse: [[z; 3]; 3],
            axial_inertia: z,
            axis: [z; 3],
            max_torque: z,
            viscous: z,
            spin_axis: [z; 3],
        }
    }

    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // the loops index several arrays
    fn load(&mut self, i: usize, run: &WheelRun) {
        let set = |x: &mut L, v: f64| *x = x.with_lane(i, v);
        // Not admitted: the lane never steps, any finite numbers do.
        let inverse = run.block_inverse.unwrap_or([[0.0; 3]; 3]);
        for j in 0..3 {
            set(&mut self.axis[j], run.axis[j]);
            set(&mut self.spin_axis[j], run.spin_axis[j]);
            for c in 0..3 {
                set(&mut self.hub_inertia[c][j], run.hub_inertia[(j, c)]);
                set(&mut self.block_inverse[c][j], inverse[c][j]);
            }
        }
        set(&mut self.axial_inertia, run.axial_inertia);
        set(&mut self.max_torque, run.max_torque);
        set(&mut self.viscous, run.viscous);
    }

    /// The right-hand side as `Spacecraft::rhs` takes it for this scene: the hub's force
    /// −ω × Iω, the wheel's torque −ω × (I_a Ω â) − (u − f) â added, ω̇ = (I − I_a â âᵀ)⁻¹ times
    /// it; then the wheel's `derivatives` and the quaternion rate. Every lane is solved (the
    /// runs whose block is not positive definite are not admitted).
    #[inline(always)]
    fn rhs(&self, y: &[L], dy: &mut [L]) -> L::Mask {
        use linalg::{cross, dot, mat_vec};
        let (y, dy) = (&y[..DIM], &mut dy[..DIM]);
        let w = [y[0], y[1], y[2]];
        let (rate, held) = (y[HUB_STATES], y[HUB_STATES + 1]);
        let a = self.axis;
        let u = self.motor_torque(held);
        let f = self.friction(rate);
        let g = u - f;
        let iw = mat_vec(&self.hub_inertia, w);
        let gyro = cross(w, iw);
        let spin = self.axial_inertia * rate;
        let rotor = [spin * a[0], spin * a[1], spin * a[2]];
        let wr = cross(w, rotor);
        let torque = [
            -gyro[0] + (-wr[0] - g * a[0]),
            -gyro[1] + (-wr[1] - g * a[1]),
            -gyro[2] + (-wr[2] - g * a[2]),
        ];
        let omega_dot = mat_vec(&self.block_inverse, torque);
        let q_dot = linalg::quaternion_rate([y[3], y[4], y[5], y[6]], w);
        dy[0] = omega_dot[0];
        dy[1] = omega_dot[1];
        dy[2] = omega_dot[2];
        dy[3] = q_dot[0];
        dy[4] = q_dot[1];
        dy[5] = q_dot[2];
        dy[6] = q_dot[3];
        dy[HUB_STATES] = g / self.axial_inertia - dot(a, omega_dot);
        dy[HUB_STATES + 1] = L::splat(0.0);
        dy[HUB_STATES + 2] = u * rate;
        dy[HUB_STATES + 3] = f * rate;
        L::Mask::splat(true)
    }

    /// The observation at `y`, with the operations (and their order) of
    /// `observe::invariants` on this scene: the hub's I ω and ½ ω·Iω, the wheel's momentum
    /// I_a Ω â and energy I_a Ω (â·ω + ½ Ω) added, its energy account summed from zero (the
    /// motor's work as work done from outside); no translation. Then the attitude, |H| and
    /// the nutation angle ([`LaneObservation::of_hub`]).
    #[inline(always)]
    fn observe(&self, y: &[L; DIM]) -> LaneObservation<L> {
        use linalg::{dot, mat_vec};
        let zero = L::splat(0.0);
        let half = L::splat(0.5);
        let w = [y[0], y[1], y[2]];
        let rate = y[HUB_STATES];
        let a = self.axis;
        let iw = mat_vec(&self.hub_inertia, w);
        let hub_kinetic = half * dot(w, iw);
        let spin = self.axial_inertia * rate;
        let h = [
            iw[0] + spin * a[0],
            iw[1] + spin * a[1],
            iw[2] + spin * a[2],
        ];
        let kinetic = hub_kinetic + spin * (dot(a, w) + half * rate);
        LaneObservation::of_hub(
            [y[3], y[4], y[5], y[6]],
            h,
            [
                kinetic,
                zero + zero,
                zero + y[HUB_STATES + 3],
                zero + self.friction(rate) * rate,
                zero + y[HUB_STATES + 2],
            ],
            self.spin_axis,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effectors::motor::Friction;
    use crate::lanes::F64x4;
    use crate::lanes::ensemble::assert_lanes_are_the_spacecrafts;
    use crate::model::RigidBody;
    use nalgebra::UnitQuaternion;

    /// A hub with products of inertia and one wheel on a tilted axis, of case `k`: stepped,
    /// or under rate damping at 10 Hz for odd `k` past 1.
    fn scene(k: usize, max_torque: Option<f64>) -> (Spacecraft, WheelRun) {
        let b = k as f64;
        let inertia = Matrix3::new(
            120.0 + b,
            1.5,
            -0.7 * b,
            1.5,
            100.0,
            0.3,
            -0.7 * b,
            0.3,
            80.0 - 3.0 * b,
        );
        let hub = RigidBody::new(inertia).expect("a valid inertia");
        let mut sc = Spacecraft::new(hub, Vector3::new(0.02 * b, 0.0, 1.0).normalize());
        let wheel = MotorWheel {
            name: "rotor".into(),
            axial_inertia: 2.0 + 0.5 * b,
            axis: Vector3::new(0.1 * b, -0.05, 1.0).normalize(),
            mode: if k > 1 && k % 2 == 1 {
                MotorMode::RateDamping(RateDamping {
                    gains: Vector3::new(0.1, -0.2 * b, -0.5),
                    clock: crate::effectors::clock::SampleClock { period: 0.1 },
                })
            } else {
                MotorMode::Torque(TorqueProfile::Steps(vec![(0.0, 0.4), (3.0, -0.2)]))
            },
            max_torque,
            friction: Friction {
                viscous: 1e-3 * b,
                coulomb: 0.0,
                smoothing_speed: 1.0,
            },
            initial_rate: 10.0 * b - 5.0,
            position: Vector3::zeros(),
            diameter: 0.3,
            max_speed: None,
        };
        sc.add_effector(Box::new(wheel)).expect("added");
        let y0 = sc.initial_state(
            &Vector3::new(0.05, -0.1 * b, 0.8),
            &UnitQuaternion::from_euler_angles(0.3, -0.2 * b, 1.1),
        );
        let run = WheelRun::new(&sc, &y0, 10.0, 0.0).expect("of the class");
        (sc, run)
    }

    /// The class's right-hand side and observation, in four lanes at once, are the scalar
    /// `Spacecraft`'s bit for bit, at states spread over the rates, attitudes, held torques
    /// (inside and beyond the limit, and without one) and energies, signed zeros included.
    #[test]
    fn the_lanes_right_hand_side_and_observation_are_the_spacecrafts() {
        let limits = [Some(0.3), None, Some(5.0), Some(0.05)];
        let scenes: Vec<_> = (0..4).map(|k| scene(k, limits[k])).collect();
        let mut lanes = WheelLanes::<F64x4>::idle();
        for (i, (_, run)) in scenes.iter().enumerate() {
            assert!(run.admitted());
            lanes.load(i, run);
        }
        let held = [0.4, -7.0, -0.0, 0.06];
        let states: Vec<[f64; DIM]> = scenes
            .iter()
            .enumerate()
            .map(|(i, (_, run))| {
                let mut y = run.initial_state();
                y[3] *= 1.0 + 1e-9 * i as f64;
                y[HUB_STATES + 1] = held[i];
                y[HUB_STATES + 2] = 0.5 * i as f64 - 0.7;
                y[HUB_STATES + 3] = 0.25 * i as f64;
                y
            })
            .collect();
        let spacecraft: Vec<_> = scenes.iter().map(|(sc, _)| sc).collect();
        assert_lanes_are_the_spacecrafts::<WheelRun, DIM>(&lanes, &spacecraft, &states, "wheel");
    }

    /// The run's stops and held torque are the scalar loop's: the profile's steps, then the
    /// end, the held torque taking each step's value there; or the clock's ticks, the command
    /// g·ω sampled at each.
    #[test]
    fn the_runs_stops_and_held_torque_are_the_profiles() {
        let (sc, run) = scene(1, None);
        assert_eq!(run.next_stop(0.0), 3.0);
        assert_eq!(run.next_stop(3.0), 10.0);
        assert_eq!(sc.next_breakpoint(0.0), Some(3.0));
        let mut y = run.initial_state();
        let mut scalar = y.to_vec();
        run.at_breakpoint(3.0, &mut y);
        sc.at_breakpoint(3.0, &mut scalar);
        assert_eq!(y.to_vec(), scalar);
        assert_eq!(y[HUB_STATES + 1], -0.2);
        // Under rate damping: the clock's ticks k × 0.1 (rounded; two of the times are
        // ticks), and the command g·ω sampled there.
        let (sc, run) = scene(3, None);
        for t in [0.0, 0.25, 0.30000000000000004, 2.9999999999999996] {
            let scalar_stop = crate::sim::next_stop_of(|t| sc.next_breakpoint(t), t, 10.0);
            assert_eq!(run.next_stop(t), scalar_stop, "after {t}");
        }
        let mut y = run.initial_state();
        y[0] = -0.7;
        let mut scalar = y.to_vec();
        run.at_breakpoint(0.3, &mut y);
        sc.at_breakpoint(0.3, &mut scalar);
        assert_eq!(y.to_vec(), scalar);
        assert_ne!(y[HUB_STATES + 1], run.initial_state()[HUB_STATES + 1]);
    }
}
