//! The driver of a chain run: builds the model ([`ChainRhs`]) and the registered integration
//! method ([`crate::integrate::method_for`]), then steps to each forcing discontinuity and to
//! t_end (a stage that lands on a discontinuity reads the torque laws' left limits there:
//! [`crate::integrate::Stretch`]); after every accepted step it hands the step to the contact events
//! ([`crate::events`]: locate on the dense output, reset, project), takes the samples due
//! ([`crate::output`]) and checks for runaway growth; it maps the run to a [`RunResult`].

use std::time::Instant;

use data::scene::PlanarChain;
use data::{ModalSettings, RunResult, Scene, StabilityVerdict};

use crate::contact::ContactState;
use crate::error::ModalError;
use crate::events::{ContactEvents, Halt};
use crate::integrate::{
    Build, DOPRI5, EXPONENTIAL, MethodInfo, OdeRhs, Stretch, TRBDF2, Tolerances, method_for,
    oscillators_disturbed, resolving_step, tolerance_refused,
};
use crate::output::{Output, runaway, stopped, too_many_events, unresolved_grazing};
use crate::setup::build_chain;

pub use crate::events::{ContactReport, EVENT_TIME_TOLERANCE, MAX_CONTACT_EVENTS};
pub use crate::output::FinalState;
pub use crate::rhs::ChainRhs;

/// Default tolerances of the adaptive integrators.
pub const DEFAULT_RTOL: f64 = 1e-8;
pub const DEFAULT_ATOL: f64 = 1e-10;
/// (rtol, atol) of the Newton convergence test of the fixed-step methods when none is given:
/// their stages are solved to a few percent of this (see [`crate::integrate::Sdirk`]), far
/// below the step's own truncation error (~1e-5 rad on the joint angles at the default step),
/// and above the round-off floor of the polynomial coordinates, where a tighter test makes
/// Newton stall (`two-link-free`, 8 poly modes, default step: 6356 failed iterations in
/// 11 000 steps at 1e-8 / 1e-10).
pub const FIXED_STEP_NEWTON_TOL: (f64, f64) = (1e-6, 1e-8);
/// (rtol, atol) of the default method of Kelvin–Voigt chains ([`default_method`]): on
/// `two-link-free` (6 poly modes, 10 s) the Kelvin–Voigt work is 5.75445e-2 against 5.75434e-2
/// at 1e-8 / 1e-10 (2e-5 relative) in 7 553 steps instead of 35 852.
pub const KELVIN_VOIGT_DEFAULT_TOL: (f64, f64) = (1e-6, 1e-8);
/// (rtol, atol) of the default method of Kelvin–Voigt chains with a tip contact: tight enough
/// that the longest contact scene closes its energy ledger well inside 1e-5 (`barhorst-case2`,
/// 30 s: 3.1e-6 at the default 6 modes, 5.1e-6 at 2 modes, against 6.9e-6 and 1.2e-5 at
/// [`KELVIN_VOIGT_DEFAULT_TOL`]); the located switching times move by less than 1e-6 s against
/// Dormand–Prince at rtol 1e-8 (docs/backends.md).
pub const KELVIN_VOIGT_CONTACT_TOL: (f64, f64) = (3e-7, 3e-9);

/// An integration method of the registry ([`crate::integrate::method_for`]).
pub type Method = &'static MethodInfo;

/// The method of a run: the one named in the settings, else the default ([`default_method`]).
pub fn method_choice(pc: &PlanarChain, settings: &ModalSettings) -> Method {
    settings
        .method
        .map_or_else(|| default_method(pc, settings), method_for)
}

/// The default method, when no tolerance is given (a tolerance given without a method asks
/// for Dormand–Prince, [`DOPRI5`]):
/// - every link Kelvin–Voigt-damped, with or without a tip contact: adaptive TR-BDF2
///   ([`TRBDF2`], tolerances [`KELVIN_VOIGT_DEFAULT_TOL`], with a contact
///   [`KELVIN_VOIGT_CONTACT_TOL`]);
/// - no link damped and no contact: the exponential method ([`EXPONENTIAL`]) at
///   min([`default_step`], 2/ω_max);
/// - otherwise (a contact on undamped links, some links damped): Dormand–Prince.
///
/// Why: an explicit method is bound by the highest Ritz frequency (ω ~ β²√(EI/ρAL⁴) grows
/// like the square of the mode number) and, at a tight tolerance, resolves every such mode.
/// The implicit method follows the stiff, Kelvin–Voigt-damped high modes with steps set by the
/// error test: short while the step release at t = 0 (joint springs away from their set points)
/// or an impact rings through every mode, long afterwards. Its dense output locates the
/// contact switches (gap, normal force) as Dormand–Prince's does. A fixed step
/// ([`TRBDF2_FIXED`](crate::integrate::TRBDF2_FIXED) at [`default_step`], still available by
/// name) cannot resolve the initial transient: on `two-link-free` (6 `poly` modes,
/// h = T₁/128 = 1.05e-3) the term `dissipated:kelvin_voigt` comes out 14 % high at 6 modes
/// and 12 % high at 8, and the error grows with the mode count. Undamped links keep their
/// high modes ringing for all time, and the joint angles feel their phases through the
/// nonlinear coupling: a method that damps or aliases them moves the answer (docs/backends.md).
/// The exponential method carries every mode of the undeformed arm exactly at any step and
/// integrates only the coupling at fourth order, so it converges where the implicit methods do
/// not and takes ~20× fewer steps than Dormand–Prince at rtol 1e-8, whose step the top mode
/// bounds (`two-link-free-undamped`, 10 s: 79 088 steps against 1 774 712, 2.9 s against
/// 64.0 s user, 6.1e-6 rad apart on the 20 Hz low-passed hub angle). A contact's constraint force would sit in its explicit remainder,
/// hence Dormand–Prince there.
pub fn default_method(pc: &PlanarChain, settings: &ModalSettings) -> Method {
    let tolerance_given = settings.rtol.is_some() || settings.atol.is_some();
    let damped = |l: &data::scene::Link| l.kelvin_voigt.is_some_and(|g| g > 0.0);
    if tolerance_given {
        &DOPRI5
    } else if pc.links.iter().all(damped) {
        &TRBDF2
    } else if !pc.links.iter().any(damped) && pc.contacts.is_empty() {
        &EXPONENTIAL
    } else {
        &DOPRI5
    }
}

/// What a run that stops on a mass matrix no longer positive definite reports.
const SINGULAR: &str = "mass matrix lost positive definiteness";

/// The stop verdict of a contact run halted at `t`.
fn halt_verdict(halt: Halt, rhs: &ChainRhs, t: f64, fixed_step: bool) -> StabilityVerdict {
    match halt {
        Halt::Singular => stopped(rhs, t, SINGULAR, None),
        Halt::TooManyEvents(count) => too_many_events(t, count),
        Halt::UnresolvedGrazing { t, h, depth } => unresolved_grazing(t, h, depth, fixed_step),
    }
}

/// Fixed steps per period of the fastest first bending mode ([`default_step`]).
pub const STEPS_PER_PERIOD: f64 = 128.0;

/// Default step of the fixed-step methods: T₁/[`STEPS_PER_PERIOD`] with T₁ = 2π/ω₁ the
/// shortest first-mode period among the links, ω₁ = β₁²√(EI/(ρA L⁴)), β₁ = 1.8751 (the
/// clamped–free cantilever; a tip mass or a child link only lowers it, so the step is
/// conservative). `two-link-free`: T₁ = 0.134 s (link 2), h = 1.05e-3.
pub fn default_step(pc: &PlanarChain) -> f64 {
    const BETA1: f64 = 1.875_104_068_711_961;
    pc.links
        .iter()
        .map(|l| {
            let omega1 = BETA1
                * BETA1
                * (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt();
            std::f64::consts::TAU / omega1 / STEPS_PER_PERIOD
        })
        .fold(f64::INFINITY, f64::min)
}

/// A run of `pc`, the chain of `scene` (whose name and simulation settings it reports).
pub fn simulate(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &ModalSettings,
) -> Result<RunResult, ModalError> {
    simulate_detailed(scene, pc, settings).map(|(r, _)| r)
}

/// [`simulate`] that also returns the final state and the contact diagnostics.
pub fn simulate_detailed(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &ModalSettings,
) -> Result<(RunResult, FinalState), ModalError> {
    let wall = Instant::now();
    let chain = build_chain(pc, settings)?;
    let method = method_choice(pc, settings);
    if method.needs_oscillators {
        let damped = pc
            .links
            .iter()
            .any(|l| l.kelvin_voigt.is_some_and(|g| g > 0.0));
        if damped || !pc.contacts.is_empty() {
            let has = if damped {
                "Kelvin–Voigt damping"
            } else {
                "a contact"
            };
            return Err(ModalError::invalid(
                "time.method",
                oscillators_disturbed(
                    method,
                    "chains without Kelvin–Voigt damping and without a tip contact",
                    &scene.name,
                    has,
                ),
            ));
        }
        if settings.rtol.is_some() || settings.atol.is_some() {
            return Err(ModalError::invalid(
                "time.rtol/atol",
                tolerance_refused(method, "2/ω_max"),
            ));
        }
    }
    let fixed_step = method.is_fixed_step();
    let default_kelvin_voigt_method = settings.method.is_none() && std::ptr::eq(method, &TRBDF2);
    let (rtol_default, atol_default) = if default_kelvin_voigt_method {
        if pc.contacts.is_empty() {
            KELVIN_VOIGT_DEFAULT_TOL
        } else {
            KELVIN_VOIGT_CONTACT_TOL
        }
    } else if fixed_step {
        FIXED_STEP_NEWTON_TOL
    } else {
        (DEFAULT_RTOL, DEFAULT_ATOL)
    };
    let rtol = settings.rtol.unwrap_or(rtol_default);
    let atol = settings.atol.unwrap_or(atol_default);
    if !(rtol > 0.0 && atol > 0.0) {
        return Err(ModalError::invalid(
            "time.rtol/atol",
            "tolerances must be positive",
        ));
    }
    let t_end = crate::setup::checked_span(scene, settings)?;
    let (n_all, n_free) = (chain.n, chain.free.len());
    let mut rhs = ChainRhs::new(chain);
    rhs.attach_contact(ContactState::from_planar_chain(pc, n_all, n_free)?);
    let mut y = rhs.initial_state();
    let dim = y.len();
    let tol = Tolerances { rtol, atol };
    let mut stepper = match method.build {
        Build::Adaptive(build) => build(dim, tol, settings.dt),
        Build::Fixed(build) => {
            let h = match settings.dt {
                Some(h) => h,
                None if method.needs_oscillators => {
                    default_step(pc).min(resolving_step(&mut rhs, 0.0, &y).map_err(|e| {
                        ModalError::Numerical {
                            t: 0.0,
                            message: e.to_string(),
                        }
                    })?)
                }
                None => default_step(pc),
            };
            build(dim, tol, h)
        }
    };
    let mut out = Output::new(&rhs, scene, t_end, dim);

    // Discontinuities of the forcing: step onto them and restart the integrator there.
    let mut breaks: Vec<f64> = Vec::new();
    for j in &rhs.chain.joints {
        if let Some(law) = &j.torque {
            breaks.extend(law.breakpoints());
        }
        if let Some(data::scene::PrescribedMotion::SpinUp { t_s, .. }) = &j.prescribed {
            breaks.push(*t_s);
        }
    }
    breaks.retain(|&b| b > 0.0 && b < t_end);
    breaks.sort_by(|a, b| a.total_cmp(b));
    breaks.dedup();
    breaks.push(t_end);

    let mut t = 0.0;
    let mut verdict = StabilityVerdict::Completed;
    let mut contact = ContactEvents::new(dim);
    contact.start(&mut rhs, &mut y)?;
    if !out.sample_initial(&mut rhs, &y) {
        return Err(ModalError::Numerical {
            t: 0.0,
            message: "mass matrix not positive definite at the initial state".into(),
        });
    }
    contact.arm(&rhs)?;
    'outer: for &target in &breaks {
        let stretch = Stretch {
            start: t,
            end: target,
        };
        while t < target {
            let t_old = t;
            rhs.set_stretch(stretch);
            let stepped = stepper.step(&mut rhs, &mut t, &mut y, target);
            rhs.set_stretch(Stretch::OPEN);
            if let Err(e) = stepped {
                verdict = stopped(&rhs, t, &e.to_string(), None);
                break 'outer;
            }
            let located = match contact.detect(&mut rhs, stepper.as_ref(), t_old, t, &y) {
                Ok(located) => located,
                Err(halt) => {
                    if let Halt::UnresolvedGrazing { .. } = halt {
                        // Keep the state of the impact, the last one the run can vouch for.
                        stepper.dense(t_old, &mut y);
                        t = t_old;
                    }
                    verdict = halt_verdict(halt, &rhs, t, fixed_step);
                    break 'outer;
                }
            };
            let t_limit = located.map_or(t, |(te, _)| te);
            if let Err(to) = out.sample_through(&mut rhs, stepper.as_ref(), t, &y, t_limit) {
                verdict = stopped(&rhs, to, SINGULAR, None);
                break 'outer;
            }
            if let Err(halt) = contact.settle(&mut rhs, stepper.as_mut(), &mut t, &mut y, located) {
                verdict = halt_verdict(halt, &rhs, t, fixed_step);
                break 'outer;
            }
            if let Some((i, v)) = runaway(&rhs, &y) {
                verdict = stopped(&rhs, t, "", Some((i, v)));
                break 'outer;
            }
        }
        stepper.reset();
    }
    let st = stepper.stats();
    let cost = {
        let mut cost = st.cost(rhs.nf(), wall);
        cost.rhs_evaluations += rhs.event_solves;
        cost
    };
    rhs.load(t, &y);
    let fin = FinalState {
        q: rhs.q.clone(),
        qd: rhs.qd.clone(),
        contact: contact.report,
    };
    let result = RunResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        observables: out.obs,
        ledger: out.ledger,
        events: contact.events,
        cost,
        verdict,
    };
    Ok((result, fin))
}
