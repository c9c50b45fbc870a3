//! Implicit midpoint rule on a reduced system (parent module docs):
//!
//! ```text
//! q₁ = q₀ + h S(q̄) ν̄,   M̄(q̄)(ν₁ − ν₀) = h (Q(t̄, ν̄) − b(q̄, ν̄)),   q̄, ν̄ the step midpoints
//! ```
//!
//! (q̄ from ν̄ by [`ReducedSystem::midpoint_configuration`]). Unknown Δν = ν₁ − ν₀; the
//! residual h(M̄ ν̇ + b − Q) at ν̇ = Δν/h is one inverse-dynamics pass. Modified Newton with the
//! matrix M̄(q̄⁽⁰⁾) + ¼h² K + ½h D, formed and Cholesky-factorized once per step: the neglected
//! terms (the configuration dependence of M̄, gyroscopic and gravity couplings) are O(h |ω|)
//! relative, so the iteration contracts by that factor. The predictor is the previous step's
//! Δν (zero on the first step). Works are booked with the scheme's own midpoint quadrature,
//! h P(t̄, ν̄).

use super::{ReducedParams, ReducedState, ReducedStepper, ReducedSystem};
use crate::error::FemError;
use crate::linalg::DenseLlt;
use crate::method::state::FixedStepCounters;

/// Newton iterations per step before the run is stopped.
pub const MAX_NEWTON: usize = 30;
/// Newton tolerance on the speed update, relative to max(1, |ν̄|∞).
pub const NEWTON_TOL: f64 = 1e-12;
/// Largest relative update accepted when the iteration stalls at round-off.
pub const STALL_TOL: f64 = 1e-9;

/// The method's storage, allocated once: the step loop does not allocate.
#[derive(Debug, Clone)]
pub struct ReducedMidpoint {
    counters: FixedStepCounters,
    mass: Vec<f64>,
    newton: Vec<f64>,
    llt: DenseLlt,
    force: Vec<f64>,
    applied: Vec<f64>,
    /// Δν of the current step (the next step's predictor)
    dnu: Vec<f64>,
    delta: Vec<f64>,
    nudot: Vec<f64>,
    qbar: Vec<f64>,
    nubar: Vec<f64>,
}

impl From<ReducedParams> for ReducedMidpoint {
    fn from(p: ReducedParams) -> Self {
        let (n, m) = (p.coordinates, p.speeds);
        ReducedMidpoint {
            counters: FixedStepCounters::default(),
            mass: vec![0.0; m * m],
            newton: vec![0.0; m * m],
            llt: DenseLlt::new(m),
            force: vec![0.0; m],
            applied: vec![0.0; m],
            dnu: vec![0.0; m],
            delta: vec![0.0; m],
            nudot: vec![0.0; m],
            qbar: vec![0.0; n],
            nubar: vec![0.0; m],
        }
    }
}

impl ReducedMidpoint {
    /// The midpoints q̄, ν̄ of the current Δν.
    fn midpoints<S: ReducedSystem + ?Sized>(&mut self, sys: &mut S, st: &ReducedState, h: f64) {
        for i in 0..self.nubar.len() {
            self.nubar[i] = st.nu[i] + 0.5 * self.dnu[i];
        }
        sys.midpoint_configuration(&st.q, &self.nubar, h, &mut self.qbar);
    }
}

impl<S: ReducedSystem + ?Sized> ReducedStepper<S> for ReducedMidpoint {
    fn step(
        &mut self,
        sys: &mut S,
        st: &mut ReducedState,
        works: &mut S::Works,
        h: f64,
    ) -> Result<(), FemError> {
        let m = self.nubar.len();
        let t_mid = st.t + 0.5 * h;
        let mut converged = false;
        let (mut last, mut last_scale) = (f64::INFINITY, 1.0);
        for it in 0..MAX_NEWTON {
            self.midpoints(sys, st, h);
            for i in 0..m {
                self.nudot[i] = self.dnu[i] / h;
            }
            let want_mass = it == 0;
            sys.inertia_forces(
                &self.qbar,
                &self.nubar,
                &self.nudot,
                want_mass.then_some(&mut self.mass[..]),
                &mut self.force,
            );
            self.counters.residuals += 1;
            sys.applied_forces(t_mid, &self.nubar, &mut self.applied);
            for i in 0..m {
                self.delta[i] = h * (self.force[i] - self.applied[i]);
            }
            if it == 0 {
                self.newton.copy_from_slice(&self.mass);
                sys.add_stiffness_and_damping(0.25 * h * h, 0.5 * h, &mut self.newton);
                self.llt
                    .factor(&self.newton)
                    .map_err(|pivot| FemError::Runaway {
                        t: st.t,
                        what: "Newton matrix not positive definite".into(),
                        location: Some(format!("speed {pivot}")),
                        why: "the reduced mass matrix lost definiteness".into(),
                        remedy: "check the scene's inertias".into(),
                    })?;
                self.counters.factorizations += 1;
            }
            self.llt.solve(&mut self.delta);
            self.counters.newton += 1;
            let mut size = 0.0f64;
            let mut scale = 1.0f64;
            for i in 0..m {
                self.dnu[i] -= self.delta[i];
                size = size.max(self.delta[i].abs());
                scale = scale.max(self.nubar[i].abs());
            }
            if !size.is_finite() {
                break;
            }
            // Converged at the tolerance, or stalled at the round-off floor of the residual
            // (the elastic forces K e of a fine mesh carry |K||e|·ε of noise): the update no
            // longer contracts and is already below the stagnation bound.
            let stalled = it > 0 && size > 0.5 * last && size <= STALL_TOL * scale;
            if size <= NEWTON_TOL * scale || stalled {
                converged = true;
                break;
            }
            last = size;
            last_scale = scale;
        }
        if !converged {
            return Err(FemError::Runaway {
                t: st.t,
                what: "Newton iteration of the midpoint step did not converge".into(),
                location: None,
                why: format!(
                    "no convergence in {MAX_NEWTON} modified-Newton iterations (last update \
                     {last:.2e}, speed scale {last_scale:.2e})"
                ),
                remedy: "reduce --dt".into(),
            });
        }
        self.midpoints(sys, st, h);
        for i in 0..st.q.len() {
            st.q[i] = 2.0 * self.qbar[i] - st.q[i];
        }
        for i in 0..m {
            st.nu[i] += self.dnu[i];
        }
        sys.book(t_mid, &self.nubar, h, works);
        st.t += h;
        self.counters.steps += 1;
        Ok(())
    }

    fn counters(&self) -> FixedStepCounters {
        self.counters
    }
}
