//! Kinematic pass: frame and point kinematics of every link (positions, velocities,
//! accelerations at the quadrature points, cumulative foreshortening), and the tip kinematics
//! that observables and contact read (positions, Jacobian, motion).

use super::geometry::{V2, perp, rot, rot_t};
use super::{Chain, FrameState, MAX_LINKS, NONE, Parts};
use crate::linalg::dot;

impl Chain {
    /// Forward pass: frame and tip kinematics of every link (no forces).
    pub(super) fn forward(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], parts: Parts) {
        let g_in = if parts.conservative {
            self.gravity
        } else {
            V2::zeros()
        };
        let inertia = if parts.inertia { 1.0 } else { 0.0 };
        let mut parent: Option<FrameState> = None;
        for li in 0..self.links.len() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let (th, dth, ddth) = match l.joint.prescribed_at(t) {
                Some(k) => k,
                None => (q[l.joint.dof], qd[l.joint.dof], qdd[l.joint.dof]),
            };
            let mut fr = FrameState {
                theta: th,
                dtheta: dth,
                ddtheta: ddth,
                ..Default::default()
            };
            match parent {
                None => {
                    fr.phi = th;
                    fr.dphi = dth;
                    fr.ddphi = ddth;
                }
                Some(p) => {
                    fr.phi = p.phi + p.slope_tip + th;
                    fr.dphi = p.dphi + p.dslope_tip + dth;
                    fr.ddphi = p.ddphi + p.ddslope_tip + ddth;
                    let pr = p.r + rot(p.phi, p.p_tip);
                    let pdr = p.dr + rot(p.phi, p.dphi * perp(p.p_tip) + p.dp_tip);
                    fr.r = pr;
                    fr.dr = pdr;
                    fr.ddr = rot(p.phi, p.a_tip);
                }
            }
            let (phi, w, dw) = (fr.phi, fr.dphi, fr.ddphi);
            let frame_acc = rot_t(phi, fr.ddr);
            let g_loc = rot_t(phi, g_in);
            // Cumulative foreshortening s, ṡ, s̈ along the link.
            let (mut s, mut sd, mut sdd) = (0.0, 0.0, 0.0);
            let fs = l.foreshortening;
            let ne = l.ne;
            for e in 0..l.n_el {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let dd = Self::elem_v(qd, &dofs);
                let ddd = Self::elem_v(qdd, &dofs);
                let (ua, ub) = (l.u_dof[e], l.u_dof[e + 1]);
                let u = V2::new(Self::val(q, ua), Self::val(q, ub));
                let ud = V2::new(Self::val(qd, ua), Self::val(qd, ub));
                let udd = V2::new(Self::val(qdd, ua), Self::val(qdd, ub));
                let xa = e as f64 * l.h;
                for j in 0..tb.ng + 1 {
                    if fs {
                        for k in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][k];
                            let wgt = tb.sub_wh[j][k];
                            let vp = dot(&dn[..ne], &d[..ne]);
                            let vpd = dot(&dn[..ne], &dd[..ne]);
                            let vpdd = dot(&dn[..ne], &ddd[..ne]);
                            s -= 0.5 * wgt * vp * vp;
                            sd -= wgt * vp * vpd;
                            sdd -= wgt * (vpd * vpd + vp * vpdd);
                        }
                    }
                    if j == tb.ng {
                        continue;
                    }
                    let g = j;
                    let n = &tb.n[g];
                    let xi = tb.xi[g];
                    let (ax, axd, axdd) = if l.axial {
                        (
                            (1.0 - xi) * u[0] + xi * u[1],
                            (1.0 - xi) * ud[0] + xi * ud[1],
                            (1.0 - xi) * udd[0] + xi * udd[1],
                        )
                    } else if fs {
                        (s, sd, sdd)
                    } else {
                        (0.0, 0.0, 0.0)
                    };
                    let p = V2::new(xa + xi * l.h + ax, dot(&n[..ne], &d[..ne]));
                    let pd = V2::new(axd, dot(&n[..ne], &dd[..ne]));
                    let pdd = V2::new(axdd, dot(&n[..ne], &ddd[..ne]));
                    let a =
                        frame_acc + (dw * perp(p)) + ((-w * w) * p + ((2.0 * w) * perp(pd) + pdd));
                    let m = l.rho_a * tb.wh[g];
                    // Applied uniform transverse load on the last link (frame y), as a density
                    // with the d'Alembert sign: Gauss-4 gives its consistent nodal loads exactly.
                    let q_load = if li + 1 == self.links.len() && parts.nonconservative {
                        self.distributed_load
                    } else {
                        0.0
                    };
                    self.force[li][e * tb.ng + g] =
                        m * (inertia * a - g_loc) - V2::new(0.0, q_load * tb.wh[g]);
                    self.pos[li][e * tb.ng + g] = p;
                    self.vel[li][e * tb.ng + g] = pd;
                }
            }
            // Tip.
            let k = l.n_el;
            let (ut, utd, utdd) = if l.axial {
                (
                    Self::val(q, l.u_dof[k]),
                    Self::val(qd, l.u_dof[k]),
                    Self::val(qdd, l.u_dof[k]),
                )
            } else if fs {
                (s, sd, sdd)
            } else {
                (0.0, 0.0, 0.0)
            };
            let p = V2::new(l.length + ut, Self::val(q, l.v_dof[k]));
            let pd = V2::new(utd, Self::val(qd, l.v_dof[k]));
            let pdd = V2::new(utdd, Self::val(qdd, l.v_dof[k]));
            fr.p_tip = p;
            fr.dp_tip = pd;
            fr.a_tip = frame_acc + (dw * perp(p)) + ((-w * w) * p + ((2.0 * w) * perp(pd) + pdd));
            fr.slope_tip = Self::val(q, l.r_dof[k]);
            fr.dslope_tip = Self::val(qd, l.r_dof[k]);
            fr.ddslope_tip = Self::val(qdd, l.r_dof[k]);
            self.frames[li] = fr;
            parent = Some(fr);
        }
    }

    /// Joint angle and rate of link `li` at a state.
    pub fn joint_state(&self, li: usize, t: f64, q: &[f64], qd: &[f64]) -> (f64, f64) {
        let j = &self.links[li].joint;
        match j.prescribed_at(t) {
            Some((a, r, _)) => (a, r),
            None => (q[j.dof], qd[j.dof]),
        }
    }

    /// Inertial tip position of every link at a state (forward pass with zero rates).
    pub fn tip_positions(&self, t: f64, q: &[f64], out: &mut [V2]) {
        let mut parent: Option<(f64, V2)> = None;
        for (li, l) in self.links.iter().enumerate() {
            let th = match l.joint.prescribed_at(t) {
                Some((a, _, _)) => a,
                None => q[l.joint.dof],
            };
            let (phi, r0) = match parent {
                None => (th, V2::new(0.0, 0.0)),
                Some((pp, r)) => (pp + th, r),
            };
            let k = l.n_el;
            let ax = if l.axial {
                Self::val(q, l.u_dof[k])
            } else if l.foreshortening {
                self.foreshortening_at_tip(li, q)
            } else {
                0.0
            };
            let p = V2::new(l.length + ax, Self::val(q, l.v_dof[k]));
            let r = r0 + rot(phi, p);
            out[li] = r;
            parent = Some((phi + Self::val(q, l.r_dof[k]), r));
        }
    }

    /// s(L) = −½∫v′² of link `li`.
    pub fn foreshortening_at_tip(&self, li: usize, q: &[f64]) -> f64 {
        self.tip_foreshortening_with_gradient(li, q, |_, _| {})
    }

    /// s(L) of link `li`, handing each term of its gradient ∂s(L)/∂d = −∫v′N′ (element DOF,
    /// value; a node's DOF once per element that holds it) to `gradient` on the way: each
    /// element's slope Gram product G d gives both.
    fn tip_foreshortening_with_gradient(
        &self,
        li: usize,
        q: &[f64],
        mut gradient: impl FnMut(usize, f64),
    ) -> f64 {
        let l = &self.links[li];
        let tb = &l.element.quad;
        let ne = l.ne;
        let mut s = 0.0;
        for e in 0..l.n_el {
            let dofs = l.elem_dofs(e);
            let d = Self::elem_v(q, &dofs);
            for a in 0..ne {
                let gd = dot(&tb.slope_gram[a][..ne], &d[..ne]);
                s -= 0.5 * d[a] * gd;
                gradient(dofs[a], -gd);
            }
        }
        s
    }

    /// Transverse deflection v(x) of link `li` (Hermite interpolation).
    pub fn deflection(&self, li: usize, q: &[f64], x: f64) -> f64 {
        let l = &self.links[li];
        let e = ((x / l.h).floor() as usize).min(l.n_el - 1);
        let xi = ((x - e as f64 * l.h) / l.h).clamp(0.0, 1.0);
        let d = Self::elem_v(q, &l.elem_dofs(e));
        dot(&l.shapes_at(xi).0[..l.ne], &d[..l.ne])
    }

    /// Axial tip displacement u(L) of link `li` (extensible links).
    pub fn tip_axial(&self, li: usize, q: &[f64]) -> f64 {
        let l = &self.links[li];
        Self::val(q, l.u_dof[l.n_el])
    }

    /// Transverse tip deflection v(L) of link `li`.
    pub fn tip_deflection(&self, li: usize, q: &[f64]) -> f64 {
        let l = &self.links[li];
        Self::val(q, l.v_dof[l.n_el])
    }

    /// Inertial position of the tip of link `li` and its Jacobian J = ∂r_tip/∂q, written as two
    /// rows (x: `jac[..n]`, y: `jac[n..2n]`, n = [`Chain::ndof`]). Exact, from the chain's own
    /// frame recursion (the same one [`Chain::tip_positions`] evaluates): every DOF either turns
    /// the frames downstream of it about a frame origin Rₖ — the joint angle θₖ about Rₖ and the
    /// tip rotation of link k about Rₖ₊₁, column ẑ × (r − R) — or moves the tip of link k in
    /// its own frame: v(L) along A(φₖ)ŷ, u(L) along A(φₖ)x̂ and, with foreshortening, every
    /// transverse DOF d along A(φₖ)x̂ with ∂s(L)/∂d = −∫ v′ N′ (the quadrature of s). O(n).
    pub fn tip_jacobian(&self, t: f64, li: usize, q: &[f64], jac: &mut [f64]) -> V2 {
        let n = self.ndof;
        jac[..2 * n].iter_mut().for_each(|x| *x = 0.0);
        let put = |jac: &mut [f64], dof: usize, c: V2| {
            if dof != NONE {
                jac[dof] += c[0];
                jac[n + dof] += c[1];
            }
        };
        let mut origin = [V2::zeros(); MAX_LINKS];
        let mut angle = [0.0; MAX_LINKS];
        let mut parent: Option<(f64, V2)> = None;
        let mut r = V2::zeros();
        for k in 0..=li {
            let l = &self.links[k];
            let th = match l.joint.prescribed_at(t) {
                Some((a, _, _)) => a,
                None => q[l.joint.dof],
            };
            let (phi, r0) = match parent {
                None => (th, V2::new(0.0, 0.0)),
                Some((pp, rr)) => (pp + th, rr),
            };
            let m = l.n_el;
            let ax = if l.axial {
                Self::val(q, l.u_dof[m])
            } else if l.foreshortening {
                // The tip moves along the link's x axis by s(L): its column for every
                // transverse DOF, from the same products as s(L).
                let ex = rot(phi, V2::new(1.0, 0.0));
                self.tip_foreshortening_with_gradient(k, q, |dof, ds| put(jac, dof, ds * ex))
            } else {
                0.0
            };
            r = r0 + rot(phi, V2::new(l.length + ax, Self::val(q, l.v_dof[m])));
            origin[k] = r0;
            angle[k] = phi;
            parent = Some((phi + Self::val(q, l.r_dof[m]), r));
        }
        for k in 0..=li {
            let l = &self.links[k];
            let m = l.n_el;
            put(jac, l.joint.dof, perp(r - origin[k]));
            if k < li {
                put(jac, l.r_dof[m], perp(r - origin[k + 1]));
            }
            put(jac, l.v_dof[m], rot(angle[k], V2::new(0.0, 1.0)));
            if l.axial {
                put(jac, l.u_dof[m], rot(angle[k], V2::new(1.0, 0.0)));
            }
        }
        r
    }

    /// Tip of link `li`: inertial position, velocity and acceleration at (q, q̇, q̈) from the
    /// forward kinematic pass of the residual (exact for every element the pass handles). With
    /// q̈ = 0 the acceleration is the convective term J̇q̇. Overwrites the point data of the
    /// last residual call (call [`Chain::residual`] again before [`Chain::newton_matrix`]).
    pub fn tip_motion(&mut self, t: f64, li: usize, q: &[f64], qd: &[f64], qdd: &[f64]) -> [V2; 3] {
        self.forward(t, q, qd, qdd, Parts::INERTIA);
        let fr = self.frames[li];
        let r = fr.r + rot(fr.phi, fr.p_tip);
        let v = fr.dr + rot(fr.phi, fr.dphi * perp(fr.p_tip) + fr.dp_tip);
        [r, v, rot(fr.phi, fr.a_tip)]
    }
}
