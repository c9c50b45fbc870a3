//! Timoshenko beam element with interdependent interpolation (IIE, Reddy 1997): free of shear
//! locking.
//!
//! Fields: transverse deflection v and section rotation θ; shear strain γ = v′ − θ, curvature θ′.
//! Energies U = ½∫EI θ′² + ½∫κGA (v′ − θ)², T = ½∫ρA v̇² + ½∫ρI θ̇².
//!
//! The interpolation is the exact homogeneous solution of the static Timoshenko equations
//! (κGA(v′ − θ))′ = 0, EI θ″ + κGA(v′ − θ) = 0: v cubic, θ = v′ − (6EI/κGA)·a₃ quadratic, so the
//! shear strain is constant and cannot lock: as κGA → ∞ the element becomes the Hermite cubic.
//! DOFs (v₁, θ₁, v₂, θ₂).

use super::Mat4;
use super::quadrature::gauss01;

/// Interpolation of an IIE element: polynomial coefficients of v and θ for each nodal DOF.
#[derive(Debug, Clone, Copy)]
pub struct TimoshenkoElement {
    pub h: f64,
    /// v(x) = Σₖ dₖ Σₚ cv[k][p] xᵖ.
    cv: [[f64; 4]; 4],
    /// θ(x) = Σₖ dₖ Σₚ ct[k][p] xᵖ.
    ct: [[f64; 4]; 4],
}

impl TimoshenkoElement {
    pub fn new(h: f64, ei: f64, kga: f64) -> Self {
        let c = 6.0 * ei / kga;
        // d = A a with a = (a₀, a₁, a₂, a₃) the coefficients of v.
        let a = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, c],
            [1.0, h, h * h, h * h * h],
            [0.0, 1.0, 2.0 * h, 3.0 * h * h + c],
        ];
        let inv = invert4(a);
        // a = inv d ⇒ coefficient p of v for DOF k is inv[p][k].
        let mut cv = [[0.0; 4]; 4];
        let mut ct = [[0.0; 4]; 4];
        for k in 0..4 {
            for p in 0..4 {
                cv[k][p] = inv[p][k];
            }
            // θ = a₁ + c a₃ + 2a₂ x + 3a₃ x²
            ct[k][0] = inv[1][k] + c * inv[3][k];
            ct[k][1] = 2.0 * inv[2][k];
            ct[k][2] = 3.0 * inv[3][k];
            ct[k][3] = 0.0;
        }
        TimoshenkoElement { h, cv, ct }
    }

    fn poly(c: &[f64; 4], x: f64) -> f64 {
        c[0] + x * (c[1] + x * (c[2] + x * c[3]))
    }
    fn dpoly(c: &[f64; 4], x: f64) -> f64 {
        c[1] + x * (2.0 * c[2] + x * 3.0 * c[3])
    }

    /// (v, v′, θ, θ′) shape-function values of each DOF at x ∈ [0, h].
    pub fn shapes(&self, x: f64) -> [[f64; 4]; 4] {
        let mut s = [[0.0; 4]; 4];
        for k in 0..4 {
            s[k] = [
                Self::poly(&self.cv[k], x),
                Self::dpoly(&self.cv[k], x),
                Self::poly(&self.ct[k], x),
                Self::dpoly(&self.ct[k], x),
            ];
        }
        s
    }

    /// Stiffness ∫EI θ′ᵢθ′ⱼ + κGA γᵢγⱼ.
    pub fn stiffness(&self, ei: f64, kga: f64) -> Mat4 {
        let (p, w) = gauss01(4);
        let mut k = [[0.0; 4]; 4];
        for (xi, wg) in p.iter().zip(w) {
            let s = self.shapes(xi * self.h);
            for i in 0..4 {
                for j in 0..4 {
                    let gi = s[i][1] - s[i][2];
                    let gj = s[j][1] - s[j][2];
                    k[i][j] += wg * self.h * (ei * s[i][3] * s[j][3] + kga * gi * gj);
                }
            }
        }
        k
    }

    /// Consistent mass ∫ρA vᵢvⱼ + ρI θᵢθⱼ.
    pub fn mass(&self, rho_a: f64, rho_i: f64) -> Mat4 {
        let (p, w) = gauss01(4);
        let mut m = [[0.0; 4]; 4];
        for (xi, wg) in p.iter().zip(w) {
            let s = self.shapes(xi * self.h);
            for i in 0..4 {
                for j in 0..4 {
                    m[i][j] +=
                        wg * self.h * (rho_a * s[i][0] * s[j][0] + rho_i * s[i][2] * s[j][2]);
                }
            }
        }
        m
    }
}

/// Inverse of a small nonsingular 4×4 matrix by Gauss–Jordan with partial pivoting.
fn invert4(mut a: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut inv = [[0.0; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for col in 0..4 {
        let piv = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        inv.swap(col, piv);
        let d = a[col][col];
        for j in 0..4 {
            a[col][j] /= d;
            inv[col][j] /= d;
        }
        for r in 0..4 {
            if r != col {
                let f = a[r][col];
                for j in 0..4 {
                    a[r][j] -= f * a[col][j];
                    inv[r][j] -= f * inv[col][j];
                }
            }
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::euler_bernoulli;

    #[test]
    fn elem_timoshenko_stiffness_matches_closed_form() {
        let (ei, kga, h) = (175.0, 6.73e6, 0.01);
        let k = TimoshenkoElement::new(h, ei, kga).stiffness(ei, kga);
        let phi = 12.0 * ei / (kga * h * h);
        let c = ei / ((1.0 + phi) * h.powi(3));
        let exact = [
            [12.0 * c, 6.0 * h * c, -12.0 * c, 6.0 * h * c],
            [
                6.0 * h * c,
                (4.0 + phi) * h * h * c,
                -6.0 * h * c,
                (2.0 - phi) * h * h * c,
            ],
            [-12.0 * c, -6.0 * h * c, 12.0 * c, -6.0 * h * c],
            [
                6.0 * h * c,
                (2.0 - phi) * h * h * c,
                -6.0 * h * c,
                (4.0 + phi) * h * h * c,
            ],
        ];
        for i in 0..4 {
            for j in 0..4 {
                // Exact quadrature of polynomials; round-off from the 4×4 inverse.
                assert!(
                    (k[i][j] - exact[i][j]).abs() < 1e-10 * exact[0][0],
                    "{i}{j}"
                );
            }
        }
    }

    #[test]
    fn elem_timoshenko_thin_limit_is_euler_bernoulli() {
        let (ei, rho_a, h) = (175.0, 0.785, 0.05);
        // κGA → ∞: Φ = 12EI/(κGA h²) = 1.2e-9 here, so the matrices approach the Hermite ones
        // at relative order Φ.
        let kga = 1e15;
        let e = TimoshenkoElement::new(h, ei, kga);
        let (k, m) = (e.stiffness(ei, kga), e.mass(rho_a, 0.0));
        let (kb, mb) = (
            euler_bernoulli::bending_stiffness(ei, h),
            euler_bernoulli::mass(rho_a, 0.0, h),
        );
        for i in 0..4 {
            for j in 0..4 {
                // Shear energy κGA γ² with γ = O(Φ) is O(Φ)·EI terms; round-off in κGA·γ²
                // (κGA ≈ 1e15 times γ ≈ 1e-9·(1 ± 1e-16·1e9)) is ≤ 1e-6 relative.
                assert!((k[i][j] - kb[i][j]).abs() < 1e-6 * kb[0][0], "K{i}{j}");
                assert!((m[i][j] - mb[i][j]).abs() < 1e-8 * mb[0][0], "M{i}{j}");
            }
        }
    }

    #[test]
    fn elem_timoshenko_rigid_modes_in_null_space() {
        let (ei, kga, h) = (175.0, 6.73e6, 0.02);
        let k = TimoshenkoElement::new(h, ei, kga).stiffness(ei, kga);
        // Translation (1, 0, 1, 0) and rotation (0, 1, h, 1) (v = x, θ = 1, γ = 0).
        for mode in [[1.0, 0.0, 1.0, 0.0], [0.0, 1.0, h, 1.0]] {
            for row in &k {
                let r: f64 = (0..4).map(|j| row[j] * mode[j]).sum();
                assert!(r.abs() < 1e-9 * k[0][0]);
            }
        }
    }
}
