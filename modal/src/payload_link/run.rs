//! The dynamic run of the payload link: the registered integrator (adaptive TR-BDF2 by default:
//! L-stable, its steps set by accuracy, not by the stiff axial and torsion modes), stepping onto
//! each discontinuity of the motor torque, sampling on the dense output.

use std::time::Instant;

use data::scene::{LinkField, LinkInitialShape, PayloadLink, PrescribedMotion};
use data::{EnergyLedger, ModalSettings, Observables, RunResult, Scene, channel, ledger_term};

use super::dynamics::LinkRhs;
use super::model::LinkModel;
use super::{SetUp, set_up, static_sag};
use crate::error::ModalError;
use crate::integrate::{
    Build, EXPONENTIAL, OdeRhs, TRBDF2, Tolerances, method_for, oscillators_disturbed,
    tolerance_refused,
};
use crate::linalg::dot;
use crate::modes::generalized_eigen;
use crate::sampled::{SampledRun, Schedule, run_sampled};

/// Default (rtol, atol) of the adaptive methods: atol is in metres and radians (coordinates are
/// unit-scaled assumed modes) and in joules for the work integrals.
pub const DEFAULT_TOL: (f64, f64) = (1e-7, 1e-10);

/// Fixed steps per period of the lowest elastic mode ([`default_step`]).
pub const STEPS_PER_PERIOD: f64 = 128.0;

/// The remedy of a stopped run's diagnostic.
const REMEDY: &str = "loosen time.rtol/time.atol, or check the scene's parameters";

/// The default method: adaptive TR-BDF2 when a Kelvin–Voigt term is on (the damped high Ritz
/// modes decay and the error test then lets the step grow far beyond their periods:
/// `single-link-3d`, 25 coordinates, 2 s in 35 233 steps, ledger closure 1.1e-7), the
/// exponential method at [`default_step`] when none is. Undamped high modes, excited by the
/// torque steps, ring for ever: an error test resolves them (`single-link-3d-stiff` took
/// 84 120 TR-BDF2 steps for its first 0.05 s at the default tolerances), and the trapezoidal
/// rule, which keeps them bounded at T₁/128, carries them at wrong frequencies that the hub
/// feels: its hub angle lies 1.45e-5 / 8.5e-6 / 3.7e-6 rad from Dormand–Prince at rtol 1e-12
/// at h = 1e-4 / 5e-5 / 2.5e-5 (0.7 s; no order). The undeformed link's M and K are constant
/// ([`LinkRhs`]'s oscillators), so the exponential method carries every mode exactly with one
/// diagonalization and integrates only the rotation's coupling: at h = T₁/128 = 1e-4 its hub
/// angle lies within the 1e-10 rad printed digits of Dormand–Prince, in about the
/// trapezoidal rule's time.
pub fn default_method(model: &LinkModel) -> &'static crate::integrate::MethodInfo {
    if model.damping.is_some() {
        &TRBDF2
    } else {
        &EXPONENTIAL
    }
}

/// T₁/[`STEPS_PER_PERIOD`], T₁ the period of the lowest elastic Ritz mode at the reference rate.
pub fn default_step(model: &LinkModel) -> Result<f64, ModalError> {
    let (k, m, _) = super::analysis::linear_pencil(model);
    let (lambda, _) = generalized_eigen(&k, &m)?;
    let top = lambda.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let omega1 = lambda
        .iter()
        .copied()
        .find(|l| *l > 1e-10 * top)
        .map(f64::sqrt)
        .ok_or_else(|| ModalError::Numerical {
            t: 0.0,
            message: "no elastic mode to set the step".into(),
        })?;
    Ok(std::f64::consts::TAU / omega1 / STEPS_PER_PERIOD)
}

/// A run of `link`, the payload link of `scene`.
pub fn simulate(
    scene: &Scene,
    link: &PayloadLink,
    settings: &ModalSettings,
) -> Result<RunResult, ModalError> {
    let wall = Instant::now();
    let SetUp { link, model } = set_up(scene, link, settings)?;
    let method = settings
        .method
        .map_or_else(|| default_method(&model), method_for);
    if method.needs_oscillators && model.damping.is_some() {
        return Err(ModalError::invalid(
            "time.method",
            oscillators_disturbed(
                method,
                "the payload link without Kelvin–Voigt damping",
                &scene.name,
                "it",
            ),
        ));
    }
    if method.needs_oscillators && (settings.rtol.is_some() || settings.atol.is_some()) {
        return Err(ModalError::invalid(
            "time.rtol/atol",
            tolerance_refused(method, "T₁/128"),
        ));
    }
    let rtol = settings.rtol.unwrap_or(DEFAULT_TOL.0);
    let atol = settings.atol.unwrap_or(DEFAULT_TOL.1);
    if !(rtol > 0.0 && atol > 0.0 && rtol.is_finite() && atol.is_finite()) {
        return Err(ModalError::invalid(
            "time.rtol/atol",
            "tolerances must be positive",
        ));
    }
    let t_end = crate::setup::checked_span(scene, settings)?;
    let q0 = match link.initial_shape {
        LinkInitialShape::StaticSag => static_sag(&model)?,
        LinkInitialShape::Undeformed => vec![0.0; model.n],
    };
    let mut rhs = LinkRhs::new(model).map_err(|m| ModalError::Numerical { t: 0.0, message: m })?;
    let mut y = rhs.initial_state(&q0);
    let dim = y.len();
    let tol = Tolerances { rtol, atol };
    let mut stepper = match method.build {
        Build::Adaptive(build) => build(dim, tol, settings.dt),
        Build::Fixed(build) => {
            let dt = match settings.dt {
                Some(dt) => dt,
                None => default_step(&rhs.model)?,
            };
            build(dim, tol, dt)
        }
    };

    let mut breaks: Vec<f64> = Vec::new();
    if let Some(law) = &rhs.model.base.torque {
        breaks.extend(law.breakpoints());
    }
    if let Some(PrescribedMotion::SpinUp { t_s, .. }) = &rhs.model.base.prescribed {
        breaks.push(*t_s);
    }
    breaks.retain(|&b| b > 0.0 && b < t_end);
    breaks.sort_by(|a, b| a.total_cmp(b));
    breaks.dedup();
    breaks.push(t_end);

    let mut out = Output::new(&rhs);
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
        cost: st.cost(rhs.nd, wall),
        verdict,
    })
}

/// Sampled observables and the energy ledger.
struct Output {
    obs: Observables,
    ledger: EnergyLedger,
    values: Vec<f64>,
    stored: Vec<f64>,
    /// The derivative the recording evaluates (it leaves the base state in `LinkRhs`).
    dy: Vec<f64>,
    has_gravity: bool,
    has_spring: bool,
}

impl Output {
    fn new(rhs: &LinkRhs) -> Self {
        let m = &rhs.model;
        let fields: Vec<LinkField> = LinkField::ALL
            .into_iter()
            .filter(|f| m.block(*f).is_some())
            .collect();
        let specs = channel::payload_link(&fields, m.stations.len());
        let has_gravity = m.gravity.is_some();
        let has_spring = m.base.spring.is_some();
        let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
        if has_gravity {
            stored.push(ledger_term::GRAVITY);
        }
        if has_spring {
            stored.push(ledger_term::JOINT_SPRING);
        }
        let input = if m.base.free {
            ledger_term::APPLIED_TORQUE
        } else {
            ledger_term::PRESCRIBED_MOTION
        };
        let mut diss = Vec::new();
        if rhs.friction_work.is_some() {
            diss.push(ledger_term::JOINT_DAMPER);
        }
        for d in &m.damped {
            diss.push(ledger_term::kelvin_voigt_of(d.field));
        }
        let n_channels = specs.len();
        Output {
            obs: Observables::with_channels(&specs),
            ledger: EnergyLedger::new(&stored, &[input], &diss),
            values: Vec::with_capacity(n_channels),
            stored: Vec::with_capacity(4),
            dy: vec![0.0; rhs.dim()],
            has_gravity,
            has_spring,
        }
    }
}

impl SampledRun<LinkRhs> for Output {
    fn record(&mut self, rhs: &mut LinkRhs, t: f64, y: &[f64]) {
        rhs.eval(t, y, &mut self.dy);
        let base = rhs.base_state(t, y);
        let torque = rhs.actuator_torque(t, y);
        let m = &rhs.model;
        let n = m.n;
        let o = rhs.q0();
        let q = &y[o..o + n];
        let qd = &y[rhs.nd + o..rhs.nd + o + n];
        let row = |r: &[f64]| dot(r, q);
        let (u, v, w) = (row(&m.tip.u), row(&m.tip.v), row(&m.tip.w));
        let (sv, sw, phi) = (row(&m.tip.slope_v), row(&m.tip.slope_w), row(&m.tip.phi));
        let c = m.reach - m.length;
        let pull = super::model::quad_form(&m.pull_in, n, q);
        let p1 = m.reach + u - pull;
        let p2 = v + c * sv;
        let p3 = w + c * sw;
        let (s, co) = base.theta.sin_cos();
        self.values.clear();
        self.values.extend_from_slice(&[
            base.theta,
            base.rate,
            torque,
            co * p1 - s * p2,
            s * p1 + co * p2,
            p3,
        ]);
        // Tip quantities of the carried fields, in the registry's order (u, v, w, φ, v′, w′).
        let tip = [u, v, w, phi, sv, sw];
        for (value, q) in tip.iter().zip(&channel::PAYLOAD_LINK_TIP) {
            if m.block(q.field).is_some() {
                self.values.push(*value);
            }
        }
        for (k, field) in [
            LinkField::Horizontal,
            LinkField::Vertical,
            LinkField::Torsion,
        ]
        .into_iter()
        .enumerate()
        {
            if m.block(field).is_some() {
                for st in &m.stations {
                    self.values.push(row(&st[k]));
                }
            }
        }
        self.obs.push(t, &self.values);
        self.stored.clear();
        self.stored.push(m.kinetic(base.rate, q, qd));
        self.stored.push(m.strain(q));
        if self.has_gravity {
            self.stored.push(m.gravity_energy(q));
        }
        if self.has_spring {
            self.stored.push(m.base.spring(base.theta).1);
        }
        let w0 = 2 * rhs.nd;
        let works = &y[w0..w0 + rhs.nw];
        self.ledger.push(t, &self.stored, &works[..1], &works[1..]);
    }
}
