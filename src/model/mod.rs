//! A spacecraft is a rigid hub plus effectors.
//!
//! The hub carries 7 states, body rates ω (rad/s) and the attitude quaternion `(w, x, y, z)`
//! (body → inertial). Each [`Effector`] appends its own states and couples to the hub through
//! [`HubCoupling`], the hub's equations of motion in the unknowns `z = [a_B; ω̇]` (the inertial
//! acceleration of the hub's centre of mass B and the angular acceleration, both in body axes):
//!
//! ```text
//! [ m_hub·1   0     ] [a_B]   [ 0                 ]
//! [ 0         I_hub ] [ ω̇ ] + Σ_e (what e adds)  =  [ −ω × (I_hub ω) + τ_ext ]
//! ```
//!
//! An effector with internal degrees of freedom solves its own equations for its accelerations
//! as an affine function of `z` and substitutes them into the hub's (back-substitution, as in
//! Basilisk's hub-and-effector design), so effectors couple to one another only through the hub
//! and the translation of the hub (the shift of the system centre of mass) is exact for any
//! number of moving masses. When no effector moves mass, only the rotational 3×3 block is
//! solved, and a scene without effectors integrates exactly 7 numbers with no matrix solve.

mod body;
mod observe;
mod secular;

pub use body::{InertiaError, RigidBody};
pub use observe::{Invariants, Observation, angle_between, angle_from};
pub use secular::{Forcing, Secular, SecularMotion, SecularRates};

use crate::integrate::OdeSystem;
use nalgebra::{Matrix3, Matrix6, UnitQuaternion, Vector3, Vector6};
use std::any::Any;

use std::cell::RefCell;
use std::fmt::Debug;

/// Largest number of torque-only effectors the lean right-hand side takes (more go through
/// the general hub coupling).
const MAX_FAST_TORQUES: usize = 4;

/// Number of hub states: ω (3) and q (4).
pub const HUB_STATES: usize = 7;

/// The hub's equations of motion `mass · [a_B; ω̇] = force` as effectors see them (body axes,
/// moments about the hub's centre of mass B).
#[derive(Debug, Clone, PartialEq)]
pub struct HubCoupling {
    /// Generalised mass (kg, kg m, kg m²): translation rows/columns first, then rotation.
    /// Symmetric: an effector may add to its lower triangle only, and the spacecraft copies
    /// that to the upper one once every effector has coupled.
    pub mass: Matrix6<f64>,
    /// Generalised force (N; N m): starts as `[0; −ω × (I ω)]`.
    pub force: Vector6<f64>,
    /// Set by effectors that move mass relative to the hub: the translational block must be
    /// solved too. Otherwise `a_B = 0` and only the rotational block is solved.
    pub translation: bool,
    /// A gravity gradient acting on the moving masses too (scenes with both); `None`
    /// otherwise.
    pub tidal: Option<TidalCoupling>,
}

/// The gravity gradient's field on the masses that move relative to the hub, and what those
/// masses report back for its work.
///
/// Each moving particle of mass m at r (about B, body axes) feels the tidal force
/// `f = m G r`, with `G = (μ/r_o³)(3 r̂ r̂ᵀ − 1)` the gradient of the central body's field at
/// the orbit position r_o (body axes). Taking the expansion about B rather than about the
/// system's centre of mass c leaves out a force `−m G c` uniform in acceleration, which
/// changes only the solved a_B, not the rotation or the coordinates (docs/environment.md,
/// "Gravity gradient on moving masses").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TidalCoupling {
    /// The gradient G (1/s², body axes).
    pub gradient: Matrix3<f64>,
    /// Σ f·(ω × r + ṙ) over the moving particles (W): their tidal power relative to B.
    pub relative_power: f64,
    /// Σ m r over the moving particles (kg m, body axes).
    pub first_moment: Vector3<f64>,
    /// Σ m (ω × r + ṙ) over the moving particles (kg m/s, body axes).
    pub relative_momentum: Vector3<f64>,
    /// Σ m over the moving particles (kg).
    pub moving_mass: f64,
}

impl TidalCoupling {
    /// No moving mass yet in the field `gradient`.
    pub fn new(gradient: Matrix3<f64>) -> TidalCoupling {
        TidalCoupling {
            gradient,
            relative_power: 0.0,
            first_moment: Vector3::zeros(),
            relative_momentum: Vector3::zeros(),
            moving_mass: 0.0,
        }
    }

    /// The tidal forces' power on the moving masses (W) in the frame of the system's centre
    /// of mass, where the total momentum is zero: Σ f·v with v = v_B + ω × r + ṙ and
    /// v_B = −Σ m (ω × r + ṙ) / (hub mass + moving mass).
    pub fn power(&self, hub_mass: f64) -> f64 {
        let v_hub = -self.relative_momentum / (hub_mass + self.moving_mass);
        self.relative_power + (self.gradient * self.first_moment).dot(&v_hub)
    }
}

impl HubCoupling {
    /// Adds a torque (N m, body axes) to the rotational equation.
    #[inline]
    pub fn add_torque(&mut self, torque: &Vector3<f64>) {
        self.force[3] += torque[0];
        self.force[4] += torque[1];
        self.force[5] += torque[2];
    }
}

/// The hub's accelerations, solved from [`HubCoupling`] (or prescribed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HubAcceleration {
    /// Inertial acceleration of the hub's centre of mass, body axes (m/s²).
    pub linear: Vector3<f64>,
    /// Angular acceleration ω̇, body axes (rad/s²).
    pub angular: Vector3<f64>,
    /// Power of the gravity gradient on the moving masses (W; [`TidalCoupling::power`]), for
    /// the gravity-gradient effector's work; 0 without it.
    pub tidal_power: f64,
}

/// The system's centre of mass C relative to the hub's centre of mass B (body axes).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CentreOfMass {
    /// c = r_C − r_B (m).
    pub offset: Vector3<f64>,
    /// v_C − v_B (m/s), the rate of the point C itself: the masses' momentum relative to B
    /// over the total mass, plus the drift of C as mass leaves from where it is.
    pub velocity: Vector3<f64>,
}

impl HubAcceleration {
    /// `[a_B; ω̇]` as one 6-vector.
    pub fn as_vector6(&self) -> Vector6<f64> {
        Vector6::new(
            self.linear[0],
            self.linear[1],
            self.linear[2],
            self.angular[0],
            self.angular[1],
            self.angular[2],
        )
    }
}

/// Read-only view of the hub state an effector sees.
#[derive(Debug, Clone, Copy)]
pub struct HubState<'a> {
    /// Simulation time (s).
    pub t: f64,
    /// Body rates (rad/s).
    pub omega: Vector3<f64>,
    /// Attitude quaternion (w, x, y, z), body → inertial, as integrated (not normalised).
    pub attitude: &'a [f64],
}

/// Mass and momentum an effector carries beyond the rigid hub, in the frame that translates
/// with the hub's centre of mass B and rotates with the body (body axes, about B).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Momentum {
    /// Moving mass (kg): mass not counted in the hub's.
    pub mass: f64,
    /// First moment Σ m r of that mass about B (kg m).
    pub first_moment: Vector3<f64>,
    /// Linear momentum Σ m (ω × r + ṙ) relative to B's velocity (kg m/s).
    pub linear: Vector3<f64>,
    /// Angular momentum about B relative to B's velocity (N m s), including any spinning
    /// rotor's relative momentum.
    pub angular: Vector3<f64>,
    /// Kinetic energy relative to B's velocity (J), beyond the hub's ½ ωᵀ I ω.
    pub kinetic_energy: f64,
}

/// Energy an effector stores and has dissipated.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyAccount {
    /// Elastic (spring) potential energy (J).
    pub elastic: f64,
    /// Energy dissipated since t = 0 (J): an integrated bookkeeping state.
    pub dissipated: f64,
    /// Work done on the spacecraft by an external torque since t = 0 (J): an integrated
    /// bookkeeping state (environmental torques). The energy balance subtracts it.
    pub work: f64,
    /// Present dissipation rate (W, ≥ 0).
    pub power: f64,
}

/// Something an effector asks the 3D view to draw, in body axes about B (m).
#[derive(Debug, Clone, PartialEq)]
pub enum Drawing {
    /// A polyline through points.
    Line {
        /// Vertices (m, body axes).
        points: Vec<Vector3<f64>>,
        /// Line width (m).
        thickness: f64,
    },
    /// A sphere.
    Sphere {
        /// Centre (m, body axes).
        center: Vector3<f64>,
        /// Diameter (m).
        diameter: f64,
    },
    /// A short cylinder (disc) about an axis.
    Disc {
        /// Centre (m, body axes).
        center: Vector3<f64>,
        /// Unit axis (body axes).
        axis: Vector3<f64>,
        /// Diameter (m).
        diameter: f64,
        /// Thickness along the axis (m).
        thickness: f64,
    },
}

/// Where an effector's state stands against the range in which its model holds.
///
/// The measure's unit is the effector's own (a deflection ratio, an angle, a speed); the run
/// warns once past `warn` and stops with a diagnosis past `limit` (`checks.on_validity`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Validity {
    /// The measure at the present state.
    pub value: f64,
    /// Past this the model's error is no longer negligible: warn once.
    pub warn: f64,
    /// Past this the model does not hold.
    pub limit: f64,
}

impl Validity {
    /// Whether the measure is past the warning threshold.
    pub fn past_warning(&self) -> bool {
        self.value > self.warn
    }

    /// Whether the measure is past the limit.
    pub fn past_limit(&self) -> bool {
        self.value > self.limit
    }
}

/// A part of the spacecraft with its own states and couplings (dampers, appendages, torques).
///
/// State layout: `num_dynamic_states()` dynamic states first, then bookkeeping states (such as
/// the dissipated energy) that nothing else depends on. Implementations must keep the counts
/// fixed for their lifetime. An effector at rest has all-zero states.
pub trait Effector: Any + Debug + Send + Sync {
    /// Unique name within the spacecraft (used for telemetry topics).
    fn name(&self) -> &str;
    /// The kind as written in YAML (`rayleigh`, `hinged_rod`, …).
    fn kind(&self) -> &'static str;
    /// Number of states this effector appends to the state vector.
    fn num_states(&self) -> usize;
    /// How many of its states (the leading ones) are dynamic; the rest are bookkeeping.
    fn num_dynamic_states(&self) -> usize {
        self.num_states()
    }
    /// Names of its states, for logs (length `num_states()`).
    fn state_names(&self) -> Vec<String>;
    /// Initial values of its states.
    fn initial_state(&self) -> Vec<f64>;
    /// Whether it moves mass relative to the hub (needs the hub's translation and mass).
    fn moves_mass(&self) -> bool {
        false
    }
    /// Whether it expels mass from the spacecraft (a thruster): the spacecraft's mass then
    /// changes with time, the angular momentum it carries out is booked
    /// ([`Effector::exhaust_rates`], [`Effector::momentum_carried_out`]), and the energy is not
    /// conserved (the motor supplies it).
    fn expels_mass(&self) -> bool {
        false
    }
    /// Whether the mass it carries changes with time without leaving the spacecraft through
    /// it (a tank that a thruster drains): the methods that need a constant mass refuse it,
    /// as they refuse a thruster.
    fn changes_mass(&self) -> bool {
        self.expels_mass()
    }
    /// For an effector that expels mass: overwrites, after [`Effector::derivatives`], the
    /// rates of its states that book what the exhaust carries out, which need the system's
    /// centre of mass `centre` (the spacecraft computes it only in scenes that expel mass).
    fn exhaust_rates(&self, _hub: &HubState, _centre: &CentreOfMass, _x: &[f64], _dx: &mut [f64]) {}
    /// The angular momentum its exhaust has carried out of the spacecraft since t = 0, about
    /// the system's centre of mass (N m s, inertial axes): H + this is conserved.
    fn momentum_carried_out(&self, _x: &[f64]) -> Vector3<f64> {
        Vector3::zeros()
    }
    /// For an effector that expels mass: the rate of change of the mass it carries (kg/s, ≤ 0)
    /// and the part of its first moment's rate (kg m/s, body axes, about B) that its
    /// [`Momentum::linear`] does not hold: ṁ r_e for mass leaving at r_e.
    fn mass_rate(&self, _t: f64) -> (f64, Vector3<f64>) {
        (0.0, Vector3::zeros())
    }
    /// Whether it applies an external torque (then H is not conserved).
    fn is_external(&self) -> bool {
        false
    }
    /// Whether its external torque is always perpendicular to H, so that it turns H without
    /// changing |H| (the energy sink). Only an effector with [`Effector::is_external`] asks.
    fn keeps_momentum_norm(&self) -> bool {
        false
    }
    /// Whether its model takes the spacecraft to be otherwise rigid (the quasi-rigid energy
    /// sink, whose Ĥ is the hub's Iω): then no effector that carries momentum of its own
    /// (one that is not [`Effector::torque_only`]) may share the spacecraft, whichever is
    /// added first.
    fn needs_rigid_spacecraft(&self) -> bool {
        false
    }
    /// The first time after `t` (s) at which its right-hand side is not smooth (a commanded
    /// torque's step or kink), for the integrators to stop at; `None` when there is none.
    fn next_breakpoint(&self, _t: f64) -> Option<f64> {
        None
    }
    /// At its breakpoint `hub.t` (s), updates its held (discrete) states `x`, which have zero
    /// derivative between breakpoints: a step profile's value is a state, not a function of
    /// time, so that no integration stage sees the wrong side of the jump. A discrete
    /// controller samples the hub state here (its tick) and holds its command. Also called
    /// once at t = 0 by [`Spacecraft::initial_state`]: a controller's first tick.
    fn at_breakpoint(&self, _hub: &HubState, _x: &mut [f64]) {}
    /// Whether it has a switching function ([`Effector::switching`]).
    fn has_switching(&self) -> bool {
        false
    }
    /// Its switching function at the hub state and its states `x`: where it changes sign, its
    /// right-hand side kinks (a slope that changes branch with the sign of a rate). The run
    /// loop of an adaptive method extrapolates it from each step to where it will cross zero,
    /// and ends the next step there if it falls inside, so that the step does not straddle
    /// the kink. `None` for none (the default).
    fn switching(&self, _hub: &HubState, _x: &[f64]) -> Option<f64> {
        None
    }
    /// For its share of a discrete linear loop on the body rate (hub torque −G ω sampled
    /// every `period` s and held): its gain matrix G (N m s, body axes) and `period`. Read by
    /// the failure diagnosis, which blames a sampled loop whose G·Δt overcorrects the inertia.
    fn sampled_rate_loop(&self) -> Option<(nalgebra::Matrix3<f64>, f64)> {
        None
    }
    /// For a rotor whose motor holds its relative rate: the states (index within this
    /// effector, value) that make the held rate an equilibrium, the rate first. `None` for
    /// anything else.
    fn held_rotor_states(&self) -> Option<Vec<(usize, f64)>> {
        None
    }
    /// Whether its field also acts on the masses other effectors move (the gravity
    /// gradient): then [`Effector::tidal_gradient`] gives it, and its work includes
    /// [`HubAcceleration::tidal_power`].
    fn acts_on_moving_masses(&self) -> bool {
        false
    }
    /// The gradient G of its field (1/s², body axes) at the hub state, for the tidal force
    /// `m G r` on a moving particle at r ([`TidalCoupling`]).
    fn tidal_gradient(&self, _hub: &HubState) -> Option<Matrix3<f64>> {
        None
    }
    /// Its effect averaged over one period of the torque-free motion, for `method: averaged`:
    /// `None` (the default) when it cannot be averaged that way. Only effectors without
    /// dynamic states whose one state is the energy they dissipated answer.
    fn secular(&self) -> Option<Box<dyn Secular>> {
        None
    }
    /// The same effector with its dissipation removed, in its initial state: the conservative
    /// system whose periodic orbits `method: averaged` averages the dissipation over. `None`
    /// (the default) when it has none to remove or cannot say.
    fn without_dissipation(&self) -> Option<Box<dyn Effector>> {
        None
    }
    /// Whether its [`Effector::couple`] only adds a torque: nothing in the mass matrix, no
    /// translation. A scene of such effectors solves the hub with its constant inverse
    /// inertia instead of the general coupled system.
    fn torque_only(&self) -> bool {
        false
    }
    /// A torque-only effector's torque on the hub (N m, body axes) at the hub state and its
    /// states `x`: what its [`Effector::couple`] adds. Torque-only scenes call this instead of
    /// `couple`, then [`Effector::derivatives`] with the torque as the scratch space (length 3
    /// when [`Effector::scratch_len`] asks for any). The default goes through `couple`.
    fn torque(&self, hub: &HubState, x: &[f64]) -> Vector3<f64> {
        let mut coupling = HubCoupling {
            mass: Matrix6::zeros(),
            force: Vector6::zeros(),
            translation: false,
            tidal: None,
        };
        let mut scratch = vec![0.0; self.scratch_len()];
        self.couple(hub, x, &mut coupling, &mut scratch);
        Vector3::new(coupling.force[3], coupling.force[4], coupling.force[5])
    }
    /// Length of the scratch space `couple` may fill for `derivatives` (numbers).
    fn scratch_len(&self) -> usize {
        0
    }
    /// Adds its terms to the hub equations, given its own states `x`; may leave intermediate
    /// results in `scratch` for [`Effector::derivatives`].
    fn couple(&self, hub: &HubState, x: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]);
    /// [`Effector::couple`] for the one effector of a scene that moves mass, with the hub's
    /// translation eliminated too: the hub (mass `hub_mass`, kg) and this effector then share
    /// a fixed centre of mass, so a_B follows from the other accelerations. Adds to the
    /// rotational rows of `coupling` only (the lower triangle of the rotational block and
    /// `force[3..]`); the spacecraft then solves the rotational block alone and hands
    /// `derivatives` a_B = 0. Returns false, having changed nothing, for an effector without
    /// this form (the spacecraft calls `couple` instead). Never called with tidal forces.
    fn couple_alone(
        &self,
        _hub: &HubState,
        _hub_mass: f64,
        _x: &[f64],
        _coupling: &mut HubCoupling,
        _scratch: &mut [f64],
    ) -> bool {
        false
    }
    /// Whether it has [`Effector::rhs_alone`]'s closed form (which may still decline a
    /// state): the spacecraft asks for it only then.
    fn has_rhs_alone(&self) -> bool {
        false
    }
    /// The whole right-hand side of a scene in which this is the only effector and eliminates
    /// the hub's translation itself (the case of [`Effector::couple_alone`]), in closed form:
    /// writes the hub's angular acceleration `omega_dot` (rad/s², body axes) and the
    /// derivatives of its own states `dx`, given the hub's inertia `hub_inertia` (kg m², about
    /// its centre of mass, lower triangle read) and mass `hub_mass` (kg). Returns false,
    /// having written nothing, for an effector without this form (the spacecraft then
    /// couples and solves). Never called with tidal forces.
    fn rhs_alone(
        &self,
        _hub: &HubState,
        _hub_inertia: &Matrix3<f64>,
        _hub_mass: f64,
        _x: &[f64],
        _omega_dot: &mut Vector3<f64>,
        _dx: &mut [f64],
    ) -> bool {
        false
    }
    /// Writes the derivatives of its own states given the hub accelerations.
    fn derivatives(
        &self,
        hub: &HubState,
        accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    );
    /// Mass and momentum it carries beyond the rigid hub.
    fn momentum(&self, _hub: &HubState, _x: &[f64]) -> Momentum {
        Momentum::default()
    }
    /// Stored and dissipated energy.
    fn energy(&self, _hub: &HubState, _x: &[f64]) -> EnergyAccount {
        EnergyAccount::default()
    }
    /// Names of its telemetry fields (units in `docs/effectors.md`).
    fn telemetry_names(&self) -> Vec<String> {
        self.state_names()
    }
    /// Telemetry values at a sample, in the order of [`Effector::telemetry_names`].
    fn telemetry(&self, _hub: &HubState, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }
    /// What the 3D view draws for it at states `x`.
    fn drawings(&self, _x: &[f64]) -> Vec<Drawing> {
        Vec::new()
    }
    /// Where its states `x` stand against the range its model holds in; `None` for a model
    /// without one. Checked after every accepted step, so it must be cheap.
    fn validity(&self, _x: &[f64]) -> Option<Validity> {
        None
    }
    /// The validity measure at `x` in words, with its value and limits, and what to do
    /// beyond them: `(where it stands, remedy)`, for warnings and diagnoses.
    fn validity_report(&self, _x: &[f64]) -> (String, String) {
        (String::new(), String::new())
    }
    /// The angle (rad, [0, π]) between its magnetic moment and the local field at `hub`, for a
    /// permanent magnet (`magnetic_dipole`): what `field_angle_deg` watches. `None` by default.
    fn field_angle(&self, _hub: &HubState) -> Option<f64> {
        None
    }
    /// Where it stands against the range its model holds in at the hub state `hub` and its
    /// states `x`: what the run checks. The default is [`Effector::validity`], which sees its
    /// states only; a model whose range depends on the hub's motion (eddy currents: the skin
    /// depth, on |ω|) answers here instead.
    fn validity_at(&self, _hub: &HubState, x: &[f64]) -> Option<Validity> {
        self.validity(x)
    }
    /// [`Effector::validity_at`] in words: `(where it stands, remedy)`. The default is
    /// [`Effector::validity_report`].
    fn validity_report_at(&self, _hub: &HubState, x: &[f64]) -> (String, String) {
        self.validity_report(x)
    }
    /// The kind of [`EffectorGroup`] it can be coupled in together with others of its scene
    /// (the flap–lag rods, lane by lane), with the function that forms those groups; `None`
    /// (the default) when it couples alone. The spacecraft calls each kind's function once
    /// with all its effectors, so it never names an effector kind itself.
    fn grouping(&self) -> Option<Grouping> {
        None
    }
}

/// A kind of [`EffectorGroup`], as an effector names it ([`Effector::grouping`]).
#[derive(Debug, Clone, Copy)]
pub struct Grouping {
    /// Names the kind: effectors that give the same name share one call of `form`.
    pub kind: &'static str,
    /// Forms the groups of this kind from all of a spacecraft's effectors and the offsets of
    /// their states in the state vector; each group claims the members it couples, and an
    /// effector left out keeps its own [`Effector::couple`].
    pub form: FormGroups,
}

/// [`Grouping::form`]: all of a spacecraft's effectors and their state offsets in, the
/// groups of one kind out.
pub type FormGroups = fn(&[Box<dyn Effector>], &[usize]) -> Vec<Box<dyn EffectorGroup>>;

/// The groups of every kind that `effectors` name, kinds in the order they first appear.
fn form_groups(effectors: &[Box<dyn Effector>], offsets: &[usize]) -> Vec<Box<dyn EffectorGroup>> {
    let mut kinds: Vec<Grouping> = Vec::new();
    for grouping in effectors.iter().filter_map(|e| e.grouping()) {
        if kinds.iter().all(|k| k.kind != grouping.kind) {
            kinds.push(grouping);
        }
    }
    kinds
        .iter()
        .flat_map(|k| (k.form)(effectors, offsets))
        .collect()
}

/// A prescribed hub rotation (a motor drives the hub; its centre of mass is pinned).
pub trait HubMotion: Debug + Send + Sync {
    /// Body rates ω(t) (rad/s).
    fn omega(&self, t: f64) -> Vector3<f64>;
    /// Angular acceleration ω̇(t) (rad/s²).
    fn omega_dot(&self, t: f64) -> Vector3<f64>;
    /// One-line description for logs.
    fn describe(&self) -> String;
}

/// Why an effector could not be added.
#[derive(Debug, Clone, PartialEq)]
pub struct AddEffectorError(pub String);

impl std::fmt::Display for AddEffectorError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for AddEffectorError {}

/// Several effectors coupled in one call, in place of their own [`Effector::couple`] (such as
/// the scene's flap–lag rods, lane by lane), formed through [`Effector::grouping`]. Used when
/// no tidal field acts on the moving masses; the members' `couple` serves otherwise.
pub trait EffectorGroup: Debug + Send + Sync {
    /// Indices of the member effectors in the spacecraft.
    fn members(&self) -> &[usize];
    /// Length of the group's own scratch space (f64s), which `couple` fills for
    /// `derivatives`.
    fn scratch_len(&self) -> usize;
    /// Adds the members' terms to `coupling`, as their own `couple` would; `y` is the whole
    /// state.
    fn couple(&self, hub: &HubState, y: &[f64], coupling: &mut HubCoupling, scratch: &mut [f64]);
    /// The members' momentum, summed: the sum of their own [`Effector::momentum`].
    fn momentum(&self, hub: &HubState, y: &[f64]) -> Momentum;
    /// Writes the members' state derivatives into `dydt` (the whole state's), as their own
    /// `couple` and `derivatives` would.
    fn derivatives(&self, accel: &HubAcceleration, y: &[f64], scratch: &[f64], dydt: &mut [f64]);
}

thread_local! {
    /// Per-thread scratch space for effectors (no allocation per right-hand-side call).
    static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The hub plus its effectors: an [`OdeSystem`] over `[ω, q, effector states…]`.
#[derive(Debug)]
pub struct Spacecraft {
    /// The rigid hub.
    pub hub: RigidBody,
    /// Hub mass (kg), required when an effector moves mass.
    pub hub_mass: Option<f64>,
    /// Unit vector in body axes whose angle to H is the reported nutation angle.
    pub spin_axis: Vector3<f64>,
    effectors: Vec<Box<dyn Effector>>,
    /// When set, the hub's rotation is prescribed and its centre of mass pinned.
    motion: Option<Box<dyn HubMotion>>,
    /// When the body axes are principal: `[(I2−I3)/I1, (I3−I1)/I2, (I1−I2)/I3]`, the
    /// coefficients of Euler's equations in their 3-term form (exact, fewer operations).
    euler_coefficients: Option<[f64; 3]>,
    /// Offset of each effector's states in the state vector.
    offsets: Vec<usize>,
    /// Number of states of each effector (its `num_states`, kept to spare a virtual call per
    /// right-hand side).
    lens: Vec<usize>,
    /// Length of each effector's scratch space (its `scratch_len`, likewise).
    scratch_lens: Vec<usize>,
    /// Offset of each effector's scratch space.
    scratch_offsets: Vec<usize>,
    scratch_len: usize,
    translation: bool,
    /// Every effector is [`Effector::torque_only`] (and there is at least one).
    torque_only: bool,
    /// Some effector has a [`Effector::field_angle`] (a permanent magnet): observations then
    /// evaluate it.
    pub(crate) has_magnet: bool,
    /// Effectors coupled together ([`EffectorGroup`]), rebuilt as effectors are added.
    groups: Vec<Box<dyn EffectorGroup>>,
    /// Whether each effector belongs to one of `groups`.
    grouped: Vec<bool>,
    /// Each group's scratch space (after the effectors').
    group_scratch: Vec<std::ops::Range<usize>>,
    /// The effector whose field acts on the moving masses too, when some effector moves
    /// mass ([`Effector::acts_on_moving_masses`]).
    tidal_source: Option<usize>,
    /// The one effector that moves mass, when there is exactly one: it may eliminate the
    /// hub's translation itself ([`Effector::couple_alone`]).
    alone: Option<usize>,
    /// Some effector expels mass ([`Effector::expels_mass`]): the right-hand side then books
    /// what its exhaust carries out ([`Spacecraft::exhaust_rates`]).
    expels_mass: bool,
    /// Whether that effector is the scene's only one, ungrouped, with no gravity gradient,
    /// and has a closed form for the whole right-hand side ([`Effector::has_rhs_alone`]): the
    /// right-hand side then first asks [`Spacecraft::lone_rhs`].
    lone_only: bool,
    dim: usize,
}

impl Spacecraft {
    /// A rigid spacecraft with no effectors. `spin_axis` is normalised here.
    pub fn new(hub: RigidBody, spin_axis: Vector3<f64>) -> Self {
        let i = &hub.inertia;
        let diagonal = (0..3).all(|r| (0..3).all(|c| r == c || i[(r, c)] == 0.0));
        let euler_coefficients = diagonal.then(|| {
            let (a, b, c) = (i[(0, 0)], i[(1, 1)], i[(2, 2)]);
            [(b - c) / a, (c - a) / b, (a - b) / c]
        });
        Spacecraft {
            euler_coefficients,
            hub,
            hub_mass: None,
            spin_axis: spin_axis.normalize(),
            effectors: Vec::new(),
            motion: None,
            offsets: Vec::new(),
            lens: Vec::new(),
            scratch_lens: Vec::new(),
            scratch_offsets: Vec::new(),
            scratch_len: 0,
            translation: false,
            torque_only: false,
            has_magnet: false,
            groups: Vec::new(),
            grouped: Vec::new(),
            group_scratch: Vec::new(),
            tidal_source: None,
            alone: None,
            expels_mass: false,
            lone_only: false,
            dim: HUB_STATES,
        }
    }

    /// Euler's coefficients `[(I₂−I₃)/I₁, (I₃−I₁)/I₂, (I₁−I₂)/I₃]` when the body axes are
    /// principal (the right-hand side then takes Euler's equations in their three-term form).
    pub fn euler_coefficients(&self) -> Option<[f64; 3]> {
        self.euler_coefficients
    }

    /// Appends an effector; its states follow those already present. Effectors that move mass
    /// need the hub mass set first.
    pub fn add_effector(&mut self, effector: Box<dyn Effector>) -> Result<(), AddEffectorError> {
        if self.effectors.iter().any(|e| e.name() == effector.name()) {
            return Err(AddEffectorError(format!(
                "two effectors are named `{}`; names must be unique",
                effector.name()
            )));
        }
        let rigid_only = |e: &dyn Effector| e.needs_rigid_spacecraft();
        let carries_momentum = |e: &dyn Effector| !e.torque_only();
        let clash = if rigid_only(effector.as_ref()) {
            self.effectors.iter().find(|e| carries_momentum(e.as_ref()))
        } else if carries_momentum(effector.as_ref()) {
            self.effectors.iter().find(|e| rigid_only(e.as_ref()))
        } else {
            None
        };
        if let Some(other) = clash {
            let (sink, carrier) = if rigid_only(effector.as_ref()) {
                (effector.as_ref(), other.as_ref())
            } else {
                (other.as_ref(), effector.as_ref())
            };
            return Err(AddEffectorError(format!(
                "effector `{}` ({}) models a quasi-rigid spacecraft, and effector `{}` ({}) \
                 carries momentum of its own, so |H| would not be kept; model the \
                 dissipation with the effector that carries the momentum instead",
                sink.name(),
                sink.kind(),
                carrier.name(),
                carrier.kind()
            )));
        }
        if effector.moves_mass() {
            if !self.hub_mass.is_some_and(|m| m.is_finite() && m > 0.0) {
                return Err(AddEffectorError(format!(
                    "effector `{}` moves mass relative to the hub, so the hub's mass is needed: \
                     expected `body.mass` (kg)",
                    effector.name()
                )));
            }
            self.translation = true;
        }
        self.expels_mass |= effector.changes_mass();
        if effector.acts_on_moving_masses() {
            if self.tidal_source.is_some() {
                return Err(AddEffectorError(format!(
                    "effector `{}`: a scene takes one gravity gradient",
                    effector.name()
                )));
            }
            self.tidal_source = Some(self.effectors.len());
        }
        self.has_magnet |= effector.kind() == "magnetic_dipole";
        self.torque_only =
            effector.torque_only() && (self.effectors.is_empty() || self.torque_only);
        self.offsets.push(self.dim);
        self.lens.push(effector.num_states());
        self.dim += effector.num_states();
        self.scratch_offsets.push(self.scratch_len);
        self.scratch_lens.push(effector.scratch_len());
        self.scratch_len += effector.scratch_len();
        self.effectors.push(effector);
        self.alone = lone_mover(&self.effectors);
        self.groups = form_groups(&self.effectors, &self.offsets);
        self.grouped = vec![false; self.effectors.len()];
        for &k in self.groups.iter().flat_map(|g| g.members()) {
            self.grouped[k] = true;
        }
        // The groups' scratch follows the effectors'.
        self.group_scratch = self
            .groups
            .iter()
            .scan(self.scratch_len, |start, g| {
                let range = *start..*start + g.scratch_len();
                *start = range.end;
                Some(range)
            })
            .collect();
        self.lone_only = self.only_the_lone_mover();
        Ok(())
    }

    /// See [`Spacecraft::lone_only`].
    fn only_the_lone_mover(&self) -> bool {
        self.alone == Some(0)
            && self.effectors.len() == 1
            && self.groups.is_empty()
            && self.tidal_source.is_none()
            && self.effectors[0].has_rhs_alone()
    }

    /// Whether a lone mass-moving effector may eliminate the hub's translation itself
    /// ([`Effector::couple_alone`]; on by default): tests compare that path with the general
    /// one.
    #[cfg(test)]
    pub(crate) fn couple_alone_effector(&mut self, on: bool) {
        self.alone = lone_mover(&self.effectors).filter(|_| on);
        self.lone_only = self.only_the_lone_mover();
    }

    /// The members of each of its effector groups ([`Effector::grouping`]).
    pub(crate) fn group_members(&self) -> Vec<Vec<usize>> {
        self.groups.iter().map(|g| g.members().to_vec()).collect()
    }

    /// Prescribes the hub's rotation (its centre of mass is then pinned in inertial space).
    pub fn set_motion(&mut self, motion: Box<dyn HubMotion>) {
        self.motion = Some(motion);
    }

    /// Whether the right-hand side is the one effector's closed form for the whole system
    /// ([`Effector::rhs_alone`]): a single effector moving mass, ungrouped, with no gravity
    /// gradient and no prescribed motion.
    pub fn takes_lone_closed_form(&self) -> bool {
        self.motion.is_none() && self.lone_only
    }

    /// Whether the right-hand side is Euler's equations in their three-term form plus the
    /// effectors' torques, each computed once (`torque_rhs`): principal body axes, every
    /// effector torque-only (at most a few), no prescribed motion, nothing expelled.
    pub fn takes_torque_closed_form(&self) -> bool {
        self.motion.is_none()
            && !self.lone_only
            && !self.effectors.is_empty()
            && self.torque_only
            && self.effectors.len() <= MAX_FAST_TORQUES
            && !self.expels_mass
            && self.euler_coefficients.is_some()
    }

    /// Whether the right-hand side is the hub's 6 × 6 equations with every effector coupled
    /// through its group (`RodLanes`, say) and none alone: the hub's mass is set, no effector
    /// is torque-only or alone in its closed form, and nothing is prescribed, expelled or
    /// acted on by a field.
    pub fn takes_grouped_closed_form(&self) -> bool {
        self.motion.is_none()
            && !self.lone_only
            && !self.torque_only
            && self.translation
            && self.tidal_source.is_none()
            && !self.expels_mass
            && !self.effectors.is_empty()
            && self.grouped.iter().all(|&g| g)
    }

    /// Whether the right-hand side is the hub's rotational equations alone with every
    /// effector coupled on its own (`couple`, then `derivatives`), solved by the rotational
    /// block's cofactor inverse: no effector moves mass, none is torque-only or grouped or
    /// alone in a closed form, and nothing is prescribed, expelled or tidal.
    pub fn takes_rotational_solve(&self) -> bool {
        self.motion.is_none()
            && !self.lone_only
            && !self.torque_only
            && !self.translation
            && self.alone.is_none()
            && self.tidal_source.is_none()
            && !self.expels_mass
            && !self.effectors.is_empty()
            && self.grouped.iter().all(|&g| !g)
    }

    /// The prescribed hub motion, if any.
    pub fn motion(&self) -> Option<&dyn HubMotion> {
        self.motion.as_deref()
    }

    /// The first breakpoint of any effector after `t` (s): where the right-hand side is not
    /// smooth and the integrators must stop and restart ([`Effector::next_breakpoint`]).
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.effectors
            .iter()
            .filter_map(|e| e.next_breakpoint(t))
            .min_by(f64::total_cmp)
    }

    /// Whether an effector has a switching function ([`Effector::has_switching`]).
    pub fn has_switching(&self) -> bool {
        self.effectors.iter().any(|e| e.has_switching())
    }

    /// Each effector's switching function at `(t, y)` into `out` (one per effector,
    /// [`Effector::switching`]; 0 where it has none).
    pub fn switching_values(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let hub = self.hub_state(t, y);
        for (k, e) in self.effectors.iter().enumerate() {
            let off = self.offsets[k];
            out[k] = e
                .switching(&hub, &y[off..off + self.lens[k]])
                .unwrap_or(0.0);
        }
    }

    /// Updates every effector's held states in `y` at the breakpoint `t` (s), where each
    /// samples the hub state in `y` ([`Effector::at_breakpoint`]).
    pub fn at_breakpoint(&self, t: f64, y: &mut [f64]) {
        let (hub_part, effector_part) = y.split_at_mut(HUB_STATES);
        let hub = HubState {
            t,
            omega: Vector3::new(hub_part[0], hub_part[1], hub_part[2]),
            attitude: &hub_part[3..7],
        };
        for (k, e) in self.effectors.iter().enumerate() {
            let off = self.offsets[k] - HUB_STATES;
            e.at_breakpoint(&hub, &mut effector_part[off..off + self.lens[k]]);
        }
    }

    /// The hub's part of the state `y` at time `t` (s), as the effectors see it.
    pub fn hub_state<'a>(&self, t: f64, y: &'a [f64]) -> HubState<'a> {
        HubState {
            t,
            omega: Vector3::new(y[0], y[1], y[2]),
            attitude: &y[3..7],
        }
    }

    /// The effectors, in state order.
    pub fn effectors(&self) -> &[Box<dyn Effector>] {
        &self.effectors
    }

    /// Whether the total angular momentum is conserved (no external torque, no prescribed
    /// motion): then its drift is a measure of integration error.
    pub fn conserves_momentum(&self) -> bool {
        self.motion.is_none() && !self.effectors.iter().any(|e| e.is_external())
    }

    /// Whether |H| is kept although H is not: every external torque is perpendicular to H
    /// (the energy sink's), so a change of |H| is drift, not the torque's work.
    pub fn keeps_momentum_norm(&self) -> bool {
        self.motion.is_none()
            && self
                .effectors
                .iter()
                .all(|e| !e.is_external() || e.keeps_momentum_norm())
    }

    /// Whether kinetic + elastic + dissipated energy is conserved (no prescribed motion, and
    /// no motor supplying energy: no effector expels mass).
    pub fn conserves_energy(&self) -> bool {
        self.motion.is_none() && !self.expels_mass
    }

    /// Whether some effector expels mass ([`Effector::expels_mass`]): the spacecraft's mass
    /// changes, and the exhaust's angular momentum is booked.
    pub fn expels_mass(&self) -> bool {
        self.expels_mass
    }

    /// The initial state vector for body rates `omega` (rad/s) and attitude `q`.
    pub fn initial_state(&self, omega: &Vector3<f64>, q: &UnitQuaternion<f64>) -> Vec<f64> {
        let mut y = Vec::with_capacity(self.dim);
        y.extend_from_slice(omega.as_slice());
        y.extend_from_slice(&[q.w, q.i, q.j, q.k]);
        for e in &self.effectors {
            y.extend(e.initial_state());
        }
        // Discrete controllers take their first sample at t = 0.
        self.at_breakpoint(0.0, &mut y);
        y
    }

    /// The state with every effector at rest (all effector states zero).
    pub fn rest_state(&self, omega: &Vector3<f64>, q: &UnitQuaternion<f64>) -> Vec<f64> {
        let mut y = vec![0.0; self.dim];
        y[..3].copy_from_slice(omega.as_slice());
        y[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        y
    }

    /// Offset of effector `index`'s states in the state vector.
    pub fn effector_offset(&self, index: usize) -> usize {
        self.offsets[index]
    }

    /// The slice of `y` holding effector `index`'s states.
    pub fn effector_states<'a>(&self, index: usize, y: &'a [f64]) -> &'a [f64] {
        let start = self.offsets[index];
        &y[start..start + self.effectors[index].num_states()]
    }

    /// Derived quantities (momentum, energy, angles) at state `y`.
    pub fn observe(&self, t: f64, y: &[f64]) -> Observation {
        observe::observe(self, t, y, true)
    }

    /// [`Spacecraft::observe`] for the run loop's event checks: the angles to the principal
    /// axes (three arctangents) are computed only if `angles`, and are NaN otherwise.
    pub(crate) fn observe_for_events(&self, t: f64, y: &[f64], angles: bool) -> Observation {
        observe::observe(self, t, y, angles)
    }

    /// The angle between `omega` (rad/s, body axes) and each principal axis of the hub, in
    /// principal order (rad, [0, π]).
    pub(crate) fn angles_to_principal(&self, omega: &Vector3<f64>) -> [f64; 3] {
        observe::angles_to_principal(self, omega)
    }

    /// Momentum, energy and `|q|` only (no angles): cheap enough for every step.
    pub fn invariants(&self, t: f64, y: &[f64]) -> Invariants {
        observe::invariants(self, t, y).0
    }

    /// Inertia tensor of the whole spacecraft about its centre of mass with the effectors in
    /// the configuration of `y`, as if locked (kg m², body axes).
    pub fn system_inertia(&self, y: &[f64]) -> Matrix3<f64> {
        // H is linear in ω and the effector rates jointly, so the difference H(ω = e_c) − H(0)
        // is the inertia's column c whatever the effectors' rates are.
        let mut frozen = y.to_vec();
        let h_of = |w: Vector3<f64>, state: &mut Vec<f64>| {
            state[..3].copy_from_slice(w.as_slice());
            self.invariants(0.0, state).h_body
        };
        let h0 = h_of(Vector3::zeros(), &mut frozen);
        let mut inertia = Matrix3::zeros();
        for c in 0..3 {
            let h = h_of(Vector3::ith(c, 1.0), &mut frozen);
            inertia.set_column(c, &(h - h0));
        }
        inertia
    }

    /// Angle (rad) between H and the maximum-inertia axis of the spacecraft as configured in
    /// `y`, and that largest moment (kg m²). When the two largest moments are within 1% of
    /// each other (a nearly axisymmetric body, whose every transverse axis is a
    /// maximum-inertia axis), the angle is to the plane they span. A flat spin has this near 0.
    pub fn angle_to_max_inertia(&self, y: &[f64]) -> (f64, f64) {
        let inertia = self.system_inertia(y);
        let eig = inertia.symmetric_eigen();
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let [min, mid, max] = order;
        let h = self.invariants(0.0, y).h_body;
        let i_max = eig.eigenvalues[max];
        let axis_angle = |c: usize| observe::angle_between(&h, &eig.eigenvectors.column(c).into());
        let angle = if i_max - eig.eigenvalues[mid] < 1e-2 * i_max {
            (std::f64::consts::FRAC_PI_2 - axis_angle(min)).abs()
        } else {
            let a = axis_angle(max);
            a.min(std::f64::consts::PI - a)
        };
        (angle, i_max)
    }

    /// Hub acceleration ω̇ (rad/s²) for the hub-only case: `I⁻¹ (−ω × Iω)`.
    #[inline(always)]
    fn rigid_omega_dot(&self, omega: &Vector3<f64>) -> Vector3<f64> {
        if let Some([c1, c2, c3]) = self.euler_coefficients {
            return Vector3::new(
                c1 * omega[1] * omega[2],
                c2 * omega[2] * omega[0],
                c3 * omega[0] * omega[1],
            );
        }
        let h = self.hub.inertia * omega;
        self.hub.inertia_inv * (-omega.cross(&h))
    }

    /// The hub's equations with every effector's terms added, at state `y`, written into
    /// `coupling` (zero on entry; filled in place because returning it by value cost a copy
    /// of some 0.3 kB per call); effectors leave their intermediate results in `scratch`. With `free_hub` (the hub's
    /// translation free and solved for), a lone mass-moving effector may eliminate that
    /// translation itself ([`Effector::couple_alone`]), and the coupling then has
    /// `translation` false.
    #[inline(always)]
    fn couple(
        &self,
        hub: &HubState,
        y: &[f64],
        scratch: &mut [f64],
        free_hub: bool,
        coupling: &mut HubCoupling,
    ) {
        let omega = hub.omega;
        // Torque-only scenes never read the mass matrix (see `rhs`).
        if !self.torque_only {
            let m = self.hub_mass.unwrap_or(1.0);
            for i in 0..3 {
                coupling.mass[(i, i)] = m;
            }
            coupling
                .mass
                .fixed_view_mut::<3, 3>(3, 3)
                .copy_from(&self.hub.inertia);
        }
        let gyro = -omega.cross(&(self.hub.inertia * omega));
        coupling.force[3] = gyro[0];
        coupling.force[4] = gyro[1];
        coupling.force[5] = gyro[2];
        coupling.translation = self.translation;
        if let Some(k) = self.tidal_source {
            coupling.tidal = self.effectors[k]
                .tidal_gradient(hub)
                .map(TidalCoupling::new);
        }
        // Grouped effectors couple through their group, unless a tidal field needs each
        // particle (their own `couple` sums the particles then).
        let use_groups = coupling.tidal.is_none();
        let alone = self.alone.filter(|_| free_hub && use_groups);
        for (k, e) in self.effectors.iter().enumerate() {
            if use_groups && self.grouped[k] {
                continue;
            }
            let off = self.offsets[k];
            let s = self.scratch_offsets[k];
            let (x, scratch) = (
                &y[off..off + self.lens[k]],
                &mut scratch[s..s + self.scratch_lens[k]],
            );
            if alone == Some(k) {
                let hub_mass = self.hub_mass.unwrap_or(f64::NAN);
                if e.couple_alone(hub, hub_mass, x, coupling, scratch) {
                    coupling.translation = false;
                    continue;
                }
            }
            e.couple(hub, x, coupling, scratch);
        }
        if use_groups {
            for (group, range) in self.groups.iter().zip(&self.group_scratch) {
                group.couple(hub, y, coupling, &mut scratch[range.clone()]);
            }
        }
        // Effectors add to the lower triangle only (the mass matrix is symmetric). The solves
        // read the lower triangle alone; the copy stays for the fallbacks, and because a
        // release build without it computed wrong accelerations in one scene
        // (docs/benchmarks.md, "Wrong accelerations from some release builds").
        for i in 0..6 {
            for j in 0..i {
                coupling.mass[(j, i)] = coupling.mass[(i, j)];
            }
        }
    }

    /// Right-hand side of a scene whose effectors only apply torques (at most
    /// [`MAX_FAST_TORQUES`]): I ω̇ = −ω × Iω + Σ τ with the constant inverse inertia, each
    /// torque computed once by [`Effector::torque`] and handed to its `derivatives` as the
    /// scratch; no hub coupling, no thread-local scratch. Returns ω̇.
    #[inline(always)]
    fn torque_rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) -> Vector3<f64> {
        let omega = Vector3::new(y[0], y[1], y[2]);
        let hub = HubState {
            t,
            omega,
            attitude: &y[3..7],
        };
        let mut torques = [Vector3::zeros(); MAX_FAST_TORQUES];
        let mut total = Vector3::zeros();
        for (k, e) in self.effectors.iter().enumerate() {
            let off = self.offsets[k];
            torques[k] = e.torque(&hub, &y[off..off + self.lens[k]]);
            total += torques[k];
        }
        // ω̇ = I⁻¹(−ω × Iω) + I⁻¹ Σ τ: with principal body axes, Euler's 3-term form plus the
        // diagonal inverse.
        let angular = if self.euler_coefficients.is_some() {
            let inv = &self.hub.inertia_inv;
            self.rigid_omega_dot(&omega)
                + Vector3::new(
                    inv[(0, 0)] * total[0],
                    inv[(1, 1)] * total[1],
                    inv[(2, 2)] * total[2],
                )
        } else {
            self.hub.inertia_inv * (total - omega.cross(&(self.hub.inertia * omega)))
        };
        let accel = HubAcceleration {
            linear: Vector3::zeros(),
            angular,
            tidal_power: 0.0,
        };
        for (k, e) in self.effectors.iter().enumerate() {
            let off = self.offsets[k];
            let n = self.lens[k];
            let scratch = &torques[k].as_slice()[..self.scratch_lens[k].min(3)];
            e.derivatives(
                &hub,
                &accel,
                &y[off..off + n],
                scratch,
                &mut dydt[off..off + n],
            );
        }
        accel.angular
    }

    /// Right-hand side of a scene whose one effector moves mass and eliminates the hub's
    /// translation itself ([`Spacecraft::lone_only`]), from the effector's closed form
    /// ([`Effector::rhs_alone`]): no coupling matrix, no scratch and no loops over effectors.
    /// Writes the whole of `dydt` and returns true, or returns false having written nothing
    /// when the effector has no such form (the general path then runs). Out of line, so that
    /// the other scenes' right-hand sides compile as before.
    #[inline(never)]
    fn lone_rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) -> bool {
        let omega = Vector3::new(y[0], y[1], y[2]);
        let hub = HubState {
            t,
            omega,
            attitude: &y[3..7],
        };
        let (off, n) = (self.offsets[0], self.lens[0]);
        let hub_mass = self.hub_mass.unwrap_or(f64::NAN);
        let mut omega_dot = Vector3::zeros();
        if !self.effectors[0].rhs_alone(
            &hub,
            &self.hub.inertia,
            hub_mass,
            &y[off..off + n],
            &mut omega_dot,
            &mut dydt[off..off + n],
        ) {
            return false;
        }
        let hub_dy = &mut dydt[..HUB_STATES];
        hub_dy[0] = omega_dot[0];
        hub_dy[1] = omega_dot[1];
        hub_dy[2] = omega_dot[2];
        quaternion_rate(&y[3..7], &omega, &mut hub_dy[3..7]);
        true
    }

    /// `start` plus every effector's [`Momentum`] at state `y` (grouped effectors' from their
    /// group), summed in state order, then the groups'.
    #[inline(always)]
    pub(crate) fn summed_momentum(&self, hub: &HubState, y: &[f64], start: Momentum) -> Momentum {
        let grouped = self.groups.iter().map(|g| g.momentum(hub, y));
        let alone = (0..self.effectors.len())
            .filter(|&k| !self.grouped[k])
            .map(|k| self.effectors[k].momentum(hub, self.effector_states(k, y)));
        let mut sum = start;
        for m in alone.chain(grouped) {
            sum.angular += m.angular;
            sum.kinetic_energy += m.kinetic_energy;
            sum.mass += m.mass;
            sum.first_moment += m.first_moment;
            sum.linear += m.linear;
        }
        sum
    }

    /// The rates of the bookkeeping of what the exhaust carries out
    /// ([`Effector::exhaust_rates`]), given the system's centre of mass. Out of line and cold:
    /// the other scenes' right-hand sides compile as before.
    #[cold]
    #[inline(never)]
    fn exhaust_rates(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let hub = &HubState {
            t,
            omega: Vector3::new(y[0], y[1], y[2]),
            attitude: &y[3..7],
        };
        let centre = self.centre_of_mass(hub, y);
        for (k, e) in self.effectors.iter().enumerate() {
            if e.expels_mass() {
                let (off, n) = (self.offsets[k], self.lens[k]);
                e.exhaust_rates(hub, &centre, &y[off..off + n], &mut dydt[off..off + n]);
            }
        }
    }

    /// The system's centre of mass relative to B at state `y`, from every effector's
    /// [`Momentum`] (for effectors that expel mass).
    fn centre_of_mass(&self, hub: &HubState, y: &[f64]) -> CentreOfMass {
        let start = Momentum {
            mass: self.hub_mass.unwrap_or(0.0),
            ..Momentum::default()
        };
        let Momentum {
            mass,
            first_moment,
            linear,
            ..
        } = self.summed_momentum(hub, y, start);
        // The point C moves at the masses' momentum over M, and also because mass leaves:
        // d/dt (S / M) gains (Σ ṁ r_e − c Σ ṁ) / M.
        let offset = first_moment / mass;
        let (mut mass_rate, mut moment_rate) = (0.0, Vector3::zeros());
        for e in &self.effectors {
            let (dm, ds) = e.mass_rate(hub.t);
            mass_rate += dm;
            moment_rate += ds;
        }
        CentreOfMass {
            offset,
            velocity: (linear + moment_rate - mass_rate * offset) / mass,
        }
    }

    /// Right-hand side with the hub's accelerations taken from `solve(coupling)`.
    #[inline(always)]
    fn effector_rhs(
        &self,
        t: f64,
        y: &[f64],
        dydt: &mut [f64],
        free_hub: bool,
        solve: impl FnOnce(&HubCoupling) -> HubAcceleration,
    ) -> Vector3<f64> {
        let omega = Vector3::new(y[0], y[1], y[2]);
        let hub = HubState {
            t,
            omega,
            attitude: &y[3..7],
        };
        SCRATCH.with(|cell| {
            let mut scratch = cell.borrow_mut();
            let len = self
                .group_scratch
                .last()
                .map_or(self.scratch_len, |r| r.end);
            if scratch.len() < len {
                scratch.resize(len, 0.0);
            }
            let mut coupling = HubCoupling {
                mass: Matrix6::zeros(),
                force: Vector6::zeros(),
                translation: false,
                tidal: None,
            };
            self.couple(&hub, y, &mut scratch, free_hub, &mut coupling);
            let mut accel = solve(&coupling);
            if let Some(tidal) = &coupling.tidal {
                accel.tidal_power = tidal.power(self.hub_mass.unwrap_or(0.0));
            }

            let use_groups = coupling.tidal.is_none();
            for (k, e) in self.effectors.iter().enumerate() {
                if use_groups && self.grouped[k] {
                    continue;
                }
                let off = self.offsets[k];
                let n = self.lens[k];
                let s = self.scratch_offsets[k];
                e.derivatives(
                    &hub,
                    &accel,
                    &y[off..off + n],
                    &scratch[s..s + self.scratch_lens[k]],
                    &mut dydt[off..off + n],
                );
            }
            if use_groups {
                for (group, range) in self.groups.iter().zip(&self.group_scratch) {
                    group.derivatives(&accel, y, &scratch[range.clone()], dydt);
                }
            }
            accel.angular
        })
    }

    /// Right-hand side with the hub's rotation prescribed as ω̇ = `omega_dot` (the state's ω
    /// is used as it is). With `free_translation` the hub's centre of mass moves so that the
    /// total linear momentum is conserved; otherwise it is pinned (a_B = 0). Used for
    /// prescribed-motion scenes and the energy-sink estimate of `linearize`.
    pub fn rhs_prescribed(
        &self,
        t: f64,
        y: &[f64],
        omega_dot: &Vector3<f64>,
        free_translation: bool,
        dydt: &mut [f64],
    ) {
        let omega = Vector3::new(y[0], y[1], y[2]);
        let wd = *omega_dot;
        let translation = self.translation;
        self.effector_rhs(t, y, dydt, false, |c| {
            let linear = if free_translation && translation {
                // Translational rows: M_tt a_B + M_tr ω̇ = f_t.
                let m_tt = c.mass.fixed_view::<3, 3>(0, 0).into_owned();
                let m_tr = c.mass.fixed_view::<3, 3>(0, 3).into_owned();
                let f_t = Vector3::new(c.force[0], c.force[1], c.force[2]);
                m_tt.lu()
                    .solve(&(f_t - m_tr * wd))
                    .unwrap_or_else(|| Vector3::repeat(f64::NAN))
            } else {
                Vector3::zeros()
            };
            HubAcceleration {
                linear,
                angular: wd,
                tidal_power: 0.0,
            }
        });
        dydt[..3].copy_from_slice(omega_dot.as_slice());
        quaternion_rate(&y[3..7], &omega, &mut dydt[3..7]);
        if self.expels_mass {
            self.exhaust_rates(t, y, dydt);
        }
    }
}

/// The index of the one effector that moves mass, when exactly one does.
fn lone_mover(effectors: &[Box<dyn Effector>]) -> Option<usize> {
    let mut movers = effectors
        .iter()
        .enumerate()
        .filter(|(_, e)| e.moves_mass())
        .map(|(k, _)| k);
    match (movers.next(), movers.next()) {
        (Some(k), None) => Some(k),
        _ => None,
    }
}

/// The inverse of a symmetric 3 × 3 matrix [[a, b, c], [b, d, e], [c, e, f]] by its
/// cofactors; `None` unless it is positive definite (Sylvester's criterion: a, a d − b² and
/// the determinant positive).
#[inline(always)]
pub(crate) fn spd_inverse3(a: f64, b: f64, c: f64, d: f64, e: f64, f: f64) -> Option<Matrix3<f64>> {
    let (c00, c01, c02) = (d * f - e * e, c * e - b * f, b * e - c * d);
    let det = a * c00 + b * c01 + c * c02;
    if !(a > 0.0 && a * d - b * b > 0.0 && det > 0.0) {
        return None;
    }
    let (c11, c12, c22) = (a * f - c * c, b * c - a * e, a * d - b * b);
    let r = 1.0 / det;
    Some(Matrix3::new(
        c00 * r,
        c01 * r,
        c02 * r,
        c01 * r,
        c11 * r,
        c12 * r,
        c02 * r,
        c12 * r,
        c22 * r,
    ))
}

/// Solves `m z = f` for a symmetric positive definite 6×6 `m` (lower triangle read) by the
/// Schur complement of its translational block: with m = [[A, Bᵀ], [B, C]] (3 × 3 blocks),
/// X = B A⁻¹ and S = C − X Bᵀ, the rotational part is z_r = S⁻¹ (f_r − X f_t) and the
/// translational one z_t = A⁻¹ f_t − Xᵀ z_r. Both 3 × 3 inverses are closed-form (cofactors),
/// so the solve is straight-line code: no loops, no square roots, two reciprocals
/// (a 6 × 6 L D Lᵀ with loops was a tenth of Explorer 1's right-hand side). `None` when
/// `m` is not positive definite (A or S is not). Kept out of line: inlined, some release
/// builds computed wrong accelerations in one scene (docs/benchmarks.md, "Wrong accelerations
/// from some release builds"); the call costs about 1% of Explorer 1's instructions.
#[inline(never)]
pub(crate) fn schur_solve6(m: &Matrix6<f64>, f: &Vector6<f64>) -> Option<Vector6<f64>> {
    let a_inv = spd_inverse3(
        m[(0, 0)],
        m[(1, 0)],
        m[(2, 0)],
        m[(1, 1)],
        m[(2, 1)],
        m[(2, 2)],
    )?;
    let b: Matrix3<f64> = m.fixed_view::<3, 3>(3, 0).into_owned();
    let x = b * a_inv;
    let s = |i: usize, j: usize| m[(3 + i, 3 + j)] - x.row(i).dot(&b.row(j));
    let s_inv = spd_inverse3(s(0, 0), s(1, 0), s(2, 0), s(1, 1), s(2, 1), s(2, 2))?;
    let f_t = Vector3::new(f[0], f[1], f[2]);
    let f_r = Vector3::new(f[3], f[4], f[5]);
    let z_r = s_inv * (f_r - x * f_t);
    let z_t = a_inv * f_t - x.tr_mul(&z_r);
    Some(Vector6::new(z_t[0], z_t[1], z_t[2], z_r[0], z_r[1], z_r[2]))
}

/// Solves the hub's equations for its accelerations.
#[inline(always)]
fn solve_hub(c: &HubCoupling) -> HubAcceleration {
    if c.translation {
        // The generalised mass is symmetric positive definite: the Schur complement of its
        // translational block (LU if rounding spoils definiteness).
        let solved = match schur_solve6(&c.mass, &c.force) {
            Some(z) => Some(z),
            None => c.mass.lu().solve(&c.force),
        };
        match solved {
            Some(z) => HubAcceleration {
                linear: Vector3::new(z[0], z[1], z[2]),
                angular: Vector3::new(z[3], z[4], z[5]),
                tidal_power: 0.0,
            },
            None => HubAcceleration {
                linear: Vector3::repeat(f64::NAN),
                angular: Vector3::repeat(f64::NAN),
                tidal_power: 0.0,
            },
        }
    } else {
        // The rotational block alone (lower triangle read), by cofactors (nalgebra's general
        // inverse if rounding spoils definiteness).
        let m = &c.mass;
        let f_r = Vector3::new(c.force[3], c.force[4], c.force[5]);
        let inverse = spd_inverse3(
            m[(3, 3)],
            m[(4, 3)],
            m[(5, 3)],
            m[(4, 4)],
            m[(5, 4)],
            m[(5, 5)],
        )
        .or_else(|| m.fixed_view::<3, 3>(3, 3).into_owned().try_inverse());
        HubAcceleration {
            linear: Vector3::zeros(),
            angular: inverse
                .map(|inv| inv * f_r)
                .unwrap_or_else(|| Vector3::repeat(f64::NAN)),
            tidal_power: 0.0,
        }
    }
}

/// `q̇ = ½ q ⊗ (0, ω)` for `q = (w, x, y, z)`, written into `dq`.
#[inline(always)]
pub fn quaternion_rate(q: &[f64], omega: &Vector3<f64>, dq: &mut [f64]) {
    // The lanes' form at f64 (one code for the scalar path and the ensembles).
    let rate = crate::lanes::linalg::quaternion_rate([q[0], q[1], q[2], q[3]], (*omega).into());
    dq[0] = rate[0];
    dq[1] = rate[1];
    dq[2] = rate[2];
    dq[3] = rate[3];
}

impl OdeSystem for Spacecraft {
    fn dim(&self) -> usize {
        self.dim
    }

    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        if let Some(motion) = &self.motion {
            let wd = motion.omega_dot(t);
            self.rhs_prescribed(t, y, &wd, false, dydt);
            return;
        }
        if self.lone_only && self.lone_rhs(t, y, dydt) {
            return;
        }
        let omega = Vector3::new(y[0], y[1], y[2]);
        let omega_dot = if self.effectors.is_empty() {
            self.rigid_omega_dot(&omega)
        } else if self.torque_only && self.effectors.len() <= MAX_FAST_TORQUES {
            self.torque_rhs(t, y, dydt)
        } else if self.torque_only {
            // I ω̇ = −ω × Iω + Σ τ: the inverse inertia is constant (the same inverse the
            // general solve computes from the same matrix, so the results are identical).
            let inverse = &self.hub.inertia_inv;
            self.effector_rhs(t, y, dydt, false, |c| HubAcceleration {
                linear: Vector3::zeros(),
                angular: inverse * Vector3::new(c.force[3], c.force[4], c.force[5]),
                tidal_power: 0.0,
            })
        } else {
            self.effector_rhs(t, y, dydt, true, solve_hub)
        };
        let hub_dy = &mut dydt[..HUB_STATES];
        hub_dy[0] = omega_dot[0];
        hub_dy[1] = omega_dot[1];
        hub_dy[2] = omega_dot[2];
        quaternion_rate(&y[3..7], &omega, &mut hub_dy[3..7]);
        if self.expels_mass {
            self.exhaust_rates(t, y, dydt);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body-fixed constant external torque with one bookkeeping state: the work it has done
    /// (J), so W' = τ·ω. Exercises the effector interface: coupling, own states, layout.
    #[derive(Debug)]
    struct ConstantTorque(Vector3<f64>);
    impl Effector for ConstantTorque {
        fn name(&self) -> &str {
            "constant_torque"
        }
        fn num_states(&self) -> usize {
            1
        }
        fn state_names(&self) -> Vec<String> {
            vec!["work".into()]
        }
        fn initial_state(&self) -> Vec<f64> {
            vec![0.0]
        }
        fn kind(&self) -> &'static str {
            "constant_torque"
        }
        fn is_external(&self) -> bool {
            true
        }
        fn couple(&self, _hub: &HubState, _x: &[f64], c: &mut HubCoupling, _s: &mut [f64]) {
            c.add_torque(&self.0);
        }
        fn derivatives(
            &self,
            hub: &HubState,
            _a: &HubAcceleration,
            _x: &[f64],
            _s: &[f64],
            dx: &mut [f64],
        ) {
            dx[0] = self.0.dot(&hub.omega);
        }
    }

    #[test]
    fn quaternion_rate_is_half_q_times_omega() {
        let q = UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1);
        let w = Vector3::new(0.4, -1.3, 0.7);
        let expected = q.quaternion() * nalgebra::Quaternion::from_imag(w) * 0.5;
        let mut dq = [0.0; 4];
        quaternion_rate(&[q.w, q.i, q.j, q.k], &w, &mut dq);
        let got = nalgebra::Quaternion::new(dq[0], dq[1], dq[2], dq[3]);
        approx::assert_relative_eq!(got, expected, epsilon = 1e-15);
    }

    #[test]
    fn effector_states_follow_the_hub_and_work_balances_energy() {
        use crate::integrate::{Dopri5, Stepper, Tolerances};
        let hub = RigidBody::from_principal([1.0, 2.0, 3.0]).unwrap();
        let mut sc = Spacecraft::new(hub, Vector3::z());
        let tau = Vector3::new(0.01, -0.02, 0.005);
        sc.add_effector(Box::new(ConstantTorque(tau))).unwrap();
        assert_eq!(sc.dim(), 8);
        let y0 = sc.initial_state(&Vector3::new(0.3, 0.5, 0.8), &UnitQuaternion::identity());
        let t0 = sc.observe(0.0, &y0).kinetic_energy;
        let tol = Tolerances {
            rtol: 1e-12,
            atol: 1e-14,
        };
        let mut s = Dopri5::new(0.0, &y0, tol, f64::INFINITY, None);
        while s.t() < 20.0 {
            s.step(&sc, 20.0).unwrap();
        }
        let y = s.y();
        let t1 = sc.observe(20.0, y).kinetic_energy;
        // Work–energy theorem: the change in T equals the work done by the torque.
        approx::assert_relative_eq!(t1 - t0, y[7], max_relative = 1e-9);
        assert!(y[7].abs() > 1e-3, "the torque must have done work");
    }

    #[test]
    fn schur_solve_solves_a_positive_definite_system_and_refuses_an_indefinite_one() {
        // B Bᵀ + 1 is positive definite; only its lower triangle is stored.
        let b = Matrix6::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 - 2.0 + 0.1 * i as f64);
        let full = b * b.transpose() + Matrix6::identity();
        let lower = Matrix6::from_fn(|i, j| if i >= j { full[(i, j)] } else { 0.0 });
        let f = Vector6::new(1.0, -2.0, 0.5, 3.0, -1.5, 0.25);
        let z = schur_solve6(&lower, &f).expect("positive definite");
        let reference = full.lu().solve(&f).expect("regular");
        approx::assert_relative_eq!(z, reference, max_relative = 1e-12);
        // Indefinite in the rotational block (S), and in the translational one (A).
        let mut indefinite = lower;
        indefinite[(4, 4)] = -1.0;
        assert!(schur_solve6(&indefinite, &f).is_none());
        let mut indefinite = lower;
        indefinite[(1, 1)] = 0.0;
        assert!(schur_solve6(&indefinite, &f).is_none());
        let mut not_a_number = lower;
        not_a_number[(5, 2)] = f64::NAN;
        assert!(schur_solve6(&not_a_number, &f).is_none());
    }
}
