//! The dynamic run: y = (q, ν, W) with q̇ = S(q) ν, M_r ν̇ = Q_r − bias and the four work
//! integrals W (wheel and joint input work, wheel and joint friction work), integrated by a
//! registered method of [`crate::integrate`], stepping onto every torque breakpoint (the
//! schedules are piecewise constant) and sampling on the dense output.
//!
//! Implicit methods get [`OdeRhs::jacobian`] from the linear stiff part (exact ∂(Sν)/∂(q, ν),
//! −M_r⁻¹K on the elastic coordinates, −M_r⁻¹D on the speeds; the configuration dependence of
//! M_r, gravity and the gyroscopic terms left out): the stages still solve the exact equations
//! (simplified Newton on an approximate matrix converges to the same root), and the neglected
//! terms (∼g/L, joint rates ∼1 rad/s) are small against 1/h.

use std::time::Instant;

use data::channel;
use data::scene::MobileManipulator;
use data::{EnergyLedger, ModalSettings, Observables, RunResult, Scene, ledger_term};

use super::model::{MobileModel, Workspace};
use super::{Inputs, set_up};
use crate::error::ModalError;
use crate::integrate::{Build, OdeRhs, Stretch, Tolerances, method_for, oscillators_refused};
use crate::linalg::{cholesky_factor, cholesky_substitute};
use crate::sampled::{SampledRun, Schedule, run_sampled};

/// Default (rtol, atol): atol in metres and radians (unit-scaled modal coordinates) and joules.
pub const DEFAULT_TOL: (f64, f64) = (1e-8, 1e-10);

/// Number of work integrals carried in the state.
pub const N_WORK: usize = 4;

/// The remedy of a stopped run's diagnostic.
const REMEDY: &str = "tighten or loosen time.rtol/time.atol, or check the scene's parameters";

/// The equations as y' = f(t, y).
pub struct MobileRhs {
    pub model: MobileModel,
    pub inputs: Inputs,
    pub ws: Workspace,
    tau: Vec<f64>,
    qd: Vec<f64>,
    sdn: Vec<f64>,
    unit: Vec<f64>,
    col: Vec<f64>,
    /// First non-positive pivot met (the reduced mass matrix lost definiteness).
    pub failure: Option<f64>,
    /// The stretch between the schedules' discontinuities being integrated: the inputs are
    /// read at [`Stretch::input_time`].
    stretch: Stretch,
}

impl MobileRhs {
    pub fn new(model: MobileModel, inputs: Inputs) -> Self {
        let ws = Workspace::new(&model);
        let (n, m) = (model.layout.n, model.layout.m);
        MobileRhs {
            model,
            inputs,
            ws,
            tau: vec![0.0; m.max(6)],
            qd: vec![0.0; n],
            sdn: vec![0.0; n],
            unit: vec![0.0; m],
            col: vec![0.0; m],
            failure: None,
            stretch: Stretch::OPEN,
        }
    }

    pub fn n(&self) -> usize {
        self.model.layout.n
    }
    pub fn m(&self) -> usize {
        self.model.layout.m
    }

    /// Evaluates M_r and the right-hand side at (t, q, ν) and solves for ν̇ into `nud`.
    pub fn accelerations(&mut self, t: f64, q: &[f64], nu: &[f64], nud: &mut [f64]) {
        let m = self.m();
        self.inputs.at(self.stretch.input_time(t), &mut self.tau);
        self.model.equations(q, nu, &self.tau, &mut self.ws);
        nud[..m].copy_from_slice(&self.ws.force);
        if cholesky_factor(&mut self.ws.mass, m).is_err() {
            self.failure.get_or_insert(t);
            nud[..m].fill(f64::NAN);
            return;
        }
        cholesky_substitute(&self.ws.mass, m, &mut nud[..m]);
    }
}

impl OdeRhs for MobileRhs {
    fn dim(&self) -> usize {
        self.n() + self.m() + N_WORK
    }

    fn set_stretch(&mut self, stretch: Stretch) {
        self.stretch = stretch;
    }

    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let (n, m) = (self.n(), self.m());
        let (q, nu) = (&y[..n], &y[n..n + m]);
        self.model.velocities(q, nu, &mut self.qd, &mut self.sdn);
        dydt[..n].copy_from_slice(&self.qd);
        let (_, rest) = dydt.split_at_mut(n);
        self.accelerations(t, q, nu, &mut rest[..m]);
        rest[m..m + N_WORK].copy_from_slice(&self.ws.power);
    }

    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> bool {
        let (n, m) = (self.n(), self.m());
        let dim = n + m + N_WORK;
        jac.fill(0.0);
        let l = self.model.layout;
        let (q, nu) = (&y[..n], &y[n..n + m]);
        // ∂(S ν)/∂ν = S (columns n + i), ∂(S ν)/∂ψ on ẋ, ẏ.
        for i in 0..m {
            self.unit.fill(0.0);
            self.unit[i] = 1.0;
            self.model
                .velocities(q, &self.unit, &mut self.qd, &mut self.sdn);
            for a in 0..n {
                jac[(n + i) * dim + a] = self.qd[a];
            }
        }
        if let (Some(pl), Some(p)) = (l.platform, &self.model.platform) {
            let (s, c) = q[pl + 2].sin_cos();
            let u = 0.5 * p.wheel_radius * (nu[0] + nu[1]);
            jac[(pl + 2) * dim + pl] = -u * s;
            jac[(pl + 2) * dim + pl + 1] = u * c;
        }
        // Mass matrix at (t, y): factor once, then M⁻¹ times the stiffness and friction columns.
        self.inputs.at(self.stretch.input_time(t), &mut self.tau);
        self.model.equations(q, nu, &self.tau, &mut self.ws);
        if cholesky_factor(&mut self.ws.mass, m).is_err() {
            return false;
        }
        let col = &mut self.col;
        let shift = l.speed_shift();
        // Friction: ∂ν̇/∂νⱼ = −M⁻¹ D eⱼ.
        let mut k = 0;
        if let Some(p) = &self.model.platform {
            for s in 0..2 {
                col.fill(0.0);
                col[s] = -p.side_friction;
                cholesky_substitute(&self.ws.mass, m, col);
                for i in 0..m {
                    jac[(n + s) * dim + n + i] = col[i];
                }
            }
            k = 2;
        }
        if l.arm.is_some() {
            for j in 0..4 {
                col.fill(0.0);
                col[k + j] = -self.model.joint_friction[j];
                cholesky_substitute(&self.ws.mass, m, col);
                for i in 0..m {
                    jac[(n + k + j) * dim + n + i] = col[i];
                }
            }
        }
        // Stiffness: ∂ν̇/∂q_e = −M⁻¹ K e.
        if let (Some(fl), Some(e0)) = (&self.model.flex, l.elastic) {
            let nm = l.modes;
            for (dir, ei) in [(0, fl.ei_out), (1, fl.ei_in)] {
                for j in 0..nm {
                    col.fill(0.0);
                    for i in 0..nm {
                        col[e0 - shift + dir * nm + i] = -ei * fl.curvature[i * nm + j];
                    }
                    cholesky_substitute(&self.ws.mass, m, col);
                    let qcol = e0 + dir * nm + j;
                    for i in 0..m {
                        jac[qcol * dim + n + i] = col[i];
                    }
                }
            }
        }
        true
    }
}

/// The method named in the settings, or the default: Dormand–Prince 5(4).
fn method(settings: &ModalSettings) -> &'static crate::integrate::MethodInfo {
    settings
        .method
        .map_or(&crate::integrate::DOPRI5, method_for)
}

/// A run of `mm`, the manipulator of `scene`.
pub fn simulate(
    scene: &Scene,
    mm: &MobileManipulator,
    settings: &ModalSettings,
) -> Result<RunResult, ModalError> {
    let wall = Instant::now();
    let (model, inputs) = set_up(mm, settings)?;
    let method = method(settings);
    if let Some(message) = oscillators_refused(method, "the mobile manipulator") {
        return Err(ModalError::invalid("time.method", message));
    }
    let rtol = settings.rtol.unwrap_or(DEFAULT_TOL.0);
    let atol = settings.atol.unwrap_or(DEFAULT_TOL.1);
    if !(rtol > 0.0 && atol > 0.0 && rtol < 1.0 && atol.is_finite()) {
        return Err(ModalError::invalid(
            "time.rtol/atol",
            "tolerances must be positive (rtol below 1)",
        ));
    }
    let t_end = crate::setup::checked_span(scene, settings)?;
    let mut rhs = MobileRhs::new(model, inputs);
    let (n, m) = (rhs.n(), rhs.m());
    let dim = n + m + N_WORK;
    let mut y = vec![0.0; dim];
    initial_state(&rhs.model, mm, &mut y);
    let tol = Tolerances { rtol, atol };
    let mut stepper = match method.build {
        Build::Adaptive(build) => build(dim, tol, settings.dt),
        Build::Fixed(build) => {
            let dt = settings.dt.ok_or_else(|| {
                ModalError::invalid(
                    "time.dt",
                    format!(
                        "the fixed-step method `{}` needs --dt on the mobile manipulator",
                        method.name
                    ),
                )
            })?;
            build(dim, tol, dt)
        }
    };
    let mut breaks = rhs.inputs.breakpoints(t_end);
    breaks.push(t_end);

    let mut out = Output::new(&rhs.model, mm);
    out.record(&mut rhs, 0.0, &y);
    let schedule = Schedule {
        breaks: &breaks,
        output_interval: scene.simulation.output_interval,
        t_end,
        remedy: REMEDY,
    };
    let verdict = run_sampled(stepper.as_mut(), &mut rhs, &mut y, schedule, &mut out);
    let st = stepper.stats();
    Ok(RunResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        observables: out.obs,
        ledger: out.ledger,
        events: Vec::new(),
        cost: st.cost(m, wall),
        verdict,
    })
}

/// y(0): the scene's pose and rates, undeformed link at rest relative to its frame, no work.
pub fn initial_state(model: &MobileModel, mm: &MobileManipulator, y: &mut [f64]) {
    let l = model.layout;
    y.fill(0.0);
    let n = l.n;
    let mut k = 0;
    if let Some(pl) = l.platform {
        y[pl] = mm.initial.x;
        y[pl + 1] = mm.initial.y;
        y[pl + 2] = mm.initial.heading;
        y[n] = mm.initial.wheel_rates[0];
        y[n + 1] = mm.initial.wheel_rates[1];
        k = 2;
    }
    if let Some(a0) = l.arm {
        y[a0..a0 + 4].copy_from_slice(&mm.initial.joint_angles);
        y[n + k..n + k + 4].copy_from_slice(&mm.initial.joint_rates);
    }
}

/// Sampled observables and the energy ledger (terms as the rigid reference names them, plus
/// `strain`).
struct Output {
    obs: Observables,
    ledger: EnergyLedger,
    row: Vec<f64>,
    qd: Vec<f64>,
    sdn: Vec<f64>,
    tau: Vec<f64>,
}

impl Output {
    fn new(model: &MobileModel, mm: &MobileManipulator) -> Self {
        let l = model.layout;
        let specs = channel::mobile_manipulator(mm);
        let mut stored = vec![ledger_term::KINETIC, ledger_term::GRAVITY];
        if model.flex.is_some() {
            stored.push(ledger_term::STRAIN);
        }
        let n = l.n;
        Output {
            obs: Observables::with_channels(&specs),
            ledger: EnergyLedger::new(
                &stored,
                &[ledger_term::WHEEL_TORQUE, ledger_term::JOINT_TORQUE],
                &[ledger_term::WHEEL_FRICTION, ledger_term::JOINT_FRICTION],
            ),
            row: Vec::with_capacity(specs.len()),
            qd: vec![0.0; n],
            sdn: vec![0.0; n],
            tau: vec![0.0; l.m.max(6)],
        }
    }
}

impl SampledRun<MobileRhs> for Output {
    fn failure(&self, rhs: &MobileRhs) -> Option<(f64, &'static str)> {
        rhs.failure
            .map(|tf| (tf, "the reduced mass matrix is not positive definite"))
    }

    fn record(&mut self, rhs: &mut MobileRhs, t: f64, y: &[f64]) {
        let model = &rhs.model;
        let l = model.layout;
        let (n, m) = (l.n, l.m);
        let (q, nu) = (&y[..n], &y[n..n + m]);
        model.velocities(q, nu, &mut self.qd, &mut self.sdn);
        rhs.inputs.at(t, &mut self.tau);
        self.row.clear();
        let mut k = 0;
        if let Some(p) = l.platform {
            self.row.extend_from_slice(&q[p..p + 5]);
            self.row.extend_from_slice(&self.tau[..2]);
            k = 2;
        }
        if let Some(a) = l.arm {
            for i in 0..4 {
                self.row.extend([q[a + i], self.qd[a + i], self.tau[k + i]]);
            }
            self.row.extend_from_slice(model.end_effector(q).as_slice());
        }
        if let Some((v, w)) = model.tip_deflection(q) {
            self.row.extend([w, v]);
        }
        self.row.push(model.constraint_residual(q, &self.qd));
        self.obs.push(t, &self.row);
        let kinetic = model.kinetic_energy(q, &self.qd, rhs.ws.nodes_mut());
        let gravity = model.gravity_energy(q, rhs.ws.nodes_mut());
        let w = &y[n + m..n + m + N_WORK];
        if model.flex.is_some() {
            let strain = model.strain_energy(q);
            self.ledger
                .push(t, &[kinetic, gravity, strain], &w[..2], &w[2..]);
        } else {
            self.ledger.push(t, &[kinetic, gravity], &w[..2], &w[2..]);
        }
    }
}
