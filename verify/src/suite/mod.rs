//! `flexverify verify`: the verification suite of `data/cases/*.toml`.
//!
//! Every row names its reference and tolerance; cases run in parallel (rayon) and the table is
//! printed in case order, so results are identical with or without threads.

pub mod evaluate;
pub mod filter;
pub mod history;
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
    // The refinement ladders are a study of every scene, not a case: `--filter` selects cases,
    // so a filtered run skips them (it would otherwise cost the whole study's wall time).
    if suite == Suite::Full && filter.is_none() {
        full_ladders(out)?;
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

/// Per-rung wall-time budget of the full suite's ladders.
const FULL_RUNG_BUDGET_S: f64 = 10.0;

/// The quantity a scene's refinement ladder follows in the full suite.
fn ladder_quantity(scene: &data::Scene) -> Option<String> {
    use data::scene::PrescribedMotion;
    if let Some(_r) = &scene.rocket {
        return Some(format!("rocket.vY@{}", scene.simulation.t_end));
    }
    let first = scene.links.first()?;
    let t = scene.simulation.t_end;
    Some(match first.joint.prescribed {
        Some(PrescribedMotion::Fixed) | Some(PrescribedMotion::ConstantRate { .. }) => {
            "freq1".into()
        }
        Some(PrescribedMotion::SpinUp { .. }) => format!("tip_deflection@{t}"),
        None => format!("joint1.angle@{t}"),
    })
}

/// `--suite full`: every catalog scene through every rung of each backend's space ladder (a
/// rung costing more than the budget ends its ladder), with convergence and work-precision
/// plots when `--out` is given.
fn full_ladders(out: Option<&Path>) -> Result<(), CliError> {
    use crate::output::text_table;
    let mut rows = Vec::new();
    for name in data::catalog_names() {
        let scene = data::load_scene(name)?;
        let Some(q) = ladder_quantity(&scene) else {
            continue;
        };
        let study = crate::study::run_study(
            &scene,
            &q,
            crate::cli::args::Refine::Space,
            &data::BackendKind::ALL,
            &data::Settings::default(),
            Some(FULL_RUNG_BUDGET_S),
        )?;
        for l in &study.ladders {
            rows.push(vec![
                name.to_string(),
                q.clone(),
                l.backend.to_string(),
                l.rungs.len().to_string(),
                l.rungs
                    .last()
                    .map_or("-".into(), |r| format!("{:.9e}", r.value)),
                l.observed_order.map_or("-".into(), |p| format!("{p:.2}")),
                l.note
                    .clone()
                    .unwrap_or_default()
                    .chars()
                    .take(90)
                    .collect(),
            ]);
        }
        if let Some(dir) = out
            && study.ladders.iter().any(|l| !l.rungs.is_empty())
        {
            crate::study::write_study(&dir.join("ladders"), &study)?;
        }
    }
    println!();
    print!(
        "{}",
        text_table(
            &[
                "scene",
                "quantity",
                "backend",
                "rungs",
                "finest value",
                "order",
                "note"
            ],
            &rows
        )
    );
    Ok(())
}
