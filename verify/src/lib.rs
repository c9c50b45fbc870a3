//! # verify — which discretization can I trust, how wrong is it, what does it cost?
//!
//! Turns the three independent solvers (`fem`, `fdm`, `modal`) into answers: analytic
//! references computed by code, verification cases declared as data, convergence and
//! work-precision studies, the stability suite, reports — and the `flexverify` command line.
//!
//! The library is usable without the command line: [`suite::run_cases`] evaluates
//! verification cases into [`suite::evaluate::Outcome`]s, [`study::run::converge`] and
//! [`study::recommend::recommend`] run refinement studies, [`stability::run_stability`]
//! judges the stiff and extreme cases, [`compare::compare_runs`] sets two run results side by
//! side (contact-episode boundaries, whole histories); each fails only with an [`Error`] and
//! reports long work to a [`progress::Progress`] observer. Module dependencies run one way: the
//! leaves `analytic`, `error`, `output`, `plot`, `progress`, `registry` ← `suite` ← `study`, and
//! `suite` ← `compare` (its history differences); `stability` uses `suite` only for its
//! [`suite::Suite`] selector; [`cli`] (clap, exit codes, printing, the progress bar) sits on top
//! of everything and nothing below it depends on it.

pub mod analytic;
pub mod cli;
pub mod compare;
pub mod coverage;
pub mod error;
pub mod output;
pub mod plot;
pub mod progress;
pub mod registry;
pub mod report;
pub mod shard;
pub mod stability;
pub mod study;
pub mod suite;
pub mod work;

pub use error::Error;
