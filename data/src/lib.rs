//! # data — what a problem is and what an answer looks like
//!
//! Shared by the three independent solver crates (`fem`, `fdm`, `modal`) and by `verify`:
//! * [`scene`] — the typed scene model (planar link chains, the variable-mass rocket, the 3-D
//!   payload link, the mobile manipulator);
//! * [`reader`] / [`validate`] — TOML → validated scene, errors with file, line, column, field;
//! * [`catalog`] — the embedded catalog of `data/scenes/*.toml`;
//! * [`results`] — observables, energy ledger, events, cost counters, stability verdict;
//! * [`channel`] — the registry of observable channel names and units;
//! * [`backend`] — the [`Backend`] trait every solver implements;
//! * [`backend_settings`] — each backend's own typed settings and methods.
//!
//! No physics lives here: agreement between backends must mean something.

pub mod backend;
pub mod backend_settings;
pub mod cases;
pub mod catalog;
pub mod channel;
pub mod coverage;
pub mod error;
pub mod locate;
mod methods;
pub mod reader;
pub mod results;
pub mod scene;
pub mod settings;
pub mod validate;

pub use backend::{Backend, BackendError, DofGroup, DofPlan, sampled_as};
pub use backend_settings::{
    FdmMethod, FdmSettings, FemMethod, FemSettings, ModalMethod, ModalSettings, ReferenceSettings,
    SettingsRefusal,
};
pub use catalog::{CATALOG, catalog_names, catalog_scene, load_scene};
pub use error::{LoadError, SceneError};
pub use reader::parse_scene;
pub use results::{
    Channel, Cost, Diagnostic, EnergyLedger, EnergyTerm, Event, ModalResult, ModeShape,
    Observables, RunResult, StabilityVerdict, StaticResult, ledger_term,
};
pub use scene::{Family, Model, PlanarChain, Scene, SceneFile};
pub use settings::{
    BackendKind, Basis, Discretization, FemElement, Method, SettingField, Settings, TimeStepping,
};
