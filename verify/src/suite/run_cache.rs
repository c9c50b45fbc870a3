//! Backend answers shared between cases: each (scene, backend, settings, analysis) is computed
//! once, even when several cases (and rayon threads) ask for it.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use data::{BackendError, BackendKind, ModalResult, RunResult, Scene, Settings, StaticResult};

use super::quantity::Analysis;
use crate::registry::backend;
use crate::work::Counters;

#[derive(Debug, Clone)]
pub enum Answer {
    Modes(Result<ModalResult, BackendError>),
    Statics(Result<StaticResult, BackendError>),
    Run(Result<RunResult, BackendError>),
}

type Slot = Arc<OnceLock<Answer>>;

#[derive(Default)]
pub struct RunCache {
    slots: Mutex<HashMap<String, Slot>>,
}

impl RunCache {
    pub fn get(
        &self,
        scene: &Scene,
        kind: BackendKind,
        settings: &Settings,
        analysis: Analysis,
        modes: usize,
    ) -> Answer {
        // The whole scene is part of the key: cases with overrides share the catalog name
        // but are different problems.
        let key = format!(
            "{}|{kind}|{}|{analysis:?}|{modes}",
            serde_json::to_string(scene).expect("serializable scene"),
            serde_json::to_string(settings).expect("serializable settings")
        );
        let slot = {
            let mut map = self.slots.lock().expect("cache lock");
            map.entry(key).or_default().clone()
        };
        slot.get_or_init(|| compute(scene, kind, settings, analysis, modes))
            .clone()
    }
}

/// One backend call for an analysis, uncached (timing repeats use it directly).
pub fn compute(
    scene: &Scene,
    kind: BackendKind,
    settings: &Settings,
    analysis: Analysis,
    modes: usize,
) -> Answer {
    let b = backend(kind);
    match analysis {
        Analysis::Modes => Answer::Modes(b.modes(scene, settings, modes)),
        Analysis::Statics => Answer::Statics(b.statics(scene, settings)),
        Analysis::Simulate => Answer::Run(b.simulate(scene, settings)),
    }
}

impl Answer {
    /// Backend wall time of a successful answer.
    pub fn wall_time_s(&self) -> Option<f64> {
        match self {
            Answer::Modes(Ok(r)) => Some(r.cost.wall_time_s),
            Answer::Statics(Ok(r)) => Some(r.cost.wall_time_s),
            Answer::Run(Ok(r)) => Some(r.cost.wall_time_s),
            _ => None,
        }
    }

    /// The backend's work counters of a successful answer.
    pub fn counters(&self) -> Option<Counters> {
        match self {
            Answer::Modes(Ok(r)) => Some((&r.cost).into()),
            Answer::Statics(Ok(r)) => Some((&r.cost).into()),
            Answer::Run(Ok(r)) => Some((&r.cost).into()),
            _ => None,
        }
    }
}
