//! The spring–mass analog of a tank's first lateral slosh mode: a [`SpringMass`] whose mass
//! may move on a second line too, with the tank's non-sloshing liquid fixed in the body
//! (docs/slosh-analogs.md, "The spring–mass form").
//!
//! The sloshing mass m sits at r = r₀ + ρ₁ p̂₁ + ρ₂ p̂₂ (p̂₁ ⊥ p̂₂, body axes; the second line is
//! optional), with springs −k₁ρ₁, −k₂ρ₂ and the damper's dashpot −c ṙ' on its velocity relative
//! to the body, whose generalised forces are −c ρ̇ₖ because the lines are ⊥. The fixed liquid
//! m₀ is a point mass at r_f, moving with the body. The equations are the particle
//! formulation's ([`super::particles`]); the damper's own closed forms stay the damper's, so a
//! scene without a tank pays nothing for this.

use super::particles::{ParticleModel, ParticlePoint};
use super::slosh_pendulum::fixed_liquid_drawing;
use super::spring_mass::SpringMass;
use crate::model::{Drawing, HubState, Validity};
use nalgebra::Vector3;

/// A tank's spring–mass slosh analog.
#[derive(Debug, Clone)]
pub struct SloshSpring {
    /// The sloshing mass on its first line: mass m_s (kg), rest point r₀, direction p̂₁, its
    /// spring k₁ and the dashpot c (which acts on both lines); `travel` is the offset |ρ| at
    /// which the run stops.
    pub spring: SpringMass,
    /// The second line through r₀, ⊥ p̂₁; `None` for a mass on one line.
    pub second: Option<SecondLine>,
    /// The tank's non-sloshing liquid m₀ (kg), fixed in the body at `fixed_position`.
    pub fixed_mass: f64,
    /// Where the non-sloshing liquid sits (m, body axes, about the hub's centre of mass).
    pub fixed_position: Vector3<f64>,
    /// The offset |ρ| (m) past which the analog leaves its small-amplitude range (warned).
    pub amplitude_warning: f64,
    /// The spin the stiffnesses were derived for: its axis (unit, body axes) and rate Ω₀
    /// (rad/s). The restoring field Ω² r_T and the across-spin term Ω² both follow the spin,
    /// the springs do not; `None` for an analog not derived from a spin.
    pub design_spin: Option<(Vector3<f64>, f64)>,
}

/// Relative change of the spin from the one a tank's springs were derived for past which the
/// run warns: the slosh frequency, ∝ Ω, is then off by about as much, the order of the
/// analog's own accuracy.
pub const SPIN_CHANGE_WARN: f64 = 0.05;

/// Relative change of the spin past which the run stops: the springs then stand for a
/// different liquid (frequency off by a quarter or more).
pub const SPIN_CHANGE_LIMIT: f64 = 0.25;

/// The second line of a [`SloshSpring`].
#[derive(Debug, Clone)]
pub struct SecondLine {
    /// Unit direction p̂₂ (body axes), ⊥ the first line's.
    pub direction: Vector3<f64>,
    /// Spring stiffness k₂ along it (N/m).
    pub stiffness: f64,
}

/// Of two measures, the one past its limit, else the one past its warning, else `a`.
fn more_urgent(a: Validity, b: Validity) -> Validity {
    if a.past_limit() {
        a
    } else if b.past_limit() || (b.past_warning() && !a.past_warning()) {
        b
    } else {
        a
    }
}

impl SloshSpring {
    /// The spin rate about the design spin's axis (rad/s; 0 without one).
    fn spin_rate(&self, hub: &HubState) -> f64 {
        self.design_spin
            .map_or(0.0, |(axis, _)| hub.omega.dot(&axis))
    }

    /// The spin's relative change from the design spin, against [`SPIN_CHANGE_WARN`] and
    /// [`SPIN_CHANGE_LIMIT`].
    fn spin_validity(&self, hub: &HubState) -> Option<Validity> {
        let (_, design) = self.design_spin?;
        Some(Validity {
            value: (self.spin_rate(hub) / design - 1.0).abs(),
            warn: SPIN_CHANGE_WARN,
            limit: SPIN_CHANGE_LIMIT,
        })
    }

    /// The sloshing mass's distance from its rest point, |ρ| (m), at coordinates `q`.
    pub fn offset(&self, q: &[f64]) -> f64 {
        match self.second {
            Some(_) => q[0].hypot(q[1]),
            None => q[0].abs(),
        }
    }

    /// The sloshing mass's position (m, body axes) at coordinates `q`.
    pub fn mass_position(&self, q: &[f64]) -> Vector3<f64> {
        let s = &self.spring;
        let mut r = s.position + q[0] * s.direction;
        if let Some(line) = &self.second {
            r += q[1] * line.direction;
        }
        r
    }
}

impl ParticleModel for SloshSpring {
    type Cache = ();
    fn kind(&self) -> &'static str {
        "spring_mass_damper"
    }
    fn undamped(&self) -> Self {
        SloshSpring {
            spring: self.spring.undamped(),
            ..self.clone()
        }
    }
    fn num_coordinates(&self) -> usize {
        if self.second.is_some() { 2 } else { 1 }
    }
    fn coordinate_names(&self) -> Vec<String> {
        let mut names = vec!["offset".to_string()];
        if self.second.is_some() {
            names.push("offset_2".into());
        }
        names
    }
    fn num_particles(&self) -> usize {
        if self.fixed_mass > 0.0 { 2 } else { 1 }
    }
    fn particle(&self, p: usize, _c: &(), q: &[f64], _u: &[f64], out: &mut ParticlePoint) {
        let n = self.num_coordinates();
        out.convective = Vector3::zeros();
        if p == 1 {
            out.mass = self.fixed_mass;
            out.position = self.fixed_position;
            out.jacobian[..n].fill(Vector3::zeros());
            return;
        }
        out.mass = self.spring.mass;
        out.position = self.mass_position(q);
        out.jacobian[0] = self.spring.direction;
        if let Some(line) = &self.second {
            out.jacobian[1] = line.direction;
        }
    }
    fn forces(&self, q: &[f64], u: &[f64], out: &mut [f64]) {
        self.spring.forces(&q[..1], &u[..1], &mut out[..1]);
        if let Some(line) = &self.second {
            out[1] = -line.stiffness * q[1] - self.spring.damping * u[1];
        }
    }
    fn elastic_energy(&self, q: &[f64]) -> f64 {
        let second = match &self.second {
            Some(line) => 0.5 * line.stiffness * q[1] * q[1],
            None => 0.0,
        };
        self.spring.elastic_energy(&q[..1]) + second
    }
    fn dissipation_power(&self, q: &[f64], u: &[f64]) -> f64 {
        let second = match &self.second {
            Some(_) => self.spring.damping * u[1] * u[1],
            None => 0.0,
        };
        self.spring.dissipation_power(&q[..1], &u[..1]) + second
    }
    fn validity(&self, q: &[f64]) -> Option<Validity> {
        Some(Validity {
            value: self.offset(q),
            warn: self.amplitude_warning,
            limit: self.spring.travel.unwrap_or(f64::INFINITY),
        })
    }
    fn validity_report(&self, q: &[f64]) -> (String, String) {
        (
            format!(
                "its sloshing mass is {:.4} m from rest: past {:.4} m the tank's free-surface \
                 wave at the wall exceeds 0.1 of the tank radius, beyond the small amplitudes \
                 the linear slosh analog is derived for (the run stops at {} m, the tank's \
                 radius)",
                self.offset(q),
                self.amplitude_warning,
                self.spring.travel.unwrap_or(f64::INFINITY)
            ),
            "more damping (baffles) or a smaller disturbance; large liquid motion needs a \
             nonlinear slosh model, which polhode does not have"
                .into(),
        )
    }
    fn validity_at(&self, hub: &HubState, q: &[f64]) -> Option<Validity> {
        let amplitude = self.validity(q);
        match (self.spin_validity(hub), amplitude) {
            (Some(spin), Some(amplitude)) => Some(more_urgent(spin, amplitude)),
            (spin, amplitude) => spin.or(amplitude),
        }
    }
    fn validity_report_at(&self, hub: &HubState, q: &[f64]) -> (String, String) {
        let (Some(spin), Some(amplitude)) = (self.spin_validity(hub), self.validity(q)) else {
            return self.validity_report(q);
        };
        if more_urgent(spin, amplitude) != spin {
            return self.validity_report(q);
        }
        let (_, design) = self.design_spin.unwrap_or_default();
        (
            format!(
                "the spin is {:.4} rad/s against the {design:.4} rad/s its springs were derived                  for ({:+.1} %): the liquid's restoring field, ∝ Ω², has moved and the springs                  have not (warned past {:.0} %, stopped past {:.0} %)",
                self.spin_rate(hub),
                100.0 * (self.spin_rate(hub) / design - 1.0),
                100.0 * SPIN_CHANGE_WARN,
                100.0 * SPIN_CHANGE_LIMIT
            ),
            "the pendulum form (`slosh_pendulum: {tank: …}`), whose restoring force follows              the spin; or a spring analog derived at the spin of the phase studied"
                .into(),
        )
    }
    fn drawings(&self, q: &[f64]) -> Vec<Drawing> {
        let s = &self.spring;
        let mut drawings = s.drawings(&q[..1]);
        if self.second.is_some() {
            // The mass where both coordinates put it, and the second line.
            let size = (s.mass.cbrt() * 0.05).clamp(0.02, 0.3);
            drawings.retain(|d| !matches!(d, Drawing::Sphere { .. }));
            if let Some(line) = &self.second {
                drawings.push(Drawing::Line {
                    points: vec![
                        s.position - 4.0 * size * line.direction,
                        s.position + 4.0 * size * line.direction,
                    ],
                    thickness: 0.1 * size,
                });
            }
            drawings.push(Drawing::Sphere {
                center: self.mass_position(q),
                diameter: size,
            });
        }
        drawings.extend(fixed_liquid_drawing(self.fixed_mass, self.fixed_position));
        drawings
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effectors::ParticleEffector;
    use crate::model::{Effector, HubCoupling, HubState};
    use nalgebra::{Matrix6, Vector6};

    /// On one line and without fixed liquid, the tank's spring is the damper: its coupling,
    /// derivatives' inputs and momentum by the general particle path equal the damper's closed
    /// forms (which the damper's own tests check against its particle sums).
    #[test]
    fn on_one_line_it_is_the_damper() {
        let damper = SpringMass {
            mass: 12.0,
            position: Vector3::new(0.8, -0.2, 0.3),
            direction: Vector3::new(0.0, 0.6, 0.8),
            stiffness: 140.0,
            damping: 3.0,
            travel: Some(0.2),
        };
        let tank = SloshSpring {
            spring: damper.clone(),
            second: None,
            fixed_mass: 0.0,
            fixed_position: Vector3::zeros(),
            amplitude_warning: 0.01,
            design_spin: None,
        };
        let a = ParticleEffector::new("a", damper, &[0.0], &[0.0]);
        let b = ParticleEffector::new("b", tank, &[0.0], &[0.0]);
        let omega = Vector3::new(0.3, -0.4, 2.0);
        let hub = HubState {
            t: 0.0,
            omega,
            attitude: &[1.0, 0.0, 0.0, 0.0],
        };
        let x = [0.03, -0.4, 0.0];
        let start = HubCoupling {
            mass: Matrix6::zeros(),
            force: Vector6::zeros(),
            translation: false,
            tidal: None,
        };
        let (mut ca, mut cb) = (start.clone(), start);
        let (mut ka, mut kb) = ([0.0; 8], [0.0; 8]);
        a.couple(&hub, &x, &mut ca, &mut ka);
        b.couple(&hub, &x, &mut cb, &mut kb);
        let scale = ca.mass.amax().max(ca.force.amax());
        assert!((ca.mass - cb.mass).amax() < 1e-13 * scale);
        assert!((ca.force - cb.force).amax() < 1e-13 * scale);
        for (p, q) in ka.iter().zip(&kb) {
            assert!(
                (p - q).abs() < 1e-13 * (1.0 + p.abs()),
                "{ka:?} against {kb:?}"
            );
        }
        let (pa, pb) = (a.momentum(&hub, &x), b.momentum(&hub, &x));
        assert!((pa.angular - pb.angular).norm() < 1e-13 * pa.angular.norm());
        assert!((pa.kinetic_energy - pb.kinetic_energy).abs() < 1e-13 * pa.kinetic_energy);
        assert_eq!(a.energy(&hub, &x).elastic, b.energy(&hub, &x).elastic);
    }
}
