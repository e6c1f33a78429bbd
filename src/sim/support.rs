//! The method contract: what each integration method, and `linearize`, supports, stated in
//! one place (docs/choosing-a-method.md, "What each method supports").
//!
//! A scene's [`Features`] are read off its spacecraft through the effector contract alone
//! (never by effector kind), so a new effector falls into a class the day it is written: it
//! adds mass-matrix terms or it does not ([`crate::model::Effector::torque_only`]), it can be
//! averaged or it cannot ([`crate::model::Effector::secular`]), it has breakpoints with held
//! states or it does not ([`crate::model::Effector::next_breakpoint`]). Every run goes
//! through [`Method::refusal`] before its first step ([`super::AnyStepper::for_simulation`]),
//! and the YAML loader asks the same question to refuse at load with the field located, so a
//! method can never meet a feature it does not support and answer `complete`.

use super::Method;
use crate::model::Spacecraft;

/// A feature of a scene that a method may not support.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Feature {
    /// Torques that average over the torque-free motion (`rayleigh`, `energy_sink`, and
    /// `eddy_currents` over the orbit as well).
    DissipationTorques,
    /// Other torque-only effectors: environmental torques (gravity gradient, aerodynamic,
    /// solar pressure, magnetic), magnetorquers.
    EnvironmentTorques,
    /// States held between breakpoints, where the run stops and updates them: sampled
    /// controllers (rate damping, B-dot) and stepped torque profiles; and kinks of a torque
    /// profile.
    HeldStates,
    /// Effectors with degrees of freedom of their own that carry momentum (dampers, rods,
    /// beams, wheels).
    InternalEffectors,
    /// A prescribed hub rotation (`hub_motion`).
    PrescribedMotion,
    /// Mass leaving the spacecraft (a thruster expelling its tank's propellant): the mass
    /// properties change with time.
    VariableMass,
}

impl Feature {
    /// Every feature, in the table's column order.
    pub const ALL: [Feature; 6] = [
        Feature::DissipationTorques,
        Feature::EnvironmentTorques,
        Feature::HeldStates,
        Feature::InternalEffectors,
        Feature::PrescribedMotion,
        Feature::VariableMass,
    ];

    /// A short name for tables and messages.
    pub fn label(self) -> &'static str {
        match self {
            Feature::DissipationTorques => "dissipation torques",
            Feature::EnvironmentTorques => "environment and control torques",
            Feature::HeldStates => "held states and breakpoints",
            Feature::InternalEffectors => "internal effectors",
            Feature::PrescribedMotion => "prescribed hub motion",
            Feature::VariableMass => "variable mass",
        }
    }
}

/// What a scene contains, as the method contract sees it: each feature with the first
/// effector (name and kind) that brings it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Features {
    found: Vec<(Feature, String)>,
}

impl Features {
    /// The features of `sc` over a run of `duration` (s): a breakpoint after the end does not
    /// count.
    pub fn of(sc: &Spacecraft, duration: f64) -> Features {
        let mut f = Features::default();
        for e in sc.effectors() {
            let who = format!("effector `{}` ({})", e.name(), e.kind());
            let class = if !e.torque_only() {
                Feature::InternalEffectors
            } else if e.secular().is_some() {
                Feature::DissipationTorques
            } else {
                Feature::EnvironmentTorques
            };
            f.add(class, &who);
            if e.changes_mass() {
                f.add(Feature::VariableMass, &who);
            }
            if e.next_breakpoint(0.0).is_some_and(|t| t < duration) {
                f.add(Feature::HeldStates, &who);
            }
        }
        if let Some(m) = sc.motion() {
            f.add(
                Feature::PrescribedMotion,
                &format!("`hub_motion` ({})", m.describe()),
            );
        }
        f
    }

    fn add(&mut self, feature: Feature, who: &str) {
        if !self.has(feature) {
            self.found.push((feature, who.to_string()));
        }
    }

    /// Whether the scene has `feature`.
    pub fn has(&self, feature: Feature) -> bool {
        self.found.iter().any(|(f, _)| *f == feature)
    }

    /// The first effector (or the hub motion) that brings `feature`, in words.
    pub fn source(&self, feature: Feature) -> Option<&str> {
        self.found
            .iter()
            .find(|(f, _)| *f == feature)
            .map(|(_, who)| who.as_str())
    }

    /// Whether the scene is a free rigid body (no effector, no prescribed motion).
    pub fn is_free_rigid_body(&self) -> bool {
        self.found.is_empty()
    }
}

/// How a method stands towards a feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// Integrated like any other term of the equations.
    Yes,
    /// Supported within the conditions the method checks at load (the averaged method: see
    /// [`crate::averaging::refusal`]).
    Partly,
    /// Refused at load.
    No,
}

impl Support {
    /// The table's cell.
    pub fn cell(self) -> &'static str {
        match self {
            Support::Yes => "yes",
            Support::Partly => "partly",
            Support::No => "refused",
        }
    }
}

/// Why a method cannot run a scene, and what to use instead.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// The reason, naming the effector.
    pub reason: String,
    /// Methods that can run it.
    pub instead: &'static str,
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}; use {}", self.reason, self.instead)
    }
}

/// What the method supports, feature by feature: the one place this is stated.
pub fn support(method: &Method, feature: Feature) -> Support {
    use Feature::*;
    match (method, feature) {
        // The closed form solves the free rigid body and nothing else.
        (Method::Exact, _) => Support::No,
        // The splitting's free part is the rigid body's own rotation, which a prescribed
        // motion replaces.
        (Method::Splitting { .. }, PrescribedMotion) => Support::No,
        // Averaging needs a torque-free motion to average over, and torques or effectors
        // whose effect averages over it.
        (Method::Averaged(_), DissipationTorques | InternalEffectors) => Support::Partly,
        (
            Method::Averaged(_),
            EnvironmentTorques | HeldStates | PrescribedMotion | VariableMass,
        ) => Support::No,
        _ => Support::Yes,
    }
}

impl Method {
    /// Why this method cannot run `sc` for `duration` (s), or `None` when it can. The
    /// averaged method's state-dependent conditions (ε, the separatrix) are checked when its
    /// stepper starts ([`crate::averaging::AveragedStepper::new`]).
    pub fn refusal(&self, sc: &Spacecraft, duration: f64) -> Option<Refusal> {
        let features = Features::of(sc, duration);
        // Variable mass first: a thruster's table also brings breakpoints, and the changing
        // mass is the more telling reason.
        let order = std::iter::once(Feature::VariableMass).chain(Feature::ALL);
        for feature in order {
            if support(self, feature) != Support::No {
                continue;
            }
            let Some(source) = features.source(feature) else {
                continue;
            };
            let averages = "averages over the torque-free motion";
            let (what, instead) = match (self, feature) {
                (Method::Exact, _) => ("solves the torque-free rigid body only", "dop853 or auto"),
                (Method::Splitting { .. }, _) => (
                    "composes the free rigid-body flow with the rest, and a prescribed motion \
                     replaces that flow",
                    "dop853 or auto",
                ),
                (Method::Averaged(_), Feature::EnvironmentTorques) => (
                    "averages over the torque-free motion, and an environmental or control \
                     torque does not average over it (it depends on the orbit, the field, \
                     time or a controller's samples)",
                    "dop853",
                ),
                (Method::Averaged(_), Feature::VariableMass) => (
                    "averages over the torque-free motion of a body of constant mass, and a \
                     thruster changes the mass properties as it burns",
                    "dop853",
                ),
                (Method::Averaged(_), Feature::HeldStates) => (
                    "averages over the torque-free motion, and cannot stop at the breakpoints \
                     where held states change",
                    "dop853",
                ),
                (Method::Averaged(_), _) => (averages, "dop853"),
                _ => ("does not support this", "dop853"),
            };
            return Some(Refusal {
                reason: format!(
                    "method `{}` {what}: {source} brings {}",
                    self.name(),
                    feature.label()
                ),
                instead,
            });
        }
        if let Method::Averaged(_) = self
            && let Some(reason) = crate::averaging::refusal(sc)
        {
            return Some(Refusal {
                reason,
                instead: "dop853",
            });
        }
        None
    }
}

/// The three analyses of `polhode linearize`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Linearisation {
    /// About a steady spin ([`crate::linearize::linearize`]).
    Spin,
    /// A gravity-gradient spacecraft about its LVLH-fixed equilibrium
    /// ([`crate::linearize::lvlh`]).
    Lvlh,
    /// The effectors about rest on a hub whose rotation is prescribed
    /// ([`crate::linearize::linearize_driven`]).
    Driven,
}

impl Linearisation {
    /// Every analysis, in the table's row order.
    pub const ALL: [Linearisation; 3] = [
        Linearisation::Spin,
        Linearisation::Lvlh,
        Linearisation::Driven,
    ];

    /// Its name in the table.
    pub fn label(self) -> &'static str {
        match self {
            Linearisation::Spin => "linearize (steady spin)",
            Linearisation::Lvlh => "linearize (LVLH, gravity gradient)",
            Linearisation::Driven => "linearize (prescribed hub motion)",
        }
    }
}

/// What each linearisation supports. They all linearise a time-invariant right-hand side
/// about an equilibrium: a held state (a sampled controller's command, a stepped torque)
/// would enter the Jacobian as a constant, opening the loop, so every one refuses it. About
/// a steady spin, an environmental torque depends on the orbit and time, so the spin is no
/// equilibrium of it; the LVLH analysis takes the gravity gradient and refuses torques that
/// vary around the orbit itself.
pub fn linearize_support(kind: Linearisation, feature: Feature) -> Support {
    use Feature::*;
    match (kind, feature) {
        (_, HeldStates | VariableMass) => Support::No,
        (Linearisation::Spin, EnvironmentTorques | PrescribedMotion) => Support::No,
        (Linearisation::Lvlh, EnvironmentTorques) => Support::Partly,
        (Linearisation::Lvlh, PrescribedMotion) => Support::No,
        (Linearisation::Driven, PrescribedMotion) => Support::Yes,
        _ => Support::Yes,
    }
}

/// Why the linearisation `kind` cannot treat `sc`, or `None`.
pub fn linearize_refusal(sc: &Spacecraft, kind: Linearisation) -> Option<Refusal> {
    let features = Features::of(sc, f64::INFINITY);
    // Variable mass and held states first: a thruster or a controller is the more telling
    // name than the torque it applies.
    let order = [Feature::VariableMass, Feature::HeldStates]
        .into_iter()
        .chain(Feature::ALL);
    for feature in order {
        if linearize_support(kind, feature) != Support::No {
            continue;
        }
        let Some(source) = features.source(feature) else {
            continue;
        };
        let reason = if feature == Feature::VariableMass {
            format!(
                "linearize linearises a time-invariant system about an equilibrium, and {source} \
                 expels mass: the mass properties change with time, so there is none"
            )
        } else if feature == Feature::HeldStates {
            format!(
                "linearize linearises a time-invariant system, and {source} has states held \
                 between breakpoints (a sampled controller's command or a stepped torque): \
                 its Jacobian would hold the command constant, opening the loop"
            )
        } else {
            format!(
                "{} needs an equilibrium that {} ({source}) does not have",
                kind.label(),
                feature.label()
            )
        };
        return Some(Refusal {
            reason,
            instead: "`polhode run` and measure the motion it simulates",
        });
    }
    None
}
