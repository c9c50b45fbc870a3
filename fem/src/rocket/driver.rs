//! The rocket's driver path: the [`RocketSystem`] stepped by a method of the registry
//! ([`crate::method::stepper`]) in fixed steps, with the rocket's ledger works.
//!
//! Steps land on the output times and on burn-out (the caller stops there: thrust, pressure and
//! the mass rate jump). A step that ends on burn-out evaluates the laws as their left limit, and
//! the method restarts there from a consistent acceleration ([`crate::method::start`]), as the
//! payload link does at its motor-law switches. A step whose Newton iteration fails is retried as
//! four quarter steps.
//!
//! **Works** are booked after every accepted step from its end states only, so the booking is
//! the same for every method: the loads' powers P(t_mid, q̄, v̄) at q̄ = ½(q₀ + q₁),
//! v̄ = ½(q̇₀ + q̇₁) times h, and the energy the burnt mass carries off,
//!
//!   D_out = −½[(m₁(t_mid) − m₁(t₀)) q̇₀ᵀM_burn q̇₀ + (m₁(t₁) − m₁(t_mid)) q̇₁ᵀM_burn q̇₁]
//!           + (m₁(t₁) − m₁(t₀)) Gᵀ M_burn (x_ref + q̄),
//!
//! the trapezoidal rule of its kinetic part −½∫ṁ₁ q̇ᵀM_burn q̇ dt and the midpoint rule of its
//! potential part ∫ṁ₁ GᵀM_burn(x_ref + q) dt (ṁ₁ is constant within a step: steps stop at
//! burn-out). For the implicit midpoint rule (q̄, v̄) is the scheme's own midpoint and the
//! balance is exact: with M(t_mid)(q̇₁ − q̇₀) = hF and v̄ = ½(q̇₀ + q̇₁), ½q̇₁ᵀM(t₁)q̇₁ −
//! ½q̇₀ᵀM(t₀)q̇₀ = h v̄·F + the kinetic part above, and the gravity potential's change is
//! h v̄·M(t_mid)G − its potential part; the ledger then closes to the Newton tolerance and the
//! O(h³) midpoint error of the cubic strain term. For the other (second-order) methods the same
//! booking is a second-order quadrature of the works, and the ledger closes to the method's
//! O(h²) energy error.

use crate::driver::fixed_steps::{FixedSteps, QuarterRetries};
use crate::error::FemError;
use crate::method::StepState;
use crate::settings::Method;
use crate::system::System;

use super::model::Model;
use super::system::RocketSystem;

/// Cumulative works (inputs) and dissipations of the rocket's ledger.
#[derive(Debug, Clone, Copy, Default)]
pub struct RocketWorks {
    pub thrust: f64,
    pub pressure: f64,
    pub coriolis: f64,
    pub damper: f64,
    pub outflow: f64,
}

/// The stepped rocket: system, method and state ([`FixedSteps`]), and the ledger works.
#[derive(Debug)]
pub struct RocketDriver {
    pub steps: FixedSteps<RocketSystem>,
    pub works: RocketWorks,
    /// Burn-out time (∞ without a burn).
    pub burnout: f64,
    qbar: Vec<f64>,
    vbar: Vec<f64>,
}

impl RocketDriver {
    /// The rocket `model` in the shape `q0` at rest at t = 0, stepped by `method` with nominal
    /// step `h` (`rho_inf`: generalized-α's spectral radius); the start's consistent
    /// acceleration solved.
    pub fn new(
        model: Model,
        q0: &[f64],
        method: Method,
        h: f64,
        rho_inf: f64,
    ) -> Result<Self, FemError> {
        let n = model.n;
        let burnout = model.burnout_time();
        let length = model.length;
        let system = RocketSystem::new(model);
        let mut state = StepState::new(n);
        state.q.copy_from_slice(q0);
        let mut steps = FixedSteps::new(system, state, method, h, rho_inf, length);
        steps.newton.tol = newton_tolerance(&steps.system.model, h);
        let mut it = RocketDriver {
            steps,
            works: RocketWorks::default(),
            burnout,
            qbar: vec![0.0; n],
            vbar: vec![0.0; n],
        };
        it.steps.consistent_acceleration(h, 0.0)?;
        Ok(it)
    }

    /// Sets the nominal step (and the Newton tolerance that scales with it).
    pub fn set_step(&mut self, h: f64) {
        self.steps.h_nominal = h;
        self.steps.newton.tol = newton_tolerance(&self.steps.system.model, h);
    }

    /// Stored energies at the current state, in the ledger's order: kinetic, strain, gravity,
    /// discrete springs.
    pub fn stored(&self) -> [f64; 4] {
        let st = &self.steps.state;
        let [kinetic, strain, spring, gravity] = self.steps.system.energies(st.t, &st.q, &st.qd);
        [kinetic, strain, gravity, spring]
    }
}

impl QuarterRetries for RocketDriver {
    type System = RocketSystem;

    fn steps(&mut self) -> &mut FixedSteps<RocketSystem> {
        &mut self.steps
    }

    /// On burn-out (the caller snaps the step to it): thrust, pressure and the mass rate jump.
    fn ends_on_jump(&self, _h: f64, t1: f64) -> bool {
        t1 == self.burnout
    }

    /// The works of the solved step t₀ → t₀ + h (module docs).
    fn book(&mut self, h: f64) {
        let st = &self.steps.state;
        let (t0, tm, t1) = (st.t, st.t + 0.5 * h, st.t + h);
        for i in 0..st.q.len() {
            self.qbar[i] = 0.5 * (st.q[i] + st.q1[i]);
            self.vbar[i] = 0.5 * (st.qd[i] + st.qd1[i]);
        }
        let p = self.steps.system.powers(tm, &self.qbar, &self.vbar);
        self.steps.counters.rhs += 1;
        let m = &self.steps.system.model;
        let (m0, mm, m1) = (m.m1(t0), m.m1(tm), m.m1(t1));
        let kin = -0.5
            * ((m1 - mm) * m.m_burn.form(&st.qd1, &st.qd1)
                + (mm - m0) * m.m_burn.form(&st.qd, &st.qd));
        for i in 0..st.q.len() {
            self.qbar[i] += m.x_ref[i];
        }
        let pot = (m1 - m0) * m.m_burn.form(&self.steps.system.gravity, &self.qbar);
        let w = &mut self.works;
        w.thrust += h * p.thrust;
        w.pressure += h * p.pressure;
        w.coriolis += h * p.coriolis;
        w.damper += h * p.damper;
        w.outflow += kin + pot;
    }
}

/// The Newton tolerance on the position update of a step h: a velocity update of 10⁻¹³ of
/// the rocket's velocity scale (the exhaust velocity, of which every rigid velocity change is a
/// fraction ln(M₀/M); √(gL) without a burn) as a position change over half a step (the
/// methods add the round-off floor 10⁻¹³(c_q|q̈| + h|q̇|), [`crate::method`]). On the catalog
/// rocket 7·10⁻⁹ in/s: below it the quasi-Newton updates stall at round-off (the rigid
/// translation in K q) and steps were retried shorter; the methods' default 10⁻¹¹ of the length
/// (1.5·10⁻⁹ in) is far above the displacements one step of 10 µs resolves.
fn newton_tolerance(model: &Model, h: f64) -> f64 {
    let v_scale = model.exhaust_velocity.max((model.g * model.length).sqrt());
    1e-13 * v_scale * 0.5 * h
}
