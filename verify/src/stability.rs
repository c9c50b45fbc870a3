//! `flexverify stability`: stiff and extreme cases.

use std::path::Path;

use crate::cli::CliError;
use crate::cli::args::Suite;
use crate::output::Format;

pub fn command(_suite: Suite, _format: Format, _out: Option<&Path>) -> Result<(), CliError> {
    Err(CliError::Unsupported("unsupported: the stability suite is not implemented yet".into()))
}
