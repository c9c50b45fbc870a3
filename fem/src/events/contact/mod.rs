//! Unilateral, frictionless tip contact with a fixed rigid line (seed 000, Barhorst's work
//! surface) for every method: `energy-midpoint` (the default; the measurements below are its),
//! `implicit-midpoint`, `generalized-alpha`, `bathe` and `central-difference` (same constraint
//! object, see "Methods" at the end).
//!
//! **Gap and Jacobian.** g(q) = n̂·(r_tip(q) − p₀) with n̂ the unit normal to the free side,
//! G = n̂ᵀJ, J = ∂r_tip/∂q from [`Chain::tip_jacobian`] (exact, O(n), checked against finite
//! differences and against the forward pass's tip velocity in `tests/dyn_contact.rs`); the
//! convective term n̂·J̇q̇ is the tip acceleration of the forward kinematic pass at q̈ = 0
//! ([`Chain::tip_motion`]).
//!
//! **Constrained phase** (multipliers, index 3 at the position level). The midpoint step gains
//! the constraint force ∇̄g λ and the equation g(q₁) = 0 (bordered Newton on (a, λ) by the
//! Schur complement, see [`crate::method::energy_midpoint`]); ∇̄g is the Gonzalez discrete gradient of g in
//! the same metric M(q̄) as the potential, so Δqᵀ∇̄g = g(q₁) − g(q₀) = 0 and the constraint
//! does no work: the ledger closes to the Newton tolerance in every phase. |g| at the step
//! ends is at the Newton tolerance (1e-11·L). G q̇ at the step ends is not enforced by the
//! scheme and drifts O(h²), reported as the running max
//! `contact1.max_normal_velocity` (|g|: `contact1.max_gap`). Drift control: after every
//! accepted constrained step the velocity is projected onto G q̇ = 0 by the plastic projection
//! q̇ ← q̇ − M⁻¹Gᵀ(G q̇)/(G M⁻¹Gᵀ) (at a release only an inward drift G q̇ < 0, so that free
//! flight does not start into the surface); its kinetic-energy loss ½(G q̇)²/(G M⁻¹Gᵀ) is
//! booked as the ledger dissipation `contact_projection`. Each step thus starts with
//! G q̇₀ = 0, which keeps its multiplier finite as h → 0 (release location, below).
//!
//! **Normal force at a state** (channel `contact1.normal_force`; also decides whether a tip
//! stays on the surface after an impact), the index-1 value of the constrained dynamics
//! M q̈ + R(q, q̇, 0) = Gᵀλ, G q̈ + n̂·J̇q̇ = 0:
//!   λ = (G M⁻¹R(q, q̇, 0) − n̂·J̇q̇) / (G M⁻¹Gᵀ),
//! with M(q) the Newton matrix ∂R/∂q̈ assembled sparsely (with foreshortening, its exact
//! augmented bordered band) and factorized by `mass_solve`: O(n). At a configuration near
//! that of the factorization at hand (the next step end), on chains without massless
//! sections, y = M⁻¹Gᵀ is refined against the current M instead of forming a new one, and
//! G M⁻¹R = yᵀR (M symmetric); a force within 100 times its error bound of zero is evaluated
//! again with a factorization at its configuration (`Contact::solve_gradient`). Positive λ
//! pushes the tip to the free side. It is evaluated at the velocity the constrained
//! dynamics allows: q̇ projected onto G q̇ = 0 (the plastic projection that ends every
//! constrained step) and made consistent along the massless directions. At a step end the
//! drift G q̇ = O(h²) would otherwise enter λ through the velocity terms, and λ of the projected
//! state — the next step's λ(h → 0⁺) — would differ from the event value, a jump that the
//! release location cannot bracket (docs/contact.md).
//!
//! **Step multiplier** λ̄: the Newton multiplier of a constrained step, its mean normal force
//! (impulse/h), the constraint force the scheme applies; it predicts the next step's λ̄. It is
//! not the release event function: after an impact the state force contains the highest mesh
//! frequencies of the constrained chain (the point impact excites them; the symmetric midpoint
//! scheme does not damp them), with amplitudes comparable to its mean: a mesh mode aliased by
//! the step (docs/contact.md). Where that oscillation takes λ through zero the
//! semi-discrete model does leave the surface: the release is located there (below) and the tip
//! comes back after a short flight — micro-bounces of the discretized model, whose number grows
//! with refinement (as in `modal`), not converged quantities. The converged quantities are the
//! contact episodes (phases separated by flights longer than the bounces), compared across
//! backends by the verify quantities `episode_startN:F` / `episode_endN:F`.
//!
//! **Massless section rotations** (Timoshenko links without rotary inertia). The directions N
//! of [`Chain::exact_massless_directions`] (every ψ DOF, and e_ψ(L) − e_θ(child) for a tip
//! section that carries a child) have M N = 0 and G N = 0 at every q, identified
//! structurally from the kinematics (no material point depends on ψ, a child frame only on
//! ψ(L) + θ): robust, unlike a numerical zero test on M, whose rows for ψ(L) are not zero
//! (ψ(L) + θ carries the child). Their equations of motion carry no inertia:
//! Nᵀ(∂V/∂q + C q̇ − Q) = 0 with C the constant damping (Kelvin–Voigt on ψ′, joint dampers).
//! With Kelvin–Voigt, NᵀCN is regular and these balances fix the N-component of q̇ from q and
//! the rest of q̇ ([`Massless::make_consistent`](crate::events::massless::Massless::make_consistent),
//! owned by the driver and handed to the impact map and the normal force; exact in one solve
//! since they are affine in q̇); positions do not jump at an impact, so these balances hold on both sides and the jump
//! satisfies Nᵀ C Δq̇ = 0 while the massive block obeys M Δq̇ = GᵀΛ. The energy-midpoint step
//! solves these rows at the midpoint (∂V/∂ψ(q̄) + C v̄ = 0, an implicit-midpoint rule for a
//! first-order equation), which does not damp a deviation from the balance (it flips sign every
//! step) and leaves the end rate v₁ = 2v̄ − v₀ undetermined: in contact runs every step ends
//! with ψ projected onto its balance (strain energy removed booked `numerical_massless`) and
//! the rates made consistent ([`crate::events::massless`], measurements there).
//! Without Kelvin–Voigt the rotations are algebraic (∂V/∂ψ = 0) and ψ̇ jumps with the massive
//! velocities (condensation q̇ = C q̇_m): refused with `unsupported`.
//! Operators M⁻¹ become (M + μNNᵀ)⁻¹ (μ the largest diagonal mass), exactly M⁻¹ on the
//! massive subspace since Gᵀ, R ⊥ N: the solution has no N-component, Λ, λ and the kinetic
//! energy are those of the massive block. The frame directions of a free joint without hub
//! inertia (turn the frame by α with v = −αx; [`Chain::massless_directions`]) move the points
//! by α·s(x) only, with a mass ∫ρA s² orders of magnitude below the link's: kept massive in M
//! they would take huge velocity jumps at an impact (docs/contact.md). They are regularized
//! the same way (μ added along them): their velocity does
//! not jump at an impact (the modal backend removes this direction from its basis: it keeps
//! v′(0) = 0): the impact map is M Δq̇ = GᵀΛ + R_f with R_f = −μN_f N_fᵀΔq̇ the reaction that
//! holds the frame directions' velocity. The momentum residual reported is that of this
//! balance, ‖M Δq̇ − R_f − GᵀΛ‖/‖M Δq̇‖ (round-off; the μ-term vanishes on the exact
//! directions). The reaction itself, ‖R_f‖/‖M Δq̇‖, is not at round-off once the links are
//! deflected; it does work where the frame directions move, so the impact loss is booked as the
//! evaluated kinetic energy difference (below). The same directions are left out of the normal
//! force (M + μN_fN_fᵀ): with them, their O(s) inertial coupling to the tip through a mass
//! O(s²) is a stiff, unresolved mode of the discretization that λ would carry (see "Grazing"
//! for where this shows).
//!
//! **Events**, located INSIDE the step by re-solving it with a shortened step h* (Illinois
//! secant on the step length, other bracket points where Newton fails; a contact start's first
//! point is the gap's root on the method's continuous extension of the step): contact start when
//! |g(q₁(h*))| ≤ [`GAP_TOL`]·L (L the longest link); release when the index-1 normal force
//! λ(q₁(h*), q̇₁(h*)) at the end of the shortened step lies in [−[`FORCE_TOL`]·W, 0] (W the
//! chain's weight, or its mass times 1 length/time² without gravity), or when the bracket is
//! below [`TIME_TOL`]·max(t, 1) (the event's `time_tolerance` is the final bracket width; the
//! release side λ ≤ 0 is the one accepted). The event's `normal_force` is that λ. Two choices
//! keep λ(h) continuous in h so that the secant converges: the velocity is projected onto
//! G q̇ = 0 after every constrained step (drift control; kinetic energy removed booked as
//! `contact_projection`), and a shortened step removes only the share (h/h_nominal)² of the
//! start gap (see [`crate::method::energy_midpoint`]) instead of carrying g(q₀)/h² into the
//! multiplier. The release rule is on the state force, not on the step multiplier λ̄: where λ̄
//! is positive over a step whose end force is negative, a rule on λ̄ could only place the
//! release at the next step start, with λ far from zero.
//!
//! **Impact** (perfectly plastic, positions unchanged): M(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0, so
//! Λ = −G q̇⁻ / (G M⁻¹Gᵀ), q̇⁺ = q̇⁻ + M⁻¹GᵀΛ. The momentum residual
//! ‖M Δq̇ − GᵀΛ‖/‖M Δq̇‖ uses an independent mass product of the applied jump Δq̇ = M⁻¹GᵀΛ
//! (not the factorized matrix). The kinetic energy lost is booked as the ledger dissipation
//! `impact` as the difference of the evaluated kinetic energies before and after: for the
//! massive block alone it is ½Λ²(G M⁻¹Gᵀ) ≥ 0, but the frame reaction R_f (above) does work
//! where the frame directions move, so the evaluated difference, not the formula, closes the
//! ledger; it can be slightly negative at micro-impacts. A normal velocity at the round-off
//! level of G q̇ is no impact.
//!
//! **Grazing** (stated rules). After an impact the phase is constrained only if the normal
//! force at (q, q̇⁺) is positive, else the tip stays free (an impact immediately followed by
//! release; no release event is recorded, as in `modal`). Two situations are not determined
//! by the values at the step ends:
//! * a free step that starts on the surface (|g₀| ≤ tol: just released, or just impacted with
//!   λ ≤ 0) and ends below it, with no flight above the gap tolerance at its end;
//! * a constrained step whose start force is not positive and whose end force is not positive
//!   either (no zero crossing to locate).
//!
//! Both are retried with a quarter step (`Post::Refine`, event `step-rejected` "grazing
//! contact undetermined at this step"), down to [`REFINE_MIN`] of the nominal step: shorter
//! steps resolve the flight after a release (then a contact start located at a positive-gap
//! bracket) or the return to the surface. At the shortest step a free step that still enters
//! the surface starts the contact at its start (impact map, no event if a release was located
//! at that instant: that release is withdrawn — the tip did not leave by more than the gap
//! tolerance), and a constrained step whose force is still not positive releases the tip at
//! its end; the event reports that force and the step as `time_tolerance`. Beyond
//! [`GRAZING_FORCE_LIMIT`]·W the run stops with a diagnostic instead; so does a step that the
//! Newton iteration fails at every length down to its shortest (the driver's
//! `unresolved_contact_phase`: same location, cause and remedy). A release is reported
//! once the free motion after it has been stepped, so that a withdrawn one never appears.
//! Every event advances time; [`MAX_EVENTS`] bounds a Zeno-like accumulation. The normal force
//! after an impact oscillates at the unresolved mesh frequencies, and the tip makes
//! micro-bounces: the point impact on an Euler–Bernoulli beam is singular (Szalai 2014) and
//! these switching times are not converged quantities; the contact episodes are.
//!
//! Bilateral contacts (circle or line wall, Coulomb friction, stick–slip) reuse the gap,
//! gradient and bordered Newton of this module with the geometry of [`crate::events::wall`] and are
//! driven by [`crate::events::contact::friction`] (`Contact::bilateral`).
//!
//! **Methods.** The driver locates the events and applies the resets whatever the method;
//! a method only has to step the constrained phase through
//! [`StepConstraint`](crate::method::StepConstraint). The
//! `energy-midpoint` and `implicit-midpoint` steps do (both have the mean acceleration ā as
//! Newton unknown, ∂q₁/∂ā = h²/2, and both apply the discrete-gradient force above, so the
//! held constraint does no work in either). `generalized-alpha` does too, with that force at t₁
//! and q̈₁ as unknown, balanced so that the rule's average of the start and end forces does the
//! end force's work (`crate::method::generalized_alpha`). With `implicit-midpoint` and
//! `generalized-alpha` the ledger closes to the rule's own energy error (works by the
//! trapezoidal rule): it falls 4× per halved step in free flight and on the friction wall, but
//! more slowly through impacts, which excite mesh modes whose energy error the non-conserving
//! rule reduces as h² only once h ω resolves them. Switching times agree with
//! energy-midpoint's to O(h²) (`tests/dyn_contact_methods.rs`; measurements in
//! docs/contact.md). `bathe` holds the constraint at the end of each sub-step, and explicit
//! `central-difference`, which has no Newton iteration, by projecting its positions and
//! velocities onto the constraint ([`crate::method`]).
//!
//! Refused with `unsupported`: unilateral circle surfaces, friction on a unilateral contact,
//! more than one contact, contact with prescribed joint motion, contact on Timoshenko links
//! without rotary inertia and without Kelvin–Voigt damping (above; for a bilateral wall:
//! without rotary inertia), `implicit-midpoint` or `generalized-alpha` contact on Timoshenko
//! links without rotary inertia at all (the end rates of the massless rotations:
//! `crate::run`), and contact with adaptive stepping (`time.rtol`).
//!
//! **Layout.** This file: the contact's parts, its construction and the gap with its gradient;
//! `mass`: the solves with M(q) + μNNᵀ; `force`: the index-1 normal force; `impact`: the impact
//! map and the plastic projection; `step`: the [`StepConstraint`](crate::method::StepConstraint)
//! the methods consume; [`friction`]: the bilateral walls.

mod force;
pub mod friction;
mod impact;
mod mass;
mod step;

use data::Event;
use data::scene::{PlanarChain, Surface};

use crate::chain::{Chain, MAX_LINKS, V2};
use crate::error::FemError;
use crate::events::mass_solve::MassSolver;

/// Gap tolerance of a located contact start, relative to the longest link.
pub const GAP_TOL: f64 = 1e-10;
/// Normal-force tolerance of a located release, relative to the chain's weight.
pub const FORCE_TOL: f64 = 1e-8;
/// Smallest event bracket (time) the secant refines to.
pub const TIME_TOL: f64 = 1e-13;
/// Relative size of the last correction at which a refined mass solve stops
/// ([`Contact::solve_gradient`]).
const REFINE_TOL: f64 = 5e-13;
/// Contraction per iteration below which a refined mass solve gives up for a new factorization.
const REFINE_RATE: f64 = 0.1;
/// A normal force from a refined solve is kept when it exceeds this multiple of its error bound
/// (else it is evaluated again with a factorization at its configuration).
const REFINE_MARGIN: f64 = 100.0;
/// Refinement iterations at most before a new factorization.
const MAX_REFINE: usize = 6;
/// Refinement iterations from which the next mass solve forms a new factorization. A
/// refinement from a factorization a few steps old reaches [`REFINE_TOL`] in 3–6 iterations
/// on the arms; an iteration (one inertial pass and one solve) costs about a tenth of a new
/// factorization (a residual pass, the assembly of the exact mass matrix, the band
/// factorization and its border solves), so only a refinement that needed the iteration limit
/// asks for one. `barhorst-case1`, 5 elements, dt 2.5e-4: 1 119 of 9 174 state-force solves
/// factorize (3 842 of 9 138 when 4 iterations asked for a new factorization), 7 % less run
/// time, episode boundaries unchanged (docs/contact.md).
const SLOW_REFINE: usize = 6;
/// First correction (relative to x) beyond which the factorization at hand is given up at once.
const FAR_REFINE: f64 = 1e-2;
/// Most contact events in a run.
pub const MAX_EVENTS: usize = 20_000;
/// Shortest step (relative to the nominal one) the stretch of an undetermined grazing contact
/// is refined to (module docs).
pub const REFINE_MIN: f64 = 1e-5;
/// Largest normal force (relative to the chain's weight) at which a grazing contact is released
/// at the end of the shortest step; beyond it the run stops (module docs).
pub const GRAZING_FORCE_LIMIT: f64 = 1e-2;
/// Diagnostic location of that stop.
pub const GRAZING_LOCATION: &str = "contact1 (grazing)";

/// The tip contact, in parts with one job each: the constraint (what a method consumes), the
/// phase of the impact law, the record of the run, the scratch of the mass solves and, for a
/// bilateral wall, the friction refinement.
#[derive(Debug, Clone)]
pub struct Contact {
    /// Gap g, its gradient G and discrete gradient ∇̄g, the step multiplier: the rows a
    /// constrained step adds to the method's equations ([`crate::method::StepConstraint`]).
    pub constraint: TipConstraint,
    /// Phase and state of the impact law (held or free, normal force, gap and drift at the
    /// current state) and the event tolerances.
    pub phase: ImpactPhase,
    /// Ledger terms, drift maxima and events of the run.
    pub record: ContactRecord,
    /// Mass factorization and buffers of the index-1 force, the impact map and the projection.
    pub(crate) solve: ConstrainedSolve,
    /// Bilateral contact (circle or line wall, Coulomb friction, stick–slip): None for the
    /// unilateral line contact of this module.
    pub bilateral: Option<Box<crate::events::contact::friction::Bilateral>>,
}

/// The constraint g(q) = n̂·(r_tip(q) − p₀) = 0 of a held phase, as a method consumes it: the
/// surface, the gradient rows of the last evaluation and the Newton multiplier.
#[derive(Debug, Clone)]
pub struct TipConstraint {
    /// Link whose tip touches the line.
    pub link: usize,
    /// Unit normal to the free side and a point of the line.
    pub normal: V2,
    pub point: V2,
    /// Multiplier of the last constrained step (its mean normal force), the Newton unknown.
    pub step_lambda: f64,
    /// Tip Jacobian J = ∂r_tip/∂q (x rows, then y rows).
    pub(crate) jac: Vec<f64>,
    /// ∇g(q̄), ∇̄g, ∇g(q₁) and S⁻¹∇̄g of the constrained Newton iteration.
    pub(crate) g_mid: Vec<f64>,
    pub(crate) g_bar: Vec<f64>,
    pub(crate) g_end: Vec<f64>,
    pub(crate) s_inv_g: Vec<f64>,
    /// The Newton matrix (`NewtonSystem::formed`) `s_inv_g` was solved with, and the Newton
    /// iteration of the current iterate within its step.
    pub(crate) s_inv_g_of: Option<u64>,
    pub(crate) iteration: usize,
}

/// State of the plastic impact law: phase, index-1 normal force, gap and normal velocity at the
/// current state, and the absolute tolerances the driver locates events with.
#[derive(Debug, Clone)]
pub struct ImpactPhase {
    /// Tip on the surface (constrained phase).
    pub constrained: bool,
    /// Normal force at the current state (index-1 value; 0 in free flight).
    pub lambda: f64,
    /// Gap and normal tip velocity G q̇ at the current state.
    pub gap: f64,
    pub normal_velocity: f64,
    /// G q̇ at the end of the last constrained step before its projection (velocity drift).
    pub drift_velocity: f64,
    /// Absolute event tolerances: gap \[length\] and normal force \[force\].
    pub gap_tol: f64,
    pub force_tol: f64,
    /// A located release not yet reported: it is reported once the free motion after it has
    /// been stepped, and withdrawn when the tip turns out not to leave the surface (module
    /// docs, "Grazing").
    pub(crate) pending_release: Option<Event>,
}

/// What the run records of the contact: ledger terms, drift maxima, events.
#[derive(Debug, Clone)]
pub struct ContactRecord {
    /// Cumulative kinetic energy lost in impacts (ledger `impact`).
    pub impact_loss: f64,
    /// Cumulative kinetic energy removed by the step-end velocity projections (ledger
    /// `contact_projection`).
    pub projection_loss: f64,
    /// Largest |g| and |G q̇| at the ends of constrained steps (constraint drift).
    pub max_gap: f64,
    pub max_normal_velocity: f64,
    /// Events since the driver last drained them, and the total count.
    pub events: Vec<Event>,
    pub n_events: usize,
}

/// Scratch of the solves with the mass matrix: M(q) + μNNᵀ factorized and the work vectors of the index-1 force, the impact map and the velocity projection.
#[derive(Debug, Clone)]
pub(crate) struct ConstrainedSolve {
    /// M(q) + μNNᵀ, sparse ([`crate::events::mass_solve`]).
    mass: MassSolver,
    /// All massless directions of [`Chain::massless_directions`] (the exact ones and the
    /// frame directions of mass O(s²)): the regularization M + μ N Nᵀ, by DOF.
    reg_dirs: Vec<Vec<(usize, f64)>>,
    /// Mass scale μ of the regularization M + μNNᵀ.
    mass_scale: f64,
    /// Consistent velocity of the last state-force evaluation.
    qd_c: Vec<f64>,
    zero: Vec<f64>,
    unit: Vec<f64>,
    col: Vec<f64>,
    minv_gt: Vec<f64>,
    tmp: Vec<f64>,
    /// Correction of the refined solve.
    dx: Vec<f64>,
    /// Configuration (t, q) of `minv_gt` = (M + μNNᵀ)⁻¹Gᵀ (None: not valid).
    minv_key_t: Option<f64>,
    minv_key_q: Vec<f64>,
    /// Whether `minv_gt` was refined (else solved with a factorization at its configuration).
    minv_refined: bool,
    /// The last refined solve needed [`SLOW_REFINE`] iterations or more: the factorization
    /// at hand is too far from the configurations asked for, the next solve forms a new one.
    refactor_next: bool,
}

impl Contact {
    /// The tip contact of the planar chain `pc` (of scene `name`) on its discretization
    /// `chain` (None without one; nothing is allocated then).
    pub fn from_planar_chain(
        name: &str,
        pc: &PlanarChain,
        chain: &Chain,
    ) -> Result<Option<Self>, FemError> {
        crate::support::check_contact(name, pc)?;
        let Some(c) = pc.contacts.first() else {
            return Ok(None);
        };
        let link = pc.links.iter().position(|l| l.name == c.link).unwrap_or(0);
        let bilateral = crate::events::contact::friction::Bilateral::from_scene(c, chain)?;
        let (point, normal) = match c.surface {
            Surface::Line { point, normal } => (V2::from(point), V2::from(normal)),
            // The circle's normal depends on the tip position: `bilateral.wall` has it.
            Surface::Circle { .. } if bilateral.is_some() => (V2::zeros(), V2::new(0.0, 1.0)),
            Surface::Circle { .. } => {
                return Err(FemError::unsupported("fem: only line contact surfaces"));
            }
        };
        let len = normal.x.hypot(normal.y);
        if !(len > 0.0 && len.is_finite()) {
            return Err(FemError::InvalidSettings {
                field: "contact.surface.normal".into(),
                message: "the normal must be a non-zero vector".into(),
            });
        }
        let l_max = chain.links.iter().fold(0.0f64, |a, l| a.max(l.length));
        let mass: f64 = chain
            .links
            .iter()
            .map(|l| l.rho_a * l.length + l.tip_mass)
            .sum();
        let g = chain.gravity[0].hypot(chain.gravity[1]);
        let weight = mass * if g > 0.0 { g } else { 1.0 };
        let n = chain.ndof;
        let z = vec![0.0; n];
        let reg_dirs = chain.massless_directions();
        Ok(Some(Contact {
            constraint: TipConstraint {
                link,
                normal: normal / len,
                point,
                step_lambda: 0.0,
                jac: vec![0.0; 2 * n],
                g_mid: z.clone(),
                g_bar: z.clone(),
                g_end: z.clone(),
                s_inv_g: z.clone(),
                s_inv_g_of: None,
                iteration: 0,
            },
            phase: ImpactPhase {
                constrained: false,
                lambda: 0.0,
                gap: 0.0,
                normal_velocity: 0.0,
                drift_velocity: 0.0,
                gap_tol: GAP_TOL * l_max,
                force_tol: FORCE_TOL * weight,
                pending_release: None,
            },
            record: ContactRecord {
                impact_loss: 0.0,
                projection_loss: 0.0,
                max_gap: 0.0,
                max_normal_velocity: 0.0,
                events: Vec::new(),
                n_events: 0,
            },
            solve: ConstrainedSolve {
                mass: MassSolver::new(chain, &reg_dirs),
                reg_dirs,
                mass_scale: 0.0,
                qd_c: z.clone(),
                zero: z.clone(),
                unit: z.clone(),
                col: z.clone(),
                minv_gt: z.clone(),
                tmp: z.clone(),
                dx: z.clone(),
                minv_key_t: None,
                minv_key_q: z,
                minv_refined: false,
                refactor_next: false,
            },
            bilateral,
        }))
    }

    /// Gap g(q) (tip positions only, no Jacobian).
    pub fn gap_at(&self, chain: &Chain, t: f64, q: &[f64]) -> f64 {
        let mut tips = [V2::zeros(); MAX_LINKS];
        chain.tip_positions(t, q, &mut tips[..chain.links.len()]);
        self.gap_of(tips[self.constraint.link])
    }

    fn gap_of(&self, r: V2) -> f64 {
        if let Some(b) = self.bilateral.as_deref() {
            return b.constraint.wall.gap(r);
        }
        self.constraint.normal.dot(&(r - self.constraint.point))
    }

    /// Gap and its gradient G = n̂ᵀJ at q, the gradient written to `out`.
    pub fn gradient(&mut self, chain: &Chain, t: f64, q: &[f64], out: &mut [f64]) -> f64 {
        let n = chain.ndof;
        let r = chain.tip_jacobian(t, self.constraint.link, q, &mut self.constraint.jac);
        // A circle's normal is that at the tip (crate::events::wall); a line's is fixed.
        let normal = match self.bilateral.as_deref() {
            Some(b) => b.constraint.wall.frame(r).normal,
            None => self.constraint.normal,
        };
        let jac = &self.constraint.jac;
        for i in 0..n {
            out[i] = normal.dot(&V2::new(jac[i], jac[n + i]));
        }
        self.gap_of(r)
    }

    /// Reports a pending release (the free motion after it was stepped).
    pub fn flush_pending(&mut self) {
        if let Some(e) = self.phase.pending_release.take() {
            self.push(e);
        }
    }

    pub(crate) fn push(&mut self, e: Event) {
        self.record.n_events += 1;
        self.record.events.push(e);
    }
}
