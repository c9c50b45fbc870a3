//! One case → one outcome row.

use data::cases::{Case, CaseSettings, Norm, Reference, scene_with_overrides};
use data::{BackendError, Scene, Settings, StabilityVerdict, load_scene};
use serde::{Deserialize, Serialize};

use super::order::{falling_prefix, fit_order, richardson};
use super::quantity::{Analysis, Quantity};
use super::reference::analytic_value;
use super::run_cache::{Answer, RunCache};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    Pass,
    Fail,
    /// The case could not be evaluated (unsupported, missing channel, …): counts as a failure.
    Error,
}

/// A row of the verification table.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Outcome {
    pub id: String,
    pub check: String,
    pub scene: String,
    pub backend: String,
    pub settings: CaseSettings,
    pub quantity: String,
    pub value: Option<f64>,
    pub reference: Option<f64>,
    /// Where the reference comes from, e.g. "analytic:clamped-free" or "modal(modes=8)".
    pub reference_label: String,
    pub norm: Norm,
    pub error: Option<f64>,
    pub tolerance: f64,
    pub status: Status,
    pub message: String,
    pub why: String,
    /// Backend wall time of the evaluated run(s), seconds.
    pub wall_time_s: f64,
}

pub(crate) fn settings_label(s: &CaseSettings) -> String {
    let mut parts = Vec::new();
    if let Some(v) = s.elements {
        parts.push(format!("elements={v}"));
    }
    if let Some(v) = s.stations {
        parts.push(format!("stations={v}"));
    }
    if let Some(v) = s.modes {
        parts.push(format!("modes={v}"));
    }
    if let Some(v) = s.basis {
        parts.push(format!("basis={}", v.name()));
    }
    if let Some(v) = s.element {
        parts.push(format!("element={}", v.name()));
    }
    if let Some(v) = s.dt {
        parts.push(format!("dt={v}"));
    }
    if let Some(v) = &s.method {
        parts.push(format!("method={v}"));
    }
    if let Some(v) = s.rtol {
        parts.push(format!("rtol={v}"));
    }
    parts.join(",")
}

/// Evaluates a quantity for one backend and settings: (value, peak scale, wall time).
pub fn measure(
    cache: &RunCache,
    scene: &Scene,
    kind: data::BackendKind,
    settings: &Settings,
    q: &Quantity,
) -> Result<(f64, Option<f64>, f64), String> {
    let modes = q.modes_needed();
    let fmt_err = |e: BackendError| format!("{kind}: {e}");
    match cache.get(scene, kind, settings, q.analysis(), modes) {
        Answer::Modes(r) => {
            let r = r.map_err(fmt_err)?;
            Ok((q.from_modes(&r)?, None, r.cost.wall_time_s))
        }
        Answer::Statics(r) => {
            let r = r.map_err(fmt_err)?;
            Ok((q.from_statics(&r)?, None, r.cost.wall_time_s))
        }
        Answer::Run(r) => {
            let r = r.map_err(fmt_err)?;
            if let StabilityVerdict::Stopped { diagnostic } = &r.verdict {
                // A stopped run is still measured (the case may be about divergence), but only
                // where the quantity lies inside the computed interval.
                if let Quantity::At { t, .. } = q
                    && *t > diagnostic.t
                {
                    return Err(format!("{kind}: run stopped before t = {t}: {diagnostic}"));
                }
            }
            Ok((q.from_run(&r)?, q.peak_scale(&r), r.cost.wall_time_s))
        }
    }
}

/// Measures the quantity on every rung of a ladder: (h of each rung, values, total wall time).
/// `h` ([`ladder_rung_sizes`]) is computed only when `need_h` is set, and is empty otherwise.
fn measure_ladder(
    cache: &RunCache,
    scene: &Scene,
    kind: data::BackendKind,
    ladder: &[CaseSettings],
    q: &Quantity,
    need_h: bool,
) -> Result<(Vec<f64>, Vec<f64>, f64), String> {
    let h = if need_h {
        ladder_rung_sizes(ladder)?
    } else {
        Vec::new()
    };
    let (mut v, mut wall) = (Vec::new(), 0.0);
    for rung in ladder {
        let (val, _, w) = measure(cache, scene, kind, &rung.to_settings(), q)?;
        v.push(val);
        wall += w;
    }
    Ok((h, v, wall))
}

pub fn evaluate(case: &Case, cache: &RunCache) -> Outcome {
    let mut out = Outcome {
        id: case.id.clone(),
        check: case.check.clone(),
        scene: case.scene.clone(),
        backend: format!("{}({})", case.backend, settings_label(&case.settings)),
        settings: case.settings.clone(),
        quantity: case.quantity.clone(),
        value: None,
        reference: None,
        reference_label: String::new(),
        norm: case.norm,
        error: None,
        tolerance: case.tolerance,
        status: Status::Error,
        message: String::new(),
        why: case.why.clone(),
        wall_time_s: 0.0,
    };
    match evaluate_inner(case, cache, &mut out) {
        Ok(()) => {
            let err = out.error.unwrap_or(f64::INFINITY);
            if err.is_finite() && err <= case.tolerance {
                out.status = Status::Pass;
            } else {
                out.status = Status::Fail;
                out.message = format!(
                    "error {err:.3e} exceeds tolerance {:.1e} ({})",
                    case.tolerance, out.reference_label
                );
            }
        }
        Err(msg) => {
            out.status = Status::Error;
            out.message = msg;
        }
    }
    out
}

/// The case's scene with its overrides and, on top, `extra` ones (a reference run on a variant
/// of the scene).
pub fn case_scene(
    case: &Case,
    extra: &std::collections::BTreeMap<String, toml::Value>,
) -> Result<Scene, String> {
    if case.overrides.is_empty() && extra.is_empty() {
        return load_scene(&case.scene).map_err(|e| e.to_string());
    }
    let mut all = case.overrides.clone();
    all.extend(extra.iter().map(|(k, v)| (k.clone(), v.clone())));
    scene_with_overrides(&case.scene, &all)
}

/// " on overrides {k = v, …}" for a reference run on a scene variant ("" otherwise).
fn variant_label(extra: &std::collections::BTreeMap<String, toml::Value>) -> String {
    if extra.is_empty() {
        return String::new();
    }
    let parts: Vec<String> = extra.iter().map(|(k, v)| format!("{k} = {v}")).collect();
    format!(" on the scene with {}", parts.join(", "))
}

fn evaluate_inner(case: &Case, cache: &RunCache, out: &mut Outcome) -> Result<(), String> {
    let scene = case_scene(case, &Default::default())?;
    let q = Quantity::parse(&case.quantity, &scene)?;
    let settings = case.settings.to_settings();

    if let Quantity::History {
        channel,
        lowpass_hz,
    } = &q
        && matches!(
            case.reference,
            Reference::Order { .. } | Reference::Richardson { .. }
        )
    {
        return history_ladder(case, cache, &scene, channel, *lowpass_hz, out);
    }

    if let Reference::Order {
        order,
        ladder,
        against,
    } = &case.reference
    {
        let (h, v, wall) = measure_ladder(cache, &scene, case.backend, ladder, &q, true)?;
        out.wall_time_s += wall;
        let errors: Vec<f64> = match against {
            Some(id) => {
                let r = analytic_value(id, &scene, &q)?;
                // a vanishing limit: absolute errors (the fitted order is scale-free)
                let scale = if r == 0.0 { 1.0 } else { r };
                v.iter().map(|x| (x - r) / scale).collect()
            }
            None => {
                let (ext, _) = richardson(&h, &v, None).ok_or(
                    "the ladder is not in the asymptotic range (non-monotone differences)",
                )?;
                v.iter().map(|x| x - ext).collect()
            }
        };
        let keep = falling_prefix(&errors);
        let observed =
            fit_order(&h[..keep], &errors[..keep]).ok_or("cannot fit an order (zero errors)")?;
        out.value = Some(observed);
        out.reference = Some(*order);
        out.reference_label = format!(
            "order {order} over {keep} of {} rungs vs {}",
            ladder.len(),
            against
                .as_deref()
                .map_or("Richardson".to_string(), |a| format!("analytic:{a}"))
        );
        out.error = Some((observed - order).abs());
        out.quantity = format!("order({})", case.quantity);
        return Ok(());
    }

    if let Reference::Monotone { decreasing, above } = &case.reference {
        let (_, values, wall) = measure_ladder(cache, &scene, case.backend, decreasing, &q, false)?;
        out.wall_time_s += wall;
        let exact = analytic_value(above, &scene, &q)?;
        // Worst violation of the Rayleigh–Ritz properties, relative to the exact value:
        // an increase along the ladder, or a value below the exact one.
        let rise = values
            .windows(2)
            .map(|w| (w[1] - w[0]) / exact.abs())
            .fold(0.0f64, f64::max);
        let below = values
            .iter()
            .map(|v| (exact - v) / exact.abs())
            .fold(0.0f64, f64::max);
        out.value = values.last().copied();
        out.reference = Some(exact);
        out.reference_label = format!(
            "monotone from above over {} rungs, bound analytic:{above}",
            values.len()
        );
        out.error = Some(rise.max(below).max(0.0));
        out.quantity = format!("monotone({})", case.quantity);
        return Ok(());
    }

    if let (
        Quantity::History {
            channel,
            lowpass_hz,
        },
        Reference::Backend {
            backend,
            settings: ref_settings,
            overrides: ref_overrides,
        },
    ) = (&q, &case.reference)
    {
        let ref_scene = case_scene(case, ref_overrides)?;
        let run = |sc: &Scene, kind, s: &Settings| match cache.get(sc, kind, s, q.analysis(), 0) {
            Answer::Run(Ok(r)) => Ok(r),
            Answer::Run(Err(e)) => Err(format!("{kind}: {e}")),
            _ => Err("not a run".to_string()),
        };
        let a = run(&scene, case.backend, &settings)?;
        let b = run(&ref_scene, *backend, &ref_settings.to_settings())?;
        let d = super::history::compare(&a, &b, channel, *lowpass_hz)
            .map_err(|e| format!("{} vs {backend}: {e}", case.backend))?;
        out.wall_time_s += a.cost.wall_time_s + b.cost.wall_time_s;
        out.value = Some(d.max_abs_diff);
        out.reference = Some(d.reference_peak);
        out.reference_label = format!(
            "history of {backend}({}){}{}, error = max|Δ| / its peak",
            settings_label(ref_settings),
            variant_label(ref_overrides),
            lowpass_hz.map_or(String::new(), |f| format!(", both low-passed at {f} Hz"))
        );
        if d.reference_peak <= 0.0 {
            return Err("the reference history is identically zero".into());
        }
        out.error = Some(d.max_abs_diff / d.reference_peak);
        return Ok(());
    }

    if let (
        Quantity::History {
            channel,
            lowpass_hz,
        },
        Reference::Analytic { analytic },
    ) = (&q, &case.reference)
    {
        let a = match cache.get(&scene, case.backend, &settings, q.analysis(), 0) {
            Answer::Run(Ok(r)) => r,
            Answer::Run(Err(e)) => return Err(format!("{}: {e}", case.backend)),
            _ => return Err("not a run".to_string()),
        };
        let d = super::history::compare_to_function(&a, channel, *lowpass_hz, |times| {
            super::reference::analytic_history(analytic, &scene, channel, times)
        })
        .map_err(|e| format!("{} vs analytic:{analytic}: {e}", case.backend))?;
        out.wall_time_s += a.cost.wall_time_s;
        out.value = Some(d.max_abs_diff);
        out.reference = Some(d.reference_peak);
        out.reference_label = format!(
            "history of analytic:{analytic}{}, error = max|Δ| / its peak",
            lowpass_hz.map_or(String::new(), |f| format!(", both low-passed at {f} Hz"))
        );
        if d.reference_peak <= 0.0 {
            return Err("the reference history is identically zero".into());
        }
        out.error = Some(d.max_abs_diff / d.reference_peak);
        return Ok(());
    }

    let (value, peak, wall) = measure(cache, &scene, case.backend, &settings, &q)?;
    out.value = Some(value);
    out.wall_time_s += wall;
    let (reference, ref_peak) = match &case.reference {
        Reference::Analytic { analytic } => {
            out.reference_label = format!("analytic:{analytic}");
            (analytic_value(analytic, &scene, &q)?, None)
        }
        Reference::Backend {
            backend,
            settings,
            overrides,
        } => {
            out.reference_label = format!(
                "{backend}({}){}",
                settings_label(settings),
                variant_label(overrides)
            );
            let ref_scene = case_scene(case, overrides)?;
            let (r, p, w) = measure(cache, &ref_scene, *backend, &settings.to_settings(), &q)?;
            out.wall_time_s += w;
            (r, p)
        }
        Reference::Richardson { richardson: ladder } => {
            let (h, v, wall) = measure_ladder(cache, &scene, case.backend, ladder, &q, true)?;
            out.wall_time_s += wall;
            let (ext, p) = richardson(&h, &v, None).ok_or("Richardson ladder not asymptotic")?;
            out.reference_label = format!("Richardson over {} rungs (p = {p:.2})", ladder.len());
            (ext, None)
        }
        Reference::Zero { .. } => {
            out.reference_label = "zero".into();
            (0.0, None)
        }
        Reference::Order { .. } | Reference::Monotone { .. } => unreachable!("handled above"),
    };
    out.reference = Some(reference);
    let err = match case.norm {
        Norm::Absolute => (value - reference).abs(),
        Norm::Relative => {
            if reference == 0.0 {
                return Err("relative norm against a zero reference".into());
            }
            ((value - reference) / reference).abs()
        }
        Norm::RelativeToPeak => {
            let scale = ref_peak
                .or(peak)
                .filter(|s| *s > 0.0)
                .ok_or("no peak scale")?;
            (value - reference).abs() / scale
        }
    };
    out.error = Some(err);
    Ok(())
}

/// One way to size a ladder rung (None when the rung leaves that parameter unset).
type RungSize = fn(&CaseSettings) -> Option<f64>;

/// Rung sizes of a ladder from the parameter its rungs refine: dt when it changes along the
/// ladder, otherwise 1/elements, 1/(stations − 1) or 1/modes. A space ladder may so pin one
/// step on every rung (the time error of a whole history does not cancel between meshes as a
/// point value's may).
pub fn ladder_rung_sizes(ladder: &[CaseSettings]) -> Result<Vec<f64>, String> {
    let pick: [RungSize; 4] = [
        |s| s.dt,
        |s| s.elements.map(|e| 1.0 / e as f64),
        |s| s.stations.map(|n| 1.0 / (n.max(2) - 1) as f64),
        |s| s.modes.map(|m| 1.0 / m as f64),
    ];
    let size = pick
        .into_iter()
        .find(|f| ladder.windows(2).any(|w| f(&w[0]) != f(&w[1])))
        .ok_or("the ladder's rungs refine no parameter (dt, elements, stations or modes)")?;
    ladder
        .iter()
        .map(|r| size(r).ok_or_else(|| "a ladder rung leaves the refined parameter unset".into()))
        .collect()
}

/// A whole history refined over a ladder (see [`super::ladder`]): the observed order of the
/// successive differences (`order`), or the case's run against the pointwise Richardson
/// extrapolation of the ladder's histories (`richardson`, norm `relative-to-peak`).
fn history_ladder(
    case: &Case,
    cache: &RunCache,
    scene: &Scene,
    channel: &str,
    lowpass_hz: Option<f64>,
    out: &mut Outcome,
) -> Result<(), String> {
    use super::ladder::{
        difference_order, extrapolated_history, max_abs_difference, successive_differences,
    };
    let run = |s: &CaseSettings| -> Result<data::RunResult, String> {
        match cache.get(scene, case.backend, &s.to_settings(), Analysis::Simulate, 0) {
            Answer::Run(Ok(r)) => Ok(r),
            Answer::Run(Err(e)) => Err(format!("{}: {e}", case.backend)),
            _ => Err("not a run".to_string()),
        }
    };
    let ladder = match &case.reference {
        Reference::Order { ladder, .. } => ladder,
        Reference::Richardson { richardson } => richardson,
        _ => return Err("a history ladder needs an `order` or `richardson` reference".into()),
    };
    let h = ladder_rung_sizes(ladder)?;
    let mut runs = Vec::with_capacity(ladder.len() + 1);
    if matches!(case.reference, Reference::Richardson { .. }) {
        runs.push(run(&case.settings)?);
    }
    for rung in ladder {
        runs.push(run(rung)?);
    }
    out.wall_time_s += runs.iter().map(|r| r.cost.wall_time_s).sum::<f64>();
    let refs: Vec<&data::RunResult> = runs.iter().collect();
    let samples = super::history::common_samples(&refs, channel, lowpass_hz)?;
    let filtered = lowpass_hz.map_or(String::new(), |f| format!(", low-passed at {f} Hz"));
    match &case.reference {
        Reference::Order { order, against, .. } => {
            if against.is_some() {
                return Err(
                    "a history ladder takes its order from its own successive differences; \
                     `against` applies to point quantities"
                        .into(),
                );
            }
            let d = successive_differences(&samples);
            let observed = difference_order(&h, &d).ok_or(
                "cannot observe an order: fewer than three rungs, sizes not decreasing, or a \
                 zero difference",
            )?;
            let listed: Vec<String> = d.iter().map(|x| format!("{x:.3e}")).collect();
            out.value = Some(observed);
            out.reference = Some(*order);
            out.reference_label = format!(
                "order {order} of the successive whole-history differences max|H_k - H_k+1| \
                 ({}) over {} rungs{filtered}",
                listed.join(", "),
                ladder.len()
            );
            out.error = Some((observed - order).abs());
            out.quantity = format!("order({})", case.quantity);
        }
        _ => {
            if case.norm != Norm::RelativeToPeak {
                return Err("a Richardson history row is measured `relative-to-peak`".into());
            }
            let (ext, p) = extrapolated_history(&h, &samples[1..])
                .ok_or("the history ladder is not in the asymptotic range (no order observed)")?;
            let peak = ext.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if peak <= 0.0 {
                return Err("the extrapolated history is identically zero".into());
            }
            let dev = max_abs_difference(&samples[0], &ext);
            out.value = Some(dev);
            out.reference = Some(peak);
            out.reference_label = format!(
                "Richardson extrapolation of the histories over {} rungs (p = {p:.2}){filtered}, \
                 error = max|Δ| / its peak",
                ladder.len()
            );
            out.error = Some(dev / peak);
        }
    }
    Ok(())
}
