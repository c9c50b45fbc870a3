//! A fine finite-element discretization of the constant-mass free-free case, used *only* to
//! compute its eigenfunctions (the basis of the reduced model). It is private to this module and
//! shares nothing with the `fem` crate.
//!
//! * bending w(x): Hermite cubic elements (nodal w, w'), C¹ across nodes — the curvature may jump
//!   at a stage junction, as EI w'' = continuous requires;
//! * axial u(x): quadratic Lagrange elements (end + mid nodes), C⁰ — the strain may jump at a
//!   junction, as EA u' = continuous requires.
//!
//! Every stage boundary is a node, so each element has uniform EA, EI and mass. Element matrices
//! are integrated by 4-point Gauss–Legendre quadrature (exact for the degree-6 integrands).

use super::body::Body;
use crate::basis::quadrature::gauss_legendre_unit;

/// One element of the fine mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element {
    pub x0: f64,
    pub h: f64,
    pub ea: f64,
    pub ei: f64,
    pub mass0: f64,
    /// Whether the element lies in the burning chamber.
    pub burning: bool,
}

/// The fine mesh: elements in order from the aft end.
#[derive(Debug, Clone, PartialEq)]
pub struct FineMesh {
    pub elements: Vec<Element>,
    pub length: f64,
}

impl FineMesh {
    /// About `target` elements, distributed over the stages in proportion to their length
    /// (at least 4 per stage), with every stage boundary on a node.
    pub fn new(body: &Body, target: usize) -> FineMesh {
        let chamber_end = body.burn.as_ref().map(|b| b.chamber_end);
        let mut elements = Vec::new();
        for seg in &body.segments {
            let count = ((target as f64 * seg.length() / body.length).round() as usize).max(4);
            let h = seg.length() / count as f64;
            for e in 0..count {
                elements.push(Element {
                    x0: seg.x0 + e as f64 * h,
                    h,
                    ea: seg.ea,
                    ei: seg.ei,
                    mass0: seg.mass0,
                    burning: chamber_end.is_some_and(|l1| seg.x1 <= l1 * (1.0 + 1e-12)),
                });
            }
        }
        FineMesh {
            elements,
            length: body.length,
        }
    }

    /// Element index and local coordinate s ∈ [0, 1] of station x (clamped to the body).
    pub fn locate(&self, x: f64) -> (usize, f64) {
        let x = x.clamp(0.0, self.length);
        let k = self
            .elements
            .partition_point(|e| e.x0 + e.h <= x)
            .min(self.elements.len() - 1);
        let e = &self.elements[k];
        (k, ((x - e.x0) / e.h).clamp(0.0, 1.0))
    }

    pub fn bending_dofs(&self) -> usize {
        2 * (self.elements.len() + 1)
    }

    pub fn axial_dofs(&self) -> usize {
        2 * self.elements.len() + 1
    }

    /// Global DOF indices of element k for the bending field (w₀, w₀', w₁, w₁').
    pub fn bending_map(k: usize) -> [usize; 4] {
        [2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3]
    }

    /// Global DOF indices of element k for the axial field (left, middle, right node).
    pub fn axial_map(k: usize) -> [usize; 3] {
        [2 * k, 2 * k + 1, 2 * k + 2]
    }
}

/// Hermite cubic shape functions at local s ∈ [0, 1] on an element of length h:
/// (values, d/dx, d²/dx²) for the DOFs (w₀, w₀', w₁, w₁').
pub fn hermite(s: f64, h: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let s2 = s * s;
    let s3 = s2 * s;
    let n = [
        1.0 - 3.0 * s2 + 2.0 * s3,
        h * (s - 2.0 * s2 + s3),
        3.0 * s2 - 2.0 * s3,
        h * (-s2 + s3),
    ];
    let d = [
        (-6.0 * s + 6.0 * s2) / h,
        1.0 - 4.0 * s + 3.0 * s2,
        (6.0 * s - 6.0 * s2) / h,
        -2.0 * s + 3.0 * s2,
    ];
    let dd = [
        (-6.0 + 12.0 * s) / (h * h),
        (-4.0 + 6.0 * s) / h,
        (6.0 - 12.0 * s) / (h * h),
        (-2.0 + 6.0 * s) / h,
    ];
    (n, d, dd)
}

/// Quadratic Lagrange shape functions at local s ∈ [0, 1] (nodes at s = 0, ½, 1):
/// (values, d/dx).
pub fn lagrange2(s: f64, h: f64) -> ([f64; 3], [f64; 3]) {
    let n = [
        2.0 * (s - 0.5) * (s - 1.0),
        4.0 * s * (1.0 - s),
        2.0 * s * (s - 0.5),
    ];
    let d = [
        (4.0 * s - 3.0) / h,
        (4.0 - 8.0 * s) / h,
        (4.0 * s - 1.0) / h,
    ];
    (n, d)
}

/// Dense (K, M) of the free-free bending problem, row-major n×n.
pub fn bending_matrices(mesh: &FineMesh) -> (Vec<f64>, Vec<f64>, usize) {
    let n = mesh.bending_dofs();
    let mut k = vec![0.0; n * n];
    let mut m = vec![0.0; n * n];
    let (gs, gw) = gauss_legendre_unit(4);
    for (e, el) in mesh.elements.iter().enumerate() {
        let map = FineMesh::bending_map(e);
        for (s, w) in gs.iter().zip(&gw) {
            let (nv, _, dd) = hermite(*s, el.h);
            let jw = w * el.h;
            for a in 0..4 {
                for b in 0..4 {
                    let idx = map[a] * n + map[b];
                    k[idx] += jw * el.ei * dd[a] * dd[b];
                    m[idx] += jw * el.mass0 * nv[a] * nv[b];
                }
            }
        }
    }
    (k, m, n)
}

/// Dense (K, M) of the free-free axial problem, row-major n×n.
pub fn axial_matrices(mesh: &FineMesh) -> (Vec<f64>, Vec<f64>, usize) {
    let n = mesh.axial_dofs();
    let mut k = vec![0.0; n * n];
    let mut m = vec![0.0; n * n];
    let (gs, gw) = gauss_legendre_unit(4);
    for (e, el) in mesh.elements.iter().enumerate() {
        let map = FineMesh::axial_map(e);
        for (s, w) in gs.iter().zip(&gw) {
            let (nv, d) = lagrange2(*s, el.h);
            let jw = w * el.h;
            for a in 0..3 {
                for b in 0..3 {
                    let idx = map[a] * n + map[b];
                    k[idx] += jw * el.ea * d[a] * d[b];
                    m[idx] += jw * el.mass0 * nv[a] * nv[b];
                }
            }
        }
    }
    (k, m, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_gauss_rule_integrates_degree_7_exactly() {
        let (x, w) = gauss_legendre_unit(4);
        for p in 0..8 {
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p)).sum();
            // exact ∫₀¹ s^p ds = 1/(p+1); round-off of a 4-term sum
            assert!((q - 1.0 / (p as f64 + 1.0)).abs() < 1e-15, "p={p} q={q}");
        }
    }

    #[test]
    fn elem_hermite_partition_and_derivatives() {
        let h = 0.7;
        for &s in &[0.0, 0.13, 0.5, 0.91, 1.0] {
            let (n, d, dd) = hermite(s, h);
            // rigid translation w = 1 and rotation w = x reproduce exactly
            assert!((n[0] + n[2] - 1.0).abs() < 1e-15);
            let x = s * h;
            assert!((n[1] + n[2] * h + n[3] - x).abs() < 1e-15);
            // derivatives against central differences of the values (error O(δ²) ~ 1e-10)
            let del = 1e-5;
            let (np, dp, _) = hermite(s + del, h);
            let (nm, dm, _) = hermite(s - del, h);
            for a in 0..4 {
                let fd = (np[a] - nm[a]) / (2.0 * del * h);
                assert!((fd - d[a]).abs() < 1e-8, "d{a}");
                let fdd = (dp[a] - dm[a]) / (2.0 * del * h);
                assert!((fdd - dd[a]).abs() < 1e-6, "dd{a}");
            }
        }
    }

    #[test]
    fn elem_lagrange2_partition_and_derivatives() {
        let h = 1.3;
        for &s in &[0.0, 0.3, 0.5, 1.0] {
            let (n, d) = lagrange2(s, h);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert!(d.iter().sum::<f64>().abs() < 1e-14);
            let (np, _) = lagrange2(s + 1e-6, h);
            let (nm, _) = lagrange2(s - 1e-6, h);
            for a in 0..3 {
                let fd = (np[a] - nm[a]) / (2e-6 * h);
                assert!((fd - d[a]).abs() < 1e-8);
            }
        }
    }
}
