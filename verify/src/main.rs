use clap::Parser;

fn main() -> std::process::ExitCode {
    verify::cli::run(verify::cli::Cli::parse())
}
