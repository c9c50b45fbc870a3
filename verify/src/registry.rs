//! The three backends, behind the common [`Backend`] trait.

use data::{
    Backend, BackendError, BackendKind, Discretization, DofPlan, ModalResult, RunResult, Scene,
    Settings, StaticResult,
};

/// The backend implementation of a kind.
pub fn backend(kind: BackendKind) -> Box<dyn Backend> {
    Box::new(Pending(kind))
}

/// A backend whose crate has not landed yet: it answers every request with `unsupported`.
struct Pending(BackendKind);

impl Pending {
    fn unsupported(&self) -> BackendError {
        BackendError::unsupported(format!("the `{}` backend is not implemented yet", self.0))
    }
}

impl Backend for Pending {
    fn kind(&self) -> BackendKind {
        self.0
    }
    fn dof_plan(&self, _: &Scene, _: &Discretization) -> Result<DofPlan, BackendError> {
        Err(self.unsupported())
    }
    fn modes(&self, _: &Scene, _: &Settings, _: usize) -> Result<ModalResult, BackendError> {
        Err(self.unsupported())
    }
    fn statics(&self, _: &Scene, _: &Settings) -> Result<StaticResult, BackendError> {
        Err(self.unsupported())
    }
    fn simulate(&self, _: &Scene, _: &Settings) -> Result<RunResult, BackendError> {
        Err(self.unsupported())
    }
}
