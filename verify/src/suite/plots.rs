//! Plots of the verification report: overlaid time histories of the backends, energy-ledger
//! terms over time, convergence and work–precision diagrams of the order cases (with their
//! measurements written as `work-<case>.json` for the scene Pareto fronts of
//! [`crate::report`]). Histories and ledgers come from the runs the cases measured (the
//! cache); only the work–precision timings run again, sequentially, so that the suite's
//! parallel runs do not distort them.

use std::path::Path;

use data::cases::{Case, CaseSettings, Reference, scene_with_overrides};
use data::{RunResult, Scene, load_scene};

use super::evaluate::{Outcome, ladder_rung_sizes};
use super::order::richardson;
use super::quantity::Quantity;
use super::reference::analytic_value;
use super::run_cache::{Answer, RunCache, compute};
use crate::plot::{Mark, Series, StyledSeries, plot, plot_styled};
use crate::work::{CaseWork, FirstRun, WorkPoint, time_rung, work_counter};

fn scene_of(case: &Case) -> Option<Scene> {
    if case.overrides.is_empty() {
        load_scene(&case.scene).ok()
    } else {
        scene_with_overrides(&case.scene, &case.overrides).ok()
    }
}

fn run(
    cache: &RunCache,
    scene: &Scene,
    case_backend: data::BackendKind,
    s: &data::Settings,
) -> Option<RunResult> {
    match cache.get(
        scene,
        case_backend,
        s,
        super::quantity::Analysis::Simulate,
        0,
    ) {
        Answer::Run(Ok(r)) => Some(r),
        _ => None,
    }
}

fn series_of(r: &RunResult, channel: &str) -> Option<Vec<(f64, f64)>> {
    let (t, v) = super::history::series(r, channel)?;
    Some(t.iter().copied().zip(v.iter().copied()).collect())
}

/// The unit of energies in a scene's unit system.
fn energy_unit(scene: &Scene) -> &'static str {
    let u = scene.units.trim_start();
    if u.starts_with("SI") {
        "J"
    } else if u.starts_with("ft") {
        "ft·lbf"
    } else if u.starts_with("in") {
        "in·lbf"
    } else {
        "energy unit"
    }
}

/// The time axis: every catalog unit system measures time in seconds.
const TIME_AXIS: &str = "t [s]";

/// A channel's generic unit (`length`, `force·length`, `rad/time`) in the scene's units.
fn concrete_unit(unit: &str, scene: &Scene) -> String {
    let (length, force, mass) = match energy_unit(scene) {
        "J" => ("m", "N", "kg"),
        "ft·lbf" => ("ft", "lbf", "slug"),
        "in·lbf" => ("in", "lbf", "lbf·s²/in"),
        _ => return unit.to_string(),
    };
    unit.replace("length", length)
        .replace("force", force)
        .replace("mass", mass)
        .replace("time", "s")
}

/// The y-axis label of a history channel: its name and unit.
fn channel_label(r: &RunResult, scene: &Scene, channel: &str) -> String {
    if channel.starts_with(data::cases::ENERGY_PREFIX) {
        return format!("{channel} [{}]", energy_unit(scene));
    }
    match r.observables.get(channel) {
        Some(c) if !c.unit.is_empty() => format!("{channel} [{}]", concrete_unit(&c.unit, scene)),
        _ => channel.to_string(),
    }
}

/// The x-axis label of a ladder: what its refinement parameter h is.
fn ladder_axis(ladder: &[CaseSettings]) -> &'static str {
    match ladder.first() {
        Some(s) if s.dt.is_some() => "dt [s]",
        Some(s) if s.elements.is_some() => "h = 1/elements [-]",
        Some(s) if s.stations.is_some() => "h = 1/(stations-1) [-]",
        Some(s) if s.modes.is_some() => "1/modes [-]",
        _ => "h [-]",
    }
}

/// Draws what can be drawn for each case; returns the number of cases with plots.
pub fn draw_all(dir: &Path, cases: &[Case], outcomes: &[Outcome], cache: &RunCache) -> usize {
    let mut count = 0;
    for (case, outcome) in cases.iter().zip(outcomes) {
        let Some(scene) = scene_of(case) else {
            continue;
        };
        let Ok(q) = Quantity::parse(&case.quantity, &scene) else {
            continue;
        };
        let settings = case.settings.to_settings();
        let stem = format!("case-{}", case.id);
        let ok = match (&q, &case.reference) {
            (
                Quantity::History { channel, .. },
                Reference::Backend {
                    backend,
                    settings: rs,
                    overrides,
                },
            ) => {
                let a = run(cache, &scene, case.backend, &settings);
                let b = super::evaluate::case_scene(case, overrides)
                    .ok()
                    .and_then(|variant| run(cache, &variant, *backend, &rs.to_settings()));
                let ylabel = a
                    .as_ref()
                    .map_or(channel.clone(), |r| channel_label(r, &scene, channel));
                match (
                    a.and_then(|r| series_of(&r, channel)),
                    b.and_then(|r| series_of(&r, channel)),
                ) {
                    (Some(pa), Some(pb)) => plot(
                        dir,
                        &stem,
                        &format!("{}: {channel}", scene.name),
                        TIME_AXIS,
                        &ylabel,
                        &[
                            Series {
                                label: outcome.backend.clone(),
                                points: &pa,
                            },
                            Series {
                                label: format!("{backend} (reference)"),
                                points: &pb,
                            },
                        ],
                        false,
                    )
                    .is_ok(),
                    _ => false,
                }
            }
            (Quantity::LedgerClosure, _) => match run(cache, &scene, case.backend, &settings) {
                Some(r) if !r.ledger.time.is_empty() => draw_ledger(dir, &stem, &scene, case, &r),
                _ => false,
            },
            (
                _,
                Reference::Order {
                    ladder,
                    against,
                    order,
                },
            ) => draw_ladder(
                dir,
                cache,
                &stem,
                &scene,
                case,
                outcome,
                &q,
                ladder,
                against.as_deref(),
                *order,
            ),
            _ => false,
        };
        if ok {
            count += 1;
        }
    }
    count
}

/// Every ledger term over time (stored, input and dissipated), the stored total, and the
/// closure residual E − E0 − W_in + W_diss on its own plot (it is orders of magnitude smaller).
fn draw_ledger(dir: &Path, stem: &str, scene: &Scene, case: &Case, r: &RunResult) -> bool {
    let l = &r.ledger;
    let unit = energy_unit(scene);
    let term = |values: &[f64]| -> Vec<(f64, f64)> {
        l.time.iter().copied().zip(values.iter().copied()).collect()
    };
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    let total: Vec<f64> = (0..l.time.len()).map(|k| l.total(k)).collect();
    curves.push(("E (stored total)".into(), term(&total)));
    for t in &l.stored {
        curves.push((format!("stored: {}", t.name), term(&t.values)));
    }
    for t in &l.inputs {
        curves.push((format!("input: {}", t.name), term(&t.values)));
    }
    for t in &l.dissipation {
        curves.push((format!("dissipated: {}", t.name), term(&t.values)));
    }
    let series: Vec<Series<'_>> = curves
        .iter()
        .map(|(label, points)| Series {
            label: label.clone(),
            points,
        })
        .collect();
    let a = plot(
        dir,
        stem,
        &format!("{} {}: energy ledger terms", scene.name, case.backend),
        TIME_AXIS,
        &format!("energy [{unit}]"),
        &series,
        false,
    )
    .is_ok();
    let resid: Vec<(f64, f64)> = (0..l.time.len())
        .map(|k| (l.time[k], l.residual(k)))
        .collect();
    let b = plot(
        dir,
        &format!("{stem}-residual"),
        &format!("{} {}: ledger closure residual", scene.name, case.backend),
        TIME_AXIS,
        &format!("E - E0 - W_in + W_diss [{unit}]"),
        &[Series {
            label: format!("{} residual", case.backend),
            points: &resid,
        }],
        false,
    )
    .is_ok();
    a && b
}

/// The convergence plot of an order case, its work–precision plots (minimum wall time over
/// repeats; the work counter) and its measurements as `work-<case>.json`.
#[allow(clippy::too_many_arguments)]
fn draw_ladder(
    dir: &Path,
    cache: &RunCache,
    stem: &str,
    scene: &Scene,
    case: &Case,
    outcome: &Outcome,
    q: &Quantity,
    ladder: &[CaseSettings],
    against: Option<&str>,
    order: f64,
) -> bool {
    // Each rung once more, sequentially: value, cost counters and repeated timings.
    let Ok(sizes) = ladder_rung_sizes(ladder) else {
        return false;
    };
    let mut rungs = Vec::new();
    for (rung, &h) in ladder.iter().zip(&sizes) {
        let s = rung.to_settings();
        let Ok((value, _, _)) = super::evaluate::measure(cache, scene, case.backend, &s, q) else {
            continue;
        };
        let cached = cache.get(scene, case.backend, &s, q.analysis(), q.modes_needed());
        let Some(cost) = cached.counters() else {
            continue;
        };
        let answer = || compute(scene, case.backend, &s, q.analysis(), q.modes_needed());
        let Some(first) = cached.wall_time_s() else {
            continue;
        };
        let Some(timing) = time_rung(first, FirstRun::Shared, || answer().wall_time_s()) else {
            continue;
        };
        rungs.push((rung, h, value, cost, timing));
    }
    if rungs.is_empty() {
        return false;
    }
    let hs: Vec<f64> = rungs.iter().map(|r| r.1).collect();
    let values: Vec<f64> = rungs.iter().map(|r| r.2).collect();
    let (reference, reference_label) =
        match against.and_then(|id| analytic_value(id, scene, q).ok()) {
            Some(x) => (x, format!("analytic:{}", against.unwrap_or_default())),
            None => match richardson(&hs, &values, None)
                .or_else(|| richardson(&hs, &values, Some(order)))
            {
                Some((x, p)) => (
                    x,
                    format!("Richardson extrapolation of the ladder (order {p:.2})"),
                ),
                None => return false,
            },
        };
    // Relative error, or absolute where the limit is zero (an excess over an analytic limit):
    // a relative error there is infinite and would not survive the JSON round trip.
    let (scale, reference_label) = if reference == 0.0 {
        (
            1.0,
            format!("{reference_label} (absolute error: the limit is 0)"),
        )
    } else {
        (reference.abs(), reference_label)
    };
    let points: Vec<WorkPoint> = rungs
        .iter()
        .map(|(rung, _, value, cost, timing)| WorkPoint {
            backend: case.backend.to_string(),
            discretization: super::evaluate::settings_label(rung),
            value: *value,
            error: (value - reference).abs() / scale,
            timing: *timing,
            counters: *cost,
        })
        .collect();
    let work = CaseWork {
        case: case.id.clone(),
        scene: outcome.scene.clone(),
        modified: !case.overrides.is_empty(),
        quantity: case.quantity.clone(),
        backend: case.backend.to_string(),
        reference_label: reference_label.clone(),
        points,
    };
    let json = serde_json::to_string_pretty(&work).expect("serializable work");
    if crate::output::write_atomic(dir, &CaseWork::file_name(&case.id), json.as_bytes()).is_err() {
        return false;
    }
    let backend = case.backend.to_string();
    let conv: Vec<(f64, f64)> = hs
        .iter()
        .zip(&work.points)
        .map(|(h, p)| (*h, p.error))
        .collect();
    let by_time: Vec<(f64, f64)> = work
        .points
        .iter()
        .map(|p| (p.timing.min_s, p.error))
        .collect();
    let (counter_name, counter) = work_counter(&work.points);
    let by_work: Vec<(f64, f64)> = work
        .points
        .iter()
        .map(|p| (counter(&p.counters) as f64, p.error))
        .collect();
    let title = |what: &str| format!("{} {}: {what}", scene.name, case.quantity);
    let ylabel = format!("relative error vs {reference_label} [-]");
    let ylabel = if ylabel.len() > 60 {
        "relative error [-]".to_string()
    } else {
        ylabel
    };
    let series = |points| {
        [StyledSeries {
            label: backend.clone(),
            points,
            mark: Mark::Line,
        }]
    };
    plot_styled(
        dir,
        &format!("{stem}-convergence"),
        &title("error vs refinement"),
        ladder_axis(ladder),
        &ylabel,
        &series(&conv),
        true,
    )
    .is_ok()
        && plot_styled(
            dir,
            &format!("{stem}-work-precision"),
            &title("error vs wall time"),
            "wall time, minimum of repeats [s]",
            &ylabel,
            &series(&by_time),
            true,
        )
        .is_ok()
        && plot_styled(
            dir,
            &format!("{stem}-work-counters"),
            &title(&format!("error vs {counter_name}")),
            &format!("work: {counter_name} [-]"),
            &ylabel,
            &series(&by_work),
            true,
        )
        .is_ok()
}
