//! Element library: one-dimensional shape functions and element operators, each testable alone.
//!
//! * [`quadrature`] — Gauss–Legendre rules on an interval;
//! * [`hermite`] — Hermite-cubic transverse interpolation (v, v′ at each node);
//! * [`euler_bernoulli`] — consistent mass, bending stiffness, geometric stiffness, von Kármán
//!   internal force and tangent for the extensible beam (linear axial interpolation);
//! * [`timoshenko`] — interdependent-interpolation (IIE) Timoshenko element, free of shear locking.

pub mod euler_bernoulli;
pub mod hermite;
pub mod quadrature;
pub mod timoshenko;

/// Small dense 4×4 matrix of an element (row-major).
pub type Mat4 = [[f64; 4]; 4];
