//! Energies and powers at a state: kinetic, strain, joint-spring and gravity energies, the
//! power of the applied loads and the dissipated powers (the ledger's terms).

use super::geometry::{add, dot, perp, rot, scale};
use super::{Chain, FrameState, dotn};

impl Chain {
    /// Stored energies at a state: (kinetic, strain, joint_spring, gravity).
    pub fn energies(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        debug_assert_eq!(qd.len(), q.len());
        let g_in = self.gravity;
        let mut parent: Option<(FrameState, [f64; 2], [f64; 2])> = None;
        let (mut kin, mut strain, mut spring, mut grav) = (0.0, 0.0, 0.0, 0.0);
        for li in 0..self.links.len() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let (th, dth) = match l.joint.prescribed_at(t) {
                Some((a, b, _)) => (a, b),
                None => (q[l.joint.dof], qd[l.joint.dof]),
            };
            let (phi, w, r0, dr0) = match parent {
                None => (th, dth, [0.0, 0.0], [0.0, 0.0]),
                Some((p, r, dr)) => (p.phi + p.slope_tip + th, p.dphi + p.dslope_tip + dth, r, dr),
            };
            spring += 0.5 * l.joint.stiffness * (th - l.joint.set_point).powi(2);
            kin += 0.5 * l.hub_inertia * w * w;
            let (mut s, mut sd) = (0.0, 0.0);
            let ne = l.ne;
            for e in 0..l.n_el {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let dd = Self::elem_v(qd, &dofs);
                let u = [Self::val(q, l.u_dof[e]), Self::val(q, l.u_dof[e + 1])];
                let ud = [Self::val(qd, l.u_dof[e]), Self::val(qd, l.u_dof[e + 1])];
                let xa = e as f64 * l.h;
                for j in 0..tb.ng + 1 {
                    if l.foreshortening {
                        for k in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][k];
                            let wgt = tb.sub_wh[j][k];
                            let vp = dotn(dn, &d, ne);
                            s -= 0.5 * wgt * vp * vp;
                            sd -= wgt * vp * dotn(dn, &dd, ne);
                        }
                    }
                    if j == tb.ng {
                        continue;
                    }
                    let xi = tb.xi[j];
                    let (ax, axd) = if l.axial {
                        (
                            (1.0 - xi) * u[0] + xi * u[1],
                            (1.0 - xi) * ud[0] + xi * ud[1],
                        )
                    } else if l.foreshortening {
                        (s, sd)
                    } else {
                        (0.0, 0.0)
                    };
                    let p = [xa + xi * l.h + ax, dotn(&tb.n[j], &d, ne)];
                    let pd = [axd, dotn(&tb.n[j], &dd, ne)];
                    let v = add(dr0, rot(phi, add(scale(w, perp(p)), pd)));
                    let m = l.rho_a * tb.wh[j];
                    kin += 0.5 * m * dot(v, v);
                    grav -= m * dot(g_in, add(r0, rot(phi, p)));
                    if l.rho_i > 0.0 {
                        // ½ρI(φ̇ + β̇)², β the section angle relative to the frame.
                        let om = w + dotn(&tb.b[j], &dd, ne);
                        kin += 0.5 * l.rho_i * tb.wh[j] * om * om;
                    }
                }
                l.element
                    .kind
                    .add_strain_energy(&l.element, u, &d, &mut strain);
            }
            let k = l.n_el;
            let (ut, utd) = if l.axial {
                (Self::val(q, l.u_dof[k]), Self::val(qd, l.u_dof[k]))
            } else if l.foreshortening {
                (s, sd)
            } else {
                (0.0, 0.0)
            };
            let p = [l.length + ut, Self::val(q, l.v_dof[k])];
            let pd = [utd, Self::val(qd, l.v_dof[k])];
            let v_tip = add(dr0, rot(phi, add(scale(w, perp(p)), pd)));
            let r_tip = add(r0, rot(phi, p));
            kin += 0.5 * l.tip_mass * dot(v_tip, v_tip);
            grav -= l.tip_mass * dot(g_in, r_tip);
            let slope = Self::val(q, l.r_dof[k]);
            let dslope = Self::val(qd, l.r_dof[k]);
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
                p += dotn(&fq, &dd, l.ne);
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
                        pkv += c * dd[a] * dotn(&l.element.kb[a], &dd, l.ne);
                    }
                }
            }
        }
        (pj, pkv)
    }
}
