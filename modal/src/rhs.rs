//! The chain as a first-order system y' = f(t, y), y = (q_free, q̇_free, cumulative works):
//! Lagrange's equations M(q) q̈ = f(q, q̇, t) of [`crate::model::Chain`] with the prescribed
//! joint motion imposed, the tip contact's constraint forces (see [`crate::contact`]) when the
//! contact is in its constrained phase, and the powers whose integrals the energy ledger books.
//! It implements [`OdeRhs`] (right-hand side, structured Newton linear algebra) and knows
//! nothing of stepping, events or output.

use crate::contact::ContactState;
use crate::integrate::{OdeRhs, Stretch};
use crate::linalg::{dot, solve2};
use crate::model::Chain;
use crate::newton::ChainNewton;

/// Which cumulative power integrals the state carries (only those the scene needs).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WorkSlots {
    pub(crate) applied: Option<usize>,
    pub(crate) prescribed: Option<usize>,
    pub(crate) joint_damper: Option<usize>,
    pub(crate) kelvin_voigt: Option<usize>,
    /// ∫ μ|λ||v_t| dt of a friction contact.
    pub(crate) friction: Option<usize>,
    count: usize,
}

/// y' = f(t, y) of the chain.
pub struct ChainRhs {
    pub chain: Chain,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub(crate) slots: WorkSlots,
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
    /// Work arrays of the power rows: ∂θ̇/∂q̇ terms of a joint, ∂(Kelvin–Voigt power)/∂q̇.
    rate_grad: Vec<(usize, f64)>,
    kv_grad: Vec<f64>,
    /// Factored Newton linear algebra ([`OdeRhs::newton_linearize`]).
    lin: ChainNewton,
    /// The state of [`OdeRhs::second_order_linearization`]: y with its elastic part zeroed.
    y_rigid: Vec<f64>,
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
            rate_grad: vec![(0, 0.0); n + 1],
            kv_grad: vec![0.0; n],
            lin: ChainNewton::new(nf, slots.count),
            y_rigid: vec![0.0; 2 * nf + slots.count],
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

    pub(crate) fn nf(&self) -> usize {
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
    pub(crate) fn load(&mut self, t: f64, y: &[f64]) {
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
                    (y[k], y[nf + k]) = self.chain.initial_joint_coordinate(i);
                }
            }
        }
        y
    }

    /// Evaluates the model at (t, y): M, forces, accelerations, prescribed torques.
    /// [`Self::solve`] outside the integrator, counted in the cost.
    pub(crate) fn solve_counted(&mut self, t: f64, y: &[f64]) -> bool {
        self.event_solves += 1;
        let ok = self.solve(t, y);
        self.painleve |= !ok && self.contact.as_ref().is_some_and(|c| c.painleve);
        ok
    }

    pub(crate) fn solve(&mut self, t: f64, y: &[f64]) -> bool {
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
                    let [ln, lt] = solve2(&[c.gmg, gmt, gmt, tmt], [rhs_n, rhs_t]);
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
        let t_law = self.chain.stretch.input_time(t);
        let p = &mut self.lin.p;
        p.iter_mut().for_each(|v| *v = 0.0);
        let base = 2 * nf;
        for (i, j) in self.chain.joints.iter().enumerate() {
            if j.prescribed.is_some() {
                continue;
            }
            // θ̇ = Σ g_k q̇_k (the coordinate itself unless behind an elbow).
            let rate = self.chain.joint_rate(i, &self.qd);
            let m = self.chain.joint_rate_gradient(i, &mut self.rate_grad);
            for &(c, g) in &self.rate_grad[..m] {
                let k = self.free_of[c];
                if let (Some(row), Some(law)) = (s.applied, &j.torque) {
                    p[(row - base) * nf + k] += law.torque(t_law) * g;
                }
                if let Some(row) = s.joint_damper {
                    p[(row - base) * nf + k] += 2.0 * j.damping * rate * g;
                }
            }
        }
        if let Some(row) = s.kelvin_voigt {
            let grad = &mut self.kv_grad;
            grad.iter_mut().for_each(|v| *v = 0.0);
            for i in 0..self.chain.links.len() {
                self.chain.kelvin_voigt_power_gradient(i, &self.qd, grad);
            }
            for (k, &g) in self.chain.free.iter().enumerate() {
                p[(row - base) * nf + k] += grad[g];
            }
        }
    }

    /// Total joint torque of joint i at the last solve (applied law + spring + damper for free
    /// joints, the spring at the reported angle — with an elbow section's lag; the required
    /// actuator torque for prescribed ones).
    pub(crate) fn joint_torque(&self, t: f64, i: usize) -> f64 {
        let j = &self.chain.joints[i];
        if j.prescribed.is_some() {
            self.chain.tau_prescribed[i]
        } else {
            j.torque
                .as_ref()
                .map_or(0.0, |l| l.torque(self.chain.stretch.input_time(t)))
                - j.stiffness
                    * (self.chain.joint_angle_with_lag(i, &self.q, &self.qd) - j.set_point)
                - j.damping * self.chain.joint_rate(i, &self.qd)
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
        let [a, b] = solve2(&[c.gmg, gmt, gmt, tmt], [gx, tx]);
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

    fn set_stretch(&mut self, stretch: Stretch) {
        self.chain.stretch = stretch;
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
        self.chain.elastic_tangent(&mut self.kt, &mut self.dt);
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
        self.chain.elastic_tangent(&mut self.kt, &mut self.dt);
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

    /// M and the elastic tangent K_t (the joint springs, the bending and shear stiffness) over
    /// the free coordinates, of the undeformed chain — elastic coordinates and rates zero — at
    /// the joint angles of y; everything else (the configuration's foreshortening terms,
    /// centrifugal, gyroscopic and gravity forces, ∂M/∂q) stays in the remainder. A chain in
    /// its constrained contact phase has no such form (its constraint force is not an
    /// oscillator).
    fn second_order_linearization(
        &mut self,
        t: f64,
        y: &[f64],
        m: &mut Vec<f64>,
        k: &mut Vec<f64>,
    ) -> Option<usize> {
        if self.contact.as_ref().is_some_and(|c| c.constrained) {
            return None;
        }
        // The undeformed arm at the current joint angles: M(q) depends on the elastic coordinates
        // only through foreshortening, and sampled at the state it would carry the phase of
        // every ringing mode into the linear part (docs/backends.md).
        let nf = self.nf();
        self.y_rigid.copy_from_slice(y);
        for (k, &g) in self.chain.free.iter().enumerate() {
            if !self.chain.links.iter().any(|l| l.theta == g) {
                self.y_rigid[k] = 0.0;
                self.y_rigid[nf + k] = 0.0;
            }
        }
        let y_rigid = std::mem::take(&mut self.y_rigid);
        let solved = self.solve(t, &y_rigid);
        self.y_rigid = y_rigid;
        if !solved {
            return None;
        }
        let n = self.chain.n;
        let nf = self.nf();
        self.chain.elastic_tangent(&mut self.kt, &mut self.dt);
        let mass = self.chain.mass_matrix();
        m.resize(nf * nf, 0.0);
        k.resize(nf * nf, 0.0);
        for (r, &gr) in self.chain.free.iter().enumerate() {
            for (c, &gc) in self.chain.free.iter().enumerate() {
                m[r * nf + c] = mass[gr * n + gc];
                k[r * nf + c] = self.kt[gr * n + gc];
            }
        }
        Some(nf)
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
            let t_law = self.chain.stretch.input_time(t);
            let mut p = 0.0;
            for (i, j) in self.chain.joints.iter().enumerate() {
                if let (None, Some(law)) = (&j.prescribed, &j.torque) {
                    p += law.torque(t_law) * self.chain.joint_rate(i, &self.qd);
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
                    let w = self.chain.joint_rate(i, &self.qd);
                    p += j.damping * w * w;
                }
            }
            dydt[k] = p;
        }
        if let Some(k) = s.kelvin_voigt {
            let mut p = 0.0;
            for i in 0..self.chain.links.len() {
                // ẋᵀD ẋ over the bending block x = [b, c] (or (b, φ) behind an elbow).
                self.chain.add_kelvin_voigt_power(i, &self.qd, &mut p);
            }
            dydt[k] = p;
        }
        if let Some(k) = s.friction {
            dydt[k] = self.contact.as_ref().map_or(0.0, |c| c.friction_power);
        }
    }
}
