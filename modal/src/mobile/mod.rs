//! # The mobile manipulator of seed 004 with a flexible pitch link, by assumed modes
//!
//! The rigid part (skid-steer platform under the no-sideways-slip and rolling constraints, yaw
//! joint θ₁, pitch joints θ₂…θ₄, gripper, joint and wheel friction, gravity, piecewise-constant
//! torques) is the model of docs/mobile-manipulator.md, written here with its own kinematics.
//! The pitch link named by `[mobile_manipulator.flexible_link]` is an Euler–Bernoulli beam in
//! its joint frame F, clamped at the joint (linear floating frame of reference: no axial, no
//! torsion, no foreshortening, no geometric stiffening):
//!
//! ```text
//! p(x) = o_F + R_F (x e_x + v(x) e_y + w(x) e_z),  v = Σ φₖ bₖ (out of plane, EI_out),
//!                                                  w = Σ φₖ cₖ (in plane, EI_in)
//! T = Σ rigid bodies + ½∫ μ |ṗ|² dx + ½ ω_F·R_F J_res R_Fᵀ ω_F,   μ = m/L,
//!     J_res = J − diag(0, mL²/12, mL²/12)
//! V = Σ m g z + ∫ μ g p_z dx + ½∫ (EI_out v″² + EI_in w″²) dx
//! R_tip = R_F R_z(v′(L)) R_y(−w′(L)),  next pitch frame R_tip R_y(−θ)
//! ```
//!
//! At EI → ∞ this is the rigid link of the reference exactly (mass m, mass centre L/2, inertia
//! J). Equations: Kane's form of the null-space Lagrange equations ([`model`]); run: [`run`];
//! `modes`: the elastic modes linearized about the initial pose with the platform and every
//! joint held (K x = ω² M_ee x, M_ee the elastic block of the reduced mass matrix at q₀: the
//! distal arm and gripper act as the tip body in their initial pose).
//!
//! The linear model is adequate here: the axial load on the link is at most the distal weight
//! and its inertial share (≲ 10 N), P L²/EI ≲ 1e-3 at the scene's EI = 784 N m², so geometric
//! stiffening changes frequencies by ≲ 0.1 %; the joint rates are ≲ a few rad/s, far below the
//! first elastic frequency (∼ 10² rad/s), so centrifugal stiffening is of the same small order.

pub mod model;
mod modes;
pub mod run;

use data::scene::{MobileManipulator, TorqueSchedule};
use data::{Basis, DofPlan, ModalSettings};

use crate::error::ModalError;
use model::{MobileModel, ShapeChoice};

pub use modes::modes;
pub use run::simulate;

/// Assumed modes per direction when the settings give none.
pub const DEFAULT_MODES: usize = 3;
/// Largest modes count per direction.
pub const MAX_MODES: usize = 12;

/// The torque schedules in ν order (τ_R, τ_L, τ₁…τ₄ as present).
#[derive(Debug, Clone)]
pub struct Inputs {
    pub drive: Option<TorqueSchedule>,
    pub arm: Option<TorqueSchedule>,
}

impl Inputs {
    pub fn at(&self, t: f64, tau: &mut [f64]) {
        tau.fill(0.0);
        let mut k = 0;
        if let Some(d) = &self.drive {
            tau[0] = d.torque(0, t);
            tau[1] = d.torque(1, t);
            k = 2;
        }
        if let Some(a) = &self.arm {
            for i in 0..4 {
                tau[k + i] = a.torque(i, t);
            }
        }
    }

    pub fn breakpoints(&self, t_end: f64) -> Vec<f64> {
        let mut b: Vec<f64> = self
            .drive
            .iter()
            .chain(self.arm.iter())
            .flat_map(|s| s.breakpoints(t_end))
            .collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}

/// Modes count and shape family of the settings, checked.
pub fn shape_choice(settings: &ModalSettings) -> Result<(usize, ShapeChoice), ModalError> {
    let n = settings.modes.unwrap_or(DEFAULT_MODES);
    if n == 0 || n > MAX_MODES {
        return Err(ModalError::invalid(
            "discretization.modes",
            format!("{n} modes per direction: the flexible link takes 1 to {MAX_MODES}"),
        ));
    }
    let choice = match settings.basis {
        None | Some(Basis::Poly) => ShapeChoice::Poly,
        Some(Basis::ClampedFree) => ShapeChoice::ClampedFree,
        Some(other) => {
            return Err(ModalError::invalid(
                "discretization.basis",
                format!(
                    "`{}` is not offered for the mobile manipulator: `poly` (the default) or \
                     `clamped-free`",
                    other.name()
                ),
            ));
        }
    };
    Ok((n, choice))
}

/// The model and inputs of the mobile manipulator `mm`.
pub fn set_up(
    mm: &MobileManipulator,
    settings: &ModalSettings,
) -> Result<(MobileModel, Inputs), ModalError> {
    let (n, choice) = shape_choice(settings)?;
    let model = MobileModel::new(mm, n, choice)?;
    let inputs = Inputs {
        drive: mm.platform.as_ref().map(|p| p.drive.clone()),
        arm: mm.arm.as_ref().map(|a| a.torques.clone()),
    };
    Ok((model, inputs))
}

/// Degrees of freedom and physics built for the scene.
pub fn dof_plan(mm: &MobileManipulator, settings: &ModalSettings) -> Result<DofPlan, ModalError> {
    let (model, _) = set_up(mm, settings)?;
    let l = model.layout;
    let mut plan = DofPlan::default();
    if l.platform.is_some() {
        plan.add("platform velocity freedoms (φ̇_R, φ̇_L)", 2);
        plan.builds.push(
            "platform x, y, ψ, φ_R, φ_L under 3 nonholonomic constraints (null-space speeds)"
                .into(),
        );
    }
    if l.arm.is_some() {
        plan.add("arm joints θ₁…θ₄", 4);
        plan.builds
            .push("turret, pitch links and gripper with full inertia tensors".into());
    }
    if let Some(fl) = &model.flex {
        plan.add(format!("link {} out-of-plane modes (v)", fl.link), l.modes);
        plan.add(format!("link {} in-plane modes (w)", fl.link), l.modes);
        let (_, choice) = shape_choice(settings)?;
        plan.builds.push(format!(
            "flexible pitch link {}: Euler–Bernoulli, {} assumed modes, residual rigid inertia",
            fl.link,
            match choice {
                ShapeChoice::Poly => "integrated Legendre polynomial (poly)",
                ShapeChoice::ClampedFree => "clamped-free eigenfunction",
            }
        ));
    }
    if model.gravity != 0.0 && l.arm.is_some() {
        plan.builds.push("gravity".into());
    }
    Ok(plan)
}
