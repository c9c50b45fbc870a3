//! Time integration of R(q, q̇, q̈, t) = 0 as a method with `step() -> Result<StopReason, _>`.
//!
//! * Implicit generalized-α (Chung–Hulbert parameters from ρ∞, Arnold–Brüls form: the equation of
//!   motion is enforced at t_{n+1}; pseudo-acceleration a with
//!   (1−α_m) a_{n+1} + α_m a_n = (1−α_f) q̈_{n+1} + α_f q̈_n,
//!   q_{n+1} = q_n + h q̇_n + h²(½ − β) a_n + h²β a_{n+1}, q̇_{n+1} = q̇_n + h(1−γ) a_n + hγ a_{n+1}).
//!   The unknown q̈_{n+1} is found by (quasi-)Newton with the bordered-band matrix
//!   S = M + γ′C + β′K (γ′ = hγ(1−α_f)/(1−α_m), β′ = h²β(1−α_f)/(1−α_m)), factorized once per
//!   step and reused across the iterations. With ρ∞ = 1 this is the trapezoidal rule, which
//!   conserves the energy of linear systems exactly.
//!   Fixed step, or adaptive when `rtol` is given: local error estimate
//!   e = h²(β − 1/6)(q̈_{n+1} − q̈_n) (Zienkiewicz–Xie), step ratio 0.9·err^(−1/3) ∈ [0.2, 2].
//! * Explicit central difference (velocity-Verlet form): q̇_{n+½} = q̇_n + h/2 q̈_n,
//!   q_{n+1} = q_n + h q̇_{n+½}, M(q_{n+1}) q̈_{n+1} = −(rest of R) with velocity terms evaluated at
//!   the predicted q̇, q̇_{n+1} = q̇_{n+½} + h/2 q̈_{n+1}. Stable for h ≤ 2/ω_max provided the
//!   step is constant: each stretch between stop times is split into equal steps ≤ dt (a
//!   periodic short step near the bound makes the composed map unstable).
//!
//! * Energy-consistent midpoint (`energy-midpoint`, the default for free-joint chains): see
//!   [`crate::midpoint`]; it shares the Newton-matrix machinery, the stops and the step control.
//!
//! The stepper stops exactly on requested times (outputs, torque-law breakpoints, t_end) so that
//! discontinuities — and later contact events — are never stepped over.

use crate::band::{BorderedBand, DenseLu};
use crate::chain::{Chain, NONE, NewtonCoefficients};
use crate::contact::{Contact, Post};
use crate::error::FemError;
use crate::linalg::{dot, max_abs};
use crate::midpoint::MidpointWork;
use crate::settings::Method;

/// How the Newton matrix is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JacobianKind {
    /// Analytic bordered-band matrix (linear cost; omits the O(v′²) foreshortening couplings).
    Banded,
    /// Exact Jacobian by one directional difference of the residual per column, dense LU
    /// (O(n²) per step): used for free chains with foreshortening.
    DenseFiniteDifference,
}

/// Why [`Integrator::step`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// A step was taken and the stop time is still ahead.
    Stepped,
    /// The step landed on the requested stop time.
    ReachedStop,
    /// The step was rejected by the error control; the state is unchanged and h reduced.
    Rejected,
}

/// Why the last step was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rejection {
    /// Newton failed (fixed step: the stretch is retried with a quarter step).
    Newton,
    /// Local error estimate above tolerance (adaptive steps).
    ErrorEstimate,
    /// A grazing contact whose phase is undetermined at this step length (crate::contact).
    ContactRefine,
}

/// Work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counters {
    pub steps: usize,
    pub rejected: usize,
    pub rhs: usize,
    pub jacobians: usize,
    pub factorizations: usize,
    pub newton: usize,
}

/// Running energy-ledger integrals (cumulative works).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Works {
    pub applied_torque: f64,
    pub applied_load: f64,
    pub prescribed_motion: f64,
    pub joint_damper: f64,
    pub kelvin_voigt: f64,
    /// Strain energy removed by projecting the massless section rotations onto their balance
    /// (`crate::massless`, ledger `numerical_massless`).
    pub numerical_massless: f64,
}

#[derive(Debug, Clone, Copy)]
struct AlphaParams {
    alpha_m: f64,
    alpha_f: f64,
    gamma: f64,
    beta: f64,
}

impl AlphaParams {
    fn from_rho(rho: f64) -> Self {
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        AlphaParams {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }
}

/// Adaptive step control.
#[derive(Debug, Clone, Copy)]
pub struct Adaptive {
    pub rtol: f64,
    pub atol: f64,
}

/// The time stepper: owns the chain, the state and all work buffers.
#[derive(Debug, Clone)]
pub struct Integrator {
    pub chain: Chain,
    pub method: Method,
    pub t: f64,
    pub h: f64,
    /// The fixed step (the step returns to it after Newton-failure retries).
    pub h_nominal: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub(crate) a: Vec<f64>,
    pub(crate) q1: Vec<f64>,
    pub(crate) qd1: Vec<f64>,
    pub(crate) qdd1: Vec<f64>,
    pub(crate) a1: Vec<f64>,
    pub(crate) res: Vec<f64>,
    pub(crate) delta: Vec<f64>,
    pub(crate) qd_mid: Vec<f64>,
    pub matrix: BorderedBand,
    pub jacobian: JacobianKind,
    pub(crate) dense: Option<DenseLu>,
    /// Step size the current Newton matrix was formed with, and whether it must be refreshed.
    pub(crate) matrix_h: f64,
    pub(crate) slow_convergence: bool,
    pub(crate) fd_q: Vec<f64>,
    pub(crate) fd_qd: Vec<f64>,
    pub(crate) fd_qdd: Vec<f64>,
    pub(crate) fd_res: Vec<f64>,
    params: AlphaParams,
    pub adaptive: Option<Adaptive>,
    /// Times the stepper must land on and restart from (torque-law discontinuities).
    pub(crate) breakpoints: Vec<f64>,
    pub(crate) next_break: usize,
    pub(crate) stop: f64,
    /// Newton displacement tolerance.
    pub(crate) newton_tol: f64,
    pub counters: Counters,
    pub works: Works,
    /// Joint torques at the start of the current step (law and required).
    pub(crate) torque_law_start: Vec<f64>,
    pub(crate) torque_req_start: Vec<f64>,
    pub(crate) theta_start: Vec<f64>,
    pub(crate) rate_start: Vec<f64>,
    /// Largest link length (scales Newton and error tolerances).
    pub length_scale: f64,
    /// Work buffers of the energy-consistent midpoint scheme (allocated only for that method).
    pub midpoint: Option<Box<MidpointWork>>,
    /// The scene's tip contact (energy-midpoint only; None without contact, nothing allocated).
    pub contact: Option<Box<Contact>>,
    /// Why the last rejected step was rejected.
    pub last_rejection: Rejection,
    /// A unilateral tip contact is stepped (impacts, releases, grazing): the Newton matrix is
    /// formed with the perturbation scaled to the velocities at every step length
    /// (`form_matrix`) and the energy-midpoint Newton iteration refreshes stale matrices
    /// ([`crate::midpoint`]). Elsewhere both are as before (results unchanged).
    pub(crate) unilateral_contact: bool,
}

impl Integrator {
    /// Sets up the stepper at t = 0 from the scene's initial state; `rho_inf` is the
    /// generalized-α spectral radius at infinity.
    pub fn new(chain: Chain, method: Method, h: f64, rho_inf: f64) -> Result<Self, FemError> {
        let n = chain.ndof;
        let nl = chain.links.len();
        let matrix = chain.new_matrix();
        let length_scale = chain.links.iter().fold(0.0f64, |a, l| a.max(l.length));
        let free_chain = chain.links.len() > 1 || chain.links.iter().any(|l| l.joint.dof != NONE);
        let jacobian = if free_chain && chain.links.iter().any(|l| l.foreshortening) {
            JacobianKind::DenseFiniteDifference
        } else {
            JacobianKind::Banded
        };
        let mut breakpoints: Vec<f64> = chain
            .links
            .iter()
            .filter_map(|l| l.joint.torque.as_ref())
            .flat_map(|law| law.breakpoints())
            .filter(|t| *t > 0.0)
            .collect();
        breakpoints.sort_by(f64::total_cmp);
        breakpoints.dedup();
        let mut it = Integrator {
            chain,
            method,
            t: 0.0,
            h,
            h_nominal: h,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            a: vec![0.0; n],
            q1: vec![0.0; n],
            qd1: vec![0.0; n],
            qdd1: vec![0.0; n],
            a1: vec![0.0; n],
            res: vec![0.0; n],
            delta: vec![0.0; n],
            qd_mid: vec![0.0; n],
            matrix,
            jacobian: JacobianKind::Banded,
            dense: None,
            matrix_h: f64::NAN,
            slow_convergence: true,
            fd_q: vec![0.0; n],
            fd_qd: vec![0.0; n],
            fd_qdd: vec![0.0; n],
            fd_res: vec![0.0; n],
            params: AlphaParams::from_rho(rho_inf),
            adaptive: None,
            breakpoints,
            next_break: 0,
            stop: f64::INFINITY,
            newton_tol: 1e-11 * length_scale.max(1e-3),
            counters: Counters::default(),
            works: Works::default(),
            torque_law_start: vec![0.0; nl],
            torque_req_start: vec![0.0; nl],
            theta_start: vec![0.0; nl],
            rate_start: vec![0.0; nl],
            length_scale,
            midpoint: None,
            contact: None,
            last_rejection: Rejection::Newton,
            unilateral_contact: false,
        };
        if method == Method::EnergyMidpoint {
            it.midpoint = Some(Box::new(MidpointWork::new(n)));
        }
        it.jacobian = jacobian;
        if jacobian == JacobianKind::DenseFiniteDifference {
            it.dense = Some(DenseLu::new(n));
        }
        it.chain.initial_state(&mut it.q, &mut it.qd);
        // The unsettled rest configuration (v = 0) is kept in q1 for the initial acceleration.
        it.q1.copy_from_slice(&it.q);
        it.chain.settle_massless(0.0, &mut it.q, &it.qd)?;
        it.initial_acceleration(0.0)?;
        Ok(it)
    }

    /// Switches on the stepping of the scene's unilateral tip contact (set in `self.contact`;
    /// energy-midpoint): the contact's massless directions (if any, with Kelvin–Voigt) are
    /// projected onto their balance and given consistent rates after every step
    /// ([`crate::massless`]), and the Newton matrix and iteration are those of
    /// `unilateral_contact`. Forms the operators here (nothing is allocated in the step loop).
    pub fn enable_unilateral_contact(&mut self) -> Result<(), FemError> {
        self.unilateral_contact = true;
        if self.method != Method::EnergyMidpoint {
            return Ok(());
        }
        let Some(ml) = self
            .contact
            .as_deref_mut()
            .and_then(|c| c.massless.as_mut())
        else {
            return Ok(());
        };
        self.counters.rhs += ml.form(&mut self.chain, self.t, &self.q);
        if ml.damped(&mut self.chain, self.t, &self.q) {
            ml.project = true;
            self.counters.rhs +=
                ml.make_consistent(&mut self.chain, self.t, &self.q, &mut self.qd)?;
        }
        Ok(())
    }

    /// Rejects a fixed step of length `h`: the stretch is retried with a quarter step (grown
    /// back afterwards). `restart` drops the midpoint predictor — where the stretch's start
    /// state may have changed (an impact applied while locating an event).
    fn retry_quarter_step(&mut self, h: f64, why: Rejection, restart: bool) -> StopReason {
        self.counters.rejected += 1;
        self.last_rejection = why;
        self.h = 0.25 * h;
        if restart && let Some(w) = self.midpoint.as_mut() {
            w.restart();
        }
        StopReason::Rejected
    }

    /// Sets the next time the stepper must land on.
    pub fn set_stop(&mut self, t_stop: f64) {
        self.stop = t_stop;
    }

    /// Consistent q̈ at the current state: solves R(q, q̇, q̈) = 0 for q̈ (R is affine in q̈; the
    /// iteration converges because the mass-matrix approximation misses only O(v′²) terms).
    fn initial_acceleration(&mut self, t_law: f64) -> Result<(), FemError> {
        if self.chain.has_massless_dofs() {
            return self.regularized_initial_acceleration(t_law);
        }
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.0,
            c_q: 0.0,
        };
        for it in 0..50 {
            self.chain
                .residual(t_law, &self.q, &self.qd, &self.qdd, &mut self.res);
            self.counters.rhs += 1;
            if it == 0 {
                self.q1.copy_from_slice(&self.q);
                self.qd1.copy_from_slice(&self.qd);
                self.qdd1.copy_from_slice(&self.qdd);
                self.form_matrix(c, t_law, self.t)?;
                self.matrix_h = f64::NAN;
            }
            self.delta.copy_from_slice(&self.res);
            self.solve_matrix();
            let mut big = 0.0f64;
            let mut amax = 0.0f64;
            for i in 0..self.qdd.len() {
                self.qdd[i] -= self.delta[i];
                big = big.max(self.delta[i].abs());
                amax = amax.max(self.qdd[i].abs());
            }
            if !big.is_finite() {
                break;
            }
            // 1e-10 relative: far below the integrator's error; tighter is round-off-limited
            // (point moments on EB elements give q̈₀ ∝ h⁻³ spikes).
            if big <= 1e-10 * amax.max(1e-12) {
                self.a.copy_from_slice(&self.qdd);
                self.record_step_start(t_law);
                return Ok(());
            }
        }
        Err(FemError::Numerical {
            t: self.t,
            message: "could not compute a consistent initial acceleration".into(),
        })
    }

    /// Initial acceleration of a chain with massless directions (Timoshenko links without
    /// rotary inertia: see `Chain::settle_massless`). There M is singular: the massless
    /// directions N are algebraic variables, whose acceleration follows from differentiating
    /// their balance Nᵀ R = 0 (to first order Nᵀ K q̈ = 0 at rest), not from M. One solve of
    /// (M₀ + εK₀) q̈ = −R(q, q̇, 0) gives both: M₀, K₀ are the matrices at the unsettled rest
    /// configuration (v = 0, kept in `q1` by `new`), where NᵀM₀ = 0 exactly, so with the
    /// settled residual (NᵀR = 0) its N-rows read ε NᵀK₀ q̈ = 0; the mass-carrying rows are
    /// M q̈ = −R up to ε K₀ q̈ (ε = 10⁻⁴h²: a relative 10⁻⁴(hω)² for the resolved modes) and the
    /// O(ψ) settling shift. (At the settled state itself NᵀM = O(ψ) ≠ 0, and that coupling,
    /// divided by ε, made generalized-α first order.) R is affine in q̈ and the band matrix
    /// is analytic; refinement passes (below) then drive the mass rows to R = 0 (measured:
    /// Timoshenko cantilever without rotary inertia, step load, trapezoidal ledger 4e-12
    /// instead of 1.6e-8 after the single solve).
    fn regularized_initial_acceleration(&mut self, t_law: f64) -> Result<(), FemError> {
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.0,
            c_q: 1e-4 * self.h * self.h,
        };
        self.qdd.iter_mut().for_each(|x| *x = 0.0);
        self.counters.rhs += 1;
        self.counters.jacobians += 1;
        self.counters.factorizations += 1;
        // The analytic band matrix even where steps use the finite-difference one:
        // differences of the small ε·K share would drown in round-off.
        self.chain
            .residual(t_law, &self.q1, &self.qd, &self.qdd, &mut self.res);
        self.chain.newton_matrix(&self.q1, c, &mut self.matrix);
        self.matrix.factorize().map_err(|e| with_time(e, self.t))?;
        // Refinement: q̈ ← q̈ − S₀⁻¹R(q̈) removes the ε K₀ q̈ error of the mass rows (factor
        // ≈ εω² per pass) while the massless rows stay balanced; where the settled state turns
        // the frame directions slightly massive (NᵀM = O(ψ)) the passes stop improving, and the
        // q̈ with the smallest residual is kept.
        let n = self.qdd.len();
        let mut best = f64::INFINITY;
        for _ in 0..10 {
            self.chain
                .residual(t_law, &self.q, &self.qd, &self.qdd, &mut self.res);
            self.counters.rhs += 1;
            let r = max_abs(&self.res);
            // Stop once a pass no longer halves the residual (or it is not finite).
            if r.is_nan() || r >= 0.5 * best {
                break;
            }
            best = r;
            self.qdd1.copy_from_slice(&self.qdd);
            self.delta.copy_from_slice(&self.res);
            self.matrix.solve_in_place(&mut self.delta);
            let (mut big, mut amax) = (0.0f64, 0.0f64);
            for i in 0..n {
                self.qdd[i] -= self.delta[i];
                big = big.max(self.delta[i].abs());
                amax = amax.max(self.qdd[i].abs());
            }
            if !big.is_finite() {
                break;
            }
            if big <= 1e-12 * amax.max(1e-12) {
                self.qdd1.copy_from_slice(&self.qdd);
                break;
            }
        }
        self.qdd.copy_from_slice(&self.qdd1);
        if !best.is_finite() || self.qdd.iter().any(|x| !x.is_finite()) {
            return Err(FemError::Numerical {
                t: self.t,
                message: "could not compute a consistent initial acceleration".into(),
            });
        }
        // Leave the chain's cached data (joint torques) at the initial state.
        self.chain
            .residual(t_law, &self.q, &self.qd, &self.qdd, &mut self.res);
        self.matrix_h = f64::NAN;
        self.a.copy_from_slice(&self.qdd);
        self.record_step_start(t_law);
        Ok(())
    }

    /// Stores the joint quantities at the start of a step for the work integrals.
    fn record_step_start(&mut self, t_law: f64) {
        for li in 0..self.chain.links.len() {
            let (th, rate) = self.chain.joint_state(li, self.t, &self.q, &self.qd);
            self.theta_start[li] = th;
            self.rate_start[li] = rate;
            self.torque_law_start[li] = self.chain.links[li].joint.applied(t_law);
            self.torque_req_start[li] = if self.chain.links[li].joint.dof == NONE {
                self.chain.joint_torque[li]
            } else {
                0.0
            };
        }
    }

    /// Advances by one step (or rejects one); never steps over the stop time or a breakpoint.
    pub fn step(&mut self) -> Result<StopReason, FemError> {
        let remaining = self.stop - self.t;
        let mut target = self.stop;
        let mut on_break = false;
        while self.next_break < self.breakpoints.len()
            && self.breakpoints[self.next_break] <= self.t + 1e-12 * self.h
        {
            self.next_break += 1;
        }
        if let Some(&b) = self.breakpoints.get(self.next_break)
            && b < target - 1e-12 * self.h
        {
            target = b;
        }
        let span = target - self.t;
        let mut h = if self.method == Method::CentralDifference {
            // Equal steps between stops: near its bound (hω → 2) each velocity-Verlet step is a
            // stable but strongly non-normal map, and a periodic pattern of full steps plus one
            // short step per output interval composes into an unstable map (measured: spin-up at
            // 0.99 × 2/ω_max, 83 full + 1 short step per 0.01 s, diverged at t ≈ 0.32 s while
            // ω_max stayed constant to 1e-9). Every step is ≤ h_nominal (up to 1e-9 relative).
            let n = (span / self.h_nominal * (1.0 - 1e-9)).ceil().max(1.0);
            span / n
        } else {
            self.h.min(span)
        };
        if target - self.t - h <= 1e-9 * h {
            h = target - self.t;
        }
        if self.next_break < self.breakpoints.len()
            && (self.t + h - self.breakpoints[self.next_break]).abs() <= 1e-12 * self.h.max(1.0)
        {
            on_break = true;
        }
        debug_assert!(remaining > 0.0);
        let t1 = self.t + h;
        // Laws are evaluated as left limits on a step that ends on a discontinuity.
        let t_law = if on_break { t1 - 1e-9 * h } else { t1 };
        let result = match self.method {
            Method::GeneralizedAlpha => self.alpha_step(h, t1, t_law),
            Method::CentralDifference => self.central_step(h, t1, t_law),
            Method::EnergyMidpoint => self.midpoint_step(h, t1, t_law),
        };
        match result {
            Ok(Some(err)) if self.adaptive.is_none() && err.is_infinite() => {
                // Fixed step: Newton failed; retry this stretch with quarter steps, then grow back.
                return Ok(self.retry_quarter_step(h, Rejection::Newton, false));
            }
            Ok(Some(err)) if self.adaptive.is_some() && err > 1.0 => {
                self.counters.rejected += 1;
                self.last_rejection = Rejection::ErrorEstimate;
                let ratio = (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 1.0);
                self.h = h * ratio;
                if self.h < 1e-14 * self.stop.abs().max(1.0) {
                    return Err(FemError::Runaway {
                        t: self.t,
                        what: "step size underflow".into(),
                        location: None,
                        why: "the error estimate could not be met".into(),
                        remedy: "loosen --rtol or refine the mesh less".into(),
                    });
                }
                return Ok(StopReason::Rejected);
            }
            Ok(err) => {
                // Contact events are located inside the step: it may be shortened to h_acc.
                let (h_acc, post) = if self.contact.is_some() {
                    match self.contact_after_trial(h) {
                        Ok(x) => x,
                        // A shortened or constrained re-solve did not converge: retry the
                        // stretch with a quarter step from the (possibly post-impact) start.
                        Err(FemError::Runaway { ref location, .. })
                            if h > 1e-6 * self.h_nominal
                                && location.as_deref()
                                    != Some(crate::contact::GRAZING_LOCATION) =>
                        {
                            return Ok(self.retry_quarter_step(h, Rejection::Newton, true));
                        }
                        Err(e) => return Err(e),
                    }
                } else {
                    (h, Post::None)
                };
                if post == Post::Refine {
                    // The contact phase over this step is undetermined at this length
                    // (crate::contact, grazing): retry the stretch with a quarter step.
                    return Ok(self.retry_quarter_step(h, Rejection::ContactRefine, true));
                }
                let (h, t1, t_law) = if h_acc < h {
                    on_break = false;
                    (h_acc, self.t + h_acc, self.t + h_acc)
                } else {
                    (h, t1, t_law)
                };
                self.accept(h, t1, t_law);
                if self.contact.is_some() {
                    self.contact_after_accept(post)?;
                }
                if self.adaptive.is_none() {
                    self.h = (2.0 * self.h).min(self.h_nominal);
                }
                if let (Some(e), Some(_)) = (err, self.adaptive) {
                    let ratio = (0.9 * e.max(1e-10).powf(-1.0 / 3.0)).clamp(0.2, 2.0);
                    // Do not let a short step that landed on a stop time shrink the next one.
                    if h >= 0.5 * self.h {
                        self.h = h * ratio;
                    } else {
                        self.h = self.h.max(h * ratio);
                    }
                }
                if on_break {
                    // Restart from the discontinuity with the new law value.
                    self.initial_acceleration(self.t)?;
                    if let Some(w) = self.midpoint.as_mut() {
                        w.restart();
                    }
                }
            }
            Err(e) => return Err(e),
        }
        self.check_state()?;
        if (self.stop - self.t).abs() <= 1e-9 * h {
            self.t = self.stop;
            Ok(StopReason::ReachedStop)
        } else {
            Ok(StopReason::Stepped)
        }
    }

    fn check_state(&self) -> Result<(), FemError> {
        if let Some(i) = self.q.iter().chain(&self.qd).position(|x| !x.is_finite()) {
            let dof = i % self.q.len();
            return Err(FemError::Runaway {
                t: self.t,
                what: "non-finite state".into(),
                location: Some(self.chain.describe_dof(dof)),
                why: "the integration diverged".into(),
                remedy: "reduce --dt or use generalized-alpha".into(),
            });
        }
        for (li, l) in self.chain.links.iter().enumerate() {
            let v = self.chain.tip_deflection(li, &self.q);
            if v.abs() > l.length {
                let model = if l.foreshortening || l.axial {
                    "the deflection is outside the small-strain floating-frame model"
                } else {
                    "the linear model (no geometric stiffening) has lost its centrifugal stiffness: \
                     spinning above the first bending frequency it grows without bound"
                };
                return Err(FemError::Runaway {
                    t: self.t,
                    what: format!(
                        "tip deflection of link {} grew to {v:.3e}, beyond the link length {}",
                        li + 1,
                        l.length
                    ),
                    location: Some(format!("link {} tip", li + 1)),
                    why: model.into(),
                    remedy: if l.foreshortening || l.axial {
                        "reduce the load or the step".into()
                    } else {
                        "switch on `foreshortening` or `axial` (geometric stiffening)".into()
                    },
                });
            }
        }
        Ok(())
    }

    /// Commits q1, q̇1, q̈1 and updates the work integrals.
    fn accept(&mut self, h: f64, t1: f64, t_law: f64) {
        if let Some(w) = self.midpoint.as_mut() {
            // The midpoint scheme books its works with its own quadrature (see `midpoint`).
            w.commit(h, &mut self.works);
            self.finish_accept(t1, t_law);
            return;
        }
        let nl = self.chain.links.len();
        // Midpoint velocity: ½(F_n + F_{n+1})·Δq for linear dampers under the trapezoidal rule.
        for i in 0..self.qd.len() {
            self.qd_mid[i] = 0.5 * (self.qd[i] + self.qd1[i]);
        }
        let (_, p_kv) = self.chain.dissipation_power(t1, &self.qd_mid);
        self.works.kelvin_voigt += p_kv * h;
        self.works.applied_load += self.chain.load_power(&self.qd_mid) * h;
        for li in 0..nl {
            let (th1, rate1) = self.chain.joint_state(li, t1, &self.q1, &self.qd1);
            let dth = th1 - self.theta_start[li];
            let j = &self.chain.links[li].joint;
            let law1 = j.applied(t_law);
            self.works.applied_torque += 0.5 * (self.torque_law_start[li] + law1) * dth;
            self.works.joint_damper += 0.5 * j.damping * (self.rate_start[li] + rate1) * dth;
            if j.dof == NONE {
                let req1 = self.chain.joint_torque[li];
                self.works.prescribed_motion += 0.5 * (self.torque_req_start[li] + req1) * dth;
            }
        }
        self.finish_accept(t1, t_law);
    }

    /// Swaps the new state in and starts the next step's work records.
    fn finish_accept(&mut self, t1: f64, t_law: f64) {
        std::mem::swap(&mut self.q, &mut self.q1);
        std::mem::swap(&mut self.qd, &mut self.qd1);
        std::mem::swap(&mut self.qdd, &mut self.qdd1);
        std::mem::swap(&mut self.a, &mut self.a1);
        self.t = t1;
        self.counters.steps += 1;
        self.record_step_start(t_law);
    }

    /// One generalized-α step; returns the scaled error estimate when adaptive.
    fn alpha_step(&mut self, h: f64, t1: f64, t_law: f64) -> Result<Option<f64>, FemError> {
        let AlphaParams {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        } = self.params;
        let r = (1.0 - alpha_f) / (1.0 - alpha_m);
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: h * gamma * r,
            c_q: h * h * beta * r,
        };
        let n = self.q.len();
        // Predictor: constant displacement q_{n+1} = q_n + h q̇_n (a_{n+1} = −(½ − β)/β a_n).
        // Robust for stiff starts (a released pre-loaded spring gives a mesh-dependent q̈₀ spike
        // that a constant-acceleration predictor would turn into a huge first iterate).
        for i in 0..n {
            let a_pred = -(0.5 - beta) / beta * self.a[i];
            self.qdd1[i] =
                (a_pred - (alpha_f * self.qdd[i] - alpha_m * self.a[i]) / (1.0 - alpha_m)) / r;
        }
        let mut converged = false;
        let mut last = f64::INFINITY;
        let mut iterations = 0;
        for it in 0..30 {
            for i in 0..n {
                self.a1[i] = (alpha_f * self.qdd[i] - alpha_m * self.a[i]) / (1.0 - alpha_m)
                    + r * self.qdd1[i];
                self.q1[i] = self.q[i]
                    + h * self.qd[i]
                    + h * h * ((0.5 - beta) * self.a[i] + beta * self.a1[i]);
                self.qd1[i] = self.qd[i] + h * ((1.0 - gamma) * self.a[i] + gamma * self.a1[i]);
            }
            if converged {
                break;
            }
            self.chain
                .residual(t_law, &self.q1, &self.qd1, &self.qdd1, &mut self.res);
            self.counters.rhs += 1;
            self.counters.newton += 1;
            // The band matrix is cheap and fresh every step (near-quadratic convergence keeps the
            // iteration error far below the tolerance, which the tight ledger checks need); the
            // dense finite-difference matrix is reused across steps (modified Newton) while
            // Newton converges in ≤ 3 iterations and the step is unchanged.
            let fresh = self.jacobian == JacobianKind::Banded
                || self.matrix_h != h
                || self.slow_convergence;
            if (it == 0 && fresh) || it == 6 || it == 12 || it == 18 {
                self.form_matrix(c, t_law, t1)?;
                self.matrix_h = h;
                self.slow_convergence = false;
            }
            self.delta.copy_from_slice(&self.res);
            self.solve_matrix();
            let mut big = 0.0f64;
            for i in 0..n {
                self.qdd1[i] -= self.delta[i];
                big = big.max(self.delta[i].abs());
            }
            let dq = big * c.c_q;
            if !dq.is_finite() {
                break;
            }
            if it > 2 && dq > 10.0 * last {
                // Diverging: give up early, the caller retries with a shorter step.
                break;
            }
            last = dq;
            // Absolute tolerance, floored at the round-off level of the update itself.
            let amax = max_abs(&self.qdd1);
            let vmax = max_abs(&self.qd1);
            iterations = it + 1;
            if dq <= self.newton_tol + 1e-13 * (c.c_q * amax + h * vmax) {
                converged = true;
            }
        }
        self.slow_convergence = !converged || iterations > 3;
        if !converged {
            if self.adaptive.is_some() || h > 1e-6 * self.h_nominal {
                return Ok(Some(f64::INFINITY));
            }
            return Err(FemError::Runaway {
                t: self.t,
                what: format!("Newton iteration did not converge (last update {last:.3e})"),
                location: None,
                why: "the step is too large for the nonlinearity or the solution diverged".into(),
                remedy: "reduce --dt or give --rtol for adaptive stepping".into(),
            });
        }
        Ok(self.adaptive.map(|ad| {
            let mut err = 0.0f64;
            for i in 0..n {
                let e = h * h * (beta - 1.0 / 6.0) * (self.qdd1[i] - self.qdd[i]);
                err = err.max(e.abs() / (ad.atol + ad.rtol * self.q1[i].abs()));
            }
            err
        }))
    }

    /// One explicit central-difference step.
    fn central_step(&mut self, h: f64, t1: f64, t_law: f64) -> Result<Option<f64>, FemError> {
        let n = self.q.len();
        for i in 0..n {
            let half = self.qd[i] + 0.5 * h * self.qdd[i];
            self.q1[i] = self.q[i] + h * half;
            self.qd1[i] = half + 0.5 * h * self.qdd[i];
            self.qdd1[i] = self.qdd[i];
        }
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.0,
            c_q: 0.0,
        };
        // M(q1) q̈1 = −rest: R is affine in q̈; iterate on the mass-matrix approximation.
        for it in 0..20 {
            self.chain
                .residual(t_law, &self.q1, &self.qd1, &self.qdd1, &mut self.res);
            self.counters.rhs += 1;
            if it == 0 {
                self.form_matrix(c, t_law, t1)?;
                self.matrix_h = f64::NAN;
            }
            self.delta.copy_from_slice(&self.res);
            self.solve_matrix();
            let (mut big, mut amax) = (0.0f64, 0.0f64);
            for i in 0..n {
                self.qdd1[i] -= self.delta[i];
                big = big.max(self.delta[i].abs());
                amax = amax.max(self.qdd1[i].abs());
            }
            if !big.is_finite() || big <= 1e-12 * amax.max(1e-12) {
                break;
            }
        }
        for i in 0..n {
            self.qd1[i] = self.qd[i] + 0.5 * h * (self.qdd[i] + self.qdd1[i]);
            self.a1[i] = self.qdd1[i];
        }
        Ok(None)
    }

    /// Forms and factorizes the Newton matrix at (q1, q̇1, q̈1) after a residual evaluation there.
    pub(crate) fn form_matrix(
        &mut self,
        c: NewtonCoefficients,
        t_law: f64,
        t: f64,
    ) -> Result<(), FemError> {
        self.counters.jacobians += 1;
        self.counters.factorizations += 1;
        match self.jacobian {
            JacobianKind::Banded => {
                self.chain.newton_matrix(&self.q1, c, &mut self.matrix);
                self.matrix.factorize().map_err(|e| with_time(e, t))
            }
            JacobianKind::DenseFiniteDifference => {
                let n = self.q.len();
                // Column j: directional difference along (c_q, c_v, 1)·e_j in (q, q̇, q̈).
                // Forward difference with ε relative to the acceleration scale: error O(ε)
                // in the matrix only slows Newton, never changes its converged answer.
                let amax = self.qdd1.iter().fold(1.0f64, |a, b| a.max(b.abs()));
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
                    // physical scale: crate::massless). The residual is affine in q̈ and the
                    // velocity terms are smooth on that scale, while the position perturbation
                    // c_q·ε must stay far above the round-off of q: with ε = 1e-7 a_max (below)
                    // it fell to 1e-13..1e-16 on short steps, the columns of the massless and
                    // almost massless directions (damping and stiffness only) were round-off,
                    // and freshly formed matrices diverged. Measured on
                    // `barhorst-case1-timoshenko` (8 elements, dt = 2.5e-5, 0.27 s of free
                    // fall): 38, 23, 0, 0 rejected steps at ε ×1, ×10, ×100, ×1000 of the
                    // rule below with its floor.
                    let vmax = self.qd1.iter().fold(1.0f64, |a, b| a.max(b.abs()));
                    (1e-5 * amax).max(1e-6 * vmax / c.c_v)
                } else {
                    // Floor: the velocity perturbation c_v·ε stays above 1e-8 of the velocity
                    // scale. Steps shortened to locate an event (h → 1e-13 s) otherwise perturb
                    // q̇ and q below their round-off, and the columns of massless directions
                    // (no mass, only damping and stiffness) vanish: a singular matrix.
                    let vmax = self.qd1.iter().fold(1.0f64, |a, b| a.max(b.abs()));
                    // Only there (h < 1e-3 h_nominal): on regular steps the floor moved
                    // measured trajectories (Newton's accepted iterate depends on the matrix
                    // within the tolerance: conv_timoshenko_stiff_shear_recovers_the_euler_chain).
                    let floor = if c.c_v > 0.0 && c.c_v < 0.5e-3 * self.h_nominal {
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
                self.fd_q.copy_from_slice(&self.q1);
                self.fd_qd.copy_from_slice(&self.qd1);
                self.fd_qdd.copy_from_slice(&self.qdd1);
                for j in 0..n {
                    self.fd_q[j] += c.c_q * eps;
                    self.fd_qd[j] += c.c_v * eps;
                    self.fd_qdd[j] += eps;
                    self.chain.residual(
                        t_law,
                        &self.fd_q,
                        &self.fd_qd,
                        &self.fd_qdd,
                        &mut self.fd_res,
                    );
                    self.fd_q[j] = self.q1[j];
                    self.fd_qd[j] = self.qd1[j];
                    self.fd_qdd[j] = self.qdd1[j];
                    for i in 0..n {
                        self.fd_res[i] = (self.fd_res[i] - self.res[i]) / eps;
                    }
                    dense.set_column(j, &self.fd_res);
                }
                self.counters.rhs += n;
                // Restore the chain's cached state (joint torques) at the unperturbed point.
                self.chain
                    .residual(t_law, &self.q1, &self.qd1, &self.qdd1, &mut self.fd_res);
                dense.factorize().map_err(|e| with_time(e, t))
            }
        }
    }

    pub(crate) fn solve_matrix(&mut self) {
        match (&self.jacobian, &self.dense) {
            (JacobianKind::DenseFiniteDifference, Some(d)) => d.solve_in_place(&mut self.delta),
            _ => self.matrix.solve_in_place(&mut self.delta),
        }
    }

    /// Largest natural frequency of the linearized system at the current state (power iteration
    /// on M⁻¹K with the band solver) and the DOF where its mode is largest.
    pub fn max_frequency(&mut self) -> Result<(f64, usize), FemError> {
        let n = self.q.len();
        self.chain
            .residual(self.t, &self.q, &self.qd, &self.qdd, &mut self.res);
        let mut kmat = self.chain.new_matrix();
        self.chain.newton_matrix(
            &self.q,
            NewtonCoefficients {
                c_a: 0.0,
                c_v: 0.0,
                c_q: 1.0,
            },
            &mut kmat,
        );
        let mut mmat = self.chain.new_matrix();
        self.chain.newton_matrix(
            &self.q,
            NewtonCoefficients {
                c_a: 1.0,
                c_v: 0.0,
                c_q: 0.0,
            },
            &mut mmat,
        );
        let mut mfac = mmat.clone();
        mfac.factorize()?;
        let mut x: Vec<f64> = (0..n)
            .map(|i| 1.0 + 0.1 * ((i * 7919) % 13) as f64)
            .collect();
        let mut y = vec![0.0; n];
        let mut mx = vec![0.0; n];
        let mut lam = 0.0;
        for _ in 0..2000 {
            kmat.matvec(&x, &mut y);
            mfac.solve_in_place(&mut y);
            // Rayleigh quotient xᵀK x / xᵀM x.
            kmat.matvec(&x, &mut mx);
            let xkx = dot(&x, &mx);
            mmat.matvec(&x, &mut mx);
            let xmx = dot(&x, &mx);
            let new = xkx / xmx;
            let norm = max_abs(&y);
            if norm == 0.0 || !norm.is_finite() {
                break;
            }
            for i in 0..n {
                x[i] = y[i] / norm;
            }
            if (new - lam).abs() <= 1e-10 * new.abs() {
                lam = new;
                break;
            }
            lam = new;
        }
        let arg = (0..n)
            .max_by(|&a, &b| x[a].abs().total_cmp(&x[b].abs()))
            .unwrap_or(0);
        Ok((lam.max(0.0).sqrt(), arg))
    }
}

fn with_time(e: FemError, t: f64) -> FemError {
    match e {
        FemError::Singular { what, pivot, .. } => FemError::Singular { what, pivot, t },
        other => other,
    }
}
