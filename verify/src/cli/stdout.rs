//! Writing results to standard output.
//!
//! `print!` panics when the reader closes the pipe (`flexverify verify | head`). The command line
//! writes through [`out!`] and [`outln!`] instead: a closed pipe ends the process silently with
//! status 141, the status of a Unix tool ended by SIGPIPE (so `set -o pipefail` still sees that
//! the output was cut short); any other write error is reported once and ends it with status 5.

use std::io::Write;

/// Exit status when the reader of standard output has gone away.
const CLOSED_PIPE_STATUS: i32 = 141;

/// Writes formatted text to standard output, ending the process on a write error.
pub(crate) fn write_fmt(args: std::fmt::Arguments<'_>) {
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout.write_fmt(args).and_then(|()| stdout.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(CLOSED_PIPE_STATUS);
        }
        eprintln!("error: cannot write to standard output: {e}");
        std::process::exit(i32::from(super::error::OUTPUT_STATUS));
    }
}

/// `print!` to standard output that ends quietly on a closed pipe.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::stdout::write_fmt(format_args!($($arg)*))
    };
}

/// `println!` to standard output that ends quietly on a closed pipe.
macro_rules! outln {
    () => {
        $crate::cli::stdout::write_fmt(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cli::stdout::write_fmt(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {out, outln};

/// `value` as pretty JSON on standard output.
pub(crate) fn print_json<T: serde::Serialize>(value: &T) -> Result<(), super::CliError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| super::CliError::Output(format!("error: cannot serialize result: {e}")))?;
    outln!("{text}");
    Ok(())
}
