//! Spatial integrals of the reduced model, computed once at set-up by Gauss quadrature on the
//! fine mesh (the eigenfunctions are piecewise polynomials there, so 4 points per element are
//! exact for every mass integral below and for the stiffness integrals).
//!
//! The case mass per length is m(x, t) = m₀(x) − s(t)·Δm·χ(x), with χ the indicator of the
//! burning chamber, Δm the burnable mass per length and s(t) ∈ [0, 1] the burnt fraction; every
//! mass integral is therefore affine in s: I(t) = `I[m₀] − s·Δm·I[χ]`. No quadrature runs per step.

use super::basis::Basis;
use crate::basis::quadrature::gauss_legendre_unit;

/// Moments of a weight ρ(x) against the basis (U_k axial, W_k bending), n modes per field.
#[derive(Debug, Clone, PartialEq)]
pub struct Moments {
    pub n: usize,
    /// ∫ρ, ∫ρx, ∫ρx²
    pub total: f64,
    pub first: f64,
    pub second: f64,
    /// ∫ρU_k, ∫ρW_k, ∫ρxU_k, ∫ρxW_k
    pub u: Vec<f64>,
    pub w: Vec<f64>,
    pub xu: Vec<f64>,
    pub xw: Vec<f64>,
    /// ∫ρU_kU_l, ∫ρW_kW_l, ∫ρU_kW_l (row-major n×n, row k = U index for `uw`)
    pub uu: Vec<f64>,
    pub ww: Vec<f64>,
    pub uw: Vec<f64>,
}

impl Moments {
    pub fn zeros(n: usize) -> Moments {
        Moments {
            n,
            total: 0.0,
            first: 0.0,
            second: 0.0,
            u: vec![0.0; n],
            w: vec![0.0; n],
            xu: vec![0.0; n],
            xw: vec![0.0; n],
            uu: vec![0.0; n * n],
            ww: vec![0.0; n * n],
            uw: vec![0.0; n * n],
        }
    }

    /// self = a − c·b, without allocating.
    pub fn set_affine(&mut self, a: &Moments, c: f64, b: &Moments) {
        self.total = a.total - c * b.total;
        self.first = a.first - c * b.first;
        self.second = a.second - c * b.second;
        let pairs: [(&mut Vec<f64>, &Vec<f64>, &Vec<f64>); 7] = [
            (&mut self.u, &a.u, &b.u),
            (&mut self.w, &a.w, &b.w),
            (&mut self.xu, &a.xu, &b.xu),
            (&mut self.xw, &a.xw, &b.xw),
            (&mut self.uu, &a.uu, &b.uu),
            (&mut self.ww, &a.ww, &b.ww),
            (&mut self.uw, &a.uw, &b.uw),
        ];
        for (dst, x, y) in pairs {
            for ((d, x), y) in dst.iter_mut().zip(x.iter()).zip(y.iter()) {
                *d = x - c * y;
            }
        }
    }
}

/// Table of the basis at quadrature points (global order: element by element).
#[derive(Debug, Clone, PartialEq)]
pub struct QuadTable {
    pub n: usize,
    pub x: Vec<f64>,
    /// Quadrature weight including the element length.
    pub weight: Vec<f64>,
    pub element: Vec<usize>,
    /// U_k, U_k', W_k, W_k' at point g: index g·n + k.
    pub u: Vec<f64>,
    pub du: Vec<f64>,
    pub w: Vec<f64>,
    pub dw: Vec<f64>,
    /// W_k'' at point g.
    pub ddw: Vec<f64>,
}

impl QuadTable {
    pub fn new(basis: &Basis, points_per_element: usize) -> QuadTable {
        let n = basis.modes();
        let mesh = &basis.mesh;
        let (gs, gw) = gauss_legendre_unit(points_per_element);
        let np = mesh.elements.len() * gs.len();
        let mut t = QuadTable {
            n,
            x: Vec::with_capacity(np),
            weight: Vec::with_capacity(np),
            element: Vec::with_capacity(np),
            u: vec![0.0; np * n],
            du: vec![0.0; np * n],
            w: vec![0.0; np * n],
            dw: vec![0.0; np * n],
            ddw: vec![0.0; np * n],
        };
        let mut g = 0;
        for (e, el) in mesh.elements.iter().enumerate() {
            for (s, wq) in gs.iter().zip(&gw) {
                t.x.push(el.x0 + s * el.h);
                t.weight.push(wq * el.h);
                t.element.push(e);
                let r = g * n..(g + 1) * n;
                basis
                    .axial
                    .eval_element(mesh, e, *s, &mut t.u[r.clone()], &mut t.du[r.clone()]);
                basis
                    .bending
                    .eval_element(mesh, e, *s, &mut t.w[r.clone()], &mut t.dw[r.clone()]);
                // evaluate W'' on this element (eval() locates by x, which at an element edge
                // could pick the neighbour: curvature jumps there, so use the element directly)
                let (_, _, dd) = super::fine_mesh::hermite(*s, el.h);
                let map = super::fine_mesh::FineMesh::bending_map(e);
                for k in 0..n {
                    let c = &basis.bending.coeffs[k];
                    t.ddw[g * n + k] = (0..4).map(|a| dd[a] * c[map[a]]).sum();
                }
                g += 1;
            }
        }
        t
    }

    pub fn points(&self) -> usize {
        self.x.len()
    }

    /// Moments of the weight ρ(x) given per quadrature point.
    pub fn moments(&self, rho: impl Fn(usize, f64) -> f64) -> Moments {
        let n = self.n;
        let mut m = Moments::zeros(n);
        for g in 0..self.points() {
            let x = self.x[g];
            let r = rho(g, x) * self.weight[g];
            if r == 0.0 {
                continue;
            }
            m.total += r;
            m.first += r * x;
            m.second += r * x * x;
            let u = &self.u[g * n..(g + 1) * n];
            let w = &self.w[g * n..(g + 1) * n];
            for k in 0..n {
                m.u[k] += r * u[k];
                m.w[k] += r * w[k];
                m.xu[k] += r * x * u[k];
                m.xw[k] += r * x * w[k];
                for l in 0..n {
                    m.uu[k * n + l] += r * u[k] * u[l];
                    m.ww[k * n + l] += r * w[k] * w[l];
                    m.uw[k * n + l] += r * u[k] * w[l];
                }
            }
        }
        m
    }

    /// Stiffness matrices K_a = ∫EA U_k'U_l', K_b = ∫EI W_k''W_l'' (row-major n×n).
    pub fn stiffness(&self, basis: &Basis) -> (Vec<f64>, Vec<f64>) {
        let n = self.n;
        let mut ka = vec![0.0; n * n];
        let mut kb = vec![0.0; n * n];
        for g in 0..self.points() {
            let el = &basis.mesh.elements[self.element[g]];
            let wa = el.ea * self.weight[g];
            let wb = el.ei * self.weight[g];
            let du = &self.du[g * n..(g + 1) * n];
            let dd = &self.ddw[g * n..(g + 1) * n];
            for k in 0..n {
                for l in 0..n {
                    ka[k * n + l] += wa * du[k] * du[l];
                    kb[k * n + l] += wb * dd[k] * dd[l];
                }
            }
        }
        (ka, kb)
    }
}
