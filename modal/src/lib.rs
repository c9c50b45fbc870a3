//! # modal — assumed-mode (Rayleigh–Ritz) reduction of flexible multibody scenes
//!
//! Each planar link is an Euler–Bernoulli (or Timoshenko, below) beam in a floating frame, clamped to the frame at its
//! root: transverse deflection v(x, t) = Σ φₖ(x) bₖ(t) with a basis chosen per run (`poly`,
//! `clamped-free`, `tip-mass`; see [`basis`]). With the frame angle α (joint convention of
//! scenes.md: αᵢ₊₁ = αᵢ + vᵢ'(Lᵢ) + θᵢ₊₁) the energies are
//!
//! * kinetic: T = ½ Σ ∫ρA |ṙ|² dx + tip masses/inertias + hub inertias,
//!   r = O + R(α)(x + u − f·s, v), s(x) = ½∫₀ˣ v'² (foreshortening, f = 1 when the scene turns
//!   it on or the link is extensible), u = Σψₖaₖ the stretch of an extensible link (`axial`);
//!   exact for every model, and exact at the tip point ([`model::body`]);
//! * strain: U = ½ Σ ∫EI v''² = ½ bᵀ K_b b; for extensible links also ½∫EA u'² = ½ aᵀK_a a,
//!   which is the von Kármán ½∫EA(u_x' + ½v'²)² of the axial displacement u_x = u − s: the
//!   axial basis holds the stretch only, so it need not represent −½v'² (the membrane locking
//!   of an axial basis that must); joint springs ½K(θ − θ₀)²; gravity −g·Σ∫ρA r;
//! * dissipation: Kelvin–Voigt γ ∫ v̇''² (damping matrix (γ/EI) K_b), joint dampers D θ̇².
//!
//! Timoshenko links (`shear`, [`model::section`]) carry an independent section rotation
//! ψ = Σ χₖ cₖ (clamped v(0) = ψ(0) = 0): U = ½∫EI ψ'² + ½∫κGA (v' − ψ)², Kelvin–Voigt
//! γ∫ψ̇'², rotary inertia ½∫ρI (α̇ + ψ̇)², tip inertia ½J(α̇ + ψ̇(L))², and the next link is
//! clamped to the tip cross-section: αᵢ₊₁ = αᵢ + ψᵢ(Lᵢ) + θᵢ₊₁ (the foreshortening keeps the
//! centre-line slope v'). Without rotary inertia ψ is massless and is
//! condensed (ψ = χᵀT b, T = −K_cc⁻¹K_cb; the Kelvin–Voigt relaxation of ψ enters to first
//! order). Rotary inertia is also accepted on Euler links (ψ = v').
//!
//! Lagrange's equations M(q) q̈ = f(q, q̇, t) follow by projecting each body's equations with
//! the chain's velocity map ([`model::chain`]); every spatial integral (modal mass, stiffness,
//! inertia invariants, foreshortening integrals ∫φ'φ'ᵀ weighted by the centrifugal load) is
//! computed once by Gauss quadrature ([`model::integrals`]), so a right-hand side needs no
//! spatial quadrature: O(N²) products of precomputed integrals (O(n⁴) per foreshortening link
//! for the exact inextensible kinetic terms) plus a dense N³/3 Cholesky of the small reduced
//! mass matrix. Prescribed hub motion is
//! imposed exactly and the torque it needs is reported. Time integration: [`integrate`]
//! (by default adaptive TR-BDF2 for Kelvin–Voigt-damped chains, with or without contact, an
//! exponential integrator exact on the undeformed arm's oscillators for undamped chains
//! without contact ([`integrate::Exponential`], [`pencil`]), Dormand–Prince 5(4) otherwise,
//! see [`simulate::default_method`]; adaptive TR-BDF2 is also
//! the method for other stiff cases: many `poly` modes, whose
//! overdamped Kelvin–Voigt eigenvalues reach −1.4e7 / −4.8e7 / −1.4e8 s⁻¹ at 16 / 20 / 24 modes
//! per link on `barhorst-case1-tipmass`). TR-BDF2 solves its Newton systems through the
//! chain's own factored linearization ([`newton`]: Cholesky of M + cD + c²K with the contact
//! rows, never M⁻¹K) and keeps it across the drift projections of the contact phase. The
//! rocket (seed 003) is in [`rocket`], the 3-D
//! link with an offset payload (seed 002) in [`payload_link`], the mobile manipulator with a
//! flexible pitch link (seed 004) in [`mobile`].
//!
//! Contact (Barhorst's work surface, [`contact`]): the gap g = n̂·(r_tip − p₀) is an event
//! function located by Illinois root finding on the integrator's dense output (bracket
//! ≤ [`events::EVENT_TIME_TOLERANCE`]); impact is the plastic generalized impulse–momentum
//! jump M(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0 (G = n̂ᵀJ_tip); while the normal force pushes, the tip
//! slides on the surface with a Lagrange multiplier (M q̈ = f + Gᵀλ, G q̈ = −Ġq̇, index 1) and
//! projection of q, q̇ back onto g = 0, G q̇ = 0 after every step; release is the located zero
//! crossing of λ. The kinetic energy lost in impacts enters the ledger as `impact`.
//!
//! Seed 001's wall (`constrained-arm`): a bilateral contact (circle or line) keeps g = 0 for all
//! time with the multiplier λ = normal force in newtons (g = R − |r − c| is the normalized form
//! of Φ = X² + Y² − L², |∇g| = 1); Coulomb friction −μ|λ| sign(v_t) t̂ enters as the generalized
//! force −μ s|λ|Tᵀ (T = t̂ᵀJ), which keeps the acceleration-level solve for λ linear for a fixed
//! sign; stick–slip transitions are located events (zero of the slip velocity, then the Coulomb
//! test with the tip held by a second constraint; while sticking, zero of μ|λ_n| − |λ_t|), and
//! the friction work ∫μ|λ||v_t| dt is integrated with the state (ledger term `friction`). Axial
//! links are accepted there: the tip position and Jacobian carry u(L). The inextensible link on
//! the circle of radius L about its own hub is refused: it must stay straight (the rigid model).

//!
//! Layout of a chain run, each module knowing only those before it: [`basis`] →
//! [`model`] (integrals, bodies, the chain's M, f, energies and tangents) → [`rhs`] (the chain
//! as y' = f(t, y) with its structured Newton linear algebra, [`newton`]) ; [`integrate`] (one
//! type per method behind [`integrate::Stepper`], registered in [`integrate::method_for`]) ;
//! [`contact`] (constraint geometry and state) → [`events`] (event functions, location on the
//! dense output, resets, projection) ; [`output`] (samples, ledger, stop diagnostics) →
//! [`simulate`] (the driver). Dense kernels: [`linalg`].

// Dense numerical kernels index several arrays with one loop variable on purpose.
#![allow(clippy::needless_range_loop)]

pub mod backend;
pub mod basis;
pub mod contact;
pub mod error;
pub mod events;
pub mod integrate;
pub mod linalg;
pub mod mobile;
pub mod model;
pub mod modes;
pub mod newton;
pub mod output;
pub mod payload_link;
pub mod pencil;
pub mod rhs;
pub mod rocket;
pub mod sampled;
pub mod setup;
pub mod simulate;
pub mod statics;

pub use backend::ModalBackend;
pub use error::ModalError;
