//! The step control of the driver: one step to the next stop time or torque-law breakpoint
//! (equal steps for a method that needs them), Newton-failure and error-estimate rejections,
//! the contact events of a converged trial ([`super::contact_events`] for the unilateral
//! contact, [`super::stick_slip`] for the bilateral friction contact) and the runaway checks of
//! the accepted state (module docs of [`super`]).

use super::contact_events::Post;
use super::state::{Driver, Rejection, StopReason};
use crate::error::FemError;
use crate::events::contact::GRAZING_LOCATION;
use crate::method::Trial;

impl Driver {
    /// Rejects a fixed step of length `h`: the stretch is retried with a quarter step (grown
    /// back afterwards). `restart` drops the method's predictor — where the stretch's start
    /// state may have changed (an impact applied while locating an event).
    fn retry_quarter_step(&mut self, h: f64, why: Rejection, restart: bool) -> StopReason {
        self.counters.rejected += 1;
        self.last_rejection = why;
        self.h = 0.25 * h;
        if restart {
            self.stepper.restart();
        }
        StopReason::Rejected
    }

    /// Rejects an adaptive step of length `h` whose scaled error estimate is `err` (∞ for a
    /// Newton failure): the next trial is shorter by the step-control ratio (at least 0.2).
    fn retry_shorter(&mut self, h: f64, why: Rejection, err: f64) -> Result<StopReason, FemError> {
        self.counters.rejected += 1;
        self.last_rejection = why;
        let ratio = (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 1.0);
        self.h = h * ratio;
        if self.h < 1e-14 * self.stop.abs().max(1.0) {
            return Err(FemError::Runaway {
                t: self.state.t,
                what: "step size underflow".into(),
                location: None,
                why: "the error estimate could not be met".into(),
                remedy: "loosen --rtol or refine the mesh less".into(),
            });
        }
        Ok(StopReason::Rejected)
    }

    /// Advances by one step (or rejects one); never steps over the stop time or a breakpoint.
    pub fn step(&mut self) -> Result<StopReason, FemError> {
        let remaining = self.stop - self.state.t;
        let mut target = self.stop;
        let mut on_break = false;
        while self.next_break < self.breakpoints.len()
            && self.breakpoints[self.next_break] <= self.state.t + 1e-12 * self.h
        {
            self.next_break += 1;
        }
        if let Some(&b) = self.breakpoints.get(self.next_break)
            && b < target - 1e-12 * self.h
        {
            target = b;
        }
        let span = target - self.state.t;
        let mut h = if self.stepper.equal_steps() {
            // Equal steps between stops: near its bound (hω → 2) each velocity-Verlet step is a
            // stable but strongly non-normal map, and a periodic pattern of full steps plus one
            // short step per output interval composes into an unstable map (measured: spin-up at
            // 0.99 × 2/ω_max, 83 full + 1 short step per 0.01 s, diverged at t ≈ 0.32 s while
            // ω_max stayed constant to 1e-9). Every step is ≤ h (up to 1e-9 relative): h_nominal,
            // or the quarter step of a retried stretch while it grows back.
            let n = (span / self.h.min(self.h_nominal) * (1.0 - 1e-9))
                .ceil()
                .max(1.0);
            span / n
        } else {
            self.h.min(span)
        };
        if target - self.state.t - h <= 1e-9 * h {
            h = target - self.state.t;
        }
        if self.next_break < self.breakpoints.len()
            && (self.state.t + h - self.breakpoints[self.next_break]).abs()
                <= 1e-12 * self.h.max(1.0)
        {
            on_break = true;
        }
        debug_assert!(remaining > 0.0);
        let t1 = self.state.t + h;
        // Laws are evaluated as left limits on a step that ends on a discontinuity.
        let t_law = if on_break { t1 - 1e-9 * h } else { t1 };
        let solved = self
            .solve(h, t1, t_law)
            .map_err(|e| self.unresolved_contact_phase(e, h));
        let error = match solved? {
            Trial::NewtonFailed if self.adaptive.is_none() => {
                // Fixed step: Newton failed; retry this stretch with quarter steps, then grow back.
                return Ok(self.retry_quarter_step(h, Rejection::Newton, false));
            }
            Trial::NewtonFailed => {
                return self.retry_shorter(h, Rejection::Newton, f64::INFINITY);
            }
            Trial::Converged { error: Some(err) } if self.adaptive.is_some() && err > 1.0 => {
                return self.retry_shorter(h, Rejection::ErrorEstimate, err);
            }
            Trial::Converged { error } => error,
        };
        // Contact events are located inside the step: it may be shortened to h_acc.
        let (h_acc, post) = if self.contact.is_some() {
            match self.events_after_trial(h) {
                Ok(x) => x,
                // A shortened or constrained re-solve did not converge: retry the
                // stretch with a quarter step from the (possibly post-impact) start.
                Err(FemError::Runaway { ref location, .. })
                    if h > 1e-6 * self.h_nominal
                        && location.as_deref() != Some(GRAZING_LOCATION) =>
                {
                    return Ok(self.retry_quarter_step(h, Rejection::Newton, true));
                }
                Err(e) => return Err(e),
            }
        } else {
            (h, Post::None)
        };
        if post == Post::Refine {
            // The contact phase over this step is undetermined at this length
            // (crate::events::contact, grazing): retry the stretch with a quarter step.
            return Ok(self.retry_quarter_step(h, Rejection::ContactRefine, true));
        }
        let (h_taken, t_taken, law_taken) = if h_acc < h {
            on_break = false;
            (h_acc, self.state.t + h_acc, self.state.t + h_acc)
        } else {
            (h, t1, t_law)
        };
        self.accept(h_taken, t_taken, law_taken);
        if self.contact.is_some() {
            self.events_after_accept(post)?;
        }
        if self.adaptive.is_none() {
            self.h = (2.0 * self.h).min(self.h_nominal);
        }
        if let (Some(e), Some(_)) = (error, self.adaptive) {
            let ratio = (0.9 * e.max(1e-10).powf(-1.0 / 3.0)).clamp(0.2, 2.0);
            // Do not let a short step that landed on a stop time shrink the next one.
            if h_taken >= 0.5 * self.h {
                self.h = h_taken * ratio;
            } else {
                self.h = self.h.max(h_taken * ratio);
            }
        }
        if on_break {
            // Restart from the discontinuity with the new law value.
            self.initial_acceleration(self.state.t)?;
            self.stepper.restart();
        }
        self.check_state()?;
        if (self.stop - self.state.t).abs() <= 1e-9 * h {
            self.state.t = self.stop;
            Ok(StopReason::ReachedStop)
        } else {
            Ok(StopReason::Stepped)
        }
    }

    fn check_state(&self) -> Result<(), FemError> {
        if let Some(i) = self
            .state
            .q
            .iter()
            .chain(&self.state.qd)
            .position(|x| !x.is_finite())
        {
            let dof = i % self.state.q.len();
            return Err(FemError::Runaway {
                t: self.state.t,
                what: "non-finite state".into(),
                location: Some(self.chain.describe_dof(dof)),
                why: "the integration diverged".into(),
                remedy: "reduce --dt or use generalized-alpha".into(),
            });
        }
        for (li, l) in self.chain.links.iter().enumerate() {
            let v = self.chain.tip_deflection(li, &self.state.q);
            if v.abs() > l.length {
                let model = if l.foreshortening || l.axial {
                    "the deflection is outside the small-strain floating-frame model"
                } else {
                    "the linear model (no geometric stiffening) has lost its centrifugal stiffness: \
                     spinning above the first bending frequency it grows without bound"
                };
                return Err(FemError::Runaway {
                    t: self.state.t,
                    what: format!(
                        "tip deflection of link {} grew to {v:.3e}, beyond the link length {}",
                        li + 1,
                        l.length
                    ),
                    location: Some(format!("link {} tip", li + 1)),
                    why: model.into(),
                    remedy: if l.foreshortening || l.axial {
                        "reduce the load or the step".into()
                    } else {
                        "switch on `foreshortening` or `axial` (geometric stiffening)".into()
                    },
                });
            }
        }
        Ok(())
    }

    /// Whether the scene's contact is the bilateral friction contact (stick–slip events).
    fn bilateral(&self) -> bool {
        self.contact
            .as_deref()
            .expect("contact integrator without a contact")
            .bilateral
            .is_some()
    }

    /// Event handling after a converged trial step of length h (state in q₁, q̇₁): returns the
    /// step length to accept (the trial for it solved) and what to do after accepting it.
    fn events_after_trial(&mut self, h: f64) -> Result<(f64, Post), FemError> {
        if self.bilateral() {
            self.bilateral_after_trial(h)
        } else {
            self.contact_after_trial(h)
        }
    }

    /// Applies the events of an accepted step at the new state.
    fn events_after_accept(&mut self, post: Post) -> Result<(), FemError> {
        if self.bilateral() {
            self.bilateral_after_accept()
        } else {
            self.contact_after_accept(post)
        }
    }
}
