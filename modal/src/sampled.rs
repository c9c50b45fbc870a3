//! The driver of the model families without events (the rocket, the 3-D link, the mobile
//! manipulator): the method steps to each breakpoint of the inputs and restarts there; the
//! outputs are sampled at the output times by the method's dense output; the run stops on an
//! integrator failure, on a failure the right-hand side reports, on a stop the family's own
//! check declares, or on a non-finite state, keeping what was sampled.
//!
//! A family takes part through [`SampledRun`]: it records the samples and may hook its own work
//! into fixed points of the loop. After each accepted step, in this order:
//! 1. [`SampledRun::failure`]: a failure the right-hand side detected during the step;
//! 2. [`SampledRun::record`] at every output time the step has passed (dense output);
//! 3. [`SampledRun::after_step`]: the family's bookkeeping of the step and its checks of the
//!    new state (the rocket lists rejected attempts and tests for a runaway);
//! 4. the driver's test for a non-finite state.
//!
//! A step that lands on a breakpoint is followed by the restart of the method
//! ([`Stepper::reset`], also at t_end, where nothing follows it) and then
//! [`SampledRun::on_break`] (the rocket switches to burn-out there and books its event). A step
//! the method cannot take ends the run with the family's diagnostic
//! ([`SampledRun::step_failed`]) or else the driver's, which names the schedule's remedy.
//!
//! The driver allocates only the dense-output buffer, before the first step.

use data::{Diagnostic, StabilityVerdict};

use crate::integrate::{IntegrateError, OdeRhs, Stepper, Stretch};

/// When a sampled run samples and restarts.
#[derive(Debug, Clone, Copy)]
pub struct Schedule<'a> {
    /// The inputs' discontinuities in (0, t_end), sorted, then t_end.
    pub breaks: &'a [f64],
    /// Output interval; samples at k·`output_interval` (k ≥ 1) below t_end and at t_end.
    pub output_interval: f64,
    pub t_end: f64,
    /// The remedy the driver's own diagnostics of a stopped run name.
    pub remedy: &'static str,
}

/// A family's part in [`run_sampled`] on the right-hand side `R`: only [`Self::record`] is
/// required; the other hooks do nothing by default.
pub trait SampledRun<R> {
    /// Records the state `y` at the output time `t`. The driver calls it at every output time
    /// after t = 0 (the caller records t = 0).
    fn record(&mut self, rhs: &mut R, t: f64, y: &[f64]);

    /// A failure the right-hand side detected during the last step: its time and why.
    fn failure(&self, _rhs: &R) -> Option<(f64, &'static str)> {
        None
    }

    /// The family's own verdict on a step the method could not take from `t`; `None` leaves the
    /// driver's diagnostic.
    fn step_failed(&self, _rhs: &R, _t: f64, _error: &IntegrateError) -> Option<StabilityVerdict> {
        None
    }

    /// Called after each accepted step, which ended at `t` with the state `y`, once the samples
    /// it passed are recorded; a verdict stops the run there.
    fn after_step(
        &mut self,
        _stepper: &dyn Stepper,
        _t: f64,
        _y: &[f64],
    ) -> Option<StabilityVerdict> {
        None
    }

    /// Called when the run has reached `breaks[index]` of the [`Schedule`] (t_end included) and
    /// the method has been restarted there.
    fn on_break(&mut self, _rhs: &mut R, _stepper: &dyn Stepper, _index: usize) {}
}

/// Steps (`t` = 0, `y`) through `schedule` with `stepper`, handing the samples and the hooks to
/// `run` (see the module docs for the order). Returns the run's verdict.
pub fn run_sampled<R: OdeRhs, S: SampledRun<R>>(
    stepper: &mut dyn Stepper,
    rhs: &mut R,
    y: &mut [f64],
    schedule: Schedule<'_>,
    run: &mut S,
) -> StabilityVerdict {
    let mut driver = Driver {
        stepper,
        rhs,
        run,
        samples: Samples::new(&schedule, y.len()),
        remedy: schedule.remedy,
    };
    let mut t = 0.0;
    for (index, &target) in schedule.breaks.iter().enumerate() {
        let stretch = Stretch {
            start: t,
            end: target,
        };
        while t < target {
            if let Some(stop) = driver.step(&mut t, y, stretch) {
                return stop;
            }
        }
        driver.restart(index);
    }
    StabilityVerdict::Completed
}

/// The output times of a run and the buffer their states are interpolated into.
struct Samples {
    interval: f64,
    t_end: f64,
    /// Output times after t = 0 are numbered 1..=`count`; the last one is t_end.
    count: usize,
    /// The first output time not yet recorded.
    next: usize,
    buf: Vec<f64>,
}

impl Samples {
    fn new(schedule: &Schedule<'_>, dim: usize) -> Samples {
        // The tolerance keeps a t_end that is a multiple of the interval up to rounding from
        // getting a second sample right after the last multiple; a t_end far below the
        // interval still gets its sample.
        let count = (schedule.t_end / schedule.output_interval - 1e-9).ceil() as usize;
        Samples {
            interval: schedule.output_interval,
            t_end: schedule.t_end,
            count: count.max(1),
            next: 1,
            buf: vec![0.0; dim],
        }
    }

    fn time(&self, k: usize) -> f64 {
        (k as f64 * self.interval).min(self.t_end)
    }

    /// Whether the step that ended at `t` has passed the next output time (the relative
    /// tolerance takes a sample time that the step's end misses by rounding).
    fn due(&self, t: f64) -> bool {
        self.next <= self.count && self.time(self.next) <= t * (1.0 + 1e-14)
    }
}

/// The parts of a sampled run the step loop works on.
struct Driver<'a, R, S> {
    stepper: &'a mut dyn Stepper,
    rhs: &'a mut R,
    run: &'a mut S,
    samples: Samples,
    remedy: &'static str,
}

impl<R: OdeRhs, S: SampledRun<R>> Driver<'_, R, S> {
    /// One accepted step from `t` toward the end of `stretch` and what follows it (module docs); the
    /// verdict when the run stops.
    fn step(&mut self, t: &mut f64, y: &mut [f64], stretch: Stretch) -> Option<StabilityVerdict> {
        self.rhs.set_stretch(stretch);
        let stepped = self.stepper.step(self.rhs, t, y, stretch.end);
        self.rhs.set_stretch(Stretch::OPEN);
        if let Err(e) = stepped {
            let own = self.run.step_failed(self.rhs, *t, &e);
            return Some(own.unwrap_or_else(|| self.stopped(*t, &e.to_string())));
        }
        if let Some((tf, why)) = self.run.failure(self.rhs) {
            return Some(self.stopped(tf, why));
        }
        self.record_passed(*t);
        if let Some(stop) = self.run.after_step(&*self.stepper, *t, y) {
            return Some(stop);
        }
        if !y.iter().all(|v| v.is_finite()) {
            return Some(self.stopped(*t, "non-finite state"));
        }
        None
    }

    /// Records every output time the step that ended at `t` has passed.
    fn record_passed(&mut self, t: f64) {
        while self.samples.due(t) {
            let ts = self.samples.time(self.samples.next);
            self.stepper.dense(ts, &mut self.samples.buf);
            self.run.record(self.rhs, ts, &self.samples.buf);
            self.samples.next += 1;
        }
    }

    /// The restart at `breaks[index]`: the method forgets its history across the discontinuity,
    /// then the family switches its inputs.
    fn restart(&mut self, index: usize) {
        self.stepper.reset();
        self.run.on_break(self.rhs, &*self.stepper, index);
    }

    fn stopped(&self, t: f64, why: &str) -> StabilityVerdict {
        integrator_stopped(t, why, self.remedy)
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Dopri5, Tolerances};

    /// y' = 1 from y(0) = 0: the state is the time, so a sample's value shows where it was taken.
    struct Clock;

    impl OdeRhs for Clock {
        fn dim(&self) -> usize {
            1
        }
        fn eval(&mut self, _t: f64, _y: &[f64], dydt: &mut [f64]) {
            dydt[0] = 1.0;
        }
    }

    /// What the driver handed to the hooks, in order; stops after `stop_after` steps if set.
    #[derive(Default)]
    struct Log {
        samples: Vec<(f64, f64)>,
        calls: Vec<String>,
        steps: usize,
        stop_after: Option<usize>,
    }

    impl SampledRun<Clock> for Log {
        fn record(&mut self, _rhs: &mut Clock, t: f64, y: &[f64]) {
            self.samples.push((t, y[0]));
            self.calls.push("record".into());
        }
        fn after_step(&mut self, _: &dyn Stepper, t: f64, _: &[f64]) -> Option<StabilityVerdict> {
            self.steps += 1;
            self.calls.push("after_step".into());
            (self.stop_after == Some(self.steps)).then(|| integrator_stopped(t, "test", "none"))
        }
        fn on_break(&mut self, _: &mut Clock, _: &dyn Stepper, index: usize) {
            self.calls.push(format!("break {index}"));
        }
    }

    fn run(breaks: &[f64], output_interval: f64, log: &mut Log) -> StabilityVerdict {
        let tol = Tolerances::default();
        let mut stepper = Dopri5::new(1, tol, None, None);
        let schedule = Schedule {
            breaks,
            output_interval,
            t_end: *breaks.last().unwrap(),
            remedy: "none",
        };
        run_sampled(&mut stepper, &mut Clock, &mut [0.0], schedule, log)
    }

    fn times(log: &Log) -> Vec<f64> {
        log.samples.iter().map(|s| s.0).collect()
    }

    #[test]
    fn dyn_samples_at_every_interval_below_t_end_and_at_t_end() {
        let mut log = Log::default();
        assert_eq!(run(&[0.25], 0.1, &mut log), StabilityVerdict::Completed);
        assert_eq!(times(&log), [0.1, 0.2, 0.25]);
        for (t, y) in &log.samples {
            assert!((y - t).abs() < 1e-12, "sample at {t} holds {y}");
        }
    }

    #[test]
    fn dyn_t_end_a_multiple_of_the_interval_up_to_rounding_is_sampled_once() {
        // 0.07 / 0.01 = 7.000000000000001: without the tolerance an eighth sample would repeat
        // t_end = 7 · 0.01
        let mut log = Log::default();
        run(&[0.07], 0.01, &mut log);
        let expected: Vec<f64> = (1..=7).map(|k| k as f64 * 0.01).collect();
        assert_eq!(times(&log), expected);
        assert_eq!(expected[6], 0.07);
    }

    #[test]
    fn dyn_t_end_far_below_the_interval_is_still_sampled() {
        let mut log = Log::default();
        run(&[1e-12], 1.0, &mut log);
        assert_eq!(times(&log), [1e-12]);
    }

    #[test]
    fn dyn_hooks_run_in_order_and_every_break_is_reached() {
        let mut log = Log::default();
        run(&[0.05, 0.1], 0.1, &mut log);
        let breaks: Vec<&str> = log
            .calls
            .iter()
            .filter(|c| c.starts_with("break"))
            .map(String::as_str)
            .collect();
        assert_eq!(breaks, ["break 0", "break 1"]);
        // the last step records t_end before its after_step, then the final break follows
        assert_eq!(
            log.calls[log.calls.len() - 3..],
            ["record", "after_step", "break 1"]
        );
        assert_eq!(times(&log), [0.1]);
    }

    #[test]
    fn dyn_a_verdict_after_a_step_stops_the_run() {
        let mut log = Log {
            stop_after: Some(1),
            ..Log::default()
        };
        let verdict = run(&[0.05, 0.1], 0.1, &mut log);
        assert!(matches!(verdict, StabilityVerdict::Stopped { .. }));
        assert_eq!(log.steps, 1);
        assert!(!log.calls.iter().any(|c| c.starts_with("break")));
    }
}
