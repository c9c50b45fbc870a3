//! The driver's state and its stepping primitives: the [`Driver`] (model, method, step state,
//! step control, counters, ledger works, the scene's contact), its set-up at t = 0 from a
//! consistent acceleration, the solve of one trial step with the method (the held contact as its
//! constraint; a contact run with massless sections ends the step on their balance), and the
//! acceptance of a step with its work integrals (module docs of [`super`]).

use crate::chain::{AugmentedLayout, Chain, NONE};
use crate::error::FemError;
use crate::events::contact::Contact;
use crate::events::massless::Massless;
use crate::method::{
    Adaptive, Counters, NewtonSystem, StepContext, StepState, Stepper, Trial, Works,
    central_difference, start,
};
use crate::settings::Method;

/// Why [`Driver::step`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// A step was taken and the stop time is still ahead.
    Stepped,
    /// The step landed on the requested stop time.
    ReachedStop,
    /// The step was rejected by the error control; the state is unchanged and h reduced.
    Rejected,
}

/// Why the last step was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rejection {
    /// Newton failed (fixed step: the stretch is retried with a quarter step).
    Newton,
    /// Local error estimate above tolerance (adaptive steps).
    ErrorEstimate,
    /// A grazing contact whose phase is undetermined at this step length
    /// ([`crate::events::contact`]).
    ContactRefine,
}

/// Joint quantities at the start of the current step, for the trapezoidal work integrals.
#[derive(Debug, Clone)]
struct JointStart {
    torque_law_start: Vec<f64>,
    torque_req_start: Vec<f64>,
    theta_start: Vec<f64>,
    rate_start: Vec<f64>,
    /// Midpoint velocity ½(q̇₀ + q̇₁) of the step being booked.
    qd_mid: Vec<f64>,
}

/// The time stepper of a run: the model, the method, the state, the step control and the
/// scene's contact.
#[derive(Debug)]
pub struct Driver {
    pub chain: Chain,
    pub method: Method,
    pub(super) stepper: Box<dyn Stepper<Chain>>,
    pub state: StepState,
    pub newton: NewtonSystem<AugmentedLayout>,
    pub h: f64,
    /// The fixed step (the step returns to it after Newton-failure retries).
    pub h_nominal: f64,
    pub adaptive: Option<Adaptive>,
    /// Times the stepper must land on and restart from (torque-law discontinuities).
    pub(super) breakpoints: Vec<f64>,
    pub(super) next_break: usize,
    pub(super) stop: f64,
    pub counters: Counters,
    pub works: Works,
    joint_start: JointStart,
    /// Strain energy removed by the massless projection of the step being solved.
    pending_massless: f64,
    /// Largest link length (scales Newton and error tolerances).
    pub length_scale: f64,
    /// The scene's tip contact (energy-midpoint or implicit-midpoint; None without contact,
    /// nothing allocated).
    pub contact: Option<Box<Contact>>,
    /// The chain's exactly massless directions and their balances (Timoshenko links without
    /// rotary inertia; None otherwise, nothing allocated): the steps end on those balances when
    /// its `project` is set ([`crate::events::massless`]: the algebraic ones in runs without
    /// contact, the damped ones with a unilateral contact, whose impact map and normal force
    /// keep the rates consistent with them).
    pub massless: Option<Massless>,
    /// Why the last rejected step was rejected.
    pub last_rejection: Rejection,
    /// Positions and rates on the method's continuous extension of a trial step, where the
    /// unilateral contact's events are first located ([`super::contact_events`]); empty
    /// without that contact.
    pub(super) dense: (Vec<f64>, Vec<f64>),
}

impl Driver {
    /// Sets up the stepper at t = 0 from the scene's initial state; `rho_inf` is the
    /// generalized-α spectral radius at infinity.
    pub fn new(chain: Chain, method: Method, h: f64, rho_inf: f64) -> Result<Self, FemError> {
        let n = chain.ndof;
        let nl = chain.links.len();
        let length_scale = chain.links.iter().fold(0.0f64, |a, l| a.max(l.length));
        let newton = NewtonSystem::new(&chain, length_scale);
        let mut breakpoints: Vec<f64> = chain
            .links
            .iter()
            .filter_map(|l| l.joint.torque.as_ref())
            .flat_map(|law| law.breakpoints())
            .filter(|t| *t > 0.0)
            .collect();
        breakpoints.sort_by(f64::total_cmp);
        breakpoints.dedup();
        let mut it = Driver {
            chain,
            method,
            stepper: crate::method::stepper(method, n, rho_inf),
            state: StepState::new(n),
            newton,
            h,
            h_nominal: h,
            adaptive: None,
            breakpoints,
            next_break: 0,
            stop: f64::INFINITY,
            counters: Counters::default(),
            works: Works::default(),
            joint_start: JointStart {
                torque_law_start: vec![0.0; nl],
                torque_req_start: vec![0.0; nl],
                theta_start: vec![0.0; nl],
                rate_start: vec![0.0; nl],
                qd_mid: vec![0.0; n],
            },
            pending_massless: 0.0,
            length_scale,
            contact: None,
            massless: None,
            last_rejection: Rejection::Newton,
            dense: (Vec::new(), Vec::new()),
        };
        let st = &mut it.state;
        it.chain.initial_state(&mut st.q, &mut st.qd);
        // The unsettled rest configuration (v = 0) is kept in q1 for the initial acceleration.
        st.q1.copy_from_slice(&st.q);
        it.chain.settle_massless(0.0, &mut st.q, &st.qd)?;
        // Undamped massless sections: every step ends on their algebraic balance, from
        // consistent rates at the start on (crate::events::massless). A unilateral contact
        // replaces this with the damped balances (`enable_unilateral_contact`).
        if crate::method::capabilities(method).projects_massless
            && let Some(mut ml) = Massless::algebraic(&it.chain)
        {
            it.counters.rhs += ml.form(&mut it.chain, 0.0, &st.q);
            if ml.damped(&mut it.chain, 0.0, &st.q) {
                ml.project = true;
                it.counters.rhs += ml.make_consistent(&mut it.chain, 0.0, &st.q, &mut st.qd)?;
            }
            it.massless = Some(ml);
        }
        it.initial_acceleration(0.0)?;
        Ok(it)
    }

    /// Switches on the stepping of the scene's unilateral tip contact (set in `self.contact`;
    /// energy-midpoint): the chain's massless directions (if any, with Kelvin–Voigt) are
    /// projected onto their damped balance and given consistent rates after every step
    /// ([`crate::events::massless`]), and the Newton matrix and iteration are those of
    /// [`NewtonSystem::unilateral_contact`]. Forms the operators here (nothing is allocated in
    /// the step loop).
    pub fn enable_unilateral_contact(&mut self) -> Result<(), FemError> {
        self.newton.unilateral_contact = true;
        let n = self.state.q.len();
        self.dense = (vec![0.0; n], vec![0.0; n]);
        self.massless = Massless::new(&self.chain);
        if !crate::method::capabilities(self.method).projects_massless {
            return Ok(());
        }
        let Some(ml) = self.massless.as_mut() else {
            return Ok(());
        };
        let st = &mut self.state;
        self.counters.rhs += ml.form(&mut self.chain, st.t, &st.q);
        if ml.damped(&mut self.chain, st.t, &st.q) {
            ml.project = true;
            self.counters.rhs += ml.make_consistent(&mut self.chain, st.t, &st.q, &mut st.qd)?;
        }
        Ok(())
    }

    /// Sets the next time the stepper must land on.
    pub fn set_stop(&mut self, t_stop: f64) {
        self.stop = t_stop;
    }

    /// The stepper and what it works on during a step (disjoint borrows of the driver).
    fn method_parts(&mut self) -> (&mut dyn Stepper<Chain>, StepContext<'_, Chain>) {
        let cx = StepContext {
            system: &mut self.chain,
            state: &mut self.state,
            newton: &mut self.newton,
            counters: &mut self.counters,
            adaptive: self.adaptive,
            h_nominal: self.h_nominal,
            length_scale: self.length_scale,
            method_works: true,
        };
        (self.stepper.as_mut(), cx)
    }

    /// Consistent q̈ at the current state ([`start::consistent_acceleration`]) and the joint
    /// quantities of the next step's start.
    pub(super) fn initial_acceleration(&mut self, t_law: f64) -> Result<(), FemError> {
        let h = self.h;
        let (_, mut cx) = self.method_parts();
        start::consistent_acceleration(&mut cx, h, t_law)?;
        self.record_step_start(t_law);
        Ok(())
    }

    /// Solves the step of length h from the current state with the method (the contact, when
    /// held, as its constraint); a converged step of a run whose massless sections are
    /// projected ends on their balance.
    pub(crate) fn solve(&mut self, h: f64, t1: f64, t_law: f64) -> Result<Trial, FemError> {
        let mut contact = self.contact.take();
        let held = contact
            .as_deref_mut()
            .filter(|c| c.phase.constrained)
            .map(|c| c as &mut dyn crate::method::StepConstraint<Chain>);
        let (stepper, mut cx) = self.method_parts();
        let result = stepper.step(&mut cx, held, h, t1, t_law);
        self.contact = contact;
        match result? {
            Trial::NewtonFailed => Ok(Trial::NewtonFailed),
            converged => {
                self.pending_massless = 0.0;
                self.end_on_massless_balance(h, t1)?;
                Ok(converged)
            }
        }
    }

    /// Runs with projected massless section rotations ([`crate::events::massless`]): the end
    /// positions projected onto their balance (strain energy removed booked), the end rates,
    /// which the step does not determine, set from the balances, and the mean acceleration
    /// with them.
    fn end_on_massless_balance(&mut self, h: f64, t1: f64) -> Result<(), FemError> {
        let Some(ml) = self.massless.as_mut().filter(|m| m.project) else {
            return Ok(());
        };
        let st = &mut self.state;
        let (removed, p) = ml.project_balance(&mut self.chain, t1, &mut st.q1);
        let (kinetic, pr) = ml.end_rates(&mut self.chain, t1, &st.q1, &mut st.qd1)?;
        self.pending_massless = removed + kinetic;
        self.counters.rhs += p + pr;
        for i in 0..st.q1.len() {
            st.qdd1[i] = (st.qd1[i] - st.qd[i]) / h;
        }
        st.a1.copy_from_slice(&st.qdd1);
        Ok(())
    }

    /// Explicit step bound of the linearized system at the current state and the DOF where
    /// the binding mode is largest ([`central_difference::stability_bound`]).
    pub fn stability_bound(&mut self) -> Result<(f64, usize), FemError> {
        central_difference::stability_bound(&mut self.chain, &self.state, &mut self.newton.res)
    }

    /// Stores the joint quantities at the start of a step for the work integrals.
    fn record_step_start(&mut self, t_law: f64) {
        for li in 0..self.chain.links.len() {
            let (th, rate) =
                self.chain
                    .joint_state(li, self.state.t, &self.state.q, &self.state.qd);
            self.joint_start.theta_start[li] = th;
            self.joint_start.rate_start[li] = rate;
            self.joint_start.torque_law_start[li] = self.chain.links[li].joint.applied(t_law);
            self.joint_start.torque_req_start[li] = if self.chain.links[li].joint.dof == NONE {
                self.chain.joint_torque[li]
            } else {
                0.0
            };
        }
    }

    /// Commits q1, q̇1, q̈1 and updates the work integrals.
    pub(super) fn accept(&mut self, h: f64, t1: f64, t_law: f64) {
        // The massless projection of the step end is the driver's, whoever books the rest.
        self.works.numerical_massless += self.pending_massless;
        if self.stepper.commit(h, &mut self.works) {
            // The method booked its works with its own quadrature (energy-midpoint, Bathe);
            // the required torques of prescribed joints are not in its DOFs.
            for li in 0..self.chain.links.len() {
                if self.chain.links[li].joint.dof == NONE {
                    self.book_prescribed_motion(li, t1);
                }
            }
            self.finish_accept(t1, t_law);
            return;
        }
        let nl = self.chain.links.len();
        // Midpoint velocity: ½(F_n + F_{n+1})·Δq for linear dampers under the trapezoidal rule.
        for i in 0..self.state.qd.len() {
            self.joint_start.qd_mid[i] = 0.5 * (self.state.qd[i] + self.state.qd1[i]);
        }
        let (_, p_kv) = self.chain.dissipation_power(t1, &self.joint_start.qd_mid);
        self.works.kelvin_voigt += p_kv * h;
        self.works.applied_load += self.chain.load_power(&self.joint_start.qd_mid) * h;
        for li in 0..nl {
            let (th1, rate1) = self
                .chain
                .joint_state(li, t1, &self.state.q1, &self.state.qd1);
            let dth = th1 - self.joint_start.theta_start[li];
            let j = &self.chain.links[li].joint;
            let law1 = j.applied(t_law);
            self.works.applied_torque += 0.5 * (self.joint_start.torque_law_start[li] + law1) * dth;
            self.works.joint_damper +=
                0.5 * j.damping * (self.joint_start.rate_start[li] + rate1) * dth;
            if j.dof == NONE {
                self.book_prescribed_motion(li, t1);
            }
        }
        self.finish_accept(t1, t_law);
    }

    /// The work of the torque a prescribed joint `li` required over the accepted step, by the
    /// trapezoidal rule on its end points.
    fn book_prescribed_motion(&mut self, li: usize, t1: f64) {
        let (th1, _) = self
            .chain
            .joint_state(li, t1, &self.state.q1, &self.state.qd1);
        let dth = th1 - self.joint_start.theta_start[li];
        let req1 = self.chain.joint_torque[li];
        self.works.prescribed_motion += 0.5 * (self.joint_start.torque_req_start[li] + req1) * dth;
    }

    /// Swaps the new state in and starts the next step's work records.
    fn finish_accept(&mut self, t1: f64, t_law: f64) {
        self.state.swap_in(t1);
        self.counters.steps += 1;
        self.record_step_start(t_law);
    }
}
