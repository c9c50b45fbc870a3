//! Assumed-mode model of a planar chain: integrals (set-up), body terms, chain assembly.

pub mod body;
pub mod chain;
pub mod integrals;
pub mod link;
pub mod section;

pub use chain::{Chain, EnergyParts};
pub use integrals::LinkIntegrals;
pub use link::{JointModel, LinkModel};
pub use section::{Section, SectionKind, SectionParams};
