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
//! by projection, as SHAKE and RATTLE do for velocity Verlet), G = ∇g:
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
//! a release. The bilateral friction wall (stick–slip phases) is refused.

use crate::band::BorderedBand;
use crate::error::FemError;
use crate::method::start::EventRestart;
use crate::linalg::{dot, max_abs};
use crate::method::{
    Capabilities, MethodParams, StepConstraint, StepContext, StepState, Stepper, };
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
    /// ∇g at the step start and at its end, and M⁻¹ applied to each.
    g_start: Vec<f64>,
    g_end: Vec<f64>,
    minv_g_start: Vec<f64>,
    minv_g_end: Vec<f64>,
    /// The start acceleration of a held step with its projection force (the state's q̈ₙ stays
    /// as it is: a rejected trial restarts from it).
    a_start: Vec<f64>,
    /// The constraint force of a restart's q̈ₙ (scratch: the start force is re-solved by the
    /// projection).
    force: Vec<f64>,
    /// When q̈ₙ is recomputed for the phase (module docs).
    restart: EventRestart,
}

impl CentralDifference {
    /// Registry entry: what the method supports.
    pub const CAPABILITIES: Capabilities = Capabilities {
        explicit: true,
        adaptive: false,
        prescribed_joints: true,
        held_constraint: true,
        bilateral_constraint: false,
        projects_massless: false,
        variable_mass: true,
    };

    /// The method for a system of `n` DOFs.
    pub fn new(n: usize) -> Self {
        CentralDifference {
            g_start: vec![0.0; n],
            g_end: vec![0.0; n],
            minv_g_start: vec![0.0; n],
            minv_g_end: vec![0.0; n],
            a_start: vec![0.0; n],
            force: vec![0.0; n],
            restart: EventRestart::new(n),
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
    ) -> Result<Option<f64>, FemError> {
        // After an event (an impact's velocity jump, a release) q̈ₙ is recomputed for the new
        // phase, with the event's normal force while the constraint is held (module docs).
        self.restart.apply(
            cx,
            constraint.as_deref_mut(),
            h,
            &mut self.force,
            "central-difference",
        )?;
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
        if let Some(k) = constraint.as_deref_mut() {
            // SHAKE: the start acceleration gains S⁻¹∇g(q₀)μ so that g(q₁) reaches its target
            // (the share (h/h_nominal)² of the start gap removed, as in the implicit methods).
            let g0 = k.gradient(cx.system, t0, &st.q, &mut self.g_start);
            cx.newton.delta.copy_from_slice(&self.g_start);
            cx.newton.solve();
            self.minv_g_start.copy_from_slice(&cx.newton.delta);
            let shortened = (h / cx.h_nominal).min(1.0);
            let target = g0 * (1.0 - shortened * shortened);
            let slope = 0.5 * h * h * dot(&self.g_start, &self.minv_g_start);
            let tol = GAP_TOL * cx.length_scale;
            let mut mu = 0.0;
            let mut gap = k.value(cx.system, t1, &st.q1);
            for _ in 0..MAX_ITERATIONS {
                let off = (gap - target).abs();
                if off <= tol || off.is_nan() {
                    break;
                }
                let dmu = -(gap - target) / slope;
                mu += dmu;
                for i in 0..n {
                    st.q1[i] += 0.5 * h * h * dmu * self.minv_g_start[i];
                }
                gap = k.value(cx.system, t1, &st.q1);
            }
            if (gap - target).abs() > tol || gap.is_nan() {
                return Err(unprojected("position", t0, gap - target));
            }
            for i in 0..n {
                self.a_start[i] = st.qdd[i] + mu * self.minv_g_start[i];
                st.qd1[i] = st.qd[i] + h * self.a_start[i];
                st.qdd1[i] = self.a_start[i];
            }
            // RATTLE: the end force ∇g(q₁)ν with ν such that ∇g(q₁)·q̇₁ = 0.
            k.gradient(cx.system, t1, &st.q1, &mut self.g_end);
            cx.newton.delta.copy_from_slice(&self.g_end);
            cx.newton.solve();
            self.minv_g_end.copy_from_slice(&cx.newton.delta);
        }
        let held = constraint.is_some();
        let g_minv_g = if held {
            dot(&self.g_end, &self.minv_g_end)
        } else {
            0.0
        };
        let mut nu = 0.0;
        // R(q₁, q̇ₙ₊½ + (h/2)q̈₁, q̈₁) = ∇g(q₁)ν, by Newton on S = M + (h/2)C.
        let mut converged = false;
        let mut last = f64::NAN;
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
            if held {
                for i in 0..n {
                    cx.newton.res[i] -= nu * self.g_end[i];
                }
            }
            cx.newton.delta.copy_from_slice(&cx.newton.res);
            cx.newton.solve();
            let (mut big, mut amax) = (0.0f64, 0.0f64);
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
                big = big.max(cx.newton.delta[i].abs());
            }
            let mut floor = 0.0;
            if held {
                // ∇g(q₁)·(q̇ₙ₊½ + h/2 q̈₁) = 0 for the updated q̈₁; the round-off of that sum,
                // divided by ½h ∇gᵀM⁻¹∇g, bounds how far the updates can settle.
                let (mut normal, mut scale) = (0.0, 0.0);
                for i in 0..n {
                    let term = self.g_end[i] * (st.qd[i] + 0.5 * h * (self.a_start[i] + st.qdd1[i]));
                    normal += term;
                    scale += term.abs();
                }
                let dnu = -normal / (0.5 * h * g_minv_g);
                nu += dnu;
                for i in 0..n {
                    st.qdd1[i] += dnu * self.minv_g_end[i];
                }
                let reach = max_abs(&self.minv_g_end);
                big = big.max(dnu.abs() * reach);
                floor = 16.0 * f64::EPSILON * scale / (0.5 * h * g_minv_g) * reach;
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
            k.set_multiplier(nu);
        }
        for i in 0..n {
            st.qd1[i] = st.qd[i] + 0.5 * h * (a0[i] + st.qdd1[i]);
            st.a1[i] = st.qdd1[i];
        }
        Ok(None)
    }

    fn equal_steps(&self) -> bool {
        true
    }

    fn restart(&mut self) {
        self.restart.request();
    }
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
