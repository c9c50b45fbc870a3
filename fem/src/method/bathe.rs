//! Bathe's composite method (Bathe & Baig 2005; Bathe 2007) on R(q, q̇, q̈, t) = 0.
//!
//! One step t₀ → t₁ = t₀ + h is two implicit sub-steps with point accelerations as unknowns:
//!
//! 1. the trapezoidal rule (Newmark β = ¼, γ = ½) over h/2,
//!    q_m = q₀ + (h/2) q̇₀ + (h²/16)(q̈₀ + q̈_m),   q̇_m = q̇₀ + (h/4)(q̈₀ + q̈_m),
//!    R(q_m, q̇_m, q̈_m, t₀ + h/2) = 0;
//! 2. the three-point backward difference through t₀, t₀ + h/2, t₁,
//!    q̇₁ = (q₀ − 4q_m + 3q₁)/h,   q̈₁ = (q̇₀ − 4q̇_m + 3q̇₁)/h,
//!    i.e. q̇₁ = (−q̇₀ + 4q̇_m)/3 + (h/3) q̈₁ and q₁ = (−q₀ + 4q_m)/3 + (h/3) q̇₁,
//!    R(q₁, q̇₁, q̈₁, t₁) = 0.
//!
//! Both sub-steps are affine in their unknown acceleration, q = q_base + c_q q̈ and
//! q̇ = v_base + c_v q̈, so one Newton iteration serves both, with the matrix
//! S = M + c_v C + c_q K of [`crate::method::newton`]: (c_v, c_q) = (h/4, h²/16) in the first,
//! (h/3, h²/9) in the second. Second order; the trapezoidal sub-step alone conserves the energy
//! of a linear system, the backward difference damps what the step does not resolve: the
//! spectral radius of the step tends to 0 as ωh → ∞ (no high-frequency ringing after impacts
//! or releases) while the resolved modes lose little amplitude (O((ωh)⁴) per step). The cost
//! is two Newton solves per step.
//!
//! Adaptive steps: for q̈ = f(t) the step's position error is h³q⃛/24 (sub-step 1 leaves
//! h³q⃛/96 at t₀ + h/2, carried with weight 4/3, plus the backward difference's own), so the
//! local error estimate is e = (h²/24)(q̈₁ − q̈₀).
//!
//! **Works** (ledger): the method books them itself ([`Stepper::commit`]), by the midpoint rule
//! on each sub-step — the non-conservative forces at the sub-step's midpoint time and
//! configuration with its mean velocity v̄ = Δq/(h/2) ([`System::midpoint_works`]); for the
//! trapezoidal sub-step v̄ is exactly the mean of its end velocities, the velocity its linear
//! dampers dissipate with. A rule on the step's end points alone cannot see q_m: on
//! `two-link-free` (16 elements, 1 s) it closed the ledger to 8.3e-4 / 2.1e-4 at dt 2.5e-4 /
//! 6.25e-5, the sub-steps close it to 3.8e-5 / 6.4e-6, for 5 % more run time. A prescribed
//! joint's required torque is not in the DOFs; the driver books it on the end points.
//!
//! **Held contact** ([`StepConstraint`], [`crate::events::contact`]): each sub-step's residual
//! gains the constraint force at its end point, R − ∇̄g λ = 0, with (q̈, λ) as unknowns and
//! the gap at its target at the sub-step end (index 3), so the tip is on the surface at
//! t₀ + h/2 and at t₁. The border factor is the sub-step's c_q (∂q/∂q̈ = h²/16, then h²/9).
//! The force direction is the Gonzalez discrete gradient ∇̄g of the sub-step's own motion
//! (q₀ → q_m, then q_m → q₁) in the metric M(q̄), as in the midpoint schemes: it differs from
//! ∇g at the end point by O(h), and the normal force does no work over either sub-step. The
//! gap targets follow the midpoint schemes' rule for a step shortened to locate an event,
//! g = (1 − (τ/h_nominal)²)·g(q₀) at τ = h/2 and τ = h (0 on a held step, whose g(q₀) is 0).
//! The trapezoidal sub-step starts from q̈₀, so
//! * after an event (an impact, a contact start or a release: [`Stepper::restart`]) q̈₀ is
//!   recomputed consistent with the phase that follows, as generalized-α does:
//!   R(q₀, q̇₀, q̈₀) − ∇g(q₀) λ₀ = 0 with the multiplier of the event (with the stale q̈₀ of
//!   the flight, the first impact of `barhorst-case1` left a ledger residual of 17 J at
//!   dt 6.25e-5);
//! * its average of the start force F₀ (in q̈₀) and the end force F_m does the work
//!   Δq·½(F₀ + F_m), of which the discrete gradient cancels only the end force's part: the
//!   end force gains c·WΔq with c·ΔqᵀWΔq = Δq·F_m − Δq·F₀ (generalized-α's work balance),
//!   so that the average does the end force's work. On `barhorst-case1` (4 elements) the
//!   ledger residual accumulated over the long held phase (0.36–0.93 s) went from −2.8e-3 /
//!   −8.6e-4 J to −2.9e-4 / −4.3e-5 J at dt 1.25e-4 / 3.125e-5.
//!
//! What the closure still shows after an impact is the quadrature of the Kelvin–Voigt work of
//! the mesh's stiffest modes, which the impact excites and which relax at κ = γk⁴/ρA: until
//! κh < 1 the midpoint rule cannot follow that relaxation (the solution's stored energies
//! agree with a fine-step reference; the booked dissipation does not).
//!
//! **Bilateral wall** (Coulomb friction, stick–slip: [`crate::events::contact::friction`]):
//! each sub-step holds the wall and, sliding, applies the friction of its own multiplier; the
//! friction work of the step is the sum over both sub-steps ([`StepConstraint::start_sub_step`]:
//! with the second sub-step's alone the ledger of `constrained-arm` closed to 3.9e-2 over
//! 0.5 s, with both to 5.4e-4). The closure falls at first order (3.8e-4 / 1.9e-4 / 8.9e-5 at
//! dt 2.5e-4 / 1.25e-4 / 6.25e-5 over 0.1 s), as on the unilateral contact's held phases: the
//! backward difference has no energy identity for the constraint forces. For a ledger,
//! energy-midpoint.

use crate::error::FemError;
use crate::method::start::EventRestart;
use crate::linalg::{dot, max_abs};
use crate::method::{
    Trial,
    Capabilities, HeldConstraint, MethodParams, StepConstraint, StepContext,
    StepState, Stepper, Works, unconverged, update_tolerance,
};
use crate::system::Parts;
use crate::system::{NewtonCoefficients, System};

/// Newton iterations at most per sub-step before the step is retried shorter.
const MAX_ITERATIONS: usize = 30;

/// Bathe's composite method with the state of its intermediate point t₀ + h/2.
#[derive(Debug, Clone)]
pub struct Bathe {
    q_mid: Vec<f64>,
    qd_mid: Vec<f64>,
    qdd_mid: Vec<f64>,
    /// The known parts of the sub-step being solved: q = q_base + c_q q̈, q̇ = v_base + c_v q̈.
    q_base: Vec<f64>,
    v_base: Vec<f64>,
    /// A held constraint's buffers and the sub-step's start and midpoint configurations.
    held: HeldConstraint,
    q_start: Vec<f64>,
    q_bar: Vec<f64>,
    /// When q̈₀ is made consistent with the contact phase (module docs).
    restart: EventRestart,
    /// The constraint force in q̈₀ (the last step's end force, or the restart's) and the end
    /// force of the step being solved (module docs, work balance).
    force_start: Vec<f64>,
    force_end: Vec<f64>,
    works: SubStepWorks,
}

/// The works of the accepted step by the midpoint rule on each sub-step (module docs), and the
/// buffers that evaluate them.
#[derive(Debug, Clone)]
struct SubStepWorks {
    pending: Works,
    dq: Vec<f64>,
    vbar: Vec<f64>,
    qbar: Vec<f64>,
    minus_q: Vec<f64>,
    zero: Vec<f64>,
}

impl SubStepWorks {
    fn new(n: usize) -> Self {
        SubStepWorks {
            pending: Works::default(),
            dq: vec![0.0; n],
            vbar: vec![0.0; n],
            qbar: vec![0.0; n],
            minus_q: vec![0.0; n],
            zero: vec![0.0; n],
        }
    }

    /// Books the sub-steps q₀ → q_m → q₁ of a step of length h from t₀: for each, the
    /// non-conservative forces at its midpoint (t, q̄, v̄ = Δq/(h/2)) and
    /// [`System::midpoint_works`].
    fn book<S: System + ?Sized>(
        &mut self,
        system: &mut S,
        (t0, h, t_law): (f64, f64, f64),
        (q0, q_mid, q1): (&[f64], &[f64], &[f64]),
    ) {
        let mut total = Works::default();
        for (k, (qa, qb)) in [(q0, q_mid), (q_mid, q1)].into_iter().enumerate() {
            for i in 0..qa.len() {
                self.dq[i] = qb[i] - qa[i];
                self.vbar[i] = self.dq[i] / (0.5 * h);
                self.qbar[i] = qa[i] + 0.5 * self.dq[i];
            }
            let t_mid = t0 + (0.25 + 0.5 * k as f64) * h;
            system.residual_parts(
                t_mid,
                &self.qbar,
                &self.vbar,
                &self.zero,
                Parts::NONCONSERVATIVE,
                &mut self.minus_q,
            );
            let w = system.midpoint_works(0.5 * h, t_mid, t_law, &self.dq, &self.vbar, &self.minus_q);
            total.applied_torque += w.applied_torque;
            total.applied_load += w.applied_load;
            total.prescribed_motion += w.prescribed_motion;
            total.joint_damper += w.joint_damper;
            total.kelvin_voigt += w.kelvin_voigt;
        }
        self.pending = total;
    }
}

impl Bathe {
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
        Bathe {
            q_mid: vec![0.0; n],
            qd_mid: vec![0.0; n],
            qdd_mid: vec![0.0; n],
            q_base: vec![0.0; n],
            v_base: vec![0.0; n],
            held: HeldConstraint::new(n),
            q_start: vec![0.0; n],
            q_bar: vec![0.0; n],
            restart: EventRestart::new(n),
            force_start: vec![0.0; n],
            force_end: vec![0.0; n],
            works: SubStepWorks::new(n),
        }
    }
}

impl From<MethodParams> for Bathe {
    fn from(p: MethodParams) -> Self {
        Bathe::new(p.n)
    }
}

/// Outcome of one sub-step's Newton iteration: converged, or the last update size.
enum SubStep {
    Converged,
    Failed { last: f64 },
}

/// A constraint held during one sub-step: its buffers, the sub-step's start configuration
/// and times, g at the start, the gap's target at the end, and the multiplier (updated in
/// place; the iteration starts from its value).
struct HeldSubStep<'a, 'k, S: System + ?Sized> {
    constraint: &'a mut (dyn StepConstraint<S> + 'k),
    held: &'a mut HeldConstraint,
    q_start: &'a [f64],
    q_bar: &'a mut [f64],
    /// Start, midpoint and end times of the sub-step.
    t: [f64; 3],
    g_start: f64,
    target: f64,
    lambda: f64,
    /// The constraint force the sub-step's start acceleration contains, when the sub-step
    /// averages it with the end force (the trapezoidal rule: work balance, module docs).
    force_start: Option<&'a [f64]>,
    /// Receives the end force of the converged sub-step.
    force_end: Option<&'a mut [f64]>,
}

/// Solves R(q_base + c_q q̈, v_base + c_v q̈, q̈, t_eval) = 0 for q̈ in the trial-end slots of
/// the state (q̈ starts from the predictor already there; q₁, q̇₁ follow it), or with a held
/// constraint R − ∇̄g λ = 0 and g at its target (module docs).
fn solve_sub_step<S: System + ?Sized>(
    cx: &mut StepContext<'_, S>,
    (q_base, v_base): (&[f64], &[f64]),
    mut held: Option<&mut HeldSubStep<'_, '_, S>>,
    c: NewtonCoefficients,
    h: f64,
    t_eval: f64,
) -> Result<SubStep, FemError> {
    let st = &mut *cx.state;
    let n = st.q.len();
    let mut last = f64::INFINITY;
    for it in 0..MAX_ITERATIONS {
        for i in 0..n {
            st.q1[i] = q_base[i] + c.c_q * st.qdd1[i];
            st.qd1[i] = v_base[i] + c.c_v * st.qdd1[i];
        }
        cx.system
            .residual(t_eval, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
        cx.counters.rhs += 1;
        cx.counters.newton += 1;
        cx.newton
            .form_if_due(it, h, cx.system, st, cx.counters, c, t_eval)?;
        if let Some(k) = held.as_deref_mut() {
            for i in 0..n {
                k.held.dq[i] = st.q1[i] - k.q_start[i];
                k.q_bar[i] = k.q_start[i] + 0.5 * k.held.dq[i];
            }
            let gap = k.held.force(
                cx.system,
                cx.counters,
                &mut *k.constraint,
                it,
                k.t,
                (k.q_start, &st.q1, &*k.q_bar),
                (k.g_start, k.lambda),
                &cx.newton.res,
            );
            if let Some(f0) = k.force_start {
                // Work balance: the end force gains c·WΔq so that the average of the start
                // and end forces does the end force's work (zero for the normal force).
                let (mut work_end, mut work_start) = (0.0, 0.0);
                for i in 0..n {
                    work_end += k.held.dq[i] * (cx.newton.res[i] - k.held.res[i]);
                    work_start += k.held.dq[i] * f0[i];
                }
                let denom = dot(&k.held.dq, &k.held.w_dq);
                let c_balance = if denom > 0.0 {
                    (work_end - work_start) / denom
                } else {
                    0.0
                };
                for i in 0..n {
                    k.held.res[i] -= c_balance * k.held.w_dq[i];
                }
            }
            let on_surface = (gap - k.target).abs() <= cx.newton.tol;
            let dlambda = k
                .constraint
                .newton_update(cx.newton, &k.held.res, c.c_q, gap, k.target);
            let dq = max_abs(&cx.newton.delta) * c.c_q;
            if !dq.is_finite() || (it > 2 && dq > 10.0 * last) {
                break;
            }
            last = dq;
            // Accept the iterate where the residual and the gap were evaluated: its multiplier
            // is the constraint's current one (q₁, q̇₁ are already that iterate's).
            if dq <= update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1) && on_surface {
                if let Some(f1) = k.force_end.as_deref_mut() {
                    for i in 0..n {
                        f1[i] = cx.newton.res[i] - k.held.res[i];
                    }
                }
                cx.newton.slow_convergence = it + 1 > 3;
                return Ok(SubStep::Converged);
            }
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
            }
            k.lambda -= dlambda;
            continue;
        }
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
        // Absolute tolerance on the position update, floored at its round-off level.
        if dq <= update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1) {
            for i in 0..n {
                st.q1[i] = q_base[i] + c.c_q * st.qdd1[i];
                st.qd1[i] = v_base[i] + c.c_v * st.qdd1[i];
            }
            cx.newton.slow_convergence = it + 1 > 3;
            return Ok(SubStep::Converged);
        }
    }
    cx.newton.slow_convergence = true;
    Ok(SubStep::Failed { last })
}

/// Which of the two sub-steps is solved: what its held constraint balances and records.
#[derive(Clone, Copy, PartialEq)]
enum Sub {
    /// The trapezoidal half step: its start force is balanced (module docs).
    Trapezoidal,
    /// The backward difference: its end force is the next step's start force.
    BackwardDifference,
}

impl Bathe {
    /// Sub-step 1: the trapezoidal rule to t₀ + h/2, into the intermediate point.
    fn trapezoidal_half<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut (dyn StepConstraint<S> + '_)>,
        h: f64,
        lambda: &mut f64,
    ) -> Result<SubStep, FemError> {
        let st: &mut StepState = cx.state;
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.25 * h,
            c_q: h * h / 16.0,
        };
        for i in 0..st.q.len() {
            self.q_base[i] = st.q[i] + 0.5 * h * st.qd[i] + c.c_q * st.qdd[i];
            self.v_base[i] = st.qd[i] + c.c_v * st.qdd[i];
            // Constant-position predictor q_m = q₀ + (h/2) q̇₀ (robust for a stiff start).
            st.qdd1[i] = -st.qdd[i];
        }
        let t0 = st.t;
        self.q_start.copy_from_slice(&st.q);
        let h_nominal = cx.h_nominal;
        let target = |g_start: f64| g_start * gap_factor(0.5 * h, h_nominal);
        let times = [t0, t0 + 0.5 * h];
        let outcome =
            self.solve_from_start(cx, constraint, (c, h, times[1]), times, target, lambda, Sub::Trapezoidal)?;
        let st = &*cx.state;
        self.q_mid.copy_from_slice(&st.q1);
        self.qd_mid.copy_from_slice(&st.qd1);
        self.qdd_mid.copy_from_slice(&st.qdd1);
        Ok(outcome)
    }

    /// Sub-step 2: the three-point backward difference to t₁ (the predictor is q̈_m); `g0` is
    /// the constraint's value at the step start.
    #[allow(clippy::too_many_arguments)]
    fn backward_difference<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut (dyn StepConstraint<S> + '_)>,
        h: f64,
        t1: f64,
        t_law: f64,
        g0: f64,
        lambda: &mut f64,
    ) -> Result<SubStep, FemError> {
        let st: &mut StepState = cx.state;
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: h / 3.0,
            c_q: h * h / 9.0,
        };
        for i in 0..st.q.len() {
            self.v_base[i] = (4.0 * self.qd_mid[i] - st.qd[i]) / 3.0;
            self.q_base[i] = (4.0 * self.q_mid[i] - st.q[i]) / 3.0 + h / 3.0 * self.v_base[i];
            st.qdd1[i] = self.qdd_mid[i];
        }
        let t_mid = st.t + 0.5 * h;
        self.q_start.copy_from_slice(&self.q_mid);
        let target = g0 * gap_factor(h, cx.h_nominal);
        let sub = Sub::BackwardDifference;
        self.solve_from_start(cx, constraint, (c, h, t_law), [t_mid, t1], |_| target, lambda, sub)
    }

    /// Solves a sub-step from `q_start` over `times` (residual at `t_eval`), with the held
    /// constraint if any: g at `target(g(q_start))` at the sub-step end, the multiplier
    /// starting from and left in `lambda`.
    #[allow(clippy::too_many_arguments)]
    fn solve_from_start<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut (dyn StepConstraint<S> + '_)>,
        (c, h, t_eval): (NewtonCoefficients, f64, f64),
        times: [f64; 2],
        target: impl FnOnce(f64) -> f64,
        lambda: &mut f64,
        sub: Sub,
    ) -> Result<SubStep, FemError> {
        let mut held = constraint.map(|k| {
            let g_start = k.value(cx.system, times[0], &self.q_start);
            HeldSubStep {
                constraint: k,
                held: &mut self.held,
                q_start: &self.q_start,
                q_bar: &mut self.q_bar,
                t: [times[0], 0.5 * (times[0] + times[1]), times[1]],
                g_start,
                target: target(g_start),
                lambda: *lambda,
                force_start: (sub == Sub::Trapezoidal).then_some(&self.force_start[..]),
                force_end: (sub == Sub::BackwardDifference).then_some(&mut self.force_end[..]),
            }
        });
        let outcome = solve_sub_step(cx, (&self.q_base, &self.v_base), held.as_mut(), c, h, t_eval)?;
        if let Some(k) = held {
            *lambda = k.lambda;
        }
        Ok(outcome)
    }
}

/// The fraction of g(q₀) a held constraint leaves at time τ into a step of nominal length
/// h_nominal: 1 − (τ/h_nominal)², 0 at the end of a full step (module docs).
fn gap_factor(tau: f64, h_nominal: f64) -> f64 {
    let r = (tau / h_nominal).min(1.0);
    1.0 - r * r
}

impl<S: System + ?Sized> Stepper<S> for Bathe {
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
            "bathe",
        )?;
        let g0 = match constraint.as_deref() {
            Some(k) => k.value(cx.system, cx.state.t, &cx.state.q),
            None => 0.0,
        };
        let mut lambda = constraint.as_deref().map_or(0.0, |k| k.multiplier());
        if let Some(k) = constraint.as_deref_mut() {
            k.start_sub_step(true);
        }
        let mut outcome = self.trapezoidal_half(cx, constraint.as_deref_mut(), h, &mut lambda)?;
        if let SubStep::Converged = outcome {
            if let Some(k) = constraint.as_deref_mut() {
                k.start_sub_step(false);
            }
            outcome = self.backward_difference(
                cx,
                constraint.as_deref_mut(),
                h,
                t1,
                t_law,
                g0,
                &mut lambda,
            )?;
        }
        if let SubStep::Failed { last } = outcome {
            return unconverged(cx.adaptive.is_some(), cx.h_nominal, cx.state.t, h, last, "");
        }
        if let Some(k) = constraint {
            k.set_multiplier(lambda);
        }
        if cx.method_works {
            let st = &*cx.state;
            self.works.book(
                &mut *cx.system,
                (st.t, h, t_law),
                (&st.q, &self.q_mid, &st.q1),
            );
        }
        let st = &mut *cx.state;
        st.a1.copy_from_slice(&st.qdd1);
        Ok(Trial::Converged {
            error: cx.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..st.q.len() {
                let e = h * h / 24.0 * (st.qdd1[i] - st.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
            }
            err
            }),
        })
    }

    fn restart(&mut self) {
        self.restart.request();
    }

    fn commit(&mut self, _h: f64, works: &mut Works) -> bool {
        // The end force of this step is the constraint force in the next step's q̈₀.
        std::mem::swap(&mut self.force_start, &mut self.force_end);
        let p = self.works.pending;
        works.applied_torque += p.applied_torque;
        works.applied_load += p.applied_load;
        works.prescribed_motion += p.prescribed_motion;
        works.joint_damper += p.joint_damper;
        works.kelvin_voigt += p.kelvin_voigt;
        true
    }
}
