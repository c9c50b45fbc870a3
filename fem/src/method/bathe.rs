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
//! local error estimate is e = (h²/24)(q̈₁ − q̈₀). The driver books the works with the
//! trapezoidal rule on the step's end points. The method takes no held constraint (contact
//! runs use the midpoint schemes or generalized-α).

use crate::error::FemError;
use crate::linalg::max_abs;
use crate::method::{
    Capabilities, MethodParams, StepConstraint, StepContext, StepState, Stepper,
    refuse_constraint, unconverged, update_tolerance,
};
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
}

impl Bathe {
    /// Registry entry: what the method supports.
    pub const CAPABILITIES: Capabilities = Capabilities {
        explicit: false,
        adaptive: true,
        prescribed_joints: true,
        held_constraint: false,
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

/// Solves R(q_base + c_q q̈, v_base + c_v q̈, q̈, t_eval) = 0 for q̈ in the trial-end slots of
/// the state (q̈ starts from the predictor already there; q₁, q̇₁ follow it).
fn solve_sub_step<S: System + ?Sized>(
    cx: &mut StepContext<'_, S>,
    q_base: &[f64],
    v_base: &[f64],
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

impl Bathe {
    /// Sub-step 1: the trapezoidal rule to t₀ + h/2, into the intermediate point.
    fn trapezoidal_half<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        h: f64,
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
        let t_mid = st.t + 0.5 * h;
        let outcome = solve_sub_step(cx, &self.q_base, &self.v_base, c, h, t_mid)?;
        let st = &*cx.state;
        self.q_mid.copy_from_slice(&st.q1);
        self.qd_mid.copy_from_slice(&st.qd1);
        self.qdd_mid.copy_from_slice(&st.qdd1);
        Ok(outcome)
    }

    /// Sub-step 2: the three-point backward difference to t₁ (the predictor is q̈_m).
    fn backward_difference<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        h: f64,
        t_law: f64,
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
        solve_sub_step(cx, &self.q_base, &self.v_base, c, h, t_law)
    }
}

impl<S: System + ?Sized> Stepper<S> for Bathe {
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        _t1: f64,
        t_law: f64,
    ) -> Result<Option<f64>, FemError> {
        refuse_constraint("bathe", constraint.is_some())?;
        let mut outcome = self.trapezoidal_half(cx, h)?;
        if let SubStep::Converged = outcome {
            outcome = self.backward_difference(cx, h, t_law)?;
        }
        if let SubStep::Failed { last } = outcome {
            return unconverged(cx.adaptive.is_some(), cx.h_nominal, cx.state.t, h, last);
        }
        let st = &mut *cx.state;
        st.a1.copy_from_slice(&st.qdd1);
        Ok(cx.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..st.q.len() {
                let e = h * h / 24.0 * (st.qdd1[i] - st.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
            }
            err
        }))
    }
}
