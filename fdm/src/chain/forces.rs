//! The chain's forces and energies: the ghost-node bending energy (clamp ghosts, link 1's tip
//! term) and its Kelvin–Voigt dissipation, the joint springs, dampers and torque laws, the
//! gravity potential of the lumped masses, the inertia terms ∂T/∂q − (∂p/∂q)q̇ and the momenta
//! p = M q̇, and the input/dissipation powers of the ledger (module docs of [`super`]).

use super::kinetic::{BE, TH, seg_energy, seg_grad};
use super::model::TwoLinkChain;
use crate::link::FloatingLink;
use crate::output::Outputs;
use crate::system::System;

impl TwoLinkChain {
    /// Link 1's tip term of the trapezoid bending energy, ¼h c κ_r² with κ_r = (y + u)/h²
    /// (u = v_{r−1}, v_r = 0, y = v_{r+1}): (energy, ∂/∂y = ∂/∂u).
    pub(super) fn tip_bending(h: f64, c: f64, u: f64, y: f64) -> (f64, f64) {
        let h3 = h * h * h;
        (c * (y + u).powi(2) / (4.0 * h3), c * (y + u) / (2.0 * h3))
    }

    /// Bending energy of one link in the tip-chord frame with the clamp ghost x: the
    /// single-link energy on u (u_r = 0) with κ₀ = 2u₁/h² replaced by (u₁ + x)/h². Adds −∂/∂u
    /// into f (its tip entry left untouched) and returns (energy, −∂/∂x).
    fn ghost_bending(h: f64, c: f64, u: &[f64], x: f64, f: &mut [f64]) -> (f64, f64) {
        let g = Self::ghost_bending_forces(h, c, u, x, f);
        (Self::ghost_bending_energy(h, c, u, x), g)
    }

    /// [`Self::ghost_bending`]'s forces alone: adds −∂/∂u into f and returns −∂/∂x.
    fn ghost_bending_forces(h: f64, c: f64, u: &[f64], x: f64, f: &mut [f64]) -> f64 {
        let r = u.len();
        let tip = f[r - 1];
        FloatingLink::add_bending_forces(h, c, u, f);
        f[r - 1] = tip;
        let h3 = h * h * h;
        f[0] += 2.0 * c * u[0] / h3;
        let g = c * (u[0] + x) / (2.0 * h3);
        f[0] -= g;
        -g
    }

    /// [`Self::ghost_bending`]'s energy alone.
    fn ghost_bending_energy(h: f64, c: f64, u: &[f64], x: f64) -> f64 {
        let e = FloatingLink::bending_energy(h, c, u);
        let h3 = h * h * h;
        e - c * u[0] * u[0] / h3 + c * (u[0] + x).powi(2) / (4.0 * h3)
    }

    /// Generalized momenta p = M(q) q̇ of the whole chain (Pᵀ of the kernel's momenta in the
    /// clamp-tangent frames plus the section rotary inertias).
    pub fn momenta(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.frames(q, qd);
        out.iter_mut().for_each(|x| *x = 0.0);
        self.inertia
            .momenta_at(&self.qk, &self.vk, &mut self.points, out);
        self.kinetic_transpose(out);
        self.add_section_inertias(qd, out);
    }

    pub fn total_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let mut e = [0.0; 4];
        let k = self.ledger_names().0.len();
        self.stored_energies(0.0, q, v, &mut e[..k]);
        e.iter().sum()
    }

    /// Gravity potential V_g = −g·Σ m r of the lumped masses at the kernel coordinates `qk`
    /// ([`Self::to_kinetic`]); writes −∂V_g/∂q' (the kernel's coordinates, tip entries
    /// included) into `out` when given. With A(α) = g·(cos α, sin α), B(α) = g·(−sin α, cos α),
    /// ∂A/∂α = B, ∂B/∂α = −A:
    /// V_g = −[A(α₁)X₁ + B(α₁)Y₁ + A(α₂)X₂ + B(α₂)Y₂], X₁ = Σm₁x + M₂L₁ − Σ_seg c₁ ½h g²
    /// (foreshortening; c₁ = outboard mass of link 1 + M₂), Y₁ = Σm₁v + M₂V (link 2 rides on
    /// the elbow), X₂ = Q₂ − Ψ, Y₂ = Σm₂w: the positions the kinetic energy uses, so the
    /// gravity work is exactly −ΔV_g.
    pub(super) fn gravity_potential(&self, qk: &[f64], out: Option<&mut [f64]>) -> f64 {
        let Some([gx, gy]) = self.gravity else {
            return 0.0;
        };
        let ine = &self.inertia;
        let (v, w) = (&qk[ine.iv()], &qk[ine.iw()]);
        let ab = |a: f64| {
            let (s, c) = a.sin_cos();
            (gx * c + gy * s, -gx * s + gy * c)
        };
        let (a1, b1) = ab(qk[TH]);
        let (a2, b2) = ab(qk[BE]);
        let mut x1 = ine.mass2 * ine.l1;
        let mut y1 = 0.0;
        for k in 0..ine.r1 {
            x1 += ine.m1[k] * (k + 1) as f64 * ine.h1;
            y1 += ine.m1[k] * v[k];
        }
        y1 += ine.mass2 * v[ine.r1 - 1];
        if ine.fs1 {
            x1 -= seg_energy(v, ine.h1, Some(&self.mu1g));
        }
        let mut x2 = ine.q2;
        let y2: f64 = (0..ine.r2).map(|j| ine.m2[j] * w[j]).sum();
        if ine.fs2 {
            x2 -= seg_energy(w, ine.h2, Some(&ine.mu2));
        }
        if let Some(out) = out {
            out[TH] += b1 * x1 - a1 * y1;
            out[BE] += b2 * x2 - a2 * y2;
            for k in 0..ine.r1 {
                let mut m = ine.m1[k];
                if k == ine.r1 - 1 {
                    m += ine.mass2;
                }
                let mut f = b1 * m;
                if ine.fs1 {
                    f -= a1 * seg_grad(v, ine.h1, Some(&self.mu1g), k);
                }
                out[2 + k] += f;
            }
            for j in 0..ine.r2 {
                let mut f = b2 * ine.m2[j];
                if ine.fs2 {
                    f -= a2 * seg_grad(w, ine.h2, Some(&ine.mu2), j);
                }
                out[2 + ine.r1 + j] += f;
            }
        }
        -(a1 * x1 + b1 * y1 + a2 * x2 + b2 * y2)
    }

    /// Adds the gravity forces −∂V_g/∂q at the kernel coordinates `qk` of the last
    /// [`Self::frames`] into `out` (Pᵀ of the kernel's).
    fn add_gravity_forces(&mut self, out: &mut [f64]) {
        if self.gravity.is_none() {
            return;
        }
        let mut gk = std::mem::take(&mut self.gk);
        gk.iter_mut().for_each(|x| *x = 0.0);
        self.gravity_potential(&self.qk, Some(&mut gk));
        self.kinetic_transpose(&mut gk);
        for (o, g) in out.iter_mut().zip(&gk) {
            *o += g;
        }
        self.gk = gk;
    }

    /// Stores the input/dissipation powers at (q, q̇) — without the force evaluation — and
    /// writes them as [`System::powers`] does. The velocity form evaluates the forces of a step
    /// end at the *predicted* velocity; its ledger takes the powers at the final one (the
    /// overdamped clamp-rotation modes make the two differ at O(1) near the step bound).
    pub(crate) fn powers_at(&mut self, t: f64, v: &[f64], out: &mut [f64]) {
        if let Some(tf) = &self.timo {
            let pw = tf.powers(v);
            self.power = [0.0, pw[0], pw[1]];
            self.powers(out);
            return;
        }
        self.vc.copy_from_slice(v);
        for s in self.ghosts() {
            self.vc[s] = 0.0;
        }
        let (iv, iw) = (self.inertia.iv(), self.inertia.iw());
        let mut p_kv = 0.0;
        if let Some(y) = self.tip_ghost {
            let u = v[self.inertia.i_tip1() - 1];
            p_kv += 2.0 * Self::tip_bending(self.hs[0], self.links[0].gamma, u, v[y]).0;
        }
        for (link, range) in [iv, iw].into_iter().enumerate() {
            let lp = &self.links[link];
            if lp.gamma == 0.0 {
                continue;
            }
            let d2 = Self::ghost_bending_energy(
                self.hs[link],
                lp.gamma,
                &self.vc[range],
                v[self.slots[link]],
            );
            p_kv += 2.0 * d2;
        }
        let (th1d, th2d) = (self.clamp_angle(v, 0), self.elbow(v));
        let j = &self.joints;
        self.power = [
            j[0].torque(t, self.closing) * th1d + j[1].torque(t, self.closing) * th2d,
            j[0].damping * th1d * th1d + j[1].damping * th2d * th2d,
            p_kv,
        ];
        self.powers(out);
    }

    /// rhs += scale·(∂T/∂q − (∂p/∂q)q̇) at the kernel copies (`qk`, `vk`) of the last
    /// [`Self::frames`] (Pᵀ of the kernel's inertia forces: P is constant); `scratch` (length
    /// n) is overwritten. The section inertias are constant.
    pub(super) fn add_inertia_terms(&mut self, scale: f64, scratch: &mut [f64], rhs: &mut [f64]) {
        self.inertia
            .inertia_forces_at(&self.qk, &self.vk, &mut self.points, scratch);
        self.kinetic_transpose(scratch);
        self.add_scaled_inertia(scale, scratch, rhs);
    }

    /// [`Self::add_inertia_terms`] with `scales[0]` at `vk`, then with `scales[1]` at the
    /// velocity `other` (the same q): both kernel passes at once. `scratch` (length n) is
    /// overwritten.
    pub(super) fn add_inertia_terms_pair(
        &mut self,
        scales: [f64; 2],
        other: &[f64],
        scratch: &mut [f64],
        rhs: &mut [f64],
    ) {
        let (mut vk2, mut f2) = (std::mem::take(&mut self.vk2), std::mem::take(&mut self.f2));
        self.to_kinetic(other, &mut vk2);
        // the rates' slopes: the current drift velocity's anew; the other's, in the velocity
        // form the last step's current one, from the last pair when its rates are those
        // numbers (the same quotients), which saves a division per station
        let [mut fresh, mut kept] = std::mem::take(&mut self.drift_slopes);
        self.inertia.rate_slopes(&self.vk, &mut fresh);
        let same = self.drift_slopes_valid
            && (self.drift_slopes_of.iter())
                .zip(&vk2)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            self.inertia.rate_slopes(&vk2, &mut kept);
        }
        self.drift_lanes
            .set(&self.inertia, [&self.vk, &vk2], [&fresh, &kept]);
        self.inertia.inertia_forces_lanes(
            &self.qk,
            &self.points.shape,
            [&self.vk, &vk2],
            &self.drift_lanes,
            &mut self.inertia_lanes,
            [&mut scratch[..], &mut f2[..]],
        );
        self.drift_slopes_of.copy_from_slice(&self.vk);
        self.drift_slopes_valid = true;
        self.drift_slopes = [kept, fresh];
        self.kinetic_transpose_z_lanes(&mut [&mut scratch[..], &mut f2[..]]);
        self.z_to_q_forces(scratch);
        self.z_to_q_forces(&mut f2);
        self.add_scaled_inertia(scales[0], scratch, rhs);
        self.add_scaled_inertia(scales[1], &f2, rhs);
        self.vk2 = vk2;
        self.f2 = f2;
    }

    /// rhs += scale·f for inertia-term forces f on q (the tip ghost moves no mass: not added).
    pub(super) fn add_scaled_inertia(&self, scale: f64, f: &[f64], rhs: &mut [f64]) {
        for i in 0..self.inertia.dofs() {
            rhs[i] += scale * f[i];
        }
    }

    /// Generalized forces Q − ∂V/∂q − ∂D/∂q̇ into `out`; sets the powers.
    pub(super) fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.split_reuse.valid = false;
        out.iter_mut().for_each(|x| *x = 0.0);
        if let Some(tf) = &self.timo {
            // condensed ψ (chain::timoshenko): −∂U_c/∂q − ∂D_c/∂q̇, no torque laws (refused)
            let (pw, [th, thd]) = tf.forces(q, v, out);
            let j = &self.joints;
            self.torques =
                [0, 1].map(|k| -j[k].stiffness * (th[k] - j[k].set_point) - j[k].damping * thd[k]);
            self.power = [0.0, pw[0], pw[1]];
            self.add_gravity_forces(out);
            return;
        }
        // the implicit kick (`implicit`) takes the damping forces separately
        let damp = !self.skip_damping;
        let (iv, iw) = (self.inertia.iv(), self.inertia.iw());
        let mut p_kv = 0.0;
        for (link, (range, f)) in [(iv, &mut self.fv), (iw, &mut self.fw)]
            .into_iter()
            .enumerate()
        {
            f.iter_mut().for_each(|x| *x = 0.0);
            let h = if link == 0 {
                self.inertia.h1
            } else {
                self.inertia.h2
            };
            let lp = &self.links[link];
            let slot = self.slots[link];
            let gx = Self::ghost_bending_forces(h, lp.ei, &self.qc[range.clone()], q[slot], f);
            let mut fx = gx;
            if lp.gamma != 0.0 && damp {
                let (d2, gv) =
                    Self::ghost_bending(h, lp.gamma, &self.vc[range.clone()], v[slot], f);
                p_kv += 2.0 * d2;
                fx += gv;
            }
            let r = f.len();
            f[r - 1] = fx; // the tip entry carries the ghost's force
            out[range].copy_from_slice(f);
        }
        if let Some(y) = self.tip_ghost {
            // link 1's tip term of the bending energy (elbow moment EIκ_r) and its Kelvin–Voigt
            // dissipation
            let (h, lp, u) = (self.hs[0], &self.links[0], self.inertia.i_tip1() - 1);
            let (_, g) = Self::tip_bending(h, lp.ei, q[u], q[y]);
            let (mut fy, mut fu) = (-g, -g);
            if lp.gamma != 0.0 && damp {
                let (d2, gv) = Self::tip_bending(h, lp.gamma, v[u], v[y]);
                p_kv += 2.0 * d2;
                fy -= gv;
                fu -= gv;
            }
            out[y] = fy;
            out[u] += fu;
        }
        let th2 = self.elbow(q);
        let th2d = self.elbow(v);
        let j = &self.joints;
        let ext = [j[0].torque(t, self.closing), j[1].torque(t, self.closing)];
        let th1 = self.clamp_angle(q, 0);
        let th1d = self.clamp_angle(v, 0);
        let dj = if damp {
            [j[0].damping, j[1].damping]
        } else {
            [0.0; 2]
        };
        let tau1 = ext[0] - j[0].stiffness * (th1 - j[0].set_point) - dj[0] * th1d;
        let tau2 = ext[1] - j[1].stiffness * (th2 - j[1].set_point) - dj[1] * th2d;
        // τ₁ on θ₁ (clamp angle of link 1); τ₂ on θ₂ = clamp angle of link 2 − θ − ψ(v)
        self.add_clamp(0, tau1, out);
        self.add_clamp(1, tau2, out);
        out[TH] -= tau2;
        for (i, c) in self.slope_stencil() {
            out[i] -= tau2 * c;
        }
        self.torques = [tau1, tau2];
        self.power = [
            ext[0] * th1d + ext[1] * th2d,
            j[0].damping * th1d * th1d + j[1].damping * th2d * th2d,
            p_kv,
        ];
        self.add_gravity_forces(out);
    }

    /// Adds the damping forces −∂D/∂q̇ = −C q̇ at `v` into `out`: Kelvin–Voigt (the ghost-node
    /// bending stencil on the rates, link 1's tip term) and the joint dampers (Euler links;
    /// the same terms as [`Self::forces`]). Linear in `v` with constant C.
    pub(crate) fn add_damping_forces(&mut self, v: &[f64], out: &mut [f64]) {
        let mut vd = std::mem::take(&mut self.vd);
        vd.copy_from_slice(v);
        for s in self.ghosts() {
            vd[s] = 0.0;
        }
        let (iv, iw) = (self.inertia.iv(), self.inertia.iw());
        for (link, (range, f)) in [(iv, &mut self.fv), (iw, &mut self.fw)]
            .into_iter()
            .enumerate()
        {
            let lp = &self.links[link];
            if lp.gamma == 0.0 {
                continue;
            }
            f.iter_mut().for_each(|x| *x = 0.0);
            let slot = self.slots[link];
            let gv =
                Self::ghost_bending_forces(self.hs[link], lp.gamma, &vd[range.clone()], v[slot], f);
            let r = f.len();
            f[r - 1] = gv;
            for (o, x) in out[range].iter_mut().zip(f.iter()) {
                *o += x;
            }
        }
        if let Some(y) = self.tip_ghost {
            let (h, lp, u) = (self.hs[0], &self.links[0], self.inertia.i_tip1() - 1);
            if lp.gamma != 0.0 {
                let (_, g) = Self::tip_bending(h, lp.gamma, v[u], v[y]);
                out[y] -= g;
                out[u] -= g;
            }
        }
        let tau1 = -self.joints[0].damping * self.clamp_angle(v, 0);
        let tau2 = -self.joints[1].damping * self.elbow(v);
        self.add_clamp(0, tau1, out);
        self.add_clamp(1, tau2, out);
        out[TH] -= tau2;
        for (i, c) in self.slope_stencil() {
            out[i] -= tau2 * c;
        }
        self.vd = vd;
    }
}
