//! LDLᵀ of a symmetric band matrix without pivoting, for matrices whose LDLᵀ exists in any
//! order: positive definite ones and the quasi-definite saddle systems [[P, Gᵀ], [G, −N⁻¹]]
//! with P and N⁻¹ positive definite (Vanderbei: the pivots of the first block stay positive,
//! those of the second negative). O(n·k²) with half-bandwidth k, no allocation after
//! construction.
//!
//! **Envelope.** Row i may start later than i − k (its first column `first[i]`): L has no fill
//! left of a row's first nonzero, and rows that start at or after a row r (every one) split the
//! matrix into independent diagonal blocks, solved one at a time. The terms left of a row's
//! first column are products with zeros, so skipping them or not gives the full band's sums
//! in the same order: near the ends (the matrix's for the factor, a block's for the solves)
//! they are skipped, elsewhere the full band runs in straight-line code (a constant
//! half-bandwidth, no per-row bookkeeping), and the factor lets two blocks take turns, so
//! that the division that ends each column overlaps the other block's.
//!
//! **Out of place.** Each assembled entry is read once, by the column that turns it into L's
//! (or D's), so the factor may read them from another matrix with the same envelope
//! ([`BandLdl::factor_from`]): a matrix assembled anew for every factor then needs no copy.

// Index loops over the band read like the factorization.
#![allow(clippy::needless_range_loop)]

use std::ops::Range;

/// Largest half-bandwidth [`BandLdl`] factors (its row scratch lives on the stack).
pub const MAX_HALF_BANDWIDTH: usize = 16;

/// A = L D Lᵀ with L unit lower triangular of half-bandwidth `k` inside an envelope, stored by
/// rows (and L's columns again for the back substitution).
#[derive(Debug, Clone, Default)]
pub struct BandLdl {
    n: usize,
    k: usize,
    /// first column of row i (≥ i − k): A and L are zero left of it
    first: Vec<usize>,
    /// last row whose envelope reaches column j
    last: Vec<usize>,
    /// whether no row at or after i reaches left of i (a block starts at i)
    block_start: Vec<bool>,
    /// the independent diagonal blocks in order
    blocks: Vec<Range<usize>>,
    /// row i holds A[i, i−k..=i] before and L[i, i−k..i] (and D at the diagonal) after factor
    a: Vec<f64>,
    /// after factor: column j of L below the diagonal, L[j+1..=j+k, j] (zero outside the
    /// envelope)
    lc: Vec<f64>,
}

impl BandLdl {
    /// Storage for an n × n matrix of half-bandwidth k, all zero.
    pub fn new(n: usize, k: usize) -> Self {
        Self::with_envelope((0..n).map(|i| i.saturating_sub(k)).collect())
    }

    /// Storage for the matrix whose row i has its entries in columns `first[i]..=i` (and
    /// their symmetric ones), all zero; the half-bandwidth is the widest row's.
    pub fn with_envelope(first: Vec<usize>) -> Self {
        let n = first.len();
        assert!(
            first.iter().enumerate().all(|(i, &f)| f <= i),
            "a row starts right of its diagonal"
        );
        let k = first
            .iter()
            .enumerate()
            .map(|(i, &f)| i - f)
            .max()
            .unwrap_or(0);
        let mut last: Vec<usize> = (0..n).collect();
        for (i, &f) in first.iter().enumerate() {
            for j in f..i {
                last[j] = last[j].max(i);
            }
        }
        let mut block_start = vec![true; n + 1];
        let mut reach = n;
        for i in (0..n).rev() {
            reach = reach.min(first[i]);
            block_start[i] = reach >= i;
        }
        let starts: Vec<usize> = (0..=n).filter(|&i| block_start[i]).collect();
        let blocks = starts.windows(2).map(|w| w[0]..w[1]).collect();
        BandLdl {
            n,
            k,
            first,
            last,
            block_start,
            blocks,
            a: vec![0.0; n * (k + 1)],
            lc: vec![0.0; n * k],
        }
    }

    fn at(&self, i: usize, j: usize) -> usize {
        assert!(
            j <= i && j >= self.first[i],
            "({i}, {j}) outside the envelope"
        );
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
            (self.first[i]..=i).flat_map(move |j| {
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

    /// A[i, j] += v inside the envelope (the symmetric entry is implied).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        let p = self.at(i, j);
        self.a[p] += v;
    }

    /// Where A[i, j] (inside the envelope; or its symmetric entry) is stored, for
    /// [`Self::set_at`].
    pub fn position(&self, i: usize, j: usize) -> usize {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        self.at(i, j)
    }

    /// The entry stored at `p` ([`Self::position`]) = v.
    pub fn set_at(&mut self, p: usize, v: f64) {
        self.a[p] = v;
    }

    /// Factors in place. Err(j): pivot j is zero or not finite (the first such of its block).
    ///
    /// Every entry outside the envelope is a zero (so is its L: a zero over a finite pivot),
    /// and subtracting a product with one from a sum that is nonzero or +0 changes nothing.
    /// The sums are never −0: each starts from an assembled entry (a sum onto +0) and only
    /// subtracts. So the columns away from the matrix's ends run over the full band,
    /// straight-line code for the common half-bandwidths, with the envelope's bits.
    pub fn factor(&mut self) -> Result<(), usize> {
        self.factor_with(InPlace)
    }

    /// [`Self::factor`] of `assembled`, a matrix with the same envelope (as assembled), into
    /// this one: the same operations on the same entries, so the same bits, and `assembled`
    /// is left as it is. This matrix's own entries are not read.
    pub fn factor_from(&mut self, assembled: &BandLdl) -> Result<(), usize> {
        assert!(
            self.n == assembled.n && self.k == assembled.k && self.first == assembled.first,
            "another envelope"
        );
        self.factor_with(Other(&assembled.a))
    }

    fn factor_with<S: Assembled>(&mut self, src: S) -> Result<(), usize> {
        assert!(
            self.k <= MAX_HALF_BANDWIDTH,
            "half-bandwidth {} above {MAX_HALF_BANDWIDTH}",
            self.k
        );
        match self.k {
            1 => self.factor_band::<1, S>(src),
            2 => self.factor_band::<2, S>(src),
            3 => self.factor_band::<3, S>(src),
            4 => self.factor_band::<4, S>(src),
            5 => self.factor_band::<5, S>(src),
            6 => self.factor_band::<6, S>(src),
            _ => (0..self.n).try_for_each(|j| self.factor_column(j, src)),
        }
    }

    /// [`Self::factor`] with half-bandwidth `K`: the columns K from the matrix's ends over the
    /// full band, two blocks in turn (their pivot chains are independent, and each column
    /// waits for the division that ends the previous one).
    fn factor_band<const K: usize, S: Assembled>(&mut self, src: S) -> Result<(), usize> {
        for pair in (0..self.blocks.len()).step_by(2) {
            let p = self.blocks[pair].clone();
            let q = self.blocks.get(pair + 1).cloned().unwrap_or(0..0);
            // the columns that reach the matrix's ends, and the others: those of a block's
            // ends reach into its neighbours only through zeros (outside the envelope), and
            // a neighbour's entries there are finite whatever its progress
            let n = self.n;
            let inner = |b: &Range<usize>| {
                let (lo, hi) = (b.start.max(K), b.end.min(n.saturating_sub(K)));
                if lo < hi { lo..hi } else { b.end..b.end }
            };
            let (ip, iq) = (inner(&p), inner(&q));
            for j in p.start..ip.start.min(p.end) {
                self.factor_column(j, src)?;
            }
            for j in q.start..iq.start.min(q.end) {
                self.factor_column(j, src)?;
            }
            let w = K + 1;
            let (a, lc) = (&mut self.a[..], &mut self.lc[..]);
            // the pivot chain's last link, L[j, j−1] and D[j−1], stays in registers from the
            // previous column
            let chain = |j: usize, a: &[f64]| (a[j * w + K - 1], a[(j - 1) * w + K]);
            let mut cp = if ip.is_empty() {
                (0.0, 0.0)
            } else {
                chain(ip.start, a)
            };
            let mut cq = if iq.is_empty() {
                (0.0, 0.0)
            } else {
                chain(iq.start, a)
            };
            for t in 0..ip.len().max(iq.len()) {
                if t < ip.len() {
                    band_column::<K, S>(a, lc, src, ip.start + t, &mut cp)?;
                }
                if t < iq.len() {
                    band_column::<K, S>(a, lc, src, iq.start + t, &mut cq)?;
                }
            }
            for j in ip.end.max(p.start)..p.end {
                self.factor_column(j, src)?;
            }
            for j in iq.end.max(q.start)..q.end {
                self.factor_column(j, src)?;
            }
        }
        Ok(())
    }

    /// Column j of [`Self::factor`] inside the envelope.
    fn factor_column<S: Assembled>(&mut self, j: usize, src: S) -> Result<(), usize> {
        let (k, w) = (self.k, self.k + 1);
        let mut ld = [0.0; MAX_HALF_BANDWIDTH];
        let a = &mut self.a;
        let fj = self.first[j];
        let row_j = j * w + w - 1 - (j - fj);
        let mut d = src.entry(a, j * w + w - 1);
        for (t, m) in (fj..j).enumerate() {
            let l = a[row_j + t];
            ld[t] = l * a[m * w + w - 1];
            d -= l * ld[t];
        }
        if d == 0.0 || !d.is_finite() {
            return Err(j);
        }
        a[j * w + w - 1] = d;
        let col = &mut self.lc[j * k..j * k + k];
        for i in j + 1..=self.last[j] {
            let fi = self.first[i];
            if fi > j {
                col[i - j - 1] = 0.0;
                continue;
            }
            // row i's entries at columns fi..j against row j's L·D
            let row_i = i * w + w - 1 - (i - fi);
            let lo = fi.max(fj);
            let li = &a[row_i + (lo - fi)..row_i + (j - fi)];
            let mut s = src.entry(a, row_i + (j - fi));
            for (l, x) in li.iter().zip(&ld[lo - fj..j - fj]) {
                s -= l * x;
            }
            let l = s / d;
            a[row_i + (j - fi)] = l;
            col[i - j - 1] = l;
        }
        Ok(())
    }

    /// X ← A⁻¹X for `m` right-hand sides stored by rows (X[i·m + c]): one sweep for all, L
    /// by rows, then D and Lᵀ together, each row of the solution gathered from L's column.
    pub fn solve_rows_in_place(&self, x: &mut [f64], m: usize) {
        self.solve_block_rows_in_place(0..self.n, x, m);
    }

    /// As [`Self::solve_rows_in_place`] on the diagonal block `rows` alone (`x` holds its
    /// rows): the block must not couple to the rest ([`Self::is_block`]).
    pub fn solve_block_rows_in_place(&self, rows: Range<usize>, x: &mut [f64], m: usize) {
        assert!(
            self.is_block(rows.clone()),
            "{rows:?} couples to other rows"
        );
        let x = &mut x[..rows.len() * m];
        match m {
            1 => self.solve_block::<1>(rows, x.as_chunks_mut().0),
            2 => self.solve_block::<2>(rows, x.as_chunks_mut().0),
            3 => self.solve_block::<3>(rows, x.as_chunks_mut().0),
            4 => self.solve_block::<4>(rows, x.as_chunks_mut().0),
            5 => self.solve_block::<5>(rows, x.as_chunks_mut().0),
            6 => self.solve_block::<6>(rows, x.as_chunks_mut().0),
            7 => self.solve_block::<7>(rows, x.as_chunks_mut().0),
            8 => self.solve_block::<8>(rows, x.as_chunks_mut().0),
            _ => self.solve_block_any(rows, x, m),
        }
    }

    /// Whether the rows `rows` form a diagonal block that no other row reaches.
    pub fn is_block(&self, rows: Range<usize>) -> bool {
        rows.start <= rows.end
            && rows.end <= self.n
            && self.block_start[rows.start]
            && self.block_start[rows.end]
    }

    /// The solve of one block with `M` right-hand sides per row, each row's in registers. With
    /// several right-hand sides the rows K from the block's ends run over the full band
    /// (zeros included) in straight-line code, which saves more than its padded terms cost; a
    /// single one pays more for them than it saves (81-station saddle: 7 and 6 right-hand
    /// sides 3.9 → 3.3 µs, one 2.6 → 5.3 µs).
    fn solve_block<const M: usize>(&self, rows: Range<usize>, x: &mut [[f64; M]]) {
        const K: usize = 4;
        let (r0, len) = (rows.start, rows.len());
        // the rows that start (forward) or end (back) within K of the block's ends
        let edge = if self.k == K && M > 1 && len > 2 * K {
            K
        } else {
            len
        };
        for t in 0..edge {
            self.forward_row(r0 + t, r0, x);
        }
        for t in edge..len {
            self.forward_band_row::<K, M>(r0, t, x);
        }
        for t in (len - edge..len).rev() {
            self.backward_row(r0 + t, r0, x);
        }
        for t in (0..len - edge).rev() {
            self.backward_band_row::<K, M>(r0, t, x);
        }
    }

    /// Row i of the forward substitution with L (`x` holds the block's rows from `r0`).
    #[inline(always)]
    fn forward_row<const M: usize>(&self, i: usize, r0: usize, x: &mut [[f64; M]]) {
        let w = self.k + 1;
        let fi = self.first[i];
        let li = &self.a[i * w + w - 1 - (i - fi)..i * w + w - 1];
        let (done, rest) = x.split_at_mut(i - r0);
        let mut xi = rest[0];
        for (l, xj) in li.iter().zip(&done[fi - r0..]) {
            for c in 0..M {
                xi[c] -= l * xj[c];
            }
        }
        rest[0] = xi;
    }

    /// Row j of D⁻¹ and the back substitution with Lᵀ, gathered from L's column j.
    #[inline(always)]
    fn backward_row<const M: usize>(&self, j: usize, r0: usize, x: &mut [[f64; M]]) {
        let (w, k) = (self.k + 1, self.k);
        let d = self.a[j * w + w - 1];
        let below = self.last[j] - j;
        let lj = &self.lc[j * k..j * k + below];
        let (head, tail) = x.split_at_mut(j - r0 + 1);
        let mut xj = head[j - r0];
        for c in 0..M {
            xj[c] /= d;
        }
        for (l, xi) in lj.iter().zip(&tail[..below]).rev() {
            for c in 0..M {
                xj[c] -= l * xi[c];
            }
        }
        head[j - r0] = xj;
    }

    /// Row r0 + t (t ≥ K) of the forward substitution over the full band.
    #[inline(always)]
    fn forward_band_row<const K: usize, const M: usize>(
        &self,
        r0: usize,
        t: usize,
        x: &mut [[f64; M]],
    ) {
        let w = K + 1;
        let i = r0 + t;
        let row: &[f64; K] = self.a[i * w..i * w + K].try_into().unwrap();
        let (done, rest) = x.split_at_mut(t);
        let prev: &[[f64; M]; K] = done[t - K..].try_into().unwrap();
        let mut xi = rest[0];
        for u in 0..K {
            for c in 0..M {
                xi[c] -= row[u] * prev[u][c];
            }
        }
        rest[0] = xi;
    }

    /// Row r0 + t (more than K rows from the block's end) of D⁻¹ and the back substitution
    /// over the full band.
    #[inline(always)]
    fn backward_band_row<const K: usize, const M: usize>(
        &self,
        r0: usize,
        t: usize,
        x: &mut [[f64; M]],
    ) {
        let j = r0 + t;
        let d = self.a[j * (K + 1) + K];
        let col: &[f64; K] = self.lc[j * K..j * K + K].try_into().unwrap();
        let (head, tail) = x.split_at_mut(t + 1);
        let next: &[[f64; M]; K] = tail[..K].try_into().unwrap();
        let mut xj = head[t];
        for c in 0..M {
            xj[c] /= d;
        }
        for u in (0..K).rev() {
            for c in 0..M {
                xj[c] -= col[u] * next[u][c];
            }
        }
        head[t] = xj;
    }

    /// [`Self::solve_block`] for any number of right-hand sides.
    fn solve_block_any(&self, rows: Range<usize>, x: &mut [f64], m: usize) {
        let (w, k, r0) = (self.k + 1, self.k, rows.start);
        for i in rows.clone() {
            let fi = self.first[i];
            let li = &self.a[i * w + w - 1 - (i - fi)..i * w + w - 1];
            let (done, rest) = x.split_at_mut((i - r0) * m);
            let xi = &mut rest[..m];
            for (t, l) in li.iter().enumerate() {
                let j = fi - r0 + t;
                for (v, u) in xi.iter_mut().zip(&done[j * m..j * m + m]) {
                    *v -= l * u;
                }
            }
        }
        for j in rows.rev() {
            let d = self.a[j * w + w - 1];
            let below = self.last[j] - j;
            let lj = &self.lc[j * k..j * k + below];
            let (head, tail) = x.split_at_mut((j - r0 + 1) * m);
            let xj = &mut head[(j - r0) * m..];
            xj.iter_mut().for_each(|v| *v /= d);
            for (t, l) in lj.iter().enumerate().rev() {
                for (v, u) in xj.iter_mut().zip(&tail[t * m..t * m + m]) {
                    *v -= l * u;
                }
            }
        }
    }
}

/// Where [`BandLdl::factor`] reads the assembled entries: the matrix being factored or another
/// with its envelope (the storage positions are the same).
trait Assembled: Copy {
    /// The assembled entry at storage position `p` (`a` the matrix being factored).
    fn entry(self, a: &[f64], p: usize) -> f64;
}

/// The matrix being factored holds them.
#[derive(Clone, Copy)]
struct InPlace;

impl Assembled for InPlace {
    #[inline(always)]
    fn entry(self, a: &[f64], p: usize) -> f64 {
        a[p]
    }
}

/// Another matrix's storage holds them.
#[derive(Clone, Copy)]
struct Other<'a>(&'a [f64]);

impl Assembled for Other<'_> {
    #[inline(always)]
    fn entry(self, _: &[f64], p: usize) -> f64 {
        self.0[p]
    }
}

/// Column j of [`BandLdl::factor`] over the full band of half-bandwidth `K` (rows `a` of
/// K + 1 entries, L's columns `lc` of K); `chain` carries L(j, j−1) and D(j−1) in and
/// L(j+1, j) and D(j) out.
#[inline(always)]
fn band_column<const K: usize, S: Assembled>(
    a: &mut [f64],
    lc: &mut [f64],
    src: S,
    j: usize,
    chain: &mut (f64, f64),
) -> Result<(), usize> {
    let w = K + 1;
    let mut d = src.entry(a, j * w + K);
    let below_at = |r: usize| src.entry(a, (j + r) * w + K - r);
    let assembled: [f64; K] = std::array::from_fn(|r| below_at(r + 1));
    let (left, right) = a.split_at_mut(j * w);
    let (row_j, below) = right.split_at_mut(w);
    let mut ld = [0.0; K];
    for t in 0..K {
        let (l, dm) = if t == K - 1 {
            *chain
        } else {
            (row_j[t], left[(j - K + t) * w + K])
        };
        ld[t] = l * dm;
        d -= l * ld[t];
    }
    if d == 0.0 || !d.is_finite() {
        return Err(j);
    }
    row_j[K] = d;
    chain.1 = d;
    let col = &mut lc[j * K..j * K + K];
    for r in 1..=K {
        let row_i = &mut below[(r - 1) * w..r * w];
        let mut s = assembled[r - 1];
        for t in r..K {
            s -= row_i[t - r] * ld[t];
        }
        let l = s / d;
        row_i[K - r] = l;
        col[r - 1] = l;
        if r == 1 {
            chain.0 = l;
        }
    }
    Ok(())
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

    #[test]
    fn elem_band_ldl_envelope_gives_the_full_bands_bits_block_by_block() {
        // two uncoupled saddle blocks interleaved as the implicit kick's (rows of the first
        // block start up to 4 left, the multipliers' 3), stored in their envelope, in the full
        // band of half-bandwidth 5 and in one of 7 (no straight-line kernel: column by column
        // inside the envelope): the three factors and solves differ by products with zeros
        // only, so every bit agrees, and each block solves alone
        let blocks = [0..19, 19..38];
        let n = 38;
        let mut first = vec![0; n];
        let mut entries = Vec::new();
        for b in &blocks {
            let (r0, len) = (b.start, b.len());
            for i in 0..len {
                let at = r0 + i;
                let reach = if i % 2 == 0 { 4 } else { 3 };
                first[at] = r0 + i.saturating_sub(reach);
                for j in first[at]..at {
                    let v = ((at * 7 + j * 3) as f64 * 0.31).sin() * 0.2;
                    entries.push((at, j, v));
                }
                let d = if i % 2 == 0 { 4.0 } else { -3.0 };
                entries.push((at, at, d + 0.1 * (i as f64).cos()));
            }
        }
        let mut envelope = BandLdl::with_envelope(first);
        let mut full = BandLdl::new(n, 5);
        // wider than the straight-line kernels: column by column inside the envelope
        let mut wide = BandLdl::new(n, 7);
        for &(i, j, v) in &entries {
            envelope.add(i, j, v);
            full.add(j, i, v);
            wide.add(i, j, v);
        }
        assert!(envelope.is_block(blocks[0].clone()) && envelope.is_block(blocks[1].clone()));
        assert!(!envelope.is_block(0..20));
        // out of place: the same bits, the assembled matrix untouched
        let assembled = envelope.clone();
        let kept = assembled.a.clone();
        let mut from = BandLdl::with_envelope(envelope.first.clone());
        from.factor_from(&assembled).unwrap();
        envelope.factor().unwrap();
        full.factor().unwrap();
        wide.factor().unwrap();
        assert_eq!(
            from.a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            envelope.a.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(
            from.lc.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            envelope.lc.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(assembled.a, kept);
        for m in [1usize, 3, 7, 8, 11] {
            let rhs: Vec<f64> = (0..n * m).map(|k| (0.37 * k as f64).cos() + 0.1).collect();
            let mut x_full = rhs.clone();
            full.solve_rows_in_place(&mut x_full, m);
            let mut x_wide = rhs.clone();
            wide.solve_rows_in_place(&mut x_wide, m);
            let mut x_env = rhs.clone();
            envelope.solve_rows_in_place(&mut x_env, m);
            let mut x_blocks = rhs.clone();
            for b in &blocks {
                envelope.solve_block_rows_in_place(
                    b.clone(),
                    &mut x_blocks[b.start * m..b.end * m],
                    m,
                );
            }
            for k in 0..n * m {
                assert_eq!(x_env[k].to_bits(), x_full[k].to_bits(), "m {m}, entry {k}");
                assert_eq!(x_wide[k].to_bits(), x_full[k].to_bits(), "m {m}, entry {k}");
                assert_eq!(
                    x_blocks[k].to_bits(),
                    x_full[k].to_bits(),
                    "m {m}, entry {k}"
                );
            }
        }
    }
}
