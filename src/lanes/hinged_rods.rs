//! The hinged-rods class in the lanes: a hub with mass carrying four flap–lag hinged rods and
//! nothing else (Explorer 1 as the PyDy model has it), whose scalar right-hand side is the
//! hub's 6 × 6 equations with the four rods coupled as one group
//! ([`crate::effectors::rod_lanes::RodLanes`]) and solved by the Schur complement. Its run is
//! [`RodsRun`]; its system in lanes, [`RodsLanes`]: each rod's closed form is
//! [`RodConstants`]' (the code the scalar group runs at `f64`), the hub's solve is
//! [`linalg::schur_solve6`] and the sines [`sin_cos_in_lanes`], with the sums in the scalar
//! path's order, so each lane's steps and state are bit for bit those of the scalar method on
//! that run's `Spacecraft` (the tests at the end compare the right-hand side and the
//! observation; tests/lanes_campaign.rs whole campaigns).
//!
//! A state at which the scalar solve would fall back to its LU factorisation (the hub's mass
//! matrix not positive definite to rounding) is declined: that run takes the scalar path.

use super::Lane;
use super::ensemble::{LaneObservation, LaneRun, LaneSystem};
use super::linalg::{self, add, cross, dot, mat_vec};
use crate::effectors::hinged_rod::{HingeFreedom, HingedRod};
use crate::effectors::particles::ParticleEffector;
use crate::effectors::rod_closed_form::{RodConstants, RodCoupling};
use crate::effectors::rod_lanes::RodLanes;
use crate::model::{EffectorGroup, Spacecraft};
use crate::sincos::sin_cos_in_lanes;
use nalgebra::{Matrix3, Matrix6, Vector3};
use std::any::Any;

/// Rods in a run.
pub const RODS: usize = 4;

/// States per rod: θ_f, θ_l (rad), θ̇_f, θ̇_l (rad/s) and the energy its dampers dissipated (J).
const ROD_STATES: usize = 5;

/// The hub's states: ω (rad/s, 3) and q (w, x, y, z).
const HUB_STATES: usize = 7;

/// States of a run: the hub's, then each rod's in turn (the scalar `Spacecraft`'s layout).
pub const DIM: usize = HUB_STATES + ROD_STATES * RODS;

/// One run of the class.
#[derive(Debug, Clone)]
pub struct RodsRun {
    /// The hub's inertia about its reference point (kg m², body axes, symmetric).
    pub hub_inertia: Matrix3<f64>,
    /// The hub's mass (kg).
    pub hub_mass: f64,
    /// The rods, in the scalar group's order.
    pub rods: [RodConstants<f64>; RODS],
    /// The rods' constant part of the hub's mass matrix, as the scalar group sums it
    /// (lower triangle).
    pub constant_mass: Matrix6<f64>,
    /// The initial state.
    pub initial_state: [f64; DIM],
    /// The scene's spin axis (body axes, unit), which the nutation angle is measured from.
    pub spin_axis: Vector3<f64>,
    /// End time (s); the run starts at t = 0.
    pub t_end: f64,
    /// Rate of the output grid (Hz; 0: none): [`LaneRun::sample_rate`].
    pub sample_rate: f64,
}

impl RodsRun {
    /// The run of `sc` from the state `y0` (its layout) to `t_end` (s) with an output grid of
    /// `sample_rate` (Hz), or why `sc` is not of the class (a sentence fragment).
    pub fn new(
        sc: &Spacecraft,
        y0: &[f64],
        t_end: f64,
        sample_rate: f64,
    ) -> Result<RodsRun, String> {
        for e in sc.effectors() {
            let any: &dyn Any = e.as_ref();
            let rod = any
                .downcast_ref::<ParticleEffector<HingedRod>>()
                .map(|p| p.model());
            if !rod.is_some_and(|r| r.freedom == HingeFreedom::FlapLag) {
                return Err(format!(
                    "its effector `{}` ({}) is not a flap–lag hinged_rod (the lanes take \
                     {RODS} of them together)",
                    e.name(),
                    e.kind(),
                ));
            }
        }
        if sc.effectors().len() != RODS || !sc.takes_grouped_closed_form() {
            return Err(format!(
                "its right-hand side is not the hub's equations with {RODS} rods as one group"
            ));
        }
        let offsets: Vec<usize> = (0..RODS).map(|k| sc.effector_offset(k)).collect();
        let groups = RodLanes::groups(sc.effectors(), &offsets);
        let [group] = groups.as_slice() else {
            return Err("its rods are not one group".into());
        };
        if sc.group_members() != [group.members().to_vec()] {
            return Err("its rods are grouped otherwise than the lanes group them".into());
        }
        let hub_mass = sc
            .hub_mass
            .ok_or_else(|| "its hub has no mass".to_string())?;
        let layout = (0..RODS).all(|k| offsets[k] == HUB_STATES + ROD_STATES * k);
        let initial_state = <[f64; DIM]>::try_from(y0)
            .ok()
            .filter(|_| layout)
            .ok_or_else(|| {
                "its state is not laid out as the lanes' (ω, q, then θ_f, θ_l, θ̇_f, θ̇_l, E \
                 of each rod)"
                    .to_string()
            })?;
        Ok(RodsRun {
            hub_inertia: sc.hub.inertia,
            hub_mass,
            rods: std::array::from_fn(|r| group.constants(r)),
            constant_mass: *group.constant_mass(),
            initial_state,
            spin_axis: sc.spin_axis,
            t_end,
            sample_rate,
        })
    }
}

impl LaneRun<DIM> for RodsRun {
    type System<L: Lane> = RodsLanes<L>;
    /// Four rods' coupling and a Schur solve: thousands of operations, beside which a call
    /// costs nothing.
    const RHS_OUT_OF_LINE: bool = true;
    fn initial_state(&self) -> [f64; DIM] {
        self.initial_state
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
pub struct RodsLanes<L: Lane> {
    hub_inertia: [[L; 3]; 3],
    hub_mass: L,
    rods: [RodConstants<L>; RODS],
    /// The lower triangle of the hub's own mass matrix: m 1 and the inertia.
    hub_matrix: [[L; 6]; 6],
    /// The lower triangle of the rods' constant part.
    constant_mass: [[L; 6]; 6],
    spin_axis: [L; 3],
    /// Whether the rods' closed form fuses its multiply–adds, as the scalar group does on
    /// this processor ([`crate::cpu::avx2_available`]).
    fma: bool,
}

impl<L: Lane> RodsLanes<L> {
    /// Rod `r`'s angles and rates in `y`, and `[sin θ_f, cos θ_f, sin θ_l, cos θ_l]`.
    #[inline(always)]
    fn rod_angles(y: &[L], r: usize) -> ([L; 4], [L; 4]) {
        let x = HUB_STATES + ROD_STATES * r;
        let angles = [y[x], y[x + 1], y[x + 2], y[x + 3]];
        let (sf, cf) = sin_cos_in_lanes(angles[0]);
        let (sl, cl) = sin_cos_in_lanes(angles[1]);
        (angles, [sf, cf, sl, cl])
    }
}

impl<L: Lane> RodsLanes<L> {
    /// Rod `r`'s closed form at state `y`, the hub turning at `w` (rad/s) with |ω|² `w2`.
    #[inline(always)]
    fn rod_coupling<const FMA: bool>(&self, y: &[L], r: usize, w: [L; 3], w2: L) -> RodCoupling<L> {
        let (angles, sines) = Self::rod_angles(y, r);
        self.rods[r].coupling::<FMA>(angles, sines, w, w2)
    }
}

impl<L: Lane> RodsLanes<L> {
    /// Whether the rods' closed form is fused: as the scalar group on this processor, and
    /// always in eight lanes, which run only where AVX-512F is, and with it AVX2 and FMA (so
    /// that engine compiles one copy).
    #[inline(always)]
    fn fuses(&self) -> bool {
        L::WIDTH == 8 || self.fma
    }

    /// [`LaneSystem::rhs`], with the rods' closed form fused where `FMA`.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // the triangle's loops index several arrays
    fn rhs_with<const FMA: bool>(&self, y: &[L], dy: &mut [L]) -> L::Mask {
        let (y, dy) = (&y[..DIM], &mut dy[..DIM]);
        let zero = L::splat(0.0);
        let w = [y[0], y[1], y[2]];
        let w2 = zero + dot(w, w);
        // Written out rather than `std::array::from_fn` and its closure, which the compiler
        // may leave out of line, where the AVX-512 lanes' operations become calls (and
        // rather than filling a zeroed array, which cost a memset and a copy per call).
        let mut rods = [
            self.rod_coupling::<FMA>(y, 0, w, w2),
            self.rod_coupling::<FMA>(y, 1, w, w2),
            self.rod_coupling::<FMA>(y, 2, w, w2),
            self.rod_coupling::<FMA>(y, 3, w, w2),
        ];
        // The force: the gyroscopic term, less the rods' sums (rod 0 first).
        let w_cross_iw = cross(w, mat_vec(&self.hub_inertia, w));
        let (mut force, mut moment) = (rods[0].hinge_force, rods[0].hinge_moment);
        for rod in &rods[1..] {
            for k in 0..3 {
                force[k] += rod.hinge_force[k];
                moment[k] += rod.hinge_moment[k];
            }
        }
        let mut f: [L; 6] = [
            zero - force[0],
            zero - force[1],
            zero - force[2],
            -w_cross_iw[0] - moment[0],
            -w_cross_iw[1] - moment[1],
            -w_cross_iw[2] - moment[2],
        ];
        // The lower triangle of M.
        let mut m = [[zero; 6]; 6];
        for i in 0..6 {
            let mut mu_v = [zero; RODS];
            for r in 0..RODS {
                mu_v[r] = self.rods[r].mu * rods[r].v[i];
            }
            for j in 0..=i {
                let mut sum = self.constant_mass[j][i];
                for r in 0..RODS {
                    sum += mu_v[r] * rods[r].v[j];
                }
                m[j][i] = self.hub_matrix[j][i] + sum;
            }
        }
        // A rod whose lag has no inertia (cos θ_f = 0, or not a number) poisons the force and
        // its own accelerations, as the scalar group does: the run stops with a diagnosis.
        let nan = L::splat(f64::NAN);
        for rod in rods.iter_mut() {
            let flat = !rod.cos2.greater_than(zero);
            f[0] = L::select(flat, nan, f[0]);
            for x in rod.rows.iter_mut() {
                *x = L::select(flat, nan, *x);
            }
        }
        let (z, solved) = linalg::schur_solve6(&m, &f);
        for (r, rod) in rods.iter().enumerate() {
            let (x, rows) = (HUB_STATES + ROD_STATES * r, &rod.rows);
            let rates = [y[x + 2], y[x + 3]];
            for k in 0..2 {
                let mut sum = rows[7 * k];
                for (a, z) in z.iter().enumerate() {
                    sum -= rows[7 * k + 1 + a] * *z;
                }
                dy[x + 2 + k] = sum;
            }
            dy[x] = rates[0];
            dy[x + 1] = rates[1];
            dy[x + 4] = self.rods[r].dissipation_power([zero, zero, rates[0], rates[1]]);
        }
        let q_dot = linalg::quaternion_rate([y[3], y[4], y[5], y[6]], w);
        dy[..3].copy_from_slice(&z[3..]);
        dy[3..7].copy_from_slice(&q_dot);
        solved
    }
}

impl<L: Lane> RodsLanes<L> {
    /// [`LaneSystem::observe`], with the rods' directions fused where `FMA`.
    #[inline(always)]
    fn observe_with<const FMA: bool>(&self, y: &[L; DIM]) -> LaneObservation<L> {
        let zero = L::splat(0.0);
        let w = [y[0], y[1], y[2]];
        let iw = mat_vec(&self.hub_inertia, w);
        let hub_kinetic = L::splat(0.5) * dot(w, iw);
        let (mut mass, mut kinetic) = (zero, zero);
        let (mut first, mut linear, mut angular) = ([zero; 3], [zero; 3], [zero; 3]);
        let (mut elastic, mut dissipated, mut power) = (zero, zero, zero);
        for (r, rod) in self.rods.iter().enumerate() {
            let (angles, sines) = Self::rod_angles(y, r);
            let m = rod.momentum::<FMA>(angles, sines, w);
            mass += m.mass;
            first = add(first, m.first_moment);
            linear = add(linear, m.linear);
            angular = add(angular, m.angular);
            kinetic += m.kinetic_energy;
            elastic += rod.elastic_energy(angles);
            dissipated += y[HUB_STATES + ROD_STATES * r + 4];
            power += rod.dissipation_power(angles);
        }
        let total_mass = self.hub_mass + mass;
        let first = add([zero; 3], first);
        let linear = add([zero; 3], linear);
        let mut h = add(iw, angular);
        let mut kinetic = hub_kinetic + kinetic;
        // The hub moves at v_B = −P/M: H gains S × v_B and T loses ½ |P|²/M.
        let moving = total_mass.greater_than(zero)
            & !(linear[0].equals(zero) & linear[1].equals(zero) & linear[2].equals(zero));
        let v_hub = linalg::each3(|k| -linear[k] / total_mass);
        let gained = cross(first, v_hub);
        h = linalg::each3(|k| L::select(moving, h[k] + gained[k], h[k]));
        let lost = L::splat(0.5) * (zero + dot(linear, linear)) / total_mass;
        kinetic = L::select(moving, kinetic - lost, kinetic);
        LaneObservation::of_hub(
            [y[3], y[4], y[5], y[6]],
            h,
            [kinetic, elastic, dissipated, power, zero + zero],
            self.spin_axis,
        )
    }
}

/// The right-hand side writes the four rods out.
const _: () = assert!(RODS == 4);

impl<L: Lane> LaneSystem<L, DIM, RodsRun> for RodsLanes<L> {
    #[inline(always)]
    fn idle() -> Self {
        let z = L::splat(0.0);
        let rod = RodConstants {
            hinge: [z; 3],
            rest: [z; 3],
            axis: [z; 3],
            binormal: [z; 3],
            m1: z,
            m2: z,
            inverse_m2: z,
            m1_over_m2: z,
            mu: z,
            hinge_mass: z,
            stiffness: [z; 2],
            damping: [z; 2],
        };
        RodsLanes {
            hub_inertia: [[z; 3]; 3],
            hub_mass: z,
            rods: [rod; RODS],
            hub_matrix: [[z; 6]; 6],
            constant_mass: [[z; 6]; 6],
            spin_axis: [z; 3],
            fma: crate::cpu::avx2_available(),
        }
    }

    #[inline(always)]
    fn load(&mut self, i: usize, run: &RodsRun) {
        let set = |x: &mut L, v: f64| *x = x.with_lane(i, v);
        let set3 = |x: &mut [L; 3], v: &[f64; 3]| {
            for (x, v) in x.iter_mut().zip(v) {
                *x = x.with_lane(i, *v);
            }
        };
        set(&mut self.hub_mass, run.hub_mass);
        for j in 0..3 {
            set(&mut self.spin_axis[j], run.spin_axis[j]);
            for c in 0..3 {
                set(&mut self.hub_inertia[c][j], run.hub_inertia[(j, c)]);
            }
        }
        // The hub's own matrix as the scalar coupling starts it: m on the translational
        // diagonal, the inertia in the rotational block.
        let mut hub = Matrix6::<f64>::zeros();
        for k in 0..3 {
            hub[(k, k)] = run.hub_mass;
        }
        hub.fixed_view_mut::<3, 3>(3, 3).copy_from(&run.hub_inertia);
        for c in 0..6 {
            for r in 0..6 {
                set(&mut self.hub_matrix[c][r], hub[(r, c)]);
                set(&mut self.constant_mass[c][r], run.constant_mass[(r, c)]);
            }
        }
        for (lanes, rod) in self.rods.iter_mut().zip(&run.rods) {
            set3(&mut lanes.hinge, &rod.hinge);
            set3(&mut lanes.rest, &rod.rest);
            set3(&mut lanes.axis, &rod.axis);
            set3(&mut lanes.binormal, &rod.binormal);
            set(&mut lanes.m1, rod.m1);
            set(&mut lanes.m2, rod.m2);
            set(&mut lanes.inverse_m2, rod.inverse_m2);
            set(&mut lanes.m1_over_m2, rod.m1_over_m2);
            set(&mut lanes.mu, rod.mu);
            set(&mut lanes.hinge_mass, rod.hinge_mass);
            for k in 0..2 {
                set(&mut lanes.stiffness[k], rod.stiffness[k]);
                set(&mut lanes.damping[k], rod.damping[k]);
            }
        }
    }

    /// The right-hand side, as `Spacecraft::rhs` takes it for this scene: the hub's equations
    /// M z = f with M = the hub's own matrix plus the group's sum (its constant part, then
    /// μ v vᵀ rod by rod) and f = [0; −ω × Iω] minus the rods' summed hinge forces and
    /// moments, solved by the Schur complement; then each rod's θ̈ = W_g − W_C z and its
    /// dampers' power. Returns the lanes the Schur solve took (the scalar path falls back to
    /// LU elsewhere).
    #[inline(always)]
    fn rhs(&self, y: &[L], dy: &mut [L]) -> L::Mask {
        if self.fuses() {
            self.rhs_with::<true>(y, dy)
        } else {
            self.rhs_with::<false>(y, dy)
        }
    }

    /// ω and the rods' angles and rates: not the attitude, nor the energy the dampers
    /// dissipated.
    const NUTATION_READS: [bool; DIM] = {
        let mut reads = [false; DIM];
        let mut i = 0;
        while i < DIM {
            let rod_state = (i as isize - HUB_STATES as isize).rem_euclid(ROD_STATES as isize);
            reads[i] = i < 3 || (i >= HUB_STATES && rod_state < 4);
            i += 1;
        }
        reads
    };

    /// The observation at state `y`, with the operations (and their order) of
    /// `observe::invariants` on this scene: the hub's I ω and ½ ω·Iω, the group's momentum
    /// summed from zero rod by rod and added to the hub's, each rod's energies summed from
    /// zero, and the hub's translation removed (the system's linear momentum is zero); then
    /// the attitude, |H| and the nutation angle ([`LaneObservation::of_hub`]).
    #[inline(always)]
    fn observe(&self, y: &[L; DIM]) -> LaneObservation<L> {
        if self.fuses() {
            self.observe_with::<true>(y)
        } else {
            self.observe_with::<false>(y)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::F64x4;
    use crate::lanes::ensemble::assert_lanes_are_the_spacecrafts;
    use crate::model::RigidBody;
    use nalgebra::UnitQuaternion;

    /// A hub with products of inertia and four rods of run `k`'s geometry (each rod its own
    /// hinge, direction, axis, length, mass, spring and damper).
    fn spacecraft(k: usize) -> Spacecraft {
        let a = k as f64;
        let inertia = Matrix3::new(
            4.9,
            0.02 * a,
            -0.01,
            0.02 * a,
            4.85 + 0.01 * a,
            0.003,
            -0.01,
            0.003,
            0.065 + 0.1 * a,
        );
        let hub = RigidBody::new(inertia).expect("a valid inertia");
        let mut sc = Spacecraft::new(hub, Vector3::new(0.01 * a, 0.0, 1.0));
        sc.hub_mass = Some(13.9 + a);
        for r in 0..RODS {
            let b = (r + 3 * k) as f64;
            let direction =
                Vector3::new((0.9 * b).cos(), (0.9 * b).sin(), 0.3 * b - 0.5).normalize();
            let axis = direction
                .cross(&Vector3::new(0.2, -0.7 + 0.1 * b, 1.0))
                .normalize();
            let model = HingedRod {
                mass: 0.139 + 0.05 * b,
                length: 0.56 + 0.1 * b,
                hinge: Vector3::new(0.03 * b, 0.076, 0.1 - 0.2 * b),
                direction,
                axis,
                freedom: HingeFreedom::FlapLag,
                stiffness: [0.565 + b, 0.3],
                damping: [1.13, 1e-3 * b],
            };
            let rod = ParticleEffector::new(format!("rod {r}"), model, &[0.0; 2], &[0.0; 2]);
            sc.add_effector(Box::new(rod)).expect("added");
        }
        sc
    }

    /// The rods' closed form fused and unfused (the scalar group's on a processor with and
    /// without FMA) is the same mathematics: the right-hand sides agree to rounding, and
    /// fusing does change bits (so the fused path is the one the other test checks).
    #[test]
    fn fused_and_unfused_right_hand_sides_agree_to_rounding() {
        let scenes: Vec<Spacecraft> = (0..4).map(spacecraft).collect();
        let mut lanes = RodsLanes::<F64x4>::idle();
        let omega = Vector3::new(0.3, -1.1, 78.5);
        let q = UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1);
        let mut differing = 0;
        for sample in 0..20 {
            let states: Vec<[f64; DIM]> = (0..4)
                .map(|k| {
                    let mut y =
                        <[f64; DIM]>::try_from(scenes[k].initial_state(&omega, &q).as_slice())
                            .expect("the class's layout");
                    for r in 0..RODS {
                        let b = (sample * 4 + k) as f64 + 5.0 * r as f64;
                        let x = HUB_STATES + ROD_STATES * r;
                        y[x..x + 4].copy_from_slice(&[
                            1.2 * (0.7 * b).sin(),
                            1.2 * (1.1 * b).cos(),
                            20.0 * (1.3 * b).cos(),
                            20.0 * (0.4 * b).sin(),
                        ]);
                    }
                    y
                })
                .collect();
            for (i, sc) in scenes.iter().enumerate() {
                let run = RodsRun::new(sc, &states[i], 1.0, 0.0).expect("of the class");
                lanes.load(i, &run);
            }
            let y: [F64x4; DIM] =
                std::array::from_fn(|j| F64x4(std::array::from_fn(|i| states[i][j])));
            let (mut fused, mut unfused) = ([F64x4::splat(0.0); DIM], [F64x4::splat(0.0); DIM]);
            lanes.rhs_with::<true>(&y, &mut fused);
            lanes.rhs_with::<false>(&y, &mut unfused);
            for j in 0..DIM {
                for i in 0..4 {
                    let (a, b) = (fused[j].lane(i), unfused[j].lane(i));
                    let scale = (0..DIM).map(|c| fused[c].lane(i).abs()).fold(0.0, f64::max);
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "sample {sample}, lane {i}, component {j}: {a} against {b}"
                    );
                    differing += usize::from(a.to_bits() != b.to_bits());
                }
            }
        }
        assert!(differing > 100, "{differing} components differ");
    }

    /// The class's right-hand side and observation, in four lanes at once, are the scalar
    /// `Spacecraft`'s bit for bit, at states spread over ±1.4 rad and ±30 rad/s for the rods
    /// and over ±80 rad/s for the hub, a rod at rest with signed zeros included, and a flap of
    /// exactly 90° (whose lag has no inertia) poisons the same way.
    #[test]
    fn the_lanes_right_hand_side_and_observation_are_the_spacecrafts() {
        let scenes: Vec<Spacecraft> = (0..4).map(spacecraft).collect();
        let mut checked = 0;
        for sample in 0..40 {
            let states: Vec<[f64; DIM]> = (0..4)
                .map(|k| {
                    let a = (sample * 4 + k) as f64;
                    let q = UnitQuaternion::from_euler_angles(0.3 * a, -0.2, 1.1 - a);
                    let omega =
                        Vector3::new(0.08 * a.cos(), -1.3 + 0.1 * a, 78.5 * (0.3 * a).sin());
                    let mut y =
                        <[f64; DIM]>::try_from(scenes[k].initial_state(&omega, &q).as_slice())
                            .expect("the class's layout");
                    y[3] *= 1.0 + 1e-9 * a;
                    for r in 0..RODS {
                        let b = a + 5.0 * r as f64;
                        let x = HUB_STATES + ROD_STATES * r;
                        y[x..x + 5].copy_from_slice(&[
                            1.4 * (0.7 * b).sin(),
                            1.4 * (1.1 * b + 0.3).cos(),
                            30.0 * (1.3 * b).cos(),
                            30.0 * (0.4 * b - 1.0).sin(),
                            0.1 * b,
                        ]);
                    }
                    if sample == 1 && k == 2 {
                        // A rod at rest, with signed zeros.
                        y[HUB_STATES..HUB_STATES + 4].copy_from_slice(&[-0.0, 0.0, -0.0, 0.0]);
                    }
                    if sample == 2 && k == 1 {
                        y[HUB_STATES + ROD_STATES] = std::f64::consts::FRAC_PI_2;
                    }
                    y
                })
                .collect();
            let mut lanes = RodsLanes::<F64x4>::idle();
            for (i, sc) in scenes.iter().enumerate() {
                let run = RodsRun::new(sc, &states[i], 1.0, 0.0).expect("of the class");
                lanes.load(i, &run);
            }
            let spacecraft: Vec<_> = scenes.iter().collect();
            let case = format!("sample {sample}");
            assert_lanes_are_the_spacecrafts::<RodsRun, DIM>(&lanes, &spacecraft, &states, &case);
            checked += 4;
        }
        assert_eq!(checked, 160);
    }

    /// A spacecraft with three rods, or with a fifth effector, is not of the class, and says so.
    #[test]
    fn other_scenes_are_not_of_the_class() {
        let mut sc = spacecraft(0);
        let y0 = sc.initial_state(&Vector3::z(), &UnitQuaternion::identity());
        assert!(RodsRun::new(&sc, &y0, 1.0, 0.0).is_ok());
        let damper = crate::effectors::Rayleigh {
            name: "damper".into(),
            gamma: Matrix3::identity() * 0.01,
        };
        sc.add_effector(Box::new(damper)).expect("added");
        let y0 = sc.initial_state(&Vector3::z(), &UnitQuaternion::identity());
        let why = RodsRun::new(&sc, &y0, 1.0, 0.0).unwrap_err();
        assert!(why.contains("`damper`"), "{why}");
    }
}
