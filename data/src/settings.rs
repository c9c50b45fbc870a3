//! How finely a backend solves a scene: the backend's name, the discretization (elements,
//! stations, modes, basis) and the time stepping (method, step, tolerances). Parsed once from
//! the command line or a case row. [`SettingField::readers`] says which backend reads each
//! field and [`Method::backends`] which backend implements each method; the boundaries (command
//! line, case rows) refuse a field or method that no backend it is meant for reads,
//! [`Settings::for_backend`] keeps one backend's fields of a request meant for several, and
//! [`Settings::fem`] / [`Settings::fdm`] / [`Settings::modal`] / [`Settings::reference`] turn
//! them into that backend's typed settings ([`crate::backend_settings`]).

use serde::{Deserialize, Serialize};

pub use crate::methods::Method;
use crate::methods::SPELLINGS;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BackendKind {
    Fem,
    Fdm,
    Modal,
    /// verify's rigid reference, for families that have one (the mobile manipulator); not a
    /// discretization, so not in [`BackendKind::ALL`].
    Reference,
}

impl BackendKind {
    /// The three discretizations.
    pub const ALL: [BackendKind; 3] = [BackendKind::Fem, BackendKind::Fdm, BackendKind::Modal];

    pub fn name(self) -> &'static str {
        match self {
            BackendKind::Fem => "fem",
            BackendKind::Fdm => "fdm",
            BackendKind::Modal => "modal",
            BackendKind::Reference => "reference",
        }
    }
}

impl std::fmt::Display for BackendKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Assumed-mode basis of the modal backend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Basis {
    /// x², x³, x⁴, … (seed 000 eq. 49).
    Poly,
    /// Clamped-free cantilever eigenfunctions.
    ClampedFree,
    /// Eigenfunctions of the cantilever with the scene's tip mass/inertia.
    TipMass,
    /// Free-free beam eigenfunctions (rocket).
    FreeFree,
}

impl Basis {
    /// Every basis, in the order messages and the command line list them.
    pub const ALL: [Basis; 4] = [
        Basis::Poly,
        Basis::ClampedFree,
        Basis::TipMass,
        Basis::FreeFree,
    ];
    /// Accepted spellings ([`Basis::name`] of each of [`Basis::ALL`]).
    pub const NAMES: [&'static str; 4] = [
        Self::ALL[0].name(),
        Self::ALL[1].name(),
        Self::ALL[2].name(),
        Self::ALL[3].name(),
    ];

    pub const fn name(self) -> &'static str {
        match self {
            Basis::Poly => "poly",
            Basis::ClampedFree => "clamped-free",
            Basis::TipMass => "tip-mass",
            Basis::FreeFree => "free-free",
        }
    }
}

impl std::str::FromStr for Basis {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let name = text.trim();
        Basis::ALL
            .into_iter()
            .find(|b| b.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown modal basis `{name}`; accepted: {}",
                    Basis::NAMES.join(", ")
                )
            })
    }
}

/// How finely space is discretized. Each field belongs to one backend
/// ([`SettingField::readers`]), which uses its documented default when the field is absent.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Discretization {
    /// FEM: elements per link.
    pub elements: Option<usize>,
    /// FDM: stations per link (including both ends).
    pub stations: Option<usize>,
    /// Modal: assumed modes per link (per field).
    pub modes: Option<usize>,
    pub basis: Option<Basis>,
    /// FEM: Euler–Bernoulli element (`hermite-cubic` when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<FemElement>,
}

/// The FEM elements a setting can name, declared once: each row `Variant => "spelling",` (with
/// its doc) gives a [`FemElement`] variant, its spelling (serde, [`FemElement::name`],
/// [`FemElement::NAMES`]) and its place in [`FemElement::ALL`]; the first row is the default. A
/// new element is one row here (plus its file and registry line in fem).
macro_rules! fem_element_table {
    (
        $(#[$default_doc:meta])* $default:ident => $default_name:literal,
        $($(#[$doc:meta])* $variant:ident => $name:literal,)*
    ) => {
        /// Euler–Bernoulli beam element of the FEM backend. All keep the nodal DOFs (v, v′), so
        /// tip bodies, loads and supports attach the same way.
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
        pub enum FemElement {
            $(#[$default_doc])*
            #[default]
            #[serde(rename = $default_name)]
            $default,
            $($(#[$doc])* #[serde(rename = $name)] $variant,)*
        }

        impl FemElement {
            /// Every element, in the order messages and the command line list them.
            pub const ALL: &'static [FemElement] = &[FemElement::$default, $(FemElement::$variant,)*];
            /// Accepted spellings ([`FemElement::name`] of each of [`FemElement::ALL`]).
            pub const NAMES: &'static [&'static str] = &[$default_name, $($name,)*];

            pub const fn name(self) -> &'static str {
                match self {
                    FemElement::$default => $default_name,
                    $(FemElement::$variant => $name,)*
                }
            }
        }
    };
}

fem_element_table! {
    /// Hermite cubic: frequency error O(h⁴).
    HermiteCubic => "hermite-cubic",
    /// Hermite cubic plus two interior C¹ bubbles (complete quintic): frequency error O(h⁸).
    HermiteQuintic => "hermite-quintic",
}

impl std::str::FromStr for FemElement {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let name = text.trim();
        FemElement::ALL
            .iter()
            .copied()
            .find(|e| e.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown FEM element `{name}`; accepted: {}",
                    FemElement::NAMES.join(", ")
                )
            })
    }
}

impl Method {
    /// Every accepted spelling, for error messages and CLI help.
    pub fn names() -> String {
        BackendKind::ALL
            .iter()
            .map(|&b| format!("{} ({b})", Method::names_for(b)))
            .collect::<Vec<_>>()
            .join("; ")
    }

    /// The canonical spelling (`robert-asselin=ν` with its coefficient when one is given).
    pub fn name(self) -> String {
        if let Method::RobertAsselin { nu: Some(nu) } = self {
            return format!("robert-asselin={nu}");
        }
        let kind = std::mem::discriminant(&self);
        SPELLINGS
            .iter()
            .find(|(m, _, _)| std::mem::discriminant(m) == kind)
            .map_or_else(String::new, |(_, name, _)| (*name).to_string())
    }
}

impl Method {
    /// Whether `backend` implements this method (a family may still refuse it, e.g. a method
    /// without event location for a contact scene): derived from the typed method lists
    /// ([`Method::fem`], [`Method::fdm`], [`Method::modal`]).
    pub fn implemented_by(self, backend: BackendKind) -> bool {
        match backend {
            BackendKind::Fem => self.fem().is_some(),
            BackendKind::Fdm => self.fdm().is_some(),
            BackendKind::Modal => self.modal().is_some(),
            BackendKind::Reference => false,
        }
    }

    /// The backends that implement this method ([`Method::implemented_by`]).
    pub fn backends(self) -> Vec<BackendKind> {
        BackendKind::ALL
            .into_iter()
            .filter(|&b| self.implemented_by(b))
            .collect()
    }

    /// The spellings `backend` implements, for error messages.
    pub fn names_for(backend: BackendKind) -> String {
        if backend == BackendKind::Reference {
            return "none (always adaptive Dormand–Prince 5(4))".into();
        }
        SPELLINGS
            .iter()
            .filter(|(m, _, _)| m.implemented_by(backend))
            .map(|(m, name, aliases)| {
                let mut text = (*name).to_string();
                if matches!(m, Method::RobertAsselin { .. }) {
                    text += "[=nu]";
                }
                if !aliases.is_empty() {
                    text += &format!(" (also {})", aliases.join(", "));
                }
                text
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

/// One spelling of every method (and of fdm's filter with its coefficient), for tests that
/// walk all of them.
#[cfg(test)]
pub(crate) fn method_spellings() -> Vec<String> {
    SPELLINGS
        .iter()
        .map(|(_, name, _)| (*name).to_string())
        .chain(["robert-asselin=0.05".to_string()])
        .collect()
}

impl std::str::FromStr for Method {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let name = text.trim();
        if let Some((method, _, _)) = SPELLINGS
            .iter()
            .find(|(_, spelling, aliases)| *spelling == name || aliases.contains(&name))
        {
            return Ok(*method);
        }
        if let Some(value) = name.strip_prefix("robert-asselin=") {
            let nu = value
                .trim()
                .parse::<f64>()
                .map_err(|_| format!("cannot read the Robert–Asselin ν in `{name}`"))?;
            return Ok(Method::RobertAsselin { nu: Some(nu) });
        }
        Err(format!(
            "unknown time-integration method `{name}`; accepted: {}",
            Method::names()
        ))
    }
}

impl TryFrom<String> for Method {
    type Error = String;

    fn try_from(text: String) -> Result<Self, String> {
        text.parse()
    }
}

impl From<Method> for String {
    fn from(m: Method) -> String {
        m.name()
    }
}

/// How time is integrated.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TimeStepping {
    /// Fixed step (or initial step of an adaptive method).
    pub dt: Option<f64>,
    /// Overrides the scene's end time.
    pub t_end: Option<f64>,
    /// Overrides the scene's output interval (the spacing of the stored samples); a run's
    /// samples are then its histories, so a low-passed history is only as good as this
    /// spacing resolves the signal (`verify::suite::filter`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_interval: Option<f64>,
    /// Integration method (None: the backend's default for the scene). Each backend implements
    /// some of the [`Method`]s ([`Method::backends`]).
    pub method: Option<Method>,
    /// Relative / absolute error tolerances of adaptive methods.
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    /// Multiplier (≤ 1) applied to a stability bound when the backend picks the step itself.
    pub safety_factor: Option<f64>,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub discretization: Discretization,
    pub time: TimeStepping,
}

/// One user-settable field of [`Settings`], with the backends that read it. The table is the
/// contract the boundaries enforce: a field set for a backend that does not read it is refused
/// (command line: [`Settings::unread_by`]; case rows: `cases::parse_cases`) instead of being
/// silently ignored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SettingField {
    Elements,
    Element,
    Stations,
    Modes,
    Basis,
    Dt,
    TEnd,
    OutputInterval,
    Method,
    Rtol,
    Atol,
    SafetyFactor,
}

impl SettingField {
    pub const ALL: [SettingField; 12] = [
        SettingField::Elements,
        SettingField::Element,
        SettingField::Stations,
        SettingField::Modes,
        SettingField::Basis,
        SettingField::Dt,
        SettingField::TEnd,
        SettingField::OutputInterval,
        SettingField::Method,
        SettingField::Rtol,
        SettingField::Atol,
        SettingField::SafetyFactor,
    ];

    /// The key as a case row's `settings = { … }` spells it.
    pub fn key(self) -> &'static str {
        match self {
            SettingField::Elements => "elements",
            SettingField::Element => "element",
            SettingField::Stations => "stations",
            SettingField::Modes => "modes",
            SettingField::Basis => "basis",
            SettingField::Dt => "dt",
            SettingField::TEnd => "t_end",
            SettingField::OutputInterval => "output_interval",
            SettingField::Method => "method",
            SettingField::Rtol => "rtol",
            SettingField::Atol => "atol",
            SettingField::SafetyFactor => "safety_factor",
        }
    }

    /// The command-line flag.
    pub fn flag(self) -> &'static str {
        match self {
            SettingField::Elements => "--elements",
            SettingField::Element => "--element",
            SettingField::Stations => "--stations",
            SettingField::Modes => "--modes",
            SettingField::Basis => "--basis",
            SettingField::Dt => "--dt",
            SettingField::TEnd => "--t-end",
            SettingField::OutputInterval => "--output-interval",
            SettingField::Method => "--method",
            SettingField::Rtol => "--rtol",
            SettingField::Atol => "--atol",
            SettingField::SafetyFactor => "--safety-factor",
        }
    }

    /// The backends that read this field. fem: elements, element, its fixed and adaptive steps
    /// (dt, rtol, atol) and the explicit scheme's safety factor; fdm: stations, dt and the
    /// safety factor of its stability-bound step; modal: modes, basis, dt and the adaptive
    /// tolerances; verify's rigid reference: only the end time and its Dormand–Prince
    /// tolerances. Every backend reads the end time and the output interval.
    pub fn readers(self) -> &'static [BackendKind] {
        use BackendKind::{Fdm, Fem, Modal, Reference};
        match self {
            SettingField::Elements | SettingField::Element => &[Fem],
            SettingField::Stations => &[Fdm],
            SettingField::Modes | SettingField::Basis => &[Modal],
            SettingField::Dt | SettingField::Method => &[Fem, Fdm, Modal],
            SettingField::TEnd | SettingField::OutputInterval => &[Fem, Fdm, Modal, Reference],
            SettingField::Rtol | SettingField::Atol => &[Fem, Modal, Reference],
            SettingField::SafetyFactor => &[Fem, Fdm],
        }
    }

    /// Whether `backend` reads this field.
    pub fn read_by(self, backend: BackendKind) -> bool {
        self.readers().contains(&backend)
    }

    /// The readers as prose: "fem", "fem and fdm", "fem, modal and reference".
    pub fn readers_text(self) -> String {
        backends_text(self.readers())
    }

    fn is_set(self, s: &Settings) -> bool {
        let (d, t) = (&s.discretization, &s.time);
        match self {
            SettingField::Elements => d.elements.is_some(),
            SettingField::Element => d.element.is_some(),
            SettingField::Stations => d.stations.is_some(),
            SettingField::Modes => d.modes.is_some(),
            SettingField::Basis => d.basis.is_some(),
            SettingField::Dt => t.dt.is_some(),
            SettingField::TEnd => t.t_end.is_some(),
            SettingField::OutputInterval => t.output_interval.is_some(),
            SettingField::Method => t.method.is_some(),
            SettingField::Rtol => t.rtol.is_some(),
            SettingField::Atol => t.atol.is_some(),
            SettingField::SafetyFactor => t.safety_factor.is_some(),
        }
    }

    fn clear(self, s: &mut Settings) {
        let (d, t) = (&mut s.discretization, &mut s.time);
        match self {
            SettingField::Elements => d.elements = None,
            SettingField::Element => d.element = None,
            SettingField::Stations => d.stations = None,
            SettingField::Modes => d.modes = None,
            SettingField::Basis => d.basis = None,
            SettingField::Dt => t.dt = None,
            SettingField::TEnd => t.t_end = None,
            SettingField::OutputInterval => t.output_interval = None,
            SettingField::Method => t.method = None,
            SettingField::Rtol => t.rtol = None,
            SettingField::Atol => t.atol = None,
            SettingField::SafetyFactor => t.safety_factor = None,
        }
    }
}

impl std::fmt::Display for SettingField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.key())
    }
}

/// Backend names as prose: "fem", "fem and fdm", "fem, modal and reference".
pub fn backends_text(backends: &[BackendKind]) -> String {
    let names: Vec<&str> = backends.iter().map(|k| k.name()).collect();
    match names.split_last() {
        Some((last, [])) => (*last).to_string(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
        None => String::new(),
    }
}

impl Settings {
    /// The command-line options that reproduce these settings, each field as set (`--elements
    /// 4`, `--dt 0.0005`; unset fields, the backends' defaults, are left out): the
    /// discretization first, then the time stepping and the output interval, the end time last.
    pub fn command_line(&self) -> Vec<String> {
        use SettingField as F;
        let (d, t) = (&self.discretization, &self.time);
        [
            (F::Elements, d.elements.map(|n| n.to_string())),
            (F::Element, d.element.map(|e| e.name().to_string())),
            (F::Stations, d.stations.map(|n| n.to_string())),
            (F::Modes, d.modes.map(|n| n.to_string())),
            (F::Basis, d.basis.map(|b| b.name().to_string())),
            (F::Method, t.method.map(|m| m.name().to_string())),
            (F::Dt, t.dt.map(|v| v.to_string())),
            (F::Rtol, t.rtol.map(|v| v.to_string())),
            (F::Atol, t.atol.map(|v| v.to_string())),
            (F::SafetyFactor, t.safety_factor.map(|v| v.to_string())),
            (F::OutputInterval, t.output_interval.map(|v| v.to_string())),
            (F::TEnd, t.t_end.map(|v| v.to_string())),
        ]
        .into_iter()
        .filter_map(|(field, value)| value.map(|v| format!("{} {v}", field.flag())))
        .collect()
    }

    /// Whether `backend` reads `field` as set here: the field is one the backend reads and,
    /// for the method, one the backend implements ([`Method::backends`]).
    pub fn read_by(&self, field: SettingField, backend: BackendKind) -> bool {
        field.read_by(backend)
            && match (field, self.time.method) {
                (SettingField::Method, Some(m)) => m.implemented_by(backend),
                _ => true,
            }
    }

    /// Why none of `backends` reads `field` as set here, for a refusal at a boundary: "`--basis`
    /// applies to modal; the requested backend fem does not read it" (`subject` is how the
    /// boundary names the backends: "the requested backend fem", "the row's backend fem").
    pub fn refusal(&self, field: SettingField, flag: &str, subject: &str, plural: bool) -> String {
        let verb = if plural { "do" } else { "does" };
        match (field, self.time.method) {
            (SettingField::Method, Some(m)) => format!(
                "`{flag} {m}` applies to {}; {subject} {verb} not implement it",
                backends_text(&m.backends())
            ),
            _ => format!(
                "`{flag}` applies to {}; {subject} {verb} not read it",
                field.readers_text()
            ),
        }
    }

    /// The fields that are set, in [`SettingField::ALL`] order.
    pub fn set_fields(&self) -> Vec<SettingField> {
        SettingField::ALL
            .into_iter()
            .filter(|f| f.is_set(self))
            .collect()
    }

    /// The set fields that none of `backends` reads.
    pub fn unread_by(&self, backends: &[BackendKind]) -> Vec<SettingField> {
        self.set_fields()
            .into_iter()
            .filter(|&f| !backends.iter().any(|&b| self.read_by(f, b)))
            .collect()
    }

    /// The settings `backend` reads: every field it does not read (and a method it does not
    /// implement) cleared, so that one set of options given for several backends reaches each
    /// only with its own fields.
    pub fn for_backend(&self, backend: BackendKind) -> Settings {
        let mut s = self.clone();
        for f in SettingField::ALL {
            if !self.read_by(f, backend) {
                f.clear(&mut s);
            }
        }
        s
    }

    /// The field that sets `backend`'s spatial resolution (fem: elements per link, fdm:
    /// stations per link, modal: modes per link and field); None for verify's rigid reference.
    pub fn resolution_field(backend: BackendKind) -> Option<SettingField> {
        match backend {
            BackendKind::Fem => Some(SettingField::Elements),
            BackendKind::Fdm => Some(SettingField::Stations),
            BackendKind::Modal => Some(SettingField::Modes),
            BackendKind::Reference => None,
        }
    }

    /// `backend`'s spatial resolution, when set.
    pub fn resolution(&self, backend: BackendKind) -> Option<usize> {
        let d = &self.discretization;
        match backend {
            BackendKind::Fem => d.elements,
            BackendKind::Fdm => d.stations,
            BackendKind::Modal => d.modes,
            BackendKind::Reference => None,
        }
    }

    /// These settings with `backend`'s spatial resolution set to `n` (unchanged for verify's
    /// rigid reference, which has none).
    pub fn with_resolution(&self, backend: BackendKind, n: usize) -> Settings {
        let mut s = self.clone();
        let d = &mut s.discretization;
        match backend {
            BackendKind::Fem => d.elements = Some(n),
            BackendKind::Fdm => d.stations = Some(n),
            BackendKind::Modal => d.modes = Some(n),
            BackendKind::Reference => {}
        }
        s
    }
}

#[cfg(test)]
mod spelling_tests {
    use super::*;

    #[test]
    fn elem_every_method_has_one_spelling_that_reads_back() {
        for (m, _, _) in SPELLINGS {
            let rows = SPELLINGS
                .iter()
                .filter(|(s, _, _)| std::mem::discriminant(s) == std::mem::discriminant(m))
                .count();
            assert_eq!(rows, 1, "{m:?}");
            let name = m.name();
            assert_eq!(name.parse::<Method>(), Ok(*m), "{name}");
            assert!(
                !m.backends().is_empty(),
                "{m:?} is implemented by no backend"
            );
        }
        assert_eq!("sdirk".parse::<Method>(), Ok(Method::TrBdf2));
        assert_eq!(
            "robert-asselin=0.05".parse::<Method>(),
            Ok(Method::RobertAsselin { nu: Some(0.05) })
        );
    }
}
