//! Bordered band solver for the Newton matrix of a floating-frame chain.
//!
//! Ordering: the n_I *interior* elastic DOFs first (banded, half-bandwidth b, because elements only
//! couple neighbouring nodes), then the n_B *border* DOFs (free joint angles and the tip-node DOFs of
//! links that carry a child), which couple densely to whole links. Factorization: band LU of the
//! interior block (no pivoting: the block is dominated by the positive definite c·M + K), then
//! the small dense Schur complement with partial pivoting. Cost O(n_I b² + n_I b n_B + n_B³):
//! linear in the number of elements. All storage is allocated once; factorize/solve allocate nothing.

use crate::error::FemError;

#[derive(Debug, Clone)]
pub struct BorderedBand {
    ni: usize,
    nb: usize,
    b: usize,
    /// Interior band, row-major: band[i*(2b+1) + (j − i + b)].
    band: Vec<f64>,
    /// S_IB (n_I × n_B), row-major.
    ib: Vec<f64>,
    /// S_BI (n_B × n_I), row-major.
    bi: Vec<f64>,
    /// S_BB (n_B × n_B); after factorization the LU of the Schur complement.
    schur: DenseLu,
    /// Y = A⁻¹ S_IB after factorization (n_I × n_B, row-major).
    y: Vec<f64>,
    tmp_b: Vec<f64>,
    factored: bool,
}

impl BorderedBand {
    pub fn new(ni: usize, nb: usize, b: usize) -> Self {
        BorderedBand {
            ni,
            nb,
            b,
            band: vec![0.0; ni * (2 * b + 1)],
            ib: vec![0.0; ni * nb],
            bi: vec![0.0; nb * ni],
            schur: DenseLu::new(nb),
            y: vec![0.0; ni * nb],
            tmp_b: vec![0.0; nb],
            factored: false,
        }
    }

    pub fn n(&self) -> usize {
        self.ni + self.nb
    }

    pub fn half_bandwidth(&self) -> usize {
        self.b
    }

    pub fn clear(&mut self) {
        self.band.iter_mut().for_each(|x| *x = 0.0);
        self.ib.iter_mut().for_each(|x| *x = 0.0);
        self.bi.iter_mut().for_each(|x| *x = 0.0);
        self.schur.a.iter_mut().for_each(|x| *x = 0.0);
        self.factored = false;
    }

    /// Adds `v` to entry (i, j) of the global matrix. Interior pairs must lie within the band.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let (ni, nb, b) = (self.ni, self.nb, self.b);
        match (i < ni, j < ni) {
            (true, true) => {
                debug_assert!(i.abs_diff(j) <= b, "entry ({i},{j}) outside band {b}");
                self.band[i * (2 * b + 1) + (j + b - i)] += v;
            }
            (true, false) => self.ib[i * nb + (j - ni)] += v,
            (false, true) => self.bi[(i - ni) * ni + j] += v,
            (false, false) => self.schur.a[(i - ni) * nb + (j - ni)] += v,
        }
    }

    /// Entry (i, j) before factorization.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (ni, nb, b) = (self.ni, self.nb, self.b);
        match (i < ni, j < ni) {
            (true, true) => {
                if i.abs_diff(j) <= b {
                    self.band[i * (2 * b + 1) + (j + b - i)]
                } else {
                    0.0
                }
            }
            (true, false) => self.ib[i * nb + (j - ni)],
            (false, true) => self.bi[(i - ni) * ni + j],
            (false, false) => self.schur.a[(i - ni) * nb + (j - ni)],
        }
    }

    /// y = A x (before factorization).
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        let (ni, nb, b) = (self.ni, self.nb, self.b);
        let w = 2 * b + 1;
        for i in 0..ni {
            let lo = i.saturating_sub(b);
            let hi = (i + b).min(ni - 1);
            let mut s = 0.0;
            for j in lo..=hi {
                s += self.band[i * w + (j + b - i)] * x[j];
            }
            for k in 0..nb {
                s += self.ib[i * nb + k] * x[ni + k];
            }
            y[i] = s;
        }
        for r in 0..nb {
            let mut s = 0.0;
            for j in 0..ni {
                s += self.bi[r * ni + j] * x[j];
            }
            for k in 0..nb {
                s += self.schur.a[r * nb + k] * x[ni + k];
            }
            y[ni + r] = s;
        }
    }

    /// In-place LU of the band (Doolittle, no pivoting).
    fn band_factor(&mut self) -> Result<(), usize> {
        let (n, b) = (self.ni, self.b);
        let w = 2 * b + 1;
        for k in 0..n {
            let piv = self.band[k * w + b];
            if piv == 0.0 || !piv.is_finite() {
                return Err(k);
            }
            let hi = (k + b).min(n.saturating_sub(1));
            for i in (k + 1)..=hi {
                let l = self.band[i * w + (k + b - i)] / piv;
                self.band[i * w + (k + b - i)] = l;
                for j in (k + 1)..=hi {
                    self.band[i * w + (j + b - i)] -= l * self.band[k * w + (j + b - k)];
                }
            }
        }
        Ok(())
    }

    fn band_solve(band: &[f64], n: usize, b: usize, x: &mut [f64], stride: usize, col: usize) {
        let w = 2 * b + 1;
        for i in 0..n {
            let lo = i.saturating_sub(b);
            let mut s = x[i * stride + col];
            for j in lo..i {
                s -= band[i * w + (j + b - i)] * x[j * stride + col];
            }
            x[i * stride + col] = s;
        }
        for i in (0..n).rev() {
            let hi = (i + b).min(n - 1);
            let mut s = x[i * stride + col];
            for j in (i + 1)..=hi {
                s -= band[i * w + (j + b - i)] * x[j * stride + col];
            }
            x[i * stride + col] = s / band[i * w + b];
        }
    }

    /// Factorizes the assembled matrix (numeric only: the pattern is fixed at construction).
    pub fn factorize(&mut self) -> Result<(), FemError> {
        let (ni, nb) = (self.ni, self.nb);
        self.band_factor().map_err(|p| FemError::Singular {
            what: "Newton (interior band)".into(),
            pivot: p,
            t: f64::NAN,
        })?;
        // Y = A⁻¹ S_IB, column by column.
        self.y.copy_from_slice(&self.ib);
        for c in 0..nb {
            Self::band_solve(&self.band, ni, self.b, &mut self.y, nb, c);
        }
        // Schur complement S = S_BB − S_BI Y.
        for r in 0..nb {
            for c in 0..nb {
                let mut s = 0.0;
                for j in 0..ni {
                    s += self.bi[r * ni + j] * self.y[j * nb + c];
                }
                self.schur.a[r * nb + c] -= s;
            }
        }
        // Dense LU with partial pivoting.
        self.schur.factorize().map_err(|e| match e {
            FemError::Singular { pivot, .. } => FemError::Singular {
                what: "Newton (border Schur complement)".into(),
                pivot: ni + pivot,
                t: f64::NAN,
            },
            other => other,
        })?;
        self.factored = true;
        Ok(())
    }

    /// Solves A x = r in place (after [`BorderedBand::factorize`]).
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        debug_assert!(self.factored);
        let (ni, nb) = (self.ni, self.nb);
        Self::band_solve(&self.band, ni, self.b, x, 1, 0);
        // r_B − S_BI x_I'
        for r in 0..nb {
            let mut s = x[ni + r];
            for j in 0..ni {
                s -= self.bi[r * ni + j] * x[j];
            }
            self.tmp_b[r] = s;
        }
        self.schur.solve_in_place(&mut self.tmp_b);
        for i in 0..ni {
            let mut s = 0.0;
            for c in 0..nb {
                s += self.y[i * nb + c] * self.tmp_b[c];
            }
            x[i] -= s;
        }
        x[ni..].copy_from_slice(&self.tmp_b);
    }
}

/// Dense LU with partial pivoting: the border Schur complement above, and the exact
/// finite-difference Jacobian of chains whose foreshortening couples whole links to the joint
/// angles.
#[derive(Debug, Clone)]
pub struct DenseLu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl DenseLu {
    pub fn new(n: usize) -> Self {
        DenseLu {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }
    /// Column j of the matrix (before factorization).
    pub fn set_column(&mut self, j: usize, col: &[f64]) {
        for i in 0..self.n {
            self.a[i * self.n + j] = col[i];
        }
    }
    pub fn factorize(&mut self) -> Result<(), FemError> {
        let n = self.n;
        for k in 0..n {
            let mut p = k;
            for i in (k + 1)..n {
                if self.a[i * n + k].abs() > self.a[p * n + k].abs() {
                    p = i;
                }
            }
            self.piv[k] = p;
            if p != k {
                for j in 0..n {
                    self.a.swap(k * n + j, p * n + j);
                }
            }
            let d = self.a[k * n + k];
            if d == 0.0 || !d.is_finite() {
                return Err(FemError::Singular {
                    what: "Newton (dense)".into(),
                    pivot: k,
                    t: f64::NAN,
                });
            }
            for i in (k + 1)..n {
                let l = self.a[i * n + k] / d;
                self.a[i * n + k] = l;
                if l != 0.0 {
                    for j in (k + 1)..n {
                        self.a[i * n + j] -= l * self.a[k * n + j];
                    }
                }
            }
        }
        Ok(())
    }
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = self.n;
        // Rows were swapped whole during factorization: permute b completely first.
        for k in 0..n {
            x.swap(k, self.piv[k]);
        }
        for k in 0..n {
            for i in (k + 1)..n {
                x[i] -= self.a[i * n + k] * x[k];
            }
        }
        for k in (0..n).rev() {
            let mut s = x[k];
            for j in (k + 1)..n {
                s -= self.a[k * n + j] * x[j];
            }
            x[k] = s / self.a[k * n + k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sys_bordered_band_solves_like_dense() {
        // Random-ish diagonally dominant nonsymmetric bordered band matrix.
        let (ni, nb, b) = (12, 3, 2);
        let n = ni + nb;
        let mut a = BorderedBand::new(ni, nb, b);
        let mut dense = vec![vec![0.0; n]; n];
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for i in 0..n {
            for j in 0..n {
                let in_pattern = i >= ni || j >= ni || i.abs_diff(j) <= b;
                if in_pattern {
                    let v = rnd() + if i == j { 6.0 } else { 0.0 };
                    a.add(i, j, v);
                    dense[i][j] = v;
                }
            }
        }
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut r: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| dense[i][j] * x_true[j]).sum())
            .collect();
        let mut y = vec![0.0; n];
        a.matvec(&x_true, &mut y);
        for i in 0..n {
            assert!((y[i] - r[i]).abs() < 1e-13);
        }
        a.factorize().unwrap();
        a.solve_in_place(&mut r);
        for i in 0..n {
            // Well-conditioned (diagonally dominant): round-off only.
            assert!((r[i] - x_true[i]).abs() < 1e-13, "{i}");
        }
    }
}
