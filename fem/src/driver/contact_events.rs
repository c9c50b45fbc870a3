//! Unilateral contact events in the driver: the gap and the normal force located inside the
//! step (Illinois secant on the step length, each value a re-solved shortened step, an impact's
//! first point the gap's root on the method's continuous extension of the step), and the
//! resets applied at the located state (impact map, release, drift projection) by the contact
//! object [`crate::events::contact::Contact`] (its module docs state the rules).

use data::Event;

use crate::driver::Driver;
use crate::error::FemError;
use crate::events::contact::{
    Contact, FORCE_TOL, GRAZING_FORCE_LIMIT, GRAZING_LOCATION, MAX_EVENTS, REFINE_MIN, TIME_TOL,
};
use crate::method::Trial;

/// Secant iterations at most per located event.
const MAX_SECANT: usize = 80;

/// What happens after the (possibly shortened) step is accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Post {
    None,
    /// The gap reached zero at the step end: contact start and impact.
    Impact {
        time_tolerance: f64,
    },
    /// The normal force reached zero at the step end.
    Release {
        time_tolerance: f64,
    },
    /// The contact phase over the step is not determined at this step length (module docs,
    /// "Grazing"): retry the stretch with a quarter step.
    Refine,
}

/// Which event function a trial step is measured by.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Watch {
    Gap,
    Force,
}

/// Outcome of [`Driver::illinois_on_step`]: the step length h reached (the bracket end
/// b ≥ root, or an accepted trial), the width of the bracket that holds the root, whether the
/// event function met its tolerance at h (`exact`, trial solved) and whether the last solved
/// trial is h.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Located {
    pub h: f64,
    pub width: f64,
    pub exact: bool,
    pub solved: bool,
}

impl Driver {
    fn contact_mut(&mut self) -> &mut Contact {
        self.contact
            .as_deref_mut()
            .expect("contact integrator without a contact")
    }

    /// Event function at the end of the trial step just solved (q₁, q̇₁ at t₁).
    fn event_value(&mut self, watch: Watch, t1: f64) -> Result<f64, FemError> {
        let Some(mut c) = self.contact.take() else {
            return Ok(0.0);
        };
        let out = match watch {
            Watch::Gap => Ok(c.gap_at(&self.chain, t1, &self.state.q1)),
            Watch::Force => c
                .state_force(
                    &mut self.chain,
                    self.massless.as_mut(),
                    t1,
                    &self.state.q1,
                    &self.state.qd1,
                )
                .map(|(l, _, passes)| {
                    self.counters.rhs += passes;
                    c.phase.lambda = l;
                    l
                }),
        };
        self.contact = Some(c);
        out
    }

    /// Solves the step of length h from the current state (phase as set) and returns the event
    /// function at its end; a Newton failure is an error here (the full step converged).
    fn trial(&mut self, watch: Watch, h: f64) -> Result<f64, FemError> {
        let t1 = self.state.t + h;
        match self.solve(h, t1, t1)? {
            Trial::NewtonFailed => Err(FemError::Runaway {
                t: self.state.t,
                what: format!("Newton failed on a shortened step (h = {h:.3e}) locating an event"),
                location: Some("contact1".into()),
                why: "the event-location step did not converge".into(),
                remedy: "reduce --dt".into(),
            }),
            _ => self.event_value(watch, t1),
        }
    }

    /// The gap at t₀ + `theta`·h on the method's continuous extension of the trial step of
    /// length h just solved ([`crate::method::Stepper::dense`]): no step is re-solved.
    fn dense_gap(&mut self, h: f64, theta: f64) -> f64 {
        let (q, qd) = (&mut self.dense.0, &mut self.dense.1);
        self.stepper.dense(&self.state, h, theta, q, qd);
        let c = self.contact.as_deref().expect("contact run");
        c.gap_at(&self.chain, self.state.t + theta * h, q)
    }

    /// Where the gap's root lies on the continuous extension of the trial step of length h just
    /// solved (gap g0 > 0 at its start a, g1 < 0 at its end h), to the gap tolerance: the first
    /// point of the impact's location on re-solved steps, which then needs fewer of them. The
    /// gap is kinematic, and the extension's error is of the order of the step's own (third
    /// order against the methods' second), so the re-solved gap at the seed lies within about
    /// the step's local error of zero. The normal force has no such seed: the force at the end
    /// of a re-solved shorter step is not the force on the extension (the constrained
    /// trajectory's stiff components respond to the step length), so a release is located on
    /// re-solved steps from the secant.
    fn dense_seed(
        &mut self,
        (a, g0): (f64, f64),
        (h, g1): (f64, f64),
        tol: f64,
    ) -> Result<f64, FemError> {
        let located = self.illinois_on_step((a, g0), (h, g1), tol, true, false, None, |s, c| {
            Ok(s.dense_gap(h, c / h))
        })?;
        Ok(located.h)
    }

    /// Illinois secant on the step length for the root of an event function F(h), each value a
    /// re-solved shortened step (`trial`): F(a) = fa > 0, F(b) = fb ≤ 0, F decreasing through
    /// the root. Stops at a trial with −tol ≤ F ≤ 0 (or 0 < F ≤ tol when `accept_positive`),
    /// which is left solved (`Located::exact`), or when the bracket is narrower than
    /// [`TIME_TOL`]·max(t, 1); `b_solved` says whether the last trial solved is b (true on
    /// entry if F(b) was the last evaluation); `first`, when given, replaces the first secant
    /// point (a root estimated without re-solving: [`Driver::dense_seed`]). A trial whose
    /// Newton iteration fails is replaced by other points of the bracket (its midpoint, then
    /// its quarter points).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn illinois_on_step(
        &mut self,
        (mut a, mut fa): (f64, f64),
        (mut b, mut fb): (f64, f64),
        tol: f64,
        accept_positive: bool,
        mut b_solved: bool,
        mut first: Option<f64>,
        mut trial: impl FnMut(&mut Self, f64) -> Result<f64, FemError>,
    ) -> Result<Located, FemError> {
        let mut side = 0i32;
        for _ in 0..MAX_SECANT {
            if b - a <= TIME_TOL * self.state.t.abs().max(1.0) {
                break;
            }
            let margin = 1e-6 * (b - a);
            let mut c = first.take().unwrap_or(b - fb * (b - a) / (fb - fa));
            if !c.is_finite() {
                c = 0.5 * (a + b);
            }
            c = c.clamp(a + margin, b - margin);
            let mut fc = trial(self, c);
            for frac in [0.5, 0.75, 0.25, 0.9] {
                if fc.is_ok() {
                    break;
                }
                c = a + frac * (b - a);
                fc = trial(self, c);
            }
            let fc = fc?;
            if fc <= 0.0 {
                b = c;
                fb = fc;
                b_solved = true;
                if fc >= -tol {
                    return Ok(Located {
                        h: b,
                        width: b - a,
                        exact: true,
                        solved: true,
                    });
                }
                if side == -1 {
                    fa *= 0.5;
                }
                side = -1;
            } else {
                if accept_positive && fc <= tol {
                    // The root lies in [c, b].
                    return Ok(Located {
                        h: c,
                        width: b - c,
                        exact: true,
                        solved: true,
                    });
                }
                a = c;
                fa = fc;
                b_solved = false;
                if side == 1 {
                    fb *= 0.5;
                }
                side = 1;
            }
        }
        Ok(Located {
            h: b,
            width: b - a,
            exact: false,
            solved: b_solved,
        })
    }

    /// Locates the root of a unilateral event function (gap or normal force) inside the step
    /// [a0, h] (F(a0) = f0 > 0, F(h) = f1 ≤ 0): to |F| ≤ tol (either side for the gap, the
    /// non-positive side for the force) or a bracket narrower than [`TIME_TOL`]. The gap's
    /// search starts at its root on the method's continuous extension ([`Driver::dense_seed`]),
    /// the force's at the secant. Leaves the accepted trial solved in q₁, q̇₁ and returns
    /// (h*, bracket width).
    fn locate(
        &mut self,
        watch: Watch,
        a0: f64,
        h: f64,
        f0: f64,
        f1: f64,
        tol: f64,
    ) -> Result<(f64, f64), FemError> {
        let gap = watch == Watch::Gap;
        let seed = if gap {
            Some(self.dense_seed((a0, f0), (h, f1), tol)?)
        } else {
            None
        };
        let loc = self.illinois_on_step((a0, f0), (h, f1), tol, gap, true, seed, |s, c| {
            s.trial(watch, c)
        })?;
        let (width, mut b) = (loc.width, loc.h);
        if loc.exact {
            return Ok((b, width));
        }
        if !loc.solved {
            let mut fb = self.trial(watch, b)?;
            // The re-solved bracket end can land on the other side by the Newton noise of the
            // event function: widen towards the full step, where F(h) ≤ 0 was measured, until
            // it does not.
            let mut k = 0;
            while fb > 0.0 && b < h && k < 20 {
                b = (b + width * 4f64.powi(k)).min(h);
                fb = self.trial(watch, b)?;
                k += 1;
            }
            return Ok((b, b - (loc.h - width)));
        }
        Ok((b, width))
    }

    /// A method's failure without a location (a Newton iteration that did not converge at
    /// the shortest step it retries, 1e-6 of the nominal one) stopping a run with a unilateral
    /// contact: at such lengths the step meets a contact phase it cannot resolve, the grazing
    /// contact of the module docs, so the diagnostic names that cause and its remedy for the
    /// chain, not the generic "reduce --dt". Measured: `barhorst-case1-timoshenko` at 6
    /// elements, dt 1.25e-4, a grazing stretch refined to 2e-9 s steps, then an impact and a
    /// release whose normal force jumps to −2.2e9 within 1e-15 s (docs/contact.md).
    pub(crate) fn unresolved_contact_phase(&self, e: FemError, h: f64) -> FemError {
        match e {
            FemError::Runaway {
                t,
                what,
                location: None,
                ..
            } if self.newton.unilateral_contact => {
                let massless = self.chain.has_massless_dofs();
                FemError::Runaway {
                    t,
                    what: format!(
                        "{what} at the shortest step ({h:.1e} s) through a contact phase"
                    ),
                    location: Some(GRAZING_LOCATION.into()),
                    why: grazing_why(massless).into(),
                    remedy: grazing_remedy(massless).into(),
                }
            }
            e => e,
        }
    }

    /// Unilateral events after a converged trial step of length h (state in q₁, q̇₁): returns
    /// the step length to accept (the trial for it solved) and what to do after accepting it.
    pub(crate) fn contact_after_trial(&mut self, h: f64) -> Result<(f64, Post), FemError> {
        let (t0, t1) = (self.state.t, self.state.t + h);
        let c = self.contact_mut();
        if c.record.n_events >= MAX_EVENTS {
            return Err(FemError::Runaway {
                t: t0,
                what: format!("{} contact events", c.record.n_events),
                location: Some("contact1".into()),
                why: "impacts and releases accumulate (Zeno-like)".into(),
                remedy: "shorten t_end or add damping".into(),
            });
        }
        let tol_g = c.phase.gap_tol;
        let constrained = c.phase.constrained;
        let refine_min = REFINE_MIN * self.h_nominal;
        if !constrained {
            let g0 = self.contact_mut().phase.gap;
            let g1 = self.event_value(Watch::Gap, t1)?;
            if g1 >= -tol_g {
                self.contact_mut().flush_pending();
                return Ok((h, Post::None));
            }
            if g0 > tol_g {
                self.contact_mut().flush_pending();
                let (hs, width) = self.locate(Watch::Gap, 0.0, h, g0, g1, tol_g)?;
                return Ok((
                    hs,
                    Post::Impact {
                        time_tolerance: width,
                    },
                ));
            }
            // Grazing: the step starts on the surface and ends below it, with no flight above
            // the gap tolerance at its end. Shorter steps first (the flight after a release,
            // or the return to the surface, is then resolved); at the shortest step the tip
            // does not leave the surface: a release just located there is withdrawn, else the
            // contact starts at the step start (module docs).
            if h > refine_min {
                return Ok((h, Post::Refine));
            }
            let mut c = self.contact.take().expect("contact");
            if c.phase.pending_release.take().is_none() {
                c.push(Event::ContactStart {
                    t: t0,
                    contact: 1,
                    time_tolerance: 0.0,
                });
            }
            let res = c.impact(
                &mut self.chain,
                self.massless.as_mut(),
                t0,
                &self.state.q,
                &mut self.state.qd,
            );
            let res = res.and_then(|e| {
                if let Some(e) = e {
                    c.push(e);
                }
                c.state_force(
                    &mut self.chain,
                    self.massless.as_mut(),
                    t0,
                    &self.state.q,
                    &self.state.qd,
                )
            });
            c.phase.constrained = true;
            if let Ok((l, _, _)) = res {
                c.phase.lambda = l;
                c.constraint.step_lambda = l.max(0.0);
            }
            self.contact = Some(c);
            res?;
            self.stepper.restart();
            if self.solve(h, t1, t1)? == Trial::NewtonFailed {
                return Err(FemError::Runaway {
                    t: t0,
                    what: "Newton failed on the constrained step of a grazing contact".into(),
                    location: Some("contact1".into()),
                    why: "the constrained step did not converge".into(),
                    remedy: "reduce --dt".into(),
                });
            }
        }
        // Constrained: the normal force at the step end decides.
        let lam0 = self.contact_mut().phase.lambda;
        let lam1 = self.event_value(Watch::Force, t1)?;
        if lam1 > 0.0 {
            return Ok((h, Post::None));
        }
        let tol_f = self.contact_mut().phase.force_tol;
        if lam0 > 0.0 {
            let (hs, width) = self.locate(Watch::Force, 0.0, h, lam0, lam1, tol_f)?;
            return Ok((
                hs,
                Post::Release {
                    time_tolerance: width,
                },
            ));
        }
        // A constrained phase whose start force is not positive (grazing): the force does not
        // cross zero inside the step. Shorter steps first; at the shortest step the tip is
        // released at its end, the force there reported (module docs).
        if h > refine_min {
            return Ok((h, Post::Refine));
        }
        let c = self.contact_mut();
        if -lam1 > GRAZING_FORCE_LIMIT * c.phase.force_tol / FORCE_TOL {
            // Far from zero: the free motion and the normal force contradict each other at the
            // shortest step (module docs, "Grazing"): stop rather than release there.
            return Err(FemError::Runaway {
                t: t0,
                what: format!(
                    "grazing contact undetermined down to the shortest step ({h:.1e} s): the \
                     free motion enters the surface while the normal force is {lam1:.3e}"
                ),
                location: Some(GRAZING_LOCATION.into()),
                why: grazing_why(self.chain.has_massless_dofs()).into(),
                remedy: grazing_remedy(self.chain.has_massless_dofs()).into(),
            });
        }
        Ok((h, Post::Release { time_tolerance: h }))
    }

    /// Records the drift of an accepted constrained step and applies the located unilateral
    /// event at the new state.
    pub(crate) fn contact_after_accept(&mut self, post: Post) -> Result<(), FemError> {
        let t = self.state.t;
        let Some(mut c) = self.contact.take() else {
            return Ok(());
        };
        let out = self.apply_post(&mut c, t, post);
        self.contact = Some(c);
        out
    }

    fn apply_post(&mut self, c: &mut Contact, t: f64, post: Post) -> Result<(), FemError> {
        if c.phase.constrained {
            // Drift of the step end (gap and G q̇ of the state-force evaluation there); at a
            // release the velocity is projected onto G q̇ = 0 if the tip moves inward (module
            // docs).
            c.phase.drift_velocity = c.phase.normal_velocity;
            c.record.max_gap = c.record.max_gap.max(c.phase.gap.abs());
            c.record.max_normal_velocity = c
                .record
                .max_normal_velocity
                .max(c.phase.drift_velocity.abs());
            if matches!(post, Post::Release { .. } | Post::None) {
                // Drift control: G q̇ = 0 at the start of every constrained step, so that the
                // state force of a shortened step (the release event function) is continuous
                // in h and the step multiplier stays finite as h → 0.
                let inward_only = post != Post::None;
                let (loss, passes) = c.project(
                    &mut self.chain,
                    self.massless.as_mut(),
                    t,
                    &self.state.q,
                    &mut self.state.qd,
                    inward_only,
                )?;
                self.counters.rhs += passes + 1;
                c.record.projection_loss += loss;
            }
        } else {
            c.phase.gap = c.gap_at(&self.chain, t, &self.state.q);
        }
        match post {
            Post::None => return Ok(()),
            Post::Refine => return Ok(()),
            Post::Release { time_tolerance } => {
                c.flush_pending();
                c.phase.pending_release = Some(Event::Release {
                    t,
                    contact: 1,
                    normal_force: c.phase.lambda,
                    time_tolerance,
                });
                c.phase.constrained = false;
                c.phase.lambda = 0.0;
                c.constraint.step_lambda = 0.0;
            }
            Post::Impact { time_tolerance } => {
                c.push(Event::ContactStart {
                    t,
                    contact: 1,
                    time_tolerance,
                });
                if let Some(e) = c.impact(
                    &mut self.chain,
                    self.massless.as_mut(),
                    t,
                    &self.state.q,
                    &mut self.state.qd,
                )? {
                    c.push(e);
                }
                let (l, _, passes) = c.state_force(
                    &mut self.chain,
                    self.massless.as_mut(),
                    t,
                    &self.state.q,
                    &self.state.qd,
                )?;
                self.counters.rhs += passes;
                if l > 0.0 {
                    c.phase.constrained = true;
                    c.phase.lambda = l;
                    c.constraint.step_lambda = l;
                } else {
                    c.phase.lambda = 0.0;
                }
            }
        }
        self.stepper.restart();
        Ok(())
    }
}

/// Why a grazing contact stays undetermined at the shortest step, by the kind of chain.
fn grazing_why(massless_dofs: bool) -> &'static str {
    if massless_dofs {
        "the normal force of the constrained dynamics (without the almost massless frame modes \
         of Timoshenko links without rotary inertia on free joints without hub inertia) \
         contradicts the stepped free motion, which carries them"
    } else {
        "the normal force of the constrained dynamics contradicts the stepped free motion, \
         which carries the tip's highest mesh modes; after each impact they grow with the mesh \
         (the point-impact singularity of Euler–Bernoulli beams)"
    }
}

/// What resolves [`grazing_why`].
fn grazing_remedy(massless_dofs: bool) -> &'static str {
    if massless_dofs {
        "refine the mesh (≥ 8 elements per link) or switch on rotary inertia"
    } else {
        "fewer elements per link, or the modal or fdm backend"
    }
}
