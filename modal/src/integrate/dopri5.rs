//! Dormand–Prince 5(4) with FSAL, PI step control and Hairer's 4th-order dense output.

use super::{
    Build, IntegrateError, MethodInfo, OdeRhs, StepStats, Stepper, StopReason, Tolerances,
    clip_step, error_norm, initial_step, min_step, next_step, shrink_after_blowup, stop_reason,
};

// Butcher tableau (Dormand & Prince 1980).
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Difference between the 5th- and 4th-order weights.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Continuous extension (Hairer's DOPRI5 CONTD5 coefficients).
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

// PI controller: β = 0.08 (Hairer's recommendation when the step is stability-limited, as in
// undamped modal chains), exponent 1/5 − 0.75β, safety 0.9.
const BETA: f64 = 0.08;
const EXPO1: f64 = 0.2 - BETA * 0.75;
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2; // largest decrease per step
const FAC_MAX: f64 = 10.0; // largest increase per step

/// Registry entry ([`super::method_for`]).
pub const DOPRI5: MethodInfo = MethodInfo {
    method: data::ModalMethod::Dopri5,
    name: "dopri5",
    build: Build::Adaptive(|dim, tol, h_init| Box::new(Dopri5::new(dim, tol, h_init, None))),
    needs_oscillators: false,
};

/// Adaptive Dormand–Prince 5(4) integrator (see the module docs).
#[derive(Debug, Clone)]
pub struct Dopri5 {
    tol: Tolerances,
    h_init: Option<f64>,
    h_max: f64,
    /// Step proposed for the next attempt (None: estimate on the next call).
    h: Option<f64>,
    err_old: f64,
    /// f(t, y) at the start of the next step is valid (FSAL).
    have_k1: bool,
    k1: Vec<f64>,
    k2: Vec<f64>,
    k3: Vec<f64>,
    k4: Vec<f64>,
    k5: Vec<f64>,
    k6: Vec<f64>,
    k7: Vec<f64>,
    y_stage: Vec<f64>,
    y_new: Vec<f64>,
    err: Vec<f64>,
    // Dense output of the last accepted step.
    rcont: [Vec<f64>; 5],
    t_prev: f64,
    h_last: f64,
    stats: StepStats,
}

impl Dopri5 {
    pub fn new(dim: usize, tol: Tolerances, h_init: Option<f64>, h_max: Option<f64>) -> Self {
        let z = || vec![0.0; dim];
        Dopri5 {
            tol,
            h_init,
            h_max: h_max.unwrap_or(f64::INFINITY),
            h: h_init,
            err_old: 1e-4,
            have_k1: false,
            k1: z(),
            k2: z(),
            k3: z(),
            k4: z(),
            k5: z(),
            k6: z(),
            k7: z(),
            y_stage: z(),
            y_new: z(),
            err: z(),
            rcont: [z(), z(), z(), z(), z()],
            t_prev: 0.0,
            h_last: 0.0,
            stats: StepStats::default(),
        }
    }

    pub fn stats(&self) -> &StepStats {
        &self.stats
    }

    pub fn tolerances(&self) -> Tolerances {
        self.tol
    }

    /// Size of the last accepted step.
    pub fn last_step(&self) -> f64 {
        self.h_last
    }

    /// Forget the FSAL stage and the controller history (call after a discontinuity in f or a
    /// jump in y). The step size proposal is kept: it is still a good scale.
    pub fn reset(&mut self) {
        self.have_k1 = false;
        self.err_old = 1e-4;
    }

    /// Advances one accepted step, never past `t_stop`. Updates `t` and `y`.
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
        if !self.have_k1 {
            f.eval(*t, y, &mut self.k1);
            self.stats.rhs_evals += 1;
            self.have_k1 = true;
        }
        if !self.k1.iter().all(|v| v.is_finite()) {
            return Err(IntegrateError::NonFinite { t: *t });
        }
        let mut h = match self.h {
            Some(h) => h,
            None => {
                let h = initial_step(
                    f,
                    &self.tol,
                    5,
                    *t,
                    y,
                    &self.k1,
                    &mut self.y_stage,
                    &mut self.k2,
                    self.h_max,
                    span,
                );
                self.stats.rhs_evals += 1;
                h
            }
        };
        h = h.min(self.h_max);
        let h_min = min_step(*t, span);
        loop {
            let (h_try, clipped) = clip_step(h, span, h_min, *t)?;
            self.stages(f, *t, y, h_try);
            for i in 0..n {
                self.err[i] = h_try
                    * (E1 * self.k1[i]
                        + E3 * self.k3[i]
                        + E4 * self.k4[i]
                        + E5 * self.k5[i]
                        + E6 * self.k6[i]
                        + E7 * self.k7[i]);
            }
            let err = error_norm(&self.tol, y, &self.y_new, &self.err);
            if !err.is_finite() {
                // Blow-up inside the step: shrink hard and retry.
                self.stats.rejected += 1;
                h = shrink_after_blowup(h_try, h_min, *t)?;
                continue;
            }
            if err <= 1.0 {
                // Accepted: PI controller for the next step.
                let fac11 = err.max(1e-16).powf(EXPO1);
                let fac =
                    (fac11 / self.err_old.powf(BETA) / SAFETY).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                let h_next = h_try / fac;
                self.err_old = err.max(1e-4);
                self.fill_dense(y, h_try);
                self.t_prev = *t;
                self.h_last = h_try;
                *t = if clipped { t_stop } else { *t + h_try };
                y.copy_from_slice(&self.y_new);
                std::mem::swap(&mut self.k1, &mut self.k7); // FSAL
                self.stats.steps += 1;
                self.h = Some(next_step(h_next, h, h_try, clipped, self.h_max));
                return Ok(());
            }
            self.stats.rejected += 1;
            let fac11 = err.powf(EXPO1);
            h = h_try / (fac11 / SAFETY).min(1.0 / FAC_MIN);
        }
    }

    fn stages<F: OdeRhs + ?Sized>(&mut self, f: &mut F, t: f64, y: &[f64], h: f64) {
        let n = y.len();
        let ys = &mut self.y_stage;
        for i in 0..n {
            ys[i] = y[i] + h * A21 * self.k1[i];
        }
        f.eval(t + C2 * h, ys, &mut self.k2);
        for i in 0..n {
            ys[i] = y[i] + h * (A31 * self.k1[i] + A32 * self.k2[i]);
        }
        f.eval(t + C3 * h, ys, &mut self.k3);
        for i in 0..n {
            ys[i] = y[i] + h * (A41 * self.k1[i] + A42 * self.k2[i] + A43 * self.k3[i]);
        }
        f.eval(t + C4 * h, ys, &mut self.k4);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A51 * self.k1[i] + A52 * self.k2[i] + A53 * self.k3[i] + A54 * self.k4[i]);
        }
        f.eval(t + C5 * h, ys, &mut self.k5);
        for i in 0..n {
            ys[i] = y[i]
                + h * (A61 * self.k1[i]
                    + A62 * self.k2[i]
                    + A63 * self.k3[i]
                    + A64 * self.k4[i]
                    + A65 * self.k5[i]);
        }
        f.eval(t + h, ys, &mut self.k6);
        for i in 0..n {
            self.y_new[i] = y[i]
                + h * (A71 * self.k1[i]
                    + A73 * self.k3[i]
                    + A74 * self.k4[i]
                    + A75 * self.k5[i]
                    + A76 * self.k6[i]);
        }
        f.eval(t + h, &self.y_new, &mut self.k7);
        self.stats.rhs_evals += 6;
    }

    fn fill_dense(&mut self, y: &[f64], h: f64) {
        let [r1, r2, r3, r4, r5] = &mut self.rcont;
        for i in 0..y.len() {
            let dy = self.y_new[i] - y[i];
            let bspl = h * self.k1[i] - dy;
            r1[i] = y[i];
            r2[i] = dy;
            r3[i] = bspl;
            r4[i] = dy - h * self.k7[i] - bspl;
            r5[i] = h
                * (D1 * self.k1[i]
                    + D3 * self.k3[i]
                    + D4 * self.k4[i]
                    + D5 * self.k5[i]
                    + D6 * self.k6[i]
                    + D7 * self.k7[i]);
        }
    }

    /// Dense output inside the last accepted step [t_prev, t]: writes y(t_out).
    pub fn dense(&self, t_out: f64, out: &mut [f64]) {
        let s = if self.h_last > 0.0 {
            (t_out - self.t_prev) / self.h_last
        } else {
            0.0
        };
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5] = &self.rcont;
        for i in 0..out.len() {
            out[i] = r1[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * r5[i])));
        }
    }

    /// Start time of the last accepted step.
    pub fn t_prev(&self) -> f64 {
        self.t_prev
    }

    /// The initial step this integrator was created with.
    pub fn h_init(&self) -> Option<f64> {
        self.h_init
    }
}

impl Stepper for Dopri5 {
    fn step(
        &mut self,
        f: &mut dyn OdeRhs,
        t: &mut f64,
        y: &mut [f64],
        t_stop: f64,
    ) -> Result<StopReason, IntegrateError> {
        Dopri5::step(self, f, t, y, t_stop)?;
        Ok(stop_reason(*t, t_stop))
    }
    fn dense(&self, t_out: f64, out: &mut [f64]) {
        Dopri5::dense(self, t_out, out)
    }
    fn stats(&self) -> StepStats {
        self.stats
    }
    fn last_step(&self) -> f64 {
        self.h_last
    }
    fn reset(&mut self) {
        Dopri5::reset(self)
    }
}
