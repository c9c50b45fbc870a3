//! Tests of symmetric 3×3 matrices (inertia tensors) by Sylvester's criteria: leading minors
//! for definiteness, all principal minors for semi-definiteness.

/// Exactly symmetric (the entries as written in the scene file).
pub(super) fn is_symmetric(m: &[[f64; 3]; 3]) -> bool {
    m[0][1] == m[1][0] && m[0][2] == m[2][0] && m[1][2] == m[2][1]
}

/// The principal minor of rows and columns `a`, `b`.
fn det2(m: &[[f64; 3]; 3], a: usize, b: usize) -> f64 {
    m[a][a] * m[b][b] - m[a][b] * m[b][a]
}

/// The determinant (cofactor expansion along the first row).
fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Sylvester's criterion: positive definite when every leading minor is positive.
pub(super) fn leading_minors_positive(m: &[[f64; 3]; 3]) -> bool {
    m[0][0] > 0.0 && det2(m, 0, 1) > 0.0 && det3(m) > 0.0
}

/// All principal minors non-negative up to round-off relative to `scale` (an entry's size):
/// positive semidefinite.
pub(super) fn principal_minors_nonnegative(m: &[[f64; 3]; 3], scale: f64) -> bool {
    let eps = 1e-12;
    (0..3).all(|k| m[k][k] >= -eps * scale)
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| det2(m, a, b) >= -eps * scale * scale)
        && det3(m) >= -eps * scale.powi(3)
}

/// All principal minors of the symmetric 3×3 matrix ≥ −1e-12 · scale^k, scale its largest
/// entry: the round-off of a matrix formed by a subtraction (the flexible link's residual
/// inertia).
pub(super) fn positive_semidefinite(j: &[[f64; 3]; 3]) -> bool {
    let s = j
        .iter()
        .flatten()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(1e-300);
    let tol = 1e-12;
    (0..3).all(|k| j[k][k] >= -tol * s)
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| det2(j, a, b) >= -tol * s * s)
        && det3(j) >= -tol * s * s * s
}
