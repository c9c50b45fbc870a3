//! Element library: one-dimensional shape functions and element operators, each testable alone.
//!
//! * [`quadrature`] — Gauss–Legendre rules on an interval;
//! * [`hermite`] — Hermite-cubic transverse interpolation (v, v′ at each node);
//! * [`euler_bernoulli`] — consistent mass, bending stiffness, geometric stiffness, von Kármán
//!   internal force and tangent for the extensible beam (linear axial interpolation);
//! * [`quintic`] — hierarchical Hermite-quintic Euler–Bernoulli element (cubic + two C¹ bubbles,
//!   O(h⁸) frequencies) for modes and statics;
//! * [`timoshenko`] — Timoshenko element with cubic v and quadratic θ (interior DOFs kept global),
//!   free of shear locking, O(h⁴) frequencies.

pub mod euler_bernoulli;
pub mod hermite;
pub mod quadrature;
pub mod quintic;
pub mod timoshenko;

/// Small dense 4×4 matrix of an element (row-major).
pub type Mat4 = [[f64; 4]; 4];
