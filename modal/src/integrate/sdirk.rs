//! TR-BDF2: an L-stable, stiffly accurate ESDIRK method of order 2 with an embedded
//! 3rd-order estimate (Hosea & Shampine 1996), simplified Newton on one factorization of
//! I − h d J shared by both implicit stages.
//!
//! Tableau (γ = 2 − √2, d = γ/2, w = √2/4):
//! ```text
//!   0 |  0  0  0
//!   γ |  d  d  0        stage 2: trapezoidal rule on [t, t + γh]
//!   1 |  w  w  d        stage 3: BDF2 on (t, t + γh, t + h)
//!  ---+---------
//!     |  w  w  d        (stiffly accurate: y₁ = z₃)
//!     | (1−w)/3  (3w+1)/3  d/3   (embedded, order 3)
//! ```
//!
//! **Linear algebra.** In order of preference: the right-hand side's own factored iteration
//! matrix ([`OdeRhs::newton_linearize`], the modal chain's Cholesky of M + cD + c²K, see
//! [`crate::newton`]); a dense LU (faer) of its analytic Jacobian ([`OdeRhs::jacobian`]);
//! a dense LU of forward differences (dim extra evaluations).
//!
//! **Newton control** (Hairer & Wanner, *Solving ODEs II*, IV.8): rate θ, η = θ/(1 − θ),
//! converged at η‖Δz‖ ≤ 0.03 (error-tolerance units), the first update judged with the
//! previous η; divergence at θ ≥ 0.99, early failure when η‖Δz‖θ^left ≥ 0.03. After a failure
//! an old Jacobian is refreshed and the same step retried; with a fresh one h is halved
//! (divergence) or cut by 0.8·ratio^(−1/(4+left)) (too slow). A cheap (analytic or
//! factored) Jacobian is also refreshed after any step whose rate exceeded 0.1; a difference
//! Jacobian only on failure. [`Sdirk::state_changed`] (a projection moved y, f unchanged) keeps
//! Jacobian and factorization; [`Sdirk::reset`] (discontinuity) drops them.
//!
//! **Error estimate.** err = (I − h d J)⁻¹·h(E₁f₁ + E₂f₂ + E₃f₃), the embedded difference
//! filtered once so that it stays bounded on stiff components (Hosea & Shampine). On a stiff
//! component that L-stability damps — the transient after an impact or a projection, the stiff
//! modes of a sliding contact phase — the once-filtered estimate tends to the component's
//! amplitude E·δ/d whatever h, and a step would be rejected attempt after attempt until h
//! resolves the component. A step that fails the test is therefore estimated again with f₁
//! taken at y + err (`Sdirk::refined_error`; Hairer & Wanner, IV.8, for Radau IIA): for a
//! linear f the estimate filtered twice, unchanged on non-stiff components and falling like
//! 1/(h d |λ|) on stiff ones.
//!
//! **Noise floor.** An iteration that stops contracting (θ ≥ 0.99 or too slow) from its second
//! update on, with its last two updates both ≤ 1 error-tolerance unit, is accepted: the stage
//! is then within the tolerance and the error test judges the step. Near an impact of a chain
//! in polynomial coordinates (M(q) with condition 10¹³–10¹⁷ at 12–24 modes: a hub rotation
//! undone by the clamped polynomials carries almost no kinetic energy) the Newton update
//! stagnates at the evaluation's round-off, not at a Jacobian error; in stiff directions that
//! noise does not shrink with h, so rejecting such iterations would cut h without end. Where
//! the floor exceeds the tolerance the steps stay small: choose atol above the floor. The error
//! test has the same limit: a stage's noise δz in a stiff component enters the estimate as
//! h·E·δz/(hd), independent of h, and the filters damp it only once hd|λ| ≫ 1, so a rejection
//! makes the next estimate *worse*. Only better-conditioned
//! coordinates would remove the floor. The measurements behind these rules (noise levels, step
//! counts, Jacobians and first impulses on `barhorst-case1-tipmass` at 12–24 modes, against the
//! earlier forward-difference Newton) are in docs/backends.md, "modal TR-BDF2 at the impact of
//! `barhorst-case1-tipmass`".

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, Par};

use super::{
    Build, IntegrateError, MethodInfo, OdeRhs, StepStats, Stepper, StopReason, Tolerances,
    clip_step, error_norm, initial_step, min_step, next_step, shrink_after_blowup, stop_reason,
};

const SQRT2: f64 = std::f64::consts::SQRT_2;
const GAMMA: f64 = 2.0 - SQRT2;
const D: f64 = GAMMA / 2.0;
const W: f64 = SQRT2 / 4.0;
// Error weights b − b̂.
const E1: f64 = (4.0 * W - 1.0) / 3.0;
const E2: f64 = -1.0 / 3.0;
const E3: f64 = 2.0 * D / 3.0;

const SAFETY: f64 = 0.9;
const MAX_NEWTON: usize = 8;
/// Newton stops when the estimated iteration error η‖Δz‖ is below this fraction of the error
/// tolerance (η = θ/(1 − θ), θ the observed contraction rate).
const NEWTON_TOL: f64 = 0.03;
/// A contraction rate at or above this is divergence.
const THETA_DIVERGE: f64 = 0.99;
/// An analytic Jacobian is refreshed at the next step once a step's rate exceeded this.
const THETA_REFRESH: f64 = 0.1;
/// Noise-floor acceptance: an iteration that stops contracting (judged from the second update
/// on) while its last two updates are both at most this (in units of the error tolerance) is
/// taken as converged.
const NOISE_ACCEPT: f64 = 1.0;

/// Why a stage's Newton iteration was abandoned.
#[derive(Debug, Clone, Copy)]
enum NewtonFail {
    /// Non-finite update or θ ≥ [`THETA_DIVERGE`] (or the iteration budget ran out).
    Diverged,
    /// Contracting, but the predicted error after the remaining iterations, η‖Δz‖θ^left,
    /// is `ratio` times the Newton tolerance.
    Slow { ratio: f64, left: usize },
}

/// The iteration matrix I − h d J: factored by the right-hand side ([`OdeRhs::newton_factor`])
/// or as a dense LU of the Jacobian.
struct IterationMatrix {
    structured: bool,
    lu: Mat<f64>,
    perm_fwd: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
}

impl IterationMatrix {
    /// x ← (I − h d J)⁻¹ x.
    fn solve<F: OdeRhs + ?Sized>(&mut self, f: &mut F, x: &mut [f64]) {
        if self.structured {
            f.newton_solve(x);
            return;
        }
        let n = x.len();
        let perm = PermRef::new_checked(&self.perm_fwd, &self.perm_inv, n);
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        solve::solve_in_place_with_conj(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

/// Registry entries ([`super::method_for`]): adaptive TR-BDF2, fixed-step TR-BDF2 and the
/// fixed-step trapezoidal rule.
pub const TRBDF2: MethodInfo = MethodInfo {
    method: data::ModalMethod::TrBdf2,
    name: "trbdf2",
    build: Build::Adaptive(|dim, tol, h_init| Box::new(Sdirk::new(dim, tol, h_init, None))),
    needs_oscillators: false,
};
pub const TRBDF2_FIXED: MethodInfo = MethodInfo {
    method: data::ModalMethod::TrBdf2Fixed,
    name: "trbdf2-fixed",
    build: Build::Fixed(|dim, tol, h| Box::new(Sdirk::fixed_step(dim, tol, h))),
    needs_oscillators: false,
};
pub const TRAPEZOID: MethodInfo = MethodInfo {
    method: data::ModalMethod::Trapezoid,
    name: "trapezoid",
    build: Build::Fixed(|dim, tol, h| Box::new(Sdirk::trapezoidal(dim, tol, h))),
    needs_oscillators: false,
};

/// Implicit adaptive TR-BDF2 integrator (see the module docs).
pub struct Sdirk {
    tol: Tolerances,
    h_max: f64,
    /// Fixed step size ([`Sdirk::fixed_step`]): no error test; `tol` scales only the Newton test.
    fixed: Option<f64>,
    /// With `fixed`: one trapezoidal stage over the whole step instead of TR + BDF2.
    trapezoid: bool,
    h: Option<f64>,
    have_f1: bool,
    f1: Vec<f64>,
    f2: Vec<f64>,
    f3: Vec<f64>,
    z: Vec<f64>,
    rhs_base: Vec<f64>,
    work: Vec<f64>,
    delta: Vec<f64>,
    err: Vec<f64>,
    y_new: Vec<f64>,
    jac: Vec<f64>,
    /// Jacobian is from the current step's start point.
    jac_fresh: bool,
    have_jac: bool,
    /// The right-hand side supplied the Jacobian ([`OdeRhs::jacobian`]): cheap to refresh.
    jac_analytic: bool,
    /// Start the next step with a fresh Jacobian (the last one contracted slowly).
    jac_refresh: bool,
    /// η = θ/(1 − θ) of the last Newton iteration, carried to the next stage's first test.
    eta: f64,
    /// Largest contraction rate θ observed in the current step's iterations.
    theta_step: f64,
    /// Iteration matrix I − h d J and the h it was built for.
    iter: IterationMatrix,
    lu_h: f64,
    // Dense output (cubic Hermite).
    t_prev: f64,
    h_last: f64,
    y_prev: Vec<f64>,
    f_prev: Vec<f64>,
    stats: StepStats,
}

impl Sdirk {
    pub fn new(dim: usize, tol: Tolerances, h_init: Option<f64>, h_max: Option<f64>) -> Self {
        let z = || vec![0.0; dim];
        let par = Par::Seq;
        let mem = MemBuffer::new(
            factor::lu_in_place_scratch::<usize, f64>(dim, dim, par, Default::default())
                .or(solve::solve_in_place_scratch::<usize, f64>(dim, 1, par)),
        );
        Sdirk {
            tol,
            h_max: h_max.unwrap_or(f64::INFINITY),
            fixed: None,
            trapezoid: false,
            h: h_init,
            have_f1: false,
            f1: z(),
            f2: z(),
            f3: z(),
            z: z(),
            rhs_base: z(),
            work: z(),
            delta: z(),
            err: z(),
            y_new: z(),
            jac: vec![0.0; dim * dim],
            jac_fresh: false,
            have_jac: false,
            jac_analytic: false,
            jac_refresh: false,
            eta: 1.0,
            theta_step: 0.0,
            iter: IterationMatrix {
                structured: false,
                lu: Mat::zeros(dim, dim),
                perm_fwd: vec![0; dim],
                perm_inv: vec![0; dim],
                mem,
            },
            lu_h: f64::NAN,
            t_prev: 0.0,
            h_last: 0.0,
            y_prev: z(),
            f_prev: z(),
            stats: StepStats::default(),
        }
    }

    /// TR-BDF2 with the fixed step `h` (steps are only shortened to land on `t_stop`, or halved
    /// for one attempt when Newton fails with a fresh Jacobian). Without the error test the
    /// step is set by the dynamics the caller wants resolved, not by the fastest component:
    /// L-stability damps what the step does not resolve (|hλ| → ∞: R → 0), so an undamped
    /// high-frequency Ritz mode neither limits the step nor grows. `tol` scales the Newton
    /// convergence test only.
    pub fn fixed_step(dim: usize, tol: Tolerances, h: f64) -> Self {
        let mut s = Self::new(dim, tol, Some(h), Some(h));
        s.fixed = Some(h);
        s
    }

    /// The trapezoidal rule y₁ = y₀ + h/2 (f(y₀) + f(y₁)) with the fixed step `h`, on the same
    /// Newton machinery (its iteration matrix I − (h/2)J is this integrator's I − h'dJ with
    /// h' = h/(2d)). A-stable with |R(iω)| = 1: undamped oscillations keep their amplitude at
    /// any step (a mode with hω ≫ 1 is carried at a wrong, high frequency, not damped), and
    /// its quadratic invariants of linear systems are conserved. Second order; cubic Hermite
    /// dense output.
    pub fn trapezoidal(dim: usize, tol: Tolerances, h: f64) -> Self {
        let mut s = Self::fixed_step(dim, tol, h);
        s.trapezoid = true;
        s
    }

    pub fn stats(&self) -> &StepStats {
        &self.stats
    }

    pub fn last_step(&self) -> f64 {
        self.h_last
    }

    /// The state was moved outside the integrator by a small amount (a projection onto a
    /// constraint manifold) while the right-hand side stayed the same: forget the FSAL stage,
    /// keep the Jacobian and its factorization.
    pub fn state_changed(&mut self) {
        self.have_f1 = false;
    }

    /// Forget the FSAL stage and the Jacobian (after a discontinuity).
    pub fn reset(&mut self) {
        self.have_f1 = false;
        self.have_jac = false;
        self.lu_h = f64::NAN;
        self.eta = 1.0;
    }

    fn update_jacobian<F: OdeRhs + ?Sized>(&mut self, f: &mut F, t: f64, y: &[f64]) {
        self.stats.jacobian_evals += 1;
        self.iter.structured = f.newton_linearize(t, y);
        self.jac_analytic = self.iter.structured || f.jacobian(t, y, &mut self.jac);
        if !self.jac_analytic {
            self.difference_jacobian(f, t, y);
        }
        self.have_jac = true;
        self.jac_fresh = true;
        self.jac_refresh = false;
        self.lu_h = f64::NAN;
    }

    /// Forward differences around (t, y) with f(t, y) = f1.
    fn difference_jacobian<F: OdeRhs + ?Sized>(&mut self, f: &mut F, t: f64, y: &[f64]) {
        let n = y.len();
        self.work.copy_from_slice(y);
        for j in 0..n {
            let yj = y[j];
            let dy = f64::EPSILON.sqrt()
                * yj.abs()
                    .max(self.tol.atol / self.tol.rtol.max(1e-300))
                    .max(1e-8);
            self.work[j] = yj + dy;
            f.eval(t, &self.work, &mut self.delta);
            self.stats.rhs_evals += 1;
            for i in 0..n {
                self.jac[j * n + i] = (self.delta[i] - self.f1[i]) / dy;
            }
            self.work[j] = yj;
        }
    }

    /// Factors I − h d J. A structured factorization that fails (the right-hand side's
    /// matrix is not definite) falls back to the dense Jacobian at the step start (t, y).
    fn factorize<F: OdeRhs + ?Sized>(&mut self, f: &mut F, t: f64, y: &[f64], h: f64) {
        self.stats.factorizations += 1;
        self.lu_h = h;
        if self.iter.structured {
            if f.newton_factor(h * D) {
                return;
            }
            self.iter.structured = false;
            if !f.jacobian(t, y, &mut self.jac) {
                self.difference_jacobian(f, t, y);
            }
        }
        let n = self.f1.len();
        let hd = h * D;
        for j in 0..n {
            for i in 0..n {
                let id = if i == j { 1.0 } else { 0.0 };
                self.iter.lu[(i, j)] = id - hd * self.jac[j * n + i];
            }
        }
        factor::lu_in_place(
            self.iter.lu.as_mut(),
            &mut self.iter.perm_fwd,
            &mut self.iter.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.iter.mem),
            Default::default(),
        );
    }

    /// Solves z = base + h d f(tz, z) by simplified Newton from the guess in `self.z`;
    /// returns the stage derivative in `f2` (`which` = 2) or `f3`.
    ///
    /// Convergence control after Hairer & Wanner (*Solving ODEs II*, IV.8): θ = ‖Δzₖ‖/‖Δzₖ₋₁‖
    /// (geometric mean of the last two ratios from the third iterate on), η = θ/(1 − θ),
    /// converged when η‖Δz‖ ≤ [`NEWTON_TOL`]; the first update is judged with the η of the
    /// previous iteration (η ← max(η, ε)^0.8). Divergence: θ ≥ [`THETA_DIVERGE`]; too slow:
    /// η‖Δz‖θ^left ≥ [`NEWTON_TOL`] (the remaining iterations cannot reach it). An iteration
    /// that stalls from the second update on with its last two updates ≤ [`NOISE_ACCEPT`]
    /// is taken as converged to the evaluation's noise floor (see the module docs).
    fn newton<F: OdeRhs + ?Sized>(
        &mut self,
        f: &mut F,
        tz: f64,
        h: f64,
        y_scale: &[f64],
        which: u8,
    ) -> Result<(), NewtonFail> {
        let n = self.z.len();
        let hd = h * D;
        self.eta = self.eta.max(f64::EPSILON).powf(0.8);
        let mut prev_norm = 0.0;
        let mut thq_old = 0.0;
        for it in 0..MAX_NEWTON {
            f.eval(tz, &self.z, &mut self.work);
            self.stats.rhs_evals += 1;
            self.stats.newton_iters += 1;
            for i in 0..n {
                self.delta[i] = self.rhs_base[i] + hd * self.work[i] - self.z[i];
            }
            self.iter.solve(f, &mut self.delta);
            for i in 0..n {
                self.z[i] += self.delta[i];
            }
            let norm = error_norm(&self.tol, y_scale, &self.z, &self.delta);
            if !norm.is_finite() {
                return Err(NewtonFail::Diverged);
            }
            let mut converged = self.eta * norm <= NEWTON_TOL || norm <= 1e-12;
            if it > 0 && !converged {
                let thq = norm / prev_norm;
                let theta = if it == 1 { thq } else { (thq * thq_old).sqrt() };
                thq_old = thq;
                self.theta_step = self.theta_step.max(theta);
                let left = MAX_NEWTON - 1 - it;
                let eta = theta / (1.0 - theta);
                let ratio = eta * norm * theta.powi(left as i32) / NEWTON_TOL;
                if theta >= THETA_DIVERGE || ratio >= 1.0 {
                    if norm <= NOISE_ACCEPT && prev_norm <= NOISE_ACCEPT {
                        // Stalled within the error tolerance: the noise floor (module docs).
                        self.eta = 1.0;
                        converged = true;
                    } else if theta >= THETA_DIVERGE {
                        return Err(NewtonFail::Diverged);
                    } else {
                        return Err(NewtonFail::Slow { ratio, left });
                    }
                } else {
                    self.eta = eta;
                    converged = eta * norm <= NEWTON_TOL;
                }
            }
            if converged {
                // Stage derivative from the stage relation (exact for the converged iterate).
                let fout = if which == 2 {
                    &mut self.f2
                } else {
                    &mut self.f3
                };
                for i in 0..n {
                    fout[i] = (self.z[i] - self.rhs_base[i]) / hd;
                }
                return Ok(());
            }
            prev_norm = norm.max(f64::MIN_POSITIVE);
        }
        Err(NewtonFail::Diverged)
    }

    /// Advances one accepted step, never past `t_stop`.
    pub fn step<F: OdeRhs + ?Sized>(
        &mut self,
        f: &mut F,
        t: &mut f64,
        y: &mut [f64],
        t_stop: f64,
    ) -> Result<(), IntegrateError> {
        let n = y.len();
        let span = t_stop - *t;
        if span <= 0.0 {
            return Ok(());
        }
        if !self.have_f1 {
            f.eval(*t, y, &mut self.f1);
            self.stats.rhs_evals += 1;
            self.have_f1 = true;
        }
        if !self.f1.iter().all(|v| v.is_finite()) {
            return Err(IntegrateError::NonFinite { t: *t });
        }
        let mut h = match self.fixed.or(self.h) {
            Some(h) => h,
            None => {
                let h = initial_step(
                    f,
                    &self.tol,
                    2,
                    *t,
                    y,
                    &self.f1,
                    &mut self.y_new,
                    &mut self.f2,
                    self.h_max,
                    span,
                );
                self.stats.rhs_evals += 1;
                h
            }
        };
        h = h.min(self.h_max);
        let h_min = min_step(*t, span);
        self.jac_fresh = false;
        if !self.have_jac || self.jac_refresh {
            self.update_jacobian(f, *t, y);
        }
        self.theta_step = 0.0;
        loop {
            let (h_try, clipped) = clip_step(h, span, h_min, *t)?;
            // The stage coefficient is h_stage·d: h for TR-BDF2, h/2 for the trapezoidal rule.
            let h_stage = if self.trapezoid {
                h_try / (2.0 * D)
            } else {
                h_try
            };
            if self.lu_h != h_stage {
                self.factorize(f, *t, y, h_stage);
            }
            if self.trapezoid {
                for i in 0..n {
                    self.rhs_base[i] = y[i] + 0.5 * h_try * self.f1[i];
                    self.z[i] = y[i] + h_try * self.f1[i];
                }
                if let Err(fail) = self.newton(f, *t + h_try, h_stage, y, 3) {
                    h = self.after_newton_failure(f, *t, y, h, h_try, h_min, fail)?;
                    continue;
                }
                self.y_new.copy_from_slice(&self.z);
                self.accept(f, t, y, h_try, clipped, t_stop);
                return Ok(());
            }
            // Stage 2 (trapezoidal to t + γh), predicted by the explicit Euler step. (The
            // linearly implicit predictor y + (I − hdJ)⁻¹γh f₁ was measured worse on the
            // contact chain: 173 against 15 Newton failures at 14 modes per link.)
            for i in 0..n {
                self.rhs_base[i] = y[i] + h_try * D * self.f1[i];
                self.z[i] = y[i] + GAMMA * h_try * self.f1[i];
            }
            let mut res = self.newton(f, *t + GAMMA * h_try, h_try, y, 2);
            if res.is_ok() {
                // Stage 3 (BDF2 to t + h), predicted by extrapolating the stage-2 slope.
                for i in 0..n {
                    self.rhs_base[i] = y[i] + h_try * W * (self.f1[i] + self.f2[i]);
                    self.z[i] = self.rhs_base[i] + h_try * D * self.f2[i];
                }
                res = self.newton(f, *t + h_try, h_try, y, 3);
            }
            if let Err(fail) = res {
                h = self.after_newton_failure(f, *t, y, h, h_try, h_min, fail)?;
                continue;
            }
            self.y_new.copy_from_slice(&self.z);
            let err = if self.fixed.is_some() {
                0.0
            } else {
                for i in 0..n {
                    self.err[i] = h_try * (E1 * self.f1[i] + E2 * self.f2[i] + E3 * self.f3[i]);
                }
                // Filter the estimate through (I − h d J)⁻¹: keeps it bounded on stiff
                // components.
                self.iter.solve(f, &mut self.err);
                let err = error_norm(&self.tol, y, &self.y_new, &self.err);
                if err > 1.0 {
                    self.refined_error(f, *t, y, h_try)
                } else {
                    err
                }
            };
            if !err.is_finite() {
                self.stats.rejected += 1;
                h = shrink_after_blowup(h_try, h_min, *t)?;
                continue;
            }
            // Error of order h³.
            let fac = (SAFETY * err.max(1e-10).powf(-1.0 / 3.0)).clamp(0.2, 5.0);
            if err <= 1.0 {
                self.accept(f, t, y, h_try, clipped, t_stop);
                let mut h_next = h_try * fac;
                // Keep the factorization when the change would be small.
                if (0.9..=1.3).contains(&(h_next / h_try)) {
                    h_next = h_try;
                }
                self.h = Some(next_step(h_next, h, h_try, clipped, self.h_max));
                return Ok(());
            }
            self.stats.rejected += 1;
            h = h_try * fac.min(0.9);
        }
    }

    /// The error estimate of a step that failed the error test, estimated again with the
    /// explicit stage's slope taken at y + err (as Hairer & Wanner, *Solving ODEs II*, IV.8, do
    /// for Radau IIA after a rejection):
    /// err ← (I − h d J)⁻¹·[h(E₁f₁ + E₂f₂ + E₃f₃) + h d (f(t, y + err) − f₁)].
    /// For a linear f this is the estimate filtered twice, (I − h d J)⁻²·h E f: unchanged on
    /// non-stiff components, falling like 1/(h d |λ|) on a stiff one, where the once-filtered
    /// estimate stays at the component's amplitude whatever h (module docs). Costs one
    /// evaluation and one solve, less than the rejected attempt it saves.
    fn refined_error<F: OdeRhs + ?Sized>(
        &mut self,
        f: &mut F,
        t: f64,
        y: &[f64],
        h_try: f64,
    ) -> f64 {
        for ((w, yi), ei) in self.work.iter_mut().zip(y).zip(&self.err) {
            *w = yi + ei;
        }
        f.eval(t, &self.work, &mut self.delta);
        self.stats.rhs_evals += 1;
        for i in 0..y.len() {
            self.err[i] = h_try * (E1 * self.f1[i] + E2 * self.f2[i] + E3 * self.f3[i])
                + h_try * D * (self.delta[i] - self.f1[i]);
        }
        self.iter.solve(f, &mut self.err);
        error_norm(&self.tol, y, &self.y_new, &self.err)
    }

    /// Handles a failed stage iteration; returns the step to try next. An old Jacobian is
    /// refreshed and the same step retried; with a fresh one the step is cut.
    #[allow(clippy::too_many_arguments)]
    fn after_newton_failure<F: OdeRhs + ?Sized>(
        &mut self,
        f: &mut F,
        t: f64,
        y: &[f64],
        h: f64,
        h_try: f64,
        h_min: f64,
        fail: NewtonFail,
    ) -> Result<f64, IntegrateError> {
        self.stats.rejected += 1;
        self.stats.newton_failures += 1;
        if !self.jac_fresh {
            // A Jacobian from an earlier step: refresh it, retry the same step.
            self.update_jacobian(f, t, y);
            return Ok(h);
        }
        let h = match fail {
            NewtonFail::Diverged => 0.5 * h_try,
            // Hairer & Wanner's reduction for an iteration that would not converge within the
            // budget: the rate scales like h.
            NewtonFail::Slow { ratio, left } => {
                0.8 * h_try * ratio.clamp(1e-4, 20.0).powf(-1.0 / (4.0 + left as f64))
            }
        };
        if h < h_min {
            return Err(IntegrateError::NewtonFailed { t });
        }
        Ok(h)
    }

    /// Commits the step to `y_new`: dense-output data, t, y and f(t₁, y₁).
    fn accept<F: OdeRhs + ?Sized>(
        &mut self,
        f: &mut F,
        t: &mut f64,
        y: &mut [f64],
        h_try: f64,
        clipped: bool,
        t_stop: f64,
    ) {
        self.t_prev = *t;
        self.h_last = h_try;
        self.y_prev.copy_from_slice(y);
        self.f_prev.copy_from_slice(&self.f1);
        *t = if clipped { t_stop } else { *t + h_try };
        y.copy_from_slice(&self.y_new);
        // f(t₁, y₁) evaluated afresh rather than taken from the stage relation: the relation
        // divides the Newton residual by h·d, which at loose tolerances feeds a wrong slope
        // into the next step (seen as blow-up on stiff axial fields).
        f.eval(*t, y, &mut self.f1);
        self.stats.rhs_evals += 1;
        self.stats.steps += 1;
        // A cheap (analytic) Jacobian is refreshed once the iteration slows down.
        self.jac_refresh = self.jac_analytic && self.theta_step > THETA_REFRESH;
    }

    /// Cubic Hermite interpolation inside the last accepted step: writes y(t_out).
    pub fn dense(&self, t_out: f64, out: &mut [f64]) {
        // The end point values are the current state y and f1 = f(t, y).
        let h = self.h_last;
        let s = if h > 0.0 {
            (t_out - self.t_prev) / h
        } else {
            0.0
        };
        let h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s);
        let h10 = s * (1.0 - s) * (1.0 - s);
        let h01 = s * s * (3.0 - 2.0 * s);
        let h11 = s * s * (s - 1.0);
        for i in 0..out.len() {
            out[i] = h00 * self.y_prev[i]
                + h10 * h * self.f_prev[i]
                + h01 * self.y_new[i]
                + h11 * h * self.f1[i];
        }
    }
}

impl Stepper for Sdirk {
    fn step(
        &mut self,
        f: &mut dyn OdeRhs,
        t: &mut f64,
        y: &mut [f64],
        t_stop: f64,
    ) -> Result<StopReason, IntegrateError> {
        Sdirk::step(self, f, t, y, t_stop)?;
        Ok(stop_reason(*t, t_stop))
    }
    fn dense(&self, t_out: f64, out: &mut [f64]) {
        Sdirk::dense(self, t_out, out)
    }
    fn stats(&self) -> StepStats {
        self.stats
    }
    fn last_step(&self) -> f64 {
        self.h_last
    }
    fn reset(&mut self) {
        Sdirk::reset(self)
    }
    /// Keeps the Jacobian and its factorization: the right-hand side is unchanged.
    fn state_changed(&mut self) {
        Sdirk::state_changed(self)
    }
}
