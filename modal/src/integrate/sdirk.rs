//! TR-BDF2: an L-stable, stiffly accurate ESDIRK method of order 2 with an embedded
//! 3rd-order estimate (Hosea & Shampine 1996), simplified Newton with a dense LU (faer).
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

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, Par};

use super::{
    IntegrateError, OdeRhs, StepStats, Tolerances, clip_step, error_norm, initial_step, min_step,
    next_step, shrink_after_blowup,
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
/// Newton stops when the scaled update is below this fraction of the error tolerance.
const NEWTON_TOL: f64 = 0.03;

/// Implicit adaptive TR-BDF2 integrator (see the module docs).
pub struct Sdirk {
    tol: Tolerances,
    h_max: f64,
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
    /// Iteration matrix I − h d J (LU factors in place) and the h it was built for.
    lu: Mat<f64>,
    lu_h: f64,
    perm_fwd: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
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
            lu: Mat::zeros(dim, dim),
            lu_h: f64::NAN,
            perm_fwd: vec![0; dim],
            perm_inv: vec![0; dim],
            mem,
            t_prev: 0.0,
            h_last: 0.0,
            y_prev: z(),
            f_prev: z(),
            stats: StepStats::default(),
        }
    }

    pub fn stats(&self) -> &StepStats {
        &self.stats
    }

    pub fn last_step(&self) -> f64 {
        self.h_last
    }

    /// Forget the FSAL stage and the Jacobian (after a discontinuity).
    pub fn reset(&mut self) {
        self.have_f1 = false;
        self.have_jac = false;
        self.lu_h = f64::NAN;
    }

    fn update_jacobian<F: OdeRhs>(&mut self, f: &mut F, t: f64, y: &[f64]) {
        let n = y.len();
        self.stats.jacobian_evals += 1;
        if !f.jacobian(t, y, &mut self.jac) {
            // Forward differences around (t, y) with f(t, y) = f1.
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
        self.have_jac = true;
        self.jac_fresh = true;
        self.lu_h = f64::NAN;
    }

    fn factorize(&mut self, h: f64) {
        let n = self.f1.len();
        let hd = h * D;
        for j in 0..n {
            for i in 0..n {
                let id = if i == j { 1.0 } else { 0.0 };
                self.lu[(i, j)] = id - hd * self.jac[j * n + i];
            }
        }
        factor::lu_in_place(
            self.lu.as_mut(),
            &mut self.perm_fwd,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        self.stats.factorizations += 1;
        self.lu_h = h;
    }

    /// x ← (I − h d J)⁻¹ x.
    fn lu_solve(lu: &Mat<f64>, fwd: &[usize], inv: &[usize], mem: &mut MemBuffer, x: &mut [f64]) {
        let n = x.len();
        let perm = PermRef::new_checked(fwd, inv, n);
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        solve::solve_in_place_with_conj(
            lu.as_ref(),
            lu.as_ref(),
            perm,
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(mem),
        );
    }

    /// Solves z = base + h d f(tz, z) by simplified Newton from the guess in `self.z`;
    /// returns the stage derivative in `fout`. Err(()) on divergence.
    fn newton<F: OdeRhs>(
        &mut self,
        f: &mut F,
        tz: f64,
        h: f64,
        y_scale: &[f64],
        which: u8,
    ) -> Result<(), ()> {
        let n = self.z.len();
        let hd = h * D;
        let mut prev_norm = f64::INFINITY;
        for it in 0..MAX_NEWTON {
            f.eval(tz, &self.z, &mut self.work);
            self.stats.rhs_evals += 1;
            self.stats.newton_iters += 1;
            for i in 0..n {
                self.delta[i] = self.rhs_base[i] + hd * self.work[i] - self.z[i];
            }
            Self::lu_solve(
                &self.lu,
                &self.perm_fwd,
                &self.perm_inv,
                &mut self.mem,
                &mut self.delta,
            );
            let mut acc = 0.0;
            for i in 0..n {
                self.z[i] += self.delta[i];
                let sc = self.tol.atol + self.tol.rtol * y_scale[i].abs().max(self.z[i].abs());
                acc += (self.delta[i] / sc).powi(2);
            }
            let norm = (acc / n.max(1) as f64).sqrt();
            if !norm.is_finite() {
                return Err(());
            }
            let rate = norm / prev_norm;
            if it > 0 && rate >= 0.9 {
                return Err(());
            }
            let converged = if it == 0 {
                norm <= 1e-3 * NEWTON_TOL
            } else {
                rate / (1.0 - rate) * norm <= NEWTON_TOL
            };
            if converged || norm <= 1e-12 {
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
            prev_norm = norm;
        }
        Err(())
    }

    /// Advances one accepted step, never past `t_stop`.
    pub fn step<F: OdeRhs>(
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
        let mut h = match self.h {
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
        if !self.have_jac {
            self.update_jacobian(f, *t, y);
        }
        loop {
            let (h_try, clipped) = clip_step(h, span, h_min, *t)?;
            if self.lu_h != h_try {
                self.factorize(h_try);
            }
            // Stage 2 (trapezoidal to t + γh).
            for i in 0..n {
                self.rhs_base[i] = y[i] + h_try * D * self.f1[i];
                self.z[i] = y[i] + GAMMA * h_try * self.f1[i];
            }
            let mut ok = self.newton(f, *t + GAMMA * h_try, h_try, y, 2).is_ok();
            if ok {
                // Stage 3 (BDF2 to t + h), predicted by extrapolating the stage-2 slope.
                for i in 0..n {
                    self.rhs_base[i] = y[i] + h_try * W * (self.f1[i] + self.f2[i]);
                    self.z[i] = self.rhs_base[i] + h_try * D * self.f2[i];
                }
                ok = self.newton(f, *t + h_try, h_try, y, 3).is_ok();
            }
            if !ok {
                self.stats.rejected += 1;
                if !self.jac_fresh {
                    self.update_jacobian(f, *t, y);
                } else {
                    h = 0.25 * h_try;
                    if h < h_min {
                        return Err(IntegrateError::NewtonFailed { t: *t });
                    }
                }
                continue;
            }
            self.y_new.copy_from_slice(&self.z);
            for i in 0..n {
                self.err[i] = h_try * (E1 * self.f1[i] + E2 * self.f2[i] + E3 * self.f3[i]);
            }
            // Filter the estimate through (I − h d J)⁻¹: keeps it bounded on stiff components.
            Self::lu_solve(
                &self.lu,
                &self.perm_fwd,
                &self.perm_inv,
                &mut self.mem,
                &mut self.err,
            );
            let err = error_norm(&self.tol, y, &self.y_new, &self.err);
            if !err.is_finite() {
                self.stats.rejected += 1;
                h = shrink_after_blowup(h_try, h_min, *t)?;
                continue;
            }
            // Error of order h³.
            let fac = (SAFETY * err.max(1e-10).powf(-1.0 / 3.0)).clamp(0.2, 5.0);
            if err <= 1.0 {
                self.t_prev = *t;
                self.h_last = h_try;
                self.y_prev.copy_from_slice(y);
                self.f_prev.copy_from_slice(&self.f1);
                *t = if clipped { t_stop } else { *t + h_try };
                y.copy_from_slice(&self.y_new);
                // f(t₁, y₁) evaluated afresh rather than taken from the stage relation: the
                // relation divides the Newton residual by h·d, which at loose tolerances feeds
                // a wrong slope into the next step (seen as blow-up on stiff axial fields).
                f.eval(*t, y, &mut self.f1);
                self.stats.rhs_evals += 1;
                self.stats.steps += 1;
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
