//! Integration methods for q̇ = v, v̇ = a(t, q, v): one type per method behind [`Stepper`].
//!
//! A method advances the levels of a [`StepState`] by one step of a length the driver chose:
//! [`Stepper::predict`] builds the new level's positions (and the velocities known without a
//! force evaluation), the driver checks them ([`crate::driver`]: growth of the computational
//! mode, non-finite states), then [`Stepper::complete`] evaluates the forces at the new level.
//! A method knows nothing of scene families, events or outputs; it reports its stability limit
//! relative to the model's σ ([`Stepper::bound_factor`]).
//!
//! Methods: [`two_step`] (the report's central difference 5.21, optionally Robert–Asselin
//! filtered) and [`velocity_form`] (one-step kick–drift–kick). [`stepper`] maps the setting
//! `time.method` to its type.

pub mod two_step;
pub mod velocity_form;

use crate::settings::Method;
use crate::system::System;

pub use two_step::TwoStep;
pub use velocity_form::VelocityForm;

/// Positions and velocities of one time level.
pub struct Levels {
    pub q: Vec<f64>,
    pub v: Vec<f64>,
}

impl Levels {
    pub fn new(n: usize) -> Self {
        Levels {
            q: vec![0.0; n],
            v: vec![0.0; n],
        }
    }
}

/// The levels a method advances: y_{j−1}, y_j and the new y_{j+1}, the accelerations at j and
/// j+1, the predicted step-end velocity, and the model's powers at j and j+1 (for the ledger).
pub struct StepState {
    pub prev: Levels,
    pub cur: Levels,
    pub next: Levels,
    /// a(t_j, q_j, v_j)
    pub acc: Vec<f64>,
    /// a at the new level (after [`Stepper::complete`]); scratch before
    pub acc_next: Vec<f64>,
    /// the step-end velocity a one-step method predicts before its force evaluation
    pub pred: Vec<f64>,
    /// powers at level j and at the new level
    pub p_cur: Vec<f64>,
    pub p_new: Vec<f64>,
}

impl StepState {
    /// `n` coordinates, `np` powers, at rest.
    pub fn new(n: usize, np: usize) -> Self {
        StepState {
            prev: Levels::new(n),
            cur: Levels::new(n),
            next: Levels::new(n),
            acc: vec![0.0; n],
            acc_next: vec![0.0; n],
            pred: vec![0.0; n],
            p_cur: vec![0.0; np],
            p_new: vec![0.0; np],
        }
    }

    /// The new level becomes level j (and level j becomes j−1).
    pub fn rotate(&mut self) {
        std::mem::swap(&mut self.prev, &mut self.cur);
        std::mem::swap(&mut self.cur, &mut self.next);
        std::mem::swap(&mut self.acc, &mut self.acc_next);
        std::mem::swap(&mut self.p_cur, &mut self.p_new);
    }
}

/// One explicit integration method.
pub trait Stepper {
    /// Ratio of the method's stability limit to the model's σ (the one-step limit 2/ω_max).
    fn bound_factor(&self) -> f64;
    /// Whether the method carries a computational (parasitic) mode.
    fn has_computational_mode(&self) -> bool;
    /// Largest |Δ²v| / peak |v| a resolved physical mode can show at the method's limit, plus
    /// margin: above it the driver reports a growing computational mode.
    fn parasitic_threshold(&self) -> f64;
    /// Start-up from level j = 0 (`cur`, `acc`, `p_cur` set): a method that needs a second
    /// level builds it as a step of length `tau` into `next`, `acc_next`, `p_new` and returns
    /// the number of force evaluations it made; 0 when no start-up step is needed.
    fn start(&mut self, sys: &mut dyn System, t: f64, tau: f64, st: &mut StepState) -> usize;
    /// First half of the step from t_j (previous step `tau_prev`) by `tau`: the new level's
    /// positions in `next.q`; may update level j itself (a filter).
    fn predict(&mut self, tau_prev: f64, tau: f64, st: &mut StepState);
    /// The step-end velocities known after [`Stepper::predict`] (monitored by the driver).
    fn predicted_velocity<'a>(&self, st: &'a StepState) -> &'a [f64];
    /// Second half: the force evaluation at t_new = t_j + `tau` into `acc_next` and `p_new`,
    /// and the final velocities in `next.v` (one force evaluation).
    fn complete(
        &mut self,
        sys: &mut dyn System,
        t_new: f64,
        tau_prev: f64,
        tau: f64,
        st: &mut StepState,
    );
}

/// The method of the setting `time.method` (the registration point of a new method).
pub fn stepper(method: Method) -> Box<dyn Stepper> {
    match method {
        Method::Report => Box::new(TwoStep::central_difference()),
        Method::RobertAsselin { nu } => Box::new(TwoStep::robert_asselin(nu)),
        Method::VelocityForm => Box::new(VelocityForm::drift_split()),
    }
}
