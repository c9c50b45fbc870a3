//! Refinement studies (`flexverify converge`, `flexverify recommend`, the full suite's
//! ladders): refinement ladders, observed orders, Richardson references and work-precision
//! (error against cost).
//!
//! One job per module, in the order a study runs:
//! * [`ladder`] — which rungs (space or time refinement) each backend measures;
//! * [`measure`] — one rung's value, repeated timings and work counters;
//! * [`run`] — the ladders rung by rung ([`run::converge`], and from given measurements for
//!   sharded studies);
//! * [`summary`] — the study's data and what it found: Richardson estimates, reference,
//!   errors, observed orders and disagreement between backends;
//! * [`recommend`] — the cheapest discretization meeting a tolerance;
//! * [`table`] — the study as tables, CSV, JSON and plots;
//! * [`survey`] — the full suite's ladders and their survey table.

pub mod ladder;
pub mod measure;
pub mod recommend;
pub mod run;
pub mod summary;
pub mod survey;
pub mod table;
