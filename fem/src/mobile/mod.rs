//! The mobile manipulator of seed 004 with one flexible pitch link (scene family
//! `[mobile_manipulator]` with `[mobile_manipulator.flexible_link]`).
//!
//! ## Model (the continuum model fem and modal share)
//! Rigid part as in the scene's convention (docs/mobile-manipulator.md): platform with the
//! no-sideways-slip and per-side rolling constraints, turret θ₁, pitch links θ₂…θ₄, gripper,
//! viscous joint and wheel friction, gravity, torque schedules. The flexible link j (frame F)
//! has material points p(x) = o_F + R_F(x e_x + v(x) e_y + w(x) e_z), x ∈ [0, L], clamped at
//! x = 0 (v = v′ = w = w′ = 0): v out of the arm's plane (EI_out), w in it (EI_in),
//! Euler–Bernoulli, linear floating frame of reference (no axial or torsional field, no
//! foreshortening, no geometric stiffening). That is acceptable here because the axial load on
//! the link stays below ~10 N, so P L²/EI ≤ 1e-3 at the scene's EI, and the joint rates are slow
//! (centrifugal stiffening ρA Ω² L⁴/EI ≪ 1). Mass: uniform line density μ = m/L; the link's
//! inertia J about its centre minus the slender rod's diag(0, mL²/12, mL²/12) is carried rigidly
//! by F (massless residual body), so that at EI → ∞ the link is the rigid link (m, com L/2, J).
//! The tip frame sits at o_F + R_F(L, v(L), w(L)) with orientation R_F R_z(v′(L)) R_y(−w′(L)),
//! and the next pitch joint rotates it about its −y.
//!
//! T = Σ rigid bodies + ½∫μ|ṗ|² dx + ½ω_F·R_F J_res R_Fᵀ ω_F + ½J_side(φ̇_R² + φ̇_L²),
//! V = Σ m g z + ∫μ g p_z dx + ½∫(EI_out v″² + EI_in w″²) dx, D = ½Σbᵢθ̇ᵢ² + ½b_side(φ̇_R² + φ̇_L²).
//!
//! ## Discretization
//! N Hermite-cubic elements ([`crate::element::hermite_cubic`]) for v and w, DOFs (v, v′, w, w′) per
//! node; mass integrals by 4-point Gauss quadrature (exact), stiffness exact. The equations
//! are written on the null space of the constraints (speeds ν = (φ̇_R, φ̇_L, θ̇₁…θ̇₄, ė)) by
//! Kane's projection of every mass element's inertial force ([`model`]). The model with its
//! inputs is a reduced system ([`system::MobileSystem`], [`crate::method::reduced`]): time
//! integration by a reduced method, the implicit midpoint rule by default (and the one
//! registered) with a modified-Newton matrix M̄ + ¼h²K + ½hD refactorized once per step
//! ([`crate::method::reduced::implicit_midpoint`]). No dense finite-difference Jacobian; the
//! step loop does not allocate.
//!
//! ## Defaults and cost
//! Elements: [`DEFAULT_ELEMENTS`]. Step: min(output interval, T₁/[`STEPS_PER_PERIOD`]) with T₁
//! the first flexible period of the whole (unconstrained-joint) system linearized at the start
//! (stiffness K against the Schur complement of M̄ on the elastic speeds), fitted to divide the
//! output interval. The steps land on the torque schedules' breakpoints (the cost of the default
//! run: docs/mobile-manipulator.md). The midpoint rule has no numerical damping: the link's
//! ringing from its undeformed start (gravity) persists, undamped as in the model, and its phase
//! is not converged at the default step (the end-effector path is: 3.3e-7 of its peak against
//! h = 1e-4 s; data/cases/mobile_flex_fem.toml). Modes above ~1/h are not resolved but stay
//! bounded.
//! A finer mesh raises |K| and with it the round-off of the elastic forces, so the Newton
//! iteration also accepts an update that has stalled at that floor
//! ([`crate::method::reduced::implicit_midpoint::STALL_TOL`]).
//!
//! ## Outputs
//! The reference's channels (`platform.x`, `platform.y`, `platform.heading`,
//! `wheel_right.angle`, `wheel_left.angle`, `wheel_right.torque`, `wheel_left.torque`,
//! `jointK.angle/rate/torque`, `ee.x/y/z` the gripper frame origin) plus `linkJ.tip_in_plane`
//! (w(L)), `linkJ.tip_out_of_plane` (v(L)) and `constraint.drift` (|A(q) S(q) ν|∞, round-off
//! by construction). Ledger: stored `kinetic`, `gravity`, `strain`; inputs `wheel_torque`,
//! `joint_torque`; dissipation `wheel_friction`, `joint_friction` (the reference's names).

pub mod model;
pub mod system;

use std::time::Instant;

use data::channel;
use data::results::ledger_term;
use data::scene::MobileManipulator;
use data::{DofPlan, EnergyLedger, FemSettings, Observables, RunResult, Scene, StabilityVerdict};

pub use model::Model;
pub use system::{Inputs, MobileSystem, Works};

use crate::error::FemError;
use crate::linalg::{DenseLlt, dot, max_abs};
use crate::method::reduced::{self, ReducedState, ReducedStepper};
use crate::settings;

/// Elements on the flexible link when `discretization.elements` is absent.
pub const DEFAULT_ELEMENTS: usize = 4;
/// Midpoint steps per first flexible period for the default step.
pub const STEPS_PER_PERIOD: f64 = 40.0;

/// Refuses the rigid manipulator (verify's reference solves it).
fn check_flexible(mm: &MobileManipulator) -> Result<(), FemError> {
    if mm.flexible_link.is_none() {
        return Err(FemError::unsupported(
            "fem mobile manipulator: rigid scenes are verify's reference (`--backend \
             reference`); fem runs the flexible variant (`[mobile_manipulator.flexible_link]`)",
        ));
    }
    Ok(())
}

fn elements(settings: &data::FemSettings) -> Result<usize, FemError> {
    settings::cubic_elements_or(
        settings,
        DEFAULT_ELEMENTS,
        "mobile manipulator",
        "the flexible link",
    )
}

/// DOFs and physics built for the scene.
pub fn dof_plan(mm: &MobileManipulator, settings: &data::FemSettings) -> Result<DofPlan, FemError> {
    check_flexible(mm)?;
    let n_el = elements(settings)?;
    let md = Model::new(mm, n_el)?;
    let mut plan = DofPlan::default();
    if md.platform.is_some() {
        plan.add("platform velocity freedoms (φ̇_R, φ̇_L)", 2);
    }
    plan.add("arm joints θ₁…θ₄", 4);
    if let Some(fl) = &md.flex {
        let j = fl.link + 1;
        plan.add(format!("link{j} out-of-plane v, v′"), 2 * n_el);
        plan.add(format!("link{j} in-plane w, w′"), 2 * n_el);
        plan.builds.push(format!(
            "link{j}: Euler–Bernoulli beam in two bending planes, {n_el} Hermite-cubic \
             elements, clamped in its frame (linear floating frame, no axial/torsion field)"
        ));
        plan.builds.push(format!(
            "link{j}: residual inertia J − diag(0, mL²/12, mL²/12) carried by its frame"
        ));
    }
    if md.platform.is_some() {
        plan.builds.push(
            "platform x, y, ψ, φ_R, φ_L under 3 nonholonomic constraints (null-space speeds)"
                .into(),
        );
    }
    plan.builds
        .push("turret, rigid pitch links and gripper with full inertia tensors".into());
    if md.gravity != 0.0 {
        plan.builds.push("gravity".into());
    }
    plan.builds
        .push("joint and wheel viscous friction, torque schedules".into());
    Ok(plan)
}

/// Initial (q, ν): the scene's pose and rates, the flexible link undeformed and at rest.
pub fn initial_state(md: &Model, mm: &MobileManipulator) -> (Vec<f64>, Vec<f64>) {
    let l = md.layout;
    let mut q = vec![0.0; l.n];
    let mut nu = vec![0.0; l.m];
    if l.platform {
        q[0] = mm.initial.x;
        q[1] = mm.initial.y;
        q[2] = mm.initial.heading;
        nu[..2].copy_from_slice(&mm.initial.wheel_rates);
    }
    q[l.q_arm..l.q_arm + 4].copy_from_slice(&mm.initial.joint_angles);
    nu[l.nu_arm..l.nu_arm + 4].copy_from_slice(&mm.initial.joint_rates);
    (q, nu)
}

/// Lowest flexible circular frequency of the system linearized at (q, ν = 0): the elastic
/// stiffness against the Schur complement of M̄ on the elastic speeds (rigid speeds free), by
/// inverse power iteration.
pub fn first_flexible_frequency(md: &Model, q: &[f64]) -> Result<f64, FemError> {
    let l = md.layout;
    let Some(fl) = &md.flex else {
        return Ok(f64::INFINITY);
    };
    let (m, nr, ne) = (l.m, l.nu_el, fl.ne);
    let mut ws = model::Workspace::new(l.n);
    let mut mass = vec![0.0; m * m];
    let mut force = vec![0.0; m];
    let zeros = vec![0.0; m];
    md.evaluate(q, &zeros, &zeros, &mut ws, Some(&mut mass), &mut force);
    // M_eff = M_ee − M_er M_rr⁻¹ M_re.
    let mut mrr = vec![0.0; nr * nr];
    for i in 0..nr {
        for j in 0..nr {
            mrr[i * nr + j] = mass[i * m + j];
        }
    }
    let singular = |what: &str| FemError::Numerical {
        t: 0.0,
        message: format!("fem mobile manipulator: {what} is not positive definite"),
    };
    let mut rigid = DenseLlt::new(nr);
    rigid
        .factor(&mrr)
        .map_err(|_| singular("the rigid block of the mass matrix"))?;
    let mut meff = vec![0.0; ne * ne];
    let mut col = vec![0.0; nr];
    for j in 0..ne {
        for i in 0..nr {
            col[i] = mass[i * m + nr + j];
        }
        rigid.solve(&mut col);
        for i in 0..ne {
            let mer: f64 = (0..nr).map(|k| mass[(nr + i) * m + k] * col[k]).sum();
            meff[i * ne + j] = mass[(nr + i) * m + nr + j] - mer;
        }
    }
    let mut k = DenseLlt::new(ne);
    k.factor(&fl.stiffness)
        .map_err(|_| singular("the elastic stiffness"))?;
    // Power iteration on K⁻¹ M_eff: its largest eigenvalue is 1/ω₁².
    let mut x = vec![1.0; ne];
    let mut y = vec![0.0; ne];
    let mut lambda = 0.0;
    for _ in 0..200 {
        for i in 0..ne {
            y[i] = (0..ne).map(|j| meff[i * ne + j] * x[j]).sum();
        }
        k.solve(&mut y);
        let xy = dot(&x, &y);
        let xx = dot(&x, &x);
        let new = xy / xx;
        let norm = max_abs(&y);
        for i in 0..ne {
            x[i] = y[i] / norm;
        }
        if (new - lambda).abs() <= 1e-10 * new {
            lambda = new;
            break;
        }
        lambda = new;
    }
    Ok(1.0 / lambda.sqrt())
}

/// A step that divides `interval`, no longer than `target`.
fn fit(target: f64, interval: f64) -> f64 {
    interval / (interval / target).ceil().max(1.0)
}

/// A run in progress: the system, its state, the method stepping it and the integrated works.
pub struct Run {
    pub system: MobileSystem,
    pub state: ReducedState,
    pub works: Works,
    pub method: Box<dyn ReducedStepper<MobileSystem>>,
}

impl Run {
    /// The run of `model` driven by `inputs` from (q, ν) at t = 0, stepped by `method`;
    /// refuses a method that does not step reduced systems.
    pub fn new(
        model: Model,
        inputs: Inputs,
        q: Vec<f64>,
        nu: Vec<f64>,
        method: settings::Method,
    ) -> Result<Self, FemError> {
        let system = MobileSystem::new(model, inputs);
        let method = reduced::stepper(method, &system).ok_or_else(|| {
            FemError::unsupported(format!(
                "fem mobile manipulator: method `{method}`; this family is a system on the \
                 null space of its nonholonomic constraints, stepped by {}",
                reduced::names("or")
            ))
        })?;
        Ok(Run {
            system,
            state: ReducedState { t: 0.0, q, nu },
            works: Works::default(),
            method,
        })
    }

    /// One step of length h.
    pub fn step(&mut self, h: f64) -> Result<(), FemError> {
        self.method
            .step(&mut self.system, &mut self.state, &mut self.works, h)
    }
}

/// A run ready to step.
pub struct Prepared {
    pub run: Run,
    pub h: f64,
    pub t_end: f64,
    pub output_interval: f64,
}

/// The run, step and output settings of `mm`, the manipulator of `scene`.
pub fn prepare(
    scene: &Scene,
    mm: &MobileManipulator,
    settings: &FemSettings,
) -> Result<Prepared, FemError> {
    check_flexible(mm)?;
    let n_el = elements(settings)?;
    if settings.rtol.is_some() || settings.atol.is_some() {
        return Err(FemError::unsupported(
            "fem mobile manipulator: adaptive steps (`time.rtol`/`time.atol`); use --dt",
        ));
    }
    let dt_user = settings::positive("time.dt", settings.dt)?;
    let t_end = settings::positive("time.t_end", settings.t_end)?.unwrap_or(scene.simulation.t_end);
    let out = scene.simulation.output_interval;
    let md = Model::new(mm, n_el)?;
    let arm = mm
        .arm
        .as_ref()
        .ok_or_else(|| FemError::unsupported("fem mobile manipulator: no arm"))?;
    let inputs = Inputs {
        drive: mm.platform.as_ref().map(|p| p.drive.clone()),
        arm: arm.torques.clone(),
    };
    let (q, nu) = initial_state(&md, mm);
    let h = match dt_user {
        Some(h) => h,
        None => {
            let omega = first_flexible_frequency(&md, &q)?;
            fit(
                (2.0 * std::f64::consts::PI / (STEPS_PER_PERIOD * omega)).min(out),
                out,
            )
        }
    };
    let method = settings.method.unwrap_or(data::FemMethod::ImplicitMidpoint);
    Ok(Prepared {
        run: Run::new(md, inputs, q, nu, method)?,
        h,
        t_end,
        output_interval: out,
    })
}

fn sample(run: &mut Run, buf: &mut Vec<f64>) {
    buf.clear();
    let Run { system, state, .. } = run;
    let (q, nu) = (&state.q, &state.nu);
    let l = system.model.layout;
    let tau = system.torques(state.t).to_vec();
    if l.platform {
        buf.extend_from_slice(&q[..5]);
        buf.extend_from_slice(&tau[..2]);
    }
    for i in 0..4 {
        buf.extend([q[l.q_arm + i], nu[l.nu_arm + i], tau[l.nu_arm + i]]);
    }
    buf.extend(system.model.end_effector(q).iter());
    if let Some(fl) = &system.model.flex {
        let tip = fl.tip(&q[l.q_el..]);
        buf.extend([tip[2], tip[0]]);
    }
    let qd = system.coordinate_rates(q, nu).to_vec();
    buf.push(system.model.constraint_residual(q, &qd));
}

fn push_ledger(run: &mut Run, ledger: &mut EnergyLedger) {
    let Run {
        system,
        state,
        works: w,
        ..
    } = run;
    let q = &state.q;
    let qd = system.coordinate_rates(q, &state.nu).to_vec();
    let md = &system.model;
    let stored = [
        md.kinetic_energy(q, &qd),
        md.gravity_energy(q),
        md.strain_energy(q),
    ];
    let (inputs, diss): (Vec<f64>, Vec<f64>) = if md.platform.is_some() {
        (
            vec![w.wheel_torque, w.joint_torque],
            vec![w.wheel_friction, w.joint_friction],
        )
    } else {
        (vec![w.joint_torque], vec![w.joint_friction])
    };
    ledger.push(state.t, &stored, &inputs, &diss);
}
/// The ledger's term names (the reference's, plus strain).
pub fn ledger_names(md: &Model) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
    let stored = vec![
        ledger_term::KINETIC,
        ledger_term::GRAVITY,
        ledger_term::STRAIN,
    ];
    if md.platform.is_some() {
        (
            stored,
            vec![ledger_term::WHEEL_TORQUE, ledger_term::JOINT_TORQUE],
            vec![ledger_term::WHEEL_FRICTION, ledger_term::JOINT_FRICTION],
        )
    } else {
        (
            stored,
            vec![ledger_term::JOINT_TORQUE],
            vec![ledger_term::JOINT_FRICTION],
        )
    }
}

/// Steps from the current state to `t_stop`, landing on every breakpoint on the way.
pub fn advance(run: &mut Run, h: f64, t_stop: f64, breakpoints: &[f64]) -> Result<(), FemError> {
    while run.state.t < t_stop - 1e-9 * h {
        let t = run.state.t;
        let next_break = breakpoints
            .iter()
            .copied()
            .find(|&b| b > t + 1e-9 * h)
            .unwrap_or(f64::INFINITY);
        let target = t_stop.min(next_break);
        let rest = target - t;
        let hk = if rest < h * (1.0 + 1e-9) { rest } else { h };
        run.step(hk)?;
        if (run.state.t - target).abs() < 1e-9 * h {
            run.state.t = target;
        }
    }
    Ok(())
}

/// A run of `mm`, the manipulator of `scene`.
pub fn simulate(
    scene: &Scene,
    mm: &MobileManipulator,
    settings: &FemSettings,
) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        mut run,
        h,
        t_end,
        output_interval,
    } = prepare(scene, mm, settings)?;
    let specs = channel::mobile_manipulator(mm);
    let mut obs = Observables::with_channels(&specs);
    let (s, i, d) = ledger_names(&run.system.model);
    let mut ledger = EnergyLedger::new(&s, &i, &d);
    let breakpoints = run.system.inputs.breakpoints(t_end);
    let mut buf = Vec::with_capacity(specs.len());
    sample(&mut run, &mut buf);
    obs.push(0.0, &buf);
    push_ledger(&mut run, &mut ledger);
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut verdict = StabilityVerdict::Completed;
    for k in 1..=n_out {
        let t_stop = (k as f64 * output_interval).min(t_end);
        if let Err(e) = advance(&mut run, h, t_stop, &breakpoints) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: e.into_stop_diagnostic()?,
            };
            break;
        }
        sample(&mut run, &mut buf);
        if buf.iter().any(|v| !v.is_finite()) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: crate::error::non_finite_state(run.state.t),
            };
            break;
        }
        obs.push(run.state.t, &buf);
        push_ledger(&mut run, &mut ledger);
    }
    Ok(crate::run::run_result(
        scene,
        settings,
        obs,
        ledger,
        Vec::new(),
        run.method.counters().cost(run.system.model.layout.m, start),
        verdict,
    ))
}
