//! Hierarchical Hermite-quintic Euler–Bernoulli element: the Hermite cubic plus two C¹ interior
//! bubbles b₁ = ξ²(1−ξ)², b₂ = ξ²(1−ξ)²(2ξ−1) (ξ = x/h).
//!
//! Local DOFs (v₁, v₁′, v₂, v₂′, a₁, a₂): the nodal DOFs are those of the cubic (the bubbles
//! vanish with their slope at both ends), so tip bodies, loads and the clamp attach unchanged;
//! a₁, a₂ are element-interior amplitudes kept as global DOFs. The span is the complete quintic,
//! so frequencies converge at O(h^{2(p−1)}) = O(h⁸) instead of the cubic's O(h⁴).
//!
//! Same energies as [`super::euler_bernoulli`]: T = ½∫ρA v̇² (+ ½∫ρI v̇′²), U = ½∫EI v″²,
//! geometric ½∫N v′². All integrals by 6-point Gauss: exact for the degree-10 mass and for the
//! geometric stiffness with N of degree ≤ 2 (the centrifugal force).

use super::contract::{Element, InteriorDof, InteriorField, Local, Shapes, pad};
use super::hermite::hermite;
use super::quadrature::gauss01;

/// Number of local DOFs of one element.
pub const NDOF: usize = 6;
/// Element-interior DOFs (bubble amplitudes).
pub const INTERIOR: usize = 2;

/// Element matrix (row-major) in the local DOF order above.
pub type Mat6 = [[f64; NDOF]; NDOF];

/// Shape functions and their first and second x-derivatives at ξ.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct QuinticAt {
    pub n: [f64; NDOF],
    pub dn: [f64; NDOF],
    pub ddn: [f64; NDOF],
}

/// Evaluates the shape functions on an element of length `h` at local coordinate `xi`.
pub fn shapes(xi: f64, h: f64) -> QuinticAt {
    let c = hermite(xi, h);
    let (x2, x3, x4) = (xi * xi, xi * xi * xi, xi * xi * xi * xi);
    let mut s = QuinticAt::default();
    s.n[..4].copy_from_slice(&c.n);
    s.dn[..4].copy_from_slice(&c.dn);
    s.ddn[..4].copy_from_slice(&c.ddn);
    // b₁ = ξ² − 2ξ³ + ξ⁴.
    s.n[4] = x2 - 2.0 * x3 + x4;
    s.dn[4] = (2.0 * xi - 6.0 * x2 + 4.0 * x3) / h;
    s.ddn[4] = (2.0 - 12.0 * xi + 12.0 * x2) / (h * h);
    // b₂ = b₁(2ξ − 1) = −ξ² + 4ξ³ − 5ξ⁴ + 2ξ⁵.
    s.n[5] = -x2 + 4.0 * x3 - 5.0 * x4 + 2.0 * x4 * xi;
    s.dn[5] = (-2.0 * xi + 12.0 * x2 - 20.0 * x3 + 10.0 * x4) / h;
    s.ddn[5] = (-2.0 + 24.0 * xi - 60.0 * x2 + 40.0 * x3) / (h * h);
    s
}

/// Consistent mass ∫ρA NᵢNⱼ (+ ∫ρI Nᵢ′Nⱼ′).
pub fn mass(rho_a: f64, rho_i: f64, h: f64) -> Mat6 {
    let (p, w) = gauss01(6);
    let mut m = [[0.0; NDOF]; NDOF];
    for (xi, wg) in p.iter().zip(w) {
        let s = shapes(*xi, h);
        for i in 0..NDOF {
            for j in 0..NDOF {
                m[i][j] += wg * h * (rho_a * s.n[i] * s.n[j] + rho_i * s.dn[i] * s.dn[j]);
            }
        }
    }
    m
}

/// Bending stiffness ∫EI Nᵢ″Nⱼ″.
pub fn bending_stiffness(ei: f64, h: f64) -> Mat6 {
    let (p, w) = gauss01(6);
    let mut k = [[0.0; NDOF]; NDOF];
    for (xi, wg) in p.iter().zip(w) {
        let s = shapes(*xi, h);
        for i in 0..NDOF {
            for j in 0..NDOF {
                k[i][j] += wg * h * ei * s.ddn[i] * s.ddn[j];
            }
        }
    }
    k
}

/// Geometric stiffness ∫N(x) Nᵢ′Nⱼ′ for an axial force N(ξ) (tension positive); exact for N of
/// degree ≤ 3.
pub fn geometric_stiffness(h: f64, axial_force: impl Fn(f64) -> f64) -> Mat6 {
    let (p, w) = gauss01(6);
    let mut k = [[0.0; NDOF]; NDOF];
    for (xi, wg) in p.iter().zip(w) {
        let s = shapes(*xi, h);
        let n = axial_force(*xi);
        for i in 0..NDOF {
            for j in 0..NDOF {
                k[i][j] += wg * h * n * s.dn[i] * s.dn[j];
            }
        }
    }
    k
}

/// The hierarchical Hermite-quintic Euler–Bernoulli element, DOFs (v₁, v₁′, v₂, v₂′, a₁, a₂).
/// An extensible link uses the element-averaged membrane strain (the element's 6-point rule
/// integrates its degree-8 v′² exactly).
#[derive(Debug, Clone, Copy)]
pub struct HermiteQuintic;

impl Element for HermiteQuintic {
    fn name(&self) -> &'static str {
        "Hermite-quintic"
    }
    fn description(&self) -> &'static str {
        "Euler–Bernoulli beam (Hermite quintic v: cubic + 2 C¹ bubbles"
    }
    fn plan_fields(&self) -> &'static [(&'static str, usize)] {
        &[
            ("transverse v", 1),
            ("slope v′", 1),
            ("bubble amplitudes a₁, a₂", INTERIOR),
        ]
    }
    fn slope_label(&self) -> &'static str {
        "v′"
    }
    fn interior(&self) -> &'static [InteriorDof] {
        &[
            InteriorDof {
                field: InteriorField::Bubble,
                label: "a₁",
                at: 0.5,
            },
            InteriorDof {
                field: InteriorField::Bubble,
                label: "a₂",
                at: 0.5,
            },
        ]
    }
    fn independent_rotation(&self) -> bool {
        false
    }
    fn gauss_points(&self) -> usize {
        6
    }
    fn sub_gauss_points(&self) -> usize {
        5
    }
    fn shapes(&self, xi: f64, h: f64) -> Shapes {
        let s = shapes(xi, h);
        Shapes::euler_bernoulli(&s.n, &s.dn, &s.ddn)
    }
    fn translates(&self, _a: usize) -> bool {
        true
    }
    fn mass(&self, rho_a: f64, rho_i: f64, h: f64) -> Local {
        pad(&mass(rho_a, rho_i, h))
    }
    fn stiffness(&self, ei: f64, _kga: f64, h: f64) -> Local {
        pad(&bending_stiffness(ei, h))
    }
    fn geometric_stiffness(&self, h: f64, axial_force: &dyn Fn(f64) -> f64) -> Option<Local> {
        Some(pad(&geometric_stiffness(h, axial_force)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::euler_bernoulli as eb;

    #[test]
    fn elem_quintic_reproduces_quintics_with_bubbles_vanishing_at_ends() {
        let (xa, h) = (0.2, 0.5);
        let f =
            |x: f64| 0.4 - x + 2.0 * x * x - 0.5 * x.powi(3) + 1.5 * x.powi(4) - 2.0 * x.powi(5);
        let df = |x: f64| -1.0 + 4.0 * x - 1.5 * x * x + 6.0 * x.powi(3) - 10.0 * x.powi(4);
        let ddf = |x: f64| 4.0 - 3.0 * x + 18.0 * x * x - 40.0 * x.powi(3);
        // Nodal DOFs from f; bubble amplitudes from the remainder r = f − cubic Hermite, which
        // is a multiple of ξ²(1−ξ)²: fit a₁, a₂ at two interior points.
        let nodal = [f(xa), df(xa), f(xa + h), df(xa + h)];
        let rem = |xi: f64| {
            let c = hermite(xi, h);
            f(xa + xi * h) - (0..4).map(|k| c.n[k] * nodal[k]).sum::<f64>()
        };
        let (r1, r2) = (rem(0.25), rem(0.75));
        let (s1, s2) = (shapes(0.25, h), shapes(0.75, h));
        let det = s1.n[4] * s2.n[5] - s1.n[5] * s2.n[4];
        let a1 = (r1 * s2.n[5] - r2 * s1.n[5]) / det;
        let a2 = (s1.n[4] * r2 - s2.n[4] * r1) / det;
        let d = [nodal[0], nodal[1], nodal[2], nodal[3], a1, a2];
        for k in 0..=10 {
            let xi = k as f64 / 10.0;
            let x = xa + xi * h;
            let s = shapes(xi, h);
            let dot = |a: &[f64; NDOF]| (0..NDOF).map(|i| a[i] * d[i]).sum::<f64>();
            // Exact reproduction of a quintic: round-off only.
            assert!((dot(&s.n) - f(x)).abs() < 1e-13, "ξ={xi}");
            assert!((dot(&s.dn) - df(x)).abs() < 1e-12, "ξ={xi}");
            assert!((dot(&s.ddn) - ddf(x)).abs() < 1e-11, "ξ={xi}");
        }
        for xi in [0.0, 1.0] {
            let s = shapes(xi, h);
            for b in 4..6 {
                assert_eq!(s.n[b], 0.0);
                assert_eq!(s.dn[b], 0.0);
            }
        }
    }

    #[test]
    fn elem_quintic_contains_cubic_block_symmetric_rigid_modes_total_mass() {
        let (rho_a, rho_i, ei, h) = (0.785, 3e-4, 175.0, 0.0625);
        let m = mass(rho_a, rho_i, h);
        let k = bending_stiffness(ei, h);
        let (mc, kc) = (eb::mass(rho_a, rho_i, h), eb::bending_stiffness(ei, h));
        for i in 0..4 {
            for j in 0..4 {
                // Hierarchical: the nodal block is the cubic element (exact quadratures both).
                assert!((m[i][j] - mc[i][j]).abs() < 1e-14 * mc[0][0]);
                assert!((k[i][j] - kc[i][j]).abs() < 1e-12 * kc[0][0]);
            }
        }
        let kmax = k.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
        for i in 0..NDOF {
            for j in 0..NDOF {
                assert!((m[i][j] - m[j][i]).abs() <= 1e-15 * m[0][0]);
                assert!((k[i][j] - k[j][i]).abs() <= 1e-15 * kmax);
            }
        }
        let t = [1.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let r = [0.0, 1.0, h, 1.0, 0.0, 0.0];
        let mt: f64 = (0..NDOF)
            .map(|i| (0..NDOF).map(|j| t[i] * m[i][j] * t[j]).sum::<f64>())
            .sum();
        // Rotary inertia does not see a translation: tᵀMt = ρA h.
        assert!((mt - rho_a * h).abs() < 1e-14 * rho_a * h);
        for mode in [t, r] {
            for row in &k {
                let f: f64 = (0..NDOF).map(|j| row[j] * mode[j]).sum();
                assert!(f.abs() < 1e-12 * kmax);
            }
        }
        // The bubbles have curvature: their stiffness block is positive definite.
        assert!(k[4][4] > 0.0 && k[5][5] > 0.0 && k[4][4] * k[5][5] > k[4][5] * k[5][4]);
    }

    #[test]
    fn elem_quintic_geometric_stiffness_matches_cubic_block_for_constant_force() {
        let (n0, h) = (3.0, 0.25);
        let kg = geometric_stiffness(h, |_| n0);
        let kc = eb::geometric_stiffness(h, |_| n0);
        for i in 0..4 {
            for j in 0..4 {
                assert!((kg[i][j] - kc[i][j]).abs() < 1e-13 * kc[0][0]);
            }
        }
        // Quadratic force (degree-10 integrand, exact for 6-point Gauss): compare with an
        // independent quadrature, a fine composite midpoint sum.
        let f = |xi: f64| 1.0 + 2.0 * xi - 3.0 * xi * xi;
        let kq = geometric_stiffness(h, f);
        let nsub = 4000;
        let mut fine = [[0.0; NDOF]; NDOF];
        for s in 0..nsub {
            let xi = (s as f64 + 0.5) / nsub as f64;
            let sh = shapes(xi, h);
            for i in 0..NDOF {
                for j in 0..NDOF {
                    fine[i][j] += h / nsub as f64 * f(xi) * sh.dn[i] * sh.dn[j];
                }
            }
        }
        let scale = kq.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
        for i in 0..NDOF {
            for j in 0..NDOF {
                // Midpoint rule error O(1/nsub²) ≈ 1e-7 of the scale (integrand derivatives of
                // order 10/h² relative).
                assert!((kq[i][j] - fine[i][j]).abs() < 1e-6 * scale, "{i}{j}");
            }
        }
    }
}
