//! Time integration of the chain: state y = (q_free, q̇_free, cumulative works), sampled
//! observables and the energy ledger.

use std::time::Instant;

use data::{
    Cost, Diagnostic, EnergyLedger, Observables, RunResult, Scene, Settings, StabilityVerdict,
    channel,
};

use crate::error::ModalError;
use crate::integrate::{Dopri5, IntegrateError, OdeRhs, Sdirk, StepStats, Tolerances};
use crate::model::Chain;
use crate::model::integrals::dot;
use crate::setup::build_chain;

/// Default tolerances of the adaptive integrators.
pub const DEFAULT_RTOL: f64 = 1e-8;
pub const DEFAULT_ATOL: f64 = 1e-10;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    Dopri5,
    Trbdf2,
}

impl Method {
    pub fn parse(name: Option<&str>) -> Result<Self, ModalError> {
        match name {
            None | Some("dopri5") => Ok(Method::Dopri5),
            Some("trbdf2") | Some("sdirk") | Some("tr-bdf2") => Ok(Method::Trbdf2),
            Some(other) => Err(ModalError::invalid(
                "time.method",
                format!(
                    "`{other}`: the modal backend offers `dopri5` (default) and `trbdf2` (alias `sdirk`)"
                ),
            )),
        }
    }
}

/// Which cumulative power integrals the state carries (only those the scene needs).
#[derive(Debug, Clone, Copy, Default)]
struct WorkSlots {
    applied: Option<usize>,
    prescribed: Option<usize>,
    joint_damper: Option<usize>,
    kelvin_voigt: Option<usize>,
    count: usize,
}

/// y' = f(t, y) of the chain.
pub struct ChainRhs {
    pub chain: Chain,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    slots: WorkSlots,
    pub singular: bool,
}

impl ChainRhs {
    pub fn new(chain: Chain) -> Self {
        let n = chain.n;
        let mut slots = WorkSlots::default();
        let nf = chain.free.len();
        let mut k = 2 * nf;
        let mut take = |on: bool| {
            if on {
                k += 1;
                Some(k - 1)
            } else {
                None
            }
        };
        slots.applied = take(
            chain
                .joints
                .iter()
                .any(|j| j.prescribed.is_none() && j.torque.is_some()),
        );
        slots.prescribed = take(chain.joints.iter().any(|j| j.prescribed.is_some()));
        slots.joint_damper = take(
            chain
                .joints
                .iter()
                .any(|j| j.prescribed.is_none() && j.damping > 0.0),
        );
        slots.kelvin_voigt = take(chain.links.iter().any(|l| l.kv_ratio > 0.0));
        slots.count = k - 2 * nf;
        ChainRhs {
            chain,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            slots,
            singular: false,
        }
    }

    fn nf(&self) -> usize {
        self.chain.free.len()
    }

    /// Full q, q̇ from the state and the prescribed motion at t.
    fn load(&mut self, t: f64, y: &[f64]) {
        let nf = self.nf();
        for (k, &g) in self.chain.free.iter().enumerate() {
            self.q[g] = y[k];
            self.qd[g] = y[nf + k];
        }
        for (i, j) in self.chain.joints.iter().enumerate() {
            if let Some((a, r, _)) = j.prescribed_state(t) {
                let th = self.chain.links[i].theta;
                self.q[th] = a;
                self.qd[th] = r;
            }
        }
    }

    pub fn initial_state(&self) -> Vec<f64> {
        let nf = self.nf();
        let mut y = vec![0.0; 2 * nf + self.slots.count];
        for (k, &g) in self.chain.free.iter().enumerate() {
            for (i, l) in self.chain.links.iter().enumerate() {
                if l.theta == g {
                    y[k] = self.chain.joints[i].initial_angle;
                    y[nf + k] = self.chain.joints[i].initial_rate;
                }
            }
        }
        y
    }

    /// Evaluates the model at (t, y): M, forces, accelerations, prescribed torques.
    fn solve(&mut self, t: f64, y: &[f64]) -> bool {
        self.load(t, y);
        self.chain.evaluate(t, &self.q, &self.qd);
        self.chain.accelerations(t, &mut self.qdd).is_ok()
    }

    /// Total joint torque of joint i at the last solve (applied law + spring + damper for free
    /// joints; the required actuator torque for prescribed ones).
    fn joint_torque(&self, t: f64, i: usize) -> f64 {
        let j = &self.chain.joints[i];
        if j.prescribed.is_some() {
            self.chain.tau_prescribed[i]
        } else {
            let th = self.chain.links[i].theta;
            j.torque.as_ref().map_or(0.0, |l| l.torque(t))
                - j.stiffness * (self.q[th] - j.set_point)
                - j.damping * self.qd[th]
        }
    }
}

impl OdeRhs for ChainRhs {
    fn dim(&self) -> usize {
        2 * self.nf() + self.slots.count
    }

    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let nf = self.nf();
        if !self.solve(t, y) {
            self.singular = true;
            dydt.iter_mut().for_each(|v| *v = f64::NAN);
            return;
        }
        for (k, &g) in self.chain.free.iter().enumerate() {
            dydt[k] = self.qd[g];
            dydt[nf + k] = self.qdd[g];
        }
        let s = self.slots;
        if let Some(k) = s.applied {
            let mut p = 0.0;
            for (i, j) in self.chain.joints.iter().enumerate() {
                if let (None, Some(law)) = (&j.prescribed, &j.torque) {
                    p += law.torque(t) * self.qd[self.chain.links[i].theta];
                }
            }
            dydt[k] = p;
        }
        if let Some(k) = s.prescribed {
            let mut p = 0.0;
            for (i, j) in self.chain.joints.iter().enumerate() {
                if j.prescribed.is_some() {
                    p += self.chain.tau_prescribed[i] * self.qd[self.chain.links[i].theta];
                }
            }
            dydt[k] = p;
        }
        if let Some(k) = s.joint_damper {
            let mut p = 0.0;
            for (i, j) in self.chain.joints.iter().enumerate() {
                if j.prescribed.is_none() {
                    let w = self.qd[self.chain.links[i].theta];
                    p += j.damping * w * w;
                }
            }
            dydt[k] = p;
        }
        if let Some(k) = s.kelvin_voigt {
            let mut p = 0.0;
            for l in &self.chain.links {
                if l.kv_ratio > 0.0 {
                    let nb = l.nb();
                    let bd = &self.qd[l.b0..l.b0 + nb];
                    for r in 0..nb {
                        p += l.kv_ratio * bd[r] * dot(&l.ints.kb[r * nb..(r + 1) * nb], bd);
                    }
                }
            }
            dydt[k] = p;
        }
    }
}

enum Stepper {
    Explicit(Dopri5),
    Implicit(Sdirk),
}

impl Stepper {
    fn step(
        &mut self,
        f: &mut ChainRhs,
        t: &mut f64,
        y: &mut [f64],
        stop: f64,
    ) -> Result<(), IntegrateError> {
        match self {
            Stepper::Explicit(s) => s.step(f, t, y, stop),
            Stepper::Implicit(s) => s.step(f, t, y, stop),
        }
    }
    fn dense(&self, t: f64, out: &mut [f64]) {
        match self {
            Stepper::Explicit(s) => s.dense(t, out),
            Stepper::Implicit(s) => s.dense(t, out),
        }
    }
    fn stats(&self) -> StepStats {
        match self {
            Stepper::Explicit(s) => *s.stats(),
            Stepper::Implicit(s) => *s.stats(),
        }
    }
    fn reset(&mut self) {
        match self {
            Stepper::Explicit(s) => s.reset(),
            Stepper::Implicit(s) => s.reset(),
        }
    }
}

/// Output layout: channel names and the energy ledger names the scene needs.
struct Output {
    obs: Observables,
    ledger: EnergyLedger,
    values: Vec<f64>,
    stations: Vec<Vec<f64>>,
    has_spring: bool,
    has_gravity: bool,
}

impl Output {
    fn new(rhs: &ChainRhs, scene: &Scene, n_samples: usize) -> Self {
        let chain = &rhs.chain;
        let ns = scene.simulation.field_stations.max(2);
        let mut specs: Vec<(String, &str)> = Vec::new();
        for (i, _) in chain.links.iter().enumerate() {
            let k = i + 1;
            specs.push((channel::joint_angle(k), "rad"));
            specs.push((channel::joint_rate(k), "rad/time"));
            specs.push((channel::joint_torque(k), "force*length"));
            specs.push((channel::tip_x(k), "length"));
            specs.push((channel::tip_y(k), "length"));
            specs.push((channel::tip_deflection(k), "length"));
            for s in 0..ns {
                specs.push((channel::field_deflection(k, s), "length"));
            }
        }
        let mut obs = Observables::with_channels(&specs);
        obs.time.reserve(n_samples);
        for c in &mut obs.channels {
            c.values.reserve(n_samples);
        }
        let has_spring = chain
            .joints
            .iter()
            .any(|j| j.prescribed.is_none() && j.stiffness > 0.0);
        let has_gravity = chain.gravity.is_some();
        let mut stored = vec!["kinetic", "strain"];
        if has_spring {
            stored.push("joint_spring");
        }
        if has_gravity {
            stored.push("gravity");
        }
        let mut inputs = Vec::new();
        if rhs.slots.applied.is_some() {
            inputs.push("applied_torque");
        }
        if rhs.slots.prescribed.is_some() {
            inputs.push("prescribed_motion");
        }
        let mut diss = Vec::new();
        if rhs.slots.joint_damper.is_some() {
            diss.push("joint_damper");
        }
        if rhs.slots.kelvin_voigt.is_some() {
            diss.push("kelvin_voigt");
        }
        let mut ledger = EnergyLedger::new(&stored, &inputs, &diss);
        ledger.time.reserve(n_samples);
        for term in ledger
            .stored
            .iter_mut()
            .chain(&mut ledger.inputs)
            .chain(&mut ledger.dissipation)
        {
            term.values.reserve(n_samples);
        }
        let stations = chain
            .links
            .iter()
            .map(|l| {
                let len = l.ints.length;
                let mut m = vec![0.0; ns * l.nb()];
                for s in 0..ns {
                    let x = len * s as f64 / (ns - 1) as f64;
                    l.transverse
                        .eval(x, 0, &mut m[s * l.nb()..(s + 1) * l.nb()]);
                }
                m
            })
            .collect();
        Output {
            values: vec![0.0; specs.len()],
            obs,
            ledger,
            stations,
            has_spring,
            has_gravity,
        }
    }

    fn sample(&mut self, rhs: &mut ChainRhs, t: f64, y: &[f64]) -> bool {
        if !rhs.solve(t, y) {
            return false;
        }
        let ns = self
            .stations
            .first()
            .map_or(0, |m| m.len() / rhs.chain.links[0].nb().max(1));
        let mut c = 0;
        for i in 0..rhs.chain.links.len() {
            let l = &rhs.chain.links[i];
            let nb = l.nb();
            let b = &rhs.q[l.b0..l.b0 + nb];
            let tip = rhs.chain.tip_position(i);
            self.values[c] = rhs.q[l.theta];
            self.values[c + 1] = rhs.qd[l.theta];
            self.values[c + 2] = rhs.joint_torque(t, i);
            self.values[c + 3] = tip[0];
            self.values[c + 4] = tip[1];
            self.values[c + 5] = dot(&l.ints.phi_l, b);
            c += 6;
            for s in 0..ns {
                self.values[c] = dot(&self.stations[i][s * nb..(s + 1) * nb], b);
                c += 1;
            }
        }
        self.obs.push(t, &self.values);
        let e = rhs.chain.energy(&rhs.q);
        let mut stored = [e.kinetic, e.strain, 0.0, 0.0];
        let mut k = 2;
        if self.has_spring {
            stored[k] = e.joint_spring;
            k += 1;
        }
        if self.has_gravity {
            stored[k] = e.gravity;
            k += 1;
        }
        let s = rhs.slots;
        let (mut inputs, mut ni) = ([0.0; 2], 0);
        for i in [s.applied, s.prescribed].into_iter().flatten() {
            inputs[ni] = y[i];
            ni += 1;
        }
        let (mut diss, mut nd) = ([0.0; 2], 0);
        for i in [s.joint_damper, s.kelvin_voigt].into_iter().flatten() {
            diss[nd] = y[i];
            nd += 1;
        }
        self.ledger
            .push(t, &stored[..k], &inputs[..ni], &diss[..nd]);
        true
    }
}

/// Links whose transverse tip deflection exceeds their length (runaway growth).
fn runaway(rhs: &ChainRhs, y: &[f64]) -> Option<(usize, f64)> {
    let nf = rhs.nf();
    for (i, l) in rhs.chain.links.iter().enumerate() {
        // b of link i sits in the free part at the positions of its global indices.
        let mut v = 0.0;
        for (k, &g) in rhs.chain.free[..nf].iter().enumerate() {
            if g >= l.b0 && g < l.b0 + l.nb() {
                v += l.ints.phi_l[g - l.b0] * y[k];
            }
        }
        if !v.is_finite() || v.abs() > l.ints.length {
            return Some((i, v));
        }
    }
    None
}

pub fn simulate(scene: &Scene, settings: &Settings) -> Result<RunResult, ModalError> {
    let wall = Instant::now();
    let chain = build_chain(scene, &settings.discretization)?;
    let method = Method::parse(settings.time.method.as_deref())?;
    let rtol = settings.time.rtol.unwrap_or(DEFAULT_RTOL);
    let atol = settings.time.atol.unwrap_or(DEFAULT_ATOL);
    if !(rtol > 0.0 && atol > 0.0) {
        return Err(ModalError::invalid(
            "time.rtol/atol",
            "tolerances must be positive",
        ));
    }
    let t_end = settings.time.t_end.unwrap_or(scene.simulation.t_end);
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(ModalError::invalid(
            "time.t_end",
            format!("{t_end} is not a positive time"),
        ));
    }
    if let Some(dt) = settings.time.dt
        && !(dt > 0.0 && dt.is_finite())
    {
        return Err(ModalError::invalid(
            "time.dt",
            format!("{dt} is not a positive step"),
        ));
    }
    let dt_out = scene.simulation.output_interval;
    let n_out = (t_end / dt_out - 1e-9).ceil() as usize + 1;

    let mut rhs = ChainRhs::new(chain);
    let mut y = rhs.initial_state();
    let dim = y.len();
    let tol = Tolerances { rtol, atol };
    let mut stepper = match method {
        Method::Dopri5 => Stepper::Explicit(Dopri5::new(dim, tol, settings.time.dt, None)),
        Method::Trbdf2 => Stepper::Implicit(Sdirk::new(dim, tol, settings.time.dt, None)),
    };
    let mut out = Output::new(&rhs, scene, n_out);

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
    let mut yd = vec![0.0; dim];
    let mut k_out = 0usize;
    let out_time = |k: usize| (k as f64 * dt_out).min(t_end);
    if !out.sample(&mut rhs, 0.0, &y) {
        return Err(ModalError::Numerical {
            t: 0.0,
            message: "mass matrix not positive definite at the initial state".into(),
        });
    }
    k_out = k_out.max(1);
    'outer: for &target in &breaks {
        while t < target {
            if let Err(e) = stepper.step(&mut rhs, &mut t, &mut y, target) {
                verdict = stopped(&rhs, t, &e.to_string(), None);
                break 'outer;
            }
            while k_out < n_out && out_time(k_out) <= t {
                let to = out_time(k_out);
                if to == t {
                    yd.copy_from_slice(&y);
                } else {
                    stepper.dense(to, &mut yd);
                }
                if !out.sample(&mut rhs, to, &yd) {
                    verdict = stopped(&rhs, to, "mass matrix lost positive definiteness", None);
                    break 'outer;
                }
                k_out += 1;
            }
            if let Some((i, v)) = runaway(&rhs, &y) {
                verdict = stopped(&rhs, t, "", Some((i, v)));
                break 'outer;
            }
        }
        stepper.reset();
    }
    let st = stepper.stats();
    let cost = Cost {
        wall_time_s: wall.elapsed().as_secs_f64(),
        dofs: rhs.nf(),
        steps: st.steps,
        rejected_steps: st.rejected,
        rhs_evaluations: st.rhs_evals,
        jacobian_evaluations: st.jacobian_evals,
        factorizations: st.factorizations,
        newton_iterations: st.newton_iters,
    };
    Ok(RunResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: settings.clone(),
        observables: out.obs,
        ledger: out.ledger,
        events: Vec::new(),
        cost,
        verdict,
    })
}

fn stopped(
    rhs: &ChainRhs,
    t: f64,
    integrator: &str,
    runaway: Option<(usize, f64)>,
) -> StabilityVerdict {
    let diagnostic = if let Some((i, v)) = runaway {
        let l = &rhs.chain.links[i];
        let stiffening = l.foreshortening;
        Diagnostic {
            t,
            what: format!(
                "transverse tip deflection {v:.3e} of link {} exceeds its length {}",
                i + 1,
                l.ints.length
            ),
            location: Some(format!("link{} tip", i + 1)),
            why: if stiffening {
                "runaway elastic growth: the small-strain assumed-mode model is no longer valid"
                    .into()
            } else {
                "runaway growth: without geometric stiffening the rotating link softens (ω² M_φ \
                 term) and loses stability once the spin rate exceeds its first bending frequency"
                    .into()
            },
            remedy: if stiffening {
                "reduce the loading or use a geometrically exact backend".into()
            } else {
                "switch on `foreshortening` (or `axial`) for the link to keep centrifugal stiffening".into()
            },
        }
    } else {
        Diagnostic {
            t,
            what: format!("integrator stopped: {integrator}"),
            location: None,
            why: if rhs.singular {
                "the mass matrix lost positive definiteness".into()
            } else {
                "the solution could not be resolved at the requested tolerance (blow-up or a \
                 singular configuration)"
                    .into()
            },
            remedy: "loosen rtol/atol, try `--method trbdf2` for stiff cases, or check the scene \
                     parameters"
                .into(),
        }
    };
    StabilityVerdict::Stopped { diagnostic }
}
