//! Settings the rocket model reads, validated (range errors → `InvalidSetting`).

use data::{Basis as BasisKind, ModalSettings};

use super::error::RocketError;
use crate::integrate::{DOPRI5, MethodInfo, method_for, names_with};

/// Default number of axial and of transverse elastic modes.
pub const DEFAULT_MODES: usize = 6;
/// Largest accepted number of modes per field.
pub const MAX_MODES: usize = 40;
/// Default integrator tolerances: relative 1e-8, absolute 1e-10 (length units for the modal
/// coordinates, which are nose displacements of ~1e-4 in the catalog scenes).
pub const DEFAULT_RTOL: f64 = 1e-8;
pub const DEFAULT_ATOL: f64 = 1e-10;

/// Time integration method: a registered method with error-controlled steps (default
/// Dormand–Prince 5(4), [`DOPRI5`]).
pub type Method = &'static MethodInfo;

/// The rocket's refusal of a fixed-step method: `time.dt` is only its initial step, and it has
/// no default fixed step.
pub(crate) fn fixed_step_refused(method: Method) -> RocketError {
    RocketError::invalid(
        "time.method",
        format!(
            "`{}` is not a rocket integrator (a fixed-step method; the rocket takes \
             error-controlled steps); use {} (default `{}`)",
            method.name,
            names_with("or", |m| !m.is_fixed_step()),
            DOPRI5.name
        ),
    )
}

pub fn modes(settings: &ModalSettings) -> Result<usize, RocketError> {
    match settings.basis {
        None | Some(BasisKind::FreeFree) => {}
        Some(other) => {
            return Err(RocketError::invalid(
                "discretization.basis",
                format!(
                    "the rocket is a free-free body: basis `{}` does not apply; use `free-free`",
                    other.name()
                ),
            ));
        }
    }
    let n = settings.modes.unwrap_or(DEFAULT_MODES);
    if n == 0 || n > MAX_MODES {
        return Err(RocketError::invalid(
            "discretization.modes",
            format!("{n} modes per field; expected 1 to {MAX_MODES}"),
        ));
    }
    Ok(n)
}

/// Time-stepping settings resolved against the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeConfig {
    pub method: Method,
    pub rtol: f64,
    pub atol: f64,
    pub t_end: f64,
    pub output_interval: f64,
    /// Initial step (the adaptive methods choose their own steps after it).
    pub dt: Option<f64>,
}

fn positive(field: &str, v: Option<f64>) -> Result<Option<f64>, RocketError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(RocketError::invalid(
            field,
            format!("{x} is not a positive finite number"),
        )),
        other => Ok(other),
    }
}

pub fn time(scene: &data::Scene, settings: &ModalSettings) -> Result<TimeConfig, RocketError> {
    let ts = settings;
    let method = ts.method.map_or(&DOPRI5, method_for);
    if method.is_fixed_step() {
        return Err(fixed_step_refused(method));
    }
    let rtol = positive("time.rtol", ts.rtol)?.unwrap_or(DEFAULT_RTOL);
    let atol = positive("time.atol", ts.atol)?.unwrap_or(DEFAULT_ATOL);
    let t_end = positive("time.t_end", ts.t_end)?.unwrap_or(scene.simulation.t_end);
    let dt = positive("time.dt", ts.dt)?;
    let output_interval = scene.simulation.output_interval;
    if !(output_interval > 0.0 && t_end / output_interval <= 1e7) {
        return Err(RocketError::invalid(
            "time.t_end",
            format!("t_end {t_end} / output_interval {output_interval} gives too many samples"),
        ));
    }
    Ok(TimeConfig {
        method,
        rtol,
        atol,
        t_end,
        output_interval,
        dt,
    })
}
