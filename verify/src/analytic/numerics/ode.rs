//! Dormand–Prince 5(4) adaptive Runge–Kutta integrator (Dormand & Prince 1980, J. Comp. Appl.
//! Math. 6; coefficients as in Hairer, Nørsett & Wanner, "Solving ODEs I", table 5.2).
//!
//! Local extrapolation (the 5th-order solution is propagated), error estimated against the
//! embedded 4th-order solution in the weighted RMS norm
//! `sqrt(mean((e_i / (atol + rtol max(|y_i|, |y_new_i|)))²))`, step control
//! `h ← h · clamp(0.9 err^(-1/5), 0.2, 5)`. The integrator always lands exactly on the requested
//! end time, so callers put discontinuities of the right-hand side at the ends of [`Dopri5::advance`]
//! calls and keep each call's right-hand side smooth.
//!
//! Scratch buffers are allocated once in [`Dopri5::new`]; stepping allocates nothing.

use serde::Serialize;

use crate::analytic::error::{AnalyticError, Result};

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
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
// Error weights: (5th-order b) − (embedded 4th-order b̂).
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;

/// Work counters of an integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct OdeStats {
    pub accepted_steps: usize,
    pub rejected_steps: usize,
    pub rhs_evaluations: usize,
}

/// Adaptive Dormand–Prince 5(4) integrator for `y' = f(t, y)`.
#[derive(Debug, Clone)]
pub struct Dopri5 {
    rtol: f64,
    atol: f64,
    max_steps: usize,
    h: f64,
    k: [Vec<f64>; 7],
    y_stage: Vec<f64>,
    y_new: Vec<f64>,
    pub stats: OdeStats,
}

impl Dopri5 {
    /// Integrator for a system of dimension `dim` with relative / absolute tolerances.
    pub fn new(dim: usize, rtol: f64, atol: f64) -> Self {
        Dopri5 {
            rtol,
            atol,
            max_steps: 1_000_000,
            h: 0.0,
            k: std::array::from_fn(|_| vec![0.0; dim]),
            y_stage: vec![0.0; dim],
            y_new: vec![0.0; dim],
            stats: OdeStats::default(),
        }
    }

    /// Integrates from `*t` to `t_end` (> `*t`), updating `t` and `y` in place.
    pub fn advance<F>(&mut self, f: &mut F, t: &mut f64, y: &mut [f64], t_end: f64) -> Result<()>
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let n = y.len();
        assert_eq!(n, self.y_new.len(), "state dimension mismatch");
        if t_end <= *t {
            return Ok(());
        }
        let span = t_end - *t;
        if self.h <= 0.0 {
            // Small first step; the controller grows it by up to 5× per step.
            self.h = span * 1e-3;
        }
        // The first stage is always recomputed at the start of a call: the caller may have
        // switched the right-hand side (a breakpoint of a torque law) since the last call.
        f(*t, y, &mut self.k[0]);
        self.stats.rhs_evaluations += 1;
        let mut steps = 0usize;
        while *t < t_end {
            steps += 1;
            if steps > self.max_steps {
                return Err(AnalyticError::TooManySteps {
                    t: *t,
                    max_steps: self.max_steps,
                });
            }
            let remaining = t_end - *t;
            let last = self.h >= remaining;
            let h = if last { remaining } else { self.h };
            if h <= 1e-14 * t.abs().max(span) {
                return Err(AnalyticError::StepSizeTooSmall { t: *t, h });
            }
            let err = self.try_step(f, *t, y, h);
            if err.is_finite() && err <= 1.0 {
                self.stats.accepted_steps += 1;
                *t = if last { t_end } else { *t + h };
                y.copy_from_slice(&self.y_new);
                // FSAL: the 7th stage is f(t + h, y_new).
                let (first, rest) = self.k.split_at_mut(1);
                first[0].copy_from_slice(&rest[5]);
                let fac = if err == 0.0 {
                    5.0
                } else {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
                };
                // Do not let the artificially short last step shrink the step for the next call.
                self.h = if last { self.h.max(h * fac) } else { h * fac };
            } else {
                self.stats.rejected_steps += 1;
                let fac = if err.is_finite() {
                    (0.9 * err.powf(-0.2)).clamp(0.1, 0.9)
                } else {
                    0.1
                };
                self.h = h * fac;
            }
        }
        Ok(())
    }

    /// One trial step of size h from (t, y); fills `y_new` and k2..k7, returns the error norm.
    fn try_step<F>(&mut self, f: &mut F, t: f64, y: &[f64], h: f64) -> f64
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let n = y.len();
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let ys = &mut self.y_stage;
        for i in 0..n {
            ys[i] = y[i] + h * A21 * k1[i];
        }
        f(t + C2 * h, ys, k2);
        for i in 0..n {
            ys[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        f(t + C3 * h, ys, k3);
        for i in 0..n {
            ys[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        f(t + C4 * h, ys, k4);
        for i in 0..n {
            ys[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        f(t + C5 * h, ys, k5);
        for i in 0..n {
            ys[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        f(t + h, ys, k6);
        let yn = &mut self.y_new;
        for i in 0..n {
            yn[i] = y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i]);
        }
        f(t + h, yn, k7);
        self.stats.rhs_evaluations += 6;
        let mut sum = 0.0;
        for i in 0..n {
            let e =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let scale = self.atol + self.rtol * y[i].abs().max(yn[i].abs());
            sum += (e / scale).powi(2);
        }
        if yn.iter().any(|v| !v.is_finite()) {
            return f64::INFINITY;
        }
        (sum / n as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ana_dopri5_harmonic_oscillator_tight_tolerance() {
        // y'' = -y over 10 periods; exact y = cos t.
        let mut f = |_t: f64, y: &[f64], d: &mut [f64]| {
            d[0] = y[1];
            d[1] = -y[0];
        };
        let mut solver = Dopri5::new(2, 1e-13, 1e-15);
        let mut y = [1.0, 0.0];
        let mut t = 0.0;
        let t_end = 20.0 * std::f64::consts::PI;
        solver.advance(&mut f, &mut t, &mut y, t_end).unwrap();
        assert_eq!(t, t_end);
        // Local error 1e-13 per step, accumulated over a few hundred steps: global < 1e-10.
        assert!((y[0] - 1.0).abs() < 1e-10, "y = {y:?}");
        assert!(y[1].abs() < 1e-10, "y = {y:?}");
        assert!(solver.stats.accepted_steps > 0);
    }

    #[test]
    fn ana_dopri5_error_falls_with_tolerance() {
        // Global error of the tolerance-controlled method is roughly proportional to tol:
        // tightening tol by 1e4 must cut the error by at least 1e2 (loose because of the
        // step-size heuristics).
        let err_at = |tol: f64| {
            let mut f = |t: f64, y: &[f64], d: &mut [f64]| d[0] = y[0] * t.cos();
            let mut s = Dopri5::new(1, tol, tol * 1e-3);
            let mut y = [1.0];
            let mut t = 0.0;
            s.advance(&mut f, &mut t, &mut y, 10.0).unwrap();
            (y[0] - 10f64.sin().exp()).abs()
        };
        let e1 = err_at(1e-6);
        let e2 = err_at(1e-10);
        assert!(e2 < e1 * 1e-2, "e1 = {e1:e}, e2 = {e2:e}");
        assert!(e2 < 1e-8);
    }

    #[test]
    fn ana_dopri5_reports_blow_up() {
        // y' = y², y(0) = 1 blows up at t = 1.
        let mut f = |_t: f64, y: &[f64], d: &mut [f64]| d[0] = y[0] * y[0];
        let mut s = Dopri5::new(1, 1e-10, 1e-12);
        let mut y = [1.0];
        let mut t = 0.0;
        let r = s.advance(&mut f, &mut t, &mut y, 2.0);
        assert!(r.is_err());
        assert!(t < 1.0 + 1e-9);
    }
}
