//! The element contract: the [`Element`] trait, the padded local arrays it works on, and one
//! element kind on a mesh ([`MeshElement`]: its operators and its shape functions tabulated at
//! the quadrature points the chain integrates with, [`Quadrature`]), with the linear-stiffness
//! and averaged-membrane operators that are the trait's defaults.
//!
//! An element of length h carries the local DOFs (v₁, β₁, v₂, β₂, interior…): the deflection
//! and the section angle β at both end nodes (β = v′ for Euler–Bernoulli, the rotation ψ for
//! Timoshenko), then its interior DOFs ([`Element::interior`]), which the assembly keeps as
//! global DOFs numbered just before the element's end node (the band stays narrow). Along the
//! element the deflection is v(ξ) = Σ Nₐ(ξ) dₐ, the section angle β(ξ) = Σ Bₐ(ξ) dₐ and the
//! curvature β′(ξ) = Σ Bₐ′(ξ) dₐ ([`Element::shapes`]; the 3-D element interpolates its two
//! bending planes with them, [`super::beam3d`]). From these and the section data the element provides the linear
//! operators (consistent mass, stiffness, geometric stiffness: modes and statics) and the
//! nonlinear ones of the floating-frame chain (internal force, tangent and strain energy of the
//! extensible beam, consistent load). The chain's kinematic and force passes need nothing else:
//! inertia, foreshortening and rotary inertia are integrated by the chain from the tabulated
//! shapes at the element's own quadrature orders ([`Element::gauss_points`],
//! [`Element::sub_gauss_points`]).
//!
//! Tabulation: the main points are the element's Gauss rule on [0, 1] (ξ, weight·h, N, N′, B).
//! Foreshortening sub-intervals: the main points split the element into ng + 1 sub-intervals,
//! each with its own Gauss rule, so that the running integral s(ξ) = −½∫₀^ξ v′² is exact at
//! every main point.
//!
//! The trait and [`MeshElement`] refer to each other (an element's operators take the mesh
//! element, which holds its kind and is tabulated from it), so they share this module.

use data::scene::Link;

use super::quadrature::gauss01;
use crate::linalg::dot;

/// Small dense 4×4 matrix of an element (row-major).
pub type Mat4 = [[f64; 4]; 4];

/// Local DOFs per element at most (Timoshenko: v₁, ψ₁, v₂, ψ₂, v(⅓), v(⅔), ψ(½)); the registry
/// ([`super::for_link`]) checks it against its elements at compile time.
pub const MAXE: usize = 7;
/// Gauss points per element at most (the quintic's degree-10 mass needs 6).
pub const MAX_GAUSS: usize = 6;
/// Gauss points per foreshortening sub-interval at most (the quintic's degree-8 v′²: 5).
pub const MAX_SUB_GAUSS: usize = 5;

/// A row of local element values, padded to [`MAXE`] (entries past the element's DOFs are 0).
pub type Row = [f64; MAXE];
/// A local element matrix padded to [`MAXE`]; only the leading block of the element is used.
pub type Local = [[f64; MAXE]; MAXE];

/// Index value meaning "no DOF" (clamped node or prescribed joint).
pub const NONE: usize = usize::MAX;

/// The field an element-interior DOF belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InteriorField {
    /// The deflection v at an interior Lagrange node.
    Deflection,
    /// The section rotation ψ at an interior Lagrange node (no material point moves with it).
    Rotation,
    /// The amplitude of a bubble function (zero value and slope at both ends).
    Bubble,
}

/// One element-interior DOF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InteriorDof {
    pub field: InteriorField,
    /// Short name in diagnostics.
    pub label: &'static str,
    /// Local coordinate ξ of its node (a bubble: the element centre).
    pub at: f64,
}

/// Shape functions of every local DOF at one point: deflection N, its x-derivative N′, the
/// section angle B (B = N′ for Euler–Bernoulli) and its x-derivative B′, the curvature (N″ for
/// Euler–Bernoulli).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Shapes {
    pub n: Row,
    pub dn: Row,
    pub b: Row,
    pub db: Row,
}

impl Shapes {
    /// Shapes of an Euler–Bernoulli element (every local DOF is a deflection DOF; the section
    /// angle is the slope, B = N′, its curvature N″), zero-padded to [`MAXE`].
    pub fn euler_bernoulli(n: &[f64], dn: &[f64], ddn: &[f64]) -> Self {
        let mut out = Shapes::default();
        out.n[..n.len()].copy_from_slice(n);
        out.dn[..dn.len()].copy_from_slice(dn);
        out.b[..dn.len()].copy_from_slice(dn);
        out.db[..ddn.len()].copy_from_slice(ddn);
        out
    }
}

/// The linear interpolation of a bar field (axial u, torsion φ) on an element of length h at
/// local coordinate ξ: the shape functions of its end values and their x-derivatives (the
/// interpolation [`bar_mass`] and [`bar_stiffness`] integrate).
pub fn bar_shapes(xi: f64, h: f64) -> ([f64; 2], [f64; 2]) {
    ([1.0 - xi, xi], [-1.0 / h, 1.0 / h])
}

/// Global DOFs of one element: axial u at both ends and the local transverse DOFs
/// ([`NONE`] where clamped or absent).
#[derive(Debug, Clone, Copy)]
pub struct ElementDofs {
    pub u: [usize; 2],
    pub d: [usize; MAXE],
}

/// One planar beam element kind (see the module docs for the contract).
pub trait Element: std::fmt::Debug + Sync {
    /// Short name in messages ("Hermite-cubic", "Timoshenko", …).
    fn name(&self) -> &'static str;
    /// What the DOF plan reports for a link of this element (completed with ", linear u").
    fn description(&self) -> &'static str;
    /// DOF-plan groups: (field name, DOFs per element).
    fn plan_fields(&self) -> &'static [(&'static str, usize)];
    /// Name of the nodal section angle in diagnostics ("v′" or "ψ").
    fn slope_label(&self) -> &'static str;
    /// The element-interior DOFs, in local order after the four nodal ones.
    fn interior(&self) -> &'static [InteriorDof];
    /// Local DOFs per element.
    fn local_dofs(&self) -> usize {
        4 + self.interior().len()
    }
    /// Whether the section angle is a field of its own (Timoshenko) rather than v′: then the
    /// section rotations carry no mass without rotary inertia.
    fn independent_rotation(&self) -> bool;
    /// Gauss points per element for inertia and loads (exact for the consistent mass).
    fn gauss_points(&self) -> usize;
    /// Gauss points per foreshortening sub-interval (exact for v′² on the sub-interval).
    fn sub_gauss_points(&self) -> usize;
    /// Shape functions at local coordinate ξ of an element of length h.
    fn shapes(&self, xi: f64, h: f64) -> Shapes;
    /// Whether local DOF `a` moves material points (a section-rotation DOF does not).
    fn translates(&self, a: usize) -> bool;
    /// Consistent mass ∫ρA NN + ρI BB.
    fn mass(&self, rho_a: f64, rho_i: f64, h: f64) -> Local;
    /// Linear stiffness: bending ∫EI B′B′ (+ shear ∫κGA(N′ − B)(N′ − B) where the rotation is
    /// independent). With κGA = 0 it is the bending part, on which Kelvin–Voigt acts.
    fn stiffness(&self, ei: f64, kga: f64, h: f64) -> Local;
    /// Consistent mass and stiffness of the axial field (u₁, u₂) of an extensible link, linear
    /// in every element (the field [`membrane`] strains). Default: the linear bar.
    fn axial_mass_and_stiffness(
        &self,
        rho_a: f64,
        ea: f64,
        h: f64,
    ) -> ([[f64; 2]; 2], [[f64; 2]; 2]) {
        (bar_mass(rho_a, h), bar_stiffness(ea, h))
    }
    /// Geometric stiffness ∫N(ξ) N′N′ for a given axial force (tension positive), or `None`
    /// when the element does not provide it.
    fn geometric_stiffness(&self, h: f64, axial_force: &dyn Fn(f64) -> f64) -> Option<Local>;

    /// Adds the elastic internal force ∂U/∂(u, d) of one element to (`fu`, `fe`). Default: the
    /// linear stiffness, U = ½dᵀKd, plus for an extensible link the membrane energy ½EA h ε̄² of
    /// the averaged strain ([`membrane`]).
    fn internal_force(
        &self,
        el: &MeshElement,
        u: [f64; 2],
        d: &Row,
        fu: &mut [f64; 2],
        fe: &mut Row,
    ) {
        linear_internal_force(el, u, d, fu, fe);
    }

    /// Adds c_q times the tangent of [`Element::internal_force`] through `add(row, col, value)`
    /// on global DOFs.
    fn tangent(
        &self,
        el: &MeshElement,
        dofs: &ElementDofs,
        u: [f64; 2],
        d: &Row,
        c_q: f64,
        add: &mut dyn FnMut(usize, usize, f64),
    ) {
        linear_tangent(el, dofs, u, d, c_q, add);
    }

    /// Adds the strain energy of one element (the potential of [`Element::internal_force`]) to
    /// `strain`, term by term.
    fn add_strain_energy(&self, el: &MeshElement, u: [f64; 2], d: &Row, strain: &mut f64) {
        linear_strain_energy(el, u, d, strain);
    }

    /// Consistent nodal loads ∫q₀N of a uniform transverse load q₀ (exact by the element's
    /// Gauss rule).
    fn consistent_load(&self, el: &MeshElement, q0: f64) -> Row {
        let tb = &el.quad;
        let mut fq = [0.0; MAXE];
        for g in 0..tb.ng {
            for a in 0..el.ne {
                fq[a] += q0 * tb.wh[g] * tb.n[g][a];
            }
        }
        fq
    }
}

/// Linear bar: consistent mass ρA h/6 [[2, 1], [1, 2]].
pub fn bar_mass(rho_a: f64, h: f64) -> [[f64; 2]; 2] {
    let c = rho_a * h / 6.0;
    [[2.0 * c, c], [c, 2.0 * c]]
}

/// Linear bar: stiffness EA/h [[1, −1], [−1, 1]].
pub fn bar_stiffness(ea: f64, h: f64) -> [[f64; 2]; 2] {
    let c = ea / h;
    [[c, -c], [-c, c]]
}

/// Copies an N×N element matrix into the padded local block.
pub fn pad<const N: usize>(a: &[[f64; N]; N]) -> Local {
    let mut out = [[0.0; MAXE]; MAXE];
    for i in 0..N {
        out[i][..N].copy_from_slice(&a[i]);
    }
    out
}

/// Internal force of the linear stiffness plus the averaged membrane (see
/// [`Element::internal_force`]).
pub fn linear_internal_force(
    el: &MeshElement,
    u: [f64; 2],
    d: &Row,
    fu: &mut [f64; 2],
    fe: &mut Row,
) {
    let ne = el.ne;
    for a in 0..ne {
        fe[a] += dot(&el.k[a][..ne], &d[..ne]);
    }
    if el.axial {
        let (eps, gr) = membrane(el, u, d);
        let nf = el.ea * el.h * eps;
        fu[0] += nf * gr[0];
        fu[1] += nf * gr[1];
        for a in 0..ne {
            fe[a] += nf * gr[2 + a];
        }
    }
}

/// Tangent of [`linear_internal_force`]: K, and the membrane EA h ggᵀ + EA ε̄ ∫N′N′ (v block).
pub fn linear_tangent(
    el: &MeshElement,
    dofs: &ElementDofs,
    u: [f64; 2],
    d: &Row,
    c_q: f64,
    add: &mut dyn FnMut(usize, usize, f64),
) {
    let ne = el.ne;
    let dd = &dofs.d;
    for a in 0..ne {
        for b in 0..ne {
            if dd[a] != NONE && dd[b] != NONE {
                add(dd[a], dd[b], c_q * el.k[a][b]);
            }
        }
    }
    if el.axial {
        let (eps, gr) = membrane(el, u, d);
        let mut all = [NONE; MAXE + 2];
        all[0] = dofs.u[0];
        all[1] = dofs.u[1];
        all[2..2 + ne].copy_from_slice(&dd[..ne]);
        for a in 0..ne + 2 {
            for b in 0..ne + 2 {
                if all[a] != NONE && all[b] != NONE {
                    add(all[a], all[b], c_q * el.ea * el.h * gr[a] * gr[b]);
                }
            }
        }
        let nf = el.ea * eps;
        let tb = &el.quad;
        for g in 0..tb.ng {
            let dn = &tb.dn[g];
            let wgt = c_q * nf * tb.wh[g];
            for a in 0..ne {
                for b in 0..ne {
                    if dd[a] != NONE && dd[b] != NONE {
                        add(dd[a], dd[b], wgt * dn[a] * dn[b]);
                    }
                }
            }
        }
    }
}

/// Strain energy of [`linear_internal_force`], added term by term.
pub fn linear_strain_energy(el: &MeshElement, u: [f64; 2], d: &Row, strain: &mut f64) {
    let ne = el.ne;
    for a in 0..ne {
        *strain += 0.5 * d[a] * dot(&el.k[a][..ne], &d[..ne]);
    }
    if el.axial {
        let (eps, _) = membrane(el, u, d);
        *strain += 0.5 * el.ea * el.h * eps * eps;
    }
}

/// Shape functions of one element tabulated at its quadrature points (all elements of a link
/// have the same length h).
#[derive(Debug, Clone)]
pub struct Quadrature {
    /// Main Gauss points used (≤ [`MAX_GAUSS`]).
    pub ng: usize,
    /// Gauss points per sub-interval used (≤ [`MAX_SUB_GAUSS`]).
    pub nsg: usize,
    /// Main Gauss points: ξ, weight·h, v shapes N, their x-derivatives N′ and the section
    /// angle shapes B.
    pub xi: [f64; MAX_GAUSS],
    pub wh: [f64; MAX_GAUSS],
    pub n: [Row; MAX_GAUSS],
    pub dn: [Row; MAX_GAUSS],
    pub b: [Row; MAX_GAUSS],
    /// Sub-interval points (ng + 1 sub-intervals × nsg): weight·h and N′.
    pub sub_wh: [[f64; MAX_SUB_GAUSS]; MAX_GAUSS + 1],
    pub sub_dn: [[Row; MAX_SUB_GAUSS]; MAX_GAUSS + 1],
    /// Σ weight·h·N′N′ᵀ over every sub-interval point: the element's ∫v′² = dᵀG d by the
    /// sub-interval quadrature, so the foreshortening at an element's end and its gradient are
    /// one small matrix product each.
    pub slope_gram: Local,
}

impl Quadrature {
    /// Tabulates `element` on an element of length `h`.
    pub fn new(element: &dyn Element, h: f64) -> Self {
        let (ng, nsg) = (element.gauss_points(), element.sub_gauss_points());
        assert!(ng <= MAX_GAUSS && nsg <= MAX_SUB_GAUSS);
        let (p, w) = gauss01(ng);
        let (ps, ws) = gauss01(nsg);
        let mut t = Quadrature {
            ng,
            nsg,
            xi: [0.0; MAX_GAUSS],
            wh: [0.0; MAX_GAUSS],
            n: [[0.0; MAXE]; MAX_GAUSS],
            dn: [[0.0; MAXE]; MAX_GAUSS],
            b: [[0.0; MAXE]; MAX_GAUSS],
            sub_wh: [[0.0; MAX_SUB_GAUSS]; MAX_GAUSS + 1],
            sub_dn: [[[0.0; MAXE]; MAX_SUB_GAUSS]; MAX_GAUSS + 1],
            slope_gram: [[0.0; MAXE]; MAXE],
        };
        for g in 0..ng {
            let s = element.shapes(p[g], h);
            t.xi[g] = p[g];
            t.wh[g] = w[g] * h;
            t.n[g] = s.n;
            t.dn[g] = s.dn;
            t.b[g] = s.b;
        }
        for j in 0..=ng {
            let a = if j == 0 { 0.0 } else { p[j - 1] };
            let b = if j == ng { 1.0 } else { p[j] };
            for k in 0..nsg {
                let xi = a + (b - a) * ps[k];
                t.sub_wh[j][k] = ws[k] * (b - a) * h;
                t.sub_dn[j][k] = element.shapes(xi, h).dn;
                let (w, dn) = (t.sub_wh[j][k], t.sub_dn[j][k]);
                for (row, &da) in t.slope_gram.iter_mut().zip(&dn) {
                    for (g, &db) in row.iter_mut().zip(&dn) {
                        *g += w * da * db;
                    }
                }
            }
        }
        t
    }
}

/// One link's element: the element kind, its section data and mesh size, its linear stiffness
/// and its tabulated shapes.
#[derive(Debug, Clone)]
pub struct MeshElement {
    pub kind: &'static dyn Element,
    /// Local DOFs per element.
    pub ne: usize,
    pub h: f64,
    pub ei: f64,
    /// EA when `axial` is on (else 0).
    pub ea: f64,
    pub axial: bool,
    /// Element stiffness (same for all elements of the link), first `ne` rows/columns used:
    /// ∫EI v″² (Euler–Bernoulli) or ∫EI ψ′² + κGA(v′ − ψ)² (Timoshenko).
    pub k: Local,
    /// Bending part ∫EI (section angle)′² of `k` (Kelvin–Voigt acts on it only).
    pub kb: Local,
    pub quad: Quadrature,
}

impl MeshElement {
    /// The element `kind` for `link` with elements of length `h`.
    pub fn new(kind: &'static dyn Element, link: &Link, h: f64) -> Self {
        let ei = link.bending_stiffness;
        // support::check_planar guarantees κGA for shear links.
        let kga = link.shear_stiffness.unwrap_or(0.0);
        MeshElement {
            kind,
            ne: kind.local_dofs(),
            h,
            ei,
            ea: if link.axial {
                link.axial_stiffness.unwrap_or(0.0)
            } else {
                0.0
            },
            axial: link.axial,
            k: kind.stiffness(ei, kga, h),
            kb: kind.stiffness(ei, 0.0, h),
            quad: Quadrature::new(kind, h),
        }
    }
}

/// Element-averaged membrane strain of an extensible element,
/// ε̄ = (u₂ − u₁)/h + (1/2h)∫v′² (the locking-free averaged strain of the von Kármán element;
/// the element's Gauss rule integrates v′² exactly), and its gradient with respect to
/// (u₁, u₂, element DOFs).
pub fn membrane(el: &MeshElement, u: [f64; 2], d: &Row) -> (f64, [f64; MAXE + 2]) {
    let (tb, h, ne) = (&el.quad, el.h, el.ne);
    let mut half_int = 0.0;
    let mut g = [0.0; MAXE + 2];
    g[0] = -1.0 / h;
    g[1] = 1.0 / h;
    for k in 0..tb.ng {
        let dn = &tb.dn[k];
        let vp = dot(&dn[..ne], &d[..ne]);
        half_int += tb.wh[k] * 0.5 * vp * vp;
        for a in 0..ne {
            g[2 + a] += tb.wh[k] / h * vp * dn[a];
        }
    }
    ((u[1] - u[0]) / h + half_int / h, g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_bar_total_mass_and_rigid_mode() {
        let (rho_a, ea, h) = (2.0, 5.0, 0.3);
        let m = bar_mass(rho_a, h);
        let k = bar_stiffness(ea, h);
        let tot: f64 = m.iter().flatten().sum();
        assert!((tot - rho_a * h).abs() < 1e-15);
        assert_eq!(k[0][0] + k[0][1], 0.0);
    }
}
