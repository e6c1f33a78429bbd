//! A slosh tank drained by a thruster: the pendulum analog of the tank's first lateral slosh
//! mode ([`super::slosh_pendulum`], [`super::slosh_analog`]) whose parameters follow the fill
//! fraction as the burn lowers it (docs/effectors.md, "Slosh that drains with its tank").
//!
//! The liquid is the analog's two point masses: the sloshing mass m_s(f) on a rod of length
//! L(f) from the pivot d = c_T + h_p(f) ẑ, and the fixed mass m₀ = M − m_s at
//! r₀ = c_T + h₀(f) ẑ, with ẑ against the restoring field and c_T the tank's centre. The fill
//! f = M/(ρV) falls as the thruster expels M's mass at ṁ(t); each parameter P(f) is a
//! Chebyshev interpolant of the analog over the fill range of the run ([`crate::chebyshev`]),
//! so that Ṗ = P′ ḟ and P̈ = P″ ḟ² + P′ f̈ are exact derivatives of the positions the
//! momentum is computed from. The dashpot c = 2 ζ m_s ω₁ takes ζ from the damping
//! correlation at the depth of the moment (an empirical fit with a kink in its slope, which
//! nothing differentiates). The bob at r_b = d + L ê(φ, θ) moves relative to the body at
//! w_b = J u + ḋ + L̇ ê, and its acceleration relative to the body, beyond J u̇, is
//! L κ + d̈ + L̈ ê + 2 (L̇/L) J u.
//!
//! Mass moves between the pieces and out: the bob gains ṁ_s, the fixed mass ṁ₀ = −ṁ − ṁ_s,
//! and ṁ leaves through the nozzle at r_e. Mass the bob gains or loses does so at the bob's
//! velocity, so the bob's equation is that of the fixed-mass pendulum, J_kᵀ (m_s a_b) = Q_k,
//! with the dashpot Q = −c Jᵀ J u on its swing. The flow inside the spacecraft runs along
//! straight paths, fixed mass to nozzle and fixed mass to bob, carrying the momentum
//! p_f = ṁ r_e + ṁ_s r_b + ṁ₀ r₀ and the angular momentum about B h_f = ṁ r₀ × r_e +
//! ṁ_s r₀ × r_b (relative to the body). With them the spacecraft's H plus what the exhaust
//! carried out is conserved exactly by the equations (as for [`super::Thruster`]'s own tank,
//! of which this is the sloshing form); the thruster, built with [`super::Thruster::fed`], adds
//! the thrust and the exhaust's flux.

use super::particles::{ParticleModel, add_mass_and_first_moment};
use super::slosh_analog::{
    Liquid, SloshAnalog, SloshError, Tank, damping_ratio_at_depth, slosh_analog,
};
use super::slosh_pendulum::SloshPendulum;
use super::thruster::Thruster;
use crate::chebyshev::Chebyshev;
use crate::model::{
    Drawing, Effector, EnergyAccount, HubAcceleration, HubCoupling, HubState, Momentum, Validity,
};
use nalgebra::{Matrix3, Vector3};

/// The analog's parameters against the fill fraction by volume, over the run's fill range.
#[derive(Debug, Clone)]
pub struct FillCurves {
    /// Sloshing mass m_s (kg).
    pub slosh_mass: Chebyshev,
    /// Rod length L (m).
    pub length: Chebyshev,
    /// Pivot height h_p above the tank's centre along ẑ (m).
    pub pivot_height: Chebyshev,
    /// Fixed mass's height h₀ above the tank's centre along ẑ (m).
    pub fixed_height: Chebyshev,
    /// The swing (rad) at which the wall wave reaches 0.1 of the tank radius.
    pub amplitude_warning: Chebyshev,
}

/// The free-surface wave at the wall, over the tank radius, at which the analog's swing is
/// warned (docs/slosh-analogs.md).
pub const WAVE_RATIO: f64 = 0.1;

/// Relative distance (of the full tank's liquid mass, of the tank radius) between the
/// interpolated analog and the analog itself that the fit must reach: far below the
/// analog's own accuracy (percents) and the sphere's Ritz convergence (1e-4), a few times
/// the Ritz solution's own noise from one fill to the next (about 1e-7).
pub const FIT_TOLERANCE: f64 = 1e-6;

impl FillCurves {
    /// The analog of `tank` filled with `liquid` in the field `field` (m/s²), interpolated
    /// over the fill fractions [`lo`, `hi`], with as many Chebyshev points (24, 48 or 96) as
    /// [`FIT_TOLERANCE`] needs, judged by each series' last four coefficients. Returns the
    /// curves and that relative estimate for the mass, length and heights; the analog's
    /// error at a fill in the range, or a message if the analog does not vary smoothly
    /// enough to be followed.
    pub fn fit(
        tank: &Tank,
        liquid: &Liquid,
        field: f64,
        lo: f64,
        hi: f64,
    ) -> Result<(FillCurves, f64), FitError> {
        let analog = |f: f64| {
            slosh_analog(tank, f, liquid, field).map_err(|e| FitError::Analog { fill: f, error: e })
        };
        // The ends first, so that a refusal names the fill the run reaches.
        analog(lo)?;
        analog(hi)?;
        let full_mass = liquid.density * tank.volume();
        let radius = tank.radius();
        let mut error = f64::INFINITY;
        for n in [24, 48, 96] {
            let nodes = Chebyshev::nodes(lo, hi, n);
            let samples = nodes
                .iter()
                .map(|&f| analog(f))
                .collect::<Result<Vec<_>, _>>()?;
            let curve = |get: &dyn Fn(&SloshAnalog) -> f64| {
                let values: Vec<f64> = samples.iter().map(get).collect();
                Chebyshev::from_samples(lo, hi, &values)
            };
            let curves = FillCurves {
                slosh_mass: curve(&|a| a.slosh_mass),
                length: curve(&|a| a.pendulum_length),
                pivot_height: curve(&|a| a.pivot_height),
                fixed_height: curve(&|a| a.fixed_mass_height),
                amplitude_warning: curve(&|a| a.max_pendulum_angle(WAVE_RATIO, radius)),
            };
            // The series' tails: each parameter against its scale.
            error = [
                curves.slosh_mass.tail(4) / full_mass,
                curves.length.tail(4) / radius,
                curves.pivot_height.tail(4) / radius,
                curves.fixed_height.tail(4) / radius,
            ]
            .into_iter()
            .fold(0.0, f64::max);
            if error <= FIT_TOLERANCE {
                return Ok((curves, error));
            }
        }
        Err(FitError::NotSmooth { error })
    }
}

/// Why a tank's analog cannot be followed over a fill range.
#[derive(Debug, Clone, PartialEq)]
pub enum FitError {
    /// The analog refuses a fill in the range.
    Analog {
        /// The fill fraction.
        fill: f64,
        /// The analog's error.
        error: SloshError,
    },
    /// 96 Chebyshev points leave the series' tail this large (relative).
    NotSmooth {
        /// The relative distance.
        error: f64,
    },
}

impl std::fmt::Display for FitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitError::Analog { fill, error } => write!(f, "at fill {fill:.4}: {error}"),
            FitError::NotSmooth { error } => write!(
                f,
                "the analog's parameters do not vary smoothly enough with the fill to be \
                 followed: 96 Chebyshev points leave them {error:.1e} (relative) from it, \
                 against {FIT_TOLERANCE:e}"
            ),
        }
    }
}

/// A slosh tank whose liquid a thruster drains. States: `[φ, θ, φ̇, θ̇, dissipated energy (J),
/// liquid mass (kg)]`; the last is bookkeeping for the views and validity checks (the
/// equations take the mass from the thruster's flow, exactly).
#[derive(Debug, Clone)]
pub struct DrainingSlosh {
    name: String,
    /// The thruster that drains it (its flow and nozzle; its tank is this one).
    pub feed: Thruster,
    /// The tank's geometric centre c_T (m, body axes, about B).
    pub center: Vector3<f64>,
    /// ẑ: against the restoring field (unit, body axes).
    pub up: Vector3<f64>,
    /// The pendulum frame [p̂₁, p̂₂, p̂₃] (body axes); p̂₁ = −ẑ.
    pub frame: [Vector3<f64>; 3],
    /// The liquid of a full tank, ρ V (kg).
    pub full_mass: f64,
    /// The liquid at t = 0 (kg).
    pub initial_mass: f64,
    /// The analog against the fill.
    pub curves: FillCurves,
    /// The tank, for the damping correlation.
    pub tank: Tank,
    /// The liquid, for the damping correlation.
    pub liquid: Liquid,
    /// The restoring field the analog was derived in (m/s²).
    pub field: f64,
    /// Multiplies the smooth-wall damping (1 for a smooth tank; baffles raise it).
    pub damping_factor: f64,
    initial: [f64; 4],
}

/// Everything the equations need at one time and state.
struct Pieces {
    /// The pendulum at this fill (for its directions and checks).
    pendulum: SloshPendulum,
    /// Bob: mass, rate, second rate (kg, kg/s, kg/s²).
    ms: [f64; 3],
    /// Fixed mass: the same.
    m0: [f64; 3],
    /// Mass flow out ṁ ≥ 0 and its rate (kg/s, kg/s²).
    flow: [f64; 2],
    /// Jacobian columns (m/rad).
    columns: [Vector3<f64>; 2],
    /// Bob position, velocity relative to the body, and acceleration relative to the body
    /// beyond J u̇ (m, m/s, m/s²).
    rb: [Vector3<f64>; 3],
    /// The fixed mass's position and its relative velocity and acceleration.
    r0: [Vector3<f64>; 3],
    /// J u (m/s).
    swing_velocity: Vector3<f64>,
}

impl DrainingSlosh {
    /// `tank` (centre `center`, m, body axes) filled to `fill` with `liquid`, its analog
    /// derived in the field `field` (m/s²) and followed by `curves`, swinging in `frame`
    /// (p̂₁ along the field), drained by `feed`; initial angles and rates `q0`, `u0` (rad,
    /// rad/s).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: impl Into<String>,
        feed: Thruster,
        tank: Tank,
        center: Vector3<f64>,
        fill: f64,
        liquid: Liquid,
        field: f64,
        frame: [Vector3<f64>; 3],
        curves: FillCurves,
        q0: [f64; 2],
        u0: [f64; 2],
    ) -> DrainingSlosh {
        let full_mass = liquid.density * tank.volume();
        DrainingSlosh {
            name: name.into(),
            feed,
            center,
            up: -frame[0],
            frame,
            full_mass,
            initial_mass: fill * full_mass,
            curves,
            tank,
            liquid,
            field,
            damping_factor: 1.0,
            initial: [q0[0], q0[1], u0[0], u0[1]],
        }
    }

    /// The same with the smooth-wall damping multiplied by `factor` (baffles).
    pub fn with_damping_factor(mut self, factor: f64) -> DrainingSlosh {
        self.damping_factor = factor;
        self
    }

    /// The pendulum's dashpot c = 2 ζ m_s ω₁ (N s/m) at fill `f` for a sloshing mass
    /// `slosh_mass` (kg) on a rod `length` (m) long: ζ from the correlation at the depth of
    /// the moment, ω₁ = √(g/L).
    fn dashpot(&self, f: f64, slosh_mass: f64, length: f64) -> f64 {
        let depth = self.tank.depth(f).unwrap_or(f64::NAN) / self.tank.radius();
        let zeta = damping_ratio_at_depth(&self.tank, &self.liquid, self.field, depth);
        2.0 * self.damping_factor * zeta * slosh_mass * (self.field / length).sqrt()
    }

    /// The liquid's mass (kg) at `t` (s).
    pub fn liquid_mass(&self, t: f64) -> f64 {
        self.initial_mass - self.feed.expelled(t)
    }

    /// The fill fraction by volume at liquid mass `mass` (kg).
    pub fn fill(&self, mass: f64) -> f64 {
        mass / self.full_mass
    }

    /// The fixed-mass pendulum of the analog at fill `f`.
    pub fn pendulum_at(&self, f: f64) -> SloshPendulum {
        let c = &self.curves;
        let mass = c.slosh_mass.at(f)[0];
        let length = c.length.at(f)[0];
        SloshPendulum {
            mass,
            length,
            pivot: self.center + c.pivot_height.at(f)[0] * self.up,
            frame: self.frame,
            damping: self.dashpot(f, mass, length),
            fixed_mass: f * self.full_mass - mass,
            fixed_position: self.center + c.fixed_height.at(f)[0] * self.up,
            amplitude_warning: Some(c.amplitude_warning.at(f)[0]),
        }
    }

    fn pieces(&self, t: f64, q: &[f64], u: &[f64]) -> Pieces {
        let (flow, flow_rate) = self.feed.mass_flow(t);
        let mass = self.liquid_mass(t);
        let f = self.fill(mass);
        let (df, d2f) = (-flow / self.full_mass, -flow_rate / self.full_mass);
        // P, Ṗ, P̈ of a parameter against time.
        let chain = |c: &Chebyshev| {
            let [p, dp, d2p] = c.at(f);
            [p, dp * df, d2p * df * df + dp * d2f]
        };
        let c = &self.curves;
        let ms = chain(&c.slosh_mass);
        let l = chain(&c.length);
        let hp = chain(&c.pivot_height);
        let h0 = chain(&c.fixed_height);
        let m0 = [mass - ms[0], -flow - ms[1], -flow_rate - ms[2]];
        let z = self.up;
        let pendulum = SloshPendulum {
            mass: ms[0],
            length: l[0],
            pivot: self.center + hp[0] * z,
            frame: self.frame,
            damping: self.dashpot(f, ms[0], l[0]),
            fixed_mass: m0[0],
            fixed_position: self.center + h0[0] * z,
            amplitude_warning: None,
        };
        let [e, e_phi, e_theta, kappa] = pendulum.directions(q, u);
        let columns = [l[0] * e_phi, l[0] * e_theta];
        let swing_velocity = columns[0] * u[0] + columns[1] * u[1];
        let rb = [
            pendulum.pivot + l[0] * e,
            swing_velocity + hp[1] * z + l[1] * e,
            l[0] * kappa + hp[2] * z + l[2] * e + (2.0 * l[1] / l[0]) * swing_velocity,
        ];
        let r0 = [pendulum.fixed_position, h0[1] * z, h0[2] * z];
        Pieces {
            pendulum,
            ms,
            m0,
            flow: [flow, flow_rate],
            columns,
            rb,
            r0,
            swing_velocity,
        }
    }

    /// Per swing coordinate k: (g_k, C_k, M_k) of the coordinates' equations M u̇ = g − Cᵀ z
    /// (M diagonal: J's columns are orthogonal), z = [a_B; ω̇].
    fn coordinate_terms(p: &Pieces, w: &Vector3<f64>) -> [(f64, [f64; 6], f64); 2] {
        let m = p.ms[0];
        let [r, v, conv] = p.rb;
        let c = w.cross(&w.cross(&r)) + 2.0 * w.cross(&v) + conv;
        let damping = p.pendulum.damping;
        p.columns.map(|j| {
            let jj = j.norm_squared();
            let rj = r.cross(&j);
            let g = -damping * j.dot(&p.swing_velocity) - m * j.dot(&c);
            (
                g,
                [m * j.x, m * j.y, m * j.z, m * rj.x, m * rj.y, m * rj.z],
                m * jj,
            )
        })
    }
}

impl Effector for DrainingSlosh {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> &'static str {
        "slosh_pendulum"
    }
    fn num_states(&self) -> usize {
        6
    }
    fn num_dynamic_states(&self) -> usize {
        4
    }
    fn state_names(&self) -> Vec<String> {
        ["phi", "theta", "phi_rate", "theta_rate"]
            .iter()
            .map(|s| s.to_string())
            .chain(["dissipated_energy".into(), "liquid_mass".into()])
            .collect()
    }
    fn initial_state(&self) -> Vec<f64> {
        let mut x = self.initial.to_vec();
        x.extend([0.0, self.initial_mass]);
        x
    }
    fn moves_mass(&self) -> bool {
        true
    }
    fn changes_mass(&self) -> bool {
        true
    }
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.feed.next_kink(t)
    }
    fn scratch_len(&self) -> usize {
        // W_k = [g_k, C_k] / M_k for the two swing coordinates, then the dashpot's power.
        15
    }
    fn couple(&self, hub: &HubState, x: &[f64], c: &mut HubCoupling, scratch: &mut [f64]) {
        let w = hub.omega;
        let p = self.pieces(hub.t, &x[..2], &x[2..4]);
        let ([ms, dms, d2ms], [m0, dm0, d2m0]) = (p.ms, p.m0);
        let ([rb, vb, ab], [r0, v0, a0]) = (p.rb, p.r0);
        let [flow, flow_rate] = p.flow;
        let re = self.feed.nozzle;
        // The two point masses in the hub's mass matrix.
        add_mass_and_first_moment(&mut c.mass, ms + m0, &(ms * rb + m0 * r0));
        let inertia = |m: f64, r: &Vector3<f64>| {
            m * (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose())
        };
        let j = inertia(ms, &rb) + inertia(m0, &r0);
        for i in 0..3 {
            for k in 0..=i {
                c.mass[(3 + i, 3 + k)] += j[(i, k)];
            }
        }
        // Their accelerations at z = 0 and u̇ = 0, the mass they gain at their velocities, and
        // the flow inside.
        let cb = w.cross(&w.cross(&rb)) + 2.0 * w.cross(&vb) + ab;
        let c0 = w.cross(&w.cross(&r0)) + 2.0 * w.cross(&v0) + a0;
        let (ub, u0) = (w.cross(&rb) + vb, w.cross(&r0) + v0);
        let p_flow = flow * re + dms * rb + dm0 * r0;
        let dp_flow = flow_rate * re + d2ms * rb + dms * vb + d2m0 * r0 + dm0 * v0;
        let h_flow = flow * r0.cross(&re) + dms * r0.cross(&rb);
        let dh_flow = flow_rate * r0.cross(&re)
            + flow * v0.cross(&re)
            + d2ms * r0.cross(&rb)
            + dms * (v0.cross(&rb) + r0.cross(&vb));
        let force = -(ms * cb + m0 * c0) - (dms * ub + dm0 * u0) - dp_flow - w.cross(&p_flow);
        let moment = -(ms * rb.cross(&cb) + m0 * r0.cross(&c0))
            - (dms * rb.cross(&ub) + dm0 * r0.cross(&u0))
            - dh_flow
            - w.cross(&h_flow);
        for i in 0..3 {
            c.force[i] += force[i];
            c.force[3 + i] += moment[i];
        }
        // The swing's coordinates eliminated: mass −= C M⁻¹ Cᵀ, force −= C M⁻¹ g; kept for
        // `derivatives` as W_k = [g_k, C_k] / M_k.
        for (k, (g, ck, mk)) in Self::coordinate_terms(&p, &w).into_iter().enumerate() {
            let r = 1.0 / mk;
            let kept = &mut scratch[7 * k..7 * k + 7];
            kept[0] = g * r;
            for (w, ca) in kept[1..].iter_mut().zip(&ck) {
                *w = ca * r;
            }
            for (a, ca) in ck.iter().enumerate() {
                c.force[a] -= ca * kept[0];
                for b in 0..=a {
                    c.mass[(a, b)] -= ca * kept[1 + b];
                }
            }
        }
        scratch[14] = p.pendulum.dissipation_power(&x[..2], &x[2..4]);
        c.translation = true;
    }
    fn derivatives(
        &self,
        hub: &HubState,
        accel: &HubAcceleration,
        x: &[f64],
        scratch: &[f64],
        dx: &mut [f64],
    ) {
        let z = accel.as_vector6();
        dx[0] = x[2];
        dx[1] = x[3];
        for k in 0..2 {
            let kept = &scratch[7 * k..7 * k + 7];
            let mut s = kept[0];
            for a in 0..6 {
                s -= kept[1 + a] * z[a];
            }
            dx[2 + k] = s;
        }
        dx[4] = scratch[14];
        dx[5] = -self.feed.mass_flow(hub.t).0;
    }
    fn momentum(&self, hub: &HubState, x: &[f64]) -> Momentum {
        let w = hub.omega;
        let p = self.pieces(hub.t, &x[..2], &x[2..4]);
        let ([ms, dms, _], [m0, dm0, _]) = (p.ms, p.m0);
        let ([rb, vb, _], [r0, v0, _]) = (p.rb, p.r0);
        let flow = p.flow[0];
        let re = self.feed.nozzle;
        let (ub, u0) = (w.cross(&rb) + vb, w.cross(&r0) + v0);
        Momentum {
            mass: ms + m0,
            first_moment: ms * rb + m0 * r0,
            linear: ms * ub + m0 * u0 + flow * re + dms * rb + dm0 * r0,
            angular: ms * rb.cross(&ub)
                + m0 * r0.cross(&u0)
                + flow * r0.cross(&re)
                + dms * r0.cross(&rb),
            kinetic_energy: 0.5 * (ms * ub.norm_squared() + m0 * u0.norm_squared()),
        }
    }
    fn energy(&self, _hub: &HubState, x: &[f64]) -> EnergyAccount {
        let f = self.fill(x[5]);
        EnergyAccount {
            elastic: 0.0,
            dissipated: x[4],
            power: self.dissipation_power(f, &x[..4]),
            work: 0.0,
        }
    }
    fn telemetry_names(&self) -> Vec<String> {
        [
            "phi",
            "theta",
            "phi_rate",
            "theta_rate",
            "dissipated_energy",
            "dissipation_power",
            "liquid_mass",
            "fill",
            "slosh_mass",
            "length",
            "swing_deg",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    }
    fn telemetry(&self, hub: &HubState, x: &[f64]) -> Vec<f64> {
        let mass = self.liquid_mass(hub.t);
        let f = self.fill(mass);
        let pendulum = self.pendulum_at(f);
        vec![
            x[0],
            x[1],
            x[2],
            x[3],
            x[4],
            self.dissipation_power(f, &x[..4]),
            mass,
            f,
            pendulum.mass,
            pendulum.length,
            pendulum.swing(&x[..2]).to_degrees(),
        ]
    }
    fn drawings(&self, x: &[f64]) -> Vec<Drawing> {
        self.pendulum_at(self.fill(x[5])).drawings(&x[..2])
    }
    fn validity(&self, x: &[f64]) -> Option<Validity> {
        self.pendulum_at(self.fill(x[5])).validity(&x[..2])
    }
    fn validity_report(&self, x: &[f64]) -> (String, String) {
        self.pendulum_at(self.fill(x[5])).validity_report(&x[..2])
    }
}

impl DrainingSlosh {
    /// The dashpot's power c |J u|² (W) at fill `f` and states `x` = [φ, θ, φ̇, θ̇].
    fn dissipation_power(&self, f: f64, x: &[f64]) -> f64 {
        self.pendulum_at(f).dissipation_power(&x[..2], &x[2..4])
    }
}
