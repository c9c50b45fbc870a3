//! LDLᵀ of a symmetric positive definite tridiagonal matrix: O(n) factorization and solve
//! without pivoting (the pivots of an SPD matrix stay positive) and without allocation after
//! construction. Used by the foreshortening constraint's axial-force system
//! ([`crate::foreshortening`]) and the condensed Timoshenko rotations ([`crate::chain::timoshenko`]).

/// A = L D Lᵀ with L unit lower bidiagonal: the pivots D and the multipliers L_{i+1,i}.
#[derive(Debug, Clone, Default)]
pub struct TridiagonalLdl {
    piv: Vec<f64>,
    mult: Vec<f64>,
}

impl TridiagonalLdl {
    /// Storage for an n × n matrix.
    pub fn new(n: usize) -> Self {
        TridiagonalLdl {
            piv: vec![0.0; n],
            mult: vec![0.0; n.saturating_sub(1)],
        }
    }

    /// Factors the matrix with diagonal `diag(i)` and off-diagonal `off(i)` = A_{i,i+1}.
    /// Err(i): pivot i is not positive (or not a number), so A is not positive definite.
    pub fn factor(
        &mut self,
        diag: impl Fn(usize) -> f64,
        off: impl Fn(usize) -> f64,
    ) -> Result<(), usize> {
        let n = self.piv.len();
        if n == 0 {
            return Ok(());
        }
        self.piv[0] = diag(0);
        for i in 0..n - 1 {
            if self.piv[i].is_nan() || self.piv[i] <= 0.0 {
                return Err(i);
            }
            let a_off = off(i);
            self.mult[i] = a_off / self.piv[i];
            self.piv[i + 1] = diag(i + 1) - self.mult[i] * a_off;
        }
        if self.piv[n - 1].is_nan() || self.piv[n - 1] <= 0.0 {
            return Err(n - 1);
        }
        Ok(())
    }

    /// x ← A⁻¹ x with the factor of the last [`Self::factor`].
    pub fn solve_in_place(&self, x: &mut [f64]) {
        self.solve_rows_in_place(x, 1);
    }

    /// X ← A⁻¹X for `m` right-hand sides stored by rows (X[i·m + c]): one sweep for all.
    pub fn solve_rows_in_place(&self, x: &mut [f64], m: usize) {
        let n = self.piv.len();
        for i in 0..n.saturating_sub(1) {
            let (head, tail) = x.split_at_mut((i + 1) * m);
            let l = self.mult[i];
            for (v, u) in tail[..m].iter_mut().zip(&head[i * m..]) {
                *v -= l * u;
            }
        }
        for (i, d) in self.piv.iter().enumerate() {
            x[i * m..i * m + m].iter_mut().for_each(|v| *v /= d);
        }
        for i in (0..n.saturating_sub(1)).rev() {
            let (head, tail) = x.split_at_mut((i + 1) * m);
            let l = self.mult[i];
            for (v, u) in head[i * m..].iter_mut().zip(&tail[..m]) {
                *v -= l * u;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_tridiagonal_ldl_solves_against_the_product_and_refuses_an_indefinite_matrix() {
        let n = 7;
        let diag = |i: usize| 4.0 + 0.5 * i as f64;
        let off = |i: usize| -1.0 - 0.1 * i as f64;
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 + 1.0).sin()).collect();
        // b = A x
        let mut b: Vec<f64> = (0..n).map(|i| diag(i) * x_true[i]).collect();
        for i in 0..n - 1 {
            b[i] += off(i) * x_true[i + 1];
            b[i + 1] += off(i) * x_true[i];
        }
        let mut ldl = TridiagonalLdl::new(n);
        ldl.factor(diag, off).unwrap();
        ldl.solve_in_place(&mut b);
        for i in 0..n {
            assert!(
                (b[i] - x_true[i]).abs() < 1e-14,
                "{i}: {} vs {}",
                b[i],
                x_true[i]
            );
        }
        // [[1, 2], [2, 1]] is indefinite: the second pivot is 1 − 4 < 0.
        let mut two = TridiagonalLdl::new(2);
        assert_eq!(two.factor(|_| 1.0, |_| 2.0), Err(1));
    }
}
