//! Typed errors of the rocket model, converted to [`data::BackendError`] at the API boundary.

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum RocketError {
    /// The scene asks for physics this backend does not model.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// A setting is out of range.
    #[error("invalid setting `{field}`: {message}")]
    InvalidSetting { field: String, message: String },
    /// The eigenfunction computation failed (e.g. mass matrix not positive definite).
    #[error("eigenfunction computation failed for the {field} field: {message}")]
    Basis {
        field: &'static str,
        message: String,
    },
    /// The reduced mass matrix lost positive definiteness during a run.
    #[error("reduced mass matrix is not positive definite at t = {t:.6e} (pivot {pivot})")]
    MassMatrix { t: f64, pivot: usize },
}

impl RocketError {
    pub fn invalid(field: &str, message: impl Into<String>) -> Self {
        RocketError::InvalidSetting {
            field: field.to_string(),
            message: message.into(),
        }
    }
}

impl From<RocketError> for data::BackendError {
    fn from(e: RocketError) -> Self {
        match e {
            RocketError::Unsupported(what) => data::BackendError::Unsupported(what),
            RocketError::InvalidSetting { field, message } => {
                data::BackendError::InvalidSettings { field, message }
            }
            RocketError::Basis { .. } => data::BackendError::Numerical {
                t: 0.0,
                message: e.to_string(),
            },
            RocketError::MassMatrix { t, .. } => data::BackendError::Numerical {
                t,
                message: e.to_string(),
            },
        }
    }
}
