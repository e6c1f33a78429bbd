//! A propellant tank whose mass, centre of mass and inertia follow the propellant left in it:
//! the depletion models of Panicucci, Allard & Schaub (J. Astronaut. Sci. 65, 2018), which
//! Basilisk's fuel tanks implement (docs/effectors.md, "Thruster").
//!
//! Every model gives, for a propellant mass m and its first two time derivatives, the mass's
//! centre r_F (body axes, about the hub's centre of mass B), its inertia J_F about r_F, and
//! the rates J_F′, r_F′, r_F″ taken in the body frame. The remaining propellant is at rest
//! in the body except for the motion of its centre r_F′ (the emptying tank's level falling);
//! the flow from the tank to the nozzle is not modelled (its momentum is neglected, as in the
//! reference).

use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// How the propellant is distributed as it is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TankModel {
    /// All the propellant at one point: no inertia about its centre.
    Point,
    /// A sphere of fixed radius (m) filled throughout at falling density (a gas, or a liquid
    /// spread by a membrane): J_F = (2/5) m R² 1.
    ConstantVolume {
        /// Tank radius (m).
        radius: f64,
    },
    /// A sphere of propellant at constant density that shrinks about a fixed centre:
    /// J_F = (2/5) m R² 1 with R ∝ m^(1/3).
    ConstantDensity {
        /// Radius of the propellant sphere at `initial_mass` (m).
        radius: f64,
        /// The mass at which it has that radius (kg).
        initial_mass: f64,
    },
    /// A spherical tank whose liquid is settled towards its outlet (by thrust or by the spin)
    /// and drains from its free surface down: the level falls and the centre of mass moves
    /// towards the outlet, along −axis.
    Emptying {
        /// Tank radius (m).
        radius: f64,
        /// Liquid density (kg/m³).
        density: f64,
    },
    /// A cylinder of fixed shape whose density falls uniformly: J_F axial (1/2) m R²,
    /// transverse m (R²/4 + L²/12).
    UniformBurn {
        /// Radius (m).
        radius: f64,
        /// Length along the axis (m).
        length: f64,
    },
    /// A cylindrical grain burning radially outwards from its bore (a solid motor): a hollow
    /// cylinder of fixed outer radius whose bore grows, density constant.
    CentrifugalBurn {
        /// Outer radius (m).
        radius: f64,
        /// Length along the axis (m).
        length: f64,
        /// Propellant density (kg/m³).
        density: f64,
    },
}

impl TankModel {
    /// The model's name as the scenario writes it.
    pub fn label(&self) -> &'static str {
        match self {
            TankModel::Point => "point",
            TankModel::ConstantVolume { .. } => "constant_volume",
            TankModel::ConstantDensity { .. } => "constant_density",
            TankModel::Emptying { .. } => "emptying",
            TankModel::UniformBurn { .. } => "uniform_burn",
            TankModel::CentrifugalBurn { .. } => "centrifugal_burn",
        }
    }

    /// The largest propellant mass the geometry holds (kg), or infinity when the model sets
    /// no bound (a point, a constant-volume tank, a uniform burn).
    pub fn capacity(&self) -> f64 {
        match *self {
            TankModel::Emptying { radius, density } => density * 4.0 / 3.0 * PI * radius.powi(3),
            TankModel::CentrifugalBurn {
                radius,
                length,
                density,
            } => density * PI * radius * radius * length,
            _ => f64::INFINITY,
        }
    }
}

/// A tank in the body: its model, where it is and how it is turned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PropellantTank {
    /// The depletion model.
    pub model: TankModel,
    /// The tank's geometric centre (m, body axes, about B).
    pub center: Vector3<f64>,
    /// Unit axis (body axes): a cylinder's axis; for the emptying tank, from the outlet to the
    /// opposite pole (the liquid settles towards −axis).
    pub axis: Vector3<f64>,
}

/// The propellant's mass properties and their body-frame rates at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankState {
    /// Propellant mass m (kg).
    pub mass: f64,
    /// Its rate dm/dt (kg/s, ≤ 0 while it is used).
    pub mass_rate: f64,
    /// Its centre of mass r_F (m, body axes, about B).
    pub center: Vector3<f64>,
    /// r_F′ (m/s, body frame).
    pub center_rate: Vector3<f64>,
    /// r_F″ (m/s², body frame).
    pub center_accel: Vector3<f64>,
    /// Inertia J_F about r_F (kg m², body axes).
    pub inertia: Matrix3<f64>,
    /// J_F′ (kg m²/s, body frame).
    pub inertia_rate: Matrix3<f64>,
}

impl TankState {
    /// Inertia about B, J_F + m (|r|² 1 − r rᵀ) (kg m², body axes).
    pub fn inertia_about_b(&self) -> Matrix3<f64> {
        self.inertia + self.mass * point_inertia(&self.center)
    }

    /// Its body-frame rate (kg m²/s): J_F′ + m′ (|r|² 1 − r rᵀ) + m (2 r·r′ 1 − r r′ᵀ − r′ rᵀ).
    pub fn inertia_about_b_rate(&self) -> Matrix3<f64> {
        let (r, v) = (&self.center, &self.center_rate);
        let cross = 2.0 * r.dot(v) * Matrix3::identity() - r * v.transpose() - v * r.transpose();
        self.inertia_rate + self.mass_rate * point_inertia(r) + self.mass * cross
    }
}

/// |r|² 1 − r rᵀ: a unit point mass's inertia about the origin.
pub fn point_inertia(r: &Vector3<f64>) -> Matrix3<f64> {
    r.norm_squared() * Matrix3::identity() - r * r.transpose()
}

impl PropellantTank {
    /// The propellant's properties at mass `mass` (kg) with rates `mass_rate` (kg/s) and
    /// `mass_accel` (kg/s²).
    pub fn state(&self, mass: f64, mass_rate: f64, mass_accel: f64) -> TankState {
        let k = &self.axis;
        // An axisymmetric tensor t 1 + (a − t) k kᵀ from transverse t and axial a moments.
        let axisymmetric = |t: f64, a: f64| t * Matrix3::identity() + (a - t) * (k * k.transpose());
        let mut s = TankState {
            mass,
            mass_rate,
            center: self.center,
            center_rate: Vector3::zeros(),
            center_accel: Vector3::zeros(),
            inertia: Matrix3::zeros(),
            inertia_rate: Matrix3::zeros(),
        };
        let (m, dm) = (mass, mass_rate);
        match self.model {
            TankModel::Point => {}
            TankModel::ConstantVolume { radius } => {
                let r2 = radius * radius;
                s.inertia = axisymmetric(0.4 * m * r2, 0.4 * m * r2);
                s.inertia_rate = axisymmetric(0.4 * dm * r2, 0.4 * dm * r2);
            }
            TankModel::ConstantDensity {
                radius,
                initial_mass,
            } => {
                let r2 = (radius * (m.max(0.0) / initial_mass).cbrt()).powi(2);
                s.inertia = axisymmetric(0.4 * m * r2, 0.4 * m * r2);
                // d/dt[(2/5) m R²] with R² ∝ m^(2/3): (2/5)(5/3) m′ R².
                s.inertia_rate = axisymmetric(2.0 / 3.0 * dm * r2, 2.0 / 3.0 * dm * r2);
            }
            TankModel::UniformBurn { radius, length } => {
                let (t, a) = (
                    radius * radius / 4.0 + length * length / 12.0,
                    radius * radius / 2.0,
                );
                s.inertia = axisymmetric(m * t, m * a);
                s.inertia_rate = axisymmetric(dm * t, dm * a);
            }
            TankModel::CentrifugalBurn {
                radius,
                length,
                density,
            } => {
                let r2 = radius * radius;
                // The bore: m = ρ π L (R² − b²).
                let b2 = (r2 - m / (density * PI * length)).max(0.0);
                let l2 = length * length / 12.0;
                s.inertia = axisymmetric(m * ((r2 + b2) / 4.0 + l2), m * (r2 + b2) / 2.0);
                // Burning removes the layer at the bore: per kg, b²/2 + L²/12 and b².
                s.inertia_rate = axisymmetric(dm * (b2 / 2.0 + l2), dm * b2);
            }
            TankModel::Emptying { radius, density } => {
                let e = emptying(radius, density, m, dm, mass_accel);
                s.center = self.center + e.offset * k;
                s.center_rate = e.offset_rate * k;
                s.center_accel = e.offset_accel * k;
                s.inertia = axisymmetric(e.transverse, e.axial);
                s.inertia_rate = axisymmetric(e.transverse_rate, e.axial_rate);
            }
        }
        s
    }
}

/// The emptying sphere along its axis: the liquid fills the sphere of radius R from its
/// outlet (z = −R) up to the free surface z_s, z measured along the axis from the centre.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Emptying {
    /// Centre of mass on the axis, from the tank's centre (m, ≤ 0).
    offset: f64,
    offset_rate: f64,
    offset_accel: f64,
    /// Moments about the liquid's centre of mass (kg m²).
    transverse: f64,
    axial: f64,
    transverse_rate: f64,
    axial_rate: f64,
}

/// The free surface's height z_s / R for a liquid volume `v` πR³ (0 ≤ v ≤ 4/3): the root in
/// [−1, 1] of c³ − 3c + (3v − 2) = 0 (the volume of the segment below z_s = cR is
/// πR³(2/3 + c − c³/3)), by the trigonometric form of the cubic.
pub fn emptying_level(v: f64) -> f64 {
    let q = (3.0 * v - 2.0).clamp(-2.0, 2.0);
    let phi = (-q / 2.0).acos();
    2.0 * (phi / 3.0 - 2.0 * PI / 3.0).cos()
}

fn emptying(radius: f64, density: f64, m: f64, dm: f64, ddm: f64) -> Emptying {
    let r = radius;
    let a = r * r;
    let c = emptying_level(m / (density * PI * r.powi(3)));
    let zs = c * r;
    // ∫ from −R to z of π (a − z²)^k-type integrands: the first moment, the axial and the
    // transverse (about the tank's centre) second moments of the liquid, per unit density.
    let first = |z: f64| PI * (a * z * z / 2.0 - z.powi(4) / 4.0);
    let quartic = |z: f64| a * a * z - 2.0 * a * z.powi(3) / 3.0 + z.powi(5) / 5.0;
    let axial = |z: f64| PI / 2.0 * quartic(z);
    let transverse = |z: f64| PI * (quartic(z) / 4.0 + a * z.powi(3) / 3.0 - z.powi(5) / 5.0);
    let q = density * (first(zs) - first(-r));
    let i_axial = density * (axial(zs) - axial(-r));
    let i_transverse_centre = density * (transverse(zs) - transverse(-r));
    let offset = if m > 0.0 { q / m } else { -r };
    // The liquid leaves from the free surface, a disc of radius² a − z_s² at z_s: per kg it
    // takes z_s of first moment, (a − z_s²)/2 of axial and (a − z_s²)/4 + z_s² of transverse
    // moment about the centre.
    let disc = a - zs * zs;
    let dq = dm * zs;
    let di_axial = dm * disc / 2.0;
    let di_transverse_centre = dm * (disc / 4.0 + zs * zs);
    let (offset_rate, offset_accel) = if m > 0.0 {
        let rate = (dq - offset * dm) / m;
        // z_s′ = m′ / (ρ π (a − z_s²)), singular only with the surface at a pole.
        let dzs = if disc > 0.0 {
            dm / (density * PI * disc)
        } else {
            0.0
        };
        let accel =
            (ddm * (zs - offset) + dm * (dzs - rate)) / m - dm * dm * (zs - offset) / (m * m);
        (rate, accel)
    } else {
        (0.0, 0.0)
    };
    Emptying {
        offset,
        offset_rate,
        offset_accel,
        transverse: i_transverse_centre - m * offset * offset,
        axial: i_axial,
        transverse_rate: di_transverse_centre
            - 2.0 * m * offset * offset_rate
            - dm * offset * offset,
        axial_rate: di_axial,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn tank(model: TankModel) -> PropellantTank {
        PropellantTank {
            model,
            center: Vector3::new(0.1, -0.2, -0.3),
            axis: Vector3::new(0.0, 0.6, 0.8),
        }
    }

    /// Every rate is the derivative of its quantity along m(t) = m₀ + ṁ t + ½ m̈ t², by
    /// central differences (the rates are closed forms; the quantities are independent).
    #[test]
    fn rates_are_the_derivatives_of_the_mass_properties() {
        let models = [
            TankModel::Point,
            TankModel::ConstantVolume { radius: 0.4 },
            TankModel::ConstantDensity {
                radius: 0.4,
                initial_mass: 300.0,
            },
            TankModel::UniformBurn {
                radius: 0.5,
                length: 0.8,
            },
            TankModel::CentrifugalBurn {
                radius: 0.5,
                length: 0.8,
                density: 1800.0,
            },
            TankModel::Emptying {
                radius: 0.4,
                density: 1000.0,
            },
        ];
        let (m0, dm, ddm) = (150.0, -3.0, 0.4);
        for model in models {
            let t = tank(model);
            let mass = |dt: f64| m0 + dm * dt + 0.5 * ddm * dt * dt;
            let at = |dt: f64| t.state(mass(dt), dm + ddm * dt, ddm);
            let h = 1e-4;
            let (before, now, after) = (at(-h), at(0.0), at(h));
            let d = |f: &dyn Fn(&TankState) -> Matrix3<f64>| (f(&after) - f(&before)) / (2.0 * h);
            let scale = now.inertia_about_b().norm().max(1.0);
            assert_relative_eq!(d(&|s| s.inertia), now.inertia_rate, epsilon = 1e-7 * scale);
            assert_relative_eq!(
                d(&|s| s.inertia_about_b()),
                now.inertia_about_b_rate(),
                epsilon = 1e-7 * scale
            );
            let v = (after.center - before.center) / (2.0 * h);
            assert_relative_eq!(v, now.center_rate, epsilon = 1e-9);
            let a = (after.center_rate - before.center_rate) / (2.0 * h);
            assert_relative_eq!(a, now.center_accel, epsilon = 1e-8);
        }
    }

    /// The emptying sphere against the sphere's own numbers: full, it is a solid sphere about
    /// its centre; half full, a hemisphere (centre 3R/8 below, moments (2/5) m R² axial and
    /// (83/320) m R² transverse about its centre of mass).
    #[test]
    fn the_emptying_sphere_is_a_sphere_full_and_a_hemisphere_half_full() {
        let (r, rho): (f64, f64) = (0.5, 800.0);
        let full = rho * 4.0 / 3.0 * PI * r.powi(3);
        let e = emptying(r, rho, full, 0.0, 0.0);
        assert_relative_eq!(e.offset, 0.0, epsilon = 1e-12);
        assert_relative_eq!(e.axial, 0.4 * full * r * r, max_relative = 1e-12);
        assert_relative_eq!(e.transverse, 0.4 * full * r * r, max_relative = 1e-12);
        let half = full / 2.0;
        let e = emptying(r, rho, half, 0.0, 0.0);
        assert_relative_eq!(e.offset, -3.0 * r / 8.0, max_relative = 1e-12);
        assert_relative_eq!(e.axial, 0.4 * half * r * r, max_relative = 1e-12);
        assert_relative_eq!(
            e.transverse,
            83.0 / 320.0 * half * r * r,
            max_relative = 1e-12
        );
        assert_relative_eq!(emptying_level(0.0), -1.0, epsilon = 1e-12);
        assert_relative_eq!(emptying_level(4.0 / 3.0), 1.0, epsilon = 1e-7);
    }

    /// The hollow grain against the thick-walled tube's moments (outer R, bore b).
    #[test]
    fn the_burning_grain_is_a_thick_walled_tube() {
        let (r, l, rho) = (0.5, 0.8, 1800.0);
        let b = 0.2;
        let m = rho * PI * (r * r - b * b) * l;
        let t = tank(TankModel::CentrifugalBurn {
            radius: r,
            length: l,
            density: rho,
        });
        let s = t.state(m, -1.0, 0.0);
        let k = t.axis;
        assert_relative_eq!(
            (s.inertia * k).dot(&k),
            m * (r * r + b * b) / 2.0,
            max_relative = 1e-12
        );
        let n = Vector3::new(1.0, 0.0, 0.0);
        assert_relative_eq!(
            (s.inertia * n).dot(&n),
            m * (3.0 * (r * r + b * b) + l * l) / 12.0,
            max_relative = 1e-12
        );
    }
}
