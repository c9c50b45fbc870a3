//! # Analytic references
//!
//! Closed forms and tightly converged semi-analytic solutions against which the three
//! backends are checked. Every number is *computed* here (Brent root finding to ≤ 1e-14
//! relative, Dormand–Prince shooting at tolerance ≤ 1e-12, double-double power series) — no
//! table is typed in. Each function documents its equation, its source and its units.
//!
//! * [`beam`] — Euler–Bernoulli βₙL for clamped–free, free–free, pinned–free, clamped–pinned;
//!   bending frequencies; cantilever with tip mass and tip inertia; axial bar (with tip mass).
//! * [`timoshenko`] — clamped–free Timoshenko frequencies below and above the cut-off.
//! * [`statics`] — linear cantilever statics and the large-deflection elastica.
//! * [`rotating`] — flapwise (Frobenius series) and in-plane rotating-cantilever frequencies.
//! * [`chain_modes`] — the straight spring-jointed chain of Euler–Bernoulli links (joint
//!   springs, hub and tip bodies) linearized about its set points: exact dynamic stiffness,
//!   Wittrick–Williams root count; its clamped (K → ∞) and pinned (K₁ → 0) single-beam limits.
//! * [`rigid`] — rigid-link limits: torque-driven link, seed 001's friction-constrained link
//!   (eq. 71), the rigid two-link Barhorst arm, the static normal force of an arm on its tip.
//! * [`payload_link`] — the 3-D link with an offset payload (seed 002): bending in both planes
//!   with the payload's mass, offset and inertia (rotating, hub-coupled), torsion, axial, linear
//!   and large-deflection sag (the seed's formula against the elastica), the rigid-base limit.
//! * [`rocket`] — rigid translation of the variable-mass rocket (rocket equation with gravity).
//! * [`rocket_modes`] — free-free axial and bending frequencies of the rocket at ignition: the
//!   stepped beam with its spring-mounted, spring-coupled masses, exact dynamic stiffness and
//!   the Wittrick–Williams count.
//! * [`numerics`] — the root finder, the adaptive Runge–Kutta and double-double arithmetic,
//!   written here so that no code is shared with a backend.

pub mod beam;
pub mod chain_modes;
mod error;
pub mod numerics;
pub mod payload_link;
pub mod rigid;
pub mod rocket;
pub mod rocket_modes;
pub mod rotating;
pub mod statics;
pub mod timoshenko;

pub use beam::{
    BeamSupport, axial_frequencies_hz, axial_tip_mass_frequencies_hz, beam_eigenvalue,
    beam_eigenvalues, bending_frequencies_hz, cantilever_tip_mass_frequencies_hz,
    cantilever_tip_mass_roots,
};
pub use chain_modes::{ChainJoint, ChainLink, SpringJointedChain};
pub use error::{AnalyticError, Result};
pub use rigid::constrained::{ConstrainedRigidLink, ConstrainedState, evolve_quadratic_friction};
pub use rigid::resting::{RestingArm, RestingState, resting_from_chain, resting_on_tip};
pub use rigid::single::{RigidLink, RigidLinkState};
pub use rigid::two_link::{RigidTwoLink, TwoLinkHistory, output_times};
pub use rocket::{RocketState, RocketTranslation};
pub use rotating::{
    RotatingPlane, flapwise_frequencies, rotating_frequencies, rotating_frequencies_hz,
};
pub use statics::{
    Elastica, TipResponse, cantilever_elastica, cantilever_tip_load, cantilever_uniform_load,
};
pub use timoshenko::{TimoshenkoBeam, timoshenko_clamped_free_hz};
