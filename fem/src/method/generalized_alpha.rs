//! Implicit generalized-α (Chung–Hulbert parameters from ρ∞, Arnold–Brüls form).
//!
//! The equation of motion is enforced at t_{n+1}; pseudo-acceleration a with
//! (1−α_m) a_{n+1} + α_m a_n = (1−α_f) q̈_{n+1} + α_f q̈_n,
//! q_{n+1} = q_n + h q̇_n + h²(½ − β) a_n + h²β a_{n+1}, q̇_{n+1} = q̇_n + h(1−γ) a_n + hγ a_{n+1}.
//! The unknown q̈_{n+1} is found by (quasi-)Newton with the Newton matrix
//! S = M + γ′C + β′K (γ′ = hγ(1−α_f)/(1−α_m), β′ = h²β(1−α_f)/(1−α_m)) of
//! [`crate::method::newton`], factorized once per step and reused across the iterations. With
//! ρ∞ = 1 this is the trapezoidal rule, which conserves the energy of linear systems exactly.
//! Fixed step, or adaptive when `rtol` is given: local error estimate
//! e = h²(β − 1/6)(q̈_{n+1} − q̈_n) (Zienkiewicz–Xie), step ratio 0.9·err^(−1/3) ∈ [0.2, 2]
//! (applied by the driver).

use crate::chain::NewtonCoefficients;
use crate::error::FemError;
use crate::linalg::max_abs;
use crate::method::{StepConstraint, StepContext, Stepper, refuse_constraint};

#[derive(Debug, Clone, Copy)]
struct AlphaParams {
    alpha_m: f64,
    alpha_f: f64,
    gamma: f64,
    beta: f64,
}

impl AlphaParams {
    fn from_rho(rho: f64) -> Self {
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        AlphaParams {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }
}

/// Generalized-α with spectral radius ρ∞ at infinity.
#[derive(Debug, Clone)]
pub struct GeneralizedAlpha {
    params: AlphaParams,
}

impl GeneralizedAlpha {
    pub fn new(rho_inf: f64) -> Self {
        GeneralizedAlpha {
            params: AlphaParams::from_rho(rho_inf),
        }
    }
}

impl Stepper for GeneralizedAlpha {
    fn step(
        &mut self,
        cx: &mut StepContext<'_>,
        constraint: Option<&mut dyn StepConstraint>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Option<f64>, FemError> {
        refuse_constraint("generalized-alpha", constraint.is_some())?;
        let st = &mut *cx.state;
        let AlphaParams {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        } = self.params;
        let r = (1.0 - alpha_f) / (1.0 - alpha_m);
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: h * gamma * r,
            c_q: h * h * beta * r,
        };
        let n = st.q.len();
        // Predictor: constant displacement q_{n+1} = q_n + h q̇_n (a_{n+1} = −(½ − β)/β a_n).
        // Robust for stiff starts (a released pre-loaded spring gives a mesh-dependent q̈₀ spike
        // that a constant-acceleration predictor would turn into a huge first iterate).
        for i in 0..n {
            let a_pred = -(0.5 - beta) / beta * st.a[i];
            st.qdd1[i] = (a_pred - (alpha_f * st.qdd[i] - alpha_m * st.a[i]) / (1.0 - alpha_m)) / r;
        }
        let mut converged = false;
        let mut last = f64::INFINITY;
        let mut iterations = 0;
        for it in 0..30 {
            for i in 0..n {
                st.a1[i] =
                    (alpha_f * st.qdd[i] - alpha_m * st.a[i]) / (1.0 - alpha_m) + r * st.qdd1[i];
                st.q1[i] =
                    st.q[i] + h * st.qd[i] + h * h * ((0.5 - beta) * st.a[i] + beta * st.a1[i]);
                st.qd1[i] = st.qd[i] + h * ((1.0 - gamma) * st.a[i] + gamma * st.a1[i]);
            }
            if converged {
                break;
            }
            cx.chain
                .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
            cx.counters.rhs += 1;
            cx.counters.newton += 1;
            cx.newton
                .form_if_due(it, h, cx.chain, st, cx.counters, c, t1)?;
            cx.newton.delta.copy_from_slice(&cx.newton.res);
            cx.newton.solve();
            let mut big = 0.0f64;
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
                big = big.max(cx.newton.delta[i].abs());
            }
            let dq = big * c.c_q;
            if !dq.is_finite() {
                break;
            }
            if it > 2 && dq > 10.0 * last {
                // Diverging: give up early, the caller retries with a shorter step.
                break;
            }
            last = dq;
            // Absolute tolerance, floored at the round-off level of the update itself.
            let amax = max_abs(&st.qdd1);
            let vmax = max_abs(&st.qd1);
            iterations = it + 1;
            if dq <= cx.newton.tol + 1e-13 * (c.c_q * amax + h * vmax) {
                converged = true;
            }
        }
        cx.newton.slow_convergence = !converged || iterations > 3;
        if !converged {
            if cx.adaptive.is_some() || h > 1e-6 * cx.h_nominal {
                return Ok(Some(f64::INFINITY));
            }
            return Err(FemError::Runaway {
                t: st.t,
                what: format!("Newton iteration did not converge (last update {last:.3e})"),
                location: None,
                why: "the step is too large for the nonlinearity or the solution diverged".into(),
                remedy: "reduce --dt or give --rtol for adaptive stepping".into(),
            });
        }
        Ok(cx.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..n {
                let e = h * h * (beta - 1.0 / 6.0) * (st.qdd1[i] - st.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
            }
            err
        }))
    }
}
