//! # The 3-D flexible link with an offset payload (seed 002) by assumed modes
//!
//! The Lagrangian of docs/single-link-3d.md (second-order kinematics, foreshortening, rotary
//! inertia of the sections, payload with offset c and full inertia matrix I_p, gravity,
//! Kelvin–Voigt damping per field, base angle θ free or prescribed) discretized by Rayleigh–Ritz:
//! u = Σψₖaₖ, v = Σφₖbₖ, w = Σφₖcₖ, φ = Σχₖdₖ, `modes` functions per carried field
//! ([`basis`]; default 6, `poly` = integrated Legendre polynomials, which converge spectrally
//! with the payload at the tip; `clamped-free` eigenfunctions converge algebraically because
//! each has a load-free tip). Every term is a constant matrix ([`model`]), so an evaluation of
//! the equations of motion ([`dynamics`]) costs a few dense products and one Cholesky of the
//! (n + 1)² mass matrix of a free base (factored once for a prescribed base).
//!
//! * `simulate` ([`run`]): adaptive TR-BDF2 from [`crate::integrate`] with the analytic
//!   Jacobian (the axial and torsion modes are stiff: an explicit method would be bound by them),
//!   energy ledger from integrated input and dissipation powers.
//! * `modes` ([`analysis`]): K_eff x = ω² M x linearized about the undeformed rod at the base's
//!   reference rate Ω (0, or the constant rate of a `constant-rate` base): K_eff = K − Ω² N
//!   (centrifugal stiffening, the softening of the in-plane field and the payload terms);
//!   a free base adds θ (rigid mode 0 Hz without a spring, kind `rigid`). At a prescribed
//!   constant rate the gyroscopic matrix Ω(Gᵀ − G) (Coriolis coupling of u with v and of w with
//!   φ) stays in: [`analysis::gyroscopic_modes`] solves M q̈ + Ω(Gᵀ − G) q̇ + K_eff q = 0 in
//!   first-order skew form; on `single-link-3d-constant-rate` (Ω = 2π rad/s, 6 modes per field)
//!   it moves the first ten frequencies by at most 1.7e-6 relative (the first in-plane mode).
//! * `statics`: K q = −f_g, the linear sag under self-weight, payload weight and the payload's
//!   offset moment (`tip_deflection` = w_L, `tip_rotation` = w′_L); also the `static-sag` start.

pub mod analysis;
pub mod basis;
mod build;
pub mod dynamics;
pub mod model;
pub mod run;

use data::scene::{LinkField, PayloadLink};
use data::{Basis, DofPlan, ModalSettings, Scene};

use crate::error::ModalError;
use crate::linalg::cholesky_solve;
use model::{BasisChoice, LinkModel};

pub use analysis::{gyroscopic_frequencies, modes, statics};
pub use run::simulate;

/// Assumed modes per field when the settings give none.
pub const DEFAULT_MODES: usize = 6;

/// The scene's link and its discretized model.
pub struct SetUp<'a> {
    pub link: &'a PayloadLink,
    pub model: LinkModel,
}

/// The modes count and basis of the settings, checked.
pub fn basis_choice(settings: &ModalSettings) -> Result<(usize, BasisChoice), ModalError> {
    let n = settings.modes.unwrap_or(DEFAULT_MODES);
    if n == 0 || n > basis::MAX_MODES {
        return Err(ModalError::invalid(
            "discretization.modes",
            format!(
                "{n} modes per field: the payload link takes 1 to {}",
                basis::MAX_MODES
            ),
        ));
    }
    let choice = match settings.basis {
        None | Some(Basis::Poly) => BasisChoice::Legendre,
        Some(Basis::ClampedFree) => BasisChoice::ClampedFree,
        Some(other) => {
            return Err(ModalError::invalid(
                "discretization.basis",
                format!(
                    "`{}` is not offered for the payload link: `poly` (integrated Legendre \
                     polynomials, the default) or `clamped-free`",
                    other.name()
                ),
            ));
        }
    };
    Ok((n, choice))
}

/// The model of `link`, the payload link of `scene` (whose field stations it samples).
pub fn set_up<'a>(
    scene: &Scene,
    link: &'a PayloadLink,
    settings: &ModalSettings,
) -> Result<SetUp<'a>, ModalError> {
    let (n, choice) = basis_choice(settings)?;
    let model = LinkModel::build(link, n, choice, scene.simulation.field_stations)?;
    Ok(SetUp { link, model })
}

/// The linear static deflection under gravity, K q = −f_g (zero without gravity).
pub fn static_sag(model: &LinkModel) -> Result<Vec<f64>, ModalError> {
    let n = model.n;
    let Some(fg) = &model.gravity else {
        return Ok(vec![0.0; n]);
    };
    let mut k = model.stiffness.clone();
    let mut q: Vec<f64> = fg.iter().map(|f| -f).collect();
    cholesky_solve(&mut k, n, &mut q).map_err(|_| ModalError::Numerical {
        t: 0.0,
        message: "the stiffness matrix is not positive definite".into(),
    })?;
    Ok(q)
}

/// Degrees of freedom and physics built for the scene.
pub fn dof_plan(link: &PayloadLink, settings: &ModalSettings) -> Result<DofPlan, ModalError> {
    let (n, choice) = basis_choice(settings)?;
    let mut plan = DofPlan::default();
    if link.base.prescribed.is_none() {
        plan.add("base angle θ", 1);
    }
    for f in LinkField::ALL {
        if link.has(f) {
            plan.add(format!("{} modes ({})", f.name(), f.symbol()), n);
        }
    }
    plan.builds.push(format!(
        "assumed modes: {}",
        match choice {
            BasisChoice::Legendre => "integrated Legendre polynomials (poly)",
            BasisChoice::ClampedFree => "clamped-free eigenfunctions",
        }
    ));
    plan.builds
        .push("foreshortening (centrifugal stiffening, payload pull-in)".into());
    plan.builds.push("rotary inertia of the sections".into());
    plan.builds.push("payload: mass, inertia matrix".into());
    if link.payload.offset != 0.0 {
        plan.builds.push("payload offset".into());
    }
    if !link.payload.is_diagonal() {
        plan.builds.push("payload products of inertia".into());
    }
    if link.gravity.is_some_and(|g| g != 0.0) {
        plan.builds.push("gravity".into());
    }
    for f in LinkField::ALL {
        if link.kelvin_voigt_on(f).is_some() {
            plan.builds.push(format!("Kelvin–Voigt {}", f.name()));
        }
    }
    if link.motor_friction() > 0.0 {
        plan.builds.push("motor friction".into());
    }
    if link.base.stiffness.is_some_and(|k| k > 0.0) {
        plan.builds.push("joint spring".into());
    }
    Ok(plan)
}
