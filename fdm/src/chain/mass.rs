//! The chain's mass matrix: the lumped diagonal plus the full columns θ, β, the clamp ghosts
//! x₁, x₂ and (Euler links) link 1's tip ghost y, solved by a Schur complement on those
//! (at most 5×5) — O(n) per force evaluation, no allocation.

// Index loops over the columns of M read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::kinetic::{BE, TH};
use super::model::TwoLinkChain;
use super::schur::{MAX_FULL, solve_small};
use crate::system::System;

impl TwoLinkChain {
    /// The state-dependent full columns of M (θ and β) at the chord-frame `qk`; the ghost
    /// columns are constant (built in `from_planar_chain`).
    pub(super) fn build_columns(&mut self) {
        let n = self.dofs();
        let full = [TH, BE];
        for (c, &idx) in full.iter().enumerate() {
            self.cols[c][self.inertia.dofs()..n]
                .iter_mut()
                .for_each(|x| *x = 0.0);
            self.unit[idx] = 1.0;
            self.inertia
                .momenta_values(&self.qk, &self.unit, &mut self.cols[c]);
            self.unit[idx] = 0.0;
            for s in self.ghosts() {
                self.cols[c][s] = 0.0;
            }
            // J_c e eᵀ: column of the frame angle gets J_c e (the ghost's −J_c e/(2h) is fixed);
            // θ's column also gets J_t e of link 1's tip section (y's column is fixed)
            let mut col = std::mem::take(&mut self.cols[c]);
            self.add_clamp(c, self.jc[c], &mut col);
            if idx == TH {
                self.add_tip(self.jt, &mut col);
            }
            self.cols[c] = col;
        }
    }

    /// The number of full columns of M: 5 with link 1's tip ghost, else 4.
    pub(super) fn nfull(&self) -> usize {
        4 + usize::from(self.tip_ghost.is_some())
    }

    /// The indices of the full columns of M: θ, β, the ghosts x₁, x₂ and (Euler) y; unused
    /// entries are `usize::MAX`.
    pub(super) fn full(&self) -> [usize; MAX_FULL] {
        [
            TH,
            BE,
            self.slots[0],
            self.slots[1],
            self.tip_ghost.unwrap_or(usize::MAX),
        ]
    }

    /// out = M⁻¹ rhs with the columns of the last [`Self::build_columns`]: Schur complement
    /// on the full columns; the rest of M is diagonal. O(n), no allocation.
    pub(super) fn solve_mass(&self, rhs: &[f64], out: &mut [f64]) {
        let n = self.dofs();
        let nf = self.nfull();
        let full = self.full();
        let full = &full[..nf];
        let mut s = [[0.0; MAX_FULL]; MAX_FULL];
        let mut b = [0.0; MAX_FULL];
        for r in 0..nf {
            b[r] = rhs[full[r]];
            for c in 0..nf {
                s[r][c] = self.cols[c][full[r]];
            }
        }
        for i in 0..n {
            if full.contains(&i) {
                continue;
            }
            let d = self.diag_mass(i);
            for r in 0..nf {
                let mri = self.cols[r][i];
                b[r] -= mri * rhs[i] / d;
                for c in 0..nf {
                    s[r][c] -= mri * self.cols[c][i] / d;
                }
            }
        }
        let x = solve_small(s, b, nf);
        for i in 0..n {
            if let Some(k) = full.iter().position(|&f| f == i) {
                out[i] = x[k];
            } else {
                let coupled: f64 = (0..nf).map(|c| self.cols[c][i] * x[c]).sum();
                out[i] = (rhs[i] - coupled) / self.diag_mass(i);
            }
        }
    }

    /// out = M x with the columns of the last [`Self::build_columns`] (M symmetric: full
    /// column c also gives row c).
    pub(super) fn mass_mul(&self, x: &[f64], out: &mut [f64]) {
        let n = self.dofs();
        let nf = self.nfull();
        let full = self.full();
        let full = &full[..nf];
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
                    + (0..nf).map(|c| self.cols[c][i] * x[full[c]]).sum::<f64>();
            }
        }
    }
}
