//! Time-integration methods: one type per method behind the [`Stepper`] trait.
//!
//! A method advances R(q, q̇, q̈, t) = 0 of a [`crate::system::System`] over one step of
//! length h from the state at the step start to a trial end ([`StepState`]) and reports how
//! the attempt ended ([`Trial`]: converged, with its local error estimate when the steps are
//! adaptive, or a Newton failure); it gives the state inside the step by its continuous
//! extension ([`Stepper::dense`]). The driver ([`crate::driver`]) chooses h, accepts or rejects
//! the trial, counts the work ([`Counters`]), books the works and handles events, and reports
//! why each of its steps returned ([`crate::driver::StopReason`]). A method never names a scene family or a contact: a bilateral constraint (a tip
//! held on a surface) reaches it only through [`StepConstraint`], which adds the constraint
//! force and the bordered Newton update to the method's own iteration.
//!
//! * [`generalized_alpha`]: implicit generalized-α (Chung–Hulbert, Arnold–Brüls form),
//!   fixed or adaptive steps;
//! * [`central_difference`]: explicit central difference (velocity-Verlet form, the damping
//!   implicit at the end velocity) under its stability bound 2/ω_max;
//! * [`energy_midpoint`]: the energy-consistent midpoint (discrete-gradient) scheme;
//! * [`implicit_midpoint`]: the implicit midpoint rule (one-stage Gauss), fixed or adaptive
//!   steps.
//! * [`bathe`]: Bathe's composite method (trapezoidal half step, then a three-point backward
//!   difference): second order, no high-frequency ringing, fixed or adaptive steps.
//!
//! A held [`StepConstraint`] is accepted by every method. The two midpoint schemes
//! take the mean acceleration ā as Newton unknown, q₁ = q₀ + h q̇₀ + (h²/2) ā (border factor
//! ∂q₁/∂ā = h²/2), and the force is the discrete gradient ∇̄g in the metric M(q̄), so it does
//! no work over a step. Generalized-α takes q̈₁ (border factor βh²(1−α_f)/(1−α_m)) with the same
//! force at t₁, balanced so that its average over the step does the end force's work, and it
//! recomputes its acceleration history at every event ([`generalized_alpha`] docs). Bathe holds
//! the constraint at the end of each sub-step (border factors h²/16 and h²/9), with the
//! trapezoidal sub-step's start force balanced as in generalized-α and q̈₀ recomputed at every
//! event; on the bilateral wall the friction work of both sub-steps adds up
//! ([`StepConstraint::start_sub_step`], [`bathe`] docs). Explicit central difference has no Newton iteration to border: it holds
//! the unilateral constraint by projection (start force so that g(q₁) is met, end force so
//! that ∇g(q₁)·q̇₁ = 0; [`central_difference`] docs), on the friction wall with the sliding
//! friction along the normal force and two rows while the tip sticks.
//!
//! Shared machinery: the Newton matrix S = c_a M + c_v C + c_q K and its solver
//! ([`newton`]), the consistent acceleration of a (re)start ([`start`]), the method–driver
//! contract (module `step`: [`Stepper`], [`StepContext`], [`StepConstraint`]) and the state and
//! counters a method carries (module `state`: [`StepState`], [`Counters`], [`Works`]). This
//! file holds only the registry, so the methods depend on `step` and `state`, never on it.
//!
//! Systems written on the null space of their velocity constraints (q̇ = S(q)ν, the mobile
//! manipulator) are not [`crate::system::System`]s; their methods are [`reduced`]'s, behind
//! its own stepper trait and registry.
//!
//! Adding a method: one new file here implementing [`Stepper`] and `From<`[`MethodParams`]`>`,
//! and its line in the registry at the end of this file (which declares the module and maps the
//! settings' method to it); in `data`, one row of the method table (`data/src/methods.rs`: its
//! [`data::Method`] variant, spellings and backends, from which [`data::FemMethod`] follows).

pub mod newton;
pub mod reduced;
pub mod start;
mod state;
mod step;

pub use newton::{JacobianKind, NewtonSystem};
pub use state::{Adaptive, Counters, FixedStepCounters, StepState, Works};
pub use step::{
    ConstraintView, ProjectionRows, StepConstraint, StepContext, Stepper, Trial, hermite_dense,
};
pub(crate) use step::{HeldConstraint, unconverged, update_tolerance};

use crate::settings::Method;
use crate::system::System;

/// What a method supports; the run refuses a scene or a setting a method cannot step, naming
/// the methods that can ([`names_with`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    /// Stepped under its stability bound in equal steps: needs a non-singular M, no
    /// adaptive steps and no held constraint.
    pub explicit: bool,
    /// Has a local error estimate (adaptive steps with `time.rtol`).
    pub adaptive: bool,
    /// Steps prescribed joint motion.
    pub prescribed_joints: bool,
    /// Accepts a held contact ([`StepConstraint`]).
    pub held_constraint: bool,
    /// Holds a bilateral wall with its stick–slip friction phases (friction work and stick
    /// multiplier booked once per step).
    pub bilateral_constraint: bool,
    /// Projects massless section rotations onto their balance in contact runs, booking the
    /// removed strain energy (Timoshenko links without rotary inertia).
    pub projects_massless: bool,
    /// Steps a mass that changes in time, M(t)q̈ = F (the burning rocket, whose burnt mass
    /// leaves at the local velocity: no Ṁq̇ term): the method's equations hold at its
    /// evaluation times with M taken there, and it keeps no M from one step to the next. The
    /// energy-consistent midpoint scheme does not: its momentum form M(q₁)q̇₁ − M(q₀)q̇₀ would
    /// book the burnt mass's momentum as a force.
    pub variable_mass: bool,
}

/// What a method is built from: the system's number of DOFs and the settings' generalized-α
/// spectral radius (the methods that need neither ignore them).
#[derive(Debug, Clone, Copy)]
pub struct MethodParams {
    pub n: usize,
    pub rho_inf: f64,
}

/// The registry: one line per method, `Variant => module::Type`, declaring the method's module,
/// building its `Type` (from [`MethodParams`]) for the settings' `Method::Variant` and reading
/// its `Type::CAPABILITIES`.
macro_rules! registry {
    ($($variant:ident => $module:ident :: $method:ident,)*) => {
        $(pub mod $module;)*

        /// The stepper of a method for a system of `n` DOFs (`rho_inf`: generalized-α spectral
        /// radius).
        pub fn stepper<S: System + ?Sized>(
            method: Method,
            n: usize,
            rho_inf: f64,
        ) -> Box<dyn Stepper<S>> {
            let params = MethodParams { n, rho_inf };
            match method {
                $(Method::$variant => Box::new($module::$method::from(params)),)*
            }
        }

        /// What `method` supports.
        pub fn capabilities(method: Method) -> Capabilities {
            match method {
                $(Method::$variant => $module::$method::CAPABILITIES,)*
            }
        }

        /// The spellings of the methods with a capability, in registry order, for messages
        /// (`` `a`, `b` or `c` `` with `conjunction` "or").
        pub fn names_with(conjunction: &str, has: impl Fn(&Capabilities) -> bool) -> String {
            crate::settings::spelled_list(
                [$(Method::$variant),*]
                    .into_iter()
                    .filter(|&m| has(&capabilities(m))),
                conjunction,
            )
        }
    };
}

registry! {
    GeneralizedAlpha => generalized_alpha::GeneralizedAlpha,
    CentralDifference => central_difference::CentralDifference,
    EnergyMidpoint => energy_midpoint::EnergyMidpoint,
    ImplicitMidpoint => implicit_midpoint::ImplicitMidpoint,
    Bathe => bathe::Bathe,
}
