//! A [`System`] stepped by a method of the registry in fixed steps that land on the caller's
//! stop times, for the models without events (the 3-D payload link, the rocket): the method,
//! its state, Newton system and counters ([`FixedSteps`]), and the retry of a step whose
//! Newton iteration fails as four quarter steps ([`QuarterRetries`]). Each model's driver
//! keeps its own works and its own trial step (what it books, where its laws jump).

use crate::error::FemError;
use crate::method::{Counters, NewtonSystem, StepContext, StepState, Stepper, start};
use crate::settings::Method;
use crate::system::{NoAugmentation, System};

/// The method, state, Newton system and counters of a system stepped in fixed steps.
#[derive(Debug)]
pub struct FixedSteps<S: System> {
    pub system: S,
    pub method: Method,
    stepper: Box<dyn Stepper<S>>,
    pub state: StepState,
    pub newton: NewtonSystem<NoAugmentation>,
    pub counters: Counters,
    /// The nominal step (a method's retries and tolerances are measured against it).
    pub h_nominal: f64,
    /// The model's length (scales the Newton tolerance).
    pub length_scale: f64,
}

impl<S: System<Augmented = NoAugmentation>> FixedSteps<S> {
    /// `system` from `state`, stepped by `method` with nominal step `h` (`rho_inf`:
    /// generalized-α's spectral radius).
    pub fn new(
        system: S,
        state: StepState,
        method: Method,
        h: f64,
        rho_inf: f64,
        length_scale: f64,
    ) -> Self {
        let n = system.ndof();
        let newton = NewtonSystem::new(&system, length_scale);
        FixedSteps {
            system,
            method,
            stepper: crate::method::stepper(method, n, rho_inf),
            state,
            newton,
            counters: Counters::default(),
            h_nominal: h,
            length_scale,
        }
    }

    /// The method and its step context (disjoint borrows).
    pub fn parts(&mut self) -> (&mut dyn Stepper<S>, StepContext<'_, S>) {
        let cx = StepContext {
            system: &mut self.system,
            state: &mut self.state,
            newton: &mut self.newton,
            counters: &mut self.counters,
            adaptive: None,
            h_nominal: self.h_nominal,
            length_scale: self.length_scale,
            method_works: false,
        };
        (self.stepper.as_mut(), cx)
    }

    /// The consistent acceleration at the current state, the laws evaluated at `t_law`.
    pub fn consistent_acceleration(&mut self, h: f64, t_law: f64) -> Result<(), FemError> {
        let (_, mut cx) = self.parts();
        start::consistent_acceleration(&mut cx, h, t_law)
    }

    /// Whether the method needs every stretch between stop times split into equal steps.
    pub fn equal_steps(&self) -> bool {
        self.stepper.equal_steps()
    }

    /// Forgets the method's history (after a law's jump or a retried step).
    pub fn restart(&mut self) {
        self.stepper.restart();
    }

    /// Hands the method's own works of the accepted step to `works`.
    pub fn commit(&mut self, h: f64, works: &mut crate::method::Works) {
        self.stepper.commit(h, works);
    }
}

/// A model's driver over [`FixedSteps`]: its trial step, and the step with retries.
pub trait QuarterRetries {
    type System: System<Augmented = NoAugmentation>;

    /// The stepped system.
    fn steps(&mut self) -> &mut FixedSteps<Self::System>;

    /// One step of length h onto t₁, its works booked; false (state unchanged) when its Newton
    /// iteration did not converge.
    fn try_step(&mut self, h: f64, t1: f64) -> Result<bool, FemError>;

    /// One step of length h onto t₁ (the caller snaps t₁ to its stop time). A step whose Newton
    /// iteration fails is retried as four quarter steps (recursively, down to 10⁻⁶ of the
    /// nominal step), the method restarted.
    fn step(&mut self, h: f64, t1: f64) -> Result<(), FemError> {
        if self.try_step(h, t1)? {
            return Ok(());
        }
        let steps = self.steps();
        let t0 = steps.state.t;
        if h <= 1e-6 * steps.h_nominal {
            return Err(FemError::Runaway {
                t: t0,
                what: format!(
                    "Newton iteration of the {} step did not converge",
                    steps.method
                ),
                location: None,
                why: format!("step h = {h:.3e} s too long for the motion"),
                remedy: "reduce --dt".into(),
            });
        }
        steps.counters.rejected += 1;
        steps.restart();
        for k in 1..=4 {
            let tk = if k == 4 { t1 } else { t0 + 0.25 * k as f64 * h };
            let t = self.steps().state.t;
            self.step(tk - t, tk)?;
        }
        Ok(())
    }
}
