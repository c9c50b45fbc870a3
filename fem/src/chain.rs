//! Floating-frame chain: kinematics, residual of Lagrange's equations, Newton matrix, energies.
//!
//! Link i carries a frame (angle φᵢ, origin Rᵢ). A material point at x has local position
//! p(x) = (x + w(x), v(x)) with w = u (axial field), w = s = −½∫₀ˣ v′² (foreshortening) or w = 0,
//! and inertial position r = Rᵢ + A(φᵢ) p. Frames: φ₁ = θ₁, R₁ = 0; φᵢ₊₁ = φᵢ + βᵢ(Lᵢ) + θᵢ₊₁,
//! Rᵢ₊₁ = rᵢ(Lᵢ) (scenes.md joint convention), with β the section angle relative to the frame:
//! v′ for Euler–Bernoulli links, the section rotation ψ for Timoshenko (`shear`) links.
//!
//! Elements: Hermite cubic v (DOFs v, v′ per node), or for `shear` links the Timoshenko element
//! of [`crate::element::timoshenko`]: cubic Lagrange v, quadratic ψ, DOFs (v, ψ) per node plus
//! v(⅓), v(⅔), ψ(½) per element (global, numbered just before the element's end node so the band
//! stays 2·dpn + 2 wide). Its strain energy ½∫EI ψ′² + ½∫κGA(v′ − ψ)² is locking-free (the
//! Kirchhoff subspace is the C¹ cubics) and reduces to the Hermite cubic as κGA → ∞; the
//! foreshortening and membrane strain use the centre-line slope v′ (quartic v′²: integrated
//! exactly). Kelvin–Voigt acts on the curvature (β′) only. Section rotary inertia adds
//! ½∫ρI(φ̇ + β̇)² (angle linear in q: mass only). The "tip slope" column of J that an ancestor
//! link contributes is β(L), so the per-point Jacobian columns (joint, tip slope, tip v, tip u
//! per ancestor) are the same for both element kinds.
//!
//! With T = ½Σ m|ṙ|² (Gauss quadrature of ρA, tip masses, tip and hub inertias) and
//! V = U_elastic + U_joint − Σ m g·r, Lagrange's equations are exactly
//!   R(q, q̇, q̈) = Σ m Jᵀ(r̈ − g) + ∂U/∂q + C q̇ − Q_joint = 0,  J = ∂r/∂q,
//! because d/dt ∂T/∂q̇ − ∂T/∂q = Σ m Jᵀ r̈. The residual is evaluated in O(n) by a forward
//! (kinematic) pass and a backward (force) pass over the chain; the foreshortening part of Jᵀ,
//! ∂s(x)/∂q = −∫₀ˣ v′ N′, is applied through the tail axial load T(ξ) = ∫_ξ^L f_x:
//!   Σ f_x ∂s/∂q = −∫ T v′ N′ dξ  (exact for the quadrature, by exchanging the two sums).
//! The Newton matrix ([`Chain::newton_matrix`]) is exact without foreshortening (checked against
//! finite differences of the residual). With foreshortening it omits the ∂s/∂q couplings, which
//! are dense over a link: O(v′²) between elastic DOFs but O(v′) in the joint rows — harmless for
//! a prescribed hub (spin-up: 2–3 Newton iterations per step), while free chains with
//! foreshortening use an exact finite-difference Jacobian instead (see `integrator`).

use data::scene::{Gravity, Link, PrescribedMotion, TorqueLaw};

use data::FemElement;

use crate::band::BorderedBand;
use crate::element::tables::dotn;
use crate::element::{self, ElementDofs, InteriorField, MeshElement};
use crate::error::FemError;

pub use crate::element::{MAXE, NONE};
/// Longest chain the backend builds (fixed-size per-point column buffers, no allocation).
pub const MAX_LINKS: usize = 6;
/// Ancestor columns of J at most: joint, tip slope, tip v, tip u per link.
const MAX_COLUMNS: usize = 4 * MAX_LINKS;

#[inline]
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}
#[inline]
fn rot(phi: f64, a: [f64; 2]) -> [f64; 2] {
    let (s, c) = phi.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}
#[inline]
fn rot_t(phi: f64, a: [f64; 2]) -> [f64; 2] {
    rot(-phi, a)
}
#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
#[inline]
fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}
#[inline]
fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline]
fn scale(s: f64, a: [f64; 2]) -> [f64; 2] {
    [s * a[0], s * a[1]]
}

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
    pub r: [f64; 2],
    pub dr: [f64; 2],
    pub ddr: [f64; 2],
    /// Joint angle θᵢ and its rates.
    pub theta: f64,
    pub dtheta: f64,
    pub ddtheta: f64,
    /// Tip local position/velocity/acceleration (frame coordinates, relative terms only).
    pub p_tip: [f64; 2],
    pub dp_tip: [f64; 2],
    /// Full inertial acceleration of the tip in frame coordinates.
    pub a_tip: [f64; 2],
    pub slope_tip: f64,
    pub dslope_tip: f64,
    pub ddslope_tip: f64,
    /// Generalized joint moment of the subtree about Rᵢ (inertial + gravity, d'Alembert sign).
    pub subtree_moment: f64,
    /// Subtree resultant force (inertial coordinates, d'Alembert sign).
    pub subtree_force: [f64; 2],
}

/// The assembled chain model with preallocated work buffers.
#[derive(Debug, Clone)]
pub struct Chain {
    pub links: Vec<LinkModel>,
    pub gravity: [f64; 2],
    pub ndof: usize,
    /// Interior/border split for the Newton matrix.
    pub n_interior: usize,
    pub half_bandwidth: usize,
    pub frames: Vec<FrameState>,
    /// Per link, per element, per Gauss point: force density f = m(a − g) (frame coords) and
    /// local position p.
    force: Vec<Vec<[f64; 2]>>,
    pos: Vec<Vec<[f64; 2]>>,
    /// Local velocity ṗ at each Gauss point (for the Coriolis part of the Newton matrix).
    vel: Vec<Vec<[f64; 2]>>,
    /// Per link, per element, per sub-interval: tail axial load T (foreshortening).
    tail: Vec<Vec<f64>>,
    /// Generalized joint torque each joint's actuator needs (prescribed) or applies (free).
    pub joint_torque: Vec<f64>,
    /// Constant transverse loads on the last link, in its frame (the scene's `[statics]` loads
    /// applied as a step at t = 0): tip force P and uniform load q.
    pub tip_load: f64,
    pub distributed_load: f64,
}

/// A column of J contributed by an ancestor (or own joint) DOF, in frame-i coordinates.
#[derive(Debug, Clone, Copy, Default)]
struct AncestorColumn {
    dof: usize,
    /// Rotation about a centre (`vec` = centre, `dvec` = its velocity) or translation along
    /// `vec` (whose frame turns at `rate`).
    rotation: bool,
    vec: [f64; 2],
    dvec: [f64; 2],
    centre_acc: [f64; 2],
    rate: f64,
    rate_dot: f64,
    /// Position along the chain (smaller = closer to the ground).
    pos: f64,
}

/// A column of J evaluated at one mass point.
#[derive(Debug, Clone, Copy, Default)]
struct ColumnAt {
    dof: usize,
    j: [f64; 2],
    jdot: [f64; 2],
    rotation: bool,
    pos: f64,
    centre_acc: [f64; 2],
    /// Angular velocity and acceleration of the frame a translation column is attached to.
    rate: f64,
    rate_dot: f64,
}

/// Which force groups [`Chain::residual_parts`] includes. The energy-consistent integrator
/// needs them apart: the inertial operator alone gives mass products M(q)x = R_in(q, 0, x) and
/// the velocity terms R_in(q, v, 0) = Ṁv − ∂T/∂q; the conservative group is ∇V; the rest is −Q.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parts {
    /// Σ m Jᵀ r̈ (with hub and tip rotary inertias).
    pub inertia: bool,
    /// ∂V/∂q: strain, joint springs, gravity.
    pub conservative: bool,
    /// −Q: applied joint torques and loads, joint dampers, Kelvin–Voigt.
    pub nonconservative: bool,
}

impl Parts {
    pub const ALL: Parts = Parts {
        inertia: true,
        conservative: true,
        nonconservative: true,
    };
    pub const INERTIA: Parts = Parts {
        inertia: true,
        conservative: false,
        nonconservative: false,
    };
    pub const CONSERVATIVE: Parts = Parts {
        inertia: false,
        conservative: true,
        nonconservative: false,
    };
    pub const NONCONSERVATIVE: Parts = Parts {
        inertia: false,
        conservative: false,
        nonconservative: true,
    };
}

/// What the Newton matrix is a derivative of: S = ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q.
#[derive(Debug, Clone, Copy)]
pub struct NewtonCoefficients {
    pub c_a: f64,
    pub c_v: f64,
    pub c_q: f64,
}

impl Chain {
    /// Builds the chain for `links` with `n_el` Hermite-cubic (Timoshenko for `shear` links)
    /// elements per link.
    pub fn new(links: &[Link], gravity: Option<&Gravity>, n_el: usize) -> Result<Self, FemError> {
        Self::with_element(links, gravity, n_el, None)
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
            .map(|m| vec![[0.0; 2]; m.n_el * m.element.quad.ng])
            .collect();
        let pos: Vec<Vec<[f64; 2]>> = models
            .iter()
            .map(|m| vec![[0.0; 2]; m.n_el * m.element.quad.ng])
            .collect();
        let vel = pos.clone();
        let tail = models
            .iter()
            .map(|m| vec![0.0; m.n_el * (m.element.quad.ng + 1)])
            .collect();
        Ok(Chain {
            links: models,
            gravity: gravity.map_or([0.0, 0.0], |g| g.vector),
            ndof: next,
            n_interior,
            half_bandwidth,
            frames: vec![FrameState::default(); nl],
            force,
            pos,
            vel,
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
                for k in 1..=l.n_el {
                    if l.v_dof[k] != NONE {
                        d.push((l.v_dof[k], -(k as f64) * l.h));
                    }
                }
                for e in 0..l.n_el {
                    for (k, idof) in interior.iter().enumerate() {
                        if idof.field == InteriorField::Deflection {
                            d.push((l.int_dof[ni * e + k], -(e as f64 + idof.at) * l.h));
                        }
                    }
                }
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

    /// Forward pass: frame and tip kinematics of every link (no forces).
    fn forward(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], parts: Parts) {
        let g_in = if parts.conservative {
            self.gravity
        } else {
            [0.0; 2]
        };
        let inertia = if parts.inertia { 1.0 } else { 0.0 };
        let mut parent: Option<FrameState> = None;
        for li in 0..self.links.len() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let (th, dth, ddth) = match l.joint.prescribed_at(t) {
                Some(k) => k,
                None => (q[l.joint.dof], qd[l.joint.dof], qdd[l.joint.dof]),
            };
            let mut fr = FrameState {
                theta: th,
                dtheta: dth,
                ddtheta: ddth,
                ..Default::default()
            };
            match parent {
                None => {
                    fr.phi = th;
                    fr.dphi = dth;
                    fr.ddphi = ddth;
                }
                Some(p) => {
                    fr.phi = p.phi + p.slope_tip + th;
                    fr.dphi = p.dphi + p.dslope_tip + dth;
                    fr.ddphi = p.ddphi + p.ddslope_tip + ddth;
                    let pr = add(p.r, rot(p.phi, p.p_tip));
                    let pdr = add(
                        p.dr,
                        rot(p.phi, add(scale(p.dphi, perp(p.p_tip)), p.dp_tip)),
                    );
                    fr.r = pr;
                    fr.dr = pdr;
                    fr.ddr = rot(p.phi, p.a_tip);
                }
            }
            let (phi, w, dw) = (fr.phi, fr.dphi, fr.ddphi);
            let frame_acc = rot_t(phi, fr.ddr);
            let g_loc = rot_t(phi, g_in);
            // Cumulative foreshortening s, ṡ, s̈ along the link.
            let (mut s, mut sd, mut sdd) = (0.0, 0.0, 0.0);
            let fs = l.foreshortening;
            let ne = l.ne;
            for e in 0..l.n_el {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let dd = Self::elem_v(qd, &dofs);
                let ddd = Self::elem_v(qdd, &dofs);
                let (ua, ub) = (l.u_dof[e], l.u_dof[e + 1]);
                let u = [Self::val(q, ua), Self::val(q, ub)];
                let ud = [Self::val(qd, ua), Self::val(qd, ub)];
                let udd = [Self::val(qdd, ua), Self::val(qdd, ub)];
                let xa = e as f64 * l.h;
                for j in 0..tb.ng + 1 {
                    if fs {
                        for k in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][k];
                            let wgt = tb.sub_wh[j][k];
                            let vp = dotn(dn, &d, ne);
                            let vpd = dotn(dn, &dd, ne);
                            let vpdd = dotn(dn, &ddd, ne);
                            s -= 0.5 * wgt * vp * vp;
                            sd -= wgt * vp * vpd;
                            sdd -= wgt * (vpd * vpd + vp * vpdd);
                        }
                    }
                    if j == tb.ng {
                        continue;
                    }
                    let g = j;
                    let n = &tb.n[g];
                    let xi = tb.xi[g];
                    let (ax, axd, axdd) = if l.axial {
                        (
                            (1.0 - xi) * u[0] + xi * u[1],
                            (1.0 - xi) * ud[0] + xi * ud[1],
                            (1.0 - xi) * udd[0] + xi * udd[1],
                        )
                    } else if fs {
                        (s, sd, sdd)
                    } else {
                        (0.0, 0.0, 0.0)
                    };
                    let p = [xa + xi * l.h + ax, dotn(n, &d, ne)];
                    let pd = [axd, dotn(n, &dd, ne)];
                    let pdd = [axdd, dotn(n, &ddd, ne)];
                    let a = add(
                        add(frame_acc, scale(dw, perp(p))),
                        add(scale(-w * w, p), add(scale(2.0 * w, perp(pd)), pdd)),
                    );
                    let m = l.rho_a * tb.wh[g];
                    // Applied uniform transverse load on the last link (frame y), as a density
                    // with the d'Alembert sign: Gauss-4 gives its consistent nodal loads exactly.
                    let q_load = if li + 1 == self.links.len() && parts.nonconservative {
                        self.distributed_load
                    } else {
                        0.0
                    };
                    self.force[li][e * tb.ng + g] = sub(
                        scale(m, sub(scale(inertia, a), g_loc)),
                        [0.0, q_load * tb.wh[g]],
                    );
                    self.pos[li][e * tb.ng + g] = p;
                    self.vel[li][e * tb.ng + g] = pd;
                }
            }
            // Tip.
            let k = l.n_el;
            let (ut, utd, utdd) = if l.axial {
                (
                    Self::val(q, l.u_dof[k]),
                    Self::val(qd, l.u_dof[k]),
                    Self::val(qdd, l.u_dof[k]),
                )
            } else if fs {
                (s, sd, sdd)
            } else {
                (0.0, 0.0, 0.0)
            };
            let p = [l.length + ut, Self::val(q, l.v_dof[k])];
            let pd = [utd, Self::val(qd, l.v_dof[k])];
            let pdd = [utdd, Self::val(qdd, l.v_dof[k])];
            fr.p_tip = p;
            fr.dp_tip = pd;
            fr.a_tip = add(
                add(frame_acc, scale(dw, perp(p))),
                add(scale(-w * w, p), add(scale(2.0 * w, perp(pd)), pdd)),
            );
            fr.slope_tip = Self::val(q, l.r_dof[k]);
            fr.dslope_tip = Self::val(qd, l.r_dof[k]);
            fr.ddslope_tip = Self::val(qdd, l.r_dof[k]);
            self.frames[li] = fr;
            parent = Some(fr);
        }
    }

    /// Residual R(q, q̇, q̈) of the equations of motion at time t (see module docs), written
    /// into `res`; also fills the joint torques.
    pub fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]) {
        self.residual_parts(t, q, qd, qdd, Parts::ALL, res);
    }

    /// The force groups `parts` of the residual (see [`Parts`]); the sum over all groups is
    /// [`Chain::residual`]. Only the full residual updates [`Chain::joint_torque`]; the Newton
    /// matrix reads the point data of the last call, which must therefore be a full residual.
    pub fn residual_parts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        res.iter_mut().for_each(|x| *x = 0.0);
        self.forward(t, q, qd, qdd, parts);
        let g_in = if parts.conservative {
            self.gravity
        } else {
            [0.0; 2]
        };
        let inertia = if parts.inertia { 1.0 } else { 0.0 };
        let (cons, noncons) = (parts.conservative, parts.nonconservative);
        let nl = self.links.len();
        // Child loads passed to the parent: resultant (inertial) and moment about the child root.
        let mut child_f = [0.0; 2];
        let mut child_m = 0.0;
        for li in (0..nl).rev() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let fr = self.frames[li];
            let g_loc = rot_t(fr.phi, g_in);
            let k = l.n_el;
            // Tip body and child loads (frame coordinates).
            let f_tipmass = scale(l.tip_mass, sub(scale(inertia, fr.a_tip), g_loc));
            // An applied tip force enters with the d'Alembert sign (R collects −Q).
            let p_tip = if li + 1 == nl && noncons {
                self.tip_load
            } else {
                0.0
            };
            let f_tip = sub(add(f_tipmass, rot_t(fr.phi, child_f)), [0.0, p_tip]);
            let m_tip = inertia * l.tip_inertia * (fr.ddphi + fr.ddslope_tip) + child_m;
            let mut add_res = |i: usize, v: f64| {
                if i != NONE {
                    res[i] += v;
                }
            };
            add_res(l.v_dof[k], f_tip[1]);
            add_res(l.u_dof[k], f_tip[0]);
            add_res(l.r_dof[k], m_tip);
            // Distributed inertia/gravity, elastic and damping forces, element by element
            // (tip to root so the tail load T accumulates).
            let mut f_sum = [0.0; 2];
            let mut m_sum = 0.0;
            let mut tail = f_tip[0];
            let ne = l.ne;
            for e in (0..l.n_el).rev() {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let mut fe = [0.0; MAXE];
                let (mut fu0, mut fu1) = (0.0, 0.0);
                for g in 0..tb.ng {
                    let f = self.force[li][e * tb.ng + g];
                    let p = self.pos[li][e * tb.ng + g];
                    f_sum = add(f_sum, f);
                    m_sum += cross(p, f);
                    for a in 0..ne {
                        fe[a] += f[1] * tb.n[g][a];
                    }
                    if l.axial {
                        let xi = tb.xi[g];
                        fu0 += f[0] * (1.0 - xi);
                        fu1 += f[0] * xi;
                    }
                }
                // Section rotary inertia: moment density ρI(φ̈ + β̈) on the section angle
                // φ + β(x) (β = v′ or ψ), which every upstream rotation turns by one.
                if l.rho_i > 0.0 && parts.inertia {
                    let ddd = Self::elem_v(qdd, &dofs);
                    for g in 0..tb.ng {
                        let b = &tb.b[g];
                        let mr = l.rho_i * tb.wh[g] * (fr.ddphi + dotn(b, &ddd, ne));
                        m_sum += mr;
                        for a in 0..ne {
                            fe[a] += mr * b[a];
                        }
                    }
                }
                if l.foreshortening {
                    for j in (0..tb.ng + 1).rev() {
                        self.tail[li][e * (tb.ng + 1) + j] = tail;
                        for kk in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][kk];
                            let vp = dotn(dn, &d, ne);
                            let c = -tail * tb.sub_wh[j][kk] * vp;
                            for a in 0..ne {
                                fe[a] += c * dn[a];
                            }
                        }
                        if j > 0 {
                            tail += self.force[li][e * tb.ng + j - 1][0];
                        }
                    }
                }
                // Elastic forces.
                if cons {
                    let u = [Self::val(q, l.u_dof[e]), Self::val(q, l.u_dof[e + 1])];
                    let mut fu = [fu0, fu1];
                    l.element
                        .kind
                        .internal_force(&l.element, u, &d, &mut fu, &mut fe);
                    [fu0, fu1] = fu;
                }
                if l.kelvin_voigt > 0.0 && noncons {
                    let dd = Self::elem_v(qd, &dofs);
                    let c = l.kelvin_voigt / l.ei;
                    for a in 0..ne {
                        fe[a] += c * dotn(&l.element.kb[a], &dd, ne);
                    }
                }
                for a in 0..ne {
                    if dofs[a] != NONE {
                        res[dofs[a]] += fe[a];
                    }
                }
                if l.axial {
                    if l.u_dof[e] != NONE {
                        res[l.u_dof[e]] += fu0;
                    }
                    if l.u_dof[e + 1] != NONE {
                        res[l.u_dof[e + 1]] += fu1;
                    }
                }
            }
            // Subtree resultant and moment about this link's root Rᵢ.
            let f_total_loc = add(f_sum, f_tip);
            let moment =
                m_sum + cross(fr.p_tip, f_tip) + m_tip + inertia * l.hub_inertia * fr.ddphi;
            let fr_mut = &mut self.frames[li];
            fr_mut.subtree_moment = moment;
            fr_mut.subtree_force = rot(fr.phi, f_total_loc);
            child_f = fr_mut.subtree_force;
            child_m = moment;
            // Joint equation: moment + spring + damper − applied = actuator torque.
            let j = &l.joint;
            let spring = if cons {
                j.stiffness * (fr.theta - j.set_point)
            } else {
                0.0
            };
            let (damper, law) = if noncons {
                (j.damping * fr.dtheta, j.applied(t))
            } else {
                (0.0, 0.0)
            };
            if j.dof != NONE {
                res[j.dof] += moment + spring + damper - law;
            }
            if parts == Parts::ALL {
                self.joint_torque[li] = if j.dof != NONE {
                    law
                } else {
                    moment + spring + damper - law
                };
            }
        }
    }

    /// Assembles the Newton matrix c_a·M + c_v·C + c_q·K at the state of the last
    /// [`Chain::residual`] call (which must precede it).
    pub fn newton_matrix(&self, q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        s.clear();
        let nl = self.links.len();
        let g_in = self.gravity;
        // Columns of J for the DOFs of ancestors (and the own joint), in frame-i coordinates.
        // Fixed-size buffer: no heap allocation per Newton matrix.
        let mut cols = [AncestorColumn::default(); MAX_COLUMNS];
        // Per-point column buffer, reused (filled up to the point's column count).
        let mut jc = [ColumnAt::default(); MAXE + 2 + MAX_COLUMNS];
        for li in 0..nl {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let fr = self.frames[li];
            let g_loc = rot_t(fr.phi, g_in);
            let mut ncols = 0usize;
            // Frame-coordinate position, velocity and acceleration of a point Rc relative to Rᵢ.
            let rel = |o: &FrameState| {
                let c = rot_t(fr.phi, sub(o.r, fr.r));
                let cdot = add(scale(-fr.dphi, perp(c)), rot_t(fr.phi, sub(o.dr, fr.dr)));
                let acc = rot_t(fr.phi, o.ddr);
                (c, cdot, acc)
            };
            for (aj, al) in self.links.iter().enumerate().take(li + 1) {
                let fa = &self.frames[aj];
                if al.joint.dof != NONE {
                    let (c, cdot, acc) = rel(fa);
                    cols[ncols] = AncestorColumn {
                        dof: al.joint.dof,
                        rotation: true,
                        vec: c,
                        dvec: cdot,
                        centre_acc: acc,
                        rate: 0.0,
                        rate_dot: 0.0,
                        pos: 2.0 * aj as f64,
                    };
                    ncols += 1;
                }
                if aj < li {
                    let child = &self.frames[aj + 1];
                    let (c, cdot, acc) = rel(child);
                    if al.r_dof[al.n_el] != NONE {
                        cols[ncols] = AncestorColumn {
                            dof: al.r_dof[al.n_el],
                            rotation: true,
                            vec: c,
                            dvec: cdot,
                            centre_acc: acc,
                            rate: 0.0,
                            rate_dot: 0.0,
                            pos: 2.0 * aj as f64 + 1.0,
                        };
                        ncols += 1;
                    }
                    for (dof, e) in [
                        (al.v_dof[al.n_el], [0.0, 1.0]),
                        (al.u_dof[al.n_el], [1.0, 0.0]),
                    ] {
                        if dof != NONE {
                            cols[ncols] = AncestorColumn {
                                dof,
                                rotation: false,
                                vec: rot_t(fr.phi, rot(fa.phi, e)),
                                dvec: [0.0; 2],
                                centre_acc: [0.0; 2],
                                rate: fa.dphi,
                                rate_dot: fa.ddphi,
                                pos: 2.0 * aj as f64 + 0.5,
                            };
                            ncols += 1;
                        }
                    }
                }
            }
            let w = fr.dphi;
            let wd = fr.ddphi;
            let local_pos = 2.0 * li as f64 + 0.5;
            // One mass point: m at local position p with velocity ṗ and d'Alembert density
            // f = m(a − g). Adds c_a·M + c_v·C + c_q·K_inertial for all its columns, with
            // C = Σ m Jᵀ 2J̇ and K_inertial = Σ m[(∂J/∂q)ᵀ(a − g) + Jᵀ ∂a/∂q].
            let point = |s: &mut BorderedBand,
                         jc: &mut [ColumnAt; MAXE + 2 + MAX_COLUMNS],
                         m: f64,
                         p: [f64; 2],
                         pd: [f64; 2],
                         f: [f64; 2],
                         local: &[(usize, [f64; 2])]| {
                let mut nj = 0;
                for &(dof, v) in local {
                    if dof != NONE {
                        jc[nj] = ColumnAt {
                            dof,
                            j: v,
                            jdot: scale(w, perp(v)),
                            rotation: false,
                            pos: local_pos,
                            centre_acc: [0.0; 2],
                            rate: w,
                            rate_dot: wd,
                        };
                        nj += 1;
                    }
                }
                for col in &cols[..ncols] {
                    jc[nj] = if col.rotation {
                        let j = perp(sub(p, col.vec));
                        ColumnAt {
                            dof: col.dof,
                            j,
                            jdot: add(scale(w, perp(j)), perp(sub(pd, col.dvec))),
                            rotation: true,
                            pos: col.pos,
                            centre_acc: col.centre_acc,
                            rate: 0.0,
                            rate_dot: 0.0,
                        }
                    } else {
                        ColumnAt {
                            dof: col.dof,
                            j: col.vec,
                            jdot: scale(col.rate, perp(col.vec)),
                            rotation: false,
                            pos: col.pos,
                            centre_acc: [0.0; 2],
                            rate: col.rate,
                            rate_dot: col.rate_dot,
                        }
                    };
                    nj += 1;
                }
                let acc = add(scale(1.0 / m, f), g_loc);
                for a in 0..nj {
                    let ca = &jc[a];
                    for b in 0..nj {
                        let cb = &jc[b];
                        let mut v = c.c_a * m * dot(ca.j, cb.j);
                        v += c.c_v * 2.0 * m * dot(ca.j, cb.jdot);
                        // ∂J_a/∂q_b: a rotation b upstream of a's attachment rotates J_a; for a
                        // rotation a, anything downstream moves the point about a's centre.
                        let dja = if cb.rotation && cb.pos <= ca.pos {
                            perp(ca.j)
                        } else if ca.rotation {
                            perp(cb.j)
                        } else {
                            [0.0; 2]
                        };
                        // ∂a/∂q_b: rigid rotation of the downstream acceleration field about the
                        // centre, or the frame's rigid acceleration field at a displaced point.
                        let dacc = if cb.rotation {
                            perp(sub(acc, cb.centre_acc))
                        } else {
                            add(
                                scale(-cb.rate * cb.rate, cb.j),
                                scale(cb.rate_dot, perp(cb.j)),
                            )
                        };
                        v += c.c_q * m * (dot(dja, sub(acc, g_loc)) + dot(ca.j, dacc));
                        if v != 0.0 {
                            s.add(ca.dof, cb.dof, v);
                        }
                    }
                }
            };
            // Rotation columns (upstream joints and tip slopes): they turn every section of
            // this link by one.
            let mut rot_dofs = [NONE; MAX_COLUMNS + 1];
            let mut nr = 0;
            for col in &cols[..ncols] {
                if col.rotation {
                    rot_dofs[nr] = col.dof;
                    nr += 1;
                }
            }
            let ne = l.ne;
            for e in 0..l.n_el {
                let dofs = l.elem_dofs(e);
                for g in 0..tb.ng {
                    let m = l.rho_a * tb.wh[g];
                    let p = self.pos[li][e * tb.ng + g];
                    let xi = tb.xi[g];
                    let n = tb.n[g];
                    // Translation columns of the point: the v shapes (the ψ DOFs of a
                    // Timoshenko element do not move it), then u.
                    let mut local = [(NONE, [0.0; 2]); MAXE + 2];
                    let mut nloc = 0;
                    for a in 0..ne {
                        if !l.element.kind.translates(a) {
                            continue;
                        }
                        local[nloc] = (dofs[a], [0.0, n[a]]);
                        nloc += 1;
                    }
                    local[nloc] = (l.u_dof[e], [1.0 - xi, 0.0]);
                    local[nloc + 1] = (l.u_dof[e + 1], [xi, 0.0]);
                    nloc += 2;
                    let pd = self.vel[li][e * tb.ng + g];
                    let f = self.force[li][e * tb.ng + g];
                    point(s, &mut jc, m, p, pd, f, &local[..nloc]);
                }
                // Section rotary inertia: the section angle is linear in q (J constant), so
                // only the mass term c_a ρI w JᵀJ.
                if l.rho_i > 0.0 && c.c_a != 0.0 {
                    for g in 0..tb.ng {
                        let mw = c.c_a * l.rho_i * tb.wh[g];
                        let b = &tb.b[g];
                        let mut jr = [(NONE, 0.0); MAX_COLUMNS + 1 + MAXE];
                        let mut nj = 0;
                        for &dof in &rot_dofs[..nr] {
                            jr[nj] = (dof, 1.0);
                            nj += 1;
                        }
                        for a in 0..ne {
                            if dofs[a] != NONE && b[a] != 0.0 {
                                jr[nj] = (dofs[a], b[a]);
                                nj += 1;
                            }
                        }
                        for &(da, va) in &jr[..nj] {
                            for &(db, vb) in &jr[..nj] {
                                s.add(da, db, mw * va * vb);
                            }
                        }
                    }
                }
                // Elastic tangent, Kelvin–Voigt, foreshortening geometric stiffness.
                {
                    let d = Self::elem_v(q, &dofs);
                    let u = [Self::val(q, l.u_dof[e]), Self::val(q, l.u_dof[e + 1])];
                    let edofs = ElementDofs {
                        u: [l.u_dof[e], l.u_dof[e + 1]],
                        d: dofs,
                    };
                    l.element
                        .kind
                        .tangent(&l.element, &edofs, u, &d, c.c_q, &mut |i, j, v| {
                            s.add(i, j, v)
                        });
                }
                if l.kelvin_voigt > 0.0 {
                    let cf = l.kelvin_voigt / l.ei;
                    for a in 0..ne {
                        for b in 0..ne {
                            if dofs[a] != NONE && dofs[b] != NONE {
                                s.add(dofs[a], dofs[b], c.c_v * cf * l.element.kb[a][b]);
                            }
                        }
                    }
                }
                if l.foreshortening {
                    let mut kg = [[0.0; MAXE]; MAXE];
                    for j in 0..tb.ng + 1 {
                        let tl = self.tail[li][e * (tb.ng + 1) + j];
                        for kk in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][kk];
                            let wgt = -tl * tb.sub_wh[j][kk];
                            for a in 0..ne {
                                for b in 0..ne {
                                    kg[a][b] += wgt * dn[a] * dn[b];
                                }
                            }
                        }
                    }
                    for a in 0..ne {
                        for b in 0..ne {
                            if dofs[a] != NONE && dofs[b] != NONE {
                                s.add(dofs[a], dofs[b], c.c_q * kg[a][b]);
                            }
                        }
                    }
                }
            }
            // Tip mass.
            let k = l.n_el;
            if l.tip_mass > 0.0 {
                let local = [(l.v_dof[k], [0.0, 1.0]), (l.u_dof[k], [1.0, 0.0])];
                let f = scale(l.tip_mass, sub(fr.a_tip, g_loc));
                point(s, &mut jc, l.tip_mass, fr.p_tip, fr.dp_tip, f, &local);
            }
            // Rotational inertias: tip (rotates with φᵢ + slope(L)) and hub (with φᵢ).
            if l.hub_inertia > 0.0 {
                for a in 0..nr {
                    for b in 0..nr {
                        s.add(rot_dofs[a], rot_dofs[b], c.c_a * l.hub_inertia);
                    }
                }
            }
            if l.tip_inertia > 0.0 {
                if l.r_dof[k] != NONE {
                    rot_dofs[nr] = l.r_dof[k];
                    nr += 1;
                }
                for a in 0..nr {
                    for b in 0..nr {
                        s.add(rot_dofs[a], rot_dofs[b], c.c_a * l.tip_inertia);
                    }
                }
            }
            // Joint spring and damper.
            if l.joint.dof != NONE {
                let jd = l.joint.dof;
                s.add(jd, jd, c.c_q * l.joint.stiffness + c.c_v * l.joint.damping);
            }
        }
    }

    /// Stored energies at a state: (kinetic, strain, joint_spring, gravity).
    pub fn energies(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        debug_assert_eq!(qd.len(), q.len());
        let g_in = self.gravity;
        let mut parent: Option<(FrameState, [f64; 2], [f64; 2])> = None;
        let (mut kin, mut strain, mut spring, mut grav) = (0.0, 0.0, 0.0, 0.0);
        for li in 0..self.links.len() {
            let l = &self.links[li];
            let tb = &l.element.quad;
            let (th, dth) = match l.joint.prescribed_at(t) {
                Some((a, b, _)) => (a, b),
                None => (q[l.joint.dof], qd[l.joint.dof]),
            };
            let (phi, w, r0, dr0) = match parent {
                None => (th, dth, [0.0, 0.0], [0.0, 0.0]),
                Some((p, r, dr)) => (p.phi + p.slope_tip + th, p.dphi + p.dslope_tip + dth, r, dr),
            };
            spring += 0.5 * l.joint.stiffness * (th - l.joint.set_point).powi(2);
            kin += 0.5 * l.hub_inertia * w * w;
            let (mut s, mut sd) = (0.0, 0.0);
            let ne = l.ne;
            for e in 0..l.n_el {
                let dofs = l.elem_dofs(e);
                let d = Self::elem_v(q, &dofs);
                let dd = Self::elem_v(qd, &dofs);
                let u = [Self::val(q, l.u_dof[e]), Self::val(q, l.u_dof[e + 1])];
                let ud = [Self::val(qd, l.u_dof[e]), Self::val(qd, l.u_dof[e + 1])];
                let xa = e as f64 * l.h;
                for j in 0..tb.ng + 1 {
                    if l.foreshortening {
                        for k in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][k];
                            let wgt = tb.sub_wh[j][k];
                            let vp = dotn(dn, &d, ne);
                            s -= 0.5 * wgt * vp * vp;
                            sd -= wgt * vp * dotn(dn, &dd, ne);
                        }
                    }
                    if j == tb.ng {
                        continue;
                    }
                    let xi = tb.xi[j];
                    let (ax, axd) = if l.axial {
                        (
                            (1.0 - xi) * u[0] + xi * u[1],
                            (1.0 - xi) * ud[0] + xi * ud[1],
                        )
                    } else if l.foreshortening {
                        (s, sd)
                    } else {
                        (0.0, 0.0)
                    };
                    let p = [xa + xi * l.h + ax, dotn(&tb.n[j], &d, ne)];
                    let pd = [axd, dotn(&tb.n[j], &dd, ne)];
                    let v = add(dr0, rot(phi, add(scale(w, perp(p)), pd)));
                    let m = l.rho_a * tb.wh[j];
                    kin += 0.5 * m * dot(v, v);
                    grav -= m * dot(g_in, add(r0, rot(phi, p)));
                    if l.rho_i > 0.0 {
                        // ½ρI(φ̇ + β̇)², β the section angle relative to the frame.
                        let om = w + dotn(&tb.b[j], &dd, ne);
                        kin += 0.5 * l.rho_i * tb.wh[j] * om * om;
                    }
                }
                l.element
                    .kind
                    .add_strain_energy(&l.element, u, &d, &mut strain);
            }
            let k = l.n_el;
            let (ut, utd) = if l.axial {
                (Self::val(q, l.u_dof[k]), Self::val(qd, l.u_dof[k]))
            } else if l.foreshortening {
                (s, sd)
            } else {
                (0.0, 0.0)
            };
            let p = [l.length + ut, Self::val(q, l.v_dof[k])];
            let pd = [utd, Self::val(qd, l.v_dof[k])];
            let v_tip = add(dr0, rot(phi, add(scale(w, perp(p)), pd)));
            let r_tip = add(r0, rot(phi, p));
            kin += 0.5 * l.tip_mass * dot(v_tip, v_tip);
            grav -= l.tip_mass * dot(g_in, r_tip);
            let slope = Self::val(q, l.r_dof[k]);
            let dslope = Self::val(qd, l.r_dof[k]);
            kin += 0.5 * l.tip_inertia * (w + dslope).powi(2);
            let fs = FrameState {
                phi,
                dphi: w,
                slope_tip: slope,
                dslope_tip: dslope,
                ..Default::default()
            };
            parent = Some((fs, r_tip, v_tip));
        }
        [kin, strain, spring, grav]
    }

    /// Power of the applied transverse loads, Qᵀq̇ (constant loads: exact work over a
    /// trapezoidal step when q̇ is the step's mean velocity).
    pub fn load_power(&self, qd: &[f64]) -> f64 {
        let Some(l) = self.links.last() else {
            return 0.0;
        };
        let mut p = self.tip_load * Self::val(qd, l.v_dof[l.n_el]);
        if self.distributed_load != 0.0 {
            let q0 = self.distributed_load;
            let fq = l.element.kind.consistent_load(&l.element, q0);
            for e in 0..l.n_el {
                let dd = Self::elem_v(qd, &l.elem_dofs(e));
                p += dotn(&fq, &dd, l.ne);
            }
        }
        p
    }

    /// Dissipated powers at a state: (joint dampers, Kelvin–Voigt).
    pub fn dissipation_power(&self, t: f64, qd: &[f64]) -> (f64, f64) {
        let (mut pj, mut pkv) = (0.0, 0.0);
        for l in &self.links {
            let dth = match l.joint.prescribed_at(t) {
                Some((_, r, _)) => r,
                None => qd[l.joint.dof],
            };
            pj += l.joint.damping * dth * dth;
            if l.kelvin_voigt > 0.0 {
                let c = l.kelvin_voigt / l.ei;
                for e in 0..l.n_el {
                    let dd = Self::elem_v(qd, &l.elem_dofs(e));
                    for a in 0..l.ne {
                        pkv += c * dd[a] * dotn(&l.element.kb[a], &dd, l.ne);
                    }
                }
            }
        }
        (pj, pkv)
    }

    /// Joint angle and rate of link `li` at a state.
    pub fn joint_state(&self, li: usize, t: f64, q: &[f64], qd: &[f64]) -> (f64, f64) {
        let j = &self.links[li].joint;
        match j.prescribed_at(t) {
            Some((a, r, _)) => (a, r),
            None => (q[j.dof], qd[j.dof]),
        }
    }

    /// Inertial tip position of every link at a state (forward pass with zero rates).
    pub fn tip_positions(&self, t: f64, q: &[f64], out: &mut [[f64; 2]]) {
        let mut parent: Option<(f64, [f64; 2])> = None;
        for (li, l) in self.links.iter().enumerate() {
            let th = match l.joint.prescribed_at(t) {
                Some((a, _, _)) => a,
                None => q[l.joint.dof],
            };
            let (phi, r0) = match parent {
                None => (th, [0.0, 0.0]),
                Some((pp, r)) => (pp + th, r),
            };
            let k = l.n_el;
            let ax = if l.axial {
                Self::val(q, l.u_dof[k])
            } else if l.foreshortening {
                self.foreshortening_at_tip(li, q)
            } else {
                0.0
            };
            let p = [l.length + ax, Self::val(q, l.v_dof[k])];
            let r = add(r0, rot(phi, p));
            out[li] = r;
            parent = Some((phi + Self::val(q, l.r_dof[k]), r));
        }
    }

    /// s(L) = −½∫v′² of link `li`.
    pub fn foreshortening_at_tip(&self, li: usize, q: &[f64]) -> f64 {
        let l = &self.links[li];
        let tb = &l.element.quad;
        let mut s = 0.0;
        for e in 0..l.n_el {
            let d = Self::elem_v(q, &l.elem_dofs(e));
            for j in 0..tb.ng + 1 {
                for k in 0..tb.nsg {
                    let vp = dotn(&tb.sub_dn[j][k], &d, l.ne);
                    s -= 0.5 * tb.sub_wh[j][k] * vp * vp;
                }
            }
        }
        s
    }

    /// Transverse deflection v(x) of link `li` (Hermite interpolation).
    pub fn deflection(&self, li: usize, q: &[f64], x: f64) -> f64 {
        let l = &self.links[li];
        let e = ((x / l.h).floor() as usize).min(l.n_el - 1);
        let xi = ((x - e as f64 * l.h) / l.h).clamp(0.0, 1.0);
        let d = Self::elem_v(q, &l.elem_dofs(e));
        dotn(&l.shapes_at(xi).0, &d, l.ne)
    }

    /// Axial tip displacement u(L) of link `li` (extensible links).
    pub fn tip_axial(&self, li: usize, q: &[f64]) -> f64 {
        let l = &self.links[li];
        Self::val(q, l.u_dof[l.n_el])
    }

    /// Transverse tip deflection v(L) of link `li`.
    pub fn tip_deflection(&self, li: usize, q: &[f64]) -> f64 {
        let l = &self.links[li];
        Self::val(q, l.v_dof[l.n_el])
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

    // ---- Tip kinematics for contact ([`crate::contact`]) ----

    /// Inertial position of the tip of link `li` and its Jacobian J = ∂r_tip/∂q, written as two
    /// rows (x: `jac[..n]`, y: `jac[n..2n]`, n = [`Chain::ndof`]). Exact, from the chain's own
    /// frame recursion (the same one [`Chain::tip_positions`] evaluates): every DOF either turns
    /// the frames downstream of it about a frame origin Rₖ — the joint angle θₖ about Rₖ and the
    /// tip rotation of link k about Rₖ₊₁, column ẑ × (r − R) — or moves the tip of link k in
    /// its own frame: v(L) along A(φₖ)ŷ, u(L) along A(φₖ)x̂ and, with foreshortening, every
    /// transverse DOF d along A(φₖ)x̂ with ∂s(L)/∂d = −∫ v′ N′ (the quadrature of s). O(n).
    pub fn tip_jacobian(&self, t: f64, li: usize, q: &[f64], jac: &mut [f64]) -> [f64; 2] {
        let n = self.ndof;
        jac[..2 * n].iter_mut().for_each(|x| *x = 0.0);
        let mut origin = [[0.0; 2]; MAX_LINKS];
        let mut angle = [0.0; MAX_LINKS];
        let mut parent: Option<(f64, [f64; 2])> = None;
        let mut r = [0.0; 2];
        for k in 0..=li {
            let l = &self.links[k];
            let th = match l.joint.prescribed_at(t) {
                Some((a, _, _)) => a,
                None => q[l.joint.dof],
            };
            let (phi, r0) = match parent {
                None => (th, [0.0, 0.0]),
                Some((pp, rr)) => (pp + th, rr),
            };
            let m = l.n_el;
            let ax = if l.axial {
                Self::val(q, l.u_dof[m])
            } else if l.foreshortening {
                self.foreshortening_at_tip(k, q)
            } else {
                0.0
            };
            r = add(r0, rot(phi, [l.length + ax, Self::val(q, l.v_dof[m])]));
            origin[k] = r0;
            angle[k] = phi;
            parent = Some((phi + Self::val(q, l.r_dof[m]), r));
        }
        let put = |jac: &mut [f64], dof: usize, c: [f64; 2]| {
            if dof != NONE {
                jac[dof] += c[0];
                jac[n + dof] += c[1];
            }
        };
        for k in 0..=li {
            let l = &self.links[k];
            let m = l.n_el;
            put(jac, l.joint.dof, perp(sub(r, origin[k])));
            if k < li {
                put(jac, l.r_dof[m], perp(sub(r, origin[k + 1])));
            }
            put(jac, l.v_dof[m], rot(angle[k], [0.0, 1.0]));
            let ex = rot(angle[k], [1.0, 0.0]);
            if l.axial {
                put(jac, l.u_dof[m], ex);
            } else if l.foreshortening {
                let tb = &l.element.quad;
                for e in 0..l.n_el {
                    let dofs = l.elem_dofs(e);
                    let d = Self::elem_v(q, &dofs);
                    let ne = l.ne;
                    let mut ds = [0.0; MAXE];
                    for j in 0..tb.ng + 1 {
                        for kk in 0..tb.nsg {
                            let dn = &tb.sub_dn[j][kk];
                            let c = -tb.sub_wh[j][kk] * dotn(dn, &d, ne);
                            for a in 0..ne {
                                ds[a] += c * dn[a];
                            }
                        }
                    }
                    for a in 0..ne {
                        put(jac, dofs[a], scale(ds[a], ex));
                    }
                }
            }
        }
        r
    }

    /// Tip of link `li`: inertial position, velocity and acceleration at (q, q̇, q̈) from the
    /// forward kinematic pass of the residual (exact for every element the pass handles). With
    /// q̈ = 0 the acceleration is the convective term J̇q̇. Overwrites the point data of the
    /// last residual call (call [`Chain::residual`] again before [`Chain::newton_matrix`]).
    pub fn tip_motion(
        &mut self,
        t: f64,
        li: usize,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> [[f64; 2]; 3] {
        self.forward(t, q, qd, qdd, Parts::INERTIA);
        let fr = self.frames[li];
        let r = add(fr.r, rot(fr.phi, fr.p_tip));
        let v = add(
            fr.dr,
            rot(fr.phi, add(scale(fr.dphi, perp(fr.p_tip)), fr.dp_tip)),
        );
        [r, v, rot(fr.phi, fr.a_tip)]
    }
}
