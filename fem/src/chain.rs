//! Floating-frame chain: kinematics, residual of Lagrange's equations, Newton matrix, energies.
//!
//! Link i carries a frame (angle φᵢ, origin Rᵢ). A material point at x has local position
//! p(x) = (x + w(x), v(x)) with w = u (axial field), w = s = −½∫₀ˣ v′² (foreshortening) or w = 0,
//! and inertial position r = Rᵢ + A(φᵢ) p. Frames: φ₁ = θ₁, R₁ = 0; φᵢ₊₁ = φᵢ + βᵢ(Lᵢ) + θᵢ₊₁,
//! Rᵢ₊₁ = rᵢ(Lᵢ) (scenes.md joint convention), with β the section angle relative to the frame:
//! v′ for Euler–Bernoulli links, the section rotation ψ for Timoshenko (`shear`) links.
//!
//! Elements: every link is meshed with one [`crate::element::Element`] (Hermite cubic or
//! quintic for Euler–Bernoulli links, the Timoshenko element for `shear` links), whose local
//! DOFs are (v, β) at both end nodes plus its interior DOFs (global, numbered just before the
//! element's end node so the band stays 2·dpn − 1 + n_interior wide). The chain integrates
//! inertia, loads and foreshortening from the element's shapes tabulated at its own Gauss orders
//! ([`crate::element::Quadrature`]); the elastic force, tangent and strain energy come from the
//! element. For a Timoshenko link the foreshortening and membrane strain use the centre-line
//! slope v′, and its ψ DOFs move no material point. Kelvin–Voigt acts on the curvature (β′)
//! only. Section rotary inertia adds ½∫ρI(φ̇ + β̇)² (angle linear in q: mass only). The "tip
//! slope" column of J that an ancestor link contributes is β(L), so the per-point Jacobian
//! columns (joint, tip slope, tip v, tip u per ancestor) are the same for every element.
//!
//! Modules, one job each: [`Chain::with_element`] here builds the DOF layout and the element
//! operators; `kinematics` is the forward pass (frame and point kinematics, tip kinematics for
//! observables and contact), `forces` the backward pass (the residual), `newton` the Newton
//! matrix, `energies` the stored energies and powers; `geometry` holds the planar vector helpers.
//!
//! With T = ½Σ m|ṙ|² (Gauss quadrature of ρA, tip masses, tip and hub inertias) and
//! V = U_elastic + U_joint − Σ m g·r, Lagrange's equations are exactly
//!   R(q, q̇, q̈) = Σ m Jᵀ(r̈ − g) + ∂U/∂q + C q̇ − Q_joint = 0,  J = ∂r/∂q,
//! because d/dt ∂T/∂q̇ − ∂T/∂q = Σ m Jᵀ r̈. The residual is evaluated in O(n) by a forward
//! (kinematic) pass and a backward (force) pass over the chain; the foreshortening part of Jᵀ,
//! ∂s(x)/∂q = −∫₀ˣ v′ N′, is applied through the tail axial load T(ξ) = ∫_ξ^L f_x:
//!   Σ f_x ∂s/∂q = −∫ T v′ N′ dξ  (exact for the quadrature, by exchanging the two sums).
//! The Newton matrix ([`Chain::newton_matrix`]) is exact without foreshortening (checked against
//! finite differences of the residual). With foreshortening the ∂s/∂q couplings are dense over
//! a link (O(v′²) between elastic DOFs, O(v′) in the joint rows) but semiseparable: they reach
//! the DOFs only through the running sums of δs, δṡ, δs̈ (forward) and of the tail load δT
//! (backward). [`Chain::exact_newton_matrix`] keeps these sums as auxiliary unknowns at the
//! nodes, which makes the exact matrix a sparse bordered band ([`AugmentedLayout`]): at every
//! mass point the x-column σ = ∂s(x)/∂q of J enters through the point's virtual axial direction
//! (its variation from Z, its generalized force into Θ and the element rows), and an ancestor's
//! s(L) moves its descendants' points like an axial tip DOF. Checked against finite
//! differences of the residual (`sys_foreshortening_tangent`).

use data::scene::{Gravity, Link, PlanarChain, PrescribedMotion, TorqueLaw};
use data::{FemElement, FemSettings};

use crate::band::BorderedBand;
use crate::element::{self, ElementDofs, InteriorField, MeshElement};
use crate::error::FemError;

pub use crate::element::{MAXE, NONE};
pub use crate::system::{NewtonCoefficients, Parts};
pub use augmented::AugmentedLayout;
pub use geometry::V2;

mod augmented;
mod energies;
mod forces;
mod geometry;
mod kinematics;
pub mod linearized;
mod newton;
mod system;
/// Longest chain the backend builds (fixed-size per-point column buffers, no allocation).
pub const MAX_LINKS: usize = 6;
/// Ancestor columns of J at most: joint, tip slope, tip v, tip u per link.
const MAX_COLUMNS: usize = 4 * MAX_LINKS;

/// The joint at a link's root.
#[derive(Debug, Clone)]
pub struct JointModel {
    /// Global DOF of the joint angle, or [`NONE`] when prescribed.
    pub dof: usize,
    pub stiffness: f64,
    pub damping: f64,
    pub set_point: f64,
    pub initial_angle: f64,
    pub initial_rate: f64,
    pub torque: Option<TorqueLaw>,
    pub prescribed: Option<PrescribedMotion>,
}

impl JointModel {
    /// Applied torque law τ(t) (0 without a law).
    pub fn applied(&self, t: f64) -> f64 {
        self.torque.as_ref().map_or(0.0, |l| l.torque(t))
    }
    /// (θ, θ̇, θ̈) of a prescribed joint.
    pub fn prescribed_at(&self, t: f64) -> Option<(f64, f64, f64)> {
        self.prescribed.as_ref().map(|p| {
            let (a, r, acc) = p.kinematics(t);
            (self.initial_angle + a, r, acc)
        })
    }
}

/// One link with its element mesh and DOF map.
#[derive(Debug, Clone)]
pub struct LinkModel {
    pub length: f64,
    pub n_el: usize,
    pub h: f64,
    pub rho_a: f64,
    pub ei: f64,
    /// EA when `axial` is on (else 0).
    pub ea: f64,
    pub axial: bool,
    pub foreshortening: bool,
    /// Timoshenko link (`shear`): the section angle is a field of its own.
    pub shear: bool,
    /// Local DOFs per element (4 nodal + interior).
    pub ne: usize,
    /// Section rotary inertia ρI when `rotary_inertia` is on (else 0).
    pub rho_i: f64,
    /// Kelvin–Voigt γ (bending moment γ v̇″, or γ ψ̇′ for a Timoshenko link).
    pub kelvin_voigt: f64,
    pub tip_mass: f64,
    pub tip_inertia: f64,
    pub hub_inertia: f64,
    pub joint: JointModel,
    /// Global DOF of v, slope and u at node k = 0..=n (node 0 clamped: [`NONE`]). The slope is
    /// v′ for an Euler–Bernoulli link and the section rotation ψ for a Timoshenko link.
    pub v_dof: Vec<usize>,
    pub r_dof: Vec<usize>,
    pub u_dof: Vec<usize>,
    /// Element-interior DOFs of element e at ni·e..ni·(e + 1), ni = the element's interior
    /// count (e.g. Timoshenko v(⅓), v(⅔), ψ(½); quintic a₁, a₂; empty for the cubic).
    pub int_dof: Vec<usize>,
    /// The element of this link: kind, operators and tabulated shapes.
    pub element: MeshElement,
}

impl LinkModel {
    /// The deflection DOFs of this link's field turned rigidly by −1 rad about its root, with
    /// their coefficients: v = −x at the nodes (root excluded), then at the elements' interior
    /// deflection points, element by element.
    fn counter_rotated_deflections(&self) -> Vec<(usize, f64)> {
        let interior = self.element.kind.interior();
        let ni = interior.len();
        let mut d = Vec::new();
        for k in 1..=self.n_el {
            if self.v_dof[k] != NONE {
                d.push((self.v_dof[k], -(k as f64) * self.h));
            }
        }
        for e in 0..self.n_el {
            for (k, idof) in interior.iter().enumerate() {
                if idof.field == InteriorField::Deflection {
                    d.push((self.int_dof[ni * e + k], -(e as f64 + idof.at) * self.h));
                }
            }
        }
        d
    }

    /// Element-interior DOFs per element.
    fn n_interior(&self) -> usize {
        self.ne - 4
    }

    fn elem_dofs(&self, e: usize) -> [usize; MAXE] {
        let mut d = [NONE; MAXE];
        d[0] = self.v_dof[e];
        d[1] = self.r_dof[e];
        d[2] = self.v_dof[e + 1];
        d[3] = self.r_dof[e + 1];
        let ni = self.n_interior();
        d[4..4 + ni].copy_from_slice(&self.int_dof[ni * e..ni * (e + 1)]);
        d
    }

    /// Shape functions at local coordinate ξ of an element: (v, section angle).
    fn shapes_at(&self, xi: f64) -> ([f64; MAXE], [f64; MAXE]) {
        let s = self.element.kind.shapes(xi, self.h);
        (s.n, s.b)
    }
}

/// Kinematics of one link's frame and tip (filled by the forward pass).
#[derive(Debug, Clone, Copy, Default)]
pub struct FrameState {
    pub phi: f64,
    pub dphi: f64,
    pub ddphi: f64,
    pub r: V2,
    pub dr: V2,
    pub ddr: V2,
    /// Joint angle θᵢ and its rates.
    pub theta: f64,
    pub dtheta: f64,
    pub ddtheta: f64,
    /// Tip local position/velocity/acceleration (frame coordinates, relative terms only).
    pub p_tip: V2,
    pub dp_tip: V2,
    /// Full inertial acceleration of the tip in frame coordinates.
    pub a_tip: V2,
    pub slope_tip: f64,
    pub dslope_tip: f64,
    pub ddslope_tip: f64,
    /// Generalized joint moment of the subtree about Rᵢ (inertial + gravity, d'Alembert sign).
    pub subtree_moment: f64,
    /// Subtree resultant force (inertial coordinates, d'Alembert sign).
    pub subtree_force: V2,
}

/// The assembled chain model with preallocated work buffers.
#[derive(Debug, Clone)]
pub struct Chain {
    pub links: Vec<LinkModel>,
    pub gravity: V2,
    pub ndof: usize,
    /// Interior/border split for the Newton matrix.
    pub n_interior: usize,
    pub half_bandwidth: usize,
    pub frames: Vec<FrameState>,
    /// Per link, per element, per Gauss point: force density f = m(a − g) (frame coords) and
    /// local position p.
    force: Vec<Vec<V2>>,
    pos: Vec<Vec<V2>>,
    /// Local velocity ṗ at each Gauss point (for the Coriolis part of the Newton matrix).
    vel: Vec<Vec<V2>>,
    /// Velocity c = u + ω ẑ×p + ṗ of each Gauss point in its link frame, at the generalized
    /// velocity of the last [`Chain::add_kinetic_gradient`] call (its own buffer: the Newton
    /// matrix reads `pos`/`vel` of the last full residual).
    kin_vel: Vec<Vec<V2>>,
    /// Per link, per element, per sub-interval: tail axial load T (foreshortening).
    tail: Vec<Vec<f64>>,
    /// Generalized joint torque each joint's actuator needs (prescribed) or applies (free: the
    /// law; the torque channel adds the joint's spring and damper).
    pub joint_torque: Vec<f64>,
    /// Constant transverse loads on the last link, in its frame (the scene's `[statics]` loads
    /// applied as a step at t = 0): tip force P and uniform load q.
    pub tip_load: f64,
    pub distributed_load: f64,
}

impl Chain {
    /// Builds the chain for `links` with `n_el` Hermite-cubic (Timoshenko for `shear` links)
    /// elements per link.
    pub fn new(links: &[Link], gravity: Option<&Gravity>, n_el: usize) -> Result<Self, FemError> {
        Self::with_element(links, gravity, n_el, None)
    }

    /// The chain of the planar chain `pc` of scene `name` at its discretization (elements per
    /// link and element kind): the chain is checked against what the backend builds
    /// ([`check_planar`]) first. Its static loads are left at zero (dynamics applies them as a
    /// step load).
    ///
    /// [`check_planar`]: crate::support::check_planar
    pub fn from_planar_chain(
        name: &str,
        pc: &PlanarChain,
        settings: &FemSettings,
    ) -> Result<Self, FemError> {
        crate::support::check_planar(name, pc)?;
        let n_el = crate::settings::elements(settings)?;
        Self::with_element(&pc.links, pc.gravity.as_ref(), n_el, settings.element)
    }

    /// Builds the chain for `links` with `n_el` elements per link of the element `choice`
    /// (`discretization.element`; see [`element::for_link`]).
    pub fn with_element(
        links: &[Link],
        gravity: Option<&Gravity>,
        n_el: usize,
        choice: Option<FemElement>,
    ) -> Result<Self, FemError> {
        let nl = links.len();
        if nl > MAX_LINKS {
            return Err(FemError::unsupported(format!(
                "fem run: chains of more than {MAX_LINKS} links ({nl} given)"
            )));
        }
        // DOF numbering: interior elastic DOFs first (link by link, node by node), then border
        // DOFs: the tip node of every link that carries a child, then free joint angles.
        let mut next = 0usize;
        let mut models = Vec::with_capacity(nl);
        for (i, l) in links.iter().enumerate() {
            if n_el == 0 {
                return Err(FemError::unsupported(
                    "fem run: a link needs at least one element".to_string(),
                ));
            }
            let h = l.length / n_el as f64;
            let kind = element::for_link(l, choice)?;
            let ni = kind.interior().len();
            let has_child = i + 1 < nl;
            let mut v_dof = vec![NONE; n_el + 1];
            let mut r_dof = vec![NONE; n_el + 1];
            let mut u_dof = vec![NONE; n_el + 1];
            let mut int_dof = vec![NONE; ni * n_el];
            let interior_nodes = if has_child { n_el - 1 } else { n_el };
            // Element e's interior DOFs precede node e + 1: every element's DOFs stay within
            // one contiguous window (the band).
            for e in 0..n_el {
                for k in 0..ni {
                    int_dof[ni * e + k] = next + k;
                }
                next += ni;
                let k = e + 1;
                if k > interior_nodes {
                    continue;
                }
                v_dof[k] = next;
                r_dof[k] = next + 1;
                next += 2;
                if l.axial {
                    u_dof[k] = next;
                    next += 1;
                }
            }
            let j = &l.joint;
            models.push(LinkModel {
                length: l.length,
                n_el,
                h,
                rho_a: l.mass_per_length,
                ei: l.bending_stiffness,
                ea: if l.axial {
                    l.axial_stiffness.unwrap_or(0.0)
                } else {
                    0.0
                },
                axial: l.axial,
                foreshortening: l.foreshortening,
                shear: l.shear,
                ne: kind.local_dofs(),
                rho_i: if l.rotary_inertia {
                    l.rotary_inertia_per_length.unwrap_or(0.0)
                } else {
                    0.0
                },
                kelvin_voigt: l.kelvin_voigt.unwrap_or(0.0),
                tip_mass: l.tip_mass.unwrap_or(0.0),
                tip_inertia: l.tip_inertia.unwrap_or(0.0),
                hub_inertia: j.hub_inertia.unwrap_or(0.0),
                joint: JointModel {
                    dof: NONE,
                    stiffness: j.stiffness.unwrap_or(0.0),
                    damping: j.damping.unwrap_or(0.0),
                    set_point: j.set_point.unwrap_or(0.0),
                    initial_angle: j.initial_angle,
                    initial_rate: j.initial_rate,
                    torque: j.torque.clone(),
                    prescribed: j.prescribed.clone(),
                },
                v_dof,
                r_dof,
                u_dof,
                int_dof,
                element: MeshElement::new(kind, l, h),
            });
        }
        let n_interior = next;
        for (i, m) in models.iter_mut().enumerate() {
            if i + 1 < nl {
                let k = n_el;
                m.v_dof[k] = next;
                m.r_dof[k] = next + 1;
                next += 2;
                if m.axial {
                    m.u_dof[k] = next;
                    next += 1;
                }
            }
        }
        for m in models.iter_mut() {
            if m.joint.prescribed.is_none() {
                m.joint.dof = next;
                next += 1;
            }
        }
        // Half-bandwidth: an element spans node e, (its interior DOFs,) node e + 1.
        let half_bandwidth = models
            .iter()
            .map(|m| {
                let dpn = if m.axial { 3 } else { 2 };
                2 * dpn - 1 + m.n_interior()
            })
            .max()
            .unwrap_or(3);
        let force = models
            .iter()
            .map(|m| vec![V2::zeros(); m.n_el * m.element.quad.ng])
            .collect();
        let pos: Vec<Vec<V2>> = models
            .iter()
            .map(|m| vec![V2::zeros(); m.n_el * m.element.quad.ng])
            .collect();
        let vel = pos.clone();
        let kin_vel = pos.clone();
        let tail = models
            .iter()
            .map(|m| vec![0.0; m.n_el * (m.element.quad.ng + 1)])
            .collect();
        Ok(Chain {
            links: models,
            gravity: gravity.map_or(V2::zeros(), |g| g.vector.into()),
            ndof: next,
            n_interior,
            half_bandwidth,
            frames: vec![FrameState::default(); nl],
            force,
            pos,
            vel,
            kin_vel,
            tail,
            joint_torque: vec![0.0; nl],
            tip_load: 0.0,
            distributed_load: 0.0,
        })
    }

    /// Whether some DOFs carry no mass: the section rotations ψ of a Timoshenko link without
    /// rotary inertia (M is singular there; the stiffness determines them).
    pub fn has_massless_dofs(&self) -> bool {
        self.links
            .iter()
            .any(|l| l.element.kind.independent_rotation() && l.rho_i == 0.0)
    }

    /// Basis of the massless directions (null space of M at a rest state) of the Timoshenko
    /// links without rotary inertia, as sparse vectors (DOF, coefficient):
    /// * every ψ DOF (interior and nodal), except the tip ψ(L) that turns a tip inertia, or a
    ///   child whose joint is prescribed; a tip ψ(L) that carries a child on a free joint turns
    ///   the child like its joint angle θ, so there the direction is e_ψ(L) − e_θ;
    /// * for a free joint without hub inertia: turning the frame by α while v = −αx (and
    ///   ψ(L) = −α, which keeps tip bodies and the child in place) moves no material point at
    ///   v = 0: the frame angle is tied to the mass only through the root section, which has no
    ///   inertia. (Euler–Bernoulli links have no such direction: v′(0) = 0 ties the frame to
    ///   the mass.) Its stiffness is the shear and bending of the root element.
    pub fn massless_directions(&self) -> Vec<Vec<(usize, f64)>> {
        self.massless_directions_with(true)
    }

    /// The directions of [`Chain::massless_directions`] that carry no mass at EVERY q (M N = 0
    /// exactly): the section rotations ψ and the pairs e_ψ(L) − e_θ(child). No material point
    /// depends on ψ (the foreshortening uses the centre-line slope v′) and a child frame only
    /// on ψ(L) + θ(child), so their rows and columns of M vanish identically — a structural
    /// fact of the kinematics, not a numerical zero test. The frame directions (turning the
    /// frame against v = −αx) are left out: they move the points by α·s(x) (the
    /// foreshortening), so they carry the mass ∫ρA s² > 0 away from v = 0.
    pub fn exact_massless_directions(&self) -> Vec<Vec<(usize, f64)>> {
        self.massless_directions_with(false)
    }

    /// The almost massless directions that turn a child link's frame through its parent's tip
    /// section: for a Timoshenko child on a free joint without hub inertia whose parent is a
    /// Timoshenko link without rotary or tip inertia, ψ(L) of the parent by α with the child's
    /// field counter-rotated, v = −αx and every ψ by −α. At v = 0 this moves no material point
    /// (the child frame turns, its centre line and sections stay); otherwise it moves the child's
    /// points by α·s(x) (the foreshortening), a mass ∫ρA s² orders of magnitude below the
    /// link's. Unlike the same turn through the child's joint angle
    /// ([`Chain::massless_directions`]), it leaves θ unchanged, so no joint damper acts on it;
    /// its stiffness is the shear and bending of the parent's tip and the child's root element.
    pub fn child_frame_directions(&self) -> Vec<Vec<(usize, f64)>> {
        let mut dirs = Vec::new();
        for li in 1..self.links.len() {
            let (p, l) = (&self.links[li - 1], &self.links[li]);
            let kind = l.element.kind;
            if !p.element.kind.independent_rotation()
                || p.rho_i > 0.0
                || p.tip_inertia > 0.0
                || l.joint.dof == NONE
                || l.hub_inertia > 0.0
                || !kind.independent_rotation()
            {
                continue;
            }
            let interior = kind.interior();
            let ni = interior.len();
            let mut d = vec![(p.r_dof[p.n_el], 1.0)];
            d.extend(l.counter_rotated_deflections());
            // every section turns back with the field (a rigid counter-rotation has no bubble
            // content)
            for e in 0..l.n_el {
                for (k, idof) in interior.iter().enumerate() {
                    if idof.field == InteriorField::Rotation {
                        d.push((l.int_dof[ni * e + k], -1.0));
                    }
                }
            }
            for k in 1..=l.n_el {
                if l.r_dof[k] != NONE {
                    d.push((l.r_dof[k], -1.0));
                }
            }
            dirs.push(d);
        }
        dirs
    }

    fn massless_directions_with(&self, frames: bool) -> Vec<Vec<(usize, f64)>> {
        let mut dirs = Vec::new();
        for (li, l) in self.links.iter().enumerate() {
            let kind = l.element.kind;
            if !kind.independent_rotation() || l.rho_i > 0.0 {
                continue;
            }
            let interior = kind.interior();
            let ni = interior.len();
            for e in 0..l.n_el {
                for (k, idof) in interior.iter().enumerate() {
                    if idof.field == InteriorField::Rotation {
                        dirs.push(vec![(l.int_dof[ni * e + k], 1.0)]);
                    }
                }
            }
            for k in 1..l.n_el {
                dirs.push(vec![(l.r_dof[k], 1.0)]);
            }
            let tip = l.r_dof[l.n_el];
            if l.tip_inertia == 0.0 {
                match self.links.get(li + 1) {
                    None => dirs.push(vec![(tip, 1.0)]),
                    Some(c) if c.joint.dof != NONE => {
                        dirs.push(vec![(tip, 1.0), (c.joint.dof, -1.0)]);
                    }
                    // A prescribed child joint: ψ(L) turns the child, it carries its mass.
                    Some(_) => {}
                }
            }
            if frames && l.joint.dof != NONE && l.hub_inertia == 0.0 {
                let mut d = vec![(l.joint.dof, 1.0)];
                d.extend(l.counter_rotated_deflections());
                if tip != NONE {
                    d.push((tip, -1.0));
                }
                dirs.push(d);
            }
        }
        dirs
    }

    /// Makes a state consistent in the massless directions (see [`Chain::has_massless_dofs`]):
    /// their equations Nᵀ R = 0 involve no acceleration — they are static balances (e.g. the
    /// tip section of a link carries the next joint's spring moment, the root section the
    /// joint's) that must hold from the start. Solves them by moving along those directions
    /// (Newton, finite-difference Jacobian; once, at the start of a run — the stepper then keeps
    /// them satisfied). Along the frame-rotation directions this shifts a joint angle by the
    /// root shear rotation of the settled state, with the material points held in place.
    /// No-op for chains without massless DOFs.
    pub fn settle_massless(&mut self, t: f64, q: &mut [f64], qd: &[f64]) -> Result<(), FemError> {
        if !self.has_massless_dofs() {
            return Ok(());
        }
        let dirs = self.massless_directions();
        let (n, nb) = (self.ndof, dirs.len());
        let zero = vec![0.0; n];
        let mut r = vec![0.0; n];
        let mut f0 = vec![0.0; nb];
        let mut col = vec![0.0; nb];
        let mut lu = crate::band::DenseLu::new(nb);
        let project = |r: &[f64], out: &mut [f64]| {
            for (k, d) in dirs.iter().enumerate() {
                out[k] = d.iter().map(|&(i, c)| c * r[i]).sum();
            }
        };
        for _ in 0..20 {
            self.residual(t, q, qd, &zero, &mut r);
            project(&r, &mut f0);
            // Forward differences with a step far below the rotations involved (linear at a
            // rest state: the Newton step is then exact to the difference error).
            let eps = 1e-7;
            for k in 0..nb {
                for &(i, c) in &dirs[k] {
                    q[i] += eps * c;
                }
                self.residual(t, q, qd, &zero, &mut r);
                for &(i, c) in &dirs[k] {
                    q[i] -= eps * c;
                }
                project(&r, &mut col);
                for i in 0..nb {
                    col[i] = (col[i] - f0[i]) / eps;
                }
                lu.set_column(k, &col);
            }
            lu.factorize()?;
            let mut dy = f0.clone();
            lu.solve_in_place(&mut dy);
            let mut big = 0.0f64;
            for (k, d) in dirs.iter().enumerate() {
                for &(i, c) in d {
                    q[i] -= dy[k] * c;
                }
                big = big.max(dy[k].abs());
            }
            if !big.is_finite() {
                break;
            }
            // Rotations: 1e-12 rad is far below any discretization error.
            if big <= 1e-12 {
                // Leave the chain's cached point data at the settled state.
                self.residual(t, q, qd, &zero, &mut r);
                return Ok(());
            }
        }
        Err(FemError::Numerical {
            t,
            message: "could not make the massless section rotations (Timoshenko links without \
                      rotary inertia) consistent with the initial state"
                .into(),
        })
    }

    /// A Newton-matrix container with this chain's pattern.
    pub fn new_matrix(&self) -> BorderedBand {
        BorderedBand::new(
            self.n_interior,
            self.ndof - self.n_interior,
            self.half_bandwidth,
        )
    }

    /// Initial state (q, q̇) from the scene: joint angles and rates, elastic fields at rest.
    pub fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        q.iter_mut().for_each(|x| *x = 0.0);
        qd.iter_mut().for_each(|x| *x = 0.0);
        for l in &self.links {
            if l.joint.dof != NONE {
                q[l.joint.dof] = l.joint.initial_angle;
                qd[l.joint.dof] = l.joint.initial_rate;
            }
        }
    }

    #[inline]
    fn val(x: &[f64], i: usize) -> f64 {
        if i == NONE { 0.0 } else { x[i] }
    }

    fn elem_v(x: &[f64], dofs: &[usize; MAXE]) -> [f64; MAXE] {
        let mut d = [0.0; MAXE];
        for (v, &i) in d.iter_mut().zip(dofs) {
            *v = Self::val(x, i);
        }
        d
    }

    /// Human-readable location of a DOF (for diagnostics).
    pub fn describe_dof(&self, dof: usize) -> String {
        for (li, l) in self.links.iter().enumerate() {
            if l.joint.dof == dof {
                return format!("joint {} angle", li + 1);
            }
            for k in 0..=l.n_el {
                let slope = l.element.kind.slope_label();
                for (what, map) in [("v", &l.v_dof), (slope, &l.r_dof), ("u", &l.u_dof)] {
                    if map[k] == dof {
                        return format!(
                            "link {} node {k} (x = {:.4}) {what}",
                            li + 1,
                            k as f64 * l.h
                        );
                    }
                }
            }
        }
        for (li, l) in self.links.iter().enumerate() {
            if let Some(p) = l.int_dof.iter().position(|&d| d == dof) {
                let interior = l.element.kind.interior();
                let (e, k) = (p / interior.len(), p % interior.len());
                let (what, at) = (interior[k].label, interior[k].at);
                return format!(
                    "link {} element {} interior {what} (x = {:.4})",
                    li + 1,
                    e + 1,
                    (e as f64 + at) * l.h
                );
            }
        }
        format!("dof {dof}")
    }

    // ---- Tip kinematics for contact (`crate::events::contact`) ----
}
