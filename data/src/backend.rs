//! The contract every solver crate implements.
//!
//! A [`Scene`] says *what*; [`Settings`] say *how finely*; a [`Backend`] turns the two into
//! results. Backends never see each other.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::results::{ModalResult, RunResult, StaticResult};
use crate::scene::Scene;
pub use crate::settings::{
    BackendKind, Basis, Discretization, FemElement, Method, Settings, TimeStepping,
};

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

/// The scene as a run samples it: with `output_interval` (a run's override, the settings'
/// `time.output_interval`) in place of the scene's own, borrowed unchanged when there is none.
/// `t_end` is the run's end-time override. The scene file's limit on the number of samples
/// ([`crate::validate::limits::MAX_OUTPUT_SAMPLES`]) holds for the run too: a count above it,
/// to the run's end at the run's spacing, is refused naming the override that raised it
/// (`time.output_interval`, else `time.t_end`), as is an interval that is not a finite
/// number > 0. An invalid end time is left to the backends' own checks.
pub fn sampled_as(
    scene: &Scene,
    output_interval: Option<f64>,
    t_end: Option<f64>,
) -> Result<std::borrow::Cow<'_, Scene>, BackendError> {
    use crate::validate::limits::{MAX_OUTPUT_SAMPLES, excess_output_samples};
    let refuse = |field: &str, message: String| BackendError::InvalidSettings {
        field: field.into(),
        message,
    };
    if let Some(interval) = output_interval
        && !(interval.is_finite() && interval > 0.0)
    {
        return Err(refuse(
            "time.output_interval",
            format!("{interval} must be a finite number > 0"),
        ));
    }
    let interval = output_interval.unwrap_or(scene.simulation.output_interval);
    let end = t_end.unwrap_or(scene.simulation.t_end);
    if let Some(samples) = excess_output_samples(end, interval) {
        let field = match output_interval {
            Some(_) => "time.output_interval",
            None => "time.t_end",
        };
        return Err(refuse(
            field,
            format!(
                "t_end / output_interval = {end} / {interval} = {samples:.3e} samples is above \
                 the limit {MAX_OUTPUT_SAMPLES:.0e}; give a larger output interval or an earlier \
                 end time"
            ),
        ));
    }
    Ok(match output_interval {
        None => std::borrow::Cow::Borrowed(scene),
        Some(interval) => {
            let mut sampled = scene.clone();
            sampled.simulation.output_interval = interval;
            std::borrow::Cow::Owned(sampled)
        }
    })
}

/// A discretization of scenes: finite elements, finite differences or assumed modes.
///
/// The methods take the user-facing [`Settings`] (and `dof_plan` its [`Discretization`]) so
/// that callers hold every backend as one `dyn Backend`; each implementation turns them into
/// its own typed settings first ([`Settings::fem`], [`Settings::fdm`], [`Settings::modal`],
/// [`Settings::reference`]), which refuses a field it does not read or a method it does not
/// implement ([`BackendError::InvalidSettings`]), and passes only those inward.
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
        for name in crate::settings::method_spellings() {
            let m: Method = name.parse().unwrap();
            assert_eq!(m.name(), name);
        }
        for alias in ["tr-bdf2", "sdirk"] {
            assert_eq!(alias.parse::<Method>(), Ok(Method::TrBdf2));
        }
        let e = "rk4".parse::<Method>().unwrap_err();
        assert!(e.contains("`rk4`") && e.contains(&Method::names()), "{e}");
        assert!("robert-asselin=x".parse::<Method>().is_err());
    }
}
