//! The `data::Backend` implementation: planar chains here, the rocket in [`crate::rocket`], the
//! 3-D payload link in [`crate::payload_link`], the mobile manipulator in [`crate::mobile`].

use data::{
    Backend, BackendError, BackendKind, Discretization, DofPlan, Family, ModalResult, RunResult,
    Scene, Settings, StaticResult,
};

use crate::{mobile, modes, payload_link, rocket, setup, simulate, statics};

/// The assumed-mode backend (unit struct; all state lives in a run).
#[derive(Debug, Clone, Copy, Default)]
pub struct ModalBackend;

impl Backend for ModalBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Modal
    }

    fn dof_plan(&self, scene: &Scene, disc: &Discretization) -> Result<DofPlan, BackendError> {
        let settings = &disc.modal()?;
        match scene.family() {
            Family::Rocket => rocket::dof_plan(scene, settings),
            Family::PayloadLink => Ok(payload_link::dof_plan(scene, settings)?),
            Family::MobileManipulator => Ok(mobile::dof_plan(scene, settings)?),
            _ => Ok(setup::dof_plan(scene, settings)?),
        }
    }

    fn modes(
        &self,
        scene: &Scene,
        settings: &Settings,
        count: usize,
    ) -> Result<ModalResult, BackendError> {
        let settings = &settings.modal()?;
        match scene.family() {
            Family::Rocket => rocket::modes(scene, settings, count),
            Family::PayloadLink => Ok(payload_link::modes(scene, settings, count)?),
            Family::MobileManipulator => Ok(mobile::modes(scene, settings, count)?),
            _ => Ok(modes::modes(scene, settings, count)?),
        }
    }

    fn statics(&self, scene: &Scene, settings: &Settings) -> Result<StaticResult, BackendError> {
        let settings = &settings.modal()?;
        match scene.family() {
            Family::Rocket => Err(BackendError::unsupported("modal: statics of the rocket")),
            Family::PayloadLink => Ok(payload_link::statics(scene, settings)?),
            Family::MobileManipulator => Err(BackendError::unsupported(
                "modal: statics of the mobile manipulator (it has no [statics] loads)",
            )),
            _ => Ok(statics::statics(scene, settings)?),
        }
    }

    fn simulate(&self, scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError> {
        let settings = &settings.modal()?;
        match scene.family() {
            Family::Rocket => rocket::simulate(scene, settings),
            Family::PayloadLink => Ok(payload_link::simulate(scene, settings)?),
            Family::MobileManipulator => Ok(mobile::simulate(scene, settings)?),
            _ => Ok(simulate::simulate(scene, settings)?),
        }
    }
}
