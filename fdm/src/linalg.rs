//! Vector kernels shared across the crate (one copy each).

/// Euclidean inner product aᵀb over the shorter of the two, summed in index order.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
