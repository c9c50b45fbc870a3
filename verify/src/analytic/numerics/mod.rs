//! Small, self-contained numerical tools used by the analytic references.
//!
//! They are written here (not borrowed from a backend) so that an agreement between a backend and
//! an analytic reference cannot come from shared code:
//! * [`roots`] — Brent's safeguarded bracketing root finder and a sign-change scanner;
//! * [`ode`] — the Dormand–Prince 5(4) adaptive Runge–Kutta integrator;
//! * [`ddouble`] — double-double arithmetic for power series whose sums cancel heavily;
//! * [`quadrature`] — Gauss–Legendre rules.

pub mod ddouble;
pub mod ode;
pub mod quadrature;
pub mod roots;
