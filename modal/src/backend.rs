//! The `data::Backend` implementation: planar chains here, the rocket in [`crate::rocket`], the
//! 3-D payload link in [`crate::payload_link`], the mobile manipulator in [`crate::mobile`].

use data::scene::Model;
use data::{
    Backend, BackendError, BackendKind, Discretization, DofPlan, ModalResult, RunResult, Scene,
    Settings, StaticResult,
};

use crate::{mobile, modes, payload_link, rocket, setup, simulate, statics};

/// The assumed-mode backend (unit struct; all state lives in a run).
#[derive(Debug, Clone, Copy, Default)]
pub struct ModalBackend;

// Each entry dispatches on the scene's model family once and hands the family on.
impl Backend for ModalBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Modal
    }

    fn dof_plan(&self, scene: &Scene, disc: &Discretization) -> Result<DofPlan, BackendError> {
        let settings = &disc.modal()?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(setup::dof_plan(pc, settings)?),
            Model::Rocket(r) => rocket::dof_plan(r, settings),
            Model::PayloadLink(link) => Ok(payload_link::dof_plan(link, settings)?),
            Model::MobileManipulator(mm) => Ok(mobile::dof_plan(mm, settings)?),
        }
    }

    fn modes(
        &self,
        scene: &Scene,
        settings: &Settings,
        count: usize,
    ) -> Result<ModalResult, BackendError> {
        let settings = &settings.modal()?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(modes::modes(scene, pc, settings, count)?),
            Model::Rocket(r) => rocket::modes(scene, r, settings, count),
            Model::PayloadLink(link) => Ok(payload_link::modes(scene, link, settings, count)?),
            Model::MobileManipulator(mm) => Ok(mobile::modes(scene, mm, settings, count)?),
        }
    }

    fn statics(&self, scene: &Scene, settings: &Settings) -> Result<StaticResult, BackendError> {
        let settings = &settings.modal()?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(statics::statics(scene, pc, settings)?),
            Model::Rocket(_) => Err(BackendError::unsupported("modal: statics of the rocket")),
            Model::PayloadLink(link) => Ok(payload_link::statics(scene, link, settings)?),
            Model::MobileManipulator(_) => Err(BackendError::unsupported(
                "modal: statics of the mobile manipulator (it has no [statics] loads)",
            )),
        }
    }

    fn simulate(&self, scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError> {
        let settings = &settings.modal()?;
        let scene = &*data::sampled_as(scene, settings.output_interval, settings.t_end)?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(simulate::simulate(scene, pc, settings)?),
            Model::Rocket(r) => rocket::simulate(scene, r, settings),
            Model::PayloadLink(link) => Ok(payload_link::simulate(scene, link, settings)?),
            Model::MobileManipulator(mm) => Ok(mobile::simulate(scene, mm, settings)?),
        }
    }
}
