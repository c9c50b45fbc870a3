//! The contract between a method and the driver: the [`Stepper`] trait, what a method works on
//! during a step ([`StepContext`]), how it sees a held constraint ([`StepConstraint`],
//! [`ConstraintView`], [`HeldConstraint`]), and the Newton helpers the methods share. All of
//! it is generic over the stepped [`System`]: a method knows the system through the trait
//! only, a constraint is implemented for the system it constrains.

use super::newton::NewtonSystem;
use super::state::{Adaptive, Counters, StepState, Works};
use crate::element::hermite::hermite;
use crate::error::FemError;
use crate::linalg::{dot, max_abs};
use crate::system::{Parts, System};

/// What a method works on during one step: the system, the state, the Newton system and the
/// counters, plus the driver's step settings.
pub struct StepContext<'a, S: System + ?Sized> {
    pub system: &'a mut S,
    pub state: &'a mut StepState,
    pub newton: &'a mut NewtonSystem<S::Augmented>,
    pub counters: &'a mut Counters,
    pub adaptive: Option<Adaptive>,
    /// The fixed step (shortened steps are measured against it).
    pub h_nominal: f64,
    /// Largest link length (scales tolerances; for a system other than a chain, its
    /// length scale).
    pub length_scale: f64,
    /// Whether the driver takes the works a method books with its own quadrature
    /// ([`Stepper::commit`]); drivers that book every work themselves (the rocket's, the
    /// payload link's) spare a method the passes that would evaluate them.
    pub method_works: bool,
}

/// One Newton iterate of a step, as a constraint sees it.
pub struct ConstraintView<'a> {
    /// Newton iteration index within the step.
    pub it: usize,
    /// t₀, t_mid, t₁.
    pub t: [f64; 3],
    pub q0: &'a [f64],
    pub q1: &'a [f64],
    pub qbar: &'a [f64],
    pub dq: &'a [f64],
    /// W Δq = M(q̄)Δq and ΔqᵀWΔq (the metric of the discrete gradients).
    pub w_dq: &'a [f64],
    pub denom: f64,
    /// Constraint value at the step start, g(q₀).
    pub g0: f64,
    /// Normal multiplier of this iterate.
    pub lambda: f64,
}

/// The Newton tolerance of a position update: the system's absolute tolerance, floored at the
/// round-off level of the update itself (`c_q`|q̈| + h|q̇|).
pub(crate) fn update_tolerance(newton_tol: f64, c_q: f64, h: f64, qdd: &[f64], qd: &[f64]) -> f64 {
    newton_tol + 1e-13 * (c_q * max_abs(qdd) + h * max_abs(qd))
}

/// A step of length `h` from `t` whose Newton iteration did not converge (`last`: its last
/// update): retried shorter when it can be (adaptive, or longer than 1e-6 of the nominal
/// step: [`Trial::NewtonFailed`]), else the run stops; `also` extends the remedy with what is
/// specific to the method.
pub(crate) fn unconverged(
    adaptive: bool,
    h_nominal: f64,
    t: f64,
    h: f64,
    last: f64,
    also: &str,
) -> Result<Trial, FemError> {
    if adaptive || h > 1e-6 * h_nominal {
        return Ok(Trial::NewtonFailed);
    }
    Err(FemError::Runaway {
        t,
        what: format!("Newton iteration did not converge (last update {last:.3e})"),
        location: None,
        why: "the step is too large for the nonlinearity or the solution diverged".into(),
        remedy: format!("reduce --dt or give --rtol for adaptive stepping{also}"),
    })
}

/// What a method's attempt at one step gives the driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Trial {
    /// Newton converged; the trial end is in the step state. `error`: the local error estimate
    /// scaled by the tolerances (≤ 1 accepts) when the steps are adaptive.
    Converged { error: Option<f64> },
    /// Newton did not converge: the driver retries the stretch with a shorter step.
    NewtonFailed,
}

/// The cubic Hermite interpolant of a step of length `h` from (q₀, q̇₀) to (q₁, q̇₁) in
/// `state`, at θ ∈ [0, 1]: positions into `q`, their rates into `qd`.
pub fn hermite_dense(state: &StepState, h: f64, theta: f64, q: &mut [f64], qd: &mut [f64]) {
    // The element's Hermite cubics on an "element" of length h in time: the basis of
    // (q₀, q̇₀, q₁, q̇₁) and its time derivative.
    let basis = hermite(theta, h);
    for i in 0..q.len() {
        let ends = [state.q[i], state.qd[i], state.q1[i], state.qd1[i]];
        q[i] = dot(&basis.n, &ends);
        qd[i] = dot(&basis.dn, &ends);
    }
}

/// Work buffers of a held constraint in a method's Newton iteration, and the one operation
/// the implicit methods share: the constraint force of an iterate on the momentum residual.
#[derive(Debug, Clone)]
pub(crate) struct HeldConstraint {
    /// Δq = q₁ − q₀ of the iterate (filled by the method) and W Δq = M(q̄)Δq.
    pub dq: Vec<f64>,
    pub w_dq: Vec<f64>,
    /// The momentum residual with the constraint force.
    pub res: Vec<f64>,
    /// Zeros (the rates of the metric pass; a zero-length step's Δq).
    pub zero: Vec<f64>,
}

impl HeldConstraint {
    /// Buffers for `n` DOFs.
    pub fn new(n: usize) -> Self {
        HeldConstraint {
            dq: vec![0.0; n],
            w_dq: vec![0.0; n],
            res: vec![0.0; n],
            zero: vec![0.0; n],
        }
    }

    /// With [`Self::dq`] filled: W Δq at q̄ (after the Newton matrix was formed: it reads the
    /// point data of the full residual pass), then [`Self::res`] = `residual` minus the
    /// constraint force of the iterate (times t₀, t_mid, t₁). Returns the constraint value
    /// Newton must drive to its target ([`StepConstraint::add_force`]).
    #[allow(clippy::too_many_arguments)]
    pub fn force<S: System + ?Sized>(
        &mut self,
        system: &mut S,
        counters: &mut Counters,
        k: &mut dyn StepConstraint<S>,
        it: usize,
        t: [f64; 3],
        (q0, q1, qbar): (&[f64], &[f64], &[f64]),
        (g0, lambda): (f64, f64),
        residual: &[f64],
    ) -> f64 {
        system.residual_parts(
            t[1],
            qbar,
            &self.zero,
            &self.dq,
            Parts::INERTIA,
            &mut self.w_dq,
        );
        counters.rhs += 1;
        let view = ConstraintView {
            it,
            t,
            q0,
            q1,
            qbar,
            dq: &self.dq,
            w_dq: &self.w_dq,
            denom: dot(&self.dq, &self.w_dq),
            g0,
            lambda,
        };
        self.res.copy_from_slice(residual);
        k.add_force(system, &view, &mut self.res)
    }
}

/// The rows a projection method (central difference: no Newton iteration to border) holds at
/// a configuration: `k` constraints (1, or 2 for a friction contact's sticking tip) with their
/// values, gradients and the directions of their multipliers' forces. A force direction differs
/// from its gradient where the multiplier also drives a non-conservative force (sliding
/// friction: ∇g − μsσT).
#[derive(Debug, Clone)]
pub struct ProjectionRows {
    pub k: usize,
    pub value: [f64; 2],
    pub gradient: [Vec<f64>; 2],
    pub force: [Vec<f64>; 2],
}

impl ProjectionRows {
    /// Rows for a system of `n` DOFs (none held yet).
    pub fn new(n: usize) -> Self {
        ProjectionRows {
            k: 0,
            value: [0.0; 2],
            gradient: [vec![0.0; n], vec![0.0; n]],
            force: [vec![0.0; n], vec![0.0; n]],
        }
    }

    /// Holds one row, `gradient[0]` as filled, of value `value`, its force along it.
    pub fn hold_one(&mut self, value: f64) {
        self.k = 1;
        self.value[0] = value;
        let (gradient, force) = (&self.gradient[0], &mut self.force[0]);
        force.copy_from_slice(gradient);
    }
}

/// A bilateral constraint held during a step on the system `S` (a tip on a surface,
/// optionally with friction), seen by a method through its force and its Newton border only.
pub trait StepConstraint<S: System + ?Sized> {
    /// Constraint value g(q) at (t, q).
    fn value(&self, system: &S, t: f64, q: &[f64]) -> f64;
    /// Constraint value g(q) at (t, q), its gradient ∇g(q) written to `out` (the projections of
    /// a method without a Newton iteration to border: central difference).
    fn gradient(&mut self, system: &S, t: f64, q: &[f64], out: &mut [f64]) -> f64;
    /// The rows a projection method holds at (t, q) ([`ProjectionRows`]); by default the
    /// constraint alone, its force along its gradient.
    fn projection_rows(&mut self, system: &S, t: f64, q: &[f64], rows: &mut ProjectionRows) {
        let value = self.gradient(system, t, q, &mut rows.gradient[0]);
        rows.hold_one(value);
    }
    /// A projection method's converged step q₀ → q₁: the start and end multipliers of each
    /// row of [`StepConstraint::projection_rows`] (forces along the rows' force directions at
    /// q₀ and at q₁). What the constraint books of it (a wall's friction work, by the
    /// trapezoidal rule as the driver books the other works); by default it keeps the end
    /// multiplier.
    fn commit_projection(
        &mut self,
        _system: &S,
        _t: [f64; 2],
        _q: [&[f64]; 2],
        _start: [f64; 2],
        end: [f64; 2],
    ) {
        self.set_multiplier(end[0]);
    }
    /// The multiplier the step starts from (the last accepted step's).
    fn multiplier(&self) -> f64;
    /// Stores the multiplier of a converged step.
    fn set_multiplier(&mut self, lambda: f64);
    /// A composite method starts a sub-step of its step (`first`: the step's first): what the
    /// constraint books over a step (a wall's friction work) restarts at the first sub-step
    /// and accumulates over the later ones. Single-stage methods never call it.
    fn start_sub_step(&mut self, _first: bool) {}
    /// Subtracts the constraint force (and friction) of the iterate from the momentum
    /// residual `res`; returns the constraint value Newton must drive to its target.
    fn add_force(&mut self, system: &S, view: &ConstraintView<'_>, res: &mut [f64]) -> f64;
    /// Bordered Newton update: leaves δa in `newton.delta` (from the residual `res`, the
    /// Newton matrix factorized in `newton`) and returns δλ; `gap1` is the value returned by
    /// [`StepConstraint::add_force`], `gap_target` what it must reach; `dq1_da` = ∂q₁/∂a, the
    /// sensitivity of the step-end configuration to the method's Newton unknown a (h²/2 for
    /// the midpoint schemes' mean acceleration, βh²(1−α_f)/(1−α_m) for generalized-α's q̈₁).
    fn newton_update(
        &mut self,
        newton: &mut NewtonSystem<S::Augmented>,
        res: &[f64],
        dq1_da: f64,
        gap1: f64,
        gap_target: f64,
    ) -> f64;
}

/// One integration method, stepping the system `S`.
pub trait Stepper<S: System + ?Sized>: std::fmt::Debug {
    /// Solves the step t₀ → t₁ = t₀ + h from `cx.state` into its trial end (laws evaluated at
    /// `t_law`, = t₁ except as a left limit at a discontinuity). `constraint`: a held bilateral
    /// constraint (methods without that support refuse it). An error is a stop the driver
    /// cannot remedy (a singular matrix, a step that cannot be shortened further).
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Trial, FemError>;

    /// The continuous extension of the trial step of length `h` just solved, at t₀ + θh
    /// (θ ∈ [0, 1]): positions into `q`, rates into `qd`. The cubic Hermite interpolant of
    /// the step's end positions and rates ([`hermite_dense`]): third order in the positions,
    /// second in the rates, one order above the methods' own, so the interpolant's error is
    /// below the step's. The driver locates events on it before it re-solves the step to the
    /// event.
    fn dense(&self, state: &StepState, h: f64, theta: f64, q: &mut [f64], qd: &mut [f64]) {
        hermite_dense(state, h, theta, q, qd);
    }

    /// Whether every stretch between stop times must be split into equal steps.
    fn equal_steps(&self) -> bool {
        false
    }

    /// Books the accepted step's works with the method's own quadrature; false when the
    /// driver books them (trapezoidal rule on the joint quantities).
    fn commit(&mut self, _h: f64, _works: &mut Works) -> bool {
        false
    }

    /// Forgets the previous step (restart after a discontinuity or an event).
    fn restart(&mut self) {}
}
