//! `simulate`: builds the chain, chooses the step, drives the stepper and samples observables and
//! the energy ledger at the scene's output interval.

use std::time::Instant;

use data::scene::{Contact as SceneContact, ContactMode, Link, PlanarChain};
use data::{
    Cost, Diagnostic, EnergyLedger, Event, FemSettings, Observables, RunResult, Scene,
    StabilityVerdict, channel, ledger_term,
};

use crate::chain::{Chain, NONE, V2};
use crate::driver::{Driver, Rejection, StopReason};
use crate::error::FemError;
use crate::events::contact::Contact;
use crate::method::{Adaptive, capabilities, names_with};
use crate::settings::{self, Method};

/// Safety factor below the central-difference bound when the backend picks the step.
pub const DEFAULT_SAFETY: f64 = 0.9;
/// Default step: this many steps per period of the stiffest link's first flexible mode
/// (ω₁ = (β₁L)²·sqrt(EI/ρA L⁴)), and never more than the output interval. A link whose joint
/// motion is prescribed vibrates like a clamped-free beam (β₁L = 1.8751…); a link on a free
/// joint like a pinned-free one (β₁L = 3.9266…, 4.4 times higher in frequency). Using the
/// clamped-free value for free chains made the default step 4.4 times too coarse: on
/// `two-link-free` the joint angle at 2 s was 19 % off and the ledger closed to 0.15 only.
pub const STEPS_PER_PERIOD: f64 = 40.0;

/// Default step of a free chain of linear beams (no foreshortening, no axial field) in which
/// nothing dissipates the flexible motion (no joint damper, no Kelvin–Voigt, no contact): this
/// many steps per first pinned-free period of its most flexible link. Without dissipation every
/// excited mode rings for the whole run and the second-order schemes' phase error, (ωh)²/12 of
/// each period, accumulates instead of decaying. Chains with foreshortening keep the 40-step
/// rule; on `two-link-free-undamped` (16 elements, joint-1 angle low-passed at 20 Hz on samples
/// every 2e-4 s, which resolve the links' ringing) the step's error falls at order 1.5: h =
/// 2e-4 / 1e-4 / 5e-5 s differ by 2.3e-4 then 8.0e-5 of the peak (data/cases/two_link_rows.toml;
/// at the scene's 0.01 s samples the ringing aliases into the 20 Hz band and hides this).
/// Over the first 2.5 s, h = 2.5e-5 s lies 3.0e-5 of the peak from h = 5e-6 s.
/// Measured against `flexverify run single-link --backend modal --modes 12 --rtol 1e-10 --atol
/// 1e-12` (16 elements, hub angle, max over 3 s): 2.6e-2 rad at 40 steps per stiffest-link
/// period, 7.4e-4 at 320 (h = 3.85e-4 s; modal's own default: 5.8e-4); on
/// the damped `two-link-free` the joint-1 angle moves by only 1.3e-4 rad between 40 steps and a
/// 4 times smaller step. The rule ignores how small a
/// stiff link's flexible amplitudes are: a link 1000 times stiffer than `single-link` gets
/// 236 000 steps for its 3 s, where a step 8 times longer changes its hub angle by far less
/// than its flexible correction; pass `--dt` there.
pub const UNDAMPED_STEPS_PER_PERIOD: f64 = 320.0;

/// Default step of a chain with a unilateral contact: this many steps per period of the
/// stiffest link's first flexible mode (fitted to the output interval, as every rule here).
/// The impacts and the held phases converge at second order in the step, and the
/// contact-episode boundaries are what a contact run is read for. On `barhorst-case1` (16
/// elements, against dt 6.25e-5; T₁ = 30.5 ms) they lie 2.5e-3 s from converged at
/// [`STEPS_PER_PERIOD`] (dt 5e-4), 1.2e-3 s at 80 steps (3.3e-4), 6.8e-4 s at 100 (2.5e-4),
/// inside the 1e-3 s a contact study asks for (measurements and the other contact scenes: docs/contact.md,
/// "fem's default step through contact").
pub const CONTACT_STEPS_PER_PERIOD: f64 = 100.0;

/// Steps per period of the first axial mode of an extensible link whose tip is held by a
/// bilateral wall (see [`axial_wall_step`]).
pub const STEPS_PER_AXIAL_PERIOD: f64 = 16.0;

/// Default-step bound for a bilateral wall on an extensible link: the wall load is carried by
/// the link's axial field (both ends held: ω_ax = π·sqrt(EA/ρA)/L), which the bending rule
/// alone leaves unresolved ([`STEPS_PER_AXIAL_PERIOD`] steps per axial period; the
/// step ladder behind the choice is in docs/backends.md, "Defaults").
pub fn axial_wall_step(pc: &PlanarChain) -> Option<f64> {
    let c = pc
        .contacts
        .iter()
        .find(|c| c.mode == ContactMode::Bilateral)?;
    let link = pc.links.iter().find(|l| l.name == c.link && l.axial)?;
    let ea = link.axial_stiffness?;
    let omega_ax = std::f64::consts::PI * (ea / link.mass_per_length).sqrt() / link.length;
    Some(2.0 * std::f64::consts::PI / (STEPS_PER_AXIAL_PERIOD * omega_ax))
}

/// Root of tan x = tanh x near 3.93 (first flexible pinned-free eigenvalue), by bisection on
/// sin x cosh x − cos x sinh x, scaled by e^{−x} to stay O(1).
pub fn pinned_free_beta1() -> f64 {
    let f = |x: f64| {
        let e = (-x).exp();
        // (sin x cosh x − cos x sinh x) e^{−x} = ½[sin x (1 + e^{−2x}) − cos x (1 − e^{−2x})]
        0.5 * (x.sin() * (1.0 + e * e) - x.cos() * (1.0 - e * e))
    };
    bisect(f, 3.5, 4.2)
}

/// Root of cos x cosh x + 1 = 0 near 1.875 (first clamped-free eigenvalue), by bisection.
pub fn clamped_free_beta1() -> f64 {
    bisect(|x: f64| x.cos() * x.cosh() + 1.0, 1.5, 2.2)
}

/// Root of `f` in the bracket [a, b] by bisection (200 halvings: to the last bit).
fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if f(a) * f(m) <= 0.0 {
            b = m;
        } else {
            a = m;
        }
    }
    0.5 * (a + b)
}

/// Generalized-α spectral radius: 1 (trapezoidal, exactly energy-conserving for linear systems,
/// what the ledger checks need) unless a link is extensible, where ρ∞ = 0.9 damps the spurious
/// high axial frequencies (EA/EI ≫ 1) that the time step cannot resolve.
pub fn default_rho_inf(links: &[Link]) -> f64 {
    if links.iter().any(|l| l.axial) {
        0.9
    } else {
        1.0
    }
}

/// Default method: `energy-midpoint` when every joint is free (torque/spring driven) and no link
/// is extensible — there its ledger closes to the Newton tolerance, where the trapezoidal rule
/// leaves an O(h²) energy error through the configuration-dependent mass M(q); else
/// generalized-α (prescribed joints are not supported by the midpoint scheme; extensible links
/// keep ρ∞ = 0.9 numerical damping of the unresolved axial modes; undamped massless Timoshenko
/// hubs: see `undamped_massless_hub`). A bilateral contact (seed 001's wall, always
/// constrained) takes `energy-midpoint` even with extensible links: its ledger closes to the
/// Newton tolerance, so the closure is the friction-work check.
pub fn default_method(pc: &PlanarChain) -> Method {
    let midpoint_steps_it = capabilities(Method::EnergyMidpoint).prescribed_joints
        || pc.links.iter().all(|l| l.joint.prescribed.is_none());
    if midpoint_steps_it && pc.contacts.iter().any(|c| c.mode == ContactMode::Bilateral) {
        return Method::EnergyMidpoint;
    }
    if midpoint_steps_it && !pc.links.iter().any(|l| l.axial || undamped_massless_hub(l)) {
        Method::EnergyMidpoint
    } else {
        Method::GeneralizedAlpha
    }
}

/// For a chain of linear beams whose joints are all free and in which nothing dissipates (no
/// joint damper, no Kelvin–Voigt, no contact), the first pinned-free frequency of its most flexible link: the
/// slowest flexible mode, whose phase error [`UNDAMPED_STEPS_PER_PERIOD`] bounds.
fn undissipated_free_chain_frequency(pc: &PlanarChain) -> Option<f64> {
    let dissipates =
        |l: &Link| l.kelvin_voigt.unwrap_or(0.0) > 0.0 || l.joint.damping.unwrap_or(0.0) > 0.0;
    if !pc.contacts.is_empty()
        || pc
            .links
            .iter()
            .any(|l| l.joint.prescribed.is_some() || dissipates(l) || l.foreshortening || l.axial)
    {
        return None;
    }
    let beta1 = pinned_free_beta1();
    pc.links
        .iter()
        .map(|l| {
            beta1 * beta1 * (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt()
        })
        .reduce(f64::min)
}

/// A Timoshenko link without rotary inertia on a free joint without hub inertia, with neither
/// Kelvin–Voigt nor joint damping: turning its frame against v = −αx moves mass only O(v²)
/// (chain::Chain::settle_massless), an undamped, almost massless and very stiff direction.
/// The energy-midpoint Newton iteration stalls on it (measured: Timoshenko
/// `two-link-free-undamped`, κGA = 100 EI/L², stopped at t = 0.32 s at the default step), while
/// generalized-α runs it (closure 5e-6): such scenes default to generalized-α.
fn undamped_massless_hub(l: &Link) -> bool {
    l.shear
        && !l.rotary_inertia
        && l.joint.prescribed.is_none()
        && l.joint.hub_inertia.unwrap_or(0.0) == 0.0
        && l.kelvin_voigt.unwrap_or(0.0) == 0.0
        && l.joint.damping.unwrap_or(0.0) == 0.0
}

/// Refuses prescribed joint motion to a method that cannot step it (energy-midpoint: a
/// prescribed joint would need the work of its actuator booked with the scheme's quadrature,
/// which is not implemented).
fn check_prescribed_joints(method: Method, links: &[Link]) -> Result<(), FemError> {
    if capabilities(method).prescribed_joints {
        return Ok(());
    }
    if let Some(i) = links.iter().position(|l| l.joint.prescribed.is_some()) {
        return Err(FemError::unsupported(format!(
            "fem {method}: prescribed joint motion (link {}); use {}",
            i + 1,
            names_with("or", |c| c.prescribed_joints)
        )));
    }
    Ok(())
}

/// Everything `simulate` needs, built once (benches reuse it).
pub struct Prepared {
    pub driver: Driver,
    pub t_end: f64,
    pub output_interval: f64,
    pub stations: usize,
    pub h_nominal: f64,
}

/// Builds the chain and the stepper for the planar chain `pc` of `scene` and the settings
/// (step chosen per the documented rule).
pub fn prepare(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &FemSettings,
) -> Result<Prepared, FemError> {
    let mut chain = Chain::from_planar_chain(&scene.name, pc, settings)?;
    let method = settings.method.unwrap_or_else(|| default_method(pc));
    let caps = capabilities(method);
    check_prescribed_joints(method, &pc.links)?;
    let dt_user = settings::positive("time.dt", settings.dt)?;
    let rtol = settings::positive("time.rtol", settings.rtol)?;
    let atol = settings::positive("time.atol", settings.atol)?;
    let t_end = settings::positive("time.t_end", settings.t_end)?.unwrap_or(scene.simulation.t_end);
    let safety = settings.safety_factor.unwrap_or(DEFAULT_SAFETY);
    if !(safety > 0.0 && safety <= 1.0) {
        return Err(FemError::InvalidSettings {
            field: "time.safety_factor".into(),
            message: format!("must lie in (0, 1], got {safety}"),
        });
    }
    if caps.explicit
        && let Some(i) = pc.links.iter().position(|l| l.shear && !l.rotary_inertia)
    {
        return Err(FemError::unsupported(format!(
            "fem {method}: link {} is a Timoshenko link without `rotary_inertia`: its section \
             rotations carry no mass (M is singular), which an explicit scheme cannot step; use \
             {}",
            i + 1,
            names_with("or", |c| !c.explicit)
        )));
    }
    if rtol.is_some() && !caps.adaptive {
        return Err(FemError::InvalidSettings {
            field: "time.rtol".into(),
            message: format!(
                "adaptive stepping is available with {} only",
                names_with("and", |c| c.adaptive)
            ),
        });
    }
    if let Some(st) = &pc.statics {
        // The scene's static loads act as a step load in dynamics (scene `cantilever`: the
        // response oscillates about the static deflection).
        chain.tip_load = st.tip_force.unwrap_or(0.0);
        chain.distributed_load = st.distributed_load.unwrap_or(0.0);
    }
    let out = scene.simulation.output_interval;
    let (beta_clamped, beta_pinned) = (clamped_free_beta1(), pinned_free_beta1());
    let omega1 = pc
        .links
        .iter()
        .map(|l| {
            let beta1 = if l.joint.prescribed.is_some() {
                beta_clamped
            } else {
                beta_pinned
            };
            beta1 * beta1 * (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt()
        })
        .fold(0.0f64, f64::max);
    let mut h_rule = (2.0 * std::f64::consts::PI / (STEPS_PER_PERIOD * omega1))
        .min(axial_wall_step(pc).unwrap_or(f64::INFINITY));
    if pc
        .contacts
        .iter()
        .any(|c| c.mode == ContactMode::Unilateral)
    {
        h_rule = h_rule.min(2.0 * std::f64::consts::PI / (CONTACT_STEPS_PER_PERIOD * omega1));
    }
    if let Some(omega_flexible) = undissipated_free_chain_frequency(pc) {
        h_rule =
            h_rule.min(2.0 * std::f64::consts::PI / (UNDAMPED_STEPS_PER_PERIOD * omega_flexible));
    }
    let contact = Contact::from_planar_chain(&scene.name, pc, &chain)?;
    if let Some(c) = &contact {
        if !caps.held_constraint {
            return Err(FemError::unsupported(format!(
                "fem: contact is implemented for {} (scene `{}`; method `{method}`)",
                names_with("and", |c| c.held_constraint),
                scene.name
            )));
        }
        if !caps.bilateral_constraint && c.bilateral.is_some() {
            return Err(FemError::unsupported(format!(
                "fem {method}: a bilateral wall (stick–slip friction phases) is implemented for \
                 {} (scene `{}`); `{method}` holds unilateral contacts only",
                names_with("and", |c| c.bilateral_constraint),
                scene.name
            )));
        }
        if !caps.projects_massless
            && let Some(i) = pc.links.iter().position(|l| l.shear && !l.rotary_inertia)
        {
            let projecting = names_with("or", |c| c.projects_massless);
            // With the massless rotations projected as for energy-midpoint (the removed strain
            // energy booked), these methods have no consistent quadrature of the Kelvin–Voigt
            // work on ψ′ (neither the projected end rates nor Δq/h close the ledger); without
            // the projection the end rates flip sign every step.
            return Err(FemError::unsupported(format!(
                "fem {}: contact on link {} (a Timoshenko link without `rotary_inertia`) is not \
                 implemented: the method leaves the end rates of its massless section rotations \
                 undetermined, which only {projecting} projects and books consistently; use \
                 {projecting}",
                method,
                i + 1,
            )));
        }
        if rtol.is_some() {
            return Err(FemError::unsupported(
                "fem: contact with adaptive stepping (`time.rtol`) is not implemented; events \
                 are located inside fixed steps",
            ));
        }
    }
    let mut integ = Driver::new(chain, method, h_rule.min(out), default_rho_inf(&pc.links))?;
    if let Some(mut c) = contact {
        c.phase.gap = c.gap_at(&integ.chain, integ.state.t, &integ.state.q);
        if c.phase.gap < -c.phase.gap_tol && c.bilateral.is_none() {
            return Err(FemError::InvalidSettings {
                field: "contact".into(),
                message: format!("the tip starts {:.3e} inside the surface", -c.phase.gap),
            });
        }
        let unilateral = c.bilateral.is_none();
        integ.contact = Some(Box::new(c));
        if unilateral {
            // Impacts, releases and grazing contacts (crate::events::contact, crate::events::massless).
            integ.enable_unilateral_contact()?;
        }
        // Bilateral wall: on the surface from t = 0, initial Coulomb test (crate::events::contact::friction).
        integ.bilateral_start()?;
    }
    // Explicit central difference: the step under its stability bound; the implicit methods:
    // the user step or the default rule, adaptive with `rtol`.
    let h_nominal = if caps.explicit {
        let (bound, dof) = integ.stability_bound()?;
        let location = integ.chain.describe_dof(dof);
        match dt_user {
            Some(dt) if dt > bound => {
                return Err(FemError::StabilityBound {
                    dt,
                    bound,
                    bound_kind: crate::method::central_difference::BOUND_KIND.into(),
                    location,
                });
            }
            Some(dt) => dt,
            None => fit(safety * bound, out),
        }
    } else {
        let h = dt_user.unwrap_or_else(|| fit(h_rule.min(out), out));
        if let Some(rtol) = rtol {
            integ.adaptive = Some(Adaptive {
                rtol,
                atol: atol.unwrap_or(rtol * 1e-3 * integ.length_scale),
            });
        }
        h
    };
    integ.h = h_nominal;
    integ.h_nominal = h_nominal;
    Ok(Prepared {
        driver: integ,
        t_end,
        output_interval: out,
        stations: scene.simulation.field_stations.max(2),
        h_nominal,
    })
}

/// Largest step ≤ h that divides the output interval evenly.
fn fit(h: f64, out: f64) -> f64 {
    if h >= out {
        out
    } else {
        out / (out / h).ceil()
    }
}

/// Channel layout of the observables of `chain` with the scene's `contacts`.
fn channel_specs(
    contacts: &[SceneContact],
    chain: &Chain,
    stations: usize,
) -> Vec<(String, &'static str)> {
    let mut specs = Vec::new();
    for (i, l) in chain.links.iter().enumerate() {
        let k = i + 1;
        specs.push(channel::spec::joint_angle(k));
        specs.push(channel::spec::joint_rate(k));
        specs.push(channel::spec::joint_torque(k));
        specs.push(channel::spec::tip_x(k));
        specs.push(channel::spec::tip_y(k));
        specs.push(channel::spec::tip_deflection(k));
        if l.axial {
            specs.push(channel::spec::tip_axial(k));
        }
        for s in 0..stations {
            specs.push(channel::spec::field_deflection(k, s));
        }
    }
    if let Some(contact) = contacts.first() {
        specs.push(channel::spec::contact_normal_force(1));
        specs.push(channel::spec::contact_phase(1));
        // Gap (constraint violation when constrained), normal tip velocity
        // G q̇, and the running maxima of |g| and |G q̇| over constrained step ends (drift).
        specs.push(channel::spec::contact_gap(1));
        specs.push(channel::spec::contact_normal_velocity(1));
        specs.push(channel::spec::contact_max_gap(1));
        specs.push(channel::spec::contact_max_normal_velocity(1));
        if contact.friction > 0.0 {
            // Friction contact (crate::events::contact::friction): slip velocity, tangential force, work.
            specs.push(channel::spec::contact_slip_velocity(1));
            specs.push(channel::spec::contact_friction_force(1));
            specs.push(channel::spec::contact_friction_work(1));
        }
    }
    specs
}

/// Samples the observables at the driver's current state into `buf`.
fn sample(integ: &Driver, stations: usize, tips: &mut [V2], buf: &mut Vec<f64>) {
    buf.clear();
    let ch = &integ.chain;
    ch.tip_positions(integ.state.t, &integ.state.q, tips);
    for (i, l) in ch.links.iter().enumerate() {
        let (th, rate) = ch.joint_state(i, integ.state.t, &integ.state.q, &integ.state.qd);
        buf.push(th);
        buf.push(rate);
        // a free joint's torque: the law plus its spring and damper, −K(θ − θ₀) − Dθ̇
        // (the scene's hub torque); a prescribed joint's: what the motion needed
        let j = &l.joint;
        buf.push(if j.dof != NONE {
            ch.joint_torque[i] - j.stiffness * (th - j.set_point) - j.damping * rate
        } else {
            ch.joint_torque[i]
        });
        buf.push(tips[i].x);
        buf.push(tips[i].y);
        buf.push(ch.tip_deflection(i, &integ.state.q));
        if l.axial {
            buf.push(ch.tip_axial(i, &integ.state.q));
        }
        for s in 0..stations {
            let x = l.length * s as f64 / (stations - 1) as f64;
            buf.push(ch.deflection(i, &integ.state.q, x));
        }
    }
    if let Some(c) = integ.contact.as_deref() {
        buf.push(c.phase.lambda);
        buf.push(crate::events::contact::friction::phase(c));
        buf.push(c.phase.gap);
        buf.push(c.phase.normal_velocity);
        buf.push(c.record.max_gap);
        buf.push(c.record.max_normal_velocity);
        if let Some(b) = c.bilateral.as_deref().filter(|b| b.has_friction()) {
            buf.push(b.phase.slip_velocity);
            buf.push(b.phase.friction_force);
            buf.push(b.record.friction_work);
        }
    }
}

/// Names of the ledger terms the scene needs.
fn ledger_terms(integ: &Driver) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
    let chain = &integ.chain;
    let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
    if chain.links.iter().any(|l| l.joint.stiffness > 0.0) {
        stored.push(ledger_term::JOINT_SPRING);
    }
    if chain.gravity != nalgebra::Vector2::zeros() {
        stored.push(ledger_term::GRAVITY);
    }
    let mut inputs = Vec::new();
    if chain.tip_load != 0.0 || chain.distributed_load != 0.0 {
        inputs.push(ledger_term::APPLIED_LOAD);
    }
    if chain.links.iter().any(|l| l.joint.torque.is_some()) {
        inputs.push(ledger_term::APPLIED_TORQUE);
    }
    if chain.links.iter().any(|l| l.joint.dof == NONE) {
        inputs.push(ledger_term::PRESCRIBED_MOTION);
    }
    let mut diss = Vec::new();
    if chain.links.iter().any(|l| l.joint.damping > 0.0) {
        diss.push(ledger_term::JOINT_DAMPER);
    }
    if chain.links.iter().any(|l| l.kelvin_voigt > 0.0) {
        diss.push(ledger_term::KELVIN_VOIGT);
    }
    if integ.massless.as_ref().is_some_and(|m| m.project) {
        diss.push(ledger_term::NUMERICAL_MASSLESS);
    }
    match integ.contact.as_deref().map(|c| c.bilateral.as_deref()) {
        // A bilateral wall has no impacts or releases; friction work when μ > 0.
        Some(Some(b)) if b.has_friction() => diss.push(ledger_term::FRICTION),
        Some(Some(_)) => {}
        Some(None) => {
            diss.push(ledger_term::IMPACT);
            diss.push(ledger_term::CONTACT_PROJECTION);
        }
        None => {}
    }
    (stored, inputs, diss)
}

fn push_ledger(integ: &Driver, ledger: &mut EnergyLedger) {
    let [kin, strain, spring, grav] =
        integ
            .chain
            .energies(integ.state.t, &integ.state.q, &integ.state.qd);
    let mut stored = [0.0; 4];
    let mut ns = 0;
    for term in &ledger.stored {
        stored[ns] = match term.name.as_str() {
            ledger_term::KINETIC => kin,
            ledger_term::STRAIN => strain,
            ledger_term::JOINT_SPRING => spring,
            _ => grav,
        };
        ns += 1;
    }
    let w = integ.works;
    let mut inputs = [0.0; 3];
    for (k, term) in ledger.inputs.iter().enumerate() {
        inputs[k] = match term.name.as_str() {
            ledger_term::APPLIED_TORQUE => w.applied_torque,
            ledger_term::APPLIED_LOAD => w.applied_load,
            _ => w.prescribed_motion,
        };
    }
    let mut diss = [0.0; 6];
    for (k, term) in ledger.dissipation.iter().enumerate() {
        diss[k] = match term.name.as_str() {
            ledger_term::JOINT_DAMPER => w.joint_damper,
            ledger_term::NUMERICAL_MASSLESS => w.numerical_massless,
            ledger_term::IMPACT => integ.contact.as_ref().map_or(0.0, |c| c.record.impact_loss),
            ledger_term::CONTACT_PROJECTION => integ
                .contact
                .as_ref()
                .map_or(0.0, |c| c.record.projection_loss),
            ledger_term::FRICTION => integ
                .contact
                .as_deref()
                .and_then(|c| c.bilateral.as_deref())
                .map_or(0.0, |b| b.record.friction_work),
            _ => w.kelvin_voigt,
        };
    }
    let (ni, nd) = (ledger.inputs.len(), ledger.dissipation.len());
    ledger.push(integ.state.t, &stored[..ns], &inputs[..ni], &diss[..nd]);
}

/// Runs the planar chain `pc` of `scene` to t_end; early stops become a `Stopped` verdict with
/// the output so far.
pub fn simulate(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &FemSettings,
) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        driver: mut integ,
        t_end,
        output_interval,
        stations,
        h_nominal,
    } = prepare(scene, pc, settings)?;
    let specs = channel_specs(&pc.contacts, &integ.chain, stations);
    let mut obs = Observables::with_channels(&specs);
    let (s, i, d) = ledger_terms(&integ);
    let mut ledger = EnergyLedger::new(&s, &i, &d);
    let mut events = Vec::new();
    let mut tips = vec![V2::zeros(); integ.chain.links.len()];
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut buf = Vec::with_capacity(specs.len());
    sample(&integ, stations, &mut tips, &mut buf);
    obs.push(0.0, &buf);
    push_ledger(&integ, &mut ledger);
    let mut verdict = StabilityVerdict::Completed;
    'outer: for k in 1..=n_out {
        let t_stop = (k as f64 * output_interval).min(t_end);
        integ.set_stop(t_stop);
        loop {
            let h_before = integ.h;
            let stepped = integ.step();
            if let Some(c) = integ.contact.as_deref_mut() {
                events.append(&mut c.record.events);
            }
            match stepped {
                Ok(StopReason::ReachedStop) => break,
                Ok(StopReason::Stepped) => {}
                Ok(StopReason::Rejected) => {
                    events.push(Event::StepRejected {
                        t: integ.state.t,
                        dt: h_before,
                        reason: match (integ.last_rejection, integ.adaptive.is_some()) {
                            (Rejection::ContactRefine, _) => {
                                "grazing contact undetermined at this step; retried with a \
                                 quarter step"
                                    .into()
                            }
                            (_, true) => {
                                "local error estimate above tolerance or Newton failure".into()
                            }
                            _ => "Newton iteration failed; retried with a quarter step".into(),
                        },
                    });
                }
                Err(FemError::Runaway {
                    t,
                    what,
                    location,
                    why,
                    remedy,
                }) => {
                    verdict = StabilityVerdict::Stopped {
                        diagnostic: Diagnostic {
                            t,
                            what,
                            location,
                            why,
                            remedy,
                        },
                    };
                    break 'outer;
                }
                Err(FemError::Singular { what, pivot, t }) => {
                    verdict = StabilityVerdict::Stopped {
                        diagnostic: Diagnostic {
                            t,
                            what: format!("singular {what} matrix"),
                            location: Some(
                                integ.chain.describe_dof(pivot.min(integ.chain.ndof - 1)),
                            ),
                            why: "the iteration matrix lost definiteness".into(),
                            remedy: "reduce --dt".into(),
                        },
                    };
                    break 'outer;
                }
                Err(e) => return Err(e),
            }
        }
        sample(&integ, stations, &mut tips, &mut buf);
        obs.push(integ.state.t, &buf);
        push_ledger(&integ, &mut ledger);
    }
    if let Some(c) = integ.contact.as_deref_mut() {
        // A release located at the last step is reported with the run.
        c.flush_pending();
        events.append(&mut c.record.events);
    }
    let _ = h_nominal;
    Ok(run_result(
        scene,
        settings,
        obs,
        ledger,
        events,
        integ.counters.cost(integ.chain.ndof, start),
        verdict,
    ))
}

/// The backend's result record of a run (chain, rocket, 3-D link and mobile drivers alike).
pub(crate) fn run_result(
    scene: &Scene,
    settings: &FemSettings,
    observables: Observables,
    ledger: EnergyLedger,
    events: Vec<Event>,
    cost: Cost,
    verdict: StabilityVerdict,
) -> RunResult {
    RunResult {
        backend: data::BackendKind::Fem,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        observables,
        ledger,
        events,
        cost,
        verdict,
    }
}

#[cfg(test)]
mod default_step_tests {
    use super::*;

    #[test]
    fn elem_pinned_free_root_solves_tan_equals_tanh() {
        let x = pinned_free_beta1();
        assert!((x.tan() - x.tanh()).abs() < 1e-12, "{x}");
        assert!(x > 3.9 && x < 3.95);
    }

    #[test]
    fn elem_clamped_free_root_solves_cos_cosh() {
        let x = clamped_free_beta1();
        assert!((x.cos() * x.cosh() + 1.0).abs() < 1e-12, "{x}");
        assert!(x > 1.87 && x < 1.88);
    }

    #[test]
    fn sys_default_step_resolves_the_axial_mode_under_a_bilateral_wall() {
        // constrained-arm: EA = 1e6, ρA = 1, L = 1 → ω_ax = π·1000 rad/s, 16 steps a period.
        let scene = data::load_scene("constrained-arm").expect("catalog scene");
        let pc = scene.planar_chain().expect("planar chain");
        let h = axial_wall_step(pc).expect("bilateral wall on an axial link");
        assert!((h - 1.0 / 8000.0).abs() < 1e-15, "{h}");
        let p = prepare(&scene, pc, &FemSettings::default()).expect("prepare");
        assert_eq!(p.h_nominal, 1.0 / 8000.0);
        // No bilateral wall (unilateral Barhorst surface, free chains): the bending rule only.
        for name in ["barhorst-case1", "single-link", "cantilever-axial"] {
            let scene = data::load_scene(name).expect("catalog scene");
            let pc = scene.planar_chain().expect("planar chain");
            assert!(axial_wall_step(pc).is_none(), "{name}");
        }
    }
}
