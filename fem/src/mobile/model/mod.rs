//! Kinematics, mass matrix and generalized forces of the mobile manipulator with one flexible
//! pitch link, in the speeds ν of the constraint null space (Kane's form of Lagrange's
//! equations: the partial velocities of every mass element project its inertial force).
//!
//! Coordinates q = (x, y, ψ, φ_R, φ_L | θ₁…θ₄ | e), speeds ν = (φ̇_R, φ̇_L | θ̇₁…θ̇₄ | ė) with
//! q̇ = S(q) ν: ẋ = u cos ψ, ẏ = u sin ψ, ψ̇ = r(φ̇_R − φ̇_L)/(2b), u = r(φ̇_R + φ̇_L)/2, the
//! identity elsewhere (the platform block is absent when the scene has no platform). e holds,
//! per node 1…N of the flexible link (node 0 is clamped), (v, v′, w, w′).
//!
//! Frames F0…F5 as in the scene's convention (F0 platform, F1 turret, F2…F4 pitch links, F5
//! gripper). The tip of the flexible link (frame F) sits at o_F + R_F(L, v_N, w_N) with
//! orientation R_F R_z(v′_N) R_y(−w′_N); the next pitch joint rotates that frame about its −y.
//! So the tip DOFs act on everything distal as two prismatic joints (along R_F e_y, R_F e_z)
//! and two revolute ones (about R_F e_z, then the rotated −e_y, through the tip point), while
//! the link's own material points p(x) = o_F + R_F(x, v(x), w(x)) move with the Hermite-cubic
//! shape functions of their element.
//!
//! For a mass element with partial velocities (J_v, J_ω)ᵢ = ∂(v, ω)/∂νᵢ:
//!
//! ```text
//! M̄ = Σ m J_vᵀ J_v + J_ωᵀ R J Rᵀ J_ω + diag(J_side on φ_R, φ_L)
//! M̄ ν̇ + b = Σ J_vᵀ m (a + g e_z) + J_ωᵀ (I α + ω × I ω) + K e
//! ```
//!
//! with the accelerations a, α of the element computed by the recursive kinematics at
//! q̈ = S ν̇ + Ṡ ν; b is the same sum at ν̇ = 0. The beam contributes ∫ μ(…) dx by 4-point Gauss
//! quadrature per element, exact here (the integrands are polynomials of degree ≤ 6 in x).
//! K = ∫ (EI_out N″ᵀN″ on v, EI_in N″ᵀN″ on w) dx, the Euler–Bernoulli strain energy.
//!
//! Layout: this file holds the model's parts; `build` their construction ([`Model::new`]);
//! `kinematics` the recursive frames and partial velocities, `dynamics` M̄ and M̄ν̇ + b,
//! `energies` the energies and constraint checks of a state.

use data::scene::PlatformComposite;
use nalgebra::{Matrix3, Vector3};

use crate::element::quadrature::gauss01;
use crate::element::{Shapes, hermite_cubic};

mod build;
mod dynamics;
mod energies;
mod kinematics;

pub use dynamics::Workspace;

pub type Vec3 = Vector3<f64>;
pub type Mat3 = Matrix3<f64>;

fn rot_z(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
/// Rotation by t about −y (= R_y(−t)): x ↦ (cos t, 0, sin t).
fn rot_pitch(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}

const EY: Vec3 = Vector3::new(0.0, 1.0, 0.0);
const EZ: Vec3 = Vector3::new(0.0, 0.0, 1.0);
const MINUS_EY: Vec3 = Vector3::new(0.0, -1.0, 0.0);

/// Gauss points per element (exact for the mass integrands of degree ≤ 7).
pub const GAUSS: usize = 4;
/// Most partial-velocity columns one mass element can have: 2 platform + 4 joints + 8 beam
/// DOFs of its element (or the 4 tip DOFs).
const MAX_COLS: usize = 14;

/// A rigid body moving with frame `frame`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    pub frame: usize,
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
}

/// The flexible pitch link.
#[derive(Debug, Clone, PartialEq)]
pub struct FlexLink {
    /// Pitch link index 0…2 (scene `link` − 1); its frame is F(2 + link).
    pub link: usize,
    pub frame: usize,
    pub length: f64,
    pub elements: usize,
    /// Element length.
    pub le: f64,
    /// Line density m/L.
    pub mu: f64,
    pub ei_in: f64,
    pub ei_out: f64,
    /// Elastic DOFs 4N.
    pub ne: usize,
    /// Stiffness K (ne × ne, row-major).
    pub stiffness: Vec<f64>,
    /// Shape functions at the Gauss points of an element (the same on every element).
    pub shapes: [Shapes; GAUSS],
    /// Gauss abscissae (fraction of the element) and weights (times le).
    pub gauss_xi: [f64; GAUSS],
    pub gauss_w: [f64; GAUSS],
}

impl FlexLink {
    /// Global elastic index of local element DOF `l` (0..4: node a value/slope, node b
    /// value/slope) of element `el` for field `field` (0 = v, 1 = w); None at the clamp.
    #[inline]
    pub fn dof(el: usize, l: usize, field: usize) -> Option<usize> {
        let node = el + l / 2;
        (node > 0).then(|| 4 * (node - 1) + 2 * field + (l % 2))
    }

    /// v(x) and w(x) (field 0, 1) of element `el` with shape values `n` from the elastic DOFs.
    fn field_at(&self, e: &[f64], el: usize, n: &[f64]) -> [f64; 2] {
        let mut out = [0.0; 2];
        for (f, o) in out.iter_mut().enumerate() {
            for l in 0..4 {
                if let Some(g) = Self::dof(el, l, f) {
                    *o += n[l] * e[g];
                }
            }
        }
        out
    }

    /// (v, v′, w, w′) at the tip.
    pub fn tip(&self, e: &[f64]) -> [f64; 4] {
        let b = self.ne - 4;
        [e[b], e[b + 1], e[b + 2], e[b + 3]]
    }

    fn assemble_stiffness(&mut self) {
        let ne = self.ne;
        self.stiffness = vec![0.0; ne * ne];
        let (xs, ws) = gauss01(GAUSS);
        for el in 0..self.elements {
            for (f, ei) in [(0, self.ei_out), (1, self.ei_in)] {
                for (xi, w) in xs.iter().zip(ws) {
                    let s = hermite_cubic().shapes(*xi, self.le);
                    for a in 0..4 {
                        let Some(ga) = Self::dof(el, a, f) else {
                            continue;
                        };
                        for b in 0..4 {
                            let Some(gb) = Self::dof(el, b, f) else {
                                continue;
                            };
                            self.stiffness[ga * ne + gb] += ei * w * self.le * s.db[a] * s.db[b];
                        }
                    }
                }
            }
        }
    }
}

/// Where each coordinate and speed sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    pub platform: bool,
    /// Index of θ₁ in q and in ν.
    pub q_arm: usize,
    pub nu_arm: usize,
    /// First elastic index in q and in ν.
    pub q_el: usize,
    pub nu_el: usize,
    /// Elastic DOFs.
    pub ne: usize,
    /// Coordinates n and speeds m.
    pub n: usize,
    pub m: usize,
}

/// The model of a `[mobile_manipulator]` scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub layout: Layout,
    pub gravity: f64,
    /// Chassis and wheels composed ([`data::scene::Platform::composite`]).
    pub platform: Option<PlatformComposite>,
    /// Fixed pose (x, y, ψ) of F0 without a platform.
    pub ground_pose: [f64; 3],
    pub mount: Vec3,
    pub base_height: f64,
    pub lengths: [f64; 3],
    /// Rigid bodies: platform (frame 0) if present, turret, the rigid links, the flexible
    /// link's residual inertia (massless), the gripper.
    pub bodies: Vec<Body>,
    pub flex: Option<FlexLink>,
    pub joint_friction: [f64; 4],
}

/// Frames F0…F5 at (q, q̇, q̈) and the axes the coordinates move them about.
#[derive(Debug, Clone, Copy, Default)]
pub struct Frames {
    pub o: [Vec3; 6],
    pub r: [Mat3; 6],
    pub w: [Vec3; 6],
    pub al: [Vec3; 6],
    pub v: [Vec3; 6],
    pub a: [Vec3; 6],
    /// Inertial axis of joint k (k = 1…4) through o\[k\].
    pub axis: [Vec3; 5],
    /// Tip of the flexible link: point, prismatic axes R_F e_y, R_F e_z, revolute axes
    /// R_F e_z (v′_N) and R_F R_z(v′_N)(−e_y) (w′_N).
    pub tip_o: Vec3,
    pub tip_axes: [Vec3; 4],
}

impl Frames {
    /// Inertial position, velocity and acceleration of a point at `d` = (d, ḋ, d̈) (frame-k
    /// components) carried by frame k: p = o + Rd, v = v_o + ω×Rd + Rḋ,
    /// a = a_o + α×Rd + ω×(ω×Rd + 2Rḋ) + Rd̈.
    fn carry(&self, k: usize, d: [Vec3; 3]) -> [Vec3; 3] {
        let r = self.r[k];
        let (dp, dv, da) = (r * d[0], r * d[1], r * d[2]);
        let w = self.w[k];
        [
            self.o[k] + dp,
            self.v[k] + w.cross(&dp) + dv,
            self.a[k] + self.al[k].cross(&dp) + w.cross(&(w.cross(&dp) + (2.0 * dv))) + da,
        ]
    }
}

/// Partial velocities of one mass element: speed index, J_v, J_ω.
#[derive(Debug, Clone, Copy)]
pub struct Partials {
    pub len: usize,
    pub idx: [usize; MAX_COLS],
    pub jv: [Vec3; MAX_COLS],
    pub jw: [Vec3; MAX_COLS],
}

impl Default for Partials {
    fn default() -> Self {
        Partials {
            len: 0,
            idx: [0; MAX_COLS],
            jv: [Vec3::zeros(); MAX_COLS],
            jw: [Vec3::zeros(); MAX_COLS],
        }
    }
}

impl Partials {
    #[inline]
    fn push(&mut self, i: usize, jv: Vec3, jw: Vec3) {
        self.idx[self.len] = i;
        self.jv[self.len] = jv;
        self.jw[self.len] = jw;
        self.len += 1;
    }
}

/// Rotates frame (r, w, al) about its local axis `u` by (t, ṫ, ẗ); returns the inertial axis.
fn revolute(r: &mut Mat3, w: &mut Vec3, al: &mut Vec3, u: Vec3, t: [f64; 3]) -> Vec3 {
    let axis = *r * u;
    *al = *al + (*w).cross(&(t[1] * axis)) + (t[2] * axis);
    *w += t[1] * axis;
    let rot = if u == EZ {
        rot_z(t[0])
    } else {
        rot_pitch(t[0])
    };
    *r *= rot;
    axis
}

/// The link body's inertia about its centre minus the slender rod's diag(0, mL²/12, mL²/12).
pub fn residual_inertia(mass: f64, length: f64, inertia: &Mat3) -> Mat3 {
    let rod = mass * length * length / 12.0;
    let mut j = *inertia;
    j[(1, 1)] -= rod;
    j[(2, 2)] -= rod;
    j
}

/// Smallest eigenvalue of a symmetric 3 × 3 matrix is ≥ −tol (Sylvester on J + tol I would
/// not do for semi-definite; the principal minors of J are checked instead).
fn positive_semidefinite(j: &Mat3, tol: f64) -> bool {
    let d = Vector3::new(j[(0, 0)], j[(1, 1)], j[(2, 2)]);
    let m2 = [
        j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)],
        j[(0, 0)] * j[(2, 2)] - j[(0, 2)] * j[(2, 0)],
        j[(1, 1)] * j[(2, 2)] - j[(1, 2)] * j[(2, 1)],
    ];
    let det = j[(0, 0)] * (j[(1, 1)] * j[(2, 2)] - j[(1, 2)] * j[(2, 1)])
        - j[(0, 1)] * (j[(1, 0)] * j[(2, 2)] - j[(1, 2)] * j[(2, 0)])
        + j[(0, 2)] * (j[(1, 0)] * j[(2, 1)] - j[(1, 1)] * j[(2, 0)]);
    let s = tol * d.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    d.iter().all(|&x| x >= -s) && m2.iter().all(|&x| x >= -s * s) && det >= -s * s * s
}
