//! The symmetric-definite pencil K x = λ M x by Cholesky reduction, in a workspace allocated
//! once: M = L Lᵀ, C = L⁻¹ K L⁻ᵀ (symmetrized), C = U Λ Uᵀ, X = L⁻ᵀ U. Eigenvalues
//! ascending, eigenvectors M-orthonormal (Xᵀ M X = I) in the columns of X.
//!
//! Used for the natural frequencies of a reduced model ([`crate::modes::generalized_eigen`],
//! once per model) and by the exponential integrator at every linearization
//! ([`crate::integrate::Exponential`]), where it must not allocate.

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::evd::{ComputeEigenvectors, self_adjoint_evd, self_adjoint_evd_scratch};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, MatRef, get_global_parallelism};

/// Why a pencil could not be reduced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PencilError {
    #[error("mass matrix is not positive definite")]
    MassNotPositiveDefinite,
    #[error("eigen-decomposition did not converge")]
    NoConvergence,
}

/// Workspace of the reduction for pencils of order n.
pub struct Pencil {
    l: Mat<f64>,
    c: Mat<f64>,
    t: Mat<f64>,
    x: Mat<f64>,
    s: Diag<f64>,
    lambda: Vec<f64>,
    mem: MemBuffer,
}

impl Pencil {
    pub fn new(n: usize) -> Self {
        let par = get_global_parallelism();
        let scratch = StackReq::any_of(&[
            cholesky_in_place_scratch::<f64>(n, par, Default::default()),
            self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, par, Default::default()),
        ]);
        Pencil {
            l: Mat::zeros(n, n),
            c: Mat::zeros(n, n),
            t: Mat::zeros(n, n),
            x: Mat::zeros(n, n),
            s: Diag::zeros(n),
            lambda: vec![0.0; n],
            mem: MemBuffer::new(scratch),
        }
    }

    pub fn order(&self) -> usize {
        self.lambda.len()
    }

    /// Reduces K x = λ M x (both read from their lower triangles; order [`Self::order`]).
    pub fn solve(&mut self, k: MatRef<'_, f64>, m: MatRef<'_, f64>) -> Result<(), PencilError> {
        let par = get_global_parallelism();
        let n = self.order();
        self.l.copy_from_triangular_lower(m);
        cholesky_in_place(
            self.l.as_mut(),
            Default::default(),
            par,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .map_err(|_| PencilError::MassNotPositiveDefinite)?;
        for j in 1..n {
            for i in 0..j {
                self.l[(i, j)] = 0.0;
            }
        }
        // T = L⁻¹K, then C = L⁻¹Tᵀ = L⁻¹ K L⁻ᵀ.
        self.t.copy_from(k);
        solve_lower_triangular_in_place(self.l.as_ref(), self.t.as_mut(), par);
        self.c.copy_from(self.t.transpose());
        solve_lower_triangular_in_place(self.l.as_ref(), self.c.as_mut(), par);
        for j in 0..n {
            for i in 0..n {
                self.t[(i, j)] = 0.5 * (self.c[(i, j)] + self.c[(j, i)]);
            }
        }
        self_adjoint_evd(
            self.t.as_ref(),
            self.s.as_mut(),
            Some(self.x.as_mut()),
            par,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .map_err(|_| PencilError::NoConvergence)?;
        let s = self.s.column_vector();
        for (i, l) in self.lambda.iter_mut().enumerate() {
            *l = s[i];
        }
        solve_upper_triangular_in_place(self.l.transpose(), self.x.as_mut(), par);
        Ok(())
    }

    /// Eigenvalues of the last [`Self::solve`], ascending.
    pub fn eigenvalues(&self) -> &[f64] {
        &self.lambda
    }

    /// M-orthonormal eigenvectors of the last [`Self::solve`] (column j: eigenvalue j).
    pub fn vectors(&self) -> MatRef<'_, f64> {
        self.x.as_ref()
    }
}
