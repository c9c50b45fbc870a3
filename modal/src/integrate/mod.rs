//! Time integrators for first-order systems y' = f(t, y).
//!
//! * [`Dopri5`] — explicit adaptive Dormand–Prince 5(4): FSAL, PI step-size control, 4th-order
//!   continuous extension (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4–II.6).
//! * [`Sdirk`] — the L-stable, stiffly accurate ESDIRK method TR-BDF2 (Bank et al. 1985;
//!   Hosea & Shampine 1996): a trapezoidal stage followed by a BDF2 stage with the same diagonal
//!   coefficient, so one LU factorization of I − hγ/2·J serves both implicit stages. Embedded
//!   3rd-order error estimate (filtered by the same factorization for stiff components),
//!   cubic Hermite dense output, simplified Newton with a finite-difference or analytic Jacobian.
//!   Also as a fixed-step method ([`Sdirk::fixed_step`], no error test: L-stable damping of
//!   what the step does not resolve) and, on the same Newton machinery, the fixed-step
//!   trapezoidal rule ([`Sdirk::trapezoidal`], no damping).
//!
//! * [`Exponential`] — fixed-step exponential Runge–Kutta (ETDRK4) that solves the right-hand
//!   side's linear oscillators exactly ([`OdeRhs::second_order_linearization`]) and the rest
//!   explicitly: no numerical dispersion of the modes a step does not resolve.
//!
//! All keep their work arrays in the struct: a step performs no heap allocation.
//!
//! Every method implements [`Stepper`] (one accepted step, dense output over it, work
//! counters, restart after a discontinuity) and has a [`MethodInfo`] (its name and how it is
//! built: error-controlled or fixed steps, [`Build`]); the registry ([`method_for`],
//! [`METHODS`]) maps the settings' [`data::ModalMethod`] to it: a driver holds a
//! `Box<dyn Stepper>` built from the registry entry and never names a method, and a model that
//! needs error-controlled steps (the rocket) refuses the fixed-step methods naming the methods
//! that can ([`names_with`]).
//!
//! Adding a method: one new file here (the method type, its `Stepper` impl and its
//! [`MethodInfo`]) and its entry in the registry at the end of this file
//! (`module { Variant => INFO }`: declares the module and maps the settings' variant to the
//! entry); in `data`, one row of the method table (`data/src/methods.rs`, from which
//! [`data::ModalMethod`] follows).

pub use dopri5::{DOPRI5, Dopri5};
pub use exponential::{
    EXPONENTIAL, Exponential, REFRESH_TOLERANCE, TOP_FREQUENCY_STEP, resolving_step,
};
pub use sdirk::{Sdirk, TRAPEZOID, TRBDF2, TRBDF2_FIXED};

/// Why [`Stepper::step`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// One step was accepted and `t` lies before `t_stop`.
    InternalStep,
    /// `t` equals `t_stop` (also when the interval was already empty).
    TstopReached,
}

/// One integration method for y' = f(t, y) with its state between steps.
pub trait Stepper {
    /// Advances one accepted step from (`t`, `y`), never past `t_stop` (landing on it exactly
    /// when it is reached).
    fn step(
        &mut self,
        f: &mut dyn OdeRhs,
        t: &mut f64,
        y: &mut [f64],
        t_stop: f64,
    ) -> Result<StopReason, IntegrateError>;
    /// y(`t_out`) inside the last accepted step (continuous extension of the method).
    fn dense(&self, t_out: f64, out: &mut [f64]);
    fn stats(&self) -> StepStats;
    /// Size of the last accepted step.
    fn last_step(&self) -> f64;
    /// Restart after a discontinuity of the right-hand side or the state (forget every stage
    /// and linearization carried between steps).
    fn reset(&mut self);
    /// The state was moved by a small amount outside the method (a projection onto a
    /// constraint manifold) while the right-hand side stayed the same; by default a restart.
    fn state_changed(&mut self) {
        self.reset();
    }
}

/// How a registered method is constructed.
#[derive(Clone, Copy)]
pub enum Build {
    /// Error-controlled step size; `h_init` is the first step (None: estimated).
    Adaptive(fn(dim: usize, tol: Tolerances, h_init: Option<f64>) -> Box<dyn Stepper>),
    /// Constant step `h`; `tol` scales the convergence test of the implicit stages only.
    Fixed(fn(dim: usize, tol: Tolerances, h: f64) -> Box<dyn Stepper>),
}

/// Registry entry of one integration method.
#[derive(Clone, Copy)]
pub struct MethodInfo {
    /// The method as the settings name it (`time.method`).
    pub method: data::ModalMethod,
    /// Its canonical spelling, for messages.
    pub name: &'static str,
    pub build: Build,
    /// The method integrates the right-hand side's linear oscillators exactly and needs them
    /// ([`OdeRhs::second_order_linearization`]): models without that form refuse it.
    pub needs_oscillators: bool,
}

impl MethodInfo {
    pub fn is_fixed_step(&self) -> bool {
        matches!(self.build, Build::Fixed(_))
    }
}

impl PartialEq for MethodInfo {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for MethodInfo {}

impl std::fmt::Debug for MethodInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// The registry: one entry per module, `module { Variant => INFO, … }`, declaring the module
/// and mapping each settings' [`data::ModalMethod`] variant to the module's [`MethodInfo`]
/// constant ([`method_for`]; [`METHODS`] in registry order).
macro_rules! registry {
    ($($module:ident { $($variant:ident => $info:ident),+ $(,)? })*) => {
        $(mod $module;)*

        /// The implementation of each method of the settings.
        pub fn method_for(method: data::ModalMethod) -> &'static MethodInfo {
            match method {
                $($(data::ModalMethod::$variant => &$module::$info,)+)*
            }
        }

        /// Every registered method, in registry order.
        pub const METHODS: &[&MethodInfo] = &[$($(&$module::$info,)+)*];
    };
}

/// The spellings of the registered methods for which `has` holds, in registry order, for
/// messages (`` `a`, `b` or `c` `` with `conjunction` "or").
pub fn names_with(conjunction: &str, has: impl Fn(&MethodInfo) -> bool) -> String {
    let names: Vec<String> = METHODS
        .iter()
        .filter(|m| has(m))
        .map(|m| format!("`{}`", m.name))
        .collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} {conjunction} {last}", rest.join(", ")),
        None => String::new(),
    }
}

registry! {
    dopri5 { Dopri5 => DOPRI5 }
    sdirk { TrBdf2 => TRBDF2, TrBdf2Fixed => TRBDF2_FIXED, Trapezoid => TRAPEZOID }
    exponential { Exponential => EXPONENTIAL }
}

/// The refusal of `method` by a model (`model`, for the message) whose right-hand side has
/// no linear oscillators ([`MethodInfo::needs_oscillators`]); `None` when the method runs.
pub fn oscillators_refused(method: &MethodInfo, model: &str) -> Option<String> {
    method.needs_oscillators.then(|| {
        format!(
            "`{}` is implemented for the planar link chains, not for {model}; use {}",
            method.name,
            names_with("or", |m| !m.needs_oscillators)
        )
    })
}

/// Why a method that needs oscillators refuses a model that has them but also a term its
/// explicit remainder must not carry: `models` is what it integrates ("chains without
/// Kelvin–Voigt damping and without a tip contact"), `scene` the scene and `has` the term.
pub fn oscillators_disturbed(method: &MethodInfo, models: &str, scene: &str, has: &str) -> String {
    format!(
        "`{}` integrates {models} (scene `{scene}` has {has}): its exact part is the undamped \
         oscillators and everything else is explicit; use {}",
        method.name,
        names_with("or", |m| !m.needs_oscillators)
    )
}

/// Why a fixed-step method without a Newton iteration refuses a tolerance; `default_step`
/// names its default step.
pub fn tolerance_refused(method: &MethodInfo, default_step: &str) -> String {
    format!(
        "`{}` takes no tolerance (fixed steps, no Newton iteration); its accuracy is set by --dt \
         (default {default_step})",
        method.name
    )
}

/// [`StopReason`] of a step that ended at `t` with target `t_stop`.
pub(crate) fn stop_reason(t: f64, t_stop: f64) -> StopReason {
    if t >= t_stop {
        StopReason::TstopReached
    } else {
        StopReason::InternalStep
    }
}

use thiserror::Error;

/// Right-hand side of y' = f(t, y).
pub trait OdeRhs {
    fn dim(&self) -> usize;
    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]);
    /// Analytic Jacobian ∂f/∂y, column-major `dim × dim` (entry (i, j) at `j * dim + i`).
    /// Return `false` (the default) to let implicit methods difference it numerically.
    fn jacobian(&mut self, _t: f64, _y: &[f64], _jac: &mut [f64]) -> bool {
        false
    }
    /// Structured linear algebra for implicit methods, preferred over [`Self::jacobian`]:
    /// linearize at (t, y) and return `true` if supported. Then [`Self::newton_factor`]
    /// factors I − c·J of that linearization and [`Self::newton_solve`] applies its inverse.
    /// Meant for systems whose Jacobian is cheap and well conditioned in factored form but not
    /// as a dense matrix (the modal chain: M(q)⁻¹K has entries ~10¹⁴ in the polynomial
    /// coordinates while M + cD + c²K factors stably).
    fn newton_linearize(&mut self, _t: f64, _y: &[f64]) -> bool {
        false
    }
    /// Factors I − c·J of the last linearization; `false` if it cannot (the caller falls back
    /// to a dense Jacobian).
    fn newton_factor(&mut self, _c: f64) -> bool {
        false
    }
    /// x ← (I − c·J)⁻¹ x with the last factorization.
    fn newton_solve(&mut self, _x: &mut [f64]) {}
    /// For a second-order system y = (q, q̇, …) with q̈ = a(t, y): the mass and stiffness
    /// matrices M, K (row-major nf × nf, resized here) of the linearization at (t, y), whose
    /// oscillators q̈ = −M⁻¹K q carry the stiff part of the dynamics. Returns nf, or `None`
    /// when the system has no such form (the default).
    fn second_order_linearization(
        &mut self,
        _t: f64,
        _y: &[f64],
        _m: &mut Vec<f64>,
        _k: &mut Vec<f64>,
    ) -> Option<usize> {
        None
    }
    /// The stretch of time the next steps integrate, between two discontinuities of the
    /// system's piecewise-constant inputs ([`Stretch`]); [`Stretch::OPEN`] outside a step. A
    /// system without such inputs ignores it (the default).
    fn set_stretch(&mut self, _stretch: Stretch) {}
}

/// A stretch [start, end] of time between two discontinuities of piecewise-constant inputs
/// (torque laws and schedules), onto which the drivers step. A method's last stage lands on
/// `end`, where a right-continuous law already takes the next stretch's value; that stage must
/// see this stretch's value (the law's left limit), or the step integrates the jump over a
/// part of itself and the error becomes first order in h (e.g. `single-link`'s bang-bang
/// torque with the fixed-step methods).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stretch {
    pub start: f64,
    pub end: f64,
}

impl Stretch {
    /// No stretch: every input at its own time.
    pub const OPEN: Stretch = Stretch {
        start: f64::NEG_INFINITY,
        end: f64::INFINITY,
    };

    /// The time at which a piecewise-constant input is read for a stage at `t`: `t` itself,
    /// or, from `end` on, the stretch's midpoint (the inputs are constant inside the stretch,
    /// so this is their left limit at `end`, free of the rounding of a time next to `end`).
    pub fn input_time(&self, t: f64) -> f64 {
        if t >= self.end {
            0.5 * (self.start + self.end)
        } else {
            t
        }
    }
}

/// Mixed error tolerance: component i is scaled by atol + rtol·max(|yᵢ(t)|, |yᵢ(t+h)|).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            rtol: 1e-8,
            atol: 1e-10,
        }
    }
}

/// Work counters of an integrator.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepStats {
    pub steps: usize,
    pub rejected: usize,
    pub rhs_evals: usize,
    pub jacobian_evals: usize,
    pub factorizations: usize,
    pub newton_iters: usize,
    /// Implicit methods: rejected attempts whose Newton iteration failed (diverged, converged
    /// too slowly, or went non-finite); the rest of `rejected` failed the error test.
    pub newton_failures: usize,
}

impl StepStats {
    /// The run's cost record: these counters, the state size `dofs` and the wall time since
    /// `start`.
    pub fn cost(&self, dofs: usize, start: std::time::Instant) -> data::Cost {
        data::Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs,
            steps: self.steps,
            rejected_steps: self.rejected,
            rhs_evaluations: self.rhs_evals,
            jacobian_evaluations: self.jacobian_evals,
            factorizations: self.factorizations,
            newton_iterations: self.newton_iters,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum IntegrateError {
    #[error(
        "step size {h:.3e} underflowed at t = {t:.9e} (the solution is not resolvable at the requested tolerance)"
    )]
    StepTooSmall { t: f64, h: f64 },
    #[error("non-finite state at t = {t:.9e}")]
    NonFinite { t: f64 },
    #[error("Newton iteration failed to converge at t = {t:.9e} even with the smallest step")]
    NewtonFailed { t: f64 },
    #[error(
        "no linear oscillators at t = {t:.9e}: the system has no second-order linearization with a \
         positive definite mass matrix there (the exponential method needs one)"
    )]
    NoLinearization { t: f64 },
}

/// Weighted RMS norm of `err` with the mixed scale of [`Tolerances`].
pub(crate) fn error_norm(tol: &Tolerances, y0: &[f64], y1: &[f64], err: &[f64]) -> f64 {
    let n = err.len().max(1);
    let mut acc = 0.0;
    for i in 0..err.len() {
        let sc = tol.atol + tol.rtol * y0[i].abs().max(y1[i].abs());
        let r = err[i] / sc;
        acc += r * r;
    }
    (acc / n as f64).sqrt()
}

/// Smallest step allowed from `t` over a remaining `span` (a few ulps of the time scale).
pub(crate) fn min_step(t: f64, span: f64) -> f64 {
    16.0 * f64::EPSILON * t.abs().max(span.abs()).max(1e-300)
}

/// The step to attempt from `t` with proposal `h` and `span` left to `t_stop`: never past
/// `t_stop`, landing exactly on it when close. Returns `(h_try, clipped)`.
pub(crate) fn clip_step(
    h: f64,
    span: f64,
    h_min: f64,
    t: f64,
) -> Result<(f64, bool), IntegrateError> {
    let clipped = h >= span * (1.0 - 1e-12);
    let h_try = if clipped { span } else { h };
    if !clipped && h_try < h_min {
        return Err(IntegrateError::StepTooSmall { t, h: h_try });
    }
    Ok((h_try, clipped))
}

/// Retry step after a non-finite error estimate (blow-up inside the step): shrink hard.
pub(crate) fn shrink_after_blowup(h_try: f64, h_min: f64, t: f64) -> Result<f64, IntegrateError> {
    let h = 0.1 * h_try;
    if h < h_min {
        return Err(IntegrateError::NonFinite { t });
    }
    Ok(h)
}

/// Step proposed after an accepted step of size `h_try` (the controller suggests `h_next`,
/// `h` was the proposal before clipping): a step clipped to `t_stop` keeps the controller's
/// natural size; the result never exceeds `h_max`.
pub(crate) fn next_step(h_next: f64, h: f64, h_try: f64, clipped: bool, h_max: f64) -> f64 {
    let h_keep = if clipped && h_next >= h_try {
        h_next.max(h)
    } else {
        h_next
    };
    h_keep.min(h_max)
}

/// Initial step guess (Hairer's HINIT): h such that an explicit Euler step changes y by about
/// the tolerance, limited by a second-derivative estimate. Uses `f0 = f(t, y)`;
/// `y1`, `f1` are scratch arrays. Costs one extra RHS evaluation.
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_step<F: OdeRhs + ?Sized>(
    f: &mut F,
    tol: &Tolerances,
    order: i32,
    t: f64,
    y: &[f64],
    f0: &[f64],
    y1: &mut [f64],
    f1: &mut [f64],
    h_max: f64,
    direction_span: f64,
) -> f64 {
    let n = y.len().max(1) as f64;
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..y.len() {
        let sc = tol.atol + tol.rtol * y[i].abs();
        dnf += (f0[i] / sc).powi(2);
        dny += (y[i] / sc).powi(2);
    }
    let (dnf, dny) = ((dnf / n).sqrt(), (dny / n).sqrt());
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        0.01 * dny / dnf
    };
    h = h.min(h_max).min(direction_span.abs().max(1e-300));
    for i in 0..y.len() {
        y1[i] = y[i] + h * f0[i];
    }
    f.eval(t + h, y1, f1);
    let mut der2 = 0.0;
    for i in 0..y.len() {
        let sc = tol.atol + tol.rtol * y[i].abs();
        der2 += ((f1[i] - f0[i]) / sc).powi(2);
    }
    let der2 = (der2 / n).sqrt() / h;
    let der12 = der2.max(dnf);
    let h1 = if der12 <= 1e-15 {
        (h * 1e-3).max(1e-6)
    } else {
        (0.01 / der12).powf(1.0 / (order as f64 + 1.0))
    };
    (100.0 * h).min(h1).min(h_max)
}
