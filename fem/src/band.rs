//! Linear solvers for the Newton matrix of a floating-frame chain, through faer.
//!
//! [`BorderedBand`]: the pattern of the chain's Newton matrix is fixed by its DOF layout. The
//! n_I *interior* elastic DOFs come first and form a band of half-bandwidth b (elements only couple
//! neighbouring nodes); the n_B *border* DOFs (free joint angles and the tip-node DOFs of links
//! that carry a child) couple densely to whole links. That pattern is built once as a compressed
//! sparse column structure, with faer's symbolic LU (COLAMD ordering) of it; every Newton matrix
//! reuses both and only refactorizes numerically (sparse LU with partial pivoting), into storage
//! and a workspace allocated once: factorize/solve allocate nothing.
//!
//! [`DenseLu`]: dense LU with partial pivoting (faer `lu_in_place`) for the small dense systems
//! of the massless-direction balance of Timoshenko links without rotary inertia: its Newton
//! matrix at the start of a run ([`crate::chain::Chain::settle_massless`]) and the stiffness and
//! damping blocks of its projection ([`crate::events::massless`]).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::lu_in_place;
use faer::linalg::triangular_solve::{
    solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::lu::{LuRef, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, Mat, MatMut, Par};

use crate::error::FemError;

/// The chain's Newton matrix in its fixed bordered-band pattern, with its sparse LU.
pub struct BorderedBand {
    ni: usize,
    nb: usize,
    b: usize,
    /// Column pointers of the pattern (column j < n_I: rows of the band, then the border rows;
    /// border column: every row).
    col_ptr: Vec<usize>,
    pattern: SymbolicSparseColMat<usize>,
    /// Entries in pattern order.
    values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    scratch: StackReq,
    mem: MemBuffer,
    factored: bool,
    /// Dedicated band LU with a dense Schur complement of the border (instead of faer's
    /// sparse LU): for the augmented Newton matrix, whose running-sum rows make a general
    /// sparse ordering fill in.
    band_lu: Option<Box<BandLu>>,
}

impl Clone for BorderedBand {
    fn clone(&self) -> Self {
        BorderedBand {
            ni: self.ni,
            nb: self.nb,
            b: self.b,
            col_ptr: self.col_ptr.clone(),
            pattern: self.pattern.clone(),
            values: self.values.clone(),
            symbolic: self.symbolic.clone(),
            numeric: self.numeric.clone(),
            scratch: self.scratch,
            mem: MemBuffer::new(self.scratch),
            factored: self.factored,
            band_lu: self.band_lu.clone(),
        }
    }
}

impl std::fmt::Debug for BorderedBand {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BorderedBand")
            .field("interior", &self.ni)
            .field("border", &self.nb)
            .field("half_bandwidth", &self.b)
            .field("nnz", &self.values.len())
            .field("factored", &self.factored)
            .finish()
    }
}

impl BorderedBand {
    pub fn new(ni: usize, nb: usize, b: usize) -> Self {
        let n = ni + nb;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut rows = Vec::new();
        col_ptr.push(0);
        for j in 0..n {
            if j < ni {
                let (lo, hi) = (j.saturating_sub(b), (j + b).min(ni - 1));
                rows.extend(lo..=hi);
                rows.extend(ni..n);
            } else {
                rows.extend(0..n);
            }
            col_ptr.push(rows.len());
        }
        let nnz = rows.len();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr.clone(), None, rows);
        // The pattern is structurally nonsingular (full diagonal): the symbolic factorization
        // cannot fail.
        let symbolic = factorize_symbolic_lu(pattern.rb(), Default::default())
            .expect("symbolic LU of the bordered-band pattern");
        let scratch = symbolic
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        BorderedBand {
            ni,
            nb,
            b,
            col_ptr,
            pattern,
            values: vec![0.0; nnz],
            symbolic,
            numeric: NumericLu::new(),
            scratch,
            mem: MemBuffer::new(scratch),
            factored: false,
            band_lu: None,
        }
    }

    /// The same pattern, factorized by a band LU with partial pivoting (LAPACK `gbtrf`
    /// style, interior block) and a dense LU of the border's Schur complement:
    /// O(n_I b² + n_I b n_B + n_B³) per factorization, O(n_I (b + n_B)) per solve.
    pub fn with_band_solver(ni: usize, nb: usize, b: usize) -> Self {
        let mut m = Self::new(ni, nb, b);
        m.band_lu = Some(Box::new(BandLu::new(ni, nb, b)));
        m
    }

    pub fn n(&self) -> usize {
        self.ni + self.nb
    }

    pub fn half_bandwidth(&self) -> usize {
        self.b
    }

    pub fn clear(&mut self) {
        self.values.iter_mut().for_each(|x| *x = 0.0);
        self.factored = false;
    }

    /// Position of entry (i, j) in `values` (None outside the pattern).
    #[inline]
    fn position(&self, i: usize, j: usize) -> Option<usize> {
        let (ni, b) = (self.ni, self.b);
        let start = self.col_ptr[j];
        if j >= ni {
            return Some(start + i);
        }
        let lo = j.saturating_sub(b);
        let hi = (j + b).min(ni - 1);
        if i < ni {
            (lo..=hi).contains(&i).then(|| start + (i - lo))
        } else {
            Some(start + (hi - lo + 1) + (i - ni))
        }
    }

    /// Adds `v` to entry (i, j) of the global matrix. Interior pairs must lie within the band.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let p = self.position(i, j);
        debug_assert!(p.is_some(), "entry ({i},{j}) outside band {}", self.b);
        if let Some(p) = p {
            self.values[p] += v;
        }
    }

    /// Entry (i, j) before factorization.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.position(i, j).map_or(0.0, |p| self.values[p])
    }

    /// y = A x (before factorization). Each row sums its entries in increasing column order.
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        let n = self.n();
        let rows = self.pattern.row_idx();
        y[..n].iter_mut().for_each(|v| *v = 0.0);
        for j in 0..n {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[rows[p]] += self.values[p] * x[j];
            }
        }
    }

    /// Factorizes the assembled matrix (numeric only: the pattern and its symbolic LU are fixed
    /// at construction).
    pub fn factorize(&mut self) -> Result<(), FemError> {
        self.factored = false;
        if let Some(p) = self.values.iter().position(|v| !v.is_finite()) {
            let col = self.col_ptr.partition_point(|&c| c <= p) - 1;
            return Err(FemError::Singular {
                what: "Newton (non-finite entry)".into(),
                pivot: col,
                t: f64::NAN,
            });
        }
        if let Some(lu) = self.band_lu.as_mut() {
            lu.factorize(&self.col_ptr, &self.values)?;
            self.factored = true;
            return Ok(());
        }
        let a = SparseColMatRef::new(self.pattern.rb(), &self.values);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                a,
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .map_err(|e| FemError::Singular {
                what: "Newton (sparse LU)".into(),
                pivot: match e {
                    faer::sparse::linalg::LuError::SymbolicSingular { index } => index,
                    faer::sparse::linalg::LuError::Generic(_) => 0,
                },
                t: f64::NAN,
            })?;
        self.factored = true;
        Ok(())
    }

    /// Solves A x = r in place (after [`BorderedBand::factorize`]).
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        debug_assert!(self.factored);
        if let Some(lu) = self.band_lu.as_mut() {
            lu.solve_in_place(x);
            return;
        }
        let n = self.n();
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut x[..n], n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

/// Band LU with partial pivoting of the interior block A (half-bandwidth b; U gets 2b
/// superdiagonals from the row interchanges) and the border by its Schur complement:
/// [A B; C D] → W = A⁻¹B, S = D − C W (dense LU). Storage allocated once.
#[derive(Debug, Clone)]
struct BandLu {
    ni: usize,
    nb: usize,
    b: usize,
    /// Row i holds columns i − b ..= i + 2b at i·width + (j + b − i) (U and, below the
    /// diagonal, the elimination workspace).
    a: Vec<f64>,
    width: usize,
    /// Multipliers of L by column: L(k + 1 + m, k) at k·b + m (contiguous for the solves; the
    /// row interchanges of later columns never move them, as in LAPACK `gbtrf`).
    l: Vec<f64>,
    /// Last column of row k of U that the elimination can have made nonzero: k + b without
    /// row interchanges, up to k + 2b with them. The entries past it are exact zeros, which the
    /// factorization and the back substitution skip.
    reach: Vec<usize>,
    piv: Vec<usize>,
    /// B, then W = A⁻¹B, column-major (n_I × n_B).
    w: Vec<f64>,
    /// C, row-major (n_B × n_I).
    c: Vec<f64>,
    schur: DenseLu,
    col: Vec<f64>,
}

impl BandLu {
    fn new(ni: usize, nb: usize, b: usize) -> Self {
        let width = 3 * b + 1;
        BandLu {
            ni,
            nb,
            b,
            a: vec![0.0; ni * width],
            width,
            l: vec![0.0; ni * b],
            reach: vec![0; ni],
            piv: vec![0; ni],
            w: vec![0.0; ni * nb],
            c: vec![0.0; nb * ni],
            schur: DenseLu::new(nb),
            col: vec![0.0; nb.max(1)],
        }
    }

    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        i * self.width + (j + self.b - i)
    }

    /// Factorizes the matrix given in the bordered-band pattern order (`col_ptr`, `values`).
    fn factorize(&mut self, col_ptr: &[usize], values: &[f64]) -> Result<(), FemError> {
        let (ni, nb, b) = (self.ni, self.nb, self.b);
        let n = ni + nb;
        self.a.iter_mut().for_each(|v| *v = 0.0);
        // Scatter: interior columns (band rows, then border rows), border columns (all rows).
        for j in 0..n {
            let start = col_ptr[j];
            if j < ni {
                let lo = j.saturating_sub(b);
                let hi = (j + b).min(ni - 1);
                for (k, i) in (lo..=hi).enumerate() {
                    let p = self.at(i, j);
                    self.a[p] = values[start + k];
                }
                let off = start + (hi - lo + 1);
                for r in 0..nb {
                    self.c[r * ni + j] = values[off + r];
                }
            } else {
                let jb = j - ni;
                self.w[jb * ni..(jb + 1) * ni].copy_from_slice(&values[start..start + ni]);
                let d = &values[start + ni..start + n];
                self.schur.set_column(jb, d);
            }
        }
        // Band LU with row interchanges. Rows are contiguous in `a`: the interchange and the
        // update of row r by row k work on slices of columns k..=right, right the reach of the
        // pivot row (its entries further right are zero).
        for (i, r) in self.reach.iter_mut().enumerate() {
            *r = (i + b).min(ni - 1);
        }
        for k in 0..ni {
            let last = (k + b).min(ni - 1);
            let mut p = k;
            let mut big = self.a[self.at(k, k)].abs();
            for r in k + 1..=last {
                let v = self.a[self.at(r, k)].abs();
                if v > big {
                    big = v;
                    p = r;
                }
            }
            if big == 0.0 || !big.is_finite() {
                return Err(FemError::Singular {
                    what: "Newton (band LU)".into(),
                    pivot: k,
                    t: f64::NAN,
                });
            }
            self.piv[k] = p;
            if p != k {
                let len = self.reach[k].max(self.reach[p]) - k + 1;
                let (x, y) = (self.at(k, k), self.at(p, k));
                let (head, tail) = self.a.split_at_mut(y);
                head[x..x + len].swap_with_slice(&mut tail[..len]);
                self.reach.swap(k, p);
            }
            let right = self.reach[k];
            let len = right - k + 1;
            let d = self.a[self.at(k, k)];
            let pivot_row = self.at(k, k) + 1;
            for r in k + 1..=last {
                let pr = self.at(r, k);
                let l = self.a[pr] / d;
                self.a[pr] = l;
                self.l[k * b + (r - k - 1)] = l;
                if l != 0.0 {
                    let (head, tail) = self.a.split_at_mut(pr + 1);
                    let upper = &head[pivot_row..pivot_row + len - 1];
                    for (x, &y) in tail[..len - 1].iter_mut().zip(upper) {
                        *x -= l * y;
                    }
                    self.reach[r] = self.reach[r].max(right);
                }
            }
        }
        // W = A⁻¹B and S = D − C W.
        let mut w = std::mem::take(&mut self.w);
        self.band_solve_columns(&mut w);
        self.w = w;
        for jb in 0..nb {
            for r in 0..nb {
                let cw: f64 = (0..ni)
                    .map(|i| self.c[r * ni + i] * self.w[jb * ni + i])
                    .sum();
                self.col[r] = -cw;
            }
            self.schur.add_to_column(jb, &self.col[..nb]);
        }
        if nb > 0 {
            self.schur.factorize()?;
        }
        Ok(())
    }

    /// X ← A⁻¹X for the columns of length n_I in `x` (column-major), all in one sweep over
    /// the factors: each column sees the operations of [`BandLu::band_solve`] in its order
    /// (bit-identical), the multipliers and rows of U are read once for all columns.
    fn band_solve_columns(&self, x: &mut [f64]) {
        let (ni, b) = (self.ni, self.b);
        if ni == 0 {
            return;
        }
        for k in 0..ni {
            let p = self.piv[k];
            let cnt = (k + b).min(ni - 1) - k;
            let lk = &self.l[k * b..k * b + cnt];
            for col in x.chunks_exact_mut(ni) {
                if p != k {
                    col.swap(k, p);
                }
                let xk = col[k];
                if xk != 0.0 {
                    for (xr, &l) in col[k + 1..k + 1 + cnt].iter_mut().zip(lk) {
                        *xr -= l * xk;
                    }
                }
            }
        }
        for k in (0..ni).rev() {
            let cnt = self.reach[k] - k;
            let diag = self.at(k, k);
            let row = &self.a[diag + 1..diag + 1 + cnt];
            let d = self.a[diag];
            for col in x.chunks_exact_mut(ni) {
                let mut v = col[k];
                for (&u, &xj) in row.iter().zip(&col[k + 1..k + 1 + cnt]) {
                    v -= u * xj;
                }
                col[k] = v / d;
            }
        }
    }

    /// x ← A⁻¹x for the factorized interior block.
    fn band_solve(&self, x: &mut [f64]) {
        let (ni, b) = (self.ni, self.b);
        for k in 0..ni {
            let p = self.piv[k];
            if p != k {
                x.swap(k, p);
            }
            let xk = x[k];
            if xk != 0.0 {
                let cnt = (k + b).min(ni - 1) - k;
                let lk = &self.l[k * b..k * b + cnt];
                for (xr, &l) in x[k + 1..k + 1 + cnt].iter_mut().zip(lk) {
                    *xr -= l * xk;
                }
            }
        }
        for k in (0..ni).rev() {
            let cnt = self.reach[k] - k;
            let diag = self.at(k, k);
            let row = &self.a[diag + 1..diag + 1 + cnt];
            let mut v = x[k];
            for (&u, &xj) in row.iter().zip(&x[k + 1..k + 1 + cnt]) {
                v -= u * xj;
            }
            x[k] = v / self.a[diag];
        }
    }

    fn solve_in_place(&mut self, x: &mut [f64]) {
        let (ni, nb) = (self.ni, self.nb);
        self.band_solve(&mut x[..ni]);
        if nb == 0 {
            return;
        }
        for r in 0..nb {
            let cx: f64 = (0..ni).map(|i| self.c[r * ni + i] * x[i]).sum();
            x[ni + r] -= cx;
        }
        self.schur.solve_in_place(&mut x[ni..ni + nb]);
        for jb in 0..nb {
            let y = x[ni + jb];
            if y != 0.0 {
                for i in 0..ni {
                    x[i] -= self.w[jb * ni + i] * y;
                }
            }
        }
    }
}

/// Dense LU with partial pivoting (faer), factorized in place.
#[derive(Debug, Clone)]
pub struct DenseLu {
    n: usize,
    a: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// Row interchanges equivalent to the pivoting permutation: applying
    /// swap(k, `swaps[k]`) for k = 0, 1, … moves row `perm[k]` of the right-hand side to k.
    swaps: Vec<usize>,
    row_at: Vec<usize>,
    /// Workspace of `lu_in_place` (allocated once).
    scratch: Vec<std::mem::MaybeUninit<u8>>,
}

impl DenseLu {
    pub fn new(n: usize) -> Self {
        DenseLu {
            n,
            a: Mat::zeros(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            swaps: vec![0; n],
            row_at: vec![0; n],
            scratch: {
                let req = faer::linalg::lu::partial_pivoting::factor::lu_in_place_scratch::<
                    usize,
                    f64,
                >(n, n, Par::Seq, Default::default());
                vec![std::mem::MaybeUninit::new(0); req.size_bytes() + req.align_bytes()]
            },
        }
    }

    /// Column j of the matrix (before factorization).
    pub fn set_column(&mut self, j: usize, col: &[f64]) {
        for i in 0..self.n {
            self.a[(i, j)] = col[i];
        }
    }

    /// Adds `col` to column j of the matrix (before factorization).
    pub fn add_to_column(&mut self, j: usize, col: &[f64]) {
        for i in 0..self.n {
            self.a[(i, j)] += col[i];
        }
    }

    pub fn factorize(&mut self) -> Result<(), FemError> {
        let n = self.n;
        for j in 0..n {
            for i in 0..n {
                if !self.a[(i, j)].is_finite() {
                    return Err(FemError::Singular {
                        what: "Newton (dense, non-finite entry)".into(),
                        pivot: j,
                        t: f64::NAN,
                    });
                }
            }
        }
        let stack = MemStack::new(&mut self.scratch);
        lu_in_place(
            self.a.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
        for k in 0..n {
            let d = self.a[(k, k)];
            if d == 0.0 || !d.is_finite() {
                return Err(FemError::Singular {
                    what: "Newton (dense)".into(),
                    pivot: k,
                    t: f64::NAN,
                });
            }
        }
        // Permutation → interchanges: `where_row[r]` is the current position of original row r,
        // `row_at[i]` the original row at position i (perm_inv is reused for the former).
        let (where_row, row_at) = (&mut self.perm_inv, &mut self.row_at);
        for r in 0..n {
            where_row[r] = r;
            row_at[r] = r;
        }
        for k in 0..n {
            let r = self.perm[k];
            let p = where_row[r];
            self.swaps[k] = p;
            let displaced = row_at[k];
            row_at[k] = r;
            row_at[p] = displaced;
            where_row[r] = k;
            where_row[displaced] = p;
        }
        Ok(())
    }

    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = self.n;
        for k in 0..n {
            x.swap(k, self.swaps[k]);
        }
        let mut rhs = MatMut::from_column_major_slice_mut(&mut x[..n], n, 1);
        solve_unit_lower_triangular_in_place(self.a.as_ref(), rhs.rb_mut(), Par::Seq);
        solve_upper_triangular_in_place(self.a.as_ref(), rhs, Par::Seq);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sys_dense_lu_solves_a_system_that_needs_pivoting() {
        // Zero leading diagonal entries: only a pivoted LU gets through.
        let n = 7;
        let a = |i: usize, j: usize| {
            if i == j {
                if i.is_multiple_of(3) { 0.0 } else { 4.0 }
            } else {
                ((i * 7 + j * 3) as f64 * 0.61).sin()
            }
        };
        let mut lu = DenseLu::new(n);
        for j in 0..n {
            let col: Vec<f64> = (0..n).map(|i| a(i, j)).collect();
            lu.set_column(j, &col);
        }
        lu.factorize().unwrap();
        let x_true: Vec<f64> = (0..n).map(|i| 1.0 + 0.3 * i as f64).collect();
        let mut r: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a(i, j) * x_true[j]).sum())
            .collect();
        lu.solve_in_place(&mut r);
        for i in 0..n {
            assert!(
                (r[i] - x_true[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                r[i],
                x_true[i]
            );
        }
    }

    #[test]
    fn sys_bordered_band_solves_like_dense() {
        // Random-ish diagonally dominant nonsymmetric bordered band matrix.
        for band_solver in [false, true] {
            bordered_band_case(band_solver, false);
        }
        // Zero interior diagonal entries: the band solver must pivot within the band.
        bordered_band_case(true, true);
    }

    fn bordered_band_case(band_solver: bool, zero_diagonal: bool) {
        let (ni, nb, b) = (12, 3, 2);
        let n = ni + nb;
        let mut a = if band_solver {
            BorderedBand::with_band_solver(ni, nb, b)
        } else {
            BorderedBand::new(ni, nb, b)
        };
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
                    let diagonal = if zero_diagonal && i < ni && i % 3 == 0 {
                        -rnd()
                    } else {
                        6.0
                    };
                    let v = rnd() + if i == j { diagonal } else { 0.0 };
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
            // Well-conditioned: round-off only.
            assert!((r[i] - x_true[i]).abs() < 1e-12, "{i}");
        }
    }
}
