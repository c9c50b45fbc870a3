//! One rung's measurement: the quantity's value and the rung's cost, measured two ways: the
//! wall time, with the suite's rule ([`crate::work::time_rung`]) as the minimum of repeats
//! (at least 5 and 0.2 s; a rung whose first run took more than 3 s is timed once, and its
//! `repeats` says so) with median, maximum and spread, or from its one run where only a choice
//! among few rungs needs the repeats ([`Timed`]); and the backend's work counters (DOFs,
//! steps, RHS evaluations, factorizations, Newton iterations), exact and machine independent.

use data::{BackendKind, Scene, Settings};
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::suite::evaluate::measure;
use crate::suite::quantity::Quantity;
use crate::suite::run_cache::{RunCache, compute};
use crate::work::{Counters, FirstRun, Timing, time_rung};

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

/// How a study times its rungs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Timed {
    /// Every rung with repeats ([`crate::work::time_rung`]): the work–precision tables of
    /// `converge` and the full suite.
    Repeated,
    /// Every rung by its one run (`repeats` = 1): `recommend`, whose choice depends only on
    /// the timings of the rungs it picks, re-timed with [`retime`] (the rung budget decides on
    /// one run either way).
    Once,
}

/// Measures one rung (the quantity must parse: see [`parse_quantity`]).
pub fn measure_rung(
    cache: &RunCache,
    scene: &Scene,
    kind: BackendKind,
    settings: &Settings,
    q: &Quantity,
    timed: Timed,
) -> RungMeasurement {
    let (value, peak, first) = measure(cache, scene, kind, settings, q)?;
    let counters = cache
        .get(scene, kind, settings, q.analysis(), q.modes_needed())
        .counters()
        .ok_or_else(|| format!("{kind}: no cost counters"))?;
    let timing = match timed {
        Timed::Repeated => retime(scene, kind, settings, q, first)
            .ok_or_else(|| format!("{kind}: a timing repeat of the run failed"))?,
        Timed::Once => Timing::once(first),
    };
    Ok(Measured {
        value,
        peak,
        timing,
        counters,
    })
}

/// The repeated timing of a rung whose first run took `first` seconds
/// ([`crate::work::time_rung`]); `None` when a repeat fails. The ladder runs alone, so its
/// first run is a repeat like the others.
pub fn retime(
    scene: &Scene,
    kind: BackendKind,
    settings: &Settings,
    q: &Quantity,
    first: f64,
) -> Option<Timing> {
    let repeat = || compute(scene, kind, settings, q.analysis(), q.modes_needed()).wall_time_s();
    time_rung(first, FirstRun::Alone, repeat)
}

/// The quantity of a study, parsed against its scene.
pub fn parse_quantity(scene: &Scene, quantity: &str) -> Result<Quantity, Error> {
    Quantity::parse(quantity, scene).map_err(|reason| Error::InvalidQuantity {
        quantity: quantity.to_string(),
        reason: reason.to_string(),
    })
}

/// The quantity of a study whose runs take the settings `base`: [`parse_quantity`], and a
/// value at a time must lie within the runs (`base`'s t_end, else the scene's). Refused here,
/// before any rung runs, every rung would fail alike.
pub fn parse_study_quantity(
    scene: &Scene,
    quantity: &str,
    base: &Settings,
) -> Result<Quantity, Error> {
    let q = parse_quantity(scene, quantity)?;
    let t_end = base.time.t_end.unwrap_or(scene.simulation.t_end);
    if let Quantity::At { t, .. } = &q
        && *t > t_end * (1.0 + 1e-12)
    {
        let source = if base.time.t_end.is_some() {
            "--t-end"
        } else {
            "the scene's t_end"
        };
        return Err(Error::InvalidQuantity {
            quantity: quantity.to_string(),
            reason: format!(
                "t = {t} lies after the runs' end, {t_end} s ({source}); ask for a time within \
                 the runs or pass --t-end {t}"
            ),
        });
    }
    Ok(q)
}
