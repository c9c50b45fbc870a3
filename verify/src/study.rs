//! Refinement studies (`flexverify converge`, `flexverify recommend`, the full suite's
//! ladders): refinement ladders, observed orders, Richardson references and work-precision
//! (error against wall time).
//!
//! Ladders are run sequentially so that the wall times are not distorted by sharing cores.

use std::path::Path;

use data::{BackendKind, Scene, Settings};
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::output::{Column, csv_table, fitted_table, text_table, wrap, write_atomic};
use crate::plot::{Series, plot};
use crate::progress::Progress;
use crate::suite::evaluate::{falling_prefix, fit_order, measure, richardson};
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
#[derive(Debug, Clone, Serialize)]
pub struct Rung {
    pub backend: BackendKind,
    /// Human-readable discretization, e.g. "elements=8".
    pub discretization: String,
    /// Refinement parameter h (1/elements, 1/(stations−1), 1/modes or dt).
    pub h: f64,
    pub value: f64,
    /// |value − reference| / scale.
    pub error: Option<f64>,
    pub wall_time_s: f64,
    #[serde(skip)]
    pub settings: Settings,
    /// Peak |channel| of this run, for time-history quantities.
    #[serde(skip)]
    pub peak: Option<f64>,
}

/// The study of one backend.
#[derive(Debug, Clone, Serialize)]
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
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Estimate {
    pub backend: BackendKind,
    pub value: f64,
    pub uncertainty: f64,
}

/// Two ladders whose estimates differ by more than their uncertainties allow: the backends
/// converge to different answers, so neither may be scored against the other.
#[derive(Debug, Clone, Copy, Serialize)]
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

#[derive(Debug, Clone, Serialize)]
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

/// Default refinement ladder of a backend (space) as settings + h.
fn space_ladder(kind: BackendKind, base: &Settings) -> Vec<(Settings, f64, String)> {
    let mut out = Vec::new();
    let with = |f: &dyn Fn(&mut Settings)| {
        let mut s = base.clone();
        f(&mut s);
        s
    };
    match kind {
        // The rigid reference has no spatial discretization.
        BackendKind::Reference => {}
        BackendKind::Fem => {
            for n in [2usize, 4, 8, 16, 32, 64] {
                out.push((
                    with(&|s| s.discretization.elements = Some(n)),
                    1.0 / n as f64,
                    format!("elements={n}"),
                ));
            }
        }
        BackendKind::Fdm => {
            for n in [11usize, 21, 41, 81, 161] {
                out.push((
                    with(&|s| s.discretization.stations = Some(n)),
                    1.0 / (n - 1) as f64,
                    format!("stations={n}"),
                ));
            }
        }
        BackendKind::Modal => {
            for n in [1usize, 2, 3, 4, 6, 8] {
                out.push((
                    with(&|s| s.discretization.modes = Some(n)),
                    1.0 / n as f64,
                    format!("modes={n}"),
                ));
            }
        }
    }
    out
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

/// Smallest backend wall time over a few repeats (the first call of a process pays one-off
/// costs, and a shared machine adds noise): repeat until 50 ms have been spent or 5 runs made.
fn min_wall_time(
    scene: &Scene,
    kind: BackendKind,
    settings: &Settings,
    q: &Quantity,
    first: f64,
) -> f64 {
    let mut best = first;
    let mut spent = first;
    let mut runs = 1;
    while spent < 0.05 && runs < 5 {
        let Some(w) = compute(scene, kind, settings, q.analysis(), q.modes_needed()).wall_time_s()
        else {
            break;
        };
        best = best.min(w);
        spent += w;
        runs += 1;
    }
    best
}

/// One rung's measurement: (value, peak |channel| for time histories, smallest wall time over
/// a few repeats), or why the backend could not give the quantity at that rung.
pub type RungMeasurement = Result<(f64, Option<f64>, f64), String>;

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
            let spec = match refine {
                Refine::Space => space_ladder(kind, base),
                Refine::Time => time_ladder(base, scene),
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
    measure(cache, scene, kind, settings, q)
        .map(|(value, peak, wall)| (value, peak, min_wall_time(scene, kind, settings, q, wall)))
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
                Ok((value, peak, wall_time_s)) => {
                    rungs.push(Rung {
                        wall_time_s,
                        backend: kind,
                        discretization: label,
                        h,
                        value,
                        error: None,
                        settings,
                        peak,
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

fn rows(study: &Study) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for l in &study.ladders {
        for r in &l.rungs {
            rows.push(vec![
                l.backend.to_string(),
                r.discretization.clone(),
                format!("{:.10e}", r.value),
                r.error.map_or("-".into(), |e| format!("{e:.3e}")),
                format!("{:.4e}", r.wall_time_s),
            ]);
        }
    }
    rows
}

/// Header of the study's CSV (the wide table says `wall [s]`).
const CSV_HEADER: [&str; 5] = ["backend", "discretization", "value", "error", "wall_s"];

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
    let series: Vec<Series<'_>> = conv
        .iter()
        .map(|(l, p)| Series {
            label: l.clone(),
            points: p,
        })
        .collect();
    let xlabel = if study.refine == "time" {
        "dt"
    } else {
        "h (1/elements, 1/(stations-1), 1/modes)"
    };
    if let Err(e) = plot(
        dir,
        &format!("{stem}-convergence"),
        &format!("{} {}: error vs refinement", study.scene, study.quantity),
        xlabel,
        "error",
        &series,
        true,
    ) {
        notes.push(format!("convergence plot not drawn: {e}"));
    }
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
    let series: Vec<Series<'_>> = work
        .iter()
        .map(|(l, p)| Series {
            label: l.clone(),
            points: p,
        })
        .collect();
    if let Err(e) = plot(
        dir,
        &format!("{stem}-work-precision"),
        &format!("{} {}: work-precision", study.scene, study.quantity),
        "wall time [s]",
        "error",
        &series,
        true,
    ) {
        notes.push(format!("work-precision plot not drawn: {e}"));
    }
    Ok(notes)
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
    csv_table(&CSV_HEADER, &rows(study))
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
    s.push_str(&text_table(
        &["backend", "discretization", "value", "error", "wall [s]"],
        &rows(study),
    ));
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
        Column::right("wall [s]"),
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
    /// The chosen rung: the smallest wall time among those with error ≤ tolerance.
    pub rung: Rung,
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
    let candidates: Vec<(&Rung, f64)> = study
        .ladders
        .iter()
        .filter_map(|l| Some((l, study.reference.or(l.estimate.map(|e| e.value))?)))
        .flat_map(|(l, reference)| l.rungs.iter().map(move |r| (r, reference)))
        .filter(|(r, _)| r.error.is_some_and(|e| e <= tol))
        .collect();
    let best = candidates
        .iter()
        .min_by(|a, b| a.0.wall_time_s.total_cmp(&b.0.wall_time_s));
    let Some(&(r, reference)) = best else {
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
        meeting: candidates.len(),
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

    /// The recommendation in three lines at full length.
    pub fn wide_text(&self) -> String {
        let r = &self.rung;
        format!(
            "recommended: {} with {} — value {:.10e}, measured error {:.3e} ≤ {:.1e} against {} = {:.10e}, wall time {:.3e} s\nre-run: flexverify {}\n{}\n",
            r.backend,
            r.discretization,
            r.value,
            r.error.unwrap_or(f64::NAN),
            self.tolerance,
            self.reference_label,
            self.reference,
            r.wall_time_s,
            self.rerun,
            self.counts()
        )
    }

    /// The recommendation for a terminal of `width` columns: one fact per line.
    pub fn terminal_text(&self, width: usize) -> String {
        let r = &self.rung;
        let lines = [
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
            format!("  wall time {:.3e} s", r.wall_time_s),
            format!("re-run: flexverify {}", self.rerun),
            self.counts(),
        ];
        lines.iter().map(|l| wrap(l, width, 4) + "\n").collect()
    }
}

/// Per-rung wall-time budget of the full suite's ladders.
pub const FULL_RUNG_BUDGET_S: f64 = 10.0;

/// The quantity a scene's refinement ladder follows in the full suite.
pub fn ladder_quantity(scene: &Scene) -> Option<String> {
    use data::scene::PrescribedMotion;
    if let Some(_r) = &scene.rocket {
        return Some(format!(
            "{}@{}",
            data::channel::ROCKET_VY,
            scene.simulation.t_end
        ));
    }
    let first = scene.links.first()?;
    let t = scene.simulation.t_end;
    Some(match first.joint.prescribed {
        Some(PrescribedMotion::Fixed) | Some(PrescribedMotion::ConstantRate { .. }) => {
            "freq1".into()
        }
        Some(PrescribedMotion::SpinUp { .. }) => format!("tip_deflection@{t}"),
        None => format!("{}@{t}", data::channel::joint_angle(1)),
    })
}

/// The full suite's survey: every catalog scene through every rung of each backend's space
/// ladder (a rung costing more than [`FULL_RUNG_BUDGET_S`] ends its ladder). With `out`, each
/// study with a measured rung is written to `out/ladders` as soon as it is done (so an
/// interrupted survey keeps what it finished). Returns the studies and the plot notes of
/// [`write_study`].
pub fn full_suite_ladders(
    out: Option<&Path>,
    progress: &dyn Progress,
) -> Result<(Vec<Study>, Vec<String>), Error> {
    let mut studies = Vec::new();
    let mut notes = Vec::new();
    for name in data::catalog_names() {
        let scene = data::load_scene(name)?;
        let Some(q) = ladder_quantity(&scene) else {
            continue;
        };
        let study = run_study(
            &scene,
            &q,
            Refine::Space,
            &BackendKind::ALL,
            &Settings::default(),
            Some(FULL_RUNG_BUDGET_S),
            progress,
        )?;
        if let Some(dir) = out
            && study.ladders.iter().any(|l| !l.rungs.is_empty())
        {
            notes.extend(write_study(&dir.join("ladders"), &study)?);
        }
        studies.push(study);
    }
    Ok((studies, notes))
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
