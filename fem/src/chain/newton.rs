//! Newton matrix S = c_a M + c_v C + c_q K at the state of the last residual: inertia of every
//! mass point through the columns of its Jacobian, section rotary inertia, the element tangent,
//! Kelvin–Voigt and the foreshortening geometric stiffness, tip and hub bodies, joint springs.

use super::geometry::{add, dot, perp, rot, rot_t, scale, sub};
use super::{Chain, ElementDofs, FrameState, MAX_COLUMNS, MAXE, NONE};
use crate::band::BorderedBand;

/// A column of J contributed by an ancestor (or own joint) DOF, in frame-i coordinates.
#[derive(Debug, Clone, Copy, Default)]
struct AncestorColumn {
    dof: usize,
    /// Rotation about a centre (`vec` = centre, `dvec` = its velocity) or translation along
    /// `vec` (whose frame turns at `rate`).
    rotation: bool,
    vec: [f64; 2],
    dvec: [f64; 2],
    centre_acc: [f64; 2],
    rate: f64,
    rate_dot: f64,
    /// Position along the chain (smaller = closer to the ground).
    pos: f64,
}

/// A column of J evaluated at one mass point.
#[derive(Debug, Clone, Copy, Default)]
struct ColumnAt {
    dof: usize,
    j: [f64; 2],
    jdot: [f64; 2],
    rotation: bool,
    pos: f64,
    centre_acc: [f64; 2],
    /// Angular velocity and acceleration of the frame a translation column is attached to.
    rate: f64,
    rate_dot: f64,
}

/// What the Newton matrix is a derivative of: S = ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q.
#[derive(Debug, Clone, Copy)]
pub struct NewtonCoefficients {
    pub c_a: f64,
    pub c_v: f64,
    pub c_q: f64,
}

impl Chain {
    /// Assembles the Newton matrix c_a·M + c_v·C + c_q·K at the state of the last
    /// [`Chain::residual`] call (which must precede it).
    pub fn newton_matrix(&self, q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        s.clear();
        let nl = self.links.len();
        let g_in = self.gravity;
        // Columns of J for the DOFs of ancestors (and the own joint), in frame-i coordinates.
        // Fixed-size buffer: no heap allocation per Newton matrix.
        let mut cols = [AncestorColumn::default(); MAX_COLUMNS];
        // Per-point column buffer, reused (filled up to the point's column count).
        let mut jc = [ColumnAt::default(); MAXE + 2 + MAX_COLUMNS];
        for li in 0..nl {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let fr = self.frames[li];
            let g_loc = rot_t(fr.phi, g_in);
            let ncols = self.ancestor_columns(li, &mut cols);
            let w = fr.dphi;
            let wd = fr.ddphi;
            let local_pos = 2.0 * li as f64 + 0.5;
            // One mass point: m at local position p with velocity ṗ and d'Alembert density
            // f = m(a − g). Adds c_a·M + c_v·C + c_q·K_inertial for all its columns, with
            // C = Σ m Jᵀ 2J̇ and K_inertial = Σ m[(∂J/∂q)ᵀ(a − g) + Jᵀ ∂a/∂q].
            let point = |s: &mut BorderedBand,
                         jc: &mut [ColumnAt; MAXE + 2 + MAX_COLUMNS],
                         m: f64,
                         p: [f64; 2],
                         pd: [f64; 2],
                         f: [f64; 2],
                         local: &[(usize, [f64; 2])]| {
                let mut nj = 0;
                for &(dof, v) in local {
                    if dof != NONE {
                        jc[nj] = ColumnAt {
                            dof,
                            j: v,
                            jdot: scale(w, perp(v)),
                            rotation: false,
                            pos: local_pos,
                            centre_acc: [0.0; 2],
                            rate: w,
                            rate_dot: wd,
                        };
                        nj += 1;
                    }
                }
                for col in &cols[..ncols] {
                    jc[nj] = if col.rotation {
                        let j = perp(sub(p, col.vec));
                        ColumnAt {
                            dof: col.dof,
                            j,
                            jdot: add(scale(w, perp(j)), perp(sub(pd, col.dvec))),
                            rotation: true,
                            pos: col.pos,
                            centre_acc: col.centre_acc,
                            rate: 0.0,
                            rate_dot: 0.0,
                        }
                    } else {
                        ColumnAt {
                            dof: col.dof,
                            j: col.vec,
                            jdot: scale(col.rate, perp(col.vec)),
                            rotation: false,
                            pos: col.pos,
                            centre_acc: [0.0; 2],
                            rate: col.rate,
                            rate_dot: col.rate_dot,
                        }
                    };
                    nj += 1;
                }
                let acc = add(scale(1.0 / m, f), g_loc);
                for a in 0..nj {
                    let ca = &jc[a];
                    for b in 0..nj {
                        let cb = &jc[b];
                        let mut v = c.c_a * m * dot(ca.j, cb.j);
                        v += c.c_v * 2.0 * m * dot(ca.j, cb.jdot);
                        // ∂J_a/∂q_b: a rotation b upstream of a's attachment rotates J_a; for a
                        // rotation a, anything downstream moves the point about a's centre.
                        let dja = if cb.rotation && cb.pos <= ca.pos {
                            perp(ca.j)
                        } else if ca.rotation {
                            perp(cb.j)
                        } else {
                            [0.0; 2]
                        };
                        // ∂a/∂q_b: rigid rotation of the downstream acceleration field about the
                        // centre, or the frame's rigid acceleration field at a displaced point.
                        let dacc = if cb.rotation {
                            perp(sub(acc, cb.centre_acc))
                        } else {
                            add(
                                scale(-cb.rate * cb.rate, cb.j),
                                scale(cb.rate_dot, perp(cb.j)),
                            )
                        };
                        v += c.c_q * m * (dot(dja, sub(acc, g_loc)) + dot(ca.j, dacc));
                        if v != 0.0 {
                            s.add(ca.dof, cb.dof, v);
                        }
                    }
                }
            };
            // Rotation columns (upstream joints and tip slopes): they turn every section of
            // this link by one.
            let mut rot_dofs = [NONE; MAX_COLUMNS + 1];
            let mut nr = 0;
            for col in &cols[..ncols] {
                if col.rotation {
                    rot_dofs[nr] = col.dof;
                    nr += 1;
                }
            }
            let ne = l.ne;
            for e in 0..l.n_el {
                let dofs = l.elem_dofs(e);
                for g in 0..tb.ng {
                    let m = l.rho_a * tb.wh[g];
                    let p = self.pos[li][e * tb.ng + g];
                    let xi = tb.xi[g];
                    let n = tb.n[g];
                    // Translation columns of the point: the v shapes (the ψ DOFs of a
                    // Timoshenko element do not move it), then u.
                    let mut local = [(NONE, [0.0; 2]); MAXE + 2];
                    let mut nloc = 0;
                    for a in 0..ne {
                        if !l.element.kind.translates(a) {
                            continue;
                        }
                        local[nloc] = (dofs[a], [0.0, n[a]]);
                        nloc += 1;
                    }
                    local[nloc] = (l.u_dof[e], [1.0 - xi, 0.0]);
                    local[nloc + 1] = (l.u_dof[e + 1], [xi, 0.0]);
                    nloc += 2;
                    let pd = self.vel[li][e * tb.ng + g];
                    let f = self.force[li][e * tb.ng + g];
                    point(s, &mut jc, m, p, pd, f, &local[..nloc]);
                }
                // Section rotary inertia: the section angle is linear in q (J constant), so
                // only the mass term c_a ρI w JᵀJ.
                // Section rotary inertia: the section angle is linear in q (J constant), so
                // only the mass term c_a ρI w JᵀJ.
                if l.rho_i > 0.0 && c.c_a != 0.0 {
                    self.section_inertia_block(li, &dofs, &rot_dofs[..nr], c.c_a, s);
                }
                self.element_stiffness_block(li, e, &dofs, q, c, s);
            }
            // Tip mass.
            let k = l.n_el;
            if l.tip_mass > 0.0 {
                let local = [(l.v_dof[k], [0.0, 1.0]), (l.u_dof[k], [1.0, 0.0])];
                let f = scale(l.tip_mass, sub(fr.a_tip, g_loc));
                point(s, &mut jc, l.tip_mass, fr.p_tip, fr.dp_tip, f, &local);
            }
            // Rotational inertias: tip (rotates with φᵢ + slope(L)) and hub (with φᵢ).
            if l.hub_inertia > 0.0 {
                for a in 0..nr {
                    for b in 0..nr {
                        s.add(rot_dofs[a], rot_dofs[b], c.c_a * l.hub_inertia);
                    }
                }
            }
            if l.tip_inertia > 0.0 {
                if l.r_dof[k] != NONE {
                    rot_dofs[nr] = l.r_dof[k];
                    nr += 1;
                }
                for a in 0..nr {
                    for b in 0..nr {
                        s.add(rot_dofs[a], rot_dofs[b], c.c_a * l.tip_inertia);
                    }
                }
            }
            // Joint spring and damper.
            if l.joint.dof != NONE {
                let jd = l.joint.dof;
                s.add(jd, jd, c.c_q * l.joint.stiffness + c.c_v * l.joint.damping);
            }
        }
    }

    /// Columns of J for the DOFs of the ancestors of link `li` (and its own joint), in
    /// frame-`li` coordinates, written into `cols`; returns their count.
    fn ancestor_columns(&self, li: usize, cols: &mut [AncestorColumn; MAX_COLUMNS]) -> usize {
        let fr = self.frames[li];
        let mut ncols = 0usize;
        // Frame-coordinate position, velocity and acceleration of a point Rc relative to Rᵢ.
        let rel = |o: &FrameState| {
            let c = rot_t(fr.phi, sub(o.r, fr.r));
            let cdot = add(scale(-fr.dphi, perp(c)), rot_t(fr.phi, sub(o.dr, fr.dr)));
            let acc = rot_t(fr.phi, o.ddr);
            (c, cdot, acc)
        };
        for (aj, al) in self.links.iter().enumerate().take(li + 1) {
            let fa = &self.frames[aj];
            if al.joint.dof != NONE {
                let (c, cdot, acc) = rel(fa);
                cols[ncols] = AncestorColumn {
                    dof: al.joint.dof,
                    rotation: true,
                    vec: c,
                    dvec: cdot,
                    centre_acc: acc,
                    rate: 0.0,
                    rate_dot: 0.0,
                    pos: 2.0 * aj as f64,
                };
                ncols += 1;
            }
            if aj < li {
                let child = &self.frames[aj + 1];
                let (c, cdot, acc) = rel(child);
                if al.r_dof[al.n_el] != NONE {
                    cols[ncols] = AncestorColumn {
                        dof: al.r_dof[al.n_el],
                        rotation: true,
                        vec: c,
                        dvec: cdot,
                        centre_acc: acc,
                        rate: 0.0,
                        rate_dot: 0.0,
                        pos: 2.0 * aj as f64 + 1.0,
                    };
                    ncols += 1;
                }
                for (dof, e) in [
                    (al.v_dof[al.n_el], [0.0, 1.0]),
                    (al.u_dof[al.n_el], [1.0, 0.0]),
                ] {
                    if dof != NONE {
                        cols[ncols] = AncestorColumn {
                            dof,
                            rotation: false,
                            vec: rot_t(fr.phi, rot(fa.phi, e)),
                            dvec: [0.0; 2],
                            centre_acc: [0.0; 2],
                            rate: fa.dphi,
                            rate_dot: fa.ddphi,
                            pos: 2.0 * aj as f64 + 0.5,
                        };
                        ncols += 1;
                    }
                }
            }
        }
        ncols
    }

    /// Section rotary inertia of one element: c_a ρI Σ w JᵀJ, J = (1 per rotation column
    /// `rot_dofs`, B per element DOF).
    fn section_inertia_block(
        &self,
        li: usize,
        dofs: &[usize; MAXE],
        rot_dofs: &[usize],
        c_a: f64,
        s: &mut BorderedBand,
    ) {
        let l = &self.links[li];
        let tb = &l.element.quad;
        let ne = l.ne;
        for g in 0..tb.ng {
            let mw = c_a * l.rho_i * tb.wh[g];
            let b = &tb.b[g];
            let mut jr = [(NONE, 0.0); MAX_COLUMNS + 1 + MAXE];
            let mut nj = 0;
            for &dof in rot_dofs {
                jr[nj] = (dof, 1.0);
                nj += 1;
            }
            for a in 0..ne {
                if dofs[a] != NONE && b[a] != 0.0 {
                    jr[nj] = (dofs[a], b[a]);
                    nj += 1;
                }
            }
            for &(da, va) in &jr[..nj] {
                for &(db, vb) in &jr[..nj] {
                    s.add(da, db, mw * va * vb);
                }
            }
        }
    }

    /// Elastic tangent (through the element), Kelvin–Voigt and the foreshortening geometric
    /// stiffness of element `e` of link `li`.
    fn element_stiffness_block(
        &self,
        li: usize,
        e: usize,
        dofs: &[usize; MAXE],
        q: &[f64],
        c: NewtonCoefficients,
        s: &mut BorderedBand,
    ) {
        let l = &self.links[li];
        let tb = &l.element.quad;
        let ne = l.ne;
        {
            let d = Self::elem_v(q, dofs);
            let u = [Self::val(q, l.u_dof[e]), Self::val(q, l.u_dof[e + 1])];
            let edofs = ElementDofs {
                u: [l.u_dof[e], l.u_dof[e + 1]],
                d: *dofs,
            };
            l.element
                .kind
                .tangent(&l.element, &edofs, u, &d, c.c_q, &mut |i, j, v| {
                    s.add(i, j, v)
                });
        }
        if l.kelvin_voigt > 0.0 {
            let cf = l.kelvin_voigt / l.ei;
            for a in 0..ne {
                for b in 0..ne {
                    if dofs[a] != NONE && dofs[b] != NONE {
                        s.add(dofs[a], dofs[b], c.c_v * cf * l.element.kb[a][b]);
                    }
                }
            }
        }
        if l.foreshortening {
            let mut kg = [[0.0; MAXE]; MAXE];
            for j in 0..tb.ng + 1 {
                let tl = self.tail[li][e * (tb.ng + 1) + j];
                for kk in 0..tb.nsg {
                    let dn = &tb.sub_dn[j][kk];
                    let wgt = -tl * tb.sub_wh[j][kk];
                    for a in 0..ne {
                        for b in 0..ne {
                            kg[a][b] += wgt * dn[a] * dn[b];
                        }
                    }
                }
            }
            for a in 0..ne {
                for b in 0..ne {
                    if dofs[a] != NONE && dofs[b] != NONE {
                        s.add(dofs[a], dofs[b], c.c_q * kg[a][b]);
                    }
                }
            }
        }
    }
}
