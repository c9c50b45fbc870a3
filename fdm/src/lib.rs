//! # fdm — the variable-step finite-difference scheme of the 1969 NASA report (seed 003 §5)
//!
//! ## Layout
//! * **Model** — [`system::System`]: a semi-discrete q̇ = v, v̇ = a(t, q, v) (accelerations,
//!   powers, stored energies, step bound, constraint projections). Implementations:
//!   [`rocket::system`], [`link`], [`chain`], [`payload_link::system`] (the 3-D link); [`beam`]
//!   for modes and statics.
//!   The backend's entries match the scene's family once; [`ChainModel`] classifies a planar
//!   chain.
//! * **Method** — [`method::Stepper`], one type per method ([`method::two_step`],
//!   [`method::velocity_form`]), each registered in one entry of the method registry, which
//!   maps `time.method` to its type ([`method::stepper`]) and its [`method::Capabilities`]
//!   (the runs refuse a method that lacks what their model needs, naming those that have it).
//! * **Events** — [`events::Events`]: located inside a step, applied as resets and constraint
//!   switches ([`events::tip_contact`]).
//! * **Driver and outputs** — [`driver::run`] (step choice, watch, ledger work),
//!   [`output`] (channel naming through [`output::Outputs`], sampling, result mapping) and
//!   [`runs`] (each model's run from the scene: model, method, events, step control).
//!
//! ## Rocket (`rocket`, `rocket-case2`, `rocket-launch-60`, `rocket-launch-75`)
//! Continuous equations (report 5.2–5.8, re-derived, OCR typos removed): per unit length of the
//! case, m A_x = ∂/∂x(EA(u' + ½w'²)) + f_u and m A_y = −∂²/∂x²(EI w'') + ∂/∂x(P w') + f_w, with
//! A the absolute acceleration in body axes (see [`rocket::system`]), P = EA u', free-free ends
//! (EA u' = EI w'' = (EI w'')' = 0, 3.59–3.60), point loads ṁ_total v_e − p A_f at x = 0 and
//! +p A_f at x = L₁, the internal-flow Coriolis load 2θ̇ m_f v with m_f v = ṁ (L₁ − x), gravity
//! (−g sin θ, −g cos θ), discrete masses on springs/dampers (5.7–5.8), and the rigid equations
//! (5.2–5.4) for the aft-end origin (X, Y, body components) and attitude θ. The mass-loss forces
//! F_M (3.43) cancel the ṁ part of d/dt ∂L/∂q̇, so every mass element obeys m A = F with m(t).
//!
//! Discretization (report §5.2):
//! * equal spatial steps h, stations 0…r; trapezoidal integrals (5.13) ⇒ lumped masses h/2 at
//!   the ends, h inside, and the operator m{·} of 5.14; discrete masses attached between two
//!   stations by linear interpolation (x = 125 in is not a station when h = 2 in);
//! * the elastic forces are −∂V/∂q of the discrete strain energy ([`rocket::operators`]); they
//!   coincide with the report's stencils 5.23/5.25 and with the ghost nodes 5.31–5.32 (tested),
//!   and stay conservative across the stage junction (the report's EA' u' form does not);
//! * the rigid/elastic split: 3×3 solve for (Ṙ, Ṡ, Ṫ) under 5.37 (5.38), then \[A₂₂\] = 1 (5.40).
//!   The elastic accelerations satisfy 5.37 exactly, so the split loses nothing;
//! * time: the two-step central difference 5.21/5.24–5.30 with (τ_j + τ_{j+1}) and steps from
//!   σ² ≤ h² m/EA, σ² ≤ h⁴ m/(4EI) per segment (5.43–5.45), recomputed every step with the
//!   masses of the new level as stage 1 burns ([`driver`]; the start-up in [`method::two_step`]).
//!   Burn-out, where thrust, pressure and flow stop, is a jump of the loads: a level lands on
//!   it and the scheme starts again there ([`method::AtJumps`]).
//!
//! **Stability finding.** The report's σ equals 2/ω_max of the discrete operator — the limit of
//! the *one-step* second-order form. The two-step form 5.21 has roots ξ = iωτ ± √(1 − ω²τ²) and
//! is stable only for ωτ ≤ 1, i.e. τ ≤ σ/2; at τ = σ its shortest bending waves grow by
//! |ξ| = 2 + √3 per step (tested; the report itself warns that 5.45 "does not ensure
//! stability"). Enforced limits, reported in the `stability_bound` channel:
//!
//! | `time.method` | scheme | step limit | computational mode |
//! |---|---|---|---|
//! | `report` (default) | two-step 5.21 | σ/2 | neutral undamped, grows with damping or velocity coupling |
//! | `robert-asselin[=ν]` (ν = 0.01) | 5.21 + filter | ½(1 − ν)σ | damped ≈ 4ν per step; accuracy drops to first order |
//! | `velocity-form` | one-step kick–drift–kick | σ | none |
//!
//! With h = 2 in: τ ≈ 1.99e-6 s (report, ≈ 50 800 steps in 0.1 s) and 3.97e-6 s (velocity form,
//! ≈ 25 400 steps). Growth of the computational mode is detected (|Δ²v| against the solution)
//! and the run stops with a diagnostic naming the coordinate and the remedies.
//!
//! Rocket observables: `rocket.X/Y` inertial mass centre (launch frame, origin at the aft end at
//! t = 0), `rocket.theta`, `rocket.mass`, `rocket.vX/vY` rigid-body velocity of the body point at
//! the mass centre, `rocket.u@k`/`rocket.w@k` elastic displacements in body axes at field
//! stations k = 0 (aft) … F−1 (nose), `rocket.massj.u/.w` the discrete masses' displacements U_j,
//! W_j in body axes (as the report's figures 9–10), `step_size`, `stability_bound`. Ledger:
//! kinetic, strain, gravity, discrete_spring | thrust, pressure, coriolis_flow |
//! discrete_damper, mass_outflow (kinetic + potential energy carried off by the burnt mass).
//!
//! ## Beams
//! * [`beam`]: the clamped-free beam (`cantilever`, `cantilever-tip-mass`; `rotating-beam`
//!   modes at its constant hub rate) — modes from the finite-difference eigenproblem with
//!   ghost nodes (clamped w₀ = 0, w₋₁ = w₁; free end 5.32; tip mass in the shear condition),
//!   statics; O(h²) convergence tested against root-found analytic values.
//! * [`link`]: one link in a rotating frame (`spin-up`, `spin-up-linear`, `single-link`,
//!   `rotating-beam` runs) on the same grid and stepping: foreshortening stiffening, prescribed
//!   hub motion (reported torque) or hub torque with inertia, spring, damper, Kelvin–Voigt.
//!   Ledger: kinetic, strain, and only the enabled terms of joint_spring | applied_torque or
//!   prescribed_motion | joint_damper, kelvin_voigt. **Default method** ([`runs::default_method`]):
//!   velocity-form when a force depends on the velocities (a free hub's İθ̇ and θ̇² terms,
//!   Kelvin–Voigt), on which the two-step scheme's computational mode grows; the report's
//!   two-step scheme for a prescribed undamped hub.
//!   **Step bound with the centrifugal tension.** The report's σ² ≤ h⁴m/(4EI) is 2/ω_max of the
//!   bending stencil alone. With foreshortening the spinning link carries the tension
//!   N(x) = θ̇² W(x) ≈ ρAθ̇²(L² − x²)/2 (W = Σ_{i>x} m_i x_i), whose string stiffness N/h² raises
//!   the sawtooth frequency: per station k, by Gershgorin on the assembled M⁻¹K,
//!   ω_k² = Σ_j |K_b,kj|/m_k + θ̇² Σ_j |Φ_kj|/m_k − θ̇² = (16EI/h⁴ + 2(N_{k−½} + N_{k+½})/h²)/ρA − θ̇²
//!   inside the link (N_{k±½} the segment tensions; the −θ̇² is the exact centrifugal softening
//!   on the diagonal), σ = min_k 2/ω_k × the Kelvin–Voigt factor with ζ_k = γ (K_b row)/(2EIω_k).
//!   It is evaluated at the current hub rate before every step (prescribed: its kinematics;
//!   torque-driven: the rate of the current state), reported in `stability_bound`, and named in
//!   forced-step refusals as kind "transverse (bending + centrifugal tension)" with the station,
//!   the rate and the three parts of ω². At rest it is the report's 5.44; under rotation it
//!   bounds the true ω_max from above where the bending-only value does not (tests
//!   `dyn_link_tension_*`; figures in docs/backends.md, "fdm: figures from its tests").
//!   Not in the bound: the free hub's rank-one coupling through θ̈ (the single link runs the
//!   velocity form, stable to 2/ω; it has not bound in any tested scene).
//! * [`chain`]: two links in series (`two-link-free`, `two-link-free-undamped`): link 2 clamped to
//!   link 1's tip and turned by the elbow angle θ₂ (clamp angle of link 2 = θ₁ + v₁'(L₁) + θ₂).
//!   Same stations, ghost-node bending energy, Kelvin–Voigt and foreshortening per link. Each
//!   link's coordinates are its tip-chord angle and the deflections from that chord (v₀ = v_r =
//!   0) with the clamp ghost node x = v₋₁ as an unknown (clamp angle ψ = chord angle + (v₁ −
//!   x)/(2h)) carrying the half-cell rotary inertia ρAh³/24; the lumped points sit in the
//!   clamp-tangent frames (the scene's foreshortening, an exact change of variables: see
//!   [`chain`]). Kinetic energy exact, ½Σm|ṙ|² of the lumped points ([`chain::kinetic`]):
//!   Kane's equations with the points' velocity-product accelerations by one dual-number pass;
//!   mass matrix = full columns θ, β, the clamp ghosts and link 1's tip ghost y = v_{r+1}, each
//!   link's lumped diagonal plus its foreshortening-rate block, and a rank-2 coupling of the
//!   links ([`chain::mass`]: Woodbury on a tridiagonal per link, a Schur complement of at most
//!   7, O(n) per step).
//!   Joint springs/dampers (set-points) on θ₁ and θ₂ = β-clamp angle − θ − ψ (ψ = central tip
//!   slope on the tip ghost; link 1's bending energy carries its trapezoid end term, so the
//!   elbow moment EIκ(L₁) = K₂θ₂ is a second-order boundary condition). Ledger: kinetic,
//!   strain, joint_spring | applied_torque | joint_damper, kelvin_voigt. **Default method:
//!   velocity-form** (free joints make the inertia forces velocity dependent and damping is on;
//!   the two-step scheme's parasitic root grows). **Modes** ([`chain::modes`]): K x = ω² M x of
//!   the integrated station equations linearized about the set points (straight links, at rest;
//!   M from the momenta, K = −∂F/∂q), undamped; Euler–Bernoulli chains only. Against the
//!   spring-jointed beams (tests/chain_modes.rs): O(h²) with hinged joints (K → 0), the scene's
//!   springs and the moment-carrying stiff elbow (K → ∞). The inertia terms quadratic in q̇ are
//!   taken from the drift velocities v_{j±½} ([`method::velocity_form`]): at the predicted
//!   velocity the foreshortening couplings would turn the unresolved bending waves into a bias
//!   growing with the number of stations.
//!   **Damping implicit** ([`chain::implicit`]; Euler links, with or without the tip
//!   contact, whose held force the kick carries): Kelvin–Voigt and the joint
//!   dampers (−Cq̇, C constant) Crank–Nicolson across the velocity form's two kicks,
//!   (M + ½τC)a = F solved through a banded quasi-definite saddle system (the foreshortening
//!   rates' multipliers beside their stations, band LDLᵀ) and the same small Schur complement,
//!   O(n) per step: `two-link-free` steps at the undamped bound.
//!   Tested (tests/chain.rs): undamped energy error bounded (no drift), O(τ²); damped ledger
//!   closure O(τ²); joint angles O(h²); the rigid limit. Step bound: 0.9 × 2/ω_max of
//!   the chain linearized at rest (no rates, so no centrifugal tension) and the per-link 5.44;
//!   the 0.9 leaves room for a 23 % rise of ω_max², while the tension share N h²/(4EI) at the
//!   undamped scene's peak rate (θ̇₁ ≈ 22 rad/s, N₁ ≈ 9e3 lbf, 21 stations) is ≈ 1e-2 —
//!   covered, but a chain spun at ≳ 100 rad/s would need the link's tension term (not done).
//!   **Gravity** on the chain: V_g = −g·Σ m r over the lumped masses at the positions the
//!   kinetic energy uses (foreshortening included), ledger term `gravity`. **Tip contact**
//!   ([`chain::contact`], its events [`events::tip_contact`]; `barhorst-case1`, `-case2`, `-case1-tipmass`, `-case1-stiff-elbow`):
//!   link 2's tip against a fixed line, unilateral and frictionless. Contact start located on
//!   the step's own drift (Illinois, 1e-10 s), impact M(q̇⁺ − q̇⁻) = GᵀΛ with the chain's own M
//!   (loss booked as `impact`), constrained sliding M q̈ = f + Gᵀλ, Gq̈ + Ġq̇ = 0 with
//!   position/velocity projection, release located on λ(step length); channels
//!   `contact1.normal_force`, `contact1.phase`, `contact1.gap`; events `contact-start`,
//!   `impact`, `release`. The damping is implicit through the contact too (A q̈ = f + Gᵀλ with
//!   A = M + ½τC in the kick, [`chain::implicit`]): the step is 0.45 of the undamped bound
//!   ([`runs::IMPLICIT_CONTACT_SAFETY`], for the ledger), its first 2000 steps at the explicit
//!   damping's bound (a preloaded joint released at t = 0), and ¼ of the bound for 2000 steps
//!   after each velocity jump. The Timoshenko chain keeps its damping explicit; its bound then
//!   also takes the fastest damping rate κ_max (power iteration on −∂a/∂q̇: the joint dampers on
//!   the clamp half-cell inertia are strongly overdamped, limit τ ≤ 1/κ).
//!   Tested (tests/contact.rs): the contact run steps above the explicit damping's bound;
//!   momentum residual and |Gq̇⁺| at round-off, the ledger, the
//!   resting force of the stiff elbow against the static equilibrium of the same model.
//! * **Timoshenko links** ([`chain::timoshenko`]; `barhorst-case1-timoshenko`, `shear` on both
//!   links, no rotary inertia): v and the section rotation ψ at the stations, U = Σ ½EI
//!   (Δψ/h)² h + Σ ½κGA (Δv/h − ψ̄)² h (ψ̄ the cell average: no shear locking), joint angles
//!   Θ₁ = θ + ψ¹₀, Θ₂ = β + ψ²₀ − θ − ψ¹_r (link 2 clamped to the section at link 1's tip),
//!   Kelvin–Voigt on ψ′. In the tip-chord frames ψ moves no mass; ∂U/∂ψ is linear with a
//!   constant SPD tridiagonal K_ψψ, so ψ is condensed: ψ = −K_ψψ⁻¹(K_ψy y + b) (exact without
//!   damping), and with damping on its slow manifold (Rayleigh function D(ẏ, Jẏ), the first
//!   order in frequency/relaxation rate ≥ EI/γ = 2.5e4 s⁻¹; the modal backend's choice) —
//!   three tridiagonal solves per force evaluation. Forces −∂U_c/∂y − ∂D_c/∂ẏ (tested
//!   against finite differences), ledger exact in its own terms. Step bound: the condensed
//!   operator's top is the shear sawtooth, ω²_max = 4κGA/(ρAh²) for every EI (derived in the
//!   module), σ = h√(ρA/κGA) per link, with the chain's power-iteration ω_max and κ_max.
//!   Tested (tests/timoshenko.rs): cantilever tip deflection error exactly −PLh²/(12EI)
//!   (ψ(L) exact); first impact of case 1 O(h²); momentum residual at round-off; the ledger of
//!   case 1 at safety 0.1, the default for Timoshenko chains with contact (the velocity form's
//!   energy error in the impact-excited shear waves is ~first order near the bound); damped
//!   free swing; κGA → ∞ approaches the Euler chain. Refused: `rotary_inertia`, mixed
//!   Euler/Timoshenko chains, torque laws with shear, single floating Timoshenko links, beam
//!   modes with shear. **Statics** of the clamped Timoshenko cantilever
//!   (`cantilever-timoshenko`) use the same cell energy ([`beam`]): tip force error exactly
//!   −PLh²/(12EI) with ψ(L) exact; distributed load v(L) exact, ψ(L) O(h²).
//! * [`payload_link`]: the 3-D link with an offset payload of seed 002 (`single-link-3d`,
//!   `-constant-rate`, `-soft-sag`, `-stiff`, `-thin`, `-heavy-payload`): u, v, w, φ at the
//!   stations (only the carried fields built), the payload's mass, offset and full inertia at
//!   the tip, base angle free (torque, friction, spring) or prescribed, gravity, per-field
//!   Kelvin–Voigt. Discrete
//!   Lagrangian to second order in the fields (docs/single-link-3d.md): constant banded field
//!   mass, affine θ coupling, quadratic M_θθ; θ̈ by a Schur complement. Velocity form of the
//!   central difference at τ = safety × min over fields of the report's bounds (axial
//!   h√(ρA/EA), bending h²√(ρA/4EI), torsion h√(ρJ/GJ)); `--dt` above it refused naming the
//!   field; only a method with implicit damping (the velocity form) steps it (a requested
//!   two-step method is refused).
//!   Kelvin–Voigt implicit in the closing kick ((M + ½τC) q̈ = …, one sparse factorization per
//!   step length): explicit it would bound the step at ≈ ρh²/(4C), 40× below the elastic bound
//!   of the catalog rod. Modes (K − Ω²H against M, flexibility form), statics (K q = f_g). Tested
//!   (tests/payload_link.rs): static sag and the torsion and axial frequencies with the payload
//!   O(h²) to the closed forms, bending O(h²), the ledger.
//!
//! The figures of these tests and of the investigations behind the design: docs/backends.md,
//! "fdm: figures from its tests".
//! * Unsupported (precise `Unsupported` messages): chains of more than two links, axial
//!   fields, shear outside the two-link chain and cantilever statics, tip inertia, gravity on beams, contact with
//!   friction, circles or bilateral mode, contact with the two-step scheme, the 3-D link with
//!   the two-step scheme, mobile
//!   scenes.

pub mod band_ldl;
pub mod beam;
pub mod chain;
pub mod driver;
pub mod error;
pub mod events;
pub mod foreshortening;
pub mod linalg;
pub mod link;
pub mod method;
pub mod output;
pub mod payload_link;
pub mod rocket;
pub mod runs;
pub mod settings;
pub mod system;
pub mod tridiagonal;

use data::scene::{Model, PlanarChain, PrescribedMotion};
use data::{
    Backend, BackendError, BackendKind, Discretization, DofPlan, ModalResult, RunResult, Scene,
    Settings, StaticResult,
};

pub use error::FdmError;
pub use settings::{Method, ValidatedSettings};

/// The finite-difference backend.
#[derive(Debug, Clone, Copy, Default)]
pub struct FdmBackend;

/// The model a planar chain becomes in this backend (the one place a chain is classified; the
/// other families have one model each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainModel {
    /// One link clamped to the ground: modes and statics ([`beam`]).
    Cantilever,
    /// One link on a hub, prescribed or torque driven ([`link`]).
    SingleLink,
    /// Two links in series, with its tip contact if any ([`chain`]).
    TwoLinkChain,
}

impl ChainModel {
    /// The model of `pc`, by its number of links.
    pub fn of(pc: &PlanarChain) -> Self {
        match pc.links.as_slice() {
            [l] if matches!(l.joint.prescribed, Some(PrescribedMotion::Fixed)) => {
                ChainModel::Cantilever
            }
            [_, _] => ChainModel::TwoLinkChain,
            // more than two links: refused with the link model's precise message
            _ => ChainModel::SingleLink,
        }
    }
}

/// The refusal of a family this backend does not solve.
fn unsupported_family(scene: &Scene) -> FdmError {
    FdmError::Unsupported(format!(
        "fdm backend: {} scenes (`{}`) are not implemented",
        scene.family(),
        scene.name
    ))
}

// Each entry dispatches on the scene's model family once and hands the family on.
impl Backend for FdmBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Fdm
    }

    fn dof_plan(&self, scene: &Scene, disc: &Discretization) -> Result<DofPlan, BackendError> {
        let s = ValidatedSettings::from_settings(&disc.fdm()?)?;
        Ok(match &scene.model {
            Model::PlanarChain(pc) => match ChainModel::of(pc) {
                ChainModel::Cantilever => beam::dof_plan(scene, pc, s.stations)?,
                ChainModel::TwoLinkChain => {
                    chain::TwoLinkChain::from_planar_chain(scene, pc, s.stations)?.dof_plan()
                }
                ChainModel::SingleLink => {
                    link::FloatingLink::from_planar_chain(scene, pc, s.stations)?.dof_plan()
                }
            },
            Model::Rocket(r) => rocket::dof_plan(r, s.stations)?,
            Model::PayloadLink(p) => {
                payload_link::PayloadLinkModel::from_payload_link(scene, p, s.stations)?.dof_plan()
            }
            Model::MobileManipulator(_) => return Err(unsupported_family(scene).into()),
        })
    }

    fn modes(
        &self,
        scene: &Scene,
        settings: &Settings,
        count: usize,
    ) -> Result<ModalResult, BackendError> {
        let s = ValidatedSettings::from_settings(&settings.fdm()?)?;
        match &scene.model {
            Model::PlanarChain(pc) => match ChainModel::of(pc) {
                ChainModel::TwoLinkChain => Ok(chain::modes::modes(scene, pc, &s, count)?),
                ChainModel::Cantilever | ChainModel::SingleLink => {
                    Ok(beam::modes(scene, pc, &s, count)?)
                }
            },
            Model::Rocket(_) => Err(BackendError::Unsupported(
                "fdm modes of the rocket: the variable-mass body has no fixed modes; use `run`"
                    .into(),
            )),
            Model::PayloadLink(p) => Ok(payload_link::analysis::modes(scene, p, &s, count)?),
            Model::MobileManipulator(_) => Err(unsupported_family(scene).into()),
        }
    }

    fn statics(&self, scene: &Scene, settings: &Settings) -> Result<StaticResult, BackendError> {
        let s = ValidatedSettings::from_settings(&settings.fdm()?)?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(beam::statics(scene, pc, &s)?),
            Model::PayloadLink(p) => Ok(payload_link::analysis::statics(scene, p, &s)?),
            Model::Rocket(_) | Model::MobileManipulator(_) => Err(BackendError::Unsupported(
                format!("fdm statics for {} scenes", scene.family()),
            )),
        }
    }

    fn simulate(&self, scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError> {
        let requested = settings.fdm()?;
        let scene = &*data::sampled_as(scene, requested.output_interval, requested.t_end)?;
        let s = ValidatedSettings::from_settings(&requested)?;
        Ok(match &scene.model {
            Model::PlanarChain(pc) => match ChainModel::of(pc) {
                ChainModel::Cantilever => return Err(beam::simulate_unsupported(scene).into()),
                ChainModel::TwoLinkChain => runs::two_link_chain(scene, pc, &s)?,
                ChainModel::SingleLink => runs::single_link(scene, pc, &s)?,
            },
            Model::Rocket(r) => runs::rocket(scene, r, &s)?,
            Model::PayloadLink(p) => runs::payload_link(scene, p, &s)?,
            Model::MobileManipulator(_) => return Err(unsupported_family(scene).into()),
        })
    }
}
