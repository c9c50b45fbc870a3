//! Kinematics, energies and Lagrange's equations of the rigid mobile manipulator.
//!
//! Frames (chain F0 → F5): F0 platform (origin at the middle-axle centre P = (x, y, 0),
//! R₀ = R_z(ψ)); F1 turret (origin at the mount, R₁ = R₀ R_z(θ₁)); F2…F4 pitch links (origin
//! at each pitch joint, Rₖ = Rₖ₋₁ R_y(−θₖ₊₁), the first `base_height` above the mount, the
//! others at the previous link's tip); F5 gripper (origin at link 3's tip). A body of mass m,
//! mass centre c and central inertia J (body axes) moving with frame F has
//!
//! ```text
//! p = o + R c,  v = v_o + ω × R c,  a = a_o + α × R c + ω × (ω × R c),
//! T_body = ½ m v·v + ½ ω·(R J Rᵀ) ω,  V_body = m g p_z
//! ```
//!
//! and each side's wheels add ½ J_side φ̇² (J_side = spin inertia × wheels per side; a wheel's
//! spin axis is principal and perpendicular to the yaw axis, so spin and yaw do not couple in T).
//! The wheels' translation and diametral inertia are lumped into the platform body.
//!
//! With T = ½ q̇ᵀ M(q) q̇, Lagrange's equations read M q̈ + h(q, q̇) = Q + Aᵀ λ with
//! h = Ṁ q̇ − ∂T/∂q + ∂V/∂q. They are evaluated here by projecting the bodies' Newton–Euler
//! wrenches on the velocity Jacobians (virtual power):
//!
//! ```text
//! M = Σ (m J_vᵀ J_v + J_ωᵀ R J Rᵀ J_ω) + diag(J_side on φ_R, φ_L)
//! M q̈ + h = Σ (J_vᵀ m (a − g) + J_ωᵀ (I α + ω × I ω)) + J_side φ̈
//! ```
//!
//! where the Jacobian column of joint j for a point p distal to it is w_j × (p − o_j) (w_j the
//! joint's inertial axis, o_j its frame origin) and w_j for rotation; x, y give e_x, e_y. The
//! tests check both against finite-difference derivatives of T and V computed from the body
//! velocities alone.
//!
//! Constraints (b = half track, r = wheel radius): no sideways slip −ẋ sin ψ + ẏ cos ψ = 0, and
//! rolling on each side ẋ cos ψ + ẏ sin ψ ± b ψ̇ − r φ̇_{R,L} = 0; A(q) q̇ = 0 with A 3 × n.
//! Null-space basis S(q) for ν = (φ̇_R, φ̇_L, θ̇₁…θ̇₄): u = r(φ̇_R + φ̇_L)/2, ψ̇ = r(φ̇_R − φ̇_L)/(2b),
//! ẋ = u cos ψ, ẏ = u sin ψ, and the identity on the wheel and joint rates, so Sᵀ B = I.

use data::scene::{MobileManipulator, Platform, PlatformComposite, RigidBody};
use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};

use crate::analytic::error::{AnalyticError, Result};

/// Largest number of generalized coordinates (5 platform + 4 arm).
pub const MAX_Q: usize = 9;
/// Number of constraints of the platform.
pub const N_CONSTRAINTS: usize = 3;

pub type Vec3 = Vector3<f64>;
pub type Mat3 = Matrix3<f64>;

fn rot_z(t: f64) -> Mat3 {
    Rotation3::from_axis_angle(&Vector3::z_axis(), t).into_inner()
}
/// Rotation by θ about −y: x ↦ (cos θ, 0, sin θ).
fn rot_pitch(t: f64) -> Mat3 {
    Rotation3::from_axis_angle(&-Vector3::y_axis(), t).into_inner()
}

/// Where each coordinate sits in q (None when that part of the system is absent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Index of x (then y, ψ, φ_R, φ_L) when there is a platform.
    pub platform: Option<usize>,
    /// Index of θ₁ (then θ₂…θ₄) when there is an arm.
    pub arm: Option<usize>,
    /// Number of coordinates n.
    pub n: usize,
    /// Number of velocity freedoms m = n − constraints.
    pub m: usize,
}

/// One arm body attached to a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    pub frame: usize,
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
}

/// The rigid model of a scene's `[mobile_manipulator]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub layout: Layout,
    pub gravity: f64,
    /// Chassis and wheels composed ([`Platform::composite`]).
    pub platform: Option<PlatformComposite>,
    /// Fixed pose of F0 when there is no platform: (x, y, ψ).
    pub ground_pose: [f64; 3],
    /// Mount, first-pitch offset and link lengths (frame offsets in the parent frame).
    pub mount: Vec3,
    pub base_height: f64,
    pub lengths: [f64; 3],
    /// Arm bodies: turret, links, gripper.
    pub bodies: Vec<Body>,
    pub joint_friction: [f64; 4],
}

/// Frames F0…F5: origin, rotation, angular velocity and acceleration, origin velocity and
/// acceleration, and the inertial joint axis that moves each frame (zero for F0 and F5).
#[derive(Debug, Clone, Copy, Default)]
pub struct Frames {
    pub o: [Vec3; 6],
    pub r: [Mat3; 6],
    pub w: [Vec3; 6],
    pub al: [Vec3; 6],
    pub v: [Vec3; 6],
    pub a: [Vec3; 6],
    pub axis: [Vec3; 6],
}

impl Model {
    pub fn from_scene(m: &MobileManipulator) -> Result<Self> {
        // A `[mobile_manipulator.flexible_link]` is ignored: the rigid model is its EI → ∞
        // limit (the backends' beam carries the link's mass m, mass centre L/2 and inertia J
        // exactly, the elastic deflection vanishing as 1/EI).
        let platform = m.platform.as_ref().map(Platform::composite);
        let mut n = 0;
        let pl = platform.as_ref().map(|_| {
            n += 5;
            0
        });
        let arm_at = m.arm.as_ref().map(|_| {
            let at = n;
            n += 4;
            at
        });
        let layout = Layout {
            platform: pl,
            arm: arm_at,
            n,
            m: n - if pl.is_some() { N_CONSTRAINTS } else { 0 },
        };
        let (mut bodies, mut mount, mut base_height, mut lengths, mut friction) =
            (Vec::new(), Vector3::zeros(), 0.0, [0.0; 3], [0.0; 4]);
        if let Some(a) = &m.arm {
            let body = |frame: usize, b: &RigidBody| Body {
                frame,
                mass: b.mass,
                com: Vector3::from(b.com),
                inertia: Matrix3::from_fn(|i, j| b.inertia[i][j]),
            };
            if a.links.len() != 3 {
                return Err(AnalyticError::Unsupported(format!(
                    "mobile reference: {} pitch links (the model has three)",
                    a.links.len()
                )));
            }
            bodies.push(body(1, &a.turret));
            for (k, l) in a.links.iter().enumerate() {
                bodies.push(body(2 + k, &l.body()));
                lengths[k] = l.length;
            }
            bodies.push(body(5, &a.gripper));
            mount = Vector3::from(a.mount);
            base_height = a.base_height;
            friction = a.joint_friction;
        }
        Ok(Model {
            layout,
            gravity: m.gravity,
            platform,
            ground_pose: [m.initial.x, m.initial.y, m.initial.heading],
            mount,
            base_height,
            lengths,
            bodies,
            joint_friction: friction,
        })
    }

    /// Recursive kinematics of F0…F5 at (q, q̇, q̈).
    pub fn frames(&self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Frames {
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
        for k in 1..6 {
            let d = f.r[k - 1] * offsets[k - 1];
            f.o[k] = f.o[k - 1] + d;
            f.v[k] = f.v[k - 1] + f.w[k - 1].cross(&d);
            f.a[k] = f.a[k - 1] + f.al[k - 1].cross(&d) + f.w[k - 1].cross(&f.w[k - 1].cross(&d));
            if k == 5 {
                f.r[k] = f.r[k - 1];
                f.w[k] = f.w[k - 1];
                f.al[k] = f.al[k - 1];
                continue;
            }
            let (u, rot) = if k == 1 {
                (Vector3::z(), rot_z(q[a0]))
            } else {
                (-Vector3::y(), rot_pitch(q[a0 + k - 1]))
            };
            let (th_d, th_dd) = (qd[a0 + k - 1], qdd[a0 + k - 1]);
            let axis = f.r[k - 1] * u;
            f.axis[k] = axis;
            f.r[k] = f.r[k - 1] * rot;
            f.w[k] = f.w[k - 1] + axis * th_d;
            f.al[k] = f.al[k - 1] + f.w[k - 1].cross(&(axis * th_d)) + axis * th_dd;
        }
        f
    }

    /// Inertial position of a body's mass centre.
    fn com_position(f: &Frames, b: &Body) -> Vec3 {
        f.o[b.frame] + f.r[b.frame] * b.com
    }

    /// Linear and angular Jacobian columns of coordinate j for a point p moving with frame k.
    fn jacobian(&self, f: &Frames, k: usize, p: Vec3, j: usize) -> (Vec3, Vec3) {
        let zero = Vector3::zeros();
        if let Some(pl) = self.layout.platform {
            match j.checked_sub(pl) {
                Some(0) => return (Vector3::x(), zero),
                Some(1) => return (Vector3::y(), zero),
                Some(2) => return (Vector3::z().cross(&(p - f.o[0])), Vector3::z()),
                Some(3) | Some(4) => return (zero, zero),
                _ => {}
            }
        }
        if let Some(a0) = self.layout.arm
            && let Some(i) = j.checked_sub(a0)
            && i < 4
        {
            let frame = i + 1;
            if k >= frame {
                let w = f.axis[frame];
                return (w.cross(&(p - f.o[frame])), w);
            }
        }
        (zero, zero)
    }

    /// The platform body (mass centre in F0, yaw inertia about it) as a rigid body.
    fn platform_body(&self) -> Option<Body> {
        self.platform.as_ref().map(|p| Body {
            frame: 0,
            mass: p.mass,
            com: Vector3::new(p.com_offset, 0.0, 0.0),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, p.yaw_inertia)),
        })
    }

    fn all_bodies(&self) -> impl Iterator<Item = Body> + '_ {
        self.platform_body()
            .into_iter()
            .chain(self.bodies.iter().copied())
    }

    /// Mass matrix M(q), row-major n × n into `m`.
    pub fn mass_matrix(&self, q: &[f64], m: &mut [[f64; MAX_Q]; MAX_Q]) {
        let n = self.layout.n;
        let zeros = [0.0; MAX_Q];
        let f = self.frames(q, &zeros[..n], &zeros[..n]);
        for row in m.iter_mut() {
            *row = [0.0; MAX_Q];
        }
        for b in self.all_bodies() {
            let p = Self::com_position(&f, &b);
            let r = &f.r[b.frame];
            let iw = r * b.inertia * r.transpose();
            let mut cols = [(Vector3::zeros(), Vector3::zeros()); MAX_Q];
            for (j, c) in cols.iter_mut().enumerate().take(n) {
                *c = self.jacobian(&f, b.frame, p, j);
            }
            for i in 0..n {
                for j in i..n {
                    let (vi, wi) = cols[i];
                    let (vj, wj) = cols[j];
                    let e = b.mass * vi.dot(&vj) + wi.dot(&(iw * wj));
                    m[i][j] += e;
                    if j != i {
                        m[j][i] += e;
                    }
                }
            }
        }
        if let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) {
            m[pl + 3][pl + 3] += p.side_spin_inertia;
            m[pl + 4][pl + 4] += p.side_spin_inertia;
        }
    }

    /// Newton–Euler inverse dynamics: M(q) q̈ + h(q, q̇) (gravity included), into `out`.
    /// With `gravity = false` the weight is left out (used to split h for the tests).
    pub fn inverse_dynamics(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        gravity: bool,
        out: &mut [f64],
    ) {
        let n = self.layout.n;
        let f = self.frames(q, qd, qdd);
        out[..n].fill(0.0);
        let g = if gravity { self.gravity } else { 0.0 };
        for b in self.all_bodies() {
            let r = &f.r[b.frame];
            let rc = r * b.com;
            let p = f.o[b.frame] + rc;
            let (w, al) = (f.w[b.frame], f.al[b.frame]);
            let acc = f.a[b.frame] + al.cross(&rc) + w.cross(&w.cross(&rc));
            let force = (acc + Vector3::new(0.0, 0.0, g)) * b.mass;
            let iw = r * b.inertia * r.transpose();
            let moment = iw * al + w.cross(&(iw * w));
            for (j, o) in out.iter_mut().enumerate().take(n) {
                let (jv, jw) = self.jacobian(&f, b.frame, p, j);
                *o += jv.dot(&force) + jw.dot(&moment);
            }
        }
        if let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) {
            out[pl + 3] += p.side_spin_inertia * qdd[pl + 3];
            out[pl + 4] += p.side_spin_inertia * qdd[pl + 4];
        }
    }

    /// Kinetic energy from the body velocities (independent of [`Model::mass_matrix`]).
    pub fn kinetic_energy(&self, q: &[f64], qd: &[f64]) -> f64 {
        let n = self.layout.n;
        let zeros = [0.0; MAX_Q];
        let f = self.frames(q, qd, &zeros[..n]);
        let mut t = 0.0;
        for b in self.all_bodies() {
            let r = &f.r[b.frame];
            let rc = r * b.com;
            let w = f.w[b.frame];
            let v = f.v[b.frame] + w.cross(&rc);
            let iw = r * b.inertia * r.transpose();
            t += 0.5 * b.mass * v.dot(&v) + 0.5 * w.dot(&(iw * w));
        }
        if let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) {
            t += 0.5 * p.side_spin_inertia * (qd[pl + 3].powi(2) + qd[pl + 4].powi(2));
        }
        t
    }

    /// Gravitational potential Σ m g z (zero at the ground plane).
    pub fn potential_energy(&self, q: &[f64]) -> f64 {
        let n = self.layout.n;
        let zeros = [0.0; MAX_Q];
        let f = self.frames(q, &zeros[..n], &zeros[..n]);
        self.all_bodies()
            .map(|b| b.mass * self.gravity * Self::com_position(&f, &b)[2])
            .sum()
    }

    /// Inertial position of the gripper frame origin (tip of link 3).
    pub fn end_effector(&self, q: &[f64]) -> Vec3 {
        let n = self.layout.n;
        let zeros = [0.0; MAX_Q];
        self.frames(q, &zeros[..n], &zeros[..n]).o[5]
    }

    /// Constraint matrix A(q) (3 × n) and the velocity-product term Ȧ q̇; None without platform.
    pub fn constraints(
        &self,
        q: &[f64],
        qd: &[f64],
    ) -> Option<([[f64; MAX_Q]; N_CONSTRAINTS], [f64; N_CONSTRAINTS])> {
        let pl = self.layout.platform?;
        let p = self.platform.as_ref()?;
        let (s, c) = q[pl + 2].sin_cos();
        let (b, r) = (p.half_track, p.wheel_radius);
        let mut a = [[0.0; MAX_Q]; N_CONSTRAINTS];
        a[0][pl] = -s;
        a[0][pl + 1] = c;
        a[1][pl] = c;
        a[1][pl + 1] = s;
        a[1][pl + 2] = b;
        a[1][pl + 3] = -r;
        a[2][pl] = c;
        a[2][pl + 1] = s;
        a[2][pl + 2] = -b;
        a[2][pl + 4] = -r;
        let (xd, yd, psid) = (qd[pl], qd[pl + 1], qd[pl + 2]);
        let lateral = -s * xd + c * yd;
        let forward = c * xd + s * yd;
        Some((a, [-psid * forward, psid * lateral, psid * lateral]))
    }

    /// Null-space map q̇ = S(q) ν into `qd`, and Ṡ ν into `sdot_nu`.
    pub fn velocities(&self, q: &[f64], nu: &[f64], qd: &mut [f64], sdot_nu: &mut [f64]) {
        let n = self.layout.n;
        qd[..n].fill(0.0);
        sdot_nu[..n].fill(0.0);
        let mut k = 0;
        if let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) {
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
            k = 2;
        }
        if let Some(a0) = self.layout.arm {
            qd[a0..a0 + 4].copy_from_slice(&nu[k..k + 4]);
        }
    }

    /// Column i of S(q) (the velocities of ν = e_i).
    pub fn null_space_column(&self, q: &[f64], i: usize, col: &mut [f64]) {
        let mut e = [0.0; MAX_Q];
        e[i] = 1.0;
        let mut scratch = [0.0; MAX_Q];
        self.velocities(q, &e[..self.layout.m], col, &mut scratch);
    }

    /// Minimal speeds ν of a constraint-consistent q̇ (the rows of S that are the identity).
    pub fn minimal_speeds(&self, qd: &[f64], nu: &mut [f64]) {
        let mut k = 0;
        if let Some(pl) = self.layout.platform {
            nu[0] = qd[pl + 3];
            nu[1] = qd[pl + 4];
            k = 2;
        }
        if let Some(a0) = self.layout.arm {
            nu[k..k + 4].copy_from_slice(&qd[a0..a0 + 4]);
        }
    }

    /// Generalized forces of the actuators and viscous friction, Q = B τ − D q̇, with inputs
    /// τ = (τ_R, τ_L, τ₁…τ₄) in the order of ν. Also returns (input power of the wheel
    /// torques, of the joint torques, wheel friction power, joint friction power).
    pub fn applied(&self, qd: &[f64], tau: &[f64], out: &mut [f64]) -> [f64; 4] {
        out[..self.layout.n].fill(0.0);
        let mut pw = [0.0; 4];
        let mut k = 0;
        if let (Some(pl), Some(p)) = (self.layout.platform, &self.platform) {
            for s in 0..2 {
                let rate = qd[pl + 3 + s];
                out[pl + 3 + s] = tau[s] - p.side_friction * rate;
                pw[0] += tau[s] * rate;
                pw[2] += p.side_friction * rate * rate;
            }
            k = 2;
        }
        if let Some(a0) = self.layout.arm {
            for i in 0..4 {
                let rate = qd[a0 + i];
                out[a0 + i] = tau[k + i] - self.joint_friction[i] * rate;
                pw[1] += tau[k + i] * rate;
                pw[3] += self.joint_friction[i] * rate * rate;
            }
        }
        pw
    }
}

/// Largest linear system of the reference: the KKT system of n coordinates and the constraints.
const MAX_SYSTEM: usize = MAX_Q + N_CONSTRAINTS;

/// Solves the dense system a x = b of size k ≤ N (the leading k × k block of `a`; `b` receives
/// x) by nalgebra's partially pivoted LU, on the block bordered by the identity to the fixed
/// size `MAX_SYSTEM` (n + constraints), so that the factorization is allocation-free. Errors on a singular or
/// non-finite system.
pub fn solve<const N: usize>(a: &[[f64; N]; N], b: &mut [f64; N], k: usize) -> Result<()> {
    const { assert!(N <= MAX_SYSTEM) };
    let k = k.min(N);
    let matrix =
        SMatrix::<f64, MAX_SYSTEM, MAX_SYSTEM>::from_fn(|i, j| match (i < k && j < k, i == j) {
            (true, _) => a[i][j],
            (false, true) => 1.0,
            (false, false) => 0.0,
        });
    let rhs = SVector::<f64, MAX_SYSTEM>::from_fn(|i, _| if i < k { b[i] } else { 0.0 });
    let x = matrix
        .lu()
        .solve(&rhs)
        .filter(|x| x.iter().all(|v| v.is_finite()))
        .ok_or(AnalyticError::Singular {
            what: "mobile reference",
            size: k,
        })?;
    b[..k].copy_from_slice(&x.as_slice()[..k]);
    Ok(())
}
