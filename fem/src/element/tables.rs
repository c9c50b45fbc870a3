//! One element kind on a mesh of element length h: its operators and its shape functions
//! tabulated at the quadrature points the chain integrates with.
//!
//! Main points: the element's Gauss rule on [0, 1] (ξ, weight·h, N, N′, B). Foreshortening
//! sub-intervals: the main points split the element into ng + 1 sub-intervals, each with its own
//! Gauss rule, so that the running integral s(ξ) = −½∫₀^ξ v′² is exact at every main point.

use data::scene::Link;

use super::quadrature::gauss01;
use super::{Element, Local, MAX_GAUSS, MAX_SUB_GAUSS, MAXE, Row};

/// Σ aₖ dₖ over the first `ne` entries (left to right).
#[inline]
pub fn dotn(a: &Row, d: &Row, ne: usize) -> f64 {
    let mut s = 0.0;
    for k in 0..ne {
        s += a[k] * d[k];
    }
    s
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
        let vp = dotn(dn, d, ne);
        half_int += tb.wh[k] * 0.5 * vp * vp;
        for a in 0..ne {
            g[2 + a] += tb.wh[k] / h * vp * dn[a];
        }
    }
    ((u[1] - u[0]) / h + half_int / h, g)
}
