//! What drives a wheel relative to the hub: the motor's mode (coasting, a commanded torque
//! profile, or a PI loop holding the relative rate) and the bearing friction.
//!
//! Conventions: Ω is the rotor's rate relative to the hub about its axis (rad/s); the motor
//! torque u acts on the rotor about its axis and −u on the hub; the friction torque f(Ω)
//! opposes Ω on the rotor (and acts +f on the hub). See `docs/actuators.md`.

/// A commanded motor torque as a function of time (N m).
#[derive(Debug, Clone, PartialEq)]
pub enum TorqueProfile {
    /// The same torque at every time.
    Constant(f64),
    /// Linear between the points `(t, u)` (times strictly increasing), held at the first and
    /// last values outside them.
    Linear(Vec<(f64, f64)>),
    /// Steps: `u_k` from `t_k` until the next time (strictly increasing); zero before the
    /// first.
    Steps(Vec<(f64, f64)>),
}

impl TorqueProfile {
    /// The commanded torque at time `t` (N m).
    pub fn at(&self, t: f64) -> f64 {
        match self {
            TorqueProfile::Constant(u) => *u,
            TorqueProfile::Linear(points) => {
                let k = points.partition_point(|p| p.0 <= t);
                if k == 0 {
                    return points[0].1;
                }
                if k == points.len() {
                    return points[k - 1].1;
                }
                let ((t0, u0), (t1, u1)) = (points[k - 1], points[k]);
                u0 + (u1 - u0) * (t - t0) / (t1 - t0)
            }
            TorqueProfile::Steps(points) => {
                let k = points.partition_point(|p| p.0 <= t);
                if k == 0 { 0.0 } else { points[k - 1].1 }
            }
        }
    }

    /// The times at which the profile is not smooth (a step's jump, a kink between linear
    /// pieces), for the integrators to stop at.
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            TorqueProfile::Constant(_) => Vec::new(),
            TorqueProfile::Linear(points) | TorqueProfile::Steps(points) => {
                points.iter().map(|p| p.0).collect()
            }
        }
    }

    /// The first breakpoint after `t` (s), if any.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        match self {
            TorqueProfile::Constant(_) => None,
            TorqueProfile::Linear(points) | TorqueProfile::Steps(points) => {
                let k = points.partition_point(|p| p.0 <= t);
                points.get(k).map(|p| p.0)
            }
        }
    }
}

/// A PI loop on the relative rate: u = K_p e + K_i z with e = Ω_cmd − Ω, saturated at
/// ±`max_torque`, and back-calculation anti-windup ż = e + (u − v)/K_p, v the unsaturated
/// command (Åström & Hägglund, *Advanced PID Control*, 2006, §3.5, with the tracking time
/// equal to the integral time K_p/K_i).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedHold {
    /// Commanded relative rate Ω_cmd (rad/s).
    pub rate: f64,
    /// Proportional gain K_p (N m s/rad).
    pub kp: f64,
    /// Integral gain K_i (N m/rad).
    pub ki: f64,
}

impl SpeedHold {
    /// The gains that place the loop's two poles at −ω_c (critically damped) for a rotor of
    /// axial inertia `inertia` on a hub that does not turn: I_a s² + K_p s + K_i = I_a (s + ω_c)²,
    /// so K_p = 2 I_a ω_c and K_i = I_a ω_c².
    pub fn from_bandwidth(rate: f64, inertia: f64, bandwidth: f64) -> SpeedHold {
        SpeedHold {
            rate,
            kp: 2.0 * inertia * bandwidth,
            ki: inertia * bandwidth * bandwidth,
        }
    }
}

/// This wheel's share of a discrete rate-damping law for the hub, sampled at the clock's
/// ticks and held: the assembly's wheels with axes â_j (the columns of A) command motor
/// torques u = K A⁺ ω, so that the hub takes −A u = −K P ω, with P = A A⁺ the projection on
/// the axes' span (the whole of −K ω when they span three dimensions). This wheel's row of
/// K A⁺ is `gains`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateDamping {
    /// This wheel's row of K A⁺ (N m s): its command is u = `gains`·ω.
    pub gains: nalgebra::Vector3<f64>,
    /// When the controller samples ω.
    pub clock: super::clock::SampleClock,
}

/// How the motor drives the rotor.
#[derive(Debug, Clone, PartialEq)]
pub enum MotorMode {
    /// No motor torque: the rotor coasts (with friction).
    Free,
    /// A commanded torque profile.
    Torque(TorqueProfile),
    /// A PI loop holding the relative rate.
    SpeedHold(SpeedHold),
    /// Its share of a discrete rate-damping law for the hub (zero-order hold).
    RateDamping(RateDamping),
}

/// Bearing friction on the rotor: viscous plus Coulomb, the Coulomb part smoothed near zero
/// speed as f_c tanh(Ω/Ω_s) so that the right-hand side stays smooth (Olsson et al.,
/// "Friction models and friction compensation", *European Journal of Control* 4, 1998,
/// discuss such regularisations).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Friction {
    /// Viscous coefficient c (N m s/rad).
    pub viscous: f64,
    /// Coulomb torque f_c (N m).
    pub coulomb: f64,
    /// Smoothing speed Ω_s of the Coulomb part (rad/s, > 0 when `coulomb` > 0).
    pub smoothing_speed: f64,
}

impl Friction {
    /// The friction torque f(Ω) (N m), opposing Ω on the rotor; f(Ω) Ω ≥ 0.
    #[inline]
    pub fn torque(&self, rate: f64) -> f64 {
        let coulomb = if self.coulomb > 0.0 {
            self.coulomb * (rate / self.smoothing_speed).tanh()
        } else {
            0.0
        };
        self.viscous * rate + coulomb
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_by_hand() {
        let lin = TorqueProfile::Linear(vec![(0.0, 1.0), (10.0, 3.0), (20.0, -1.0)]);
        assert_eq!(lin.at(-5.0), 1.0);
        assert_eq!(lin.at(5.0), 2.0);
        assert_eq!(lin.at(10.0), 3.0);
        assert_eq!(lin.at(15.0), 1.0);
        assert_eq!(lin.at(25.0), -1.0);
        let steps = TorqueProfile::Steps(vec![(1.0, 0.5), (2.0, -0.25)]);
        assert_eq!(steps.at(0.999), 0.0);
        assert_eq!(steps.at(1.0), 0.5);
        assert_eq!(steps.at(1.999), 0.5);
        assert_eq!(steps.at(2.0), -0.25);
        assert_eq!(steps.at(1e9), -0.25);
        assert_eq!(steps.breakpoints(), vec![1.0, 2.0]);
        assert_eq!(steps.next_breakpoint(0.0), Some(1.0));
        assert_eq!(steps.next_breakpoint(1.0), Some(2.0));
        assert_eq!(steps.next_breakpoint(2.0), None);
        assert!(TorqueProfile::Constant(2.0).breakpoints().is_empty());
    }

    #[test]
    fn friction_opposes_the_rate_and_is_odd() {
        let f = Friction {
            viscous: 0.01,
            coulomb: 0.002,
            smoothing_speed: 0.1,
        };
        for w in [-100.0, -1.0, -1e-3, 0.0, 1e-3, 1.0, 100.0] {
            assert!(f.torque(w) * w >= 0.0, "{w}");
            assert_eq!(f.torque(-w), -f.torque(w));
        }
        // Far from zero speed the Coulomb part is its full value: tanh(1000) = 1.
        assert!((f.torque(100.0) - (1.0 + 0.002)).abs() < 1e-15);
    }

    #[test]
    fn bandwidth_gains_give_a_double_pole() {
        let h = SpeedHold::from_bandwidth(10.0, 0.02, 5.0);
        // I s² + Kp s + Ki with a double root at −5: discriminant zero, root −Kp/(2I).
        let (i, kp, ki) = (0.02, h.kp, h.ki);
        assert!((kp * kp - 4.0 * i * ki).abs() < 1e-15);
        assert!((-kp / (2.0 * i) + 5.0).abs() < 1e-12);
    }
}
