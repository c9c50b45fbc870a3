//! `flexverify verify`: the verification suite of `data/cases/*.toml`.
//!
//! Every row names its reference and tolerance; cases run in parallel (rayon) and the table is
//! printed in case order, so results are identical with or without threads.

pub mod evaluate;
pub mod plots;
pub mod quantity;
pub mod reference;
pub mod report;
pub mod run_cache;

use std::path::Path;

use data::cases::{SuiteName, all_cases};
use rayon::prelude::*;

use crate::cli::CliError;
use crate::cli::args::Suite;
use crate::output::Format;
use evaluate::{Outcome, Status, evaluate};
use run_cache::RunCache;

/// Runs the selected cases and returns them with their outcomes in case order, and the cache
/// of backend answers (for the report's plots).
pub fn run_cases(
    suite: Suite,
    filter: Option<&str>,
) -> Result<(Vec<data::cases::Case>, Vec<Outcome>, RunCache), CliError> {
    let cases = all_cases().map_err(|e| CliError::Input(format!("error: {e}")))?;
    let selected: Vec<_> = cases
        .into_iter()
        .filter(|c| suite == Suite::Full || c.suite == SuiteName::Quick)
        .filter(|c| filter.is_none_or(|f| c.id.contains(f)))
        .collect();
    if selected.is_empty() {
        return Err(CliError::Input(format!(
            "error: no verification case matches (suite {suite:?}, filter {filter:?})"
        )));
    }
    let cache = RunCache::default();
    let bar = indicatif::ProgressBar::new(selected.len() as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} cases {elapsed}")
            .expect("static template"),
    );
    let outcomes: Vec<Outcome> = selected
        .par_iter()
        .map(|c| {
            let o = evaluate(c, &cache);
            bar.inc(1);
            o
        })
        .collect();
    bar.finish_and_clear();
    Ok((selected, outcomes, cache))
}

pub fn command(
    suite: Suite,
    filter: Option<&str>,
    format: Format,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    let (cases, outcomes, cache) = run_cases(suite, filter)?;
    let wall = started.elapsed().as_secs_f64();
    match format {
        Format::Table => print!("{}", report::table(&outcomes)),
        Format::Csv => print!("{}", report::csv(&outcomes)),
        Format::Json => println!("{}", report::json(&outcomes)),
    }
    if let Some(dir) = out {
        plots::draw_all(dir, &cases, &outcomes, &cache);
        report::write_all(dir, &outcomes)?;
        eprintln!(
            "wrote the verification report to {}/index.html",
            dir.display()
        );
    }
    let failed: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.status != Status::Pass)
        .collect();
    eprintln!(
        "{} passed, {} failed ({:.1} s wall)",
        outcomes.len() - failed.len(),
        failed.len(),
        wall
    );
    if failed.is_empty() {
        Ok(())
    } else {
        Err(CliError::Failed(
            failed
                .iter()
                .map(|o| format!("FAILED {}: {}", o.id, o.message))
                .collect::<Vec<_>>()
                .join("\n"),
        ))
    }
}
