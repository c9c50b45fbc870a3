//! The driver of the model families without events (the 3-D link, the mobile manipulator): the
//! method steps to each breakpoint of the inputs and restarts there; the outputs are sampled at
//! the output times by the method's dense output; the run stops on an integrator failure, on a
//! failure the right-hand side reports, or on a non-finite state, keeping what was sampled.

use data::{Diagnostic, StabilityVerdict};

use crate::integrate::{OdeRhs, Stepper};

/// When a sampled run samples and restarts.
#[derive(Debug, Clone, Copy)]
pub struct Schedule<'a> {
    /// The inputs' discontinuities in (0, t_end), sorted, then t_end.
    pub breaks: &'a [f64],
    /// Output interval; samples at k·`output_interval` and at t_end.
    pub output_interval: f64,
    pub t_end: f64,
    /// The remedy a stopped run's diagnostic names.
    pub remedy: &'static str,
}

/// Steps (`t` = 0, `y`) through `schedule` with `stepper`, calling `record(rhs, t, y)` at every
/// output time after t = 0 (the caller records t = 0). `failure(rhs)` reports a failure the
/// right-hand side detected during the last step (its time and why). Returns the run's verdict.
pub fn run_sampled<R: OdeRhs>(
    stepper: &mut dyn Stepper,
    rhs: &mut R,
    y: &mut [f64],
    schedule: Schedule<'_>,
    failure: impl Fn(&R) -> Option<(f64, &'static str)>,
    mut record: impl FnMut(&mut R, f64, &[f64]),
) -> StabilityVerdict {
    let Schedule {
        breaks,
        output_interval,
        t_end,
        remedy,
    } = schedule;
    let n_samples = (t_end / output_interval - 1e-9).ceil() as usize + 1;
    let sample_time = |k: usize| (k as f64 * output_interval).min(t_end);
    let mut ys = vec![0.0; y.len()];
    let mut next = 1;
    let mut t = 0.0;
    for &target in breaks {
        while t < target {
            if let Err(e) = stepper.step(rhs, &mut t, y, target) {
                return integrator_stopped(t, &e.to_string(), remedy);
            }
            if let Some((tf, why)) = failure(rhs) {
                return integrator_stopped(tf, why, remedy);
            }
            while next < n_samples && sample_time(next) <= t * (1.0 + 1e-14) {
                let ts = sample_time(next);
                stepper.dense(ts, &mut ys);
                record(rhs, ts, &ys);
                next += 1;
            }
            if !y.iter().all(|v| v.is_finite()) {
                return integrator_stopped(t, "non-finite state", remedy);
            }
        }
        stepper.reset();
    }
    StabilityVerdict::Completed
}

/// The stop of a run whose time integration could not continue at `t`, for the reason `why`,
/// with the run's own `remedy`.
fn integrator_stopped(t: f64, why: &str, remedy: &str) -> StabilityVerdict {
    StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: "the integrator could not continue".into(),
            location: None,
            why: why.into(),
            remedy: remedy.into(),
        },
    }
}
