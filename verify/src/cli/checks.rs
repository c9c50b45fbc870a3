//! `verify` and `stability`: run a suite through the library, print it, map failures to exit 1.

use std::path::{Path, PathBuf};

use super::CliError;
use super::progress::Bar;
use super::stdout::{out, outln};
use crate::error::Error;
use crate::output::{Format, TERMINAL_WIDTH, write_atomic};
use crate::shard::{self, Shard, ShardFile};
use crate::stability::{self, Verdict};
use crate::study::summary::Study;
use crate::study::survey::{self, LadderSpec};
use crate::suite::evaluate::{Outcome, Status};
use crate::suite::{Suite, plots, report, run_selected, select_cases};

/// The cases and (full suite) the refinement ladders whose ids contain `filter`. No case
/// matching is an error only when no ladder matches either.
fn select(
    suite: Suite,
    filter: Option<&str>,
) -> Result<(Vec<data::cases::Case>, Vec<LadderSpec>), CliError> {
    let ladders = match suite {
        Suite::Full => survey::select_ladders(filter)?,
        Suite::Quick => Vec::new(),
    };
    let cases = match select_cases(suite, filter) {
        Err(Error::NoCaseMatches { .. }) if !ladders.is_empty() => Vec::new(),
        selected => selected?,
    };
    Ok((cases, ladders))
}

/// The survey table of the ladder studies, after the rows (nothing without ladders).
fn print_survey(studies: &[Study], format: Format) {
    if studies.is_empty() {
        return;
    }
    outln!();
    match format {
        Format::Table => out!("{}", survey::survey_terminal_table(studies, TERMINAL_WIDTH)),
        Format::Wide | Format::Csv | Format::Json => {
            out!("{}", survey::survey_wide_table(studies))
        }
    }
}

pub fn verify(
    suite: Suite,
    filter: Option<&str>,
    format: Format,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    let bar = Bar::new();
    let (cases, ladders) = select(suite, filter)?;
    let (outcomes, cache) = run_selected(&cases, &bar);
    bar.clear();
    let wall = started.elapsed().as_secs_f64();
    print_outcomes(&outcomes, format);
    // The full suite's refinement ladders (a study per scene, ids `ladder-<scene>`) run after
    // the cases, sequentially: their timings must not share the cores.
    let (studies, notes) = survey::run_ladders(&ladders, out, &bar)?;
    bar.clear();
    for n in notes {
        eprintln!("note: {n}");
    }
    print_survey(&studies, format);
    if let Some(dir) = out {
        plots::draw_all(dir, &cases, &outcomes, &cache);
        for n in crate::report::write_all(dir, &outcomes)? {
            eprintln!("note: {n}");
        }
        eprintln!(
            "wrote the verification report to {}/index.html",
            dir.display()
        );
    }
    summarize(&outcomes, &format!("{wall:.1} s wall"))
}

/// `verify --shard I/N`: this shard's share of the selected cases, printed, and written as
/// `shard-I-of-N.json` (with the cases' plots) for `flexverify merge`.
pub fn verify_shard(
    suite: Suite,
    filter: Option<&str>,
    format: Format,
    out: Option<&Path>,
    shard: Shard,
) -> Result<(), CliError> {
    let Some(dir) = out else {
        return Err(CliError::Input(
            "error: --shard needs --out DIR (where the shard writes its partial result)".into(),
        ));
    };
    let started = std::time::Instant::now();
    let (selection, ladder_selection) = select(suite, filter)?;
    let cases = shard.share(&selection);
    let bar = Bar::new();
    let (outcomes, cache) = run_selected(&cases, &bar);
    bar.clear();
    let wall = started.elapsed().as_secs_f64();
    print_outcomes(&outcomes, format);
    std::fs::create_dir_all(dir)?;
    let (studies, notes) = survey::run_ladders(&shard.share(&ladder_selection), Some(dir), &bar)?;
    bar.clear();
    for n in notes {
        eprintln!("note: {n}");
    }
    print_survey(&studies, format);
    plots::draw_all(dir, &cases, &outcomes, &cache);
    let file = ShardFile::new(
        suite,
        filter,
        shard,
        selection.iter().map(|c| c.id.clone()).collect(),
        outcomes,
        ladder_selection,
        studies,
    );
    write_atomic(dir, &shard.file_name(), file.to_json().as_bytes())?;
    eprintln!(
        "wrote shard {shard} ({} of {} cases, {} of {} ladders) to {}",
        file.outcomes.len(),
        selection.len(),
        file.ladders.len(),
        file.ladder_selection.len(),
        dir.join(shard.file_name()).display()
    );
    summarize(&file.outcomes, &format!("{wall:.1} s wall, shard {shard}"))
}

/// `flexverify merge`: the shards' rows combined into the report of one unsharded run (or,
/// for `converge` parts, the study of one unsharded run).
pub fn merge(dirs: &[PathBuf], format: Format, out: &Path) -> Result<(), CliError> {
    let files = match shard::read_dirs(dirs).map_err(|e| CliError::Input(format!("error: {e}")))? {
        shard::Parts::Verify(files) => files,
        shard::Parts::Converge(files) => {
            return super::studies::merge_converge(&files, dirs, format, out);
        }
    };
    let merged = shard::merge(&files).map_err(|e| CliError::Input(format!("error: {e}")))?;
    let outcomes = merged.outcomes;
    print_outcomes(&outcomes, format);
    print_survey(&merged.ladders, format);
    std::fs::create_dir_all(out)?;
    for study in &merged.ladders {
        for n in survey::write_ladder(out, study)? {
            eprintln!("note: {n}");
        }
    }
    shard::copy_plots(dirs, out)?;
    crate::work::copy_work_files(dirs, out)?;
    for n in crate::report::write_all(out, &outcomes)? {
        eprintln!("note: {n}");
    }
    eprintln!(
        "wrote the verification report to {}/index.html",
        out.display()
    );
    summarize(
        &outcomes,
        &format!("merged from {} shards", files[0].1.shard.count),
    )
}

fn print_outcomes(outcomes: &[Outcome], format: Format) {
    match format {
        Format::Table => out!("{}", report::terminal_table(outcomes, TERMINAL_WIDTH)),
        Format::Wide => out!("{}", report::wide_table(outcomes)),
        Format::Csv => out!("{}", report::csv(outcomes)),
        Format::Json => outln!("{}", report::json(outcomes)),
    }
}

/// Prints the pass/fail count; a failed check is exit 1.
fn summarize(outcomes: &[Outcome], note: &str) -> Result<(), CliError> {
    let failed: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.status != Status::Pass)
        .collect();
    eprintln!(
        "{} passed, {} failed ({note})",
        outcomes.len() - failed.len(),
        failed.len(),
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

pub fn stability(
    suite: Suite,
    filter: Option<&str>,
    format: Format,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let verdicts = stability::run_stability(suite, filter)?;
    if verdicts.is_empty() {
        return Err(CliError::Input(format!(
            "error: no stability case of the {} suite matches --filter `{}`",
            if suite == Suite::Full {
                "full"
            } else {
                "quick"
            },
            filter.unwrap_or_default()
        )));
    }
    match format {
        Format::Table => out!("{}", stability::terminal_table(&verdicts, TERMINAL_WIDTH)),
        Format::Wide => out!("{}", stability::wide_table(&verdicts)),
        Format::Csv => out!("{}", stability::csv(&verdicts)),
        Format::Json => outln!("{}", stability::json(&verdicts)),
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
        Format::Json => outln!(
            "{}",
            serde_json::to_string_pretty(&c)
                .map_err(|e| CliError::Output(format!("error: cannot serialize: {e}")))?
        ),
        _ => out!("{}", crate::coverage::report(&c)),
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
