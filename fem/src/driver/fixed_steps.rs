//! A [`System`] stepped by a method of the registry in fixed steps that land on the caller's
//! stop times, for the models without events (the 3-D payload link, the rocket): the method,
//! its state, Newton system and counters ([`FixedSteps`]), and the retry of a step whose
//! Newton iteration fails as four quarter steps, the trial step landing on the laws' jumps
//! ([`QuarterRetries`]). Each model's driver says where its laws jump and books its own works.

use crate::error::FemError;
use crate::method::{Counters, NewtonSystem, StepContext, StepState, Stepper, Trial, start};
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

/// A model's driver over [`FixedSteps`]: where its laws jump and what it books of a step; the
/// trial step and the step with retries are the same for every model.
pub trait QuarterRetries {
    type System: System<Augmented = NoAugmentation>;

    /// The stepped system.
    fn steps(&mut self) -> &mut FixedSteps<Self::System>;

    /// Whether a step of length h ending at t₁ ends on a jump of the model's laws (a motor
    /// law's switch, burn-out): the step then takes the laws' left limit and the method
    /// restarts after it.
    fn ends_on_jump(&self, h: f64, t1: f64) -> bool;

    /// Books the works of the solved step of length h (the state holds its start and its
    /// trial end).
    fn book(&mut self, h: f64);

    /// One step of length h onto t₁, its works booked; false (state unchanged) when its Newton
    /// iteration did not converge. A step that ends on a jump evaluates the laws as their left
    /// limit, and the method restarts there from a consistent acceleration
    /// ([`crate::method::start`]).
    fn try_step(&mut self, h: f64, t1: f64) -> Result<bool, FemError> {
        let on_jump = self.ends_on_jump(h, t1);
        let t_law = if on_jump { t1 - 1e-9 * h } else { t1 };
        let (stepper, mut cx) = self.steps().parts();
        if stepper.step(&mut cx, None, h, t1, t_law)? == Trial::NewtonFailed {
            return Ok(false);
        }
        self.book(h);
        let steps = self.steps();
        steps.state.swap_in(t1);
        steps.counters.steps += 1;
        if on_jump {
            steps.consistent_acceleration(h, t1)?;
            steps.restart();
        }
        Ok(true)
    }

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
