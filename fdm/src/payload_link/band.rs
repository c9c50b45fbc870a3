//! Symmetric positive definite banded matrices: assembly from triplets and a banded Cholesky
//! factorization (O(n b²) once, O(n b) per solve, no allocation in `solve_in_place`).

// Band loops index the factor and the right-hand side together.
#![allow(clippy::needless_range_loop)]

use crate::error::FdmError;

/// Symmetric matrix entries as triplets (both triangles stored), with products.
#[derive(Debug, Clone, Default)]
pub struct Triplets {
    pub entries: Vec<(usize, usize, f64)>,
}

impl Triplets {
    /// Adds coef · a bᵀ (a, b: linear functionals as (index, coefficient) lists).
    pub fn outer(&mut self, coef: f64, a: &[(usize, f64)], b: &[(usize, f64)]) {
        for &(i, ai) in a {
            for &(j, bj) in b {
                self.entries.push((i, j, coef * ai * bj));
            }
        }
    }
    /// Adds coef · (a bᵀ + b aᵀ).
    pub fn sym_outer(&mut self, coef: f64, a: &[(usize, f64)], b: &[(usize, f64)]) {
        self.outer(coef, a, b);
        self.outer(coef, b, a);
    }
    /// out += A x.
    pub fn mul_add(&self, x: &[f64], out: &mut [f64]) {
        for &(i, j, c) in &self.entries {
            out[i] += c * x[j];
        }
    }
    /// out += Aᵀ x.
    pub fn mul_t_add(&self, x: &[f64], out: &mut [f64]) {
        for &(i, j, c) in &self.entries {
            out[j] += c * x[i];
        }
    }
    /// xᵀ A y.
    pub fn form(&self, x: &[f64], y: &[f64]) -> f64 {
        self.entries.iter().map(|&(i, j, c)| x[i] * c * y[j]).sum()
    }
    /// Largest |i − j| of the stored entries.
    pub fn bandwidth(&self) -> usize {
        self.entries
            .iter()
            .map(|&(i, j, _)| i.abs_diff(j))
            .max()
            .unwrap_or(0)
    }
    /// Dense copy (n × n, row-major) for one-off analyses (modes, statics).
    pub fn dense(&self, n: usize) -> Vec<f64> {
        let mut d = vec![0.0; n * n];
        for &(i, j, c) in &self.entries {
            d[i * n + j] += c;
        }
        d
    }
}

/// Banded Cholesky factor L (A = L Lᵀ), lower band of half-width `b`.
#[derive(Debug, Clone)]
pub struct BandCholesky {
    n: usize,
    b: usize,
    /// l[i (b + 1) + (i − j)] = L_ij for i − b ≤ j ≤ i
    l: Vec<f64>,
}

impl BandCholesky {
    /// Factors Σ scale_k A_k (the sum of symmetric triplet matrices, each scaled).
    pub fn factor(n: usize, parts: &[(&Triplets, f64)], what: &str) -> Result<Self, FdmError> {
        let b = parts.iter().map(|(t, _)| t.bandwidth()).max().unwrap_or(0);
        let w = b + 1;
        let mut l = vec![0.0; n * w];
        for (t, s) in parts {
            for &(i, j, c) in &t.entries {
                if j <= i {
                    l[i * w + (i - j)] += s * c;
                }
            }
        }
        for j in 0..n {
            let k0 = j.saturating_sub(b);
            let mut d = l[j * w];
            for k in k0..j {
                let ljk = l[j * w + (j - k)];
                d -= ljk * ljk;
            }
            if !(d > 0.0 && d.is_finite()) {
                return Err(FdmError::Numerical {
                    t: 0.0,
                    message: format!("{what} is not positive definite (pivot {j}: {d:e})"),
                });
            }
            let djj = d.sqrt();
            l[j * w] = djj;
            for i in j + 1..(j + b + 1).min(n) {
                let mut s = l[i * w + (i - j)];
                for k in i.saturating_sub(b)..j {
                    s -= l[i * w + (i - k)] * l[j * w + (j - k)];
                }
                l[i * w + (i - j)] = s / djj;
            }
        }
        Ok(BandCholesky { n, b, l })
    }

    /// x ← A⁻¹ x.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let (n, b, w) = (self.n, self.b, self.b + 1);
        for i in 0..n {
            let mut s = x[i];
            for k in i.saturating_sub(b)..i {
                s -= self.l[i * w + (i - k)] * x[k];
            }
            x[i] = s / self.l[i * w];
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..(i + b + 1).min(n) {
                s -= self.l[k * w + (k - i)] * x[k];
            }
            x[i] = s / self.l[i * w];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_band_cholesky_solves_against_dense_product() {
        let n = 9;
        let mut t = Triplets::default();
        for i in 0..n {
            t.entries.push((i, i, 4.0 + i as f64));
            if i + 2 < n {
                t.entries.push((i, i + 2, -1.0));
                t.entries.push((i + 2, i, -1.0));
            }
        }
        let f = BandCholesky::factor(n, &[(&t, 1.0)], "test").unwrap();
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut y = vec![0.0; n];
        t.mul_add(&x, &mut y);
        f.solve_in_place(&mut y);
        for i in 0..n {
            assert!((y[i] - x[i]).abs() < 1e-14, "{i}");
        }
    }
}
