//! The rigid hub's mass properties: inertia tensor, principal axes, physical validity.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use std::fmt;

/// Why an inertia tensor is not that of a physical rigid body.
#[derive(Debug, Clone, PartialEq)]
pub enum InertiaError {
    /// Some entry is NaN or infinite.
    NonFinite,
    /// `I[i][j] != I[j][i]` beyond rounding.
    NotSymmetric {
        /// Row of the offending entry (0-based).
        row: usize,
        /// Column of the offending entry (0-based).
        col: usize,
    },
    /// A principal moment is zero or negative (kg m²).
    NotPositiveDefinite {
        /// The principal moments found, ascending (kg m²).
        principal: [f64; 3],
    },
    /// `I_a + I_b < I_c` for the principal moments: no mass distribution has this tensor.
    TriangleInequality {
        /// The principal moments found, ascending (kg m²).
        principal: [f64; 3],
    },
}

impl fmt::Display for InertiaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InertiaError::NonFinite => write!(f, "every entry must be a finite number"),
            InertiaError::NotSymmetric { row, col } => write!(
                f,
                "the tensor must be symmetric, but entry [{row}][{col}] differs from [{col}][{row}]"
            ),
            InertiaError::NotPositiveDefinite { principal: p } => write!(
                f,
                "the tensor must be positive definite, but its principal moments are \
                 {:.6e}, {:.6e}, {:.6e} kg m²",
                p[0], p[1], p[2]
            ),
            InertiaError::TriangleInequality { principal: p } => write!(
                f,
                "principal moments {:.6e}, {:.6e}, {:.6e} kg m² violate the triangle inequality \
                 I1 + I2 >= I3 (no rigid body has them)",
                p[0], p[1], p[2]
            ),
        }
    }
}

impl std::error::Error for InertiaError {}

/// Mass properties of a rigid body about its centre of mass, in body axes.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    /// Inertia tensor in body axes (kg m²).
    pub inertia: Matrix3<f64>,
    /// Its inverse (1/(kg m²)), precomputed for the equations of motion.
    pub inertia_inv: Matrix3<f64>,
    /// Principal moments, ascending (kg m²).
    pub principal_moments: Vector3<f64>,
    /// Columns are the unit principal axes in body coordinates, ordered as
    /// `principal_moments`, forming a right-handed frame.
    pub principal_axes: Matrix3<f64>,
}

impl RigidBody {
    /// Validates `inertia` (symmetric, positive definite, triangle inequalities) and computes
    /// its principal axes.
    pub fn new(inertia: Matrix3<f64>) -> Result<Self, InertiaError> {
        if inertia.iter().any(|v| !v.is_finite()) {
            return Err(InertiaError::NonFinite);
        }
        let scale = inertia.amax();
        for row in 0..3 {
            for col in (row + 1)..3 {
                if (inertia[(row, col)] - inertia[(col, row)]).abs() > 1e-12 * scale {
                    return Err(InertiaError::NotSymmetric { row, col });
                }
            }
        }
        let sym = 0.5 * (inertia + inertia.transpose());
        let eig = SymmetricEigen::new(sym);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let principal = [
            eig.eigenvalues[order[0]],
            eig.eigenvalues[order[1]],
            eig.eigenvalues[order[2]],
        ];
        if principal[0] <= 0.0 {
            return Err(InertiaError::NotPositiveDefinite { principal });
        }
        // Tolerate rounding for bodies exactly on the boundary (thin rods, flat plates).
        if principal[0] + principal[1] < principal[2] * (1.0 - 1e-12) {
            return Err(InertiaError::TriangleInequality { principal });
        }
        let mut axes = Matrix3::from_columns(&[
            eig.eigenvectors.column(order[0]).into_owned(),
            eig.eigenvectors.column(order[1]).into_owned(),
            eig.eigenvectors.column(order[2]).into_owned(),
        ]);
        // Make each axis point into the positive half of the body axis it is closest to,
        // so that for a diagonal tensor the principal axes are +x, +y, +z in some order.
        for c in 0..3 {
            let col = axes.column(c).into_owned();
            let (imax, _) = col.iamax_full();
            if col[imax] < 0.0 {
                axes.set_column(c, &(-col));
            }
        }
        if axes.determinant() < 0.0 {
            let c = -axes.column(2).into_owned();
            axes.set_column(2, &c);
        }
        let inertia_inv = sym
            .try_inverse()
            .ok_or(InertiaError::NotPositiveDefinite { principal })?;
        Ok(RigidBody {
            inertia: sym,
            inertia_inv,
            principal_moments: Vector3::from(principal),
            principal_axes: axes,
        })
    }

    /// The principal axes as reported (docs/conventions.md): unit vectors in body axes, in
    /// the order of the moments, each pointing into the positive half of the body axis it is
    /// closest to. Unlike [`RigidBody::principal_axes`], which is a rotation (right-handed),
    /// the listed triad is left-handed when the ascending order of the moments is an odd
    /// permutation of x, y, z (e.g. I_z < I_y < I_x).
    pub fn reported_axes(axes: &Matrix3<f64>) -> [[f64; 3]; 3] {
        std::array::from_fn(|c| {
            let col = axes.column(c);
            let (imax, _) = col.iamax_full();
            let sign = if col[imax] < 0.0 { -1.0 } else { 1.0 };
            // `+ 0.0` turns −0 into 0, so no axis prints as `-0.000`.
            std::array::from_fn(|r| sign * col[r] + 0.0)
        })
    }

    /// A body with principal moments `[i1, i2, i3]` (kg m²) along the body x, y, z axes.
    pub fn from_principal(moments: [f64; 3]) -> Result<Self, InertiaError> {
        Self::new(Matrix3::from_diagonal(&Vector3::from(moments)))
    }

    /// Box dimensions (m) with the proportions of this inertia, the largest being `size`:
    /// a uniform box of sides a, b, c has I_a ∝ b² + c², so a² ∝ I_b + I_c − I_a.
    /// Returned along the principal axes.
    pub fn equivalent_box(&self, size: f64) -> Vector3<f64> {
        let p = self.principal_moments;
        let sq = |a: f64, b: f64, c: f64| (b + c - a).max(0.0).sqrt();
        let dims = Vector3::new(
            sq(p[0], p[1], p[2]),
            sq(p[1], p[0], p[2]),
            sq(p[2], p[0], p[1]),
        );
        let largest = dims.max();
        // Keep a visible minimum thickness for flat plates.
        dims.map(|d| (size * d / largest).max(0.02 * size))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Rotation3, Unit};

    #[test]
    fn reported_axes_point_into_the_positive_half_whatever_the_order() {
        // A 3U CubeSat lying along x: I_z < I_y < I_x, an odd permutation of x, y, z, so the
        // right-handed rotation must flip one axis; the reported directions do not.
        let body = RigidBody::from_principal([0.035, 0.033, 0.008]).unwrap();
        let rotation = body.principal_axes;
        assert_relative_eq!(rotation.determinant(), 1.0, epsilon = 1e-12);
        let reported = RigidBody::reported_axes(&rotation);
        assert_eq!(
            reported,
            [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
        );
        assert!(reported.iter().flatten().all(|v| v.is_sign_positive()));
        // An even permutation (x, y, z ascending) is right-handed as reported.
        let body = RigidBody::from_principal([1.0, 2.0, 3.0]).unwrap();
        let reported = RigidBody::reported_axes(&body.principal_axes);
        assert_eq!(
            reported,
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        );
    }

    #[test]
    fn principal_axes_of_a_rotated_tensor() {
        let r = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, 0.5)), 0.7);
        let d = Matrix3::from_diagonal(&Vector3::new(3.0, 1.0, 2.0));
        let i = r.matrix() * d * r.matrix().transpose();
        let body = RigidBody::new(i).unwrap();
        assert_relative_eq!(
            body.principal_moments,
            Vector3::new(1.0, 2.0, 3.0),
            epsilon = 1e-12
        );
        for c in 0..3 {
            let a = body.principal_axes.column(c).into_owned();
            assert_relative_eq!(i * a, body.principal_moments[c] * a, epsilon = 1e-12);
        }
        assert_relative_eq!(body.principal_axes.determinant(), 1.0, epsilon = 1e-12);
    }

    #[test]
    fn rejects_unphysical_tensors() {
        let bad = |m: Matrix3<f64>| RigidBody::new(m).unwrap_err();
        assert!(matches!(
            bad(Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 3.0))),
            InertiaError::TriangleInequality { .. }
        ));
        assert!(matches!(
            bad(Matrix3::from_diagonal(&Vector3::new(-1.0, 2.0, 2.0))),
            InertiaError::NotPositiveDefinite { .. }
        ));
        let mut asym = Matrix3::identity();
        asym[(0, 1)] = 0.1;
        assert!(matches!(bad(asym), InertiaError::NotSymmetric { .. }));
        let mut nan = Matrix3::identity();
        nan[(2, 2)] = f64::NAN;
        assert_eq!(bad(nan), InertiaError::NonFinite);
    }

    #[test]
    fn equivalent_box_reproduces_the_inertia_ratios() {
        // A uniform box 3 × 2 × 1 (mass 12) has I = (2²+1², 3²+1², 3²+2²) = (5, 10, 13).
        let body = RigidBody::from_principal([5.0, 10.0, 13.0]).unwrap();
        let b = body.equivalent_box(3.0);
        assert_relative_eq!(b, Vector3::new(3.0, 2.0, 1.0), epsilon = 1e-12);
    }
}
