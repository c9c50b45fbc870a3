//! The driver: the loop that chooses each step, lets a [`Stepper`] take it, watches the
//! solution, samples the outputs and books the ledger.
//!
//! **Step choice.** Every step from the model's stability bound (the report's 5.45,
//! τ_{j+1} = min_i σ_i, times the method's factor and the user's safety factor), or forced by
//! the user and then checked against that bound before every step. With `lookahead` the bound
//! is also evaluated at t + τ and the smaller kept (the report evaluates σ with the masses of
//! the new level, m_{i,j+1}; right for bounds that only shrink, like a burning stage).
//!
//! **Watch.** Between the method's prediction and its force evaluation the driver checks the
//! new level: non-finite values, |Δ²v| over the monitored (elastic) coordinates against the
//! peak |v| (the computational mode of a two-step method grows as a sign-alternating
//! velocity), and runaway growth of q. It stops with a diagnostic naming the coordinate, the
//! cause and the remedy.
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
use crate::method::{StepState, Stepper, stepper};
use crate::output::{Outcome, Outputs, Recorder};
use crate::settings::{Method, ValidatedSettings};
use crate::system::{Bound, DeflectionModel, Overextension, System};

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
pub fn run<S: Model, E: Events<S>>(
    sys: &mut S,
    method: &mut dyn Stepper,
    events: &mut E,
    q0: &[f64],
    v0: &[f64],
    ctl: &StepControl,
) -> Result<Outcome, FdmError> {
    let clock = Instant::now();
    let n = sys.dofs();
    let (_, inp, dis) = sys.ledger_names();
    let np = inp.len() + dis.len();
    let factor = method.bound_factor();
    let mut rec = Recorder::new(sys, ctl.t_end, ctl.output_interval);
    let mut log = Vec::new();
    let mut cost = Cost {
        dofs: n,
        ..Cost::default()
    };

    // Levels, accelerations and powers (the method's), accumulated work at two levels.
    let mut st = StepState::new(n, np);
    let mut w_cur = vec![0.0; np];
    let mut w_new = vec![0.0; np];
    st.cur.q.copy_from_slice(q0);
    st.cur.v.copy_from_slice(v0);

    let mut t = 0.0;
    events.begin(sys, &st.cur)?;
    sys.accel(t, &st.cur.q, &st.cur.v, &mut st.acc);
    sys.powers(&mut st.p_cur);
    events.level_powers(sys, t, &st.cur.v, &mut st.p_cur);
    cost.rhs_evaluations += 1;
    let (mut tau, limit, _) = choose_step(sys, ctl, factor, t)?;
    events.first_step(tau);
    let mut tau_logged = tau;
    let (mut tau_min, mut tau_max) = (tau, tau);
    rec.record(sys, t, &st.cur, &w_cur, t, &st.cur, &w_cur, tau, limit);

    let mon = sys.monitored();
    let damped = sys.damped();
    let mut peak_v = inf_norm(&st.cur.v[mon.clone()]).max(1e-300);
    let mut peak_q = inf_norm(&st.cur.q[mon.clone()]).max(1e-300);
    let parasitic_threshold = method.parasitic_threshold();
    let two_step = method.has_computational_mode();
    let mut verdict = StabilityVerdict::Completed;

    // Start-up (a second level for the two-step forms).
    let start_evaluations = method.start(sys, t, tau, &mut st);
    if start_evaluations > 0 {
        cost.rhs_evaluations += start_evaluations;
        let t_new = t + tau;
        for k in 0..np {
            w_new[k] = w_cur[k] + 0.5 * tau * (st.p_cur[k] + st.p_new[k]);
        }
        rec.record(sys, t, &st.cur, &w_cur, t_new, &st.next, &w_new, tau, limit);
        st.rotate();
        std::mem::swap(&mut w_cur, &mut w_new);
        t = t_new;
        cost.steps += 1;
    }

    while !rec.done() {
        let (tau_next, limit_next, b) = choose_step(sys, ctl, factor, t)?;
        if ((tau_next - tau_logged) / tau_logged).abs() > ctl.log_change {
            log.push(Event::StepSizeChange {
                t,
                from: tau_logged,
                to: tau_next,
                reason: format!(
                    "{} stability bound moved to {:.4e} ({}) as the mass or the hub rate changed",
                    b.kind.name(),
                    limit_next,
                    sys.describe(&b)
                ),
            });
            tau_logged = tau_next;
        }
        tau_min = tau_min.min(tau_next);
        tau_max = tau_max.max(tau_next);
        let tau_step = match events.step_factor(t) {
            Some(f) if ctl.forced_dt.is_none() => tau_next * f,
            _ => tau_next,
        };
        method.predict(tau, tau_step, &mut st);
        // Monitor the computational mode: |Δ²v| over the elastic coordinates. The maxima alone
        // while every value is finite (the common case: max is exact, so they equal the full
        // scan's); the full scan with the worst coordinates when anything is off.
        let new_v = method.predicted_velocity(&st);
        let (mut w, clean) = Watch::maxima(mon.clone(), new_v, &st);
        if !clean {
            w = Watch::scan(mon.clone(), new_v, &st);
        }
        for i in 0..n {
            w.finite &= st.next.q[i].is_finite();
        }
        let step_count = cost.steps;
        let parasitic = step_count > 4 && w.d2 > parasitic_threshold * peak_v;
        let runaway = w.qmax > 1e8 * peak_q && step_count > 4;
        if (!w.finite || parasitic || runaway) && clean {
            // the worst coordinates for the diagnostic (same maxima)
            let finite = w.finite;
            w = Watch::scan(mon.clone(), new_v, &st);
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
            verdict = StabilityVerdict::Stopped {
                diagnostic: growth_diagnostic(
                    sys,
                    Growth {
                        t,
                        tau: tau_step,
                        limit: limit_next,
                        parasitic,
                        finite,
                        computational_mode: damped && two_step,
                        worst_d2,
                        worst_q,
                        d2,
                        peak_v,
                    },
                ),
            };
            break;
        }
        if let Some(over) = sys.overextended(&st.next.q) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: overextension_diagnostic(t + tau_step, over),
            };
            break;
        }
        peak_v = peak_v.max(vmax);
        peak_q = peak_q.max(qmax);

        // Accelerations at the new level.
        finish_step(method, sys, t, tau, tau_step, &mut st);
        cost.rhs_evaluations += 1;
        // An event inside the step: the step is re-taken up to it.
        let mut retake = Retake {
            method: &mut *method,
            t,
            tau_prev: tau,
            evaluations: 0,
        };
        let located = events.locate(sys, t, tau_step, &mut st, &mut retake);
        cost.rhs_evaluations += retake.evaluations;
        let tau_taken = match located {
            Err(stop) => {
                verdict = stop;
                break;
            }
            Ok(at) => at,
        };
        let tau_eff = tau_taken.unwrap_or(tau_step);
        let t_new = t + tau_eff;
        if tau_eff > 0.0 {
            events.level_powers(sys, t_new, &st.next.v, &mut st.p_new);
        }
        events.committed(sys, tau_eff);
        for k in 0..np {
            w_new[k] = w_cur[k] + 0.5 * tau_eff * (st.p_cur[k] + st.p_new[k]);
        }
        if tau_eff > 0.0 {
            rec.record(
                sys, t, &st.cur, &w_cur, t_new, &st.next, &w_new, tau_eff, limit_next,
            );
            cost.steps += 1;
        }
        st.rotate();
        std::mem::swap(&mut w_cur, &mut w_new);
        t = t_new;
        tau = tau_eff;
        if tau_taken.is_some() {
            match events.apply(sys, t, &mut st, &mut w_cur, &mut log) {
                Ok(evaluations) => cost.rhs_evaluations += evaluations,
                Err(stop) => {
                    verdict = stop;
                    break;
                }
            }
            // a reset starts a new history for the watch: no Δ²v across it
            st.prev.q.copy_from_slice(&st.cur.q);
            st.prev.v.copy_from_slice(&st.cur.v);
            peak_v = peak_v.max(inf_norm(&st.cur.v[mon.clone()]));
        }
        events.settled(sys, &st.cur);
    }
    cost.wall_time_s = clock.elapsed().as_secs_f64();
    Ok(Outcome {
        observables: rec.obs,
        ledger: rec.ledger,
        events: log,
        cost,
        verdict,
        tau_min,
        tau_max,
    })
}

/// The watch's scan of a new level over the monitored coordinates: max |Δ²v| of the predicted
/// velocities, max |v|, max |q|, whether they are finite, and where the maxima sit.
struct Watch {
    d2: f64,
    vmax: f64,
    qmax: f64,
    finite: bool,
    worst_d2: usize,
    worst_q: usize,
}

impl Watch {
    /// The maxima only, and whether every Δ²v and q was finite (then they equal [`Watch::scan`]'s;
    /// a finite Δ²v has finite terms). The worst coordinates are left at the range's start.
    fn maxima(mon: std::ops::Range<usize>, new_v: &[f64], st: &StepState) -> (Self, bool) {
        let (prev, cur, next) = (&st.prev.v[mon.clone()], &st.cur.v[mon.clone()], &st.next.q);
        let (nv, q) = (&new_v[mon.clone()], &next[mon.clone()]);
        // four independent lanes: the maxima's dependency chains overlap
        const L: usize = 4;
        let (mut d2, mut vmax, mut qmax) = ([0.0f64; L], [0.0f64; L], [0.0f64; L]);
        let mut clean = [true; L];
        let mut lane = |l: usize, i: usize| {
            let d = (nv[i] - 2.0 * cur[i] + prev[i]).abs();
            let (v, x) = (nv[i].abs(), q[i].abs());
            clean[l] &= d.is_finite() & x.is_finite();
            d2[l] = if d > d2[l] { d } else { d2[l] };
            vmax[l] = if v > vmax[l] { v } else { vmax[l] };
            qmax[l] = if x > qmax[l] { x } else { qmax[l] };
        };
        let m = nv.len();
        for c in 0..m / L {
            for l in 0..L {
                lane(l, c * L + l);
            }
        }
        for i in m / L * L..m {
            lane(0, i);
        }
        let max = |a: [f64; L]| a.into_iter().fold(0.0f64, |m, x| if x > m { x } else { m });
        let clean = clean.into_iter().all(|c| c);
        let w = Watch {
            d2: max(d2),
            vmax: max(vmax),
            qmax: max(qmax),
            finite: clean,
            worst_d2: mon.start,
            worst_q: mon.start,
        };
        (w, clean)
    }

    /// The full scan: non-finite values propagate into the maxima and name their coordinate.
    fn scan(mon: std::ops::Range<usize>, new_v: &[f64], st: &StepState) -> Self {
        let (prev, cur, next) = (&st.prev, &st.cur, &st.next);
        let mut w = Watch {
            d2: 0.0,
            vmax: 0.0,
            qmax: 0.0,
            finite: true,
            worst_d2: mon.start,
            worst_q: mon.start,
        };
        for i in mon {
            let nv = new_v[i];
            w.finite &= nv.is_finite() && next.q[i].is_finite();
            let d = (nv - 2.0 * cur.v[i] + prev.v[i]).abs();
            if d > w.d2 || d.is_nan() {
                w.d2 = d;
                w.worst_d2 = i;
            }
            w.vmax = w.vmax.max(nv.abs());
            if next.q[i].abs() > w.qmax || next.q[i].is_nan() {
                w.qmax = next.q[i].abs();
                w.worst_q = i;
            }
        }
        w
    }
}

/// What the watch saw when it stopped the run.
struct Growth {
    t: f64,
    tau: f64,
    limit: f64,
    /// the sign-alternating velocity grew (else q ran away or went non-finite)
    parasitic: bool,
    finite: bool,
    /// damping or velocity coupling on under a method with a computational mode
    computational_mode: bool,
    worst_d2: usize,
    worst_q: usize,
    d2: f64,
    peak_v: f64,
}

/// A link deflected beyond its length: outside the beam model, whatever the step.
fn overextension_diagnostic(t: f64, o: Overextension) -> Diagnostic {
    let (why, remedy) = match o.model {
        DeflectionModel::SmallStrain => (
            "the deflection is outside the small-strain floating-frame model",
            "reduce the load",
        ),
        DeflectionModel::Linear => (
            "the linear model (no geometric stiffening) has lost its centrifugal stiffness: \
             spinning above the first bending frequency it grows without bound",
            "switch on `foreshortening` (geometric stiffening)",
        ),
        DeflectionModel::ChordFrames => (
            "the finite-difference chain measures deflections from each link's tip chord and \
             holds only while the clamp slope against the chord stays well below 1",
            "stiffer links, smaller initial angles or joint loads, or the fem or modal backend",
        ),
    };
    Diagnostic {
        t,
        what: format!(
            "tip deflection of link {} grew to {:.3e}, beyond the link length {}",
            o.link, o.deflection, o.length
        ),
        location: Some(format!("link {} tip", o.link)),
        why: why.into(),
        remedy: remedy.into(),
    }
}

fn growth_diagnostic<S: Model + ?Sized>(sys: &S, g: Growth) -> Diagnostic {
    let Growth {
        t,
        tau,
        limit,
        parasitic,
        finite,
        computational_mode,
        worst_d2,
        worst_q,
        d2,
        peak_v,
    } = g;
    let bound_b = sys.bound(t);
    let location = if parasitic {
        format!(
            "largest sign-alternating velocity in {}",
            sys.dof_name(worst_d2)
        )
    } else {
        format!(
            "largest growth in {}; binding bound at {}",
            sys.dof_name(worst_q),
            sys.describe(&bound_b)
        )
    };
    let (what, why, remedy) = if computational_mode && finite {
        (
            "computational (parasitic) mode of the two-step central difference grew".to_string(),
            format!(
                "damping or velocity-coupled forces are on: the two-step scheme's spurious root \
                 ξ ≈ −(1 + cτ/m) has modulus > 1 for any step, so the sign-alternating mode grows \
                 (|Δ²v| = {d2:.3e} vs peak |v| = {peak_v:.3e})"
            ),
            "use --method robert-asselin (filtered two-step, limit ½(1 − ν)σ) or --method velocity-form (one-step, limit σ)".to_string(),
        )
    } else {
        (
            if finite {
                "elastic response grew without bound".to_string()
            } else {
                "non-finite state".to_string()
            },
            format!(
                "step {tau:.3e} against the method's limit {limit:.3e} ({} bound); \
                 the report's σ (5.43–5.44) is the limit of the one-step form, the two-step form needs σ/2",
                bound_b.kind.name()
            ),
            "omit --dt (the scheme then picks a stable step) or lower the safety factor"
                .to_string(),
        )
    };
    Diagnostic {
        t,
        what,
        location: Some(location),
        why,
        remedy,
    }
}

#[cfg(test)]
mod tests {
    use super::Watch;
    use crate::method::StepState;

    /// The lane-wise maxima of the common case are the full scan's, for every range length
    /// (lanes and remainder); a non-finite Δ²v or q is flagged so that the full scan decides.
    #[test]
    fn elem_watch_maxima_are_the_full_scans() {
        let n = 23;
        let mut st = StepState::new(n, 0);
        let val = |k: usize, s: f64| ((k as f64 * 0.7 + s).sin() * 1e3).round() / 7.0;
        for i in 0..n {
            st.prev.v[i] = val(i, 0.1);
            st.cur.v[i] = val(i, 1.3);
            st.next.q[i] = val(i, 2.9);
            st.pred[i] = val(i, 4.1);
        }
        for start in [0, 1, 2] {
            for end in start..=n {
                let (fast, clean) = Watch::maxima(start..end, &st.pred, &st);
                let full = Watch::scan(start..end, &st.pred, &st);
                assert!(clean && full.finite);
                assert_eq!(
                    (fast.d2, fast.vmax, fast.qmax),
                    (full.d2, full.vmax, full.qmax),
                    "{start}..{end}"
                );
            }
        }
        for bad in [f64::NAN, f64::INFINITY] {
            let mut s2 = StepState::new(n, 0);
            s2.pred.copy_from_slice(&st.pred);
            s2.next.q[n - 1] = bad;
            assert!(!Watch::maxima(0..n, &s2.pred, &s2).1);
            let mut s3 = StepState::new(n, 0);
            s3.cur.v[n - 2] = bad;
            assert!(!Watch::maxima(0..n, &s3.pred, &s3).1);
        }
    }
}
