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
//!
//! **Held contact** ([`StepConstraint`], [`crate::events::contact`]): the momentum equation
//! gains the constraint force, R(q̄, v̄, ā, t_mid) − ∇̄g λ = 0, and the unknowns become (ā, λ)
//! with g(q₁) = target at the step end (index 3; the target is 0, or for a step shortened to
//! locate an event (1 − (h/h_nominal)²)·g(q₀), as in [`crate::method::energy_midpoint`]).
//! Since q₁ = q₀ + h q̇₀ + (h²/2) ā, ∂q₁/∂ā = h²/2, the border of the bordered Newton update
//! ([`StepConstraint::newton_update`], Schur complement, two solves of S per iteration; three
//! while a friction contact sticks). The force uses the Gonzalez discrete gradient ∇̄g in the
//! metric W = M(q̄), as energy-midpoint does, not ∇g(q̄): then Δqᵀ∇̄g = g(q₁) − g(q₀) exactly,
//! the held constraint does no work in the discrete step, and the run's energy error stays the
//! rule's own O(h²) error of the configuration-dependent mass (the driver's trapezoidal
//! works), with no constraint work added to it. It costs one inertial pass (W Δq) per
//! constrained iteration. Friction on a bilateral wall (sliding force −μsσλ̄T(q̄), the stick
//! constraint with its own discrete gradient, friction work D = μsσλ̄ΔqᵀT(q̄) booked per step)
//! comes from the same constraint object. A constrained step accepts the iterate at which the
//! residual and the gap were evaluated (the update below tolerance, |g(q₁) − target| within
//! the Newton tolerance): its multipliers and friction work are those of the accepted state.
//! The constraint force enters through λ only (its dependence on ā through ∇̄g(q̄) is not in
//! S), so a constrained step converges linearly at the rate λh²|∇²g|/|M|.

use crate::error::FemError;
use crate::linalg::max_abs;
use crate::method::{
    Trial,
    Capabilities, HeldConstraint, MethodParams, StepConstraint, StepContext, Stepper, unconverged,
    update_tolerance,
};
use crate::system::{NewtonCoefficients, System};

/// Newton iterations at most before the step is retried shorter.
const MAX_ITERATIONS: usize = 30;

/// The implicit midpoint rule. The previous mean acceleration, kept in the state's q̈ slot, is
/// the Newton predictor; the buffers serve a held constraint (allocated once per run).
#[derive(Debug, Clone)]
pub struct ImplicitMidpoint {
    /// Step end q₁ = 2q̄ − q₀ of the iterate (q̄ lives in the state's trial-end slot).
    q_end: Vec<f64>,
    held: HeldConstraint,
}

impl From<MethodParams> for ImplicitMidpoint {
    fn from(p: MethodParams) -> Self {
        ImplicitMidpoint::new(p.n)
    }
}

impl ImplicitMidpoint {
    /// Registry entry: what the method supports.
    pub const CAPABILITIES: Capabilities = Capabilities {
        explicit: false,
        adaptive: true,
        prescribed_joints: true,
        held_constraint: true,
        bilateral_constraint: true,
        projects_massless: false,
        variable_mass: true,
    };

    /// The method for `n` DOFs.
    pub fn new(n: usize) -> Self {
        ImplicitMidpoint {
            q_end: vec![0.0; n],
            held: HeldConstraint::new(n),
        }
    }
}

impl<S: System + ?Sized> Stepper<S> for ImplicitMidpoint {
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        mut constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Trial, FemError> {
        let st = &mut *cx.state;
        let n = st.q.len();
        let t0 = st.t;
        let t_mid = st.t + 0.5 * h;
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.5 * h,
            c_q: 0.25 * h * h,
        };
        // Held constraint: g(q₀), the multiplier's start value (the last step's) and the
        // target of g(q₁) (module docs).
        let g0 = constraint
            .as_ref()
            .map_or(0.0, |k| k.value(cx.system, t0, &st.q));
        let mut lambda = constraint.as_ref().map_or(0.0, |k| k.multiplier());
        let r = (h / cx.h_nominal).min(1.0);
        let gap_target = g0 * (1.0 - r * r);
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
            cx.system
                .residual(t_mid, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
            cx.counters.rhs += 1;
            cx.counters.newton += 1;
            cx.newton
                .form_if_due(it, h, cx.system, st, cx.counters, c, t1)?;
            let mut dlambda = 0.0;
            let mut on_surface = true;
            if let Some(k) = constraint.as_deref_mut() {
                let held = &mut self.held;
                for i in 0..n {
                    held.dq[i] = 2.0 * (st.q1[i] - st.q[i]);
                    self.q_end[i] = st.q[i] + held.dq[i];
                }
                let gap1 = held.force(
                    cx.system,
                    cx.counters,
                    k,
                    it,
                    [t0, t_mid, t1],
                    (&st.q, &self.q_end, &st.q1),
                    (g0, lambda),
                    &cx.newton.res,
                );
                on_surface = (gap1 - gap_target).abs() <= cx.newton.tol;
                dlambda = k.newton_update(cx.newton, &held.res, 0.5 * h * h, gap1, gap_target);
            } else {
                cx.newton.delta.copy_from_slice(&cx.newton.res);
                cx.newton.solve();
            }
            let dq = max_abs(&cx.newton.delta) * c.c_q;
            if constraint.is_some() {
                if !dq.is_finite() || (it > 2 && dq > 10.0 * last) {
                    break;
                }
                last = dq;
                iterations = it + 1;
                let tol = update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1);
                // Accept the iterate where the residual and the gap were evaluated (module
                // docs): its multipliers and friction work are the constraint's current ones.
                if dq <= tol && on_surface {
                    converged = true;
                    break;
                }
                for i in 0..n {
                    st.qdd1[i] -= cx.newton.delta[i];
                }
                lambda -= dlambda;
                continue;
            }
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
            }
            if !dq.is_finite() || (it > 2 && dq > 10.0 * last) {
                // Not finite or diverging: the driver retries with a shorter step.
                break;
            }
            last = dq;
            iterations = it + 1;
            // Absolute tolerance on the position update, floored at its round-off level.
            if dq <= update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1) {
                converged = true;
                break;
            }
        }
        if let Some(k) = constraint.filter(|_| converged) {
            k.set_multiplier(lambda);
        }
        cx.newton.slow_convergence = !converged || iterations > 3;
        if !converged {
            return unconverged(cx.adaptive.is_some(), cx.h_nominal, st.t, h, last, "");
        }
        for i in 0..n {
            let v_bar = st.qd[i] + 0.5 * h * st.qdd1[i];
            st.q1[i] = st.q[i] + h * v_bar;
            st.qd1[i] = st.qd[i] + h * st.qdd1[i];
        }
        st.a1.copy_from_slice(&st.qdd1);
        // Joint torques (laws and required torques) at the end point, for the ledger.
        cx.system
            .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
        cx.counters.rhs += 1;
        Ok(Trial::Converged {
            error: cx.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..n {
                let e = h * h / 12.0 * (st.qdd1[i] - st.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
            }
            err
            }),
        })
    }
}
