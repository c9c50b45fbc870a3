//! The three backends and verify's rigid reference, behind the common [`Backend`] trait.

use data::{
    Backend, BackendError, BackendKind, Discretization, DofPlan, ModalResult, RunResult, Scene,
    Settings, StaticResult,
};

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

impl Backend for ReferenceBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Reference
    }

    fn dof_plan(&self, scene: &Scene, _disc: &Discretization) -> Result<DofPlan, BackendError> {
        crate::analytic::rigid::mobile::dof_plan(scene)
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
        crate::analytic::rigid::mobile::simulate(scene, settings)
    }
}
