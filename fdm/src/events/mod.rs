//! Events a run consumes: discontinuities located inside a step (a contact starting, a normal
//! force crossing zero), the resets applied there (an impact's velocity jump) and the switch
//! of the active constraints (sliding on a surface).
//!
//! The driver ([`crate::driver::run`]) calls an [`Events`] object at fixed points of every
//! step: before it (a step factor: refinement after a reset), after it (locate an event inside
//! the step and re-take the step up to it through [`Retake`]), when the step is committed, and
//! at a located event (apply the reset, switch the constraints, log the event). The active
//! constraints themselves are the model's ([`System::project_position`],
//! [`System::project_velocity`], and the constrained accelerations of [`System::accel`]). A
//! method whose step depends on level j alone (the velocity form with every force at the
//! predicted velocity) can be re-taken with any length, so it supports events.
//!
//! Event kinds: [`tip_contact`] (unilateral frictionless contact of the two-link chain's tip).

pub mod tip_contact;

use data::{Event, StabilityVerdict};

use crate::error::FdmError;
use crate::method::{Levels, StepState, Stepper};
use crate::system::System;

/// Re-takes the current step from level j with another length (event location).
pub struct Retake<'a> {
    pub(crate) method: &'a mut dyn Stepper,
    pub(crate) t: f64,
    pub(crate) tau_prev: f64,
    /// force evaluations made by re-takes
    pub(crate) evaluations: usize,
}

impl Retake<'_> {
    /// The step of length `len` from level j into `st.next` (with the model's constraint
    /// projections): one force evaluation.
    pub fn take(&mut self, sys: &mut dyn System, st: &mut StepState, len: f64) {
        take_step(self.method, sys, self.t, self.tau_prev, len, st);
        self.evaluations += 1;
    }

    /// The positions the step of length `len` from level j reaches, into `q`, without a force
    /// evaluation ([`Stepper::step_positions`]).
    pub fn positions(&self, st: &StepState, len: f64, q: &mut [f64]) {
        self.method.step_positions(st, self.tau_prev, len, q);
    }
}

/// One step of `method` from t by `tau` with the model's constraint projections: positions
/// projected before the force evaluation of the step end, velocities after the final kick.
pub(crate) fn take_step(
    method: &mut dyn Stepper,
    sys: &mut dyn System,
    t: f64,
    tau_prev: f64,
    tau: f64,
    st: &mut StepState,
) {
    method.predict(tau_prev, tau, st);
    finish_step(method, sys, t, tau_prev, tau, st);
}

/// The second half of [`take_step`] (after the method's prediction).
pub(crate) fn finish_step(
    method: &mut dyn Stepper,
    sys: &mut dyn System,
    t: f64,
    tau_prev: f64,
    tau: f64,
    st: &mut StepState,
) {
    sys.project_position(&mut st.next.q);
    method.complete(sys, t + tau, tau_prev, tau, st);
    sys.project_velocity(&mut st.next.v);
}

/// The event hooks of a run; every hook defaults to "no event".
pub trait Events<S: ?Sized> {
    /// At t = 0 before the first force evaluation: `Err` for an inconsistent start.
    fn begin(&mut self, sys: &mut S, level: &Levels) -> Result<(), FdmError> {
        let _ = (sys, level);
        Ok(())
    }
    /// The first step the driver chose (from the bound at t = 0).
    fn first_step(&mut self, tau: f64) {
        let _ = tau;
    }
    /// Factor on the step chosen at t (not applied to a forced step).
    fn step_factor(&self, t: f64) -> Option<f64> {
        let _ = t;
        None
    }
    /// The ledger's powers at a level (t, v), overwriting the method's (which are at its
    /// predicted velocity).
    fn level_powers(&mut self, sys: &mut S, t: f64, v: &[f64], out: &mut [f64]) {
        let _ = (sys, t, v, out);
    }
    /// After the step of length `tau` from t into `st.next`: `Err` stops the run; `Ok(Some(s))`
    /// when an event lies inside the step — the step is then re-taken with length s ≤ `tau`
    /// (s = 0: `next` is level j itself) before returning.
    fn locate(
        &mut self,
        sys: &mut S,
        t: f64,
        tau: f64,
        st: &mut StepState,
        retake: &mut Retake<'_>,
    ) -> Result<Option<f64>, StabilityVerdict> {
        let _ = (sys, t, tau, st, retake);
        Ok(None)
    }
    /// The step of length `tau` is committed (diagnostics of the step).
    fn committed(&mut self, sys: &mut S, tau: f64) {
        let _ = (sys, tau);
    }
    /// At the located event at t (level j = the event state; `work` the ledger's accumulated
    /// input/dissipation work): apply the reset and the switch, log it, bring `st.acc` and
    /// `st.p_cur` to the new phase. Returns the force evaluations made; `Err` stops the run.
    fn apply(
        &mut self,
        sys: &mut S,
        t: f64,
        st: &mut StepState,
        work: &mut [f64],
        log: &mut Vec<Event>,
    ) -> Result<usize, StabilityVerdict> {
        let _ = (sys, t, st, work, log);
        Ok(0)
    }
    /// After every step (and event): level j is final.
    fn settled(&mut self, sys: &mut S, level: &Levels) {
        let _ = (sys, level);
    }
}

/// A run without events.
pub struct NoEvents;
impl<S: ?Sized> Events<S> for NoEvents {}

/// Illinois regula falsi on [a, b] with f(a) > 0 ≥ f(b) (or the reverse): stops when the
/// bracket is narrower than `tol_w`, or when |f| ≤ `tol_f` and |f| over the secant slope is
/// below `tol_w`. Returns (point, time tolerance, evaluations): the point is the last evaluated
/// one, the tolerance the bracket width or |f|/|secant slope|.
pub fn illinois(
    mut f: impl FnMut(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    tol_w: f64,
    tol_f: f64,
) -> (f64, f64, usize) {
    let mut side = 0;
    let mut evals = 0;
    let mut c = b;
    for _ in 0..200 {
        c = if fb != fa {
            (b - fb * (b - a) / (fb - fa)).clamp(a.min(b), a.max(b))
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        evals += 1;
        if fc == 0.0 {
            return (c, 0.0, evals);
        }
        if fc.abs() <= tol_f {
            // |f| small enough; the time is known to |f|/|f'| (grazing: f' small, go on)
            let slope = ((fb - fa) / (b - a)).abs();
            let tol = if slope > 0.0 {
                (fc.abs() / slope).min((b - a).abs())
            } else {
                (b - a).abs()
            };
            if tol <= tol_w {
                return (c, tol, evals);
            }
        }
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if (b - a).abs() <= tol_w {
            break;
        }
    }
    (c, (b - a).abs(), evals)
}
