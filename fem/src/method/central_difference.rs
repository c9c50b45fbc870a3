//! Explicit central difference (velocity-Verlet form): q̇_{n+½} = q̇_n + h/2 q̈_n,
//! q_{n+1} = q_n + h q̇_{n+½}, M(q_{n+1}) q̈_{n+1} = −(rest of R) with velocity terms evaluated
//! at the predicted q̇ = q̇_n + h q̈_n, q̇_{n+1} = q̇_{n+½} + h/2 q̈_{n+1}. Stable provided the
//! step is constant (each stretch between stop times is split into equal steps ≤ dt: a periodic
//! short step near the bound makes the composed map unstable; [`Stepper::equal_steps`]) and
//! below the bound of [`stability_bound`].
//!
//! **Bound.** On a mode q̈ = −ω²q − κq̇ (κ = 2ζω) the step maps (q, q̇, q̈) linearly, and the
//! map's eigenvalue leaves the unit circle through −1 where det(A + I) = 4 − 4κh − ω²h² = 0:
//!
//!   h ≤ 2 / (κ + √(κ² + ω²)),
//!
//! 2/ω undamped, 1/κ for a pure damper — stricter than the textbook (2/ω)(√(1 + ζ²) − ζ)
//! because the damping acts on the predicted velocity q̇_n + h q̈_n. The binding mode is either
//! the stiffest one (Kelvin–Voigt damping grows with ω) or the most damped one (a joint damper
//! on a small inertia): both are found by power iteration, on M⁻¹K and on M⁻¹C, and each
//! gives the bound with its Rayleigh quotients (κ = xᵀCx/xᵀMx, ω² = xᵀKx/xᵀMx).

use crate::error::FemError;
use crate::linalg::{dot, max_abs};
use crate::method::{
    Capabilities, MethodParams, StepConstraint, StepContext, StepState, Stepper, refuse_constraint,
};
use crate::band::BorderedBand;
use crate::system::{NewtonCoefficients, System};

/// Central difference (no state of its own).
#[derive(Debug, Clone, Copy)]
pub struct CentralDifference;

impl CentralDifference {
    /// Registry entry: what the method supports.
    pub const CAPABILITIES: Capabilities = Capabilities {
        explicit: true,
        adaptive: false,
        prescribed_joints: true,
        held_constraint: false,
        bilateral_constraint: false,
        projects_massless: false,
        variable_mass: true,
    };
}

impl From<MethodParams> for CentralDifference {
    fn from(_: MethodParams) -> Self {
        CentralDifference
    }
}

impl<S: System + ?Sized> Stepper<S> for CentralDifference {
    fn step(
        &mut self,
        cx: &mut StepContext<'_, S>,
        constraint: Option<&mut dyn StepConstraint<S>>,
        h: f64,
        t1: f64,
        t_law: f64,
    ) -> Result<Option<f64>, FemError> {
        refuse_constraint("central-difference", constraint.is_some())?;
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
            c_v: 0.0,
            c_q: 0.0,
        };
        // M(q1) q̈1 = −rest: R is affine in q̈; iterate on the mass-matrix approximation.
        for it in 0..20 {
            cx.system
                .residual(t_law, &st.q1, &st.qd1, &st.qdd1, &mut cx.newton.res);
            cx.counters.rhs += 1;
            if it == 0 {
                cx.newton.form(cx.system, st, cx.counters, c, t1)?;
                cx.newton.matrix_h = f64::NAN;
            }
            cx.newton.delta.copy_from_slice(&cx.newton.res);
            cx.newton.solve();
            let (mut big, mut amax) = (0.0f64, 0.0f64);
            for i in 0..n {
                st.qdd1[i] -= cx.newton.delta[i];
                big = big.max(cx.newton.delta[i].abs());
                amax = amax.max(st.qdd1[i].abs());
            }
            if !big.is_finite() || big <= 1e-12 * amax.max(1e-12) {
                break;
            }
        }
        for i in 0..n {
            st.qd1[i] = st.qd[i] + 0.5 * h * (st.qdd[i] + st.qdd1[i]);
            st.a1[i] = st.qdd1[i];
        }
        Ok(None)
    }

    fn equal_steps(&self) -> bool {
        true
    }
}

/// The step bound of the linearized system at the current state (module docs) and the DOF
/// where the binding mode is largest.
pub fn stability_bound<S: System + ?Sized>(
    system: &mut S,
    st: &StepState,
    res: &mut [f64],
) -> Result<(f64, usize), FemError> {
    system.residual(st.t, &st.q, &st.qd, &st.qdd, res);
    let matrix = |system: &mut S, c_a: f64, c_v: f64, c_q: f64| {
        let mut m = system.new_matrix();
        system.newton_matrix(&st.q, NewtonCoefficients { c_a, c_v, c_q }, &mut m);
        m
    };
    let kmat = matrix(system, 0.0, 0.0, 1.0);
    let cmat = matrix(system, 0.0, 1.0, 0.0);
    let mmat = matrix(system, 1.0, 0.0, 0.0);
    let mut mfac = mmat.clone();
    mfac.factorize()?;
    let quotient = |a: &BorderedBand, x: &[f64], ax: &mut [f64]| {
        a.matvec(x, ax);
        let xax = dot(x, ax);
        mmat.matvec(x, ax);
        xax / dot(x, ax)
    };
    let mut ax = vec![0.0; st.q.len()];
    let mut binding = (f64::INFINITY, 0);
    for (top_of, stiffest) in [(&kmat, true), (&cmat, false)] {
        let (lam, x) = dominant_mode(top_of, &mmat, &mut mfac);
        let omega2 = if stiffest {
            lam
        } else {
            quotient(&kmat, &x, &mut ax)
        }
        .max(0.0);
        let kappa = quotient(&cmat, &x, &mut ax).max(0.0);
        let bound = 2.0 / (kappa + (kappa * kappa + omega2).sqrt());
        if bound < binding.0 {
            let dof = (0..x.len())
                .max_by(|&a, &b| x[a].abs().total_cmp(&x[b].abs()))
                .unwrap_or(0);
            binding = (bound, dof);
        }
    }
    Ok(binding)
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
