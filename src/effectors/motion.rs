//! Prescribed hub rotations (the hub is driven by a motor about an axis fixed in inertial
//! space; its centre of mass is pinned).

use crate::model::HubMotion;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// The smooth spin-up of Kane, Ryan & Banerjee (J. Guidance 10(2), 1987): hub angle
/// θ(t) = (Ω_s/T_s)[t²/2 + (T_s/2π)²(cos(2πt/T_s) − 1)] for t ≤ T_s, Ω_s t − Ω_s T_s/2 after,
/// about a body axis â (which stays fixed in inertial space).
#[derive(Debug, Clone)]
pub struct SpinUp {
    /// Unit spin axis â (body axes).
    pub axis: Vector3<f64>,
    /// Final rate Ω_s (rad/s).
    pub rate: f64,
    /// Ramp duration T_s (s).
    pub ramp_time: f64,
}

impl SpinUp {
    /// θ̇(t) (rad/s).
    pub fn angle_rate(&self, t: f64) -> f64 {
        let (w, ts) = (self.rate, self.ramp_time);
        if t >= ts {
            w
        } else {
            (w / ts) * (t - ts / (2.0 * PI) * (2.0 * PI * t / ts).sin())
        }
    }

    /// θ̈(t) (rad/s²).
    pub fn angle_acceleration(&self, t: f64) -> f64 {
        let (w, ts) = (self.rate, self.ramp_time);
        if t >= ts {
            0.0
        } else {
            (w / ts) * (1.0 - (2.0 * PI * t / ts).cos())
        }
    }
}

impl HubMotion for SpinUp {
    fn omega(&self, t: f64) -> Vector3<f64> {
        self.angle_rate(t) * self.axis
    }
    fn omega_dot(&self, t: f64) -> Vector3<f64> {
        self.angle_acceleration(t) * self.axis
    }
    fn describe(&self) -> String {
        format!(
            "prescribed spin-up about [{:.3}, {:.3}, {:.3}] to {} rad/s over {} s",
            self.axis[0], self.axis[1], self.axis[2], self.rate, self.ramp_time
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_is_the_derivative_of_the_angle_profile() {
        let s = SpinUp {
            axis: Vector3::z(),
            rate: 6.0,
            ramp_time: 15.0,
        };
        let theta = |t: f64| {
            let (w, ts) = (6.0, 15.0);
            if t <= ts {
                (w / ts)
                    * (t * t / 2.0 + (ts / (2.0 * PI)).powi(2) * ((2.0 * PI * t / ts).cos() - 1.0))
            } else {
                w * t - w * ts / 2.0
            }
        };
        for t in [0.5, 3.0, 7.5, 14.0, 20.0] {
            let h = 1e-5;
            let d = (theta(t + h) - theta(t - h)) / (2.0 * h);
            assert!((d - s.angle_rate(t)).abs() < 1e-8, "t = {t}");
            let dd = (s.angle_rate(t + h) - s.angle_rate(t - h)) / (2.0 * h);
            assert!((dd - s.angle_acceleration(t)).abs() < 1e-8, "t = {t}");
        }
        assert_eq!(s.angle_rate(0.0), 0.0);
        assert!((s.angle_rate(15.0) - 6.0).abs() < 1e-12);
    }
}
