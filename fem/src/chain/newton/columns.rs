//! A column of the point Jacobian J evaluated at one mass point, the derivatives of the
//! columns and of the point's acceleration with respect to a DOF (the Coriolis and stiffness
//! parts of ∂(Jᵀf)/∂q), and the sink the matrix entries go to (the chain's numbering or the
//! augmented layout of the exact matrix).

use crate::band::BorderedBand;
use crate::chain::NONE;
use crate::chain::augmented::AugmentedLayout;
use crate::chain::geometry::{V2, perp};

/// A column of J evaluated at one mass point.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ColumnAt {
    pub(super) dof: usize,
    pub(super) j: V2,
    pub(super) jdot: V2,
    pub(super) rotation: bool,
    pub(super) pos: f64,
    pub(super) centre_acc: V2,
    /// Angular velocity and acceleration of the frame a translation column is attached to.
    pub(super) rate: f64,
    pub(super) rate_dot: f64,
}

/// Where the Newton matrix entries go: the chain's own numbering, or the augmented layout of
/// the exact matrix (chain DOFs through `map`, auxiliary unknowns directly).
pub(super) struct Sink<'a> {
    pub(super) s: &'a mut BorderedBand,
    pub(super) layout: Option<&'a AugmentedLayout>,
}

impl Sink<'_> {
    /// Adds `v` at chain DOFs (i, j).
    #[inline]
    pub(super) fn add(&mut self, i: usize, j: usize, v: f64) {
        match self.layout {
            None => self.s.add(i, j, v),
            Some(l) => self.s.add(l.map[i], l.map[j], v),
        }
    }

    /// Index of a chain DOF in the matrix.
    #[inline]
    pub(super) fn index(&self, i: usize) -> usize {
        match self.layout {
            Some(l) if i != NONE => l.map[i],
            _ => i,
        }
    }

    /// Adds `v` at matrix indices (i, j) (skipped where either is [`NONE`]).
    #[inline]
    pub(super) fn add_at(&mut self, i: usize, j: usize, v: f64) {
        if i != NONE && j != NONE && v != 0.0 {
            self.s.add(i, j, v);
        }
    }
}

/// ∂J_a/∂q_b at a point: an upstream rotation b turns J_a; for a rotation a, a DOF b that
/// moves the point relative to a's centre (b downstream of it) adds perp(J_b). A translation
/// upstream of a's centre moves the centre with the point and leaves J_a unchanged.
#[inline]
pub(super) fn column_derivative(a_rotation: bool, a_pos: f64, a_j: V2, b: &ColumnAt) -> V2 {
    if b.rotation && b.pos <= a_pos {
        perp(a_j)
    } else if a_rotation && b.pos > a_pos {
        perp(b.j)
    } else {
        V2::zeros()
    }
}

/// ∂a/∂q_b at a point with acceleration `acc`: rigid rotation of the downstream acceleration
/// field about the centre, or the frame's rigid acceleration field at a displaced point.
#[inline]
pub(super) fn dacc(b: &ColumnAt, acc: V2) -> V2 {
    if b.rotation {
        perp(acc - b.centre_acc)
    } else {
        (-b.rate * b.rate) * b.j + (b.rate_dot * perp(b.j))
    }
}
