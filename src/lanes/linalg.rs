//! Small vector algebra in lanes: 3-vectors as `[L; 3]`, 3 × 3 matrices as columns
//! `[[L; 3]; 3]` (`m[j][i]` is row i, column j: nalgebra's storage), and the hub's quaternion
//! kinematics.
//!
//! Each operation sums in the order nalgebra does for `Vector3<f64>` and `Matrix3<f64>`
//! (`dot`: x + y + z left to right; `cross`: `a_y b_z − a_z b_y`, …; a matrix times a vector:
//! column 0, then plus column 1, then plus column 2), so code that moved from nalgebra to these
//! keeps its bits.

use super::Lane;

/// `a · b`.
#[inline(always)]
pub fn dot<L: Lane>(a: [L; 3], b: [L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a·b + c`, rounded once ([`Lane::mul_add`]) where `FMA`, twice (the product, then the
/// sum) otherwise.
#[inline(always)]
pub fn mul_add<L: Lane, const FMA: bool>(a: L, b: L, c: L) -> L {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// `a · b` as `a₂b₂ + (a₁b₁ + a₀b₀)` by [`mul_add`]: without `FMA`, [`dot`]'s bits.
#[inline(always)]
pub fn dot_fma<L: Lane, const FMA: bool>(a: [L; 3], b: [L; 3]) -> L {
    mul_add::<L, FMA>(a[2], b[2], mul_add::<L, FMA>(a[1], b[1], a[0] * b[0]))
}

/// `a × b`, each component `aᵢbⱼ − aⱼbᵢ` as `aᵢbⱼ + (−aⱼbᵢ)` by [`mul_add`]: without `FMA`,
/// [`cross`]'s bits.
#[inline(always)]
pub fn cross_fma<L: Lane, const FMA: bool>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [
        mul_add::<L, FMA>(a[1], b[2], -(a[2] * b[1])),
        mul_add::<L, FMA>(a[2], b[0], -(a[0] * b[2])),
        mul_add::<L, FMA>(a[0], b[1], -(a[1] * b[0])),
    ]
}

/// `s a + t b` as `s a + (t b)` by [`mul_add`]: without `FMA`, the bits of
/// `add(scale(s, a), scale(t, b))`.
#[inline(always)]
pub fn axpby<L: Lane, const FMA: bool>(s: L, a: [L; 3], t: L, b: [L; 3]) -> [L; 3] {
    [
        mul_add::<L, FMA>(s, a[0], t * b[0]),
        mul_add::<L, FMA>(s, a[1], t * b[1]),
        mul_add::<L, FMA>(s, a[2], t * b[2]),
    ]
}

/// `|a|` as nalgebra's `Vector3::norm` rounds it: `√(0 + ((x² + y²) + z²))`.
#[inline(always)]
pub fn norm<L: Lane>(a: [L; 3]) -> L {
    (L::splat(0.0) + dot(a, a)).sqrt()
}

/// `a × b`.
#[inline(always)]
pub fn cross<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `s a`.
#[inline(always)]
pub fn scale<L: Lane>(s: L, a: [L; 3]) -> [L; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// `a + b`.
#[inline(always)]
pub fn add<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline(always)]
pub fn sub<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `m x` for a 3 × 3 matrix given by columns: column 0 times x₀, plus column 1 times x₁, plus
/// column 2 times x₂.
#[inline(always)]
pub fn mat_vec<L: Lane>(m: &[[L; 3]; 3], x: [L; 3]) -> [L; 3] {
    let y = scale(x[0], m[0]);
    let y = add(scale(x[1], m[1]), y);
    add(scale(x[2], m[2]), y)
}

/// The inverse of a symmetric 3 × 3 matrix [[a, b, c], [b, d, e], [c, e, f]] by its cofactors
/// (symmetric: its rows are its columns), and the lanes in which it is positive definite (Sylvester's criterion: a, a d − b²
/// and the determinant positive); the other lanes' inverse is meaningless. The same cofactors
/// as `model::spd_inverse3`, which the general path keeps for itself.
#[inline(always)]
pub fn spd_inverse3<L: Lane>(a: L, b: L, c: L, d: L, e: L, f: L) -> ([[L; 3]; 3], L::Mask) {
    let zero = L::splat(0.0);
    let (c00, c01, c02) = (d * f - e * e, c * e - b * f, b * e - c * d);
    let det = a * c00 + b * c01 + c * c02;
    let minor2 = a * d - b * b;
    let ok = a.greater_than(zero) & minor2.greater_than(zero) & det.greater_than(zero);
    let (c11, c12, c22) = (a * f - c * c, b * c - a * e, minor2);
    let r = L::splat(1.0) / det;
    (
        [
            [c00 * r, c01 * r, c02 * r],
            [c01 * r, c11 * r, c12 * r],
            [c02 * r, c12 * r, c22 * r],
        ],
        ok,
    )
}

/// `Σᵢ aᵢ bᵢ` of two rows of 3 × 3 matrices given by columns, as nalgebra's `dot` of two
/// row views sums them: from zero, left to right.
#[inline(always)]
fn row_dot<L: Lane>(a: &[[L; 3]; 3], i: usize, b: &[[L; 3]; 3], j: usize) -> L {
    L::splat(0.0) + a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j]
}

/// Solves `m z = f` for a symmetric positive definite 6 × 6 `m` given by columns (`m[c][r]` is
/// row r, column c; the lower triangle is read) by the Schur complement of its translational
/// block, with the operations (and their order) of the scalar hub solve
/// (`model::schur_solve6`): with m = [[A, Bᵀ], [B, C]], X = B A⁻¹, S = C − X Bᵀ,
/// z_r = S⁻¹ (f_r − X f_t) and z_t = A⁻¹ f_t − Xᵀ z_r. Returns z and the lanes in which A and
/// S are positive definite (the others' z is meaningless: the scalar path falls back to an
/// LU solve there).
#[inline(always)]
pub fn schur_solve6<L: Lane>(m: &[[L; 6]; 6], f: &[L; 6]) -> ([L; 6], L::Mask) {
    let (a_inv, a_ok) = spd_inverse3(m[0][0], m[0][1], m[0][2], m[1][1], m[1][2], m[2][2]);
    // B, rows 3–5 of columns 0–2, by columns.
    let b: [[L; 3]; 3] = [0, 1, 2].map(|c| [m[c][3], m[c][4], m[c][5]]);
    // X = B A⁻¹, column by column: B times A⁻¹'s column.
    let x: [[L; 3]; 3] = [
        mat_vec(&b, a_inv[0]),
        mat_vec(&b, a_inv[1]),
        mat_vec(&b, a_inv[2]),
    ];
    let s = |i: usize, j: usize| m[3 + j][3 + i] - row_dot(&x, i, &b, j);
    let (s_inv, s_ok) = spd_inverse3(s(0, 0), s(1, 0), s(2, 0), s(1, 1), s(2, 1), s(2, 2));
    let f_t = [f[0], f[1], f[2]];
    let f_r = [f[3], f[4], f[5]];
    let z_r = mat_vec(&s_inv, sub(f_r, mat_vec(&x, f_t)));
    // Xᵀ z_r: each column of X dotted with z_r.
    let xt_z = each3(|c| dot(x[c], z_r));
    let z_t = sub(mat_vec(&a_inv, f_t), xt_z);
    (
        [z_t[0], z_t[1], z_t[2], z_r[0], z_r[1], z_r[2]],
        a_ok & s_ok,
    )
}

/// `q̇ = ½ q ⊗ (0, ω)` for `q = (w, x, y, z)` (scalar first) and the body rate `omega` (rad/s,
/// body axes); units of q per second.
#[inline(always)]
pub fn quaternion_rate<L: Lane>(q: [L; 4], omega: [L; 3]) -> [L; 4] {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let (p, r, s) = (omega[0], omega[1], omega[2]);
    let half = L::splat(0.5);
    [
        L::splat(-0.5) * (x * p + y * r + z * s),
        half * (w * p + y * s - z * r),
        half * (w * r + z * p - x * s),
        half * (w * s + x * r - y * p),
    ]
}

/// `[f(0), f(1), f(2)]`, written out: `std::array::from_fn` may leave its closure out of line,
/// and an out-of-line function does not get the instruction set of the engine it is called
/// from (the eight AVX-512 lanes' intrinsics then become calls).
#[inline(always)]
pub fn each3<L: Lane>(f: impl Fn(usize) -> L) -> [L; 3] {
    [f(0), f(1), f(2)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    /// The lane forms give nalgebra's bits (the scalar path moved from nalgebra to these).
    #[test]
    fn products_give_nalgebras_bits() {
        let a = Vector3::new(0.3, -1.7e-3, 2.9);
        let b = Vector3::new(-4.1, 0.77, 1.0 / 3.0);
        let m = Matrix3::new(1.1, 0.2, -0.3, 0.25, 2.2, 0.4, -0.35, 0.45, 3.3);
        let (av, bv) = ([a.x, a.y, a.z], [b.x, b.y, b.z]);
        assert_eq!(dot(av, bv).to_bits(), a.dot(&b).to_bits());
        assert_eq!(cross(av, bv), <[f64; 3]>::from(a.cross(&b)));
        assert_eq!(mat_vec(&m.data.0, av), <[f64; 3]>::from(m * a));
    }

    /// Unfused, the multiply–add forms give the plain forms' bits (nalgebra's); fused, the
    /// first product of each sum is not rounded, which keeps low bits that separate rounding
    /// loses (values worked out by hand, below).
    #[test]
    fn multiply_add_forms_round_once_only_when_fused() {
        let a = Vector3::new(0.3, -1.7e-3, 2.9);
        let b = Vector3::new(-4.1, 0.77, 1.0 / 3.0);
        let (av, bv) = ([a.x, a.y, a.z], [b.x, b.y, b.z]);
        assert_eq!(dot_fma::<f64, false>(av, bv).to_bits(), a.dot(&b).to_bits());
        assert_eq!(
            cross_fma::<f64, false>(av, bv),
            <[f64; 3]>::from(a.cross(&b))
        );
        let (s, t) = (0.7, -1.3);
        assert_eq!(
            axpby::<f64, false>(s, av, t, bv),
            <[f64; 3]>::from(a * s + b * t)
        );
        // x = 1 + 2⁻³⁰, y = 1 + 2⁻²⁹: x·x − y·y with the exact products 1 + 2⁻²⁹ + 2⁻⁶⁰ and
        // 1 + 2⁻²⁸ + 2⁻⁵⁸. Unfused, both low parts are lost: −2⁻²⁹. Fused, only the second
        // product is rounded: −2⁻²⁹ + 2⁻⁶⁰. Likewise x·x − x·x is −2⁻⁶⁰ fused (the first
        // product exact, the second rounded), 0 unfused; and x·x − y is 2⁻⁶⁰ fused.
        let (x, y) = (1.0 + 2f64.powi(-30), 1.0 + 2f64.powi(-29));
        let (p, q) = ([0.0, x, y], [0.0, y, x]);
        let low = -(2f64.powi(-29));
        assert_eq!(cross_fma::<f64, false>(p, q)[0], low);
        assert_eq!(cross_fma::<f64, true>(p, q)[0], low + 2f64.powi(-60));
        assert_eq!(
            dot_fma::<f64, true>([x, 0.0, x], [x, 0.0, -x]),
            -(2f64.powi(-60))
        );
        assert_eq!(dot_fma::<f64, false>([x, 0.0, x], [x, 0.0, -x]), 0.0);
        assert_eq!(
            axpby::<f64, true>(x, [x; 3], -y, [1.0; 3]),
            [2f64.powi(-60); 3]
        );
    }

    /// The lanes' Schur solve is the scalar hub solve's, bit for bit, on 2000 symmetric
    /// positive definite matrices of a hub with appendages (mass and inertia blocks coupled by
    /// first moments, products of inertia, moments over four decades) four at a time, and
    /// both decline an indefinite one.
    #[test]
    fn the_schur_solve_is_the_hub_solves() {
        use crate::lanes::{F64x4, LaneMask};
        use nalgebra::{Matrix6, Vector6};
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut uniform = move |lo: f64, hi: f64| {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            let u = (state.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 11) as f64 / (1u64 << 53) as f64;
            lo + (hi - lo) * u
        };
        // A hub with appendages: mass and inertia blocks coupled by first moments, and each
        // rod's reduced mass adding μ v vᵀ (v = [ê; h × ê]), which fills every block.
        let mut draw = || {
            let mass = uniform(1.0, 5000.0);
            let s = Vector3::new(uniform(-3.0, 3.0), uniform(-3.0, 3.0), uniform(-3.0, 3.0));
            let moments = Vector3::new(uniform(0.1, 1000.0), uniform(0.1, 1000.0), 0.0);
            let i3 = uniform(0.1, 1000.0) + moments.x.max(moments.y);
            let (p, q, r) = (
                uniform(-0.05, 0.05),
                uniform(-0.05, 0.05),
                uniform(-0.05, 0.05),
            );
            let inertia = Matrix3::new(moments.x, p, q, p, moments.y, r, q, r, i3)
                + (s.norm_squared() * Matrix3::identity() - s * s.transpose()) / mass;
            let mut m = Matrix6::<f64>::zeros();
            for i in 0..3 {
                m[(i, i)] = mass;
            }
            let sx = s.cross_matrix();
            m.fixed_view_mut::<3, 3>(3, 0).copy_from(&sx);
            m.fixed_view_mut::<3, 3>(0, 3).copy_from(&sx.transpose());
            m.fixed_view_mut::<3, 3>(3, 3).copy_from(&inertia);
            for _ in 0..4 {
                let e = Vector3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
                let h = Vector3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
                let he = h.cross(&e);
                let v = Vector6::new(e.x, e.y, e.z, he.x, he.y, he.z);
                m += uniform(0.01, 10.0) * v * v.transpose();
            }
            let f = Vector6::from_fn(|_, _| uniform(-50.0, 50.0));
            (m, f)
        };
        let mut solved = 0;
        for _ in 0..500 {
            let cases: [(Matrix6<f64>, Vector6<f64>); 4] = std::array::from_fn(|_| draw());
            let m: [[F64x4; 6]; 6] = std::array::from_fn(|c| {
                std::array::from_fn(|r| F64x4(cases.each_ref().map(|(m, _)| m[(r, c)])))
            });
            let f: [F64x4; 6] = std::array::from_fn(|r| F64x4(cases.each_ref().map(|(_, f)| f[r])));
            let (z, ok) = schur_solve6(&m, &f);
            for (i, (m, f)) in cases.iter().enumerate() {
                let Some(expected) = crate::model::schur_solve6(m, f) else {
                    assert!(!ok.test(i));
                    continue;
                };
                assert!(ok.test(i));
                solved += 1;
                for r in 0..6 {
                    assert_eq!(z[r].lane(i).to_bits(), expected[r].to_bits(), "z[{r}]");
                }
            }
        }
        assert!(solved > 1900, "{solved} of 2000 solved");
        // Indefinite (a negative mass): both decline.
        let (mut bad, f) = draw();
        bad[(0, 0)] = -1.0;
        assert!(crate::model::schur_solve6(&bad, &f).is_none());
        let cols: [[f64; 6]; 6] = std::array::from_fn(|c| std::array::from_fn(|r| bad[(r, c)]));
        let f: [f64; 6] = std::array::from_fn(|r| f[r]);
        assert!(!schur_solve6(&cols, &f).1);
    }

    #[test]
    fn spd_inverse_inverts_and_rejects_indefinite_matrices() {
        let (inv, ok) = spd_inverse3(4.0, 1.0, 0.5, 3.0, 0.25, 2.0);
        assert!(ok);
        let m = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.25, 0.5, 0.25, 2.0);
        let expected = m.try_inverse().unwrap();
        for i in 0..3 {
            for j in 0..3 {
                assert!((inv[i][j] - expected[(i, j)]).abs() < 1e-15);
            }
        }
        assert!(!spd_inverse3(1.0, 2.0, 0.0, 1.0, 0.0, 1.0).1);
        assert!(!spd_inverse3(f64::NAN, 0.0, 0.0, 1.0, 0.0, 1.0).1);
    }
}
