//! `flexverify compare`: two run results side by side ([`crate::compare`]) as tables, JSON or
//! CSV.

use std::path::Path;

use data::Settings;

use super::CliError;
use super::stdout::{out, outln, print_json};
use crate::compare::{CompareOptions, Comparison, EpisodeComparison, RunSummary};
use crate::compare::{compare_runs, load_run};
use crate::output::{Column, Format, TERMINAL_WIDTH, csv_table, fitted_table, wrap};

/// The CSV's columns; a history row puts the reference's peak in `reference`.
const CSV_HEADER: [&str; 6] = ["kind", "name", "run", "reference", "abs_diff", "relative"];

/// The JSON: the files read, then the comparison.
#[derive(serde::Serialize)]
struct Report<'a> {
    run_file: &'a Path,
    reference_file: &'a Path,
    #[serde(flatten)]
    comparison: &'a Comparison,
}

pub fn compare(
    run: &Path,
    reference: &Path,
    opts: &CompareOptions,
    format: Format,
) -> Result<(), CliError> {
    let (run_file, run_result) = load_run(run)?;
    let (reference_file, reference_result) = load_run(reference)?;
    let comparison = compare_runs(&run_result, &reference_result, opts).map_err(named_by_flag)?;
    match format {
        Format::Json => print_json(&Report {
            run_file: &run_file,
            reference_file: &reference_file,
            comparison: &comparison,
        })?,
        Format::Csv => out!("{}", csv_table(&CSV_HEADER, &csv_rows(&comparison))),
        Format::Table | Format::Wide => print_tables(
            &comparison,
            [run_file.as_path(), reference_file.as_path()],
            format == Format::Wide,
        ),
    }
    Ok(())
}

/// The library names an option by its field in [`CompareOptions`]; the user typed its flag.
fn named_by_flag(e: crate::Error) -> CliError {
    match e {
        crate::Error::InvalidOption { option, reason } => {
            let flag = match option {
                "min_flight" => "--min-flight",
                "channels" => "--channel",
                "lowpass_hz" => "--lowpass",
                other => other,
            };
            CliError::Input(format!("error: {flag}: {reason}"))
        }
        e => e.into(),
    }
}

/// The flags that reproduce a run's settings (`run … --elements 4 --t-end 0.35`).
fn settings_flags(s: &Settings) -> String {
    let flags = s.command_line();
    if flags.is_empty() {
        "(defaults)".into()
    } else {
        flags.join(" ")
    }
}

fn time(t: f64) -> String {
    format!("{t:.9e}")
}

fn diff(d: f64) -> String {
    format!("{d:.3e}")
}

fn or_dash(v: Option<f64>, f: fn(f64) -> String) -> String {
    v.map_or("-".into(), f)
}

/// Prints one table, fitted to the terminal (its elastic column giving way) or with every column
/// at full width (`wide`).
fn print_table(columns: &[Column<'_>], rows: &[Vec<String>], wide: bool) {
    let width = if wide { usize::MAX } else { TERMINAL_WIDTH };
    out!("{}", fitted_table(columns, rows, width));
}

/// Prints a sentence, wrapped to the terminal unless `wide`.
fn say(text: &str, wide: bool) {
    if wide {
        outln!("{text}");
    } else {
        outln!("{}", wrap(text, TERMINAL_WIDTH, 4));
    }
}

fn print_tables(c: &Comparison, files: [&Path; 2], wide: bool) {
    let runs = [("run", &c.run), ("reference", &c.reference)];
    say(&format!("scene {}", c.scene), wide);
    let rows: Vec<Vec<String>> = runs
        .iter()
        .map(|(role, r)| {
            vec![
                role.to_string(),
                r.backend.to_string(),
                format!("{:.6}", r.t_reached),
                if r.stopped().is_some() {
                    "STOPPED"
                } else {
                    "completed"
                }
                .into(),
                format!("{:.3e}", r.wall_time_s),
                r.dofs.to_string(),
                settings_flags(&r.settings),
            ]
        })
        .collect();
    let columns = [
        Column::left(""),
        Column::right("backend"),
        Column::right("t reached"),
        Column::right("verdict"),
        Column::right("wall [s]"),
        Column::right("dofs"),
        Column::left("settings").elastic(),
    ];
    print_table(&columns, &rows, wide);
    for ((role, r), file) in runs.iter().zip(files) {
        say(&format!("{role}: {}", file.display()), wide);
        if let Some(d) = r.stopped() {
            say(
                &format!("{role} stopped at t = {:.6e}: {}", d.t, d.what),
                wide,
            );
        }
    }
    let ended_first = match (c.run.t_reached, c.reference.t_reached) {
        (a, b) if a == b => "both runs",
        (a, b) if a < b => "the run",
        _ => "the reference",
    };
    say(
        &format!(
            "compared over t ≤ {:.6} (the span {ended_first} reached)",
            c.common_end
        ),
        wide,
    );
    if let Some(e) = &c.episodes {
        outln!();
        print_episodes(e, c.common_end, wide);
    }
    outln!();
    let filtered = c
        .lowpass_hz
        .map_or(String::new(), |f| format!(", both low-passed at {f} Hz"));
    say(
        &format!(
            "histories over the run's output times{filtered}; relative = max|run − ref| / \
             reference peak"
        ),
        wide,
    );
    let rows: Vec<Vec<String>> = c
        .histories
        .iter()
        .map(|h| {
            vec![
                h.channel.clone(),
                format!("{:.6e}", h.max_abs_diff),
                format!("{:.6e}", h.reference_peak),
                or_dash(h.relative, diff),
            ]
        })
        .collect();
    let columns = [
        Column::left("channel").elastic(),
        Column::right("max|run − ref|"),
        Column::right("reference peak"),
        Column::right("relative"),
    ];
    print_table(&columns, &rows, wide);
    for (role, only) in [("run", &c.only_in_run), ("reference", &c.only_in_reference)] {
        if !only.is_empty() {
            say(
                &format!("not compared, only in the {role}: {}", only.join(", ")),
                wide,
            );
        }
    }
}

fn print_episodes(e: &EpisodeComparison, common_end: f64, wide: bool) {
    let heading = format!(
        "contact episodes starting before t = {common_end:.6} (free flights shorter than {} s \
         merged)",
        e.min_flight
    );
    let Some(pairs) = &e.pairs else {
        say(
            &format!(
                "{heading}: the run has {}, the reference {}: the boundaries are not paired",
                e.run.len(),
                e.reference.len()
            ),
            wide,
        );
        let rows: Vec<Vec<String>> = (0..e.run.len().max(e.reference.len()))
            .map(|k| {
                let mut row = vec![(k + 1).to_string()];
                for list in [&e.run, &e.reference] {
                    let episode = list.get(k);
                    row.push(or_dash(episode.map(|x| x.start), time));
                    row.push(or_dash(episode.and_then(|x| x.end), time));
                }
                row
            })
            .collect();
        let columns = [
            "episode",
            "run start",
            "run end",
            "reference start",
            "reference end",
        ]
        .map(Column::right);
        print_table(&columns, &rows, wide);
        return;
    };
    say(&format!("{heading}:"), wide);
    let rows: Vec<Vec<String>> = pairs
        .iter()
        .map(|p| {
            vec![
                p.episode.to_string(),
                time(p.run_start),
                time(p.reference_start),
                diff(p.start_diff),
                or_dash(p.run_end, time),
                or_dash(p.reference_end, time),
                or_dash(p.end_diff, diff),
            ]
        })
        .collect();
    let columns = [
        "episode",
        "run start",
        "reference start",
        "|Δ start|",
        "run end",
        "reference end",
        "|Δ end|",
    ]
    .map(Column::right);
    print_table(&columns, &rows, wide);
    if pairs
        .iter()
        .any(|p| p.end_diff.is_none() && (p.run_end.is_some() || p.reference_end.is_some()))
    {
        say(
            &format!(
                "(an end is compared only when both runs have one at or before t = \
                 {common_end:.6}; `-`: in contact at the end)"
            ),
            wide,
        );
    }
    match e.largest {
        Some(l) => say(
            &format!(
                "largest boundary difference: {:.6e} s (episode {} {})",
                l.abs_diff, l.episode, l.boundary
            ),
            wide,
        ),
        None => say("no contact episode in the common span", wide),
    }
}

fn csv_rows(c: &Comparison) -> Vec<Vec<String>> {
    let num = |v: f64| format!("{v:.9e}");
    let opt = |v: Option<f64>| v.map_or(String::new(), num);
    let row = |kind: &str, name: String, cells: [String; 4]| {
        let mut r = vec![kind.to_string(), name];
        r.extend(cells);
        r
    };
    let summary = |f: fn(&RunSummary) -> f64| [&c.run, &c.reference].map(f);
    let [t_run, t_ref] = summary(|r| r.t_reached);
    let [wall_run, wall_ref] = summary(|r| r.wall_time_s);
    let mut rows = vec![
        row(
            "t_reached",
            String::new(),
            [
                num(t_run),
                num(t_ref),
                num((t_run - t_ref).abs()),
                String::new(),
            ],
        ),
        row(
            "wall_time_s",
            String::new(),
            [num(wall_run), num(wall_ref), String::new(), String::new()],
        ),
    ];
    if let Some(e) = &c.episodes {
        match &e.pairs {
            Some(pairs) => {
                for p in pairs {
                    let k = p.episode.to_string();
                    rows.push(row(
                        "episode_start",
                        k.clone(),
                        [
                            num(p.run_start),
                            num(p.reference_start),
                            num(p.start_diff),
                            String::new(),
                        ],
                    ));
                    rows.push(row(
                        "episode_end",
                        k,
                        [
                            opt(p.run_end),
                            opt(p.reference_end),
                            opt(p.end_diff),
                            String::new(),
                        ],
                    ));
                }
                if let Some(l) = e.largest {
                    rows.push(row(
                        "largest_episode_boundary",
                        format!("{} {}", l.episode, l.boundary),
                        [String::new(), String::new(), num(l.abs_diff), String::new()],
                    ));
                }
            }
            None => {
                for k in 0..e.run.len().max(e.reference.len()) {
                    let (a, b) = (e.run.get(k), e.reference.get(k));
                    let name = (k + 1).to_string();
                    rows.push(row(
                        "episode_start",
                        name.clone(),
                        [
                            opt(a.map(|x| x.start)),
                            opt(b.map(|x| x.start)),
                            String::new(),
                            String::new(),
                        ],
                    ));
                    rows.push(row(
                        "episode_end",
                        name,
                        [
                            opt(a.and_then(|x| x.end)),
                            opt(b.and_then(|x| x.end)),
                            String::new(),
                            String::new(),
                        ],
                    ));
                }
            }
        }
    }
    for h in &c.histories {
        rows.push(row(
            "history",
            h.channel.clone(),
            [
                String::new(),
                num(h.reference_peak),
                num(h.max_abs_diff),
                opt(h.relative),
            ],
        ));
    }
    rows
}
