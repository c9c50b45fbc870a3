//! The three backends, behind the common [`Backend`] trait.

use data::{Backend, BackendKind};

/// The backend implementation of a kind.
pub fn backend(kind: BackendKind) -> Box<dyn Backend> {
    match kind {
        BackendKind::Fem => Box::new(fem::FemBackend),
        BackendKind::Fdm => Box::new(fdm::FdmBackend),
        BackendKind::Modal => Box::new(modal::ModalBackend),
    }
}
