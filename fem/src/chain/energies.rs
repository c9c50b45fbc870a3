//! Energies and powers at a state: kinetic, strain, joint-spring and gravity energies, the
//! power of the applied loads and the dissipated powers (the ledger's terms), and the gradient
//! ∂T/∂q of the kinetic energy.
//!
//! ∂T/∂q(q, x) of T = ½xᵀM(q)x in one forward and one backward sweep: T is invariant under a
//! rigid rotation, so it is written in link-frame coordinates. Link i turns at ω_i (linear in
//! x, free of q); its origin moves at u_i (frame coordinates), u₁ = 0 (fixed root) and
//! u_{i+1} = A(γ_{i+1})ᵀ c_tip,i with γ_{i+1} = β_tip,i + θ_{i+1}; a point at local position
//! p = (x + s(x) or x + u(x), v(x)) moves at c = u_i + ω_i ẑ×p + ṗ and T = Σ ½ m|c|² + rotary
//! terms ½I(φ̇ + β̇)² that do not depend on q. With g = m c: ∂T/∂u_i = Σ g, ∂T/∂p = ω(g_y, −g_x),
//! ∂T/∂ṗ = g; p_y = N·d, and p_x, ṗ_x reach the transverse DOFs through s(x) = −½∫v′²,
//! ṡ(x) = −∫v′v̇′ (the same sub-interval quadrature as the residual, applied through the tail
//! sums of ∂T/∂p_x and ∂T/∂ṗ_x); ∂u_{i+1}/∂γ = −ẑ×u_{i+1}, and the parent receives
//! A(γ)∂T/∂u_{i+1} at its tip. Exact for the quadrature (no difference step).

use super::geometry::{V2, perp, rot, rot_t};
use super::{Chain, FrameState, LinkModel, MAX_LINKS, MAXE, NONE};
use crate::linalg::dot;

impl LinkModel {
    /// Walks the link's material points at configuration `q` and generalized velocity `x`, in
    /// link-frame coordinates: at Gauss point j of element e, `point(e, j, p, ṗ, ẋ_e)` with
    /// p = (x + u(x), v(x)) (extensible link) or (x + s(x), v(x)) (foreshortening,
    /// s(x) = −½∫v′², ṡ = −∫v′v̇′ on the sub-interval quadrature) or (x, v(x)), and ẋ_e the
    /// element's velocity vector; after each element `element_done(e, u_e, q_e)` with its nodal
    /// axial values and its transverse vector. Returns the tip's (p, ṗ). The one point loop of
    /// [`Chain::energies`] and [`Chain::add_kinetic_gradient`]; no allocation.
    #[inline]
    fn walk_points(
        &self,
        q: &[f64],
        x: &[f64],
        mut point: impl FnMut(usize, usize, V2, V2, &[f64; MAXE]),
        mut element_done: impl FnMut(usize, [f64; 2], &[f64; MAXE]),
    ) -> (V2, V2) {
        let tb = &self.element.quad;
        let (mut s, mut sd) = (0.0, 0.0);
        // An extensible link carries its axial field instead of the foreshortening.
        let fs = self.foreshortening && !self.axial;
        let ne = self.ne;
        for e in 0..self.n_el {
            let dofs = self.elem_dofs(e);
            let d = Chain::elem_v(q, &dofs);
            let dd = Chain::elem_v(x, &dofs);
            let u = [
                Chain::val(q, self.u_dof[e]),
                Chain::val(q, self.u_dof[e + 1]),
            ];
            let ud = [
                Chain::val(x, self.u_dof[e]),
                Chain::val(x, self.u_dof[e + 1]),
            ];
            let xa = e as f64 * self.h;
            for j in 0..tb.ng + 1 {
                if fs {
                    for k in 0..tb.nsg {
                        let dn = &tb.sub_dn[j][k];
                        let wgt = tb.sub_wh[j][k];
                        let vp = dot(&dn[..ne], &d[..ne]);
                        s -= 0.5 * wgt * vp * vp;
                        sd -= wgt * vp * dot(&dn[..ne], &dd[..ne]);
                    }
                }
                if j == tb.ng {
                    continue;
                }
                let xi = tb.xi[j];
                let (ax, axd) = if self.axial {
                    (
                        (1.0 - xi) * u[0] + xi * u[1],
                        (1.0 - xi) * ud[0] + xi * ud[1],
                    )
                } else if fs {
                    (s, sd)
                } else {
                    (0.0, 0.0)
                };
                let p = V2::new(xa + xi * self.h + ax, dot(&tb.n[j][..ne], &d[..ne]));
                let pd = V2::new(axd, dot(&tb.n[j][..ne], &dd[..ne]));
                point(e, j, p, pd, &dd);
            }
            element_done(e, u, &d);
        }
        let k = self.n_el;
        let (ut, utd) = if self.axial {
            (Chain::val(q, self.u_dof[k]), Chain::val(x, self.u_dof[k]))
        } else if fs {
            (s, sd)
        } else {
            (0.0, 0.0)
        };
        (
            V2::new(self.length + ut, Chain::val(q, self.v_dof[k])),
            V2::new(utd, Chain::val(x, self.v_dof[k])),
        )
    }
}

impl Chain {
    /// Stored energies at a state: (kinetic, strain, joint_spring, gravity).
    pub fn energies(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        debug_assert_eq!(qd.len(), q.len());
        let g_in = self.gravity;
        let mut parent: Option<(FrameState, V2, V2)> = None;
        let (mut kin, mut strain, mut spring, mut grav) = (0.0, 0.0, 0.0, 0.0);
        for li in 0..self.links.len() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let (th, dth) = match l.joint.prescribed_at(t) {
                Some((a, b, _)) => (a, b),
                None => (q[l.joint.dof], qd[l.joint.dof]),
            };
            let (phi, w, r0, dr0) = match parent {
                None => (th, dth, V2::new(0.0, 0.0), V2::new(0.0, 0.0)),
                Some((p, r, dr)) => (p.phi + p.slope_tip + th, p.dphi + p.dslope_tip + dth, r, dr),
            };
            spring += 0.5 * l.joint.stiffness * (th - l.joint.set_point).powi(2);
            kin += 0.5 * l.hub_inertia * w * w;
            let ne = l.ne;
            let (p, pd) = l.walk_points(
                q,
                qd,
                |_, j, p, pd, dd| {
                    let v = dr0 + rot(phi, w * perp(p) + pd);
                    let m = l.rho_a * tb.wh[j];
                    kin += 0.5 * m * v.dot(&v);
                    grav -= m * g_in.dot(&(r0 + rot(phi, p)));
                    if l.rho_i > 0.0 {
                        // ½ρI(φ̇ + β̇)², β the section angle relative to the frame.
                        let om = w + dot(&tb.b[j][..ne], &dd[..ne]);
                        kin += 0.5 * l.rho_i * tb.wh[j] * om * om;
                    }
                },
                |_, u, d| {
                    l.element
                        .kind
                        .add_strain_energy(&l.element, u, d, &mut strain)
                },
            );
            let v_tip = dr0 + rot(phi, w * perp(p) + pd);
            let r_tip = r0 + rot(phi, p);
            kin += 0.5 * l.tip_mass * v_tip.dot(&v_tip);
            grav -= l.tip_mass * g_in.dot(&r_tip);
            let slope = Self::val(q, l.r_dof[l.n_el]);
            let dslope = Self::val(qd, l.r_dof[l.n_el]);
            kin += 0.5 * l.tip_inertia * (w + dslope).powi(2);
            let fs = FrameState {
                phi,
                dphi: w,
                slope_tip: slope,
                dslope_tip: dslope,
                ..Default::default()
            };
            parent = Some((fs, r_tip, v_tip));
        }
        [kin, strain, spring, grav]
    }

    /// The potential parts (strain, joint_spring, gravity) at (t, q), on the positions and
    /// frames of the last kinematic pass, which must have been at q (any time, rates and
    /// groups): equal to those of [`Chain::energies`] bit for bit (same terms, same order),
    /// without the point walk. A chain with a prescribed joint (whose frames depend on the
    /// pass's time) takes the walk at t.
    pub fn potential_at_last_q(&self, t: f64, q: &[f64]) -> [f64; 3] {
        if self.links.iter().any(|l| l.joint.prescribed.is_some()) {
            let [_, strain, spring, gravity] = self.energies(t, q, q);
            return [strain, spring, gravity];
        }
        let g_in = self.gravity;
        let (mut strain, mut spring, mut grav) = (0.0, 0.0, 0.0);
        for (li, l) in self.links.iter().enumerate() {
            let th = q[l.joint.dof];
            spring += 0.5 * l.joint.stiffness * (th - l.joint.set_point).powi(2);
            let fr = &self.frames[li];
            let tb = &l.element.quad;
            for e in 0..l.n_el {
                for j in 0..tb.ng {
                    let m = l.rho_a * tb.wh[j];
                    let p = self.pos[li][e * tb.ng + j];
                    grav -= m * g_in.dot(&(fr.r + rot(fr.phi, p)));
                }
                let u = [Chain::val(q, l.u_dof[e]), Chain::val(q, l.u_dof[e + 1])];
                let d = Chain::elem_v(q, &l.elem_dofs(e));
                l.element
                    .kind
                    .add_strain_energy(&l.element, u, &d, &mut strain);
            }
            grav -= l.tip_mass * g_in.dot(&(fr.r + rot(fr.phi, fr.p_tip)));
        }
        [strain, spring, grav]
    }

    /// Adds `sign`·∂T/∂q(q, x) to `out`, T = ½xᵀM(q)x the kinetic energy at generalized
    /// velocity x (module docs; prescribed joints move at their law's rate at t). O(n), no
    /// allocation.
    pub fn add_kinetic_gradient(
        &mut self,
        t: f64,
        q: &[f64],
        x: &[f64],
        sign: f64,
        out: &mut [f64],
    ) {
        let nl = self.links.len();
        let mut omega = [0.0; MAX_LINKS];
        let mut u_frame = [V2::zeros(); MAX_LINKS];
        let mut gamma = [0.0; MAX_LINKS];
        let mut c_tip = [V2::zeros(); MAX_LINKS];
        // Forward sweep: frame rates, frame-origin velocities and point velocities.
        for li in 0..nl {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let (th, dth) = match l.joint.prescribed_at(t) {
                Some((a, r, _)) => (a, r),
                None => (q[l.joint.dof], x[l.joint.dof]),
            };
            let (w, u) = if li == 0 {
                (dth, V2::zeros())
            } else {
                let pl = &self.links[li - 1];
                let k = pl.n_el;
                let g = Self::val(q, pl.r_dof[k]) + th;
                gamma[li] = g;
                (
                    omega[li - 1] + Self::val(x, pl.r_dof[k]) + dth,
                    rot_t(g, c_tip[li - 1]),
                )
            };
            omega[li] = w;
            u_frame[li] = u;
            let ng = tb.ng;
            let kin_vel = &mut self.kin_vel[li];
            let (p, pd) = l.walk_points(
                q,
                x,
                |e, j, p, pd, _| kin_vel[e * ng + j] = u + (w * perp(p) + pd),
                |_, _, _| {},
            );
            c_tip[li] = u + (w * perp(p) + pd);
        }
        // Backward sweep: g = m c at the points, ∂T/∂u_i accumulated in `big_g`.
        let mut put = |i: usize, v: f64| {
            if i != NONE {
                out[i] += sign * v;
            }
        };
        let mut child = V2::zeros();
        for li in (0..nl).rev() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let w = omega[li];
            let k = l.n_el;
            let g_tip = l.tip_mass * c_tip[li] + child;
            let mut big_g = g_tip;
            put(l.v_dof[k], -w * g_tip[0]);
            put(l.u_dof[k], w * g_tip[1]);
            // Tail sums of ∂T/∂p_x and ∂T/∂ṗ_x (foreshortening).
            let (mut tail_s, mut tail_sd) = (w * g_tip[1], g_tip[0]);
            // An extensible link carries its axial field instead of the foreshortening.
            let fs = l.foreshortening && !l.axial;
            let ne = l.ne;
            for e in (0..l.n_el).rev() {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let dd = Self::elem_v(x, &dofs);
                let mut fe = [0.0; super::MAXE];
                let (mut fu0, mut fu1) = (0.0, 0.0);
                for j in (0..tb.ng + 1).rev() {
                    if fs {
                        for kk in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][kk];
                            let c = -tb.sub_wh[j][kk]
                                * (tail_s * dot(&dn[..ne], &d[..ne])
                                    + tail_sd * dot(&dn[..ne], &dd[..ne]));
                            for a in 0..ne {
                                fe[a] += c * dn[a];
                            }
                        }
                    }
                    if j == 0 {
                        continue;
                    }
                    let gp = j - 1;
                    let g = (l.rho_a * tb.wh[gp]) * self.kin_vel[li][e * tb.ng + gp];
                    big_g += g;
                    for a in 0..ne {
                        fe[a] -= w * g[0] * tb.n[gp][a];
                    }
                    if l.axial {
                        let xi = tb.xi[gp];
                        fu0 += w * g[1] * (1.0 - xi);
                        fu1 += w * g[1] * xi;
                    }
                    tail_s += w * g[1];
                    tail_sd += g[0];
                }
                for a in 0..ne {
                    put(dofs[a], fe[a]);
                }
                if l.axial {
                    put(l.u_dof[e], fu0);
                    put(l.u_dof[e + 1], fu1);
                }
            }
            if li > 0 {
                // u_i = A(γ)ᵀ c_tip,i−1: ∂u_i/∂γ = −ẑ×u_i.
                let dg = -big_g.dot(&perp(u_frame[li]));
                put(l.joint.dof, dg);
                let pl = &self.links[li - 1];
                put(pl.r_dof[pl.n_el], dg);
                child = rot(gamma[li], big_g);
            }
        }
    }

    /// Power of the applied transverse loads, Qᵀq̇ (constant loads: exact work over a
    /// trapezoidal step when q̇ is the step's mean velocity).
    pub fn load_power(&self, qd: &[f64]) -> f64 {
        let Some(l) = self.links.last() else {
            return 0.0;
        };
        let mut p = self.tip_load * Self::val(qd, l.v_dof[l.n_el]);
        if self.distributed_load != 0.0 {
            let q0 = self.distributed_load;
            let fq = l.element.kind.consistent_load(&l.element, q0);
            for e in 0..l.n_el {
                let dd = Self::elem_v(qd, &l.elem_dofs(e));
                p += dot(&fq[..l.ne], &dd[..l.ne]);
            }
        }
        p
    }

    /// Dissipated powers at a state: (joint dampers, Kelvin–Voigt).
    pub fn dissipation_power(&self, t: f64, qd: &[f64]) -> (f64, f64) {
        let (mut pj, mut pkv) = (0.0, 0.0);
        for l in &self.links {
            let dth = match l.joint.prescribed_at(t) {
                Some((_, r, _)) => r,
                None => qd[l.joint.dof],
            };
            pj += l.joint.damping * dth * dth;
            if l.kelvin_voigt > 0.0 {
                let c = l.kelvin_voigt / l.ei;
                for e in 0..l.n_el {
                    let dd = Self::elem_v(qd, &l.elem_dofs(e));
                    for a in 0..l.ne {
                        pkv += c * dd[a] * dot(&l.element.kb[a][..l.ne], &dd[..l.ne]);
                    }
                }
            }
        }
        (pj, pkv)
    }
}
