//! Floating-frame chain of assumed-mode links: mass matrix M(q), generalized forces, energies.
//!
//! Generalized coordinates, link by link: q = [θᵢ, aᵢ (axial), bᵢ (transverse)]. Each link is a
//! body with frame origin Oᵢ, frame angle αᵢ and body velocities νᵢ = (V, ω, ė) (V = frame-origin
//! velocity in the frame's own axes). Its kinetic energy is Tᵢ = ½ νᵢᵀ 𝕄ᵢ(e) νᵢ (see
//! [`super::body`]). The chain kinematics of scenes.md (link i+1 clamped to the tip of link i and
//! turned by θᵢ₊₁: αᵢ₊₁ = αᵢ + ψᵢ(Lᵢ) + θᵢ₊₁, ψᵢ(Lᵢ) = vᵢ'(Lᵢ) for Euler links; behind a condensed
//! Timoshenko link the coordinate of a free joint is φ = ψᵢ(Lᵢ) + θᵢ₊₁ and αᵢ₊₁ = αᵢ + φ,
//! [`super::elbow`]) give νᵢ = Gᵢ(q) q̇ and ν̇ᵢ = Gᵢ q̈ + γᵢ(q, q̇), so
//! Lagrange's equations of the chain are the body equations projected by Gᵢᵀ:
//!
//!   Σᵢ Gᵢᵀ 𝕄ᵢ Gᵢ q̈ = Q − Σᵢ Gᵢᵀ (𝕄ᵢ γᵢ + hᵢ − Q_gravity,ᵢ)
//!
//! with hᵢ = 𝕄̇ᵢ νᵢ + (ω J P, −(J P)·V, −∂Tᵢ/∂e), P the body's linear momentum in its frame, and
//! Q the elastic, Kelvin–Voigt, joint spring/damper and applied torques. All per-step work is
//! O(N²) products of precomputed integrals — no spatial quadrature.

use super::body::{BodyScratch, body_terms};
use super::elbow::Elbow;
use super::link::{JointModel, LinkModel};
use super::section::SectionKind;
use crate::integrate::Stretch;
use crate::linalg::{cholesky_solve, cholesky_substitute, dot};

#[derive(Debug, Clone, Copy, Default)]
pub struct EnergyParts {
    pub kinetic: f64,
    pub strain: f64,
    pub joint_spring: f64,
    pub gravity: f64,
}

/// Per-link state of the last evaluation.
#[derive(Debug, Clone)]
pub(crate) struct LinkWork {
    /// Rows (V_x, V_y, ω) of Gᵢ, each of length N.
    pub gr: Vec<f64>,
    /// Convective part of V̇ (the ω part is identically zero for this joint convention).
    pub gamma: [f64; 2],
    pub alpha: f64,
    pub origin: [f64; 2],
    pub nu: Vec<f64>,
    pub mb: Vec<f64>,
    pub h: Vec<f64>,
    pub qg: Vec<f64>,
    pub x: Vec<f64>,
    pub u: Vec<f64>,
    pub scratch: BodyScratch,
}

#[derive(Debug, Clone)]
pub struct Chain {
    pub links: Vec<LinkModel>,
    pub joints: Vec<JointModel>,
    pub gravity: Option<[f64; 2]>,
    /// Number of generalized coordinates.
    pub n: usize,
    /// Indices of free / prescribed coordinates.
    pub free: Vec<usize>,
    pub prescribed: Vec<usize>,
    pub(crate) work: Vec<LinkWork>,
    /// M(q), N × N row-major, and the force side of the last evaluation.
    pub(crate) mass: Vec<f64>,
    pub(crate) force: Vec<f64>,
    wrows: Vec<f64>,
    mff: Vec<f64>,
    rhs_f: Vec<f64>,
    /// Torques the prescribed joints needed at the last `accelerations` call (per joint; 0 for free).
    pub(crate) tau_prescribed: Vec<f64>,
    /// Constant generalized force of the scene's `[statics]` loads, applied as a step at t = 0
    /// (N entries; None without loads). Its work is fᵀ(q − q₀).
    pub step_load: Option<Vec<f64>>,
    /// Per joint: the condensation with the elbow when the joint is free and its parent link
    /// a condensed Timoshenko link ([`super::elbow`]); the joint coordinate is then φ.
    pub elbows: Vec<Option<Elbow>>,
    /// The stretch between the torque laws' discontinuities being integrated: the laws are
    /// read at [`Stretch::input_time`].
    pub(crate) stretch: Stretch,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingularMass;

impl Chain {
    pub fn new(links: Vec<LinkModel>, joints: Vec<JointModel>, gravity: Option<[f64; 2]>) -> Self {
        let n = links.last().map_or(0, |l| l.a0 + l.ne());
        let mut free = Vec::new();
        let mut prescribed = Vec::new();
        for (i, l) in links.iter().enumerate() {
            if joints[i].prescribed.is_some() {
                prescribed.push(l.theta);
            } else {
                free.push(l.theta);
            }
            free.extend(l.a0..l.a0 + l.ne());
        }
        let work = links
            .iter()
            .map(|l| {
                let d = l.body_dim();
                LinkWork {
                    gr: vec![0.0; 3 * n],
                    gamma: [0.0; 2],
                    alpha: 0.0,
                    origin: [0.0; 2],
                    nu: vec![0.0; d],
                    mb: vec![0.0; d * d],
                    h: vec![0.0; d],
                    qg: vec![0.0; d],
                    x: vec![0.0; d * n],
                    u: vec![0.0; d],
                    scratch: BodyScratch::new(l.na(), l.nb(), l.nc()),
                }
            })
            .collect();
        let nf = free.len();
        let nj = joints.len();
        Chain {
            links,
            joints,
            gravity,
            n,
            free,
            prescribed,
            work,
            mass: vec![0.0; n * n],
            force: vec![0.0; n],
            wrows: vec![0.0; 2 * n],
            mff: vec![0.0; nf * nf],
            rhs_f: vec![0.0; nf],
            tau_prescribed: vec![0.0; nj],
            step_load: None,
            elbows: vec![None; nj],
            stretch: Stretch::OPEN,
        }
    }

    /// Switches every free joint after a condensed Timoshenko link to the frame-to-frame
    /// coordinate φ with the elbow in the condensation ([`super::elbow`]).
    pub fn attach_elbows(&mut self) -> Result<(), String> {
        for i in 1..self.links.len() {
            let (p, j) = (&self.links[i - 1], &self.joints[i]);
            if j.prescribed.is_some() || p.section.kind != SectionKind::TimoshenkoCondensed {
                continue;
            }
            let Some(blocks) = &p.section.blocks else {
                continue;
            };
            let mut e = Elbow::new(i - 1, p.nb(), blocks, j.stiffness, j.set_point, j.damping)
                .map_err(|m| format!("link {}: {m}", i))?;
            if let Some(law) = &j.torque {
                e.book_torque_steps(law);
            }
            self.elbows[i] = Some(e);
        }
        Ok(())
    }

    /// Applied work and section-relaxation loss of the applied-torque jumps behind elbows at
    /// times ≤ t (booked by the ledger beside the integrated powers, [`Elbow::book_torque_steps`]).
    pub fn torque_step_books(&self, t: f64) -> (f64, f64) {
        self.elbows
            .iter()
            .flatten()
            .map(|e| e.torque_step_books(t))
            .fold((0.0, 0.0), |(w, l), (a, b)| (w + a, l + b))
    }

    /// Whether link i's bending block is condensed with its child's elbow.
    fn has_elbow_child(&self, i: usize) -> bool {
        self.elbows.get(i + 1).is_some_and(|e| e.is_some())
    }

    /// Joint angle θᵢ (after `evaluate`): the coordinate, or φ − χᵀc behind an elbow.
    pub fn joint_angle(&self, i: usize, q: &[f64]) -> f64 {
        let th = q[self.links[i].theta];
        match &self.elbows[i] {
            Some(e) => e.angle(th),
            None => th,
        }
    }

    /// Joint angle θᵢ with the elbow section's first-order lag (after `evaluate`).
    pub fn joint_angle_with_lag(&self, i: usize, q: &[f64], qd: &[f64]) -> f64 {
        let th = self.joint_angle(i, q);
        match &self.elbows[i] {
            Some(e) => {
                let p = &self.links[e.parent];
                th + e.angle_lag(&qd[p.b0..p.b0 + e.nb], qd[self.links[i].theta])
            }
            None => th,
        }
    }

    /// Joint rate θ̇ᵢ: the coordinate's rate, or wᵀ(ḃ, φ̇) behind an elbow.
    pub fn joint_rate(&self, i: usize, qd: &[f64]) -> f64 {
        let th = qd[self.links[i].theta];
        match &self.elbows[i] {
            Some(e) => {
                let p = &self.links[e.parent];
                e.rate(&qd[p.b0..p.b0 + e.nb], th)
            }
            None => th,
        }
    }

    /// ∂θ̇ᵢ/∂q̇ as (coordinate, coefficient) pairs written into `out` (returns the count).
    pub fn joint_rate_gradient(&self, i: usize, out: &mut [(usize, f64)]) -> usize {
        let th = self.links[i].theta;
        match &self.elbows[i] {
            Some(e) => {
                let p = &self.links[e.parent];
                for k in 0..e.nb {
                    out[k] = (p.b0 + k, e.w[k]);
                }
                out[e.nb] = (th, e.w[e.nb]);
                e.nb + 1
            }
            None => {
                out[0] = (th, 1.0);
                1
            }
        }
    }

    /// Initial coordinate and rate of joint i from the scene's θ(0), θ̇(0): the links' centre
    /// lines straight at those angles and rates (elastic coordinates at rest). Behind an elbow
    /// the coordinate is the frame-to-frame angle φ, which at b = 0 is the angle between the
    /// centre lines, so φ(0) = θ(0); the massless sections then take their balance, and the
    /// reported θ = φ − χᵀc starts off θ(0) by the tip section's turn (data's scene docs).
    pub fn initial_joint_coordinate(&self, i: usize) -> (f64, f64) {
        let j = &self.joints[i];
        (j.initial_angle, j.initial_rate)
    }

    /// Visits the rows of link i's Kelvin–Voigt damping D ẋ over its bending block (over
    /// (b, φ) with D_kv when condensed with its child's elbow): `visit(index in q, (D ẋ)_row)`,
    /// in row order.
    fn kelvin_voigt_rows(&self, i: usize, qd: &[f64], mut visit: impl FnMut(usize, f64)) {
        let l = &self.links[i];
        if let Some(Some(e)) = self.elbows.get(i + 1) {
            let bd = &qd[l.b0..l.b0 + e.nb];
            let th = self.links[i + 1].theta;
            let phid = qd[th];
            for r in 0..e.nb {
                visit(l.b0 + r, e.kv_row(r, bd, phid));
            }
            visit(th, e.kv_row(e.nb, bd, phid));
            return;
        }
        if !l.has_kelvin_voigt() {
            return;
        }
        let nbc = l.nbc();
        let xd = &qd[l.b0..l.b0 + nbc];
        for r in 0..nbc {
            visit(l.b0 + r, dot(&l.section.dbc[r * nbc..(r + 1) * nbc], xd));
        }
    }

    /// Adds the Kelvin–Voigt power ẋᵀD ẋ of link i's bending block to `p`.
    pub fn add_kelvin_voigt_power(&self, i: usize, qd: &[f64], p: &mut f64) {
        self.kelvin_voigt_rows(i, qd, |g, row| *p += qd[g] * row);
    }

    /// ∂(Kelvin–Voigt power of link i)/∂q̇ = 2 D ẋ added into `out` (length N).
    pub fn kelvin_voigt_power_gradient(&self, i: usize, qd: &[f64], out: &mut [f64]) {
        self.kelvin_voigt_rows(i, qd, |g, row| out[g] += 2.0 * row);
    }

    /// Kinematics, body terms, M(q) and the force side f(q, q̇, t) (everything except the
    /// actuator torques of prescribed joints).
    pub fn evaluate(&mut self, t: f64, q: &[f64], qd: &[f64]) {
        let n = self.n;
        let t_law = self.stretch.input_time(t);
        self.mass.iter_mut().for_each(|v| *v = 0.0);
        match &self.step_load {
            Some(f) => self.force.copy_from_slice(f),
            None => self.force.iter_mut().for_each(|v| *v = 0.0),
        }
        let g = self.gravity;
        for i in 0..self.links.len() {
            // Frame kinematics of link i.
            if i == 0 {
                let th = self.links[0].theta;
                let w = &mut self.work[0];
                w.gr.iter_mut().for_each(|v| *v = 0.0);
                w.gr[2 * n + th] = 1.0;
                w.gamma = [0.0; 2];
                w.alpha = q[th];
                w.origin = [0.0; 2];
                w.nu[0] = 0.0;
                w.nu[1] = 0.0;
                w.nu[2] = qd[th];
            } else {
                self.propagate(i - 1, q, qd);
            }
            // Elastic body velocities.
            {
                let (a0, ne) = (self.links[i].a0, self.links[i].ne());
                let w = &mut self.work[i];
                w.nu[3..3 + ne].copy_from_slice(&qd[a0..a0 + ne]);
            }
            let link = &self.links[i];
            let w = &mut self.work[i];
            let a = &q[link.a0..link.a0 + link.na()];
            let b = &q[link.b0..link.b0 + link.nb()];
            let g_loc = g.map(|gv| {
                let (s, c) = w.alpha.sin_cos();
                [c * gv[0] + s * gv[1], -s * gv[0] + c * gv[1]]
            });
            body_terms(
                link,
                a,
                b,
                &w.nu,
                g_loc,
                &mut w.mb,
                &mut w.h,
                &mut w.qg,
                &mut w.scratch,
            );
            // Project: M += Gᵀ 𝕄 G, f += Gᵀ (Q_g − 𝕄 γ − h). Gᵢ has no column past the
            // link's own coordinates (`span`): the coordinates are ordered link by link.
            let d = link.body_dim();
            let span = link.a0 + link.ne();
            for l in 0..d {
                let mrow = &w.mb[l * d..(l + 1) * d];
                let xrow = &mut w.x[l * n..l * n + span];
                for c in 0..span {
                    xrow[c] = mrow[0] * w.gr[c] + mrow[1] * w.gr[n + c] + mrow[2] * w.gr[2 * n + c];
                }
                // Elastic body coordinates e = [a, b, c] are contiguous in q from a0.
                for m in 3..d {
                    xrow[link.a0 + m - 3] += mrow[m];
                }
                w.u[l] = w.qg[l] - w.h[l] - mrow[0] * w.gamma[0] - mrow[1] * w.gamma[1];
            }
            for l in 0..3 {
                let grow = &w.gr[l * n..l * n + span];
                let xrow = &w.x[l * n..l * n + span];
                for r in 0..span {
                    let gr = grow[r];
                    if gr != 0.0 {
                        let mrow = &mut self.mass[r * n..r * n + span];
                        for c in 0..span {
                            mrow[c] += gr * xrow[c];
                        }
                        self.force[r] += gr * w.u[l];
                    }
                }
            }
            for l in 3..d {
                let gl = link.a0 + l - 3;
                let xrow = &w.x[l * n..l * n + span];
                let mrow = &mut self.mass[gl * n..gl * n + span];
                for c in 0..span {
                    mrow[c] += xrow[c];
                }
                self.force[gl] += w.u[l];
            }
            // Elastic forces of the bending block x = [b, c]: −K x − D ẋ; axial −K_a a.
            let nbc = link.nbc();
            let xb = &q[link.b0..link.b0 + nbc];
            let xbd = &qd[link.b0..link.b0 + nbc];
            let sec = &link.section;
            // Behind an elbow the bending block is condensed with the joint (below).
            let own = !self.elbows.get(i + 1).is_some_and(|e| e.is_some());
            for r in 0..if own { nbc } else { 0 } {
                let mut fr = dot(&sec.kbc[r * nbc..(r + 1) * nbc], xb);
                if !sec.dbc.is_empty() {
                    fr += dot(&sec.dbc[r * nbc..(r + 1) * nbc], xbd);
                }
                self.force[link.b0 + r] -= fr;
            }
            let na = link.na();
            for r in 0..na {
                let row = &link.ints.ka[r * na..(r + 1) * na];
                self.force[link.a0 + r] -= dot(row, a);
            }
            // Joint laws (free joints only; a prescribed joint's actuator is the unknown torque).
            let j = &self.joints[i];
            if let Some(e) = self.elbows[i].as_mut() {
                // f_b = −(K_bb b + K_bc c) − (D_eff ẋ)_b, f_φ = τ − K(θ − θ₀) − (D_eff ẋ)_φ.
                let th = link.theta;
                let p = &self.links[e.parent];
                let (nb, nc) = (e.nb, e.nc);
                let b = &q[p.b0..p.b0 + nb];
                let bd = &qd[p.b0..p.b0 + nb];
                let tau = j.torque.as_ref().map_or(0.0, |law| law.torque(t_law));
                e.condense(b, q[th], tau);
                let rate = e.rate(bd, qd[th]);
                let blk = &e.blocks;
                for r in 0..nb {
                    let fr = dot(&blk.kbb[r * nb..(r + 1) * nb], b)
                        + dot(&blk.kbc[r * nc..(r + 1) * nc], &e.c)
                        + e.kv_row(r, bd, qd[th])
                        + e.damping * rate * e.w[r];
                    self.force[p.b0 + r] -= fr;
                }
                self.force[th] += tau
                    - e.stiffness * (e.angle(q[th]) - e.set_point)
                    - e.kv_row(nb, bd, qd[th])
                    - e.damping * rate * e.w[nb];
            } else if j.prescribed.is_none() {
                let th = link.theta;
                let mut tau = -j.stiffness * (q[th] - j.set_point) - j.damping * qd[th];
                if let Some(law) = &j.torque {
                    tau += law.torque(t_law);
                }
                self.force[th] += tau;
            }
        }
        // Exact symmetry of M (the projections are symmetric up to summation order).
        for r in 0..n {
            for c in 0..r {
                let v = 0.5 * (self.mass[r * n + c] + self.mass[c * n + r]);
                self.mass[r * n + c] = v;
                self.mass[c * n + r] = v;
            }
        }
    }

    /// Frame kinematics of link i+1 from link i (whose body terms are already computed). The
    /// columns of Gᵢ₊₁ past link i+1's own coordinates stay zero (never written).
    fn propagate(&mut self, i: usize, q: &[f64], qd: &[f64]) {
        let n = self.n;
        let (head, tail) = self.work.split_at_mut(i + 1);
        let wi = &head[i];
        let wn = &mut tail[0];
        let li = &self.links[i];
        let ln = &self.links[i + 1];
        let sc = &wi.scratch;
        let (pl, wl, pld) = (sc.p_tip, sc.w_tip, sc.pd_tip);
        let fsf = if li.foreshortening { 1.0 } else { 0.0 };
        // Rows of the tip velocity w_L = B_L Gᵢ q̇ in link-i axes.
        let span = ln.a0 + ln.ne();
        let (wx, wy) = self.wrows.split_at_mut(n);
        for c in 0..span {
            wx[c] = wi.gr[c] - pl[1] * wi.gr[2 * n + c];
            wy[c] = wi.gr[n + c] + pl[0] * wi.gr[2 * n + c];
        }
        for k in 0..li.na() {
            wx[li.a0 + k] += li.ints.psi_l[k];
        }
        for k in 0..li.nb() {
            wx[li.b0 + k] += -fsf * sc.slb[k];
            wy[li.b0 + k] += li.ints.phi_l[k];
        }
        let bdi = &qd[li.b0..li.b0 + li.nb()];
        // Joint convention: the next frame turns with the tip cross-section, ψᵢ(Lᵢ) = r(L)ᵀe.
        // Behind an elbow the coordinate is the frame-to-frame angle φ: no ψᵢ(Lᵢ) term.
        let ne = if self.elbows[i + 1].is_some() {
            0
        } else {
            li.ne()
        };
        let rot_l = &li.section.rot_l[..ne];
        let delta = dot(rot_l, &q[li.a0..li.a0 + ne]) + q[ln.theta];
        let delta_d = dot(rot_l, &qd[li.a0..li.a0 + ne]) + qd[ln.theta];
        let (s, c) = delta.sin_cos();
        // V_{i+1} = R(−δ) w_L.
        for col in 0..span {
            let (x, y) = (wx[col], wy[col]);
            wn.gr[col] = c * x + s * y;
            wn.gr[n + col] = -s * x + c * y;
            wn.gr[2 * n + col] = wi.gr[2 * n + col];
        }
        for k in 0..ne {
            wn.gr[2 * n + li.a0 + k] += rot_l[k];
        }
        wn.gr[2 * n + ln.theta] += 1.0;
        wn.nu[0] = c * wl[0] + s * wl[1];
        wn.nu[1] = -s * wl[0] + c * wl[1];
        wn.nu[2] = wi.nu[2] + delta_d;
        // γ_{i+1} = R(−δ)[γᵢ + Ḃ_L νᵢ − δ̇ J w_L], Ḃ_L ν = ω J ṗ_L + (−ḃᵀ S_L ḃ, 0).
        let om = wi.nu[2];
        let bsb = if li.foreshortening {
            dot(bdi, &sc.slbd)
        } else {
            0.0
        };
        let gx = wi.gamma[0] - om * pld[1] - bsb + delta_d * wl[1];
        let gy = wi.gamma[1] + om * pld[0] - delta_d * wl[0];
        wn.gamma = [c * gx + s * gy, -s * gx + c * gy];
        let (sa, ca) = wi.alpha.sin_cos();
        wn.origin = [
            wi.origin[0] + ca * pl[0] - sa * pl[1],
            wi.origin[1] + sa * pl[0] + ca * pl[1],
        ];
        wn.alpha = wi.alpha + delta;
    }

    /// Solves for q̈ (free part from the equations, prescribed part from the motion law) and
    /// stores the actuator torques the prescribed joints needed. Requires `evaluate` first.
    pub fn accelerations(&mut self, t: f64, qdd: &mut [f64]) -> Result<(), SingularMass> {
        let n = self.n;
        for (i, j) in self.joints.iter().enumerate() {
            if let Some((_, _, acc)) = j.prescribed_state(t) {
                qdd[self.links[i].theta] = acc;
            }
        }
        let nf = self.free.len();
        for (r, &gr) in self.free.iter().enumerate() {
            let mut v = self.force[gr];
            for &p in &self.prescribed {
                v -= self.mass[gr * n + p] * qdd[p];
            }
            self.rhs_f[r] = v;
            for (c, &gc) in self.free.iter().enumerate() {
                self.mff[r * nf + c] = self.mass[gr * n + gc];
            }
        }
        cholesky_solve(&mut self.mff, nf, &mut self.rhs_f).map_err(|_| SingularMass)?;
        for (r, &gr) in self.free.iter().enumerate() {
            qdd[gr] = self.rhs_f[r];
        }
        for (i, link) in self.links.iter().enumerate() {
            self.tau_prescribed[i] = if self.joints[i].prescribed.is_some() {
                let p = link.theta;
                let row = &self.mass[p * n..(p + 1) * n];
                dot(row, qdd) - self.force[p]
            } else {
                0.0
            };
        }
        Ok(())
    }

    /// Stored energies at the last evaluated state (call `evaluate` first). No allocation.
    pub fn energy(&self, q: &[f64]) -> EnergyParts {
        let quad = |m: &[f64], n: usize, x: &[f64]| -> f64 {
            let mut acc = 0.0;
            for r in 0..n {
                acc += x[r] * dot(&m[r * n..(r + 1) * n], x);
            }
            acc
        };
        let mut e = EnergyParts::default();
        for (i, link) in self.links.iter().enumerate() {
            let w = &self.work[i];
            e.kinetic += 0.5 * quad(&w.mb, link.body_dim(), &w.nu);
            let nbc = link.nbc();
            match self.elbows.get(i + 1) {
                Some(Some(el)) => e.strain += el.strain(&q[link.b0..link.b0 + el.nb]),
                _ => e.strain += 0.5 * quad(&link.section.kbc, nbc, &q[link.b0..link.b0 + nbc]),
            }
            let na = link.na();
            if na > 0 {
                let a = &q[link.a0..link.a0 + na];
                // ½∫EA u'² of the stretch (the von Kármán strain, see super::body).
                e.strain += 0.5 * quad(&link.ints.ka, na, a);
            }
            let j = &self.joints[i];
            if let Some(el) = &self.elbows[i] {
                e.joint_spring +=
                    0.5 * el.stiffness * (el.angle(q[link.theta]) - el.set_point).powi(2);
            } else if j.prescribed.is_none() {
                e.joint_spring += 0.5 * j.stiffness * (q[link.theta] - j.set_point).powi(2);
            }
            if let Some(gv) = self.gravity {
                // V_g = −g·(m_tot O + R p̄).
                let (s, c) = w.alpha.sin_cos();
                let pb = w.scratch.p_bar;
                let r = [c * pb[0] - s * pb[1], s * pb[0] + c * pb[1]];
                let mt = link.ints.m + link.tip_mass;
                e.gravity -= gv[0] * (mt * w.origin[0] + r[0]) + gv[1] * (mt * w.origin[1] + r[1]);
            }
        }
        e
    }

    /// Tip of link i: inertial position, and its frame angle α (after `evaluate`).
    pub fn tip_position(&self, i: usize) -> [f64; 2] {
        let w = &self.work[i];
        let pl = w.scratch.p_tip;
        let (s, c) = w.alpha.sin_cos();
        [
            w.origin[0] + c * pl[0] - s * pl[1],
            w.origin[1] + s * pl[0] + c * pl[1],
        ]
    }

    pub fn frame_angle(&self, i: usize) -> f64 {
        self.work[i].alpha
    }

    /// Inertial tip-velocity Jacobian of link i (2 × N row-major): ṙ_tip = J q̇ (after
    /// `evaluate`). Provided for constraint/impact formulations.
    pub fn tip_jacobian(&self, i: usize, out: &mut [f64]) {
        let n = self.n;
        let w = &self.work[i];
        let li = &self.links[i];
        let sc = &w.scratch;
        let pl = sc.p_tip;
        let fsf = if li.foreshortening { 1.0 } else { 0.0 };
        let (wx, wy) = out.split_at_mut(n);
        for c in 0..n {
            wx[c] = w.gr[c] - pl[1] * w.gr[2 * n + c];
            wy[c] = w.gr[n + c] + pl[0] * w.gr[2 * n + c];
        }
        for k in 0..li.na() {
            wx[li.a0 + k] += li.ints.psi_l[k];
        }
        for k in 0..li.nb() {
            wx[li.b0 + k] += -fsf * sc.slb[k];
            wy[li.b0 + k] += li.ints.phi_l[k];
        }
        let (s, c) = w.alpha.sin_cos();
        for col in 0..n {
            let (x, y) = (wx[col], wy[col]);
            wx[col] = c * x - s * y;
            wy[col] = s * x + c * y;
        }
    }

    /// Velocity-dependent part of the inertial tip acceleration of link i, r̈_tip = J q̈ + c(q, q̇)
    /// (after `evaluate`; requires no prescribed joint before link i, whose q̈ would enter J q̈).
    /// In the link frame ẇ_L + ω J w_L with w_L = V + ω J p + ṗ gives
    /// c = R(α)[γ + ω J ṗ + (−f ḃᵀS_L ḃ, 0) + ω J w_L].
    pub fn tip_convective_acceleration(&self, i: usize) -> [f64; 2] {
        let w = &self.work[i];
        let li = &self.links[i];
        let sc = &w.scratch;
        let (pld, wl) = (sc.pd_tip, sc.w_tip);
        let om = w.nu[2];
        let bsb = if li.foreshortening {
            let nb = li.nb();
            dot(&w.nu[3 + li.na()..3 + li.na() + nb], &sc.slbd)
        } else {
            0.0
        };
        let cx = w.gamma[0] - om * pld[1] - bsb - om * wl[1];
        let cy = w.gamma[1] + om * pld[0] + om * wl[0];
        let (s, c) = w.alpha.sin_cos();
        [c * cx - s * cy, s * cx + c * cy]
    }

    /// Solves M_ff x = b with the Cholesky factor of the free block left by the last successful
    /// `accelerations` call (b of length = number of free coordinates, overwritten by x).
    pub fn solve_free_mass(&self, b: &mut [f64]) {
        cholesky_substitute(&self.mff, self.free.len(), b);
    }

    /// Tangents of the elastic, Kelvin–Voigt and joint spring/damper forces at q: writes
    /// K_t = −∂F/∂q and D_t = −∂F/∂q̇ of those terms (N × N row-major, overwritten). They are
    /// the stiff part of the force side: the bending block K, D of every link
    /// ([`super::section`]), the axial stiffness K_a of the stretch (its strain is the von
    /// Kármán strain, [`super::body`]), and the joint spring and damper of each free joint. Inertial (M(q), the
    /// convective and centrifugal terms), gravity and contact terms are left out: they are
    /// bounded by the rigid-body rates, not by the Ritz frequencies. No allocation.
    pub fn elastic_tangent(&self, kt: &mut [f64], dt: &mut [f64]) {
        let n = self.n;
        kt.iter_mut().for_each(|v| *v = 0.0);
        dt.iter_mut().for_each(|v| *v = 0.0);
        for (i, link) in self.links.iter().enumerate() {
            let nbc = if self.has_elbow_child(i) {
                0
            } else {
                link.nbc()
            };
            let sec = &link.section;
            for r in 0..nbc {
                let row = link.b0 + r;
                for c in 0..nbc {
                    kt[row * n + link.b0 + c] = sec.kbc[r * nbc + c];
                    if !sec.dbc.is_empty() {
                        dt[row * n + link.b0 + c] = sec.dbc[r * nbc + c];
                    }
                }
            }
            let na = link.na();
            for r in 0..na {
                for c in 0..na {
                    kt[(link.a0 + r) * n + link.a0 + c] = link.ints.ka[r * na + c];
                }
            }
            let j = &self.joints[i];
            if let Some(e) = &self.elbows[i] {
                // H and D_eff over x = (b of the parent, φ).
                let p = &self.links[e.parent];
                let nx = e.nb + 1;
                let idx = |k: usize| if k < e.nb { p.b0 + k } else { link.theta };
                for r in 0..nx {
                    for c in 0..nx {
                        let (gr, gc) = (idx(r), idx(c));
                        kt[gr * n + gc] += e.h[r * nx + c];
                        let kv = if e.d_kv.is_empty() {
                            0.0
                        } else {
                            e.d_kv[r * nx + c]
                        };
                        dt[gr * n + gc] += kv + e.damping * e.w[r] * e.w[c];
                    }
                }
            } else if j.prescribed.is_none() {
                let th = link.theta;
                kt[th * n + th] += j.stiffness;
                dt[th * n + th] += j.damping;
            }
        }
    }

    /// M(q) of the last evaluation (row-major N × N).
    pub fn mass_matrix(&self) -> &[f64] {
        &self.mass
    }

    /// Force side f(q, q̇, t) of the last evaluation.
    pub fn force(&self) -> &[f64] {
        &self.force
    }
}
