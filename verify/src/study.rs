//! Refinement studies (`flexverify converge`, `flexverify recommend`, the full suite's
//! ladders): refinement ladders, observed orders, Richardson references and work-precision
//! (error against cost).
//!
//! Ladders are run sequentially so that the wall times are not distorted by sharing cores.
//! Each rung's cost is measured two ways, with the suite's rule
//! ([`crate::report::work::time_rung`]): the wall time as the minimum of repeats (at least 5
//! and 0.2 s; a rung whose first run took more than 3 s is timed once, and its `repeats` says
//! so), with median, maximum and spread; and the backend's work counters (DOFs, steps, RHS
//! evaluations, factorizations, Newton iterations), exact and machine independent.
//!
//! `recommend` picks, in each backend's ladder, the rung meeting the tolerance with the least
//! work (the ladder's work counter, so the pick inside a ladder never depends on the timer);
//! across backends, the pick with the smallest minimum wall time, unless the timings cannot
//! separate them (the runner-up's minimum within the winner's spread), in which case the one
//! with fewer DOFs wins.

use std::path::Path;

use data::{BackendKind, Scene, Settings};
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::output::{Column, csv_table, fitted_table, text_table, wrap, write_atomic};
use crate::plot::{Series, plot};
use crate::progress::Progress;
use crate::report::work::{Counters, FirstRun, Timing, time_rung, work_counter_of};
use crate::suite::evaluate::measure;
use crate::suite::order::{falling_prefix, fit_order, richardson};
use crate::suite::quantity::Quantity;
use crate::suite::reference::{analytic_value, default_analytic_id};
use crate::suite::run_cache::{RunCache, compute};

/// What a study refines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Refine {
    /// Elements, stations or modes (the backend's space discretization).
    Space,
    /// The time step.
    Time,
}

/// One rung of a refinement ladder.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Rung {
    pub backend: BackendKind,
    /// Human-readable discretization, e.g. "elements=8".
    pub discretization: String,
    /// Refinement parameter h (1/elements, 1/(stations−1), 1/modes or dt).
    pub h: f64,
    pub value: f64,
    /// |value − reference| / scale.
    pub error: Option<f64>,
    /// Minimum wall time over the repeats of [`Rung::timing`].
    pub wall_time_s: f64,
    /// Repeated timings: minimum, median, maximum and the number of repeats.
    pub timing: Timing,
    /// The backend's work counters of this rung.
    pub counters: Counters,
    #[serde(skip)]
    pub settings: Settings,
    /// Peak |channel| of this run, for time-history quantities.
    #[serde(skip)]
    pub peak: Option<f64>,
}

/// The study of one backend.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Ladder {
    pub backend: BackendKind,
    pub rungs: Vec<Rung>,
    /// Least-squares order over the rungs with a positive error.
    pub observed_order: Option<f64>,
    /// Richardson extrapolation of this ladder (value, order used).
    pub richardson: Option<(f64, f64)>,
    /// True if the values decrease monotonically with refinement (Rayleigh–Ritz bound).
    pub monotone_from_above: bool,
    /// First rung where the error stopped falling (round-off plateau), excluded from the fit.
    pub plateau_from: Option<String>,
    /// Why the ladder stopped early, if it did (unsupported, stopped run, …).
    pub note: Option<String>,
    /// The ladder's own estimate of the converged value (its Richardson extrapolation).
    pub estimate: Option<Estimate>,
}

/// Where a ladder says the quantity converges to: its Richardson extrapolation, with the
/// distance of its finest rung from that value as the uncertainty (the finest rung's own error
/// estimate, an upper bound on the extrapolation's once the ladder is asymptotic).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Estimate {
    pub backend: BackendKind,
    pub value: f64,
    pub uncertainty: f64,
}

/// Two ladders whose estimates differ by more than their uncertainties allow: the backends
/// converge to different answers, so neither may be scored against the other.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Disagreement {
    pub first: Estimate,
    pub second: Estimate,
    /// |first − second| over the quantity's scale (the same scale the rung errors use).
    pub relative_difference: f64,
}

impl Disagreement {
    /// One sentence with both values, for tables and error messages.
    pub fn sentence(&self) -> String {
        let (a, b) = (self.first, self.second);
        format!(
            "the models disagree: {} converges to {:.10e} (± {:.1e}), {} to {:.10e} (± {:.1e}); \
             the difference {:.3e} of the scale exceeds both error estimates",
            a.backend,
            a.value,
            a.uncertainty,
            b.backend,
            b.value,
            b.uncertainty,
            self.relative_difference
        )
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Study {
    pub scene: String,
    pub quantity: String,
    pub refine: String,
    pub reference: Option<f64>,
    pub reference_label: String,
    pub ladders: Vec<Ladder>,
    /// Set when no analytic value exists and two ladders converge to different answers; each
    /// ladder's errors are then measured against its own estimate.
    pub disagreement: Option<Disagreement>,
}

/// Default refinement ladder of a backend (space) as settings + h: the backend's resolution
/// ([`Settings::with_resolution`]) over its rungs, h the reciprocal number of intervals.
fn space_ladder(kind: BackendKind, base: &Settings) -> Vec<(Settings, f64, String)> {
    let (rungs, intervals): (&[usize], fn(usize) -> usize) = match kind {
        // The rigid reference has no spatial discretization.
        BackendKind::Reference => return Vec::new(),
        BackendKind::Fem => (&[2, 4, 8, 16, 32, 64], |n| n),
        // Stations include both ends.
        BackendKind::Fdm => (&[11, 21, 41, 81, 161], |n| n - 1),
        BackendKind::Modal => (&[1, 2, 3, 4, 6, 8], |n| n),
    };
    let field = Settings::resolution_field(kind).map_or("", |f| f.key());
    rungs
        .iter()
        .map(|&n| {
            (
                base.with_resolution(kind, n),
                1.0 / intervals(n) as f64,
                format!("{field}={n}"),
            )
        })
        .collect()
}

fn time_ladder(base: &Settings, scene: &Scene) -> Vec<(Settings, f64, String)> {
    let dt0 = base.time.dt.unwrap_or(scene.simulation.output_interval);
    (0..5)
        .map(|k| {
            let dt = dt0 / f64::from(1u32 << k);
            let mut s = base.clone();
            s.time.dt = Some(dt);
            (s, dt, format!("dt={dt:.3e}"))
        })
        .collect()
}

/// One rung's measurement: the quantity's value, the peak |channel| for time histories, the
/// repeated timings and the work counters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    pub value: f64,
    pub peak: Option<f64>,
    pub timing: Timing,
    pub counters: Counters,
}

/// One rung's measurement, or why the backend could not give the quantity at that rung.
pub type RungMeasurement = Result<Measured, String>;

/// A rung to measure: its settings, refinement parameter h and label.
pub type RungSpec = (Settings, f64, String);

/// The ladders of a study: per backend, each rung's settings, h and label, in refinement order.
pub fn rung_specs(
    scene: &Scene,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
) -> Vec<(BackendKind, Vec<RungSpec>)> {
    kinds
        .iter()
        .map(|&kind| {
            let base = base.for_backend(kind);
            let spec = match refine {
                Refine::Space => space_ladder(kind, &base),
                Refine::Time => time_ladder(&base, scene),
            };
            (kind, spec)
        })
        .collect()
}

/// Measures one rung (the quantity must parse: see [`parse_quantity`]).
pub fn measure_rung(
    cache: &RunCache,
    scene: &Scene,
    kind: BackendKind,
    settings: &Settings,
    q: &Quantity,
) -> RungMeasurement {
    let (value, peak, first) = measure(cache, scene, kind, settings, q)?;
    let counters = cache
        .get(scene, kind, settings, q.analysis(), q.modes_needed())
        .counters()
        .ok_or_else(|| format!("{kind}: no cost counters"))?;
    // The ladder runs alone, so its first run is a repeat like the others.
    let repeat = || compute(scene, kind, settings, q.analysis(), q.modes_needed()).wall_time_s();
    let timing = time_rung(first, FirstRun::Alone, repeat)
        .ok_or_else(|| format!("{kind}: a timing repeat of the run failed"))?;
    Ok(Measured {
        value,
        peak,
        timing,
        counters,
    })
}

/// The quantity of a study, parsed against its scene.
pub fn parse_quantity(scene: &Scene, quantity: &str) -> Result<Quantity, Error> {
    Quantity::parse(quantity, scene).map_err(|reason| Error::InvalidQuantity {
        quantity: quantity.to_string(),
        reason: reason.to_string(),
    })
}

/// Runs the ladders and fills errors against the best available reference, reporting each
/// rung to `progress`.
pub fn run_study(
    scene: &Scene,
    quantity: &str,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    rung_budget_s: Option<f64>,
    progress: &dyn Progress,
) -> Result<Study, Error> {
    let q = parse_quantity(scene, quantity)?;
    let cache = RunCache::default();
    let measured = |kind: BackendKind, _rung: usize, settings: &Settings| {
        measure_rung(&cache, scene, kind, settings, &q)
    };
    study_from_rungs(
        scene,
        quantity,
        refine,
        kinds,
        base,
        rung_budget_s,
        progress,
        &measured,
    )
}

/// The study built from rung measurements given by `measured(backend, rung index, settings)`
/// — fresh runs ([`run_study`]) or the rows of `converge --shard` parts (`merge`). A ladder
/// ends at the first failure after a success, or when a rung costs more than the budget.
#[allow(clippy::too_many_arguments)]
pub fn study_from_rungs(
    scene: &Scene,
    quantity: &str,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    rung_budget_s: Option<f64>,
    progress: &dyn Progress,
    measured: &dyn Fn(BackendKind, usize, &Settings) -> RungMeasurement,
) -> Result<Study, Error> {
    let q = parse_quantity(scene, quantity)?;
    let mut ladders = Vec::new();
    let specs = rung_specs(scene, refine, kinds, base);
    progress.begin(specs.iter().map(|(_, s)| s.len()).sum(), "rungs");
    for (kind, rungs_spec) in specs {
        let mut rungs: Vec<Rung> = Vec::new();
        let mut note = None;
        let rungs_total = rungs_spec.len();
        for (rung_index, (settings, h, label)) in rungs_spec.into_iter().enumerate() {
            progress.start(&format!("{} {quantity}: {kind} {label}", scene.name));
            // A full-suite ladder stops once a rung costs more than the budget: the next
            // rung would cost several times more.
            if let (Some(budget), Some(last)) = (rung_budget_s, rungs.last())
                && last.wall_time_s > budget
            {
                break;
            }
            match measured(kind, rung_index, &settings) {
                Ok(m) => {
                    rungs.push(Rung {
                        wall_time_s: m.timing.min_s,
                        timing: m.timing,
                        counters: m.counters,
                        backend: kind,
                        discretization: label,
                        h,
                        value: m.value,
                        error: None,
                        settings,
                        peak: m.peak,
                    });
                    progress.advance();
                }
                Err(e) => {
                    progress.advance();
                    // Coarse rungs may be rejected (too few elements for the scene); only a
                    // failure after a success ends the ladder.
                    if rungs.is_empty() && !e.contains("unsupported") {
                        continue;
                    }
                    note = Some(e);
                    break;
                }
            }
        }
        if let Some(budget) = rung_budget_s
            && note.is_none()
            && let Some(last) = rungs.last()
            && last.wall_time_s > budget
            && rungs.len() < rungs_total
        {
            note = Some(format!(
                "ladder capped after {}: that rung took {:.1} s, above the {budget} s budget per rung",
                last.discretization, last.wall_time_s
            ));
        }
        let values: Vec<f64> = rungs.iter().map(|r| r.value).collect();
        let hs: Vec<f64> = rungs.iter().map(|r| r.h).collect();
        let monotone_from_above =
            values.len() >= 2 && values.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-13));
        let extrapolation = richardson(&hs, &values, None);
        let estimate = extrapolation
            .zip(rungs.last())
            .map(|((value, _), finest)| Estimate {
                backend: kind,
                value,
                uncertainty: (finest.value - value).abs(),
            });
        ladders.push(Ladder {
            backend: kind,
            richardson: extrapolation,
            rungs,
            observed_order: None,
            plateau_from: None,
            monotone_from_above,
            note,
            estimate,
        });
    }
    let scale_of = |l: &Ladder, value: f64| match q {
        Quantity::At { .. } => l.rungs.last().and_then(|r| r.peak).unwrap_or(value.abs()),
        _ => value.abs(),
    };

    // Reference: analytic when the scene/quantity has one; else, unless two ladders converge
    // to different answers, the Richardson value of the ladder whose last two rungs agree best
    // (its own estimate of its error is smallest).
    let analytic = default_analytic_id(scene, &q)
        .and_then(|id| analytic_value(&id, scene, &q).ok().map(|v| (v, id)));
    let disagreement = if analytic.is_none() {
        worst_disagreement(&ladders, scale_of)
    } else {
        None
    };
    let (reference, reference_label) = match analytic {
        Some((v, id)) => (Some(v), format!("analytic:{id}")),
        None if disagreement.is_some() => (
            None,
            "each ladder against its own Richardson extrapolation (the models disagree)".into(),
        ),
        None => {
            let best = ladders
                .iter()
                .filter_map(|l| {
                    let (ext, p) = l.richardson?;
                    let last = l.rungs.last()?.value;
                    Some(((last - ext).abs(), ext, p, l.backend))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match best {
                Some((_, ext, p, b)) => (
                    Some(ext),
                    format!("Richardson of the {b} ladder (p = {p:.2})"),
                ),
                None => (None, "none (no ladder reached the asymptotic range)".into()),
            }
        }
    };
    for l in &mut ladders {
        let own = l.estimate.map(|e| e.value);
        let Some(r) = reference.or(disagreement.and(own)) else {
            continue;
        };
        let scale = scale_of(&*l, r);
        for rung in &mut l.rungs {
            rung.error = (scale > 0.0).then(|| (rung.value - r).abs() / scale);
        }
        let (h, e): (Vec<f64>, Vec<f64>) = l
            .rungs
            .iter()
            .filter_map(|r| Some((r.h, r.error?)))
            .filter(|(_, e)| *e > 1e-13)
            .unzip();
        let keep = falling_prefix(&e);
        if keep < e.len() {
            l.plateau_from = Some(l.rungs[keep].discretization.clone());
        }
        l.observed_order = fit_order(&h[..keep], &e[..keep]);
    }
    progress.finish();
    Ok(Study {
        scene: scene.name.clone(),
        quantity: quantity.to_string(),
        refine: format!("{refine:?}").to_lowercase(),
        reference,
        reference_label,
        ladders,
        disagreement,
    })
}

/// The pair of ladder estimates that differ most beyond their combined uncertainty (plus a
/// round-off allowance of 1e-10 of the scale), if any pair does.
fn worst_disagreement(
    ladders: &[Ladder],
    scale_of: impl Fn(&Ladder, f64) -> f64,
) -> Option<Disagreement> {
    let with_estimates: Vec<(&Ladder, Estimate)> = ladders
        .iter()
        .filter_map(|l| Some((l, l.estimate?)))
        .collect();
    let mut worst: Option<(f64, Disagreement)> = None;
    for (i, &(la, a)) in with_estimates.iter().enumerate() {
        for &(lb, b) in &with_estimates[i + 1..] {
            let scale = scale_of(la, a.value).max(scale_of(lb, b.value));
            if scale <= 0.0 {
                continue;
            }
            let difference = (a.value - b.value).abs();
            let excess = difference - a.uncertainty - b.uncertainty - 1e-10 * scale;
            if excess > 0.0 && worst.is_none_or(|(e, _)| excess > e) {
                worst = Some((
                    excess,
                    Disagreement {
                        first: a,
                        second: b,
                        relative_difference: difference / scale,
                    },
                ));
            }
        }
    }
    worst.map(|(_, d)| d)
}

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
    let xlabel = if study.refine == "time" {
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

/// A study for `converge`: [`run_study`] without a rung budget, failing when no
/// backend measured the quantity on any rung.
pub fn converge(
    scene: &Scene,
    quantity: &str,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    progress: &dyn Progress,
) -> Result<Study, Error> {
    let q = parse_quantity(scene, quantity)?;
    let cache = RunCache::default();
    let measured = |kind: BackendKind, _rung: usize, settings: &Settings| {
        measure_rung(&cache, scene, kind, settings, &q)
    };
    converge_from_rungs(scene, quantity, refine, kinds, base, progress, &measured)
}

/// [`converge`] from given rung measurements (see [`study_from_rungs`]).
pub fn converge_from_rungs(
    scene: &Scene,
    quantity: &str,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    progress: &dyn Progress,
    measured: &dyn Fn(BackendKind, usize, &Settings) -> RungMeasurement,
) -> Result<Study, Error> {
    let study = study_from_rungs(
        scene, quantity, refine, kinds, base, None, progress, measured,
    )?;
    if study.ladders.iter().all(|l| l.rungs.is_empty()) {
        return Err(Error::QuantityNotProduced {
            quantity: quantity.to_string(),
            notes: study
                .ladders
                .iter()
                .filter_map(|l| l.note.clone())
                .collect(),
        });
    }
    Ok(study)
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

/// The cheapest measured discretization meeting a tolerance.
#[derive(Debug, Clone, Serialize)]
pub struct Recommendation {
    pub scene: String,
    pub quantity: String,
    pub tolerance: f64,
    /// The chosen rung (see the module doc): per backend the least-work rung with
    /// error ≤ tolerance, across backends the smallest minimum wall time.
    pub rung: Rung,
    /// The other backends' picks, fastest first: how clearly the choice was made.
    pub runners_up: Vec<Rung>,
    /// Whether the timings could not separate the chosen rung from a runner-up (its minimum
    /// within the fastest pick's spread), so fewer DOFs decided.
    pub decided_by_dofs: bool,
    pub reference: f64,
    pub reference_label: String,
    /// The `flexverify` arguments that re-run the chosen discretization and print the quantity
    /// (e.g. `run spin-up --backend modal --modes 1 --t-end 15`).
    pub rerun: String,
    /// How many measured rungs meet the tolerance, of how many measured.
    pub meeting: usize,
    pub measured: usize,
}

/// The cheapest backend and space discretization whose measured error on `quantity` is at
/// most `tol`, from a space-refinement study of `kinds`.
pub fn recommend(
    scene: &Scene,
    quantity: &str,
    tol: f64,
    kinds: &[BackendKind],
    base: &Settings,
    progress: &dyn Progress,
) -> Result<Recommendation, Error> {
    let study = run_study(scene, quantity, Refine::Space, kinds, base, None, progress)?;
    // Models that converge to answers further apart than the tolerance cannot both meet it,
    // and which one is right is not a question of discretization.
    if let Some(d) = study.disagreement
        && d.relative_difference > tol
    {
        return Err(Error::ModelsDisagree {
            quantity: quantity.to_string(),
            scene: scene.name.clone(),
            tolerance: tol,
            sentence: d.sentence(),
        });
    }
    if study.reference.is_none() && study.disagreement.is_none() {
        return Err(Error::NoReference {
            quantity: quantity.to_string(),
            scene: scene.name.clone(),
            why: study.reference_label,
        });
    }
    // Each rung with its ladder's reference (the study's, or its own estimate when the
    // models disagree by less than the tolerance).
    let meets = |r: &&Rung| r.error.is_some_and(|e| e <= tol);
    let meeting = study
        .ladders
        .iter()
        .flat_map(|l| l.rungs.iter().filter(meets))
        .count();
    // Per ladder, the rung meeting the tolerance with the least work (first on ties).
    let mut picks: Vec<(&Rung, f64)> = study
        .ladders
        .iter()
        .filter_map(|l| {
            let reference = study.reference.or(l.estimate.map(|e| e.value))?;
            let counters: Vec<Counters> = l.rungs.iter().map(|r| r.counters).collect();
            let (_, work) = work_counter_of(&counters);
            let pick = l
                .rungs
                .iter()
                .filter(meets)
                .min_by_key(|r| work(&r.counters))?;
            Some((pick, reference))
        })
        .collect();
    // Across backends: fastest minimum wall time, unless the timings cannot tell the picks
    // apart (within the fastest's spread): then fewer DOFs, then backend order.
    picks.sort_by(|a, b| a.0.wall_time_s.total_cmp(&b.0.wall_time_s));
    let chosen = picks.first().map(|&(fastest, _)| {
        let within = fastest.timing.min_s * (1.0 + fastest.timing.spread());
        let tied = picks.iter().filter(|(r, _)| r.wall_time_s <= within);
        let by_dofs = tied
            .enumerate()
            .min_by_key(|(i, (r, _))| (r.counters.dofs, *i))
            .map_or(0, |(i, _)| i);
        (
            by_dofs,
            picks
                .iter()
                .filter(|(r, _)| r.wall_time_s <= within)
                .count()
                > 1,
        )
    });
    let best = chosen.map(|(i, _)| picks[i]);
    let decided_by_dofs = chosen.is_some_and(|(_, tied)| tied);
    let Some((r, reference)) = best else {
        let best_err = study
            .ladders
            .iter()
            .flat_map(|l| l.rungs.iter())
            .filter_map(|r| Some((r.error?, r)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        return Err(Error::ToleranceNotMet {
            tolerance: tol,
            best: best_err.map(|(e, r)| (r.backend, r.discretization.clone(), e)),
            reference_label: study.reference_label,
        });
    };
    let flag = r.discretization.replace('=', " ");
    // Ending the re-run at the quantity's time makes its final value the quantity.
    let parsed = Quantity::parse(quantity, scene);
    let until = match parsed {
        Ok(Quantity::At { t, .. }) => format!(" --t-end {t}"),
        _ => String::new(),
    };
    let what = match parsed {
        Ok(Quantity::Frequency { .. }) => "modes",
        Ok(Quantity::StaticTip) => "statics",
        _ => "run",
    };
    Ok(Recommendation {
        scene: scene.name.clone(),
        quantity: quantity.to_string(),
        tolerance: tol,
        rung: r.clone(),
        reference,
        reference_label: match study.disagreement {
            Some(d) if study.reference.is_none() => format!(
                "{}'s own Richardson extrapolation (the backends converge {:.1e} apart, within \
                 the tolerance)",
                r.backend, d.relative_difference
            ),
            _ => study.reference_label.clone(),
        },
        rerun: format!(
            "{what} {} --backend {} --{flag}{until}",
            scene.name, r.backend
        ),
        runners_up: picks
            .iter()
            .filter(|(p, _)| !std::ptr::eq(*p, r))
            .map(|(p, _)| (*p).clone())
            .collect(),
        decided_by_dofs,
        meeting,
        measured: study.ladders.iter().map(|l| l.rungs.len()).sum(),
    })
}

impl Recommendation {
    fn counts(&self) -> String {
        format!(
            "({} of {} measured discretizations meet the tolerance)",
            self.meeting, self.measured
        )
    }

    fn cost(r: &Rung) -> String {
        let c = &r.counters;
        format!(
            "wall time {:.3e} s (minimum of {} repeat{}, spread {:.0}%); work: {} DOFs, {} steps, \
             {} RHS evaluations, {} factorizations",
            r.timing.min_s,
            r.timing.repeats,
            if r.timing.repeats == 1 { "" } else { "s" },
            100.0 * r.timing.spread(),
            c.dofs,
            c.steps,
            c.rhs_evaluations,
            c.factorizations
        )
    }

    /// How the choice was made against the other backends' picks.
    fn choice(&self) -> Option<String> {
        let next = self.runners_up.first()?;
        let ratio = next.wall_time_s / self.rung.wall_time_s;
        Some(if self.decided_by_dofs {
            format!(
                "timings too close to separate from {} with {} ({:.3e} s): fewer DOFs decided ({} vs {})",
                next.backend,
                next.discretization,
                next.wall_time_s,
                self.rung.counters.dofs,
                next.counters.dofs
            )
        } else {
            format!(
                "next cheapest: {} with {}, {:.3e} s ({ratio:.1}x)",
                next.backend, next.discretization, next.wall_time_s
            )
        })
    }

    /// The recommendation at full length, one fact per line.
    pub fn wide_text(&self) -> String {
        let r = &self.rung;
        let mut s = format!(
            "recommended: {} with {} — value {:.10e}, measured error {:.3e} ≤ {:.1e} against {} = {:.10e}\n{}\n",
            r.backend,
            r.discretization,
            r.value,
            r.error.unwrap_or(f64::NAN),
            self.tolerance,
            self.reference_label,
            self.reference,
            Self::cost(r),
        );
        if let Some(c) = self.choice() {
            s.push_str(&c);
            s.push('\n');
        }
        s.push_str(&format!(
            "re-run: flexverify {}\n{}\n",
            self.rerun,
            self.counts()
        ));
        s
    }

    /// The recommendation for a terminal of `width` columns: one fact per line.
    pub fn terminal_text(&self, width: usize) -> String {
        let r = &self.rung;
        let mut lines = vec![
            format!("recommended: {} with {}", r.backend, r.discretization),
            format!(
                "  value {:.10e}, measured error {:.3e} ≤ {:.1e}",
                r.value,
                r.error.unwrap_or(f64::NAN),
                self.tolerance
            ),
            format!(
                "  against {} = {:.10e}",
                self.reference_label, self.reference
            ),
            format!("  {}", Self::cost(r)),
        ];
        lines.extend(self.choice().map(|c| format!("  {c}")));
        lines.push(format!("re-run: flexverify {}", self.rerun));
        lines.push(self.counts());
        lines.iter().map(|l| wrap(l, width, 4) + "\n").collect()
    }
}

/// Per-rung wall-time budget of the full suite's ladders.
pub const FULL_RUNG_BUDGET_S: f64 = 10.0;

/// The quantity a scene's refinement ladder follows in the full suite.
pub fn ladder_quantity(scene: &Scene) -> Option<String> {
    use data::scene::PrescribedMotion;
    if let Some(_r) = scene.rocket() {
        return Some(format!(
            "{}@{}",
            data::channel::ROCKET_VY,
            scene.simulation.t_end
        ));
    }
    let first = scene.links().first()?;
    let t = scene.simulation.t_end;
    Some(match first.joint.prescribed {
        Some(PrescribedMotion::Fixed) | Some(PrescribedMotion::ConstantRate { .. }) => {
            "freq1".into()
        }
        Some(PrescribedMotion::SpinUp { .. }) => format!("tip_deflection@{t}"),
        None => format!("{}@{t}", data::channel::joint_angle(1)),
    })
}

/// Id of a scene's refinement ladder in the full suite: what `verify --filter` matches, as
/// it matches case ids.
pub fn ladder_id(scene: &str) -> String {
    format!("ladder-{scene}")
}

/// One ladder of the full suite: the scene's catalog name and the quantity it follows.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LadderSpec {
    pub scene: String,
    pub quantity: String,
}

/// The full suite's ladders whose [`ladder_id`] contains `filter` (every one without a
/// filter), in catalog order; scenes without a ladder quantity have none.
pub fn select_ladders(filter: Option<&str>) -> Result<Vec<LadderSpec>, Error> {
    let mut out = Vec::new();
    for name in data::catalog_names() {
        if !filter.is_none_or(|f| ladder_id(name).contains(f)) {
            continue;
        }
        let scene = data::load_scene(name)?;
        if let Some(quantity) = ladder_quantity(&scene) {
            out.push(LadderSpec {
                scene: name.to_string(),
                quantity,
            });
        }
    }
    Ok(out)
}

/// The full suite's survey: each selected scene through every rung of each backend's space
/// ladder (a rung costing more than [`FULL_RUNG_BUDGET_S`] ends its ladder). With `out`, each
/// study is written by [`write_ladder`] as soon as it is done (so an interrupted survey keeps
/// what it finished). Returns the studies and the plot notes of [`write_study`].
pub fn run_ladders(
    selection: &[LadderSpec],
    out: Option<&Path>,
    progress: &dyn Progress,
) -> Result<(Vec<Study>, Vec<String>), Error> {
    let mut studies = Vec::new();
    let mut notes = Vec::new();
    for spec in selection {
        let scene = data::load_scene(&spec.scene)?;
        let study = run_study(
            &scene,
            &spec.quantity,
            Refine::Space,
            &BackendKind::ALL,
            &Settings::default(),
            Some(FULL_RUNG_BUDGET_S),
            progress,
        )?;
        if let Some(dir) = out {
            notes.extend(write_ladder(dir, &study)?);
        }
        studies.push(study);
    }
    Ok((studies, notes))
}

/// Writes a full-suite study into `dir/ladders` (when a rung was measured).
pub fn write_ladder(dir: &Path, study: &Study) -> Result<Vec<String>, Error> {
    if study.ladders.iter().any(|l| !l.rungs.is_empty()) {
        write_study(&dir.join("ladders"), study)
    } else {
        Ok(Vec::new())
    }
}

const SURVEY_HEADER: [&str; 7] = [
    "scene",
    "quantity",
    "backend",
    "rungs",
    "finest value",
    "order",
    "note",
];

fn survey_rows(studies: &[Study]) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for study in studies {
        for l in &study.ladders {
            rows.push(vec![
                study.scene.clone(),
                study.quantity.clone(),
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
    }
    rows
}

/// One line per scene and backend of the full suite's survey, at full width.
pub fn survey_wide_table(studies: &[Study]) -> String {
    text_table(&SURVEY_HEADER, &survey_rows(studies))
}

/// [`survey_wide_table`] for a terminal of `width` columns (notes cut with `…`).
pub fn survey_terminal_table(studies: &[Study], width: usize) -> String {
    let columns = [
        Column::left("scene"),
        Column::left("quantity"),
        Column::left("backend"),
        Column::right("rungs"),
        Column::right("finest value"),
        Column::right("order"),
        Column::left("note").elastic(),
    ];
    fitted_table(&columns, &survey_rows(studies), width).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ladder of `value(h) = limit + c h²` on h = 1/4, 1/8, 1/16.
    fn ladder(backend: BackendKind, limit: f64, c: f64) -> Ladder {
        let rungs: Vec<Rung> = [4.0, 8.0, 16.0]
            .iter()
            .map(|n: &f64| Rung {
                backend,
                discretization: format!("n={n}"),
                h: 1.0 / n,
                value: limit + c / (n * n),
                error: None,
                wall_time_s: 1.0,
                timing: Timing {
                    min_s: 1.0,
                    median_s: 1.0,
                    max_s: 1.0,
                    repeats: 1,
                },
                counters: Counters {
                    dofs: 0,
                    steps: 0,
                    rhs_evaluations: 0,
                    factorizations: 0,
                    newton_iterations: 0,
                },
                settings: Settings::default(),
                peak: None,
            })
            .collect();
        let hs: Vec<f64> = rungs.iter().map(|r| r.h).collect();
        let values: Vec<f64> = rungs.iter().map(|r| r.value).collect();
        let extrapolation = richardson(&hs, &values, None);
        let finest = rungs.last().unwrap().value;
        Ladder {
            backend,
            estimate: extrapolation.map(|(value, _)| Estimate {
                backend,
                value,
                uncertainty: (finest - value).abs(),
            }),
            richardson: extrapolation,
            rungs,
            observed_order: None,
            plateau_from: None,
            monotone_from_above: false,
            note: None,
        }
    }

    fn scale(_: &Ladder, v: f64) -> f64 {
        v.abs()
    }

    #[test]
    fn cross_ladders_converging_apart_are_reported_with_both_limits() {
        // Two second-order ladders whose limits differ by 1e-3 relative, far beyond their
        // finest rungs' distance from their extrapolations (c/256 = 4e-6).
        let ladders = [
            ladder(BackendKind::Fem, 1.0, 1e-3),
            ladder(BackendKind::Fdm, 1.001, 1e-3),
        ];
        let d = worst_disagreement(&ladders, scale).expect("a disagreement");
        assert!((d.first.value - 1.0).abs() < 1e-12, "{d:?}");
        assert!((d.second.value - 1.001).abs() < 1e-12, "{d:?}");
        assert!((d.relative_difference - 1e-3 / 1.001).abs() < 1e-12);
        let sentence = d.sentence();
        assert!(
            sentence.contains("fem converges to 1.0000000000e0"),
            "{sentence}"
        );
        assert!(sentence.contains("fdm to 1.0010000000e0"), "{sentence}");
    }

    #[test]
    fn cross_ladders_within_their_estimates_are_not_flagged() {
        // Limits 1e-6 apart, but each ladder's finest rung is still 4e-5 from its limit.
        let ladders = [
            ladder(BackendKind::Fem, 1.0, 1e-2),
            ladder(BackendKind::Modal, 1.0 + 1e-6, -1e-2),
        ];
        assert!(worst_disagreement(&ladders, scale).is_none());
        // One ladder alone cannot disagree.
        assert!(worst_disagreement(&ladders[..1], scale).is_none());
    }

    #[test]
    fn cross_the_worst_pair_is_reported() {
        let ladders = [
            ladder(BackendKind::Fem, 1.0, 1e-3),
            ladder(BackendKind::Fdm, 1.01, 1e-3),
            ladder(BackendKind::Modal, 1.0 + 1e-4, 1e-3),
        ];
        let d = worst_disagreement(&ladders, scale).unwrap();
        assert_eq!(d.first.backend, BackendKind::Fem);
        assert_eq!(d.second.backend, BackendKind::Fdm);
    }
}
