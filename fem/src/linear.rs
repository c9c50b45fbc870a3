//! Linear model of one clamped link (modes and statics): dense K and M about the reference state.
//!
//! Elements ([`crate::element::for_link`]): Hermite cubic (default) or hierarchical Hermite
//! quintic for Euler–Bernoulli links (`discretization.element`), the cubic-v/quadratic-θ element
//! for `shear` links. DOF order per element e = 0..n−1: its interior DOFs (quintic bubbles a₁, a₂; Timoshenko
//! v(⅓), v(⅔), θ(½)), then the DOFs of its end node e+1: v, rotation (v′ for Euler–Bernoulli, θ
//! for Timoshenko), then u when `axial` is on. Node 0 is clamped and has no DOFs. Interleaving the
//! interior DOFs keeps the matrices banded. For a hub spinning at constant Ω (prescribed
//! `constant-rate`), the linearization of the floating-frame energy about the undeformed state adds
//! * with `foreshortening`: the centrifugal geometric stiffness ∫N v′² with
//!   N(x) = ρAΩ²(L² − x²)/2 + m_tip Ω² L (from −Ω²∫ρA x s, s = −½∫v′²), and
//! * always: the rotating-frame softening −Ω²∫ρA v² (−Ω² m_tip v_tip²),
//!
//! so that in-plane bending obeys ω_in² = ω_out² − Ω² for the inextensible model.

use data::scene::{Link, PrescribedMotion};
use faer::Mat;

use crate::element::quadrature::gauss01;
use crate::element::{Element, Local, MAXE};
use crate::error::FemError;

/// The element kind of a link (from [`crate::element::for_link`]).
pub type ElementKind = &'static dyn Element;

/// Where the DOFs sit: per element, `interior` DOFs, then `dofs_per_node` DOFs of its end node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeLayout {
    pub dofs_per_node: usize,
    pub interior: usize,
    pub axial: bool,
    pub shear: bool,
}

impl NodeLayout {
    fn block(&self) -> usize {
        self.dofs_per_node + self.interior
    }
    pub fn v(&self, node: usize) -> Option<usize> {
        (node > 0).then(|| (node - 1) * self.block() + self.interior)
    }
    pub fn rot(&self, node: usize) -> Option<usize> {
        self.v(node).map(|i| i + 1)
    }
    pub fn u(&self, node: usize) -> Option<usize> {
        self.v(node).filter(|_| self.axial).map(|i| i + 2)
    }
    /// Interior DOF `k` of element `e`.
    pub fn interior(&self, e: usize, k: usize) -> usize {
        debug_assert!(k < self.interior);
        e * self.block() + k
    }
    /// Whether global DOF `i` is an axial displacement u.
    pub fn is_axial(&self, i: usize) -> bool {
        self.axial && i % self.block() == self.interior + 2
    }
    /// Global index of each local transverse DOF of element `e` (None: clamped).
    pub fn element_dofs(&self, e: usize) -> [Option<usize>; MAXE] {
        let mut d = [None; MAXE];
        d[0] = self.v(e);
        d[1] = self.rot(e);
        d[2] = self.v(e + 1);
        d[3] = self.rot(e + 1);
        for k in 0..self.interior {
            d[4 + k] = Some(self.interior(e, k));
        }
        d
    }
}

/// Assembled linear system of one clamped link.
#[derive(Debug, Clone)]
pub struct LinearLink {
    pub layout: NodeLayout,
    pub element: ElementKind,
    pub n_el: usize,
    pub length: f64,
    pub m: Mat<f64>,
    pub k: Mat<f64>,
}

/// Constant hub rate of a link's joint (0 for a clamped root).
pub fn hub_rate(link: &Link) -> Result<f64, FemError> {
    match &link.joint.prescribed {
        Some(PrescribedMotion::Fixed) => Ok(0.0),
        Some(PrescribedMotion::ConstantRate { rate }) => Ok(*rate),
        Some(PrescribedMotion::SpinUp { .. }) => Err(FemError::unsupported(
            "fem modes/statics: a spin-up hub has no constant reference state; use `run`",
        )),
        None => Err(FemError::unsupported(
            "fem modes/statics: link with a free joint (linearization of a free chain about its \
             initial configuration is not implemented)",
        )),
    }
}

impl LinearLink {
    /// Assembles K and M of `link` with `n_el` elements of kind `element`, spinning at constant
    /// `omega`.
    pub fn assemble(
        link: &Link,
        n_el: usize,
        omega: f64,
        element: ElementKind,
    ) -> Result<Self, FemError> {
        let layout = NodeLayout {
            dofs_per_node: if link.axial { 3 } else { 2 },
            interior: element.interior().len(),
            axial: link.axial,
            shear: link.shear,
        };
        if link.axial && omega != 0.0 {
            return Err(FemError::unsupported(
                "fem modes: extensible link on a spinning hub: the axial–bending Coriolis \
                 coupling makes this a gyroscopic (state-space) eigenproblem, not implemented",
            ));
        }
        let n = n_el * layout.block();
        let h = link.length / n_el as f64;
        let mut m = Mat::<f64>::zeros(n, n);
        let mut k = Mat::<f64>::zeros(n, n);
        let rho_a = link.mass_per_length;
        let rho_i = if link.rotary_inertia {
            link.rotary_inertia_per_length.unwrap_or(0.0)
        } else {
            0.0
        };
        let tip_mass = link.tip_mass.unwrap_or(0.0);
        let l = link.length;
        let w2 = omega * omega;
        let nl = element.local_dofs();
        // Same for every element: h is uniform. ρI enters through the slope for Euler–Bernoulli
        // and through θ for Timoshenko.
        let ei = link.bending_stiffness;
        // support::check_planar guarantees κGA for shear links.
        let kga = link.shear_stiffness.unwrap_or(f64::INFINITY);
        let (me, ke) = (element.mass(rho_a, rho_i, h), element.stiffness(ei, kga, h));
        // Rotating-frame softening −Ω²∫ρA v² (translational mass only).
        let mv = element.mass(rho_a, 0.0, h);
        for e in 0..n_el {
            let dofs = layout.element_dofs(e);
            let mut kt = ke;
            if w2 != 0.0 {
                for i in 0..nl {
                    for j in 0..nl {
                        kt[i][j] -= w2 * mv[i][j];
                    }
                }
                if link.foreshortening {
                    let xa = e as f64 * h;
                    let force = |xi: f64| {
                        let x = xa + xi * h;
                        0.5 * rho_a * w2 * (l * l - x * x) + tip_mass * w2 * l
                    };
                    let kg: Local = element.geometric_stiffness(h, &force).ok_or_else(|| {
                        FemError::unsupported(format!(
                            "fem modes: centrifugal stiffening of a {} link is not implemented",
                            element.name()
                        ))
                    })?;
                    for i in 0..nl {
                        for j in 0..nl {
                            kt[i][j] += kg[i][j];
                        }
                    }
                }
            }
            for i in 0..nl {
                let Some(a) = dofs[i] else { continue };
                for j in 0..nl {
                    let Some(b) = dofs[j] else { continue };
                    m[(a, b)] += me[i][j];
                    k[(a, b)] += kt[i][j];
                }
            }
            if link.axial {
                let ea = link.axial_stiffness.unwrap_or(0.0);
                let (mb, kb) = element.axial_mass_and_stiffness(rho_a, ea, h);
                let ud = [layout.u(e), layout.u(e + 1)];
                for i in 0..2 {
                    let Some(a) = ud[i] else { continue };
                    for j in 0..2 {
                        let Some(b) = ud[j] else { continue };
                        m[(a, b)] += mb[i][j];
                        k[(a, b)] += kb[i][j];
                    }
                }
            }
        }
        // Tip body at node n.
        if let Some(vt) = layout.v(n_el) {
            m[(vt, vt)] += tip_mass;
            k[(vt, vt)] -= w2 * tip_mass;
        }
        if let (Some(rt), Some(j)) = (layout.rot(n_el), link.tip_inertia) {
            m[(rt, rt)] += j;
        }
        if let Some(ut) = layout.u(n_el) {
            m[(ut, ut)] += tip_mass;
        }
        Ok(LinearLink {
            layout,
            element,
            n_el,
            length: l,
            m,
            k,
        })
    }

    pub fn ndof(&self) -> usize {
        self.m.nrows()
    }

    /// Transverse deflection at x for DOF vector `d`, with the element's own interpolation.
    pub fn deflection_at(&self, d: &[f64], x: f64) -> f64 {
        let h = self.length / self.n_el as f64;
        let e = ((x / h).floor() as usize).min(self.n_el - 1);
        let xi = ((x - e as f64 * h) / h).clamp(0.0, 1.0);
        let n = self.element.shapes(xi, h).n;
        let dofs = self.layout.element_dofs(e);
        (0..self.element.local_dofs())
            .map(|k| dofs[k].map_or(0.0, |i| n[k] * d[i]))
            .sum()
    }

    /// Consistent load vector ∫q Nᵥ of a uniform transverse load q (exact: 6-point Gauss).
    pub fn uniform_load(&self, q: f64, f: &mut [f64]) {
        let h = self.length / self.n_el as f64;
        let (pts, wts) = gauss01(6);
        let nl = self.element.local_dofs();
        let mut fe = [0.0; MAXE];
        for (xi, w) in pts.iter().zip(wts) {
            let nv = self.element.shapes(*xi, h).n;
            for k in 0..nl {
                fe[k] += w * h * q * nv[k];
            }
        }
        for e in 0..self.n_el {
            let dofs = self.layout.element_dofs(e);
            for k in 0..nl {
                if let Some(i) = dofs[k] {
                    f[i] += fe[k];
                }
            }
        }
    }
}
