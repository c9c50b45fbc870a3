//! The chain's mass matrix and its solve. M couples every coordinate through the full columns
//! F = {θ, β, x₁, x₂, y} (the frame angles, the clamp ghosts, link 1's tip ghost); on the
//! remaining deflections R it is
//!
//!   M_RR = A₁ ⊕ A₂ + U C Uᵀ,   U = [f₁ f₂],   C = [[0, 1], [1, 0]],
//!
//! A_ℓ = D_ℓ + G_ℓᵀN_ℓG_ℓ each link's stations with their foreshortening rates
//! (`rates`), f₁ = G₁ᵀ1 link 1's tip rate Ṡ and f₂ = cos φ G₂ᵀμ + sin φ m₂ what link 2's
//! stations move along it (from ½Σm₂|ṙ|² ∋ Ṡ Σm₂(σ̇ cos φ + ẇ sin φ)). With y = Uᵀx_R and
//! Z = A⁻¹[M_RF U], the unknowns (x_F, y) solve a system of at most 7, and
//! x_R = A⁻¹b_R − Z_F x_F − Z_U C y: O(n) per solve, the A factorizations and Z once per state.

// Index loops over the columns of M read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::kinetic::{BE, TH};
use super::model::TwoLinkChain;
use super::rates::LinkRates;
use super::schur::{MAX_FULL, MAX_SMALL, solve_small};
use crate::system::System;

impl TwoLinkChain {
    /// The deflection ranges R of links 1 and 2 (stations with an unknown, the tip left out).
    pub(super) fn deflections(&self, link: usize) -> std::ops::Range<usize> {
        let first = self.first(link);
        first..self.slots[link]
    }

    /// x_R ← A⁻¹x_R on both links' deflections (F entries untouched).
    fn solve_blocks(&mut self, x: &mut [f64]) {
        for link in 0..2 {
            let r = self.deflections(link);
            self.factors.links[link].solve_in_place(&mut x[r]);
        }
    }

    /// The state-dependent full columns of M (θ and β) at the chord-frame `qk`, the ghost
    /// columns (constant, built in `from_planar_chain`), and the factors of the solve.
    pub(super) fn build_columns(&mut self) {
        let n = self.dofs();
        let full = [TH, BE];
        for (c, &idx) in full.iter().enumerate() {
            self.cols[c][self.inertia.dofs()..n]
                .iter_mut()
                .for_each(|x| *x = 0.0);
            self.unit[idx] = 1.0;
            self.inertia
                .momenta_values(&self.qk, &self.unit, &mut self.points, &mut self.cols[c]);
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
        self.factor_blocks();
    }

    /// A_ℓ and U at `qk` (Z follows with the first solve).
    fn factor_blocks(&mut self) {
        self.factors.z_current = false;
        let hs = self.hs;
        for link in 0..2 {
            let r = self.deflections(link);
            let start = r.start;
            let mut rates = std::mem::replace(&mut self.factors.links[link], LinkRates::empty());
            rates.set_state(&self.qk[r], hs[link], |i| self.diag_mass(start + i));
            self.factors.links[link] = rates;
        }
        let ine = &self.inertia;
        self.factors.nu = if ine.fs1 { 2 } else { 0 };
        if ine.fs1 {
            let (r1, r2) = (self.deflections(0), self.deflections(1));
            let g1 = self.factors.links[0].slopes();
            for (k, i) in r1.enumerate() {
                self.factors.u[0][i] = g1[k] - g1[k + 1];
            }
            let g2 = self.factors.links[1].slopes();
            let (sn, c) = (self.qk[BE] - self.qk[TH]).sin_cos();
            for (j, i) in r2.enumerate() {
                let along = if ine.fs2 {
                    ine.mu2[j] * g2[j] - ine.mu2[j + 1] * g2[j + 1]
                } else {
                    0.0
                };
                self.factors.u[1][i] = c * along + sn * ine.m2[j];
            }
        }
    }

    /// Z = A⁻¹[M_RF U] at the state of the last [`Self::build_columns`]: per link, the columns'
    /// deflection entries by rows, one sweep.
    fn solve_columns(&mut self) {
        let ns = self.nfull() + self.factors.nu;
        let nf = self.nfull();
        let mut rows = std::mem::take(&mut self.factors.rows);
        for link in 0..2 {
            let r = self.deflections(link);
            let len = r.len();
            for (k, i) in r.clone().enumerate() {
                for c in 0..ns {
                    rows[k * ns + c] = if c < nf {
                        self.cols[c][i]
                    } else {
                        self.factors.u[c - nf][i]
                    };
                }
            }
            self.factors.links[link].solve_rows_in_place(&mut rows[..len * ns], ns);
            for (k, i) in r.enumerate() {
                for c in 0..ns {
                    self.factors.z[c][i] = rows[k * ns + c];
                }
            }
        }
        self.factors.rows = rows;
        self.factors.z_current = true;
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

    /// out = M⁻¹ rhs with the factors of the last [`Self::build_columns`] (module docs).
    /// O(n), no allocation.
    pub(super) fn solve_mass(&mut self, rhs: &[f64], out: &mut [f64]) {
        if !self.factors.z_current {
            self.solve_columns();
        }
        let nf = self.nfull();
        let full = self.full();
        let mut zb = std::mem::take(&mut self.factors.zb);
        zb.copy_from_slice(rhs);
        for &f in &full[..nf] {
            zb[f] = 0.0;
        }
        self.solve_blocks(&mut zb);
        let fc = &self.factors;
        let cols = &self.cols;
        schur_finish(
            &full[..nf],
            |c, i| cols[c][i],
            &fc.z,
            &fc.u[..fc.nu],
            &zb,
            rhs,
            out,
        );
        self.factors.zb = zb;
    }

    /// out = M x at the chord-frame `qk` (the exact kinetic energy's momenta at velocity x
    /// plus the section inertias).
    pub(super) fn mass_mul(&mut self, x: &[f64], out: &mut [f64]) {
        let mut xk = std::mem::take(&mut self.vd);
        xk.copy_from_slice(x);
        for s in self.ghosts() {
            xk[s] = 0.0;
        }
        out.iter_mut().for_each(|o| *o = 0.0);
        self.inertia
            .momenta_values(&self.qk, &xk, &mut self.points, out);
        self.vd = xk;
        self.add_section_inertias(x, out);
    }

    /// Zeroes the ghost rows of `out` and adds the clamp and tip sections' rotary inertias
    /// J e eᵀ·x (the ghosts move no lumped mass; their sections turn).
    pub(super) fn add_section_inertias(&self, x: &[f64], out: &mut [f64]) {
        for s in self.ghosts() {
            out[s] = 0.0;
        }
        for k in 0..2 {
            let w = self.jc[k] * self.clamp_angle(x, k);
            self.add_clamp(k, w, out);
        }
        if self.tip_ghost.is_some() {
            self.add_tip(self.jt * self.tip_angle(x), out);
        }
    }
}

/// The small system of the Schur solve and the back substitution (module docs): `col(c, i)`
/// is entry i of full column c of the matrix, `z` its columns' A⁻¹ (the F columns, then U's),
/// `zb` = A⁻¹b_R (zero on F). Writes the solution into `out`.
pub(super) fn schur_finish(
    full: &[usize],
    col: impl Fn(usize, usize) -> f64,
    z: &[Vec<f64>],
    u: &[Vec<f64>],
    zb: &[f64],
    rhs: &[f64],
    out: &mut [f64],
) {
    let n = rhs.len();
    let (nf, nu) = (full.len(), u.len());
    let ns = nf + nu;
    let mut s = [[0.0; MAX_SMALL]; MAX_SMALL];
    let mut b = [0.0; MAX_SMALL];
    // unknown k: x_F[k] (k < nf) or (Cy)[k − nf]; the y rows read y_a = (Cy)_{1−a}. One pass
    // over q forms M_FR Z, M_FR A⁻¹b_R, UᵀZ and UᵀA⁻¹b_R (z and zb vanish on F).
    for r in 0..nf {
        b[r] = rhs[full[r]];
        for k in 0..nf {
            s[r][k] = col(k, full[r]);
        }
    }
    for i in 0..n {
        if full.contains(&i) {
            continue;
        }
        for r in 0..ns {
            let c = if r < nf { col(r, i) } else { u[r - nf][i] };
            b[r] -= c * zb[i];
            for k in 0..ns {
                s[r][k] -= c * z[k][i];
            }
        }
    }
    for a in 0..nu {
        s[nf + a][nf + 1 - a] -= 1.0;
    }
    let x = solve_small(s, b, ns);
    for i in 0..n {
        out[i] = match full.iter().position(|&f| f == i) {
            Some(k) => x[k],
            None => zb[i] - (0..ns).map(|k| z[k][i] * x[k]).sum::<f64>(),
        };
    }
}
