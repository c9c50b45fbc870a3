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

use crate::error::FemError;
use crate::method::{Counters, NewtonSystem, StepContext, StepState, Stepper, Works, start};
use crate::settings::Method;
use crate::system::{NoAugmentation, System};

use super::model::Model;
use super::system::{LinkSystem, LinkWorks};

/// The stepped link: system, method, state and works.
#[derive(Debug)]
pub struct LinkDriver {
    pub system: LinkSystem,
    pub method: Method,
    stepper: Box<dyn Stepper<LinkSystem>>,
    pub state: StepState,
    pub newton: NewtonSystem<NoAugmentation>,
    pub counters: Counters,
    /// The ledger works of the run (cumulative).
    pub works: LinkWorks,
    /// What a method that books its own works books (the same terms as [`Self::works`],
    /// Kelvin–Voigt summed over the fields; not reported).
    method_works: Works,
    /// The nominal step (a method's retries and tolerances are measured against it).
    pub h_nominal: f64,
    /// The link length (scales the Newton tolerance).
    pub length_scale: f64,
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
        let nq = system.ndof();
        let mut state = StepState::new(nq);
        state.q[..n].copy_from_slice(d0);
        if free {
            state.q[n] = theta;
            state.qd[n] = rate;
        }
        let newton = NewtonSystem::new(&system, length_scale);
        let mut it = LinkDriver {
            system,
            method,
            stepper: crate::method::stepper(method, nq, rho_inf),
            state,
            newton,
            counters: Counters::default(),
            works: LinkWorks::default(),
            method_works: Works::default(),
            h_nominal: h,
            length_scale,
            breakpoints,
            scratch: [vec![0.0; nq], vec![0.0; nq], vec![0.0; nq]],
        };
        it.consistent_acceleration(h, 0.0)?;
        Ok(it)
    }

    /// The method and its step context (disjoint borrows of the driver).
    fn method_parts(&mut self) -> (&mut dyn Stepper<LinkSystem>, StepContext<'_, LinkSystem>) {
        let cx = StepContext {
            system: &mut self.system,
            state: &mut self.state,
            newton: &mut self.newton,
            counters: &mut self.counters,
            adaptive: None,
            h_nominal: self.h_nominal,
            length_scale: self.length_scale,
        };
        (self.stepper.as_mut(), cx)
    }

    fn consistent_acceleration(&mut self, h: f64, t_law: f64) -> Result<(), FemError> {
        let (_, mut cx) = self.method_parts();
        start::consistent_acceleration(&mut cx, h, t_law)
    }

    /// The first breakpoint after the current time, if any.
    pub fn next_breakpoint(&self) -> Option<f64> {
        let t = self.state.t;
        self.breakpoints
            .iter()
            .copied()
            .find(|&b| b > t + 1e-12 * self.h_nominal)
    }

    /// One step of length h onto t₁ (the caller snaps t₁ to its stop time); books its works.
    /// A step whose Newton iteration fails is retried as four quarter steps (recursively, down
    /// to 10⁻⁶ of the nominal step), the method restarted.
    pub fn step(&mut self, h: f64, t1: f64) -> Result<(), FemError> {
        if self.try_step(h, t1)? {
            return Ok(());
        }
        let t0 = self.state.t;
        if h <= 1e-6 * self.h_nominal {
            return Err(FemError::Runaway {
                t: t0,
                what: format!(
                    "Newton iteration of the {} step did not converge",
                    self.method
                ),
                location: None,
                why: format!("step h = {h:.3e} s too long for the motion"),
                remedy: "reduce --dt".into(),
            });
        }
        self.counters.rejected += 1;
        self.stepper.restart();
        for k in 1..=4 {
            let tk = if k == 4 { t1 } else { t0 + 0.25 * k as f64 * h };
            self.step(tk - self.state.t, tk)?;
        }
        Ok(())
    }

    /// One step; false (state unchanged) when its Newton iteration did not converge.
    fn try_step(&mut self, h: f64, t1: f64) -> Result<bool, FemError> {
        let on_break = self
            .breakpoints
            .iter()
            .any(|&b| (t1 - b).abs() <= 1e-12 * self.h_nominal.max(1.0));
        let t_law = if on_break { t1 - 1e-9 * h } else { t1 };
        let t0 = self.state.t;
        let (stepper, mut cx) = self.method_parts();
        if let Some(e) = stepper.step(&mut cx, None, h, t1, t_law)?
            && e.is_infinite()
        {
            return Ok(false);
        }
        self.stepper.commit(h, &mut self.method_works);
        let st = &self.state;
        self.system.step_works(
            t0,
            h,
            (&st.q, &st.q1),
            (&st.qd, &st.qd1),
            &mut self.scratch,
            &mut self.works,
        );
        self.state.swap_in(t1);
        self.counters.steps += 1;
        if on_break {
            // Restart from the discontinuity with the new law value.
            self.consistent_acceleration(h, t1)?;
            self.stepper.restart();
        }
        Ok(true)
    }
}
