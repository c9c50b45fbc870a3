//! The payload link's run: the model as a [`PayloadLinkSystem`], stepped by the velocity form
//! ([`VelocityForm`], implicit Kelvin–Voigt damping in its closing kick) inside
//! [`crate::driver::run`] (step choice and refusal, watch, sampled outputs, ledger).

use data::scene::{LinkInitialShape, PayloadLink};
use data::{RunResult, Scene};

use super::PayloadLinkModel;
use super::system::PayloadLinkSystem;
use crate::driver::{StepControl, choose_step, run};
use crate::error::FdmError;
use crate::events::NoEvents;
use crate::method::{Stepper, VelocityForm};
use crate::settings::{Method, ValidatedSettings};

impl PayloadLinkModel {
    /// Ledger term names: stored, inputs, dissipation.
    pub fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        use super::BaseDrive;
        use data::ledger_term;
        let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
        if self.f_gravity.is_some() {
            stored.push(ledger_term::GRAVITY);
        }
        let mut inputs = Vec::new();
        let mut diss = Vec::new();
        match &self.drive {
            BaseDrive::Prescribed(_) => inputs.push(ledger_term::PRESCRIBED_MOTION),
            BaseDrive::Free {
                law,
                stiffness,
                damping,
                ..
            } => {
                if *stiffness != 0.0 {
                    stored.push(ledger_term::JOINT_SPRING);
                }
                if law.is_some() {
                    inputs.push(ledger_term::APPLIED_TORQUE);
                }
                if *damping != 0.0 {
                    diss.push(ledger_term::JOINT_DAMPER);
                }
            }
        }
        diss.extend(self.kv_names());
        (stored, inputs, diss)
    }
}

/// Runs the scene. Only the velocity form steps the 3-D link: a requested two-step method is
/// refused (its explicit damping would need the damped step bound, and its computational mode
/// grows under the Kelvin–Voigt and Coriolis forces).
pub fn simulate(
    scene: &Scene,
    p: &PayloadLink,
    s: &ValidatedSettings,
) -> Result<RunResult, FdmError> {
    if s.requested.method.is_some() && s.method != Method::VelocityForm {
        return Err(FdmError::Unsupported(format!(
            "fdm: the 3-D payload link with time.method = {}: only velocity-form steps it (its \
             Kelvin–Voigt damping is implicit in the velocity form's closing kick)",
            s.method.name()
        )));
    }
    let model = PayloadLinkModel::from_payload_link(scene, p, s.stations)?;
    let mut sys = PayloadLinkSystem::new(model)?;
    let ctl = StepControl::for_scene(scene, s, Method::VelocityForm, false, true);
    let mut method = VelocityForm::drift_split();
    // the step is constant (the bound does not move): A = M_ff + ½τC factored once, before
    // the start level needs it
    let (tau, _, _) = choose_step(&sys, &ctl, method.bound_factor(), 0.0)?;
    sys.set_step(tau)?;
    let (q0, v0) = sys.initial_state(p.initial_shape == LinkInitialShape::StaticSag)?;
    let mut out = run(&mut sys, &mut method, &mut NoEvents, &q0, &v0, &ctl)?;
    out.cost.factorizations = sys.factorizations();
    Ok(out.into_run_result(scene, s))
}
