//! Two flexible links in series (`two-link-free`, `two-link-free-undamped`): link 2 is clamped to
//! the tip of link 1 and rotated by the elbow angle θ₂, so its clamp tangent has the angle
//! θ₁ + ψ + θ₂ with ψ = v₁'(L₁) (scenes.md; Barhorst's q₁, q₅).
//!
//! **Frames.** Each link's floating frame is its *tip chord* (v₀ = v_r = 0): θ and β are the
//! chord angles of links 1 and 2. The clamp condition is the report's ghost node, kept as an
//! unknown x = v₋₁: the clamp tangent turns by (v₁ − x)/(2h) from the chord and κ₀ =
//! (v₁ + x)/h². Pinning the tip to the chord makes every frame rotation move the link's mass
//! (in the clamp-tangent frame of the single link, with zero hub inertia, a tangent-frame
//! rotation against the opposite linear deflection moves no lumped mass). The clamp section's
//! own rotation carries the half-cell rotary inertia J_c = ρA h³/24 (O(h³), exact positive
//! term ½J_c(clamp angle rate)²).
//!
//! The foreshortening s = ½∫v′² is written in these chord frames, while the scene defines it in
//! the clamp-tangent frame (as fem and modal write it). The two second-order models agree to
//! fourth order in the slopes under distributed loads but differ at order (F L²/EI)·φ when a
//! transverse force F acts at the tip (φ the chord–tangent angle): the chord component F sin φ
//! adds a geometric stiffness the tangent model lacks (about 1 % of link 2's deflection while the
//! tip of `barhorst-case1-stiff-elbow` is held; docs/contact.md).
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
//! forward-mode dual-number pass over the points' velocities, [`kinetic`], [`dual`]). M couples
//! every coordinate through the full columns θ, β, x₁, x₂ (and y): the momenta at unit
//! velocities plus J_c e eᵀ (J_t e eᵀ); on the deflections it is each link's lumped diagonal
//! plus its foreshortening rates (a semiseparable block with a tridiagonal inverse) plus a
//! rank-2 coupling of link 1's tip rate with link 2 ([`mass`]): O(n) per solve, no allocation in
//! the step loop.
//!
//! **Step.** Velocity form by default (free joints: velocity-dependent inertia forces; damping
//! on). Without contact the damping (constant C) is implicit in the closing kick ([`implicit`]:
//! Crank–Nicolson in the damping, banded solve) and the bound is the undamped one below (ζ = 0);
//! with contact (restartable steps) it is explicit and the bound carries the damping.
//! Bound: 0.9 · 2/ω_max with ω_max from a power iteration on the linearized chain at t = 0
//! (once per run, O(n²)), with ζ = max(Kelvin–Voigt ζ of that frequency, κ_max/(2ω_max)) —
//! κ_max the fastest damping rate, a power iteration on −∂a/∂q̇ (the joint dampers act on the
//! clamp half-cell inertia: overdamped modes, velocity-form limit τ → 1/κ) — and the
//! clamp-rotation modes and link 1's tip-rotation mode with their joint-damper ratios. Gravity: V_g of the lumped masses
//! ([`TwoLinkChain`]'s `gravity_potential`). Tip contact: [`contact`]. Observables: joint angles/rates (clamp angles),
//! torques = law + spring + damper, tip positions, and deflections in the clamp-tangent frame.
//!
//! **Timoshenko links** (`shear` on both links): [`timoshenko`] — ψ at the stations replaces the
//! clamp ghost (the clamp section's turn from the chord is ψ₀), ψ is massless in the chord
//! frames and condensed; the clamp ghost slots of q stay in place, unused (zero force, a
//! decoupled unit mass), so the mass solve and the contact code are shared unchanged; there is
//! no tip ghost (link 1's tip section is the condensed ψ).
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
mod schur;
mod surface;
mod system;
pub mod timoshenko;

pub use build::DEFAULT_STATIONS;
pub use model::TwoLinkChain;
