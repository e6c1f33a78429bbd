//! `modal_appendage`: a cantilever beam clamped to the hub, represented by its first N
//! bending modes in one or two transverse directions, with geometric (centrifugal) stiffening.
//!
//! The beam leaves the attachment point p₀ along â; it bends along t̂₁ (`flap`) and/or
//! t̂₂ = â × t̂₁ (`lag`). A material point at distance x from the root is at
//!
//! ```text
//! r(x) = p₀ + (x − s(x)) â + Σ_d w_d(x) t̂_d,   w_d = Σ_i q_di φ_i(x),
//! s(x) = ½ Σ_d Σ_ij q_di q_dj S_ij(x),         S_ij(x) = ∫₀ˣ φ_i' φ_j' dξ,
//! ```
//!
//! where s is the axial foreshortening of an inextensible beam. Keeping it in the kinematics
//! is what produces the centrifugal stiffening Ω² ∫ ρA (L² − x²)/2 φ_i'φ_j' dx of a spun beam
//! (Kane, Ryan & Banerjee 1987); without it (`geometric_stiffening: false`, the "conventional"
//! model) a beam spun above its first frequency diverges. The modes and the mass nodes come
//! from [`super::beam`] (Rayleigh–Ritz, tip mass included); the beam is that set of mass nodes,
//! so the particle formulation applies exactly. Modal damping: Q = −ω_i² q − 2ζ ω_i q̇.
//!
//! The coupling does not sum over the nodes at each right-hand side: every sum is a
//! contraction of state-dependent coefficients with the node sums Σm, Σm x, Σm φ_i, …,
//! Σm S_ij S_kl (the shape integrals), taken once by [`ModalBeam::new`]; the node loop
//! remains for the gravity gradient's tidal forces (equations in `docs/effectors.md`).

use super::beam::BeamModes;
use super::modal_integrals::{Geometry, ShapeIntegrals};
use super::particles::{ParticleModel, ParticlePoint, ParticleSums};
use crate::model::{Drawing, Momentum, Validity};
use nalgebra::Vector3;

/// A modal cantilever beam.
#[derive(Debug, Clone)]
pub struct ModalBeam {
    /// Modes and mass nodes. The coupling sums them once, at [`ModalBeam::new`] (the shape
    /// integrals): change them by making a new beam.
    pub modes: BeamModes,
    /// Root point p₀ (m, body axes, about the hub's centre of mass).
    pub attachment: Vector3<f64>,
    /// Unit beam axis â.
    pub axis: Vector3<f64>,
    /// Bending directions (unit, ⊥ â) with their names (`flap`, `lag`).
    pub bending: Vec<(String, Vector3<f64>)>,
    /// Modal damping ratio ζ (–).
    pub damping_ratio: f64,
    /// Whether the foreshortening (and so the geometric stiffening) is modelled.
    pub geometric_stiffening: bool,
    /// Nodes that carry mass (indices into `modes.nodes`).
    massive: Vec<usize>,
    /// The node sums of the mass model (`None`: the coupling sums node by node).
    integrals: Option<ShapeIntegrals>,
}

impl ModalBeam {
    /// A beam from its modes and geometry.
    pub fn new(
        modes: BeamModes,
        attachment: Vector3<f64>,
        axis: Vector3<f64>,
        bending: Vec<(String, Vector3<f64>)>,
        damping_ratio: f64,
        geometric_stiffening: bool,
    ) -> Self {
        let massive = (0..modes.nodes.len())
            .filter(|&g| modes.nodes[g].mass > 0.0)
            .collect();
        let integrals = ShapeIntegrals::new(&modes);
        ModalBeam {
            integrals,
            modes,
            attachment,
            axis,
            bending,
            damping_ratio,
            geometric_stiffening,
            massive,
        }
    }

    fn n_modes(&self) -> usize {
        self.modes.frequencies.len()
    }

    /// Position of node `g` at coordinates `q` (m, body axes).
    fn node_position(&self, g: usize, q: &[f64]) -> Vector3<f64> {
        let n = self.n_modes();
        let node = &self.modes.nodes[g];
        let mut r = self.attachment + node.x * self.axis;
        for (d, (_, t)) in self.bending.iter().enumerate() {
            let qd = &q[d * n..(d + 1) * n];
            let w: f64 = (0..n).map(|i| qd[i] * node.phi[i]).sum();
            r += w * t;
            if self.geometric_stiffening {
                r -= 0.5 * quadratic(&node.shortening, qd, qd, n) * self.axis;
            }
        }
        r
    }

    /// The geometry the shape integrals are contracted with (`None` past two bending
    /// directions). (Built in place: a copy of the directions assembled piece by piece and
    /// read back whole stalls the store forwarding of some processors.)
    #[inline(always)]
    fn geometry(&self) -> Option<Geometry> {
        let count = self.bending.len();
        if count > 2 {
            return None;
        }
        let direction = |d: usize| self.bending.get(d).map_or_else(Vector3::zeros, |b| b.1);
        Some(Geometry {
            attachment: self.attachment,
            axis: self.axis,
            directions: [direction(0), direction(1)],
            count,
            stiffening: self.geometric_stiffening,
        })
    }

    /// Tip deflection along each bending direction (m).
    pub fn tip_deflection(&self, q: &[f64]) -> Vec<f64> {
        let n = self.n_modes();
        let tip = &self.modes.nodes[self.modes.tip];
        (0..self.bending.len())
            .map(|d| (0..n).map(|i| q[d * n + i] * tip.phi[i]).sum())
            .collect()
    }
}

/// Tip deflection over length at which the small-deflection beam stops being accurate: the
/// linear tip deflection of a tip-loaded cantilever is 1 % above the inextensible elastica's
/// at δ/L = 0.1 (Bisshopp & Drucker 1945; docs/effectors.md). Past it the run warns.
pub const DEFLECTION_WARN: f64 = 0.1;
/// Tip deflection over length past which the model does not hold: the linear deflection is
/// 10 % above the elastica's at δ/L = 0.30 (PL²/EI = 1, δ/L = 0.3017 exactly), and the
/// second-order foreshortening has lost the same order. Past it the run stops.
pub const DEFLECTION_LIMIT: f64 = 0.3;

impl ModalBeam {
    /// Beam length L (m): the tip's distance from the root.
    pub fn length(&self) -> f64 {
        self.modes.nodes[self.modes.tip].x
    }

    /// Axial foreshortening of the tip s(L) (m), as the second-order kinematics has it.
    pub fn tip_foreshortening(&self, q: &[f64]) -> f64 {
        let n = self.n_modes();
        let tip = &self.modes.nodes[self.modes.tip];
        (0..self.bending.len())
            .map(|d| {
                let qd = &q[d * n..(d + 1) * n];
                0.5 * quadratic(&tip.shortening, qd, qd, n)
            })
            .sum()
    }

    /// Tip deflection off the beam's axis, all bending directions together (m).
    fn tip_offset(&self, q: &[f64]) -> f64 {
        let n = self.n_modes();
        let tip = &self.modes.nodes[self.modes.tip];
        (0..self.bending.len())
            .map(|d| {
                let w: f64 = (0..n).map(|i| q[d * n + i] * tip.phi[i]).sum();
                w * w
            })
            .sum::<f64>()
            .sqrt()
    }
}

/// aᵀ S b for row-major n × n `s`.
fn quadratic(s: &[f64], a: &[f64], b: &[f64], n: usize) -> f64 {
    let mut total = 0.0;
    for i in 0..n {
        let row = &s[i * n..(i + 1) * n];
        let sb: f64 = row.iter().zip(b).map(|(x, y)| x * y).sum();
        total += a[i] * sb;
    }
    total
}

impl ParticleModel for ModalBeam {
    type Cache = ();
    fn kind(&self) -> &'static str {
        "modal_appendage"
    }
    fn undamped(&self) -> Self {
        ModalBeam {
            damping_ratio: 0.0,
            ..self.clone()
        }
    }
    fn num_coordinates(&self) -> usize {
        self.bending.len() * self.n_modes()
    }
    fn coordinate_names(&self) -> Vec<String> {
        let n = self.n_modes();
        self.bending
            .iter()
            .flat_map(|(name, _)| (1..=n).map(move |i| format!("{name}_{i}")))
            .collect()
    }
    fn num_particles(&self) -> usize {
        self.massive.len()
    }
    fn particle(&self, p: usize, _c: &(), q: &[f64], u: &[f64], out: &mut ParticlePoint) {
        let n = self.n_modes();
        let node = &self.modes.nodes[self.massive[p]];
        out.mass = node.mass;
        let mut r = self.attachment + node.x * self.axis;
        let mut kappa = 0.0;
        for (d, (_, t)) in self.bending.iter().enumerate() {
            let qd = &q[d * n..(d + 1) * n];
            let ud = &u[d * n..(d + 1) * n];
            let w: f64 = (0..n).map(|i| qd[i] * node.phi[i]).sum();
            r += w * t;
            for i in 0..n {
                out.jacobian[d * n + i] = node.phi[i] * t;
            }
            if self.geometric_stiffening {
                let s = &node.shortening;
                r -= 0.5 * quadratic(s, qd, qd, n) * self.axis;
                for i in 0..n {
                    let sq: f64 = (0..n).map(|j| s[i * n + j] * qd[j]).sum();
                    out.jacobian[d * n + i] -= sq * self.axis;
                }
                kappa += quadratic(s, ud, ud, n);
            }
        }
        out.position = r;
        out.convective = -kappa * self.axis;
    }
    fn summed<const N: usize>(
        &self,
        q: &[f64],
        u: &[f64],
        omega: &Vector3<f64>,
        out: &mut ParticleSums<N>,
    ) -> bool {
        let (Some(integrals), Some(geometry)) = (&self.integrals, self.geometry()) else {
            return false;
        };
        integrals.sums(&geometry, q, u, omega, out);
        true
    }
    fn momentum_closed_form(&self, q: &[f64], u: &[f64], omega: &Vector3<f64>) -> Option<Momentum> {
        let integrals = self.integrals.as_ref()?;
        let geometry = self.geometry()?;
        Some(integrals.momentum(&geometry, q, u, omega))
    }
    fn forces(&self, q: &[f64], u: &[f64], out: &mut [f64]) {
        let n = self.n_modes();
        for (k, o) in out.iter_mut().enumerate() {
            let w = self.modes.frequencies[k % n];
            *o = -w * w * q[k] - 2.0 * self.damping_ratio * w * u[k];
        }
    }
    fn elastic_energy(&self, q: &[f64]) -> f64 {
        let n = self.n_modes();
        q.iter()
            .enumerate()
            .map(|(k, x)| 0.5 * self.modes.frequencies[k % n].powi(2) * x * x)
            .sum()
    }
    fn dissipation_power(&self, _q: &[f64], u: &[f64]) -> f64 {
        let n = self.n_modes();
        u.iter()
            .enumerate()
            .map(|(k, v)| 2.0 * self.damping_ratio * self.modes.frequencies[k % n] * v * v)
            .sum()
    }
    fn extra_telemetry_names(&self) -> Vec<String> {
        self.bending
            .iter()
            .map(|(name, _)| format!("tip_{name}"))
            .collect()
    }
    fn extra_telemetry(&self, q: &[f64]) -> Vec<f64> {
        self.tip_deflection(q)
    }
    fn validity(&self, q: &[f64]) -> Option<Validity> {
        Some(Validity {
            value: self.tip_offset(q) / self.length(),
            warn: DEFLECTION_WARN,
            limit: DEFLECTION_LIMIT,
        })
    }
    fn validity_report(&self, q: &[f64]) -> (String, String) {
        let length = self.length();
        let offset = self.tip_offset(q);
        (
            format!(
                "its tip is {offset:.4} m off the beam's axis, δ/L = {:.3} of its {length} m \
                 length (foreshortened by {:.4} m); the small-deflection modal model is \
                 accurate to δ/L = {DEFLECTION_WARN} (1% error) and does not hold past \
                 δ/L = {DEFLECTION_LIMIT} (10%)",
                offset / length,
                self.tip_foreshortening(q)
            ),
            "a stiffer boom (bending_stiffness) or more damping to keep the deflection small, \
             or rigid `hinged_rod` links for large motion; more modes help only if the shape \
             is not the first mode's"
                .into(),
        )
    }
    fn drawings(&self, q: &[f64]) -> Vec<Drawing> {
        // About a dozen vertices along the beam, root and tip included.
        let count = self.modes.nodes.len();
        let step = (count / 12).max(1);
        let mut points = vec![self.attachment];
        let mut order: Vec<usize> = (0..count).collect();
        order.sort_by(|&a, &b| self.modes.nodes[a].x.total_cmp(&self.modes.nodes[b].x));
        for (k, &g) in order.iter().enumerate() {
            if k % step == 0 || g == self.modes.tip {
                points.push(self.node_position(g, q));
            }
        }
        let length = self.modes.nodes[self.modes.tip].x;
        vec![Drawing::Line {
            points,
            thickness: (0.01 * length).max(0.005),
        }]
    }
}
