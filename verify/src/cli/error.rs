//! The command line's error: why a command did not succeed, and its exit status.

use thiserror::Error;

/// Why a command did not succeed, mapped to the documented exit status.
#[derive(Debug, Error)]
pub enum CliError {
    #[error("{0}")]
    Input(String),
    #[error("{0}")]
    Unsupported(String),
    #[error("{0}")]
    Failed(String),
    #[error("{0}")]
    Stopped(String),
    /// A result or file could not be written (serialized, created, renamed).
    #[error("{0}")]
    Output(String),
}

/// Exit status of [`CliError::Output`].
pub(super) const OUTPUT_STATUS: u8 = 5;

impl CliError {
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Failed(_) => 1,
            CliError::Input(_) => 2,
            CliError::Unsupported(_) => 3,
            CliError::Stopped(_) => 4,
            CliError::Output(_) => OUTPUT_STATUS,
        }
    }
}

impl From<data::LoadError> for CliError {
    fn from(e: data::LoadError) -> Self {
        CliError::Input(format!("error: {e}"))
    }
}

impl From<data::BackendError> for CliError {
    fn from(e: data::BackendError) -> Self {
        match e {
            data::BackendError::Unsupported(_) => CliError::Unsupported(e.to_string()),
            data::BackendError::InvalidSettings { .. }
            | data::BackendError::StabilityBound { .. } => CliError::Input(format!("error: {e}")),
            data::BackendError::Numerical { .. } => CliError::Stopped(format!("error: {e}")),
        }
    }
}

impl From<crate::Error> for CliError {
    fn from(e: crate::Error) -> Self {
        use crate::Error as E;
        match e {
            E::Backend(e) => e.into(),
            E::Io(e) => e.into(),
            E::InvalidQuantity { reason, .. } => {
                CliError::Input(format!("error: --quantity: {reason}"))
            }
            E::Scene(_)
            | E::Cases(_)
            | E::NoCaseMatches { .. }
            | E::RunFile { .. }
            | E::RunsNotComparable { .. }
            | E::InvalidOption { .. } => CliError::Input(format!("error: {e}")),
            E::QuantityNotProduced { .. } => CliError::Unsupported(format!("unsupported: {e}")),
            E::NoReference { .. } | E::ToleranceNotMet { .. } | E::ModelsDisagree { .. } => {
                CliError::Failed(e.to_string())
            }
        }
    }
}

impl From<std::io::Error> for CliError {
    fn from(e: std::io::Error) -> Self {
        CliError::Output(format!("error: cannot write output: {e}"))
    }
}
