//! Kinematics and Kane's (null-space Lagrange) equations of the mobile manipulator with one
//! assumed-mode pitch link.
//!
//! Coordinates q = (x, y, ψ, φ_R, φ_L | θ₁…θ₄ | b₁…b_N, c₁…c_N) (each part only when present),
//! speeds ν = (φ̇_R, φ̇_L | θ̇₁…θ̇₄ | ḃ, ċ) and q̇ = S(q) ν: the platform rows of S are the
//! rolling/no-slip map u = r(φ̇_R + φ̇_L)/2, ψ̇ = r(φ̇_R − φ̇_L)/(2b), ẋ = u cos ψ, ẏ = u sin ψ;
//! every other row is the identity.
//!
//! The flexible link (frame F) has v(x) = Σ φₖ(x) bₖ (out of plane, along F's y) and
//! w(x) = Σ φₖ(x) cₖ (in plane, along F's z). Its material point and the tip frame are
//!
//! ```text
//! p(x) = o_F + R_F (x, v, w),   ṗ = v_F + ω_F × R_F r + R_F ṙ,
//! p̈ = a_F + α_F × R_F r + ω_F × (ω_F × R_F r) + 2 ω_F × R_F ṙ + R_F r̈,
//! R_tip = R_F R_z(v′(L)) R_y(−w′(L))
//! ```
//!
//! so the tip rotation acts like two revolute joints at the tip point (axis R_F e_z turned by
//! s = v′(L), then R_F R_z(s)(−e_y) turned by c = w′(L)); the next pitch joint sits on it.
//!
//! The equations are Kane's: with the partial velocities (vᵢ, ωᵢ) of every body and material
//! point (the velocities for ν = eᵢ, exact because velocities are linear in ν),
//!
//! ```text
//! M_r(q) ν̇ + Σ vᵢ·m (a₀ + g e_z) + ωᵢ·(I α₀ + ω × I ω) + ∫ vᵢ·μ (a₀ + g e_z) dx = Q_r
//! M_r[i][j] = Σ m vᵢ·vⱼ + ωᵢ·I ωⱼ + ∫ μ vᵢ·vⱼ dx (+ J_side on the wheel speeds)
//! ```
//!
//! where a₀, α₀ are the accelerations at ν̇ = 0 (q̈ = Ṡ ν) and Q_r = τ − D ν on the wheel and
//! joint speeds and −K (b, c) on the elastic speeds, K = ∫ EI φ″φ″ᵀ dx per direction. This is
//! Sᵀ(M q̈ + h − Q) = 0, the null-space form of Lagrange's equations with the nonholonomic
//! constraints (A S = 0), and it conserves E = T + V_g + U up to the friction and input work.
//! The beam integrals use Gauss quadrature exact for the polynomial basis (N + 4 points for
//! degree-(N + 1) shapes); the eigenfunction basis gets the composite rule of
//! [`Quadrature::for_wavenumber`].

use data::scene::{MobileManipulator, Platform, PlatformComposite, RigidBody};
use nalgebra::{Matrix3, Vector3};

use crate::basis::ShapeSet;
use crate::basis::quadrature::Quadrature;
use crate::error::ModalError;
use crate::linalg::dot;

pub type Vec3 = Vector3<f64>;
pub type Mat3 = Matrix3<f64>;

fn rot_z(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
/// Rotation by θ about −y (R_y(−θ)): x ↦ (cos θ, 0, sin θ).
fn rot_pitch(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    Matrix3::new(c, 0.0, -s, 0.0, 1.0, 0.0, s, 0.0, c)
}

const EZ: Vec3 = Vector3::new(0.0, 0.0, 1.0);
const MINUS_EY: Vec3 = Vector3::new(0.0, -1.0, 0.0);

/// Where each part of q and ν starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Index of x in q (speeds: φ̇_R at 0) when there is a platform.
    pub platform: Option<usize>,
    /// Index of θ₁ in q when there is an arm.
    pub arm: Option<usize>,
    /// Index of b₁ in q when a link is flexible (then c₁ at + modes).
    pub elastic: Option<usize>,
    /// Assumed modes per direction (0 without a flexible link).
    pub modes: usize,
    /// Coordinates n and speeds m.
    pub n: usize,
    pub m: usize,
}

impl Layout {
    /// Offset between a coordinate index and its speed index for the arm and elastic parts
    /// (the platform's five coordinates carry two speeds).
    pub fn speed_shift(&self) -> usize {
        if self.platform.is_some() { 3 } else { 0 }
    }
}

/// A rigid body moving with frame `frame` (0 platform … 5 gripper).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    pub frame: usize,
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
}

/// The flexible pitch link's discretization.
#[derive(Debug, Clone)]
pub struct FlexLink {
    /// Pitch link 1..3; its frame is F_{link+1}.
    pub link: usize,
    pub frame: usize,
    pub length: f64,
    /// Line density m/L.
    pub density: f64,
    pub ei_out: f64,
    pub ei_in: f64,
    /// Quadrature nodes and weights on [0, L].
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
    /// φₖ at the nodes (node-major: node g, mode k at g·N + k).
    pub phi: Vec<f64>,
    /// φₖ(L) and φₖ′(L).
    pub phi_tip: Vec<f64>,
    pub slope_tip: Vec<f64>,
    /// Stiffness ∫ φ″ φ″ᵀ dx (row-major N × N; times EI per direction).
    pub curvature: Vec<f64>,
    /// Residual rigid inertia J − diag(0, mL²/12, mL²/12) (link axes), carried by F.
    pub residual_inertia: Mat3,
}

/// Assumed-mode family of the flexible link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeChoice {
    /// Integrated Legendre polynomials (the span of ξ², …, ξᴺ⁺¹).
    Poly,
    /// Clamped-free cantilever eigenfunctions.
    ClampedFree,
}

/// The whole model of a `[mobile_manipulator]` scene.
#[derive(Debug, Clone)]
pub struct MobileModel {
    pub layout: Layout,
    pub gravity: f64,
    /// Chassis and wheels composed ([`Platform::composite`]).
    pub platform: Option<PlatformComposite>,
    pub ground_pose: [f64; 3],
    pub mount: Vec3,
    pub base_height: f64,
    pub lengths: [f64; 3],
    /// Rigid bodies: platform, turret, rigid links (the flexible link's residual inertia as a
    /// massless body), gripper.
    pub bodies: Vec<Body>,
    pub joint_friction: [f64; 4],
    pub flex: Option<FlexLink>,
}

/// Frames F0…F5 (origin, rotation, angular velocity/acceleration, origin velocity/acceleration).
#[derive(Debug, Clone, Copy, Default)]
pub struct Frames {
    pub o: [Vec3; 6],
    pub r: [Mat3; 6],
    pub w: [Vec3; 6],
    pub al: [Vec3; 6],
    pub v: [Vec3; 6],
    pub a: [Vec3; 6],
}

impl Frames {
    /// Inertial position, velocity and acceleration of a point at `d` (with rates `dd`, `ddd`,
    /// all in frame-k components) carried by frame k: p = o + Rd,
    /// v = v_o + ω×Rd + Rḋ, a = a_o + α×Rd + ω×(ω×Rd) + (2ω×Rḋ + Rd̈).
    fn carry(&self, k: usize, d: Vec3, dd: Vec3, ddd: Vec3) -> [Vec3; 3] {
        let (d, dd, ddd) = (self.r[k] * d, self.r[k] * dd, self.r[k] * ddd);
        let w = self.w[k];
        [
            self.o[k] + d,
            self.v[k] + w.cross(&d) + dd,
            self.a[k] + self.al[k].cross(&d) + w.cross(&w.cross(&d)) + (2.0 * w.cross(&dd) + ddd),
        ]
    }
}

/// Kinematics of the beam's quadrature nodes (inertial position, velocity, acceleration).
#[derive(Debug, Clone, Default)]
pub struct NodeKinematics {
    pub p: Vec<Vec3>,
    pub v: Vec<Vec3>,
    pub a: Vec<Vec3>,
}

impl MobileModel {
    /// Builds the model of the manipulator `m` with `modes` assumed modes per bending direction
    /// of the flexible link, of the family `shapes`.
    pub fn new(
        m: &MobileManipulator,
        modes: usize,
        shapes: ShapeChoice,
    ) -> Result<Self, ModalError> {
        let platform = m.platform.as_ref().map(Platform::composite);
        let flexible = m.flexible_link.as_ref().filter(|_| m.arm.is_some());
        let mut n = 0;
        let mut speeds = 0;
        let pl = platform.as_ref().map(|_| {
            n += 5;
            speeds += 2;
            0
        });
        let arm_at = m.arm.as_ref().map(|_| {
            let at = n;
            n += 4;
            speeds += 4;
            at
        });
        let modes = if flexible.is_some() { modes } else { 0 };
        let elastic = flexible.map(|_| {
            let at = n;
            n += 2 * modes;
            speeds += 2 * modes;
            at
        });
        let layout = Layout {
            platform: pl,
            arm: arm_at,
            elastic,
            modes,
            n,
            m: speeds,
        };
        let mut bodies = Vec::new();
        if let Some(p) = &platform {
            bodies.push(Body {
                frame: 0,
                mass: p.mass,
                com: Vector3::new(p.com_offset, 0.0, 0.0),
                inertia: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, p.yaw_inertia),
            });
        }
        let (mut mount, mut base_height, mut lengths, mut friction) =
            (Vec3::zeros(), 0.0, [0.0; 3], [0.0; 4]);
        let mut flex = None;
        if let Some(a) = &m.arm {
            if a.links.len() != 3 {
                return Err(ModalError::Unsupported(format!(
                    "mobile manipulator: {} pitch links (the model has three)",
                    a.links.len()
                )));
            }
            let body = |frame: usize, b: &RigidBody| Body {
                frame,
                mass: b.mass,
                com: Vector3::from(b.com),
                inertia: Matrix3::from(b.inertia).transpose(),
            };
            bodies.push(body(1, &a.turret));
            for (k, l) in a.links.iter().enumerate() {
                lengths[k] = l.length;
                match flexible {
                    Some(f) if f.link == k + 1 => {
                        let fl = FlexLink::build(f, l, modes, shapes)?;
                        bodies.push(Body {
                            frame: k + 2,
                            mass: 0.0,
                            com: Vec3::zeros(),
                            inertia: fl.residual_inertia,
                        });
                        flex = Some(fl);
                    }
                    _ => bodies.push(body(2 + k, &l.body())),
                }
            }
            bodies.push(body(5, &a.gripper));
            mount = Vector3::from(a.mount);
            base_height = a.base_height;
            friction = a.joint_friction;
        }
        Ok(MobileModel {
            layout,
            gravity: m.gravity,
            platform,
            ground_pose: [m.initial.x, m.initial.y, m.initial.heading],
            mount,
            base_height,
            lengths,
            bodies,
            joint_friction: friction,
            flex,
        })
    }

    /// Number of beam quadrature nodes (0 without a flexible link).
    pub fn node_count(&self) -> usize {
        self.flex.as_ref().map_or(0, |f| f.nodes.len())
    }

    /// Recursive kinematics of F0…F5 and of the beam nodes at (q, q̇, q̈) (full coordinates).
    pub fn kinematics(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        nodes: Option<&mut NodeKinematics>,
    ) -> Frames {
        let mut f = Frames::default();
        match self.layout.platform {
            Some(p) => {
                f.o[0] = Vector3::new(q[p], q[p + 1], 0.0);
                f.r[0] = rot_z(q[p + 2]);
                f.w[0] = Vector3::new(0.0, 0.0, qd[p + 2]);
                f.al[0] = Vector3::new(0.0, 0.0, qdd[p + 2]);
                f.v[0] = Vector3::new(qd[p], qd[p + 1], 0.0);
                f.a[0] = Vector3::new(qdd[p], qdd[p + 1], 0.0);
            }
            None => {
                let [x, y, psi] = self.ground_pose;
                f.o[0] = Vector3::new(x, y, 0.0);
                f.r[0] = rot_z(psi);
            }
        }
        let Some(a0) = self.layout.arm else {
            return f;
        };
        let offsets = [
            self.mount,
            Vector3::new(0.0, 0.0, self.base_height),
            Vector3::new(self.lengths[0], 0.0, 0.0),
            Vector3::new(self.lengths[1], 0.0, 0.0),
            Vector3::new(self.lengths[2], 0.0, 0.0),
        ];
        let flex_frame = self.flex.as_ref().map(|fl| fl.frame);
        for k in 1..6 {
            let p = k - 1;
            let (base_r, base_w, base_al);
            if flex_frame == Some(p) {
                let fl = self.flex.as_ref().expect("flexible frame without its link");
                let e0 = self
                    .layout
                    .elastic
                    .expect("flexible link without coordinates");
                let nm = self.layout.modes;
                let tip = |x: &[f64], shapes: &[f64]| -> (f64, f64) {
                    let v = dot(&shapes[..nm], &x[e0..e0 + nm]);
                    let w = dot(&shapes[..nm], &x[e0 + nm..e0 + 2 * nm]);
                    (v, w)
                };
                let (vl, wl) = tip(q, &fl.phi_tip);
                let (vld, wld) = tip(qd, &fl.phi_tip);
                let (vldd, wldd) = tip(qdd, &fl.phi_tip);
                let (s, c) = tip(q, &fl.slope_tip);
                let (sd, cd) = tip(qd, &fl.slope_tip);
                let (sdd, cdd) = tip(qdd, &fl.slope_tip);
                [f.o[k], f.v[k], f.a[k]] = f.carry(
                    p,
                    Vector3::new(fl.length, vl, wl),
                    Vector3::new(0.0, vld, wld),
                    Vector3::new(0.0, vldd, wldd),
                );
                // Two virtual revolute joints at the tip: s about R_F e_z, then c about
                // R_F R_z(s) (−e_y).
                let axis1 = f.r[p] * EZ;
                let rs = f.r[p] * rot_z(s);
                let axis2 = rs * MINUS_EY;
                let w1 = f.w[p] + (sd * axis1);
                let al1 = f.al[p] + f.w[p].cross(&(sd * axis1)) + (sdd * axis1);
                base_r = rs * rot_pitch(c);
                base_w = w1 + (cd * axis2);
                base_al = al1 + w1.cross(&(cd * axis2)) + (cdd * axis2);
            } else {
                let d = f.r[p] * offsets[p];
                f.o[k] = f.o[p] + d;
                f.v[k] = f.v[p] + f.w[p].cross(&d);
                f.a[k] = f.a[p] + f.al[p].cross(&d) + f.w[p].cross(&f.w[p].cross(&d));
                base_r = f.r[p];
                base_w = f.w[p];
                base_al = f.al[p];
            }
            if k == 5 {
                f.r[k] = base_r;
                f.w[k] = base_w;
                f.al[k] = base_al;
                continue;
            }
            let (u, joint_rot) = if k == 1 {
                (EZ, rot_z(q[a0]))
            } else {
                (MINUS_EY, rot_pitch(q[a0 + k - 1]))
            };
            let (th_d, th_dd) = (qd[a0 + k - 1], qdd[a0 + k - 1]);
            let axis = base_r * u;
            f.r[k] = base_r * joint_rot;
            f.w[k] = base_w + (th_d * axis);
            f.al[k] = base_al + base_w.cross(&(th_d * axis)) + (th_dd * axis);
        }
        if let (Some(fl), Some(nk)) = (&self.flex, nodes) {
            let e0 = self
                .layout
                .elastic
                .expect("flexible link without coordinates");
            let nm = self.layout.modes;
            let k = fl.frame;
            for g in 0..fl.nodes.len() {
                let ph = &fl.phi[g * nm..(g + 1) * nm];
                let field = |x: &[f64]| -> (f64, f64) {
                    let v = dot(ph, &x[e0..e0 + nm]);
                    let w = dot(ph, &x[e0 + nm..e0 + 2 * nm]);
                    (v, w)
                };
                let (v, w) = field(q);
                let (vd, wd) = field(qd);
                let (vdd, wdd) = field(qdd);
                [nk.p[g], nk.v[g], nk.a[g]] = f.carry(
                    k,
                    Vector3::new(fl.nodes[g], v, w),
                    Vector3::new(0.0, vd, wd),
                    Vector3::new(0.0, vdd, wdd),
                );
            }
        }
        f
    }

    /// q̇ = S(q) ν into `qd` and Ṡ(q, ν) ν into `sdot_nu`.
    pub fn velocities(&self, q: &[f64], nu: &[f64], qd: &mut [f64], sdot_nu: &mut [f64]) {
        let l = self.layout;
        qd[..l.n].fill(0.0);
        sdot_nu[..l.n].fill(0.0);
        if let (Some(pl), Some(p)) = (l.platform, &self.platform) {
            let (s, c) = q[pl + 2].sin_cos();
            let (wr, wl) = (nu[0], nu[1]);
            let u = 0.5 * p.wheel_radius * (wr + wl);
            let psid = 0.5 * p.wheel_radius / p.half_track * (wr - wl);
            qd[pl] = u * c;
            qd[pl + 1] = u * s;
            qd[pl + 2] = psid;
            qd[pl + 3] = wr;
            qd[pl + 4] = wl;
            sdot_nu[pl] = -u * s * psid;
            sdot_nu[pl + 1] = u * c * psid;
        }
        let shift = l.speed_shift();
        let start = l.arm.or(l.elastic);
        if let Some(s0) = start {
            qd[s0..l.n].copy_from_slice(&nu[s0 - shift..l.n - shift]);
        }
    }

    /// Nonholonomic constraint residual |A(q) q̇|∞ (no sideways slip, rolling per side).
    pub fn constraint_residual(&self, q: &[f64], qd: &[f64]) -> f64 {
        let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) else {
            return 0.0;
        };
        let (s, c) = q[pl + 2].sin_cos();
        let (xd, yd, psid) = (qd[pl], qd[pl + 1], qd[pl + 2]);
        let lateral = -s * xd + c * yd;
        let forward = c * xd + s * yd;
        let right = forward + p.half_track * psid - p.wheel_radius * qd[pl + 3];
        let left = forward - p.half_track * psid - p.wheel_radius * qd[pl + 4];
        lateral.abs().max(right.abs()).max(left.abs())
    }

    /// Kinetic energy from the bodies' and material points' velocities (independent of the
    /// mass matrix).
    pub fn kinetic_energy(&self, q: &[f64], qd: &[f64], nodes: &mut NodeKinematics) -> f64 {
        let zeros = vec![0.0; self.layout.n];
        let f = self.kinematics(q, qd, &zeros, Some(nodes));
        let mut t = 0.0;
        for b in &self.bodies {
            let r = &f.r[b.frame];
            let rc = r * b.com;
            let w = f.w[b.frame];
            let v = f.v[b.frame] + w.cross(&rc);
            let iw = r * b.inertia * r.transpose();
            t += 0.5 * b.mass * v.dot(&v) + 0.5 * w.dot(&(iw * w));
        }
        if let Some(fl) = &self.flex {
            for g in 0..fl.nodes.len() {
                t += 0.5 * fl.density * fl.weights[g] * nodes.v[g].dot(&nodes.v[g]);
            }
        }
        if let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) {
            t += 0.5 * p.side_spin_inertia * (qd[pl + 3].powi(2) + qd[pl + 4].powi(2));
        }
        t
    }

    /// Gravitational potential Σ m g z + ∫ μ g p_z dx.
    pub fn gravity_energy(&self, q: &[f64], nodes: &mut NodeKinematics) -> f64 {
        let zeros = vec![0.0; self.layout.n];
        let f = self.kinematics(q, &zeros, &zeros, Some(nodes));
        let mut v = 0.0;
        for b in &self.bodies {
            v += b.mass * self.gravity * (f.o[b.frame] + (f.r[b.frame] * b.com))[2];
        }
        if let Some(fl) = &self.flex {
            for g in 0..fl.nodes.len() {
                v += fl.density * fl.weights[g] * self.gravity * nodes.p[g][2];
            }
        }
        v
    }

    /// Strain energy ½ EI_out bᵀ K b + ½ EI_in cᵀ K c.
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let (Some(fl), Some(e0)) = (&self.flex, self.layout.elastic) else {
            return 0.0;
        };
        let nm = self.layout.modes;
        let quad = |x: &[f64]| -> f64 {
            let mut s = 0.0;
            for i in 0..nm {
                for j in 0..nm {
                    s += x[i] * fl.curvature[i * nm + j] * x[j];
                }
            }
            s
        };
        0.5 * fl.ei_out * quad(&q[e0..e0 + nm]) + 0.5 * fl.ei_in * quad(&q[e0 + nm..e0 + 2 * nm])
    }

    /// Inertial position of the gripper frame origin (tip of link 3).
    pub fn end_effector(&self, q: &[f64]) -> Vec3 {
        let zeros = vec![0.0; self.layout.n];
        self.kinematics(q, &zeros, &zeros, None).o[5]
    }

    /// (v(L), w(L)): the flexible link's tip deflection out of and in the arm's plane.
    pub fn tip_deflection(&self, q: &[f64]) -> Option<(f64, f64)> {
        let fl = self.flex.as_ref()?;
        let e0 = self.layout.elastic?;
        let nm = self.layout.modes;
        let v = dot(&fl.phi_tip[..nm], &q[e0..e0 + nm]);
        let w = dot(&fl.phi_tip[..nm], &q[e0 + nm..e0 + 2 * nm]);
        Some((v, w))
    }
}

impl FlexLink {
    fn build(
        f: &data::scene::FlexibleLink,
        l: &data::scene::ArmLink,
        modes: usize,
        shapes: ShapeChoice,
    ) -> Result<Self, ModalError> {
        let length = l.length;
        let set = match shapes {
            ShapeChoice::Poly => ShapeSet::poly(length, modes),
            ShapeChoice::ClampedFree => {
                ShapeSet::clamped_free(length, modes).map_err(|source| ModalError::Basis {
                    link: f.link,
                    source,
                })?
            }
        };
        let quad = match shapes {
            // Integrands are polynomials of degree ≤ 2N + 2 (φφ), N + 4 points are exact.
            ShapeChoice::Poly => Quadrature::composite(length, 1, modes + 4),
            ShapeChoice::ClampedFree => Quadrature::for_wavenumber(length, set.max_wavenumber()),
        };
        let mut phi = vec![0.0; quad.x.len() * modes];
        for (g, &x) in quad.x.iter().enumerate() {
            set.eval(x, 0, &mut phi[g * modes..(g + 1) * modes]);
        }
        let mut phi_tip = vec![0.0; modes];
        let mut slope_tip = vec![0.0; modes];
        set.eval(length, 0, &mut phi_tip);
        set.eval(length, 1, &mut slope_tip);
        let mut curvature = vec![0.0; modes * modes];
        let mut d2 = vec![0.0; modes];
        for (&x, &w) in quad.x.iter().zip(&quad.w) {
            set.eval(x, 2, &mut d2);
            for i in 0..modes {
                for j in 0..modes {
                    curvature[i * modes + j] += w * d2[i] * d2[j];
                }
            }
        }
        let rod = l.mass * length * length / 12.0;
        let mut residual_inertia = Matrix3::from(l.inertia).transpose();
        residual_inertia[(1, 1)] -= rod;
        residual_inertia[(2, 2)] -= rod;
        Ok(FlexLink {
            link: f.link,
            frame: f.link + 1,
            length,
            density: l.mass / length,
            ei_out: f.bending_stiffness_out_of_plane,
            ei_in: f.bending_stiffness_in_plane,
            nodes: quad.x,
            weights: quad.w,
            phi,
            phi_tip,
            slope_tip,
            curvature,
            residual_inertia,
        })
    }
}

/// Preallocated storage of one evaluation of the equations (no allocation per call).
#[derive(Debug, Clone)]
pub struct Workspace {
    /// Partial velocities (v, ω) of each body's mass centre, speed-major: [i · bodies + b].
    body_partials: Vec<(Vec3, Vec3)>,
    /// Partial velocities of the beam nodes, speed-major: [i · nodes + g].
    node_partials: Vec<Vec3>,
    nodes: NodeKinematics,
    qd: Vec<f64>,
    sdn: Vec<f64>,
    unit: Vec<f64>,
    zeros: Vec<f64>,
    /// Reduced mass matrix (row-major m × m) and the right-hand side Q_r − bias.
    pub mass: Vec<f64>,
    pub force: Vec<f64>,
    /// Input power (wheel, joint) and friction power (wheel, joint) at the evaluated state.
    pub power: [f64; 4],
}

impl Workspace {
    pub fn new(model: &MobileModel) -> Self {
        let l = model.layout;
        let nb = model.bodies.len();
        let ng = model.node_count();
        let nodes = NodeKinematics {
            p: vec![Vec3::zeros(); ng],
            v: vec![Vec3::zeros(); ng],
            a: vec![Vec3::zeros(); ng],
        };
        Workspace {
            body_partials: vec![(Vec3::zeros(), Vec3::zeros()); l.m * nb],
            node_partials: vec![Vec3::zeros(); l.m * ng],
            nodes,
            qd: vec![0.0; l.n],
            sdn: vec![0.0; l.n],
            unit: vec![0.0; l.m],
            zeros: vec![0.0; l.n],
            mass: vec![0.0; l.m * l.m],
            force: vec![0.0; l.m],
            power: [0.0; 4],
        }
    }

    /// Node kinematics scratch (for the energy functions).
    pub fn nodes_mut(&mut self) -> &mut NodeKinematics {
        &mut self.nodes
    }
}

impl MobileModel {
    /// Assembles M_r(q) into `ws.mass` and Q_r − bias(q, ν) into `ws.force` for the inputs
    /// `tau` (ν order: τ_R, τ_L, τ₁…τ₄ as present), and the powers into `ws.power`.
    pub fn equations(&self, q: &[f64], nu: &[f64], tau: &[f64], ws: &mut Workspace) {
        let l = self.layout;
        let (n, m) = (l.n, l.m);
        let nb = self.bodies.len();
        let ng = self.node_count();
        // Partial velocities: the kinematics at ν = eᵢ.
        for i in 0..m {
            ws.unit.fill(0.0);
            ws.unit[i] = 1.0;
            self.velocities(q, &ws.unit, &mut ws.qd, &mut ws.sdn);
            let f = self.kinematics(q, &ws.qd, &ws.zeros, Some(&mut ws.nodes));
            for (b, body) in self.bodies.iter().enumerate() {
                let rc = f.r[body.frame] * body.com;
                let w = f.w[body.frame];
                ws.body_partials[i * nb + b] = (f.v[body.frame] + w.cross(&rc), w);
            }
            ws.node_partials[i * ng..(i + 1) * ng].copy_from_slice(&ws.nodes.v);
        }
        // Velocity-product accelerations (ν̇ = 0, q̈ = Ṡ ν).
        self.velocities(q, nu, &mut ws.qd, &mut ws.sdn);
        let f = self.kinematics(q, &ws.qd, &ws.sdn, Some(&mut ws.nodes));
        let g = Vector3::new(0.0, 0.0, self.gravity);
        ws.mass.fill(0.0);
        ws.force.fill(0.0);
        for (b, body) in self.bodies.iter().enumerate() {
            let r = &f.r[body.frame];
            let rc = r * body.com;
            let (w, al) = (f.w[body.frame], f.al[body.frame]);
            let acc = f.a[body.frame] + al.cross(&rc) + w.cross(&w.cross(&rc));
            let lin = body.mass * (acc + g);
            let iw = r * body.inertia * r.transpose();
            let ang = iw * al + w.cross(&(iw * w));
            for i in 0..m {
                let (vi, wi) = ws.body_partials[i * nb + b];
                ws.force[i] -= vi.dot(&lin) + wi.dot(&ang);
                let iwi = iw * wi;
                for j in i..m {
                    let (vj, wj) = ws.body_partials[j * nb + b];
                    ws.mass[i * m + j] += body.mass * vi.dot(&vj) + wj.dot(&iwi);
                }
            }
        }
        if let Some(fl) = &self.flex {
            for gi in 0..ng {
                let mw = fl.density * fl.weights[gi];
                let lin = mw * (ws.nodes.a[gi] + g);
                for i in 0..m {
                    let vi = ws.node_partials[i * ng + gi];
                    ws.force[i] -= vi.dot(&lin);
                    for j in i..m {
                        ws.mass[i * m + j] += mw * vi.dot(&ws.node_partials[j * ng + gi]);
                    }
                }
            }
        }
        for i in 0..m {
            for j in 0..i {
                ws.mass[i * m + j] = ws.mass[j * m + i];
            }
        }
        // Wheels' spin, inputs and friction on the identity rows of S.
        let mut power = [0.0; 4];
        let mut k = 0;
        if let Some(p) = &self.platform {
            for s in 0..2 {
                ws.mass[s * m + s] += p.side_spin_inertia;
                let rate = nu[s];
                ws.force[s] += tau[s] - p.side_friction * rate;
                power[0] += tau[s] * rate;
                power[2] += p.side_friction * rate * rate;
            }
            k = 2;
        }
        if l.arm.is_some() {
            for i in 0..4 {
                let rate = nu[k + i];
                ws.force[k + i] += tau[k + i] - self.joint_friction[i] * rate;
                power[1] += tau[k + i] * rate;
                power[3] += self.joint_friction[i] * rate * rate;
            }
            k += 4;
        }
        if let (Some(fl), Some(e0)) = (&self.flex, l.elastic) {
            let nm = l.modes;
            for (dir, ei) in [(0, fl.ei_out), (1, fl.ei_in)] {
                for i in 0..nm {
                    let s = dot(
                        &fl.curvature[i * nm..(i + 1) * nm],
                        &q[e0 + dir * nm..e0 + (dir + 1) * nm],
                    );
                    ws.force[k + dir * nm + i] -= ei * s;
                }
            }
        }
        debug_assert_eq!(n, l.n);
        ws.power = power;
    }
}
