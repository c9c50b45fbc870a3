//! Force pass: the residual R(q, q̇, q̈) of Lagrange's equations by a backward sweep over the
//! chain (element forces from the tabulated point loads, elastic forces through the element,
//! subtree resultants and joint equations).

use super::geometry::{V2, rot, rot_t};
use super::{Chain, MAXE, NONE};
use crate::linalg::dot;
use crate::system::Parts;

impl Chain {
    /// Residual R(q, q̇, q̈) of the equations of motion at time t (see module docs), written
    /// into `res`; also fills the joint torques.
    pub fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]) {
        self.residual_parts(t, q, qd, qdd, Parts::ALL, res);
    }

    /// The force groups `parts` of the residual (see [`Parts`]); the sum over all groups is
    /// [`Chain::residual`]. Only the full residual updates [`Chain::joint_torque`]; the Newton
    /// matrix reads the point data of the last call, which must therefore be a full residual.
    pub fn residual_parts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        self.forward(t, q, qd, qdd, parts);
        self.backward(t, q, qd, qdd, parts, res);
    }

    /// The force groups `parts` without inertia (gravity, strain, joint springs, applied
    /// loads, dampers) at the configuration of the last kinematic pass, which must have been
    /// at (t, q) (any rates, any groups): equal to [`Chain::residual_parts`] at (t, q, q̇, 0)
    /// bit for bit up to the sign of exact zeros. The positions and frame angles it reads are
    /// functions of q alone, and the point loads of these groups (gravity, the distributed
    /// load) need no rates: only the joint rates are set from `qd`, so the kinematic pass is
    /// not repeated (the energy-midpoint iteration evaluates three groups at q̄).
    pub fn residual_parts_at_last_q(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        debug_assert!(!parts.inertia, "the inertia group needs the kinematic pass");
        let g_in = if parts.conservative {
            self.gravity
        } else {
            V2::zeros()
        };
        let nl = self.links.len();
        for li in 0..nl {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let fr = &mut self.frames[li];
            fr.dtheta = match l.joint.prescribed_at(t) {
                Some((_, dth, _)) => dth,
                None => qd[l.joint.dof],
            };
            // Multiplied by the inertia flag (0) in the force pass.
            fr.ddphi = 0.0;
            fr.ddslope_tip = 0.0;
            fr.a_tip = V2::zeros();
            let g_loc = rot_t(fr.phi, g_in);
            let q_load = if li + 1 == nl && parts.nonconservative {
                self.distributed_load
            } else {
                0.0
            };
            let force = &mut self.force[li];
            for e in 0..l.n_el {
                for g in 0..tb.ng {
                    let m = l.rho_a * tb.wh[g];
                    force[e * tb.ng + g] =
                        m * (V2::zeros() - g_loc) - V2::new(0.0, q_load * tb.wh[g]);
                }
            }
        }
        self.backward(t, q, qd, &[], parts, res);
    }

    /// Force (backward) pass of [`Chain::residual_parts`] on the point data of the last
    /// kinematic pass (`qdd` is read for the section rotary inertia only).
    fn backward(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        res.iter_mut().for_each(|x| *x = 0.0);
        let g_in = if parts.conservative {
            self.gravity
        } else {
            V2::zeros()
        };
        let inertia = if parts.inertia { 1.0 } else { 0.0 };
        let (cons, noncons) = (parts.conservative, parts.nonconservative);
        let nl = self.links.len();
        // Child loads passed to the parent: resultant (inertial) and moment about the child root.
        let mut child_f = V2::zeros();
        let mut child_m = 0.0;
        for li in (0..nl).rev() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let fr = self.frames[li];
            let g_loc = rot_t(fr.phi, g_in);
            let k = l.n_el;
            // Tip body and child loads (frame coordinates).
            let f_tipmass = l.tip_mass * (inertia * fr.a_tip - g_loc);
            // An applied tip force enters with the d'Alembert sign (R collects −Q).
            let p_tip = if li + 1 == nl && noncons {
                self.tip_load
            } else {
                0.0
            };
            let f_tip = f_tipmass + rot_t(fr.phi, child_f) - V2::new(0.0, p_tip);
            let m_tip = inertia * l.tip_inertia * (fr.ddphi + fr.ddslope_tip) + child_m;
            let mut add_res = |i: usize, v: f64| {
                if i != NONE {
                    res[i] += v;
                }
            };
            add_res(l.v_dof[k], f_tip[1]);
            add_res(l.u_dof[k], f_tip[0]);
            add_res(l.r_dof[k], m_tip);
            // Distributed inertia/gravity, elastic and damping forces, element by element
            // (tip to root so the tail load T accumulates).
            let mut f_sum = V2::zeros();
            let mut m_sum = 0.0;
            let mut tail = f_tip[0];
            let ne = l.ne;
            for e in (0..l.n_el).rev() {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let mut fe = [0.0; MAXE];
                let (mut fu0, mut fu1) = (0.0, 0.0);
                for g in 0..tb.ng {
                    let f = self.force[li][e * tb.ng + g];
                    let p = self.pos[li][e * tb.ng + g];
                    f_sum += f;
                    m_sum += p.perp(&f);
                    for a in 0..ne {
                        fe[a] += f[1] * tb.n[g][a];
                    }
                    if l.axial {
                        let xi = tb.xi[g];
                        fu0 += f[0] * (1.0 - xi);
                        fu1 += f[0] * xi;
                    }
                }
                // Section rotary inertia: moment density ρI(φ̈ + β̈) on the section angle
                // φ + β(x) (β = v′ or ψ), which every upstream rotation turns by one.
                if l.rho_i > 0.0 && parts.inertia {
                    let ddd = Self::elem_v(qdd, &dofs);
                    for g in 0..tb.ng {
                        let b = &tb.b[g];
                        let mr = l.rho_i * tb.wh[g] * (fr.ddphi + dot(&b[..ne], &ddd[..ne]));
                        m_sum += mr;
                        for a in 0..ne {
                            fe[a] += mr * b[a];
                        }
                    }
                }
                if l.foreshortening {
                    for j in (0..tb.ng + 1).rev() {
                        self.tail[li][e * (tb.ng + 1) + j] = tail;
                        for kk in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][kk];
                            let vp = dot(&dn[..ne], &d[..ne]);
                            let c = -tail * tb.sub_wh[j][kk] * vp;
                            for a in 0..ne {
                                fe[a] += c * dn[a];
                            }
                        }
                        if j > 0 {
                            tail += self.force[li][e * tb.ng + j - 1][0];
                        }
                    }
                }
                // Elastic forces.
                if cons {
                    let u = [Self::val(q, l.u_dof[e]), Self::val(q, l.u_dof[e + 1])];
                    let mut fu = [fu0, fu1];
                    l.element
                        .kind
                        .internal_force(&l.element, u, &d, &mut fu, &mut fe);
                    [fu0, fu1] = fu;
                }
                if l.kelvin_voigt > 0.0 && noncons {
                    let dd = Self::elem_v(qd, &dofs);
                    let c = l.kelvin_voigt / l.ei;
                    for a in 0..ne {
                        fe[a] += c * dot(&l.element.kb[a][..ne], &dd[..ne]);
                    }
                }
                for a in 0..ne {
                    if dofs[a] != NONE {
                        res[dofs[a]] += fe[a];
                    }
                }
                if l.axial {
                    if l.u_dof[e] != NONE {
                        res[l.u_dof[e]] += fu0;
                    }
                    if l.u_dof[e + 1] != NONE {
                        res[l.u_dof[e + 1]] += fu1;
                    }
                }
            }
            // Subtree resultant and moment about this link's root Rᵢ.
            let f_total_loc = f_sum + f_tip;
            let moment = m_sum + fr.p_tip.perp(&f_tip) + m_tip + inertia * l.hub_inertia * fr.ddphi;
            let fr_mut = &mut self.frames[li];
            fr_mut.subtree_moment = moment;
            fr_mut.subtree_force = rot(fr.phi, f_total_loc);
            child_f = fr_mut.subtree_force;
            child_m = moment;
            // Joint equation: moment + spring + damper − applied = actuator torque.
            let j = &l.joint;
            let spring = if cons {
                j.stiffness * (fr.theta - j.set_point)
            } else {
                0.0
            };
            let (damper, law) = if noncons {
                (j.damping * fr.dtheta, j.applied(t))
            } else {
                (0.0, 0.0)
            };
            if j.dof != NONE {
                res[j.dof] += moment + spring + damper - law;
            }
            if parts == Parts::ALL {
                self.joint_torque[li] = if j.dof != NONE {
                    law
                } else {
                    moment + spring + damper - law
                };
            }
        }
    }
}
