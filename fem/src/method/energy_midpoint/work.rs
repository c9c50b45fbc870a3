//! The step's work buffers and its phases: the fixed data of a step, the predictor, the
//! iterate, its discrete-gradient momentum residual and constraint force, the Newton matrix and
//! update, the accepted step's works and the error estimate.

use crate::error::FemError;
use crate::linalg::{dot, max_abs};
use crate::method::{
    Adaptive, ConstraintView, NewtonSystem, StepConstraint, StepContext, StepState, Works,
    update_tolerance,
};
use crate::system::{NewtonCoefficients, Parts, System};

use super::anderson::Anderson;
use super::iteration::{Iteration, Measured};

/// Steps at most that reuse one Newton matrix in runs without contact.
pub(super) const MAX_MATRIX_AGE: usize = 8;
/// Relative difference of step sizes up to which a unilateral-contact run reuses a Newton
/// matrix: steps that land on output times (the stop time minus the start time, off the
/// nominal step by the round-off of t: 2e-12 of a 0.5 ms step at t = 3) and the trials of an
/// event location, which re-solve one stretch with lengths that approach each other. S changes
/// by about 2Δh/h in its stiffness part, and a matrix that then contracts too slowly is
/// re-formed by the stale-matrix refresh.
pub(super) const CLOSE_STEP: f64 = 0.02;
/// Relative difference of two step sizes that counts as the same step in runs without
/// contact: a step that lands on an output time is the stop time minus the start time, off
/// the nominal step by the round-off of t (2e-12 of a 0.5 ms step at t = 3). Compared bit for
/// bit, that step and the full step after it each formed a new matrix (`barhorst-case1`
/// without its contact table, 5 elements, dt 2.5e-4: 5 998 matrices in 12 000 steps against
/// 1 346 with this tolerance, 0.66 against 0.45 s; docs/backends.md).
pub(super) const SAME_STEP: f64 = 1e-9;
/// The predictor of a step's mean acceleration in runs without a unilateral contact, once
/// three regular steps have been accepted since the last (re)start (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Predictor {
    /// The previous step's mean acceleration.
    Previous,
    /// Extrapolated from the last three mean accelerations (the default; module docs).
    Extrapolated,
}

/// Work buffers of the midpoint step (allocated once per run).
#[derive(Debug, Clone)]
pub struct MidpointWork {
    /// p₀ = M(q₀)v₀.
    pub(super) p0: Vec<f64>,
    pub(super) qbar: Vec<f64>,
    pub(super) vbar: Vec<f64>,
    /// b = ½(v₁ − v₀).
    pub(super) half_dv: Vec<f64>,
    pub(super) dq: Vec<f64>,
    /// M(q₁)v₁.
    pub(super) mv1: Vec<f64>,
    /// ∇V(q̄).
    pub(super) grad_v: Vec<f64>,
    /// Non-conservative part of R at (q̄, v̄): −Q.
    pub(super) minus_q: Vec<f64>,
    /// ∇g(q̄).
    pub(super) grad_g: Vec<f64>,
    /// W Δq = M(q̄)Δq.
    pub(super) w_dq: Vec<f64>,
    /// Residual of the momentum equation divided by h.
    pub(super) res: Vec<f64>,
    pub(super) zero: Vec<f64>,
    /// Whether the previous step's mean acceleration is in `StepState::qdd` (else it holds
    /// the point acceleration of a (re)start), and that step's length.
    pub(super) have_prev: bool,
    pub(super) h_prev: f64,
    /// The mean accelerations of the two steps before the previous one, ā_{k−1} and ā_{k−2},
    /// and their lengths; `older_count` of them were accepted since the last (re)start.
    pub(super) older: [Vec<f64>; 2],
    pub(super) h_older: [f64; 2],
    pub(super) older_count: usize,
    /// Whether the last converged solve contracted regularly (θ ≤ ½ throughout, at most 8
    /// iterations), and the regular steps accepted in a row since the last (re)start.
    pub(super) regular_solve: bool,
    pub(super) regular_run: usize,
    /// `StepState::qdd` at the start of the last converged solve: `older[0]` once that solve
    /// is accepted.
    pub(super) start_a: Vec<f64>,
    /// Whether a solve from the current start failed since the last accepted step.
    pub(super) failed: bool,
    /// The predictor once three steps are accepted (runs without a unilateral contact).
    pub predictor: Predictor,
    /// The last converged solve that was not accepted (a trial of an event location re-solves
    /// the same stretch with another length): its start time, start velocity, length and mean
    /// acceleration, the predictor of the next re-solve from the same start.
    pub(super) resolve: Option<(f64, f64)>,
    pub(super) resolve_qd: Vec<f64>,
    pub(super) resolve_a: Vec<f64>,
    /// Anderson acceleration of the quasi-Newton iteration (runs without contact).
    pub(super) anderson: Anderson,
    /// Steps solved with the current Newton matrix since it was formed by this stepper in a
    /// run without contact (`None`: no matrix this stepper may reuse).
    pub(super) matrix_age: Option<usize>,
    /// Iterations of the last step that formed its matrix at its first iteration, and of the
    /// last step.
    pub(super) fresh_iterations: usize,
    pub(super) last_iterations: usize,
    /// Works of the step being taken, added to the ledger on acceptance.
    pub(super) pending: Works,
    /// Last Gonzalez correction factor relative to the midpoint-gradient work (diagnostic).
    pub last_correction: f64,
}

impl MidpointWork {
    pub fn new(n: usize) -> Self {
        let z = vec![0.0; n];
        MidpointWork {
            p0: z.clone(),
            qbar: z.clone(),
            vbar: z.clone(),
            half_dv: z.clone(),
            dq: z.clone(),
            mv1: z.clone(),
            grad_v: z.clone(),
            minus_q: z.clone(),
            grad_g: z.clone(),
            w_dq: z.clone(),
            res: z.clone(),
            zero: z,
            anderson: Anderson::new(n),
            matrix_age: None,
            fresh_iterations: 0,
            last_iterations: 0,
            have_prev: false,
            h_prev: 0.0,
            older: [vec![0.0; n], vec![0.0; n]],
            h_older: [0.0; 2],
            older_count: 0,
            regular_solve: false,
            regular_run: 0,
            start_a: vec![0.0; n],
            failed: false,
            predictor: Predictor::Extrapolated,
            resolve: None,
            resolve_qd: vec![0.0; n],
            resolve_a: vec![0.0; n],
            pending: Works::default(),
            last_correction: 0.0,
        }
    }

    /// Forget the previous step (restart at a torque-law discontinuity).
    pub fn restart(&mut self) {
        self.have_prev = false;
        self.h_prev = 0.0;
        self.older_count = 0;
        self.regular_run = 0;
        self.failed = false;
        self.resolve = None;
        self.matrix_age = None;
    }

    /// Adds the accepted step's works to the ledger integrals.
    pub fn commit(&mut self, h: f64, works: &mut Works) {
        let p = self.pending;
        works.applied_torque += p.applied_torque;
        works.applied_load += p.applied_load;
        works.joint_damper += p.joint_damper;
        works.kelvin_voigt += p.kelvin_voigt;
        // The accepted step started from the previous step's mean acceleration (a point
        // acceleration right after a (re)start, which is not kept).
        self.older.swap(0, 1);
        std::mem::swap(&mut self.older[0], &mut self.start_a);
        self.h_older = [self.h_prev, self.h_older[0]];
        self.older_count = if self.have_prev {
            (self.older_count + 1).min(2)
        } else {
            0
        };
        self.regular_run = if self.regular_solve {
            self.regular_run + 1
        } else {
            0
        };
        self.have_prev = true;
        self.h_prev = h;
        self.failed = false;
        self.resolve = None;
    }
}

/// Residual passes of [`MidpointWork::momentum_residual`]: M(q₁)v₁, W Δq, ∇V, −Q and the two
/// kinetic gradients (V(q₁) reuses the first one's kinematics).
pub(super) const MOMENTUM_PASSES: usize = 6;

/// What one step keeps fixed over its Newton iteration.
pub(super) struct StepSetup {
    pub(super) h: f64,
    pub(super) t0: f64,
    /// t₀ + h/2, where the laws and the forces are sampled.
    pub(super) t_mid: f64,
    pub(super) t1: f64,
    /// V(q₀) and the energy scale |T₀| + Σ|V parts(q₀)| of the energy-defect test.
    pub(super) v0_pot: f64,
    pub(super) scale0: f64,
    /// Constraint value g(q₀) and the target of g(q₁) (0 for a full step).
    pub(super) g0: f64,
    pub(super) gap_target: f64,
    /// S = M + (h/2)C + (h²/4)K: ∂q̄/∂a = h²/4, ∂v̄/∂a = h/2.
    pub(super) c: NewtonCoefficients,
}

impl MidpointWork {
    /// The step's fixed data: p₀ = M(q₀)v₀ (at t_mid, as M(q₁)v₁), the energies at the start,
    /// g(q₀) of a held constraint and the target of g(q₁), the Newton coefficients.
    pub(super) fn begin<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
    ) -> StepSetup {
        let st = &*cx.state;
        let t0 = st.t;
        // Laws are sampled at the midpoint: exact work for piecewise-constant torques, since
        // steps land on their breakpoints.
        let t_mid = t0 + 0.5 * h;
        cx.system.residual_parts(
            t_mid,
            &st.q,
            &self.zero,
            &st.qd,
            Parts::INERTIA,
            &mut self.p0,
        );
        let [k0, s0, sp0, gr0] = cx.system.energies(t0, &st.q, &st.qd);
        let g0 = constraint.map_or(0.0, |c| c.value(cx.system, t0, &st.q));
        // Target of g(q₁): 0 for a full step; a step shortened to h removes only the share
        // (h/h_nominal)² of the start gap (≤ the Newton tolerance), so that the multiplier
        // stays finite as h → 0 (it would carry g(q₀)/h² otherwise; ∝ 2g(q₀)/h_nominal² now)
        // and is continuous in h, as the release event function (`crate::events::contact`) needs.
        let r = (h / cx.h_nominal).min(1.0);
        StepSetup {
            h,
            t0,
            t_mid,
            t1,
            v0_pot: s0 + sp0 + gr0,
            scale0: k0.abs() + s0.abs() + sp0.abs() + gr0.abs(),
            g0,
            gap_target: g0 * (1.0 - r * r),
            c: NewtonCoefficients {
                c_a: 1.0,
                c_v: 0.5 * h,
                c_q: 0.25 * h * h,
            },
        }
    }

    /// The predictor of the mean acceleration a into `st.qdd1`: a re-solve of the same stretch
    /// (same start time and velocity, a length within a factor 1.5 of the last converged
    /// solve, unilateral-contact runs) starts from that solve's a — the trials of an event
    /// location differ by less than the step that predicts them. Without a unilateral contact,
    /// once three steps have been accepted since the last (re)start and no solve from this
    /// start has failed, the extrapolation of [`Self::extrapolation`]. Otherwise the previous
    /// step's mean acceleration; zero after a (re)start, where the point acceleration of a
    /// released pre-loaded spring is a mesh-dependent spike, and (`robust`) after a step more
    /// than 10× shorter (a located event just before): its mean acceleration is close to the
    /// point value, which after an impact carries the mesh modes (measured 5e6 at the tip node
    /// 2 µs after an impact, a predicted velocity change of 1e3 ft/s over the next 0.43 ms
    /// step, which diverged).
    pub(super) fn predict(&self, st: &mut StepState, h: f64, robust: bool) {
        let predict = self.have_prev && (!robust || self.h_prev >= 0.1 * h);
        let t0 = st.t;
        let re_solve = robust
            && self.resolve.is_some_and(|(t_start, h_solved)| {
                t_start.to_bits() == t0.to_bits() && (h_solved - h).abs() <= 0.5 * h
            })
            && self
                .resolve_qd
                .iter()
                .zip(&st.qd)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        let ratio = self.extrapolation(h, robust);
        let [a1, a2] = &self.older;
        for i in 0..st.q.len() {
            st.qdd1[i] = if re_solve {
                self.resolve_a[i]
            } else if let Some(r) = ratio {
                a1[i] + (st.qdd[i] - a2[i]) * r
            } else if predict {
                st.qdd[i]
            } else {
                0.0
            };
        }
    }

    /// The ratio r of the extrapolation ā_{k+1} = ā_{k−1} + (ā_k − ā_{k−2})·r (module docs)
    /// for a step of length h, r = (h + 2h_k + h_{k−1})/(h_k + 2h_{k−1} + h_{k−2}) — the
    /// distance between the midpoints of steps k+1 and k−1 over that of steps k and k−2 — where
    /// it applies: [`Predictor::Extrapolated`], no unilateral contact (`robust`), ā_k, ā_{k−1}
    /// and ā_{k−2} accepted since the last (re)start from regularly contracting solves (module
    /// docs), no failed solve from this start, and
    /// r ≤ 2 (no reach beyond twice the span of the data).
    pub(super) fn extrapolation(&self, h: f64, robust: bool) -> Option<f64> {
        if self.predictor != Predictor::Extrapolated
            || robust
            || !self.have_prev
            || self.older_count < 2
            || self.regular_run < 3
            || self.failed
        {
            return None;
        }
        let [h1, h2] = self.h_older;
        let r = (h + 2.0 * self.h_prev + h1) / (self.h_prev + 2.0 * h1 + h2);
        (r <= 2.0).then_some(r)
    }

    /// Whether the step reuses the factorized matrix of an earlier step (module docs): formed
    /// by this stepper at the same step size (within `SAME_STEP`; `CLOSE_STEP` with a
    /// unilateral contact, `robust`), younger than `MAX_MATRIX_AGE` steps, and the last step
    /// took at most one iteration more than the last step with a fresh matrix. Every contact
    /// event restarts the stepper (a fresh matrix).
    pub(super) fn may_reuse<A>(&self, newton: &NewtonSystem<A>, h: f64, robust: bool) -> bool {
        let same_step = if robust { CLOSE_STEP } else { SAME_STEP };
        (newton.matrix_h - h).abs() <= same_step * h
            && !newton.slow_convergence
            && self.matrix_age.is_some_and(|age| age < MAX_MATRIX_AGE)
            && self.last_iterations <= self.fresh_iterations + 1
    }

    /// The iterate of the mean acceleration a = `st.qdd1`: v̄ = v₀ + (h/2)a, b = ½(v₁ − v₀) =
    /// (h/2)a, Δq = h v̄, q̄ = q₀ + Δq/2, q₁ = q₀ + Δq, v₁ = v₀ + h a.
    pub(super) fn set_iterate(&mut self, st: &mut StepState, h: f64) {
        for i in 0..st.q.len() {
            let a = st.qdd1[i];
            self.vbar[i] = st.qd[i] + 0.5 * h * a;
            self.half_dv[i] = 0.5 * h * a;
            self.dq[i] = h * self.vbar[i];
            self.qbar[i] = st.q[i] + 0.5 * self.dq[i];
            st.q1[i] = st.q[i] + self.dq[i];
            st.qd1[i] = st.qd[i] + h * a;
        }
    }

    /// The momentum residual of the iterate divided by h into `res` (module docs):
    ///
    ///   res = (M(q₁)v₁ − p₀)/h + ∇V(q̄) − ∇g(q̄) + corr·WΔq − Q(t_mid, q̄, v̄),
    ///   corr = (Φ(q₁) − Φ(q₀) − (∇V − ∇g)(q̄)·Δq) / (ΔqᵀWΔq),  Φ = V − ½v₀ᵀM v₁,
    ///
    /// with ∇g(q̄) = ∂T/∂q(q̄, v̄) − ∂T/∂q(q̄, ½Δv) and W = M(q̄). Returns ΔqᵀWΔq and the energy
    /// scale at the end, |T₁| + Σ|V parts(q₁)|; [`MOMENTUM_PASSES`] passes.
    pub(super) fn momentum_residual<S: System + ?Sized>(
        &mut self,
        system: &mut S,
        st: &StepState,
        setup: &StepSetup,
    ) -> (f64, f64) {
        let (h, t_mid) = (setup.h, setup.t_mid);
        // Momentum and potential at the end point.
        system.residual_parts(
            t_mid,
            &st.q1,
            &self.zero,
            &st.qd1,
            Parts::INERTIA,
            &mut self.mv1,
        );
        // V(q₁) on that pass's configuration; T₁ = ½q̇₁ᵀM(q₁)q̇₁ from the momentum just formed.
        let [s1, sp1, g1] = system.potential_at_last_q(setup.t1, &st.q1);
        let k1 = 0.5 * dot(&st.qd1, &self.mv1);
        let v1_pot = s1 + sp1 + g1;
        let scale1 = k1.abs() + s1.abs() + sp1.abs() + g1.abs();
        // Metric W = M(q̄) (the kinematic pass at q̄), then the forces at the midpoint on
        // its positions and frames.
        system.residual_parts(
            t_mid,
            &self.qbar,
            &self.zero,
            &self.dq,
            Parts::INERTIA,
            &mut self.w_dq,
        );
        system.residual_parts_at_last_q(
            t_mid,
            &self.qbar,
            &self.zero,
            Parts::CONSERVATIVE,
            &mut self.grad_v,
        );
        system.residual_parts_at_last_q(
            t_mid,
            &self.qbar,
            &self.vbar,
            Parts::NONCONSERVATIVE,
            &mut self.minus_q,
        );
        self.grad_g.iter_mut().for_each(|x| *x = 0.0);
        for (x, sign) in [(&self.vbar, 1.0), (&self.half_dv, -1.0)] {
            system.add_kinetic_gradient(t_mid, &self.qbar, x, sign, &mut self.grad_g);
        }
        let phi1 = v1_pot - 0.5 * dot(&st.qd, &self.mv1);
        let phi0 = setup.v0_pot - 0.5 * dot(&self.p0, &st.qd1);
        let mut grad_dq = 0.0;
        for i in 0..self.dq.len() {
            grad_dq += (self.grad_v[i] - self.grad_g[i]) * self.dq[i];
        }
        let denom = dot(&self.dq, &self.w_dq);
        let corr = if denom > 0.0 {
            (phi1 - phi0 - grad_dq) / denom
        } else {
            0.0
        };
        self.last_correction = if grad_dq != 0.0 {
            (phi1 - phi0 - grad_dq) / grad_dq
        } else {
            0.0
        };
        for i in 0..self.res.len() {
            self.res[i] = (self.mv1[i] - self.p0[i]) / h + self.grad_v[i] - self.grad_g[i]
                + corr * self.w_dq[i]
                + self.minus_q[i];
        }
        (denom, scale1)
    }

    /// Subtracts the constraint force of the iterate — the discrete gradient of g in the same
    /// metric (it does no work) — and friction, from the constraint itself, from `res`;
    /// returns g(q₁).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_constraint_force<S: System + ?Sized>(
        &mut self,
        constraint: &mut (dyn StepConstraint<S> + '_),
        system: &S,
        st: &StepState,
        setup: &StepSetup,
        it: usize,
        denom: f64,
        lambda: f64,
    ) -> f64 {
        let view = ConstraintView {
            it,
            t: [setup.t0, setup.t_mid, setup.t1],
            q0: &st.q,
            q1: &st.q1,
            qbar: &self.qbar,
            dq: &self.dq,
            w_dq: &self.w_dq,
            denom,
            g0: setup.g0,
            lambda,
        };
        constraint.add_force(system, &view, &mut self.res)
    }

    /// The size of the update in `newton.delta` and its tests ([`Measured`]); `scale1` from
    /// [`Self::momentum_residual`], `gap1` = g(q₁).
    pub(super) fn measure<S: System + ?Sized>(
        &self,
        cx: &StepContext<'_, S>,
        setup: &StepSetup,
        scale1: f64,
        gap1: f64,
    ) -> Measured {
        let (h, c) = (setup.h, setup.c);
        let st = &*cx.state;
        let big = max_abs(&cx.newton.delta);
        Measured {
            dq: big * c.c_q,
            // The state where the residual was evaluated is kept (the update is below
            // tolerance).
            tol: update_tolerance(cx.newton.tol, c.c_q, h, &st.qdd1, &st.qd1),
            // The energy balance of the step is off by exactly h v̄ᵀ(residual).
            defect: (h * dot(&self.vbar, &self.res)).abs(),
            e_scale: setup.scale0 + scale1 + dot(&self.minus_q, &self.dq).abs(),
            on_surface: (gap1 - setup.gap_target).abs() <= cx.newton.tol,
        }
    }

    /// The next iterate a ← a − δa, or with `accelerate` Anderson's extrapolation of it (its
    /// history restarted on a `new_map`).
    pub(super) fn apply_update(
        &mut self,
        st: &mut StepState,
        delta: &[f64],
        accelerate: bool,
        new_map: bool,
    ) {
        if accelerate {
            if new_map {
                self.anderson.reset();
            }
            self.anderson.advance(&mut st.qdd1, delta);
        } else {
            for (a, d) in st.qdd1.iter_mut().zip(delta) {
                *a -= d;
            }
        }
    }

    /// Matrix bookkeeping after a solve: the age of a matrix later steps may reuse (0 when
    /// this solve formed it, `None` when it failed or the run may not reuse), the iterations
    /// of the last step with a fresh matrix and of this step.
    pub(super) fn book_matrix(&mut self, iter: &Iteration, reusable: bool) {
        self.matrix_age = match iter.formed_it {
            _ if !(reusable && iter.converged) => None,
            Some(0) => {
                self.fresh_iterations = iter.iterations;
                Some(0)
            }
            Some(_) => Some(0),
            None => self.matrix_age.map(|age| age + 1),
        };
        self.last_iterations = iter.iterations;
    }

    /// The converged step: (`robust`) the solve kept as the predictor of a re-solve, the works
    /// with the scheme's own quadrature (their sum is Δqᵀ Q(t_mid, q̄, v̄); booked on
    /// acceptance), and the mean acceleration ā in the q̈ slot of the trial end (predictor and
    /// error estimate of the next step).
    pub(super) fn accept<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        setup: &StepSetup,
        robust: bool,
        t_law: f64,
    ) {
        let st = &mut *cx.state;
        self.start_a.copy_from_slice(&st.qdd);
        if robust {
            self.resolve = Some((setup.t0, setup.h));
            self.resolve_qd.copy_from_slice(&st.qd);
            self.resolve_a.copy_from_slice(&st.qdd1);
        }
        self.pending = cx.system.midpoint_works(
            setup.h,
            setup.t_mid,
            t_law,
            &self.dq,
            &self.vbar,
            &self.minus_q,
        );
        st.a1.copy_from_slice(&st.qdd1);
    }

    /// Scaled local error estimate max_i |e_i|/(atol + rtol|q₁ᵢ|), e = (h²/12)(ā_k − ā_{k−1})
    /// ·2h_k/(h_k + h_{k−1}) (module docs).
    pub(super) fn error_estimate(&self, st: &StepState, h: f64, ad: Adaptive) -> f64 {
        let ratio = 2.0 * h / (h + if self.have_prev { self.h_prev } else { 0.0 });
        let mut err = 0.0f64;
        for i in 0..st.q.len() {
            let e = h * h / 12.0 * (st.qdd1[i] - st.qdd[i]) * ratio;
            err = err.max(e.abs() / (ad.atol + ad.rtol * st.q1[i].abs()));
        }
        err
    }
}

/// Forms and factorizes the Newton matrix at (q̄, v̄, a): a full residual there fills the
/// system's point data the matrix reads; then q₁, v₁ are restored. Ok(false): a singular
/// matrix at an iterate far from the solution with a unilateral contact — a Newton failure
/// (the caller retries shorter), unless the step is already tiny.
pub(super) fn form_matrix<S: System + ?Sized>(
    w: &MidpointWork,
    cx: &mut StepContext<'_, S>,
    setup: &StepSetup,
) -> Result<bool, FemError> {
    let st = &mut *cx.state;
    let h = setup.h;
    st.q1.copy_from_slice(&w.qbar);
    st.qd1.copy_from_slice(&w.vbar);
    cx.system
        .residual(setup.t_mid, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
    if let Err(e) = cx
        .newton
        .form(cx.system, st, cx.counters, setup.c, setup.t1)
    {
        let robust = cx.newton.unilateral_contact;
        if robust && h > 1e-6 * cx.h_nominal && matches!(e, FemError::Singular { .. }) {
            return Ok(false);
        }
        return Err(e);
    }
    cx.newton.matrix_h = h;
    cx.newton.slow_convergence = false;
    for i in 0..st.q.len() {
        st.q1[i] = st.q[i] + w.dq[i];
        st.qd1[i] = st.qd[i] + h * st.qdd1[i];
    }
    Ok(true)
}

/// The Newton update δa into `newton.delta` from the residual `res`: S δa = res, or with a
/// held constraint the bordered (a, λ) system (the constraint's Schur complement, ∂q₁/∂a =
/// h²/2); returns δλ (0 without constraint).
pub(super) fn solve_update<S: System + ?Sized>(
    newton: &mut NewtonSystem<S::Augmented>,
    constraint: Option<&mut (dyn StepConstraint<S> + '_)>,
    res: &[f64],
    setup: &StepSetup,
    gap1: f64,
) -> f64 {
    if let Some(c) = constraint {
        let h = setup.h;
        return c.newton_update(newton, res, 0.5 * h * h, gap1, setup.gap_target);
    }
    newton.delta.copy_from_slice(res);
    newton.solve();
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean accelerations s + d·t_mid + (−1)^k c over steps of unequal lengths, t_mid the
    /// step midpoints: the extrapolation reproduces the next one to round-off (module docs);
    /// with a unilateral contact, after a restart or a failed solve it is not used.
    #[test]
    fn sys_midpoint_predictor_is_exact_for_a_linear_trend_plus_a_sawtooth() {
        let (s, d, c) = ([0.3, -2.0], [5.0, 40.0], [7.0, -1e3]);
        let hs = [1.0e-3, 0.9e-3, 1.2e-3, 1.5e-3];
        let mut mids = Vec::new();
        let mut t = 0.0;
        for h in hs {
            mids.push(t + 0.5 * h);
            t += h;
        }
        let abar = |k: usize| -> Vec<f64> {
            let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
            (0..2)
                .map(|i| s[i] + d[i] * mids[k] + sign * c[i])
                .collect()
        };
        let mut w = MidpointWork::new(2);
        let mut st = StepState::new(2);
        w.older = [abar(1), abar(0)];
        w.h_older = [hs[1], hs[0]];
        w.older_count = 2;
        w.regular_run = 3;
        w.have_prev = true;
        w.h_prev = hs[2];
        st.t = t - hs[3];
        st.qdd = abar(2);
        w.predict(&mut st, hs[3], false);
        let want = abar(3);
        for i in 0..2 {
            assert!(
                (st.qdd1[i] - want[i]).abs() <= 1e-12 * c[i].abs(),
                "{i}: {} against {}",
                st.qdd1[i],
                want[i]
            );
        }
        // The previous step's ā where the extrapolation does not apply.
        for (robust, failed, predictor) in [
            (true, false, Predictor::Extrapolated),
            (false, true, Predictor::Extrapolated),
            (false, false, Predictor::Previous),
        ] {
            w.failed = failed;
            w.predictor = predictor;
            w.predict(&mut st, hs[3], robust);
            assert_eq!(st.qdd1, st.qdd);
        }
        w.restart();
        w.predict(&mut st, hs[3], false);
        assert_eq!(st.qdd1, [0.0, 0.0]);
    }
}
