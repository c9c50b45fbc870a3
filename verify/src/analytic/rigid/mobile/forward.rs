//! Forward dynamics two ways, inverse dynamics, and the run's observables and energy ledger.
//!
//! * Reduced (minimal) form: state (q, ν), q̇ = S ν, Sᵀ M S ν̇ = Sᵀ (Q − M Ṡ ν − h). The
//!   multipliers never appear; this run gives the reported histories.
//! * Lagrange multipliers (index-1 DAE): state (q, q̇), `[M −Aᵀ; A 0] (q̈, λ) = (Q − h, −Ȧ q̇)`;
//!   after every output interval the drift |A q̇| is recorded and q̇ is projected back
//!   (M-orthogonally) onto A q̇ = 0. No Baumgarte terms.
//! * Inverse dynamics at every output sample: τ = Sᵀ (M q̈ + h + D q̇) with q̈ = S ν̇ + Ṡ ν from
//!   the reduced run (M q̈ + h by Newton–Euler), compared with the applied torques.
//!
//! Both runs use Dormand–Prince 5(4) at rtol = atol = 1e-12 (settings may override), stepping
//! exactly onto output times and torque breakpoints (the schedules are piecewise constant, so
//! every step sees a smooth right-hand side). Each state carries the integrals of input power
//! (wheel, joint torques) and friction power (wheel, joint), so the ledger
//! E(t) − E(0) − W_in + W_friction = 0 is checkable.

use data::scene::{MobileManipulator, TorqueSchedule};

use super::model::{MAX_Q, Model, N_CONSTRAINTS, solve};
use crate::analytic::error::{AnalyticError, Result};
use crate::analytic::numerics::ode::{Dopri5, OdeStats};

/// Largest KKT system: n + 3.
const KKT: usize = MAX_Q + N_CONSTRAINTS;
/// Number of energy integrals carried in the state.
const N_WORK: usize = 4;

/// Integration settings of the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
        }
    }
}

/// The model plus its inputs and initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    pub model: Model,
    pub drive: Option<TorqueSchedule>,
    pub arm_torques: Option<TorqueSchedule>,
    pub q0: [f64; MAX_Q],
    pub nu0: [f64; MAX_Q],
}

/// One output sample of a reference run.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    pub t: f64,
    /// Coordinates and rates of the reduced run.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// q̈ of the reduced run at this sample.
    pub qdd: Vec<f64>,
    /// Applied inputs (τ_R, τ_L, τ₁…τ₄ as present).
    pub tau: Vec<f64>,
    /// Inverse-dynamics torques from (q, q̇, q̈).
    pub tau_inverse: Vec<f64>,
    pub kinetic: f64,
    pub potential: f64,
    /// Input work of wheel and joint torques, friction work of wheels and joints.
    pub work: [f64; N_WORK],
    /// max |A q̇| of the multiplier run before its projection.
    pub drift: f64,
    /// max_i |q_i(DAE) − q_i(reduced)| and max_i |ν_i(DAE) − ν_i(reduced)|.
    pub position_gap: f64,
    pub rate_gap: f64,
    pub end_effector: [f64; 3],
}

/// A whole run: samples and integrator work of both formulations.
#[derive(Debug, Clone, PartialEq)]
pub struct History {
    pub samples: Vec<Sample>,
    pub reduced_stats: OdeStats,
    pub dae_stats: OdeStats,
}

impl Reference {
    pub fn from_scene(m: &MobileManipulator) -> Result<Self> {
        let model = Model::from_scene(m)?;
        let l = model.layout;
        let mut q0 = [0.0; MAX_Q];
        let mut nu0 = [0.0; MAX_Q];
        let mut k = 0;
        if let Some(pl) = l.platform {
            q0[pl] = m.initial.x;
            q0[pl + 1] = m.initial.y;
            q0[pl + 2] = m.initial.heading;
            nu0[..2].copy_from_slice(&m.initial.wheel_rates);
            k = 2;
        }
        if let Some(a0) = l.arm {
            q0[a0..a0 + 4].copy_from_slice(&m.initial.joint_angles);
            nu0[k..k + 4].copy_from_slice(&m.initial.joint_rates);
        }
        Ok(Reference {
            drive: m.platform.as_ref().map(|p| p.drive.clone()),
            arm_torques: m.arm.as_ref().map(|a| a.torques.clone()),
            model,
            q0,
            nu0,
        })
    }

    /// Inputs in ν order at time t.
    pub fn inputs(&self, t: f64, tau: &mut [f64]) {
        let mut k = 0;
        if let Some(d) = &self.drive {
            tau[0] = d.torque(0, t);
            tau[1] = d.torque(1, t);
            k = 2;
        }
        if let Some(a) = &self.arm_torques {
            for i in 0..4 {
                tau[k + i] = a.torque(i, t);
            }
        }
    }

    fn breakpoints(&self, t_end: f64) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .drive
            .iter()
            .chain(self.arm_torques.iter())
            .flat_map(|s| s.breakpoints(t_end))
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// Reduced right-hand side: y = (q, ν, W), dy = (S ν, ν̇, power). Also returns q̈ in `qdd`.
    pub fn reduced_rhs(&self, t: f64, y: &[f64], dy: &mut [f64], qdd: &mut [f64]) -> Result<()> {
        let (n, m) = (self.model.layout.n, self.model.layout.m);
        let (q, nu) = (&y[..n], &y[n..n + m]);
        let mut qd = [0.0; MAX_Q];
        let mut sdn = [0.0; MAX_Q];
        self.model.velocities(q, nu, &mut qd, &mut sdn);
        let mut tau = [0.0; MAX_Q];
        self.inputs(t, &mut tau);
        let mut force = [0.0; MAX_Q];
        let power = self.model.applied(&qd[..n], &tau, &mut force);
        // M Ṡν + h by Newton–Euler with q̈ = Ṡν.
        let mut bias = [0.0; MAX_Q];
        self.model
            .inverse_dynamics(q, &qd[..n], &sdn[..n], true, &mut bias);
        let mut mm = [[0.0; MAX_Q]; MAX_Q];
        self.model.mass_matrix(q, &mut mm);
        let mut cols = [[0.0; MAX_Q]; MAX_Q];
        for (i, c) in cols.iter_mut().enumerate().take(m) {
            self.model.null_space_column(q, i, c);
        }
        let mut red = [[0.0; MAX_Q]; MAX_Q];
        let mut rhs = [0.0; MAX_Q];
        for i in 0..m {
            for j in 0..m {
                let mut s = 0.0;
                for a in 0..n {
                    if cols[i][a] == 0.0 {
                        continue;
                    }
                    let mut row = 0.0;
                    for b in 0..n {
                        row += mm[a][b] * cols[j][b];
                    }
                    s += cols[i][a] * row;
                }
                red[i][j] = s;
            }
            rhs[i] = (0..n).map(|a| cols[i][a] * (force[a] - bias[a])).sum();
        }
        solve(&red, &mut rhs, m)?;
        dy[..n].copy_from_slice(&qd[..n]);
        dy[n..n + m].copy_from_slice(&rhs[..m]);
        dy[n + m..n + m + N_WORK].copy_from_slice(&power);
        for a in 0..n {
            qdd[a] = sdn[a] + (0..m).map(|i| cols[i][a] * rhs[i]).sum::<f64>();
        }
        Ok(())
    }

    /// KKT system of the multiplier form at (q, q̇): returns the matrix and (Q − h, −Ȧq̇).
    fn kkt(&self, t: f64, q: &[f64], qd: &[f64]) -> ([[f64; KKT]; KKT], [f64; KKT], [f64; 4]) {
        let n = self.model.layout.n;
        let mut mm = [[0.0; MAX_Q]; MAX_Q];
        self.model.mass_matrix(q, &mut mm);
        let mut tau = [0.0; MAX_Q];
        self.inputs(t, &mut tau);
        let mut force = [0.0; MAX_Q];
        let power = self.model.applied(qd, &tau, &mut force);
        let mut bias = [0.0; MAX_Q];
        let zeros = [0.0; MAX_Q];
        self.model
            .inverse_dynamics(q, qd, &zeros[..n], true, &mut bias);
        let mut k = [[0.0; KKT]; KKT];
        let mut r = [0.0; KKT];
        for i in 0..n {
            k[i][..n].copy_from_slice(&mm[i][..n]);
            r[i] = force[i] - bias[i];
        }
        if let Some((a, adot_qd)) = self.model.constraints(q, qd) {
            for c in 0..N_CONSTRAINTS {
                for j in 0..n {
                    k[n + c][j] = a[c][j];
                    k[j][n + c] = -a[c][j];
                }
                r[n + c] = -adot_qd[c];
            }
        }
        (k, r, power)
    }

    fn kkt_size(&self) -> usize {
        self.model.layout.n
            + if self.model.layout.platform.is_some() {
                N_CONSTRAINTS
            } else {
                0
            }
    }

    /// Multiplier-form right-hand side: y = (q, q̇, W).
    pub fn dae_rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
        let n = self.model.layout.n;
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        let (k, mut r, power) = self.kkt(t, q, qd);
        solve(&k, &mut r, self.kkt_size())?;
        dy[..n].copy_from_slice(qd);
        dy[n..2 * n].copy_from_slice(&r[..n]);
        dy[2 * n..2 * n + N_WORK].copy_from_slice(&power);
        Ok(())
    }

    /// |A q̇|∞ before, then the M-orthogonal projection of q̇ onto A q̇ = 0.
    fn project(&self, q: &[f64], qd: &mut [f64]) -> Result<f64> {
        let n = self.model.layout.n;
        let Some((a, _)) = self.model.constraints(q, qd) else {
            return Ok(0.0);
        };
        let mut k = [[0.0; KKT]; KKT];
        let mut r = [0.0; KKT];
        let mut mm = [[0.0; MAX_Q]; MAX_Q];
        self.model.mass_matrix(q, &mut mm);
        let mut drift = 0.0f64;
        for i in 0..n {
            k[i][..n].copy_from_slice(&mm[i][..n]);
        }
        for c in 0..N_CONSTRAINTS {
            let aq: f64 = (0..n).map(|j| a[c][j] * qd[j]).sum();
            drift = drift.max(aq.abs());
            for j in 0..n {
                k[n + c][j] = a[c][j];
                k[j][n + c] = a[c][j];
            }
            r[n + c] = -aq;
        }
        solve(&k, &mut r, n + N_CONSTRAINTS)?;
        for j in 0..n {
            qd[j] += r[j];
        }
        Ok(drift)
    }

    /// Integrates both formulations over [0, t_end], sampling every `dt_out`.
    pub fn run(&self, t_end: f64, dt_out: f64, tol: Tolerances) -> Result<History> {
        let (n, m) = (self.model.layout.n, self.model.layout.m);
        let mut yr = vec![0.0; n + m + N_WORK];
        yr[..n].copy_from_slice(&self.q0[..n]);
        yr[n..n + m].copy_from_slice(&self.nu0[..m]);
        let mut yd = vec![0.0; 2 * n + N_WORK];
        yd[..n].copy_from_slice(&self.q0[..n]);
        let mut scratch = [0.0; MAX_Q];
        self.model.velocities(
            &self.q0[..n],
            &self.nu0[..m],
            &mut yd[n..2 * n],
            &mut scratch,
        );
        let mut ode_r = Dopri5::new(yr.len(), tol.rtol, tol.atol);
        let mut ode_d = Dopri5::new(yd.len(), tol.rtol, tol.atol);
        let breaks = self.breakpoints(t_end);
        let count = (t_end / dt_out).round().max(1.0) as usize;
        let mut samples = Vec::with_capacity(count + 1);
        let mut err: Option<AnalyticError> = None;
        let (mut tr, mut td) = (0.0, 0.0);
        let mut drift = 0.0;
        samples.push(self.sample(0.0, &yr, &yd, drift)?);
        for k in 1..=count {
            let t_next = if k == count { t_end } else { k as f64 * dt_out };
            let mut stops: Vec<f64> = breaks
                .iter()
                .copied()
                .filter(|&b| b > tr && b < t_next)
                .collect();
            stops.push(t_next);
            for &stop in &stops {
                let mut fr = |t: f64, y: &[f64], dy: &mut [f64]| {
                    let mut qdd = [0.0; MAX_Q];
                    if let Err(e) = self.reduced_rhs(t, y, dy, &mut qdd) {
                        err.get_or_insert(e);
                        dy.fill(0.0);
                    }
                };
                ode_r.advance(&mut fr, &mut tr, &mut yr, stop)?;
                let mut fd = |t: f64, y: &[f64], dy: &mut [f64]| {
                    if let Err(e) = self.dae_rhs(t, y, dy) {
                        err.get_or_insert(e);
                        dy.fill(0.0);
                    }
                };
                ode_d.advance(&mut fd, &mut td, &mut yd, stop)?;
                if let Some(e) = err.take() {
                    return Err(e);
                }
            }
            let (q, qd) = yd.split_at_mut(n);
            drift = self.project(q, &mut qd[..n])?;
            samples.push(self.sample(t_next, &yr, &yd, drift)?);
        }
        Ok(History {
            samples,
            reduced_stats: ode_r.stats,
            dae_stats: ode_d.stats,
        })
    }

    fn sample(&self, t: f64, yr: &[f64], yd: &[f64], drift: f64) -> Result<Sample> {
        let (n, m) = (self.model.layout.n, self.model.layout.m);
        let mut dy = vec![0.0; yr.len()];
        let mut qdd = [0.0; MAX_Q];
        self.reduced_rhs(t, yr, &mut dy, &mut qdd)?;
        let q = &yr[..n];
        let qd = &dy[..n];
        let mut tau = [0.0; MAX_Q];
        self.inputs(t, &mut tau);
        let tau_inverse = self.inverse_torques(q, qd, &qdd[..n]);
        let mut nu_dae = [0.0; MAX_Q];
        self.model.minimal_speeds(&yd[n..2 * n], &mut nu_dae);
        let position_gap = (0..n).fold(0.0f64, |g, i| g.max((yd[i] - yr[i]).abs()));
        let rate_gap = (0..m).fold(0.0f64, |g, i| g.max((nu_dae[i] - yr[n + i]).abs()));
        let mut work = [0.0; N_WORK];
        work.copy_from_slice(&yr[n + m..n + m + N_WORK]);
        Ok(Sample {
            t,
            q: q.to_vec(),
            qd: qd.to_vec(),
            qdd: qdd[..n].to_vec(),
            tau: tau[..m].to_vec(),
            tau_inverse,
            kinetic: self.model.kinetic_energy(q, qd),
            potential: self.model.potential_energy(q),
            work,
            drift,
            position_gap,
            rate_gap,
            end_effector: self.model.end_effector(q).into(),
        })
    }

    /// Inverse dynamics τ = Sᵀ (M q̈ + h + D q̇) for a constraint-consistent motion.
    pub fn inverse_torques(&self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
        let (n, m) = (self.model.layout.n, self.model.layout.m);
        let mut nh = [0.0; MAX_Q];
        self.model.inverse_dynamics(q, qd, qdd, true, &mut nh);
        let mut friction = [0.0; MAX_Q];
        let zeros = [0.0; MAX_Q];
        self.model.applied(qd, &zeros, &mut friction);
        let mut col = [0.0; MAX_Q];
        (0..m)
            .map(|i| {
                self.model.null_space_column(q, i, &mut col);
                (0..n).map(|a| col[a] * (nh[a] - friction[a])).sum()
            })
            .collect()
    }
}
