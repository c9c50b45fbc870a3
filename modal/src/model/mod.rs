//! Assumed-mode model of a planar chain: integrals (set-up), body terms, chain assembly.

pub mod body;
pub mod chain;
pub mod integrals;

pub use chain::{Chain, EnergyParts, JointModel, LinkModel};
pub use integrals::LinkIntegrals;
