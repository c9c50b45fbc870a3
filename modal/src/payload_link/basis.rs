//! Assumed modes of one field of the payload link, clamped at x = 0.
//!
//! * `poly` (default): integrated Legendre polynomials in t = 2x/L − 1. Axial stretch and twist
//!   (ψ(0) = 0): ψₖ ∝ Qₖ(t) = ∫₋₁ᵗ Pₖ, k = 0 … n−1 (Q₀ = t + 1, Qₖ = (Pₖ₊₁ − Pₖ₋₁)/(2k + 1)).
//!   Bending (φ(0) = φ′(0) = 0): φₖ ∝ Rₖ(t) = ∫₋₁ᵗ Qₖ (R₀ = (t + 1)²/2,
//!   Rₖ = (Qₖ₊₁ − Qₖ₋₁)/(2k + 1)). The n functions span every polynomial of degree ≤ n (≤ n+1 for
//!   bending) that meets the clamped conditions, with the strain-energy Gram matrices ∫ψ′ψ′,
//!   ∫φ″φ″ diagonal (Legendre orthogonality), so the Ritz matrices stay well conditioned at any
//!   count, unlike monomials. They carry no boundary condition at the tip: the payload's
//!   inertia loads there (shear, moment, axial force, torque) are natural conditions the Ritz
//!   solution meets in the limit, and the Ritz frequencies converge spectrally.
//! * `clamped-free`: cantilever eigenfunctions for bending and sin((2k − 1)πx/2L) for stretch and
//!   twist. Each has zero shear/moment (axial force/torque) at the tip, where the payload's
//!   inertia loads are not zero, so the Ritz frequencies converge only algebraically (measured
//!   in `conv_payload_link_*`); offered for comparison, not the default.
//!
//! Each function is scaled to unit maximum magnitude on [0, L], so every coordinate is a
//! length (u, v, w) or an angle (φ).

use crate::basis::ShapeSet;
use crate::error::ModalError;

/// Which clamped conditions a field's functions meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clamp {
    /// ψ(0) = 0 (stretch, twist).
    Value,
    /// φ(0) = φ′(0) = 0 (bending).
    ValueAndSlope,
}

#[derive(Debug, Clone)]
enum Family {
    Legendre,
    Eigen(ShapeSet),
}

/// n assumed modes of one field on [0, L].
#[derive(Debug, Clone)]
pub struct FieldBasis {
    pub length: f64,
    pub count: usize,
    pub clamp: Clamp,
    family: Family,
    /// 1 / max|fₖ| of the unscaled functions.
    scale: Vec<f64>,
}

impl FieldBasis {
    /// Integrated Legendre polynomials (the default).
    pub fn legendre(length: f64, count: usize, clamp: Clamp) -> Self {
        let mut b = FieldBasis {
            length,
            count,
            clamp,
            family: Family::Legendre,
            scale: vec![1.0; count],
        };
        b.scale = b.unit_scales();
        b
    }

    /// Clamped-free eigenfunctions (cantilever for bending, fixed-free bar for stretch/twist).
    pub fn clamped_free(length: f64, count: usize, clamp: Clamp) -> Result<Self, ModalError> {
        let set = match clamp {
            Clamp::Value => ShapeSet::axial_sine(length, count),
            Clamp::ValueAndSlope => ShapeSet::clamped_free(length, count)
                .map_err(|source| ModalError::Basis { link: 1, source })?,
        };
        let mut b = FieldBasis {
            length,
            count,
            clamp,
            family: Family::Eigen(set),
            scale: vec![1.0; count],
        };
        b.scale = b.unit_scales();
        Ok(b)
    }

    /// 1 / max|fₖ| over 257 samples of [0, L].
    fn unit_scales(&self) -> Vec<f64> {
        let mut max = vec![0.0f64; self.count];
        let mut v = vec![0.0; self.count];
        for s in 0..=256 {
            self.eval(self.length * s as f64 / 256.0, 0, &mut v);
            for (m, x) in max.iter_mut().zip(&v) {
                *m = m.max(x.abs());
            }
        }
        max.iter()
            .map(|m| if *m > 0.0 { 1.0 / m } else { 1.0 })
            .collect()
    }

    /// d^deriv fₖ/dx^deriv at x for every k (deriv ≤ 2).
    pub fn eval(&self, x: f64, deriv: usize, out: &mut [f64]) {
        match &self.family {
            Family::Eigen(set) => {
                set.eval(x, deriv, &mut out[..self.count]);
                for (o, s) in out.iter_mut().zip(&self.scale) {
                    *o *= s;
                }
            }
            Family::Legendre => {
                let scale = &self.scale;
                let n = self.count;
                let t = 2.0 * x / self.length - 1.0;
                let dt = 2.0 / self.length;
                // P₀ … Pₙ₊₁, then Q₀ … Qₙ and R₀ … Rₙ₋₁ as needed.
                let mut p = [0.0f64; MAX_MODES + 3];
                p[0] = 1.0;
                p[1] = t;
                for k in 1..=n + 1 {
                    p[k + 1] =
                        ((2 * k + 1) as f64 * t * p[k] - k as f64 * p[k - 1]) / (k + 1) as f64;
                }
                let q = |k: usize| -> f64 {
                    if k == 0 {
                        t + 1.0
                    } else {
                        (p[k + 1] - p[k - 1]) / (2 * k + 1) as f64
                    }
                };
                let r = |k: usize| -> f64 {
                    if k == 0 {
                        0.5 * (t + 1.0) * (t + 1.0)
                    } else {
                        (q(k + 1) - q(k - 1)) / (2 * k + 1) as f64
                    }
                };
                for k in 0..n {
                    let v = match (self.clamp, deriv) {
                        (Clamp::Value, 0) => q(k),
                        (Clamp::Value, 1) => p[k] * dt,
                        (Clamp::Value, _) => {
                            // d/dt Pₖ = Σ (2j + 1) Pⱼ over j = k−1, k−3, …
                            let mut d = 0.0;
                            let mut j = k as isize - 1;
                            while j >= 0 {
                                d += (2 * j + 1) as f64 * p[j as usize];
                                j -= 2;
                            }
                            d * dt * dt
                        }
                        (Clamp::ValueAndSlope, 0) => r(k),
                        (Clamp::ValueAndSlope, 1) => q(k) * dt,
                        (Clamp::ValueAndSlope, _) => p[k] * dt * dt,
                    };
                    out[k] = scale[k] * v;
                }
            }
        }
    }
}

/// Largest mode count per field (the Legendre recurrence's fixed buffer).
pub const MAX_MODES: usize = 40;
