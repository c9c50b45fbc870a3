//! `flexverify converge` and `flexverify recommend`: refinement ladders, observed orders,
//! Richardson references and work-precision (error against wall time).
//!
//! Ladders are run sequentially so that the wall times are not distorted by sharing cores.

use data::{BackendKind, Scene, Settings, load_scene};
use serde::Serialize;

use crate::cli::CliError;
use crate::cli::args::{CommonOpts, Refine};
use crate::output::{Format, csv_table, text_table, write_atomic};
use crate::plot::{Series, plot};
use crate::suite::evaluate::{falling_prefix, fit_order, measure, richardson};
use crate::suite::quantity::Quantity;
use crate::suite::reference::{analytic_value, default_analytic_id};
use crate::suite::run_cache::{RunCache, compute};

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
}

#[derive(Debug, Clone, Serialize)]
pub struct Study {
    pub scene: String,
    pub quantity: String,
    pub refine: String,
    pub reference: Option<f64>,
    pub reference_label: String,
    pub ladders: Vec<Ladder>,
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

/// Runs the ladders and fills errors against the best available reference.
pub fn run_study(
    scene: &Scene,
    quantity: &str,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    rung_budget_s: Option<f64>,
) -> Result<Study, CliError> {
    let q = Quantity::parse(quantity, scene)
        .map_err(|e| CliError::Input(format!("error: --quantity: {e}")))?;
    let cache = RunCache::default();
    let mut ladders = Vec::new();
    for &kind in kinds {
        let rungs_spec = match refine {
            Refine::Space => space_ladder(kind, base),
            Refine::Time => time_ladder(base, scene),
        };
        let mut rungs: Vec<Rung> = Vec::new();
        let mut note = None;
        let rungs_total = rungs_spec.len();
        for (settings, h, label) in rungs_spec {
            // A full-suite ladder stops once a rung costs more than the budget: the next
            // rung would cost several times more.
            if let (Some(budget), Some(last)) = (rung_budget_s, rungs.last())
                && last.wall_time_s > budget
            {
                break;
            }
            match measure(&cache, scene, kind, &settings, &q) {
                Ok((value, peak, wall)) => rungs.push(Rung {
                    wall_time_s: min_wall_time(scene, kind, &settings, &q, wall),
                    backend: kind,
                    discretization: label,
                    h,
                    value,
                    error: None,
                    settings,
                    peak,
                }),
                Err(e) => {
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
        ladders.push(Ladder {
            backend: kind,
            richardson: richardson(&hs, &values, None),
            rungs,
            observed_order: None,
            plateau_from: None,
            monotone_from_above,
            note,
        });
    }

    // Reference: analytic when the scene/quantity has one, else the Richardson value of the
    // ladder whose last two rungs agree best (its own estimate of its error is smallest).
    let (reference, reference_label) = match default_analytic_id(scene, &q)
        .and_then(|id| analytic_value(&id, scene, &q).ok().map(|v| (v, id)))
    {
        Some((v, id)) => (Some(v), format!("analytic:{id}")),
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
    if let Some(r) = reference {
        let relative_to_peak = matches!(q, Quantity::At { .. });
        for l in &mut ladders {
            let scale_peak = l.rungs.last().and_then(|r| r.peak);
            for rung in &mut l.rungs {
                let scale = if relative_to_peak {
                    scale_peak.unwrap_or(r.abs())
                } else {
                    r.abs()
                };
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
    }
    Ok(Study {
        scene: scene.name.clone(),
        quantity: quantity.to_string(),
        refine: format!("{refine:?}").to_lowercase(),
        reference,
        reference_label,
        ladders,
    })
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

pub fn write_study(dir: &std::path::Path, study: &Study) -> Result<(), CliError> {
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
    write_atomic(
        dir,
        &format!("{stem}.csv"),
        csv_table(
            &["backend", "discretization", "value", "error", "wall_s"],
            &rows(study),
        )
        .as_bytes(),
    )?;
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
        eprintln!("note: convergence plot not drawn: {e}");
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
        eprintln!("note: work-precision plot not drawn: {e}");
    }
    Ok(())
}

pub fn converge_command(
    scene: &str,
    quantity: &str,
    refine: Refine,
    opts: &CommonOpts,
) -> Result<(), CliError> {
    let scene = load_scene(scene)?;
    let study = run_study(
        &scene,
        quantity,
        refine,
        &opts.backend.kinds(),
        &opts.settings(),
        None,
    )?;
    if study.ladders.iter().all(|l| l.rungs.is_empty()) {
        let notes: Vec<String> = study
            .ladders
            .iter()
            .filter_map(|l| l.note.clone())
            .collect();
        return Err(CliError::Unsupported(format!(
            "unsupported: no backend produced `{quantity}`:\n{}",
            notes.join("\n")
        )));
    }
    if let Some(dir) = &opts.out {
        write_study(dir, &study)?;
        eprintln!("wrote the study and its plots to {}", dir.display());
    }
    match opts.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&study).expect("json")),
        Format::Csv => print!(
            "{}",
            csv_table(
                &["backend", "discretization", "value", "error", "wall_s"],
                &rows(&study)
            )
        ),
        Format::Table => {
            println!(
                "{} {} ({} refinement); reference: {} {}",
                study.scene,
                study.quantity,
                study.refine,
                study.reference.map_or("-".into(), |r| format!("{r:.12e}")),
                study.reference_label
            );
            print!(
                "{}",
                text_table(
                    &["backend", "discretization", "value", "error", "wall [s]"],
                    &rows(&study)
                )
            );
            for l in &study.ladders {
                println!(
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
                );
            }
        }
    }
    Ok(())
}

pub fn recommend_command(
    scene_name: &str,
    quantity: &str,
    tol: f64,
    opts: &CommonOpts,
) -> Result<(), CliError> {
    let scene = load_scene(scene_name)?;
    let study = run_study(
        &scene,
        quantity,
        Refine::Space,
        &opts.backend.kinds(),
        &opts.settings(),
        None,
    )?;
    let Some(reference) = study.reference else {
        return Err(CliError::Failed(format!(
            "no reference could be established for `{quantity}` on `{}`: {}",
            scene.name, study.reference_label
        )));
    };
    let candidates: Vec<&Rung> = study
        .ladders
        .iter()
        .flat_map(|l| l.rungs.iter())
        .filter(|r| r.error.is_some_and(|e| e <= tol))
        .collect();
    let best = candidates
        .iter()
        .min_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s));
    match best {
        Some(r) => {
            let flag = r.discretization.replace('=', " ");
            println!(
                "recommended: {} with {} — value {:.10e}, measured error {:.3e} ≤ {tol:.1e} against {} = {reference:.10e}, wall time {:.3e} s",
                r.backend,
                r.discretization,
                r.value,
                r.error.unwrap_or(f64::NAN),
                study.reference_label,
                r.wall_time_s
            );
            // Ending the re-run at the quantity's time makes its final value the quantity.
            let parsed = Quantity::parse(quantity, &scene);
            let until = match parsed {
                Ok(Quantity::At { t, .. }) => format!(" --t-end {t}"),
                _ => String::new(),
            };
            let what = match parsed {
                Ok(Quantity::Frequency { .. }) => "modes",
                Ok(Quantity::StaticTip) => "statics",
                _ => "run",
            };
            println!(
                "re-run: flexverify {what} {} --backend {} --{flag}{until}",
                scene.name, r.backend
            );
            println!(
                "({} of {} measured discretizations meet the tolerance)",
                candidates.len(),
                study.ladders.iter().map(|l| l.rungs.len()).sum::<usize>()
            );
            Ok(())
        }
        None => {
            let best_err = study
                .ladders
                .iter()
                .flat_map(|l| l.rungs.iter())
                .filter_map(|r| Some((r.error?, r)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            Err(CliError::Failed(match best_err {
                Some((e, r)) => format!(
                    "no measured discretization meets {tol:.1e}: the best is {} {} with error {e:.3e} (against {})",
                    r.backend, r.discretization, study.reference_label
                ),
                None => "no discretization could be measured".into(),
            }))
        }
    }
}
