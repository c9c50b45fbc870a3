//! The backend's settings ([`data::FdmSettings`]), validated once: ranges checked, defaults
//! filled in.

use crate::error::FdmError;

pub use crate::method::payload::DEFAULT_ASSELIN_NU;

/// Relative change of the step τ that is logged as a `StepSizeChange` event (the rocket's step
/// follows the burning mass; 1 % changes mark the burn without flooding the event list).
pub const STEP_LOG_CHANGE: f64 = 0.01;

/// Time-integration method (`time.method`), declared by the method registry.
pub use crate::method::Method;

/// The backend's settings validated: [`data::FdmSettings`] with its ranges checked and the
/// defaults filled in.
#[derive(Debug, Clone, PartialEq)]
pub struct ValidatedSettings {
    /// The settings as requested (None where the default applies), recorded in the results.
    pub requested: data::FdmSettings,
    pub stations: Option<usize>,
    pub dt: Option<f64>,
    pub safety: f64,
    pub method: Method,
    pub t_end: Option<f64>,
    /// Relative step change logged as an event ([`STEP_LOG_CHANGE`]).
    pub step_log_change: f64,
}

impl ValidatedSettings {
    pub fn from_settings(s: &data::FdmSettings) -> Result<Self, FdmError> {
        if let Some(n) = s.stations
            && !(5..=100_000).contains(&n)
        {
            return Err(FdmError::invalid(
                "discretization.stations",
                format!("{n} stations: must lie in 5..=100000"),
            ));
        }
        if let Some(dt) = s.dt
            && !(dt.is_finite() && dt > 0.0)
        {
            return Err(FdmError::invalid("time.dt", format!("{dt} must be > 0")));
        }
        let safety = s.safety_factor.unwrap_or(1.0);
        if !(safety > 0.0 && safety <= 1.0) {
            return Err(FdmError::invalid(
                "time.safety_factor",
                format!("{safety} must lie in (0, 1]"),
            ));
        }
        if let Some(t) = s.t_end
            && !(t.is_finite() && t > 0.0)
        {
            return Err(FdmError::invalid("time.t_end", format!("{t} must be > 0")));
        }
        let method = match s.method {
            Some(m) => Method::from_data(m)?,
            None => Method::Report,
        };
        Ok(ValidatedSettings {
            requested: s.clone(),
            stations: s.stations,
            dt: s.dt,
            safety,
            method,
            t_end: s.t_end,
            step_log_change: STEP_LOG_CHANGE,
        })
    }

    /// The request as the results record it.
    pub fn request(&self) -> data::Settings {
        data::Settings::from(&self.requested)
    }
}
