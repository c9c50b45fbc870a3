//! Explicit central difference (velocity-Verlet form): q̇_{n+½} = q̇_n + h/2 q̈_n,
//! q_{n+1} = q_n + h q̇_{n+½}, M(q_{n+1}) q̈_{n+1} = −(rest of R) with velocity terms evaluated
//! at the predicted q̇, q̇_{n+1} = q̇_{n+½} + h/2 q̈_{n+1}. Stable for h ≤ 2/ω_max
//! ([`max_frequency`]) provided the step is constant: each stretch between stop times is split
//! into equal steps ≤ dt (a periodic short step near the bound makes the composed map
//! unstable; [`Stepper::equal_steps`]).

use crate::error::FemError;
use crate::linalg::{dot, max_abs};
use crate::method::{
    Capabilities, MethodParams, StepConstraint, StepContext, StepState, Stepper, refuse_constraint,
};
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
        projects_massless: false,
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

/// Largest natural frequency of the linearized system at the current state (power iteration
/// on M⁻¹K with the band solver) and the DOF where its mode is largest.
pub fn max_frequency<S: System + ?Sized>(
    system: &mut S,
    st: &StepState,
    res: &mut [f64],
) -> Result<(f64, usize), FemError> {
    let n = st.q.len();
    system.residual(st.t, &st.q, &st.qd, &st.qdd, res);
    let mut kmat = system.new_matrix();
    system.newton_matrix(
        &st.q,
        NewtonCoefficients {
            c_a: 0.0,
            c_v: 0.0,
            c_q: 1.0,
        },
        &mut kmat,
    );
    let mut mmat = system.new_matrix();
    system.newton_matrix(
        &st.q,
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
