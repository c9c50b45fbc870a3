//! Typed errors of the modal backend, converted to `data::BackendError` at the trait boundary.

use thiserror::Error;

use crate::basis::BasisError;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModalError {
    #[error("unsupported: {0}")]
    Unsupported(String),
    #[error("invalid setting `{field}`: {message}")]
    InvalidSettings { field: String, message: String },
    #[error("basis construction failed for link {link}: {source}")]
    Basis { link: usize, source: BasisError },
    #[error("numerical failure at t = {t:.6e}: {message}")]
    Numerical { t: f64, message: String },
}

impl ModalError {
    pub fn invalid(field: &str, message: impl Into<String>) -> Self {
        ModalError::InvalidSettings {
            field: field.to_string(),
            message: message.into(),
        }
    }
}

impl From<ModalError> for data::BackendError {
    fn from(e: ModalError) -> Self {
        match e {
            ModalError::Unsupported(s) => data::BackendError::Unsupported(s),
            ModalError::InvalidSettings { field, message } => {
                data::BackendError::InvalidSettings { field, message }
            }
            ModalError::Basis { .. } => data::BackendError::Numerical {
                t: 0.0,
                message: e.to_string(),
            },
            ModalError::Numerical { t, message } => data::BackendError::Numerical { t, message },
        }
    }
}
