//! Covariance matrices of correlated normal draws: the checks a matrix must pass to be one,
//! and the factor that turns independent standard normal draws into correlated ones.
//!
//! A draw x = μ + L z, z ~ N(0, I), has covariance L Lᵀ. For a positive definite matrix L is
//! its Cholesky factor; a positive *semi*definite one (a covariance of rank below its size,
//! e.g. two components that move together) has no Cholesky factor, so the factorisation below
//! skips the zero pivots: L stays lower triangular with a zero column where the matrix has no
//! variance left (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., §10.3).

use nalgebra::{DMatrix, SymmetricEigen};

/// Relative tolerance of the checks: entries are compared with this times the largest
/// diagonal entry (a pivot below it is zero, an asymmetry above it is refused).
pub const RELATIVE_TOLERANCE: f64 = 1e-12;

/// Why a matrix is not a covariance.
#[derive(Debug, Clone, PartialEq)]
pub enum NotCovariance {
    /// It is not n × n.
    Shape {
        /// Rows expected (and numbers per row).
        expected: usize,
        /// Row `row` has `len` numbers (or, with `row == usize::MAX`, there are `len` rows).
        row: usize,
        /// What was found.
        len: usize,
    },
    /// An entry is not finite.
    NotFinite {
        /// Row.
        row: usize,
        /// Column.
        column: usize,
    },
    /// Entry (i, j) differs from (j, i).
    NotSymmetric {
        /// Row.
        row: usize,
        /// Column.
        column: usize,
        /// Entry (row, column).
        upper: f64,
        /// Entry (column, row).
        lower: f64,
    },
    /// It has a negative eigenvalue.
    NotSemidefinite {
        /// Its smallest eigenvalue.
        smallest_eigenvalue: f64,
    },
}

impl std::fmt::Display for NotCovariance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Shape {
                expected,
                row: usize::MAX,
                len,
            } => write!(
                f,
                "expected {expected} rows of {expected} numbers (one per component drawn), got \
                 {len} rows"
            ),
            Self::Shape { expected, row, len } => write!(
                f,
                "expected {expected} rows of {expected} numbers (one per component drawn); row \
                 {row} has {len}"
            ),
            Self::NotFinite { row, column } => {
                write!(f, "entry [{row}][{column}] is not a finite number")
            }
            Self::NotSymmetric {
                row,
                column,
                upper,
                lower,
            } => write!(
                f,
                "a covariance matrix is symmetric, but entry [{row}][{column}] is {upper} and \
                 [{column}][{row}] is {lower}"
            ),
            Self::NotSemidefinite {
                smallest_eigenvalue,
            } => write!(
                f,
                "a covariance matrix is positive semidefinite (no variance below 0 in any \
                 direction), but this one has the eigenvalue {smallest_eigenvalue:.6e}; check \
                 that every correlation |Cᵢⱼ|/√(CᵢᵢCⱼⱼ) is at most 1 and that they agree with \
                 each other"
            ),
        }
    }
}

/// The lower-triangular factor L of the covariance `c` (rows), n × n with L Lᵀ = c; `Err`
/// when `c` is not n × n, not finite, not symmetric or not positive semidefinite, each to
/// [`RELATIVE_TOLERANCE`] of its largest diagonal entry.
pub fn factor(c: &[Vec<f64>], n: usize) -> Result<Vec<Vec<f64>>, NotCovariance> {
    if c.len() != n {
        return Err(NotCovariance::Shape {
            expected: n,
            row: usize::MAX,
            len: c.len(),
        });
    }
    for (i, row) in c.iter().enumerate() {
        if row.len() != n {
            return Err(NotCovariance::Shape {
                expected: n,
                row: i,
                len: row.len(),
            });
        }
        if let Some(j) = row.iter().position(|x| !x.is_finite()) {
            return Err(NotCovariance::NotFinite { row: i, column: j });
        }
    }
    let scale = (0..n).map(|i| c[i][i].abs()).fold(0.0, f64::max);
    let tol = RELATIVE_TOLERANCE * scale;
    for (i, row) in c.iter().enumerate() {
        for (j, &upper) in row.iter().enumerate().skip(i + 1) {
            let lower = c[j][i];
            if (upper - lower).abs() > tol {
                return Err(NotCovariance::NotSymmetric {
                    row: i,
                    column: j,
                    upper,
                    lower,
                });
            }
        }
    }
    let not_semidefinite = || NotCovariance::NotSemidefinite {
        smallest_eigenvalue: smallest_eigenvalue(c),
    };
    let mut l = vec![vec![0.0; n]; n];
    for j in 0..n {
        let pivot = c[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if pivot < -tol {
            return Err(not_semidefinite());
        }
        if pivot <= tol {
            // No variance left along this component: its column stays zero, and so must
            // what remains of its covariances with the later ones (|cᵢⱼ| ≤ √(cᵢᵢ cⱼⱼ)).
            for i in j + 1..n {
                let rest = c[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
                if rest.abs() > (tol * c[i][i].abs()).sqrt() + tol {
                    return Err(not_semidefinite());
                }
            }
            continue;
        }
        let d = pivot.sqrt();
        l[j][j] = d;
        for i in j + 1..n {
            let rest = c[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = rest / d;
        }
    }
    Ok(l)
}

/// L z for the lower-triangular `l` and the draws `z`.
pub fn correlate(l: &[Vec<f64>], z: &[f64]) -> Vec<f64> {
    l.iter()
        .map(|row| row.iter().zip(z).map(|(a, b)| a * b).sum())
        .collect()
}

/// The smallest eigenvalue of the symmetric part of `c` (for messages).
fn smallest_eigenvalue(c: &[Vec<f64>]) -> f64 {
    let n = c.len();
    let m = DMatrix::from_fn(n, n, |i, j| 0.5 * (c[i][j] + c[j][i]));
    SymmetricEigen::new(m).eigenvalues.min()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn product(l: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let n = l.len();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| (0..n).map(|k| l[i][k] * l[j][k]).sum())
                    .collect()
            })
            .collect()
    }

    #[test]
    fn factor_of_a_definite_matrix_is_its_cholesky_factor() {
        // [[4, 2], [2, 5]] = L Lᵀ with L = [[2, 0], [1, 2]] (by hand).
        let l = factor(&[vec![4.0, 2.0], vec![2.0, 5.0]], 2).unwrap();
        assert_eq!(l, vec![vec![2.0, 0.0], vec![1.0, 2.0]]);
    }

    #[test]
    fn semidefinite_matrices_factor_with_zero_columns() {
        // Two components that move together (correlation 1), and a third independent one.
        let c = vec![
            vec![4.0, 6.0, 0.0],
            vec![6.0, 9.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ];
        let l = factor(&c, 3).unwrap();
        assert_eq!(l[1][1], 0.0);
        for (a, b) in product(&l).iter().flatten().zip(c.iter().flatten()) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // The zero matrix: no variance at all.
        assert_eq!(factor(&[vec![0.0]], 1).unwrap(), vec![vec![0.0]]);
    }

    #[test]
    fn matrices_that_are_not_covariances_are_refused() {
        assert!(matches!(
            factor(&[vec![1.0, 0.5], vec![0.4, 1.0]], 2),
            Err(NotCovariance::NotSymmetric {
                row: 0,
                column: 1,
                ..
            })
        ));
        // Correlation 2: eigenvalues 1 ± 2, the smallest −1.
        match factor(&[vec![1.0, 2.0], vec![2.0, 1.0]], 2) {
            Err(NotCovariance::NotSemidefinite {
                smallest_eigenvalue,
            }) => assert!((smallest_eigenvalue + 1.0).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        // Pairwise correlations of 1, 1 and 0 cannot hold together (determinant −1).
        let c = vec![
            vec![1.0, 1.0, 0.0],
            vec![1.0, 1.0, 1.0],
            vec![0.0, 1.0, 1.0],
        ];
        assert!(matches!(
            factor(&c, 3),
            Err(NotCovariance::NotSemidefinite { .. })
        ));
        assert!(matches!(
            factor(&[vec![-1.0]], 1),
            Err(NotCovariance::NotSemidefinite { .. })
        ));
        assert!(matches!(
            factor(&[vec![1.0, 0.0]], 2),
            Err(NotCovariance::Shape { .. })
        ));
        assert!(matches!(
            factor(&[vec![1.0, 0.0], vec![0.0]], 2),
            Err(NotCovariance::Shape { row: 1, .. })
        ));
    }
}
