//! Plots of the verification report: overlaid time histories, energy-ledger residuals,
//! convergence and work-precision diagrams of the order cases. Everything plotted comes from
//! the runs the cases measured (the cache), so no run is repeated.

use std::path::Path;

use data::cases::{Case, Reference, scene_with_overrides};
use data::{RunResult, Scene, load_scene};

use super::evaluate::{Outcome, measure, rung_size};
use super::quantity::Quantity;
use super::reference::analytic_value;
use super::run_cache::{Answer, RunCache};
use crate::plot::{Series, plot};

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

/// Draws what can be drawn for each case; returns the number of plots written.
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
                match (
                    a.and_then(|r| series_of(&r, channel)),
                    b.and_then(|r| series_of(&r, channel)),
                ) {
                    (Some(pa), Some(pb)) => plot(
                        dir,
                        &stem,
                        &format!("{}: {channel}", scene.name),
                        "t",
                        channel,
                        &[
                            Series {
                                label: outcome.backend.clone(),
                                points: &pa,
                            },
                            Series {
                                label: outcome.reference_label.clone(),
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
                Some(r) if !r.ledger.time.is_empty() => {
                    let total: Vec<(f64, f64)> = r
                        .ledger
                        .time
                        .iter()
                        .enumerate()
                        .map(|(k, t)| (*t, r.ledger.total(k)))
                        .collect();
                    let resid: Vec<(f64, f64)> = r
                        .ledger
                        .time
                        .iter()
                        .enumerate()
                        .map(|(k, t)| (*t, r.ledger.residual(k)))
                        .collect();
                    let a = plot(
                        dir,
                        &stem,
                        &format!("{} {}: stored energy", scene.name, case.backend),
                        "t",
                        "E",
                        &[Series {
                            label: "E(t)".into(),
                            points: &total,
                        }],
                        false,
                    )
                    .is_ok();
                    let b = plot(
                        dir,
                        &format!("{stem}-residual"),
                        &format!(
                            "{} {}: ledger residual E - E0 - W_in + W_diss",
                            scene.name, case.backend
                        ),
                        "t",
                        "residual",
                        &[Series {
                            label: "residual".into(),
                            points: &resid,
                        }],
                        false,
                    )
                    .is_ok();
                    a && b
                }
                _ => false,
            },
            (
                _,
                Reference::Order {
                    ladder, against, ..
                },
            ) => {
                let exact = against
                    .as_ref()
                    .and_then(|id| analytic_value(id, &scene, &q).ok());
                let mut conv = Vec::new();
                let mut work = Vec::new();
                for rung in ladder {
                    let s = rung.to_settings();
                    let h = rung_size(rung);
                    if let (Ok((v, _, wall)), Some(h), Some(x)) =
                        (measure(cache, &scene, case.backend, &s, &q), h, exact)
                    {
                        let e = ((v - x) / x).abs();
                        conv.push((h, e));
                        work.push((wall.max(1e-7), e));
                    }
                }
                !conv.is_empty()
                    && plot(
                        dir,
                        &format!("{stem}-convergence"),
                        &format!("{} {}: error vs h", scene.name, case.quantity),
                        "h",
                        "relative error",
                        &[Series {
                            label: case.backend.to_string(),
                            points: &conv,
                        }],
                        true,
                    )
                    .is_ok()
                    && plot(
                        dir,
                        &format!("{stem}-work-precision"),
                        &format!("{} {}: work-precision", scene.name, case.quantity),
                        "wall time [s]",
                        "relative error",
                        &[Series {
                            label: case.backend.to_string(),
                            points: &work,
                        }],
                        true,
                    )
                    .is_ok()
            }
            _ => false,
        };
        if ok {
            count += 1;
        }
    }
    count
}
