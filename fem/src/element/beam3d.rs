//! 3-D beam element of the payload link (seed 002), composed from the planar element contract:
//! each bending plane, v (turning plane) and w (vertical), is interpolated by a planar
//! Euler–Bernoulli [`Element`] of the registry (its deflection, slope and curvature shapes,
//! [`Element::shapes`]), axial u and torsion φ by the linear bar ([`bar_shapes`]). The nodal
//! layout carries (v, v′) per node, so the bending element is one whose local DOFs are those
//! of its two nodes ([`bending_element`]: the Hermite cubic).
//!
//! Nodal DOFs, in this order, for the fields the scene carries: u, v, v′, w, w′, φ. Node 0 is the
//! clamped root (no DOFs); node k ≥ 1 numbers its DOFs from (k − 1)·n_node, so an element couples
//! DOFs at most 2·n_node − 1 apart (the half-bandwidth of every assembled matrix). Along element e
//! (x = (e + ξ)h) each field and its x-derivatives are sparse rows over the global DOFs
//! ([`Row`]): the model assembles every operator as sums of weighted outer products of such rows
//! at Gauss points, and the payload attaches through the tip node's rows.

use data::scene::LinkField;

use super::contract::{Element, bar_shapes};

/// The planar element both bending planes use: the registry's Hermite cubic, whose local DOFs
/// are its two nodes' (v, v′), the nodal layout's (an element with interior DOFs has no place in
/// it: the family refuses another `discretization.element`,
/// [`crate::settings::cubic_elements_or`]).
pub fn bending_element() -> &'static dyn Element {
    super::hermite_cubic()
}

/// Slots of the nodal DOFs.
pub const U: usize = 0;
pub const V: usize = 1;
pub const V_SLOPE: usize = 2;
pub const W: usize = 3;
pub const W_SLOPE: usize = 4;
pub const PHI: usize = 5;

/// Which nodal DOFs exist (fields not carried are not built) and where they sit in a node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeLayout {
    pub per_node: usize,
    offset: [Option<usize>; 6],
}

impl NodeLayout {
    pub fn new(fields: &[LinkField]) -> Self {
        let mut offset = [None; 6];
        let mut k = 0;
        let mut take = |slots: &[usize], on: bool| {
            if on {
                for &s in slots {
                    offset[s] = Some(k);
                    k += 1;
                }
            }
        };
        take(&[U], fields.contains(&LinkField::Axial));
        take(&[V, V_SLOPE], fields.contains(&LinkField::Horizontal));
        take(&[W, W_SLOPE], fields.contains(&LinkField::Vertical));
        take(&[PHI], fields.contains(&LinkField::Torsion));
        NodeLayout {
            per_node: k,
            offset,
        }
    }

    /// Global index of a nodal DOF (None at the clamped root or for a field not carried).
    pub fn dof(&self, node: usize, slot: usize) -> Option<usize> {
        if node == 0 {
            return None;
        }
        self.offset[slot].map(|o| (node - 1) * self.per_node + o)
    }

    /// Half-bandwidth of the assembled operators.
    pub fn half_bandwidth(&self) -> usize {
        (2 * self.per_node).saturating_sub(1)
    }
}

/// A linear functional of the DOFs, `Σ val·d[idx]`, with at most four terms.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Row {
    pub len: usize,
    pub idx: [usize; 4],
    pub val: [f64; 4],
}

impl Row {
    /// The row picking one DOF (empty when the DOF does not exist).
    pub fn unit(dof: Option<usize>) -> Self {
        let mut r = Row::default();
        r.push(dof, 1.0);
        r
    }

    pub fn push(&mut self, dof: Option<usize>, v: f64) {
        if let Some(i) = dof {
            self.idx[self.len] = i;
            self.val[self.len] = v;
            self.len += 1;
        }
    }

    pub fn scaled(&self, s: f64) -> Self {
        let mut r = *self;
        r.val.iter_mut().for_each(|v| *v *= s);
        r
    }

    /// self + s·other (at most four terms in total).
    pub fn plus(&self, s: f64, other: &Row) -> Self {
        let mut r = *self;
        for k in 0..other.len {
            r.push(Some(other.idx[k]), s * other.val[k]);
        }
        r
    }

    pub fn dot(&self, d: &[f64]) -> f64 {
        (0..self.len).map(|k| self.val[k] * d[self.idx[k]]).sum()
    }

    pub fn terms(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        (0..self.len).map(|k| (self.idx[k], self.val[k]))
    }
}

/// The fields and their derivatives at one point of an element, as rows over the global DOFs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PointRows {
    pub u: Row,
    pub du: Row,
    pub v: Row,
    pub dv: Row,
    pub ddv: Row,
    pub w: Row,
    pub dw: Row,
    pub ddw: Row,
    pub phi: Row,
    pub dphi: Row,
}

/// Rows of element `e` (nodes e, e + 1) of length `h` at local coordinate ξ ∈ [0, 1], both
/// bending planes interpolated by `bending` ([`bending_element`]).
pub fn rows_at(layout: &NodeLayout, bending: &dyn Element, e: usize, h: f64, xi: f64) -> PointRows {
    let (a, b) = (e, e + 1);
    let (lin, dlin) = bar_shapes(xi, h);
    let shapes = bending.shapes(xi, h);
    let mut p = PointRows::default();
    for (k, node) in [a, b].into_iter().enumerate() {
        let u = layout.dof(node, U);
        p.u.push(u, lin[k]);
        p.du.push(u, dlin[k]);
        let f = layout.dof(node, PHI);
        p.phi.push(f, lin[k]);
        p.dphi.push(f, dlin[k]);
        for (slot_value, slot_slope, val, der, sec) in [
            (V, V_SLOPE, &mut p.v, &mut p.dv, &mut p.ddv),
            (W, W_SLOPE, &mut p.w, &mut p.dw, &mut p.ddw),
        ] {
            let (dv, ds) = (layout.dof(node, slot_value), layout.dof(node, slot_slope));
            val.push(dv, shapes.n[2 * k]);
            val.push(ds, shapes.n[2 * k + 1]);
            der.push(dv, shapes.dn[2 * k]);
            der.push(ds, shapes.dn[2 * k + 1]);
            sec.push(dv, shapes.db[2 * k]);
            sec.push(ds, shapes.db[2 * k + 1]);
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_layout_builds_only_carried_fields() {
        let all = NodeLayout::new(&LinkField::ALL);
        assert_eq!(all.per_node, 6);
        assert_eq!(all.half_bandwidth(), 11);
        assert_eq!(all.dof(0, U), None);
        assert_eq!(all.dof(2, PHI), Some(11));
        let vw = NodeLayout::new(&[LinkField::Vertical, LinkField::Torsion]);
        assert_eq!(vw.per_node, 3);
        assert_eq!(vw.dof(1, U), None);
        assert_eq!(vw.dof(1, V), None);
        assert_eq!(vw.dof(1, W), Some(0));
        assert_eq!(vw.dof(1, PHI), Some(2));
    }

    #[test]
    fn elem_bending_element_has_only_nodal_deflection_dofs() {
        let e = bending_element();
        assert!(e.interior().is_empty() && !e.independent_rotation());
        assert_eq!(e.local_dofs(), 4);
    }

    #[test]
    fn elem_rows_interpolate_nodal_values_and_slopes() {
        let lay = NodeLayout::new(&LinkField::ALL);
        let h = 0.25;
        let n = 2 * lay.per_node;
        let d: Vec<f64> = (0..n).map(|i| 0.1 * (i as f64 + 1.0)).collect();
        // Element 1 (nodes 1, 2) at its ends reproduces the nodal DOFs.
        let cubic = bending_element();
        let at0 = rows_at(&lay, cubic, 1, h, 0.0);
        let at1 = rows_at(&lay, cubic, 1, h, 1.0);
        let get = |node: usize, slot: usize| d[lay.dof(node, slot).unwrap()];
        assert!((at0.v.dot(&d) - get(1, V)).abs() < 1e-15);
        assert!((at0.dv.dot(&d) - get(1, V_SLOPE)).abs() < 1e-14);
        assert!((at1.w.dot(&d) - get(2, W)).abs() < 1e-15);
        assert!((at1.dw.dot(&d) - get(2, W_SLOPE)).abs() < 1e-14);
        assert!((at1.phi.dot(&d) - get(2, PHI)).abs() < 1e-15);
        assert!((at0.du.dot(&d) - (get(2, U) - get(1, U)) / h).abs() < 1e-13);
    }
}
