//! The driver: the loop that chooses each step, lets a [`Stepper`] take it, watches the
//! solution, samples the outputs and books the ledger.
//!
//! **Step choice.** Every step from the model's stability bound (the report's 5.45,
//! τ_{j+1} = min_i σ_i, times the method's factor and the user's safety factor), or forced by
//! the user and then checked against that bound before every step. With `lookahead` the bound
//! is also evaluated at t + τ and the smaller kept (the report evaluates σ with the masses of
//! the new level, m_{i,j+1}; right for bounds that only shrink, like a burning stage).
//!
//! **Jumps.** Every method lands on the applied laws' jumps (torque switches, burn-out): the
//! step that would pass one ends on it, closed at the laws' left limits; a one-step method's
//! next step opens at their new values, a two-step method starts again there (`jumps` module,
//! [`crate::method::AtJumps`]).
//!
//! **Watch.** Between the method's prediction and its force evaluation the driver checks the
//! new level: non-finite values, |Δ²v| over the monitored (elastic) coordinates against the
//! peak |v| (the computational mode of a two-step method grows as a sign-alternating
//! velocity), and runaway growth of q. It stops with a diagnostic naming the coordinate, the
//! cause and the remedy. After each sample it also checks the ledger: a residual above 5 % of
//! the energy that flowed (`watch::LEDGER_LOST`, judged from the 50th step on) means the step
//! no longer resolves the motion — the bound is the linearized system's at t = 0 — and the run
//! stops there rather than present the rest as a solution (two-step methods that can excite
//! their computational mode keep their own, more specific watch).
//!
//! **Work.** The ledger's input and dissipation terms integrate the model's powers by the
//! trapezoidal rule over each step. Nothing here allocates inside the step loop (output storage
//! is reserved before the loop).

// Index loops run over several parallel level buffers at once.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use data::{Cost, Diagnostic, Event, StabilityVerdict};

use crate::error::FdmError;
use crate::events::{Events, NoEvents, Retake, finish_step};
use crate::method::{AtJumps, StepState, Stepper, capabilities, stepper};
use crate::output::{LevelRecord, Outcome, Outputs, Recorder};
use crate::settings::{Method, ValidatedSettings};
use crate::system::{Bound, System};
use jumps::Jumps;
use watch::{
    Growth, LEDGER_LOST, LEDGER_SETTLED_STEPS, Watch, growth_diagnostic, ledger_diagnostic,
    overextension_diagnostic,
};

mod jumps;
mod watch;

/// How to step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    pub method: Method,
    pub safety: f64,
    pub forced_dt: Option<f64>,
    pub t_end: f64,
    pub output_interval: f64,
    /// Relative change of τ that is logged as a `StepSizeChange` event.
    pub log_change: f64,
    /// Evaluate the bound also at t + τ and keep the smaller (the report's m_{i,j+1}; right for
    /// bounds that only shrink, like a burning stage).
    pub lookahead: bool,
    /// Skip the forced-step bound check (only for tests that demonstrate what the check
    /// prevents).
    pub enforce_bound: bool,
}

impl StepControl {
    /// The control every scene run uses: step settings from `s` (τ changes logged at
    /// [`ValidatedSettings::step_log_change`]), horizon and output grid from the scene.
    pub(crate) fn for_scene(
        scene: &data::Scene,
        s: &ValidatedSettings,
        method: Method,
        lookahead: bool,
        enforce_bound: bool,
    ) -> Self {
        StepControl {
            method,
            safety: s.safety,
            forced_dt: s.dt,
            t_end: s.t_end.unwrap_or(scene.simulation.t_end),
            output_interval: scene.simulation.output_interval,
            log_change: s.step_log_change,
            lookahead,
            enforce_bound,
        }
    }
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// A model the driver can run: its physics and its output naming.
pub trait Model: System + Outputs {}
impl<S: System + Outputs> Model for S {}

/// The step τ under `ctl` at time t for a method with stability factor `factor`: (τ, the
/// method's limit, the binding bound). `Err` when a forced step exceeds the limit or the limit
/// is not positive.
pub(crate) fn choose_step<S: Model + ?Sized>(
    sys: &S,
    ctl: &StepControl,
    factor: f64,
    t: f64,
) -> Result<(f64, f64, Bound), FdmError> {
    let b0 = sys.bound(t);
    let trial = ctl.safety * factor * b0.sigma;
    let b = if ctl.lookahead {
        let b1 = sys.bound(t + ctl.forced_dt.unwrap_or(trial));
        if b1.sigma < b0.sigma { b1 } else { b0 }
    } else {
        b0
    };
    let limit = factor * b.sigma;
    let tau = match ctl.forced_dt {
        Some(dt) => {
            if ctl.enforce_bound && dt > limit * (1.0 + 1e-12) {
                return Err(FdmError::StabilityBound {
                    t,
                    dt,
                    bound: limit,
                    kind: b.kind.name().to_string(),
                    location: sys.describe(&b),
                });
            }
            dt
        }
        None => ctl.safety * limit,
    };
    if !(tau.is_finite() && tau > 0.0) {
        return Err(FdmError::Numerical {
            t,
            message: format!("stability bound {limit:e} is not positive"),
        });
    }
    Ok((tau, limit, b))
}

/// Integrates from (q0, v0) at t = 0 to `ctl.t_end` with the method `ctl.method`.
pub fn integrate<S: Model>(
    sys: &mut S,
    q0: &[f64],
    v0: &[f64],
    ctl: &StepControl,
) -> Result<Outcome, FdmError> {
    run(
        sys,
        stepper(ctl.method).as_mut(),
        &mut NoEvents,
        q0,
        v0,
        ctl,
    )
}

/// Integrates from (q0, v0) at t = 0 to `ctl.t_end` with `method`, consuming `events`.
///
/// Phases: `RunState::begin` (initial accelerations, powers, first step and sample),
/// `RunState::start_up` (a two-step form's second level), then per step
/// `RunState::next_step` (the bound's step, logged when it moves), the method's prediction,
/// `RunState::watch` (stop on growth or overextension) and `RunState::advance` (force
/// evaluation, event location, work, sample, reset).
pub fn run<S: Model, E: Events<S>>(
    sys: &mut S,
    method: &mut dyn Stepper,
    events: &mut E,
    q0: &[f64],
    v0: &[f64],
    ctl: &StepControl,
) -> Result<Outcome, FdmError> {
    let clock = Instant::now();
    let factor = method.bound_factor();
    let mut rec = Recorder::new(sys, ctl.t_end, ctl.output_interval);
    let (mut rs, limit) = RunState::begin(sys, &*method, events, q0, v0, ctl, factor, &mut rec)?;
    let watch = WatchSettings {
        mon: sys.monitored(),
        parasitic_threshold: method.parasitic_threshold(),
        computational_mode: sys.damped() && method.has_computational_mode(),
    };
    let mut verdict = StabilityVerdict::Completed;
    let at_jumps = capabilities(ctl.method).at_jumps;
    let mut jumps = Jumps::new(&*sys);
    let first = rs.tau;
    rs.start_onto_jumps(
        sys,
        method,
        events,
        &mut jumps,
        ctl,
        factor,
        (first, limit),
        &mut rec,
    )?;

    while !rec.done() {
        let (tau_next, limit_next) = rs.next_step(sys, ctl, factor)?;
        let tau_bound = match events.step_factor(rs.t) {
            Some(f) if ctl.forced_dt.is_none() => tau_next * f,
            _ => tau_next,
        };
        let (tau_step, landing) = jumps.toward(rs.t, tau_bound);
        sys.close_stretch_at(landing);
        method.predict(rs.tau, tau_step, &mut rs.st);
        if let Some(diagnostic) = rs.watch(sys, method, &watch, tau_step, limit_next) {
            sys.close_stretch_at(None);
            verdict = StabilityVerdict::Stopped { diagnostic };
            break;
        }
        let advanced = rs.advance(
            sys, method, events, &watch, tau_step, landing, limit_next, &mut rec,
        );
        sys.close_stretch_at(None);
        match (advanced, landing) {
            (Err(stop), _) => {
                verdict = stop;
                break;
            }
            (Ok(true), Some(jump)) => {
                rs.cost.rhs_evaluations += jumps.open(sys, events, jump, &mut rs.st);
                if at_jumps == AtJumps::Restarts && !rec.done() {
                    let step = rs.next_step(sys, ctl, factor)?;
                    rs.start_onto_jumps(
                        sys, method, events, &mut jumps, ctl, factor, step, &mut rec,
                    )?;
                }
            }
            _ => {}
        }
    }
    rs.cost.wall_time_s = clock.elapsed().as_secs_f64();
    Ok(Outcome {
        observables: rec.obs,
        ledger: rec.ledger,
        events: rs.log,
        cost: rs.cost,
        verdict,
        tau_min: rs.tau_min,
        tau_max: rs.tau_max,
    })
}

/// What the watch looks at: the monitored (elastic) coordinates, the method's threshold for
/// |Δ²v| against the peak |v|, and whether a computational mode can be excited (damping or
/// velocity coupling under a two-step method).
struct WatchSettings {
    mon: std::ops::Range<usize>,
    parasitic_threshold: f64,
    computational_mode: bool,
}

/// The loop's state between steps: levels, accelerations and powers (the method's),
/// accumulated work at two levels, time and step, the step statistics, the watch's peaks, the
/// event log and the cost.
struct RunState {
    st: StepState,
    w_cur: Vec<f64>,
    w_new: Vec<f64>,
    n: usize,
    np: usize,
    t: f64,
    tau: f64,
    tau_logged: f64,
    tau_min: f64,
    tau_max: f64,
    peak_v: f64,
    peak_q: f64,
    log: Vec<Event>,
    cost: Cost,
}

impl RunState {
    /// The initial level (q0, v0) at t = 0: accelerations, powers, the first step from the
    /// bound and the first sample. Returns the state and the method's limit at t = 0.
    #[allow(clippy::too_many_arguments)]
    fn begin<S: Model, E: Events<S>>(
        sys: &mut S,
        method: &dyn Stepper,
        events: &mut E,
        q0: &[f64],
        v0: &[f64],
        ctl: &StepControl,
        factor: f64,
        rec: &mut Recorder,
    ) -> Result<(Self, f64), FdmError> {
        let n = sys.dofs();
        let (_, inp, dis) = sys.ledger_names();
        let np = inp.len() + dis.len();
        let mut cost = Cost {
            dofs: n,
            ..Cost::default()
        };
        let mut st = StepState::new(n, np);
        let w_cur = vec![0.0; np];
        let w_new = vec![0.0; np];
        st.cur.q.copy_from_slice(q0);
        st.cur.v.copy_from_slice(v0);

        let t = 0.0;
        events.begin(sys, &st.cur)?;
        sys.accel(t, &st.cur.q, &st.cur.v, &mut st.acc);
        sys.powers(&mut st.p_cur);
        events.level_powers(sys, t, &st.cur.v, &mut st.p_cur);
        cost.rhs_evaluations += 1;
        let (tau, limit, _) = choose_step(sys, ctl, factor, t)?;
        events.first_step(tau);
        let level = LevelRecord {
            t,
            state: &st.cur,
            work: &w_cur,
            power: &st.p_cur,
        };
        rec.record(sys, method, level, level, tau, limit, false);

        let mon = sys.monitored();
        let peak_v = inf_norm(&st.cur.v[mon.clone()]).max(1e-300);
        let peak_q = inf_norm(&st.cur.q[mon]).max(1e-300);
        let rs = RunState {
            st,
            w_cur,
            w_new,
            n,
            np,
            t,
            tau,
            tau_logged: tau,
            tau_min: tau,
            tau_max: tau,
            peak_v,
            peak_q,
            log: Vec::new(),
            cost,
        };
        Ok((rs, limit))
    }

    /// The start-up of a method that needs a second level (nothing for one-step methods), at
    /// t = 0 and at the jumps it restarts at ([`AtJumps::Restarts`]): a step of `step`'s
    /// length (and method limit), shortened onto a jump it would pass, which is then opened
    /// and started from again.
    #[allow(clippy::too_many_arguments)]
    fn start_onto_jumps<S: Model, E: Events<S>>(
        &mut self,
        sys: &mut S,
        method: &mut dyn Stepper,
        events: &mut E,
        jumps: &mut Jumps,
        ctl: &StepControl,
        factor: f64,
        mut step: (f64, f64),
        rec: &mut Recorder,
    ) -> Result<(), FdmError> {
        loop {
            let (tau, landing) = jumps.toward(self.t, step.0);
            sys.close_stretch_at(landing);
            let stepped = self.start_up(sys, method, tau, landing, step.1, rec);
            sys.close_stretch_at(None);
            match landing {
                Some(jump) if stepped => {
                    self.cost.rhs_evaluations += jumps.open(sys, events, jump, &mut self.st);
                    if rec.done() {
                        return Ok(());
                    }
                    step = self.next_step(sys, ctl, factor)?;
                }
                _ => return Ok(()),
            }
        }
    }

    /// The start-up step of `tau` from the current level (ending on `landing` when it lands on
    /// a jump); false for a method that needs none.
    fn start_up<S: Model>(
        &mut self,
        sys: &mut S,
        method: &mut dyn Stepper,
        tau: f64,
        landing: Option<f64>,
        limit: f64,
        rec: &mut Recorder,
    ) -> bool {
        let t = self.t;
        let start_evaluations = method.start(sys, t, tau, &mut self.st);
        if start_evaluations > 0 {
            self.tau = tau;
            self.cost.rhs_evaluations += start_evaluations;
            let t_new = landing.unwrap_or(t + tau);
            self.book_work(tau);
            rec.record(
                sys,
                &*method,
                self.level(t),
                self.next_level(t_new),
                tau,
                limit,
                landing.is_some(),
            );
            self.st.rotate();
            std::mem::swap(&mut self.w_cur, &mut self.w_new);
            self.t = t_new;
            self.cost.steps += 1;
            true
        } else {
            false
        }
    }

    /// The current level at time t, as the recorder reads it.
    fn level(&self, t: f64) -> LevelRecord<'_> {
        LevelRecord {
            t,
            state: &self.st.cur,
            work: &self.w_cur,
            power: &self.st.p_cur,
        }
    }

    /// The new level at time t, as the recorder reads it.
    fn next_level(&self, t: f64) -> LevelRecord<'_> {
        LevelRecord {
            t,
            state: &self.st.next,
            work: &self.w_new,
            power: &self.st.p_new,
        }
    }

    /// Work at the new level by the trapezoidal rule over a step of length τ:
    /// W_new = W_cur + ½τ(P_cur + P_new).
    #[inline]
    fn book_work(&mut self, tau: f64) {
        for k in 0..self.np {
            self.w_new[k] = self.w_cur[k] + 0.5 * tau * (self.st.p_cur[k] + self.st.p_new[k]);
        }
    }

    /// The next step from the bound at t ([`choose_step`]): logs a `StepSizeChange` when τ
    /// moved by more than `ctl.log_change` since the last logged value, and keeps τ's range.
    /// Returns (τ, the method's limit).
    #[inline]
    fn next_step<S: Model>(
        &mut self,
        sys: &S,
        ctl: &StepControl,
        factor: f64,
    ) -> Result<(f64, f64), FdmError> {
        let t = self.t;
        let (tau_next, limit_next, b) = choose_step(sys, ctl, factor, t)?;
        if ((tau_next - self.tau_logged) / self.tau_logged).abs() > ctl.log_change {
            self.log.push(Event::StepSizeChange {
                t,
                from: self.tau_logged,
                to: tau_next,
                reason: format!(
                    "{} stability bound moved to {:.4e} ({}) as the mass or the hub rate changed",
                    b.kind.name(),
                    limit_next,
                    sys.describe(&b)
                ),
            });
            self.tau_logged = tau_next;
        }
        self.tau_min = self.tau_min.min(tau_next);
        self.tau_max = self.tau_max.max(tau_next);
        Ok((tau_next, limit_next))
    }

    /// The watch on the predicted level: non-finite values, the computational mode
    /// (|Δ²v| > threshold × peak |v| over the monitored coordinates), runaway growth of q
    /// (> 1e8 × its peak), then overextension. Returns the diagnostic that stops the run, or
    /// updates the peaks.
    #[inline]
    fn watch<S: Model>(
        &mut self,
        sys: &S,
        method: &dyn Stepper,
        ws: &WatchSettings,
        tau_step: f64,
        limit_next: f64,
    ) -> Option<Diagnostic> {
        let (st, mon, n) = (&self.st, &ws.mon, self.n);
        // Monitor the computational mode: |Δ²v| over the elastic coordinates. The maxima alone
        // while every value is finite (the common case: max is exact, so they equal the full
        // scan's); the full scan with the worst coordinates when anything is off.
        let new_v = method.predicted_velocity(st);
        let (mut w, clean) = Watch::maxima(mon.clone(), new_v, st);
        if !clean {
            w = Watch::scan(mon.clone(), new_v, st);
        }
        for i in 0..n {
            w.finite &= st.next.q[i].is_finite();
        }
        let step_count = self.cost.steps;
        let parasitic = step_count > 4 && w.d2 > ws.parasitic_threshold * self.peak_v;
        let runaway = w.qmax > 1e8 * self.peak_q && step_count > 4;
        if (!w.finite || parasitic || runaway) && clean {
            // the worst coordinates for the diagnostic (same maxima)
            let finite = w.finite;
            w = Watch::scan(mon.clone(), new_v, st);
            w.finite &= finite;
        }
        let Watch {
            d2,
            vmax,
            qmax,
            finite,
            worst_d2,
            worst_q,
        } = w;
        if !finite || parasitic || runaway {
            return Some(growth_diagnostic(
                sys,
                Growth {
                    t: self.t,
                    tau: tau_step,
                    limit: limit_next,
                    parasitic,
                    finite,
                    computational_mode: ws.computational_mode,
                    worst_d2,
                    worst_q,
                    d2,
                    peak_v: self.peak_v,
                },
            ));
        }
        if let Some(over) = sys.overextended(&st.next.q) {
            return Some(overextension_diagnostic(self.t + tau_step, over));
        }
        self.peak_v = self.peak_v.max(vmax);
        self.peak_q = self.peak_q.max(qmax);
        None
    }

    /// Completes the step: accelerations at the new level, an event inside the step located
    /// (the step re-taken up to it), the work booked, the sample recorded, the levels rotated,
    /// and at an event its reset applied (a new history for the watch). A step aimed at the
    /// jump `landing` that no event cut short ends exactly on it (returns true; a sample at the
    /// jump is left to the stretch it opens). `Err` stops the run with the events' verdict.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn advance<S: Model, E: Events<S>>(
        &mut self,
        sys: &mut S,
        method: &mut dyn Stepper,
        events: &mut E,
        ws: &WatchSettings,
        tau_step: f64,
        landing: Option<f64>,
        limit_next: f64,
        rec: &mut Recorder,
    ) -> Result<bool, StabilityVerdict> {
        let (t, tau) = (self.t, self.tau);
        finish_step(method, sys, t, tau, tau_step, &mut self.st);
        self.cost.rhs_evaluations += 1;
        let mut retake = Retake {
            method: &mut *method,
            t,
            tau_prev: tau,
            evaluations: 0,
        };
        let located = events.locate(sys, t, tau_step, &mut self.st, &mut retake);
        self.cost.rhs_evaluations += retake.evaluations;
        let tau_taken = located?;
        let tau_eff = tau_taken.unwrap_or(tau_step);
        let landed = landing.filter(|_| tau_taken.is_none());
        let t_new = landed.unwrap_or(t + tau_eff);
        if tau_eff > 0.0 {
            events.level_powers(sys, t_new, &self.st.next.v, &mut self.st.p_new);
        }
        events.committed(sys, tau_eff);
        self.book_work(tau_eff);
        if tau_eff > 0.0 {
            rec.record(
                sys,
                &*method,
                self.level(t),
                self.next_level(t_new),
                tau_eff,
                limit_next,
                landed.is_some(),
            );
            self.cost.steps += 1;
            // a two-step scheme whose computational mode can grow has its own, more specific
            // watch (the mode's growth drives the ledger off first)
            if !ws.computational_mode
                && self.cost.steps >= LEDGER_SETTLED_STEPS
                && rec.last_closure() > LEDGER_LOST
            {
                return Err(StabilityVerdict::Stopped {
                    diagnostic: ledger_diagnostic(t_new, rec.last_closure(), tau_eff),
                });
            }
        }
        self.st.rotate();
        std::mem::swap(&mut self.w_cur, &mut self.w_new);
        self.t = t_new;
        self.tau = tau_eff;
        if tau_taken.is_some() {
            let evaluations =
                events.apply(sys, t_new, &mut self.st, &mut self.w_cur, &mut self.log)?;
            self.cost.rhs_evaluations += evaluations;
            // a reset starts a new history for the watch: no Δ²v across it
            self.st.prev.q.copy_from_slice(&self.st.cur.q);
            self.st.prev.v.copy_from_slice(&self.st.cur.v);
            self.peak_v = self.peak_v.max(inf_norm(&self.st.cur.v[ws.mon.clone()]));
        }
        events.settled(sys, &self.st.cur);
        Ok(landed.is_some())
    }
}
