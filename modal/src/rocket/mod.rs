//! # The variable-mass flexible rocket by free-free eigenfunctions (seed 003)
//!
//! The report's conclusion proposes expanding the case's elastic displacements "in terms of
//! sets of eigenfunctions corresponding to the associated constant-mass system, thereby
//! converting the partial differential equations into ordinary differential equations". This
//! module does exactly that.
//!
//! ## Body and coordinates
//! A free-free slender case in the plane, x from the aft end (nozzle, x = 0) to the nose
//! (x = L), made of uniform stages; stage 1 (0 ≤ x ≤ L₁) burns uniformly:
//! m₁(t) = (w₁ − ṁg·t)/g, floored at the casing mass (burn-out). Discrete masses M_j sit at x_j
//! on springs k_u, k_w (and dampers) to the case and to each other.
//!
//! The body frame has its origin O at the aft end of the undeformed axis and angle θ from the
//! horizontal. A case point is at R = R_O + A(θ)(x + u, w), a discrete mass at
//! R_j = R_O + A(θ)(x_j + u_j, w_j). The generalized coordinates are
//! `X, Y` (inertial position of O), `θ`, n axial modal coordinates a_k and n transverse b_k with
//! u = Σ a_k U_k(x), w = Σ b_k W_k(x), and the discrete masses' (u_j, w_j).
//! A spring between two masses stretches by their gap in the whole body's axes (case and
//! masses, docs/rocket.md): transversely w_i − w_j − (x_i − x_j)ψ, ψ = Σ M_p(x_p − x_c)w_p / I_c
//! the whole body's mean-axis angle in this frame (`Model::coupling_stretch_w` in `dynamics`).
//!
//! U_k, W_k are the *elastic* free-free eigenfunctions of the constant-mass case at ignition
//! (stepped EA, EI and mass; discrete masses not included), computed numerically on a fine
//! private finite-element mesh (`fine_mesh`, `basis`). They are orthogonal to the rigid modes
//! with respect to the ignition mass: ∫m₀U_k = ∫m₀W_k = ∫m₀xW_k = 0, so at ignition the frame is
//! a mean-axis frame of the case. As stage 1 burns, and through the discrete masses, the
//! elastic coordinates are no longer orthogonal to the rigid motion; the coupling is *kept* in
//! the full reduced mass matrix rather than neglected (unlike a pure rigid/elastic split).
//!
//! ## Equations (see `dynamics` for the derivation)
//! d'Alembert's principle with the current mass m(x, t) — burnt mass leaves with the local
//! case velocity, so the report's ṁṘ terms cancel — gives M(q, t) v̇ = Q − h with
//! quasi-velocities v = (Aᵀ Ṙ_O, θ̇, ȧ, ḃ, u̇_j, ẇ_j). Loads (report eqs. 5.16–5.18, in vacuum):
//! * thrust Q̇·v_e at the (displaced) nozzle point x = 0, in the direction γ from the body axis
//!   (not from the local slope of the deformed case, as in eq. 5.16), Q̇ = ṁ L₁ the mass flow;
//! * chamber pressure: −p·A_f at x = 0 and +p·A_f at x = L₁ along the axis (zero resultant);
//! * jet Coriolis force 2θ̇ m_f v per length on 0 ≤ x ≤ L₁, m_f v = Q̇ (1 − x/L₁);
//! * gravity m g at launch angle θ₀ (g = −g e_Y);
//! * strain energy ½∫EA u'² + ½∫EI w''² + ½∫EA u' w'² (the report's ½P w'², P = EA u'), and the
//!   discrete springs; thrust, pressure and flow stop at burn-out. The run is split there: the
//!   integrator lands exactly on the burn-out time, is restarted, and a `StepSizeChange` event
//!   records it (no step straddles the discontinuity).
//!
//! All spatial integrals are computed once by Gauss quadrature; the mass-dependent ones are
//! affine in the burnt fraction (`integrals`).
//!
//! Initial state (as in the report): the case has the scene's `initial_shape` w(x, 0),
//! projected onto the bending modes by m₀-weighted least squares (what the elastic basis cannot
//! hold — the rigid-body part of w₀ with respect to the stepped mass, and higher modes — is
//! dropped and reported as `DetailedRun::initial_shape_residual`); u = 0; the discrete masses
//! start at u_j = w_j = 0 (so their transverse springs start stretched by w(x_j, 0)); all
//! velocities are zero; X = Y = 0 (aft end at the origin), θ = θ₀.
//!
//! ## Settings
//! `discretization.modes` (default 6, 1–40) modes per field; `discretization.basis` must be
//! `free-free` (default); `time.method` = `dopri5` (default) or `tr-bdf2` (alias `sdirk`);
//! `time.rtol`/`time.atol` (defaults 1e-8/1e-10; the modal coordinates are nose displacements
//! in length units); `time.dt` is only the initial step of the adaptive methods; `time.t_end`
//! overrides the scene. The fine mesh that computes the eigenfunctions has
//! 16·(modes + 2) elements (96 to 480).
//!
//! ## Outputs
//! `rocket.X/Y`: the mass centre of case + discrete masses (inertial; the origin is the aft end
//! at launch). `rocket.vX/vY`: P/M, the mass-averaged velocity of the material in the body
//! (this is what the rocket equation governs; d(rocket.X)/dt differs from it by the drift of the
//! mass centre through the body as stage 1 burns). `rocket.theta`: the frame angle θ.
//! `rocket.u@k`, `rocket.w@k`: elastic u, w at `simulation.field_stations` equally spaced
//! stations, k = 0 at the aft end. `rocket.mass{j}.u/.w`: u_j, w_j (body-frame displacement of
//! mass j from its station x_j, as in the report). Because the modes are m₀-orthogonal to the
//! rigid motions, the body frame is the case's mean axis with respect to its ignition mass
//! (∫m₀u = ∫m₀w = ∫m₀xw = 0) and θ its angle: the frame-invariant definition the fdm backend
//! also reports.
//!
//! ## Energy ledger (variable mass)
//! stored: `kinetic` (½vᵀMv), `strain`, `gravity` (g ∫m R_Y), `discrete_spring`;
//! inputs: `thrust`, `pressure`, `coriolis` (powers of those forces at their material points)
//! and `mass_outflow` = ∫∫ṁ(½|Ṙ|² + g R_Y) dx dt (≤ 0), the kinetic and potential energy the
//! burnt mass takes with it; dissipation: `discrete_damper` when dampers exist.
//! With these terms the ledger closes to integrator tolerance (it is an identity of the model,
//! tested). What it does *not* describe is the gas: the exhaust's own kinetic energy and the
//! chemical energy released are outside the body's account.
//!
//! ## Momentum
//! [`simulate_detailed`] also returns a [`MomentumBalance`]:
//! P(t) − P(0) = ∫(thrust + pressure resultant + Coriolis resultant + M g) dt + ∫∫ṁṘ dx dt.

// Numerical kernels index several arrays with one loop variable; index loops read clearer there.
#![allow(clippy::needless_range_loop)]

mod basis;
mod body;
mod config;
mod dynamics;
mod eig;
mod error;
mod fine_mesh;
mod integrals;
mod modes;
mod run;

use data::scene::Rocket;

pub use config::{DEFAULT_ATOL, DEFAULT_MODES, DEFAULT_RTOL, MAX_MODES};
pub use error::RocketError;
pub use run::{DetailedRun, MomentumBalance, RocketOde};

/// DOF table of the rocket model for this scene and discretization.
pub fn dof_plan(
    r: &Rocket,
    settings: &data::ModalSettings,
) -> Result<data::DofPlan, data::BackendError> {
    let body = body::Body::from_rocket(r)?;
    let n = config::modes(settings)?;
    let mut plan = data::DofPlan::default();
    plan.add("rigid body X, Y, θ", 3);
    plan.add("axial free-free modes", n);
    plan.add("transverse free-free modes", n);
    plan.add("discrete mass axial u_j", body.masses.len());
    plan.add("discrete mass transverse w_j", body.masses.len());
    plan.builds.push(format!(
        "free-free eigenfunction basis of the constant-mass stepped case ({} fine elements)",
        basis::fine_elements(n)
    ));
    plan.builds.push("gravity at the launch angle".into());
    plan.builds
        .push("axial-force / bending coupling ½∫EA u' w'²".into());
    if body.burn.is_some() {
        plan.builds.push(
            "variable mass: uniform burn of stage 1 (integrals affine in the burnt fraction)"
                .into(),
        );
        plan.builds.push("thrust at the nozzle".into());
        plan.builds
            .push("chamber pressure ±p·A_f at x = 0, L₁".into());
        plan.builds.push("jet Coriolis force 2θ̇ m_f v".into());
    }
    if body.nozzle_angle != 0.0 {
        plan.builds.push("nozzle misalignment γ".into());
    }
    if !body.masses.is_empty() {
        plan.builds
            .push("discrete masses on springs to the case and to each other".into());
    }
    if body.has_dampers() {
        plan.builds.push("discrete dampers".into());
    }
    Ok(plan)
}

/// Free-free elastic frequencies (Hz, ascending) of `r`, the rocket of `scene`, at ignition
/// mass, kinds "axial"/"bending".
pub fn modes(
    scene: &data::Scene,
    r: &Rocket,
    settings: &data::ModalSettings,
    count: usize,
) -> Result<data::ModalResult, data::BackendError> {
    Ok(modes::modes(scene, r, settings, count)?)
}

/// Dynamic response of `r`, the rocket of `scene`, over [0, t_end].
pub fn simulate(
    scene: &data::Scene,
    r: &Rocket,
    settings: &data::ModalSettings,
) -> Result<data::RunResult, data::BackendError> {
    Ok(run::simulate_detailed(scene, r, settings)?.run)
}

/// [`simulate`] plus the momentum balance, the initial-shape projection residual and the basis
/// frequencies.
pub fn simulate_detailed(
    scene: &data::Scene,
    r: &Rocket,
    settings: &data::ModalSettings,
) -> Result<DetailedRun, data::BackendError> {
    Ok(run::simulate_detailed(scene, r, settings)?)
}
