//! Which rungs a study measures: each backend's space ladder (elements, stations or modes,
//! h the reciprocal number of intervals) or a time ladder (the step halved four times from the
//! requested or output interval).

use data::{BackendKind, Scene, Settings};
use serde::{Deserialize, Serialize};

/// What a study refines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Refine {
    /// Elements, stations or modes (the backend's space discretization).
    Space,
    /// The time step.
    Time,
}

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

/// Default refinement ladder of a backend (space) as settings + h: the backend's resolution
/// ([`Settings::with_resolution`]) over its rungs, h the reciprocal number of intervals.
fn space_ladder(kind: BackendKind, base: &Settings) -> Vec<RungSpec> {
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

/// The time ladder: the requested step (or the output interval) halved four times.
fn time_ladder(base: &Settings, scene: &Scene) -> Vec<RungSpec> {
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
