//! The dense block of the chain's mass solves: the full columns of M (θ, β, the clamp ghost
//! slots — ψ₁, ψ₂ in the solve's coordinates — and, with Euler links, link 1's tip ghost y) couple every coordinate, so the solves
//! eliminate the lumped diagonal and are left with an at most 5×5 Schur complement on those
//! columns ([`super::mass`], [`super::implicit`]).

// Index loops over the rows and columns of the block read like the formulas.
#![allow(clippy::needless_range_loop)]

/// Largest number of full columns (θ, β, the two ghost slots, y).
pub(super) const MAX_FULL: usize = 5;
/// Largest small system of the mass solve: the full columns and the two columns of the
/// links' foreshortening-rate coupling ([`super::rates`]).
pub(super) const MAX_SMALL: usize = MAX_FULL + 2;

/// Gaussian elimination with partial pivoting on the leading `n`×`n` block.
pub(super) fn solve_small<const M: usize>(
    mut a: [[f64; M]; M],
    mut b: [f64; M],
    n: usize,
) -> [f64; M] {
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..n {
            let f = a[row][col] / a[col][col];
            for k in col..n {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; M];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}
