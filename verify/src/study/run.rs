//! Runs a study: each backend's ladder rung by rung, then its summary. Ladders are run
//! sequentially so that the wall times are not distorted by sharing cores. A ladder ends at the
//! first failure after a success (coarse rungs a backend rejects are skipped), or when a rung
//! costs more than the budget.

use data::{BackendKind, Scene, Settings};

use super::ladder::{Refine, rung_specs};
use super::measure::{RungMeasurement, Timed, measure_rung, parse_study_quantity};
use super::summary::{CAPPED, Rung, Study, summarize, summarize_ladder};
use crate::error::Error;
use crate::progress::Progress;
use crate::suite::run_cache::RunCache;

/// Runs the ladders and fills errors against the best available reference, reporting each
/// rung to `progress`; each rung timed as `timed` says.
#[allow(clippy::too_many_arguments)]
pub fn run_study(
    scene: &Scene,
    quantity: &str,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    rung_budget_s: Option<f64>,
    timed: Timed,
    progress: &dyn Progress,
) -> Result<Study, Error> {
    let q = parse_study_quantity(scene, quantity, base)?;
    let cache = RunCache::default();
    let measured = |kind: BackendKind, _rung: usize, settings: &Settings| {
        measure_rung(&cache, scene, kind, settings, &q, timed)
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
    let q = parse_study_quantity(scene, quantity, base)?;
    let mut ladders = Vec::new();
    let specs = rung_specs(scene, refine, kinds, base);
    progress.begin(specs.iter().map(|(_, s)| s.len()).sum(), "rungs");
    for (kind, rungs_spec) in specs {
        let mut rungs: Vec<Rung> = Vec::new();
        let mut note = None;
        let mut skipped = None;
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
                        skipped = Some(e);
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
                "{CAPPED} after {}: that rung took {:.1} s, above the {budget} s budget per rung",
                last.discretization, last.wall_time_s
            ));
        }
        if rungs.is_empty() && note.is_none() {
            // no rung measured: the last rejection says why
            note = skipped;
        }
        ladders.push(summarize_ladder(kind, rungs, note));
    }
    let study = summarize(scene, &q, quantity, refine, ladders);
    progress.finish();
    Ok(study)
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
    let q = parse_study_quantity(scene, quantity, base)?;
    let cache = RunCache::default();
    let measured = |kind: BackendKind, _rung: usize, settings: &Settings| {
        measure_rung(&cache, scene, kind, settings, &q, Timed::Repeated)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::Silent;

    #[test]
    fn sys_a_ladder_whose_every_rung_fails_says_why() {
        // Coarse rungs may be rejected and skipped; when no rung measures the quantity, the
        // last rejection is the ladder's note, so the refusal is not empty.
        let scene = data::load_scene("cantilever").unwrap();
        let why = "fdm: the run stopped at t = 1e-3: diverged";
        let failing =
            |_: BackendKind, _: usize, _: &Settings| -> RungMeasurement { Err(why.to_string()) };
        let err = converge_from_rungs(
            &scene,
            "tip_deflection@0.01",
            Refine::Space,
            &[BackendKind::Fdm],
            &Settings::default(),
            &Silent,
            &failing,
        )
        .unwrap_err();
        assert!(
            matches!(&err, Error::QuantityNotProduced { notes, .. } if notes == &[why]),
            "{err}"
        );
    }
}
