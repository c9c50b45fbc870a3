//! DOF layout of the exact Newton matrix of chains with foreshortening.
//!
//! The foreshortening s(x) = −½∫₀ˣ v′² makes every material point's axial position depend on
//! all transverse DOFs between the root and x, so the exact Jacobian of the residual is dense
//! over a link. Its dense part is semiseparable: it reaches the DOFs only through two running
//! sums along the link. The linearized residual is therefore written as a sparse system in the
//! chain DOFs Δ plus, at every node k ≥ 1 of a link with foreshortening, four auxiliary unknowns:
//!
//! * Zₖ = (δs, δṡ, δs̈)(xₖ): the variation of the foreshortening and its rates at the node
//!   (forward running sum, Zₖ₊₁ = Zₖ + Yₑ Δₑ over element e);
//! * Θₖ: the variation of the tail axial load T(xₖ) = Σ_{x > xₖ} f_x (backward running sum,
//!   Θₖ = Θₖ₊₁ + Σ_{points of e} δf_x, Θ at the tip = δ of the tip's axial load).
//!
//! Interleaving them with the nodes keeps the system a bordered band: element e couples only
//! its own DOFs, Zₑ, Zₑ₊₁, Θₑ and Θₑ₊₁. The tip unknowns of a link that carries a child join
//! the border (its child's points move with s(L)). Eliminating the auxiliary unknowns gives
//! back the exact n × n Jacobian (their block is triangular with unit diagonal), so a solve of
//! the augmented system with zero auxiliary right-hand sides is an exact Newton solve.

use super::{Chain, NONE};

/// Augmented indices of the chain DOFs and of the auxiliary running-sum unknowns.
#[derive(Debug, Clone)]
pub struct AugmentedLayout {
    /// Augmented index of every chain DOF.
    pub map: Vec<usize>,
    /// Per link, per node k = 0..=n_el: indices of (δs, δṡ, δs̈) at the node ([`NONE`] at the
    /// root and on links without foreshortening).
    pub z: Vec<Vec<[usize; 3]>>,
    /// Per link, per node: index of δT at the node ([`NONE`] at the root and on links without
    /// foreshortening).
    pub theta: Vec<Vec<usize>>,
    /// Augmented size, interior (band) part and half-bandwidth.
    pub n: usize,
    pub n_interior: usize,
    pub half_bandwidth: usize,
}

impl AugmentedLayout {
    /// Chain DOFs are `map`ped; the rest of the `n` unknowns are auxiliary.
    pub fn n_auxiliary(&self) -> usize {
        self.n - self.map.len()
    }
}

impl Chain {
    /// Whether some link has foreshortening (the exact Newton matrix needs the augmented
    /// layout).
    pub fn has_foreshortening(&self) -> bool {
        self.links.iter().any(|l| l.foreshortening)
    }

    /// The augmented layout of this chain's exact Newton matrix (module docs of
    /// `chain::augmented`). Interior: link by link, element by element, the element's interior
    /// DOFs, then its end node's DOFs and auxiliary unknowns; border: the tip nodes of links
    /// with a child (with their auxiliary unknowns), then the free joint angles.
    pub fn augmented_layout(&self) -> AugmentedLayout {
        let nl = self.links.len();
        let mut map = vec![NONE; self.ndof];
        let mut z = Vec::with_capacity(nl);
        let mut theta = Vec::with_capacity(nl);
        let mut next = 0usize;
        let node_block = |l: &super::LinkModel,
                          k: usize,
                          map: &mut Vec<usize>,
                          z: &mut [[usize; 3]],
                          theta: &mut [usize],
                          next: &mut usize| {
            for dof in [l.v_dof[k], l.r_dof[k], l.u_dof[k]] {
                if dof != NONE {
                    map[dof] = *next;
                    *next += 1;
                }
            }
            if l.foreshortening {
                z[k] = [*next, *next + 1, *next + 2];
                theta[k] = *next + 3;
                *next += 4;
            }
        };
        for l in &self.links {
            let ni = l.n_interior();
            let mut zl = vec![[NONE; 3]; l.n_el + 1];
            let mut tl = vec![NONE; l.n_el + 1];
            for e in 0..l.n_el {
                for &dof in &l.int_dof[ni * e..ni * (e + 1)] {
                    map[dof] = next;
                    next += 1;
                }
                let k = e + 1;
                if l.v_dof[k] < self.n_interior {
                    node_block(l, k, &mut map, &mut zl, &mut tl, &mut next);
                }
            }
            z.push(zl);
            theta.push(tl);
        }
        let n_interior = next;
        for (li, l) in self.links.iter().enumerate() {
            if li + 1 < nl {
                node_block(l, l.n_el, &mut map, &mut z[li], &mut theta[li], &mut next);
            }
        }
        for l in &self.links {
            if l.joint.dof != NONE {
                map[l.joint.dof] = next;
                next += 1;
            }
        }
        debug_assert!(map.iter().all(|&i| i != NONE), "every chain DOF is mapped");
        // Half-bandwidth: the widest element window (its interior DOFs and the auxiliary
        // unknowns of its two nodes).
        let mut half_bandwidth = 0;
        for (li, l) in self.links.iter().enumerate() {
            for e in 0..l.n_el {
                let (mut lo, mut hi) = (usize::MAX, 0);
                let mut see = |i: usize| {
                    if i != NONE && i < n_interior {
                        lo = lo.min(i);
                        hi = hi.max(i);
                    }
                };
                for &dof in &l.elem_dofs(e) {
                    if dof != NONE {
                        see(map[dof]);
                    }
                }
                for dof in [l.u_dof[e], l.u_dof[e + 1]] {
                    if dof != NONE {
                        see(map[dof]);
                    }
                }
                for k in [e, e + 1] {
                    for i in z[li][k] {
                        see(i);
                    }
                    see(theta[li][k]);
                }
                if hi >= lo {
                    half_bandwidth = half_bandwidth.max(hi - lo);
                }
            }
        }
        AugmentedLayout {
            map,
            z,
            theta,
            n: next,
            n_interior,
            half_bandwidth: half_bandwidth.max(1),
        }
    }
}
