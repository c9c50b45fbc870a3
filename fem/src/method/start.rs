//! Consistent acceleration at a (re)start: q̈ from R(q, q̇, q̈, t) = 0 at the current state (at
//! t = 0 and after a torque-law discontinuity), with the Newton machinery of
//! [`crate::method::newton`].

use crate::error::FemError;
use crate::linalg::max_abs;
use crate::method::newton::with_time;
use crate::method::{ConstraintView, StepConstraint, StepContext};
use crate::system::{NewtonCoefficients, System};

/// Consistent q̈ at the current state: solves R(q, q̇, q̈) = 0 for q̈ (R is affine in q̈; the
/// iteration converges because the mass-matrix approximation misses only O(v′²) terms).
pub fn consistent_acceleration<S: System + ?Sized>(
    cx: &mut StepContext<'_, S>,
    h: f64,
    t_law: f64,
) -> Result<(), FemError> {
    if cx.system.has_massless_dofs() {
        return regularized_acceleration(cx, h, t_law);
    }
    accelerate_with(cx, t_law, |_, _, _| {})
}

/// Consistent q̈ under extra forces: solves R(q, q̇, q̈) − F = 0 for q̈, where
/// `subtract_forces(system, q, res)` subtracts F(q) from the residual (a held constraint's
/// force, for a method's restart; systems without massless directions).
pub fn accelerate_with<S: System + ?Sized>(
    cx: &mut StepContext<'_, S>,
    t_law: f64,
    mut subtract_forces: impl FnMut(&S, &[f64], &mut [f64]),
) -> Result<(), FemError> {
    let st = &mut *cx.state;
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.0,
        c_q: 0.0,
    };
    for it in 0..50 {
        cx.system
            .residual(t_law, &st.q, &st.qd, &st.qdd, &mut cx.newton.res);
        cx.counters.rhs += 1;
        if it == 0 {
            st.q1.copy_from_slice(&st.q);
            st.qd1.copy_from_slice(&st.qd);
            st.qdd1.copy_from_slice(&st.qdd);
            cx.newton.form(cx.system, st, cx.counters, c, st.t)?;
            cx.newton.matrix_h = f64::NAN;
        }
        subtract_forces(cx.system, &st.q, &mut cx.newton.res);
        cx.newton.delta.copy_from_slice(&cx.newton.res);
        cx.newton.solve();
        let mut big = 0.0f64;
        let mut amax = 0.0f64;
        for i in 0..st.qdd.len() {
            st.qdd[i] -= cx.newton.delta[i];
            big = big.max(cx.newton.delta[i].abs());
            amax = amax.max(st.qdd[i].abs());
        }
        if !big.is_finite() {
            break;
        }
        // 1e-10 relative: far below the integrator's error; tighter is round-off-limited
        // (point moments on EB elements give q̈₀ ∝ h⁻³ spikes).
        if big <= 1e-10 * amax.max(1e-12) {
            st.a.copy_from_slice(&st.qdd);
            return Ok(());
        }
    }
    Err(FemError::Numerical {
        t: st.t,
        message: "could not compute a consistent initial acceleration".into(),
    })
}

/// When and how a method that carries q̈ₙ from step to step recomputes it for the phase a step
/// starts in: after every event (impact, release: [`crate::method::Stepper::restart`]) of a run
/// that has held a constraint, and at the first held step. Runs that never held one keep the
/// q̈₀ of the driver's start (their restarts follow no change of the force law).
#[derive(Debug, Clone)]
pub(crate) struct EventRestart {
    pending: bool,
    constrained_before: bool,
    /// Zeros (the zero-length view of the constrained start) and scratch.
    zero: Vec<f64>,
    before: Vec<f64>,
}

impl EventRestart {
    /// For a system of `n` DOFs.
    pub fn new(n: usize) -> Self {
        EventRestart {
            pending: true,
            constrained_before: false,
            zero: vec![0.0; n],
            before: vec![0.0; n],
        }
    }

    /// An event happened: recompute at the next step start.
    pub fn request(&mut self) {
        self.pending = true;
    }

    /// At a step start: when a restart is due, q̈ₙ for the phase the step is in, with the held
    /// constraint's force (the event's normal force, [`constrained_acceleration`]; `force`
    /// receives the force applied) or free ([`consistent_acceleration`]). `method` names the
    /// method in an error. Returns whether q̈ₙ was recomputed.
    pub fn apply<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut (dyn StepConstraint<S> + '_)>,
        h: f64,
        force: &mut [f64],
        method: &str,
    ) -> Result<bool, FemError> {
        self.constrained_before |= constraint.is_some();
        if !(self.pending && self.constrained_before) {
            return Ok(false);
        }
        self.pending = false;
        let t0 = cx.state.t;
        match constraint {
            Some(k) => {
                constrained_acceleration(cx, k, t0, &self.zero, &mut self.before, force, method)?
            }
            None => consistent_acceleration(cx, h, t0)?,
        }
        Ok(true)
    }
}

/// Consistent q̈ at the current state under a held constraint, R(q, q̇, q̈) − ∇g(q) λ = 0 with
/// the constraint's current multiplier λ (a method's restart after a contact event, whose
/// multiplier is the event's index-1 normal force): the constraint force at q itself, through
/// a view of zero length (∇̄g = ∇g(q)). `zero` holds zeros; `before` is scratch; `force`
/// receives the constraint force applied. `method` names the method in the error.
#[allow(clippy::too_many_arguments)]
fn constrained_acceleration<S: System + ?Sized>(
    cx: &mut StepContext<'_, S>,
    constraint: &mut dyn StepConstraint<S>,
    t_law: f64,
    zero: &[f64],
    before: &mut [f64],
    force: &mut [f64],
    method: &str,
) -> Result<(), FemError> {
    let t0 = cx.state.t;
    let g0 = constraint.value(cx.system, t0, &cx.state.q);
    let lambda = constraint.multiplier();
    accelerate_with(cx, t_law, |system, q, res| {
        let view = ConstraintView {
            it: 0,
            t: [t0; 3],
            q0: q,
            q1: q,
            qbar: q,
            dq: zero,
            w_dq: zero,
            denom: 0.0,
            g0,
            lambda,
        };
        before.copy_from_slice(res);
        constraint.add_force(system, &view, res);
        for i in 0..res.len() {
            force[i] = before[i] - res[i];
        }
    })
    .map_err(|e| match e {
        FemError::Numerical { t, .. } => FemError::Numerical {
            t,
            message: format!(
                "{method}: could not compute the constrained acceleration at a restart"
            ),
        },
        other => other,
    })
}

/// Initial acceleration of a chain with massless directions (Timoshenko links without
/// rotary inertia: see `Chain::settle_massless`). There M is singular: the massless
/// directions N are algebraic variables, whose acceleration follows from differentiating
/// their balance Nᵀ R = 0 (to first order Nᵀ K q̈ = 0 at rest), not from M. One solve of
/// (M₀ + εK₀) q̈ = −R(q, q̇, 0) gives both: M₀, K₀ are the matrices at the unsettled rest
/// configuration (v = 0, kept in `q1` by `Driver::new`), where NᵀM₀ = 0 exactly, so with the
/// settled residual (NᵀR = 0) its N-rows read ε NᵀK₀ q̈ = 0; the mass-carrying rows are
/// M q̈ = −R up to ε K₀ q̈ (ε = 10⁻⁴h²: a relative 10⁻⁴(hω)² for the resolved modes) and the
/// O(ψ) settling shift. (At the settled state itself NᵀM = O(ψ) ≠ 0, and that coupling,
/// divided by ε, made generalized-α first order.) R is affine in q̈ and the band matrix
/// is analytic; refinement passes (below) then drive the mass rows to R = 0 (measured:
/// Timoshenko cantilever without rotary inertia, step load, trapezoidal ledger 4e-12
/// instead of 1.6e-8 after the single solve).
fn regularized_acceleration<S: System + ?Sized>(
    cx: &mut StepContext<'_, S>,
    h: f64,
    t_law: f64,
) -> Result<(), FemError> {
    let st = &mut *cx.state;
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.0,
        c_q: 1e-4 * h * h,
    };
    st.qdd.iter_mut().for_each(|x| *x = 0.0);
    cx.counters.rhs += 1;
    cx.counters.jacobians += 1;
    cx.counters.factorizations += 1;
    // The band matrix of the chain DOFs (also for chains with foreshortening): the
    // iteration only needs a contracting approximation of M + ε·K.
    cx.system
        .residual(t_law, &st.q1, &st.qd, &st.qdd, &mut cx.newton.res);
    cx.system.newton_matrix(&st.q1, c, &mut cx.newton.matrix);
    cx.newton
        .matrix
        .factorize()
        .map_err(|e| with_time(e, st.t))?;
    // Refinement: q̈ ← q̈ − S₀⁻¹R(q̈) removes the ε K₀ q̈ error of the mass rows (factor
    // ≈ εω² per pass) while the massless rows stay balanced; where the settled state turns
    // the frame directions slightly massive (NᵀM = O(ψ)) the passes stop improving, and the
    // q̈ with the smallest residual is kept.
    let n = st.qdd.len();
    let mut best = f64::INFINITY;
    for _ in 0..10 {
        cx.system
            .residual(t_law, &st.q, &st.qd, &st.qdd, &mut cx.newton.res);
        cx.counters.rhs += 1;
        let r = max_abs(&cx.newton.res);
        // Stop once a pass no longer halves the residual (or it is not finite).
        if r.is_nan() || r >= 0.5 * best {
            break;
        }
        best = r;
        st.qdd1.copy_from_slice(&st.qdd);
        cx.newton.delta.copy_from_slice(&cx.newton.res);
        cx.newton.matrix.solve_in_place(&mut cx.newton.delta);
        let (mut big, mut amax) = (0.0f64, 0.0f64);
        for i in 0..n {
            st.qdd[i] -= cx.newton.delta[i];
            big = big.max(cx.newton.delta[i].abs());
            amax = amax.max(st.qdd[i].abs());
        }
        if !big.is_finite() {
            break;
        }
        if big <= 1e-12 * amax.max(1e-12) {
            st.qdd1.copy_from_slice(&st.qdd);
            break;
        }
    }
    st.qdd.copy_from_slice(&st.qdd1);
    if !best.is_finite() || st.qdd.iter().any(|x| !x.is_finite()) {
        return Err(FemError::Numerical {
            t: st.t,
            message: "could not compute a consistent initial acceleration".into(),
        });
    }
    // Leave the system's cached data (a chain's joint torques) at the initial state.
    cx.system
        .residual(t_law, &st.q, &st.qd, &st.qdd, &mut cx.newton.res);
    cx.newton.matrix_h = f64::NAN;
    st.a.copy_from_slice(&st.qdd);
    Ok(())
}
