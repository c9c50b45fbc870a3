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
//! * ∇V(q̄) = conservative part; Q = −(non-conservative part); V(q₁) from [`System::energies`].
//!   Both on the kinematic pass of the metric product M(q̄)Δq
//!   ([`System::residual_parts_at_last_q`]: positions and frame angles depend on q̄ alone), so
//!   an iteration makes one kinematic pass at q̄ instead of three.
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
//! Without contact and with a unilateral contact, a step reuses the factorized matrix of an
//! earlier step (the same step size, with a contact up to `CLOSE_STEP`; formed by this scheme)
//! for up to `MAX_MATRIX_AGE` steps, while the last step needed at most one
//! iteration more than the last step with a fresh matrix: over a step S changes by O(h), far
//! less than the mismatch of the undifferentiated terms that already sets the contraction.
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
//! * the predictor is the previous mean acceleration only if that step was not 10× shorter
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
use crate::linalg::{dot, max_abs};
use crate::method::{
    Adaptive, ConstraintView, NewtonSystem, StepConstraint, StepContext, StepState, Stepper, Works,
    unconverged, update_tolerance,
};
use crate::system::{NewtonCoefficients, Parts, System};

/// Relative size of the finite-difference perturbation of q for Ṁ(x)x in the oracle
/// [`kinetic_gradient_fd`].
pub const FD_STEP: f64 = 1e-5;
/// Newton iterations at most before the step is retried shorter.
const MAX_ITERATIONS: usize = 30;
/// Steps at most that reuse one Newton matrix in runs without contact.
const MAX_MATRIX_AGE: usize = 8;
/// Relative difference of step sizes up to which a unilateral-contact run reuses a Newton
/// matrix: steps that land on output times (the stop time minus the start time, off the
/// nominal step by the round-off of t: 2e-12 of a 0.5 ms step at t = 3) and the trials of an
/// event location, which re-solve one stretch with lengths that approach each other. S changes
/// by about 2Δh/h in its stiffness part, and a matrix that then contracts too slowly is
/// re-formed by the stale-matrix refresh. Runs without contact reuse a matrix only at the
/// bit-identical step size.
const CLOSE_STEP: f64 = 0.02;
/// Energy defect h v̄ᵀ(residual) accepted per step, relative to the step's energy scale
/// (kinetic + |potential parts| at both ends + |work of the step|). Where round-off (of the
/// momentum difference) keeps the defect above this, the
/// iteration stops once the defect no longer falls (measured floor ≈ 1e-13 on `single-link`).
const ENERGY_TOL: f64 = 1e-14;

/// Work buffers of the midpoint step (allocated once per run).
#[derive(Debug, Clone)]
pub struct MidpointWork {
    /// p₀ = M(q₀)v₀.
    p0: Vec<f64>,
    qbar: Vec<f64>,
    vbar: Vec<f64>,
    /// b = ½(v₁ − v₀).
    half_dv: Vec<f64>,
    dq: Vec<f64>,
    /// M(q₁)v₁.
    mv1: Vec<f64>,
    /// ∇V(q̄).
    grad_v: Vec<f64>,
    /// Non-conservative part of R at (q̄, v̄): −Q.
    minus_q: Vec<f64>,
    /// ∇g(q̄).
    grad_g: Vec<f64>,
    /// W Δq = M(q̄)Δq.
    w_dq: Vec<f64>,
    /// Residual of the momentum equation divided by h.
    res: Vec<f64>,
    zero: Vec<f64>,
    /// Whether the previous step's mean acceleration is in `StepState::qdd` (else it holds
    /// the point acceleration of a (re)start), and that step's length.
    have_prev: bool,
    h_prev: f64,
    /// The last converged solve that was not accepted (a trial of an event location re-solves
    /// the same stretch with another length): its start time, start velocity, length and mean
    /// acceleration, the predictor of the next re-solve from the same start.
    resolve: Option<(f64, f64)>,
    resolve_qd: Vec<f64>,
    resolve_a: Vec<f64>,
    /// Anderson acceleration of the quasi-Newton iteration (runs without contact).
    anderson: Anderson,
    /// Steps solved with the current Newton matrix since it was formed by this stepper in a
    /// run without contact (`None`: no matrix this stepper may reuse).
    matrix_age: Option<usize>,
    /// Iterations of the last step that formed its matrix at its first iteration, and of the
    /// last step.
    fresh_iterations: usize,
    last_iterations: usize,
    /// Works of the step being taken, added to the ledger on acceptance.
    pending: Works,
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
        self.have_prev = true;
        self.h_prev = h;
        self.resolve = None;
    }
}

/// History length of [`Anderson`].
const ANDERSON_DEPTH: usize = 3;

/// Anderson acceleration (type II, depth [`ANDERSON_DEPTH`]) of the fixed-point iteration
/// a ↦ a + f(a), f = −S⁻¹·res(a) the quasi-Newton update: with the differences Δa_j, Δf_j of
/// the last iterates, γ = argmin‖f − ΔF γ‖₂ (normal equations, m ≤ 3) and
/// a ← a + f − (ΔA + ΔF)γ. The quasi-Newton map is nearly affine (S fixed, residual smooth):
/// the differences then span its slowly contracting directions and the extrapolation removes
/// them. Buffers allocated once.
#[derive(Debug, Clone)]
struct Anderson {
    n: usize,
    len: usize,
    next: usize,
    da: Vec<f64>,
    df: Vec<f64>,
    a_last: Vec<f64>,
    f_last: Vec<f64>,
    have_last: bool,
}

impl Anderson {
    fn new(n: usize) -> Self {
        Anderson {
            n,
            len: 0,
            next: 0,
            da: vec![0.0; ANDERSON_DEPTH * n],
            df: vec![0.0; ANDERSON_DEPTH * n],
            a_last: vec![0.0; n],
            f_last: vec![0.0; n],
            have_last: false,
        }
    }

    fn reset(&mut self) {
        self.len = 0;
        self.next = 0;
        self.have_last = false;
    }

    /// Replaces `a` by the accelerated iterate; `delta` = S⁻¹·res(a) (f = −delta).
    fn advance(&mut self, a: &mut [f64], delta: &[f64]) {
        let n = self.n;
        if self.have_last {
            let col = self.next * n;
            for i in 0..n {
                self.da[col + i] = a[i] - self.a_last[i];
                self.df[col + i] = -delta[i] - self.f_last[i];
            }
            self.next = (self.next + 1) % ANDERSON_DEPTH;
            self.len = (self.len + 1).min(ANDERSON_DEPTH);
        }
        self.a_last.copy_from_slice(a);
        for i in 0..n {
            self.f_last[i] = -delta[i];
        }
        self.have_last = true;
        let m = self.len;
        let mut gamma = [0.0; ANDERSON_DEPTH];
        if m > 0 {
            let mut g = [[0.0; ANDERSON_DEPTH + 1]; ANDERSON_DEPTH];
            for j in 0..m {
                let dj = &self.df[j * n..(j + 1) * n];
                for k in 0..=j {
                    let v = dot(dj, &self.df[k * n..(k + 1) * n]);
                    g[j][k] = v;
                    g[k][j] = v;
                }
                g[j][m] = dot(dj, &self.f_last);
            }
            if !solve_small(&mut g, m, &mut gamma) {
                // Nearly dependent differences (round-off near convergence): plain step.
                gamma = [0.0; ANDERSON_DEPTH];
            }
        }
        for i in 0..n {
            let mut x = a[i] + self.f_last[i];
            for j in 0..m {
                x -= gamma[j] * (self.da[j * n + i] + self.df[j * n + i]);
            }
            a[i] = x;
        }
    }
}

/// Solves the m × m system in the first m columns of `g` (right-hand side in column m) by
/// Gaussian elimination with partial pivoting; false when a pivot is below 1e-12 of the
/// largest diagonal (then `x` is not written).
fn solve_small(
    g: &mut [[f64; ANDERSON_DEPTH + 1]; ANDERSON_DEPTH],
    m: usize,
    x: &mut [f64; ANDERSON_DEPTH],
) -> bool {
    let dmax = (0..m).fold(0.0f64, |a, i| a.max(g[i][i].abs()));
    if dmax.is_nan() || dmax <= 0.0 || !dmax.is_finite() {
        return false;
    }
    for k in 0..m {
        let p = (k..m)
            .max_by(|&i, &j| g[i][k].abs().total_cmp(&g[j][k].abs()))
            .unwrap_or(k);
        g.swap(k, p);
        if g[k][k].abs() <= 1e-12 * dmax {
            return false;
        }
        for i in k + 1..m {
            let l = g[i][k] / g[k][k];
            for j in k..=m {
                g[i][j] -= l * g[k][j];
            }
        }
    }
    for k in (0..m).rev() {
        let mut v = g[k][m];
        for j in k + 1..m {
            v -= g[k][j] * x[j];
        }
        x[k] = v / g[k][k];
    }
    true
}

/// ∂T/∂q at (q, x) with T = ½xᵀM(q)x, analytic ([`System::add_kinetic_gradient`], the one
/// the scheme uses). Allocates: for checks, not for step loops.
pub fn kinetic_gradient<S: System + ?Sized>(
    system: &mut S,
    t: f64,
    q: &[f64],
    x: &[f64],
) -> Vec<f64> {
    let mut out = vec![0.0; q.len()];
    system.add_kinetic_gradient(t, q, x, 1.0, &mut out);
    out
}

/// ∂T/∂q at (q, x) by the identity ∂T/∂q = Ṁ(x)x − R_in(q, x, 0) with the central difference
/// Ṁ(x)x = [M(q + εx)x − M(q − εx)x]/(2ε), ε‖x‖∞ = `delta` (truncation ~10⁻¹⁰, round-off
/// ~10⁻¹¹ relative at `delta` = [`FD_STEP`]): 3 inertial passes of the residual, independent of
/// the analytic sweep — its test oracle. Allocates: for checks, not for step loops.
pub fn kinetic_gradient_fd<S: System + ?Sized>(
    system: &mut S,
    t: f64,
    q: &[f64],
    x: &[f64],
    delta: f64,
) -> Vec<f64> {
    let n = q.len();
    let zero = vec![0.0; n];
    let mut out = zero.clone();
    let xmax = max_abs(x);
    if xmax == 0.0 {
        return out;
    }
    let eps = delta / xmax;
    let (mut tmp, mut tmp2) = (zero.clone(), zero.clone());
    let qp: Vec<f64> = q.iter().zip(x).map(|(a, b)| a + eps * b).collect();
    system.residual_parts(t, &qp, &zero, x, Parts::INERTIA, &mut tmp);
    let qm: Vec<f64> = q.iter().zip(x).map(|(a, b)| a - eps * b).collect();
    system.residual_parts(t, &qm, &zero, x, Parts::INERTIA, &mut tmp2);
    for i in 0..n {
        out[i] = (tmp[i] - tmp2[i]) / (2.0 * eps);
    }
    system.residual_parts(t, q, x, &zero, Parts::INERTIA, &mut tmp);
    for i in 0..n {
        out[i] -= tmp[i];
    }
    out
}

/// The mass product M(q)x = R_in(q, 0, x). Allocates: for checks, not for step loops.
pub fn mass_product<S: System + ?Sized>(system: &mut S, t: f64, q: &[f64], x: &[f64]) -> Vec<f64> {
    let n = q.len();
    let zero = vec![0.0; n];
    let mut out = zero.clone();
    system.residual_parts(t, q, &zero, x, Parts::INERTIA, &mut out);
    out
}

/// The energy-consistent midpoint scheme (module docs) with its work buffers.
#[derive(Debug, Clone)]
pub struct EnergyMidpoint {
    pub work: MidpointWork,
}

impl EnergyMidpoint {
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
    ) -> Result<Option<f64>, FemError> {
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
            let st = &*cx.state;
            return unconverged(cx.adaptive.is_some(), cx.h_nominal, st.t, h, iter.last);
        }
        w.accept(cx, &setup, robust, t_law);
        Ok(cx.adaptive.map(|ad| w.error_estimate(cx.state, h, ad)))
    }

    fn commit(&mut self, h: f64, works: &mut Works) -> bool {
        self.work.commit(h, works);
        true
    }

    fn restart(&mut self) {
        self.work.restart();
    }
}

/// Residual passes of [`MidpointWork::momentum_residual`]: M(q₁)v₁, W Δq, ∇V, −Q and the two
/// kinetic gradients, plus V(q₁) counted as one.
const MOMENTUM_PASSES: usize = 7;

/// What one step keeps fixed over its Newton iteration.
struct StepSetup {
    h: f64,
    t0: f64,
    /// t₀ + h/2, where the laws and the forces are sampled.
    t_mid: f64,
    t1: f64,
    /// V(q₀) and the energy scale |T₀| + Σ|V parts(q₀)| of the energy-defect test.
    v0_pot: f64,
    scale0: f64,
    /// Constraint value g(q₀) and the target of g(q₁) (0 for a full step).
    g0: f64,
    gap_target: f64,
    /// S = M + (h/2)C + (h²/4)K: ∂q̄/∂a = h²/4, ∂v̄/∂a = h/2.
    c: NewtonCoefficients,
}

/// The outcome of one Newton update ([`Iteration::judge`]).
enum Verdict {
    /// The iterate where the residual was evaluated is the solution.
    Converged,
    /// Not finite or diverging: the step fails (the driver retries shorter).
    Failed,
    /// A stale matrix let the update grow: re-form it at the same iterate, update not applied.
    Refresh,
    /// Apply the update and iterate.
    Apply,
}

/// The size of one Newton update and the tests it is measured by.
struct Measured {
    /// c_q‖δa‖∞: the update of the positions.
    dq: f64,
    /// Absolute tolerance, floored at the round-off level of the update itself.
    tol: f64,
    /// Energy defect |h v̄ᵀ(residual)| and the step's energy scale it is measured against.
    defect: f64,
    e_scale: f64,
    /// Whether g(q₁) is at its target within the Newton tolerance (true without constraint).
    on_surface: bool,
}

/// The control state of a step's Newton iteration: the last update, when the matrix was formed
/// and the forced refreshes of a stale one.
struct Iteration {
    converged: bool,
    /// The last applied update (∞ before the first).
    last: f64,
    /// Iteration at which the Newton matrix was last formed in this solve, and the forced
    /// refreshes (a stale matrix that stops contracting or diverges).
    formed_it: Option<usize>,
    force_refresh: bool,
    forced: usize,
    forced_now: bool,
    /// The tolerance of the last update, and its energy defect while within it (∞ otherwise).
    polish_tol: f64,
    last_defect: f64,
    iterations: usize,
}

impl Iteration {
    fn new() -> Self {
        Iteration {
            converged: false,
            last: f64::INFINITY,
            formed_it: None,
            force_refresh: false,
            forced: 0,
            forced_now: false,
            polish_tol: 0.0,
            last_defect: f64::INFINITY,
            iterations: 0,
        }
    }

    /// Whether iteration `it` forms the Newton matrix: at the first iteration unless an earlier
    /// step's matrix is reused (`reuse`); every 6th iteration while the update is above
    /// tolerance (once it is within tolerance and only the energy defect is being polished,
    /// the matrix still contracts, 1e-2..1e-3 per iteration, and a new one only costs — with a
    /// unilateral contact it also added noise); every iteration with `refresh`; and where a
    /// stale matrix was found ([`Self::judge`]).
    fn wants_matrix(&self, it: usize, reuse: bool, refresh: bool) -> bool {
        let periodic = (it == 6 || it == 12 || it == 18) && self.last > self.polish_tol;
        (it == 0 && !reuse) || periodic || refresh || self.force_refresh
    }

    /// Records that the matrix is formed at iteration `it`.
    fn formed(&mut self, it: usize) {
        self.formed_it = Some(it);
        self.forced_now = self.force_refresh;
        self.force_refresh = false;
    }

    /// Judges the update `m` of iteration `it`. Converged: the update is settled — within
    /// tolerance, or with contraction θ = dq/last > ½ under an unchanged matrix (remaining error
    /// ≈ dq/(1 − θ)) within 2(1 − θ)·tol — the constraint is on its target and the energy
    /// defect is below `ENERGY_TOL`·scale, no longer falls, or the update is far below
    /// tolerance. With a unilateral contact (`robust`) also when the previous update was within
    /// tolerance and this one grows (round-off noise). Failed: not finite, growing tenfold, or
    /// (`robust`) larger than `length_scale`.
    fn judge(&mut self, it: usize, m: &Measured, robust: bool, length_scale: f64) -> Verdict {
        let Measured {
            dq,
            tol,
            defect,
            e_scale,
            on_surface,
        } = *m;
        if !dq.is_finite() {
            return Verdict::Failed;
        }
        self.iterations = it + 1;
        // The iterate's remaining error is about dq/(1 − θ), θ the contraction of the
        // update under an unchanged matrix: a reused or stale matrix (stiff shear, after an
        // impact) contracts slowly, and a small update alone would stop the iteration
        // short of the tolerance. Up to θ = ½ the update test stands as is.
        let last = self.last;
        let theta = if it >= 1 && self.formed_it != Some(it) && last.is_finite() && last > 0.0 {
            dq / last
        } else {
            0.0
        };
        let settled = if theta <= 0.5 {
            dq <= tol
        } else {
            theta < 1.0 && dq <= 2.0 * (1.0 - theta) * tol
        };
        // The energy balance of the step is off by exactly the defect: demand it small too,
        // unless it has reached its round-off floor (no longer falls) or the update is far
        // below tolerance.
        if settled
            && on_surface
            && (defect <= ENERGY_TOL * e_scale
                || defect >= 0.5 * self.last_defect
                || dq <= 1e-4 * tol
                || it + 1 == MAX_ITERATIONS)
        {
            return Verdict::Converged;
        }
        self.last_defect = if dq <= tol { defect } else { f64::INFINITY };
        // A matrix formed at an earlier iterate (or step) that no longer contracts: form it
        // at the current iterate. Where the update grows, it is not applied (the residual
        // is re-evaluated at the same point with the new matrix); where it contracts
        // poorly, it is applied and the next iteration uses a fresh matrix. The matrix
        // changes along the almost massless frame directions (mass O(s²)) and with the
        // velocity-dependent foreshortening terms after impacts, where a reused matrix
        // failed (measured: free flight at dt = 2.5e-5, 8 elements, 33 rejected steps
        // before the first impact).
        if robust && dq > last && last <= self.polish_tol {
            // The previous update was within tolerance (only the energy defect was being
            // reduced) and this one is round-off noise: the current iterate, where the
            // residual was just evaluated, is the converged one.
            return Verdict::Converged;
        }
        self.polish_tol = tol;
        let stale = robust && self.formed_it != Some(it) && self.forced < 4 && it >= 1;
        if stale && dq > last {
            self.force_refresh = true;
            self.forced += 1;
            return Verdict::Refresh;
        }
        if (it > 2 && dq > 10.0 * last && !(self.forced_now && self.formed_it == Some(it)))
            || (robust && dq > length_scale)
        {
            // Diverging: give up early, the caller retries with a shorter step. (Not on
            // the iteration of a refresh forced by a stalled stale matrix: its updates
            // were too small, a larger first update of the fresh matrix is no
            // divergence. Never an update of a link length.)
            return Verdict::Failed;
        }
        if stale && dq > 0.2 * last {
            self.force_refresh = true;
            self.forced += 1;
        }
        self.last = dq;
        Verdict::Apply
    }
}

impl MidpointWork {
    /// The step's fixed data: p₀ = M(q₀)v₀ (at t_mid, as M(q₁)v₁), the energies at the start,
    /// g(q₀) of a held constraint and the target of g(q₁), the Newton coefficients.
    fn begin<S: System + ?Sized>(
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
    /// location differ by less than the step that predicts them; otherwise the previous step's
    /// mean acceleration; zero after a (re)start, where the point acceleration of a released
    /// pre-loaded spring is a mesh-dependent spike, and (`robust`) after a step more than 10×
    /// shorter (a located event just before): its mean acceleration is close to the point
    /// value, which after an impact carries the mesh modes (measured 5e6 at the tip node 2 µs
    /// after an impact, a predicted velocity change of 1e3 ft/s over the next 0.43 ms step,
    /// which diverged).
    fn predict(&self, st: &mut StepState, h: f64, robust: bool) {
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
        for i in 0..st.q.len() {
            st.qdd1[i] = if re_solve {
                self.resolve_a[i]
            } else if predict {
                st.qdd[i]
            } else {
                0.0
            };
        }
    }

    /// Whether the step reuses the factorized matrix of an earlier step (module docs): formed
    /// by this stepper at the same step size (within `CLOSE_STEP` with a unilateral contact,
    /// `robust`), younger than `MAX_MATRIX_AGE` steps, and the last step took at most one
    /// iteration more than the last step with a fresh matrix. Every contact event restarts
    /// the stepper (a fresh matrix).
    fn may_reuse<A>(&self, newton: &NewtonSystem<A>, h: f64, robust: bool) -> bool {
        let same_step = if robust { CLOSE_STEP } else { 0.0 };
        (newton.matrix_h - h).abs() <= same_step * h
            && !newton.slow_convergence
            && self.matrix_age.is_some_and(|age| age < MAX_MATRIX_AGE)
            && self.last_iterations <= self.fresh_iterations + 1
    }

    /// The iterate of the mean acceleration a = `st.qdd1`: v̄ = v₀ + (h/2)a, b = ½(v₁ − v₀) =
    /// (h/2)a, Δq = h v̄, q̄ = q₀ + Δq/2, q₁ = q₀ + Δq, v₁ = v₀ + h a.
    fn set_iterate(&mut self, st: &mut StepState, h: f64) {
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
    fn momentum_residual<S: System + ?Sized>(
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
        let [k1, s1, sp1, g1] = system.energies(setup.t1, &st.q1, &st.qd1);
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
    fn add_constraint_force<S: System + ?Sized>(
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
    fn measure<S: System + ?Sized>(
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
    fn apply_update(&mut self, st: &mut StepState, delta: &[f64], accelerate: bool, new_map: bool) {
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
    fn book_matrix(&mut self, iter: &Iteration, reusable: bool) {
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
    fn accept<S: System + ?Sized>(
        &mut self,
        cx: &mut StepContext<'_, S>,
        setup: &StepSetup,
        robust: bool,
        t_law: f64,
    ) {
        let st = &mut *cx.state;
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
    fn error_estimate(&self, st: &StepState, h: f64, ad: Adaptive) -> f64 {
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
fn form_matrix<S: System + ?Sized>(
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
fn solve_update<S: System + ?Sized>(
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
