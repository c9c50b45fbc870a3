//! Implicit midpoint rule on the second-order equations R(q, q̇, q̈, t) = 0.
//!
//! One step t₀ → t₁ = t₀ + h with the mean acceleration ā = (q̇₁ − q̇₀)/h as unknown:
//!
//!   v̄ = q̇₀ + (h/2) ā,   q̄ = q₀ + (h/2) v̄,   R(q̄, v̄, ā, t₀ + h/2) = 0,
//!   q₁ = q₀ + h v̄ = 2q̄ − q₀,   q̇₁ = q̇₀ + h ā,
//!
//! i.e. the one-stage Gauss collocation method (second order, A-stable, symmetric, no
//! numerical damping; symplectic where M is constant). Newton on ā with the matrix
//! S = M + (h/2) C + (h²/4) K at (q̄, v̄, ā) of [`crate::method::newton`] (∂v̄/∂ā = h/2,
//! ∂q̄/∂ā = h²/4). Unlike [`crate::method::energy_midpoint`] it evaluates the equations at the
//! midpoint only: with a configuration-dependent mass M(q) its energy error is O(h²), and the
//! driver books the works with the trapezoidal rule. After convergence one residual pass at
//! the end point leaves the chain's joint torques (the required torque of a prescribed joint)
//! at t₁. Adaptive steps: local error estimate e = (h²/12)(ā_k − ā_{k−1}) (the third-derivative
//! term of the rule), as for the energy-consistent midpoint scheme.

use crate::chain::NewtonCoefficients;
use crate::error::FemError;
use crate::linalg::max_abs;
use crate::method::{StepConstraint, StepContext, Stepper, refuse_constraint};

/// Newton iterations at most before the step is retried shorter.
const MAX_ITERATIONS: usize = 30;

/// The implicit midpoint rule (no state of its own: the previous mean acceleration, kept in
/// the state's q̈ slot, is the Newton predictor).
#[derive(Debug, Clone, Copy)]
pub struct ImplicitMidpoint;

impl Stepper for ImplicitMidpoint {
    fn step(
        &mut self,
        cx: &mut StepContext<'_>,
        constraint: Option<&mut dyn StepConstraint>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Option<f64>, FemError> {
        refuse_constraint("implicit-midpoint", constraint.is_some())?;
        let st = &mut *cx.state;
        let n = st.q.len();
        let t_mid = st.t + 0.5 * h;
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.5 * h,
            c_q: 0.25 * h * h,
        };
        // Predictor: the previous step's mean acceleration (the point value after a start).
        st.qdd1.copy_from_slice(&st.qdd);
        let mut converged = false;
        let mut last = f64::INFINITY;
        let mut iterations = 0;
        for it in 0..MAX_ITERATIONS {
            // The Newton point (q̄, v̄, ā) lives in the trial-end slots while iterating.
            for i in 0..n {
                st.qd1[i] = st.qd[i] + 0.5 * h * st.qdd1[i];
                st.q1[i] = st.q[i] + 0.5 * h * st.qd1[i];
            }
            cx.chain
                .residual(t_mid, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
            cx.counters.rhs += 1;
            cx.counters.newton += 1;
            cx.newton
                .form_if_due(it, h, cx.chain, st, cx.counters, c, t1)?;
            cx.newton.delta.copy_from_slice(&cx.newton.res);
            cx.newton.solve();
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
            }
            let dq = max_abs(&cx.newton.delta) * c.c_q;
            if !dq.is_finite() || (it > 2 && dq > 10.0 * last) {
                // Not finite or diverging: the driver retries with a shorter step.
                break;
            }
            last = dq;
            iterations = it + 1;
            // Absolute tolerance on the position update, floored at its round-off level.
            let amax = max_abs(&st.qdd1);
            let vmax = max_abs(&st.qd1);
            if dq <= cx.newton.tol + 1e-13 * (c.c_q * amax + h * vmax) {
                converged = true;
                break;
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
        for i in 0..n {
            let v_bar = st.qd[i] + 0.5 * h * st.qdd1[i];
            st.q1[i] = st.q[i] + h * v_bar;
            st.qd1[i] = st.qd[i] + h * st.qdd1[i];
        }
        st.a1.copy_from_slice(&st.qdd1);
        // Joint torques (laws and required torques) at the end point, for the ledger.
        cx.chain
            .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
        cx.counters.rhs += 1;
        Ok(cx.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..n {
                let e = h * h / 12.0 * (st.qdd1[i] - st.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
            }
            err
        }))
    }
}
