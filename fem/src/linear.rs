//! Linear model of one clamped link (modes and statics): dense K and M about the reference state.
//!
//! DOFs per node k = 1..n (node 0 is clamped): v, rotation (v′ for Euler–Bernoulli, θ for
//! Timoshenko), then u when `axial` is on. For a hub spinning at constant Ω (prescribed
//! `constant-rate`), the linearization of the floating-frame energy about the undeformed state adds
//! * with `foreshortening`: the centrifugal geometric stiffness ∫N v′² with
//!   N(x) = ρAΩ²(L² − x²)/2 + m_tip Ω² L (from −Ω²∫ρA x s, s = −½∫v′²), and
//! * always: the rotating-frame softening −Ω²∫ρA v² (−Ω² m_tip v_tip²),
//!
//! so that in-plane bending obeys ω_in² = ω_out² − Ω² for the inextensible model.

use data::scene::{Link, PrescribedMotion};
use faer::Mat;

use crate::element::euler_bernoulli as eb;
use crate::element::hermite::hermite;
use crate::element::timoshenko::TimoshenkoElement;
use crate::error::FemError;

/// Where a node's DOFs sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeLayout {
    pub dofs_per_node: usize,
    pub axial: bool,
    pub shear: bool,
}

impl NodeLayout {
    pub fn v(&self, node: usize) -> Option<usize> {
        (node > 0).then(|| (node - 1) * self.dofs_per_node)
    }
    pub fn rot(&self, node: usize) -> Option<usize> {
        (node > 0).then(|| (node - 1) * self.dofs_per_node + 1)
    }
    pub fn u(&self, node: usize) -> Option<usize> {
        (node > 0 && self.axial).then(|| (node - 1) * self.dofs_per_node + 2)
    }
}

/// Assembled linear system of one clamped link.
#[derive(Debug, Clone)]
pub struct LinearLink {
    pub layout: NodeLayout,
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
    /// Assembles K and M of `link` with `n_el` elements, spinning at constant `omega`.
    pub fn assemble(link: &Link, n_el: usize, omega: f64) -> Result<Self, FemError> {
        let layout = NodeLayout {
            dofs_per_node: if link.axial { 3 } else { 2 },
            axial: link.axial,
            shear: link.shear,
        };
        if link.axial && omega != 0.0 {
            return Err(FemError::unsupported(
                "fem modes: extensible link on a spinning hub: the axial–bending Coriolis \
                 coupling makes this a gyroscopic (state-space) eigenproblem, not implemented",
            ));
        }
        let n = n_el * layout.dofs_per_node;
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
        for e in 0..n_el {
            let dofs = [
                layout.v(e),
                layout.rot(e),
                layout.v(e + 1),
                layout.rot(e + 1),
            ];
            let (me, ke) = if link.shear {
                let kga = link.shear_stiffness.unwrap_or(f64::INFINITY);
                let el = TimoshenkoElement::new(h, link.bending_stiffness, kga);
                (
                    el.mass(rho_a, rho_i),
                    el.stiffness(link.bending_stiffness, kga),
                )
            } else {
                (
                    eb::mass(rho_a, rho_i, h),
                    eb::bending_stiffness(link.bending_stiffness, h),
                )
            };
            let mut kt = ke;
            if w2 != 0.0 {
                // Rotating-frame softening −Ω²∫ρA v² (translational mass only).
                let mv = eb::mass(rho_a, 0.0, h);
                let mv = if link.shear {
                    TimoshenkoElement::new(
                        h,
                        link.bending_stiffness,
                        link.shear_stiffness.unwrap_or(f64::INFINITY),
                    )
                    .mass(rho_a, 0.0)
                } else {
                    mv
                };
                for i in 0..4 {
                    for j in 0..4 {
                        kt[i][j] -= w2 * mv[i][j];
                    }
                }
                if link.foreshortening {
                    let xa = e as f64 * h;
                    let kg = eb::geometric_stiffness(h, |xi| {
                        let x = xa + xi * h;
                        0.5 * rho_a * w2 * (l * l - x * x) + tip_mass * w2 * l
                    });
                    for i in 0..4 {
                        for j in 0..4 {
                            kt[i][j] += kg[i][j];
                        }
                    }
                }
            }
            for i in 0..4 {
                let Some(a) = dofs[i] else { continue };
                for j in 0..4 {
                    let Some(b) = dofs[j] else { continue };
                    m[(a, b)] += me[i][j];
                    k[(a, b)] += kt[i][j];
                }
            }
            if link.axial {
                let ea = link.axial_stiffness.unwrap_or(0.0);
                let (mb, kb) = (eb::bar_mass(rho_a, h), eb::bar_stiffness(ea, h));
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
            n_el,
            length: l,
            m,
            k,
        })
    }

    pub fn ndof(&self) -> usize {
        self.m.nrows()
    }

    /// Transverse deflection at x for DOF vector `d` (Hermite interpolation for Euler–Bernoulli,
    /// the element's own interpolation for Timoshenko).
    pub fn deflection_at(&self, d: &[f64], x: f64, link: &Link) -> f64 {
        let h = self.length / self.n_el as f64;
        let e = ((x / h).floor() as usize).min(self.n_el - 1);
        let xi = ((x - e as f64 * h) / h).clamp(0.0, 1.0);
        let get = |o: Option<usize>| o.map_or(0.0, |i| d[i]);
        let nd = [
            get(self.layout.v(e)),
            get(self.layout.rot(e)),
            get(self.layout.v(e + 1)),
            get(self.layout.rot(e + 1)),
        ];
        let n = if link.shear {
            let el = TimoshenkoElement::new(
                h,
                link.bending_stiffness,
                link.shear_stiffness.unwrap_or(f64::INFINITY),
            );
            let s = el.shapes(xi * h);
            [s[0][0], s[1][0], s[2][0], s[3][0]]
        } else {
            hermite(xi, h).n
        };
        (0..4).map(|k| n[k] * nd[k]).sum()
    }
}
