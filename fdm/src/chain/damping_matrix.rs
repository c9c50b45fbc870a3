//! The data of the implicit damping kick ([`super::implicit`]): the constant damping matrix C
//! on the band (diagonal and two sub-diagonals) and on the full columns of M, the LDLᵀ of the
//! pentadiagonal D_B + ½τC_BB for the step τ, the Schur block of the constant ghost columns,
//! and the scratch of a kick.

// Index loops over band positions read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::schur::MAX_FULL;

/// Full columns of M that depend on the state (θ, β come first; the ghost columns after them
/// are constant).
pub(super) const STATE_COLUMNS: usize = 2;

/// C and the banded factorization of the implicit kick (module docs).
#[derive(Debug, Clone)]
pub struct ImplicitDamping {
    /// q-index of each band position (the coordinates outside the full columns, in q order)
    pub(super) band: Vec<usize>,
    /// C on the band: diagonal, first and second sub-diagonals (by band position)
    pub(super) c0: Vec<f64>,
    pub(super) c1: Vec<f64>,
    pub(super) c2: Vec<f64>,
    /// C's full columns over q
    pub(super) cf: [Vec<f64>; MAX_FULL],
    /// LDLᵀ of D_B + ½τC_BB for the step `tau` (NaN: none yet)
    pub(super) d: Vec<f64>,
    pub(super) l1: Vec<f64>,
    pub(super) l2: Vec<f64>,
    pub(super) tau: f64,
    /// Schur complement block of the constant (ghost) columns, rows and columns ≥ `STATE_COLUMNS`
    /// (computed with the factorization)
    pub(super) s_ghost: [[f64; MAX_FULL]; MAX_FULL],
    /// scratch: A_BF columns and Z = A_BB⁻¹A_BF over band positions (the ghost columns' kept
    /// from the factorization), A_BB⁻¹ r_B, v_{j+1}
    pub(super) abf: [Vec<f64>; MAX_FULL],
    pub(super) z: [Vec<f64>; MAX_FULL],
    pub(super) zb: Vec<f64>,
    pub(super) vnew: Vec<f64>,
}

impl ImplicitDamping {
    /// LDLᵀ of the pentadiagonal D_B + ½τC_BB.
    pub(super) fn factor(&mut self, diag: impl Fn(usize) -> f64, tau: f64) {
        let nb = self.band.len();
        let ht = 0.5 * tau;
        for j in 0..nb {
            let mut dj = diag(self.band[j]) + ht * self.c0[j];
            if j >= 1 {
                dj -= self.l1[j - 1] * self.l1[j - 1] * self.d[j - 1];
            }
            if j >= 2 {
                dj -= self.l2[j - 2] * self.l2[j - 2] * self.d[j - 2];
            }
            self.d[j] = dj;
            if j + 1 < nb {
                let mut a = ht * self.c1[j];
                if j >= 1 {
                    a -= self.l2[j - 1] * self.l1[j - 1] * self.d[j - 1];
                }
                self.l1[j] = a / dj;
            }
            if j + 2 < nb {
                self.l2[j] = ht * self.c2[j] / dj;
            }
        }
        self.tau = tau;
    }

    /// x ← (LDLᵀ)⁻¹ x.
    pub(super) fn solve(d: &[f64], l1: &[f64], l2: &[f64], x: &mut [f64]) {
        let nb = x.len();
        for i in 1..nb {
            let mut s = x[i] - l1[i - 1] * x[i - 1];
            if i >= 2 {
                s -= l2[i - 2] * x[i - 2];
            }
            x[i] = s;
        }
        for i in 0..nb {
            x[i] /= d[i];
        }
        for i in (0..nb.saturating_sub(1)).rev() {
            let mut s = x[i] - l1[i] * x[i + 1];
            if i + 2 < nb {
                s -= l2[i] * x[i + 2];
            }
            x[i] = s;
        }
    }
}
