//! The `flexverify` command line: argument definitions, dispatch, printing, and the mapping of
//! library errors to exit statuses. The only module that knows clap and the terminal.
//!
//! Exit status: 0 success; 1 a verification check failed; 2 bad input (scene file,
//! arguments); 3 unsupported (a backend or subcommand cannot do what was asked); 4 a run stopped
//! early or failed numerically, with a diagnostic (its partial results, if any, are still
//! written); 5 output could not be
//! written; 141 the reader of standard output closed the pipe (module `stdout`).

pub mod args;
mod checks;
mod commands;
mod progress;
mod stdout;
mod studies;

pub use args::{Cli, Command, CommonOpts};

use std::process::ExitCode;

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
const OUTPUT_STATUS: u8 = 5;

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
            E::Scene(_) | E::Cases(_) | E::NoCaseMatches { .. } => {
                CliError::Input(format!("error: {e}"))
            }
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

/// Runs a parsed command line; prints results to stdout and the error (if any) to stderr.
pub fn run(cli: Cli) -> ExitCode {
    // Parallelism lives at the level of cases and sweeps (rayon); inside one solve faer runs
    // sequentially, which keeps results bit-identical and wall times comparable.
    faer::set_global_parallelism(faer::Par::Seq);
    match commands::dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::from(e.exit_code())
        }
    }
}
