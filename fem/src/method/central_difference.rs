//! Explicit central difference (velocity-Verlet form, Newmark β = 0, γ = ½):
//!
//! ```text
//! q̇ₙ₊½ = q̇ₙ + (h/2) q̈ₙ,   qₙ₊₁ = qₙ + h q̇ₙ₊½,   q̇ₙ₊₁ = q̇ₙ₊½ + (h/2) q̈ₙ₊₁,
//! R(qₙ₊₁, q̇ₙ₊₁, q̈ₙ₊₁) = 0,
//! ```
//!
//! explicit in the configuration and implicit in the velocity: q̈ₙ₊₁ comes from Newton on the
//! matrix M + (h/2)C at qₙ₊₁ (C = ∂R/∂q̇), which the step factorizes in place of M alone —
//! the same band, the same cost. The iteration starts from q̈ₙ, and the residual's velocity
//! terms are linear (dampers, Kelvin–Voigt) or quadratic (gyroscopic), so it converges in a few
//! passes; an iteration that stops contracting at the round-off of the stiff terms is accepted
//! within `STALL_TOL`. Stable provided the step is constant (each stretch between stop times is
//! split into equal steps ≤ dt: a periodic short step near the bound makes the composed map
//! unstable; [`Stepper::equal_steps`]) and below the bound of [`stability_bound`].
//!
//! **Bound.** On a mode q̈ = −ω²q − κq̇ the step maps (q, q̇, q̈) linearly; with the damping at
//! the end velocity (trapezoidal in the damping) the map stays in the unit disc for
//!
//!   h ≤ 2/ω
//!
//! whatever κ: the damping never binds (with the damping at a predicted velocity instead the
//! bound would be 2/(κ + √(κ² + ω²)), which the Kelvin–Voigt damping of the top mesh modes,
//! κ ∝ ω², drives far below 2/ω_max: 6.0e-7 against 9.8e-6 s on `two-link-free`). The bound is
//! that of the stiffest mode, found by power iteration on M⁻¹K. Heavily damped mesh modes
//! (κh ≫ 1) are not damped out in one step as in the continuous system: the trapezoidal rule
//! leaves them a factor (1 − κh/2)/(1 + κh/2) per step, close to −1, and they decay over many
//! steps.
//!
//! **Held constraint** g(q) = 0 (a tip held on a surface; no Newton iteration to border, so
//! by projection, as SHAKE and RATTLE do for velocity Verlet), G = ∇g (one row; the rows of
//! the friction wall below):
//!
//! ```text
//! q₁ = qₙ + h q̇ₙ + (h²/2)(q̈ₙ + S⁻¹Gₙᵀμ),           g(q₁) = target   (μ: chord iteration)
//! R(q₁, q̇₁, q̈₁) = G₁ᵀν,                               G₁ q̇₁ = 0        (ν: with q̈₁)
//! q̇₁ = q̇ₙ + (h/2)(q̈ₙ + S⁻¹Gₙᵀμ + q̈₁)
//! ```
//!
//! S⁻¹ is the factorization of S = M + (h/2)C at the predicted end point that the step forms
//! anyway (the response of the accelerations to a force under the implicit damping). μ and ν
//! are the start and end constraint forces: the step stays second order and explicit in the
//! configuration (one factorization per step, as in free flight), and the held step ends with
//! G₁q̇₁ = 0, so
//! the driver's drift projection removes nothing. The target of g(q₁) removes the share
//! (h/h_nominal)² of the start gap, as in the implicit methods, so that the event location's
//! shortened steps are continuous in h. The free chain's bound also covers the held phases
//! (a constraint can only lower the highest frequency). The driver books the works by
//! the trapezoidal rule; the constraint forces do work of the order of the scheme's error
//! (the ledger closure falls 4× per halved step through impacts and held phases). After every
//! event (restart) of a run that has held a constraint, q̈ₙ is recomputed for the new phase:
//! with the event's normal force while held (`start::EventRestart`), without after
//! a release.
//!
//! **Friction wall** (bilateral, stick–slip: [`StepConstraint::projection_rows`]). Sliding, the
//! normal multiplier's force runs along F = G − μsσT (Coulomb friction −μs|λ|T with the sign σ
//! of λ fixed for the step), so μ and ν act along S⁻¹Fᵀ while the rows stay G: the chord and
//! the velocity solve use G·S⁻¹Fᵀ. Sticking, the tip is also held at its stick point by
//! h = t̂_s·(r_tip − p_s) = 0: two rows, 2 × 2 chord and velocity solves. The constraint books
//! the friction work by the trapezoidal rule, D = ½μsσ(λ₀T(q₀) + νT(q₁))·Δq, λ₀ the start
//! force (the one q̈ₙ carries plus μ), and the step's normal multiplier as the mean of the
//! two ([`StepConstraint::commit_projection`]).

use crate::band::BorderedBand;
use crate::error::FemError;
use crate::method::start::EventRestart;
use crate::linalg::{dot, max_abs, solve2};
use crate::method::{
    Trial,
    Capabilities, MethodParams, ProjectionRows, StepConstraint, StepContext, StepState, Stepper,
    Works,
};
use crate::system::{NewtonCoefficients, System};

/// Iterations of the end-acceleration solve and of the position projection.
const MAX_ITERATIONS: usize = 20;
/// Gap accuracy of the position projection of a held step, relative to the length scale.
const GAP_TOL: f64 = 1e-12;
/// What a refusal of a step above [`stability_bound`] names as the bound.
pub const BOUND_KIND: &str = "central-difference (2/ω_max of the stiffest mode)";
/// Largest update, relative to the largest acceleration, accepted from an end-acceleration
/// iteration that no longer contracts: the round-off floor of the residual's stiff Kelvin–Voigt
/// and elastic terms (measured ~1e-11 on `two-link-free`, 16 elements), two decades above it and
/// far below the step's truncation error.
const STALL_TOL: f64 = 1e-9;

/// Central difference: the buffers of a held constraint's projections and the restart state.
#[derive(Debug, Clone)]
pub struct CentralDifference {
    /// The held rows at the step start and at its end, and S⁻¹ applied to each row's force
    /// direction.
    start: ProjectionRows,
    end: ProjectionRows,
    minv_start: [Vec<f64>; 2],
    minv_end: [Vec<f64>; 2],
    /// The start acceleration of a held step with its projection force (the state's q̈ₙ stays
    /// as it is: a rejected trial restarts from it).
    a_start: Vec<f64>,
    /// The constraint force of a restart's q̈ₙ (scratch: the start force is re-solved by the
    /// projection).
    force: Vec<f64>,
    /// When q̈ₙ is recomputed for the phase (module docs).
    restart: EventRestart,
    /// The multipliers of the constraint forces q̈ₙ carries (the last accepted step's end
    /// forces, or a restart's), and the end multipliers of the trial step.
    carried: [f64; 2],
    trial_end: [f64; 2],
}

impl CentralDifference {
    /// Registry entry: what the method supports.
    pub const CAPABILITIES: Capabilities = Capabilities {
        explicit: true,
        adaptive: false,
        prescribed_joints: true,
        held_constraint: true,
        bilateral_constraint: true,
        projects_massless: false,
        variable_mass: true,
    };

    /// The method for a system of `n` DOFs.
    pub fn new(n: usize) -> Self {
        CentralDifference {
            start: ProjectionRows::new(n),
            end: ProjectionRows::new(n),
            minv_start: [vec![0.0; n], vec![0.0; n]],
            minv_end: [vec![0.0; n], vec![0.0; n]],
            a_start: vec![0.0; n],
            force: vec![0.0; n],
            restart: EventRestart::new(n),
            carried: [0.0; 2],
            trial_end: [0.0; 2],
        }
    }
}

impl From<MethodParams> for CentralDifference {
    fn from(p: MethodParams) -> Self {
        CentralDifference::new(p.n)
    }
}

impl<S: System + ?Sized> Stepper<S> for CentralDifference {
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        mut constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Trial, FemError> {
        // After an event (an impact's velocity jump, a release) q̈ₙ is recomputed for the new
        // phase, with the event's normal force while the constraint is held (module docs).
        if self.restart.apply(
            cx,
            constraint.as_deref_mut(),
            h,
            &mut self.force,
            "central-difference",
        )? {
            // q̈ₙ now carries the constraint force at its current multiplier, or none.
            self.carried = [constraint.as_deref().map_or(0.0, |k| k.multiplier()), 0.0];
        }
        let t0 = cx.state.t;
        let st = &mut *cx.state;
        let n = st.q.len();
        for i in 0..n {
            let half = st.qd[i] + 0.5 * h * st.qdd[i];
            st.q1[i] = st.q[i] + h * half;
            st.qd1[i] = half + 0.5 * h * st.qdd[i];
            st.qdd1[i] = st.qdd[i];
        }
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.5 * h,
            c_q: 0.0,
        };
        // M + (h/2)C at the predicted end point, the iteration matrix of every solve of the
        // step: the derivative of R(q₁, q̇ₙ₊½ + (h/2)q̈₁, q̈₁) in q̈₁ (it misses only the
        // configuration change of a held step's projection and the O(v′²) terms).
        cx.system
            .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
        cx.counters.rhs += 1;
        cx.newton.form(cx.system, st, cx.counters, c, t1)?;
        cx.newton.matrix_h = f64::NAN;
        let mut mu_start = [0.0; 2];
        if let Some(k) = constraint.as_deref_mut() {
            // SHAKE: the start acceleration gains S⁻¹Fₙᵀμ (Fₙ the rows' force directions at
            // q₀) so that the rows' values at q₁ reach their targets (the share
            // (h/h_nominal)² of the start values removed, as in the implicit methods).
            k.projection_rows(cx.system, t0, &st.q, &mut self.start);
            let rows = self.start.k;
            for r in 0..rows {
                cx.newton.delta.copy_from_slice(&self.start.force[r]);
                cx.newton.solve();
                self.minv_start[r].copy_from_slice(&cx.newton.delta);
            }
            let shortened = (h / cx.h_nominal).min(1.0);
            let target = self.start.value.map(|v| v * (1.0 - shortened * shortened));
            let slope = coupling(0.5 * h * h, &self.start, &self.minv_start);
            let tol = GAP_TOL * cx.length_scale;
            let mut mu = [0.0; 2];
            let mut off = self.offsets(k, cx.system, t1, &st.q1, target);
            for _ in 0..MAX_ITERATIONS {
                if within(off, rows, tol) || off.iter().any(|x| x.is_nan()) {
                    break;
                }
                let dmu = solve_rows(&slope, off, rows);
                for r in 0..rows {
                    mu[r] += dmu[r];
                    for i in 0..n {
                        st.q1[i] += 0.5 * h * h * dmu[r] * self.minv_start[r][i];
                    }
                }
                off = self.offsets(k, cx.system, t1, &st.q1, target);
            }
            if !within(off, rows, tol) {
                let worst = if off[0].abs() >= off[1].abs() || off[0].is_nan() {
                    off[0]
                } else {
                    off[1]
                };
                return Err(unprojected("position", t0, worst));
            }
            for i in 0..n {
                let mut a = st.qdd[i];
                for r in 0..rows {
                    a += mu[r] * self.minv_start[r][i];
                }
                self.a_start[i] = a;
                st.qd1[i] = st.qd[i] + h * self.a_start[i];
                st.qdd1[i] = self.a_start[i];
            }
            // RATTLE: the end forces F₁ᵀν with ν such that the rows' rates ∇c(q₁)·q̇₁ vanish.
            k.projection_rows(cx.system, t1, &st.q1, &mut self.end);
            for r in 0..self.end.k {
                cx.newton.delta.copy_from_slice(&self.end.force[r]);
                cx.newton.solve();
                self.minv_end[r].copy_from_slice(&cx.newton.delta);
            }
            mu_start = mu;
        }
        let rows = if constraint.is_some() { self.end.k } else { 0 };
        // ½h ∇c(q₁)·S⁻¹F₁ᵀ: the response of the rows' end rates to the end forces.
        let rate_coupling = coupling(0.5 * h, &self.end, &self.minv_end);
        let mut nu = [0.0; 2];
        // R(q₁, q̇ₙ₊½ + (h/2)q̈₁, q̈₁) = F₁ᵀν, by Newton on S = M + (h/2)C.
        let mut converged = false;
        let mut last = f64::NAN;
        let held = rows > 0;
        let a0 = if held { &self.a_start } else { &st.qdd };
        for it in 0..MAX_ITERATIONS {
            if it > 0 {
                // The velocity terms at the end velocity of the updated q̈₁ (implicit).
                for i in 0..n {
                    st.qd1[i] = st.qd[i] + 0.5 * h * (a0[i] + st.qdd1[i]);
                }
                cx.system
                    .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
                cx.counters.rhs += 1;
            }
            for r in 0..rows {
                for i in 0..n {
                    cx.newton.res[i] -= nu[r] * self.end.force[r][i];
                }
            }
            cx.newton.delta.copy_from_slice(&cx.newton.res);
            cx.newton.solve();
            let (mut big, mut amax) = (0.0f64, 0.0f64);
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
                big = big.max(cx.newton.delta[i].abs());
            }
            let mut floor = 0.0f64;
            if held {
                // ∇c(q₁)·(q̇ₙ₊½ + h/2 q̈₁) = 0 for the updated q̈₁; the round-off of those sums,
                // divided by the rows' rate coupling, bounds how far the updates can settle.
                let (mut rate, mut scale) = ([0.0; 2], [0.0; 2]);
                for r in 0..rows {
                    for i in 0..n {
                        let term = self.end.gradient[r][i]
                            * (st.qd[i] + 0.5 * h * (self.a_start[i] + st.qdd1[i]));
                        rate[r] += term;
                        scale[r] += term.abs();
                    }
                }
                let dnu = solve_rows(&rate_coupling, rate, rows);
                for r in 0..rows {
                    nu[r] += dnu[r];
                    for i in 0..n {
                        st.qdd1[i] += dnu[r] * self.minv_end[r][i];
                    }
                    let reach = max_abs(&self.minv_end[r]);
                    big = big.max(dnu[r].abs() * reach);
                    floor = floor.max(
                        16.0 * f64::EPSILON * scale[r] / rate_coupling[r][r].abs() * reach,
                    );
                }
            }
            for v in st.qdd1.iter() {
                amax = amax.max(v.abs());
            }
            if !big.is_finite() {
                last = big;
                break;
            }
            // Within tolerance, or stalled at the round-off of the residual's stiff terms (the
            // velocity terms change with q̈₁, so each evaluation rounds anew).
            let stalled = it > 0 && big >= 0.5 * last && big <= STALL_TOL * amax;
            last = big;
            if big <= 1e-12 * amax.max(1e-12) + floor || stalled {
                converged = true;
                break;
            }
        }
        if held && !converged {
            return Err(unprojected("velocity", t0, last));
        }
        if let Some(k) = constraint {
            // The start forces: those q̈ₙ carries plus the position projection's.
            let start = [self.carried[0] + mu_start[0], self.carried[1] + mu_start[1]];
            k.commit_projection(cx.system, [t0, t1], [&st.q, &st.q1], start, nu);
        }
        self.trial_end = nu;
        for i in 0..n {
            st.qd1[i] = st.qd[i] + 0.5 * h * (a0[i] + st.qdd1[i]);
            st.a1[i] = st.qdd1[i];
        }
        Ok(Trial::Converged { error: None })
    }

    fn equal_steps(&self) -> bool {
        true
    }

    /// The accepted step's end forces are what q̈ₙ carries into the next step; the driver
    /// books the works.
    fn commit(&mut self, _h: f64, _works: &mut Works) -> bool {
        self.carried = self.trial_end;
        false
    }

    fn restart(&mut self) {
        self.restart.request();
    }
}

impl CentralDifference {
    /// The held rows' values at q₁ minus their targets: the constraint's value alone for one
    /// row, else every row's through [`StepConstraint::projection_rows`] (into the end rows,
    /// which the step re-forms at the converged q₁).
    fn offsets<S: System + ?Sized>(
        &mut self,
        k: &mut (dyn StepConstraint<S> + '_),
        system: &S,
        t1: f64,
        q1: &[f64],
        target: [f64; 2],
    ) -> [f64; 2] {
        if self.start.k == 1 {
            return [k.value(system, t1, q1) - target[0], 0.0];
        }
        k.projection_rows(system, t1, q1, &mut self.end);
        [self.end.value[0] - target[0], self.end.value[1] - target[1]]
    }
}

/// c·∇cᵢ·S⁻¹Fⱼᵀ for the held rows (`minv`: S⁻¹ applied to each row's force direction).
fn coupling(c: f64, rows: &ProjectionRows, minv: &[Vec<f64>; 2]) -> [[f64; 2]; 2] {
    let mut a = [[0.0; 2]; 2];
    for i in 0..rows.k {
        for j in 0..rows.k {
            a[i][j] = c * dot(&rows.gradient[i], &minv[j]);
        }
    }
    a
}

/// −A⁻¹r for the first `k` rows (k ≤ 2).
fn solve_rows(a: &[[f64; 2]; 2], r: [f64; 2], k: usize) -> [f64; 2] {
    match k {
        1 => [-r[0] / a[0][0], 0.0],
        2 => solve2(*a, r).map(|x| -x),
        _ => [0.0; 2],
    }
}

/// Whether the first `k` offsets are within `tol` (false for NaN).
fn within(off: [f64; 2], k: usize, tol: f64) -> bool {
    off[..k].iter().all(|x| x.abs() <= tol)
}

/// A held step whose projection onto the constraint did not converge (`residual`: the last gap
/// error, or the last acceleration update of the velocity projection).
fn unprojected(level: &str, t: f64, residual: f64) -> FemError {
    FemError::Runaway {
        t,
        what: format!(
            "central-difference: the {level} projection of a held contact step did not \
             converge (residual {residual:.3e})"
        ),
        location: Some("contact1".into()),
        why: "the step is too large for the constraint's curvature".into(),
        remedy: "reduce --dt".into(),
    }
}

/// The step bound 2/ω_max of the linearized system at the current state (module docs) and the
/// DOF where the stiffest mode is largest.
pub fn stability_bound<S: System + ?Sized>(
    system: &mut S,
    st: &StepState,
    res: &mut [f64],
) -> Result<(f64, usize), FemError> {
    system.residual(st.t, &st.q, &st.qd, &st.qdd, res);
    let matrix = |system: &mut S, c_a: f64, c_q: f64| {
        let mut m = system.new_matrix();
        system.newton_matrix(
            &st.q,
            NewtonCoefficients {
                c_a,
                c_v: 0.0,
                c_q,
            },
            &mut m,
        );
        m
    };
    let kmat = matrix(system, 0.0, 1.0);
    let mmat = matrix(system, 1.0, 0.0);
    let mut mfac = mmat.clone();
    mfac.factorize()?;
    let (omega2, x) = dominant_mode(&kmat, &mmat, &mut mfac);
    let dof = (0..x.len())
        .max_by(|&a, &b| x[a].abs().total_cmp(&x[b].abs()))
        .unwrap_or(0);
    Ok((2.0 / omega2.max(0.0).sqrt(), dof))
}

/// The largest generalized eigenvalue of A x = λ M x and its mode (power iteration on M⁻¹A,
/// stopped when the Rayleigh quotient settles to 1e-10).
fn dominant_mode(
    a: &BorderedBand,
    m: &BorderedBand,
    m_factors: &mut BorderedBand,
) -> (f64, Vec<f64>) {
    let n = a.n();
    let mut x: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.1 * ((i * 7919) % 13) as f64)
        .collect();
    let mut y = vec![0.0; n];
    let mut mx = vec![0.0; n];
    let mut lam = 0.0;
    for _ in 0..2000 {
        a.matvec(&x, &mut y);
        m_factors.solve_in_place(&mut y);
        // Rayleigh quotient xᵀA x / xᵀM x.
        a.matvec(&x, &mut mx);
        let xax = dot(&x, &mx);
        m.matvec(&x, &mut mx);
        let new = xax / dot(&x, &mx);
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
    (lam, x)
}
