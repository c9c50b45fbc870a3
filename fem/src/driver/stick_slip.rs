//! Stick–slip switching of the bilateral friction contact in the driver: the friction-sign
//! check of a step, the slip-stop and breakaway event functions located inside the step, and
//! the Coulomb test at a switch (rules in [`crate::events::contact::friction`]).

use data::Event;

use crate::driver::Driver;
use crate::driver::contact_events::Post;
use crate::error::FemError;
use crate::events::contact::friction::{
    Forces, MIN_TRIAL, STICK_VT_TOL, Switch, VT_TOL, sign, sticking,
};
use crate::events::contact::{Contact, MAX_EVENTS};
use crate::events::wall::row_along;
use crate::linalg::dot;
use crate::method::Trial;

impl Driver {
    fn with_bilateral<R>(
        &mut self,
        f: impl FnOnce(&mut Self, &mut Contact) -> Result<R, FemError>,
    ) -> Result<R, FemError> {
        let Some(mut c) = self.contact.take() else {
            return Err(FemError::Numerical {
                t: self.state.t,
                message: "bilateral contact missing".into(),
            });
        };
        let out = f(self, &mut c);
        self.contact = Some(c);
        out
    }

    /// Index-1 forces at (q, q̇) (`end`: the trial end q₁, q̇₁ at t₁; else the current state).
    fn contact_forces(&mut self, end: bool, t: f64, held: bool) -> Result<Forces, FemError> {
        self.with_bilateral(|s, c| {
            let link = c.constraint.link;
            let b = c.bilateral.as_deref_mut().expect("bilateral contact");
            let (q, qd) = if end {
                (&s.state.q1, &s.state.qd1)
            } else {
                (&s.state.q, &s.state.qd)
            };
            let out = b.forces(&mut s.chain, link, t, q, qd, held);
            s.counters.rhs += s.chain.ndof + 2;
            out
        })
    }

    /// Sets up the bilateral contact at t = 0: the tip must start on the wall; forces, and the
    /// Coulomb test that decides the initial phase (module docs).
    pub fn bilateral_start(&mut self) -> Result<(), FemError> {
        let t = self.state.t;
        let Some(c) = self.contact.as_deref_mut() else {
            return Ok(());
        };
        if c.bilateral.is_none() {
            return Ok(());
        }
        c.phase.constrained = true;
        c.phase.gap = c.gap_at(&self.chain, t, &self.state.q);
        if c.phase.gap.abs() > c.phase.gap_tol {
            return Err(FemError::InvalidSettings {
                field: "contact".into(),
                message: format!(
                    "the tip starts {:.3e} off the surface of the bilateral contact (tolerance \
                     {:.1e})",
                    c.phase.gap, c.phase.gap_tol
                ),
            });
        }
        let mu = c.bilateral.as_deref().map_or(0.0, |b| b.constraint.mu);
        let vt_tol = VT_TOL * self.length_scale;
        let held = self.contact_forces(false, t, true)?;
        let c = self.contact.as_deref_mut().expect("contact");
        let b = c.bilateral.as_deref_mut().expect("bilateral");
        let mut sticking = false;
        if mu > 0.0 {
            if held.vt.abs() <= vt_tol && held.lambda_t.abs() <= mu * held.lambda_n.abs() {
                sticking = true;
            } else {
                b.phase.slip_dir = if held.vt.abs() > vt_tol {
                    sign(held.vt)
                } else {
                    -sign(held.lambda_t)
                };
            }
            c.record.n_events += 1;
            c.record.events.push(Event::StickSlip {
                t,
                contact: 1,
                sticking,
            });
        }
        if sticking {
            b.phase.sticking = true;
            b.constraint.stick_point = held.tip;
            b.constraint.stick_tangent = held.tangent;
            b.constraint.step_lambda_t = held.lambda_t;
        }
        self.record_state()
    }

    /// Index-1 forces at the current state for the current phase, stored in
    /// the contact; Painlevé stop; the event function for the next step.
    fn record_state(&mut self) -> Result<(), FemError> {
        let t = self.state.t;
        let sticking = sticking(self.contact.as_deref().expect("contact"));
        let fr = self.contact_forces(false, t, sticking)?;
        let c = self.contact.as_deref_mut().expect("contact");
        let b = c.bilateral.as_deref_mut().expect("bilateral");
        c.phase.lambda = fr.lambda_n;
        c.phase.gap = fr.gap;
        c.phase.normal_velocity = fr.vn;
        c.record.max_gap = c.record.max_gap.max(fr.gap.abs());
        c.record.max_normal_velocity = c.record.max_normal_velocity.max(fr.vn.abs());
        b.phase.friction_force = fr.lambda_t;
        b.phase.slip_velocity = fr.vt;
        if b.phase.sticking {
            let (ts, ps) = (b.constraint.stick_tangent, b.constraint.stick_point);
            let off = ts.dot(&(fr.tip - ps));
            b.record.max_stick_offset = b.record.max_stick_offset.max(off.abs());
            b.record.max_stick_velocity = b.record.max_stick_velocity.max(fr.vt.abs());
            b.phase.e0 = b.constraint.mu * fr.lambda_n.abs() - fr.lambda_t.abs();
        } else {
            if b.constraint.mu > 0.0 {
                b.record.min_painleve_margin = b
                    .record
                    .min_painleve_margin
                    .min((fr.gmg - b.constraint.mu * fr.gmt.abs()) / fr.gmg);
                if fr.painleve {
                    return Err(FemError::Runaway {
                        t,
                        what: "Painlevé paradox of the friction contact".into(),
                        location: Some("contact1".into()),
                        why: format!(
                            "G M⁻¹Gᵀ = {:.4e} ≤ μ|G M⁻¹Tᵀ| = {:.4e}: the sliding normal force \
                             has no or several solutions",
                            fr.gmg,
                            b.constraint.mu * fr.gmt.abs()
                        ),
                        remedy: "no consistent Coulomb solution in this model; reduce μ".into(),
                    });
                }
                if fr.lambda_n != 0.0 {
                    b.phase.sigma = sign(fr.lambda_n);
                }
            }
            b.phase.e0 = b.phase.slip_dir * fr.vt;
        }
        if b.phase.fresh {
            // Newton predictor of a new phase: the index-1 value.
            c.constraint.step_lambda = fr.lambda_n;
        }
        Ok(())
    }

    /// Re-solves the current step of length h (phase as set); a Newton failure is an error.
    fn bilateral_solve(&mut self, h: f64) -> Result<(), FemError> {
        let t1 = self.state.t + h;
        if self.solve(h, t1, t1)? == Trial::NewtonFailed {
            return Err(FemError::Runaway {
                t: self.state.t,
                what: format!("Newton failed on a friction-contact step (h = {h:.3e})"),
                location: Some("contact1".into()),
                why: "the re-solved step did not converge".into(),
                remedy: "reduce --dt".into(),
            });
        }
        self.sigma_check(h)
    }

    /// Sliding: the converged mean multiplier must have the sign σ the friction term assumed;
    /// else the step is re-solved once with σ flipped (module docs).
    fn sigma_check(&mut self, h: f64) -> Result<(), FemError> {
        let c = self.contact.as_deref_mut().expect("contact");
        let tiny = c.phase.force_tol;
        let lam = c.constraint.step_lambda;
        let b = c.bilateral.as_deref_mut().expect("bilateral");
        if b.phase.sticking
            || b.constraint.mu == 0.0
            || lam * b.phase.sigma >= 0.0
            || lam.abs() <= tiny
        {
            return Ok(());
        }
        b.phase.sigma = -b.phase.sigma;
        let t1 = self.state.t + h;
        let failed = self.solve(h, t1, t1)? == Trial::NewtonFailed;
        let c = self.contact.as_deref_mut().expect("contact");
        let lam2 = c.constraint.step_lambda;
        let sigma = c.bilateral.as_deref().map_or(1.0, |b| b.phase.sigma);
        if failed || (lam2 * sigma < 0.0 && lam2.abs() > tiny) {
            return Err(FemError::Runaway {
                t: self.state.t,
                what: "no consistent Coulomb solution of the friction step".into(),
                location: Some("contact1".into()),
                why: format!(
                    "the step's normal multiplier changes sign with the assumed friction sign \
                     (λ̄ = {lam:.4e} with σ = {:.0}, {lam2:.4e} with σ = {sigma:.0}): \
                     Painlevé-type inconsistency",
                    -sigma
                ),
                remedy: "reduce --dt; if it persists the model has no Coulomb solution".into(),
            });
        }
        Ok(())
    }

    /// Event function of `kind` at the end of the trial step just solved.
    fn switch_value(&mut self, kind: Switch, t1: f64) -> Result<f64, FemError> {
        match kind {
            Switch::SlipStop => self.with_bilateral(|s, c| {
                let link = c.constraint.link;
                let b = c.bilateral.as_deref_mut().expect("bilateral");
                let r = s
                    .chain
                    .tip_jacobian(t1, link, &s.state.q1, &mut b.constraint.jac);
                let f = b.constraint.wall.frame(r);
                row_along(f.tangent, &b.constraint.jac, &mut b.constraint.t_row);
                Ok(b.phase.slip_dir * dot(&b.constraint.t_row, &s.state.qd1))
            }),
            Switch::Breakaway => {
                let fr = self.contact_forces(true, t1, true)?;
                let mu = self
                    .contact
                    .as_deref()
                    .and_then(|c| c.bilateral.as_deref())
                    .map_or(0.0, |b| b.constraint.mu);
                Ok(mu * fr.lambda_n.abs() - fr.lambda_t.abs())
            }
        }
    }

    fn switch_trial(&mut self, kind: Switch, h: f64) -> Result<f64, FemError> {
        self.bilateral_solve(h)?;
        self.switch_value(kind, self.state.t + h)
    }

    /// Zero of the event function inside the step (F(0) > 0, F(h) = f1 ≤ 0) by
    /// [`Driver::illinois_on_step`], to −tol ≤ F ≤ 0 or a bracket below
    /// [`crate::events::contact::TIME_TOL`]; leaves the accepted trial solved and returns
    /// (h*, bracket width). Trial steps are never shorter than
    /// [`MIN_TRIAL`]·h: on a step of length h → 0 the constraint g(q₁) = 0, met only to the
    /// Newton tolerance ε at q₀, takes a multiplier ~ε/h² and the event function jumps by
    /// ~ε/h (measured: λ̄ = 5e12 N on a 7e-15 s trial). A root inside that first fraction is
    /// returned as None: the switch is made at the step start.
    fn locate_switch(
        &mut self,
        kind: Switch,
        h: f64,
        f1: f64,
        tol: f64,
    ) -> Result<Option<(f64, f64)>, FemError> {
        let h_min = MIN_TRIAL * h;
        let f_min = self.switch_trial(kind, h_min)?;
        if f_min <= 0.0 {
            return Ok(None);
        }
        let loc =
            self.illinois_on_step((h_min, f_min), (h, f1), tol, false, false, None, |s, c| {
                s.switch_trial(kind, c)
            })?;
        if !loc.solved {
            self.switch_trial(kind, loc.h)?;
        }
        Ok(Some((loc.h, loc.width)))
    }

    /// Bilateral counterpart of [`Driver::contact_after_trial`]: the friction sign check,
    /// then the stick–slip event of the phase, located inside the step.
    pub(crate) fn bilateral_after_trial(&mut self, h: f64) -> Result<(f64, Post), FemError> {
        let t1 = self.state.t + h;
        let c = self.contact.as_deref_mut().expect("contact");
        if c.record.n_events >= MAX_EVENTS {
            return Err(FemError::Runaway {
                t: self.state.t,
                what: format!("{} stick–slip events", c.record.n_events),
                location: Some("contact1".into()),
                why: "stick–slip transitions accumulate".into(),
                remedy: "shorten t_end or add damping".into(),
            });
        }
        self.sigma_check(h)?;
        let t0 = self.state.t;
        let c = self.contact.as_deref_mut().expect("contact");
        let force_tol = c.phase.force_tol;
        let b = c.bilateral.as_deref_mut().expect("bilateral");
        b.phase.pending = None;
        if b.constraint.mu == 0.0 {
            return Ok((h, Post::None));
        }
        if !b.phase.sticking && b.phase.fresh && b.constraint.pending_work < 0.0 {
            // First step of a slide whose tip moved against s: friction would have done
            // negative work. The discrete Coulomb choice: the tip sticks for this step (held
            // at its start position; the held-tip constraint does no work).
            let held = self.contact_forces(false, t0, true)?;
            let c = self.contact.as_deref_mut().expect("contact");
            let b = c.bilateral.as_deref_mut().expect("bilateral");
            b.phase.sticking = true;
            b.constraint.stick_point = held.tip;
            b.constraint.stick_tangent = held.tangent;
            b.constraint.step_lambda_t = held.lambda_t;
            b.record.inconsistent_slides += 1;
            c.record.n_events += 1;
            c.record.events.push(Event::StickSlip {
                t: t0,
                contact: 1,
                sticking: true,
            });
            self.stepper.restart();
            self.bilateral_solve(h)?;
        }
        loop {
            let c = self.contact.as_deref_mut().expect("contact");
            let b = c.bilateral.as_deref_mut().expect("bilateral");
            let (kind, tol) = if b.phase.sticking {
                (Switch::Breakaway, force_tol)
            } else {
                (Switch::SlipStop, VT_TOL * self.length_scale)
            };
            let f0 = b.phase.e0;
            let located = !b.phase.fresh && f0 > 0.0;
            let f1 = self.switch_value(kind, t1)?;
            if f1 > 0.0 {
                return Ok((h, Post::None));
            }
            let found = if located {
                self.locate_switch(kind, h, f1, tol)?
            } else {
                // First step of a phase: not shortened (the one-step rule, module docs), the
                // switch is made at its end.
                Some((h, 0.0))
            };
            let Some((h_acc, width)) = found else {
                // The root lies within the first MIN_TRIAL of the step: switch at its start
                // and re-solve the step in the new phase (whose first step is not shortened).
                self.apply_switch(kind, true)?;
                self.record_state()?;
                self.bilateral_solve(h)?;
                continue;
            };
            let b = self
                .contact
                .as_deref_mut()
                .and_then(|c| c.bilateral.as_deref_mut())
                .expect("bilateral");
            b.phase.pending = Some((kind, width, located));
            return Ok((h_acc, Post::None));
        }
    }

    /// Books the accepted step (friction work, tangential multiplier), applies a located
    /// switch at the new state and records the forces there.
    pub(crate) fn bilateral_after_accept(&mut self) -> Result<(), FemError> {
        let c = self.contact.as_deref_mut().expect("contact");
        let b = c.bilateral.as_deref_mut().expect("bilateral");
        b.record.friction_work += b.constraint.pending_work;
        b.constraint.pending_work = 0.0;
        if b.phase.sticking {
            b.constraint.step_lambda_t = b.constraint.lt_eval;
        }
        b.phase.fresh = false;
        let Some((kind, _width, located)) = b.phase.pending.take() else {
            return self.record_state();
        };
        self.apply_switch(kind, located)?;
        self.record_state()
    }

    /// Switch of `kind` at the current state (q, q̇ at t): the Coulomb test with the held-tip
    /// forces (module docs), event, midpoint restart. `located`: the state is a located zero
    /// of the event function (else the end of a first step, where a tip still moving slides
    /// on in its direction of motion).
    fn apply_switch(&mut self, kind: Switch, located: bool) -> Result<(), FemError> {
        let t = self.state.t;
        let held = self.contact_forces(false, t, true)?;
        let vt_tol = STICK_VT_TOL * self.length_scale;
        let c = self.contact.as_deref_mut().expect("contact");
        let b = c.bilateral.as_deref_mut().expect("bilateral");
        let mu = b.constraint.mu;
        b.phase.fresh = true;
        let moving = !located && held.vt.abs() > vt_tol;
        let stick =
            kind == Switch::SlipStop && !moving && held.lambda_t.abs() <= mu * held.lambda_n.abs();
        if moving && kind == Switch::SlipStop {
            b.phase.slip_dir = sign(held.vt);
            b.record.reversals += 1;
        } else if stick {
            b.phase.sticking = true;
            b.constraint.stick_point = held.tip;
            b.constraint.stick_tangent = held.tangent;
            b.constraint.step_lambda_t = held.lambda_t;
        } else {
            let s = -sign(held.lambda_t);
            if kind == Switch::SlipStop && s != b.phase.slip_dir {
                b.record.reversals += 1;
            }
            b.phase.slip_dir = s;
            b.phase.sticking = false;
        }
        if kind == Switch::Breakaway || stick {
            c.record.n_events += 1;
            c.record.events.push(Event::StickSlip {
                t,
                contact: 1,
                sticking: stick,
            });
        }
        self.stepper.restart();
        Ok(())
    }
}
