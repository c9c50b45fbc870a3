//! The mobile manipulator as a reduced system ([`ReducedSystem`]): the model with its torque
//! schedules, and the scratch of its evaluations.
//!
//! The midpoint configuration is explicit: S depends on the heading ψ only and ψ̇ on ν only,
//! so ψ̄ = ψ + ½h ψ̇(ν̄) first, then q̄ = q + ½h S(q̄) ν̄. The works are the wheel and joint
//! inputs τ·ν and the viscous friction b ν² of the wheels' sides and of the joints.

use data::scene::TorqueSchedule;

use super::model::{Model, Workspace};
use crate::method::reduced::ReducedSystem;

/// The torque inputs: side torques (τ_R, τ_L) and joint torques τ₁…τ₄.
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs {
    pub drive: Option<TorqueSchedule>,
    pub arm: TorqueSchedule,
}

impl Inputs {
    /// τ in ν order (zero on the elastic speeds).
    pub fn at(&self, model: &Model, t: f64, tau: &mut [f64]) {
        tau.fill(0.0);
        if let Some(d) = &self.drive {
            tau[0] = d.torque(0, t);
            tau[1] = d.torque(1, t);
        }
        let a = model.layout.nu_arm;
        for i in 0..4 {
            tau[a + i] = self.arm.torque(i, t);
        }
    }

    /// Schedule discontinuities inside (0, t_end), sorted.
    pub fn breakpoints(&self, t_end: f64) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .drive
            .iter()
            .chain(std::iter::once(&self.arm))
            .flat_map(|s| s.breakpoints(t_end))
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}

/// Integrated works: wheel input, joint input, wheel friction, joint friction.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Works {
    pub wheel_torque: f64,
    pub joint_torque: f64,
    pub wheel_friction: f64,
    pub joint_friction: f64,
}

/// The model, its inputs and evaluation scratch (allocated once).
#[derive(Debug, Clone)]
pub struct MobileSystem {
    pub model: Model,
    pub inputs: Inputs,
    ws: Workspace,
    tau: Vec<f64>,
    /// the time `tau` holds the torques of (NaN: none yet): a step evaluates them once, at its
    /// midpoint, for all its Newton iterations and its booking
    tau_time: f64,
    qd: Vec<f64>,
    sdn: Vec<f64>,
}

impl MobileSystem {
    pub fn new(model: Model, inputs: Inputs) -> Self {
        let (n, m) = (model.layout.n, model.layout.m);
        MobileSystem {
            model,
            inputs,
            ws: Workspace::new(n),
            tau: vec![0.0; m],
            tau_time: f64::NAN,
            qd: vec![0.0; n],
            sdn: vec![0.0; n],
        }
    }

    /// The applied torques at time t (ν order).
    pub fn torques(&mut self, t: f64) -> &[f64] {
        if t != self.tau_time {
            self.inputs.at(&self.model, t, &mut self.tau);
            self.tau_time = t;
        }
        &self.tau
    }

    /// q̇ = S(q) ν.
    pub fn coordinate_rates(&mut self, q: &[f64], nu: &[f64]) -> &[f64] {
        self.model.velocities(q, nu, &mut self.qd, &mut self.sdn);
        &self.qd
    }
}

impl ReducedSystem for MobileSystem {
    type Works = Works;

    fn coordinates(&self) -> usize {
        self.model.layout.n
    }

    fn speeds(&self) -> usize {
        self.model.layout.m
    }

    fn midpoint_configuration(&mut self, q: &[f64], nubar: &[f64], h: f64, qbar: &mut [f64]) {
        qbar.copy_from_slice(q);
        if let Some(p) = &self.model.platform {
            let psid = 0.5 * p.wheel_radius / p.half_track * (nubar[0] - nubar[1]);
            qbar[2] = q[2] + 0.5 * h * psid;
        }
        self.model
            .velocities(qbar, nubar, &mut self.qd, &mut self.sdn);
        for i in 0..q.len() {
            qbar[i] = q[i] + 0.5 * h * self.qd[i];
        }
    }

    fn inertia_forces(
        &mut self,
        q: &[f64],
        nu: &[f64],
        nudot: &[f64],
        mass: Option<&mut [f64]>,
        force: &mut [f64],
    ) {
        self.model.evaluate(q, nu, nudot, &mut self.ws, mass, force);
    }

    fn applied_forces(&mut self, t: f64, nu: &[f64], out: &mut [f64]) {
        self.torques(t);
        self.model.applied(nu, &self.tau, out);
    }

    fn add_stiffness_and_damping(&self, c_k: f64, c_d: f64, matrix: &mut [f64]) {
        let l = self.model.layout;
        let m = l.m;
        if let Some(p) = &self.model.platform {
            for s in 0..2 {
                matrix[s * m + s] += c_d * p.side_friction;
            }
        }
        for i in 0..4 {
            let j = l.nu_arm + i;
            matrix[j * m + j] += c_d * self.model.joint_friction[i];
        }
        if let Some(fl) = &self.model.flex {
            for i in 0..fl.ne {
                for j in 0..fl.ne {
                    matrix[(l.nu_el + i) * m + l.nu_el + j] += c_k * fl.stiffness[i * fl.ne + j];
                }
            }
        }
    }

    fn book(&mut self, t: f64, nu: &[f64], weight: f64, works: &mut Works) {
        self.torques(t);
        let l = self.model.layout;
        if let Some(p) = &self.model.platform {
            for s in 0..2 {
                let r = nu[s];
                works.wheel_torque += weight * self.tau[s] * r;
                works.wheel_friction += weight * p.side_friction * r * r;
            }
        }
        for i in 0..4 {
            let j = l.nu_arm + i;
            let r = nu[j];
            works.joint_torque += weight * self.tau[j] * r;
            works.joint_friction += weight * self.model.joint_friction[i] * r * r;
        }
    }
}
