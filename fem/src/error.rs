//! Typed errors of the FEM crate, converted to [`data::BackendError`] at the trait boundary.

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum FemError {
    #[error("unsupported: {0}")]
    Unsupported(String),
    #[error("invalid setting `{field}`: {message}")]
    InvalidSettings { field: String, message: String },
    #[error(
        "time step {dt:.3e} exceeds the {bound_kind} stability bound {bound:.3e} at {location}"
    )]
    StabilityBound {
        dt: f64,
        bound: f64,
        bound_kind: String,
        location: String,
    },
    #[error("numerical failure at t = {t:.6e}: {message}")]
    Numerical { t: f64, message: String },
    /// The solution left the model's range or the iteration failed during a run: the driver
    /// turns this into a `Stopped` verdict and keeps the output computed so far.
    #[error("run stopped at t = {t:.6e}: {what}")]
    Runaway {
        t: f64,
        what: String,
        location: Option<String>,
        why: String,
        remedy: String,
    },
    #[error("singular {what} matrix at pivot {pivot} (t = {t:.6e})")]
    Singular { what: String, pivot: usize, t: f64 },
}

impl FemError {
    pub fn unsupported(what: impl Into<String>) -> Self {
        FemError::Unsupported(what.into())
    }

    /// A runaway as the diagnostic of a run that stops early (its results up to then are
    /// kept); every other error stays an error.
    pub fn into_stop_diagnostic(self) -> Result<data::Diagnostic, FemError> {
        match self {
            FemError::Runaway {
                t,
                what,
                location,
                why,
                remedy,
            } => Ok(data::Diagnostic {
                t,
                what,
                location,
                why,
                remedy,
            }),
            other => Err(other),
        }
    }
}

/// The diagnostic of a run whose sampled state is no longer finite: the implicit step diverged.
pub fn non_finite_state(t: f64) -> data::Diagnostic {
    data::Diagnostic {
        t,
        what: "non-finite state".into(),
        location: None,
        why: "the implicit step diverged".into(),
        remedy: "reduce --dt".into(),
    }
}

impl From<FemError> for data::BackendError {
    fn from(e: FemError) -> Self {
        use data::BackendError as B;
        match e {
            FemError::Unsupported(s) => B::Unsupported(s),
            FemError::InvalidSettings { field, message } => B::InvalidSettings { field, message },
            FemError::StabilityBound {
                dt,
                bound,
                bound_kind,
                location,
            } => B::StabilityBound {
                t: 0.0,
                dt,
                bound,
                bound_kind,
                location,
            },
            FemError::Numerical { t, message } => B::Numerical { t, message },
            FemError::Runaway { t, what, why, .. } => B::Numerical {
                t,
                message: format!("{what}: {why}"),
            },
            FemError::Singular { what, pivot, t } => B::Numerical {
                t,
                message: format!("singular {what} matrix at pivot {pivot}"),
            },
        }
    }
}
