//! A study as text: the terminal and wide tables (every rung with its value, error, timing and
//! work counter, then each ladder's observed order), CSV, JSON, and the files of `--out` with
//! the convergence and work-precision plots.

use std::path::Path;

use super::ladder::Refine;
use super::summary::{Ladder, Study};
use crate::error::Error;
use crate::output::{Column, csv_table, fitted_table, text_table, wrap, write_atomic};
use crate::plot::{Series, plot};
use crate::work::{Counters, work_counter_of};

/// Short name of a work counter, for table cells.
fn counter_abbreviation(name: &str) -> &'static str {
    match name {
        "RHS evaluations" => "rhs",
        "steps" => "steps",
        "factorizations" => "fact",
        _ => "dofs",
    }
}

/// The rungs for the tables: value, error, minimum wall time, repeats, spread and the
/// ladder's work counter.
fn rows(study: &Study) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for l in &study.ladders {
        let counters: Vec<Counters> = l.rungs.iter().map(|r| r.counters).collect();
        let (name, counter) = work_counter_of(&counters);
        for r in &l.rungs {
            rows.push(vec![
                l.backend.to_string(),
                r.discretization.clone(),
                format!("{:.10e}", r.value),
                r.error.map_or("-".into(), |e| format!("{e:.3e}")),
                format!("{:.4e}", r.wall_time_s),
                r.timing.repeats.to_string(),
                format!("{:.0}%", 100.0 * r.timing.spread()),
                format!("{} {}", counter(&r.counters), counter_abbreviation(name)),
            ]);
        }
    }
    rows
}

/// Header of the table rows of [`rows`].
const TABLE_HEADER: [&str; 8] = [
    "backend",
    "discretization",
    "value",
    "error",
    "min wall [s]",
    "reps",
    "spread",
    "work",
];

/// Header of the study's CSV: the machine-independent columns first, then the timings.
const CSV_HEADER: [&str; 15] = [
    "backend",
    "discretization",
    "h",
    "value",
    "error",
    "dofs",
    "steps",
    "rhs_evaluations",
    "factorizations",
    "newton_iterations",
    "wall_s",
    "wall_median_s",
    "wall_max_s",
    "repeats",
    "spread",
];

fn csv_rows(study: &Study) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for l in &study.ladders {
        for r in &l.rungs {
            let c = &r.counters;
            rows.push(vec![
                l.backend.to_string(),
                r.discretization.clone(),
                format!("{:e}", r.h),
                format!("{:e}", r.value),
                r.error.map_or(String::new(), |e| format!("{e:e}")),
                c.dofs.to_string(),
                c.steps.to_string(),
                c.rhs_evaluations.to_string(),
                c.factorizations.to_string(),
                c.newton_iterations.to_string(),
                format!("{:e}", r.timing.min_s),
                format!("{:e}", r.timing.median_s),
                format!("{:e}", r.timing.max_s),
                r.timing.repeats.to_string(),
                format!("{:e}", r.timing.spread()),
            ]);
        }
    }
    rows
}

/// Writes the study as JSON and CSV and draws its convergence and work-precision plots into
/// `dir`. Returns a note for each plot that could not be drawn (the data files are written
/// regardless).
pub fn write_study(dir: &Path, study: &Study) -> Result<Vec<String>, Error> {
    let mut notes = Vec::new();
    let stem = format!(
        "converge-{}-{}",
        study.scene,
        study.quantity.replace(['@', ':', '.'], "_")
    );
    write_atomic(
        dir,
        &format!("{stem}.json"),
        serde_json::to_string_pretty(study)
            .expect("json")
            .as_bytes(),
    )?;
    write_atomic(dir, &format!("{stem}.csv"), csv(study).as_bytes())?;
    let conv: Vec<(String, Vec<(f64, f64)>)> = study
        .ladders
        .iter()
        .map(|l| {
            (
                format!(
                    "{} (order {})",
                    l.backend,
                    l.observed_order.map_or("-".into(), |p| format!("{p:.2}"))
                ),
                l.rungs
                    .iter()
                    .filter_map(|r| Some((r.h, r.error?)))
                    .collect(),
            )
        })
        .collect();
    let xlabel = if study.refine == Refine::Time.name() {
        "dt"
    } else {
        "h (1/elements, 1/(stations-1), 1/modes)"
    };
    draw_error_plot(
        dir,
        &format!("{stem}-convergence"),
        &format!("{} {}: error vs refinement", study.scene, study.quantity),
        xlabel,
        &conv,
        &mut notes,
    );
    let work: Vec<(String, Vec<(f64, f64)>)> = study
        .ladders
        .iter()
        .map(|l| {
            (
                l.backend.to_string(),
                l.rungs
                    .iter()
                    .filter_map(|r| Some((r.wall_time_s, r.error?)))
                    .collect(),
            )
        })
        .collect();
    draw_error_plot(
        dir,
        &format!("{stem}-work-precision"),
        &format!("{} {}: work-precision", study.scene, study.quantity),
        "wall time, minimum of repeats [s]",
        &work,
        &mut notes,
    );
    // The same against each ladder's work counter (named in the legend): exact, and the
    // primary cost axis for rungs too long to repeat.
    let work: Vec<(String, Vec<(f64, f64)>)> = study
        .ladders
        .iter()
        .map(|l| {
            let counters: Vec<Counters> = l.rungs.iter().map(|r| r.counters).collect();
            let (name, counter) = work_counter_of(&counters);
            (
                format!("{} ({name})", l.backend),
                l.rungs
                    .iter()
                    .filter_map(|r| Some((counter(&r.counters) as f64, r.error?)))
                    .collect(),
            )
        })
        .collect();
    draw_error_plot(
        dir,
        &format!("{stem}-work-counters"),
        &format!("{} {}: error vs work counters", study.scene, study.quantity),
        "work: the ladder's counter (legend) [-]",
        &work,
        &mut notes,
    );
    Ok(notes)
}

/// One log–log plot of labelled lines of (x, error) points; a plot that cannot be drawn
/// becomes a note instead of an error (the study's data are written regardless).
fn draw_error_plot(
    dir: &Path,
    name: &str,
    title: &str,
    xlabel: &str,
    lines: &[(String, Vec<(f64, f64)>)],
    notes: &mut Vec<String>,
) {
    let series: Vec<Series<'_>> = lines
        .iter()
        .map(|(label, points)| Series {
            label: label.clone(),
            points,
        })
        .collect();
    if let Err(e) = plot(dir, name, title, xlabel, "error", &series, true) {
        notes.push(format!("{name}: plot not drawn: {e}"));
    }
}

/// The study's rungs as CSV.
pub fn csv(study: &Study) -> String {
    csv_table(&CSV_HEADER, &csv_rows(study))
}

/// The study as JSON.
pub fn json(study: &Study) -> String {
    serde_json::to_string_pretty(study).expect("serializable study")
}

fn heading(study: &Study) -> String {
    format!(
        "{} {} ({} refinement); reference: {} {}",
        study.scene,
        study.quantity,
        study.refine,
        study.reference.map_or("-".into(), |r| format!("{r:.12e}")),
        study.reference_label
    )
}

fn ladder_summary(l: &Ladder) -> String {
    format!(
        "{}: observed order {}{}{}",
        l.backend,
        l.observed_order.map_or("-".into(), |p| format!("{p:.2}")),
        if l.monotone_from_above {
            ", monotone from above"
        } else {
            ""
        },
        l.note
            .as_ref()
            .map_or(String::new(), |n| format!(" (ladder ended: {n})"))
    )
}

/// Heading, every rung, and each ladder's observed order, lines at full length.
pub fn wide_table(study: &Study) -> String {
    let mut s = format!("{}\n", heading(study));
    s.push_str(&text_table(&TABLE_HEADER, &rows(study)));
    for l in &study.ladders {
        s.push_str(&ladder_summary(l));
        s.push('\n');
    }
    if let Some(d) = &study.disagreement {
        s.push_str(&d.sentence());
        s.push('\n');
    }
    s
}

/// [`wide_table`] for a terminal of `width` columns (long lines wrapped).
pub fn terminal_table(study: &Study, width: usize) -> String {
    let columns = [
        Column::left("backend"),
        Column::left("discretization").elastic(),
        Column::right("value"),
        Column::right("error"),
        Column::right("min wall [s]"),
        Column::right("reps"),
        Column::right("spread"),
        Column::right("work"),
    ];
    let mut s = format!("{}\n", wrap(&heading(study), width, 4));
    s.push_str(&fitted_table(&columns, &rows(study), width).to_string());
    for l in &study.ladders {
        s.push_str(&wrap(&ladder_summary(l), width, 4));
        s.push('\n');
    }
    if let Some(d) = &study.disagreement {
        s.push_str(&wrap(&d.sentence(), width, 4));
        s.push('\n');
    }
    s
}
