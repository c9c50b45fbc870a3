//! `verify` and `stability`: run a suite through the library, print it, map failures to exit 1.

use std::path::Path;

use super::CliError;
use super::progress::Bar;
use crate::output::{Format, TERMINAL_WIDTH};
use crate::stability::{self, Verdict};
use crate::study;
use crate::suite::evaluate::{Outcome, Status};
use crate::suite::{Suite, plots, report, run_cases_with_progress};

pub fn verify(
    suite: Suite,
    filter: Option<&str>,
    format: Format,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    let bar = Bar::new();
    let (cases, outcomes, cache) = run_cases_with_progress(suite, filter, &bar)?;
    bar.clear();
    let wall = started.elapsed().as_secs_f64();
    match format {
        Format::Table => print!("{}", report::terminal_table(&outcomes, TERMINAL_WIDTH)),
        Format::Wide => print!("{}", report::wide_table(&outcomes)),
        Format::Csv => print!("{}", report::csv(&outcomes)),
        Format::Json => println!("{}", report::json(&outcomes)),
    }
    // The refinement ladders are a study of every scene, not a case: `--filter` selects cases,
    // so a filtered run skips them (it would otherwise cost the whole study's wall time).
    if suite == Suite::Full && filter.is_none() {
        let (studies, notes) = study::full_suite_ladders(out, &bar)?;
        bar.clear();
        for n in notes {
            eprintln!("note: {n}");
        }
        println!();
        match format {
            Format::Table => print!("{}", study::survey_terminal_table(&studies, TERMINAL_WIDTH)),
            Format::Wide | Format::Csv | Format::Json => {
                print!("{}", study::survey_wide_table(&studies))
            }
        }
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

pub fn stability(suite: Suite, format: Format, out: Option<&Path>) -> Result<(), CliError> {
    let verdicts = stability::run_stability(suite)?;
    match format {
        Format::Table => print!("{}", stability::terminal_table(&verdicts, TERMINAL_WIDTH)),
        Format::Wide => print!("{}", stability::wide_table(&verdicts)),
        Format::Csv => print!("{}", stability::csv(&verdicts)),
        Format::Json => println!("{}", stability::json(&verdicts)),
    }
    if let Some(dir) = out {
        stability::write_all(dir, &verdicts)?;
    }
    let failures: Vec<&Verdict> = verdicts.iter().filter(|v| v.failure).collect();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(CliError::Failed(
            failures
                .iter()
                .map(|v| {
                    format!(
                        "FAILED {} ({}): {} — {}",
                        v.case, v.backend, v.verdict, v.detail
                    )
                })
                .collect::<Vec<_>>()
                .join("\n"),
        ))
    }
}

/// `flexverify coverage`: the coverage report; a gap not listed in
/// `data/cases/coverage-exceptions.toml`, or a listed exception that rows now cover, fails.
pub fn coverage(format: Format) -> Result<(), CliError> {
    let c = crate::coverage::analyse_embedded().map_err(|e| CliError::Input(e.to_string()))?;
    match format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&c)
                .map_err(|e| CliError::Failed(format!("error: cannot serialize: {e}")))?
        ),
        _ => print!("{}", crate::coverage::report(&c)),
    }
    let unexcused = c.unexcused().count();
    if unexcused + c.stale_exceptions.len() > 0 {
        return Err(CliError::Failed(format!(
            "coverage: {unexcused} gap(s) not listed in data/cases/coverage-exceptions.toml, {} \
             stale exception(s)",
            c.stale_exceptions.len()
        )));
    }
    Ok(())
}
