//! The dense block of the chain's mass solves: the full columns of M (θ, β, the clamp ghost
//! slots — ψ₁, ψ₂ in the solve's coordinates — and, with Euler links, link 1's tip ghost y)
//! couple every coordinate, so the solves eliminate the lumped diagonal and are left with a
//! small Schur complement on those columns and on the two columns of the links'
//! foreshortening-rate coupling, at most 7 × 7 ([`super::mass`], [`super::implicit`]).

// Index loops over the rows and columns of the block read like the formulas.
#![allow(clippy::needless_range_loop)]

/// Largest number of full columns (θ, β, the two ghost slots, y).
pub const MAX_FULL: usize = 5;
/// Largest small system of the mass solve: the full columns and the two columns of the
/// links' foreshortening-rate coupling (U of [`super::mass`]).
pub const MAX_SMALL: usize = MAX_FULL + 2;

/// The LU factors (partial pivoting) of the leading `n`×`n` block of a small system, kept so
/// that every right-hand side at one state reuses them.
#[derive(Debug, Clone, Copy, Default)]
pub struct SmallLu {
    /// U on and above the diagonal; below it, the multiplier of each row at the step that
    /// eliminated it (later row swaps leave it in place, so a solve repeats the elimination)
    lu: [[f64; MAX_SMALL]; MAX_SMALL],
    /// the row swapped with row k at step k
    swap: [usize; MAX_SMALL],
    n: usize,
}

impl SmallLu {
    /// Gaussian elimination with partial pivoting of the leading `n`×`n` block of `a`.
    pub fn factor(mut a: [[f64; MAX_SMALL]; MAX_SMALL], n: usize) -> Self {
        let mut swap = [0; MAX_SMALL];
        for col in 0..n {
            let piv = (col..n)
                .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
                .unwrap_or(col);
            // the multipliers left of the column stay with the step that formed them
            for k in col..n {
                let t = a[col][k];
                a[col][k] = a[piv][k];
                a[piv][k] = t;
            }
            swap[col] = piv;
            for row in col + 1..n {
                let f = a[row][col] / a[col][col];
                for k in col + 1..n {
                    a[row][k] -= f * a[col][k];
                }
                a[row][col] = f;
            }
        }
        SmallLu { lu: a, swap, n }
    }

    /// x with A x = b.
    pub fn solve(&self, mut b: [f64; MAX_SMALL]) -> [f64; MAX_SMALL] {
        let (a, n) = (&self.lu, self.n);
        for col in 0..n {
            b.swap(col, self.swap[col]);
            for row in col + 1..n {
                b[row] -= a[row][col] * b[col];
            }
        }
        let mut x = [0.0; MAX_SMALL];
        for row in (0..n).rev() {
            let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
            x[row] = (b[row] - s) / a[row][row];
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_small_lu_solves_with_row_swaps_at_every_step() {
        // a 6 × 6 system whose partial pivoting swaps rows at several steps (the largest entry
        // of each column sits low), checked by its residual for two right-hand sides
        let n = 6;
        let mut a = [[0.0; MAX_SMALL]; MAX_SMALL];
        for (i, row) in a.iter_mut().enumerate().take(n) {
            for (k, v) in row.iter_mut().enumerate().take(n) {
                *v = ((i * 7 + k * 3) as f64 * 0.37).sin() + if i == n - 1 - k { 4.0 } else { 0.0 };
            }
        }
        let lu = SmallLu::factor(a, n);
        assert!(
            (0..n).filter(|&k| lu.swap[k] != k).count() >= 2,
            "{:?}",
            lu.swap
        );
        for b in [
            std::array::from_fn(|i| if i < n { 1.0 + i as f64 } else { 0.0 }),
            std::array::from_fn(|i| if i < n { (i as f64).cos() } else { 0.0 }),
        ] {
            let x = lu.solve(b);
            for i in 0..n {
                let res: f64 = (0..n).map(|k| a[i][k] * x[k]).sum::<f64>() - b[i];
                assert!(res.abs() < 1e-13, "row {i}: residual {res:e}");
            }
        }
    }
}
