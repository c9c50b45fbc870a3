//! The HTML verification report (`verify --out DIR`, `merge --out DIR`): static pages with
//! relative links only, readable from a file system or any web server.
//!
//! - `index.html`: pass/fail per check kind and per scene, the failures (each linked to its
//!   row's plots), the coverage matrix of [`crate::coverage`] (computed by the library), the
//!   work–precision fronts and the refinement ladders of the full suite.
//! - `scene-<name>.html`: the scene's rows (status, value, reference, error, tolerance, wall
//!   time, why), then per row its plots — the backends' overlaid histories, the ledger terms
//!   over time and their closure residual, the convergence and work–precision plots with the
//!   repeated timings and work counters — and the scene's Pareto fronts.
//!
//! Pages are built from the outcomes and from the files the plotting step left in the
//! directory (`case-<id>*.svg`, `work-<id>.json`), so a report merged from shards is built the
//! same way as one of a single machine. [`work`] is a leaf (it depends on `data` only) used by
//! the suite's plotting step; the pages depend on `suite` and `coverage`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use crate::coverage::{CheckKind, Coverage};
use crate::output::write_atomic;
use crate::plot::{Mark, StyledSeries, backend_css_color, plot_styled};
use crate::suite::evaluate::{Outcome, Status};
use crate::suite::report as suite_report;
use crate::work::{self, CaseWork, pareto_front, work_counter};

/// Suffixes of the plots a case may have, in the order they are shown.
pub const CASE_PLOT_SUFFIXES: [&str; 5] = [
    "",
    "-residual",
    "-convergence",
    "-work-precision",
    "-work-counters",
];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A name safe in a file name and a URL.
fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// File name of a scene's page.
pub fn scene_page(scene: &str) -> String {
    format!("scene-{}.html", slug(scene))
}

fn row_anchor(id: &str) -> String {
    format!("row-{}", slug(id))
}

/// Anchor of a case's line in a scene page's rows table (every row has one, with or without
/// plots).
fn line_anchor(id: &str) -> String {
    format!("line-{}", slug(id))
}

/// A line under a scene page's summary linking to each failed row (empty when none failed).
fn failed_list(rows: &[&Outcome]) -> String {
    let failed: Vec<String> = rows
        .iter()
        .filter(|o| o.status != Status::Pass)
        .map(|o| format!("<a href=\"#{}\">{}</a>", line_anchor(&o.id), esc(&o.id)))
        .collect();
    if failed.is_empty() {
        String::new()
    } else {
        format!(
            "<p><span class=\"FAIL\">Failed:</span> {}</p>\n",
            failed.join(", ")
        )
    }
}

/// What a case plot shows, from its file name (`case-<id><suffix>.svg`) and the row's check.
fn plot_label(file: &str, check: &str) -> &'static str {
    let stem = file.trim_end_matches(".svg");
    if stem.ends_with("-residual") {
        "ledger residual"
    } else if stem.ends_with("-convergence") {
        "convergence"
    } else if stem.ends_with("-work-precision") {
        "work–precision"
    } else if stem.ends_with("-work-counters") {
        "work counters"
    } else if check.contains("ledger") {
        "ledger terms"
    } else {
        "histories"
    }
}

const STYLE: &str = "body{font-family:'DejaVu Sans',Verdana,sans-serif;margin:24px auto;\
max-width:1180px;padding:0 16px;color:#222;line-height:1.4}\
h1{font-size:1.6em;margin-bottom:4px}h2{margin-top:32px;border-bottom:2px solid #ddd}\
h3{margin-top:26px}table{border-collapse:collapse;margin:8px 0;font-size:0.92em}\
td,th{padding:3px 8px;border-bottom:1px solid #e3e3e3;text-align:left;vertical-align:top}\
th{background:#f3f3f3}td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}\
.pass{color:#1a7f37;font-weight:bold}.FAIL,.ERROR,.gap{color:#c00;font-weight:bold}\
.exc{color:#a66a00}.muted{color:#777}.why{font-size:0.9em;color:#444;max-width:420px}\
tr.main td{border-bottom:none;padding-top:7px}tr.whyrow td{font-size:0.86em;color:#444;\
padding-bottom:7px}tr.failed td{background:#fff1f0}td.id,.nowrap{white-space:nowrap}td.ref{text-align:right;\
max-width:230px}.small{font-size:0.85em}\
.chip{display:inline-block;width:10px;height:10px;border-radius:2px;margin-right:5px}\
figure{margin:10px 0}figure img{max-width:100%;border:1px solid #ddd}\
nav a{margin-right:14px}.summary{font-size:1.1em}";

fn page(title: &str, body: &str) -> String {
    format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>{}</title><style>{STYLE}</style></head><body>\n{body}</body></html>\n",
        esc(title)
    )
}

fn status_name(s: Status) -> &'static str {
    match s {
        Status::Pass => "pass",
        Status::Fail => "FAIL",
        Status::Error => "ERROR",
    }
}

fn backend_chip(name: &str) -> String {
    match backend_css_color(name) {
        Some(c) => format!(
            "<span class=\"chip\" style=\"background:{c}\"></span>{}",
            esc(name)
        ),
        None => esc(name),
    }
}

fn num(v: Option<f64>) -> String {
    v.map_or("-".into(), |x| format!("{x:.6e}"))
}

/// A row's backend: the coloured kind, its settings below it.
fn backend_cell(label: &str) -> String {
    match label.split_once('(') {
        Some((kind, rest)) => {
            let settings = rest.trim_end_matches(')').replace(',', ", ");
            format!(
                "<span class=\"nowrap\">{}</span><br><span class=\"muted small\">{}</span>",
                backend_chip(kind),
                esc(&settings)
            )
        }
        None => backend_chip(label),
    }
}

/// The backend kind of a row: its backend label before the settings (`fem(elements=16)`).
fn backend_kind(o: &Outcome) -> &str {
    o.backend.split('(').next().unwrap_or_default()
}

/// The plots of a case present in `dir` (file names, in display order).
fn case_plots(dir: &Path, id: &str) -> Vec<String> {
    CASE_PLOT_SUFFIXES
        .iter()
        .map(|s| format!("case-{id}{s}.svg"))
        .filter(|f| dir.join(f).is_file())
        .collect()
}

/// (passed, failed) of a set of outcomes.
fn counts<'a>(outcomes: impl Iterator<Item = &'a Outcome>) -> (usize, usize) {
    outcomes.fold((0, 0), |(p, f), o| {
        if o.status == Status::Pass {
            (p + 1, f)
        } else {
            (p, f + 1)
        }
    })
}

fn count_cells(passed: usize, failed: usize) -> String {
    format!(
        "<td class=\"num\">{}</td><td class=\"num pass\">{passed}</td><td class=\"num{}\">{failed}</td>",
        passed + failed,
        if failed > 0 { " FAIL" } else { "" }
    )
}

/// Values in order of first appearance.
fn first_seen<'a>(items: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut seen: Vec<&str> = Vec::new();
    for i in items {
        if !seen.contains(&i) {
            seen.push(i);
        }
    }
    seen
}

/// One Pareto front of a scene: the group's key and the plot's file stem.
struct Front<'a> {
    scene: &'a str,
    quantity: &'a str,
    modified: bool,
    reference_label: &'a str,
    cases: Vec<&'a CaseWork>,
    stem: String,
}

/// The method of a ladder case beyond its backend: its settings other than the refined
/// parameter (e.g. `element=hermite-quintic`), empty for the backend's defaults.
fn method_of(w: &CaseWork) -> String {
    let Some(p) = w.points.first() else {
        return String::new();
    };
    p.discretization
        .split(',')
        .filter(|kv| {
            !["elements=", "stations=", "modes=", "dt="]
                .iter()
                .any(|k| kv.starts_with(k))
        })
        .collect::<Vec<_>>()
        .join(",")
}

fn series_label(w: &CaseWork) -> String {
    let m = method_of(w);
    if m.is_empty() {
        w.backend.clone()
    } else {
        format!("{} {m}", w.backend)
    }
}

/// Groups the ladder measurements by scene, quantity and reference, and draws each group's
/// points (one colour per backend) with its Pareto front of (minimum wall time, error).
fn draw_fronts<'a>(dir: &Path, works: &'a [CaseWork]) -> Vec<Front<'a>> {
    let mut groups: BTreeMap<(&str, bool, &str, &str), Vec<&CaseWork>> = BTreeMap::new();
    for w in works {
        groups
            .entry((&w.scene, w.modified, &w.quantity, &w.reference_label))
            .or_default()
            .push(w);
    }
    let mut fronts = Vec::new();
    for ((scene, modified, quantity, reference_label), cases) in groups {
        let stem = format!(
            "pareto-{}-{}{}",
            slug(scene),
            slug(quantity),
            if modified {
                format!("-modified-{}", slug(&cases[0].case))
            } else {
                String::new()
            }
        );
        let pts: Vec<Vec<(f64, f64)>> = cases
            .iter()
            .map(|w| w.points.iter().map(|p| (p.timing.min_s, p.error)).collect())
            .collect();
        let all: Vec<(f64, f64)> = pts.iter().flatten().copied().collect();
        let front: Vec<(f64, f64)> = pareto_front(&all).into_iter().map(|i| all[i]).collect();
        let mut series: Vec<StyledSeries<'_>> = cases
            .iter()
            .zip(&pts)
            .map(|(w, p)| StyledSeries {
                label: series_label(w),
                points: p,
                mark: Mark::Points,
            })
            .collect();
        series.push(StyledSeries {
            label: "Pareto front".into(),
            points: &front,
            mark: Mark::Front,
        });
        let drawn = plot_styled(
            dir,
            &stem,
            &format!("{scene} {quantity}: work-precision, all backends and methods"),
            "wall time, minimum of repeats [s]",
            "relative error [-]",
            &series,
            true,
        );
        if drawn.is_ok() {
            fronts.push(Front {
                scene,
                quantity,
                modified,
                reference_label,
                cases,
                stem,
            });
        }
    }
    fronts
}

/// The coverage matrix as an HTML table (scene × check kind: number of rows, GAP / exc on
/// the enforced kinds), as `flexverify coverage` prints it.
fn coverage_table(c: &Coverage, with_page: &[&str]) -> String {
    use data::coverage::MissingCheck;
    let mut s = String::from("<table><tr><th>scene</th><th>runs</th>");
    for k in CheckKind::ALL {
        let _ = write!(s, "<th title=\"{}\">{}</th>", k.name(), k.column());
    }
    s.push_str("</tr>\n");
    for sc in &c.scenes {
        let runners: Vec<String> = sc
            .runners()
            .iter()
            .map(|b| backend_chip(&b.to_string()))
            .collect();
        let name = if with_page.contains(&sc.scene.as_str()) {
            format!(
                "<a href=\"{}\">{}</a>",
                scene_page(&sc.scene),
                esc(&sc.scene)
            )
        } else {
            esc(&sc.scene)
        };
        let _ = write!(s, "<tr><td>{name}</td><td>{}</td>", runners.join(" "));
        for kind in CheckKind::ALL {
            let n = sc.cells.get(&kind).map_or(0, |c| c.rows.len());
            let enforced = match kind {
                CheckKind::CrossHistory => Some(MissingCheck::CrossHistory),
                CheckKind::Convergence => Some(MissingCheck::Convergence),
                _ => None,
            };
            let gaps: Vec<_> = sc
                .gaps
                .iter()
                .filter(|g| Some(g.missing) == enforced)
                .collect();
            let (mark, class, title) = if gaps.iter().any(|g| g.excused_by.is_none()) {
                (
                    " GAP",
                    "gap",
                    "not covered and not listed as an exception".to_string(),
                )
            } else if let Some(g) = gaps.first() {
                (" exc", "exc", g.excused_by.clone().unwrap_or_default())
            } else {
                ("", "", String::new())
            };
            let cell = if n == 0 && mark.is_empty() {
                "<span class=\"muted\">-</span>".to_string()
            } else {
                format!("{n}{mark}")
            };
            let _ = write!(
                s,
                "<td class=\"num {class}\" title=\"{}\">{cell}</td>",
                esc(&title)
            );
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
    s
}

fn work_table(w: &CaseWork) -> String {
    let (counter_name, _) = work_counter(&w.points);
    let mut s = format!(
        "<p class=\"muted\">Errors against {}; wall time over repeated sequential runs \
         (minimum, median, maximum; spread = (median − min)/min); work counters from the \
         backend's cost report (the work–counter plot uses {counter_name}).</p>\
         <table><tr><th>discretization</th><th>value</th><th>error</th><th>min [s]</th>\
         <th>median [s]</th><th>max [s]</th><th>repeats</th><th>spread</th><th>DOFs</th>\
         <th>steps</th><th>RHS evals</th><th>factorizations</th><th>Newton its</th></tr>\n",
        esc(&w.reference_label)
    );
    for p in &w.points {
        let t = &p.timing;
        let c = &p.counters;
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td class=\"num\">{:.9e}</td><td class=\"num\">{:.2e}</td>\
             <td class=\"num\">{:.3e}</td><td class=\"num\">{:.3e}</td><td class=\"num\">{:.3e}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{:.0}%</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td></tr>",
            esc(&p.discretization),
            p.value,
            p.error,
            t.min_s,
            t.median_s,
            t.max_s,
            t.repeats,
            100.0 * t.spread(),
            c.dofs,
            c.steps,
            c.rhs_evaluations,
            c.factorizations,
            c.newton_iterations
        );
    }
    s.push_str("</table>\n");
    s
}

fn figure(file: &str) -> String {
    format!(
        "<figure><a href=\"{f}\"><img src=\"{f}\" alt=\"{f}\" width=\"900\" \
         height=\"500\"></a></figure>\n",
        f = esc(file)
    )
}

/// The refinement-ladder plots of the full suite (`ladders/*.svg`), sorted.
fn ladder_plots(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir.join("ladders"))
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".svg"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn front_section(f: &Front<'_>) -> String {
    let mut s = format!(
        "<h3 id=\"{}\">{} {}{}</h3>\n<p class=\"muted\">Every measured rung of the ladder \
         cases {} (errors against {}), one colour per backend; the black staircase is the \
         Pareto front: no other measurement is both cheaper and more accurate.</p>\n",
        esc(&f.stem),
        esc(f.scene),
        esc(f.quantity),
        if f.modified { " (modified scene)" } else { "" },
        f.cases
            .iter()
            .map(|w| format!("<a href=\"#{}\">{}</a>", row_anchor(&w.case), esc(&w.case)))
            .collect::<Vec<_>>()
            .join(", "),
        esc(f.reference_label)
    );
    s.push_str(&figure(&format!("{}.svg", f.stem)));
    let all: Vec<(&CaseWork, &work::WorkPoint)> = f
        .cases
        .iter()
        .flat_map(|w| w.points.iter().map(move |p| (*w, p)))
        .collect();
    let xy: Vec<(f64, f64)> = all.iter().map(|(_, p)| (p.timing.min_s, p.error)).collect();
    s.push_str(
        "<table><tr><th>on the front</th><th>backend</th><th>discretization</th>\
         <th>error</th><th>min wall [s]</th></tr>\n",
    );
    for i in pareto_front(&xy) {
        let (w, p) = all[i];
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{:.2e}</td>\
             <td class=\"num\">{:.3e}</td></tr>",
            esc(&w.case),
            backend_chip(&w.backend),
            esc(&p.discretization),
            p.error,
            p.timing.min_s
        );
    }
    s.push_str("</table>\n");
    s
}

/// JSON, CSV and the HTML pages of the suite's outcomes (the plots are drawn before, by
/// [`crate::suite::plots::draw_all`] or copied from shards). Returns notes on what the pages
/// could not include.
pub fn write_all(dir: &Path, outcomes: &[Outcome]) -> std::io::Result<Vec<String>> {
    std::fs::create_dir_all(dir)?;
    write_atomic(
        dir,
        "verification.json",
        suite_report::json(outcomes).as_bytes(),
    )?;
    write_atomic(
        dir,
        "verification.csv",
        suite_report::csv(outcomes).as_bytes(),
    )?;
    write_pages(dir, outcomes)
}

/// Writes `index.html` and one page per scene into `dir` (the JSON and CSV it links are
/// written by [`write_all`]). Draws the scene Pareto fronts from the
/// `work-*.json` files in `dir`. Returns notes on what could not be included.
pub fn write_pages(dir: &Path, outcomes: &[Outcome]) -> std::io::Result<Vec<String>> {
    let mut notes = Vec::new();
    let (works, work_notes) = work::read_all(dir);
    notes.extend(work_notes);
    let fronts = draw_fronts(dir, &works);
    let scenes = first_seen(outcomes.iter().map(|o| o.scene.as_str()));
    let ladders = ladder_plots(dir);
    let index = index_page(dir, outcomes, &scenes, &fronts, &ladders, &mut notes);
    write_atomic(
        dir,
        "index.html",
        page("flexverify verification report", &index).as_bytes(),
    )?;
    for sc in &scenes {
        let b = scene_page_body(dir, outcomes, sc, &works, &fronts, &ladders);
        write_atomic(
            dir,
            &scene_page(sc),
            page(&format!("{sc} — flexverify"), &b).as_bytes(),
        )?;
    }
    Ok(notes)
}

/// The index page's body: the summary and navigation, the failures, the rows by check kind and
/// by scene, the coverage matrix, the work–precision fronts and the full suite's ladders.
fn index_page(
    dir: &Path,
    outcomes: &[Outcome],
    scenes: &[&str],
    fronts: &[Front<'_>],
    ladders: &[String],
    notes: &mut Vec<String>,
) -> String {
    let coverage = crate::coverage::analyse_embedded();
    let (passed, failed) = counts(outcomes.iter());
    let kinds = first_seen(outcomes.iter().map(|o| o.check.as_str()));
    let mut b = String::new();
    let _ = write!(
        b,
        "<h1>flexverify verification report</h1>\n<p class=\"summary\">{} rows: \
         <span class=\"pass\">{passed} passed</span>, <span class=\"{}\">{failed} failed</span>.\
         </p>\n<nav><a href=\"#failures\">Failures</a><a href=\"#kinds\">By check kind</a>\
         <a href=\"#scenes\">By scene</a><a href=\"#coverage\">Coverage</a>\
         <a href=\"#fronts\">Work–precision</a><a href=\"verification.json\">JSON</a>\
         <a href=\"verification.csv\">CSV</a></nav>\n",
        outcomes.len(),
        if failed > 0 { "FAIL" } else { "muted" }
    );
    b.push_str("<h2 id=\"failures\">Failures</h2>\n");
    let failures: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.status != Status::Pass)
        .collect();
    if failures.is_empty() {
        b.push_str("<p>None: every row passed.</p>\n");
    } else {
        b.push_str(
            "<table><tr><th>status</th><th>case</th><th>scene</th><th>error</th>\
                    <th>tolerance</th><th>message</th><th>plots</th></tr>\n",
        );
        for o in &failures {
            let plots: Vec<String> = case_plots(dir, &o.id)
                .iter()
                .map(|f| {
                    format!(
                        "<a class=\"nowrap\" href=\"{f}\" title=\"{t}\">{}</a>",
                        plot_label(f, &o.check),
                        t = esc(f)
                    )
                })
                .collect();
            let _ = writeln!(
                b,
                "<tr><td class=\"{s}\">{s}</td><td><a href=\"{page}#{a}\">{id}</a></td>\
                 <td>{scene}</td><td class=\"num\">{e}</td><td class=\"num\">{t:.1e}</td>\
                 <td class=\"why\">{m}</td><td>{p}</td></tr>",
                s = status_name(o.status),
                page = scene_page(&o.scene),
                a = line_anchor(&o.id),
                id = esc(&o.id),
                scene = esc(&o.scene),
                e = o.error.map_or("-".into(), |e| format!("{e:.2e}")),
                t = o.tolerance,
                m = esc(&o.message),
                p = if plots.is_empty() {
                    "-".into()
                } else {
                    plots.join("<br>")
                },
            );
        }
        b.push_str("</table>\n");
    }
    b.push_str(
        "<h2 id=\"kinds\">By check kind</h2>\n<table><tr><th>check</th><th>rows</th>\
                <th>passed</th><th>failed</th></tr>\n",
    );
    for k in &kinds {
        let (p, f) = counts(outcomes.iter().filter(|o| o.check == *k));
        let _ = writeln!(b, "<tr><td>{}</td>{}</tr>", esc(k), count_cells(p, f));
    }
    b.push_str(
        "</table>\n<h2 id=\"scenes\">By scene</h2>\n<table><tr><th>scene</th>\
                <th>rows</th><th>passed</th><th>failed</th><th>backends</th><th>plots</th></tr>\n",
    );
    for sc in scenes {
        let rows: Vec<&Outcome> = outcomes.iter().filter(|o| o.scene == *sc).collect();
        let (p, f) = counts(rows.iter().copied());
        let backends: Vec<String> = first_seen(rows.iter().map(|o| backend_kind(o)))
            .into_iter()
            .map(backend_chip)
            .collect();
        let n_plots: usize = rows
            .iter()
            .map(|o| case_plots(dir, &o.id).len())
            .sum::<usize>()
            + fronts.iter().filter(|f| f.scene == *sc).count();
        let _ = writeln!(
            b,
            "<tr><td><a href=\"{}\">{}</a></td>{}<td>{}</td><td class=\"num\">{n_plots}</td></tr>",
            scene_page(sc),
            esc(sc),
            count_cells(p, f),
            backends.join(" ")
        );
    }
    b.push_str("</table>\n<h2 id=\"coverage\">Coverage</h2>\n");
    match &coverage {
        Ok(c) => {
            b.push_str(
                "<p class=\"muted\">Rows of the whole case catalog per scene and check kind \
                 (as <code>flexverify coverage</code>); GAP: an enforced check no row covers; \
                 exc: a gap listed in data/cases/coverage-exceptions.toml (hover for the \
                 reason). Scenes without rows in this run have no page (no link).</p>\n",
            );
            b.push_str(&coverage_table(c, scenes));
        }
        Err(e) => {
            notes.push(format!("coverage matrix not included: {e}"));
            let _ = writeln!(
                b,
                "<p class=\"FAIL\">Coverage could not be computed: {}</p>",
                esc(&e.to_string())
            );
        }
    }
    b.push_str("<h2 id=\"fronts\">Work–precision</h2>\n");
    if fronts.is_empty() {
        b.push_str("<p>No ladder case ran (the order cases draw work–precision).</p>\n");
    } else {
        b.push_str(
            "<p class=\"muted\">Per scene and quantity, every rung of the ladder cases \
                    of every backend and method, with the Pareto front of minimum wall time \
                    against error.</p>\n<ul>\n",
        );
        for f in fronts {
            let _ = writeln!(
                b,
                "<li><a href=\"{}#{}\">{} {}{}</a> ({} cases)</li>",
                scene_page(f.scene),
                esc(&f.stem),
                esc(f.scene),
                esc(f.quantity),
                if f.modified { " (modified scene)" } else { "" },
                f.cases.len()
            );
        }
        b.push_str("</ul>\n");
    }
    if !ladders.is_empty() {
        b.push_str("<h2 id=\"ladders\">Refinement ladders (full suite)</h2>\n<ul>\n");
        for l in ladders {
            let _ = writeln!(b, "<li><a href=\"ladders/{f}\">{f}</a></li>", f = esc(l));
        }
        b.push_str("</ul>\n");
    }
    b
}

/// The body of one scene's page: its rows (each with its check kind and why), the plots of the
/// rows that draw, the scene's work–precision fronts and its refinement ladders.
fn scene_page_body(
    dir: &Path,
    outcomes: &[Outcome],
    sc: &str,
    works: &[work::CaseWork],
    fronts: &[Front<'_>],
    ladders: &[String],
) -> String {
    let rows: Vec<&Outcome> = outcomes.iter().filter(|o| o.scene == *sc).collect();
    let (p, f) = counts(rows.iter().copied());
    let mut b = format!(
        "<nav><a href=\"index.html\">← index</a><a href=\"#rows\">Rows</a>\
         <a href=\"#plots\">Plots</a><a href=\"#fronts\">Work–precision</a></nav>\n\
         <h1>{}</h1>\n<p class=\"summary\">{} rows: <span class=\"pass\">{p} passed</span>, \
         <span class=\"{}\">{f} failed</span>.</p>\n{}<h2 id=\"rows\">Rows</h2>\n\
         <p class=\"muted\">Each row, then on a line of its own the check kind and why \
         the tolerance is what it is.</p>\n\
         <table><tr><th>status</th><th>case</th><th>backend</th><th>quantity</th>\
         <th>value</th><th>reference</th><th>error</th><th>tolerance</th>\
         <th>wall [s]</th></tr>\n",
        esc(sc),
        rows.len(),
        if f > 0 { "FAIL" } else { "muted" },
        failed_list(&rows),
    );
    for o in &rows {
        let has_plots = !case_plots(dir, &o.id).is_empty();
        let id = if has_plots {
            format!("<a href=\"#{}\">{}</a>", row_anchor(&o.id), esc(&o.id))
        } else {
            esc(&o.id)
        };
        let _ = writeln!(
            b,
            "<tr class=\"main{failed}\" id=\"{line}\"><td class=\"{s}\">{s}</td>\
             <td class=\"id\">{id}</td>\
             <td>{backend}</td><td>{q}</td><td class=\"num\">{v}</td>\
             <td class=\"ref\">{r}<br><span class=\"muted\">{rl}</span></td>\
             <td class=\"num\">{e}</td><td class=\"num\">{t:.1e} {norm}</td>\
             <td class=\"num\">{w:.3}</td></tr>\n<tr class=\"whyrow{failed}\"><td></td>\
             <td colspan=\"8\"><b>{check}</b>: {why}{msg}</td></tr>",
            s = status_name(o.status),
            failed = if o.status == Status::Pass {
                ""
            } else {
                " failed"
            },
            line = line_anchor(&o.id),
            check = esc(&o.check),
            backend = backend_cell(&o.backend),
            q = esc(&o.quantity),
            v = num(o.value),
            r = num(o.reference),
            rl = esc(&o.reference_label),
            e = o.error.map_or("-".into(), |e| format!("{e:.2e}")),
            t = o.tolerance,
            norm = match o.norm {
                data::cases::Norm::Relative => "rel.",
                data::cases::Norm::Absolute => "abs.",
                data::cases::Norm::RelativeToPeak => "rel. to peak",
            },
            w = o.wall_time_s,
            why = esc(&o.why),
            msg = if o.status == Status::Pass {
                String::new()
            } else {
                format!("<br><span class=\"FAIL\">{}</span>", esc(&o.message))
            },
        );
    }
    b.push_str("</table>\n<h2 id=\"plots\">Plots</h2>\n");
    let mut any = false;
    for o in &rows {
        let plots = case_plots(dir, &o.id);
        if plots.is_empty() {
            continue;
        }
        any = true;
        let _ = writeln!(
            b,
            "<h3 id=\"{}\">{} <span class=\"{s}\">{s}</span></h3>\n<p class=\"small\">{}</p>",
            row_anchor(&o.id),
            esc(&o.id),
            esc(&o.why),
            s = status_name(o.status)
        );
        for plot in &plots {
            b.push_str(&figure(plot));
        }
        if let Some(w) = works.iter().find(|w| w.case == o.id) {
            b.push_str(&work_table(w));
        }
    }
    if !any {
        b.push_str(
            "<p>No row of this scene has plots (only history, ledger and ladder \
                    rows draw).</p>\n",
        );
    }
    b.push_str("<h2 id=\"fronts\">Work–precision across backends and methods</h2>\n");
    let mine: Vec<&Front<'_>> = fronts.iter().filter(|f| f.scene == sc).collect();
    if mine.is_empty() {
        b.push_str("<p>No ladder case of this scene ran.</p>\n");
    }
    for f in mine {
        b.push_str(&front_section(f));
    }
    let prefix = format!("converge-{sc}-");
    let own_ladders: Vec<&String> = ladders.iter().filter(|l| l.starts_with(&prefix)).collect();
    if !own_ladders.is_empty() {
        b.push_str("<h2 id=\"ladders\">Refinement ladders (full suite)</h2>\n");
        for l in own_ladders {
            b.push_str(&figure(&format!("ladders/{l}")));
        }
    }
    b
}
