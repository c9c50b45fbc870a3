//! Seed 004's printed expressions and their corrections (docs/mobile-manipulator.md lists them
//! with the test that shows each).
//!
//! Closed form of the yaw joint for a fixed-base arm whose bodies have their principal axes
//! along the link frames and their mass centres on the link axes (turret's on the yaw axis).
//! With absolute pitch angles β₁ = θ₂, β₂ = θ₂ + θ₃, β₃ = θ₂ + θ₃ + θ₄, the horizontal distance
//! of body k's mass centre from the yaw axis is ρ_k = Σ_{j<k} l_j cos β_j + c_k cos β_k (the
//! gripper at c_g beyond l₃), and the yaw axis has components (sin β, 0, cos β) in a pitched
//! link's frame, so
//!
//! ```text
//! A = J_turret,zz + Σ_k [m_k ρ_k² + J_k,xx sin²β_k + J_k,zz cos²β_k]          (corrected eq. 38)
//! Q = θ̇₁ Ȧ = θ̇₁ Σ_k [2 m_k ρ_k ρ̇_k + (J_k,xx − J_k,zz) sin 2β_k β̇_k]          (corrected eq. 42)
//! τ₁ = A θ̈₁ + Q + b₁ θ̇₁,  B = C = D = 0 and U = 0 (eqs. 37, 39–41, 43 hold)
//! ```
//!
//! The printed eq. 38 instead has w_c (the gripper's weight) where m_c belongs, m_b r² where eq. 6
//! gives I_b = ½ m_b r², cos θ₂ where cos(θ₂ + θ₃) belongs in the m₂ term, and no rotary inertia
//! of the links about the vertical; the printed eq. 42 has cos θ₂ for sin θ₂ in the m₃ term and
//! drops the ½ of the m₁ term (eq. 33 has it).

use data::scene::{MobileManipulator, RigidBody};

/// Parameters of one pitch body for the closed forms: mass, offset of its mass centre along
/// the link axis, principal moments J_xx (about the link axis) and J_zz, and the length of the
/// link (0 for the gripper).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PitchBody {
    pub mass: f64,
    pub com: f64,
    pub jxx: f64,
    pub jzz: f64,
    pub length: f64,
}

/// The fixed-base arm of the seed's joint-1 closed form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedFormArm {
    pub turret_jzz: f64,
    /// Three links then the gripper.
    pub bodies: [PitchBody; 4],
    pub friction1: f64,
    pub gravity: f64,
}

fn aligned(b: &RigidBody) -> bool {
    let j = &b.inertia;
    j[0][1] == 0.0 && j[0][2] == 0.0 && j[1][2] == 0.0 && b.com[1] == 0.0 && b.com[2] == 0.0
}

impl ClosedFormArm {
    /// The closed-form data of a scene when the closed form applies (no platform, principal
    /// axes aligned, mass centres on the axes).
    pub fn from_scene(m: &MobileManipulator) -> Option<Self> {
        if m.platform.is_some() {
            return None;
        }
        let a = m.arm.as_ref()?;
        let t = &a.turret;
        let turret_ok =
            t.com[0] == 0.0 && t.com[1] == 0.0 && t.inertia[0][2] == 0.0 && t.inertia[1][2] == 0.0;
        if !turret_ok || a.links.len() != 3 || !aligned(&a.gripper) {
            return None;
        }
        let mut bodies = [PitchBody {
            mass: 0.0,
            com: 0.0,
            jxx: 0.0,
            jzz: 0.0,
            length: 0.0,
        }; 4];
        for (k, l) in a.links.iter().enumerate() {
            if !aligned(&l.body()) {
                return None;
            }
            bodies[k] = PitchBody {
                mass: l.mass,
                com: l.com[0],
                jxx: l.inertia[0][0],
                jzz: l.inertia[2][2],
                length: l.length,
            };
        }
        let g = &a.gripper;
        bodies[3] = PitchBody {
            mass: g.mass,
            com: g.com[0],
            jxx: g.inertia[0][0],
            jzz: g.inertia[2][2],
            length: 0.0,
        };
        Some(ClosedFormArm {
            turret_jzz: t.inertia[2][2],
            bodies,
            friction1: a.joint_friction[0],
            gravity: m.gravity,
        })
    }

    fn pitch(th: &[f64; 4], thd: &[f64; 4]) -> ([f64; 4], [f64; 4]) {
        let b1 = th[1];
        let b2 = b1 + th[2];
        let b3 = b2 + th[3];
        let d1 = thd[1];
        let d2 = d1 + thd[2];
        let d3 = d2 + thd[3];
        ([b1, b2, b3, b3], [d1, d2, d3, d3])
    }

    /// ρ_k and ρ̇_k of the four pitch bodies.
    fn radii(&self, beta: &[f64; 4], dbeta: &[f64; 4]) -> ([f64; 4], [f64; 4]) {
        let mut rho = [0.0; 4];
        let mut drho = [0.0; 4];
        let (mut base, mut dbase) = (0.0, 0.0);
        for k in 0..4 {
            let b = &self.bodies[k];
            // `base` reaches the joint of body k (for the gripper, link 3's tip).
            rho[k] = base + b.com * beta[k].cos();
            drho[k] = dbase - b.com * beta[k].sin() * dbeta[k];
            if k < 3 {
                base += b.length * beta[k].cos();
                dbase -= b.length * beta[k].sin() * dbeta[k];
            }
        }
        (rho, drho)
    }

    /// Corrected eq. 38: the yaw inertia A(θ).
    pub fn yaw_inertia_corrected(&self, th: &[f64; 4]) -> f64 {
        let (beta, _) = Self::pitch(th, &[0.0; 4]);
        let (rho, _) = self.radii(&beta, &[0.0; 4]);
        self.turret_jzz
            + (0..4)
                .map(|k| {
                    let b = &self.bodies[k];
                    let (s, c) = beta[k].sin_cos();
                    b.mass * rho[k] * rho[k] + b.jxx * s * s + b.jzz * c * c
                })
                .sum::<f64>()
    }

    /// Corrected eq. 42: the velocity-product term Q = θ̇₁ Ȧ.
    pub fn q_corrected(&self, th: &[f64; 4], thd: &[f64; 4]) -> f64 {
        let (beta, dbeta) = Self::pitch(th, thd);
        let (rho, drho) = self.radii(&beta, &dbeta);
        thd[0]
            * (0..4)
                .map(|k| {
                    let b = &self.bodies[k];
                    2.0 * b.mass * rho[k] * drho[k]
                        + (b.jxx - b.jzz) * (2.0 * beta[k]).sin() * dbeta[k]
                })
                .sum::<f64>()
    }

    /// Corrected eq. 37: τ₁ = A θ̈₁ + Q + b₁ θ̇₁.
    pub fn tau1_corrected(&self, th: &[f64; 4], thd: &[f64; 4], thdd: &[f64; 4]) -> f64 {
        self.yaw_inertia_corrected(th) * thdd[0]
            + self.q_corrected(th, thd)
            + self.friction1 * thd[0]
    }

    /// The seed's symbols: l₁…l₃, m₁…m₃ (lumped at the link centres), m_c at the tip, m_b and
    /// r of the base disc (I_b = ½ m_b r², so m_b r² = 2 J_turret,zz).
    fn seed_symbols(&self) -> ([f64; 3], [f64; 3], f64, f64) {
        let l = [
            self.bodies[0].length,
            self.bodies[1].length,
            self.bodies[2].length,
        ];
        let m = [
            self.bodies[0].mass,
            self.bodies[1].mass,
            self.bodies[2].mass,
        ];
        (l, m, self.bodies[3].mass, 2.0 * self.turret_jzz)
    }

    /// Printed eq. 38, term by term as printed (w_c = m_c g).
    pub fn yaw_inertia_printed(&self, th: &[f64; 4]) -> f64 {
        let (l, m, mc, mb_r2) = self.seed_symbols();
        let wc = mc * self.gravity;
        let (c2, c23, c234) = (
            th[1].cos(),
            (th[1] + th[2]).cos(),
            (th[1] + th[2] + th[3]).cos(),
        );
        m[2] * (l[1] * c23 + l[0] * c2 + l[2] * c234 / 2.0).powi(2)
            + wc * (l[1] * c23 + l[0] * c2 + l[2] * c234).powi(2)
            + mb_r2
            + m[1] * (l[1] * c2 + 2.0 * l[0] * c2).powi(2) / 4.0
            + l[0] * l[0] * m[0] * c2 * c2 / 4.0
    }

    /// Printed eq. 42 as printed.
    pub fn q_printed(&self, th: &[f64; 4], thd: &[f64; 4]) -> f64 {
        let (l, m, mc, _) = self.seed_symbols();
        let wc = mc * self.gravity;
        let (s2, c2) = th[1].sin_cos();
        let (s23, c23) = (th[1] + th[2]).sin_cos();
        let (s234, c234) = (th[1] + th[2] + th[3]).sin_cos();
        let (d1, d2, d3, d4) = (thd[0], thd[1], thd[2], thd[3]);
        -(m[1]
            * d1
            * (2.0 * l[0] * d2 * s2 + l[1] * s23 * (d2 + d3))
            * (l[1] * c23 + 2.0 * l[0] * c2))
            / 2.0
            - 2.0
                * m[2]
                * d1
                * (l[0] * d2 * c2 + l[2] * s234 * (d2 + d3 + d4) / 2.0 + l[1] * s23 * (d2 + d3))
                * (l[1] * c23 + l[0] * c2 + l[2] * c234 / 2.0)
            - 2.0
                * d1
                * wc
                * (l[0] * d2 * s2 + l[2] * s234 * (d2 + d3 + d4) + l[1] * s23 * (d2 + d3))
                * (l[1] * c23 + l[0] * c2 + l[2] * c234)
            - l[0] * l[0] * m[0] * d1 * d2 * c2 * s2
    }

    /// Printed eq. 30: the gripper's potential energy w_c g (height of the tip).
    pub fn gripper_potential_printed(&self, th: &[f64; 4]) -> f64 {
        let (l, _, mc, _) = self.seed_symbols();
        let wc = mc * self.gravity;
        wc * self.gravity * self.tip_height(&l, th)
    }

    /// Corrected eq. 30: m_c g (height of the tip above the first pitch axis).
    pub fn gripper_potential_corrected(&self, th: &[f64; 4]) -> f64 {
        let (l, _, mc, _) = self.seed_symbols();
        mc * self.gravity * self.tip_height(&l, th)
    }

    fn tip_height(&self, l: &[f64; 3], th: &[f64; 4]) -> f64 {
        l[0] * th[1].sin() + l[1] * (th[1] + th[2]).sin() + l[2] * (th[1] + th[2] + th[3]).sin()
    }

    /// Printed eqs. 7–29 (pitch part, θ₁ fixed): T = Σ ½ m_k v_k² + ½ I_k ω_k² with
    /// I_k = m_k x_k² (x_k the horizontal coordinate of the mass centre, eqs. 11, 17, 23, 29)
    /// and ω_k the relative rate θ̇_{k+1} of eqs. 7, 13, 19, 25 (the gripper with θ̇₄).
    pub fn pitch_kinetic_printed(&self, th: &[f64; 4], thd: &[f64; 4]) -> f64 {
        let (beta, dbeta) = Self::pitch(th, thd);
        let (rho, drho) = self.radii(&beta, &dbeta);
        let heights = self.heights(&beta, &dbeta);
        let rel = [thd[1], thd[2], thd[3], thd[3]];
        (0..4)
            .map(|k| {
                let m = self.bodies[k].mass;
                let v2 = drho[k].powi(2) + heights.1[k].powi(2);
                0.5 * m * v2 + 0.5 * m * rho[k].powi(2) * rel[k].powi(2)
            })
            .sum()
    }

    /// Corrected pitch kinetic energy (θ₁ fixed): Σ ½ m_k v_k² + ½ J_k,yy β̇_k² with the
    /// absolute pitch rate β̇_k and the body's own central moment about the pitch axis.
    pub fn pitch_kinetic_corrected(&self, th: &[f64; 4], thd: &[f64; 4], jyy: &[f64; 4]) -> f64 {
        let (beta, dbeta) = Self::pitch(th, thd);
        let (_, drho) = self.radii(&beta, &dbeta);
        let heights = self.heights(&beta, &dbeta);
        (0..4)
            .map(|k| {
                let m = self.bodies[k].mass;
                0.5 * m * (drho[k].powi(2) + heights.1[k].powi(2)) + 0.5 * jyy[k] * dbeta[k].powi(2)
            })
            .sum()
    }

    /// Heights of the mass centres above the first pitch axis and their rates.
    fn heights(&self, beta: &[f64; 4], dbeta: &[f64; 4]) -> ([f64; 4], [f64; 4]) {
        let mut z = [0.0; 4];
        let mut dz = [0.0; 4];
        let (mut base, mut dbase) = (0.0, 0.0);
        for k in 0..4 {
            let b = &self.bodies[k];
            z[k] = base + b.com * beta[k].sin();
            dz[k] = dbase + b.com * beta[k].cos() * dbeta[k];
            if k < 3 {
                base += b.length * beta[k].sin();
                dbase += b.length * beta[k].cos() * dbeta[k];
            }
        }
        (z, dz)
    }
}

/// The platform's forward and yaw accelerations for side torques (τ_R, τ_L) from rest-free
/// motion of a symmetric platform (mass centre on the middle axle, no arm): printed eqs. 66–67
/// and the corrected forms from T = ½ m u² + ½ I ψ̇² + ½ J_side (φ̇_R² + φ̇_L²) with
/// u = r(φ̇_R + φ̇_L)/2, ψ̇ = r(φ̇_R − φ̇_L)/(2b):
///
/// ```text
/// printed:   u̇ = (τ_R + τ_L)/(m r),              ω̇ = I (τ_R + τ_L)/(I r)
/// corrected: u̇ = (τ_R + τ_L) r/(m r² + 2 J_side), ω̇ = (τ_R − τ_L) r b/(I r² + 2 J_side b²)
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatformClosedForm {
    pub mass: f64,
    pub yaw_inertia: f64,
    pub wheel_radius: f64,
    pub half_track: f64,
    pub side_spin_inertia: f64,
}

impl PlatformClosedForm {
    pub fn accelerations_printed(&self, tau_r: f64, tau_l: f64) -> (f64, f64) {
        let i = self.yaw_inertia;
        (
            (tau_r + tau_l) / (self.mass * self.wheel_radius),
            i * (tau_r + tau_l) / (i * self.wheel_radius),
        )
    }

    pub fn accelerations_corrected(&self, tau_r: f64, tau_l: f64) -> (f64, f64) {
        let (r, b, js) = (self.wheel_radius, self.half_track, self.side_spin_inertia);
        (
            (tau_r + tau_l) * r / (self.mass * r * r + 2.0 * js),
            (tau_r - tau_l) * r * b / (self.yaw_inertia * r * r + 2.0 * js * b * b),
        )
    }
}
