//! The 3-D flexible link with an offset payload (seed 002, scene family `[payload_link]`):
//! modes, gravity statics and dynamics with 3-D beam elements in the turning frame.
//!
//! ## Model (docs/single-link-3d.md)
//! Base angle θ about Z; the rod along the turning frame's x carries u (axial), v (turning
//! plane), w (vertical) and φ (twist), each only if the scene's `fields` lists it. Element
//! ([`crate::element::beam3d`]): u, φ linear, v, w Hermite cubic; DOFs per node u, v, v′, w, w′, φ;
//! every operator integrated by 4-point Gauss quadrature (exact for all integrands).
//!
//! The kinetic energy truncated at second order in the fields (θ̇ of order zero) is a quadratic
//! form in the velocities whose coefficients are polynomials of degree ≤ 2 in the DOFs d:
//!
//! T = ½J(d)θ̇² + θ̇ b(d)·ḋ + ½ḋᵀMḋ,  J(d) = J₀ + 2j₁·d + dᵀK_c d,  b(d) = b₀ + Gᵀd,
//!
//! with constant band operators ([`model::Model`]) summed from two building blocks:
//! * a point of mass m at reference abscissa a with displacements (u, y, z) — rod sections
//!   (ρA dx at x) and the payload's centre (a = L + c, y = v_L + c v′_L, z = w_L + c w′_L):
//!   ½m[u̇² + ẏ² + ż² + 2θ̇(uẏ − u̇y) + 2θ̇aẏ + θ̇²(a² + 2au + u² + y²)], plus the foreshortening
//!   term −θ̇²m a S (S = s(x), or s_L + ½c(v′_L² + w′_L²) for the payload), which for the rod
//!   integrates to −½θ̇²∫ρA·½(L² − x²)(v′² + w′²) dx (the centrifugal tension);
//! * a rigid body of inertia I in the section axes (ρ dx·diag(J, I, I) for rod sections, I_p
//!   for the payload) with orientation R = R_t(0, −w′, v′)R_x(φ): its body angular velocity
//!   RᵀΩ = θ̇(w′, φ − ½v′w′, 1 − ½(w′² + φ²)) + (φ̇ + ½(w′v̇′ − v′ẇ′), −ẇ′ + φv̇′, v̇′ + φẇ′)
//!   gives ½(RᵀΩ)ᵀI(RᵀΩ) truncated at second order (products of inertia included).
//!
//! V = ½dᵀK_s d + f_g·d + ½K(θ − θ₀)² (K_s from EA u′², EI v″², EI w″², GJ φ′²; f_g from
//! g(ρA∫w + m_p(w_L + c w′_L))); Rayleigh ½b_mθ̇² + ½ḋᵀCḋ with C = Σ C_f, one band per damped
//! field (C_X A u̇′², C_Y I v̇″², C_Z I ẇ″², C_Φ J φ̇′²). Lagrange's equations:
//! * M d̈ + b(d)θ̈ + θ̇(Gᵀ − G)ḋ − θ̇²(j₁ + K_c d) + K_s d + Cḋ + f_g = 0,
//! * J(d)θ̈ + b(d)·d̈ + 2θ̇(j₁ + K_c d)·ḋ + ḋᵀGḋ = T_mot(t) − b_mθ̇ − K(θ − θ₀)
//!   (a prescribed base drops this equation; its left side plus b_mθ̇ + K(θ − θ₀) is the torque
//!   the motion needs, channel `joint1.torque`).
//!
//! Geometric stiffening and softening with θ̇² sit in −θ̇²K_c, the Coriolis/gyroscopic coupling
//! in θ̇(Gᵀ − G), the θ̈ coupling in b(d).
//!
//! ## Modes ([`modes()`])
//! Linearized about the undeformed rod at the base's reference rate Ω (0, or the rate of a
//! `constant-rate` base): K = K_s − Ω²K_c, M; a free base adds θ (mass row J₀, b₀; stiffness the
//! joint spring). The generalized symmetric problem is solved densely ([`crate::modes`])
//! ([`link_modes`]). At a prescribed constant rate the gyroscopic term Ω(Gᵀ − G) (it couples u
//! with v and w′ with φ) stays in: the quadratic eigenproblem M q̈ + Ω(Gᵀ − G)q̇ + Kq = 0 in
//! first-order skew form ([`gyroscopic_modes`]). A free base without spring has a rigid rotation,
//! listed first at 0 Hz with kind `rigid`. Kinds: the field holding most of a mode's kinetic
//! energy (`axial`, `bending-horizontal`, `bending-vertical`, `torsion`, `rigid` for θ).
//!
//! ## Statics ([`statics()`])
//! K_s d = −f_g: the linear sag of the clamped rod under self-weight, payload weight and the
//! payload's offset moment; `tip_deflection` = w_L, `tip_rotation` = w′_L. The same d is the
//! `static-sag` initial shape.
//!
//! ## Dynamics ([`simulate()`])
//! The link is a [`crate::system::System`] ([`system::LinkSystem`]: residual groups, analytic
//! Newton matrix S = c_a ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q, energies) stepped by a method of the
//! registry ([`crate::method::stepper`]) on the link's driver path ([`driver`]): fixed steps onto
//! the output times and the motor law's switches, works booked with the midpoint rule,
//! Kelvin–Voigt per damped field. Methods: `implicit-midpoint` (the default), `generalized-alpha`
//! (ρ∞ = 0.9 with the axial field, else 1), `energy-midpoint`, `bathe`, and `central-difference`
//! (its step under 2/ω_max, [`crate::method::central_difference::stability_bound`]: the
//! Kelvin–Voigt damping of the kHz axial and torsion modes is implicit in it). Adaptive
//! steps are refused.
//! Default mesh 16 elements ([`crate::settings::DEFAULT_ELEMENTS`]); default step of the implicit
//! methods [`default_step`]: the largest step (fitted to divide the output interval) whose
//! estimated phase error of the modes the scene's loads excite (gravity against the initial
//! shape, centrifugal load, motor torque and its switches, a prescribed base's acceleration),
//! each damped by its Kelvin–Voigt decay, stays below [`PHASE_ERROR_TOLERANCE`] of the scale of
//! the payload's height, its turning-plane position and the base angle (the estimate is the
//! implicit midpoint rule's phase error). Torsion and axial modes (hundreds of Hz to kHz on the
//! catalog rods) hardly move those observables and are not resolved by that step: the midpoint
//! rule keeps them bounded and undamped, with a phase error in `tip_twist`.

pub mod driver;
pub mod model;
mod modes;
mod plan;
mod simulate;
mod statics;
mod step_rule;
pub mod system;

pub use modes::{Mode3d, gyroscopic_modes, link_modes, modes};
pub use plan::{dof_plan, elements};
pub use simulate::{Prepared, prepare, simulate};
pub use statics::{static_sag, statics};
pub use step_rule::{PHASE_ERROR_TOLERANCE, default_step};
