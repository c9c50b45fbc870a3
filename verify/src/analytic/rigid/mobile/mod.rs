//! Rigid reference of the mobile manipulator (seed 004), derived from the energies.
//!
//! Coordinates q = (x, y, ψ, φ_R, φ_L, θ₁, θ₂, θ₃, θ₄) (the platform's or the arm's part only
//! when the other is absent). Kinetic energy T = ½ q̇ᵀ M(q) q̇ from the bodies' velocities,
//! potential V = Σ m g z, Rayleigh function D = ½ Σ bᵢ θ̇ᵢ² + ½ b_side (φ̇_R² + φ̇_L²); the
//! platform's no-sideways-slip and rolling constraints A(q) q̇ = 0 are nonholonomic, so there
//! is no position-level constraint to drift. Equations and frames: [`model`]; the two
//! formulations (multipliers / null space), inverse dynamics and the ledger: [`forward`]; the
//! seed's printed expressions next to their corrections: [`seed`]. A scene's
//! `[mobile_manipulator.flexible_link]` is ignored: the reference is the flexible variant's
//! EI → ∞ limit (the backends' beam carries the link's mass, mass centre and inertia exactly).
//!
//! The run's observables: `platform.x`, `platform.y`, `platform.heading`, `wheel_right.angle`,
//! `wheel_left.angle`, `jointI.angle` / `.rate` / `.torque`, `ee.x`, `ee.y`, `ee.z` (tip of link
//! 3, inertial), and the self-checks `constraint.drift` (|A q̇|∞ of the multiplier run before
//! each projection), `formulations.position_gap` / `.rate_gap` (multiplier run − reduced run),
//! `inverse.torque_residual` (inverse-dynamics torques − applied, max over inputs) and, for a
//! fixed-base arm whose bodies' principal axes are aligned with the link frames,
//! `seed_eq37.residual` (|τ₁ inverse − τ₁ of the corrected eqs. 37–43|). Ledger: stored
//! `kinetic`, `gravity`; inputs `wheel_torque`, `joint_torque`; dissipation `wheel_friction`,
//! `joint_friction`.

pub mod forward;
pub mod model;
pub mod seed;

use std::time::Instant;

use data::channel::{self, spec};
use data::ledger_term;
use data::scene::MobileManipulator;
use data::{
    BackendError, BackendKind, Cost, EnergyLedger, Observables, RunResult, Scene, Settings,
    StabilityVerdict,
};

pub use forward::{History, Reference, Sample, Tolerances};
pub use model::Model;

use crate::analytic::error::AnalyticError;

fn to_backend_error(e: AnalyticError) -> BackendError {
    match e {
        AnalyticError::Unsupported(s) => BackendError::Unsupported(s),
        e => BackendError::Numerical {
            t: f64::NAN,
            message: format!("mobile reference: {e}"),
        },
    }
}

/// The rigid reference of a `[mobile_manipulator]` scene (`mm` is its model) as a run result
/// (backend `reference`).
pub fn simulate(
    scene: &Scene,
    mm: &MobileManipulator,
    settings: &Settings,
) -> Result<RunResult, BackendError> {
    let start = Instant::now();
    let settings = settings.reference()?;
    let mut tol = Tolerances::default();
    for (field, v, slot) in [
        ("rtol", settings.rtol, &mut tol.rtol),
        ("atol", settings.atol, &mut tol.atol),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0 && v < 1.0) {
                return Err(BackendError::InvalidSettings {
                    field: field.into(),
                    message: format!("{v} is not in (0, 1)"),
                });
            }
            *slot = v;
        }
    }
    let t_end = settings.t_end.unwrap_or(scene.simulation.t_end);
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(BackendError::InvalidSettings {
            field: "t_end".into(),
            message: format!("{t_end} is not positive"),
        });
    }
    let reference = Reference::from_scene(mm).map_err(to_backend_error)?;
    let history = reference
        .run(t_end, scene.simulation.output_interval, tol)
        .map_err(to_backend_error)?;
    let closed_form = seed::ClosedFormArm::from_scene(mm);
    let model = &reference.model;
    let layout = model.layout;

    let mut specs = channel::mobile_manipulator_rigid(mm);
    specs.extend([
        spec::formulations_position_gap(),
        spec::formulations_rate_gap(),
        spec::inverse_torque_residual(),
    ]);
    if closed_form.is_some() {
        specs.push(spec::seed_eq37_residual());
    }
    let mut obs = Observables::with_channels(&specs);
    let mut ledger = EnergyLedger::new(
        &[ledger_term::KINETIC, ledger_term::GRAVITY],
        &[ledger_term::WHEEL_TORQUE, ledger_term::JOINT_TORQUE],
        &[ledger_term::WHEEL_FRICTION, ledger_term::JOINT_FRICTION],
    );
    let mut row = Vec::with_capacity(specs.len());
    for s in &history.samples {
        row.clear();
        let mut k = 0;
        if let Some(p) = layout.platform {
            row.extend_from_slice(&s.q[p..p + 5]);
            row.extend_from_slice(&s.tau[..2]);
            k = 2;
        }
        if let Some(a) = layout.arm {
            for i in 0..4 {
                row.extend([s.q[a + i], s.qd[a + i], s.tau[k + i]]);
            }
            row.extend_from_slice(&s.end_effector);
        }
        let residual = s
            .tau
            .iter()
            .zip(&s.tau_inverse)
            .fold(0.0f64, |r, (a, b)| r.max((a - b).abs()));
        row.extend([s.drift, s.position_gap, s.rate_gap, residual]);
        if let (Some(cf), Some(a)) = (&closed_form, layout.arm) {
            let th: [f64; 4] = std::array::from_fn(|i| s.q[a + i]);
            let thd: [f64; 4] = std::array::from_fn(|i| s.qd[a + i]);
            let thdd: [f64; 4] = std::array::from_fn(|i| s.qdd[a + i]);
            row.push((cf.tau1_corrected(&th, &thd, &thdd) - s.tau_inverse[0]).abs());
        }
        obs.push(s.t, &row);
        ledger.push(s.t, &[s.kinetic, s.potential], &s.work[..2], &s.work[2..]);
    }
    let stats = history.reduced_stats;
    Ok(RunResult {
        backend: BackendKind::Reference,
        scene: scene.name.clone(),
        settings: Settings::from(&settings),
        observables: obs,
        ledger,
        events: Vec::new(),
        cost: Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs: layout.m,
            steps: stats.accepted_steps + history.dae_stats.accepted_steps,
            rejected_steps: stats.rejected_steps + history.dae_stats.rejected_steps,
            rhs_evaluations: stats.rhs_evaluations + history.dae_stats.rhs_evaluations,
            ..Cost::default()
        },
        verdict: StabilityVerdict::Completed,
    })
}

/// DOF plan of the reference for `describe`.
pub fn dof_plan(mm: &MobileManipulator) -> Result<data::DofPlan, BackendError> {
    let model = Model::from_scene(mm).map_err(to_backend_error)?;
    let mut plan = data::DofPlan::default();
    if model.layout.platform.is_some() {
        plan.add("platform velocity freedoms (φ̇_R, φ̇_L)", 2);
        plan.builds.push(format!(
            "platform x, y, ψ, φ_R, φ_L under {} nonholonomic constraints (no sideways slip, rolling per side)",
            model::N_CONSTRAINTS
        ));
    }
    if model.layout.arm.is_some() {
        plan.add("arm joints θ₁…θ₄", 4);
        plan.builds
            .push("turret, three pitch links and gripper with full inertia tensors".into());
    }
    plan.builds.push(
        "two formulations (multipliers with projection; null space Sᵀ M S) and inverse dynamics"
            .into(),
    );
    Ok(plan)
}
