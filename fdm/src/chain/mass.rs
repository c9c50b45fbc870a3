//! The chain's mass matrix and its solve. The solve works in z: q with ψ_ℓ = (v₁ − x_ℓ)/(2h_ℓ)
//! in each clamp ghost slot (Euler links; z = q for Timoshenko links), M_z = Q⁻ᵀM Q⁻¹, so
//! M⁻¹r = Q⁻¹M_z⁻¹Q⁻ᵀr with Q⁻ᵀ (r_{v₁} += r_x, r_ψ = −2h r_x) and Q⁻¹ (x = v₁ − 2hψ) O(1).
//! In z every lumped point moves with its own deflection rate, its link's foreshortening rates
//! and the full columns F = {θ, β, ψ₁, ψ₂, y} (the frame angles, the clamp tangents' turns,
//! link 1's tip ghost); on the remaining deflections R it is
//!
//!   M_RR = A₁ ⊕ A₂ + U C Uᵀ,   U = [f₁ f₂],   C = [[0, 1], [1, 0]],
//!
//! A_ℓ = D_ℓ + G_ℓᵀN_ℓG_ℓ each link's stations with their foreshortening rates (`rates`, with
//! the clamp-tangent slopes g^t = g − ψ), f₁ = G₁ᵀ1 link 1's tip rate Ṡ and
//! f₂ = cos φ G₂ᵀμ + sin φ m₂ what link 2's stations move along it (from
//! ½Σm₂|ṙ|² ∋ Ṡ Σm₂(σ̇ cos φ + ẇ sin φ)), φ = α₂ − α₁. With y = Uᵀx_R and Z = A⁻¹[M_RF U],
//! the unknowns (x_F, y) solve a system of at most 7, and x_R = A⁻¹b_R − Z_F x_F − Z_U C y:
//! O(n) per solve, the A factorizations, Z and the small system's LU once per state.

// Index loops over the columns of M read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::kinetic::{BE, RateLanes, TH};
use super::model::TwoLinkChain;
use super::rates::LinkRates;
use super::schur::{MAX_FULL, MAX_SMALL, SmallLu};
use crate::system::System;

impl TwoLinkChain {
    /// The deflection ranges R of links 1 and 2 (stations with an unknown, the tip left out).
    pub(super) fn deflections(&self, link: usize) -> std::ops::Range<usize> {
        let first = self.first(link);
        first..self.slots[link]
    }

    /// The tridiagonal block N⁻¹ + GD⁻¹Gᵀ of `link`'s foreshortening rates at (q, q̇), the
    /// matrix of [`super::rate_block`]: its diagonal (one entry per segment) and off-diagonal
    /// (the kernel's test against faer reads it).
    pub fn link_rate_block(&mut self, q: &[f64], qd: &[f64], link: usize) -> (Vec<f64>, Vec<f64>) {
        self.frames(q, qd);
        self.build_columns();
        self.factors.links[link].block()
    }

    /// x_R ← A⁻¹x_R on both links' deflections (F entries untouched).
    fn solve_blocks(&mut self, x: &mut [f64]) {
        for link in 0..2 {
            let r = self.deflections(link);
            self.factors.links[link].solve_in_place(&mut x[r]);
        }
    }

    /// The full columns of M in the mass solve's coordinates z at the kernel coordinates
    /// `qk`: θ, β and (Euler links) ψ₁, ψ₂ are state dependent — P_zᵀ of the kernel's momenta
    /// at the unit rate P_z e_c, plus the clamp sections' J_c e eᵀ (e = 1 at the frame and at
    /// ψ) and link 1's tip section J_t e eᵀ; link 1's tip-ghost column (and, Timoshenko, the
    /// unused slots) are constant, built in `from_planar_chain`. Then the factors of the solve.
    pub(super) fn build_columns(&mut self) {
        self.split_reuse.valid = false;
        if let Some(imp) = self.implicit.as_mut() {
            imp.factored_for = None;
        }
        let n = self.dofs();
        let nd = self.inertia.dofs();
        let mut cols = std::mem::take(&mut self.cols);
        if self.timo.is_none() {
            let [c0, c1, c2, c3, _] = &mut cols;
            let mut lanes = [&mut c0[..], &mut c1[..], &mut c2[..], &mut c3[..]];
            for col in lanes.iter_mut() {
                col[nd..n].iter_mut().for_each(|x| *x = 0.0);
            }
            let units = self.units.each_ref().map(|u| &u[..]);
            self.inertia.momenta_lanes(
                &self.qk,
                &self.points.shape,
                units,
                &self.unit_lanes,
                &mut self.column_lanes,
                lanes.each_mut().map(|c| &mut c[..]),
            );
            self.kinetic_transpose_z_lanes(&mut lanes);
            for (c, col) in lanes.into_iter().enumerate() {
                self.add_clamp_z(c % 2, self.jc[c % 2], col);
                // θ's column also gets J_t e of link 1's tip section (y's column is fixed)
                if c == 0 {
                    self.add_tip(self.jt, col);
                }
            }
        } else {
            for c in 0..2 {
                let col = &mut cols[c];
                col[nd..n].iter_mut().for_each(|x| *x = 0.0);
                self.inertia
                    .momenta_at(&self.qk, &self.units[c], &mut self.points, col);
                self.kinetic_transpose_z(col);
                self.add_clamp(c, self.jc[c], col);
            }
        }
        self.cols = cols;
        self.factor_blocks();
    }

    /// The rate blocks' station masses (the lumped diagonal of M).
    pub(super) fn set_station_masses(&mut self) {
        for link in 0..2 {
            let start = self.deflections(link).start;
            let mut rates = std::mem::replace(&mut self.factors.links[link], LinkRates::empty());
            rates.set_masses(|i| self.diag_mass(start + i));
            self.factors.links[link] = rates;
        }
    }

    /// The kernel's rates at unit rate of the state-dependent full columns (the frame angle,
    /// and for ψ_ℓ also the tangent frame's deflections −ξ_k, tip −L) and their slopes.
    pub(super) fn set_unit_rates(&mut self) {
        for c in 0..4 {
            let link = c % 2;
            let (first, slot, h) = (self.first(link), self.slots[link], self.hs[link]);
            let unit = &mut self.units[c];
            unit[if link == 0 { TH } else { BE }] = 1.0;
            if c >= 2 {
                for (k, i) in (first..=slot).enumerate() {
                    unit[i] = -((k + 1) as f64) * h;
                }
            }
        }
        self.unit_lanes = RateLanes::new(&self.inertia, self.units.each_ref().map(|u| &u[..]));
    }

    /// A_ℓ and U at `qk` (Z follows with the first solve).
    fn factor_blocks(&mut self) {
        self.factors.z_current = false;
        for link in 0..2 {
            // the kernel's slopes at `qk` (its shape): the tip's deflection sits in the slot
            // after the link's deflections
            let shape = &self.points.shape;
            let g = if link == 0 { &shape.g1 } else { &shape.g2 };
            self.factors.links[link].set_state(g);
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
        let fc = &self.factors;
        let cols = &self.cols;
        self.factors.small = schur_matrix(
            self.dofs(),
            &self.full()[..nf],
            |c, i| cols[c][i],
            &fc.z[..ns],
            &fc.u[..fc.nu],
        );
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
        let mut rz = std::mem::take(&mut self.factors.rz);
        rz.copy_from_slice(rhs);
        self.q_to_z_forces(&mut rz);
        let mut zb = std::mem::take(&mut self.factors.zb);
        zb.copy_from_slice(&rz);
        for &f in &full[..nf] {
            zb[f] = 0.0;
        }
        self.solve_blocks(&mut zb);
        let fc = &self.factors;
        let cols = &self.cols;
        schur_solve(
            &full[..nf],
            |c, i| cols[c][i],
            &fc.small,
            &fc.z,
            &fc.u[..fc.nu],
            &zb,
            &rz,
            out,
        );
        self.factors.zb = zb;
        self.factors.rz = rz;
        self.z_to_q_motion(out);
    }

    /// out = M x at the kernel coordinates `qk` (Pᵀ of the exact kinetic energy's momenta
    /// at velocity P x, plus the section inertias).
    pub(super) fn mass_mul(&mut self, x: &[f64], out: &mut [f64]) {
        let mut xk = std::mem::take(&mut self.vd);
        self.to_kinetic(x, &mut xk);
        out.iter_mut().for_each(|o| *o = 0.0);
        self.inertia
            .momenta_at(&self.qk, &xk, &mut self.points, out);
        self.vd = xk;
        self.kinetic_transpose(out);
        self.add_section_inertias(x, out);
    }

    /// Adds the clamp and tip sections' rotary inertias J e eᵀ·x (q coordinates).
    pub(super) fn add_section_inertias(&self, x: &[f64], out: &mut [f64]) {
        for k in 0..2 {
            let w = self.jc[k] * self.clamp_angle(x, k);
            self.add_clamp(k, w, out);
        }
        if self.tip_ghost.is_some() {
            self.add_tip(self.jt * self.tip_angle(x), out);
        }
    }
}

/// The small system of the Schur solve (module docs) of an n × n matrix, factored
/// ([`schur_system`]).
pub(super) fn schur_matrix(
    n: usize,
    full: &[usize],
    col: impl Fn(usize, usize) -> f64,
    z: &[Vec<f64>],
    u: &[Vec<f64>],
) -> SmallLu {
    let (s, ns) = schur_system(n, full, col, z, u);
    SmallLu::factor(s, ns)
}

/// The small system of the Schur solve (module docs) of an n × n matrix and its order:
/// `col(c, i)` is entry i of full column c of the matrix, `z` its columns' A⁻¹ (the F columns,
/// then U's, zero on F).
pub(super) fn schur_system(
    n: usize,
    full: &[usize],
    col: impl Fn(usize, usize) -> f64,
    z: &[Vec<f64>],
    u: &[Vec<f64>],
) -> ([[f64; MAX_SMALL]; MAX_SMALL], usize) {
    let (nf, nu) = (full.len(), u.len());
    let ns = nf + nu;
    let mut s = [[0.0; MAX_SMALL]; MAX_SMALL];
    // unknown k: x_F[k] (k < nf) or (Cy)[k − nf]; the y rows read y_a = (Cy)_{1−a}. One pass
    // over q forms M_FR Z and UᵀZ.
    for r in 0..nf {
        for k in 0..nf {
            s[r][k] = col(k, full[r]);
        }
    }
    // Row i of every column gathered once (the columns are separate vectors); each s[r][k]
    // still accumulates over i in increasing order.
    let mut zi = [0.0; MAX_SMALL];
    for i in 0..n {
        if full.contains(&i) {
            continue;
        }
        for k in 0..ns {
            zi[k] = z[k][i];
        }
        for r in 0..ns {
            let c = if r < nf { col(r, i) } else { u[r - nf][i] };
            for (sk, zk) in s[r][..ns].iter_mut().zip(&zi[..ns]) {
                *sk -= c * zk;
            }
        }
    }
    for a in 0..nu {
        s[nf + a][nf + 1 - a] -= 1.0;
    }
    (s, ns)
}

/// The Schur solve's right-hand side, its small solve with the factors `small` of
/// [`schur_matrix`] and the back substitution: `zb` = A⁻¹b_R (zero on F), `rhs` the whole
/// right-hand side. Writes the solution into `out`.
#[allow(clippy::too_many_arguments)]
pub(super) fn schur_solve(
    full: &[usize],
    col: impl Fn(usize, usize) -> f64,
    small: &SmallLu,
    z: &[Vec<f64>],
    u: &[Vec<f64>],
    zb: &[f64],
    rhs: &[f64],
    out: &mut [f64],
) {
    let n = rhs.len();
    let (nf, nu) = (full.len(), u.len());
    let ns = nf + nu;
    let mut b = [0.0; MAX_SMALL];
    // M_FR A⁻¹b_R and UᵀA⁻¹b_R in one pass over q
    for r in 0..nf {
        b[r] = rhs[full[r]];
    }
    for i in 0..n {
        if full.contains(&i) {
            continue;
        }
        for r in 0..ns {
            let c = if r < nf { col(r, i) } else { u[r - nf][i] };
            b[r] -= c * zb[i];
        }
    }
    let x = small.solve(b);
    for i in 0..n {
        out[i] = match full.iter().position(|&f| f == i) {
            Some(k) => x[k],
            None => zb[i] - (0..ns).map(|k| z[k][i] * x[k]).sum::<f64>(),
        };
    }
}
