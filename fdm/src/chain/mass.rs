//! The chain's mass matrix: the lumped diagonal plus four full columns (θ, β and the clamp
//! ghosts x₁, x₂), solved by a 4×4 Schur complement — O(n) per force evaluation, no
//! allocation.

// Index loops over the columns of M read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::TwoLinkChain;
use super::kinetic::{BE, TH};
use crate::system::System;

impl TwoLinkChain {
    /// The state-dependent full columns of M (θ and β) at the chord-frame `qk`; the ghost
    /// columns are constant (built in `from_scene`).
    pub(super) fn build_columns(&mut self) {
        let n = self.dofs();
        let full = [TH, BE];
        for (c, &idx) in full.iter().enumerate() {
            self.cols[c].iter_mut().for_each(|x| *x = 0.0);
            self.unit[idx] = 1.0;
            self.inertia
                .momenta(&self.qk, &self.zeros, &self.unit, &mut self.p);
            self.unit[idx] = 0.0;
            for i in 0..n {
                self.cols[c][i] = self.p[i].re;
            }
            for s in self.slots {
                self.cols[c][s] = 0.0;
            }
            // J_c e eᵀ: column of the frame angle gets J_c e (the ghost's −J_c e/(2h) is fixed)
            let mut col = std::mem::take(&mut self.cols[c]);
            self.add_clamp(c, self.jc[c], &mut col);
            self.cols[c] = col;
        }
    }

    /// The indices of the four full columns of M: θ, β and the ghosts x₁, x₂.
    pub(super) fn full(&self) -> [usize; 4] {
        [TH, BE, self.slots[0], self.slots[1]]
    }

    /// out = M⁻¹ rhs with the columns of the last [`Self::build_columns`]: Schur complement
    /// on {θ, β, x₁, x₂}; the rest of M is diagonal. O(n), no allocation.
    pub(super) fn solve_mass(&self, rhs: &[f64], out: &mut [f64]) {
        let n = self.dofs();
        let full = self.full();
        let mut s = [[0.0; 4]; 4];
        let mut b = [0.0; 4];
        for r in 0..4 {
            b[r] = rhs[full[r]];
            for c in 0..4 {
                s[r][c] = self.cols[c][full[r]];
            }
        }
        for i in 0..n {
            if full.contains(&i) {
                continue;
            }
            let d = self.diag_mass(i);
            for r in 0..4 {
                let mri = self.cols[r][i];
                b[r] -= mri * rhs[i] / d;
                for c in 0..4 {
                    s[r][c] -= mri * self.cols[c][i] / d;
                }
            }
        }
        let x = solve4(s, b);
        for i in 0..n {
            if let Some(k) = full.iter().position(|&f| f == i) {
                out[i] = x[k];
            } else {
                let coupled: f64 = (0..4).map(|c| self.cols[c][i] * x[c]).sum();
                out[i] = (rhs[i] - coupled) / self.diag_mass(i);
            }
        }
    }

    /// out = M x with the columns of the last [`Self::build_columns`] (M symmetric: full
    /// column c also gives row c).
    pub(super) fn mass_mul(&self, x: &[f64], out: &mut [f64]) {
        let n = self.dofs();
        let full = self.full();
        for i in 0..n {
            if let Some(r) = full.iter().position(|&f| f == i) {
                let mut acc = 0.0;
                for j in 0..n {
                    if let Some(c) = full.iter().position(|&f| f == j) {
                        acc += self.cols[c][i] * x[j];
                    } else {
                        acc += self.cols[r][j] * x[j];
                    }
                }
                out[i] = acc;
            } else {
                out[i] = self.diag_mass(i) * x[i]
                    + (0..4).map(|c| self.cols[c][i] * x[full[c]]).sum::<f64>();
            }
        }
    }
}

/// Gaussian elimination with partial pivoting on a 4×4 system.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for col in 0..4 {
        let piv = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..4 {
            let f = a[row][col] / a[col][col];
            for k in col..4 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 4];
    for row in (0..4).rev() {
        let s: f64 = (row + 1..4).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}
