//! Exponential Runge–Kutta on the chain's linearized oscillators: a fixed-step method whose
//! error does not depend on the stiffness of the elastic modes.
//!
//! **Splitting.** The state is y = (q, q̇, works) with q̈ = a(q, q̇, t) (the right-hand side's
//! free coordinates). At the start of each step the right-hand side gives the mass and
//! stiffness matrices M_n, K_n of its linear oscillators ([`OdeRhs::second_order_linearization`];
//! the chain's are those of the undeformed arm at the step's joint angles) and the step writes
//!
//! ```text
//! y' = A_n y + N_n(y, t),   A_n = [[0, I], [−M_n⁻¹K_n, 0]],   N_n = f − A_n y = (0, a + M_n⁻¹K_n q, powers)
//! ```
//!
//! A_n is solved exactly in the M_n-orthonormal eigenvectors X of K_n X = M_n X Λ
//! (Xᵀ M_n X = I, z = XᵀM_n q, w = XᵀM_n q̇): each mode is the 2×2 block
//! J = [[0, 1], [−λ, 0]], and every function the method needs is f(τJ) = a·I + b·J with
//! a, b from the scalar f at the eigenvalues ±τ√−λ (cosines and sines for λ > 0, hyperbolic
//! functions for λ < 0, the power series where |λ|τ² ≤ 1). In those coordinates the
//! remainder is η = XᵀM_n a + Λ z and has no position part. A linearization within
//! [`REFRESH_TOLERANCE`] of the last diagonalized one, at the same step, keeps its
//! eigenvectors and φ functions (one link on its hub: the undeformed arm's M and K do not
//! depend on the joint angle; two links: they follow the elbow angle slowly).
//!
//! **Method.** Cox & Matthews' ETDRK4 (J. Comput. Phys. 176, 2002): stages at t + h/2 (twice)
//! and t + h,
//!
//! ```text
//! u_a = e^{hA/2} u₀ + (h/2) φ₁(hA/2) N₀
//! u_b = e^{hA/2} u₀ + (h/2) φ₁(hA/2) N_a
//! u_c = e^{hA/2} u_a + (h/2) φ₁(hA/2) (2N_b − N₀)
//! u₁  = e^{hA} u₀ + h [(φ₁ − 3φ₂ + 4φ₃) N₀ + 2(φ₂ − 2φ₃)(N_a + N_b) + (4φ₃ − φ₂) N_c]
//! ```
//!
//! with φ_k(Z) = Σ_j Z^j/(j + k)!. Fourth order for non-stiff problems, exact for a linear
//! system with constant M and K at any step: a mode the step does not resolve keeps its
//! frequency and amplitude (no numerical dispersion, no damping), which is what an undamped
//! arm needs — its every mode rings for the whole run and its phase reaches the joint angles
//! through the foreshortening coupling (docs/backends.md).
//!
//! **Dense output.** y(t + θh) = e^{θhA} u₀ + θh φ₁(θhA) N₀ + θ²h φ₂(θhA) D, with D fixed by
//! y(t + h) = u₁ (φ₂ of a 2×2 block is invertible): exact for the linear part, second order in
//! the remainder, continuous at both ends of the step.
//!
//! Cost per step: four right-hand sides, one linearization and one symmetric generalized
//! eigenproblem of the free coordinates.

use faer::Mat;

use crate::pencil::Pencil;

use super::{
    Build, IntegrateError, MethodInfo, OdeRhs, StepStats, Stepper, StopReason, stop_reason,
};

/// Registry entry ([`super::method_for`]).
pub const EXPONENTIAL: MethodInfo = MethodInfo {
    method: data::ModalMethod::Exponential,
    name: "exponential",
    build: Build::Fixed(|dim, _tol, h| Box::new(Exponential::new(dim, h))),
    needs_oscillators: true,
};

/// ω_max·h of the default step ([`resolving_step`]).
pub const TOP_FREQUENCY_STEP: f64 = 2.0;

/// The default step: [`TOP_FREQUENCY_STEP`]/ω_max, ω_max the highest frequency of the
/// linearization at (t, y). The linear part is exact at any step, but the remainder couples
/// the modes (foreshortening, centrifugal and gyroscopic terms) and the stages resolve that
/// coupling only at steps of a few 1/ω_max. On `two-link-free-undamped` (6 `poly` modes,
/// ω_max = 1.58e4 rad/s, 10 s) the 20 Hz low-passed hub angle's successive differences are
/// 2.4e-2, 9.3e-4, 1.5e-4, 4.9e-6 and 3.8e-7 rad from h = 1e-3 to 3.125e-5 (ω_max·h = 16 … 0.5,
/// halving): fourth order is reached from ω_max·h ≈ 2 on (docs/backends.md).
pub fn resolving_step(f: &mut dyn OdeRhs, t: f64, y: &[f64]) -> Result<f64, IntegrateError> {
    let (mut m_rows, mut k_rows) = (Vec::new(), Vec::new());
    let nf = f
        .second_order_linearization(t, y, &mut m_rows, &mut k_rows)
        .ok_or(IntegrateError::NoLinearization { t })?;
    let (mut m, mut k) = (Mat::zeros(nf, nf), Mat::zeros(nf, nf));
    symmetrize(&m_rows, &mut m);
    symmetrize(&k_rows, &mut k);
    let mut pencil = Pencil::new(nf);
    pencil
        .solve(k.as_ref(), m.as_ref())
        .map_err(|_| IntegrateError::NoLinearization { t })?;
    let top = pencil.eigenvalues().iter().fold(0.0f64, |a, &l| a.max(l.abs()));
    Ok(TOP_FREQUENCY_STEP / top.sqrt().max(f64::MIN_POSITIVE))
}

/// out = ½(A + Aᵀ) of the row-major square `rows` (the pencil reads one triangle).
fn symmetrize(rows: &[f64], out: &mut Mat<f64>) {
    let n = out.nrows();
    for i in 0..n {
        for j in 0..n {
            out[(i, j)] = 0.5 * (rows[i * n + j] + rows[j * n + i]);
        }
    }
}

/// f(τJ) = a·I + b·J of one mode's block J = [[0, 1], [−λ, 0]].
#[derive(Debug, Clone, Copy, Default)]
struct Block {
    a: f64,
    b: f64,
}

impl Block {
    /// (z, w) ← f(τJ)·(z, w).
    fn apply(self, lambda: f64, z: f64, w: f64) -> (f64, f64) {
        (self.a * z + self.b * w, self.a * w - lambda * self.b * z)
    }
    /// f(τJ)·(0, η): the remainder has no position part.
    fn apply_velocity(self, eta: f64) -> (f64, f64) {
        (self.b * eta, self.a * eta)
    }
}

/// φ₀ … φ₃ of τJ for the eigenvalue λ (φ₀ = exp).
fn phi_blocks(lambda: f64, tau: f64) -> [Block; 4] {
    let mu = -lambda * tau * tau;
    let mut out = [Block::default(); 4];
    if mu.abs() <= 1.0 {
        // a_k = Σ μ^m/(2m + k)!, b_k = τ Σ μ^m/(2m + 1 + k)! (Horner; the last term kept,
        // 1/24!, is below 1e-23).
        for (k, blk) in out.iter_mut().enumerate() {
            let (mut a, mut b) = (0.0, 0.0);
            for m in (0..SERIES_TERMS).rev() {
                a = a * mu + INV_FACTORIAL[2 * m + k];
                b = b * mu + INV_FACTORIAL[2 * m + 1 + k];
            }
            *blk = Block { a, b: tau * b };
        }
        return out;
    }
    if lambda > 0.0 {
        // φ_k(ix) by φ_k = (φ_{k−1} − 1/(k−1)!)/(ix); a = Re, b = τ Im / x.
        let x = lambda.sqrt() * tau;
        let (mut re, mut im) = (x.cos(), x.sin());
        out[0] = Block {
            a: re,
            b: tau * im / x,
        };
        for k in 1..4 {
            // (re − c + i im)/(i x) = im/x − i (re − c)/x
            let (r, i) = (im / x, -(re - INV_FACTORIAL[k - 1]) / x);
            re = r;
            im = i;
            out[k] = Block {
                a: re,
                b: tau * im / x,
            };
        }
    } else {
        let s = (-lambda).sqrt() * tau;
        let (mut p, mut m) = (s.exp(), (-s).exp());
        for k in 0..4 {
            if k > 0 {
                p = (p - INV_FACTORIAL[k - 1]) / s;
                m = (m - INV_FACTORIAL[k - 1]) / -s;
            }
            out[k] = Block {
                a: 0.5 * (p + m),
                b: tau * (p - m) / (2.0 * s),
            };
        }
    }
    out
}

/// Terms of the power series of [`phi_blocks`] (|μ| ≤ 1).
const SERIES_TERMS: usize = 11;

/// 1/n! for n < 2·[`SERIES_TERMS`] + 4.
const INV_FACTORIAL: [f64; 2 * SERIES_TERMS + 4] = {
    let mut t = [1.0; 2 * SERIES_TERMS + 4];
    let mut n = 1;
    while n < t.len() {
        t[n] = t[n - 1] / n as f64;
        n += 1;
    }
    t
};

/// A linearization (M, K) whose every entry lies within this fraction of √(dᵢdⱼ) of the last
/// diagonalized one's (dᵢ its diagonal) keeps that diagonalization, at steps of
/// [`TOP_FREQUENCY_STEP`]/ω_max and longer; at shorter steps the fraction shrinks like
/// (ω_max·h/[`TOP_FREQUENCY_STEP`])⁴, so that the kept mismatch vanishes with the step (a
/// constant fraction left a step-independent error that cut the observed order on the
/// undamped arm from 3.6 to 3.5 between h = 6.25e-5 and 3.125e-5). The splitting stays exact
/// whatever A_n is (the remainder takes the difference), so the tolerance trades the
/// remainder's size against the eigenproblems solved. On `two-link-free-undamped` (10 s, 20 Hz
/// low-passed hub angle and raw elbow angle against Dormand–Prince at rtol 1e-8, resp. the
/// method at h = 4e-5 for 8 modes): at 1e-4 the 6-mode default diagonalizes 38 822 of 79 088
/// steps (3.42 → 2.75 s) at 6.1e-6 / 2.0e-5 rad instead of 8.2e-6 / 3.0e-5, and 8 modes
/// 74 585 of 192 350 (14.3 → 12.8 s) at 1.1e-5 / 2.3e-5 instead of 1.1e-5 / 3.2e-5; at 1e-3
/// the 8-mode elbow angle is 6.9e-4 rad off, and a tolerance scaled by the largest entry
/// instead of the diagonal diverged at 1e-2.
pub const REFRESH_TOLERANCE: f64 = 1e-4;

/// Whether every entry of the row-major n × n `a` lies within `tol`·√(bᵢᵢbⱼⱼ) of `b`'s (at 0:
/// bitwise equal).
fn within(a: &[f64], b: &[f64], n: usize, tol: f64) -> bool {
    if a.len() != b.len() {
        return false;
    }
    if tol == 0.0 {
        return a == b;
    }
    (0..n).all(|i| {
        (0..n).all(|j| {
            let bound = tol * (b[i * n + i] * b[j * n + j]).abs().sqrt();
            (a[i * n + j] - b[i * n + j]).abs() <= bound
        })
    })
}

/// Fixed-step exponential Runge–Kutta integrator (see the module docs).
pub struct Exponential {
    h: f64,
    /// Free coordinates (0 before the first linearization).
    nf: usize,
    stats: StepStats,
    /// M_n, K_n over the free coordinates: row-major from the right-hand side, then as matrices.
    m_rows: Vec<f64>,
    k_rows: Vec<f64>,
    /// The rows and the step of the last diagonalization: an identical linearization (a
    /// chain whose undeformed mass and stiffness do not depend on its joint angles, e.g. one
    /// link on its hub) keeps its modes and φ functions.
    m_rows_last: Vec<f64>,
    k_rows_last: Vec<f64>,
    h_last_linearized: f64,
    /// See [`REFRESH_TOLERANCE`].
    refresh_tolerance: f64,
    m: Mat<f64>,
    k: Mat<f64>,
    pencil: Pencil,
    /// Λ, X (row-major, column j: mode j) and P = XᵀM_n (row j: mode j).
    lambda: Vec<f64>,
    x: Vec<f64>,
    p: Vec<f64>,
    /// φ₀(hA/2), φ₁(hA/2) and φ₀ … φ₃(hA) per mode.
    half: Vec<[Block; 2]>,
    full: Vec<[Block; 4]>,
    /// Modal start, stage and end states; remainders at the start and the stages.
    u0: Vec<f64>,
    ua: Vec<f64>,
    ub: Vec<f64>,
    uc: Vec<f64>,
    u1: Vec<f64>,
    n0: Vec<f64>,
    na: Vec<f64>,
    nb: Vec<f64>,
    nc: Vec<f64>,
    /// Dense-output correction D (modal), start and end of the last step, its length, its end
    /// state.
    d: Vec<f64>,
    t_prev: f64,
    t_last: f64,
    h_last: f64,
    y_end: Vec<f64>,
    y_phys: Vec<f64>,
    f_phys: Vec<f64>,
}

impl Exponential {
    pub fn new(dim: usize, h: f64) -> Self {
        Exponential {
            h,
            nf: 0,
            stats: StepStats::default(),
            m_rows: Vec::new(),
            k_rows: Vec::new(),
            m_rows_last: Vec::new(),
            k_rows_last: Vec::new(),
            h_last_linearized: f64::NAN,
            refresh_tolerance: REFRESH_TOLERANCE,
            m: Mat::zeros(0, 0),
            k: Mat::zeros(0, 0),
            pencil: Pencil::new(0),
            lambda: Vec::new(),
            x: Vec::new(),
            p: Vec::new(),
            half: Vec::new(),
            full: Vec::new(),
            u0: vec![0.0; dim],
            ua: vec![0.0; dim],
            ub: vec![0.0; dim],
            uc: vec![0.0; dim],
            u1: vec![0.0; dim],
            n0: vec![0.0; dim],
            na: vec![0.0; dim],
            nb: vec![0.0; dim],
            nc: vec![0.0; dim],
            d: vec![0.0; dim],
            t_prev: 0.0,
            t_last: 0.0,
            h_last: 0.0,
            y_end: vec![0.0; dim],
            y_phys: vec![0.0; dim],
            f_phys: vec![0.0; dim],
        }
    }

    /// The same method with another refresh tolerance ([`REFRESH_TOLERANCE`]; 0 diagonalizes
    /// every linearization that differs in any bit).
    pub fn with_refresh_tolerance(mut self, tolerance: f64) -> Self {
        self.refresh_tolerance = tolerance;
        self
    }

    /// Work arrays for `nf` free coordinates (once: the count is the system's).
    fn size_for(&mut self, nf: usize) {
        if self.nf == nf {
            return;
        }
        self.nf = nf;
        self.m = Mat::zeros(nf, nf);
        self.k = Mat::zeros(nf, nf);
        self.pencil = Pencil::new(nf);
        self.lambda = vec![0.0; nf];
        self.x = vec![0.0; nf * nf];
        self.p = vec![0.0; nf * nf];
        self.half = vec![[Block::default(); 2]; nf];
        self.full = vec![[Block::default(); 4]; nf];
    }

    /// Linearizes at (t, y), diagonalizes the pencil (K_n, M_n) and tabulates the step's φ
    /// functions for the step `h`.
    fn linearize(
        &mut self,
        f: &mut dyn OdeRhs,
        t: f64,
        y: &[f64],
        h: f64,
    ) -> Result<(), IntegrateError> {
        let nf = f
            .second_order_linearization(t, y, &mut self.m_rows, &mut self.k_rows)
            .ok_or(IntegrateError::NoLinearization { t })?;
        self.size_for(nf);
        self.stats.jacobian_evals += 1;
        // The kept diagonalization's mismatch enters the explicit remainder; scaled like
        // (ω_max·h)⁴ below the default step, it vanishes with h faster than the method's error.
        let top = self.lambda.iter().fold(0.0f64, |a, &l| a.max(l.abs()));
        let resolved = (h * top.sqrt() / TOP_FREQUENCY_STEP).min(1.0);
        let tol = self.refresh_tolerance * resolved.powi(4);
        if h == self.h_last_linearized
            && within(&self.m_rows, &self.m_rows_last, nf, tol)
            && within(&self.k_rows, &self.k_rows_last, nf, tol)
        {
            return Ok(());
        }
        symmetrize(&self.m_rows, &mut self.m);
        symmetrize(&self.k_rows, &mut self.k);
        self.pencil
            .solve(self.k.as_ref(), self.m.as_ref())
            .map_err(|_| IntegrateError::NoLinearization { t })?;
        self.stats.factorizations += 1;
        self.lambda.copy_from_slice(self.pencil.eigenvalues());
        let x = self.pencil.vectors();
        for i in 0..nf {
            for j in 0..nf {
                self.x[i * nf + j] = x[(i, j)];
            }
        }
        for j in 0..nf {
            for c in 0..nf {
                let mut s = 0.0;
                for i in 0..nf {
                    s += x[(i, j)] * self.m[(i, c)];
                }
                self.p[j * nf + c] = s;
            }
        }
        for j in 0..nf {
            let half = phi_blocks(self.lambda[j], 0.5 * h);
            self.half[j] = [half[0], half[1]];
            self.full[j] = phi_blocks(self.lambda[j], h);
        }
        self.m_rows_last.clone_from(&self.m_rows);
        self.k_rows_last.clone_from(&self.k_rows);
        self.h_last_linearized = h;
        Ok(())
    }

    /// out = (X z, X w, works) of the modal state u.
    fn to_physical(x: &[f64], nf: usize, u: &[f64], out: &mut [f64]) {
        out[..2 * nf].iter_mut().for_each(|v| *v = 0.0);
        for j in 0..nf {
            let (z, w) = (u[j], u[nf + j]);
            for i in 0..nf {
                let xij = x[i * nf + j];
                out[i] += xij * z;
                out[nf + i] += xij * w;
            }
        }
        out[2 * nf..].copy_from_slice(&u[2 * nf..]);
    }

    /// Remainder at the modal state u and time t into `out`: η = P a + Λz per mode (no
    /// position part), then the powers.
    fn remainder(&mut self, f: &mut dyn OdeRhs, t: f64, u: &[f64], out: &mut [f64]) {
        let nf = self.nf;
        Self::to_physical(&self.x, nf, u, &mut self.y_phys);
        f.eval(t, &self.y_phys, &mut self.f_phys);
        self.stats.rhs_evals += 1;
        for j in 0..nf {
            let row = &self.p[j * nf..(j + 1) * nf];
            let pa: f64 = row.iter().zip(&self.f_phys[nf..2 * nf]).map(|(a, b)| a * b).sum();
            out[j] = 0.0;
            out[nf + j] = pa + self.lambda[j] * u[j];
        }
        out[2 * nf..].copy_from_slice(&self.f_phys[2 * nf..]);
    }

    /// out = e^{hA/2} base + (h/2) φ₁(hA/2) r.
    fn half_stage(&self, h: f64, base: &[f64], r: &[f64], out: &mut [f64]) {
        let nf = self.nf;
        for j in 0..nf {
            let [e, p1] = self.half[j];
            let (z, w) = e.apply(self.lambda[j], base[j], base[nf + j]);
            let (dz, dw) = p1.apply_velocity(r[nf + j]);
            out[j] = z + 0.5 * h * dz;
            out[nf + j] = w + 0.5 * h * dw;
        }
        for i in 2 * nf..out.len() {
            out[i] = base[i] + 0.5 * h * r[i];
        }
    }

    fn step_impl(
        &mut self,
        f: &mut dyn OdeRhs,
        t: &mut f64,
        y: &mut [f64],
        t_stop: f64,
    ) -> Result<(), IntegrateError> {
        let span = t_stop - *t;
        if span <= 0.0 {
            return Ok(());
        }
        let clipped = self.h >= span * (1.0 - 1e-12);
        let h = if clipped { span } else { self.h };
        let t0 = *t;
        self.linearize(f, t0, y, h)?;
        let nf = self.nf;
        let dim = y.len();
        let mut u0 = std::mem::take(&mut self.u0);
        for j in 0..nf {
            let row = &self.p[j * nf..(j + 1) * nf];
            u0[j] = row.iter().zip(&y[..nf]).map(|(a, b)| a * b).sum();
            u0[nf + j] = row.iter().zip(&y[nf..2 * nf]).map(|(a, b)| a * b).sum();
        }
        u0[2 * nf..].copy_from_slice(&y[2 * nf..]);
        let (mut n0, mut na, mut nb, mut nc) = (
            std::mem::take(&mut self.n0),
            std::mem::take(&mut self.na),
            std::mem::take(&mut self.nb),
            std::mem::take(&mut self.nc),
        );
        let (mut ua, mut ub, mut uc, mut u1) = (
            std::mem::take(&mut self.ua),
            std::mem::take(&mut self.ub),
            std::mem::take(&mut self.uc),
            std::mem::take(&mut self.u1),
        );
        let t_half = t0 + 0.5 * h;
        self.remainder(f, t0, &u0, &mut n0);
        self.half_stage(h, &u0, &n0, &mut ua);
        self.remainder(f, t_half, &ua, &mut na);
        self.half_stage(h, &u0, &na, &mut ub);
        self.remainder(f, t_half, &ub, &mut nb);
        for i in 0..dim {
            u1[i] = 2.0 * nb[i] - n0[i];
        }
        self.half_stage(h, &ua, &u1, &mut uc);
        self.remainder(f, t0 + h, &uc, &mut nc);
        for j in 0..nf {
            let lambda = self.lambda[j];
            let [e, p1, p2, p3] = self.full[j];
            let weights = [
                (p1.a - 3.0 * p2.a + 4.0 * p3.a, p1.b - 3.0 * p2.b + 4.0 * p3.b),
                (2.0 * (p2.a - 2.0 * p3.a), 2.0 * (p2.b - 2.0 * p3.b)),
                (4.0 * p3.a - p2.a, 4.0 * p3.b - p2.b),
            ];
            let etas = [n0[nf + j], na[nf + j] + nb[nf + j], nc[nf + j]];
            let (ez, ew) = e.apply(lambda, u0[j], u0[nf + j]);
            let (mut z, mut w) = (ez, ew);
            for ((a, b), eta) in weights.into_iter().zip(etas) {
                let (dz, dw) = Block { a, b }.apply_velocity(eta);
                z += h * dz;
                w += h * dw;
            }
            u1[j] = z;
            u1[nf + j] = w;
            // D = φ₂(hA)⁻¹ (u₁ − e^{hA}u₀ − hφ₁(hA)N₀)/h, with (aI + bJ)⁻¹ = (aI − bJ)/(a² + λb²).
            let (pz, pw) = p1.apply_velocity(n0[nf + j]);
            let (rz, rw) = ((z - ez - h * pz) / h, (w - ew - h * pw) / h);
            let det = p2.a * p2.a + lambda * p2.b * p2.b;
            let inverse = Block {
                a: p2.a / det,
                b: -p2.b / det,
            };
            let (dz, dw) = inverse.apply(lambda, rz, rw);
            self.d[j] = dz;
            self.d[nf + j] = dw;
        }
        // The powers: A = 0, φ_k(0) = 1/k!.
        for i in 2 * nf..dim {
            u1[i] = u0[i] + h * (n0[i] + 2.0 * (na[i] + nb[i]) + nc[i]) / 6.0;
            self.d[i] = 2.0 * (u1[i] - u0[i] - h * n0[i]) / h;
        }
        Self::to_physical(&self.x, nf, &u1, y);
        self.y_end.copy_from_slice(y);
        self.t_prev = t0;
        self.h_last = h;
        *t = if clipped { t_stop } else { t0 + h };
        self.t_last = *t;
        self.stats.steps += 1;
        (self.u0, self.ua, self.ub, self.uc, self.u1) = (u0, ua, ub, uc, u1);
        (self.n0, self.na, self.nb, self.nc) = (n0, na, nb, nc);
        if !y.iter().all(|v| v.is_finite()) {
            return Err(IntegrateError::NonFinite { t: *t });
        }
        Ok(())
    }

    fn dense_impl(&self, t_out: f64, out: &mut [f64]) {
        if t_out >= self.t_last {
            out.copy_from_slice(&self.y_end);
            return;
        }
        let h = self.h_last;
        let theta = (t_out - self.t_prev) / h;
        let nf = self.nf;
        let tau = theta * h;
        out[..2 * nf].iter_mut().for_each(|v| *v = 0.0);
        for j in 0..nf {
            let lambda = self.lambda[j];
            let [e, p1, p2, _] = phi_blocks(lambda, tau);
            let (mut z, mut w) = e.apply(lambda, self.u0[j], self.u0[nf + j]);
            let (dz, dw) = p1.apply_velocity(self.n0[nf + j]);
            z += tau * dz;
            w += tau * dw;
            let (dz, dw) = p2.apply(lambda, self.d[j], self.d[nf + j]);
            z += theta * tau * dz;
            w += theta * tau * dw;
            for i in 0..nf {
                let xij = self.x[i * nf + j];
                out[i] += xij * z;
                out[nf + i] += xij * w;
            }
        }
        for i in 2 * nf..out.len() {
            out[i] = self.u0[i] + tau * self.n0[i] + 0.5 * theta * tau * self.d[i];
        }
    }
}

impl Stepper for Exponential {
    fn step(
        &mut self,
        f: &mut dyn OdeRhs,
        t: &mut f64,
        y: &mut [f64],
        t_stop: f64,
    ) -> Result<StopReason, IntegrateError> {
        self.step_impl(f, t, y, t_stop)?;
        Ok(stop_reason(*t, t_stop))
    }
    fn dense(&self, t_out: f64, out: &mut [f64]) {
        self.dense_impl(t_out, out)
    }
    fn stats(&self) -> StepStats {
        self.stats
    }
    fn last_step(&self) -> f64 {
        self.h_last
    }
    /// Nothing is carried between steps but the last diagonalization, which every step checks
    /// against its own linearization.
    fn reset(&mut self) {}
}
