//! Contact events and resets of the chain's tip contact ([`crate::contact`] holds its geometry
//! and constraint state): the event function of each phase (gap in free flight, normal force
//! while constrained, slip velocity while sliding with friction, Coulomb margin while
//! sticking), located by Illinois root finding on the stepper's dense output to
//! [`EVENT_TIME_TOLERANCE`]; the resets at a located root (plastic impact, release, stick–slip
//! switch with the Coulomb test); the drift projection of the constrained phase; the start of a
//! bilateral run. The driver consumes them through `ContactEvents`; any [`Stepper`] with dense
//! output supports contact.

use crate::contact::{ContactState, locate_crossing};
use crate::error::ModalError;
use crate::integrate::Stepper;
use crate::linalg::{dot, solve2};
use crate::rhs::ChainRhs;

/// Time tolerance of the contact-start and release events (width of the final bracket).
pub const EVENT_TIME_TOLERANCE: f64 = 1e-12;
/// Upper bound on the number of contact events in a run (guards a Zeno-like accumulation).
pub const MAX_CONTACT_EVENTS: usize = 20_000;

/// Diagnostics of a contact run that the `RunResult` has no field for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactReport {
    /// Largest |g| and |G q̇| found at the end of a constrained step, before the projection.
    pub max_gap_violation: f64,
    pub max_normal_velocity_violation: f64,
    /// Largest penetration −g seen in free flight at a located contact start.
    pub max_gap_at_contact_start: f64,
    /// Stated time tolerance of the event location (bracket width bound).
    pub time_tolerance: f64,
    /// Number of drift projections applied.
    pub projections: usize,
    /// Largest constraint power |λ·G q̇| at the end of a constrained step (zero in exact
    /// arithmetic on a fixed frictionless surface) and the kinetic energy the velocity
    /// projections removed in total (½(Gq̇)²/(GM⁻¹Gᵀ) each).
    pub max_constraint_power: f64,
    pub projection_energy: f64,
    /// Friction contact: largest |v_t| and tangential drift |t̂·(r − stick point)| found at the
    /// end of a stick step, before the projection; number of slip reversals (v_t crossed zero
    /// and the Coulomb test sent the tip back the other way without sticking).
    pub max_stick_velocity: f64,
    pub max_stick_offset: f64,
    pub slip_reversals: usize,
}

/// The contact events of a run as the driver consumes them: the event function of the current
/// phase ([`phase_event_value`]) is checked after every accepted step and its root located on
/// the stepper's dense output; at a located root the reset is applied (impact, release,
/// stick–slip switch) and the stepper restarted; after a constrained step without event the
/// state is projected back onto the constraint manifold.
pub(crate) struct ContactEvents {
    /// Event function of the current phase at the last accepted state.
    prev: f64,
    pub(crate) events: Vec<data::Event>,
    pub(crate) report: ContactReport,
    scratch: Vec<f64>,
    /// Start of the current free phase when an impact began it (its would-be normal force ≤ 0).
    free_from_impact: Option<f64>,
}

/// Why the event machinery stopped the run.
pub(crate) enum Halt {
    /// The mass matrix lost positive definiteness (or the friction contact met Painlevé's
    /// paradox) in a model evaluation.
    Singular,
    /// [`MAX_CONTACT_EVENTS`] events were reached.
    TooManyEvents(usize),
    /// The step [t, t + h] after a plastic impact at t that left the tip free (normal force
    /// ≤ 0) went `depth` below the surface: taking the contact again at t would repeat the same
    /// decision at the same instant.
    UnresolvedGrazing { t: f64, h: f64, depth: f64 },
}

impl ContactEvents {
    pub(crate) fn new(dim: usize) -> Self {
        ContactEvents {
            prev: 0.0,
            events: Vec::new(),
            report: ContactReport {
                time_tolerance: EVENT_TIME_TOLERANCE,
                ..Default::default()
            },
            scratch: vec![0.0; dim],
            free_from_impact: None,
        }
    }

    /// Before the first sample: a bilateral contact starts on the surface (see
    /// [`start_bilateral`]).
    pub(crate) fn start(&mut self, rhs: &mut ChainRhs, y: &mut [f64]) -> Result<(), ModalError> {
        if rhs.contact.as_ref().is_some_and(|c| c.bilateral) {
            start_bilateral(rhs, y, &mut self.events, &mut self.report)?;
        }
        Ok(())
    }

    /// After the first sample (the model evaluated at the initial state): the event function
    /// at t = 0; a unilateral contact must not start inside the surface.
    pub(crate) fn arm(&mut self, rhs: &ChainRhs) -> Result<(), ModalError> {
        // Event function of the current phase at the last accepted state: the gap in free
        // flight, the normal force when constrained, the slip velocity or the Coulomb margin
        // with friction.
        self.prev = match &rhs.contact {
            Some(c) if c.bilateral => phase_event_value(rhs),
            Some(c) => c.gap,
            None => 0.0,
        };
        if self.prev < 0.0 && rhs.contact.as_ref().is_some_and(|c| !c.bilateral) {
            return Err(ModalError::invalid(
                "contact",
                format!("the tip starts {:.3e} inside the surface", -self.prev),
            ));
        }
        Ok(())
    }

    /// Event detection at the end of the step [t_old, t] just taken: the located event time
    /// and the width of its final bracket, if the phase ends inside the step.
    pub(crate) fn detect(
        &mut self,
        rhs: &mut ChainRhs,
        stepper: &dyn Stepper,
        t_old: f64,
        t: f64,
        y: &[f64],
    ) -> Result<Option<(f64, f64)>, Halt> {
        if rhs.contact.is_none() {
            return Ok(None);
        }
        if !rhs.solve_counted(t, y) {
            return Err(Halt::Singular);
        }
        let now = phase_event_value(rhs);
        if now <= 0.0 && self.prev > 0.0 {
            let scratch = &mut self.scratch;
            let mut eval = |tau: f64| {
                stepper.dense(tau, scratch);
                if rhs.solve_counted(tau, scratch) {
                    phase_event_value(rhs)
                } else {
                    f64::NAN
                }
            };
            let (te, _, width) =
                locate_crossing(&mut eval, t_old, self.prev, t, now, EVENT_TIME_TOLERANCE);
            return Ok(Some((te, width)));
        }
        if now < 0.0 && !rhs.contact.as_ref().is_some_and(|c| c.constrained) {
            // Free flight that began on the surface and went below it without first
            // leaving: take the contact at the step start (reported tolerance: the step).
            let tol_gap = 1e-9
                * rhs.chain.links[rhs.contact.as_ref().unwrap().link]
                    .ints
                    .length;
            if now < -tol_gap {
                if self.free_from_impact == Some(t_old) {
                    return Err(Halt::UnresolvedGrazing {
                        t: t_old,
                        h: t - t_old,
                        depth: -now,
                    });
                }
                return Ok(Some((t_old, t - t_old)));
            }
        }
        Ok(None)
    }

    /// After the step and its samples: moves (t, y) back to a located event and applies its
    /// reset (then restarts the stepper), or projects a constrained state; then evaluates the
    /// event function of the (new) phase.
    pub(crate) fn settle(
        &mut self,
        rhs: &mut ChainRhs,
        stepper: &mut dyn Stepper,
        t: &mut f64,
        y: &mut [f64],
        located: Option<(f64, f64)>,
    ) -> Result<(), Halt> {
        if let Some((te, tol_t)) = located {
            if te != *t {
                stepper.dense(te, &mut self.scratch);
                y.copy_from_slice(&self.scratch);
                *t = te;
            }
            if self.events.len() >= MAX_CONTACT_EVENTS {
                return Err(Halt::TooManyEvents(self.events.len()));
            }
            if !switch_phase(rhs, *t, y, tol_t, &mut self.events, &mut self.report) {
                return Err(Halt::Singular);
            }
            let impact_left_free = matches!(self.events.last(), Some(data::Event::Impact { .. }))
                && rhs.contact.as_ref().is_some_and(|c| !c.constrained);
            self.free_from_impact = impact_left_free.then_some(*t);
            stepper.reset();
        } else if rhs.contact.as_ref().is_some_and(|c| c.constrained) {
            if !project(rhs, *t, y, &mut self.report) {
                return Err(Halt::Singular);
            }
            stepper.state_changed();
        }
        if rhs.contact.is_some() {
            if !rhs.solve_counted(*t, y) {
                return Err(Halt::Singular);
            }
            self.prev = phase_event_value(rhs);
        }
        Ok(())
    }
}

/// Event function of the current phase (after `solve`): the gap in free flight, the normal
/// force in contact. A phase ends when it goes from positive to non-positive.
fn phase_event_value(rhs: &ChainRhs) -> f64 {
    match &rhs.contact {
        Some(c) if c.bilateral && !c.has_friction() => 1.0,
        Some(c) if c.bilateral && c.sticking => c.mu * c.lambda.abs() - c.lambda_t.abs(),
        Some(c) if c.bilateral => c.slip_dir * c.slip_velocity,
        Some(c) if c.constrained => c.lambda,
        Some(c) => c.gap,
        None => 0.0,
    }
}

/// Applies the located event at (t, y): contact start + impact (then constrained or free by the
/// sign of the would-be normal force), or release. Returns false on a singular mass matrix.
fn switch_phase(
    rhs: &mut ChainRhs,
    t: f64,
    y: &mut [f64],
    time_tolerance: f64,
    events: &mut Vec<data::Event>,
    report: &mut ContactReport,
) -> bool {
    let nf = rhs.nf();
    if !rhs.solve_counted(t, y) {
        return false;
    }
    let c = rhs.contact.as_ref().expect("contact run");
    if c.bilateral {
        if c.sticking {
            // The Coulomb margin reached zero: slide in the direction the tangential load drives.
            let s = if c.lambda_t > 0.0 { -1.0 } else { 1.0 };
            let c = rhs.contact.as_mut().unwrap();
            c.sticking = false;
            c.slip_dir = s;
            events.push(data::Event::StickSlip {
                t,
                contact: 1,
                sticking: false,
            });
            return true;
        }
        let s = c.slip_dir;
        return coulomb_test(rhs, t, y, events, report, Some(s));
    }
    if c.constrained {
        events.push(data::Event::Release {
            t,
            contact: 1,
            normal_force: c.lambda,
            time_tolerance,
        });
        rhs.contact.as_mut().unwrap().constrained = false;
        return true;
    }
    report.max_gap_at_contact_start = report.max_gap_at_contact_start.max(-c.gap);
    events.push(data::Event::ContactStart {
        t,
        contact: 1,
        time_tolerance,
    });
    // Impact: Λ = −G q̇⁻ / (G M⁻¹ Gᵀ), q̇⁺ = q̇⁻ + M⁻¹Gᵀ Λ.
    let ke_before = rhs.chain.energy(&rhs.q).kinetic;
    let v_before = c.normal_velocity;
    let impulse = -v_before / c.gmg;
    let velocity_before: Vec<f64> = y[nf..2 * nf].to_vec();
    for k in 0..nf {
        y[nf + k] += c.minv_gt[k] * impulse;
    }
    // Momentum residual with the mass matrix at q (unchanged by the jump).
    let n = rhs.chain.n;
    let mass = rhs.chain.mass_matrix();
    let (mut res2, mut mom2) = (0.0, 0.0);
    for (r, &gr) in rhs.chain.free.iter().enumerate() {
        let mut m_dv = 0.0;
        for (k, &gc) in rhs.chain.free.iter().enumerate() {
            m_dv += mass[gr * n + gc] * (y[nf + k] - velocity_before[k]);
        }
        let r_k = m_dv - c.g_row[r] * impulse;
        res2 += r_k * r_k;
        mom2 += m_dv * m_dv;
    }
    let momentum_residual = if mom2 > 0.0 {
        (res2 / mom2).sqrt()
    } else {
        res2.sqrt()
    };
    // Decide the next phase by the sign of the would-be normal force at (q, q̇⁺).
    rhs.contact.as_mut().unwrap().constrained = true;
    if !rhs.solve_counted(t, y) {
        return false;
    }
    let ke_after = rhs.chain.energy(&rhs.q).kinetic;
    let c = rhs.contact.as_mut().unwrap();
    let loss = ke_before - ke_after;
    c.impact_loss += loss;
    events.push(data::Event::Impact {
        t,
        contact: 1,
        velocity_before,
        velocity_after: y[nf..2 * nf].to_vec(),
        impulse,
        momentum_residual,
        normal_velocity_before: v_before,
        normal_velocity_after: c.normal_velocity,
        kinetic_energy_lost: loss,
    });
    if c.lambda <= 0.0 {
        c.constrained = false;
    }
    true
}

/// Start of a bilateral contact run: the initial state must lie on the surface; its velocity is
/// projected onto G q̇ = 0 and, with friction, the phase is decided (a tip at rest gets the
/// Coulomb test, a moving one slides in the direction of v_t).
fn start_bilateral(
    rhs: &mut ChainRhs,
    y: &mut [f64],
    events: &mut Vec<data::Event>,
    report: &mut ContactReport,
) -> Result<(), ModalError> {
    let singular = || ModalError::Numerical {
        t: 0.0,
        message: "mass matrix not positive definite at the initial state".into(),
    };
    // The geometry (gap, G) is set even when the constrained solve fails: check it first.
    let solved = rhs.solve_counted(0.0, y);
    let c = rhs.contact.as_ref().unwrap();
    let len = rhs.chain.links[c.link].ints.length;
    if c.gap.abs() > 1e-9 * len {
        return Err(ModalError::invalid(
            "contact",
            format!(
                "bilateral contact: the tip starts {:.3e} off the surface (the initial state must \
                 satisfy the constraint to 1e-9 L)",
                c.gap
            ),
        ));
    }
    if c.gmg.is_nan() || c.gmg <= 0.0 {
        return Err(ModalError::Unsupported(
            "modal: the bilateral constraint gradient G = n̂ᵀJ vanishes at the initial state \
             (no coordinate moves the tip along the normal): the constraint is degenerate"
                .into(),
        ));
    }
    if !solved {
        return Err(if rhs.painleve {
            ModalError::Numerical {
                t: 0.0,
                message: "Painlevé's paradox at the initial state: G M⁻¹Gᵀ ≤ μ|G M⁻¹Tᵀ|".into(),
            }
        } else {
            singular()
        });
    }
    let c = rhs.contact.as_ref().unwrap();
    if c.has_friction() {
        let vt = c.slip_velocity;
        if vt == 0.0 {
            if !coulomb_test(rhs, 0.0, y, events, report, None) {
                return Err(singular());
            }
        } else {
            rhs.contact.as_mut().unwrap().slip_dir = vt.signum();
        }
    }
    if !project(rhs, 0.0, y, report) {
        return Err(singular());
    }
    Ok(())
}

/// Coulomb test with the tip at rest tangentially (v_t = 0): the forces that hold it
/// (λ_n, λ_t) decide stick (|λ_t| ≤ μ|λ_n|) or slip in direction −sign λ_t. `sliding` is the
/// direction before (None at the start of the run).
fn coulomb_test(
    rhs: &mut ChainRhs,
    t: f64,
    y: &[f64],
    events: &mut Vec<data::Event>,
    report: &mut ContactReport,
    sliding: Option<f64>,
) -> bool {
    rhs.contact.as_mut().unwrap().sticking = true;
    if !rhs.solve_counted(t, y) {
        return false;
    }
    let link = rhs.contact.as_ref().unwrap().link;
    let tip = rhs.chain.tip_position(link);
    let c = rhs.contact.as_mut().unwrap();
    if c.lambda_t.abs() <= c.mu * c.lambda.abs() {
        c.stick_point = tip;
        c.stick_offset = 0.0;
        events.push(data::Event::StickSlip {
            t,
            contact: 1,
            sticking: true,
        });
    } else {
        c.sticking = false;
        let s = if c.lambda_t > 0.0 { -1.0 } else { 1.0 };
        match sliding {
            None => events.push(data::Event::StickSlip {
                t,
                contact: 1,
                sticking: false,
            }),
            Some(old) if old != s => report.slip_reversals += 1,
            Some(_) => {}
        }
        c.slip_dir = s;
    }
    true
}

/// Drift control of the constrained phase: Newton on the position constraints in the M⁻¹
/// metric, q ← q − M⁻¹Aᵀ(A M⁻¹Aᵀ)⁻¹e (at most 3 passes), then the M-orthogonal velocity
/// projection q̇ ← q̇ − M⁻¹Aᵀ(A M⁻¹Aᵀ)⁻¹A q̇. A = G (e = g) while sliding; A = (G; T),
/// e = (g, t̂·(r − stick point)) while sticking.
fn project(rhs: &mut ChainRhs, t: f64, y: &mut [f64], report: &mut ContactReport) -> bool {
    let nf = rhs.nf();
    if !rhs.solve_counted(t, y) {
        return false;
    }
    {
        let c = rhs.contact.as_ref().unwrap();
        report.max_gap_violation = report.max_gap_violation.max(c.gap.abs());
        report.max_normal_velocity_violation = report
            .max_normal_velocity_violation
            .max(c.normal_velocity.abs());
        report.max_constraint_power = report
            .max_constraint_power
            .max((c.lambda * c.normal_velocity).abs());
        if c.sticking {
            report.max_stick_velocity = report.max_stick_velocity.max(c.slip_velocity.abs());
            report.max_stick_offset = report.max_stick_offset.max(c.stick_offset.abs());
        }
    }
    // (a, b) = (A M⁻¹Aᵀ)⁻¹ r for the active rows (b = 0 while sliding).
    let weights = |c: &ContactState, r: [f64; 2]| -> [f64; 2] {
        if c.sticking {
            let gmt = dot(&c.g_row, &c.minv_tt);
            let tmt = dot(&c.t_row, &c.minv_tt);
            solve2(&[c.gmg, gmt, gmt, tmt], r)
        } else {
            [r[0] / c.gmg, 0.0]
        }
    };
    for pass in 0..3 {
        let c = rhs.contact.as_ref().unwrap();
        let [a, b] = weights(c, [c.gap, c.stick_offset]);
        for k in 0..nf {
            y[k] -= c.minv_gt[k] * a;
            if c.sticking {
                y[k] -= c.minv_tt[k] * b;
            }
        }
        if !rhs.solve_counted(t, y) {
            return false;
        }
        let c = rhs.contact.as_ref().unwrap();
        let len = rhs.chain.links[c.link].ints.length;
        let held = !c.sticking || c.stick_offset.abs() <= 1e-14 * len;
        if (c.gap.abs() <= 1e-14 * len && held) || pass == 2 {
            break;
        }
    }
    let c = rhs.contact.as_ref().unwrap();
    let vt = if c.sticking { c.slip_velocity } else { 0.0 };
    let [a, b] = weights(c, [c.normal_velocity, vt]);
    report.projection_energy += 0.5 * (a * c.normal_velocity + b * vt);
    for k in 0..nf {
        y[nf + k] -= c.minv_gt[k] * a;
        if c.sticking {
            y[nf + k] -= c.minv_tt[k] * b;
        }
    }
    report.projections += 1;
    true
}
