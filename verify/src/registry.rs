//! The three backends and verify's rigid reference, behind the common [`Backend`] trait.

use data::scene::Model;
use data::{
    Backend, BackendError, BackendKind, Discretization, DofPlan, ModalResult, RunResult, Scene,
    Settings, StaticResult,
};

use crate::analytic::rigid::mobile;

/// The backend implementation of a kind.
pub fn backend(kind: BackendKind) -> Box<dyn Backend> {
    match kind {
        BackendKind::Fem => Box::new(fem::FemBackend),
        BackendKind::Fdm => Box::new(fdm::FdmBackend),
        BackendKind::Modal => Box::new(modal::ModalBackend),
        BackendKind::Reference => Box::new(ReferenceBackend),
    }
}

/// verify's rigid reference as a backend (`--backend reference`): the families with a
/// reference run it; every other request is `unsupported`.
pub struct ReferenceBackend;

// Each entry dispatches on the scene's model family once and hands the family on.
impl Backend for ReferenceBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Reference
    }

    fn dof_plan(&self, scene: &Scene, _disc: &Discretization) -> Result<DofPlan, BackendError> {
        match &scene.model {
            Model::MobileManipulator(mm) => mobile::dof_plan(mm),
            Model::PlanarChain(_) | Model::Rocket(_) | Model::PayloadLink(_) => {
                Err(BackendError::unsupported(format!(
                    "reference: no verify reference for the {} family",
                    scene.family()
                )))
            }
        }
    }

    fn modes(&self, _: &Scene, _: &Settings, _: usize) -> Result<ModalResult, BackendError> {
        Err(BackendError::unsupported(
            "reference: natural frequencies (the rigid reference only runs)",
        ))
    }

    fn statics(&self, _: &Scene, _: &Settings) -> Result<StaticResult, BackendError> {
        Err(BackendError::unsupported(
            "reference: statics (the rigid reference only runs)",
        ))
    }

    fn simulate(&self, scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError> {
        let time = &settings.time;
        let scene = &*data::sampled_as(scene, time.output_interval, time.t_end)?;
        match &scene.model {
            Model::MobileManipulator(mm) => mobile::simulate(scene, mm, settings),
            Model::PlanarChain(_) | Model::Rocket(_) | Model::PayloadLink(_) => {
                Err(BackendError::unsupported(format!(
                    "reference: no verify reference for the {} family (only the mobile \
                     manipulator)",
                    scene.family()
                )))
            }
        }
    }
}
