//! Assumed-mode model of a planar chain: integrals (set-up), body terms, chain assembly.

pub mod body;
pub mod chain;
pub mod elbow;
pub mod integrals;
pub mod link;
pub mod section;

pub use chain::{Chain, EnergyParts};
pub use elbow::Elbow;
pub use integrals::LinkIntegrals;
pub use link::{JointModel, LinkModel};
pub use section::{CondensedBlocks, Section, SectionKind, SectionParams};
