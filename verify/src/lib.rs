//! # verify — which discretization can I trust, how wrong is it, what does it cost?
//!
//! Turns the three independent solvers (`fem`, `fdm`, `modal`) into answers: analytic
//! references computed by code, verification cases declared as data, convergence and
//! work-precision studies, the stability suite, reports — and the `flexverify` command line.

pub mod analytic;
pub mod cli;
pub mod coverage;
pub mod output;
pub mod plot;
pub mod registry;
pub mod stability;
pub mod study;
pub mod suite;
