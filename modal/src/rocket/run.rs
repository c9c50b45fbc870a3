//! The run of the reduced rocket on the shared sampled driver ([`crate::sampled`]), and the
//! observables, energy ledger and momentum balance sampled on it.
//!
//! The loads have one discontinuity, burn-out, the schedule's one breakpoint when it falls
//! inside the run: the method lands on it exactly and restarts there, and the right-hand side
//! is told the phase for each interval (burning up to burn-out, burnt out after it) rather than
//! deciding by time, so the step that ends at burn-out sees the burning loads at its end point
//! and the step that starts there sees none.
//! The rocket's hooks ([`RocketRun`]) add to the driver: a `StepRejected` event for each
//! accepted step that followed rejected attempts (at most [`MAX_REJECTION_EVENTS`]), a
//! `StepSizeChange` event at burn-out whose `to` is the first step after the restart, a stop when
//! an elastic displacement runs away ([`runaway`]), and a step failure diagnostic that names a
//! lost positive definiteness of the reduced mass matrix.

use std::time::Instant;

use data::scene::Rocket;

use data::{
    BackendKind, Diagnostic, EnergyLedger, Event, ModalSettings, Observables, RunResult,
    StabilityVerdict, channel, ledger_term,
};

use super::basis::Basis;
use super::body::Body;
use super::config::{self, Method, TimeConfig};
use super::dynamics::{Model, Phase, StationModes, Workspace, quad, rhs, snapshot};
use super::error::RocketError;
use crate::integrate::{Build, IntegrateError, OdeRhs, Stepper, Tolerances};
use crate::sampled::{SampledRun, Schedule, run_sampled};

/// The ODE right-hand side handed to the integrators.
struct RocketRhs<'a> {
    model: &'a Model,
    ws: Workspace,
}

impl OdeRhs for RocketRhs<'_> {
    fn dim(&self) -> usize {
        self.model.layout.state_len()
    }
    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        rhs(self.model, &mut self.ws, t, y, dydt);
    }
}

/// The reduced rocket as a first-order ODE y' = f(t, y), for callers that integrate it
/// themselves (benches, allocation checks, other integrators). State layout:
/// [q (X, Y, θ, a, b, u_j, w_j) | quasi-velocities (V_x, V_y, ω, ȧ, ḃ, u̇_j, ẇ_j) | 15 balances].
pub struct RocketOde {
    model: Model,
    ws: Workspace,
}

impl RocketOde {
    pub fn new(r: &Rocket, settings: &ModalSettings) -> Result<RocketOde, RocketError> {
        let body = Body::from_rocket(r)?;
        let n = config::modes(settings)?;
        let basis = Basis::new(&body, n)?;
        let model = Model::new(body, &basis);
        let ws = Workspace::new(model.layout);
        Ok(RocketOde { model, ws })
    }

    /// The scene's initial state (see the module docs).
    pub fn initial_state(&self) -> Vec<f64> {
        initial_state(&self.model)
    }

    /// Number of generalized coordinates (3 + 2n + 2·masses).
    pub fn dofs(&self) -> usize {
        self.model.layout.dofs()
    }
}

impl OdeRhs for RocketOde {
    fn dim(&self) -> usize {
        self.model.layout.state_len()
    }
    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        rhs(&self.model, &mut self.ws, t, y, dydt);
    }
}

fn initial_state(model: &Model) -> Vec<f64> {
    let l = model.layout;
    let mut y = vec![0.0; l.state_len()];
    y[2] = model.body.launch_angle;
    y[l.b()..l.b() + l.n].copy_from_slice(&model.initial_b);
    y
}

/// The stepper of an error-controlled method from the initial step `h0` (a fixed-step method,
/// possible in a [`TimeConfig`] built by hand, is refused as [`config::time`] refuses it).
fn stepper(
    method: Method,
    dim: usize,
    tol: Tolerances,
    h0: Option<f64>,
) -> Result<Box<dyn Stepper>, RocketError> {
    match method.build {
        Build::Adaptive(build) => Ok(build(dim, tol, h0)),
        Build::Fixed(_) => Err(config::fixed_step_refused(method)),
    }
}

/// Linear-momentum account of a run, sampled at the output times (inertial components).
///
/// Balance: P(t) − P(0) = I_thrust + I_pressure + I_coriolis + I_gravity + P_outflow, where
/// P_outflow = ∫∫ ṁ Ṙ dx dt is the momentum the burnt mass takes with it (it leaves the case
/// with the local case velocity). All impulses are integrated with the state, so the balance
/// holds to the integrator's tolerance.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MomentumBalance {
    pub time: Vec<f64>,
    pub total_mass: Vec<f64>,
    pub momentum: Vec<[f64; 2]>,
    pub impulse_thrust: Vec<[f64; 2]>,
    pub impulse_pressure: Vec<[f64; 2]>,
    pub impulse_coriolis: Vec<[f64; 2]>,
    pub impulse_gravity: Vec<[f64; 2]>,
    pub momentum_outflow: Vec<[f64; 2]>,
}

impl MomentumBalance {
    /// max over samples of |P − P₀ − Σ impulses| / max |P|.
    pub fn relative_residual(&self) -> f64 {
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for k in 0..self.time.len() {
            for c in 0..2 {
                let r = self.momentum[k][c]
                    - self.momentum[0][c]
                    - self.impulse_thrust[k][c]
                    - self.impulse_pressure[k][c]
                    - self.impulse_coriolis[k][c]
                    - self.impulse_gravity[k][c]
                    - self.momentum_outflow[k][c];
                worst = worst.max(r.abs());
                scale = scale.max(self.momentum[k][c].abs());
            }
        }
        if scale > 0.0 { worst / scale } else { worst }
    }
}

/// A run with the extra accounts the generic [`RunResult`] has no place for.
#[derive(Debug, Clone, PartialEq)]
pub struct DetailedRun {
    pub run: RunResult,
    pub balance: MomentumBalance,
    /// Relative m₀-weighted residual of projecting the initial shape onto the basis.
    pub initial_shape_residual: f64,
    /// Elastic frequencies (Hz) of the constant-mass case used as the basis (axial, bending).
    pub basis_frequencies_hz: (Vec<f64>, Vec<f64>),
}

/// Names of the channels, in recording order.
fn channel_specs(stations: usize, masses: usize) -> Vec<(String, &'static str)> {
    let mut v: Vec<(String, &'static str)> = vec![
        channel::spec::rocket_x(),
        channel::spec::rocket_y(),
        channel::spec::rocket_theta(),
        channel::spec::rocket_mass(),
        channel::spec::rocket_vx(),
        channel::spec::rocket_vy(),
    ];
    for k in 0..stations {
        v.push(channel::spec::rocket_axial(k));
    }
    for k in 0..stations {
        v.push(channel::spec::rocket_transverse(k));
    }
    for j in 1..=masses {
        v.push(channel::spec::rocket_mass_axial(j));
    }
    for j in 1..=masses {
        v.push(channel::spec::rocket_mass_transverse(j));
    }
    v
}

struct Recorder<'a> {
    model: &'a Model,
    stations: Vec<StationModes>,
    obs: Observables,
    ledger: EnergyLedger,
    balance: MomentumBalance,
    row: Vec<f64>,
    has_burn: bool,
    has_masses: bool,
    has_dampers: bool,
}

impl<'a> Recorder<'a> {
    fn new(model: &'a Model, basis: &Basis, scene: &data::Scene) -> Recorder<'a> {
        let ns = scene.simulation.field_stations.max(2);
        let len = model.body.length;
        let stations = (0..ns)
            .map(|k| StationModes::new(basis, len * k as f64 / (ns - 1) as f64))
            .collect::<Vec<_>>();
        let nm = model.layout.nm;
        let has_burn = model.body.burn.is_some();
        let has_masses = nm > 0;
        let has_dampers = model.body.has_dampers();
        let mut stored = vec![
            ledger_term::KINETIC,
            ledger_term::STRAIN,
            ledger_term::GRAVITY,
        ];
        if has_masses {
            stored.push(ledger_term::DISCRETE_SPRING);
        }
        let inputs: Vec<&str> = if has_burn {
            vec![
                ledger_term::THRUST,
                ledger_term::PRESSURE,
                ledger_term::CORIOLIS,
                ledger_term::MASS_OUTFLOW,
            ]
        } else {
            vec![]
        };
        let diss: Vec<&str> = if has_dampers {
            vec![ledger_term::DISCRETE_DAMPER]
        } else {
            vec![]
        };
        let specs = channel_specs(ns, nm);
        Recorder {
            model,
            stations,
            row: vec![0.0; specs.len()],
            obs: Observables::with_channels(&specs),
            ledger: EnergyLedger::new(&stored, &inputs, &diss),
            balance: MomentumBalance::default(),
            has_burn,
            has_masses,
            has_dampers,
        }
    }

    fn record(&mut self, ws: &mut Workspace, t: f64, y: &[f64]) {
        let m = self.model;
        let l = m.layout;
        let n = l.n;
        let snap = snapshot(m, ws, t, y);
        let q = &y[..l.dofs()];
        let (a, b) = (&q[l.a()..l.a() + n], &q[l.b()..l.b() + n]);
        let mt = snap.total_mass;
        let mut i = 0;
        for v in [
            snap.centre.0,
            snap.centre.1,
            q[2],
            mt,
            snap.momentum.0 / mt,
            snap.momentum.1 / mt,
        ] {
            self.row[i] = v;
            i += 1;
        }
        for st in &self.stations {
            self.row[i] = crate::linalg::dot(&st.u, a);
            i += 1;
        }
        for st in &self.stations {
            self.row[i] = crate::linalg::dot(&st.w, b);
            i += 1;
        }
        for j in 0..l.nm {
            self.row[i] = q[l.mu() + j];
            i += 1;
        }
        for j in 0..l.nm {
            self.row[i] = q[l.mw() + j];
            i += 1;
        }
        self.obs.push(t, &self.row);

        let qs = &y[l.quad()..];
        let stored = [snap.kinetic, snap.strain, snap.gravity, snap.springs];
        let inputs = [
            qs[quad::W_THRUST],
            qs[quad::W_PRESSURE],
            qs[quad::W_CORIOLIS],
            qs[quad::E_OUTFLOW],
        ];
        let diss = [qs[quad::W_DAMPING]];
        // the ledger holds only the terms this scene has (see `Recorder::new`)
        let ns = if self.has_masses { 4 } else { 3 };
        let ni = if self.has_burn { 4 } else { 0 };
        let nd = if self.has_dampers { 1 } else { 0 };
        self.ledger
            .push(t, &stored[..ns], &inputs[..ni], &diss[..nd]);

        let pair = |k: usize| [qs[k], qs[k + 1]];
        let bal = &mut self.balance;
        bal.time.push(t);
        bal.total_mass.push(mt);
        bal.momentum.push([snap.momentum.0, snap.momentum.1]);
        bal.impulse_thrust.push(pair(quad::IMP_THRUST));
        bal.impulse_pressure.push(pair(quad::IMP_PRESSURE));
        bal.impulse_coriolis.push(pair(quad::IMP_CORIOLIS));
        bal.impulse_gravity.push(pair(quad::IMP_GRAVITY));
        bal.momentum_outflow.push(pair(quad::MOM_OUTFLOW));
    }
}

/// At most this many `StepRejected` events are listed (oscillatory runs reject a few percent of
/// their steps); the total is always in `cost.rejected_steps`.
const MAX_REJECTION_EVENTS: usize = 100;

/// Largest elastic displacement before a run is declared run away: 5 % of the body length, far
/// outside the small-deflection kinematics the model assumes.
const RUNAWAY_FRACTION: f64 = 0.05;

fn runaway(model: &Model, y: &[f64]) -> Option<(String, f64)> {
    let l = model.layout;
    let limit = RUNAWAY_FRACTION * model.body.length;
    for (i, v) in y.iter().enumerate() {
        if !v.is_finite() {
            return Some((format!("state component {i}"), *v));
        }
    }
    for i in l.a()..l.dofs() {
        if y[i].abs() > limit {
            let what = if i < l.b() {
                format!("axial mode {}", i - l.a() + 1)
            } else if i < l.mu() {
                format!("bending mode {}", i - l.b() + 1)
            } else if i < l.mw() {
                format!("discrete mass {} axial", i - l.mu() + 1)
            } else {
                format!("discrete mass {} transverse", i - l.mw() + 1)
            };
            return Some((what, y[i]));
        }
    }
    None
}

/// The remedy of a run stopped by a non-finite state.
const NON_FINITE_REMEDY: &str = "check the scene parameters; try time.method = \"tr-bdf2\"";

/// The stop of a run whose elastic displacement ran away at `t` (see [`runaway`]).
fn runaway_stop(model: &Model, t: f64, y: &[f64]) -> Option<StabilityVerdict> {
    let (where_, value) = runaway(model, y)?;
    Some(StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: "elastic displacement grew without bound".into(),
            location: Some(where_),
            why: format!(
                "value {value:.3e} exceeds {RUNAWAY_FRACTION} × body length: outside the \
                 small-deflection model (physical instability or integration error)"
            ),
            remedy: "tighten time.rtol/time.atol or use time.method = \"tr-bdf2\"; check \
                     stiffness and spring parameters"
                .into(),
        },
    })
}

/// The stop of a run whose method could not take a step from `t`; `failed_pivot` is where the
/// reduced mass matrix lost positive definiteness, if it did (the likely cause).
fn step_failure(
    t: f64,
    error: &IntegrateError,
    failed_pivot: Option<(f64, usize)>,
) -> StabilityVerdict {
    let (what, remedy) = match error {
        IntegrateError::StepTooSmall { .. } => (
            "step size underflow",
            "loosen time.rtol/time.atol or use time.method = \"tr-bdf2\" for stiff cases (many \
             modes)",
        ),
        _ => ("non-finite state", NON_FINITE_REMEDY),
    };
    let why = match failed_pivot {
        Some((tp, p)) => format!(
            "{error}; reduced mass matrix lost positive definiteness at t = {tp:.6e} (pivot {p})"
        ),
        None => error.to_string(),
    };
    StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: what.into(),
            location: None,
            why,
            remedy: remedy.into(),
        },
    }
}

/// Burn-out time, when it falls inside the run (before `t_end`).
fn burnout_within(model: &Model, t_end: f64) -> Option<f64> {
    model
        .body
        .burn
        .as_ref()
        .map(|b| b.burnout_time())
        .filter(|tb| *tb < t_end)
}

/// The rocket's part in the sampled run: the samples, the events and the stops of its own.
struct RocketRun<'a> {
    model: &'a Model,
    rec: Recorder<'a>,
    /// The recorder's own workspace (its phase stays `ByTime`).
    rec_ws: Workspace,
    /// Burn-out time when it falls inside the run: `breaks[0]` of the schedule.
    burnout: Option<f64>,
    events: Vec<Event>,
    /// Rejected attempts counted by the method up to the last accepted step.
    rejected_seen: usize,
    rejection_events: usize,
    /// The burn-out event whose `to` waits for the first step after the restart.
    pending_burnout: Option<usize>,
}

impl<'a> RocketRun<'a> {
    fn new(model: &'a Model, rec: Recorder<'a>, burnout: Option<f64>) -> RocketRun<'a> {
        RocketRun {
            model,
            rec,
            rec_ws: Workspace::new(model.layout),
            burnout,
            // room for every event a run can list, so the list does not grow in the step loop
            events: Vec::with_capacity(MAX_REJECTION_EVENTS + 1),
            rejected_seen: 0,
            rejection_events: 0,
            pending_burnout: None,
        }
    }

    /// The phase the right-hand side starts in: burning up to a burn-out inside the run, else
    /// decided by time (the loads do not switch within the run).
    fn initial_phase(&self) -> Phase {
        match self.burnout {
            Some(_) => Phase::Burning,
            None => Phase::ByTime,
        }
    }

    /// A `StepRejected` event when the last accepted step, which ended at `t`, followed
    /// rejected attempts (while fewer than [`MAX_REJECTION_EVENTS`] are listed).
    fn list_rejections(&mut self, stepper: &dyn Stepper, t: f64) {
        let rejected = stepper.stats().rejected;
        if rejected > self.rejected_seen && self.rejection_events < MAX_REJECTION_EVENTS {
            self.rejection_events += 1;
            self.events.push(Event::StepRejected {
                t,
                dt: stepper.last_step(),
                reason: format!(
                    "local error above tolerance: {} attempt(s) rejected before this accepted step",
                    rejected - self.rejected_seen
                ),
            });
        }
        self.rejected_seen = rejected;
    }

    /// Fills the burn-out event's `to` with the first step after the restart.
    fn complete_burnout_event(&mut self, stepper: &dyn Stepper) {
        if let Some(idx) = self.pending_burnout.take()
            && let Some(Event::StepSizeChange { to, .. }) = self.events.get_mut(idx)
        {
            *to = stepper.last_step();
        }
    }
}

impl<'m> SampledRun<RocketRhs<'m>> for RocketRun<'_> {
    fn record(&mut self, _rhs: &mut RocketRhs<'m>, t: f64, y: &[f64]) {
        self.rec.record(&mut self.rec_ws, t, y);
    }

    fn step_failed(
        &self,
        rhs: &RocketRhs<'m>,
        t: f64,
        error: &IntegrateError,
    ) -> Option<StabilityVerdict> {
        Some(step_failure(t, error, rhs.ws.failed_pivot))
    }

    fn after_step(&mut self, stepper: &dyn Stepper, t: f64, y: &[f64]) -> Option<StabilityVerdict> {
        self.list_rejections(stepper, t);
        self.complete_burnout_event(stepper);
        runaway_stop(self.model, t, y)
    }

    /// At burn-out thrust, chamber pressure and internal flow end; the driver has restarted the
    /// method there, and the event's `to` is filled in with the first step after the restart.
    fn on_break(&mut self, rhs: &mut RocketRhs<'m>, stepper: &dyn Stepper, index: usize) {
        let Some(tb) = self.burnout.filter(|_| index == 0) else {
            return;
        };
        rhs.ws.phase = Phase::BurntOut;
        self.events.push(Event::StepSizeChange {
            t: tb,
            from: stepper.last_step(),
            to: stepper.last_step(),
            reason: "burn-out: thrust, chamber pressure and internal flow end; integrator \
                     restarted at the discontinuity"
                .into(),
        });
        self.pending_burnout = Some(self.events.len() - 1);
    }
}

/// A run of the rocket `r` of `scene`, with the accounts [`DetailedRun`] adds.
pub fn simulate_detailed(
    scene: &data::Scene,
    r: &Rocket,
    settings: &ModalSettings,
) -> Result<DetailedRun, RocketError> {
    let wall = Instant::now();
    let body = Body::from_rocket(r)?;
    let n = config::modes(settings)?;
    let tc: TimeConfig = config::time(scene, settings)?;
    let basis = Basis::new(&body, n)?;
    let model = Model::new(body, &basis);
    let l = model.layout;
    let dim = l.state_len();

    let mut y = initial_state(&model);
    let tol = Tolerances {
        rtol: tc.rtol,
        atol: tc.atol,
    };
    let mut stepper = stepper(tc.method, dim, tol, tc.dt)?;

    let burnout = burnout_within(&model, tc.t_end);
    let breaks: Vec<f64> = burnout.into_iter().chain([tc.t_end]).collect();
    let mut run = RocketRun::new(&model, Recorder::new(&model, &basis, scene), burnout);
    let mut f = RocketRhs {
        model: &model,
        ws: Workspace::new(l),
    };
    f.ws.phase = run.initial_phase();
    run.record(&mut f, 0.0, &y);
    let schedule = Schedule {
        breaks: &breaks,
        output_interval: tc.output_interval,
        t_end: tc.t_end,
        remedy: NON_FINITE_REMEDY,
    };
    let verdict = run_sampled(stepper.as_mut(), &mut f, &mut y, schedule, &mut run);

    let st = stepper.stats();
    let cost = st.cost(l.dofs(), wall);
    let hz = |w: &Vec<f64>| w.iter().map(|w| w / (2.0 * std::f64::consts::PI)).collect();
    Ok(DetailedRun {
        run: RunResult {
            backend: BackendKind::Modal,
            scene: scene.name.clone(),
            settings: data::Settings::from(settings),
            observables: run.rec.obs,
            ledger: run.rec.ledger,
            events: run.events,
            cost,
            verdict,
        },
        balance: run.rec.balance,
        initial_shape_residual: model.initial_shape_residual,
        basis_frequencies_hz: (hz(&model.omega_axial), hz(&model.omega_bending)),
    })
}
