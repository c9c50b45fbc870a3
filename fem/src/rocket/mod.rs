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
//! Implicit midpoint rule (one-stage Gauss, second order, no numerical damping) on the first
//! order form q̇ = v, M(t)v̇ = F(t, q, v): with the midpoint velocity v_m as unknown,
//! 2M(t_m)(v_m − v₀) = hF(t_m, q₀ + ½hv_m, v_m). Newton with the linear part of the Jacobian,
//! J = 2M(t_m) + ½h²K + hC (K: beam and springs in launch axes); the loads' and the mass-to-mass
//! springs' dependence on the mean axes and the cubic strain term are left to the iteration (their Jacobian is 1e-5 of J
//! at the catalog scenes). J changes with the mass every step and is refactorized numerically in
//! a bordered band pattern (symbolic LU once). Steps land on the output times and on burn-out.
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
//! the burnt mass, booked from M(t₁) − M(t_m) and M(t_m) − M(t₀) so that the midpoint rule's
//! balance closes to the Newton tolerance and the O(h³) midpoint error of the cubic strain term).

pub mod model;

use std::time::Instant;

use data::channel::spec;
use data::results::ledger_term;
use data::scene::Rocket;
use data::{
    DofPlan, EnergyLedger, FemSettings, ModalResult, ModeShape, Observables, RunResult, Scene,
    StabilityVerdict,
};
use faer::Mat;

use crate::band::BorderedBand;
use crate::error::FemError;
use crate::linalg::max_abs;
use crate::method::FixedStepCounters;
use model::{DOFS_PER_NODE, Model};

/// Elements when `discretization.elements` is absent (h = 5 in on the catalog rocket).
pub const DEFAULT_ELEMENTS: usize = 30;
/// Time step when `time.dt` is absent.
pub const DEFAULT_STEP: f64 = 1.0e-5;
/// Newton: converged when the update is below this times (1 + |v_m|∞).
const NEWTON_TOL: f64 = 1e-13;
/// Accepted after the iteration limit when the update is below this times (1 + |v_m|∞)
/// (round-off of the rigid translation in K q).
const NEWTON_ACCEPT: f64 = 1e-10;
const NEWTON_MAX: usize = 12;

/// The discretized model of the rocket `r`.
/// Elements of the rocket's beam (Hermite cubics only).
fn elements(settings: &FemSettings) -> Result<usize, FemError> {
    crate::settings::cubic_elements_or(settings, DEFAULT_ELEMENTS, "rocket", "the beam")
}

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

/// Powers of the loads at one evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub struct Powers {
    pub thrust: f64,
    pub pressure: f64,
    pub coriolis: f64,
    pub damper: f64,
}

/// Cumulative works (inputs) and dissipations.
#[derive(Debug, Clone, Copy, Default)]
pub struct Works {
    pub thrust: f64,
    pub pressure: f64,
    pub coriolis: f64,
    pub damper: f64,
    pub outflow: f64,
}

/// State and scratch of the implicit-midpoint integration (no allocation per step).
#[derive(Debug, Clone)]
pub struct Stepper {
    pub model: Model,
    pub t: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub works: Works,
    pub counters: FixedStepCounters,
    gravity: Vec<f64>,
    springs: Vec<(usize, usize, f64, f64)>,
    jac: BorderedBand,
    vm: Vec<f64>,
    qm: Vec<f64>,
    f: Vec<f64>,
    r: Vec<f64>,
    tmp: Vec<f64>,
}

impl Stepper {
    pub fn new(model: Model, q: Vec<f64>, v: Vec<f64>) -> Self {
        let n = model.n;
        let (g_xi, g_eta) = model.gravity();
        let gravity = (0..n)
            .map(|i| g_xi * model.t_xi[i] + g_eta * model.t_eta[i])
            .collect();
        let springs = model.spring_entries();
        let ni = DOFS_PER_NODE * model.nodes;
        let jac = BorderedBand::new(ni, n - ni, 2 * DOFS_PER_NODE - 1);
        Stepper {
            model,
            t: 0.0,
            q,
            v,
            works: Works::default(),
            counters: FixedStepCounters::default(),
            gravity,
            springs,
            jac,
            vm: vec![0.0; n],
            qm: vec![0.0; n],
            f: vec![0.0; n],
            r: vec![0.0; n],
            tmp: vec![0.0; n],
        }
    }

    /// Generalized forces F(t, q, v) (everything but inertia) into `f`; returns the loads'
    /// powers at velocity v.
    pub fn loads(
        model: &Model,
        gravity: &[f64],
        t: f64,
        q: &[f64],
        v: &[f64],
        f: &mut [f64],
    ) -> Powers {
        f.iter_mut().for_each(|x| *x = 0.0);
        model.mass_mul_add(model.m1(t), 1.0, gravity, f);
        model.add_elastic_forces(q, f);
        let axis = model.mean_axis(q, v);
        let (_, damper) = model.add_spring_forces(axis.phi, q, v, f);
        let mut p = Powers {
            damper,
            ..Default::default()
        };
        if model.burning(t) {
            let flow = model.mass_flow(t);
            let thrust = flow * model.exhaust_velocity;
            let (dc, ds) = (
                (axis.phi + model.gamma).cos(),
                (axis.phi + model.gamma).sin(),
            );
            f[0] += thrust * dc;
            f[1] += thrust * ds;
            p.thrust = thrust * (dc * v[0] + ds * v[1]);
            let (ec, es) = (axis.phi.cos(), axis.phi.sin());
            let pa = model.pressure_force;
            f[0] -= pa * ec;
            f[1] -= pa * es;
            model.add_point_force(&model.pressure_point, (pa * ec, pa * es), f);
            let (ul, wl) = model.at(&model.pressure_point, v);
            p.pressure = pa * (ec * (ul - v[0]) + es * (wl - v[1]));
            let c = 2.0 * axis.rate * flow;
            if c != 0.0 {
                let (nx, ny) = (-es, ec);
                for i in 0..model.n {
                    let fi = c * (nx * model.cor_u[i] + ny * model.cor_w[i]);
                    f[i] += fi;
                    p.coriolis += fi * v[i];
                }
            }
        }
        p
    }

    /// One implicit-midpoint step of size h.
    pub fn step(&mut self, h: f64) -> Result<(), FemError> {
        let m = &self.model;
        let n = m.n;
        let (t0, tm, t1) = (self.t, self.t + 0.5 * h, self.t + h);
        let m1m = m.m1(tm);
        self.jac.clear();
        for &(i, j, val) in &m.m_fixed.0 {
            self.jac.add(i, j, 2.0 * val);
        }
        for &(i, j, val) in &m.m_burn.0 {
            self.jac.add(i, j, 2.0 * m1m * val);
        }
        for (j, dm) in m.masses.iter().enumerate() {
            let (iu, iw) = m.mass_dofs(j);
            self.jac.add(iu, iu, 2.0 * dm.mass);
            self.jac.add(iw, iw, 2.0 * dm.mass);
        }
        for &(i, j, val) in &m.k_beam.0 {
            self.jac.add(i, j, 0.5 * h * h * val);
        }
        for &(i, j, k, c) in &self.springs {
            self.jac.add(i, j, 0.5 * h * h * k + h * c);
        }
        self.jac
            .factorize()
            .map_err(|e| runaway(t0, format!("Newton matrix: {e}")))?;
        self.counters.factorizations += 1;
        self.vm.copy_from_slice(&self.v);
        let mut converged = false;
        let mut last = f64::INFINITY;
        for _ in 0..NEWTON_MAX {
            for i in 0..n {
                self.qm[i] = self.q[i] + 0.5 * h * self.vm[i];
                self.tmp[i] = self.vm[i] - self.v[i];
            }
            Self::loads(m, &self.gravity, tm, &self.qm, &self.vm, &mut self.f);
            self.counters.residuals += 1;
            for i in 0..n {
                self.r[i] = -h * self.f[i];
            }
            m.mass_mul_add(m1m, 2.0, &self.tmp, &mut self.r);
            self.jac.solve_in_place(&mut self.r);
            for i in 0..n {
                self.vm[i] -= self.r[i];
            }
            self.counters.newton += 1;
            last = max_abs(&self.r);
            if last <= NEWTON_TOL * (1.0 + max_abs(&self.vm)) {
                converged = true;
                break;
            }
        }
        let acceptable = last <= NEWTON_ACCEPT * (1.0 + max_abs(&self.vm));
        if !converged && !acceptable {
            return Err(runaway(
                t0,
                format!("Newton did not converge (last update {last:.3e})"),
            ));
        }
        for i in 0..n {
            self.qm[i] = self.q[i] + 0.5 * h * self.vm[i];
        }
        let p = Self::loads(m, &self.gravity, tm, &self.qm, &self.vm, &mut self.f);
        self.counters.residuals += 1;
        // Energy carried off by the burnt mass (kinetic and potential), exact for the scheme.
        let (m0, m1) = (m.m1(t0), m.m1(t1));
        for i in 0..n {
            self.tmp[i] = 2.0 * self.vm[i] - self.v[i];
        }
        let kin = -0.5
            * ((m1 - m1m) * m.m_burn.form(&self.tmp, &self.tmp)
                + (m1m - m0) * m.m_burn.form(&self.v, &self.v));
        for i in 0..n {
            self.r[i] = m.x_ref[i] + self.qm[i];
        }
        let pot = (m1 - m0) * m.m_burn.form(&self.gravity, &self.r);
        self.works.thrust += h * p.thrust;
        self.works.pressure += h * p.pressure;
        self.works.coriolis += h * p.coriolis;
        self.works.damper += h * p.damper;
        self.works.outflow += kin + pot;
        for i in 0..n {
            self.q[i] += h * self.vm[i];
            self.v[i] = self.tmp[i];
        }
        self.t = t1;
        self.counters.steps += 1;
        Ok(())
    }

    /// Stored energies: kinetic, strain, gravity, discrete springs.
    pub fn stored(&self) -> [f64; 4] {
        let m = &self.model;
        let m1 = m.m1(self.t);
        let kinetic = 0.5 * m.mass_form(m1, &self.v, &self.v);
        let strain = m.strain_energy(&self.q);
        let pos: Vec<f64> = (0..m.n).map(|i| m.x_ref[i] + self.q[i]).collect();
        let gravity = -m.mass_form(m1, &self.gravity, &pos);
        let axis = m.mean_axis(&self.q, &self.v);
        let mut scratch = vec![0.0; m.n];
        let (spring, _) = m.add_spring_forces(axis.phi, &self.q, &self.v, &mut scratch);
        [kinetic, strain, gravity, spring]
    }
}

fn runaway(t: f64, what: String) -> FemError {
    FemError::Runaway {
        t,
        what,
        location: None,
        why: "the implicit midpoint iteration failed".into(),
        remedy: "reduce --dt".into(),
    }
}

/// Channel list (the same names and order as the other backends).
pub fn channel_specs(model: &Model, stations: usize) -> Vec<(String, &'static str)> {
    let mut c = vec![
        spec::rocket_x(),
        spec::rocket_y(),
        spec::rocket_theta(),
        spec::rocket_mass(),
        spec::rocket_vx(),
        spec::rocket_vy(),
    ];
    c.extend((0..stations).map(spec::rocket_axial));
    c.extend((0..stations).map(spec::rocket_transverse));
    for j in 1..=model.masses.len() {
        c.push(spec::rocket_mass_axial(j));
        c.push(spec::rocket_mass_transverse(j));
    }
    c
}

/// Samples the channels of [`channel_specs`].
pub fn observe(model: &Model, t: f64, q: &[f64], v: &[f64], stations: usize, out: &mut Vec<f64>) {
    out.clear();
    let m1 = model.m1(t);
    let mass = model.mass_form(m1, &model.t_xi, &model.t_xi);
    let pos: Vec<f64> = (0..model.n).map(|i| model.x_ref[i] + q[i]).collect();
    let cm = (
        model.mass_form(m1, &model.t_xi, &pos) / mass,
        model.mass_form(m1, &model.t_eta, &pos) / mass,
    );
    let vel = (
        model.mass_form(m1, &model.t_xi, v) / mass,
        model.mass_form(m1, &model.t_eta, v) / mass,
    );
    let (c, s) = (model.theta0.cos(), model.theta0.sin());
    let axis = model.mean_axis(q, v);
    out.push(c * cm.0 - s * cm.1);
    out.push(s * cm.0 + c * cm.1);
    out.push(model.theta0 + axis.phi);
    out.push(mass);
    out.push(c * vel.0 - s * vel.1);
    out.push(s * vel.0 + c * vel.1);
    let rel: Vec<(f64, f64)> = (0..stations)
        .map(|k| {
            let x = k as f64 * model.length / (stations - 1) as f64;
            let (u, w) = model.at(&model.point(x), q);
            axis.relative(model.x_bar, x, x + u, w)
        })
        .collect();
    out.extend(rel.iter().map(|r| r.0));
    out.extend(rel.iter().map(|r| r.1));
    for (j, dm) in model.masses.iter().enumerate() {
        let (iu, iw) = model.mass_dofs(j);
        let (u, w) = axis.relative(model.x_bar, dm.at.x, dm.at.x + q[iu], q[iw]);
        out.push(u);
        out.push(w);
    }
}

pub struct Prepared {
    pub stepper: Stepper,
    pub h: f64,
    pub t_end: f64,
    pub output_interval: f64,
    pub stations: usize,
}

/// The stepper, step and output settings of a run of `r`, the rocket of `scene`.
pub fn prepare(scene: &Scene, r: &Rocket, settings: &FemSettings) -> Result<Prepared, FemError> {
    match settings.method {
        None | Some(data::FemMethod::ImplicitMidpoint) => {}
        Some(other) => {
            return Err(FemError::unsupported(format!(
                "fem rocket: method `{other}`; only `implicit-midpoint` is implemented for the \
                 rocket"
            )));
        }
    }
    if settings.rtol.is_some() || settings.atol.is_some() {
        return Err(FemError::unsupported(
            "fem rocket: adaptive steps (`time.rtol`/`time.atol`); use --dt",
        ));
    }
    let h = crate::settings::positive("time.dt", settings.dt)?.unwrap_or(DEFAULT_STEP);
    let t_end =
        crate::settings::positive("time.t_end", settings.t_end)?.unwrap_or(scene.simulation.t_end);
    let model = build(r, settings)?;
    let q = model.initial_shape(&r.initial_shape);
    let v = vec![0.0; model.n];
    Ok(Prepared {
        stepper: Stepper::new(model, q, v),
        h,
        t_end,
        output_interval: scene.simulation.output_interval,
        stations: scene.simulation.field_stations.max(2),
    })
}

fn push_ledger(st: &Stepper, ledger: &mut EnergyLedger) {
    let w = st.works;
    ledger.push(
        st.t,
        &st.stored(),
        &[w.thrust, w.pressure, w.coriolis],
        &[w.damper, w.outflow],
    );
}

/// A run of `r`, the rocket of `scene`.
pub fn simulate(scene: &Scene, r: &Rocket, settings: &FemSettings) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        mut stepper,
        h,
        t_end,
        output_interval,
        stations,
    } = prepare(scene, r, settings)?;
    let specs = channel_specs(&stepper.model, stations);
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
    observe(
        &stepper.model,
        0.0,
        &stepper.q,
        &stepper.v,
        stations,
        &mut buf,
    );
    obs.push(0.0, &buf);
    push_ledger(&stepper, &mut ledger);
    let burnout = stepper.model.burnout_time();
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut verdict = StabilityVerdict::Completed;
    'outer: for k in 1..=n_out {
        let t_stop = (k as f64 * output_interval).min(t_end);
        while stepper.t < t_stop - 1e-9 * h {
            // Land on the output time and on burn-out (the loads and the mass rate jump there).
            let mut target = t_stop;
            if stepper.t < burnout - 1e-9 * h && burnout < target {
                target = burnout;
            }
            let rest = target - stepper.t;
            let hk = if rest < h * (1.0 + 1e-9) { rest } else { h };
            if let Err(e) = stepper.step(hk) {
                verdict = StabilityVerdict::Stopped {
                    diagnostic: e.into_stop_diagnostic()?,
                };
                break 'outer;
            }
            if (stepper.t - target).abs() < 1e-9 * h {
                stepper.t = target;
            }
        }
        observe(
            &stepper.model,
            stepper.t,
            &stepper.q,
            &stepper.v,
            stations,
            &mut buf,
        );
        if buf.iter().any(|v| !v.is_finite()) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: crate::error::non_finite_state(stepper.t),
            };
            break;
        }
        obs.push(stepper.t, &buf);
        push_ledger(&stepper, &mut ledger);
    }
    Ok(crate::run::run_result(
        scene,
        settings,
        obs,
        ledger,
        Vec::new(),
        stepper.counters.cost(stepper.model.n, start),
        verdict,
    ))
}

/// Free-free modes at ignition mass, discrete masses on their springs: K φ = ω² M(0) φ with K
/// the beam and spring stiffness (no thrust prestress). The three rigid-body modes are dropped.
pub struct RocketMode {
    pub omega: f64,
    pub kind: &'static str,
    pub vector: Vec<f64>,
}

pub fn rocket_modes(model: &Model, count: usize) -> Result<Vec<RocketMode>, FemError> {
    let n = model.n;
    let mut k = Mat::<f64>::zeros(n, n);
    let mut mm = Mat::<f64>::zeros(n, n);
    for &(i, j, v) in &model.k_beam.0 {
        k[(i, j)] += v;
    }
    for (i, j, v, _) in model.spring_entries() {
        k[(i, j)] += v;
    }
    for (i, j, v) in model.coupling_rotation_stiffness() {
        k[(i, j)] += v;
    }
    let mut e = vec![0.0; n];
    let mut col = vec![0.0; n];
    for j in 0..n {
        e[j] = 1.0;
        col.iter_mut().for_each(|x| *x = 0.0);
        model.mass_mul_add(model.m1_0, 1.0, &e, &mut col);
        for i in 0..n {
            mm[(i, j)] = col[i];
        }
        e[j] = 0.0;
    }
    // K is singular (three rigid modes): a Cholesky of K may still succeed on round-off pivots
    // and then ranks the rigid modes' 1/λ as the largest, pushing the elastic ones below the
    // solver's round-off floor. Solve the shifted pencil (K + σM, M), positive definite, and
    // shift back; σ of the order of the elastic spectrum (the smallest K_ii/M_ii) keeps the
    // relative accuracy of the lowest elastic λ near σ/λ·ε.
    let sigma = (0..n)
        .filter(|&i| k[(i, i)] > 0.0 && mm[(i, i)] > 0.0)
        .map(|i| k[(i, i)] / mm[(i, i)])
        .fold(f64::INFINITY, f64::min);
    if !sigma.is_finite() {
        return Err(FemError::Numerical {
            t: 0.0,
            message: "free-free rocket: no stiffness on any degree of freedom".into(),
        });
    }
    let mut k_shifted = k.clone();
    for j in 0..n {
        for i in 0..n {
            k_shifted[(i, j)] += sigma * mm[(i, j)];
        }
    }
    let (mut lam, x) = crate::modes::generalized_eigen(&k_shifted, &mm)?;
    lam.iter_mut().for_each(|l| *l -= sigma);
    const RIGID: usize = 3;
    if lam.len() <= RIGID || lam[..RIGID].iter().any(|l| l.abs() > 1e-6 * lam[RIGID]) {
        return Err(FemError::Numerical {
            t: 0.0,
            message: format!(
                "free-free rocket: the three rigid-body modes were not found (σ = {sigma:.3e}, \
                 lowest eigenvalues {:?})",
                &lam[..lam.len().min(5)]
            ),
        });
    }
    let mut out = Vec::new();
    for (jm, &l) in lam.iter().enumerate().skip(RIGID).take(count) {
        let v: Vec<f64> = (0..n).map(|i| x[(i, jm)]).collect();
        let mut axial = vec![0.0; n];
        for i in 0..n {
            if model.t_xi[i] != 0.0 {
                axial[i] = v[i];
            }
        }
        let total = model.mass_form(model.m1_0, &v, &v);
        let share = model.mass_form(model.m1_0, &axial, &axial) / total;
        out.push(RocketMode {
            omega: l.max(0.0).sqrt(),
            kind: if share > 0.5 { "axial" } else { "bending" },
            vector: v,
        });
    }
    Ok(out)
}

/// The free-free modes of `r`, the rocket of `scene`, at ignition mass.
pub fn modes(
    scene: &Scene,
    r: &Rocket,
    settings: &FemSettings,
    count: usize,
) -> Result<ModalResult, FemError> {
    let start = Instant::now();
    let model = build(r, settings)?;
    let modes = rocket_modes(&model, count)?;
    let stations = scene.simulation.field_stations.max(2);
    let shapes = modes
        .iter()
        .map(|md| {
            let x: Vec<f64> = (0..stations)
                .map(|k| k as f64 * model.length / (stations - 1) as f64)
                .collect();
            let w: Vec<f64> = x
                .iter()
                .map(|&xx| model.at(&model.point(xx), &md.vector).1)
                .collect();
            let scale = w.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            ModeShape {
                link: 1,
                x,
                transverse: w
                    .iter()
                    .map(|v| if scale > 0.0 { v / scale } else { 0.0 })
                    .collect(),
            }
        })
        .collect();
    Ok(crate::modes::modal_result(
        scene,
        settings,
        modes.iter().map(|m| (m.omega, m.kind.to_string())),
        shapes,
        model.n,
        start,
    ))
}

/// Momentum P = T_ξᵀM v, T_ηᵀM v (launch axes) — used by tests.
pub fn momentum(model: &Model, t: f64, v: &[f64]) -> (f64, f64) {
    let m1 = model.m1(t);
    (
        model.mass_form(m1, &model.t_xi, v),
        model.mass_form(m1, &model.t_eta, v),
    )
}

/// Kinetic energy ½vᵀM(t)v — used by tests.
pub fn kinetic(model: &Model, t: f64, v: &[f64]) -> f64 {
    0.5 * model.mass_form(model.m1(t), v, v)
}
