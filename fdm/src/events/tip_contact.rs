//! The tip contact of the two-link chain as events: contact start (located on the step's own
//! drift), impact (the velocity reset), constrained sliding (the chain's constraint switched
//! on) and release (located on the normal force). The geometry, the constraint and the impact
//! map are the chain's ([`crate::chain::contact`]); this object decides when they act.
//!
//! * free flight: when a step ends with g < 0, the crossing is located on the step's own drift
//!   q(s) = q + s q̇ + ½s² q̈ (exact for the velocity form with every force at the predicted
//!   velocity: the positions of a step of length s need no new force evaluation) by Illinois
//!   regula falsi to |g| ≤ 1e-13 L or a bracket of [`EVENT_TIME_TOLERANCE`]; the step is
//!   re-taken with that length, so the state lands on the event;
//! * at a contact start: the impact M(q̇⁺ − q̇⁻) = GᵀΛ, its kinetic energy loss booked in the
//!   ledger term `impact`; the next phase follows from the sign of the would-be normal force;
//! * constrained sliding: the chain's constrained accelerations and projections;
//! * release when λ crosses zero from above: located by Illinois on λ(s) of the re-taken
//!   constrained step of length s (one force evaluation per trial), then free flight.
//!
//! After every velocity jump (the start, every impact) the step is ¼ of the bound for 2000
//! steps: the jump excites the shortest waves and the overdamped clamp-rotation modes, whose
//! transients the velocity form at the bound — and the trapezoidal work of their dampers —
//! resolve poorly. Measured on `barhorst-case2` (2 s): ledger closure 1.7e-5 without, 1.2e-6
//! to 4e-6 with ¼ of the bound for 0.9–9 ms, for ≈ 10 % more steps.
//!
//! With the damping implicit (its bound the undamped one) the start is stepped at the explicit
//! damping's bound for 2000 steps instead: a preloaded joint released at t = 0 rings through
//! the heavily damped mesh modes, which the Crank–Nicolson damping at the undamped bound
//! leaves ringing instead of decaying. On `barhorst-case1-stiff-elbow` (the elbow at 5° against
//! K₂ = 5000) the whole 10 s ledger residual arose in the first 2 ms: closure 4.5e-5 without
//! the start window, 2.6e-6 with it (0.45 of the undamped bound).

use data::{Diagnostic, Event, StabilityVerdict};

use super::{Events, Retake, illinois};
use crate::chain::TwoLinkChain;
use crate::chain::contact::GAP_TOLERANCE;
use crate::error::FdmError;
use crate::method::{Levels, StepState};
use crate::system::System;

/// Width of the time bracket at which event location stops (s).
pub const EVENT_TIME_TOLERANCE: f64 = 1e-10;
/// Step factor on the bound, and its number of steps, after a velocity jump (module docs).
const REFINE_FACTOR: f64 = 0.25;
const REFINE_STEPS: usize = 2000;
/// Upper bound on contact events (guards a Zeno-like accumulation).
const MAX_CONTACT_EVENTS: usize = 20_000;

/// Diagnostics of a contact run that [`data::RunResult`] has no field for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactReport {
    /// Largest |g| found at a step end of a constrained phase, before the position projection.
    pub max_gap_violation: f64,
    /// Largest |Gq̇| at a step end of a constrained phase, before the velocity projection.
    pub max_normal_velocity_violation: f64,
    /// Kinetic energy removed by the velocity projections (not booked in the ledger).
    pub projection_energy: f64,
    /// Largest |g| at a located contact start.
    pub max_gap_at_event: f64,
    /// Largest |λ| at a located release.
    pub max_release_force: f64,
    /// Largest time bracket of a located event.
    pub max_time_tolerance: f64,
    /// Smallest and largest step.
    pub tau_min: f64,
    pub tau_max: f64,
}

enum Switch {
    Contact { tol: f64 },
    Release { tol: f64 },
}

/// The verdict when the constraint's GM⁻¹Gᵀ is not positive (M lost definiteness).
fn singular(t: f64) -> StabilityVerdict {
    StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: "the constraint's G M⁻¹ Gᵀ is not positive".into(),
            location: Some("contact1".into()),
            why: "the chain's mass matrix is positive definite at every deflection its chord \
                  frames describe (its kinetic energy is that of the lumped points), so the mass \
                  solve met a state that is not finite or an ill-conditioned mass matrix"
                .into(),
            remedy: "use a smaller time step or fewer stations, or the fem or modal backend".into(),
        },
    }
}

/// The tip contact's event state over a run.
pub struct TipContactEvents {
    pub report: ContactReport,
    /// gap at level j (free flight) and normal force at level j (constrained)
    g_prev: f64,
    lam_prev: f64,
    /// located steps of zero length in a row (a re-contact right after a release)
    zero_length: usize,
    /// refinement window after a velocity jump, and its end
    window: f64,
    refine_until: f64,
    /// L₁ + L₂ and the gap tolerance GAP_TOLERANCE·(L₁ + L₂)
    len: f64,
    tol_gap: f64,
    /// index of the ledger's `impact` term among inputs and dissipations
    i_impact: usize,
    /// drift positions of a trial step length (allocated once)
    trial: Vec<f64>,
    pending: Option<Switch>,
    /// With implicit damping: the step factor that brings the step to the explicit damping's
    /// bound (< 1), and the end of the start window stepped at it
    start_factor: f64,
    start_until: f64,
}

impl TipContactEvents {
    /// Events of `chain`'s tip contact; `work_terms` = inputs + dissipations of its ledger
    /// (the last one is `impact`).
    pub fn new(chain: &TwoLinkChain, work_terms: usize) -> Self {
        let len = chain.total_length();
        TipContactEvents {
            report: ContactReport::default(),
            g_prev: 0.0,
            lam_prev: 0.0,
            zero_length: 0,
            window: 0.0,
            refine_until: 0.0,
            len,
            tol_gap: GAP_TOLERANCE * len,
            i_impact: work_terms - 1,
            trial: vec![0.0; chain.dofs()],
            pending: None,
            start_factor: 1.0,
            start_until: 0.0,
        }
    }
}

impl Events<TwoLinkChain> for TipContactEvents {
    fn begin(&mut self, sys: &mut TwoLinkChain, level: &Levels) -> Result<(), FdmError> {
        self.start_factor = (sys.explicit_damping_bound() / sys.bound(0.0).sigma).min(1.0);
        self.g_prev = sys.gap(&level.q);
        if self.g_prev < 0.0 {
            return Err(FdmError::invalid(
                "contact",
                format!("the tip starts {:.3e} inside the surface", -self.g_prev),
            ));
        }
        Ok(())
    }

    fn first_step(&mut self, tau: f64) {
        self.report.tau_min = tau;
        self.report.tau_max = tau;
        self.window = REFINE_STEPS as f64 * REFINE_FACTOR * tau;
        self.refine_until = self.window;
        if self.start_factor < REFINE_FACTOR {
            self.start_until = REFINE_STEPS as f64 * self.start_factor * tau;
        }
    }

    fn step_factor(&self, t: f64) -> Option<f64> {
        if t < self.start_until {
            return Some(self.start_factor);
        }
        (t < self.refine_until).then_some(REFINE_FACTOR)
    }

    /// The powers at the level's own (final) velocity: the forces of a step end are evaluated
    /// at the predicted velocity, and the overdamped clamp-rotation modes make the two differ
    /// at O(1) near the step bound.
    fn level_powers(&mut self, sys: &mut TwoLinkChain, t: f64, v: &[f64], out: &mut [f64]) {
        sys.powers_at(t, v, out);
    }

    fn locate(
        &mut self,
        sys: &mut TwoLinkChain,
        t: f64,
        tau: f64,
        st: &mut StepState,
        retake: &mut Retake<'_>,
    ) -> Result<Option<f64>, StabilityVerdict> {
        if sys.is_constrained() && !sys.normal_force().is_finite() {
            return Err(singular(t));
        }
        if !(st.next.q.iter().chain(&st.next.v).all(|x| x.is_finite())) {
            return Err(StabilityVerdict::Stopped {
                diagnostic: Diagnostic {
                    t,
                    what: "non-finite state".into(),
                    location: Some(format!(
                        "{} phase",
                        if sys.is_constrained() {
                            "constrained"
                        } else {
                            "free"
                        }
                    )),
                    why: format!(
                        "step {tau:.3e} against the bound {:.3e}",
                        sys.bound(t).sigma
                    ),
                    remedy: "lower the safety factor".into(),
                },
            });
        }
        let mut tau_eff = tau;
        if !sys.is_constrained() {
            let g1 = sys.gap(&st.next.q);
            if g1 < 0.0 && self.g_prev > 0.0 {
                // the gap at the positions a step of length s reaches (the method's own, no
                // force evaluation)
                let trial = &mut self.trial;
                let gap_at = |s: f64| {
                    retake.positions(st, s, trial);
                    sys.gap_of(trial)
                };
                let (s_e, tol, _) = illinois(
                    gap_at,
                    (0.0, self.g_prev),
                    (tau, g1),
                    EVENT_TIME_TOLERANCE,
                    self.tol_gap,
                );
                tau_eff = s_e;
                self.pending = Some(Switch::Contact { tol });
            } else if g1 < -self.tol_gap.max(1e-9 * self.len) {
                // left the surface at a release and came back within one step: the contact
                // starts at the step start (tolerance: the step)
                tau_eff = 0.0;
                self.pending = Some(Switch::Contact { tol: tau });
            }
        } else if sys.normal_force() <= 0.0 && self.lam_prev > 0.0 {
            let l1 = sys.normal_force();
            let lam_at = |s: f64| {
                retake.take(sys, st, s);
                sys.normal_force()
            };
            let (s_e, tol, _) = illinois(
                lam_at,
                (0.0, self.lam_prev),
                (tau, l1),
                EVENT_TIME_TOLERANCE,
                0.0,
            );
            tau_eff = s_e;
            self.pending = Some(Switch::Release { tol });
        }
        if self.pending.is_none() {
            return Ok(None);
        }
        if tau_eff > 0.0 {
            retake.take(sys, st, tau_eff);
            self.zero_length = 0;
        } else {
            st.next.q.copy_from_slice(&st.cur.q);
            st.next.v.copy_from_slice(&st.cur.v);
            st.acc_next.copy_from_slice(&st.acc);
            st.p_new.copy_from_slice(&st.p_cur);
            self.zero_length += 1;
        }
        Ok(Some(tau_eff))
    }

    fn committed(&mut self, sys: &mut TwoLinkChain, tau: f64) {
        if sys.is_constrained() {
            let [gap, normal_velocity, energy] = sys.last_projection();
            let r = &mut self.report;
            r.max_gap_violation = r.max_gap_violation.max(gap);
            r.max_normal_velocity_violation = r.max_normal_velocity_violation.max(normal_velocity);
            r.projection_energy += energy;
        }
        if tau > 0.0 {
            self.report.tau_min = self.report.tau_min.min(tau);
            self.report.tau_max = self.report.tau_max.max(tau);
        }
    }

    fn apply(
        &mut self,
        sys: &mut TwoLinkChain,
        t: f64,
        st: &mut StepState,
        work: &mut [f64],
        log: &mut Vec<Event>,
    ) -> Result<usize, StabilityVerdict> {
        let Some(switch) = self.pending.take() else {
            return Ok(0);
        };
        if log.len() >= MAX_CONTACT_EVENTS || self.zero_length > 3 {
            return Err(StabilityVerdict::Stopped {
                diagnostic: Diagnostic {
                    t,
                    what: format!("{} contact events", log.len()),
                    location: Some("contact1".into()),
                    why: "impacts/releases accumulate (Zeno-like chattering)".into(),
                    remedy: "shorten t_end or add damping".into(),
                },
            });
        }
        let r = &mut self.report;
        r.max_time_tolerance = r.max_time_tolerance.max(match switch {
            Switch::Contact { tol } | Switch::Release { tol } => tol,
        });
        let mut evaluations = 0;
        let cur = &mut st.cur;
        match switch {
            Switch::Contact { tol } => {
                r.max_gap_at_event = r.max_gap_at_event.max(sys.gap(&cur.q).abs());
                log.push(Event::ContactStart {
                    t,
                    contact: 1,
                    time_tolerance: tol,
                });
                let Some(ev) = sys.impact(t, &cur.q, &mut cur.v) else {
                    return Err(singular(t));
                };
                self.refine_until = t + self.window;
                if let Event::Impact {
                    kinetic_energy_lost,
                    ..
                } = &ev
                {
                    work[self.i_impact] += kinetic_energy_lost;
                }
                log.push(ev);
                // the phase follows from the sign of the would-be normal force
                sys.set_constrained(true);
                sys.accel(t, &cur.q, &cur.v, &mut st.acc);
                evaluations += 1;
                if sys.normal_force() <= 0.0 {
                    sys.set_constrained(false);
                    sys.accel(t, &cur.q, &cur.v, &mut st.acc);
                    evaluations += 1;
                }
            }
            Switch::Release { tol } => {
                r.max_release_force = r.max_release_force.max(sys.normal_force().abs());
                log.push(Event::Release {
                    t,
                    contact: 1,
                    normal_force: sys.normal_force(),
                    time_tolerance: tol,
                });
                sys.set_constrained(false);
                sys.accel(t, &cur.q, &cur.v, &mut st.acc);
                evaluations += 1;
            }
        }
        sys.powers_at(t, &cur.v, &mut st.p_cur);
        Ok(evaluations)
    }

    fn settled(&mut self, sys: &mut TwoLinkChain, level: &Levels) {
        if sys.is_constrained() {
            self.lam_prev = sys.normal_force();
        } else {
            self.g_prev = sys.gap(&level.q);
        }
    }
}
