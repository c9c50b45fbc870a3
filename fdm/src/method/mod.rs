//! Integration methods for q̇ = v, v̇ = a(t, q, v): one type per method behind [`Stepper`].
//!
//! A method advances the levels of a [`StepState`] by one step of a length the driver chose:
//! [`Stepper::predict`] builds the new level's positions (and the velocities known without a
//! force evaluation), the driver checks them ([`crate::driver`]: growth of the computational
//! mode, non-finite states), then [`Stepper::complete`] evaluates the forces at the new level;
//! [`Stepper::dense`] gives the state inside a taken step, on which the outputs are sampled,
//! and [`Stepper::step_positions`] the positions a step of any length would reach, on which an
//! event is located before the step is re-taken to it.
//! A method knows nothing of scene families, events or outputs; it reports its stability limit
//! relative to the model's σ ([`Stepper::bound_factor`]) and what it supports
//! ([`Capabilities`]), from which a run refuses a model the method cannot step, naming the
//! methods that can ([`names_with`]).
//!
//! Methods: [`two_step`] (the report's central difference 5.21, optionally Robert–Asselin
//! filtered) and [`velocity_form`] (one-step kick–drift–kick).
//!
//! Adding a method: one new file here with the method type, its [`Stepper`] impl, its
//! `CAPABILITIES` and `From<`[`MethodParams`]`>`, and its entry in the registry at the end of
//! this file (`module::Type { Variant }`: declares the module, the [`Method`] variant, the
//! conversion from [`data::FdmMethod`] and the dispatch); in `data`, one row of the method
//! table (`data/src/methods.rs`, from which [`data::FdmMethod`] follows). A payload field of a
//! variant is `Option<T>` in `data` (None: the backend's default) and `T` here, checked by the
//! function of the same name in [`payload`].

pub mod dense;
mod levels;
pub mod payload;

use crate::error::FdmError;
use crate::system::System;

pub use levels::{Levels, StepState};
pub use two_step::TwoStep;
pub use velocity_form::VelocityForm;

/// One explicit integration method.
pub trait Stepper {
    /// Ratio of the method's stability limit to the model's σ (the one-step limit 2/ω_max).
    fn bound_factor(&self) -> f64;
    /// Whether the method carries a computational (parasitic) mode.
    fn has_computational_mode(&self) -> bool;
    /// Largest |Δ²v| / peak |v| a resolved physical mode can show at the method's limit, plus
    /// margin: above it the driver reports a growing computational mode.
    fn parasitic_threshold(&self) -> f64;
    /// Start-up from level j (`cur`, `acc`, `p_cur` set; t = 0, or a jump the method restarts
    /// at, [`AtJumps::Restarts`]): a method that needs a second level builds it as a step of
    /// length `tau` into `next`, `acc_next`, `p_new` and returns the number of force
    /// evaluations it made; 0 when no start-up step is needed.
    fn start(&mut self, sys: &mut dyn System, t: f64, tau: f64, st: &mut StepState) -> usize;
    /// First half of the step from t_j (previous step `tau_prev`) by `tau`: the new level's
    /// positions in `next.q`; may update level j itself (a filter).
    fn predict(&mut self, tau_prev: f64, tau: f64, st: &mut StepState);
    /// The step-end velocities known after [`Stepper::predict`] (monitored by the driver).
    fn predicted_velocity<'a>(&self, st: &'a StepState) -> &'a [f64];
    /// Second half: the force evaluation at t_new = t_j + `tau` into `acc_next` and `p_new`,
    /// and the final velocities in `next.v` (one force evaluation).
    fn complete(
        &mut self,
        sys: &mut dyn System,
        t_new: f64,
        tau_prev: f64,
        tau: f64,
        st: &mut StepState,
    );
    /// The continuous extension of the step from level `a` to level `b` at θ ∈ [0, 1] of it:
    /// positions into `q`, velocities into `v`. The outputs are sampled on it. By default the
    /// linear interpolant of the two levels ([`dense::linear`], whose module docs say why not
    /// a cubic).
    fn dense(&self, a: &Levels, b: &Levels, theta: f64, q: &mut [f64], v: &mut [f64]) {
        dense::linear(a, b, theta, q, v);
    }
    /// The positions a step of length `s` from level j (previous step `tau_prev`) reaches, into
    /// `q`: what [`Stepper::predict`] would give, without a force evaluation and without
    /// touching the levels. An event locates its root on them before it re-takes the step.
    fn step_positions(&self, st: &StepState, tau_prev: f64, s: f64, q: &mut [f64]);
}

/// What a method supports; a run refuses a model that needs what its method lacks, naming the
/// methods that have it ([`names_with`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    /// Built with [`MethodParams::restartable`], a step depends on level j alone, so it can be
    /// re-taken from the same level with another length: event location (the two-link chain's
    /// tip contact).
    pub restarts_at_events: bool,
    /// Built without [`MethodParams::restartable`], takes the closing kick with the system's
    /// linear damping implicit ([`System::implicit_kick`]), so the step stays at the undamped
    /// bound (required by the 3-D payload link; switched on in the two-link chain).
    pub implicit_damping: bool,
    /// How a step meets a jump of an applied law ([`System::jumps`]).
    pub at_jumps: AtJumps,
}

/// How a method takes a jump of an applied law (a torque switch, a burn-out): every method
/// lands a step on it (a jump inside a step, read at the step's levels, costs an error first
/// order in the step) and differs in how it carries on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AtJumps {
    /// The kicks split at every level (an opening and a closing half kick): a step ends on the
    /// jump with the closing kick at the law's left limit, and the next opening kick takes its
    /// new value (the driver's `Jumps::open`).
    SplitsKicks,
    /// A step ends on the jump, reading the law before it, and the method starts again from
    /// the landed level with the law's new value ([`Stepper::start`]).
    Restarts,
}

/// What a method is built from: the validated method (with its payload) and whether the run
/// re-takes steps from a located event ([`Capabilities::restarts_at_events`]; the methods
/// without that capability ignore it).
#[derive(Debug, Clone, Copy)]
pub struct MethodParams {
    pub method: Method,
    pub restartable: bool,
}

/// The registry: one entry per method type, `module::Type { Variant, … }`, declaring the
/// type's module, the [`Method`] variants it steps (with their documentation and payload), the
/// conversion from [`data::FdmMethod`] (`Variant [Alias]`: `data` variants that mean this one
/// here), the spellings ([`Method::name`]), the dispatch to `Type::from` ([`MethodParams`]) and
/// `Type::CAPABILITIES`, and the list [`METHODS`].
macro_rules! registry {
    (
        $(
            $module:ident :: $method:ident {
                $(
                    $(#[$doc:meta])*
                    $variant:ident $({ $field:ident: $fty:ty })? $([$($alias:ident),+])?
                ),+ $(,)?
            }
        )*
    ) => {
        $(pub mod $module;)*

        /// Time-integration method (`time.method`) with its payload checked; [`stepper`] gives
        /// its type.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Method {
            $($($(#[$doc])* $variant $({ $field: $fty })?,)+)*
        }

        impl Method {
            /// The method named in the settings (payloads checked, their defaults filled in by
            /// [`payload`]).
            pub fn from_data(method: data::FdmMethod) -> Result<Self, FdmError> {
                Ok(match method {
                    $($(
                        data::FdmMethod::$variant $({ $field })? $($(| data::FdmMethod::$alias)+)?
                            => Method::$variant $({ $field: payload::$field($field)? })?,
                    )+)*
                })
            }

            /// The canonical spelling (`data`'s table; a payload with its value).
            pub fn name(&self) -> String {
                data::Method::from(data::FdmMethod::from(*self)).name()
            }
        }

        impl From<Method> for data::FdmMethod {
            fn from(method: Method) -> Self {
                match method {
                    $($(Method::$variant $({ $field })? => data::FdmMethod::$variant $({
                        $field: Some($field)
                    })?,)+)*
                }
            }
        }

        /// The stepper of a method built from `params`.
        pub fn build(params: MethodParams) -> Box<dyn Stepper> {
            match params.method {
                $($(Method::$variant { .. } => Box::new($module::$method::from(params)),)+)*
            }
        }

        /// What `method` supports.
        pub fn capabilities(method: Method) -> Capabilities {
            match method {
                $($(Method::$variant { .. } => $module::$method::CAPABILITIES,)+)*
            }
        }

        /// Every registered method (a payload at its default) with its capabilities, in
        /// registry order.
        pub const METHODS: &[(data::FdmMethod, Capabilities)] = &[$($((
            data::FdmMethod::$variant $({ $field: None })?,
            $module::$method::CAPABILITIES,
        ),)+)*];
    };
}

/// The stepper of the setting `time.method` (steps never re-taken).
pub fn stepper(method: Method) -> Box<dyn Stepper> {
    build(MethodParams {
        method,
        restartable: false,
    })
}

/// The spellings of the methods with a capability, in registry order, for messages
/// (`` `a`, `b` or `c` `` with `conjunction` "or").
pub fn names_with(conjunction: &str, has: impl Fn(&Capabilities) -> bool) -> String {
    let names: Vec<String> = METHODS
        .iter()
        .filter(|(_, caps)| has(caps))
        .map(|&(m, _)| format!("`{}`", data::Method::from(m).name()))
        .collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} {conjunction} {last}", rest.join(", ")),
        None => String::new(),
    }
}

registry! {
    two_step::TwoStep {
        /// The report's two-step central difference (5.21, 5.24–5.30):
        /// y_{j+1} = y_{j−1} + (τ_j + τ_{j+1}) f(t_j, y_j).
        ///
        /// `central-difference` (fem's explicit method) is this scheme here.
        Report [CentralDifference],
        /// The report's scheme with a Robert–Asselin filter of the middle level:
        /// ȳ_j = y_j + ν (ȳ_{j−1} − 2 y_j + y_{j+1}).
        RobertAsselin { nu: f64 },
    }
    velocity_form::VelocityForm {
        /// One-step velocity (kick–drift–kick) form: no computational mode.
        VelocityForm,
    }
}
