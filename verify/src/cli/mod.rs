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
mod compare;
mod error;
mod progress;
mod stdout;
mod studies;

pub use args::{Cli, Command, CommonOpts};
pub use error::CliError;

use std::process::ExitCode;

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
