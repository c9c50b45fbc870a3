//! The stability suite (`flexverify stability`): stiff and extreme cases (verification.md §9).
//!
//! For every case and backend the verdict is one of
//! * `bounded` — reached t_end, every output finite, energy ledger closed to 1e-3 relative;
//! * `stopped` — the backend refused or stopped early with a diagnostic (what, when, why, remedy);
//! * `unsupported` — the backend says it cannot do the scene (not a failure, reported);
//! * `BLEW UP UNDETECTED` — non-finite output presented as a result, or
//!   `SILENT FAILURE` — a completed run whose energy ledger is off by more than 10 %: both are
//!   failures of ours (exit status 1).
//!
//! With `probe_bound`, explicit schemes are also run at 0.99 and 1.01 times the smallest
//! stability bound they reported: the first must complete, the second must be refused.

use std::path::Path;

use data::cases::{scene_with_overrides, stability_cases};
use data::{BackendError, BackendKind, StabilityVerdict, channel};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::Error;
use crate::output::{Column, csv_table, fitted_table, text_table, wrap, write_atomic};
use crate::registry::backend;
use crate::suite::Suite;

/// Ledger closure accepted for a `bounded` verdict: 1e-3 relative is far above any
/// integrator error at default tolerances and far below a silent blow-up.
const LEDGER_OK: f64 = 1e-3;
/// Ledger residual above which a completed run is judged to have blown up.
const LEDGER_BLOWN: f64 = 0.1;

#[derive(Debug, Clone, Serialize)]
pub struct Verdict {
    pub case: String,
    pub what: String,
    pub scene: String,
    pub backend: BackendKind,
    pub verdict: String,
    pub detail: String,
    pub failure: bool,
    pub wall_time_s: f64,
}

fn judge(case: &data::cases::StabilityCase, kind: BackendKind) -> Vec<Verdict> {
    let mk = |verdict: &str, detail: String, failure: bool, wall: f64| Verdict {
        case: case.id.clone(),
        what: case.what.clone(),
        scene: case.scene.clone(),
        backend: kind,
        verdict: verdict.into(),
        detail,
        failure,
        wall_time_s: wall,
    };
    let scene = match scene_with_overrides(&case.scene, &case.overrides) {
        Ok(s) => s,
        Err(e) => return vec![mk("invalid case", e, true, 0.0)],
    };
    // Each backend takes the fields it reads, as on the command line (a row may set fields,
    // or a method, for one of its backends).
    let settings = case.settings.to_settings().for_backend(kind);
    let b = backend(kind);
    let mut out = Vec::new();
    let result = b.simulate(&scene, &settings);
    let mut bound = None;
    match result {
        Err(BackendError::Unsupported(why)) => out.push(mk("unsupported", why, false, 0.0)),
        Err(e @ BackendError::StabilityBound { .. }) => {
            out.push(mk("stopped", e.to_string(), false, 0.0))
        }
        Err(e) => out.push(mk("stopped", e.to_string(), false, 0.0)),
        Ok(r) => {
            let wall = r.cost.wall_time_s;
            bound = r
                .observables
                .get(channel::STABILITY_BOUND)
                .map(|c| {
                    c.values
                        .iter()
                        .copied()
                        .filter(|v| v.is_finite() && *v > 0.0)
                        .fold(f64::INFINITY, f64::min)
                })
                .filter(|v| v.is_finite());
            let closure = r.ledger.relative_closure();
            if let Some(div) = &case.expect_divergence {
                let grown = r.observables.get(&div.channel).map(|c| {
                    c.values
                        .iter()
                        .filter(|v| v.is_finite())
                        .fold(0.0f64, |m, v| m.max(v.abs()))
                });
                let nonfinite = r.observables.first_non_finite();
                let v = match (grown, &r.verdict, nonfinite) {
                    (_, _, Some((c, t))) => mk(
                        "BLEW UP UNDETECTED",
                        format!(
                            "must diverge, but emitted non-finite `{c}` at t = {t:.6e} instead of stopping"
                        ),
                        true,
                        wall,
                    ),
                    (Some(g), StabilityVerdict::Stopped { diagnostic }, None) => mk(
                        "diverged (stopped)",
                        format!("|{}| reached {g:.3e}; {diagnostic}", div.channel),
                        false,
                        wall,
                    ),
                    (Some(g), StabilityVerdict::Completed, None) if g > div.threshold => mk(
                        "diverged",
                        format!(
                            "|{}| reached {g:.3e} > {:.3e}, as the physics demands",
                            div.channel, div.threshold
                        ),
                        false,
                        wall,
                    ),
                    (Some(g), _, None) => mk(
                        "WRONG: bounded",
                        format!(
                            "must diverge, but |{}| stayed at {g:.3e} ≤ {:.3e}",
                            div.channel, div.threshold
                        ),
                        true,
                        wall,
                    ),
                    (None, _, None) => mk(
                        "invalid case",
                        format!("no channel `{}`", div.channel),
                        true,
                        wall,
                    ),
                };
                out.push(v);
                return out;
            }
            match (&r.verdict, r.observables.first_non_finite()) {
                (_, Some((c, t))) => out.push(mk(
                    "BLEW UP UNDETECTED",
                    format!("non-finite `{c}` at t = {t:.6e}"),
                    true,
                    wall,
                )),
                (StabilityVerdict::Stopped { diagnostic }, None) => {
                    out.push(mk("stopped", diagnostic.to_string(), false, wall))
                }
                (StabilityVerdict::Completed, None) if closure > LEDGER_BLOWN => out.push(mk(
                    "SILENT FAILURE",
                    format!("completed, but the energy ledger is off by {closure:.2e} relative"),
                    true,
                    wall,
                )),
                (StabilityVerdict::Completed, None) => out.push(mk(
                    if closure <= LEDGER_OK {
                        "bounded"
                    } else {
                        "bounded, ledger loose"
                    },
                    format!("ledger closure {closure:.2e}, {} steps", r.cost.steps),
                    false,
                    wall,
                )),
            }
        }
    }
    if case.probe_bound && bound.is_none() {
        // Schemes that check their bound at set-up report it in the refusal of a huge step.
        let mut s = settings.clone();
        s.time.dt = Some(scene.simulation.t_end);
        if let Err(BackendError::StabilityBound { bound: b, .. }) = b.simulate(&scene, &s) {
            bound = Some(b);
        }
    }
    if case.probe_bound
        && let Some(bound) = bound
    {
        for (factor, must_run) in [(0.99, true), (1.01, false)] {
            let mut s = settings.clone();
            s.time.dt = Some(bound * factor);
            let label = format!("dt = {factor} × bound {bound:.3e}");
            match (b.simulate(&scene, &s), must_run) {
                (Ok(r), true)
                    if matches!(r.verdict, StabilityVerdict::Completed)
                        && r.observables.first_non_finite().is_none() =>
                {
                    out.push(mk(
                        "bounded",
                        format!("{label}: runs"),
                        false,
                        r.cost.wall_time_s,
                    ))
                }
                (Ok(r), true) => out.push(mk(
                    "stopped",
                    format!(
                        "{label}: should run below its bound but did not ({:?})",
                        r.verdict
                    ),
                    true,
                    r.cost.wall_time_s,
                )),
                (Err(e), true) => out.push(mk(
                    "stopped",
                    format!("{label}: refused below its bound: {e}"),
                    true,
                    0.0,
                )),
                (Err(e @ BackendError::StabilityBound { .. }), false) => {
                    out.push(mk("stopped", format!("{label}: refused: {e}"), false, 0.0))
                }
                (other, false) => out.push(mk(
                    "BLEW UP UNDETECTED",
                    format!(
                        "{label}: accepted a step above its own bound ({})",
                        match other {
                            Ok(_) => "ran".to_string(),
                            Err(e) => e.to_string(),
                        }
                    ),
                    true,
                    0.0,
                )),
            }
        }
    }
    out
}

/// Judges every case of the suite on each of its backends (in parallel; verdicts in case
/// order); with a filter, only the cases whose id or scene contains it.
pub fn run_stability(suite: Suite, filter: Option<&str>) -> Result<Vec<Verdict>, Error> {
    let cases = stability_cases()?;
    let jobs: Vec<_> = cases
        .iter()
        .filter(|c| suite.includes(c.suite))
        .filter(|c| filter.is_none_or(|f| c.id.contains(f) || c.scene.contains(f)))
        .flat_map(|c| c.backends.iter().map(move |k| (c, *k)))
        .collect();
    Ok(jobs.par_iter().flat_map(|(c, k)| judge(c, *k)).collect())
}

const HEADER: [&str; 7] = [
    "#", "case", "scene", "backend", "verdict", "wall [s]", "detail",
];

fn rows(verdicts: &[Verdict]) -> Vec<Vec<String>> {
    verdicts
        .iter()
        .enumerate()
        .map(|(i, v)| {
            vec![
                (i + 1).to_string(),
                v.case.clone(),
                v.scene.clone(),
                v.backend.to_string(),
                v.verdict.clone(),
                format!("{:.3}", v.wall_time_s),
                v.detail.clone(),
            ]
        })
        .collect()
}

/// The verdicts at full width; details (long diagnostics) listed under the table, keyed by
/// row number.
pub fn wide_table(verdicts: &[Verdict]) -> String {
    let rows = rows(verdicts);
    let short: Vec<Vec<String>> = rows.iter().map(|r| r[..6].to_vec()).collect();
    let mut s = text_table(&HEADER[..6], &short);
    for r in &rows {
        s.push_str(&format!("  [{}] {}\n", r[0], r[6]));
    }
    s
}

/// The verdicts for a terminal of `width` columns: case ids cut with `…` only if needed,
/// details wrapped.
pub fn terminal_table(verdicts: &[Verdict], width: usize) -> String {
    let rows = rows(verdicts);
    let columns = [
        Column::right("#"),
        Column::left("case").elastic(),
        Column::left("scene"),
        Column::left("backend"),
        Column::left("verdict"),
        Column::right("wall [s]"),
    ];
    let short: Vec<Vec<String>> = rows.iter().map(|r| r[..6].to_vec()).collect();
    let mut s = fitted_table(&columns, &short, width).to_string();
    for r in &rows {
        s.push_str(&wrap(&format!("  [{}] {}", r[0], r[6]), width, 6));
        s.push('\n');
    }
    s
}

/// The verdicts as CSV.
pub fn csv(verdicts: &[Verdict]) -> String {
    csv_table(&HEADER, &rows(verdicts))
}

/// The verdicts as JSON.
pub fn json(verdicts: &[Verdict]) -> String {
    serde_json::to_string_pretty(verdicts).expect("serializable verdicts")
}

/// Writes `stability.json` and `stability.csv` into `dir`.
pub fn write_all(dir: &Path, verdicts: &[Verdict]) -> std::io::Result<()> {
    write_atomic(dir, "stability.json", json(verdicts).as_bytes())?;
    write_atomic(dir, "stability.csv", csv(verdicts).as_bytes())?;
    Ok(())
}
