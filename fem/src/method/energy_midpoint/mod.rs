//! Energy-consistent midpoint scheme (`energy-midpoint`) for chains whose joints are all free.
//!
//! State (q, v), energy E(q, v) = ½vᵀM(q)v + V(q) with V = strain + joint springs + gravity, and
//! non-conservative generalized forces Q(t, q, v) (applied joint torques and loads, joint
//! dampers, Kelvin–Voigt). One step t₀ → t₁ = t₀ + h solves, for v₁,
//!
//!   q₁ − q₀ = h v̄,   v̄ = ½(v₀ + v₁),
//!   M(q₁)v₁ − M(q₀)v₀ = −h ∇̄Φ + h Q(t₀ + h/2, q̄, v̄),   q̄ = ½(q₀ + q₁),
//!
//! with Φ(q) = V(q) − g(q), g(q) = ½v₀ᵀM(q)v₁ (v₀, v₁ frozen) and ∇̄ the Gonzalez discrete
//! gradient in the metric W = M(q̄):
//!
//!   ∇̄Φ = ∇Φ(q̄) + [(Φ(q₁) − Φ(q₀) − ∇Φ(q̄)·Δq) / (ΔqᵀWΔq)] WΔq   (no correction if Δq = 0).
//!
//! Energy identity: with p = M(q)v, v̄ᵀ(p₁ − p₀) = ΔT + Δg (M symmetric), and Δqᵀ∇̄Φ = ΔΦ exactly,
//! so v̄ᵀ(momentum equation) gives E₁ − E₀ = Δqᵀ Q(t_mid, q̄, v̄) exactly — to the Newton
//! tolerance and round-off. The backend books the works with that same midpoint quadrature
//! (applied torque τ(t_mid)Δθ, joint damper D θ̄̇Δθ, Kelvin–Voigt h v̄ᵀC v̄, applied loads
//! Q_load(q̄)·Δq), so the ledger closes by construction. The scheme is symmetric and second
//! order: ∇g(q) = ½∇(v₀ᵀMv₁) approximates ∂T/∂q|_v̄, i.e. it discretizes Lagrange's equations.
//!
//! Ingredients, each one O(n) pass of [`System::residual_parts`]:
//! * M(q)x = R_in(q, 0, x) (inertial part only, exact: R is affine in q̈);
//! * ∂T/∂q(q, x) analytic, one forward and one backward sweep
//!   ([`System::add_kinetic_gradient`]; the chain's: T written in link-frame coordinates,
//!   reverse sweep of the velocity recursion). The identity R_in(q, x, 0) = Ṁ(x)x − ∂T/∂q
//!   with a central difference for Ṁ(x)x ([`kinetic_gradient_fd`], 3 inertial passes) is
//!   its test oracle;
//! * ∇g(q̄) = ∂T/∂q(q̄, a) − ∂T/∂q(q̄, b), a = v̄, b = ½(v₁ − v₀) (polarization);
//! * ∇V(q̄) = conservative part; Q = −(non-conservative part). Both on the kinematic pass of
//!   the metric product M(q̄)Δq ([`System::residual_parts_at_last_q`]: positions and frame
//!   angles depend on q̄ alone), so an iteration makes one kinematic pass at q̄ instead of
//!   three;
//! * V(q₁) on the kinematic pass of the momentum M(q₁)v₁ ([`System::potential_at_last_q`]),
//!   and T₁ = ½v₁ᵀ(M(q₁)v₁) from that momentum, so the end point takes one pass.
//!
//! Newton on the mean acceleration a = (v₁ − v₀)/h with the generalized-α matrix machinery at
//! (q̄, v̄, a): S = M + (h/2)C + (h²/4)K (∂q̄/∂a = h²/4, ∂v̄/∂a = h/2), analytic — the
//! bordered band, or for chains with foreshortening the exact augmented bordered band
//! ([`crate::chain::AugmentedLayout`]) — and formed at the first iteration of a step. S is
//! the derivative of R(q̄, v̄, a), not of the discrete equations, and the correction term is not
//! differentiated (quasi-Newton), so convergence is linear — about 1e-2..1e-3 per iteration.
//! The matrix is re-formed every 6th iteration only while the update is above tolerance: the
//! iterations that only reduce the energy defect keep it, as it still contracts. Runs without
//! contact accelerate the iteration (Anderson, depth 3, history restarted with every step
//! and new matrix; `Anderson`).
//! The predictor (the first iterate of a step, `MidpointWork::predict`) without a unilateral
//! contact, once the last three steps were accepted since the last (re)start (every event and
//! law discontinuity restarts), each with a regular contraction (θ ≤ ½ at every iteration, at
//! most 8 iterations), and no solve from the step's start has failed:
//!
//!   ā_{k+1} = ā_{k−1} + (ā_k − ā_{k−2})·(h_{k+1} + 2h_k + h_{k−1})/(h_k + 2h_{k−1} + h_{k−2}),
//!
//! the mean accelerations taken at their step midpoints. It is exact for a mean acceleration
//! linear in time plus a component that flips sign every step: the midpoint rule maps the
//! unresolved stiff modes (ωh ≫ 1, undamped or Kelvin–Voigt) to the amplification −1, and
//! these sawtooth components dominate the step-to-step change of ā on the arms. Constant
//! extrapolation leaves twice their amplitude in the first iterate, linear extrapolation from
//! the last two steps four times. Where the contraction is slow (stiff shear under a reused
//! matrix), a first iterate that close gives a first update within tolerance before θ is
//! measured, and the iteration would stop short: those stretches keep the previous step's ā.
//! Otherwise the previous step's ā, zero after a (re)start.
//! `Predictor::Previous` keeps the previous step's ā throughout (a reference for tests).
//! Without contact and with a unilateral contact, a step reuses the factorized matrix of an
//! earlier step (the same step size up to round-off, `SAME_STEP`; with a contact up to
//! `CLOSE_STEP`; formed by this scheme) for up to `MAX_MATRIX_AGE` steps, while the last step
//! needed at most one iteration more than the last step with a fresh matrix: over a step S
//! changes by O(h), far less than the mismatch of the undifferentiated terms that already sets
//! the contraction.
//! With a unilateral contact the free and the constrained phases alike reuse it (the
//! constraint borders S through its Schur complement, S itself is the same); every contact
//! event restarts the scheme with a fresh matrix, and the trials of an event location, which
//! re-solve one stretch with lengths that approach each other, reuse the matrix of a trial
//! within `CLOSE_STEP` of their length and start from that trial's mean acceleration.
//! The convergence test weighs the update by the iteration's contraction θ (ratio of successive
//! updates under one matrix): past θ = ½ the remaining error dq/(1 − θ) must be within twice the
//! tolerance, so a slowly contracting reused matrix (stiff shear) iterates on instead of
//! stopping at a small update. Matrices and iterations per step on the free arms are in
//! `docs/backends.md`.
//! The iterate is accepted at the point where the residual was evaluated, so the
//! booked energies and works are those of the equations actually solved.
//!
//! Tip contact ([`crate::events::contact`], through [`StepConstraint`]): in a constrained phase the momentum equation gains
//! −∇̄g λ (∇̄g the discrete gradient of the gap, same metric and formula as for Φ) and the
//! unknowns become (a, λ) with g(q₁) = 0 (a step shortened to h < h_nominal aims at
//! (1 − (h/h_nominal)²)·g(q₀) instead: λ finite as h → 0), ∂q₁/∂a = h²/2; each iteration solves S twice
//! (Schur complement of the border). Shortened steps that locate an event re-form the Newton
//! matrix every iteration (impulsive multipliers spoil the quasi-Newton contraction).
//!
//! Runs with a unilateral tip contact (`NewtonSystem::unilateral_contact`; other runs are
//! unchanged) step through impacts, releases and grazing contacts, where the iteration starts
//! far from the solution and at step lengths down to 1e-13 s. There:
//! * a matrix formed at an earlier iterate or step is re-formed at the current iterate as soon
//!   as an update is not 5× smaller than the previous one (where the update grew it is not
//!   applied); the first update of such a fresh matrix may be larger than the stalled ones
//!   (no divergence test on it), an update larger than a link length is a failure, and a
//!   singular matrix at an iterate is a Newton failure (the stretch is retried shorter);
//! * the iterate is accepted once the update is within tolerance and the next one is larger
//!   (round-off noise while the energy defect is being reduced; a new matrix there only added
//!   noise, and its larger update was taken for divergence);
//! * the predictor is the previous mean acceleration, not the extrapolation above (here it
//!   saves iterations but not run time, which event location, contact forces and matrices
//!   take, and it reorders micro-bounces), and only if that step was not 10× shorter
//!   (a located event just before: its mean acceleration is close to the point value, which is
//!   huge right after an impact);
//! * constrained steps shortened to locate an event rely on the refresh above instead of a new
//!   matrix every iteration.
//!
//! The failures and rejected steps these rules remove on `barhorst-case1-timoshenko`, and the
//! figures above: docs/contact.md, "fem contact: the measurements behind the design".
//!
//! Adaptive steps (`rtol`): local error estimate e = (h²/12)(ā_k − ā_{k−1})·2h_k/(h_k + h_{k−1})
//! (third-derivative term of the trapezoidal/midpoint family, from successive mean
//! accelerations), step ratio 0.9·err^(−1/3) as for generalized-α.

use crate::error::FemError;
mod anderson;
mod gradients;
mod iteration;
mod work;

pub use gradients::{FD_STEP, kinetic_gradient, kinetic_gradient_fd, mass_product};
pub use work::{MidpointWork, Predictor};

use crate::method::{
    Capabilities, MethodParams, StepConstraint, StepContext, Stepper, Trial, Works, unconverged,
};
use crate::system::System;
use iteration::{Iteration, MAX_ITERATIONS, Verdict};
use work::{MOMENTUM_PASSES, form_matrix, solve_update};

/// The energy-consistent midpoint scheme (module docs) with its work buffers.
#[derive(Debug, Clone)]
pub struct EnergyMidpoint {
    pub work: MidpointWork,
}

impl From<MethodParams> for EnergyMidpoint {
    fn from(p: MethodParams) -> Self {
        EnergyMidpoint::new(p.n)
    }
}

impl EnergyMidpoint {
    /// Registry entry: what the method supports.
    pub const CAPABILITIES: Capabilities = Capabilities {
        explicit: false,
        adaptive: true,
        prescribed_joints: false,
        held_constraint: true,
        bilateral_constraint: true,
        projects_massless: true,
        variable_mass: false,
    };

    pub fn new(n: usize) -> Self {
        EnergyMidpoint {
            work: MidpointWork::new(n),
        }
    }
}

impl<S: System + ?Sized> Stepper<S> for EnergyMidpoint {
    /// One energy-midpoint step; returns the scaled error estimate when adaptive (infinite when
    /// Newton failed). A held `constraint` borders the Newton system (module docs).
    ///
    /// Phases: the step's fixed data (`begin`), the predictor (`predict`), then per Newton
    /// iteration the iterate (`set_iterate`), its momentum residual (`momentum_residual`) with
    /// the constraint force, the Newton matrix when due (`form_matrix`), the update
    /// (`solve_update`), its test (`Iteration::judge`) and the next iterate (`apply_update`);
    /// finally the matrix bookkeeping, the accepted step's works and the error estimate.
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        mut constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Trial, FemError> {
        let w = &mut self.work;
        let robust = cx.newton.unilateral_contact;
        let setup = w.begin(cx, constraint.as_deref(), h, t1);
        // Residual passes: p₀ and the start energies so far.
        let mut passes = 2usize;
        let mut lambda = constraint.as_ref().map_or(0.0, |c| c.multiplier());
        let mut gap1 = 0.0;
        w.predict(cx.state, h, robust);
        // Anderson acceleration where the quasi-Newton map is smooth: no contact (impacts and
        // releases keep the unilateral-contact iteration's own safeguards; a bordered (a, λ)
        // system updates λ beside a).
        let accelerate = !robust && constraint.is_none();
        let reusable = accelerate || robust;
        let reuse = reusable && w.may_reuse(cx.newton, h, robust);
        // Constrained steps shortened to locate an event re-form the matrix every iteration
        // without a unilateral contact (their impulsive multipliers make the quasi-Newton
        // contraction poor; the unilateral contact refreshes stale matrices instead).
        let refresh = !robust && constraint.is_some() && h < 0.999 * cx.h_nominal;
        let mut iter = Iteration::new();
        for it in 0..MAX_ITERATIONS {
            w.set_iterate(cx.state, h);
            let (denom, scale1) = w.momentum_residual(cx.system, cx.state, &setup);
            passes += MOMENTUM_PASSES;
            if let Some(c) = constraint.as_deref_mut() {
                gap1 = w.add_constraint_force(c, cx.system, cx.state, &setup, it, denom, lambda);
            }
            cx.counters.newton += 1;
            if iter.wants_matrix(it, reuse, refresh) {
                iter.formed(it);
                passes += 1;
                if !form_matrix(w, cx, &setup)? {
                    break;
                }
            }
            let dlambda = solve_update(cx.newton, constraint.as_deref_mut(), &w.res, &setup, gap1);
            let m = w.measure(cx, &setup, scale1, gap1);
            match iter.judge(it, &m, robust, cx.length_scale) {
                Verdict::Converged => {
                    iter.converged = true;
                    break;
                }
                Verdict::Failed => break,
                Verdict::Refresh => continue,
                Verdict::Apply => {}
            }
            // A new matrix or a new step is a new fixed-point map.
            let new_map = it == 0 || iter.formed_it == Some(it);
            w.apply_update(cx.state, &cx.newton.delta, accelerate, new_map);
            lambda -= dlambda;
        }
        if let Some(c) = constraint.filter(|_| iter.converged) {
            c.set_multiplier(lambda);
        }
        cx.counters.rhs += passes;
        w.book_matrix(&iter, reusable);
        // See the module docs: the linear contraction makes > 3 iterations normal here.
        cx.newton.slow_convergence = !iter.converged || iter.iterations > 8;
        if !iter.converged {
            w.failed = true;
            let st = &*cx.state;
            // Its energy-defect test can stall at a round-off floor that a shorter step raises
            // (massless sections without Kelvin–Voigt: docs/limits.md).
            return unconverged(
                cx.adaptive.is_some(),
                cx.h_nominal,
                st.t,
                h,
                iter.last,
                "; if shorter steps fail too, use --method implicit-midpoint or generalized-alpha",
            );
        }
        w.regular_solve = iter.max_theta <= 0.5 && iter.iterations <= 8;
        w.accept(cx, &setup, robust, t_law);
        Ok(Trial::Converged {
            error: cx.adaptive.map(|ad| w.error_estimate(cx.state, h, ad)),
        })
    }

    fn commit(&mut self, h: f64, works: &mut Works) -> bool {
        self.work.commit(h, works);
        true
    }

    fn restart(&mut self) {
        self.work.restart();
    }
}
