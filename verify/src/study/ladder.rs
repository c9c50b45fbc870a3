//! Which rungs a study measures: each backend's space ladder (elements, stations or modes,
//! h the reciprocal number of intervals), a time ladder (the step halved four times from the
//! requested or output interval), or both together (the space ladder with each rung's step
//! scaled like its spacing, so that the observed order is min(p_space, p_time) and neither
//! error is left behind at a fixed value — a space ladder at a fixed step converges to that
//! step's answer, not to the scene's).

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
    /// Space and time together: each space rung with the step scaled like its spacing.
    SpaceTime,
}

impl Refine {
    /// The name the command line and the study's summary use.
    pub fn name(self) -> &'static str {
        match self {
            Refine::Space => "space",
            Refine::Time => "time",
            Refine::SpaceTime => "space-time",
        }
    }
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
                Refine::SpaceTime => space_time_ladder(kind, &base, scene),
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

/// The space ladder with each rung's step scaled like its spacing h (relative to the coarsest
/// rung's). fem steps at fixed steps: the coarsest rung at the requested step or the output
/// interval, dt ∝ h after it. fdm's default step is its stability bound, ∝ h² already, so its
/// step is left to the backend unless one was requested (then scaled ∝ h², keeping it under
/// the bound). modal's default integrators are adaptive (their time error is set by the
/// tolerance), so its step is scaled only when one was requested (a fixed-step method).
fn space_time_ladder(kind: BackendKind, base: &Settings, scene: &Scene) -> Vec<RungSpec> {
    let rungs = space_ladder(kind, base);
    let Some(h0) = rungs.first().map(|r| r.1) else {
        return rungs;
    };
    let requested = base.time.dt;
    rungs
        .into_iter()
        .map(|(mut settings, h, label)| {
            let ratio = h / h0;
            let dt = match kind {
                BackendKind::Fdm => requested.map(|dt| dt * ratio * ratio),
                BackendKind::Modal | BackendKind::Reference => requested.map(|dt| dt * ratio),
                BackendKind::Fem => {
                    Some(requested.unwrap_or(scene.simulation.output_interval) * ratio)
                }
            };
            settings.time.dt = dt;
            let label = match dt {
                Some(dt) => format!("{label} dt={dt:.3e}"),
                None => label,
            };
            (settings, h, label)
        })
        .collect()
}
