//! Symmetric positive definite sparse matrices of the 3-D link: assembly from triplets and a
//! Cholesky factorization through faer's sparse LLᵀ ([`SpdFactor`]; no allocation in
//! `solve_in_place`), the faster of the two measured against a banded Cholesky
//! (`cargo bench -p fdm --bench payload_link -- --quick payload-link-step-matrix`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Par, Side};

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

/// Cholesky factor of a sparse symmetric positive definite matrix, through faer's sparse LLᵀ
/// (AMD ordering; simplicial or supernodal as faer chooses). The factorization runs once per
/// matrix; a solve reuses the factor and a workspace allocated with it, so it allocates nothing.
pub struct SpdFactor {
    n: usize,
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    mem: MemBuffer,
}

impl std::fmt::Debug for SpdFactor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpdFactor")
            .field("n", &self.n)
            .field("factor_entries", &self.values.len())
            .finish()
    }
}

impl SpdFactor {
    /// Factors Σ scale_k A_k (the sum of symmetric triplet matrices, each scaled; both
    /// triangles stored, the lower one read). `what` names the matrix in the error.
    pub fn factor(n: usize, parts: &[(&Triplets, f64)], what: &str) -> Result<Self, FdmError> {
        let triplets: Vec<Triplet<usize, usize, f64>> = parts
            .iter()
            .flat_map(|(t, s)| {
                t.entries
                    .iter()
                    .map(move |&(i, j, v)| Triplet::new(i, j, s * v))
            })
            .collect();
        let generic = |e: &dyn std::fmt::Display| FdmError::Numerical {
            t: 0.0,
            message: format!("{what}: {e}"),
        };
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| generic(&format!("{e:?}")))?;
        let symbolic = factorize_symbolic_cholesky(
            matrix.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| generic(&format!("{e:?}")))?;
        let mut values = vec![0.0; symbolic.len_val()];
        let mut mem = MemBuffer::new(
            symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
        );
        symbolic
            .factorize_numeric_llt::<f64>(
                &mut values,
                matrix.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| FdmError::Numerical {
                t: 0.0,
                message: format!("{what} is not positive definite ({e:?})"),
            })?;
        Ok(SpdFactor {
            n,
            symbolic,
            values,
            mem,
        })
    }

    /// x ← A⁻¹ x.
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        let llt = LltRef::<usize, f64>::new(&self.symbolic, &self.values);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, self.n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_spd_factor_solves_against_the_product() {
        let n = 9;
        let mut t = Triplets::default();
        for i in 0..n {
            t.entries.push((i, i, 4.0 + i as f64));
            if i + 2 < n {
                t.entries.push((i, i + 2, -1.0));
                t.entries.push((i + 2, i, -1.0));
            }
        }
        let mut f = SpdFactor::factor(n, &[(&t, 1.0)], "test").unwrap();
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut y = vec![0.0; n];
        t.mul_add(&x, &mut y);
        f.solve_in_place(&mut y);
        for (i, (y, x)) in y.iter().zip(&x).enumerate() {
            assert!((y - x).abs() < 1e-14, "{i}");
        }
    }
}
