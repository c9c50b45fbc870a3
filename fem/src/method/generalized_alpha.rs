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
//!
//! **Held contact** ([`StepConstraint`], [`crate::events::contact`]): the residual at t₁ gains
//! the constraint force, R(q₁, q̇₁, q̈₁, t₁) − ∇̄g λ = 0, and the unknowns become (q̈₁, λ) with
//! g(q₁) at its target (index 3; the target is 0, or (1 − (h/h_nominal)²)·g(q₀) on a step
//! shortened to locate an event, as in the midpoint schemes). The border factor is
//! ∂q₁/∂q̈₁ = h²β(1−α_f)/(1−α_m). The force direction is the Gonzalez discrete gradient ∇̄g of
//! q₀ → q₁ in the metric M(q̄) (the midpoint schemes' choice: the held constraint does no work
//! over the step); it differs from ∇g(q₁) by O(h). A constrained step accepts the iterate at
//! which the residual and the gap were evaluated, so that λ and the friction work belong to
//! the accepted state.
//!
//! **Work balance.** With ρ∞ = 1 the method is the trapezoidal rule: over a step it realizes
//! the work Δq·½(F₀ + F₁) of the constraint force F applied at the step start (the previous
//! step's end force, or the restart's) and end. The discrete gradient makes Δq·F₁ the work the
//! ledger books (zero for the normal force on the surface, the friction work otherwise), but
//! Δq·F₀ is of the previous step's direction: O(h²) per held step, O(h) over a held phase.
//! So the end force gains c·WΔq, W = M(q̄), with c·ΔqᵀWΔq = Δq·F₁ − Δq·F₀: the average then
//! does the work Δq·F₁ of the end force, and the ledger closes to the rule's own energy error
//! (a consistent O(h) correction along the step's own motion, not in the Newton matrix). For
//! ρ∞ < 1 the same correction is applied; the method's weights of F₀ and F₁ then differ from ½
//! by O(1 − ρ∞), and the balance holds to that order.
//!
//! **Restarts.** The method carries the acceleration history (q̈ₙ, aₙ) from step to step. An
//! impact changes q̇, a contact start or release changes the force law, and a history from
//! before the event is not that of the motion after it: the first step after the event would
//! create energy (docs/contact.md). So once a run has held a constraint, after every event
//! ([`Stepper::restart`]) and at the first held step, q̈ₙ = aₙ is recomputed consistent with
//! the current phase:
//! R(qₙ, q̇ₙ, q̈ₙ) − ∇g(qₙ) λₙ = 0 with the constraint's multiplier λₙ (the index-1 normal
//! force the driver computes at each contact event; the friction force or stick multiplier of
//! the current friction phase), by Newton with S = M.

use crate::error::FemError;
use crate::method::start::EventRestart;
use crate::linalg::{dot, max_abs};
use crate::method::{
    Trial,
    Capabilities, HeldConstraint, MethodParams, StepConstraint, StepContext, Stepper, Works,
    unconverged, update_tolerance,
};
use crate::system::{NewtonCoefficients, System};

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

/// Newton iterations at most before the step is retried shorter.
const MAX_ITERATIONS: usize = 30;

/// Generalized-α with spectral radius ρ∞ at infinity. The buffers serve a held constraint
/// (allocated once per run).
#[derive(Debug, Clone)]
pub struct GeneralizedAlpha {
    params: AlphaParams,
    /// When the acceleration history is made consistent with the phase (module docs).
    restart: EventRestart,
    /// q̄ = (q₀ + q₁)/2 of the iterate.
    q_mid: Vec<f64>,
    held: HeldConstraint,
    /// The constraint (and friction) force the method applied at the step start: the last
    /// accepted step's end force, or the restart's (module docs, work balance).
    force_start: Vec<f64>,
    /// The end force of the step being solved; the start force of the next once accepted.
    force_end: Vec<f64>,
}

impl From<MethodParams> for GeneralizedAlpha {
    fn from(p: MethodParams) -> Self {
        GeneralizedAlpha::new(p.rho_inf, p.n)
    }
}

impl GeneralizedAlpha {
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

    /// The method with spectral radius `rho_inf` for `n` DOFs.
    pub fn new(rho_inf: f64, n: usize) -> Self {
        GeneralizedAlpha {
            params: AlphaParams::from_rho(rho_inf),
            restart: EventRestart::new(n),
            q_mid: vec![0.0; n],
            held: HeldConstraint::new(n),
            force_start: vec![0.0; n],
            force_end: vec![0.0; n],
        }
    }
}

impl<S: System + ?Sized> Stepper<S> for GeneralizedAlpha {
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        mut constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Trial, FemError> {
        self.restart.apply(
            cx,
            constraint.as_deref_mut(),
            h,
            &mut self.force_start,
            "generalized-alpha",
        )?;
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
        // Held constraint: g(q₀), the multiplier's start value (the last step's) and the
        // target of g(q₁) (module docs).
        let t0 = st.t;
        let t_mid = t0 + 0.5 * h;
        let g0 = constraint
            .as_ref()
            .map_or(0.0, |k| k.value(cx.system, t0, &st.q));
        let mut lambda = constraint.as_ref().map_or(0.0, |k| k.multiplier());
        let shortened = (h / cx.h_nominal).min(1.0);
        let gap_target = g0 * (1.0 - shortened * shortened);
        let mut converged = false;
        let mut last = f64::INFINITY;
        let mut iterations = 0;
        for it in 0..MAX_ITERATIONS {
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
            cx.system
                .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
            cx.counters.rhs += 1;
            cx.counters.newton += 1;
            cx.newton
                .form_if_due(it, h, cx.system, st, cx.counters, c, t1)?;
            if let Some(k) = constraint.as_deref_mut() {
                let held = &mut self.held;
                for i in 0..n {
                    held.dq[i] = st.q1[i] - st.q[i];
                    self.q_mid[i] = st.q[i] + 0.5 * held.dq[i];
                }
                let gap1 = held.force(
                    cx.system,
                    cx.counters,
                    k,
                    it,
                    [t0, t_mid, t1],
                    (&st.q, &st.q1, &self.q_mid),
                    (g0, lambda),
                    &cx.newton.res,
                );
                // Work balance (module docs): the end force gains c·WΔq so that the step's
                // average of the start and end forces does the work of the end force alone.
                let (mut work_end, mut work_start) = (0.0, 0.0);
                for i in 0..n {
                    work_end += held.dq[i] * (cx.newton.res[i] - held.res[i]);
                    work_start += held.dq[i] * self.force_start[i];
                }
                let denom = dot(&held.dq, &held.w_dq);
                let c_balance = if denom > 0.0 {
                    (work_end - work_start) / denom
                } else {
                    0.0
                };
                for i in 0..n {
                    held.res[i] -= c_balance * held.w_dq[i];
                }
                let on_surface = (gap1 - gap_target).abs() <= cx.newton.tol;
                let dlambda = k.newton_update(cx.newton, &held.res, c.c_q, gap1, gap_target);
                let dq = max_abs(&cx.newton.delta) * c.c_q;
                if !dq.is_finite() || (it > 2 && dq > 10.0 * last) {
                    break;
                }
                last = dq;
                iterations = it + 1;
                let tol = update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1);
                // Accept the iterate where the residual and the gap were evaluated (module
                // docs): its multipliers and friction work are the constraint's current ones.
                if dq <= tol && on_surface {
                    for i in 0..n {
                        self.force_end[i] = cx.newton.res[i] - held.res[i];
                    }
                    converged = true;
                    break;
                }
                for i in 0..n {
                    st.qdd1[i] -= cx.newton.delta[i];
                }
                lambda -= dlambda;
                continue;
            }
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
            iterations = it + 1;
            if dq <= update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1) {
                converged = true;
            }
        }
        if let Some(k) = constraint.filter(|_| converged) {
            k.set_multiplier(lambda);
        }
        cx.newton.slow_convergence = !converged || iterations > 3;
        if !converged {
            return unconverged(cx.adaptive.is_some(), cx.h_nominal, st.t, h, last, "");
        }
        Ok(Trial::Converged {
            error: cx.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..n {
                let e = h * h * (beta - 1.0 / 6.0) * (st.qdd1[i] - st.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
            }
            err
            }),
        })
    }

    fn commit(&mut self, _h: f64, _works: &mut Works) -> bool {
        std::mem::swap(&mut self.force_start, &mut self.force_end);
        false
    }

    fn restart(&mut self) {
        self.restart.request();
    }
}
