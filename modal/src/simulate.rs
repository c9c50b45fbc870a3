//! Time integration of the chain: state y = (q_free, q̇_free, cumulative works), sampled
//! observables and the energy ledger.

use std::time::Instant;

use data::{
    Cost, Diagnostic, EnergyLedger, Observables, RunResult, Scene, Settings, StabilityVerdict,
    channel,
};

use crate::contact::{ContactState, locate_crossing};
use crate::error::ModalError;
use crate::integrate::{
    Build, DOPRI5, METHODS, MethodInfo, OdeRhs, TRBDF2_FIXED, Tolerances, method_named,
    method_names,
};
use crate::model::Chain;
use crate::model::integrals::dot;
use crate::newton::ChainNewton;
use crate::setup::build_chain;

/// Default tolerances of the adaptive integrators.
pub const DEFAULT_RTOL: f64 = 1e-8;
pub const DEFAULT_ATOL: f64 = 1e-10;
/// (rtol, atol) of the Newton convergence test of the fixed-step methods when none is given:
/// their stages are solved to a few percent of this (see [`crate::integrate::Sdirk`]), far
/// below the step's own truncation error (~1e-5 rad on the joint angles at the default step),
/// and above the round-off floor of the polynomial coordinates, where a tighter test makes
/// Newton stall (`two-link-free`, 8 poly modes, default step: 6356 failed iterations in
/// 11 000 steps at 1e-8 / 1e-10).
pub const FIXED_STEP_NEWTON_TOL: (f64, f64) = (1e-6, 1e-8);

/// An integration method of the registry ([`crate::integrate::METHODS`]).
pub type Method = &'static MethodInfo;

/// The registered method called `name` (None: the default, Dormand–Prince).
pub fn parse_method(name: Option<&str>) -> Result<Method, ModalError> {
    let Some(name) = name else {
        return Ok(METHODS[0]);
    };
    method_named(name).ok_or_else(|| {
        ModalError::invalid(
            "time.method",
            format!("`{name}`: the modal backend offers {}", method_names()),
        )
    })
}

/// The method of a run: the one named in the settings, else the default ([`default_method`]).
pub fn method_choice(scene: &Scene, settings: &Settings) -> Result<Method, ModalError> {
    match settings.time.method.as_deref() {
        Some(name) => parse_method(Some(name)),
        None => Ok(default_method(scene, settings)),
    }
}

/// The default method: fixed-step TR-BDF2 ([`TRBDF2_FIXED`](crate::integrate::TRBDF2_FIXED), step [`default_step`]) for
/// a chain without contact whose every link carries Kelvin–Voigt damping, when no tolerance is
/// given; otherwise Dormand–Prince.
///
/// Why: an explicit method is bound by the highest Ritz frequency (ω ~ β²√(EI/ρAL⁴) grows
/// like the square of the mode number) and, at a tight tolerance, resolves every such mode:
/// `two-link-free` (6 clamped-free modes per link) took 48 931 Dormand–Prince steps for 10 s.
/// TR-BDF2 with the fixed step T₁/[`STEPS_PER_PERIOD`] takes 10⁴ steps and is within 2.3e-5
/// rad of it on the 20 Hz low-passed joint-1 angle. The L-stable method damps what its step
/// does not resolve; that is consistent with the model only where the high modes are
/// physically damped. Undamped links keep their high modes ringing for all time, and their
/// mean (foreshortening) effect on the slow motion is lost when they are damped numerically:
/// on `two-link-free-undamped` fixed-step TR-BDF2 at h = 1e-3 is 1.9e-3 rad off (the
/// trapezoidal rule, which keeps the amplitudes at wrong frequencies, 6.8e-3), so undamped
/// scenes keep the explicit method. A tolerance given (`rtol`/`atol`) asks for an adaptive
/// method; a contact scene keeps Dormand–Prince, whose switching times are located on the
/// tolerance-controlled dense output.
pub fn default_method(scene: &Scene, settings: &Settings) -> Method {
    let tolerance_given = settings.time.rtol.is_some() || settings.time.atol.is_some();
    let all_damped = scene
        .links
        .iter()
        .all(|l| l.kelvin_voigt.is_some_and(|g| g > 0.0));
    if tolerance_given || !scene.contacts.is_empty() || !all_damped {
        &DOPRI5
    } else {
        &TRBDF2_FIXED
    }
}

/// Fixed steps per period of the fastest first bending mode ([`default_step`]).
pub const STEPS_PER_PERIOD: f64 = 128.0;

/// Default step of the fixed-step methods: T₁/[`STEPS_PER_PERIOD`] with T₁ = 2π/ω₁ the
/// shortest first-mode period among the links, ω₁ = β₁²√(EI/(ρA L⁴)), β₁ = 1.8751 (the
/// clamped–free cantilever; a tip mass or a child link only lowers it, so the step is
/// conservative). `two-link-free`: T₁ = 0.134 s (link 2), h = 1.05e-3.
pub fn default_step(scene: &Scene) -> f64 {
    const BETA1: f64 = 1.875_104_068_711_961;
    scene
        .links
        .iter()
        .map(|l| {
            let omega1 = BETA1
                * BETA1
                * (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt();
            std::f64::consts::TAU / omega1 / STEPS_PER_PERIOD
        })
        .fold(f64::INFINITY, f64::min)
}

/// Which cumulative power integrals the state carries (only those the scene needs).
#[derive(Debug, Clone, Copy, Default)]
struct WorkSlots {
    applied: Option<usize>,
    prescribed: Option<usize>,
    joint_damper: Option<usize>,
    kelvin_voigt: Option<usize>,
    /// ∫ μ|λ||v_t| dt of a friction contact.
    friction: Option<usize>,
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
    /// A failed evaluation was Painlevé's paradox of the friction contact, not a singular M.
    pub painleve: bool,
    /// The tip contact, when the scene has one (see [`crate::contact`]).
    pub contact: Option<ContactState>,
    /// Model evaluations outside the integrator (event location, impacts, projections).
    pub event_solves: usize,
    /// Work arrays of [`OdeRhs::jacobian`]: the N × N force tangents and one free column.
    kt: Vec<f64>,
    dt: Vec<f64>,
    col: Vec<f64>,
    /// Position of each coordinate among the free ones (usize::MAX for prescribed).
    free_of: Vec<usize>,
    /// Factored Newton linear algebra ([`OdeRhs::newton_linearize`]).
    lin: ChainNewton,
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
        slots.kelvin_voigt = take(chain.links.iter().any(|l| l.has_kelvin_voigt()));
        slots.count = k - 2 * nf;
        let mut free_of = vec![usize::MAX; n];
        for (k, &g) in chain.free.iter().enumerate() {
            free_of[g] = k;
        }
        ChainRhs {
            free_of,
            lin: ChainNewton::new(nf, slots.count),
            kt: vec![0.0; n * n],
            dt: vec![0.0; n * n],
            col: vec![0.0; nf],
            chain,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            slots,
            singular: false,
            painleve: false,
            contact: None,
            event_solves: 0,
        }
    }

    fn nf(&self) -> usize {
        self.chain.free.len()
    }

    /// Attaches the tip contact; a friction contact gets its dissipation integral in the state.
    pub fn attach_contact(&mut self, contact: Option<ContactState>) {
        if contact.as_ref().is_some_and(|c| c.has_friction()) {
            self.slots.friction = Some(2 * self.nf() + self.slots.count);
            self.slots.count += 1;
            self.lin = ChainNewton::new(self.nf(), self.slots.count);
        }
        self.contact = contact;
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
    /// [`Self::solve`] outside the integrator, counted in the cost.
    fn solve_counted(&mut self, t: f64, y: &[f64]) -> bool {
        self.event_solves += 1;
        let ok = self.solve(t, y);
        self.painleve |= !ok && self.contact.as_ref().is_some_and(|c| c.painleve);
        ok
    }

    fn solve(&mut self, t: f64, y: &[f64]) -> bool {
        self.load(t, y);
        self.chain.evaluate(t, &self.q, &self.qd);
        if self.chain.accelerations(t, &mut self.qdd).is_err() {
            return false;
        }
        if let Some(c) = self.contact.as_mut() {
            let chain = &self.chain;
            let n = chain.n;
            chain.tip_jacobian(c.link, &mut c.jac);
            c.set_geometry(chain.tip_position(c.link));
            let (nv, tv) = (c.normal, c.tangent);
            for (k, &g) in chain.free.iter().enumerate() {
                c.g_row[k] = nv[0] * c.jac[g] + nv[1] * c.jac[n + g];
                c.t_row[k] = tv[0] * c.jac[g] + tv[1] * c.jac[n + g];
                c.minv_gt[k] = c.g_row[k];
            }
            chain.solve_free_mass(&mut c.minv_gt);
            c.gmg = dot(&c.g_row, &c.minv_gt);
            let (mut vn, mut vt, mut g_qdd, mut t_qdd) = (0.0, 0.0, 0.0, 0.0);
            for (k, &g) in chain.free.iter().enumerate() {
                vn += c.g_row[k] * self.qd[g];
                vt += c.t_row[k] * self.qd[g];
                g_qdd += c.g_row[k] * self.qdd[g];
                t_qdd += c.t_row[k] * self.qdd[g];
            }
            c.normal_velocity = vn;
            c.slip_velocity = vt;
            c.lambda = 0.0;
            c.lambda_t = 0.0;
            c.friction_power = 0.0;
            c.painleve = false;
            if c.constrained {
                let conv = chain.tip_convective_acceleration(c.link);
                // g̈ = G q̈ + n̂·c − κ v_t² must vanish (see crate::contact).
                let hn = nv[0] * conv[0] + nv[1] * conv[1] - c.curvature * vt * vt;
                let rhs_n = -(g_qdd + hn);
                let friction = c.bilateral && c.mu > 0.0;
                if friction {
                    c.minv_tt.copy_from_slice(&c.t_row);
                    chain.solve_free_mass(&mut c.minv_tt);
                }
                if c.sticking {
                    // Tip held: J q̈ + c = 0 in (n̂, t̂); the tip is at rest so κ v_t² ≈ 0.
                    let gmt = dot(&c.g_row, &c.minv_tt);
                    let tmt = dot(&c.t_row, &c.minv_tt);
                    let rhs_t = -(t_qdd + tv[0] * conv[0] + tv[1] * conv[1]);
                    let [ln, lt] = crate::contact::solve2(c.gmg, gmt, tmt, [rhs_n, rhs_t]);
                    c.lambda = ln;
                    c.lambda_t = lt;
                    for (k, &g) in chain.free.iter().enumerate() {
                        self.qdd[g] += c.minv_gt[k] * ln + c.minv_tt[k] * lt;
                    }
                } else if friction {
                    let gmt = dot(&c.g_row, &c.minv_tt);
                    if c.gmg <= c.mu * gmt.abs() {
                        c.painleve = true;
                        return false;
                    }
                    // Both denominators are positive: σ = sign λ = sign rhs_n.
                    let s = c.slip_dir;
                    let sigma = if rhs_n >= 0.0 { 1.0 } else { -1.0 };
                    let lam = rhs_n / (c.gmg - c.mu * s * sigma * gmt);
                    let ft = -c.mu * s * lam.abs();
                    c.lambda = lam;
                    c.lambda_t = ft;
                    c.friction_power = c.mu * lam.abs() * vt.abs();
                    for (k, &g) in chain.free.iter().enumerate() {
                        self.qdd[g] += c.minv_gt[k] * lam + c.minv_tt[k] * ft;
                    }
                } else {
                    c.lambda = rhs_n / c.gmg;
                    for (k, &g) in chain.free.iter().enumerate() {
                        self.qdd[g] += c.minv_gt[k] * c.lambda;
                    }
                }
            }
        }
        true
    }

    /// ∂P/∂q̇ of the cumulative-work powers at the last solve into `lin.p` (one row per work
    /// slot, free columns): exact for applied torques (τ(t)), joint dampers (2dθ̇) and the
    /// Kelvin–Voigt dissipation (2Dẋ); zero for the prescribed-motion and friction powers,
    /// whose rows only delay their own slot's convergence by one Newton iteration (no other
    /// component depends on a work).
    fn power_rows(&mut self, t: f64) {
        let nf = self.nf();
        let s = self.slots;
        let p = &mut self.lin.p;
        p.iter_mut().for_each(|v| *v = 0.0);
        let base = 2 * nf;
        for (i, j) in self.chain.joints.iter().enumerate() {
            if j.prescribed.is_some() {
                continue;
            }
            let th = self.chain.links[i].theta;
            let k = self.free_of[th];
            if let (Some(row), Some(law)) = (s.applied, &j.torque) {
                p[(row - base) * nf + k] += law.torque(t);
            }
            if let Some(row) = s.joint_damper {
                p[(row - base) * nf + k] += 2.0 * j.damping * self.qd[th];
            }
        }
        if let Some(row) = s.kelvin_voigt {
            for l in &self.chain.links {
                if l.has_kelvin_voigt() {
                    let nbc = l.nbc();
                    let xd = &self.qd[l.b0..l.b0 + nbc];
                    for r in 0..nbc {
                        let k = self.free_of[l.b0 + r];
                        p[(row - base) * nf + k] +=
                            2.0 * dot(&l.section.dbc[r * nbc..(r + 1) * nbc], xd);
                    }
                }
            }
        }
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

/// x ← P x for the accelerations of the constrained phase: with the contact active,
/// q̈ = M⁻¹F + M⁻¹Aᵀλ(F) and λ solves A q̈ = −(convective terms), so a change M⁻¹δF of the
/// unconstrained accelerations becomes P M⁻¹δF with P = I − M⁻¹Aᵀ(A M⁻¹Aᵀ)⁻¹A (A = G sliding,
/// (G; T) sticking); with sliding friction the tangential force −μ s|λ| rides on λ, so
/// P = I − (M⁻¹Gᵀ − μsσ M⁻¹Tᵀ)G / (G M⁻¹Gᵀ − μsσ G M⁻¹Tᵀ), σ = sign λ (as in `solve`).
fn constrain_column(c: &ContactState, x: &mut [f64]) {
    if !c.constrained {
        return;
    }
    let gx = dot(&c.g_row, x);
    if c.sticking {
        let tx = dot(&c.t_row, x);
        let gmt = dot(&c.g_row, &c.minv_tt);
        let tmt = dot(&c.t_row, &c.minv_tt);
        let [a, b] = crate::contact::solve2(c.gmg, gmt, tmt, [gx, tx]);
        for k in 0..x.len() {
            x[k] -= c.minv_gt[k] * a + c.minv_tt[k] * b;
        }
    } else if c.bilateral && c.mu > 0.0 {
        let gmt = dot(&c.g_row, &c.minv_tt);
        let ms = c.sliding_friction_slope();
        let a = gx / (c.gmg - ms * gmt);
        for k in 0..x.len() {
            x[k] -= (c.minv_gt[k] - ms * c.minv_tt[k]) * a;
        }
    } else {
        let a = gx / c.gmg;
        for k in 0..x.len() {
            x[k] -= c.minv_gt[k] * a;
        }
    }
}

impl OdeRhs for ChainRhs {
    fn dim(&self) -> usize {
        2 * self.nf() + self.slots.count
    }

    /// Structured Jacobian of y' = (q̇, q̈, powers): ∂q̇/∂q̇ = I; the acceleration rows
    /// ∂q̈/∂q = −P M⁻¹K_t, ∂q̈/∂q̇ = −P M⁻¹D_t with M = M(q) at y (its Cholesky factor from the
    /// evaluation), K_t, D_t the elastic/Kelvin–Voigt/joint tangents
    /// ([`Chain::elastic_tangent`]) and P the constraint projection of the contact phase
    /// (`constrain_column`); the power rows are exact for the joint dampers (2dθ̇), the
    /// Kelvin–Voigt dissipation (2Dẋ) and applied torques (τ(t)), zero for the prescribed-motion
    /// and friction powers. What it leaves out — ∂M/∂q·q̈, gravity, centrifugal and gyroscopic
    /// terms, the convective constraint terms — is bounded by the rigid-body rates, while the
    /// columns kept carry every stiff eigenvalue (up to (γ/EI)ω²_max of the overdamped
    /// Kelvin–Voigt modes). Costs one model evaluation and 2·N_free Cholesky substitutions,
    /// against 2·dim evaluations for forward differences, and is free of their cancellation
    /// error (see [`crate::integrate::Sdirk`]).
    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> bool {
        if !self.solve(t, y) {
            return false;
        }
        let nf = self.nf();
        let dim = self.dim();
        let n = self.chain.n;
        self.chain
            .elastic_tangent(&self.q, &mut self.kt, &mut self.dt);
        jac.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..nf {
            jac[(nf + k) * dim + k] = 1.0;
        }
        for (cf, &gc) in self.chain.free.iter().enumerate() {
            for (m, jcol) in [(&self.kt, cf), (&self.dt, nf + cf)] {
                let mut any = false;
                for (r, &gr) in self.chain.free.iter().enumerate() {
                    self.col[r] = m[gr * n + gc];
                    any |= self.col[r] != 0.0;
                }
                if !any {
                    continue;
                }
                self.chain.solve_free_mass(&mut self.col);
                if let Some(c) = &self.contact {
                    constrain_column(c, &mut self.col);
                }
                let out = &mut jac[jcol * dim + nf..jcol * dim + 2 * nf];
                for (o, v) in out.iter_mut().zip(&self.col) {
                    *o = -v;
                }
            }
        }
        self.power_rows(t);
        for r in 0..self.slots.count {
            for k in 0..nf {
                jac[(nf + k) * dim + 2 * nf + r] = self.lin.p[r * nf + k];
            }
        }
        true
    }

    /// The linearization of [`Self::jacobian`] in factored form ([`ChainNewton`]): M, K, D over
    /// the free coordinates, the contact rows and the power rows at (t, y).
    fn newton_linearize(&mut self, t: f64, y: &[f64]) -> bool {
        if !self.solve(t, y) {
            return false;
        }
        let n = self.chain.n;
        let nf = self.nf();
        self.chain
            .elastic_tangent(&self.q, &mut self.kt, &mut self.dt);
        let mass = self.chain.mass_matrix();
        for (r, &gr) in self.chain.free.iter().enumerate() {
            for (c, &gc) in self.chain.free.iter().enumerate() {
                self.lin.m[r * nf + c] = mass[gr * n + gc];
                self.lin.k[r * nf + c] = self.kt[gr * n + gc];
                self.lin.d[r * nf + c] = self.dt[gr * n + gc];
            }
        }
        self.lin.rows = 0;
        if let Some(c) = self.contact.as_ref().filter(|c| c.constrained) {
            let lin = &mut self.lin;
            lin.a[..nf].copy_from_slice(&c.g_row);
            lin.w[..nf].copy_from_slice(&c.g_row);
            lin.rows = 1;
            if c.sticking {
                lin.a[nf..2 * nf].copy_from_slice(&c.t_row);
                lin.w[nf..2 * nf].copy_from_slice(&c.t_row);
                lin.rows = 2;
            } else if c.bilateral && c.mu > 0.0 {
                // The friction force −μ s|λ| rides on λ (see `solve`): W = Gᵀ − μsσTᵀ.
                let ms = c.sliding_friction_slope();
                for k in 0..nf {
                    lin.w[k] -= ms * c.t_row[k];
                }
            }
        }
        self.power_rows(t);
        true
    }

    fn newton_factor(&mut self, c: f64) -> bool {
        self.lin.factor(c)
    }

    fn newton_solve(&mut self, x: &mut [f64]) {
        self.lin.solve(x);
    }

    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let nf = self.nf();
        if !self.solve(t, y) {
            self.singular = true;
            self.painleve |= self.contact.as_ref().is_some_and(|c| c.painleve);
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
                if l.has_kelvin_voigt() {
                    // ẋᵀD ẋ over the bending block x = [b, c].
                    let nbc = l.nbc();
                    let xd = &self.qd[l.b0..l.b0 + nbc];
                    for r in 0..nbc {
                        p += xd[r] * dot(&l.section.dbc[r * nbc..(r + 1) * nbc], xd);
                    }
                }
            }
            dydt[k] = p;
        }
        if let Some(k) = s.friction {
            dydt[k] = self.contact.as_ref().map_or(0.0, |c| c.friction_power);
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
        let has_contact = rhs.contact.is_some();
        if has_contact {
            specs.push((channel::contact_normal_force(1), "force"));
            specs.push((channel::contact_phase(1), "1"));
            // Not a standard channel: the constraint violation (penetration < 0) at the samples.
            specs.push(("contact1.gap".to_string(), "length"));
        }
        let has_friction = rhs.contact.as_ref().is_some_and(|c| c.has_friction());
        if has_friction {
            // Not standard channels: tangential tip velocity T q̇ and friction force along t̂.
            specs.push((SLIP_VELOCITY_CHANNEL.to_string(), "length/time"));
            specs.push((FRICTION_FORCE_CHANNEL.to_string(), "force"));
            specs.push((FRICTION_WORK_CHANNEL.to_string(), "energy"));
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
        if rhs.contact.as_ref().is_some_and(|c| !c.bilateral) {
            diss.push("impact");
        }
        if rhs.slots.friction.is_some() {
            diss.push("friction");
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
        if let Some(ct) = &rhs.contact {
            self.values[c] = ct.lambda;
            self.values[c + 1] = if ct.sticking {
                2.0
            } else if ct.constrained {
                1.0
            } else {
                0.0
            };
            self.values[c + 2] = ct.gap;
            if ct.has_friction() {
                self.values[c + 3] = ct.slip_velocity;
                self.values[c + 4] = ct.lambda_t;
                self.values[c + 5] = rhs.slots.friction.map_or(0.0, |i| y[i]);
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
        let (mut diss, mut nd) = ([0.0; 4], 0);
        for i in [s.joint_damper, s.kelvin_voigt].into_iter().flatten() {
            diss[nd] = y[i];
            nd += 1;
        }
        if let Some(ct) = rhs.contact.as_ref().filter(|c| !c.bilateral) {
            diss[nd] = ct.impact_loss;
            nd += 1;
        }
        if let Some(i) = s.friction {
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

/// Diagnostics of a contact run that the `RunResult` has no field for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactReport {
    /// Largest |g| and |G q̇| found at the end of a constrained step, before the projection.
    pub max_gap_violation: f64,
    pub max_normal_velocity_violation: f64,
    /// Largest penetration −g seen in free flight at a located contact start.
    pub max_gap_at_contact_start: f64,
    /// Stated time tolerance of the event location (bracket width bound).
    pub time_tolerance: f64,
    /// Number of drift projections applied.
    pub projections: usize,
    /// Largest constraint power |λ·G q̇| at the end of a constrained step (zero in exact
    /// arithmetic on a fixed frictionless surface) and the kinetic energy the velocity
    /// projections removed in total (½(Gq̇)²/(GM⁻¹Gᵀ) each).
    pub max_constraint_power: f64,
    pub projection_energy: f64,
    /// Friction contact: largest |v_t| and tangential drift |t̂·(r − stick point)| found at the
    /// end of a stick step, before the projection; number of slip reversals (v_t crossed zero
    /// and the Coulomb test sent the tip back the other way without sticking).
    pub max_stick_velocity: f64,
    pub max_stick_offset: f64,
    pub slip_reversals: usize,
}

/// Full generalized coordinates q and rates q̇ at the end of a run, plus the contact report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FinalState {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub contact: ContactReport,
}

/// Tangential tip velocity v_t = t̂·ṙ_tip of a friction contact (no `data::channel` convention
/// exists for it).
pub const SLIP_VELOCITY_CHANNEL: &str = "contact1.slip_velocity";
/// Tangential (friction) force on the tip along t̂ of a friction contact.
pub const FRICTION_FORCE_CHANNEL: &str = "contact1.friction_force";

/// Cumulative friction work ∫ μ|λ||v_t| dt (the ledger's `friction` term, as a channel so that
/// summaries show it).
pub const FRICTION_WORK_CHANNEL: &str = "contact1.friction_work";

/// Time tolerance of the contact-start and release events (width of the final bracket).
pub const EVENT_TIME_TOLERANCE: f64 = 1e-12;
/// Upper bound on the number of contact events in a run (guards a Zeno-like accumulation).
pub const MAX_CONTACT_EVENTS: usize = 20_000;

pub fn simulate(scene: &Scene, settings: &Settings) -> Result<RunResult, ModalError> {
    simulate_detailed(scene, settings).map(|(r, _)| r)
}

/// [`simulate`] that also returns the final state and the contact diagnostics.
pub fn simulate_detailed(
    scene: &Scene,
    settings: &Settings,
) -> Result<(RunResult, FinalState), ModalError> {
    let wall = Instant::now();
    let chain = build_chain(scene, &settings.discretization)?;
    let method = method_choice(scene, settings)?;
    let fixed_step = method.is_fixed_step();
    let (rtol_default, atol_default) = if fixed_step {
        FIXED_STEP_NEWTON_TOL
    } else {
        (DEFAULT_RTOL, DEFAULT_ATOL)
    };
    let rtol = settings.time.rtol.unwrap_or(rtol_default);
    let atol = settings.time.atol.unwrap_or(atol_default);
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

    let (n_all, n_free) = (chain.n, chain.free.len());
    let mut rhs = ChainRhs::new(chain);
    rhs.attach_contact(ContactState::from_scene(scene, n_all, n_free)?);
    let mut y = rhs.initial_state();
    let dim = y.len();
    let tol = Tolerances { rtol, atol };
    let mut stepper = match method.build {
        Build::Adaptive(build) => build(dim, tol, settings.time.dt),
        Build::Fixed(build) => build(
            dim,
            tol,
            settings.time.dt.unwrap_or_else(|| default_step(scene)),
        ),
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
    let mut events: Vec<data::Event> = Vec::new();
    let mut report = ContactReport {
        time_tolerance: EVENT_TIME_TOLERANCE,
        ..Default::default()
    };
    if rhs.contact.as_ref().is_some_and(|c| c.bilateral) {
        start_bilateral(&mut rhs, &mut y, &mut events, &mut report)?;
    }
    if !out.sample(&mut rhs, 0.0, &y) {
        return Err(ModalError::Numerical {
            t: 0.0,
            message: "mass matrix not positive definite at the initial state".into(),
        });
    }
    k_out = k_out.max(1);
    // Event function of the current phase at the last accepted state: the gap in free flight,
    // the normal force when constrained, the slip velocity or the Coulomb margin with friction.
    let mut event_prev = match &rhs.contact {
        Some(c) if c.bilateral => phase_event_value(&rhs),
        Some(c) => c.gap,
        None => 0.0,
    };
    if event_prev < 0.0 && rhs.contact.as_ref().is_some_and(|c| !c.bilateral) {
        return Err(ModalError::invalid(
            "contact",
            format!("the tip starts {:.3e} inside the surface", -event_prev),
        ));
    }
    let mut scratch = vec![0.0; dim];
    'outer: for &target in &breaks {
        while t < target {
            let t_old = t;
            if let Err(e) = stepper.step(&mut rhs, &mut t, &mut y, target) {
                verdict = stopped(&rhs, t, &e.to_string(), None);
                break 'outer;
            }
            // Event detection at the end of the step, located on the dense output.
            let mut event_time = None;
            if rhs.contact.is_some() {
                if !rhs.solve_counted(t, &y) {
                    verdict = stopped(&rhs, t, "mass matrix lost positive definiteness", None);
                    break 'outer;
                }
                let now = phase_event_value(&rhs);
                if now <= 0.0 && event_prev > 0.0 {
                    let mut eval = |tau: f64| {
                        stepper.dense(tau, &mut scratch);
                        if rhs.solve_counted(tau, &scratch) {
                            phase_event_value(&rhs)
                        } else {
                            f64::NAN
                        }
                    };
                    let (te, _, width) =
                        locate_crossing(&mut eval, t_old, event_prev, t, now, EVENT_TIME_TOLERANCE);
                    event_time = Some((te, width));
                } else if now < 0.0 && !rhs.contact.as_ref().is_some_and(|c| c.constrained) {
                    // Free flight that began on the surface and went below it without first
                    // leaving: take the contact at the step start (reported tolerance: the step).
                    let tol_gap = 1e-9
                        * rhs.chain.links[rhs.contact.as_ref().unwrap().link]
                            .ints
                            .length;
                    if now < -tol_gap {
                        event_time = Some((t_old, t - t_old));
                    }
                }
            }
            let t_limit = event_time.map_or(t, |(te, _)| te);
            while k_out < n_out && out_time(k_out) <= t_limit {
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
            if let Some((te, tol_t)) = event_time {
                if te != t {
                    stepper.dense(te, &mut yd);
                    y.copy_from_slice(&yd);
                    t = te;
                }
                if events.len() >= MAX_CONTACT_EVENTS {
                    verdict = StabilityVerdict::Stopped {
                        diagnostic: Diagnostic {
                            t,
                            what: format!("{} contact events", events.len()),
                            location: Some("contact1".into()),
                            why: "impacts/releases or stick–slip transitions accumulate \
                                  (Zeno-like chattering)"
                                .into(),
                            remedy: "shorten t_end or add damping".into(),
                        },
                    };
                    break 'outer;
                }
                if !switch_phase(&mut rhs, t, &mut y, tol_t, &mut events, &mut report) {
                    verdict = stopped(&rhs, t, "mass matrix lost positive definiteness", None);
                    break 'outer;
                }
                stepper.reset();
            } else if rhs.contact.as_ref().is_some_and(|c| c.constrained) {
                if !project(&mut rhs, t, &mut y, &mut report) {
                    verdict = stopped(&rhs, t, "mass matrix lost positive definiteness", None);
                    break 'outer;
                }
                stepper.state_changed();
            }
            if rhs.contact.is_some() {
                if !rhs.solve_counted(t, &y) {
                    verdict = stopped(&rhs, t, "mass matrix lost positive definiteness", None);
                    break 'outer;
                }
                event_prev = phase_event_value(&rhs);
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
        rhs_evaluations: st.rhs_evals + rhs.event_solves,
        jacobian_evaluations: st.jacobian_evals,
        factorizations: st.factorizations,
        newton_iterations: st.newton_iters,
    };
    rhs.load(t, &y);
    let fin = FinalState {
        q: rhs.q.clone(),
        qd: rhs.qd.clone(),
        contact: report,
    };
    let result = RunResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: settings.clone(),
        observables: out.obs,
        ledger: out.ledger,
        events,
        cost,
        verdict,
    };
    Ok((result, fin))
}

/// Event function of the current phase (after `solve`): the gap in free flight, the normal
/// force in contact. A phase ends when it goes from positive to non-positive.
fn phase_event_value(rhs: &ChainRhs) -> f64 {
    match &rhs.contact {
        Some(c) if c.bilateral && !c.has_friction() => 1.0,
        Some(c) if c.bilateral && c.sticking => c.mu * c.lambda.abs() - c.lambda_t.abs(),
        Some(c) if c.bilateral => c.slip_dir * c.slip_velocity,
        Some(c) if c.constrained => c.lambda,
        Some(c) => c.gap,
        None => 0.0,
    }
}

/// Applies the located event at (t, y): contact start + impact (then constrained or free by the
/// sign of the would-be normal force), or release. Returns false on a singular mass matrix.
fn switch_phase(
    rhs: &mut ChainRhs,
    t: f64,
    y: &mut [f64],
    time_tolerance: f64,
    events: &mut Vec<data::Event>,
    report: &mut ContactReport,
) -> bool {
    let nf = rhs.nf();
    if !rhs.solve_counted(t, y) {
        return false;
    }
    let c = rhs.contact.as_ref().expect("contact run");
    if c.bilateral {
        if c.sticking {
            // The Coulomb margin reached zero: slide in the direction the tangential load drives.
            let s = if c.lambda_t > 0.0 { -1.0 } else { 1.0 };
            let c = rhs.contact.as_mut().unwrap();
            c.sticking = false;
            c.slip_dir = s;
            events.push(data::Event::StickSlip {
                t,
                contact: 1,
                sticking: false,
            });
            return true;
        }
        let s = c.slip_dir;
        return coulomb_test(rhs, t, y, events, report, Some(s));
    }
    if c.constrained {
        events.push(data::Event::Release {
            t,
            contact: 1,
            normal_force: c.lambda,
            time_tolerance,
        });
        rhs.contact.as_mut().unwrap().constrained = false;
        return true;
    }
    report.max_gap_at_contact_start = report.max_gap_at_contact_start.max(-c.gap);
    events.push(data::Event::ContactStart {
        t,
        contact: 1,
        time_tolerance,
    });
    // Impact: Λ = −G q̇⁻ / (G M⁻¹ Gᵀ), q̇⁺ = q̇⁻ + M⁻¹Gᵀ Λ.
    let ke_before = rhs.chain.energy(&rhs.q).kinetic;
    let v_before = c.normal_velocity;
    let impulse = -v_before / c.gmg;
    let velocity_before: Vec<f64> = y[nf..2 * nf].to_vec();
    for k in 0..nf {
        y[nf + k] += c.minv_gt[k] * impulse;
    }
    // Momentum residual with the mass matrix at q (unchanged by the jump).
    let n = rhs.chain.n;
    let mass = rhs.chain.mass_matrix();
    let (mut res2, mut mom2) = (0.0, 0.0);
    for (r, &gr) in rhs.chain.free.iter().enumerate() {
        let mut m_dv = 0.0;
        for (k, &gc) in rhs.chain.free.iter().enumerate() {
            m_dv += mass[gr * n + gc] * (y[nf + k] - velocity_before[k]);
        }
        let r_k = m_dv - c.g_row[r] * impulse;
        res2 += r_k * r_k;
        mom2 += m_dv * m_dv;
    }
    let momentum_residual = if mom2 > 0.0 {
        (res2 / mom2).sqrt()
    } else {
        res2.sqrt()
    };
    // Decide the next phase by the sign of the would-be normal force at (q, q̇⁺).
    rhs.contact.as_mut().unwrap().constrained = true;
    if !rhs.solve_counted(t, y) {
        return false;
    }
    let ke_after = rhs.chain.energy(&rhs.q).kinetic;
    let c = rhs.contact.as_mut().unwrap();
    let loss = ke_before - ke_after;
    c.impact_loss += loss;
    events.push(data::Event::Impact {
        t,
        contact: 1,
        velocity_before,
        velocity_after: y[nf..2 * nf].to_vec(),
        impulse,
        momentum_residual,
        normal_velocity_after: c.normal_velocity,
        kinetic_energy_lost: loss,
    });
    if c.lambda <= 0.0 {
        c.constrained = false;
    }
    true
}

/// Start of a bilateral contact run: the initial state must lie on the surface; its velocity is
/// projected onto G q̇ = 0 and, with friction, the phase is decided (a tip at rest gets the
/// Coulomb test, a moving one slides in the direction of v_t).
fn start_bilateral(
    rhs: &mut ChainRhs,
    y: &mut [f64],
    events: &mut Vec<data::Event>,
    report: &mut ContactReport,
) -> Result<(), ModalError> {
    let singular = || ModalError::Numerical {
        t: 0.0,
        message: "mass matrix not positive definite at the initial state".into(),
    };
    // The geometry (gap, G) is set even when the constrained solve fails: check it first.
    let solved = rhs.solve_counted(0.0, y);
    let c = rhs.contact.as_ref().unwrap();
    let len = rhs.chain.links[c.link].ints.length;
    if c.gap.abs() > 1e-9 * len {
        return Err(ModalError::invalid(
            "contact",
            format!(
                "bilateral contact: the tip starts {:.3e} off the surface (the initial state must                  satisfy the constraint to 1e-9 L)",
                c.gap
            ),
        ));
    }
    if c.gmg.is_nan() || c.gmg <= 0.0 {
        return Err(ModalError::Unsupported(
            "modal: the bilateral constraint gradient G = n̂ᵀJ vanishes at the initial state \
             (no coordinate moves the tip along the normal): the constraint is degenerate"
                .into(),
        ));
    }
    if !solved {
        return Err(if rhs.painleve {
            ModalError::Numerical {
                t: 0.0,
                message: "Painlevé's paradox at the initial state: G M⁻¹Gᵀ ≤ μ|G M⁻¹Tᵀ|".into(),
            }
        } else {
            singular()
        });
    }
    let c = rhs.contact.as_ref().unwrap();
    if c.has_friction() {
        let vt = c.slip_velocity;
        if vt == 0.0 {
            if !coulomb_test(rhs, 0.0, y, events, report, None) {
                return Err(singular());
            }
        } else {
            rhs.contact.as_mut().unwrap().slip_dir = vt.signum();
        }
    }
    if !project(rhs, 0.0, y, report) {
        return Err(singular());
    }
    Ok(())
}

/// Coulomb test with the tip at rest tangentially (v_t = 0): the forces that hold it
/// (λ_n, λ_t) decide stick (|λ_t| ≤ μ|λ_n|) or slip in direction −sign λ_t. `sliding` is the
/// direction before (None at the start of the run).
fn coulomb_test(
    rhs: &mut ChainRhs,
    t: f64,
    y: &[f64],
    events: &mut Vec<data::Event>,
    report: &mut ContactReport,
    sliding: Option<f64>,
) -> bool {
    rhs.contact.as_mut().unwrap().sticking = true;
    if !rhs.solve_counted(t, y) {
        return false;
    }
    let link = rhs.contact.as_ref().unwrap().link;
    let tip = rhs.chain.tip_position(link);
    let c = rhs.contact.as_mut().unwrap();
    if c.lambda_t.abs() <= c.mu * c.lambda.abs() {
        c.stick_point = tip;
        c.stick_offset = 0.0;
        events.push(data::Event::StickSlip {
            t,
            contact: 1,
            sticking: true,
        });
    } else {
        c.sticking = false;
        let s = if c.lambda_t > 0.0 { -1.0 } else { 1.0 };
        match sliding {
            None => events.push(data::Event::StickSlip {
                t,
                contact: 1,
                sticking: false,
            }),
            Some(old) if old != s => report.slip_reversals += 1,
            Some(_) => {}
        }
        c.slip_dir = s;
    }
    true
}

/// Drift control of the constrained phase: Newton on the position constraints in the M⁻¹
/// metric, q ← q − M⁻¹Aᵀ(A M⁻¹Aᵀ)⁻¹e (at most 3 passes), then the M-orthogonal velocity
/// projection q̇ ← q̇ − M⁻¹Aᵀ(A M⁻¹Aᵀ)⁻¹A q̇. A = G (e = g) while sliding; A = (G; T),
/// e = (g, t̂·(r − stick point)) while sticking.
fn project(rhs: &mut ChainRhs, t: f64, y: &mut [f64], report: &mut ContactReport) -> bool {
    let nf = rhs.nf();
    if !rhs.solve_counted(t, y) {
        return false;
    }
    {
        let c = rhs.contact.as_ref().unwrap();
        report.max_gap_violation = report.max_gap_violation.max(c.gap.abs());
        report.max_normal_velocity_violation = report
            .max_normal_velocity_violation
            .max(c.normal_velocity.abs());
        report.max_constraint_power = report
            .max_constraint_power
            .max((c.lambda * c.normal_velocity).abs());
        if c.sticking {
            report.max_stick_velocity = report.max_stick_velocity.max(c.slip_velocity.abs());
            report.max_stick_offset = report.max_stick_offset.max(c.stick_offset.abs());
        }
    }
    // (a, b) = (A M⁻¹Aᵀ)⁻¹ r for the active rows (b = 0 while sliding).
    let weights = |c: &ContactState, r: [f64; 2]| -> [f64; 2] {
        if c.sticking {
            let gmt = dot(&c.g_row, &c.minv_tt);
            let tmt = dot(&c.t_row, &c.minv_tt);
            crate::contact::solve2(c.gmg, gmt, tmt, r)
        } else {
            [r[0] / c.gmg, 0.0]
        }
    };
    for pass in 0..3 {
        let c = rhs.contact.as_ref().unwrap();
        let [a, b] = weights(c, [c.gap, c.stick_offset]);
        for k in 0..nf {
            y[k] -= c.minv_gt[k] * a;
            if c.sticking {
                y[k] -= c.minv_tt[k] * b;
            }
        }
        if !rhs.solve_counted(t, y) {
            return false;
        }
        let c = rhs.contact.as_ref().unwrap();
        let len = rhs.chain.links[c.link].ints.length;
        let held = !c.sticking || c.stick_offset.abs() <= 1e-14 * len;
        if (c.gap.abs() <= 1e-14 * len && held) || pass == 2 {
            break;
        }
    }
    let c = rhs.contact.as_ref().unwrap();
    let vt = if c.sticking { c.slip_velocity } else { 0.0 };
    let [a, b] = weights(c, [c.normal_velocity, vt]);
    report.projection_energy += 0.5 * (a * c.normal_velocity + b * vt);
    for k in 0..nf {
        y[nf + k] -= c.minv_gt[k] * a;
        if c.sticking {
            y[nf + k] -= c.minv_tt[k] * b;
        }
    }
    report.projections += 1;
    true
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
            why: if rhs.painleve {
                "Painlevé's paradox: G M⁻¹Gᵀ ≤ μ|G M⁻¹Tᵀ|, the sliding friction contact has no \
                 unique normal force"
                    .into()
            } else if rhs.singular {
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
