//! # The variable-mass flexible rocket by finite elements (seed 003, docs/rocket.md)
//!
//! ## Model
//! The stepped free-free case (x from the aft end, stages of constant EA, EI and mass per
//! length; stage 1 burns uniformly, m₁(t) = max(m₁(0) − ṁt, casing)) is meshed with equal
//! elements: u linear, w Hermite cubic, DOFs (u, w, w′) per node, plus (U_j, W_j) per discrete
//! mass. All displacements are taken in the fixed *launch axes* (ξ along the body axis at
//! launch, η across it; origin at the aft end at launch), rigid motion included: no body frame
//! is introduced, so no frame choice enters the equations. With the current mass matrix
//! M(t) = M_fixed + m₁(t)M_burn + diag(M_j) (consistent, exact quadrature), d'Alembert's
//! principle with burnt mass leaving at the local case velocity (report eqs. 3.16–3.18, 3.43:
//! the ṁṘ terms cancel) gives
//!
//!   M(t) q̈ = M(t)G − ∂V/∂q + f_springs + f_thrust + f_pressure + f_Coriolis,
//!
//! G the nodal gravity field (g at launch angle θ₀), V = ∫½EA u′² + ½EI w″² + ½EA u′w′² (report
//! eq. 3.50, P = EA u′: thrust compression softens bending). The loads follow the report
//! (eqs. 5.16–5.18) with their directions defined by the case's **mean axis** (docs/rocket.md):
//! the rigid placement (centroid c, angle φ) that best fits the case's material points in the
//! least-squares sense weighted with the ignition mass m₀(x) ([`model::Model::mean_axis`]).
//! * thrust Q̇v_e (Q̇ = ṁL₁) at the aft end, at angle γ from the mean axis;
//! * chamber pressure −pA_f at x = 0 and +pA_f at x = L₁, along the mean axis;
//! * jet Coriolis 2φ̇ Q̇(1 − x/L₁) per length on stage 1, normal to the mean axis (φ̇ the mean
//!   axis' rate), as consistent loads;
//! * springs and dampers between a discrete mass and the case act along and across the mean
//!   axis (with k_u = k_w, as in the catalog scenes, the spring is isotropic and the axis does
//!   not enter); those between two masses in the whole body's axes (case and masses, ignition
//!   mass; report eqs. 3.50, 5.37), so a rigid rotation stretches none of them.
//!
//! ## Time integration
//! The rocket is a [`crate::system::System`] ([`system::RocketSystem`]: R = M(t)q̈ − F(t, q, q̇),
//! the Newton matrix S = c_a M(t) + c_v C + c_q K with K the beam and springs in launch axes;
//! the loads' and the mass-to-mass springs' dependence on the mean axes and the cubic strain
//! term are left to the iteration, their Jacobian being 1e-5 of S at the catalog scenes)
//! stepped by a method of the registry ([`crate::method::stepper`]) on the rocket's driver path
//! ([`driver`]): fixed steps that land on the output times and on burn-out, where the method
//! restarts from a consistent acceleration. M(t) changes every step: S is formed and factorized
//! numerically at every step's first Newton iteration (symbolic LU once per run). Methods:
//! `implicit-midpoint` (the default: one-stage Gauss, second order, no numerical damping; with
//! the mean acceleration as unknown, M(t_m)ā = F(t_m, q₀ + ½hv̄, v̄), v̄ = q̇₀ + ½hā),
//! `generalized-alpha` (ρ∞ = [`RHO_INF`]), `bathe`, and `central-difference` under its
//! stability bound at the smallest mass of the run (burn-out or t_end: the bound shrinks as the
//! mass burns). `energy-midpoint` is refused: its momentum form M(q₁)v₁ − M(q₀)v₀ does not
//! hold for a mass that leaves at the local velocity (M(t)q̈ = F, no Ṁq̇), the capability
//! [`crate::method::Capabilities::variable_mass`]. Adaptive steps are refused.
//! Default step [`DEFAULT_STEP`] (the axial fundamental, ≈ 360 Hz, has ≈ 280 steps per
//! period); default mesh [`DEFAULT_ELEMENTS`] (h = 5 in on the catalog rocket: nodes on the
//! stage junction and on every discrete mass).
//!
//! ## Outputs (definitions of docs/rocket.md)
//! `rocket.X/Y`: mass centre of case and discrete masses, inertial (origin the aft end at
//! launch); `rocket.vX/vY`: momentum / mass; `rocket.theta`: θ₀ + φ, the mean axis' attitude;
//! `rocket.mass`; `rocket.u@k`, `rocket.w@k` and `rocket.mass{j}.u/.w`: positions of the
//! material points relative to the mean axis, r = A(φ)ᵀ(R − c) + (x̄, 0), minus the reference
//! abscissa (u) — at ignition the same frame as the modal backend's modes (m₀-orthogonal to the
//! rigid motions) and fdm's mean-axis channels.
//!
//! Ledger — stored: `kinetic` ½vᵀM(t)v, `strain` V, `gravity` −GᵀM(t)(x_ref + q),
//! `discrete_spring`; inputs: `thrust`, `pressure`, `coriolis` (works of those loads at the
//! midpoints); dissipation: `discrete_damper`, `mass_outflow` (kinetic and potential energy of
//! the burnt mass). All are booked per step from the step's end states, the same for every
//! method ([`driver`]): for the implicit midpoint rule the balance closes to the Newton
//! tolerance and the O(h³) midpoint error of the cubic strain term, for the other methods to
//! their O(h²) energy error.

pub mod driver;
pub mod model;
pub mod modes;
pub mod outputs;
pub mod system;

use std::time::Instant;

use data::results::ledger_term;
use data::scene::Rocket;
use data::{DofPlan, EnergyLedger, FemSettings, Observables, RunResult, Scene, StabilityVerdict};

use crate::driver::fixed_steps::QuarterRetries;
use crate::error::FemError;
use crate::method::capabilities;
use crate::settings::Method;
use crate::system::System;
use driver::RocketDriver;
use model::Model;

pub use modes::{RocketMode, modes, rocket_modes};
pub use outputs::{channel_specs, kinetic, momentum, observe};

/// Elements when `discretization.elements` is absent (h = 5 in on the catalog rocket).
pub const DEFAULT_ELEMENTS: usize = 30;
/// Time step when `time.dt` is absent.
pub const DEFAULT_STEP: f64 = 1.0e-5;
/// Generalized-α's spectral radius: the thrust's step excites the mesh's axial modes far above
/// what the step resolves (the chain's rule for links with an axial field,
/// [`crate::run::default_rho_inf`]).
pub const RHO_INF: f64 = 0.9;

/// Elements of the rocket's beam (Hermite cubics only).
fn elements(settings: &FemSettings) -> Result<usize, FemError> {
    crate::settings::cubic_elements_or(settings, DEFAULT_ELEMENTS, "rocket", "the beam")
}

/// The discretized model of the rocket `r`.
pub fn build(r: &Rocket, settings: &FemSettings) -> Result<Model, FemError> {
    Model::new(r, elements(settings)?)
}

pub fn dof_plan(r: &Rocket, settings: &data::FemSettings) -> Result<DofPlan, FemError> {
    let n_el = elements(settings)?;
    let nm = r.discrete_masses.len();
    let mut plan = DofPlan::default();
    plan.add(
        "axial u at nodes (launch axes, rigid motion included)",
        n_el + 1,
    );
    plan.add("transverse w, w′ at nodes (launch axes)", 2 * (n_el + 1));
    plan.add("discrete-mass U", nm);
    plan.add("discrete-mass W", nm);
    plan.builds = vec![
        "consistent mass of the stepped case, variable with the stage-1 burn".into(),
        "thrust, chamber pressure, jet Coriolis along the case's mean axis".into(),
        "gravity at launch angle".into(),
        "axial-force / bending coupling ½∫EA u′w′²".into(),
    ];
    if nm > 0 {
        plan.builds
            .push("discrete masses on springs to the case and to each other".into());
    }
    if r.discrete_masses
        .iter()
        .any(|m| m.axial_damping > 0.0 || m.transverse_damping > 0.0)
        || r.springs
            .iter()
            .any(|m| m.axial_damping > 0.0 || m.transverse_damping > 0.0)
    {
        plan.builds.push("discrete dampers".into());
    }
    Ok(plan)
}

/// The driver, step and output settings of a run.
pub struct Prepared {
    pub driver: RocketDriver,
    pub h: f64,
    pub t_end: f64,
    pub output_interval: f64,
    pub stations: usize,
}

/// The driver, step and output settings of a run of `r`, the rocket of `scene`.
pub fn prepare(scene: &Scene, r: &Rocket, settings: &FemSettings) -> Result<Prepared, FemError> {
    let method = settings.method.unwrap_or(Method::ImplicitMidpoint);
    let caps = capabilities(method);
    if !caps.variable_mass {
        return Err(FemError::unsupported(format!(
            "fem rocket: method `{method}` cannot step the burning rocket's time-varying mass \
             M(t) (its momentum form would book the momentum the burnt mass carries off as a \
             force); use {}",
            crate::method::names_with("or", |c| c.variable_mass)
        )));
    }
    if settings.rtol.is_some() || settings.atol.is_some() {
        return Err(FemError::unsupported(
            "fem rocket: adaptive steps (`time.rtol`/`time.atol`); use --dt",
        ));
    }
    let dt_user = crate::settings::positive("time.dt", settings.dt)?;
    let t_end =
        crate::settings::positive("time.t_end", settings.t_end)?.unwrap_or(scene.simulation.t_end);
    let model = build(r, settings)?;
    let q = model.initial_shape(&r.initial_shape);
    let h = dt_user.unwrap_or(DEFAULT_STEP);
    let mut driver = RocketDriver::new(model, &q, method, h, RHO_INF)?;
    if caps.explicit {
        let bound = explicit_bound(&mut driver, t_end)?;
        let h = match dt_user {
            Some(dt) if dt > bound.0 => {
                return Err(FemError::StabilityBound {
                    dt,
                    bound: bound.0,
                    bound_kind: format!(
                        "{}, at the run's smallest mass",
                        crate::method::central_difference::BOUND_KIND
                    ),
                    location: describe_dof(&driver.steps.system.model, bound.1),
                });
            }
            Some(dt) => dt,
            None => {
                let safety = settings.safety_factor.unwrap_or(crate::run::DEFAULT_SAFETY);
                if !(safety > 0.0 && safety <= 1.0) {
                    return Err(FemError::InvalidSettings {
                        field: "time.safety_factor".into(),
                        message: format!("must lie in (0, 1], got {safety}"),
                    });
                }
                DEFAULT_STEP.min(safety * bound.0)
            }
        };
        driver.set_step(h);
    }
    Ok(Prepared {
        h: driver.steps.h_nominal,
        driver,
        t_end,
        output_interval: scene.simulation.output_interval,
        stations: scene.simulation.field_stations.max(2),
    })
}

/// Central difference's step bound of the linearized rocket at its smallest mass in the run
/// (at burn-out or t_end, whichever comes first: the bound shrinks as the stage burns; K and C
/// are constant), and the DOF where the binding mode is largest.
fn explicit_bound(driver: &mut RocketDriver, t_end: f64) -> Result<(f64, usize), FemError> {
    let mut st = driver.steps.state.clone();
    st.t = driver.burnout.min(t_end);
    let mut res = vec![0.0; driver.steps.system.ndof()];
    crate::method::central_difference::stability_bound(&mut driver.steps.system, &st, &mut res)
}

/// A DOF of the rocket by name: the node and slot of a case DOF, or a discrete mass's U or W.
fn describe_dof(model: &Model, dof: usize) -> String {
    let base = model.base();
    if dof < base {
        let slot = ["u", "w", "w′"][dof % model::DOFS_PER_NODE];
        return format!("rocket node {} {slot}", dof / model::DOFS_PER_NODE + 1);
    }
    let nm = model.masses.len();
    let (j, slot) = ((dof - base) % nm, if dof - base < nm { "U" } else { "W" });
    format!("rocket discrete_mass[{j}] {slot}")
}

/// A run of `r`, the rocket of `scene`.
pub fn simulate(scene: &Scene, r: &Rocket, settings: &FemSettings) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        mut driver,
        h,
        t_end,
        output_interval,
        stations,
    } = prepare(scene, r, settings)?;
    let specs = channel_specs(&driver.steps.system.model, stations);
    let mut obs = Observables::with_channels(&specs);
    let mut ledger = EnergyLedger::new(
        &[
            ledger_term::KINETIC,
            ledger_term::STRAIN,
            ledger_term::GRAVITY,
            ledger_term::DISCRETE_SPRING,
        ],
        &[
            ledger_term::THRUST,
            ledger_term::PRESSURE,
            ledger_term::CORIOLIS,
        ],
        &[ledger_term::DISCRETE_DAMPER, ledger_term::MASS_OUTFLOW],
    );
    let mut buf = Vec::with_capacity(specs.len());
    let sample = |d: &RocketDriver, buf: &mut Vec<f64>| {
        observe(
            &d.steps.system.model,
            d.steps.state.t,
            &d.steps.state.q,
            &d.steps.state.qd,
            stations,
            buf,
        )
    };
    sample(&driver, &mut buf);
    obs.push(0.0, &buf);
    outputs::push_ledger(&driver, &mut ledger);
    let burnout = driver.burnout;
    let equal = driver.steps.equal_steps();
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut verdict = StabilityVerdict::Completed;
    'outer: for k in 1..=n_out {
        let t_out = (k as f64 * output_interval).min(t_end);
        while driver.steps.state.t < t_out - 1e-9 * h {
            // Land on the output time and on burn-out (the loads and the mass rate jump there).
            let t = driver.steps.state.t;
            let t_stop = if t < burnout - 1e-9 * h && burnout < t_out {
                burnout
            } else {
                t_out
            };
            let rest = t_stop - t;
            let hk = if equal {
                // Central difference: equal steps between stop times (its stability).
                rest / (rest / h - 1e-9).ceil().max(1.0)
            } else if rest < h * (1.0 + 1e-9) {
                rest
            } else {
                h
            };
            let mut t1 = t + hk;
            if (t1 - t_stop).abs() < 1e-9 * h {
                t1 = t_stop;
            }
            if let Err(e) = driver.step(t1 - t, t1) {
                verdict = StabilityVerdict::Stopped {
                    diagnostic: e.into_stop_diagnostic()?,
                };
                break 'outer;
            }
        }
        sample(&driver, &mut buf);
        if buf.iter().any(|v| !v.is_finite()) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: crate::error::non_finite_state(driver.steps.state.t),
            };
            break;
        }
        obs.push(driver.steps.state.t, &buf);
        outputs::push_ledger(&driver, &mut ledger);
    }
    Ok(crate::run::run_result(
        scene,
        settings,
        obs,
        ledger,
        Vec::new(),
        driver
            .steps
            .counters
            .cost(driver.steps.system.model.n, start),
        verdict,
    ))
}
