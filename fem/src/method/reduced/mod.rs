//! Systems written on the null space of their velocity constraints, and the methods that step
//! them: one type per method behind [`ReducedStepper`].
//!
//! A reduced system has coordinates q (n of them) and independent speeds ν (m ≤ n) with
//!
//! ```text
//! q̇ = S(q) ν,   M̄(q) ν̇ + b(q, ν) = Q(t, ν),
//! ```
//!
//! M̄ = SᵀMS the reduced mass matrix (symmetric positive definite), b the velocity terms of the
//! inertia with the gravity and elastic forces, Q the applied generalized forces (inputs and
//! viscous friction). Velocity constraints A(q) q̇ = 0 (nonholonomic ones included) hold by
//! construction, A S ≡ 0, so no method has to correct a drift. Such a system is not a
//! [`crate::system::System`]: its speeds are not the rates of its coordinates, so the
//! second-order methods of [`crate::method`] cannot step it.
//!
//! The problem is [`ReducedSystem`] (kinematics, inverse dynamics with the reduced mass matrix,
//! applied forces, the constant parts of the Newton matrix, the booking of the works); a method
//! advances a [`ReducedState`] by one step of a length the driver chose and knows nothing of
//! the model; the driver (the family's module, [`crate::mobile`]) lands on the inputs'
//! breakpoints and samples the outputs.
//!
//! Adding a method: one new file here implementing [`ReducedStepper`] and `From<`[`ReducedParams`]`>`,
//! and its line in the registry at the end of this file (which declares the module and maps the
//! settings' method to it).

use super::state::FixedStepCounters;
use crate::error::FemError;
use crate::settings::Method;

/// The problem a reduced method steps (module docs).
pub trait ReducedSystem {
    /// The integrated works of the system's energy ledger.
    type Works;

    /// Number of coordinates n.
    fn coordinates(&self) -> usize;

    /// Number of speeds m.
    fn speeds(&self) -> usize;

    /// The configuration q̄ = q + ½h S(q̄) ν̄ reached from q over half a step of length h at
    /// constant speeds ν̄ (the system solves it with its kinematics' structure).
    fn midpoint_configuration(&mut self, q: &[f64], nubar: &[f64], h: f64, qbar: &mut [f64]);

    /// M̄(q) ν̇ + b(q, ν) into `force` (one inverse-dynamics pass); with `mass`, also M̄(q)
    /// (row-major m × m).
    fn inertia_forces(
        &mut self,
        q: &[f64],
        nu: &[f64],
        nudot: &[f64],
        mass: Option<&mut [f64]>,
        force: &mut [f64],
    );

    /// Q(t, ν) into `out`.
    fn applied_forces(&mut self, t: f64, nu: &[f64], out: &mut [f64]);

    /// Adds c_k K + c_d D to the row-major m × m `matrix`: K the constant elastic stiffness on
    /// the speeds, D the viscous friction (−∂Q/∂ν).
    fn add_stiffness_and_damping(&self, c_k: f64, c_d: f64, matrix: &mut [f64]);

    /// Books into `works` the works of a step by the one-point quadrature weight·P(t, ν) of
    /// each power P (inputs, friction).
    fn book(&mut self, t: f64, nu: &[f64], weight: f64, works: &mut Self::Works);
}

/// Time, coordinates and speeds of a reduced system.
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedState {
    pub t: f64,
    pub q: Vec<f64>,
    pub nu: Vec<f64>,
}

/// One integration method for a [`ReducedSystem`].
pub trait ReducedStepper<S: ReducedSystem + ?Sized> {
    /// Advances `state` by one step of length h and books the step's works into `works`; an
    /// error when the step cannot be taken (the state is then unchanged).
    fn step(
        &mut self,
        sys: &mut S,
        state: &mut ReducedState,
        works: &mut S::Works,
        h: f64,
    ) -> Result<(), FemError>;

    /// The work done so far.
    fn counters(&self) -> FixedStepCounters;
}

/// What a reduced method is built from: the system's numbers of coordinates and speeds.
#[derive(Debug, Clone, Copy)]
pub struct ReducedParams {
    pub coordinates: usize,
    pub speeds: usize,
}

/// The registry: one line per method, `Variant => module::Type`, declaring the method's module
/// and building its `Type` (from [`ReducedParams`]) for the settings' `Method::Variant`.
macro_rules! registry {
    ($($variant:ident => $module:ident :: $method:ident,)*) => {
        $(pub mod $module;)*

        /// The stepper of `method` for `sys`; `None` when the method does not step reduced
        /// systems ([`names`] lists those that do).
        pub fn stepper<S: ReducedSystem + ?Sized>(
            method: Method,
            sys: &S,
        ) -> Option<Box<dyn ReducedStepper<S>>> {
            let params = ReducedParams {
                coordinates: sys.coordinates(),
                speeds: sys.speeds(),
            };
            #[allow(unreachable_patterns)]
            match method {
                $(Method::$variant => Some(Box::new($module::$method::from(params))),)*
                _ => None,
            }
        }

        /// The spellings of the methods that step reduced systems, in registry order
        /// (`` `a`, `b` or `c` `` with `conjunction` "or").
        pub fn names(conjunction: &str) -> String {
            crate::settings::spelled_list([$(Method::$variant),*], conjunction)
        }
    };
}

registry! {
    ImplicitMidpoint => implicit_midpoint::ReducedMidpoint,
}
