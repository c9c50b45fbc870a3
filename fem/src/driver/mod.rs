//! The driver: steps a [`Chain`](crate::chain::Chain) with a [`Stepper`](crate::method::Stepper)
//! to requested stop times, locates and applies contact events, and books the works of the
//! energy ledger.
//!
//! * Step control: the driver lands exactly on requested times (outputs, torque-law
//!   breakpoints, t_end), so discontinuities and events are never stepped over; laws are
//!   evaluated as left limits on a step that ends on a discontinuity, and the method restarts
//!   there from a consistent acceleration ([`crate::method::start`]). Fixed steps (Newton
//!   failures retry the stretch with quarter steps, grown back afterwards) or adaptive ones
//!   (`rtol`: the method's error estimate, step ratio 0.9·err^(−1/3) ∈ [0.2, 2]). A method
//!   that needs equal steps between stops (central difference) gets them.
//! * Events: a contact ([`crate::events::contact::Contact`]) is handed to the method as a
//!   [`crate::method::StepConstraint`] while it is held; after each converged trial the
//!   driver watches its event functions and locates their roots inside the step by
//!   re-solving it shorter, so the event state satisfies the method's equations (an
//!   impact's search starts at the gap's root on the method's dense output,
//!   [`Stepper::dense`](crate::method::Stepper::dense)) ([`contact_events`]: impact, release,
//!   grazing; [`stick_slip`]:
//!   slip stop and breakaway), then applies the reset at the accepted state. Contact runs
//!   with massless section rotations end every step on their balance
//!   ([`crate::events::massless`]).
//! * Ledger: works by the trapezoidal rule on the joint quantities (applied and required
//!   torque, joint damper) and on the midpoint velocity (Kelvin–Voigt, applied loads), unless
//!   the method books its own ([`Stepper::commit`](crate::method::Stepper::commit): the
//!   energy-midpoint quadrature, which closes its ledger to the Newton tolerance).
//!
//! Modules, each using only those listed before it: [`state`] — the [`Driver`], its set-up,
//! the solve of one trial step and the acceptance of a step with its works;
//! [`contact_events`] — the unilateral events located inside a step (and the Illinois secant
//! on the step length both contact kinds use); [`stick_slip`] — the bilateral friction
//! contact's switches; [`step`] — the step control, which dispatches a converged trial to the
//! events of the scene's contact.
//!
//! Module graph: model ([`crate::chain`]) ← methods ([`crate::method`]) ← events
//! ([`crate::events`]) ← driver ← outputs ([`crate::run`]).

pub mod contact_events;
pub mod fixed_steps;
pub mod state;
pub mod step;
pub mod stick_slip;

pub use state::{Driver, Rejection, StopReason};
