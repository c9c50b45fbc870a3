//! Gauss–Legendre quadrature: nodes as the roots of P_n by Newton's method from Tricomi's
//! initial guesses, weights 2 / ((1 − z²) P_n′(z)²). Exact for polynomials of degree 2n − 1.

use std::f64::consts::PI;

/// Nodes and weights of the n-point rule on \[−1, 1\].
pub fn gauss_legendre_nodes(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|i| {
            let mut z = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, z);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                let dz = p1 / dp;
                z -= dz;
                if dz.abs() < 1e-16 {
                    break;
                }
            }
            (z, 2.0 / ((1.0 - z * z) * dp * dp))
        })
        .collect()
}

/// ∫ₐᵇ g by the n-point rule.
pub fn gauss_legendre(a: f64, b: f64, n: usize, g: &dyn Fn(f64) -> f64) -> f64 {
    let sum: f64 = gauss_legendre_nodes(n)
        .into_iter()
        .map(|(z, w)| w * g(0.5 * (b - a) * z + 0.5 * (a + b)))
        .sum();
    0.5 * (b - a) * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in 1..8 {
            for d in 0..2 * n {
                let exact =
                    (2.0f64.powi(d as i32 + 1) - 0.5f64.powi(d as i32 + 1)) / (d + 1) as f64;
                let got = gauss_legendre(0.5, 2.0, n, &|x| x.powi(d as i32));
                assert!(
                    (got - exact).abs() < 1e-13 * exact,
                    "n {n} degree {d}: {got} vs {exact}"
                );
            }
        }
    }
}
