//! Each model's run, built from the scene: the model, its method (the scene's `time.method` or
//! the model's default), its events, the step control, then [`crate::driver::run`].

use data::scene::{LinkInitialShape, PayloadLink, PlanarChain, Rocket};
use data::{RunResult, Scene};

use crate::chain::TwoLinkChain;
use crate::driver::{StepControl, choose_step, integrate, run};
use crate::error::FdmError;
use crate::events::NoEvents;
use crate::events::tip_contact::{ContactReport, TipContactEvents};
use crate::link::FloatingLink;
use crate::method::{MethodParams, build, capabilities, names_with, stepper};
use crate::output::{Outcome, Outputs};
use crate::payload_link::PayloadLinkModel;
use crate::payload_link::system::PayloadLinkSystem;
use crate::rocket::system::RocketSystem;
use crate::settings::{Method, ValidatedSettings};
use crate::system::System;

/// Default safety factor of a Timoshenko chain with contact (an accuracy choice, not a
/// stability one). Impacts excite the condensed operator's shear waves near the step bound,
/// where the velocity-form step is only about first order in energy: at safety 1 the ledger of
/// `barhorst-case1-timoshenko` closes to 1.3e-4 over 0.4 s, at 0.1 to 7.5e-6 (3 s: 3.9e-6,
/// ~9 s wall), inside the 1e-5. `time.safety_factor` overrides it.
pub const TIMOSHENKO_CONTACT_SAFETY: f64 = 0.1;

/// Default safety factor of an Euler chain with contact, whose damping is implicit (an
/// accuracy choice, not a stability one: the step is the undamped bound). The ledger closure
/// of the catalog's contact scenes at safety 1 lies at the 1e-5 target (`barhorst-case2`, 30 s:
/// 9.29e-6; `-stiff-elbow`, 10 s: 8.65e-6), at 0.45 a third of it or less (1.94e-6 in 1.45 M
/// steps, 2.61e-6 in 0.51 M; the explicit damping's bound took 7.65 M and 4.54 M steps).
/// The error it bounds is the velocity form's energy error of the top modes each impact excites
/// (O((ωτ)²) of their energy, frozen in by the impact), larger the less those modes are damped
/// (docs/contact.md, "fdm's step through contact"). `time.safety_factor` overrides it.
pub const IMPLICIT_CONTACT_SAFETY: f64 = 0.45;

/// Runs the rocket with explicit control over the bound check (tests use `enforce_bound =
/// false` to show what happens above the bound).
pub fn rocket_with(
    scene: &Scene,
    r: &Rocket,
    s: &ValidatedSettings,
    enforce_bound: bool,
) -> Result<(RocketSystem, Outcome), FdmError> {
    let mut sys = crate::rocket::build(scene, r, s)?;
    let (q0, v0) = sys.initial_state(&r.initial_shape);
    let ctl = StepControl::for_scene(scene, s, s.method, true, enforce_bound);
    let out = integrate(&mut sys, &q0, &v0, &ctl)?;
    Ok((sys, out))
}

/// Runs `r`, the rocket of `scene`.
pub fn rocket(scene: &Scene, r: &Rocket, s: &ValidatedSettings) -> Result<RunResult, FdmError> {
    let (_, out) = rocket_with(scene, r, s, true)?;
    Ok(out.into_run_result(scene, s))
}

/// The method of a run: the scene's `time.method` when set; otherwise the one that converges
/// for the model — the one-step velocity form when any force depends on the velocities
/// ([`System::damped`]: damping, or the gyroscopic İθ̇ and θ̇² terms of a free hub), on which
/// the two-step scheme's computational mode grows; else the report's two-step scheme.
pub fn default_method(s: &ValidatedSettings, sys: &dyn System) -> Method {
    if s.requested.method.is_none() && sys.damped() {
        Method::VelocityForm
    } else {
        s.method
    }
}

/// Runs one link on its hub (method: [`default_method`] — the velocity form for a torque-driven
/// hub or Kelvin–Voigt damping, the report's two-step scheme for a prescribed undamped hub).
pub fn single_link(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
) -> Result<RunResult, FdmError> {
    let mut sys = FloatingLink::from_planar_chain(scene, pc, s.stations)?;
    let (q0, v0) = sys.initial_state();
    let method = default_method(s, &sys);
    let ctl = StepControl::for_scene(scene, s, method, false, true);
    Ok(integrate(&mut sys, &q0, &v0, &ctl)?.into_run_result(scene, s))
}

/// Runs a two-link chain. Default method (no `time.method`): the one-step velocity form — the
/// free joints make the inertia forces velocity dependent and damping is on in the damped scene,
/// both of which grow the two-step scheme's computational mode.
pub fn two_link_chain(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
) -> Result<RunResult, FdmError> {
    if !pc.contacts.is_empty() {
        return Ok(two_link_chain_with_contact(scene, pc, s)?.0);
    }
    let mut sys = TwoLinkChain::from_planar_chain(scene, pc, s.stations)?;
    let method = if s.requested.method.is_none() {
        Method::VelocityForm
    } else {
        s.method
    };
    if capabilities(method).implicit_damping {
        // damping implicit in the closing kick: the step stays at the undamped bound
        sys.enable_implicit_damping();
    }
    let (q0, v0) = sys.initial_state();
    let ctl = StepControl::for_scene(scene, s, method, false, true);
    Ok(integrate(&mut sys, &q0, &v0, &ctl)?.into_run_result(scene, s))
}

/// Runs a two-link chain with its tip contact: a method that restarts at located events
/// ([`crate::method::Capabilities::restarts_at_events`]; default the velocity form), built to
/// re-take steps from the same level (the velocity form: every force at the predicted
/// velocity), the contact as events ([`TipContactEvents`]). Returns the run and the contact
/// diagnostics.
pub fn two_link_chain_with_contact(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
) -> Result<(RunResult, ContactReport), FdmError> {
    let method = match s.requested.method {
        None => Method::VelocityForm,
        Some(_) if capabilities(s.method).restarts_at_events => s.method,
        Some(_) => {
            return Err(FdmError::Unsupported(format!(
                "fdm: contact with time.method = {}: the method cannot restart at a located \
                 event (it needs a second level there); use {}",
                s.method.name(),
                names_with("or", |c| c.restarts_at_events)
            )));
        }
    };
    let mut sys = TwoLinkChain::from_planar_chain(scene, pc, s.stations)?;
    // damping implicit in the closing kick, the tip's force included: the step is the
    // undamped bound (not for the Timoshenko chain)
    let implicit = capabilities(method).implicit_damping && sys.enable_implicit_damping();
    let (q0, v0) = sys.initial_state();
    let mut ctl = StepControl::for_scene(scene, s, method, false, true);
    if implicit && s.requested.safety_factor.is_none() {
        ctl.safety = IMPLICIT_CONTACT_SAFETY;
    }
    if sys.timoshenko().is_some() && s.requested.safety_factor.is_none() {
        ctl.safety = TIMOSHENKO_CONTACT_SAFETY;
    }
    // the step follows the refinement windows after each impact: no step-change events
    ctl.log_change = f64::INFINITY;
    let (_, inp, dis) = sys.ledger_names();
    let mut events = TipContactEvents::new(&sys, inp.len() + dis.len());
    let out = run(
        &mut sys,
        build(MethodParams {
            method,
            restartable: true,
        })
        .as_mut(),
        &mut events,
        &q0,
        &v0,
        &ctl,
    )?;
    Ok((out.into_run_result(scene, s), events.report))
}

/// Runs `p`, the payload link of `scene` (default method: the velocity form). A requested method
/// without implicit damping ([`crate::method::Capabilities::implicit_damping`]) is refused: its
/// explicit damping would need the damped step bound (and the two-step scheme's computational
/// mode grows under the Kelvin–Voigt and Coriolis forces).
pub fn payload_link(
    scene: &Scene,
    p: &PayloadLink,
    s: &ValidatedSettings,
) -> Result<RunResult, FdmError> {
    let method = match s.requested.method {
        None => Method::VelocityForm,
        Some(_) if capabilities(s.method).implicit_damping => s.method,
        Some(_) => {
            return Err(FdmError::Unsupported(format!(
                "fdm: the 3-D payload link with time.method = {}: the method cannot take the \
                 link's Kelvin–Voigt damping implicit in its closing kick; use {}",
                s.method.name(),
                names_with("or", |c| c.implicit_damping)
            )));
        }
    };
    let model = PayloadLinkModel::from_payload_link(scene, p, s.stations)?;
    let mut sys = PayloadLinkSystem::new(model)?;
    let ctl = StepControl::for_scene(scene, s, method, false, true);
    let mut method = stepper(method);
    // the step is constant (the bound does not move): A = M_ff + ½τC factored once, before
    // the start level needs it
    let (tau, _, _) = choose_step(&sys, &ctl, method.bound_factor(), 0.0)?;
    sys.set_step(tau)?;
    let (q0, v0) = sys.initial_state(p.initial_shape == LinkInitialShape::StaticSag)?;
    let mut out = run(&mut sys, method.as_mut(), &mut NoEvents, &q0, &v0, &ctl)?;
    out.cost.factorizations = sys.factorizations();
    Ok(out.into_run_result(scene, s))
}
