//! # fem — planar floating-frame beam finite elements
//!
//! Solves the planar link-chain scenes with beam finite elements: modes, linear statics and
//! nonlinear dynamics, including unilateral tip contact with a rigid line (seed 000).
//!
//! ## Governing equations
//! Each link is a beam of length L clamped (v = v′ = 0, u = 0; Timoshenko: v = ψ = 0) to a
//! frame that rotates with its joint. Per link, with ρA, EI (EA, κGA, ρI when switched on):
//! * strain energy U = ½∫EI v″² (Euler–Bernoulli), ½∫EI ψ′² + ½∫κGA(v′ − ψ)² (Timoshenko,
//!   `shear`: section rotation ψ relative to the frame), plus ½∫EA(u′ + ½v′²)² with `axial`
//!   (von Kármán; element-averaged membrane strain);
//! * `foreshortening` (inextensible): axial position x + s(x), s = −½∫₀ˣ v′², which carries the
//!   centrifugal stiffening through the kinetic energy without axial DOFs;
//! * kinetic energy T = ½∫ρA|ṙ|² + ½m_tip|ṙ_tip|² + ½J_tip(φ̇ + β̇(L))² + ½J_hub φ̇²
//!   (+ ½∫ρI(φ̇ + β̇)² with `rotary_inertia`), β the section angle relative to the frame (v′,
//!   or ψ for Timoshenko), r = R + A(φ)(x + w, v) the inertial position (the foreshortening w
//!   uses the centre-line slope v′) and the frames chained by the joint convention
//!   φᵢ₊₁ = φᵢ + βᵢ(Lᵢ) + θᵢ₊₁, Rᵢ₊₁ = rᵢ(Lᵢ);
//! * joints: torque −K(θ − θ₀) − Dθ̇ + τ(t), or prescribed θ(t) (the needed torque is reported);
//!   Kelvin–Voigt bending moment γ β̇′ (dissipation ∫γ β̇′², no shear damping); gravity
//!   −∫ρA g·r.
//!
//! Lagrange's equations are R(q, q̇, q̈, t) = Σ m Jᵀ(r̈ − g) + ∂U/∂q + C q̇ − Q = 0 with
//! J = ∂r/∂q ([`chain`]), evaluated in O(n) per link by a forward kinematic and a backward force
//! pass. Discretization: one [`element::Element`] per link, the same in modes, statics
//! ([`linear`]) and dynamics ([`chain`]): Hermite-cubic v (+ linear u), consistent mass by
//! 4-point Gauss quadrature (frequency error O(h⁴)); the hierarchical Hermite-quintic element
//! (`discretization.element = "hermite-quintic"`: cubic plus two C¹ interior bubbles, 6-point
//! Gauss, frequency error O(h⁸)); for `shear` links the Timoshenko element with cubic v and
//! quadratic ψ (locking-free, O(h⁴)). Interior DOFs (the quintic's bubble amplitudes, the
//! Timoshenko v(⅓), v(⅔), ψ(½)) are global DOFs, never condensed.
//!
//! Timoshenko links without rotary inertia have massless directions (every ψ, and turning the
//! frame against v = −αx when the hub has no inertia): their equations are static balances
//! (a DAE). The run starts from a state that satisfies them (`Chain::settle_massless`: the ψ
//! carry e.g. the next joint's spring moment from t = 0), the initial acceleration treats them
//! as algebraic ([`method::start`]), and central difference refuses such links. The step end
//! rates along them are not determined by a midpoint step (M N = 0): energy-midpoint ends every
//! step on their balances ([`events::massless`]) — with a unilateral contact the damped ones
//! (Kelvin–Voigt required), without contact, where some are undamped, the algebraic balance
//! ∂V/∂ψ = 0 with rates from its time derivative, also along the almost massless turn of a
//! child frame through its parent's tip section, which no damper reaches
//! ([`chain::Chain::child_frame_directions`]).
//!
//! ## Time integration
//! Default for chains whose joints are all free (torque/spring driven: `single-link`,
//! `two-link-free`, `two-link-free-undamped`): the energy-consistent midpoint scheme
//! `energy-midpoint` ([`method::energy_midpoint`]). With E = ½vᵀM(q)v + V(q) and non-conservative forces Q,
//!   q₁ − q₀ = h v̄,  M(q₁)v₁ − M(q₀)v₀ = −h ∇̄Φ + h Q(t_mid, q̄, v̄),  Φ = V − ½v₀ᵀM(q)v₁,
//! with ∇̄ the Gonzalez discrete gradient (metric M(q̄)). Since v̄ᵀ(p₁ − p₀) = ΔT + Δ(½v₀ᵀMv₁)
//! and Δqᵀ∇̄Φ = ΔΦ, every step satisfies E₁ − E₀ = Δqᵀ Q(t_mid, q̄, v̄) exactly (to the Newton
//! tolerance, which also bounds this energy defect per step at 1e-14 of the step's energy
//! scale or its round-off floor); the works are booked with that same midpoint quadrature, so
//! the ledger closes to the Newton tolerance instead of to the trapezoidal rule's O(h²), an
//! error the configuration-dependent mass M(q) causes. Second order and symmetric. Its Newton
//! iteration evaluates several residual-type passes per iteration (the discrete gradient) but
//! keeps its factorization across steps. Ledger closures and cost per step against
//! generalized-α: docs/backends.md ("fem energy-midpoint: ledger closure and cost").
//!
//! Elsewhere (prescribed joint motion, extensible links, an undamped Timoshenko link without
//! rotary inertia on a free joint without hub inertia — its almost massless frame direction
//! stalls the midpoint Newton iteration), and on request: generalized-α
//! (ρ∞ = 1, i.e. the trapezoidal rule, unless a link is extensible: ρ∞ = 0.9) with
//! a constant-displacement predictor and Newton on q̈. Newton matrix (both implicit schemes): the
//! analytic bordered-band matrix (mass, Coriolis C = Σm Jᵀ2J̇, inertial and elastic stiffness;
//! cost linear in the elements) for prescribed-hub links and chains without foreshortening; for
//! free chains *with* foreshortening, whose ∂s/∂q couplings reach whole links from the joint
//! rows, the exact matrix augmented with the running sums of the foreshortening (still a
//! bordered band: [`chain::AugmentedLayout`], factorized by a band LU). Newton failures in
//! fixed-step mode retry the stretch with quarter steps (reported as rejected steps). Default
//! step: min(output interval, T₁/40) with T₁ the first flexible period of the stiffest link
//! (clamped-free on a prescribed joint, pinned-free on a free one) — and at most T₁/320 of the
//! most flexible link in a free chain where nothing dissipates
//! ([`run::UNDAMPED_STEPS_PER_PERIOD`]), T₁/100 with a unilateral contact
//! ([`run::CONTACT_STEPS_PER_PERIOD`]: impacts and held phases) — fitted to divide the output
//! interval. Central
//! difference: 2/ω_max of the stiffest mode (power iteration on the linearized K, M at t = 0;
//! the damping is implicit in its step and does not lower it); a user step above it is
//! refused, the automatic step is 0.9× it. On request also the implicit midpoint rule
//! `implicit-midpoint` (one-stage Gauss, second order, no numerical damping, works booked by the
//! trapezoidal rule: [`method::implicit_midpoint`]) and Bathe's composite method `bathe`
//! (trapezoidal half step, three-point backward difference: second order, damps what the step
//! does not resolve, works booked by the midpoint rule on each sub-step; [`method::bathe`]).
//!
//! ## Contact (seed 000: impact, constrained sliding, release)
//! Unilateral frictionless contact of the tip of a named link with a fixed line
//! ([`events::contact`]), with every method: `energy-midpoint` (described here),
//! `implicit-midpoint` (ledger O(h²): [`method::implicit_midpoint`]), `generalized-alpha`
//! (acceleration history recomputed at every event: [`method::generalized_alpha`]), `bathe`
//! (the constraint held at both sub-step ends: [`method::bathe`]) and
//! explicit `central-difference` (positions and velocities projected onto the constraint, on
//! the bilateral wall too: [`method::central_difference`]).
//! Gap g = n̂·(r_tip − p₀), G = n̂ᵀ∂r_tip/∂q
//! (exact, [`chain::Chain::tip_jacobian`]).
//! * Detection inside the step: the step is re-solved shortened (Illinois secant on h) until
//!   |g(q₁(h))| ≤ 1e-10·L (event `contact-start` with the bracket width as time tolerance).
//! * Impact, perfectly plastic: M(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0, Λ = −G q̇⁻/(G M⁻¹Gᵀ), M(q) the
//!   dense LU of the mass matrix assembled from exact mass products; momentum residual from an
//!   independent mass product (at round-off); loss ½Λ²G M⁻¹Gᵀ booked `impact`.
//! * Constrained phase: the midpoint step with the force ∇̄g λ (Gonzalez discrete gradient of g,
//!   metric M(q̄)) and g(q₁) = 0, bordered Newton on (a, λ). The constraint does no work
//!   (Δqᵀ∇̄g = g(q₁) − g(q₀)), so it adds nothing to the ledger. |g| ≤ 1e-11·L; G q̇ drifts
//!   O(h²) within a step (reported) and is projected to zero after every constrained step
//!   (plastic projection, its kinetic-energy loss booked `contact_projection`; at a release
//!   only an inward drift).
//! * Normal force (channel `contact1.normal_force`): λ = (G M⁻¹R(q, q̇, 0) − n̂·J̇q̇)/(G M⁻¹Gᵀ)
//!   at the state, its velocity projected onto G q̇ = 0. Release where λ crosses zero, located
//!   inside the step (state force at the end of the re-solved shortened step) to
//!   −1e-8·W ≤ λ ≤ 0 (W the weight) or a 1e-13 s bracket (event `release`). The force
//!   carries unresolved mesh frequencies after impacts: micro-bounces of the discretized model
//!   ([`events::contact`]). Grazing contacts whose phase the step ends do not determine are
//!   refined (quarter steps, down to 1e-5 of the step), never released at an arbitrary force
//!   ([`events::contact`], "Grazing").
//! * Timoshenko links without rotary inertia: the massless directions (every ψ, ψ(L) − θ of
//!   the child) follow their balances Nᵀ(∂V/∂q + C q̇) = 0 (Kelvin–Voigt required), the impact
//!   map and the normal force act on the massive block ([`events::contact`]); every step ends with the
//!   section rotations projected onto their balance (the midpoint rule does not damp their
//!   stiff relaxation; strain energy removed booked `numerical_massless`) and consistent rates
//!   ([`events::massless`]). The Newton iteration of contact runs is hardened for impacts and short
//!   steps ([`method::energy_midpoint`]).
//! * Phase channel `contact1.phase` (0 free, 1 constrained); `contact1.gap`,
//!   `contact1.normal_velocity`, running maxima `contact1.max_gap`, `contact1.max_normal_velocity`.
//! * Refused (`unsupported`): unilateral circle surfaces, friction on unilateral contacts,
//!   several contacts, prescribed joints, adaptive steps, massless
//!   Timoshenko sections without Kelvin–Voigt (with `implicit-midpoint` or
//!   `generalized-alpha`: at all). Without contact nothing is allocated.
//!
//! ## Bilateral wall with Coulomb friction (seed 001, `constrained-arm`)
//! [`events::contact::friction`] with the geometry in [`events::wall`] (circle g = R − |r_tip − c|, n̂ = −(r − c)/|r − c|,
//! t̂ counter-clockwise, κ = 1/|r − c|; or a line). The tip is on the wall from t = 0 and never
//! released (λ of either sign); the scene's default method becomes `energy-midpoint`.
//! * Constraint as in the constrained phase above (discrete gradient, g(q₁) = 0 in Newton):
//!   |g| at round-off, channel `contact1.gap` / `contact1.max_gap`.
//! * Sliding: friction −μ s σ λ̄ T(q̄)ᵀ in the step (T = t̂ᵀJ, σ = sign λ fixed per step, step
//!   re-solved if λ̄ comes out with the other sign, stop if that is inconsistent too); the ledger
//!   books D = μ s σ λ̄ ΔqᵀT(q̄) (term `friction`, channel `contact1.friction_work`), exactly
//!   the work of the applied friction force, so the ledger closes to the Newton tolerance;
//!   D − μ∫|λ||v_t| dt is O(h²) (tested).
//! * Index-1 forces from the dense M(q): sliding λ(GM⁻¹Gᵀ − μsσGM⁻¹Tᵀ) = GM⁻¹R − n̂·J̇q̇ + κv_t²
//!   (Painlevé GM⁻¹Gᵀ ≤ μ|GM⁻¹Tᵀ| stops the run), held tip: 2 × 2 with GM⁻¹Gᵀ, GM⁻¹Tᵀ, TM⁻¹Tᵀ.
//! * Stick–slip: s·v_t = 0 and μ|λ_n| − |λ_t| = 0 located inside the step (secant on the step
//!   length), Coulomb cone test at the stop, stick = second constraint t̂_s·(r − p_s) = 0 with
//!   its own discrete gradient (no work), same test at t = 0; events `StickSlip`; phase channel
//!   1 sliding / 2 sticking; no-chattering rule in [`events::contact::friction`].
//! * Refused: the inextensible link on the circle of radius L about its hub (simple flexure =
//!   the rigid model), Timoshenko links without rotary inertia (M singular).
//!
//! The scene's `[statics]` loads (tip force, uniform load on the last link) act as step loads
//! in `simulate`; their work is the ledger input `applied_load`.
//!
//! ## 3-D payload link (seed 002)
//! Scenes of the `[payload_link]` family are solved by [`payload_link`]: 3-D beam elements
//! ([`element::beam3d`]: axial, two bending planes, torsion) in the turning frame with the
//! second-order kinematics of docs/single-link-3d.md, the payload as a rigid body at the tip,
//! modes (gyroscopic at a constant base rate), gravity statics and dynamics: the link is a
//! [`system::System`] ([`payload_link::system`]) stepped by the method registry on its own
//! driver path (implicit midpoint by default). It shares the element tables (Hermite cubics,
//! Gauss rules), the bordered-band LU ([`band`]), the dense eigensolver ([`modes`]) and the
//! methods with the planar chains, nothing else.
//!
//! ## Mobile manipulator with a flexible pitch link (seed 004)
//! Scenes of the `[mobile_manipulator]` family with a `flexible_link` are solved by [`mobile`]:
//! the platform, turret, rigid links and gripper as rigid bodies on the null space of the
//! nonholonomic constraints, the flexible link as Hermite-cubic beam elements in two bending
//! planes (linear floating frame). The model is a reduced system (q̇ = S(q)ν) stepped by a
//! method of [`method::reduced`], the implicit midpoint rule. It shares the Hermite tables, Gauss
//! rules and the dense Cholesky ([`linalg`]) with the planar chains, nothing else. Rigid mobile
//! scenes are the reference's.

//! ## Problem, method, events
//! The planar chains' time integration is split three ways. The problem is the discretized
//! system R(t, q, q̇, q̈) = 0 behind the [`system::System`] trait: residual and its force
//! groups, Newton matrix c_a·∂R/∂q̈ + c_v·∂R/∂q̇ + c_q·∂R/∂q, mass products, ∂T/∂q, energies and
//! the midpoint works of the ledger; [`chain::Chain`] and the 3-D link implement it. The methods
//! ([`method`], one type per method behind [`method::Stepper`]) are generic over the system
//! and name nothing else of the model. The events are objects the driver consumes: a held
//! constraint reaches a method only through [`method::StepConstraint`], implemented for the
//! system it constrains (the tip contact for the chain, which needs its tip kinematics); the
//! driver ([`driver`]) locates impacts, releases and stick–slip switches and applies the
//! resets. The 3-D link and the variable-mass rocket ([`rocket::system`]: M(t)q̈ = F, stepped on
//! its own driver path [`rocket::driver`], which lands on burn-out) are systems stepped by the same
//! methods. The mobile manipulator is split the same way: a reduced system on its speeds
//! ([`method::reduced::ReducedSystem`], implemented by [`mobile::MobileSystem`]) stepped by the
//! reduced methods ([`method::reduced::ReducedStepper`]), driven by [`mobile`].
//!
//! ## Layers
//! Each layer imports only the ones above it:
//! 1. model: [`element`] (the element trait and its registry; element operators tested alone)
//!    → [`linear`] (assembled linear link: modes, statics) and [`chain`] (nonlinear
//!    floating-frame system), [`band`] (faer sparse LU of the bordered-band Newton matrix,
//!    symbolic part reused; linear cost per step); [`system`] (what a method may ask of a
//!    discretized system; the chain implements it);
//! 2. methods: [`method`] — one type per integration method behind
//!    [`method::Stepper`] ([`method::generalized_alpha`], [`method::central_difference`],
//!    [`method::energy_midpoint`], [`method::implicit_midpoint`]), generic over the
//!    [`system::System`] they step, the Newton system and the consistent start; a held
//!    contact reaches a method only through [`method::StepConstraint`];
//! 3. events: [`events`] — contact (gap, impact map, drift projection, normal force),
//!    bilateral wall friction and stick constraint, massless-section balances;
//! 4. driver: [`driver`] — step control, event location and resets, work booking;
//! 5. outputs: [`run`] (observables, energy ledger, cost).
//!
//! ## Public API
//! [`FemBackend`] implements [`data::Backend`].

// Element and matrix kernels index several arrays with the same subscripts, as the formulas
// do; iterator rewrites would hide the math.
#![allow(clippy::needless_range_loop)]

pub mod band;
pub mod chain;
pub mod driver;
pub mod element;
pub mod error;
pub mod events;
pub mod linalg;
pub mod linear;
pub mod method;
pub mod mobile;
pub mod modes;
pub mod payload_link;
pub mod plan;
pub mod rocket;
pub mod run;
pub mod settings;
pub mod statics;
pub mod support;
pub mod system;

use std::time::Instant;

use data::scene::{Link, Model, PlanarChain};
use data::{
    Backend, BackendError, BackendKind, Cost, Discretization, DofPlan, FemSettings, ModalResult,
    ModeShape, RunResult, Scene, Settings, StaticResult,
};

pub use error::FemError;

/// The finite-element backend.
#[derive(Debug, Clone, Copy, Default)]
pub struct FemBackend;

/// The single clamped/spinning link of `pc` (scene `name`) that modes and statics linearize.
fn single_link<'a>(name: &str, pc: &'a PlanarChain, what: &str) -> Result<&'a Link, FemError> {
    support::check_planar(name, pc)?;
    match pc.links.as_slice() {
        [link] => Ok(link),
        links => Err(FemError::unsupported(format!(
            "fem {what}: chains of {} links (linearization of a free chain about its initial \
             configuration is not implemented)",
            links.len()
        ))),
    }
}

impl FemBackend {
    fn modes_impl(
        &self,
        scene: &Scene,
        pc: &PlanarChain,
        settings: &FemSettings,
        count: usize,
    ) -> Result<ModalResult, FemError> {
        let start = Instant::now();
        let link = single_link(&scene.name, pc, "modes")?;
        let n_el = settings::elements(settings)?;
        let omega = linear::hub_rate(link)?;
        let element = element::for_link(link, settings.element)?;
        let sys = linear::LinearLink::assemble(link, n_el, omega, element)?;
        let modes = modes::link_modes(&sys, count)?;
        let stations = scene.simulation.field_stations;
        let mut shapes = Vec::with_capacity(modes.len());
        for m in &modes {
            let (x, transverse) = modes::sample_shape(&sys, &m.vector, stations);
            shapes.push(ModeShape {
                link: 1,
                x,
                transverse,
            });
        }
        Ok(crate::modes::modal_result(
            scene,
            settings,
            modes.iter().map(|m| (m.omega, m.kind.to_string())),
            shapes,
            sys.ndof(),
            start,
        ))
    }

    fn statics_impl(
        &self,
        scene: &Scene,
        pc: &PlanarChain,
        settings: &FemSettings,
    ) -> Result<StaticResult, FemError> {
        let start = Instant::now();
        let link = single_link(&scene.name, pc, "statics")?;
        let n_el = settings::elements(settings)?;
        let omega = linear::hub_rate(link)?;
        let element = element::for_link(link, settings.element)?;
        let sys = linear::LinearLink::assemble(link, n_el, omega, element)?;
        let (tip_deflection, tip_rotation) = statics::solve(pc, &sys)?;
        Ok(StaticResult {
            backend: BackendKind::Fem,
            scene: scene.name.clone(),
            settings: data::Settings::from(settings),
            tip_deflection,
            tip_rotation,
            cost: Cost {
                wall_time_s: start.elapsed().as_secs_f64(),
                dofs: sys.ndof(),
                factorizations: 1,
                ..Default::default()
            },
        })
    }
}

// Each entry dispatches on the scene's model family once and hands the family on.
impl Backend for FemBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Fem
    }

    fn dof_plan(&self, scene: &Scene, disc: &Discretization) -> Result<DofPlan, BackendError> {
        let settings = &disc.fem()?;
        match &scene.model {
            Model::PlanarChain(pc) => {
                let n_el = settings::elements(settings)?;
                Ok(plan::dof_plan(&scene.name, pc, n_el, settings.element)?)
            }
            Model::PayloadLink(l) => {
                let n_el = payload_link::elements(settings)?;
                Ok(payload_link::dof_plan(l, n_el)?)
            }
            Model::Rocket(r) => Ok(rocket::dof_plan(r, settings)?),
            Model::MobileManipulator(mm) => Ok(mobile::dof_plan(mm, settings)?),
        }
    }

    fn modes(
        &self,
        scene: &Scene,
        settings: &Settings,
        count: usize,
    ) -> Result<ModalResult, BackendError> {
        let settings = &settings.fem()?;
        match &scene.model {
            Model::PlanarChain(pc) if chain::linearized::applies(pc) => {
                Ok(chain::linearized::modes(scene, pc, settings, count)?)
            }
            Model::PlanarChain(pc) => Ok(self.modes_impl(scene, pc, settings, count)?),
            Model::PayloadLink(l) => Ok(payload_link::modes(scene, l, settings, count)?),
            Model::Rocket(r) => Ok(rocket::modes(scene, r, settings, count)?),
            Model::MobileManipulator(_) => Err(support::unsupported_family(scene).into()),
        }
    }

    fn statics(&self, scene: &Scene, settings: &Settings) -> Result<StaticResult, BackendError> {
        let settings = &settings.fem()?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(self.statics_impl(scene, pc, settings)?),
            Model::PayloadLink(l) => Ok(payload_link::statics(scene, l, settings)?),
            Model::Rocket(_) | Model::MobileManipulator(_) => {
                Err(support::unsupported_family(scene).into())
            }
        }
    }

    fn simulate(&self, scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError> {
        let settings = &settings.fem()?;
        let scene = &*data::sampled_as(scene, settings.output_interval, settings.t_end)?;
        match &scene.model {
            Model::PlanarChain(pc) => Ok(run::simulate(scene, pc, settings)?),
            Model::PayloadLink(l) => Ok(payload_link::simulate(scene, l, settings)?),
            Model::Rocket(r) => Ok(rocket::simulate(scene, r, settings)?),
            Model::MobileManipulator(mm) => Ok(mobile::simulate(scene, mm, settings)?),
        }
    }
}
