//! Contact and friction as objects the driver consumes ([`crate::driver`]) and the methods see
//! through [`crate::method::StepConstraint`].
//!
//! * [`contact`]: the tip contact — gap g and its gradient G, the constraint force of a held
//!   phase (discrete gradient, bordered Newton update), the index-1 normal force, the plastic
//!   impact map and the drift projection (seed 000: impact, constrained sliding, release);
//! * [`contact::friction`]: the bilateral wall's Coulomb friction and stick constraint, the
//!   index-1 wall forces (seed 001: stick–slip), a refinement of the contact it belongs to;
//! * [`wall`]: circle and line geometry of a bilateral wall;
//! * `mass_solve`: solves with the mass matrix M(q) of these maps (sparse, O(n));
//! * [`massless`]: the balances of massless section rotations in contact runs.
//!
//! Locating the events (roots of the gap, the normal force, the slip velocity and the
//! Coulomb margin inside a step) is the driver's ([`crate::driver::contact_events`],
//! [`crate::driver::stick_slip`]): it re-solves the step shorter with the method.

pub mod contact;
pub(crate) mod mass_solve;
pub mod massless;
pub mod wall;
