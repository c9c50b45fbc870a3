//! Implicit damping for the velocity form ([`crate::method::velocity_form`]): the chain's
//! Kelvin–Voigt and joint-damper forces are −C q̇ with a constant symmetric C ≥ 0 (D = ½q̇ᵀCq̇:
//! the ghost-node bending stencil on the rates, link 1's tip term, D₁e₁e₁ᵀ + D₂e₂e₂ᵀ with eⱼ
//! the constant gradients of the joint rates). The closing kick solves
//!
//! (M(q_{j+1}) + ½τC) a_{j+1} = F_rest(q_{j+1}, v_{j±½}) − C v_{j+½},  v_{j+1} = v_{j+½} + ½τa_{j+1},
//!
//! i.e. −½τM⁻¹C v_{j+1} in the closing kick beside −½τM⁻¹C v_j in the opening one:
//! Crank–Nicolson in the damping, stable for every κτ, so the step is the undamped bound (the
//! elastic h²√(ρA/4EI) and the ghost rotations) instead of the damped one, whose dampers on
//! the clamp half cells ρAh³/24 shrink it like h³–h⁴.
//!
//! **Solve.** In the mass solve's coordinates z ([`super::mass`]: ψ in the ghost slots,
//! C_z = Q⁻ᵀCQ⁻¹) M + ½τC has M's structure plus C. Outside the full columns
//! F = {θ, β, ψ₁, ψ₂, y} ("band": v₁…v_{r−1}, w₁…w_{r−1} in q order) C_z is pentadiagonal — the
//! bending stencil per link (the elbow damper reaches v_{r−1}; its w₁ term in q is ψ₂'s in z) — so
//! the band block is P + ⊕GᵀNG + UCUᵀ with P = D_B + ½τC_BB SPD pentadiagonal. Its first two
//! terms are the saddle system [[P, Gᵀ], [G, −N⁻¹]] (λ = NGx, N⁻¹ tridiagonal), banded when
//! each segment's multiplier sits next to its station: quasi-definite, so its LDLᵀ exists
//! without pivoting (`crate::band_ldl`), O(n) per kick (G follows the slopes). The rank-2 U
//! and the full columns close it as in the mass solve: Z = A⁻¹[A_BF U], a system of at most
//! 7, back substitution; no allocation. The saddle system is assembled in a matrix of its own
//! (the constant entries once per τ, G's per state) and factored out of place from it, without
//! a copy. The links' blocks of the saddle system do not couple (C_z has no entry across the
//! elbow), so each is stored in its envelope and solved alone with the columns that are not
//! zero on it: the other link's U column and a constant full column without entries there
//! (link 1's tip ghost on link 2) have a zero A⁻¹ on the link. C_z itself is read once from
//! `TwoLinkChain::add_damping_forces` by probing (at Q⁻¹e, then Q⁻ᵀ): each full column alone,
//! the band columns in five interleaved colours (bandwidth 2).
//!
//! **Held tip** (restartable steps of a contact run, [`crate::method::velocity_form`]). With A =
//! M + ½τC, A q̈ = f + Gᵀλ and G q̈ + Ġq̇ = 0 (Ġq̇ at the predicted velocity, as in the explicit
//! kick): λ = −(G a_free + Ġq̇)/(G A⁻¹Gᵀ), one more right-hand side on the kick's factors (the
//! saddle LDLᵀ, Z and the small system are kept per state and τ). The drift projections after
//! the kick keep the metric M (G and M⁻¹Gᵀ from the mass solve).
//!
//! **Ledger.** The powers are those of the level velocities (v_{j+1}ᵀCv_{j+1} and the joint
//! dampers' D θ̇², as in the explicit form), integrated by the driver's trapezoid rule.

// Index loops over band positions and full columns read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::damping_matrix::{ImplicitDamping, KickBlock, MAX_SOLVED};
use super::model::TwoLinkChain;
use super::schur::{MAX_FULL, MAX_SMALL, SmallLu};
use crate::band_ldl::BandLdl;
use crate::linalg::dot;
use crate::system::{DriftVelocities, System};

impl TwoLinkChain {
    /// Switches the velocity form's closing kick to implicit damping (module docs) when the
    /// chain has damping and Euler links; returns whether it did.
    pub fn enable_implicit_damping(&mut self) -> bool {
        if self.timo.is_some() || !(self.any_kv() || self.any_damper()) {
            return false;
        }
        let n = self.dofs();
        let nf = self.nfull();
        let full = self.full();
        let band: Vec<usize> = (0..n).filter(|i| !full[..nf].contains(i)).collect();
        let nb = band.len();
        let mut e = vec![0.0; n];
        let mut y = vec![0.0; n];
        let mut eq = vec![0.0; n];
        // C in the mass solve's coordinates z (ψ in the ghost slots): C_z = Q⁻ᵀCQ⁻¹
        let mut probe = |sys: &mut Self, e: &[f64], y: &mut [f64]| {
            eq.copy_from_slice(e);
            sys.z_to_q_motion(&mut eq);
            y.iter_mut().for_each(|x| *x = 0.0);
            sys.add_damping_forces(&eq, y);
            sys.q_to_z_forces(y);
        };
        let mut cf: [Vec<f64>; MAX_FULL] = std::array::from_fn(|_| vec![0.0; n]);
        for c in 0..nf {
            e[full[c]] = 1.0;
            probe(self, &e, &mut y);
            e[full[c]] = 0.0;
            for i in 0..n {
                cf[c][i] = -y[i];
            }
        }
        let (mut c0, mut c1, mut c2) = (vec![0.0; nb], vec![0.0; nb], vec![0.0; nb]);
        for colour in 0..5 {
            e.iter_mut().for_each(|x| *x = 0.0);
            for b in (colour..nb).step_by(5) {
                e[band[b]] = 1.0;
            }
            probe(self, &e, &mut y);
            for b in (colour..nb).step_by(5) {
                c0[b] = -y[band[b]];
                if b + 1 < nb {
                    c1[b] = -y[band[b + 1]];
                }
                if b + 2 < nb {
                    c2[b] = -y[band[b + 2]];
                }
            }
        }
        let (at_band, at_segment) = self.saddle_layout(&band);
        let size = at_segment[1].last().map_or(0, |p| p + 1);
        let saddle =
            BandLdl::with_envelope(self.saddle_envelope(size, &at_band, &at_segment, [&c1, &c2]));
        let blocks = self.kick_blocks(&saddle, &band, &at_segment, &cf);
        // G's entries in the envelope, found once
        let (mut g_plus, mut g_minus): ([Vec<usize>; 2], [Vec<usize>; 2]) = Default::default();
        let mut first = 0;
        for (link, segs) in at_segment.iter().enumerate() {
            let r = segs.len();
            for seg in 0..r {
                if seg < r - 1 {
                    g_plus[link].push(saddle.position(segs[seg], at_band[first + seg]));
                }
                if seg >= 1 {
                    g_minus[link].push(saddle.position(segs[seg], at_band[first + seg - 1]));
                }
            }
            first += r - 1;
        }
        self.implicit = Some(Box::new(ImplicitDamping {
            assembled: saddle.clone(),
            constant_for: None,
            g_plus,
            g_minus,
            c0,
            c1,
            c2,
            cf,
            saddle,
            at_band,
            at_segment,
            blocks,
            system: [[0.0; MAX_SMALL]; MAX_SMALL],
            small: SmallLu::default(),
            factored_for: None,
            failed: false,
            vnew: vec![0.0; n],
            damped_g: vec![0.0; n],
            band,
        }));
        true
    }

    /// Positions of the saddle system's unknowns, interleaved by station so that it is banded:
    /// per link the deflection of station i, then the multiplier of segment i, and the last
    /// segment's multiplier after the link's last station. Returns the positions of the band
    /// unknowns and of each link's segment multipliers.
    fn saddle_layout(&self, band: &[usize]) -> (Vec<usize>, [Vec<usize>; 2]) {
        let mut at_band = vec![0; band.len()];
        let mut at_segment: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        let mut pos = 0;
        let mut b = 0;
        for link in 0..2 {
            let r = self.deflections(link).len() + 1;
            for _ in 0..r - 1 {
                at_band[b] = pos;
                at_segment[link].push(pos + 1);
                pos += 2;
                b += 1;
            }
            at_segment[link].push(pos);
            pos += 1;
        }
        (at_band, at_segment)
    }

    /// Each link's block of the saddle system with the columns of [A_BF U] solved on it (module
    /// docs): every full column but a constant one without entries on the link (link 1's
    /// tip-ghost column; θ, β, ψ₁, ψ₂ follow the state), the link's own U column. Links whose
    /// blocks couple (C across the elbow) are solved as one block with every column.
    fn kick_blocks(
        &self,
        saddle: &BandLdl,
        band: &[usize],
        at_segment: &[Vec<usize>; 2],
        cf: &[Vec<f64>; MAX_FULL],
    ) -> [KickBlock; 2] {
        let nf = self.nfull();
        let nu = if self.inertia.fs1 { 2 } else { 0 };
        let size = saddle.n();
        let split = at_segment[0].last().map_or(0, |p| p + 1);
        let nb1 = self.deflections(0).len();
        let (rows, bands, links): ([_; 2], [_; 2], [&[usize]; 2]) =
            if saddle.is_block(0..split) && saddle.is_block(split..size) {
                (
                    [0..split, split..size],
                    [0..nb1, nb1..band.len()],
                    [&[0], &[1]],
                )
            } else {
                ([0..size, size..size], [0..band.len(), 0..0], [&[0, 1], &[]])
            };
        std::array::from_fn(|l| {
            let on = &band[bands[l].clone()];
            let mut cols = [0; MAX_SOLVED];
            let mut m = 0;
            for c in 0..nf {
                let constant = c >= 4;
                if constant
                    && on
                        .iter()
                        .all(|&i| self.cols[c][i] == 0.0 && cf[c][i] == 0.0)
                {
                    continue;
                }
                cols[m] = c;
                m += 1;
            }
            for &link in links[l] {
                if link < nu {
                    cols[m] = nf + link;
                    m += 1;
                }
            }
            // the right-hand side
            m += 1;
            let len = rows[l].len();
            KickBlock {
                rows: rows[l].clone(),
                band: bands[l].clone(),
                cols,
                m,
                rhs: vec![0.0; on.len() * m],
                sol: vec![0.0; len * m],
                one: vec![0.0; len],
            }
        })
    }

    /// The first column of each row of the saddle system: its entries are those
    /// `assemble_saddle` adds, C's sub-diagonals where they are not zero (C is constant; the
    /// links' blocks do not couple), G and N⁻¹ always (the slopes change).
    fn saddle_envelope(
        &self,
        size: usize,
        at_band: &[usize],
        at_segment: &[Vec<usize>; 2],
        [c1, c2]: [&[f64]; 2],
    ) -> Vec<usize> {
        let mut first: Vec<usize> = (0..size).collect();
        let mut reach = |i: usize, j: usize| {
            let (i, j) = (i.max(j), i.min(j));
            first[i] = first[i].min(j);
        };
        let nb = at_band.len();
        for b in 0..nb {
            if b + 1 < nb && c1[b] != 0.0 {
                reach(at_band[b + 1], at_band[b]);
            }
            if b + 2 < nb && c2[b] != 0.0 {
                reach(at_band[b + 2], at_band[b]);
            }
        }
        let mut start = 0;
        for segs in at_segment {
            let r = segs.len();
            for seg in 0..r {
                if seg < r - 1 {
                    reach(segs[seg], at_band[start + seg]);
                }
                if seg >= 1 {
                    reach(segs[seg], at_band[start + seg - 1]);
                }
                if seg + 1 < r {
                    reach(segs[seg + 1], segs[seg]);
                }
            }
            start += r - 1;
        }
        first
    }

    /// Whether the damping is implicit (the bound then leaves it out).
    pub fn implicit_damping(&self) -> bool {
        self.implicit.is_some()
    }

    /// The implicit closing kick (module docs): a_{j+1} into `a`, powers at v_{j+1}.
    pub(super) fn implicit_kick_solve(
        &mut self,
        t: f64,
        q: &[f64],
        drift: DriftVelocities,
        tau: f64,
        a: &mut [f64],
    ) {
        let mut rhs = std::mem::take(&mut self.rhs);
        self.frames(q, drift.current);
        self.skip_damping = true;
        self.forces(t, q, drift.current, &mut rhs);
        self.skip_damping = false;
        // (a zero weight, w = −1: the inertia terms at `previous` alone, no pass at `current`)
        let w_current = 1.0 + drift.w;
        if w_current != 0.0 && drift.w != 0.0 {
            self.add_inertia_terms_pair([w_current, -drift.w], drift.previous, a, &mut rhs);
        } else {
            if w_current != 0.0 {
                self.add_inertia_terms(w_current, a, &mut rhs);
            }
            if drift.w != 0.0 {
                self.frames_velocity(drift.previous);
                self.add_inertia_terms(-drift.w, a, &mut rhs);
            }
            self.frames_velocity(drift.current);
        }
        self.build_columns();
        self.add_damping_forces(drift.current, &mut rhs);
        self.solve_damped_mass(tau, &rhs, a);
        self.rhs = rhs;
        self.constraint.lambda = 0.0;
        if self.constraint.constrained {
            self.hold_tip(q, drift.predicted, tau, a);
        }
        let mut imp = self.implicit.take().expect("implicit damping");
        for i in 0..a.len() {
            imp.vnew[i] = drift.current[i] + 0.5 * tau * a[i];
        }
        let mut sink = [0.0; 4];
        self.powers_at(t, &imp.vnew, &mut sink);
        self.implicit = Some(imp);
    }

    /// The held tip's force in the implicit kick (module docs): with A = M + ½τC and the free
    /// kick's a_free in `a`, A q̈ = f + Gᵀλ, G q̈ + Ġq̇ = 0 (Ġq̇ at the predicted velocity, as
    /// the explicit kick takes it) ⇒ λ = −(G a_free + Ġq̇)/(G A⁻¹Gᵀ), q̈ = a_free + A⁻¹Gᵀλ.
    /// Also leaves G and M⁻¹Gᵀ for the velocity projection after the kick, whose metric is M.
    fn hold_tip(&mut self, q: &[f64], predicted: &[f64], tau: f64, a: &mut [f64]) {
        self.frames(q, predicted);
        let (_, curvature) = self.constraint_solve();
        let grow = std::mem::take(&mut self.constraint.grow);
        let mut imp = self.implicit.take().expect("implicit damping");
        let mut damped_g = std::mem::take(&mut imp.damped_g);
        self.implicit = Some(imp);
        self.solve_damped_mass(tau, &grow, &mut damped_g);
        let gag = dot(&grow, &damped_g);
        let ga = dot(&grow, a);
        // a G A⁻¹Gᵀ that is not a positive number (a failed solve) stops the contact driver
        // through NaN
        let lam = if gag > 0.0 {
            -(ga + curvature) / gag
        } else {
            f64::NAN
        };
        for i in 0..a.len() {
            a[i] += damped_g[i] * lam;
        }
        self.constraint.lambda = lam;
        self.constraint.grow = grow;
        if let Some(imp) = self.implicit.as_mut() {
            imp.damped_g = damped_g;
        }
    }

    /// out = (M + ½τC)⁻¹ rhs at the state of the last `build_columns` (module docs). O(n), no
    /// allocation. The first solve at a state and τ factors and sweeps the columns Z with its
    /// right-hand side; a later one at them (the held tip's column after the kick) reuses the
    /// factors and sweeps its right-hand side alone. A saddle system that does not factor
    /// (masses or damping not positive) gives NaN, which stops the run.
    pub fn solve_damped_mass(&mut self, tau: f64, rhs: &[f64], out: &mut [f64]) {
        let mut imp = self.implicit.take().expect("implicit damping");
        let refactor = imp.factored_for != Some(tau);
        if refactor {
            imp.factored_for = Some(tau);
            imp.failed = !self.factor_saddle(tau, &mut imp);
        }
        if imp.failed {
            out.iter_mut().for_each(|x| *x = f64::NAN);
            self.implicit = Some(imp);
            return;
        }
        let ht = 0.5 * tau;
        let nf = self.nfull();
        let full = self.full();
        let full = &full[..nf];
        let nu = self.factors.nu;
        let mut rz = std::mem::take(&mut self.factors.rz);
        rz.copy_from_slice(rhs);
        self.q_to_z_forces(&mut rz);
        let ImplicitDamping {
            band,
            cf,
            saddle,
            at_band,
            blocks,
            system,
            small,
            ..
        } = &mut *imp;
        let u = &self.factors.u;
        let col = |c: usize, i: usize| {
            if c < nf {
                self.cols[c][i] + ht * cf[c][i]
            } else {
                u[c - nf][i]
            }
        };
        // the small system's right-hand side b and (a new factor) the system itself: the
        // columns Z = A⁻¹[A_BF U] and A⁻¹r_B by one sweep per block, then M_FR Z, UᵀZ and
        // their products with A⁻¹r_B in one pass over the band rows in q order
        let mut b = [0.0; MAX_SMALL];
        for r in 0..nf {
            b[r] = rz[full[r]];
        }
        if refactor {
            let mut s = [[0.0; MAX_SMALL]; MAX_SMALL];
            for r in 0..nf {
                for k in 0..nf {
                    s[r][k] = col(k, full[r]);
                }
            }
            for blk in blocks.iter_mut() {
                let m = blk.m;
                // the block's columns (those of M's full columns take their damping), then
                // the right-hand side
                let mut src: [(&[f64], Option<&[f64]>); MAX_SOLVED] = [(&[], None); MAX_SOLVED];
                for a in 0..m - 1 {
                    src[a] = match blk.cols[a] {
                        c if c < nf => (&self.cols[c], Some(&cf[c])),
                        c => (&u[c - nf], None),
                    };
                }
                src[m - 1] = (&rz, None);
                let src = &src[..m];
                let (rows, at) = (&band[blk.band.clone()], &at_band[blk.band.clone()]);
                match m {
                    1 => put_rows::<1>(blk, rows, at, src, ht),
                    2 => put_rows::<2>(blk, rows, at, src, ht),
                    3 => put_rows::<3>(blk, rows, at, src, ht),
                    4 => put_rows::<4>(blk, rows, at, src, ht),
                    5 => put_rows::<5>(blk, rows, at, src, ht),
                    6 => put_rows::<6>(blk, rows, at, src, ht),
                    7 => put_rows::<7>(blk, rows, at, src, ht),
                    8 => put_rows::<8>(blk, rows, at, src, ht),
                    m => unreachable!("{m} right-hand sides"),
                }
                saddle.solve_block_rows_in_place(blk.rows.clone(), &mut blk.sol, m);
                schur_rows(blk, &at_band[blk.band.clone()], &mut s, &mut b);
            }
            for a in 0..nu {
                s[nf + a][nf + 1 - a] -= 1.0;
            }
            *system = s;
            *small = SmallLu::factor(s, nf + nu);
        } else {
            for blk in blocks.iter_mut() {
                let (m, r0) = (blk.m, blk.rows.start);
                blk.one.iter_mut().for_each(|v| *v = 0.0);
                for p in blk.band.clone() {
                    blk.one[at_band[p] - r0] = rz[band[p]];
                }
                saddle.solve_block_rows_in_place(blk.rows.clone(), &mut blk.one, 1);
                for (t, p) in blk.band.clone().enumerate() {
                    let zb = blk.one[at_band[p] - r0];
                    for a in 0..m - 1 {
                        b[blk.cols[a]] -= blk.rhs[t * m + a] * zb;
                    }
                }
            }
        }
        let x = small.solve(b);
        for blk in blocks.iter() {
            let range = blk.band.clone();
            let (rows, at) = (&band[range.clone()], &at_band[range]);
            let one = (!refactor).then_some(&blk.one[..]);
            match blk.m {
                1 => back_rows::<1>(blk, rows, at, &x, one, out),
                2 => back_rows::<2>(blk, rows, at, &x, one, out),
                3 => back_rows::<3>(blk, rows, at, &x, one, out),
                4 => back_rows::<4>(blk, rows, at, &x, one, out),
                5 => back_rows::<5>(blk, rows, at, &x, one, out),
                6 => back_rows::<6>(blk, rows, at, &x, one, out),
                7 => back_rows::<7>(blk, rows, at, &x, one, out),
                8 => back_rows::<8>(blk, rows, at, &x, one, out),
                m => unreachable!("{m} right-hand sides"),
            }
        }
        for (k, &f) in full.iter().enumerate() {
            out[f] = x[k];
        }
        self.implicit = Some(imp);
        self.factors.rz = rz;
        self.z_to_q_motion(out);
    }

    /// The saddle system of the implicit kick (module docs) at (q, q̇) and step τ, assembled
    /// and not factored (the kernel's bench and its test against faer read it). Requires
    /// [`Self::enable_implicit_damping`].
    pub fn implicit_kick_saddle(&mut self, q: &[f64], qd: &[f64], tau: f64) -> BandLdl {
        self.frames(q, qd);
        self.build_columns();
        let mut imp = self.implicit.take().expect("implicit damping");
        self.assemble_saddle(tau, &mut imp);
        imp.factored_for = None;
        let saddle = imp.assembled.clone();
        self.implicit = Some(imp);
        saddle
    }

    /// The small system of the implicit kick's Schur solve (module docs) at (q, q̇) and step τ
    /// and its order, not factored (the kernel's bench reads it). Requires
    /// [`Self::enable_implicit_damping`].
    pub fn implicit_kick_schur(
        &mut self,
        q: &[f64],
        qd: &[f64],
        tau: f64,
    ) -> ([[f64; MAX_SMALL]; MAX_SMALL], usize) {
        self.frames(q, qd);
        self.build_columns();
        // a solve at the state forms it
        let zero = vec![0.0; self.dofs()];
        let mut x = vec![0.0; self.dofs()];
        self.solve_damped_mass(tau, &zero, &mut x);
        let imp = self.implicit.as_ref().expect("implicit damping");
        (imp.system, self.nfull() + self.factors.nu)
    }

    /// Assembles and factors the saddle system of M + ½τC at the state of the last
    /// `build_columns`; false when it does not factor.
    fn factor_saddle(&self, tau: f64, imp: &mut ImplicitDamping) -> bool {
        self.assemble_saddle(tau, imp);
        imp.saddle.factor_from(&imp.assembled).is_ok()
    }

    /// The saddle system [[D_B + ½τC_BB, Gᵀ], [G, −N⁻¹]] interleaved by station into
    /// `imp.assembled`.
    fn assemble_saddle(&self, tau: f64, imp: &mut ImplicitDamping) {
        if imp.constant_for != Some(tau) {
            self.assemble_constant(tau, imp);
            imp.constant_for = Some(tau);
        }
        let ImplicitDamping {
            assembled,
            g_plus,
            g_minus,
            ..
        } = imp;
        // every entry takes one term: the constant ones, and G's onto their zeros, which
        // the last assembly's G took (the sum 0 + g that adding it to the zero formed)
        for link in 0..2 {
            let g = self.factors.links[link].slopes();
            for (&p, &g) in g_plus[link].iter().zip(g) {
                assembled.set_at(p, 0.0 + g);
            }
            for (&p, &g) in g_minus[link].iter().zip(&g[1..]) {
                assembled.set_at(p, 0.0 - g);
            }
        }
    }

    /// The saddle system's entries that do not follow the state, D_B + ½τC_BB and −N⁻¹, into
    /// `imp.assembled` (G's entries zero).
    fn assemble_constant(&self, tau: f64, imp: &mut ImplicitDamping) {
        let ht = 0.5 * tau;
        let nb = imp.band.len();
        let ImplicitDamping {
            band,
            c0,
            c1,
            c2,
            assembled,
            at_band,
            at_segment,
            ..
        } = imp;
        assembled.clear();
        for b in 0..nb {
            assembled.add(at_band[b], at_band[b], self.diag_mass(band[b]) + ht * c0[b]);
            // a zero of C is no entry of the envelope (adding it changed nothing)
            if b + 1 < nb && c1[b] != 0.0 {
                assembled.add(at_band[b + 1], at_band[b], ht * c1[b]);
            }
            if b + 2 < nb && c2[b] != 0.0 {
                assembled.add(at_band[b + 2], at_band[b], ht * c2[b]);
            }
        }
        for (link, segs) in at_segment.iter().enumerate() {
            let w = self.factors.links[link].weights();
            let r = segs.len();
            for seg in 0..r {
                let mut nd = 1.0 / w[seg];
                if seg >= 1 {
                    nd += 1.0 / w[seg - 1];
                }
                assembled.add(segs[seg], segs[seg], -nd);
                if seg + 1 < r {
                    assembled.add(segs[seg + 1], segs[seg], 1.0 / w[seg]);
                }
            }
        }
    }
}

/// The right-hand sides of one block's factoring solve, row by row: `src[a]` is column a's
/// values over q (and its damping, taken with weight `ht`), `rows` and `at` the block's band
/// rows in q and in the saddle system. Into `blk.rhs` by band rows and into `blk.sol` by
/// saddle rows, the multipliers' rows zero.
fn put_rows<const M: usize>(
    blk: &mut KickBlock,
    rows: &[usize],
    at: &[usize],
    src: &[(&[f64], Option<&[f64]>)],
    ht: f64,
) {
    let src: &[_; M] = src.try_into().unwrap();
    let r0 = blk.rows.start;
    let (rhs, sol) = (
        blk.rhs.as_chunks_mut::<M>().0,
        blk.sol.as_chunks_mut::<M>().0,
    );
    let mut next = 0;
    for ((&i, &p), c) in rows.iter().zip(at).zip(rhs.iter_mut()) {
        let mut v = [0.0; M];
        for a in 0..M {
            v[a] = match src[a] {
                (value, Some(damping)) => value[i] + ht * damping[i],
                (value, None) => value[i],
            };
        }
        *c = v;
        sol[next..p - r0].fill([0.0; M]);
        sol[p - r0] = v;
        next = p - r0 + 1;
    }
    sol[next..].fill([0.0; M]);
}

/// The small system's products over one block's band rows, in order: s(r, k) −= c_r z_k and
/// b(r) −= c_r z_b for the block's columns r, k (c the right-hand sides as formed, z their
/// solutions; the other columns are zero on the block). `at` are the rows' saddle rows.
fn schur_rows(
    blk: &KickBlock,
    at: &[usize],
    s: &mut [[f64; MAX_SMALL]; MAX_SMALL],
    b: &mut [f64; MAX_SMALL],
) {
    match blk.m {
        1 => schur_rows_m::<1>(blk, at, s, b),
        2 => schur_rows_m::<2>(blk, at, s, b),
        3 => schur_rows_m::<3>(blk, at, s, b),
        4 => schur_rows_m::<4>(blk, at, s, b),
        5 => schur_rows_m::<5>(blk, at, s, b),
        6 => schur_rows_m::<6>(blk, at, s, b),
        7 => schur_rows_m::<7>(blk, at, s, b),
        8 => schur_rows_m::<8>(blk, at, s, b),
        m => unreachable!("{m} right-hand sides"),
    }
}

/// [`schur_rows`] with `M` solved columns (the right-hand side last), the block of s and b
/// held locally.
fn schur_rows_m<const M: usize>(
    blk: &KickBlock,
    at: &[usize],
    s: &mut [[f64; MAX_SMALL]; MAX_SMALL],
    b: &mut [f64; MAX_SMALL],
) {
    let cols = &blk.cols[..M - 1];
    let mut acc = [[0.0; M]; M];
    for (a, &r) in cols.iter().enumerate() {
        for (k, &c) in cols.iter().enumerate() {
            acc[a][k] = s[r][c];
        }
        acc[a][M - 1] = b[r];
    }
    let r0 = blk.rows.start;
    let (rhs, sol) = (blk.rhs.as_chunks::<M>().0, blk.sol.as_chunks::<M>().0);
    // two rows of acc at a time, each sum over the band rows in order as one lane of packed
    // products (all rows at once spill, and the compiler then kept every product scalar)
    let mut a = 0;
    while a + 1 < M - 1 {
        let mut pair: [[f64; 2]; M] = std::array::from_fn(|k| [acc[a][k], acc[a + 1][k]]);
        schur_pair(&mut pair, [a, a + 1], rhs, sol, at, r0);
        for k in 0..M {
            [acc[a][k], acc[a + 1][k]] = pair[k];
        }
        a += 2;
    }
    if a < M - 1 {
        // the last row alone: the pair's second lane repeats it and is dropped
        let mut pair: [[f64; 2]; M] = std::array::from_fn(|k| [acc[a][k], acc[a][k]]);
        schur_pair(&mut pair, [a, a], rhs, sol, at, r0);
        for k in 0..M {
            acc[a][k] = pair[k][0];
        }
    }
    for (a, &r) in cols.iter().enumerate() {
        for (k, &c) in cols.iter().enumerate() {
            s[r][c] = acc[a][k];
        }
        b[r] = acc[a][M - 1];
    }
}

/// Rows `rows` of [`schur_rows_m`]'s sums, lane by lane: acc_k −= (c_{rows₀}, c_{rows₁}) z_k
/// over the band rows (`at` their saddle rows). Out of line: inlined, the compiler left the
/// products scalar.
#[inline(never)]
fn schur_pair<const M: usize>(
    acc: &mut [[f64; 2]; M],
    rows: [usize; 2],
    rhs: &[[f64; M]],
    sol: &[[f64; M]],
    at: &[usize],
    r0: usize,
) {
    let mut sums = *acc;
    for (c, &p) in rhs.iter().zip(at) {
        let z = &sol[p - r0];
        let ca = [c[rows[0]], c[rows[1]]];
        for k in 0..M {
            sums[k][0] -= ca[0] * z[k];
            sums[k][1] -= ca[1] * z[k];
        }
    }
    *acc = sums;
}

/// The back substitution of the Schur solve on one block's band rows (q indices `rows`,
/// saddle rows `at`): out = A⁻¹r_B − Z x, A⁻¹r_B from the factoring solve's last column or
/// from `one` (a later right-hand side's solution).
fn back_rows<const M: usize>(
    blk: &KickBlock,
    rows: &[usize],
    at: &[usize],
    x: &[f64; MAX_SMALL],
    one: Option<&[f64]>,
    out: &mut [f64],
) {
    let xs: [f64; M] = std::array::from_fn(|a| if a + 1 < M { x[blk.cols[a]] } else { 0.0 });
    let r0 = blk.rows.start;
    let sol = blk.sol.as_chunks::<M>().0;
    for (&i, &p) in rows.iter().zip(at) {
        let z = &sol[p - r0];
        let zb = match one {
            Some(one) => one[p - r0],
            None => z[M - 1],
        };
        out[i] = zb - (0..M - 1).map(|a| z[a] * xs[a]).sum::<f64>();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::System;

    #[test]
    fn elem_implicit_kick_solves_the_damped_mass_system() {
        // (M + ½τC) x = r checked by M x (the chain's own product) and C x (the damping forces
        // themselves), at a deformed, moving state and a step far above the damped bound: the
        // first solve at the state (factors and columns), a second right-hand side on the same
        // factors (the held tip's), and another τ (factored again)
        let scene = data::load_scene("two-link-free").unwrap();
        let mut sys =
            TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(9))
                .unwrap();
        assert!(sys.enable_implicit_damping());
        let n = sys.dofs();
        let q: Vec<f64> = (0..n)
            .map(|i| 0.3 + 0.02 * (0.9 * i as f64).sin())
            .collect();
        let v: Vec<f64> = (0..n).map(|i| 0.3 * (1.7 * i as f64).cos()).collect();
        sys.frames(&q, &v);
        sys.build_columns();
        let rhs: [Vec<f64>; 2] = [
            (0..n).map(|i| (0.37 * i as f64).cos() + 0.1).collect(),
            (0..n).map(|i| (-0.2 * i as f64).exp() - 0.3).collect(),
        ];
        let mut x = vec![0.0; n];
        let mut reused = vec![0.0; n];
        for (tau, r) in [(1e-3, &rhs[0]), (1e-3, &rhs[1]), (4e-3, &rhs[1])] {
            sys.solve_damped_mass(tau, r, &mut x);
            let mut mx = vec![0.0; n];
            sys.mass_mul(&x, &mut mx);
            let mut cx = vec![0.0; n];
            sys.add_damping_forces(&x, &mut cx);
            let scale = r.iter().fold(0.0f64, |m, r| m.max(r.abs()));
            for i in 0..n {
                let res = mx[i] - 0.5 * tau * cx[i] - r[i];
                assert!(
                    res.abs() < 1e-10 * scale,
                    "τ {tau}, row {i}: residual {res:e}"
                );
            }
            // C is symmetric and positive semi-definite: xᵀCx = −x·(damping forces) ≥ 0
            let d: f64 = -(0..n).map(|i| x[i] * cx[i]).sum::<f64>();
            assert!(d > 0.0, "{d}");
            if tau == 1e-3 && std::ptr::eq(r, &rhs[1]) {
                reused.copy_from_slice(&x);
            }
        }
        // the reused factors give the fresh solve's bits
        sys.build_columns();
        sys.solve_damped_mass(1e-3, &rhs[1], &mut x);
        assert_eq!(x, reused);
    }
}
