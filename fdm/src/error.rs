//! Typed errors of the finite-difference backend, converted to [`data::BackendError`] at the
//! trait boundary.

use data::BackendError;
use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum FdmError {
    #[error("unsupported: {0}")]
    Unsupported(String),
    #[error("invalid setting `{field}`: {message}")]
    InvalidSettings { field: String, message: String },
    /// A user-forced step exceeds the scheme's stability bound.
    #[error(
        "time step {dt:.3e} exceeds the {kind} stability bound {bound:.3e} at {location} (t = {t:.6e})"
    )]
    StabilityBound {
        t: f64,
        dt: f64,
        bound: f64,
        kind: String,
        location: String,
    },
    #[error("numerical failure at t = {t:.6e}: {message}")]
    Numerical { t: f64, message: String },
}

impl FdmError {
    /// Rejects a scene that switches on physics the finite-difference `model` does not carry:
    /// `Err` naming every switch in `switches` that is on (`subject` names the scene/link).
    pub(crate) fn check_switches(
        subject: &str,
        model: &str,
        switches: &[(&str, bool)],
    ) -> Result<(), Self> {
        let missing: Vec<&str> = switches
            .iter()
            .filter(|&&(_, on)| on)
            .map(|&(flag, _)| flag)
            .collect();
        if missing.is_empty() {
            return Ok(());
        }
        Err(FdmError::Unsupported(format!(
            "fdm: {subject} switches on {} — not implemented by the finite-difference {model}",
            missing.join(", ")
        )))
    }

    pub fn invalid(field: &str, message: impl Into<String>) -> Self {
        FdmError::InvalidSettings {
            field: field.to_string(),
            message: message.into(),
        }
    }
}

impl From<FdmError> for BackendError {
    fn from(e: FdmError) -> Self {
        match e {
            FdmError::Unsupported(s) => BackendError::Unsupported(s),
            FdmError::InvalidSettings { field, message } => {
                BackendError::InvalidSettings { field, message }
            }
            FdmError::StabilityBound {
                t,
                dt,
                bound,
                kind,
                location,
            } => BackendError::StabilityBound {
                t,
                dt,
                bound,
                bound_kind: kind,
                location,
            },
            FdmError::Numerical { t, message } => BackendError::Numerical { t, message },
        }
    }
}
