//! Flap–lag hinged rods coupled together, up to [`LANES`] per call, one rod per lane.
//!
//! A scene's rods (Explorer 1's four antennas) run through the same closed form
//! ([`HingedRod`]'s `couple_closed_form`, docs/effectors.md "Closed forms"). Here the rods'
//! parameters and states sit in arrays of one entry per rod (structure of arrays), so the
//! closed form is one loop of [`LANES`] iterations with no branches, which the compiler turns
//! into vector instructions, and the hinge's constant part of the hub mass,
//! Σ (m − μ) [[1, −[h×]], [[h×], |h|² 1 − h hᵀ]], is summed once when the group is built
//! instead of at every call. The result is each rod's own closed form to rounding (tested);
//! the rods keep their own effectors for states, `derivatives`, momentum and telemetry.

use super::hinged_rod::{HingeFreedom, HingedRod, add_hinge_mass};
use super::particles::ParticleEffector;
use super::rod_closed_form::{ROWS, RodConstants};
use crate::model::{Effector, EffectorGroup, HubAcceleration, HubCoupling, HubState, Momentum};
use crate::sincos::sin_cos_lanes;
use nalgebra::{Matrix6, Vector3};
use std::any::Any;

/// Rods per group.
pub const LANES: usize = 4;

/// One number per lane.
type Lanes = [f64; LANES];

/// Sines and cosines of the lanes' flap angles, then of their lag angles.
type Sines = ([f64; 2 * LANES], [f64; 2 * LANES]);

/// A vector per lane: x, y and z components, each over the lanes.
type LaneVectors = [Lanes; 3];

fn set_lane(v: &mut LaneVectors, r: usize, value: &Vector3<f64>) {
    for (component, x) in v.iter_mut().zip(value.iter()) {
        component[r] = *x;
    }
}

/// Up to [`LANES`] flap–lag rods coupled in one call. Lanes past `count` repeat lane 0 with
/// zero weight: they are computed and not used.
#[derive(Debug, Clone)]
pub struct RodLanes {
    /// Effector index of each rod.
    members: Vec<usize>,
    /// Rods in use.
    count: usize,
    /// 1 for a rod in use, 0 for a padding lane.
    weight: Lanes,
    /// Offset of each lane's states `[θ_f, θ_l, θ̇_f, θ̇_l, …]` in the state vector.
    state_offsets: [usize; LANES],
    /// Hinge point h (m, body axes).
    hinge: LaneVectors,
    /// Rest direction ê₀.
    rest: LaneVectors,
    /// Hinge axis n̂.
    axis: LaneVectors,
    /// b̂ = n̂ × ê₀.
    binormal: LaneVectors,
    /// m₁ = m L/2 (kg m).
    m1: Lanes,
    /// m₂ = m L²/3 (kg m²).
    m2: Lanes,
    /// 1/m₂ (1/(kg m²)).
    inverse_m2: Lanes,
    /// m₁/m₂ (1/m).
    m1_over_m2: Lanes,
    /// μ = m₁²/m₂ (kg).
    mu: Lanes,
    /// m − μ (kg).
    hinge_mass: Lanes,
    /// Torsional stiffness, flap and lag (N m/rad).
    stiffness: [Lanes; 2],
    /// Torsional damping, flap and lag (N m s/rad).
    damping: [Lanes; 2],
    /// Σ (m − μ) [[1, −[h×]], [[h×], |h|² 1 − h hᵀ]] over the rods in use (lower triangle).
    constant_mass: Matrix6<f64>,
    /// Run the versions compiled for AVX2 (the processor has it, checked once at build).
    avx2: bool,
}

impl RodLanes {
    /// The group of `rods`: (effector index, rod, state offset), at least one and at most
    /// [`LANES`], each with both freedoms.
    pub fn new(rods: &[(usize, &HingedRod, usize)]) -> RodLanes {
        assert!(!rods.is_empty() && rods.len() <= LANES);
        let zero = [[0.0; LANES]; 3];
        let mut group = RodLanes {
            members: rods.iter().map(|r| r.0).collect(),
            count: rods.len(),
            weight: [0.0; LANES],
            state_offsets: [0; LANES],
            hinge: zero,
            rest: zero,
            axis: zero,
            binormal: zero,
            m1: [0.0; LANES],
            m2: [0.0; LANES],
            inverse_m2: [0.0; LANES],
            m1_over_m2: [0.0; LANES],
            mu: [0.0; LANES],
            hinge_mass: [0.0; LANES],
            stiffness: [[0.0; LANES]; 2],
            damping: [[0.0; LANES]; 2],
            constant_mass: Matrix6::zeros(),
            avx2: crate::cpu::avx2_available(),
        };
        for r in 0..LANES {
            let used = r < rods.len();
            let (_, rod, state) = rods[if used { r } else { 0 }];
            assert_eq!(rod.freedom, HingeFreedom::FlapLag);
            let (m1, m2) = rod.moments();
            let mu = m1 * m1 / m2;
            group.weight[r] = if used { 1.0 } else { 0.0 };
            group.state_offsets[r] = state;
            set_lane(&mut group.hinge, r, &rod.hinge);
            set_lane(&mut group.rest, r, &rod.direction);
            set_lane(&mut group.axis, r, &rod.axis);
            set_lane(&mut group.binormal, r, &rod.axis.cross(&rod.direction));
            group.m1[r] = m1;
            group.m2[r] = m2;
            group.inverse_m2[r] = 1.0 / m2;
            group.m1_over_m2[r] = m1 / m2;
            group.mu[r] = mu;
            group.hinge_mass[r] = rod.mass - mu;
            for k in 0..2 {
                group.stiffness[k][r] = rod.stiffness[k];
                group.damping[k][r] = rod.damping[k];
            }
            if used {
                add_hinge_mass(&mut group.constant_mass, rod.mass - mu, &rod.hinge);
            }
        }
        group
    }

    /// Each lane's (θ_f, θ_l, θ̇_f, θ̇_l), each over the lanes, and the sines and cosines of
    /// [θ_f (lanes); θ_l (lanes)].
    #[inline(always)]
    fn angles(&self, y: &[f64]) -> ([Lanes; 4], Sines) {
        let mut angles = [[0.0; LANES]; 4];
        for (r, &offset) in self.state_offsets.iter().enumerate() {
            for (a, value) in angles.iter_mut().zip(&y[offset..offset + 4]) {
                a[r] = *value;
            }
        }
        let mut both = [0.0; 2 * LANES];
        both[..LANES].copy_from_slice(&angles[0]);
        both[LANES..].copy_from_slice(&angles[1]);
        (angles, sin_cos_lanes(both))
    }

    /// Lane `r`'s rod as the closed form takes it.
    #[inline(always)]
    pub(crate) fn constants(&self, r: usize) -> RodConstants<f64> {
        let at = |v: &LaneVectors| [v[0][r], v[1][r], v[2][r]];
        RodConstants {
            hinge: at(&self.hinge),
            rest: at(&self.rest),
            axis: at(&self.axis),
            binormal: at(&self.binormal),
            m1: self.m1[r],
            m2: self.m2[r],
            inverse_m2: self.inverse_m2[r],
            m1_over_m2: self.m1_over_m2[r],
            mu: self.mu[r],
            hinge_mass: self.hinge_mass[r],
            stiffness: [self.stiffness[0][r], self.stiffness[1][r]],
            damping: [self.damping[0][r], self.damping[1][r]],
        }
    }

    /// Lane `r`'s angles and rates, and `[sin θ_f, cos θ_f, sin θ_l, cos θ_l]`, from
    /// [`RodLanes::angles`].
    #[inline(always)]
    fn lane_angles(angles: &[Lanes; 4], (s, c): &Sines, r: usize) -> ([f64; 4], [f64; 4]) {
        (
            [angles[0][r], angles[1][r], angles[2][r], angles[3][r]],
            [s[r], c[r], s[LANES + r], c[LANES + r]],
        )
    }

    /// The rods' constant part of the hub's mass matrix (lower triangle).
    pub(crate) fn constant_mass(&self) -> &Matrix6<f64> {
        &self.constant_mass
    }

    /// The groups of a spacecraft's flap–lag rods, [`LANES`] at a time in the order the
    /// effectors come; a last rod left alone keeps its own `couple`.
    pub fn groups(effectors: &[Box<dyn Effector>], state_offsets: &[usize]) -> Vec<RodLanes> {
        let rods: Vec<_> = effectors
            .iter()
            .enumerate()
            .filter_map(|(k, e)| {
                let any: &dyn Any = e.as_ref();
                let rod = any.downcast_ref::<ParticleEffector<HingedRod>>()?.model();
                (rod.freedom == HingeFreedom::FlapLag).then_some((k, rod, state_offsets[k]))
            })
            .collect();
        rods.chunks(LANES)
            .filter(|chunk| chunk.len() > 1)
            .map(RodLanes::new)
            .collect()
    }

    /// [`RodLanes::groups`] as the spacecraft takes them ([`crate::model::Grouping::form`]).
    pub fn form_groups(
        effectors: &[Box<dyn Effector>],
        state_offsets: &[usize],
    ) -> Vec<Box<dyn EffectorGroup>> {
        RodLanes::groups(effectors, state_offsets)
            .into_iter()
            .map(|g| Box::new(g) as Box<dyn EffectorGroup>)
            .collect()
    }
}

/// The group's arithmetic, inlined into each instruction-set version of it below.
impl RodLanes {
    #[allow(clippy::needless_range_loop)] // lane loops index several arrays by lane
    #[inline(always)]
    fn momentum_lanes<const FMA: bool>(&self, hub: &HubState, y: &[f64]) -> Momentum {
        let omega = [hub.omega.x, hub.omega.y, hub.omega.z];
        let (angles, sines) = self.angles(y);
        let mut sum = Momentum::default();
        for r in 0..self.count {
            let (a, s) = Self::lane_angles(&angles, &sines, r);
            let m = self.constants(r).momentum::<FMA>(a, s, omega);
            sum.mass += m.mass;
            sum.first_moment += Vector3::from(m.first_moment);
            sum.linear += Vector3::from(m.linear);
            sum.angular += Vector3::from(m.angular);
            sum.kinetic_energy += m.kinetic_energy;
        }
        sum
    }

    #[allow(clippy::needless_range_loop)] // lane loops index several arrays by lane
    #[inline(always)]
    fn couple_lanes<const FMA: bool>(
        &self,
        hub: &HubState,
        y: &[f64],
        coupling: &mut HubCoupling,
        scratch: &mut [f64],
    ) {
        let omega = hub.omega;
        let w2 = omega.norm_squared();
        let (angles, sines) = self.angles(y);
        // Per lane, what the rod's own closed form computes: the hinge force and moment
        // (times the lane's weight), v = [ê; h × ê] and the W rows.
        let mut force = [[0.0; LANES]; 3];
        let mut moment = [[0.0; LANES]; 3];
        let mut v = [[0.0; LANES]; 6];
        // W, row entry by row entry, each over the lanes.
        let (rows, _) = scratch.split_at_mut(ROWS * LANES);
        let mut cos2 = [0.0; LANES];
        let omega = [omega.x, omega.y, omega.z];
        for r in 0..LANES {
            let (a, s) = Self::lane_angles(&angles, &sines, r);
            let rod = self.constants(r).coupling::<FMA>(a, s, omega, w2);
            cos2[r] = rod.cos2;
            let weight = self.weight[r];
            for i in 0..3 {
                force[i][r] = weight * rod.hinge_force[i];
                moment[i][r] = weight * rod.hinge_moment[i];
            }
            for i in 0..6 {
                v[i][r] = rod.v[i];
            }
            for (row, x) in rod.rows.into_iter().enumerate() {
                rows[row * LANES + r] = x;
            }
        }
        for i in 0..3 {
            coupling.force[i] -= force[i].iter().sum::<f64>();
            coupling.force[3 + i] -= moment[i].iter().sum::<f64>();
        }
        let hub_mass = &mut coupling.mass;
        let mut weighted_mu = [0.0; LANES];
        for r in 0..LANES {
            weighted_mu[r] = self.weight[r] * self.mu[r];
        }
        for i in 0..6 {
            let mut mu_vi = [0.0; LANES];
            for r in 0..LANES {
                mu_vi[r] = weighted_mu[r] * v[i][r];
            }
            for j in 0..=i {
                let mut sum = self.constant_mass[(i, j)];
                for r in 0..LANES {
                    sum += mu_vi[r] * v[j][r];
                }
                hub_mass[(i, j)] += sum;
            }
        }
        for r in 0..self.count {
            if cos2[r].is_nan() || cos2[r] <= 0.0 {
                // Lag has no inertia: poison the hub solve, so the run stops with a diagnosis.
                coupling.force[0] = f64::NAN;
                for row in 0..ROWS {
                    rows[row * LANES + r] = f64::NAN;
                }
            }
        }
        coupling.translation = true;
    }

    #[allow(clippy::needless_range_loop)] // lane loops index several arrays by lane
    #[inline(always)]
    fn derivatives_lanes(
        &self,
        accel: &HubAcceleration,
        y: &[f64],
        scratch: &[f64],
        dydt: &mut [f64],
    ) {
        let z = accel.as_vector6();
        let rows = &scratch[..ROWS * LANES];
        // u̇ = W_g − W_C z (L = 1), as `ParticleEffector::derivatives`, lane by lane.
        let mut u_dot = [[0.0; LANES]; 2];
        for (k, t) in u_dot.iter_mut().enumerate() {
            for r in 0..LANES {
                let mut sum = rows[7 * k * LANES + r];
                for a in 0..6 {
                    sum -= rows[(7 * k + 1 + a) * LANES + r] * z[a];
                }
                t[r] = sum;
            }
        }
        for r in 0..self.count {
            let x = self.state_offsets[r];
            let (flap_rate, lag_rate) = (y[x + 2], y[x + 3]);
            dydt[x..x + 5].copy_from_slice(&[
                flap_rate,
                lag_rate,
                u_dot[0][r],
                u_dot[1][r],
                self.constants(r)
                    .dissipation_power([0.0, 0.0, flap_rate, lag_rate]),
            ]);
        }
    }
}

/// The same arithmetic compiled for AVX2 and FMA, where the four lanes fill one 256-bit
/// register instead of two 128-bit ones and the closed form's fused multiply–adds are one
/// instruction each (the baseline build calls the C library's `fma`, which rounds the same
/// way). Rust contracts no other multiply–add, so these give the baseline build's bits.
#[cfg(target_arch = "x86_64")]
impl RodLanes {
    #[target_feature(enable = "avx2,fma")]
    fn momentum_avx2(&self, hub: &HubState, y: &[f64]) -> Momentum {
        self.momentum_lanes::<true>(hub, y)
    }

    #[target_feature(enable = "avx2,fma")]
    fn couple_avx2(
        &self,
        hub: &HubState,
        y: &[f64],
        coupling: &mut HubCoupling,
        scratch: &mut [f64],
    ) {
        self.couple_lanes::<true>(hub, y, coupling, scratch)
    }

    #[target_feature(enable = "avx2,fma")]
    fn derivatives_avx2(
        &self,
        accel: &HubAcceleration,
        y: &[f64],
        scratch: &[f64],
        dydt: &mut [f64],
    ) {
        self.derivatives_lanes(accel, y, scratch, dydt)
    }
}

impl EffectorGroup for RodLanes {
    fn members(&self) -> &[usize] {
        &self.members
    }

    fn scratch_len(&self) -> usize {
        ROWS * LANES
    }

    fn momentum(&self, hub: &HubState, y: &[f64]) -> Momentum {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the processor has AVX2.
            return unsafe { self.momentum_avx2(hub, y) };
        }
        self.momentum_lanes::<false>(hub, y)
    }

    fn couple(&self, hub: &HubState, y: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: as above.
            return unsafe { self.couple_avx2(hub, y, coupling, scratch) };
        }
        // Without AVX2 and FMA, unfused (`cpu::avx2_available`, which the lanes follow too).
        self.couple_lanes::<false>(hub, y, coupling, scratch)
    }

    fn derivatives(&self, accel: &HubAcceleration, y: &[f64], scratch: &[f64], dydt: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: as above.
            return unsafe { self.derivatives_avx2(accel, y, scratch, dydt) };
        }
        self.derivatives_lanes(accel, y, scratch, dydt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effectors::ParticleModel;
    use nalgebra::Vector6;

    /// A flap–lag rod of the `k`-th sampled geometry and parameters (hinge, rest direction
    /// and hinge axis ⊥ it, spring and damper).
    fn rod(k: usize, freedom: HingeFreedom) -> Box<dyn Effector> {
        let a = k as f64;
        let direction = Vector3::new((0.9 * a).cos(), (0.9 * a).sin(), 0.3 * a - 0.5).normalize();
        let axis = direction
            .cross(&Vector3::new(0.2, -0.7 + 0.1 * a, 1.0))
            .normalize();
        let model = HingedRod {
            mass: 0.139 + 0.05 * a,
            length: 0.56 + 0.1 * a,
            hinge: Vector3::new(0.03 * a, 0.076, 0.1 - 0.2 * a),
            direction,
            axis,
            freedom,
            stiffness: [0.565 + a, 0.3],
            damping: [6e-4, 1e-3 * a],
        };
        let n = model.num_coordinates();
        Box::new(ParticleEffector::new(
            format!("rod {k}"),
            model,
            &[0.0; 2][..n],
            &[0.0; 2][..n],
        ))
    }

    /// Effectors, their state offsets (after the hub's 7) and scratch offsets.
    fn layout(effectors: &[Box<dyn Effector>]) -> (Vec<usize>, Vec<usize>, usize, usize) {
        let (mut states, mut scratch) = (Vec::new(), Vec::new());
        let (mut dim, mut len) = (7, 0);
        for e in effectors {
            states.push(dim);
            scratch.push(len);
            dim += e.num_states();
            len += e.scratch_len();
        }
        (states, scratch, dim, len)
    }

    fn start() -> HubCoupling {
        HubCoupling {
            mass: Matrix6::zeros(),
            force: Vector6::zeros(),
            translation: false,
            tidal: None,
        }
    }

    /// Groups take the flap–lag rods four at a time, in order, past effectors of other kinds,
    /// and leave a last rod alone.
    #[test]
    fn groups_take_flap_lag_rods_four_at_a_time() {
        let effectors: Vec<_> = (0..7)
            .map(|k| {
                let freedom = if k == 2 {
                    HingeFreedom::Flap
                } else {
                    HingeFreedom::FlapLag
                };
                rod(k, freedom)
            })
            .collect();
        let (states, ..) = layout(&effectors);
        let groups = RodLanes::groups(&effectors, &states);
        let members: Vec<_> = groups.iter().map(|g| g.members().to_vec()).collect();
        assert_eq!(members, vec![vec![0, 1, 3, 4], vec![5, 6]]);
        let groups = RodLanes::groups(&effectors[..4], &states);
        let members: Vec<_> = groups.iter().map(|g| g.members().to_vec()).collect();
        assert_eq!(members, vec![vec![0, 1, 3]]);
        assert!(RodLanes::groups(&effectors[..3], &states)[0].members() == [0, 1]);
        assert!(RodLanes::groups(&effectors[..1], &states).is_empty());
    }

    /// A spacecraft forms the same groups through the rods' own `grouping`, without naming
    /// the rods: the hub's contract, as effectors are added one by one past a damper.
    #[test]
    fn a_spacecraft_groups_its_rods_through_the_effector_contract() {
        use crate::effectors::Rayleigh;
        use crate::model::{RigidBody, Spacecraft};
        let hub = RigidBody::from_principal([10.0, 11.0, 12.0]).unwrap();
        let mut spacecraft = Spacecraft::new(hub, Vector3::z());
        spacecraft.hub_mass = Some(14.0);
        let damper = Rayleigh {
            name: "damper".into(),
            gamma: nalgebra::Matrix3::identity() * 0.01,
        };
        spacecraft.add_effector(Box::new(damper)).unwrap();
        for k in 0..7 {
            let freedom = if k == 2 {
                HingeFreedom::Flap
            } else {
                HingeFreedom::FlapLag
            };
            spacecraft.add_effector(rod(k, freedom)).unwrap();
            if k == 0 {
                assert!(spacecraft.group_members().is_empty(), "one rod stays alone");
            }
        }
        // Effector indices are one past the rods' (the damper comes first).
        assert_eq!(
            spacecraft.group_members(),
            vec![vec![1, 2, 4, 5], vec![6, 7]]
        );
    }

    /// A group couples its rods as each rod's own `couple` and `derivatives` do, to
    /// rounding: the hub's mass and force, each rod's derivatives and the rods' summed
    /// momentum, for groups of 1 to 4
    /// rods of different geometries, at states spread over ±1.4 rad and ±30 rad/s; a
    /// non-finite angle poisons the hub's force and the rod's accelerations.
    #[test]
    fn a_group_couples_its_rods_as_each_rod_alone() {
        let mut worst = 0.0f64;
        for count in 1..=LANES {
            // A one-freedom rod in between, so the rods' states are not adjacent.
            let mut effectors: Vec<_> = (0..count)
                .map(|k| rod(k + count, HingeFreedom::FlapLag))
                .collect();
            effectors.insert(1, rod(9, HingeFreedom::Lag));
            let (states, scratch_offsets, dim, len) = layout(&effectors);
            let rods: Vec<_> = (0..effectors.len())
                .filter(|&k| k != 1)
                .map(|k| {
                    let any: &dyn Any = effectors[k].as_ref();
                    let rod = any.downcast_ref::<ParticleEffector<HingedRod>>().unwrap();
                    (k, rod.model(), states[k])
                })
                .collect();
            let group = RodLanes::new(&rods);
            for sample in 0..20 {
                let a = sample as f64;
                // Angles over ±1.4 rad, rates over ±30 rad/s.
                let mut y = vec![0.0; dim];
                for (r, &(_, _, offset)) in rods.iter().enumerate() {
                    let b = a + 5.0 * r as f64;
                    y[offset..offset + 4].copy_from_slice(&[
                        1.4 * (0.7 * b).sin(),
                        1.4 * (1.1 * b + 0.3).cos(),
                        30.0 * (1.3 * b).cos(),
                        30.0 * (0.4 * b - 1.0).sin(),
                    ]);
                }
                let hub = HubState {
                    t: 0.0,
                    omega: Vector3::new(0.4 * a.cos(), -1.3, 4.0 * a),
                    attitude: &[1.0, 0.0, 0.0, 0.0],
                };
                let accel = HubAcceleration {
                    linear: Vector3::new(0.3, -2.0, 0.7 * a),
                    angular: Vector3::new(-1.1, 0.2 * a, 5.0),
                    tidal_power: 0.0,
                };
                // Each rod alone: its couple, then its derivatives from what it kept.
                let (mut alone, mut together) = (start(), start());
                let mut d_alone = vec![0.0; dim];
                let mut kept = vec![0.0; len];
                for &(k, ..) in &rods {
                    let (s, n) = (scratch_offsets[k], effectors[k].scratch_len());
                    let x = states[k]..states[k] + effectors[k].num_states();
                    effectors[k].couple(&hub, &y[x.clone()], &mut alone, &mut kept[s..s + n]);
                    effectors[k].derivatives(
                        &hub,
                        &accel,
                        &y[x.clone()],
                        &kept[s..s + n],
                        &mut d_alone[x],
                    );
                }
                let mut own = vec![0.0; group.scratch_len()];
                group.couple(&hub, &y, &mut together, &mut own);
                let mut d_together = vec![0.0; dim];
                group.derivatives(&accel, &y, &own, &mut d_together);
                let mut close = |a: &[f64], b: &[f64], what: &str| {
                    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    for (x, y) in a.iter().zip(b) {
                        let error = (x - y).abs() / scale;
                        worst = worst.max(error);
                        assert!(
                            error <= 1e-13,
                            "{what}: together {x:e}, alone {y:e} (scale {scale:e}), \
                             {count} rods, sample {sample}"
                        );
                    }
                };
                let lower = |m: &Matrix6<f64>| {
                    (0..6)
                        .flat_map(|i| (0..=i).map(move |j| m[(i, j)]))
                        .collect::<Vec<_>>()
                };
                close(&lower(&together.mass), &lower(&alone.mass), "mass");
                close(together.force.as_slice(), alone.force.as_slice(), "force");
                assert!(together.translation);
                for &(k, ..) in &rods {
                    let x = states[k];
                    // θ̇ and the dissipated power exactly; θ̈ to rounding.
                    assert_eq!(d_together[x..x + 2], d_alone[x..x + 2]);
                    assert_eq!(d_together[x + 4], d_alone[x + 4]);
                    close(&d_together[x + 2..x + 4], &d_alone[x + 2..x + 4], "θ̈");
                }
                // The momentum, summed.
                let mut each = Momentum::default();
                for &(k, ..) in &rods {
                    let x = states[k]..states[k] + effectors[k].num_states();
                    let m = effectors[k].momentum(&hub, &y[x]);
                    each.mass += m.mass;
                    each.first_moment += m.first_moment;
                    each.linear += m.linear;
                    each.angular += m.angular;
                    each.kinetic_energy += m.kinetic_energy;
                }
                let sum = group.momentum(&hub, &y);
                // The baseline build of the same arithmetic (the closed form unfused, as on a
                // processor without AVX2 and FMA) gives the same numbers as the one this
                // processor runs to rounding, and the same bits where this one is the
                // baseline too.
                let mut baseline = group.clone();
                baseline.avx2 = false;
                let mut baseline_coupling = start();
                let mut baseline_scratch = vec![0.0; group.scratch_len()];
                baseline.couple(&hub, &y, &mut baseline_coupling, &mut baseline_scratch);
                let mut d_baseline = vec![0.0; dim];
                baseline.derivatives(&accel, &y, &baseline_scratch, &mut d_baseline);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                if group.avx2 {
                    close(
                        &lower(&together.mass),
                        &lower(&baseline_coupling.mass),
                        "mass, baseline",
                    );
                    close(
                        together.force.as_slice(),
                        baseline_coupling.force.as_slice(),
                        "force, baseline",
                    );
                    for &(k, ..) in &rods {
                        let x = states[k];
                        close(
                            &d_together[x + 2..x + 4],
                            &d_baseline[x + 2..x + 4],
                            "θ̈, baseline",
                        );
                    }
                } else {
                    assert_eq!(
                        bits(together.mass.as_slice()),
                        bits(baseline_coupling.mass.as_slice())
                    );
                    assert_eq!(
                        bits(together.force.as_slice()),
                        bits(baseline_coupling.force.as_slice())
                    );
                    assert_eq!(bits(&d_together), bits(&d_baseline));
                    assert_eq!(bits(&own), bits(&baseline_scratch));
                    assert_eq!(
                        format!("{sum:?}"),
                        format!("{:?}", baseline.momentum(&hub, &y))
                    );
                }
                close(&[sum.mass], &[each.mass], "mass");
                close(
                    &[sum.kinetic_energy],
                    &[each.kinetic_energy],
                    "kinetic energy",
                );
                for (together, alone, what) in [
                    (sum.first_moment, each.first_moment, "Σ m r"),
                    (sum.linear, each.linear, "linear momentum"),
                    (sum.angular, each.angular, "angular momentum"),
                ] {
                    close(together.as_slice(), alone.as_slice(), what);
                }
                // The one-freedom rod's derivatives are not written.
                let x = states[1];
                assert!(
                    d_together[x..x + effectors[1].num_states()]
                        .iter()
                        .all(|v| *v == 0.0)
                );
                // A non-finite flap angle of the last rod poisons the force.
                let last = states[rods[count - 1].0];
                y[last] = f64::NAN;
                let mut poisoned = start();
                group.couple(&hub, &y, &mut poisoned, &mut own);
                assert!(poisoned.force[0].is_nan());
                group.derivatives(&accel, &y, &own, &mut d_together);
                assert!(d_together[last + 2..last + 4].iter().all(|v| v.is_nan()));
            }
        }
        eprintln!("largest difference, relative to each quantity's scale: {worst:e}");
    }
}
