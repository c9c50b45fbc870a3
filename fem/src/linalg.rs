//! Small vector kernels shared by the crate's methods and events (one copy each).

/// Euclidean inner product aᵀb, summed in index order.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The solution x of the 2 × 2 system A x = r by Cramer's rule (the Schur complement of a
/// constraint pair; not finite where A is singular, which stops the caller's iteration).
pub fn solve2(a: [[f64; 2]; 2], r: [f64; 2]) -> [f64; 2] {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    [
        (a[1][1] * r[0] - a[0][1] * r[1]) / det,
        (a[0][0] * r[1] - a[1][0] * r[0]) / det,
    ]
}

/// Largest magnitude ‖a‖∞ (0 for an empty slice).
pub fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}
