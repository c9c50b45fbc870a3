//! Two flexible links in series (`two-link-free`, `two-link-free-undamped`): link 2 is clamped to
//! the tip of link 1 and rotated by the elbow angle θ₂, so its clamp tangent has the angle
//! θ₁ + ψ + θ₂ with ψ = v₁'(L₁) (scenes.md; Barhorst's q₁, q₅).
//!
//! **Coordinates.** q = (θ, β, v, x₁, w, x₂, y): θ and β are the *tip-chord* angles of links
//! 1 and 2, v and w the deflections from the chords (v₀ = v_r = 0). The clamp condition is the
//! report's ghost node, kept as an unknown x = v₋₁: the clamp tangent turns by
//! ψ = (v₁ − x)/(2h) from the chord and κ₀ = (v₁ + x)/h². The bending energy, the damping, the
//! joint angles and the step bound are written in these coordinates.
//!
//! **Kinematics: the clamp-tangent frames** (the scene's model, as fem and modal write it).
//! Each link's points sit in its clamp-tangent frame, α = (chord angle) + ψ, at
//! (ξ − s^t, v^t) with v^t_k = v_k − ξ_kψ (v^t₀ = 0, tip −Lψ) and s^t_k = ½h Σ_{seg ≤ k}
//! (g_seg − ψ)², g the chord-frame segment slopes; link 2 hangs from the elbow E, link 1's
//! point r: E = R(α₁)(L₁ − S^t₁, −L₁ψ₁). This is an exact change of variables of the tangent
//! model: ξψ has zero second difference, so κ^t = κ, and the clamp angle α and every joint
//! angle are unchanged. The map q ↦ (α, v^t) is linear and constant (P, `to_kinetic`): T, the
//! gravity potential and the contact gap are the kernel's ([`kinetic`]: frame angles and
//! deflections with the tip's) at P q, their forces Pᵀ of the kernel's. (The chord frames
//! with s = ½∫v′² of the chord-frame deflections are a different second-order model: under a
//! transverse tip force F the chord component F sin φ adds a geometric stiffness of order
//! (F L²/EI)·φ the tangent model lacks — about 1 % of link 2's deflection while the tip of
//! `barhorst-case1-stiff-elbow` is held.) The clamp section's own rotation carries the
//! half-cell rotary inertia J_c = ρA h³/24 (O(h³), exact positive term ½J_c α̇²); the hub rotor
//! J₁ turns with α₁.
//!
//! **Equations.** Lagrange's equations of L = T − V with the dissipation function D:
//! * T: [`kinetic`] (½Σm|ṙ|² of the lumped points, exact) + Σ ½J_c,ℓ (clamp angle rate)²;
//! * V = Σ_ℓ ½ Σᵢ cᵢ h EI κᵢ² (the single link's ghost-node bending energy, [`crate::link`],
//!   with κ₀ from the clamp ghost) plus ½K₁(θ₁ − θ₁⁰)² + ½K₂(θ₂ − θ₂⁰)², θ₁ the clamp angle of
//!   link 1, θ₂ = (clamp angle of link 2) − θ − ψ, ψ = (y − v_{r−1})/(2h₁) the central tip
//!   slope of link 1 with its **tip ghost** y = v_{r+1} (v_r = 0). Link 1's sum runs to the
//!   elbow station with the trapezoid end weight c_r = ½ and κ_r = (y + v_{r−1})/h², so ∂V/∂y
//!   = 0 reads EI κ_r = K₂(θ₂ − θ₂⁰) + O(h²): the elbow moment is a second-order boundary
//!   condition (as the clamp ghost's κ₀ at each root), and the shear is the reaction of v_r = 0
//!   in the frame equations. (Treating link 1's tip as a free end, κ_r = 0 in the energy with
//!   a one-sided slope, is O(h) wherever the elbow carries a moment.) The tip section turns
//!   with θ + ψ and carries its half cell's rotary inertia J_t = ρA₁h₁³/24 (O(h³), as J_c);
//! * D = Σ_ℓ ½ Σᵢ cᵢ h γ κ̇ᵢ² + ½D₁θ̇₁² + ½D₂θ̇₂² (link 1's sum with the same tip term);
//!   applied torque laws τⱼ(t) do the work ∫τⱼ θ̇ⱼ.
//!
//! M(q) q̈ = Q − ∂V/∂q − ∂D/∂q̇ + f_inertia(q, q̇), the inertia forces in Kane's form (one
//! forward-mode dual-number pass over the points' velocities, [`kinetic`], [`dual`], then Pᵀ).
//! The mass solve works in z, q with ψ₁, ψ₂ in the ghost slots (x = v₁ − 2hψ): there every
//! point moves with its own deflection rate, its link's foreshortening rates and the full
//! columns θ, β, ψ₁, ψ₂ (and y), the momenta at unit velocities plus J_c e eᵀ (J_t e eᵀ); on
//! the deflections M is each link's lumped diagonal plus its foreshortening rates (a
//! semiseparable block with a tridiagonal inverse, tangent-frame slopes) plus a rank-2 coupling
//! of link 1's tip rate with link 2 ([`mass`]): O(n) per solve, no allocation in the step loop.
//!
//! **Step.** Velocity form by default (free joints: velocity-dependent inertia forces; damping
//! on). The damping (constant C) is implicit in the closing kick ([`implicit`]: Crank–Nicolson
//! in the damping, banded solve; with the tip contact's held force and restartable steps too)
//! and the bound is the undamped one below (ζ = 0); the Timoshenko chain keeps it explicit and
//! the bound carries the damping. Without
//! damping the velocity-quadratic inertia terms take the velocity form's time-symmetric corrector
//! pass: the clamp-rotation inertia J_c + Σm(s^t)² changes with the deflections, and the
//! extrapolated rule alone lets the ledger drift ([`crate::method::velocity_form`]).
//! Bound: 0.9 · 2/ω_max with ω_max from a power iteration on the linearized chain at t = 0
//! (once per run, O(n²); the bound names a clamp's or link 1's tip rotation mode when that
//! ghost is the top mode's largest component — on the catalog's arms link 2's clamp, its ghost
//! against J_c stiffened by the curvature term's 2EI/h: ω² ≈ 48EI/(ρAh⁴), √3 above the
//! bending waves' (4/h²)√(EI/ρA)), with ζ = max(Kelvin–Voigt ζ of that frequency,
//! κ_max/(2ω_max)) — κ_max the fastest damping rate, a power iteration on −∂a/∂q̇ (the joint
//! dampers act on the clamp half-cell inertia: overdamped modes, velocity-form limit τ → 1/κ)
//! — and the clamp-rotation modes and link 1's tip-rotation mode with their joint-damper
//! ratios. Gravity: V_g of the lumped masses ([`TwoLinkChain`]'s `gravity_potential`). Tip contact: [`contact`]. Observables: joint angles/rates (clamp angles),
//! torques = law + spring + damper, tip positions, and deflections in the clamp-tangent frame
//! (the kernel's v^t).
//!
//! **Timoshenko links** (`shear` on both links): [`timoshenko`] — ψ at the stations replaces the
//! clamp ghost (the clamp section's turn from the chord is ψ₀), ψ is massless in the chord
//! frames and condensed; the clamp ghost slots of q stay in place, unused (zero force, a
//! decoupled unit mass), so the mass solve and the contact code are shared unchanged; there is
//! no tip ghost (link 1's tip section is the condensed ψ). Timoshenko links keep the
//! *chord-frame* kinematics (P zeroes the ghost slots, z = q): in the clamp-section frame the
//! condensed ψ₀ would move every lumped mass, and the condensation assumes a massless ψ.
//!
//! **Modules.** The chain's data sit in modules that use no operation of the chain: `model`
//! ([`TwoLinkChain`], its joints and links, and the coordinate maps: clamp, tip and elbow
//! angles, chord-frame copies, the lumped diagonal of M) and the types of its parts —
//! [`kinetic`], [`dual`], [`timoshenko`], `surface` (the contact line and the constraint state),
//! `damping_matrix` (C and the saddle system of the implicit kick), `rates` (a link's
//! foreshortening-rate block and its Woodbury solve) and `schur` (the small dense system of the
//! mass solves). The operations extend [`TwoLinkChain`] in their own modules:
//! `build` (construction, DOF plan, initial state), `forces` (forces, energies, momenta,
//! powers), [`mass`] (M's structure and its solve), [`contact`] (gap, constraint, impact,
//! projections), [`implicit`] (the damping kick), `bound` (step bound), `system` (the chain as a
//! [`System`](crate::system::System)), `outputs` (channels, ledger) and [`modes`] (linearized
//! modes).

// Index loops over parallel buffers (q, v, a, columns of M) read like the formulas.
#![allow(clippy::needless_range_loop)]

mod bound;
mod build;
pub mod contact;
mod damping_matrix;
pub mod dual;
mod forces;
pub mod implicit;
pub mod kinetic;
pub mod mass;
mod model;
pub mod modes;
mod outputs;
mod rates;
pub mod schur;
mod surface;
mod system;
pub mod timoshenko;

pub use build::DEFAULT_STATIONS;
pub use model::TwoLinkChain;
pub use rates::rate_block;
