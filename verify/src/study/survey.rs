//! The full suite's ladder survey: which scenes have a ladder and the quantity each follows,
//! the studies run under a per-rung budget, and the one-line-per-ladder survey table.

use std::path::Path;

use data::{BackendKind, Scene, Settings};
use serde::{Deserialize, Serialize};

use super::ladder::Refine;
use super::measure::Timed;
use super::run::run_study;
use super::summary::Study;
use super::table::write_study;
use crate::error::Error;
use crate::output::{Column, fitted_table, text_table};
use crate::progress::Progress;

/// Per-rung wall-time budget of the full suite's ladders.
pub const FULL_RUNG_BUDGET_S: f64 = 10.0;

/// The quantity a scene's refinement ladder follows in the full suite (the payload link and
/// the mobile manipulator have none).
pub fn ladder_quantity(scene: &Scene) -> Option<String> {
    use data::scene::{Model, PrescribedMotion};
    let t = scene.simulation.t_end;
    let first = match &scene.model {
        Model::Rocket(_) => return Some(format!("{}@{t}", data::channel::ROCKET_VY)),
        Model::PlanarChain(chain) => chain.links.first()?,
        Model::PayloadLink(_) | Model::MobileManipulator(_) => return None,
    };
    Some(match first.joint.prescribed {
        Some(PrescribedMotion::Fixed) | Some(PrescribedMotion::ConstantRate { .. }) => {
            "freq1".into()
        }
        Some(PrescribedMotion::SpinUp { .. }) => format!("tip_deflection@{t}"),
        None => format!("{}@{t}", data::channel::joint_angle(1)),
    })
}

/// Id of a scene's refinement ladder in the full suite: what `verify --filter` matches, as
/// it matches case ids.
pub fn ladder_id(scene: &str) -> String {
    format!("ladder-{scene}")
}

/// One ladder of the full suite: the scene's catalog name and the quantity it follows.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LadderSpec {
    pub scene: String,
    pub quantity: String,
}

/// The full suite's ladders whose [`ladder_id`] contains `filter` (every one without a
/// filter), in catalog order; scenes without a ladder quantity have none.
pub fn select_ladders(filter: Option<&str>) -> Result<Vec<LadderSpec>, Error> {
    let mut out = Vec::new();
    for name in data::catalog_names() {
        if !filter.is_none_or(|f| ladder_id(name).contains(f)) {
            continue;
        }
        let scene = data::load_scene(name)?;
        if let Some(quantity) = ladder_quantity(&scene) {
            out.push(LadderSpec {
                scene: name.to_string(),
                quantity,
            });
        }
    }
    Ok(out)
}

/// The full suite's survey: each selected scene through every rung of each backend's space
/// ladder (a rung costing more than [`FULL_RUNG_BUDGET_S`] ends its ladder). With `out`, each
/// study is written by [`write_ladder`] as soon as it is done (so an interrupted survey keeps
/// what it finished). Returns the studies and the plot notes of [`write_study`].
pub fn run_ladders(
    selection: &[LadderSpec],
    out: Option<&Path>,
    progress: &dyn Progress,
) -> Result<(Vec<Study>, Vec<String>), Error> {
    let mut studies = Vec::new();
    let mut notes = Vec::new();
    for spec in selection {
        let scene = data::load_scene(&spec.scene)?;
        let study = run_study(
            &scene,
            &spec.quantity,
            Refine::Space,
            &BackendKind::ALL,
            &Settings::default(),
            Some(FULL_RUNG_BUDGET_S),
            Timed::Repeated,
            progress,
        )?;
        if let Some(dir) = out {
            notes.extend(write_ladder(dir, &study)?);
        }
        studies.push(study);
    }
    Ok((studies, notes))
}

/// Writes a full-suite study into `dir/ladders` (when a rung was measured).
pub fn write_ladder(dir: &Path, study: &Study) -> Result<Vec<String>, Error> {
    if study.ladders.iter().any(|l| !l.rungs.is_empty()) {
        write_study(&dir.join("ladders"), study)
    } else {
        Ok(Vec::new())
    }
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
