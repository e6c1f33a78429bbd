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
