//! Assumed-mode model of a planar chain: integrals (set-up), body terms, chain assembly.

pub mod body;
pub mod chain;
pub mod integrals;
pub mod section;

pub use chain::{Chain, EnergyParts, JointModel, LinkModel};
pub use integrals::LinkIntegrals;
pub use section::{Section, SectionKind, SectionParams};
