//! The state and bookkeeping a method carries between steps: the step state (start and trial
//! end), the work counters, the running works of the ledger and the adaptive tolerances.

use std::time::Instant;

use data::Cost;

pub use crate::system::Works;

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

impl Counters {
    /// The run's cost record: `dofs` unknowns, wall time since `start`.
    pub fn cost(&self, dofs: usize, start: Instant) -> Cost {
        Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs,
            steps: self.steps,
            rejected_steps: self.rejected,
            rhs_evaluations: self.rhs,
            jacobian_evaluations: self.jacobians,
            factorizations: self.factorizations,
            newton_iterations: self.newton,
        }
    }
}

/// Work counters of the mobile manipulator's fixed-step implicit-midpoint stepper: every
/// Newton iteration evaluates one residual and factorizes one Newton matrix (a Jacobian
/// evaluation per factorization); no step is rejected.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FixedStepCounters {
    pub steps: usize,
    pub newton: usize,
    pub residuals: usize,
    pub factorizations: usize,
}

impl FixedStepCounters {
    /// The run's cost record: `dofs` unknowns, wall time since `start`.
    pub fn cost(&self, dofs: usize, start: Instant) -> Cost {
        Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs,
            steps: self.steps,
            rejected_steps: 0,
            rhs_evaluations: self.residuals,
            jacobian_evaluations: self.factorizations,
            factorizations: self.factorizations,
            newton_iterations: self.newton,
        }
    }
}

/// Adaptive step control.
#[derive(Debug, Clone, Copy)]
pub struct Adaptive {
    pub rtol: f64,
    pub atol: f64,
}

/// The state at the step start (t, q, q̇, q̈ and the generalized-α pseudo-acceleration a)
/// and the trial end of the step being solved (q₁, q̇₁, q̈₁, a₁).
#[derive(Debug, Clone)]
pub struct StepState {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub a: Vec<f64>,
    pub q1: Vec<f64>,
    pub qd1: Vec<f64>,
    pub qdd1: Vec<f64>,
    pub a1: Vec<f64>,
}

impl StepState {
    /// All zero at t = 0 for `n` DOFs.
    pub fn new(n: usize) -> Self {
        StepState {
            t: 0.0,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            a: vec![0.0; n],
            q1: vec![0.0; n],
            qd1: vec![0.0; n],
            qdd1: vec![0.0; n],
            a1: vec![0.0; n],
        }
    }

    /// Makes the trial end the current state at t₁.
    pub fn swap_in(&mut self, t1: f64) {
        std::mem::swap(&mut self.q, &mut self.q1);
        std::mem::swap(&mut self.qd, &mut self.qd1);
        std::mem::swap(&mut self.qdd, &mut self.qdd1);
        std::mem::swap(&mut self.a, &mut self.a1);
        self.t = t1;
    }
}
