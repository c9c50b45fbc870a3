//! Lagrange's equations of the payload link as y′ = f(t, y), with the analytic Jacobian.
//!
//! From T, V, R of [`super::model`] (p_θ = ∂T/∂θ̇, J(q) = J₀ + 2hᵀq + qᵀNq):
//!
//! * field equations: M q̈ + θ̈ (b + Gᵀq) = −θ̇ (Gᵀ − G) q̇ + θ̇² (h + N q) − C q̇ − K q − f_g;
//! * base (free θ): J(q) θ̈ + (b + Gᵀq)ᵀ q̈ = T_mot − b_m θ̇ − K_θ(θ − θ₀) − q̇ᵀG q̇
//!   − 2θ̇ (hᵀq̇ + qᵀN q̇);
//! * prescribed θ(t): the field equations alone with θ, θ̇, θ̈ given (constant mass matrix M,
//!   factored once); the actuator torque is d p_θ/dt + b_m θ̇ + K_θ(θ − θ₀).
//!
//! The state is (positions, velocities, works): the works are the integrals of the input power
//! and of each dissipation rate (motor friction, each Kelvin–Voigt field), so the ledger closes
//! to the integrator's tolerance: d(T + V)/dt = T_mot θ̇ − b_m θ̇² − Σ q̇ᵀC_f q̇.
//!
//! The Jacobian of the accelerations is exact: M_f⁻¹(∂F/∂y − (∂M_f/∂y) ÿ). The work rows are left
//! zero: nothing depends on the works, so the simplified Newton iteration settles them one
//! iteration after the rest.

use crate::integrate::{OdeRhs, Stretch};
use crate::linalg::{cholesky_factor, cholesky_substitute, dot};

use super::model::LinkModel;

/// The link as a first-order system.
#[derive(Debug, Clone)]
pub struct LinkRhs {
    pub model: LinkModel,
    /// Second-order coordinates: θ (free base) then q.
    pub nd: usize,
    /// Number of work integrals after the velocities.
    pub nw: usize,
    /// Index (within the works) of the motor-friction dissipation, if any.
    pub friction_work: Option<usize>,
    /// Index of the first Kelvin–Voigt work (one per damped field, in `model.damped` order).
    pub kv_work: usize,
    /// Factored M (prescribed base) or scratch for M_f (free base).
    factor: Vec<f64>,
    acc: Vec<f64>,
    force: Vec<f64>,
    gqd: Vec<f64>,
    gtq: Vec<f64>,
    gtqd: Vec<f64>,
    nq: Vec<f64>,
    nqd: Vec<f64>,
    cols: Vec<f64>,
    scratch: Vec<f64>,
    pub evaluations: usize,
    /// The stretch between the torque law's discontinuities being integrated: the law is
    /// read at [`Stretch::input_time`].
    stretch: Stretch,
}

/// The quantities of one evaluation the outputs need.
#[derive(Debug, Clone, Copy, Default)]
pub struct BaseState {
    pub theta: f64,
    pub rate: f64,
    pub accel: f64,
}

impl LinkRhs {
    pub fn new(model: LinkModel) -> Result<Self, String> {
        let n = model.n;
        let nd = n + usize::from(model.base.free);
        let friction_work = (model.base.friction > 0.0).then_some(1);
        let kv_work = 1 + usize::from(friction_work.is_some());
        let nw = kv_work + model.damped.len();
        let mut factor = vec![0.0; nd * nd];
        if !model.base.free {
            factor.copy_from_slice(&model.mass);
            cholesky_factor(&mut factor, n)
                .map_err(|_| "the field mass matrix is not positive definite".to_string())?;
        }
        let dim = 2 * nd + nw;
        Ok(LinkRhs {
            model,
            nd,
            nw,
            friction_work,
            kv_work,
            factor,
            acc: vec![0.0; nd],
            force: vec![0.0; nd],
            gqd: vec![0.0; n],
            gtq: vec![0.0; n],
            gtqd: vec![0.0; n],
            nq: vec![0.0; n],
            nqd: vec![0.0; n],
            cols: vec![0.0; nd * 2 * nd],
            scratch: vec![0.0; dim],
            evaluations: 0,
            stretch: Stretch::OPEN,
        })
    }

    pub fn dim(&self) -> usize {
        2 * self.nd + self.nw
    }

    /// Offset of q within the positions (1 with a free base).
    pub fn q0(&self) -> usize {
        usize::from(self.model.base.free)
    }

    /// The state at t = 0 with the fields at `q` and at rest relative to the base.
    pub fn initial_state(&self, q: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        let o = self.q0();
        y[o..o + self.model.n].copy_from_slice(q);
        if self.model.base.free {
            y[0] = self.model.base.initial_angle;
            y[self.nd] = self.model.base.initial_rate;
        }
        y
    }

    /// θ, θ̇, θ̈ at (t, y) after an evaluation there.
    pub fn base_state(&self, t: f64, y: &[f64]) -> BaseState {
        if self.model.base.free {
            BaseState {
                theta: y[0],
                rate: y[self.nd],
                accel: self.acc[0],
            }
        } else {
            let (theta, rate, accel) = self.model.base.prescribed_state(t);
            BaseState { theta, rate, accel }
        }
    }

    /// Field accelerations q̈ of the last evaluation.
    pub fn field_accel(&self) -> &[f64] {
        &self.acc[self.q0()..]
    }

    /// The torque the base receives from its actuator: T_mot (free base) or what the prescribed
    /// motion needs, d p_θ/dt + b_m θ̇ − (spring torque), after an evaluation at (t, y).
    pub fn actuator_torque(&self, t: f64, y: &[f64]) -> f64 {
        let base = &self.model.base;
        if base.free {
            return base.motor_torque(self.stretch.input_time(t));
        }
        let m = &self.model;
        let n = m.n;
        let s = self.base_state(t, y);
        let q = &y[..n];
        let qd = &y[self.nd..self.nd + n];
        let qdd = &self.acc[..n];
        let mut dp = 0.0;
        let mut jq = m.j0;
        for i in 0..n {
            let row = i * n..(i + 1) * n;
            let (gyro, centrifugal) = (&m.gyro[row.clone()], &m.centrifugal[row]);
            let (gqdd, gqd) = (dot(gyro, qdd), dot(gyro, qd));
            let (nqd, nq) = (dot(centrifugal, qd), dot(centrifugal, q));
            dp += m.b[i] * qdd[i]
                + q[i] * gqdd
                + qd[i] * gqd
                + 2.0 * s.rate * (m.h[i] * qd[i] + q[i] * nqd);
            jq += 2.0 * m.h[i] * q[i] + q[i] * nq;
        }
        dp += s.accel * jq;
        dp + base.friction * s.rate - base.spring(s.theta).0
    }

    /// Evaluates the accelerations into `self.acc`; false if M_f is not positive definite.
    fn accelerations(&mut self, t: f64, y: &[f64]) -> bool {
        let m = &self.model;
        let n = m.n;
        let free = m.base.free;
        let o = usize::from(free);
        let nd = self.nd;
        let q = &y[o..o + n];
        let qd = &y[nd + o..nd + o + n];
        let (theta, rate, accel) = if free {
            (y[0], y[nd], 0.0)
        } else {
            m.base.prescribed_state(t)
        };
        for i in 0..n {
            let (mut a, mut bq, mut c, mut d, mut e) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for j in 0..n {
                a += m.gyro[i * n + j] * qd[j];
                bq += m.gyro[j * n + i] * q[j];
                c += m.gyro[j * n + i] * qd[j];
                d += m.centrifugal[i * n + j] * q[j];
                e += m.centrifugal[i * n + j] * qd[j];
            }
            self.gqd[i] = a;
            self.gtq[i] = bq;
            self.gtqd[i] = c;
            self.nq[i] = d;
            self.nqd[i] = e;
        }
        for i in 0..n {
            let mut f = -rate * (self.gtqd[i] - self.gqd[i]) + rate * rate * (m.h[i] + self.nq[i]);
            let mut kq = 0.0;
            for j in 0..n {
                kq += m.stiffness[i * n + j] * q[j];
            }
            f -= kq;
            if let Some(cm) = &m.damping {
                let mut cq = 0.0;
                for j in 0..n {
                    cq += cm[i * n + j] * qd[j];
                }
                f -= cq;
            }
            if let Some(fg) = &m.gravity {
                f -= fg[i];
            }
            if !free {
                f -= accel * (m.b[i] + self.gtq[i]);
            }
            self.force[o + i] = f;
        }
        if free {
            let mut f = m.base.motor_torque(self.stretch.input_time(t)) - m.base.friction * rate
                + m.base.spring(theta).0;
            let mut jq = m.j0;
            for i in 0..n {
                f -= qd[i] * self.gqd[i] + 2.0 * rate * (m.h[i] * qd[i] + q[i] * self.nqd[i]);
                jq += 2.0 * m.h[i] * q[i] + q[i] * self.nq[i];
            }
            self.force[0] = f;
            let fm = &mut self.factor;
            fm[0] = jq;
            for i in 0..n {
                let c = m.b[i] + self.gtq[i];
                fm[1 + i] = c;
                fm[(1 + i) * nd] = c;
                fm[(1 + i) * nd + 1..(1 + i) * nd + 1 + n]
                    .copy_from_slice(&m.mass[i * n..(i + 1) * n]);
            }
            if cholesky_factor(fm, nd).is_err() {
                return false;
            }
        }
        self.acc.copy_from_slice(&self.force);
        cholesky_substitute(&self.factor, nd, &mut self.acc);
        true
    }
}

impl OdeRhs for LinkRhs {
    fn dim(&self) -> usize {
        2 * self.nd + self.nw
    }

    fn set_stretch(&mut self, stretch: Stretch) {
        self.stretch = stretch;
    }

    /// The oscillators of the undeformed link: M = [[J₀, bᵀ], [b, M_qq]] (free base; M_qq
    /// alone with a prescribed one) and K = diag(K_θ, K_qq). Both are constant, so the
    /// exponential method diagonalizes them once; the centrifugal softening, the gyroscopic and
    /// nonlinear inertia terms, gravity and the motor stay in its remainder.
    fn second_order_linearization(
        &mut self,
        _t: f64,
        _y: &[f64],
        m: &mut Vec<f64>,
        k: &mut Vec<f64>,
    ) -> Option<usize> {
        let model = &self.model;
        let (n, nd) = (model.n, self.nd);
        let o = nd - n;
        m.clear();
        m.resize(nd * nd, 0.0);
        k.clear();
        k.resize(nd * nd, 0.0);
        for i in 0..n {
            for j in 0..n {
                m[(o + i) * nd + o + j] = model.mass[i * n + j];
                k[(o + i) * nd + o + j] = model.stiffness[i * n + j];
            }
        }
        if model.base.free {
            m[0] = model.j0;
            for i in 0..n {
                m[1 + i] = model.b[i];
                m[(1 + i) * nd] = model.b[i];
            }
            k[0] = model.base.spring.map_or(0.0, |(ks, _)| ks);
        }
        Some(nd)
    }

    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.evaluations += 1;
        let nd = self.nd;
        if !self.accelerations(t, y) {
            dydt.iter_mut().for_each(|v| *v = f64::NAN);
            return;
        }
        dydt[..nd].copy_from_slice(&y[nd..2 * nd]);
        dydt[nd..2 * nd].copy_from_slice(&self.acc);
        let rate = self.base_state(t, y).rate;
        let input = self.actuator_torque(t, y) * rate;
        let w = 2 * nd;
        dydt[w] = input;
        if let Some(k) = self.friction_work {
            dydt[w + k] = self.model.base.friction * rate * rate;
        }
        let o = self.q0();
        let qd = &y[nd + o..nd + o + self.model.n];
        for (k, d) in self.model.damped.iter().enumerate() {
            dydt[w + self.kv_work + k] = self.model.dissipation_rate(d, qd);
        }
    }

    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> bool {
        let dim = self.dim();
        let mut scratch = std::mem::take(&mut self.scratch);
        self.eval(t, y, &mut scratch);
        self.scratch = scratch;
        if !self.acc.iter().all(|a| a.is_finite()) {
            return false;
        }
        jac.iter_mut().for_each(|v| *v = 0.0);
        let nd = self.nd;
        let m = &self.model;
        let n = m.n;
        let free = m.base.free;
        let o = usize::from(free);
        let q = &y[o..o + n];
        let qd = &y[nd + o..nd + o + n];
        let (theta_acc, rate, accel) = if free {
            (self.acc[0], y[nd], self.acc[0])
        } else {
            let s = m.base.prescribed_state(t);
            (0.0, s.1, s.2)
        };
        let qdd = &self.acc[o..];
        // Columns of ∂F/∂y − (∂M_f/∂y) ÿ over the 2 nd position/velocity coordinates, stored
        // as nd-vectors in `cols`.
        let cols = &mut self.cols;
        cols.iter_mut().for_each(|v| *v = 0.0);
        let col = |c: usize| c * nd;
        if free {
            // θ.
            cols[col(0)] = -m.base.spring.map_or(0.0, |(k, _)| k);
            // θ̇.
            let c = col(nd);
            let mut s = 0.0;
            for i in 0..n {
                s += m.h[i] * qd[i] + q[i] * self.nqd[i];
            }
            cols[c] = -m.base.friction - 2.0 * s;
            for i in 0..n {
                cols[c + 1 + i] =
                    -(self.gtqd[i] - self.gqd[i]) + 2.0 * rate * (m.h[i] + self.nq[i]);
            }
        }
        for j in 0..n {
            // q_j.
            let c = col(o + j);
            if free {
                let mut gq = 0.0;
                for k in 0..n {
                    gq += m.gyro[j * n + k] * qdd[k];
                }
                cols[c] =
                    -2.0 * rate * self.nqd[j] - (2.0 * (m.h[j] + self.nq[j]) * theta_acc + gq);
            }
            for i in 0..n {
                cols[c + o + i] = rate * rate * m.centrifugal[i * n + j]
                    - m.stiffness[i * n + j]
                    - accel * m.gyro[j * n + i];
            }
            // q̇_j.
            let c = col(nd + o + j);
            if free {
                let mut gtqd = 0.0;
                for k in 0..n {
                    gtqd += m.gyro[k * n + j] * qd[k];
                }
                cols[c] = -(self.gqd[j] + gtqd) - 2.0 * rate * (m.h[j] + self.nq[j]);
            }
            for i in 0..n {
                let mut v = -rate * (m.gyro[j * n + i] - m.gyro[i * n + j]);
                if let Some(cm) = &m.damping {
                    v -= cm[i * n + j];
                }
                cols[c + o + i] = v;
            }
        }
        for c in 0..2 * nd {
            let v = &mut cols[col(c)..col(c) + nd];
            cholesky_substitute(&self.factor, nd, v);
            for r in 0..nd {
                jac[c * dim + nd + r] = v[r];
            }
        }
        for r in 0..nd {
            jac[(nd + r) * dim + r] = 1.0;
        }
        true
    }
}
