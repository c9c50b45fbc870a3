//! `flexverify converge` and `flexverify recommend`: refinement studies and work-precision.

use crate::cli::args::{CommonOpts, Refine};
use crate::cli::CliError;

pub fn converge_command(_scene: &str, _quantity: &str, _refine: Refine, _opts: &CommonOpts) -> Result<(), CliError> {
    Err(CliError::Unsupported("unsupported: convergence studies are not implemented yet".into()))
}

pub fn recommend_command(_scene: &str, _quantity: &str, _tol: f64, _opts: &CommonOpts) -> Result<(), CliError> {
    Err(CliError::Unsupported("unsupported: recommendations are not implemented yet".into()))
}
