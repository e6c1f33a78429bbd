//! One flap–lag hinged rod's closed form (docs/effectors.md, "Closed forms"), written once over
//! [`Lane`]: at `f64` for each rod of a scene's group ([`super::rod_lanes::RodLanes`], the
//! scalar path), and over runs side by side for the campaigns' hinged-rods class
//! ([`crate::lanes::hinged_rods`]), so a run in the lanes has the scalar path's bits. The
//! direction ([`RodConstants::direction`]) and the coupling ([`RodConstants::coupling`]) take
//! their dot and cross products and their sums of two products as fused multiply–adds where
//! `FMA` ([`crate::lanes::linalg::mul_add`]): about half their arithmetic instructions, each
//! rounded once; the rest of the momentum is nalgebra's operations for `Vector3<f64>` in its
//! order ([`crate::lanes::linalg`]). Both paths fuse where the processor has AVX2 and FMA
//! ([`crate::cpu::avx2_available`]) and neither does elsewhere, where the bits are those of
//! the same operations unfused (nalgebra's order).
//!
//! Notation (body axes): h the hinge point, ê₀ the rest direction, n̂ the hinge axis,
//! b̂ = n̂ × ê₀; the lag circle c = cos θ_l ê₀ + sin θ_l b̂ and the rod's direction
//! ê = cos θ_f c + sin θ_f n̂; m₁ = m L/2, m₂ = m L²/3, μ = m₁²/m₂.

use crate::lanes::Lane;
use crate::lanes::linalg::{add, axpby, cross, cross_fma, dot, dot_fma, mul_add, scale, sub};

/// Entries of the rows W per rod: two rows of 7, W_k = [g_k, Cᵀ_k] / M_kk.
pub const ROWS: usize = 14;

/// |a|² as nalgebra's `norm_squared` rounds it: 0 + ((x² + y²) + z²).
#[inline(always)]
fn norm_squared<L: Lane>(a: [L; 3]) -> L {
    L::splat(0.0) + dot(a, a)
}

/// A rod's constants (one rod, or one rod of each of several runs).
#[derive(Debug, Clone, Copy)]
pub struct RodConstants<L> {
    /// Hinge point h (m, body axes).
    pub hinge: [L; 3],
    /// Rest direction ê₀ (unit).
    pub rest: [L; 3],
    /// Hinge axis n̂ (unit, ⊥ ê₀).
    pub axis: [L; 3],
    /// b̂ = n̂ × ê₀.
    pub binormal: [L; 3],
    /// m₁ = m L/2 (kg m).
    pub m1: L,
    /// m₂ = m L²/3 (kg m²).
    pub m2: L,
    /// 1/m₂ (1/(kg m²)), divided once: the flap's row is over it.
    pub inverse_m2: L,
    /// m₁/m₂ (1/m), divided once.
    pub m1_over_m2: L,
    /// μ = m₁²/m₂ (kg).
    pub mu: L,
    /// m − μ (kg).
    pub hinge_mass: L,
    /// Torsional stiffness, flap and lag (N m/rad).
    pub stiffness: [L; 2],
    /// Torsional damping, flap and lag (N m s/rad).
    pub damping: [L; 2],
}

/// ê, its derivatives ∂ê/∂θ_f and ∂ê/∂θ_l, and the lag circle's c and ∂c/∂θ_l.
#[derive(Debug, Clone, Copy)]
pub struct Direction<L> {
    /// c (unit).
    pub c: [L; 3],
    /// ∂c/∂θ_l.
    pub c_prime: [L; 3],
    /// ê (unit).
    pub e: [L; 3],
    /// ∂ê/∂θ_f.
    pub e_f: [L; 3],
    /// ∂ê/∂θ_l.
    pub e_l: [L; 3],
}

/// What a rod adds to the hub's equations and keeps for its own accelerations.
#[derive(Debug, Clone, Copy)]
pub struct RodCoupling<L> {
    /// The force the rod exerts on the hub at its hinge, with its sign reversed (N).
    pub hinge_force: [L; 3],
    /// Its moment about the hub's reference point, sign reversed (N m).
    pub hinge_moment: [L; 3],
    /// v = [ê; h × ê]: the reduced mass μ adds μ v vᵀ to the hub's mass matrix.
    pub v: [L; 6],
    /// The rows W: θ̈_k = W_k(0) − Σ_a W_k(1 + a) z_a, z the hub's acceleration (a_B, ω̇).
    pub rows: [L; ROWS],
    /// |∂ê/∂θ_l|² = cos² θ_f: the lag's inertia over m₂ (zero at a flap of 90°).
    pub cos2: L,
}

/// A rod's mass, first moment (kg m), momentum (N s, N m s) and kinetic energy (J) in the
/// hub's frame.
#[derive(Debug, Clone, Copy)]
pub struct RodMomentum<L> {
    /// m (kg).
    pub mass: L,
    /// m h + m₁ ê (kg m).
    pub first_moment: [L; 3],
    /// Linear momentum (N s).
    pub linear: [L; 3],
    /// Angular momentum about the hub's reference point (N m s).
    pub angular: [L; 3],
    /// Kinetic energy (J).
    pub kinetic_energy: L,
}

/// One row of W for the freedom whose ∂ê/∂θ is `j`, whose inertia's reciprocal is `inv`
/// (1/(kg m²)) and generalised force `q_k` (N m): [(Q − j·F_s) / M_kk, m₁ j / M_kk,
/// (p₂ × j) / M_kk], with p₂ = m₁ h + m₂ ê and F_s the rod's inertial force per unit of m₂
/// (written out, without loops or closures, for the AVX-512 lanes).
#[inline(always)]
fn row<L: Lane, const FMA: bool>(
    j: [L; 3],
    inv: L,
    q_k: L,
    m1: L,
    p2: [L; 3],
    force_s: [L; 3],
) -> [L; 7] {
    let torque = cross_fma::<L, FMA>(p2, j);
    [
        (q_k - dot_fma::<L, FMA>(j, force_s)) * inv,
        m1 * j[0] * inv,
        m1 * j[1] * inv,
        m1 * j[2] * inv,
        torque[0] * inv,
        torque[1] * inv,
        torque[2] * inv,
    ]
}

impl<L: Lane> RodConstants<L> {
    /// ê and its derivatives from `[sin θ_f, cos θ_f, sin θ_l, cos θ_l]`, as
    /// `HingedRod::direction_at`.
    #[inline(always)]
    pub fn direction<const FMA: bool>(&self, [sf, cf, sl, cl]: [L; 4]) -> Direction<L> {
        let axpby = axpby::<L, FMA>;
        let c = axpby(cl, self.rest, sl, self.binormal);
        let c_prime = axpby(-sl, self.rest, cl, self.binormal);
        let e = axpby(cf, c, sf, self.axis);
        Direction {
            c,
            c_prime,
            e,
            e_f: axpby(-sf, c, cf, self.axis),
            e_l: scale(cf, c_prime),
        }
    }

    /// The closed form at the angles and rates `[θ_f, θ_l, θ̇_f, θ̇_l]` (rad, rad/s), their
    /// sines and cosines (as [`RodConstants::direction`] takes them), the hub's rate ω
    /// (rad/s) and |ω|² (nalgebra's `norm_squared`).
    #[inline(always)]
    pub fn coupling<const FMA: bool>(
        &self,
        angles: [L; 4],
        sines: [L; 4],
        omega: [L; 3],
        w2: L,
    ) -> RodCoupling<L> {
        let [f, l, df, dl] = angles;
        let [sf, cf, ..] = sines;
        let (h, m1, m2, mu) = (self.hinge, self.m1, self.m2, self.mu);
        let two = L::splat(2.0);
        let Direction {
            c,
            c_prime,
            e,
            e_f,
            e_l,
        } = self.direction::<FMA>(sines);
        // κ = Σ ∂²ê u u: −cos θ_f θ̇_l² c − 2 sin θ_f θ̇_f θ̇_l c′ − θ̇_f² ê.
        let kappa = sub(
            sub(scale(-cf * dl * dl, c), scale(two * sf * df * dl, c_prime)),
            scale(df * df, e),
        );
        let cos2 = norm_squared(e_l);
        let q_flap = -self.stiffness[0] * f - self.damping[0] * df;
        let q_lag = -self.stiffness[1] * l - self.damping[1] * dl;
        let (dot, cross) = (dot_fma::<L, FMA>, cross_fma::<L, FMA>);
        let axpby = axpby::<L, FMA>;
        let joint = axpby(q_flap, e_f, q_lag / cos2, e_l);
        let e_rate = axpby(df, e_f, dl, e_l);
        let relative = add(scale(two, cross(omega, e_rate)), kappa);
        let omega_e = dot(omega, e);
        let lambda = mul_add::<L, FMA>(omega_e, omega_e, -w2) + dot(e, relative);
        let a_h = axpby(dot(omega, h), omega, -w2, h);
        let hinge_force = add(
            axpby(
                self.hinge_mass,
                a_h,
                mul_add::<L, FMA>(mu, dot(e, a_h), m1 * lambda),
                e,
            ),
            scale(self.m1_over_m2, joint),
        );
        let hinge_moment = add(cross(h, hinge_force), cross(e, joint));
        let he = cross(h, e);
        // The rows W (L = 1).
        let p2 = axpby(m1, h, m2, e);
        let force_s = add(axpby(dot(omega, p2), omega, -w2, p2), scale(m2, relative));
        // The flap's inertia is m₂, whose reciprocal is a constant (the same bits as dividing
        // here); the lag's, m₂ cos² θ_f.
        let flap = row::<L, FMA>(e_f, self.inverse_m2, q_flap, m1, p2, force_s);
        let lag = row::<L, FMA>(e_l, L::splat(1.0) / (m2 * cos2), q_lag, m1, p2, force_s);
        let rows = [
            flap[0], flap[1], flap[2], flap[3], flap[4], flap[5], flap[6], lag[0], lag[1], lag[2],
            lag[3], lag[4], lag[5], lag[6],
        ];
        RodCoupling {
            hinge_force,
            hinge_moment,
            v: [e[0], e[1], e[2], he[0], he[1], he[2]],
            rows,
            cos2,
        }
    }

    /// The rod's momentum and kinetic energy at the angles and rates `[θ_f, θ_l, θ̇_f, θ̇_l]`
    /// with their sines and cosines, the hub turning at ω (rad/s): the velocity along the rod
    /// is v(s) = v_h + s v_ê, v_h = ω × h, v_ê = ω × ê + θ̇_f ∂ê/∂θ_f + θ̇_l ∂ê/∂θ_l.
    #[inline(always)]
    pub fn momentum<const FMA: bool>(
        &self,
        angles: [L; 4],
        sines: [L; 4],
        omega: [L; 3],
    ) -> RodMomentum<L> {
        let Direction { e, e_f, e_l, .. } = self.direction::<FMA>(sines);
        let (m, m1, m2, h) = (self.hinge_mass + self.mu, self.m1, self.m2, self.hinge);
        let (half, two) = (L::splat(0.5), L::splat(2.0));
        let v_h = cross(omega, h);
        let v_e = add(
            add(cross(omega, e), scale(angles[2], e_f)),
            scale(angles[3], e_l),
        );
        RodMomentum {
            mass: m,
            first_moment: add(scale(m, h), scale(m1, e)),
            linear: add(scale(m, v_h), scale(m1, v_e)),
            angular: add(
                add(
                    scale(m, cross(h, v_h)),
                    scale(m1, add(cross(h, v_e), cross(e, v_h))),
                ),
                scale(m2, cross(e, v_e)),
            ),
            kinetic_energy: half * (m * norm_squared(v_h) + two * m1 * dot(v_h, v_e))
                + half * m2 * norm_squared(v_e),
        }
    }

    /// The springs' elastic energy at `[θ_f, θ_l, …]` (J), as `HingedRod::elastic_energy`:
    /// ½ (k_f θ_f² + k_l θ_l²).
    #[inline(always)]
    pub fn elastic_energy(&self, angles: [L; 4]) -> L {
        let [f, l, ..] = angles;
        L::splat(0.5) * (self.stiffness[0] * f * f + self.stiffness[1] * l * l)
    }

    /// The dampers' dissipation rate at `[…, θ̇_f, θ̇_l]` (W), as
    /// `HingedRod::dissipation_power`: c_f θ̇_f² + c_l θ̇_l².
    #[inline(always)]
    pub fn dissipation_power(&self, angles: [L; 4]) -> L {
        let [_, _, df, dl] = angles;
        self.damping[0] * df * df + self.damping[1] * dl * dl
    }
}
