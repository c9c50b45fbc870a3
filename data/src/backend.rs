//! The contract every solver crate implements.
//!
//! A [`Scene`] says *what*; [`Settings`] say *how finely*; a [`Backend`] turns the two into
//! results. Backends never see each other.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::results::{ModalResult, RunResult, StaticResult};
use crate::scene::Scene;

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
    pub fn name(self) -> &'static str {
        match self {
            Basis::Poly => "poly",
            Basis::ClampedFree => "clamped-free",
            Basis::TipMass => "tip-mass",
            Basis::FreeFree => "free-free",
        }
    }
}

/// How finely space is discretized. Each backend reads the field it understands and uses its
/// documented default when the field is absent.
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

/// Euler–Bernoulli beam element of the FEM backend. Both keep the nodal DOFs (v, v′), so tip
/// bodies, loads and supports attach the same way.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FemElement {
    /// Hermite cubic: frequency error O(h⁴).
    #[default]
    HermiteCubic,
    /// Hermite cubic plus two interior C¹ bubbles (complete quintic): frequency error O(h⁸).
    HermiteQuintic,
}

impl FemElement {
    /// Accepted spellings, for error messages and CLI help.
    pub const NAMES: [&'static str; 2] = ["hermite-cubic", "hermite-quintic"];

    pub fn name(self) -> &'static str {
        match self {
            FemElement::HermiteCubic => "hermite-cubic",
            FemElement::HermiteQuintic => "hermite-quintic",
        }
    }
}

/// A time-integration method, as `time.method` (case files) and `--method` (CLI) spell it.
///
/// One list for all backends: each backend declares the subset it implements and answers the
/// others with an error naming that subset. Spellings are parsed here, once ([`Method::NAMES`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum Method {
    /// fem: energy-consistent implicit midpoint (discrete gradient) for free-joint chains.
    EnergyMidpoint,
    /// fem: implicit generalized-α (Chung–Hulbert).
    GeneralizedAlpha,
    /// Explicit central difference: fem's velocity-Verlet form; fdm's report scheme.
    CentralDifference,
    /// fem: implicit midpoint rule (one-stage Gauss).
    ImplicitMidpoint,
    /// fdm: the report's two-step central difference.
    Report,
    /// fdm: the report's scheme with a Robert–Asselin filter of coefficient ν (None: the
    /// backend's default ν). Spelled `robert-asselin` or `robert-asselin=ν`.
    RobertAsselin { nu: Option<f64> },
    /// fdm: one-step velocity (kick–drift–kick) form.
    VelocityForm,
    /// modal: adaptive Dormand–Prince 5(4).
    Dopri5,
    /// modal: adaptive TR-BDF2 (also spelled `tr-bdf2`, `sdirk`).
    TrBdf2,
    /// modal: TR-BDF2 at a fixed step.
    TrBdf2Fixed,
    /// modal: trapezoidal rule at a fixed step.
    Trapezoid,
}

impl Method {
    /// Every accepted spelling, for error messages and CLI help.
    pub const NAMES: &'static str = "energy-midpoint, generalized-alpha, central-difference, \
        implicit-midpoint (fem); report, central-difference, robert-asselin[=nu], velocity-form \
        (fdm); dopri5, trbdf2 (also tr-bdf2, sdirk), trbdf2-fixed, trapezoid (modal)";

    /// The canonical spelling (`robert-asselin=ν` with its coefficient when one is given).
    pub fn name(self) -> String {
        let fixed = match self {
            Method::EnergyMidpoint => "energy-midpoint",
            Method::GeneralizedAlpha => "generalized-alpha",
            Method::CentralDifference => "central-difference",
            Method::ImplicitMidpoint => "implicit-midpoint",
            Method::Report => "report",
            Method::RobertAsselin { nu: Some(nu) } => return format!("robert-asselin={nu}"),
            Method::RobertAsselin { nu: None } => "robert-asselin",
            Method::VelocityForm => "velocity-form",
            Method::Dopri5 => "dopri5",
            Method::TrBdf2 => "trbdf2",
            Method::TrBdf2Fixed => "trbdf2-fixed",
            Method::Trapezoid => "trapezoid",
        };
        fixed.to_string()
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let name = text.trim();
        Ok(match name {
            "energy-midpoint" => Method::EnergyMidpoint,
            "generalized-alpha" => Method::GeneralizedAlpha,
            "central-difference" => Method::CentralDifference,
            "implicit-midpoint" => Method::ImplicitMidpoint,
            "report" => Method::Report,
            "robert-asselin" => Method::RobertAsselin { nu: None },
            "velocity-form" => Method::VelocityForm,
            "dopri5" => Method::Dopri5,
            "trbdf2" | "tr-bdf2" | "sdirk" => Method::TrBdf2,
            "trbdf2-fixed" => Method::TrBdf2Fixed,
            "trapezoid" => Method::Trapezoid,
            _ => {
                if let Some(value) = name.strip_prefix("robert-asselin=") {
                    let nu = value
                        .trim()
                        .parse::<f64>()
                        .map_err(|_| format!("cannot read the Robert–Asselin ν in `{name}`"))?;
                    return Ok(Method::RobertAsselin { nu: Some(nu) });
                }
                return Err(format!(
                    "unknown time-integration method `{name}`; accepted: {}",
                    Method::NAMES
                ));
            }
        })
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
    /// Integration method (None: the backend's default for the scene). Each backend implements
    /// some of the [`Method`]s and rejects the others, naming the ones it offers.
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

/// Degrees of freedom a backend would build for a scene: a table of (what, count).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DofPlan {
    pub groups: Vec<DofGroup>,
    /// Physics the backend builds for this scene, in words (e.g. "foreshortening stiffening").
    pub builds: Vec<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DofGroup {
    pub what: String,
    pub count: usize,
}

impl DofPlan {
    pub fn total(&self) -> usize {
        self.groups.iter().map(|g| g.count).sum()
    }
    pub fn add(&mut self, what: impl Into<String>, count: usize) {
        if count > 0 {
            self.groups.push(DofGroup {
                what: what.into(),
                count,
            });
        }
    }
}

/// Errors a backend may return instead of a result.
#[derive(Debug, Clone, PartialEq, Error, Serialize, Deserialize)]
pub enum BackendError {
    /// The backend does not implement what the scene or the request needs.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// A setting is out of range for this scene.
    #[error("invalid setting `{field}`: {message}")]
    InvalidSettings { field: String, message: String },
    /// A user-forced step is above an explicit scheme's stability bound.
    #[error(
        "time step {dt:.6e} exceeds the {bound_kind} stability bound {bound:.6e} at {location} \
         (t = {t:.6e}); use a --dt below {bound:.6e}, or omit --dt to let the scheme choose"
    )]
    StabilityBound {
        t: f64,
        dt: f64,
        bound: f64,
        bound_kind: String,
        location: String,
    },
    /// A numerical failure that has no partial result worth keeping (e.g. singular mass matrix
    /// at set-up).
    #[error("numerical failure at t = {t:.6e}: {message}")]
    Numerical { t: f64, message: String },
}

impl BackendError {
    pub fn unsupported(what: impl Into<String>) -> Self {
        BackendError::Unsupported(what.into())
    }
}

/// A discretization of scenes: finite elements, finite differences or assumed modes.
///
/// `simulate` returns `Ok` also when the run stops early: the result then carries a
/// [`crate::StabilityVerdict::Stopped`] diagnostic and the output up to that time.
pub trait Backend: Sync {
    fn kind(&self) -> BackendKind;

    /// The degrees of freedom and physics this backend would build for the scene.
    fn dof_plan(&self, scene: &Scene, disc: &Discretization) -> Result<DofPlan, BackendError>;

    /// Natural frequencies (Hz) and shapes, linearized about the scene's reference state.
    fn modes(
        &self,
        scene: &Scene,
        settings: &Settings,
        count: usize,
    ) -> Result<ModalResult, BackendError>;

    /// Linear static response to the scene's `[statics]` loads.
    fn statics(&self, scene: &Scene, settings: &Settings) -> Result<StaticResult, BackendError>;

    /// Dynamic response over [0, t_end].
    fn simulate(&self, scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError>;
}

#[cfg(test)]
mod tests {
    use super::Method;

    #[test]
    fn method_spellings_round_trip_and_unknown_names_list_the_accepted_ones() {
        for name in [
            "energy-midpoint",
            "generalized-alpha",
            "central-difference",
            "implicit-midpoint",
            "report",
            "robert-asselin",
            "robert-asselin=0.05",
            "velocity-form",
            "dopri5",
            "trbdf2",
            "trbdf2-fixed",
            "trapezoid",
        ] {
            let m: Method = name.parse().unwrap();
            assert_eq!(m.name(), name);
        }
        for alias in ["tr-bdf2", "sdirk"] {
            assert_eq!(alias.parse::<Method>(), Ok(Method::TrBdf2));
        }
        let e = "rk4".parse::<Method>().unwrap_err();
        assert!(e.contains("`rk4`") && e.contains(Method::NAMES), "{e}");
        assert!("robert-asselin=x".parse::<Method>().is_err());
    }
}
