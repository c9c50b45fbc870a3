//! The Newton system of the implicit methods: S = c_a M + c_v C + c_q K at a trial point,
//! formed as the analytic bordered-band matrix (linear cost; omits the O(v′²) foreshortening
//! couplings of free chains) or as the exact finite-difference Jacobian with dense LU (free
//! chains with foreshortening), factorized once and solved in place.

use crate::band::{BorderedBand, DenseLu};
use crate::chain::{Chain, NONE, NewtonCoefficients};
use crate::error::FemError;
use crate::method::{Counters, StepState};

/// How the Newton matrix is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JacobianKind {
    /// Analytic bordered-band matrix (linear cost; omits the O(v′²) foreshortening couplings).
    Banded,
    /// Exact Jacobian by one directional difference of the residual per column, dense LU
    /// (O(n²) per step): used for free chains with foreshortening.
    DenseFiniteDifference,
}

/// The Newton matrix, its factorization, and the residual and update vectors.
#[derive(Debug, Clone)]
pub struct NewtonSystem {
    pub matrix: BorderedBand,
    pub jacobian: JacobianKind,
    pub dense: Option<DenseLu>,
    /// Step size the current matrix was formed with, and whether it must be refreshed.
    pub matrix_h: f64,
    pub slow_convergence: bool,
    /// Residual at the trial point (input of [`NewtonSystem::form`]).
    pub res: Vec<f64>,
    /// Right-hand side and solution of [`NewtonSystem::solve`].
    pub delta: Vec<f64>,
    /// Newton displacement tolerance.
    pub tol: f64,
    /// A unilateral tip contact is stepped (impacts, releases, grazing): the finite-difference
    /// matrix perturbs q̇ by a share of its scale at every step length, and the energy-midpoint
    /// iteration refreshes stale matrices ([`crate::method::energy_midpoint`]).
    pub unilateral_contact: bool,
    fd_q: Vec<f64>,
    fd_qd: Vec<f64>,
    fd_qdd: Vec<f64>,
    fd_res: Vec<f64>,
}

impl NewtonSystem {
    /// The Newton system of `chain` (`length_scale`: the longest link, scales the tolerance).
    pub fn new(chain: &Chain, length_scale: f64) -> Self {
        let n = chain.ndof;
        let free_chain = chain.links.len() > 1 || chain.links.iter().any(|l| l.joint.dof != NONE);
        let jacobian = if free_chain && chain.links.iter().any(|l| l.foreshortening) {
            JacobianKind::DenseFiniteDifference
        } else {
            JacobianKind::Banded
        };
        NewtonSystem {
            matrix: chain.new_matrix(),
            jacobian,
            dense: (jacobian == JacobianKind::DenseFiniteDifference).then(|| DenseLu::new(n)),
            matrix_h: f64::NAN,
            slow_convergence: true,
            res: vec![0.0; n],
            delta: vec![0.0; n],
            tol: 1e-11 * length_scale.max(1e-3),
            unilateral_contact: false,
            fd_q: vec![0.0; n],
            fd_qd: vec![0.0; n],
            fd_qdd: vec![0.0; n],
            fd_res: vec![0.0; n],
        }
    }

    /// Re-forms and factors the matrix when it is due in Newton iteration `it` of a step of
    /// size `h`: at the first iteration when it is stale — the band matrix is cheap and formed
    /// fresh every step (near-quadratic convergence keeps the iteration error far below the
    /// tolerance, which the tight ledger checks need), the dense finite-difference matrix is
    /// reused across steps (modified Newton) while Newton converges in ≤ 3 iterations at an
    /// unchanged step — and every 6th iteration.
    #[allow(clippy::too_many_arguments)]
    pub fn form_if_due(
        &mut self,
        it: usize,
        h: f64,
        chain: &mut Chain,
        st: &StepState,
        counters: &mut Counters,
        h_nominal: f64,
        c: NewtonCoefficients,
        t_law: f64,
        t: f64,
    ) -> Result<(), FemError> {
        let fresh =
            self.jacobian == JacobianKind::Banded || self.matrix_h != h || self.slow_convergence;
        if (it == 0 && fresh) || it == 6 || it == 12 || it == 18 {
            self.form(chain, st, counters, h_nominal, c, t_law, t)?;
            self.matrix_h = h;
            self.slow_convergence = false;
        }
        Ok(())
    }

    /// Forms and factorizes the Newton matrix at (q1, q̇1, q̈1) after a residual evaluation there.
    #[allow(clippy::too_many_arguments)]
    pub fn form(
        &mut self,
        chain: &mut Chain,
        st: &StepState,
        counters: &mut Counters,
        h_nominal: f64,
        c: NewtonCoefficients,
        t_law: f64,
        t: f64,
    ) -> Result<(), FemError> {
        counters.jacobians += 1;
        counters.factorizations += 1;
        match self.jacobian {
            JacobianKind::Banded => {
                chain.newton_matrix(&st.q1, c, &mut self.matrix);
                self.matrix.factorize().map_err(|e| with_time(e, t))
            }
            JacobianKind::DenseFiniteDifference => {
                let n = st.q.len();
                // Column j: directional difference along (c_q, c_v, 1)·e_j in (q, q̇, q̈).
                // Forward difference with ε relative to the acceleration scale: error O(ε)
                // in the matrix only slows Newton, never changes its converged answer.
                let amax = st.qdd1.iter().fold(1.0f64, |a, b| a.max(b.abs()));
                // A pure mass matrix (c_v = c_q = 0: consistent initial accelerations, central
                // difference) is the derivative of a residual affine in q̈: a large ε has no
                // truncation error, while 1e-7 left the columns of the small rotary masses
                // (ρA h³ ~ 1e-6 at 32 elements) at the round-off of the O(10²) residual, and
                // the initial-acceleration iteration contracted by only 0.85 per step.
                let eps = if c.c_v == 0.0 && c.c_q == 0.0 {
                    1e3 * amax
                } else if self.unilateral_contact {
                    // Contact runs: ε = max(1e-5 a_max, 1e-6 v_max/c_v), i.e. the velocity
                    // perturbation is 1e-6 of the velocity scale at every step length (the
                    // rates along the massless directions are consistent, so v_max is a
                    // physical scale: crate::events::massless). The residual is affine in q̈ and the
                    // velocity terms are smooth on that scale, while the position perturbation
                    // c_q·ε must stay far above the round-off of q: with ε = 1e-7 a_max (below)
                    // it fell to 1e-13..1e-16 on short steps, the columns of the massless and
                    // almost massless directions (damping and stiffness only) were round-off,
                    // and freshly formed matrices diverged. Measured on
                    // `barhorst-case1-timoshenko` (8 elements, dt = 2.5e-5, 0.27 s of free
                    // fall): 38, 23, 0, 0 rejected steps at ε ×1, ×10, ×100, ×1000 of the
                    // rule below with its floor.
                    let vmax = st.qd1.iter().fold(1.0f64, |a, b| a.max(b.abs()));
                    (1e-5 * amax).max(1e-6 * vmax / c.c_v)
                } else {
                    // Floor: the velocity perturbation c_v·ε stays above 1e-8 of the velocity
                    // scale. Steps shortened to locate an event (h → 1e-13 s) otherwise perturb
                    // q̇ and q below their round-off, and the columns of massless directions
                    // (no mass, only damping and stiffness) vanish: a singular matrix.
                    let vmax = st.qd1.iter().fold(1.0f64, |a, b| a.max(b.abs()));
                    // Only there (h < 1e-3 h_nominal): on regular steps the floor moved
                    // measured trajectories (Newton's accepted iterate depends on the matrix
                    // within the tolerance: conv_timoshenko_stiff_shear_recovers_the_euler_chain).
                    let floor = if c.c_v > 0.0 && c.c_v < 0.5e-3 * h_nominal {
                        1e-8 * vmax / c.c_v
                    } else {
                        0.0
                    };
                    (1e-7 * amax).max(floor)
                };
                let Some(dense) = self.dense.as_mut() else {
                    return Ok(());
                };
                // Perturb one entry per column and restore it afterwards (O(n) per column,
                // not three full copies).
                self.fd_q.copy_from_slice(&st.q1);
                self.fd_qd.copy_from_slice(&st.qd1);
                self.fd_qdd.copy_from_slice(&st.qdd1);
                for j in 0..n {
                    self.fd_q[j] += c.c_q * eps;
                    self.fd_qd[j] += c.c_v * eps;
                    self.fd_qdd[j] += eps;
                    chain.residual(
                        t_law,
                        &self.fd_q,
                        &self.fd_qd,
                        &self.fd_qdd,
                        &mut self.fd_res,
                    );
                    self.fd_q[j] = st.q1[j];
                    self.fd_qd[j] = st.qd1[j];
                    self.fd_qdd[j] = st.qdd1[j];
                    for i in 0..n {
                        self.fd_res[i] = (self.fd_res[i] - self.res[i]) / eps;
                    }
                    dense.set_column(j, &self.fd_res);
                }
                counters.rhs += n;
                // Restore the chain's cached state (joint torques) at the unperturbed point.
                chain.residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut self.fd_res);
                dense.factorize().map_err(|e| with_time(e, t))
            }
        }
    }

    /// Solves S x = `delta` in place.
    pub fn solve(&mut self) {
        match (&self.jacobian, &self.dense) {
            (JacobianKind::DenseFiniteDifference, Some(d)) => d.solve_in_place(&mut self.delta),
            _ => self.matrix.solve_in_place(&mut self.delta),
        }
    }
}

/// Stamps a singular-matrix error with the time.
pub fn with_time(e: FemError, t: f64) -> FemError {
    match e {
        FemError::Singular { what, pivot, .. } => FemError::Singular { what, pivot, t },
        other => other,
    }
}
