//! Each backend's own settings, typed: [`FemSettings`], [`FdmSettings`], [`ModalSettings`] and
//! [`ReferenceSettings`] (verify's rigid reference) hold exactly the fields
//! [`SettingField::readers`] gives that backend, and [`FemMethod`], [`FdmMethod`] and
//! [`ModalMethod`] exactly the methods it implements.
//!
//! [`Settings`] stays the request as the user writes it (command line, case rows, the
//! `settings` object of a result); [`Settings::fem`], [`Settings::fdm`], [`Settings::modal`] and
//! [`Settings::reference`] turn it into one backend's settings and refuse a field that backend does not read or a method
//! it does not implement ([`SettingsRefusal`]). The way back ([`From`] into [`Settings`]) gives
//! the request with only that backend's fields, as the result records it.
//!
//! Values are not range-checked here: the ranges (stations ≥ 5, a positive step, ν in (0, ½))
//! are the backends' own.

use thiserror::Error;

use crate::backend::BackendError;
use crate::settings::{
    BackendKind, Basis, Discretization, FemElement, Method, SettingField, Settings, TimeStepping,
};

pub use crate::methods::{FdmMethod, FemMethod, ModalMethod};

macro_rules! method_display {
    ($($t:ty),*) => {$(
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(&Method::from(*self).name())
            }
        }
    )*};
}
method_display!(FemMethod, FdmMethod, ModalMethod);

/// The FEM backend's settings (None: the backend's default).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FemSettings {
    /// Elements per link.
    pub elements: Option<usize>,
    /// Euler–Bernoulli element (`hermite-cubic` when absent).
    pub element: Option<FemElement>,
    pub method: Option<FemMethod>,
    /// Fixed step (or first step of the adaptive step control).
    pub dt: Option<f64>,
    /// Overrides the scene's end time.
    pub t_end: Option<f64>,
    /// Overrides the scene's output interval ([`crate::sampled_as`]).
    pub output_interval: Option<f64>,
    /// Relative / absolute tolerances of the adaptive step control.
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    /// Multiplier (≤ 1) of the explicit scheme's stability bound.
    pub safety_factor: Option<f64>,
}

/// The FDM backend's settings (None: the backend's default).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FdmSettings {
    /// Stations per link, both ends included.
    pub stations: Option<usize>,
    pub method: Option<FdmMethod>,
    /// Fixed step (checked against the stability bound).
    pub dt: Option<f64>,
    /// Overrides the scene's end time.
    pub t_end: Option<f64>,
    /// Overrides the scene's output interval ([`crate::sampled_as`]).
    pub output_interval: Option<f64>,
    /// Multiplier (≤ 1) of the stability bound when the backend picks the step.
    pub safety_factor: Option<f64>,
}

/// The modal backend's settings (None: the backend's default).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModalSettings {
    /// Assumed modes per link (per field).
    pub modes: Option<usize>,
    pub basis: Option<Basis>,
    pub method: Option<ModalMethod>,
    /// Fixed step, or first step of an adaptive method.
    pub dt: Option<f64>,
    /// Overrides the scene's end time.
    pub t_end: Option<f64>,
    /// Overrides the scene's output interval ([`crate::sampled_as`]).
    pub output_interval: Option<f64>,
    /// Relative / absolute tolerances of the adaptive methods.
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
}

/// The settings of verify's rigid reference (None: its default). It has no spatial
/// discretization and always integrates with adaptive Dormand–Prince 5(4).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReferenceSettings {
    /// Overrides the scene's end time.
    pub t_end: Option<f64>,
    /// Overrides the scene's output interval ([`crate::sampled_as`]).
    pub output_interval: Option<f64>,
    /// Relative / absolute tolerances of the step control.
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
}

/// A field set for a backend that does not read it, or a method it does not implement.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{message}")]
pub struct SettingsRefusal {
    pub field: SettingField,
    pub backend: BackendKind,
    pub message: String,
}

impl From<SettingsRefusal> for BackendError {
    fn from(r: SettingsRefusal) -> BackendError {
        BackendError::InvalidSettings {
            field: r.field.path().into(),
            message: r.message,
        }
    }
}

impl SettingField {
    /// The field's path in [`Settings`]: `discretization.elements`, `time.method`, ….
    pub fn path(self) -> &'static str {
        match self {
            SettingField::Elements => "discretization.elements",
            SettingField::Element => "discretization.element",
            SettingField::Stations => "discretization.stations",
            SettingField::Modes => "discretization.modes",
            SettingField::Basis => "discretization.basis",
            SettingField::Dt => "time.dt",
            SettingField::TEnd => "time.t_end",
            SettingField::OutputInterval => "time.output_interval",
            SettingField::Method => "time.method",
            SettingField::Rtol => "time.rtol",
            SettingField::Atol => "time.atol",
            SettingField::SafetyFactor => "time.safety_factor",
        }
    }
}

impl Settings {
    /// The first set field `backend` does not read (or a method it does not implement), as a
    /// refusal naming what the backend offers.
    fn refuse_foreign(&self, backend: BackendKind) -> Result<(), SettingsRefusal> {
        let Some(field) = self
            .set_fields()
            .into_iter()
            .find(|&f| !self.read_by(f, backend))
        else {
            return Ok(());
        };
        let subject = format!("the {backend} backend");
        let message = match (field, self.time.method) {
            (SettingField::Method, Some(m)) => format!(
                "{subject} does not implement `{m}`; it offers {}",
                Method::names_for(backend)
            ),
            _ => self.refusal(field, field.key(), &subject, false),
        };
        Err(SettingsRefusal {
            field,
            backend,
            message,
        })
    }

    /// The FEM backend's settings; refused if a field it does not read is set.
    pub fn fem(&self) -> Result<FemSettings, SettingsRefusal> {
        self.refuse_foreign(BackendKind::Fem)?;
        let (d, t) = (&self.discretization, &self.time);
        Ok(FemSettings {
            elements: d.elements,
            element: d.element,
            method: t.method.and_then(Method::fem),
            dt: t.dt,
            t_end: t.t_end,
            output_interval: t.output_interval,
            rtol: t.rtol,
            atol: t.atol,
            safety_factor: t.safety_factor,
        })
    }

    /// The FDM backend's settings; refused if a field it does not read is set.
    pub fn fdm(&self) -> Result<FdmSettings, SettingsRefusal> {
        self.refuse_foreign(BackendKind::Fdm)?;
        let (d, t) = (&self.discretization, &self.time);
        Ok(FdmSettings {
            stations: d.stations,
            method: t.method.and_then(Method::fdm),
            dt: t.dt,
            t_end: t.t_end,
            output_interval: t.output_interval,
            safety_factor: t.safety_factor,
        })
    }

    /// The modal backend's settings; refused if a field it does not read is set.
    pub fn modal(&self) -> Result<ModalSettings, SettingsRefusal> {
        self.refuse_foreign(BackendKind::Modal)?;
        let (d, t) = (&self.discretization, &self.time);
        Ok(ModalSettings {
            modes: d.modes,
            basis: d.basis,
            method: t.method.and_then(Method::modal),
            dt: t.dt,
            t_end: t.t_end,
            output_interval: t.output_interval,
            rtol: t.rtol,
            atol: t.atol,
        })
    }

    /// The rigid reference's settings; refused if a field it does not read is set.
    pub fn reference(&self) -> Result<ReferenceSettings, SettingsRefusal> {
        self.refuse_foreign(BackendKind::Reference)?;
        let t = &self.time;
        Ok(ReferenceSettings {
            t_end: t.t_end,
            output_interval: t.output_interval,
            rtol: t.rtol,
            atol: t.atol,
        })
    }
}

impl Discretization {
    /// As settings without time stepping (what [`crate::Backend::dof_plan`] reads).
    fn as_settings(&self) -> Settings {
        Settings {
            discretization: self.clone(),
            time: TimeStepping::default(),
        }
    }

    /// The FEM backend's settings of this discretization ([`Settings::fem`]).
    pub fn fem(&self) -> Result<FemSettings, SettingsRefusal> {
        self.as_settings().fem()
    }

    /// The FDM backend's settings of this discretization ([`Settings::fdm`]).
    pub fn fdm(&self) -> Result<FdmSettings, SettingsRefusal> {
        self.as_settings().fdm()
    }

    /// The modal backend's settings of this discretization ([`Settings::modal`]).
    pub fn modal(&self) -> Result<ModalSettings, SettingsRefusal> {
        self.as_settings().modal()
    }
}

impl From<&FemSettings> for Settings {
    fn from(s: &FemSettings) -> Settings {
        Settings {
            discretization: Discretization {
                elements: s.elements,
                element: s.element,
                ..Discretization::default()
            },
            time: TimeStepping {
                dt: s.dt,
                t_end: s.t_end,
                output_interval: s.output_interval,
                method: s.method.map(Method::from),
                rtol: s.rtol,
                atol: s.atol,
                safety_factor: s.safety_factor,
            },
        }
    }
}

impl From<&FdmSettings> for Settings {
    fn from(s: &FdmSettings) -> Settings {
        Settings {
            discretization: Discretization {
                stations: s.stations,
                ..Discretization::default()
            },
            time: TimeStepping {
                dt: s.dt,
                t_end: s.t_end,
                output_interval: s.output_interval,
                method: s.method.map(Method::from),
                safety_factor: s.safety_factor,
                ..TimeStepping::default()
            },
        }
    }
}

impl From<&ModalSettings> for Settings {
    fn from(s: &ModalSettings) -> Settings {
        Settings {
            discretization: Discretization {
                modes: s.modes,
                basis: s.basis,
                ..Discretization::default()
            },
            time: TimeStepping {
                dt: s.dt,
                t_end: s.t_end,
                output_interval: s.output_interval,
                method: s.method.map(Method::from),
                rtol: s.rtol,
                atol: s.atol,
                ..TimeStepping::default()
            },
        }
    }
}

impl From<&ReferenceSettings> for Settings {
    fn from(s: &ReferenceSettings) -> Settings {
        Settings {
            discretization: Discretization::default(),
            time: TimeStepping {
                t_end: s.t_end,
                output_interval: s.output_interval,
                rtol: s.rtol,
                atol: s.atol,
                ..TimeStepping::default()
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn every_field() -> Settings {
        Settings {
            discretization: Discretization {
                elements: Some(4),
                stations: Some(21),
                modes: Some(3),
                basis: Some(Basis::Poly),
                element: Some(FemElement::HermiteQuintic),
            },
            time: TimeStepping {
                dt: Some(1e-3),
                t_end: Some(0.5),
                output_interval: Some(1e-3),
                method: None,
                rtol: Some(1e-6),
                atol: Some(1e-8),
                safety_factor: Some(0.5),
            },
        }
    }

    #[test]
    fn each_backend_takes_exactly_the_fields_it_reads_and_gives_them_back() {
        let all = every_field();
        for backend in [BackendKind::ALL.as_slice(), &[BackendKind::Reference]].concat() {
            let own = all.for_backend(backend);
            let back = match backend {
                BackendKind::Fem => Settings::from(&own.fem().unwrap()),
                BackendKind::Fdm => Settings::from(&own.fdm().unwrap()),
                BackendKind::Modal => Settings::from(&own.modal().unwrap()),
                BackendKind::Reference => Settings::from(&own.reference().unwrap()),
            };
            assert_eq!(back, own, "{backend}");
            for f in back.set_fields() {
                assert!(f.read_by(backend), "{backend} got {f}");
            }
            let refused = match backend {
                BackendKind::Fem => all.fem().map(drop),
                BackendKind::Fdm => all.fdm().map(drop),
                BackendKind::Modal => all.modal().map(drop),
                BackendKind::Reference => all.reference().map(drop),
            }
            .unwrap_err();
            assert_eq!(refused.backend, backend);
            assert!(!refused.field.read_by(backend), "{refused:?}");
            assert!(
                refused
                    .message
                    .contains(&format!("the {backend} backend does not read it")),
                "{}",
                refused.message
            );
        }
    }

    #[test]
    fn each_method_reaches_exactly_the_backends_that_implement_it() {
        for name in crate::settings::method_spellings() {
            let m: Method = name.parse().unwrap();
            assert!(!m.backends().is_empty(), "{name} reaches no backend");
            let s = Settings {
                time: TimeStepping {
                    method: Some(m),
                    ..TimeStepping::default()
                },
                ..Settings::default()
            };
            for backend in [BackendKind::ALL.as_slice(), &[BackendKind::Reference]].concat() {
                let typed = match backend {
                    BackendKind::Fem => s.fem().map(|t| t.method.map(Method::from)),
                    BackendKind::Fdm => s.fdm().map(|t| t.method.map(Method::from)),
                    BackendKind::Modal => s.modal().map(|t| t.method.map(Method::from)),
                    // the reference implements no method: every one is refused
                    BackendKind::Reference => s.reference().map(|_| None),
                };
                if m.implemented_by(backend) {
                    assert_eq!(typed, Ok(Some(m)), "{name} on {backend}");
                } else {
                    let e = typed.unwrap_err();
                    assert_eq!(e.field, SettingField::Method);
                    assert_eq!(
                        e.message,
                        format!(
                            "the {backend} backend does not implement `{name}`; it offers {}",
                            Method::names_for(backend)
                        )
                    );
                }
            }
        }
    }
}
