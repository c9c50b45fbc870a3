//! LDLᵀ of a symmetric band matrix without pivoting, for matrices whose LDLᵀ exists in any
//! order: positive definite ones and the quasi-definite saddle systems [[P, Gᵀ], [G, −N⁻¹]]
//! with P and N⁻¹ positive definite (Vanderbei: the pivots of the first block stay positive,
//! those of the second negative). O(n·k²) with half-bandwidth k, no allocation after
//! construction.

// Index loops over the band read like the factorization.
#![allow(clippy::needless_range_loop)]

/// Largest half-bandwidth [`BandLdl`] factors (its row scratch lives on the stack).
pub const MAX_HALF_BANDWIDTH: usize = 16;

/// A = L D Lᵀ with L unit lower triangular of half-bandwidth `k`, stored by rows.
#[derive(Debug, Clone, Default)]
pub struct BandLdl {
    n: usize,
    k: usize,
    /// row i holds A[i, i−k..=i] before and L[i, i−k..i] (and D at the diagonal) after factor
    a: Vec<f64>,
}

impl BandLdl {
    /// Storage for an n × n matrix of half-bandwidth k, all zero.
    pub fn new(n: usize, k: usize) -> Self {
        BandLdl {
            n,
            k,
            a: vec![0.0; n * (k + 1)],
        }
    }

    fn at(&self, i: usize, j: usize) -> usize {
        debug_assert!(j <= i && i - j <= self.k, "({i}, {j}) outside the band");
        i * (self.k + 1) + self.k - (i - j)
    }

    /// The order n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The nonzero entries (i, j, A[i, j]) of the symmetric matrix as assembled (before
    /// [`Self::factor`]), both triangles, row by row of the lower one.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (0..self.n).flat_map(move |i| {
            (i.saturating_sub(self.k)..=i).flat_map(move |j| {
                let v = self.a[self.at(i, j)];
                let lower = (v != 0.0).then_some((i, j, v));
                let upper = (v != 0.0 && i != j).then_some((j, i, v));
                lower.into_iter().chain(upper)
            })
        })
    }

    /// Zeroes the matrix.
    pub fn clear(&mut self) {
        self.a.iter_mut().for_each(|x| *x = 0.0);
    }

    /// A[i, j] += v for |i − j| ≤ k (the symmetric entry is implied).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        let p = self.at(i, j);
        self.a[p] += v;
    }

    /// Factors in place. Err(j): pivot j is zero or not finite. `scratch` holds row j of L
    /// times D while column j is eliminated.
    pub fn factor(&mut self) -> Result<(), usize> {
        let (n, k, w) = (self.n, self.k, self.k + 1);
        let mut ld = [0.0; MAX_HALF_BANDWIDTH];
        assert!(
            k <= MAX_HALF_BANDWIDTH,
            "half-bandwidth {k} above {MAX_HALF_BANDWIDTH}"
        );
        for j in 0..n {
            let lo = j.saturating_sub(k);
            let row_j = j * w + w - 1 - (j - lo);
            let mut d = self.a[j * w + w - 1];
            for (t, m) in (lo..j).enumerate() {
                let l = self.a[row_j + t];
                ld[t] = l * self.a[m * w + w - 1];
                d -= l * ld[t];
            }
            if d == 0.0 || !d.is_finite() {
                return Err(j);
            }
            self.a[j * w + w - 1] = d;
            for i in j + 1..(j + k + 1).min(n) {
                // row i's entries at columns lo_i..j against row j's L·D
                let lo_i = i - k.min(i);
                let row_i = i * w + w - 1 - (i - lo_i);
                let mut s = self.a[row_i + (j - lo_i)];
                for m in lo_i.max(lo)..j {
                    s -= self.a[row_i + (m - lo_i)] * ld[m - lo];
                }
                self.a[row_i + (j - lo_i)] = s / d;
            }
        }
        Ok(())
    }

    /// X ← A⁻¹X for `m` right-hand sides stored by rows (X[i·m + c]): one sweep for all, L
    /// by rows, D, then Lᵀ with the rows of L read as its columns (contiguous band rows).
    pub fn solve_rows_in_place(&self, x: &mut [f64], m: usize) {
        let (n, w) = (self.n, self.k + 1);
        for i in 0..n {
            let lo = i.saturating_sub(self.k);
            let (done, rest) = x.split_at_mut(i * m);
            let xi = &mut rest[..m];
            for (t, j) in (lo..i).enumerate() {
                let l = self.a[i * w + w - 1 - (i - lo) + t];
                for (v, u) in xi.iter_mut().zip(&done[j * m..j * m + m]) {
                    *v -= l * u;
                }
            }
        }
        for i in 0..n {
            let d = self.a[i * w + w - 1];
            x[i * m..i * m + m].iter_mut().for_each(|v| *v /= d);
        }
        for i in (0..n).rev() {
            let lo = i.saturating_sub(self.k);
            let (head, rest) = x.split_at_mut(i * m);
            let xi = &rest[..m];
            for (t, j) in (lo..i).enumerate() {
                let l = self.a[i * w + w - 1 - (i - lo) + t];
                for (v, u) in head[j * m..j * m + m].iter_mut().zip(xi) {
                    *v -= l * u;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_band_ldl_solves_a_quasi_definite_saddle_system_as_faer_does() {
        // [[P, Gᵀ], [G, −N]] interleaved: P SPD pentadiagonal, N SPD tridiagonal, G bidiagonal;
        // the residual of the solution and faer's dense LU solution as references
        let m = 9;
        let n = 2 * m;
        let (pz, pl) = (|i: usize| 2 * i, |i: usize| 2 * i + 1);
        let mut band = BandLdl::new(n, 4);
        let mut dense = faer::Mat::<f64>::zeros(n, n);
        let mut put = |i: usize, j: usize, v: f64| {
            band.add(i, j, v);
            dense[(i, j)] += v;
            if i != j {
                dense[(j, i)] += v;
            }
        };
        for i in 0..m {
            put(pz(i), pz(i), 4.0 + 0.1 * i as f64);
            if i + 1 < m {
                put(pz(i + 1), pz(i), -1.0);
            }
            if i + 2 < m {
                put(pz(i + 2), pz(i), 0.3);
            }
            put(pl(i), pl(i), -(2.0 + 0.05 * i as f64));
            if i + 1 < m {
                put(pl(i + 1), pl(i), 0.7);
            }
            put(pl(i), pz(i), 0.4 + 0.02 * i as f64);
            if i > 0 {
                put(pl(i), pz(i - 1), -0.5);
            }
        }
        band.factor().unwrap();
        // four right-hand sides by rows, one sweep; each column against its residual and
        // against faer's solution
        let m = 4;
        let rhs = faer::Mat::<f64>::from_fn(n, m, |i, c| match c {
            0 => (0.37 * i as f64).cos() + 0.2,
            1 => 1.0 + i as f64,
            2 => {
                if i % 3 == 0 {
                    1.0
                } else {
                    0.0
                }
            }
            _ => (-0.5 * i as f64).exp(),
        });
        let mut rows: Vec<f64> = (0..n * m).map(|k| rhs[(k / m, k % m)]).collect();
        band.solve_rows_in_place(&mut rows, m);
        let y = {
            use faer::prelude::Solve;
            dense.partial_piv_lu().solve(&rhs)
        };
        for c in 0..m {
            let scale = (0..n).fold(0.0f64, |a, i| a.max(rhs[(i, c)].abs()));
            for i in 0..n {
                let res: f64 =
                    (0..n).map(|j| dense[(i, j)] * rows[j * m + c]).sum::<f64>() - rhs[(i, c)];
                assert!(
                    res.abs() < 1e-13 * scale,
                    "column {c}, row {i}: residual {res:e}"
                );
                let x = rows[i * m + c];
                assert!(
                    (x - y[(i, c)]).abs() < 1e-12 * (1.0 + y[(i, c)].abs()),
                    "x[{i}, {c}]"
                );
            }
        }
    }
}
