//! Implicit midpoint rule on the reduced first-order system (q, ν), q̇ = S(q) ν,
//! M̄(q) ν̇ = Q(t, ν) − b(q, ν):
//!
//! ```text
//! q₁ = q₀ + h S(q̄) ν̄,   M̄(q̄)(ν₁ − ν₀) = h (Q(t̄, ν̄) − b(q̄, ν̄)),   q̄, ν̄ the step midpoints
//! ```
//!
//! (ψ̄ follows from ν̄ alone, so q̄ is explicit in ν̄). Unknown Δν = ν₁ − ν₀; the residual
//! h(M̄ ν̇ + b − Q) at ν̇ = Δν/h is one inverse-dynamics pass. Modified Newton with the matrix
//! M̄(q̄⁽⁰⁾) + ¼h² K + ½h D (K the elastic stiffness on the elastic speeds, D the viscous
//! friction), formed and Cholesky-factorized once per step: the neglected terms (the
//! configuration dependence of M̄, gyroscopic and gravity couplings) are O(h |ω|) relative, so
//! the iteration contracts by that factor. The constraints A(q) S(q) ≡ 0 hold for every q, so
//! A q̇ = A S ν stays at round-off: the nonholonomic constraints cannot drift in this form.
//!
//! Works are booked with the scheme's own midpoint quadrature, h τ(t̄)·ν̄ and h b ν̄².

use data::scene::TorqueSchedule;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::{MatMut, MatRef, Par};

use super::model::{Model, Workspace};
use crate::error::FemError;
use crate::method::FixedStepCounters;

/// Newton iterations per step before the run is stopped.
pub const MAX_NEWTON: usize = 30;
/// Newton tolerance on the speed update, relative to max(1, |ν̄|∞).
pub const NEWTON_TOL: f64 = 1e-12;
/// Largest relative update accepted when the iteration stalls at round-off.
pub const STALL_TOL: f64 = 1e-9;

/// The torque inputs: side torques (τ_R, τ_L) and joint torques τ₁…τ₄.
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs {
    pub drive: Option<TorqueSchedule>,
    pub arm: TorqueSchedule,
}

impl Inputs {
    /// τ in ν order (zero on the elastic speeds).
    pub fn at(&self, model: &Model, t: f64, tau: &mut [f64]) {
        tau.fill(0.0);
        if let Some(d) = &self.drive {
            tau[0] = d.torque(0, t);
            tau[1] = d.torque(1, t);
        }
        let a = model.layout.nu_arm;
        for i in 0..4 {
            tau[a + i] = self.arm.torque(i, t);
        }
    }

    /// Schedule discontinuities inside (0, t_end), sorted.
    pub fn breakpoints(&self, t_end: f64) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .drive
            .iter()
            .chain(std::iter::once(&self.arm))
            .flat_map(|s| s.breakpoints(t_end))
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}

/// Integrated works: wheel input, joint input, wheel friction, joint friction.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Works {
    pub wheel_torque: f64,
    pub joint_torque: f64,
    pub wheel_friction: f64,
    pub joint_friction: f64,
}

/// State, inputs and preallocated scratch of a run.
#[derive(Debug, Clone)]
pub struct Stepper {
    pub model: Model,
    pub inputs: Inputs,
    pub t: f64,
    pub q: Vec<f64>,
    pub nu: Vec<f64>,
    pub works: Works,
    pub counters: FixedStepCounters,
    ws: Workspace,
    mass: Vec<f64>,
    newton: Vec<f64>,
    llt: DenseLlt,
    force: Vec<f64>,
    applied: Vec<f64>,
    tau: Vec<f64>,
    dnu: Vec<f64>,
    delta: Vec<f64>,
    nudot: Vec<f64>,
    qbar: Vec<f64>,
    nubar: Vec<f64>,
    qd: Vec<f64>,
    sdn: Vec<f64>,
}

impl Stepper {
    pub fn new(model: Model, inputs: Inputs, q: Vec<f64>, nu: Vec<f64>) -> Self {
        let (n, m) = (model.layout.n, model.layout.m);
        Stepper {
            model,
            inputs,
            t: 0.0,
            q,
            nu,
            works: Works::default(),
            counters: FixedStepCounters::default(),
            ws: Workspace::new(n),
            mass: vec![0.0; m * m],
            newton: vec![0.0; m * m],
            llt: DenseLlt::new(m),
            force: vec![0.0; m],
            applied: vec![0.0; m],
            tau: vec![0.0; m],
            dnu: vec![0.0; m],
            delta: vec![0.0; m],
            nudot: vec![0.0; m],
            qbar: vec![0.0; n],
            nubar: vec![0.0; m],
            qd: vec![0.0; n],
            sdn: vec![0.0; n],
        }
    }

    /// The applied torques at time t (ν order).
    pub fn torques(&mut self, t: f64) -> &[f64] {
        self.inputs.at(&self.model, t, &mut self.tau);
        &self.tau
    }

    /// Midpoints q̄, ν̄ of the current Δν.
    fn midpoints(&mut self, h: f64) {
        let l = self.model.layout;
        for i in 0..l.m {
            self.nubar[i] = self.nu[i] + 0.5 * self.dnu[i];
        }
        // S depends on ψ only and ψ̇ on ν only: ψ̄ first, then the rest with S(q̄).
        self.qbar.copy_from_slice(&self.q);
        if let Some(p) = &self.model.platform {
            let psid = 0.5 * p.wheel_radius / p.half_track * (self.nubar[0] - self.nubar[1]);
            self.qbar[2] = self.q[2] + 0.5 * h * psid;
        }
        self.model
            .velocities(&self.qbar, &self.nubar, &mut self.qd, &mut self.sdn);
        for i in 0..l.n {
            self.qbar[i] = self.q[i] + 0.5 * h * self.qd[i];
        }
    }

    /// One step of length h.
    pub fn step(&mut self, h: f64) -> Result<(), FemError> {
        let l = self.model.layout;
        let m = l.m;
        let t_mid = self.t + 0.5 * h;
        self.inputs.at(&self.model, t_mid, &mut self.tau);
        // Predictor: the previous step's Δν (zero on the first step).
        let mut converged = false;
        let (mut last, mut last_scale) = (f64::INFINITY, 1.0);
        for it in 0..MAX_NEWTON {
            self.midpoints(h);
            for i in 0..m {
                self.nudot[i] = self.dnu[i] / h;
            }
            let want_mass = it == 0;
            self.model.evaluate(
                &self.qbar,
                &self.nubar,
                &self.nudot,
                &mut self.ws,
                want_mass.then_some(&mut self.mass[..]),
                &mut self.force,
            );
            self.counters.residuals += 1;
            self.model
                .applied(&self.nubar, &self.tau, &mut self.applied);
            for i in 0..m {
                self.delta[i] = h * (self.force[i] - self.applied[i]);
            }
            if it == 0 {
                self.form_newton_matrix(h);
                self.llt
                    .factor(&self.newton)
                    .map_err(|pivot| FemError::Runaway {
                        t: self.t,
                        what: "Newton matrix not positive definite".into(),
                        location: Some(format!("speed {pivot}")),
                        why: "the reduced mass matrix lost definiteness".into(),
                        remedy: "check the scene's inertias".into(),
                    })?;
                self.counters.factorizations += 1;
            }
            self.llt.solve(&mut self.delta);
            self.counters.newton += 1;
            let mut size = 0.0f64;
            let mut scale = 1.0f64;
            for i in 0..m {
                self.dnu[i] -= self.delta[i];
                size = size.max(self.delta[i].abs());
                scale = scale.max(self.nubar[i].abs());
            }
            if !size.is_finite() {
                break;
            }
            // Converged at the tolerance, or stalled at the round-off floor of the residual
            // (the elastic forces K e of a fine mesh carry |K||e|·ε of noise): the update no
            // longer contracts and is already below the stagnation bound.
            let stalled = it > 0 && size > 0.5 * last && size <= STALL_TOL * scale;
            if size <= NEWTON_TOL * scale || stalled {
                converged = true;
                break;
            }
            last = size;
            last_scale = scale;
        }
        if !converged {
            return Err(FemError::Runaway {
                t: self.t,
                what: "Newton iteration of the midpoint step did not converge".into(),
                location: None,
                why: format!(
                    "no convergence in {MAX_NEWTON} modified-Newton iterations (last update \
                     {last:.2e}, speed scale {last_scale:.2e})"
                ),
                remedy: "reduce --dt".into(),
            });
        }
        self.midpoints(h);
        for i in 0..l.n {
            self.q[i] = 2.0 * self.qbar[i] - self.q[i];
        }
        for i in 0..m {
            self.nu[i] += self.dnu[i];
        }
        self.book_works(h);
        self.t += h;
        self.counters.steps += 1;
        Ok(())
    }

    fn book_works(&mut self, h: f64) {
        let l = self.model.layout;
        if let Some(p) = &self.model.platform {
            for s in 0..2 {
                let r = self.nubar[s];
                self.works.wheel_torque += h * self.tau[s] * r;
                self.works.wheel_friction += h * p.side_friction * r * r;
            }
        }
        for i in 0..4 {
            let j = l.nu_arm + i;
            let r = self.nubar[j];
            self.works.joint_torque += h * self.tau[j] * r;
            self.works.joint_friction += h * self.model.joint_friction[i] * r * r;
        }
    }

    /// M̄ + ¼h² K + ½h D into `newton`.
    fn form_newton_matrix(&mut self, h: f64) {
        let l = self.model.layout;
        let m = l.m;
        self.newton.copy_from_slice(&self.mass);
        if let Some(p) = &self.model.platform {
            for s in 0..2 {
                self.newton[s * m + s] += 0.5 * h * p.side_friction;
            }
        }
        for i in 0..4 {
            let j = l.nu_arm + i;
            self.newton[j * m + j] += 0.5 * h * self.model.joint_friction[i];
        }
        if let Some(fl) = &self.model.flex {
            let c = 0.25 * h * h;
            for i in 0..fl.ne {
                for j in 0..fl.ne {
                    self.newton[(l.nu_el + i) * m + l.nu_el + j] += c * fl.stiffness[i * fl.ne + j];
                }
            }
        }
    }

    /// M̄(q) at the current state (row-major m × m).
    pub fn mass_matrix(&mut self) -> &[f64] {
        let m = self.model.layout.m;
        self.nudot.fill(0.0);
        self.model.evaluate(
            &self.q,
            &self.nu,
            &self.nudot,
            &mut self.ws,
            Some(&mut self.mass[..]),
            &mut self.force,
        );
        &self.mass[..m * m]
    }

    /// q̇ = S ν at the current state.
    pub fn coordinate_rates(&mut self) -> &[f64] {
        self.model
            .velocities(&self.q, &self.nu, &mut self.qd, &mut self.sdn);
        &self.qd
    }
}

/// L Lᵀ factorization of a dense SPD matrix through faer, with its scratch allocated once, so
/// refactoring and solving in the step loop allocate nothing.
pub struct DenseLlt {
    n: usize,
    factor: Vec<f64>,
    scratch: StackReq,
    mem: MemBuffer,
}

impl Clone for DenseLlt {
    fn clone(&self) -> Self {
        DenseLlt {
            n: self.n,
            factor: self.factor.clone(),
            scratch: self.scratch,
            mem: MemBuffer::new(self.scratch),
        }
    }
}

impl std::fmt::Debug for DenseLlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLlt").field("n", &self.n).finish()
    }
}

impl DenseLlt {
    pub fn new(n: usize) -> Self {
        let scratch =
            llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default())
                .or(llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq));
        DenseLlt {
            n,
            factor: vec![0.0; n * n],
            scratch,
            mem: MemBuffer::new(scratch),
        }
    }

    /// Factors the row-major matrix `a` (its lower triangle is read); Err(pivot) at the first
    /// pivot that is not positive.
    pub fn factor(&mut self, a: &[f64]) -> Result<(), usize> {
        let n = self.n;
        self.factor.copy_from_slice(&a[..n * n]);
        llt::factor::cholesky_in_place(
            MatMut::from_row_major_slice_mut(&mut self.factor, n, n),
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .map(|_| ())
        .map_err(|e| match e {
            llt::factor::LltError::NonPositivePivot { index } => index,
        })
    }

    /// Solves L Lᵀ x = b in place with the last factor.
    pub fn solve(&mut self, b: &mut [f64]) {
        let n = self.n;
        llt::solve::solve_in_place(
            MatRef::from_row_major_slice(&self.factor, n, n),
            MatMut::from_column_major_slice_mut(&mut b[..n], n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}
