//! Anderson acceleration of the quasi-Newton fixed-point iteration of runs without contact.

use crate::linalg::dot;

/// History length of [`Anderson`].
pub(super) const ANDERSON_DEPTH: usize = 3;

/// Anderson acceleration (type II, depth [`ANDERSON_DEPTH`]) of the fixed-point iteration
/// a ↦ a + f(a), f = −S⁻¹·res(a) the quasi-Newton update: with the differences Δa_j, Δf_j of
/// the last iterates, γ = argmin‖f − ΔF γ‖₂ (normal equations, m ≤ 3) and
/// a ← a + f − (ΔA + ΔF)γ. The quasi-Newton map is nearly affine (S fixed, residual smooth):
/// the differences then span its slowly contracting directions and the extrapolation removes
/// them. Buffers allocated once.
#[derive(Debug, Clone)]
pub(super) struct Anderson {
    pub(super) n: usize,
    pub(super) len: usize,
    pub(super) next: usize,
    pub(super) da: Vec<f64>,
    pub(super) df: Vec<f64>,
    pub(super) a_last: Vec<f64>,
    pub(super) f_last: Vec<f64>,
    pub(super) have_last: bool,
}

impl Anderson {
    pub(super) fn new(n: usize) -> Self {
        Anderson {
            n,
            len: 0,
            next: 0,
            da: vec![0.0; ANDERSON_DEPTH * n],
            df: vec![0.0; ANDERSON_DEPTH * n],
            a_last: vec![0.0; n],
            f_last: vec![0.0; n],
            have_last: false,
        }
    }

    pub(super) fn reset(&mut self) {
        self.len = 0;
        self.next = 0;
        self.have_last = false;
    }

    /// Replaces `a` by the accelerated iterate; `delta` = S⁻¹·res(a) (f = −delta).
    pub(super) fn advance(&mut self, a: &mut [f64], delta: &[f64]) {
        let n = self.n;
        if self.have_last {
            let col = self.next * n;
            for i in 0..n {
                self.da[col + i] = a[i] - self.a_last[i];
                self.df[col + i] = -delta[i] - self.f_last[i];
            }
            self.next = (self.next + 1) % ANDERSON_DEPTH;
            self.len = (self.len + 1).min(ANDERSON_DEPTH);
        }
        self.a_last.copy_from_slice(a);
        for i in 0..n {
            self.f_last[i] = -delta[i];
        }
        self.have_last = true;
        let m = self.len;
        let mut gamma = [0.0; ANDERSON_DEPTH];
        if m > 0 {
            let mut g = [[0.0; ANDERSON_DEPTH + 1]; ANDERSON_DEPTH];
            for j in 0..m {
                let dj = &self.df[j * n..(j + 1) * n];
                for k in 0..=j {
                    let v = dot(dj, &self.df[k * n..(k + 1) * n]);
                    g[j][k] = v;
                    g[k][j] = v;
                }
                g[j][m] = dot(dj, &self.f_last);
            }
            if !solve_small(&mut g, m, &mut gamma) {
                // Nearly dependent differences (round-off near convergence): plain step.
                gamma = [0.0; ANDERSON_DEPTH];
            }
        }
        for i in 0..n {
            let mut x = a[i] + self.f_last[i];
            for j in 0..m {
                x -= gamma[j] * (self.da[j * n + i] + self.df[j * n + i]);
            }
            a[i] = x;
        }
    }
}

/// Solves the m × m system in the first m columns of `g` (right-hand side in column m) by
/// Gaussian elimination with partial pivoting; false when a pivot is below 1e-12 of the
/// largest diagonal (then `x` is not written).
pub(super) fn solve_small(
    g: &mut [[f64; ANDERSON_DEPTH + 1]; ANDERSON_DEPTH],
    m: usize,
    x: &mut [f64; ANDERSON_DEPTH],
) -> bool {
    let dmax = (0..m).fold(0.0f64, |a, i| a.max(g[i][i].abs()));
    if dmax.is_nan() || dmax <= 0.0 || !dmax.is_finite() {
        return false;
    }
    for k in 0..m {
        let p = (k..m)
            .max_by(|&i, &j| g[i][k].abs().total_cmp(&g[j][k].abs()))
            .unwrap_or(k);
        g.swap(k, p);
        if g[k][k].abs() <= 1e-12 * dmax {
            return false;
        }
        for i in k + 1..m {
            let l = g[i][k] / g[k][k];
            for j in k..=m {
                g[i][j] -= l * g[k][j];
            }
        }
    }
    for k in (0..m).rev() {
        let mut v = g[k][m];
        for j in k + 1..m {
            v -= g[k][j] * x[j];
        }
        x[k] = v / g[k][k];
    }
    true
}
