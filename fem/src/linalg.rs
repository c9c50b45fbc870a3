//! Small vector kernels shared by the crate's methods and events (one copy each), and the
//! dense Cholesky factorization (through faer) of small SPD systems.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::{MatMut, MatRef, Par};

/// Euclidean inner product aᵀb over the shorter of the two, summed in index order.
#[inline]
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

/// L Lᵀ factorization of a dense SPD matrix through faer, with its scratch allocated once, so
/// refactoring and solving in the step loop allocate nothing.
pub struct DenseLlt {
    n: usize,
    factor: Vec<f64>,
    scratch: StackReq,
    mem: MemBuffer,
}

impl Clone for DenseLlt {
    fn clone(&self) -> Self {
        DenseLlt {
            n: self.n,
            factor: self.factor.clone(),
            scratch: self.scratch,
            mem: MemBuffer::new(self.scratch),
        }
    }
}

impl std::fmt::Debug for DenseLlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLlt").field("n", &self.n).finish()
    }
}

impl DenseLlt {
    pub fn new(n: usize) -> Self {
        let scratch =
            llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default())
                .or(llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq));
        DenseLlt {
            n,
            factor: vec![0.0; n * n],
            scratch,
            mem: MemBuffer::new(scratch),
        }
    }

    /// Factors the row-major matrix `a` (its lower triangle is read); Err(pivot) at the first
    /// pivot that is not positive.
    pub fn factor(&mut self, a: &[f64]) -> Result<(), usize> {
        let n = self.n;
        self.factor.copy_from_slice(&a[..n * n]);
        llt::factor::cholesky_in_place(
            MatMut::from_row_major_slice_mut(&mut self.factor, n, n),
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .map(|_| ())
        .map_err(|e| match e {
            llt::factor::LltError::NonPositivePivot { index } => index,
        })
    }

    /// Solves L Lᵀ x = b in place with the last factor.
    pub fn solve(&mut self, b: &mut [f64]) {
        let n = self.n;
        llt::solve::solve_in_place(
            MatRef::from_row_major_slice(&self.factor, n, n),
            MatMut::from_column_major_slice_mut(&mut b[..n], n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}
