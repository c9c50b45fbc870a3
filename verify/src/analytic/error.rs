//! Typed errors of the analytic references.

use thiserror::Error;

/// Why an analytic reference could not be produced.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AnalyticError {
    /// A physical parameter is outside the range where the formula holds.
    #[error("invalid parameter {name} = {value}: {why}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    /// The root finder was given an interval without a sign change.
    #[error("root not bracketed in [{a}, {b}]: f(a) = {fa}, f(b) = {fb}")]
    NotBracketed { a: f64, b: f64, fa: f64, fb: f64 },
    /// A function value was NaN or infinite.
    #[error("non-finite value {value} of {what} at x = {x}")]
    NonFinite {
        what: &'static str,
        x: f64,
        value: f64,
    },
    /// A linear system is singular (or its solution not finite).
    #[error("{what}: singular {size} × {size} system")]
    Singular { what: &'static str, size: usize },
    /// An iteration did not converge.
    #[error("{what}: no convergence after {iterations} iterations")]
    NoConvergence {
        what: &'static str,
        iterations: usize,
    },
    /// Fewer roots than requested were found in the scanned range.
    #[error("{what}: found only {found} of {wanted} roots below {limit}")]
    TooFewRoots {
        what: &'static str,
        found: usize,
        wanted: usize,
        limit: f64,
    },
    /// The adaptive integrator's step fell below round-off.
    #[error("ODE integrator: step size {h:e} too small at t = {t}")]
    StepSizeTooSmall { t: f64, h: f64 },
    /// The adaptive integrator exceeded its step budget.
    #[error("ODE integrator: more than {max_steps} steps before t = {t}")]
    TooManySteps { t: f64, max_steps: usize },
    /// The scene asks for physics that this analytic reference does not model.
    #[error("unsupported: {0}")]
    Unsupported(String),
}

pub type Result<T> = std::result::Result<T, AnalyticError>;

/// Checks that a parameter is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(AnalyticError::InvalidParameter {
            name,
            value,
            why: "must be finite and > 0",
        })
    }
}

/// Checks that a parameter is finite and non-negative.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(AnalyticError::InvalidParameter {
            name,
            value,
            why: "must be finite and >= 0",
        })
    }
}

/// Checks that a parameter is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(AnalyticError::InvalidParameter {
            name,
            value,
            why: "must be finite",
        })
    }
}
