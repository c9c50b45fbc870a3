//! Hermite-cubic interpolation on an element of length h, local coordinate ξ = (x − x_a)/h ∈ [0, 1].
//!
//! Element DOFs (v₁, v₁′, v₂, v₂′): v(ξ) = Σ Nₖ(ξ) dₖ reproduces every cubic exactly, which is why
//! a cantilever under a tip load is nodally exact (PL³/3EI to round-off).

/// Shape functions and their first and second x-derivatives at ξ.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HermiteAt {
    pub n: [f64; 4],
    pub dn: [f64; 4],
    pub ddn: [f64; 4],
}

/// Evaluates the Hermite cubics on an element of length `h` at local coordinate `xi`.
pub fn hermite(xi: f64, h: f64) -> HermiteAt {
    let (x2, x3) = (xi * xi, xi * xi * xi);
    let n = [
        1.0 - 3.0 * x2 + 2.0 * x3,
        h * (xi - 2.0 * x2 + x3),
        3.0 * x2 - 2.0 * x3,
        h * (-x2 + x3),
    ];
    let dn = [
        (-6.0 * xi + 6.0 * x2) / h,
        1.0 - 4.0 * xi + 3.0 * x2,
        (6.0 * xi - 6.0 * x2) / h,
        -2.0 * xi + 3.0 * x2,
    ];
    let ddn = [
        (-6.0 + 12.0 * xi) / (h * h),
        (-4.0 + 6.0 * xi) / h,
        (6.0 - 12.0 * xi) / (h * h),
        (-2.0 + 6.0 * xi) / h,
    ];
    HermiteAt { n, dn, ddn }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::dot;

    #[test]
    fn elem_hermite_reproduces_cubics_and_derivatives() {
        let (xa, h) = (0.3, 0.7);
        let f = |x: f64| 1.0 - 2.0 * x + 0.5 * x * x + 1.5 * x * x * x;
        let df = |x: f64| -2.0 + x + 4.5 * x * x;
        let ddf = |x: f64| 1.0 + 9.0 * x;
        let d = [f(xa), df(xa), f(xa + h), df(xa + h)];
        for k in 0..=10 {
            let xi = k as f64 / 10.0;
            let x = xa + xi * h;
            let s = hermite(xi, h);
            // Exact interpolation of a cubic: only round-off remains.
            assert!((dot(&s.n, &d) - f(x)).abs() < 1e-14);
            assert!((dot(&s.dn, &d) - df(x)).abs() < 1e-13);
            assert!((dot(&s.ddn, &d) - ddf(x)).abs() < 1e-12);
        }
    }
}
