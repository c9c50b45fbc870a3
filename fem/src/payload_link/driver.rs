//! The payload link's driver path: the [`LinkSystem`] stepped by a method of the registry
//! ([`crate::method::stepper`]) in fixed steps, with the link's ledger works.
//!
//! Steps land on the requested times (outputs, t_end) and on the motor law's breakpoints
//! (bang-bang switches): a step that ends on a breakpoint evaluates the law as its left limit,
//! and the method restarts there from a consistent acceleration ([`crate::method::start`]), as
//! the chain's driver does ([`crate::driver`]). A step whose Newton iteration fails is retried
//! as four quarter steps (the chain's driver retries a quarter step and grows back). The works
//! are booked after every accepted step with the midpoint rule ([`LinkSystem::step_works`]),
//! Kelvin–Voigt per damped field: the implicit midpoint rule's own quadrature, and
//! energy-midpoint's (which books the same terms, its fields summed, through
//! [`crate::system::System::midpoint_works`]); for the other methods a second-order quadrature
//! of the works.

use crate::driver::fixed_steps::{FixedSteps, QuarterRetries};
use crate::error::FemError;
use crate::method::{StepState, Works};
use crate::settings::Method;

use super::model::Model;
use super::system::{LinkSystem, LinkWorks};

/// The stepped link: system, method and state ([`FixedSteps`]), and the ledger works.
#[derive(Debug)]
pub struct LinkDriver {
    pub steps: FixedSteps<LinkSystem>,
    /// The ledger works of the run (cumulative).
    pub works: LinkWorks,
    /// What a method that books its own works books (the same terms as [`Self::works`],
    /// Kelvin–Voigt summed over the fields; not reported).
    method_works: Works,
    /// Motor-law discontinuities after t = 0, increasing.
    pub breakpoints: Vec<f64>,
    scratch: [Vec<f64>; 3],
}

impl LinkDriver {
    /// The link `model` at rest in the shape `d0` at t = 0 (a free base at its initial angle and
    /// rate), stepped by `method` with nominal step `h` (`rho_inf`: generalized-α's spectral
    /// radius); the start's consistent acceleration solved.
    pub fn new(
        model: Model,
        d0: &[f64],
        method: Method,
        h: f64,
        rho_inf: f64,
    ) -> Result<Self, FemError> {
        let n = model.n;
        let free = model.free_base();
        let length_scale = model.length;
        let mut breakpoints: Vec<f64> = match &model.base {
            super::model::Base::Free {
                torque: Some(law), ..
            } => law.breakpoints().into_iter().filter(|&t| t > 0.0).collect(),
            _ => Vec::new(),
        };
        breakpoints.sort_by(f64::total_cmp);
        breakpoints.dedup();
        let (theta, rate) = (model.initial_angle, model.initial_rate);
        let system = LinkSystem::new(model);
        let nq = crate::system::System::ndof(&system);
        let mut state = StepState::new(nq);
        state.q[..n].copy_from_slice(d0);
        if free {
            state.q[n] = theta;
            state.qd[n] = rate;
        }
        let mut it = LinkDriver {
            steps: FixedSteps::new(system, state, method, h, rho_inf, length_scale),
            works: LinkWorks::default(),
            method_works: Works::default(),
            breakpoints,
            scratch: [vec![0.0; nq], vec![0.0; nq], vec![0.0; nq]],
        };
        it.steps.consistent_acceleration(h, 0.0)?;
        Ok(it)
    }

    /// The first breakpoint after the current time, if any.
    pub fn next_breakpoint(&self) -> Option<f64> {
        let t = self.steps.state.t;
        self.breakpoints
            .iter()
            .copied()
            .find(|&b| b > t + 1e-12 * self.steps.h_nominal)
    }
}

impl QuarterRetries for LinkDriver {
    type System = LinkSystem;

    fn steps(&mut self) -> &mut FixedSteps<LinkSystem> {
        &mut self.steps
    }

    /// On a motor-law breakpoint (within 10⁻¹² of the nominal step, or of 1 s).
    fn ends_on_jump(&self, _h: f64, t1: f64) -> bool {
        self.breakpoints
            .iter()
            .any(|&b| (t1 - b).abs() <= 1e-12 * self.steps.h_nominal.max(1.0))
    }

    /// The method's own works (not reported), then the link's works (module docs).
    fn book(&mut self, h: f64) {
        self.steps.commit(h, &mut self.method_works);
        let FixedSteps { system, state, .. } = &mut self.steps;
        system.step_works(
            state.t,
            h,
            (&state.q, &state.q1),
            (&state.qd, &state.qd1),
            &mut self.scratch,
            &mut self.works,
        );
    }
}
