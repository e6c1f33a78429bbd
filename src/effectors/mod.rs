//! Effectors: the parts a spacecraft is composed of beyond its rigid hub (docs/effectors.md).
//!
//! - [`Rayleigh`]: Rayleigh dissipation torque −Γω (external; drains |H| and T).
//! - [`EnergySink`]: the quasi-rigid internal-dissipation torque that keeps |H|.
//! - [`SpringMass`]: a particle on a line with spring and dashpot.
//! - [`WheelDamper`]: a viscous wheel damper about a body axis.
//! - [`HingedRod`]: a rigid rod on a hinge with one or two rotational degrees of freedom.
//! - [`SloshPendulum`]: a damped spherical pendulum, the analog of a tank's lateral slosh.
//! - [`ModalBeam`]: a cantilever beam by its first bending modes, with geometric stiffening.
//! - [`GravityGradient`]: the central body's gravity-gradient torque on the hub in orbit.
//! - [`MagneticDipole`]: a constant magnetic dipole moment in the Earth's field (IGRF dipole).
//! - [`EddyCurrents`]: eddy-current damping of a conducting body by its magnetic tensor.
//! - [`HysteresisRod`]: a soft-magnetic rod whose flux density follows the field along it
//!   through a hysteresis loop (Flatley & Henretty), damping the body's motion in the field.
//! - [`Magnetorquer`]: coils commanded by a discrete B-dot detumbling law, saturated per axis.
//! - [`MotorWheel`]: a driven rotor (free, torque profile, speed hold, or rate damping).
//! - [`SolarPressure`]: solar radiation pressure on a flat plate, with the Earth's shadow.
//! - [`Thruster`]: thrust from a nozzle, expelling its tank's propellant ([`propellant_tank`]):
//!   the variable-mass terms and the exhaust's momentum.
//! - [`Aerodynamic`]: drag on a constant projected area with a fixed centre of pressure,
//!   and [`aerodynamic::ShapeAerodynamic`] on the facets of the body's shape.
//!
//! The mass-moving ones share the particle formulation of [`particles`]; each effector
//! adds only its own states.

pub mod aerodynamic;
pub mod beam;
pub mod clock;
pub mod draining_slosh;
pub mod eddy_currents;
pub mod energy_sink;
pub mod environment;
pub mod gravity_gradient;
pub mod hinged_rod;
pub mod hysteresis_rod;
pub mod magnetic_dipole;
pub mod magnetorquer;
pub mod modal;
mod modal_integrals;
pub mod motion;
pub mod motor;
pub mod motor_wheel;
pub mod particles;
pub mod propellant_tank;
pub mod rayleigh;
pub mod rod_closed_form;
pub mod rod_lanes;
pub mod slosh_analog;
pub mod slosh_pendulum;
pub mod slosh_spring;
pub mod solar_pressure;
pub mod spring_mass;
pub mod thruster;
pub mod wheel;

pub use aerodynamic::Aerodynamic;
pub use draining_slosh::DrainingSlosh;
pub use eddy_currents::EddyCurrents;
pub use energy_sink::EnergySink;
pub use gravity_gradient::GravityGradient;
pub use hinged_rod::{HingeFreedom, HingedRod};
pub use hysteresis_rod::HysteresisRod;
pub use magnetic_dipole::MagneticDipole;
pub use magnetorquer::Magnetorquer;
pub use modal::ModalBeam;
pub use motion::SpinUp;
pub use motor_wheel::MotorWheel;
pub use particles::{ParticleEffector, ParticleModel};
pub use rayleigh::Rayleigh;
pub use slosh_pendulum::SloshPendulum;
pub use slosh_spring::SloshSpring;
pub use solar_pressure::SolarPressure;
pub use spring_mass::SpringMass;
pub use thruster::Thruster;
pub use wheel::WheelDamper;

#[cfg(test)]
mod tests;
