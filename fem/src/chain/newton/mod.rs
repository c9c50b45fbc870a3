//! Newton matrix S = c_a M + c_v C + c_q K at the state of the last residual: inertia of every
//! mass point through the columns of its Jacobian, section rotary inertia, the element tangent,
//! Kelvin–Voigt and the foreshortening geometric stiffness, tip and hub bodies, joint springs.
//!
//! Layout: this file assembles link by link; [`columns`] holds the Jacobian columns at a
//! point, their derivatives and the entry sink; [`foreshortening`] the virtual directions and
//! running sums of the exact (augmented) matrix.

use super::augmented::AugmentedLayout;
use super::geometry::{V2, perp, rot, rot_t};
use super::{Chain, ElementDofs, FrameState, MAX_COLUMNS, MAX_LINKS, MAXE, NONE};
use crate::band::BorderedBand;
use crate::system::NewtonCoefficients;
use columns::{ColumnAt, Sink, column_derivative, dacc};
use foreshortening::{Running, Virtual, virtual_terms};

mod columns;
mod foreshortening;

/// A column of J contributed by an ancestor (or own joint) DOF, in frame-i coordinates.
#[derive(Debug, Clone, Copy, Default)]
struct AncestorColumn {
    dof: usize,
    /// Rotation about a centre (`vec` = centre, `dvec` = its velocity) or translation along
    /// `vec` (whose frame turns at `rate`).
    rotation: bool,
    vec: V2,
    dvec: V2,
    centre_acc: V2,
    rate: f64,
    rate_dot: f64,
    /// Position along the chain (smaller = closer to the ground).
    pos: f64,
}

/// The assembly's view of the link being assembled ([`Chain::begin_link`]): what its mass
/// points share, plus a per-point column buffer. Fixed size: no heap allocation per matrix.
struct LinkAssembly {
    c: NewtonCoefficients,
    /// Angular velocity and acceleration of the link frame.
    w: f64,
    wd: f64,
    /// Gravity in frame coordinates.
    g_loc: V2,
    /// Chain position of the link's own DOFs (between its joint, 2i, and its tip slope).
    local_pos: f64,
    /// Columns of J for the DOFs of ancestors (and the own joint), in frame coordinates.
    cols: [AncestorColumn; MAX_COLUMNS],
    ncols: usize,
    /// DOFs of the rotation columns, with room for the tip slope (tip inertia).
    rot_dofs: [usize; MAX_COLUMNS + 1],
    nr: usize,
    /// Axial displacement directions of a point whose variation comes through auxiliary
    /// unknowns: `virt[0]` its own link's foreshortening (set per point), `virt[1..=nanc]`
    /// each ancestor's s(L).
    virt: [Virtual; MAX_LINKS + 1],
    nanc: usize,
    /// Per-point column buffer (filled up to the point's column count).
    jc: [ColumnAt; MAXE + 2 + MAX_COLUMNS],
}

impl LinkAssembly {
    fn new(c: NewtonCoefficients) -> Self {
        LinkAssembly {
            c,
            w: 0.0,
            wd: 0.0,
            g_loc: V2::zeros(),
            local_pos: 0.0,
            cols: [AncestorColumn::default(); MAX_COLUMNS],
            ncols: 0,
            rot_dofs: [NONE; MAX_COLUMNS + 1],
            nr: 0,
            virt: [Virtual::default(); MAX_LINKS + 1],
            nanc: 0,
            jc: [ColumnAt::default(); MAXE + 2 + MAX_COLUMNS],
        }
    }

    /// The columns of J at a point p with velocity ṗ into `jc`: the link's own DOFs `local`
    /// (translations along their vector in the frame, J̇ = ω perp(J)), then the shared columns
    /// (a rotation about centre c: J = perp(p − c), J̇ = ω perp(J) + perp(ṗ − ċ); a translation
    /// along an ancestor frame's axis: J̇ = rate·perp(J)). Returns their count.
    fn point_columns(&mut self, p: V2, pd: V2, local: &[(usize, V2)]) -> usize {
        let (w, wd) = (self.w, self.wd);
        let mut nj = 0;
        for &(dof, v) in local {
            if dof != NONE {
                self.jc[nj] = ColumnAt {
                    dof,
                    j: v,
                    jdot: w * perp(v),
                    rotation: false,
                    pos: self.local_pos,
                    centre_acc: V2::zeros(),
                    rate: w,
                    rate_dot: wd,
                };
                nj += 1;
            }
        }
        for col in &self.cols[..self.ncols] {
            self.jc[nj] = if col.rotation {
                let j = perp(p - col.vec);
                ColumnAt {
                    dof: col.dof,
                    j,
                    jdot: w * perp(j) + perp(pd - col.dvec),
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
                    jdot: col.rate * perp(col.vec),
                    rotation: false,
                    pos: col.pos,
                    centre_acc: V2::zeros(),
                    rate: col.rate,
                    rate_dot: col.rate_dot,
                }
            };
            nj += 1;
        }
        nj
    }

    /// One mass point: m at local position p with velocity ṗ and d'Alembert density
    /// f = m(a − g). Adds c_a·M + c_v·C + c_q·K_inertial for all its columns, with
    /// C = Σ m Jᵀ 2J̇ and K_inertial = Σ m[(∂J/∂q)ᵀ(a − g) + Jᵀ ∂a/∂q], and the couplings
    /// through the auxiliary unknowns of the ancestors' virtual directions and (`own`) of the
    /// point's own one, `virt[0]`.
    fn mass_point(
        &mut self,
        s: &mut Sink<'_>,
        own: bool,
        m: f64,
        (p, pd, f): (V2, V2, V2),
        local: &[(usize, V2)],
    ) {
        let c = self.c;
        let g_loc = self.g_loc;
        let nj = self.point_columns(p, pd, local);
        let jc = &self.jc[..nj];
        let acc = (1.0 / m) * f + g_loc;
        for ca in jc {
            for cb in jc {
                let mut v = c.c_a * m * ca.j.dot(&cb.j);
                // A zero coefficient skips its term (the mass matrix of the contact
                // maps): adding its ±0 would leave v unchanged.
                if c.c_v != 0.0 {
                    v += c.c_v * 2.0 * m * ca.j.dot(&cb.jdot);
                }
                if c.c_q != 0.0 {
                    let dja = column_derivative(ca.rotation, ca.pos, ca.j, cb);
                    v += c.c_q * m * (dja.dot(&(acc - g_loc)) + ca.j.dot(&dacc(cb, acc)));
                }
                if v != 0.0 {
                    s.add(ca.dof, cb.dof, v);
                }
            }
        }
        let first = if own { 0 } else { 1 };
        let virt = &self.virt[first..1 + self.nanc];
        if !virt.is_empty() {
            virtual_terms(s, jc, virt, m, acc, f, c);
        }
    }
}

impl Chain {
    /// Assembles the Newton matrix c_a·M + c_v·C + c_q·K at the state of the last
    /// [`Chain::residual`] call (which must precede it). Exact without foreshortening; with
    /// foreshortening it omits the dense ∂s/∂q couplings (see [`Chain::exact_newton_matrix`]).
    pub fn newton_matrix(&self, q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        s.clear();
        let mut sink = Sink { s, layout: None };
        self.assemble(q, q, q, c, &mut sink);
    }

    /// The exact Newton matrix c_a·M + c_v·C + c_q·K of a chain with foreshortening, as the
    /// augmented sparse system of `layout` ([`Chain::augmented_layout`]; module docs of
    /// `chain::augmented`), at the state (q, q̇, q̈) of the last [`Chain::residual`] call (which
    /// must precede it). `s` has the layout's pattern ([`Chain::new_augmented_matrix`]).
    pub fn exact_newton_matrix(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        c: NewtonCoefficients,
        layout: &AugmentedLayout,
        s: &mut BorderedBand,
    ) {
        s.clear();
        let mut sink = Sink {
            s,
            layout: Some(layout),
        };
        self.assemble(q, qd, qdd, c, &mut sink);
    }

    /// A matrix container with the pattern of `layout`, factorized by the band solver with a
    /// dense border Schur complement ([`BorderedBand::with_band_solver`]).
    pub fn new_augmented_matrix(&self, layout: &AugmentedLayout) -> BorderedBand {
        BorderedBand::with_band_solver(
            layout.n_interior,
            layout.n - layout.n_interior,
            layout.half_bandwidth,
        )
    }

    /// The Newton matrix into `s`; with a layout, also every foreshortening coupling through
    /// the auxiliary unknowns (q̇, q̈ are read only then). Link by link, from the ground: the
    /// link's shared columns ([`Chain::begin_link`]), its elements ([`Chain::element_block`]),
    /// its tip body ([`Chain::tip_mass`], [`Chain::rotary_inertias`]) and its joint spring and
    /// damper.
    fn assemble(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        c: NewtonCoefficients,
        s: &mut Sink<'_>,
    ) {
        // Fixed-size buffers: no heap allocation per Newton matrix.
        let mut la = LinkAssembly::new(c);
        for li in 0..self.links.len() {
            let l = &self.links[li];
            self.begin_link(li, s.layout, &mut la);
            for e in 0..l.n_el {
                self.element_block(li, e, (q, qd, qdd), &mut la, s);
            }
            self.tip_mass(li, &mut la, s);
            self.rotary_inertias(li, &mut la, s);
            // Joint spring and damper.
            if l.joint.dof != NONE {
                let jd = l.joint.dof;
                s.add(jd, jd, c.c_q * l.joint.stiffness + c.c_v * l.joint.damping);
            }
        }
    }

    /// What every point of link `li` shares, into `la`: the frame's rates, gravity in frame
    /// coordinates, the columns of J of the ancestor (and own-joint) DOFs and which of them are
    /// rotations, and with a `layout` the virtual directions of the ancestors' tip
    /// foreshortenings s(Lₖ) (translations along frame k's x axis).
    fn begin_link(&self, li: usize, layout: Option<&AugmentedLayout>, la: &mut LinkAssembly) {
        let fr = self.frames[li];
        la.g_loc = rot_t(fr.phi, self.gravity);
        la.ncols = self.ancestor_columns(li, &mut la.cols);
        la.w = fr.dphi;
        la.wd = fr.ddphi;
        la.local_pos = 2.0 * li as f64 + 0.5;
        la.nanc = 0;
        if let Some(lay) = layout {
            for k in 0..li {
                if !self.links[k].foreshortening {
                    continue;
                }
                let fa = &self.frames[k];
                let tip = self.links[k].n_el;
                let mut v = Virtual {
                    j: rot_t(fr.phi, rot(fa.phi, V2::new(1.0, 0.0))),
                    rate: fa.dphi,
                    rate_dot: fa.ddphi,
                    pos: 2.0 * k as f64 + 0.5,
                    ..Default::default()
                };
                v.set_node(lay.z[k][tip], lay.theta[k][tip]);
                la.virt[1 + la.nanc] = v;
                la.nanc += 1;
            }
        }
        // Rotation columns (upstream joints and tip slopes): they turn every section of
        // this link by one.
        la.rot_dofs = [NONE; MAX_COLUMNS + 1];
        la.nr = 0;
        for col in &la.cols[..la.ncols] {
            if col.rotation {
                la.rot_dofs[la.nr] = col.dof;
                la.nr += 1;
            }
        }
    }

    /// Element `e` of link `li`: its Gauss points as mass points (with the link's own
    /// foreshortening, the running sums Y, σ over the element's sub-intervals give each point
    /// its virtual direction), the section rotary inertia, the element stiffness, and with
    /// foreshortening the element's rows of the running sums.
    fn element_block(
        &self,
        li: usize,
        e: usize,
        (q, qd, qdd): (&[f64], &[f64], &[f64]),
        la: &mut LinkAssembly,
        s: &mut Sink<'_>,
    ) {
        let l = &self.links[li];
        let tb = &l.element.quad;
        let ne = l.ne;
        let c = la.c;
        let own_fs = s.layout.is_some() && l.foreshortening;
        let dofs = l.elem_dofs(e);
        // Running sums over the element's foreshortening sub-intervals: Y (the
        // c-weighted variations of s, ṡ, s̈ per local DOF) and σ = ∂s/∂q.
        let mut run = Running::default();
        let (d, dd, ddd) = if own_fs {
            (
                Self::elem_v(q, &dofs),
                Self::elem_v(qd, &dofs),
                Self::elem_v(qdd, &dofs),
            )
        } else {
            ([0.0; MAXE], [0.0; MAXE], [0.0; MAXE])
        };
        for g in 0..tb.ng {
            let m = l.rho_a * tb.wh[g];
            let p = self.pos[li][e * tb.ng + g];
            let xi = tb.xi[g];
            let n = tb.n[g];
            // Translation columns of the point: the v shapes (the ψ DOFs of a
            // Timoshenko element do not move it), then u.
            let mut local = [(NONE, V2::zeros()); MAXE + 2];
            let mut nloc = 0;
            for a in 0..ne {
                if !l.element.kind.translates(a) {
                    continue;
                }
                local[nloc] = (dofs[a], V2::new(0.0, n[a]));
                nloc += 1;
            }
            local[nloc] = (l.u_dof[e], V2::new(1.0 - xi, 0.0));
            local[nloc + 1] = (l.u_dof[e + 1], V2::new(xi, 0.0));
            nloc += 2;
            let pd = self.vel[li][e * tb.ng + g];
            let f = self.force[li][e * tb.ng + g];
            let own = if let (true, Some(lay)) = (own_fs, s.layout) {
                run.sub_interval(l, g, &d, &dd, &ddd, c);
                la.virt[0] = run.own_point(lay, li, e, &dofs, ne, la.w, la.wd, la.local_pos);
                true
            } else {
                false
            };
            la.mass_point(s, own, m, (p, pd, f), &local[..nloc]);
        }
        // Section rotary inertia: the section angle is linear in q (J constant), so
        // only the mass term c_a ρI w JᵀJ.
        if l.rho_i > 0.0 && c.c_a != 0.0 {
            self.section_inertia_block(li, &dofs, &la.rot_dofs[..la.nr], c.c_a, s);
        }
        self.element_stiffness_block(li, e, &dofs, q, c, s);
        if let (true, Some(lay)) = (own_fs, s.layout) {
            run.sub_interval(l, tb.ng, &d, &dd, &ddd, c);
            run.element_rows(s, lay, li, e, &dofs, ne);
        }
    }

    /// The tip of link `li`: with the own foreshortening the tail row of the tip node (δT at
    /// the tip is the variation of the tip's axial load), and the tip mass as a mass point
    /// (force m(a_tip − g), virtual direction the tip's s(L)).
    fn tip_mass(&self, li: usize, la: &mut LinkAssembly, s: &mut Sink<'_>) {
        let l = &self.links[li];
        let fr = self.frames[li];
        let k = l.n_el;
        let own_fs = s.layout.is_some() && l.foreshortening;
        if let (true, Some(lay)) = (own_fs, s.layout) {
            s.add_at(lay.theta[li][k], lay.theta[li][k], 1.0);
        }
        if l.tip_mass > 0.0 {
            let local = [
                (l.v_dof[k], V2::new(0.0, 1.0)),
                (l.u_dof[k], V2::new(1.0, 0.0)),
            ];
            let f = l.tip_mass * (fr.a_tip - la.g_loc);
            let own = if let (true, Some(lay)) = (own_fs, s.layout) {
                let mut v = Virtual {
                    j: V2::new(1.0, 0.0),
                    rate: la.w,
                    rate_dot: la.wd,
                    pos: la.local_pos,
                    ..Default::default()
                };
                v.set_node(lay.z[li][k], lay.theta[li][k]);
                la.virt[0] = v;
                true
            } else {
                false
            };
            la.mass_point(s, own, l.tip_mass, (fr.p_tip, fr.dp_tip, f), &local);
        }
    }

    /// Rotational inertias of link `li`: c_a I JᵀJ for the hub (turning with every rotation
    /// column of the link) and the tip body (those plus the tip slope).
    fn rotary_inertias(&self, li: usize, la: &mut LinkAssembly, s: &mut Sink<'_>) {
        let l = &self.links[li];
        let c = la.c;
        if l.hub_inertia > 0.0 {
            for a in 0..la.nr {
                for b in 0..la.nr {
                    s.add(la.rot_dofs[a], la.rot_dofs[b], c.c_a * l.hub_inertia);
                }
            }
        }
        if l.tip_inertia > 0.0 {
            let k = l.n_el;
            if l.r_dof[k] != NONE {
                la.rot_dofs[la.nr] = l.r_dof[k];
                la.nr += 1;
            }
            for a in 0..la.nr {
                for b in 0..la.nr {
                    s.add(la.rot_dofs[a], la.rot_dofs[b], c.c_a * l.tip_inertia);
                }
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
            let c = rot_t(fr.phi, o.r - fr.r);
            let cdot = (-fr.dphi) * perp(c) + rot_t(fr.phi, o.dr - fr.dr);
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
                    (al.v_dof[al.n_el], V2::new(0.0, 1.0)),
                    (al.u_dof[al.n_el], V2::new(1.0, 0.0)),
                ] {
                    if dof != NONE {
                        cols[ncols] = AncestorColumn {
                            dof,
                            rotation: false,
                            vec: rot_t(fr.phi, rot(fa.phi, e)),
                            dvec: V2::zeros(),
                            centre_acc: V2::zeros(),
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
        s: &mut Sink<'_>,
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
        s: &mut Sink<'_>,
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
