//! The exact Newton matrix's foreshortening couplings: the axial displacements of mass points
//! whose variation comes through auxiliary unknowns (a link's own foreshortening s(x), an
//! ancestor's tip s(L)) as virtual directions, their couplings with the real Jacobian columns,
//! and the running sums over an element's foreshortening sub-intervals with the element's
//! rows of the augmented system.

use super::columns::{ColumnAt, Sink, dacc};
use crate::chain::augmented::AugmentedLayout;
use crate::chain::geometry::{V2, perp};
use crate::chain::{LinkModel, MAXE, NONE};
use crate::linalg::dot;
use crate::system::NewtonCoefficients;

/// Longest expansion of a virtual direction: one auxiliary unknown plus the element's DOFs.
const VIRTUAL_TERMS: usize = MAXE + 1;

/// An axial displacement of a point whose variation is not a chain DOF: the foreshortening
/// s(x) of the point's own link (or the tip s(L) of an ancestor), a translation along `j`
/// attached to a frame turning at `rate`. Its variation (δs, δṡ, δs̈) is the combination `col`
/// of matrix columns (a node's Z plus the element's running sums), and its generalized force
/// f·j enters the rows `row` (the node's tail Θ with −1, and the element's DOFs with
/// σ = ∂s(x)/∂q).
#[derive(Debug, Clone, Copy)]
pub(super) struct Virtual {
    pub(super) j: V2,
    pub(super) rate: f64,
    pub(super) rate_dot: f64,
    pub(super) pos: f64,
    pub(super) col: [[(usize, f64); VIRTUAL_TERMS]; 3],
    pub(super) ncol: usize,
    pub(super) row: [(usize, f64); VIRTUAL_TERMS],
    pub(super) nrow: usize,
}

impl Default for Virtual {
    fn default() -> Self {
        Virtual {
            j: V2::zeros(),
            rate: 0.0,
            rate_dot: 0.0,
            pos: 0.0,
            col: [[(NONE, 0.0); VIRTUAL_TERMS]; 3],
            ncol: 0,
            row: [(NONE, 0.0); VIRTUAL_TERMS],
            nrow: 0,
        }
    }
}

impl Virtual {
    /// A node's own unknowns: variation Z (three columns) and tail Θ (row, −1).
    pub(super) fn set_node(&mut self, z: [usize; 3], theta: usize) {
        for t in 0..3 {
            self.col[t][0] = (z[t], 1.0);
        }
        self.ncol = 1;
        self.row[0] = (theta, -1.0);
        self.nrow = 1;
    }

    /// (∂a/∂u, ∂a/∂u̇) of the point for this direction (∂a/∂ü = j).
    pub(super) fn motion(&self) -> (V2, V2) {
        (
            (-self.rate * self.rate) * self.j + (self.rate_dot * perp(self.j)),
            (2.0 * self.rate) * perp(self.j),
        )
    }

    /// Adds `weight`·(k₀ δs + k₁ δṡ + k₂ δs̈) of this direction to matrix row `row`.
    pub(super) fn add_columns(&self, s: &mut Sink<'_>, row: usize, weight: f64, k: [f64; 3]) {
        if row == NONE || weight == 0.0 {
            return;
        }
        for t in 0..3 {
            if k[t] == 0.0 {
                continue;
            }
            for &(col, cc) in &self.col[t][..self.ncol] {
                s.add_at(row, col, weight * k[t] * cc);
            }
        }
    }
}

/// The couplings of one mass point m (acceleration `acc`, d'Alembert force `f`, real columns
/// `jc`) through its virtual directions `virt`: the rows of the real columns on the
/// variations (δs, δṡ, δs̈) (mass, Coriolis and stiffness parts of ∂(J_aᵀ f)/∂u), the virtual
/// rows on the real columns, and the virtual rows on the virtual columns.
pub(super) fn virtual_terms(
    s: &mut Sink<'_>,
    jc: &[ColumnAt],
    virt: &[Virtual],
    m: f64,
    acc: V2,
    f: V2,
    c: NewtonCoefficients,
) {
    for u in virt {
        let (dacc_u, two_jdot_u) = u.motion();
        for a in jc {
            let mut k = [
                m * a.j.dot(&dacc_u),
                m * a.j.dot(&two_jdot_u),
                m * a.j.dot(&u.j),
            ];
            if a.rotation && u.pos > a.pos {
                k[0] += perp(u.j).dot(&f);
            }
            let ra = s.index(a.dof);
            u.add_columns(s, ra, 1.0, k);
        }
        for b in jc {
            let dja = if b.rotation && b.pos <= u.pos {
                perp(u.j)
            } else {
                V2::zeros()
            };
            let v = c.c_a * m * u.j.dot(&b.j)
                + c.c_v * 2.0 * m * u.j.dot(&b.jdot)
                + c.c_q * (dja.dot(&f) + m * u.j.dot(&dacc(b, acc)));
            if v != 0.0 {
                let cb = s.index(b.dof);
                for &(row, cr) in &u.row[..u.nrow] {
                    s.add_at(row, cb, cr * v);
                }
            }
        }
        for w in virt {
            let (dacc_w, two_jdot_w) = w.motion();
            let k = [
                m * u.j.dot(&dacc_w),
                m * u.j.dot(&two_jdot_w),
                m * u.j.dot(&w.j),
            ];
            for &(row, cr) in &u.row[..u.nrow] {
                w.add_columns(s, row, cr, k);
            }
        }
    }
}

/// Running sums over one element's foreshortening sub-intervals (the quadrature of
/// s = −½∫v′²): Y, the variations of (s, ṡ, s̈) per local DOF weighted with the Newton
/// coefficients — δs = −∫c_q v′ δ′, δṡ = −∫(c_q v̇′ + c_v v′) δ′,
/// δs̈ = −∫(c_q v̈′ + 2c_v v̇′ + c_a v′) δ′ — and σ = ∂s/∂q = −∫ v′ N′.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Running {
    pub(super) y: [[f64; MAXE]; 3],
    pub(super) sigma: [f64; MAXE],
}

impl Running {
    /// Adds sub-interval `j` of the element with local values (d, ḋ, d̈).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn sub_interval(
        &mut self,
        l: &LinkModel,
        j: usize,
        d: &[f64; MAXE],
        dd: &[f64; MAXE],
        ddd: &[f64; MAXE],
        c: NewtonCoefficients,
    ) {
        let tb = &l.element.quad;
        let ne = l.ne;
        for k in 0..tb.nsg {
            let dn = &tb.sub_dn[j][k];
            let w = tb.sub_wh[j][k];
            let vp = dot(&dn[..ne], &d[..ne]);
            let vpd = dot(&dn[..ne], &dd[..ne]);
            let vpdd = dot(&dn[..ne], &ddd[..ne]);
            let coef = [
                c.c_q * vp,
                c.c_q * vpd + c.c_v * vp,
                c.c_q * vpdd + 2.0 * c.c_v * vpd + c.c_a * vp,
            ];
            for a in 0..ne {
                let wdn = -w * dn[a];
                self.sigma[a] += wdn * vp;
                for t in 0..3 {
                    self.y[t][a] += wdn * coef[t];
                }
            }
        }
    }

    /// The virtual direction of a Gauss point of element `e` after its sub-intervals.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn own_point(
        &self,
        lay: &AugmentedLayout,
        li: usize,
        e: usize,
        dofs: &[usize; MAXE],
        ne: usize,
        rate: f64,
        rate_dot: f64,
        pos: f64,
    ) -> Virtual {
        let mut v = Virtual {
            j: V2::new(1.0, 0.0),
            rate,
            rate_dot,
            pos,
            ..Default::default()
        };
        v.set_node(lay.z[li][e], lay.theta[li][e]);
        for a in 0..ne {
            let i = if dofs[a] == NONE {
                NONE
            } else {
                lay.map[dofs[a]]
            };
            for t in 0..3 {
                v.col[t][1 + a] = (i, self.y[t][a]);
            }
            v.row[1 + a] = (i, self.sigma[a]);
        }
        v.ncol = 1 + ne;
        v.nrow = 1 + ne;
        v
    }

    /// The element's rows of the running sums (after all its sub-intervals):
    /// Zₑ₊₁ − Zₑ − YΔ = 0, the identity part Θₑ − Θₑ₊₁ of the tail row (its point loads come
    /// from the virtual rows), and σ Θₑ₊₁ in the element's DOF rows.
    pub(super) fn element_rows(
        &self,
        s: &mut Sink<'_>,
        lay: &AugmentedLayout,
        li: usize,
        e: usize,
        dofs: &[usize; MAXE],
        ne: usize,
    ) {
        let (z0, z1) = (lay.z[li][e], lay.z[li][e + 1]);
        for t in 0..3 {
            s.add_at(z1[t], z1[t], 1.0);
            s.add_at(z1[t], z0[t], -1.0);
            for a in 0..ne {
                if dofs[a] != NONE {
                    s.add_at(z1[t], lay.map[dofs[a]], -self.y[t][a]);
                }
            }
        }
        let (t0, t1) = (lay.theta[li][e], lay.theta[li][e + 1]);
        s.add_at(t0, t0, 1.0);
        s.add_at(t0, t1, -1.0);
        for a in 0..ne {
            if dofs[a] != NONE {
                s.add_at(lay.map[dofs[a]], t1, self.sigma[a]);
            }
        }
    }
}
