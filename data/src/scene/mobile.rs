//! The mobile manipulator of seed 004: a skid-steer platform (wheels grouped per side, no
//! sideways slip, rolling without longitudinal slip) carrying an arm with a yaw joint θ₁ on a
//! turret and three pitch joints θ₂…θ₄, with a gripper/payload at the tip.
//!
//! Either part may be absent: without `[mobile_manipulator.platform]` the arm stands on fixed
//! ground (its mount is then an inertial point, heading `initial.heading`); without
//! `[mobile_manipulator.arm]` only the platform moves. Coordinates (verify's rigid reference):
//! platform x, y, heading ψ, side wheel angles φ_R, φ_L; joint angles θ₁…θ₄.
//!
//! Frames: z is up, gravity acts along −z. The platform frame has its origin at the centre of
//! the middle axle (ground-projected), x forward, y to the left. The turret (yaw joint θ₁ about
//! the platform's z axis) sits at `arm.mount`; the first pitch axis is `arm.base_height` above
//! the mount, along the turret's −y axis so that θ₂ > 0 raises the arm. Each pitch link lies
//! along its own x axis; link k's frame is the turret frame pitched by θ₂ + … + θ_{k+1}.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MobileManipulator {
    /// Gravitational acceleration (magnitude, along −z).
    pub gravity: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub platform: Option<Platform>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm: Option<Arm>,
    #[serde(default)]
    pub initial: InitialState,
    /// Flexible variant: the named pitch link as a beam (the backends' model; the rigid
    /// reference ignores it and runs the EI → ∞ limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flexible_link: Option<FlexibleLink>,
}

/// The skid-steer platform. Wheels sit on `wheel_count / 2` equally spaced axles spanning
/// `wheelbase`, at ±`half_track`; all wheels of a side roll together (chain-coupled), so the
/// side torque τ_R or τ_L is the sum over that side's driven wheels (seed eq. 49).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Platform {
    /// Chassis mass without wheels.
    pub chassis_mass: f64,
    /// Chassis moment of inertia about the vertical axis through its own mass centre.
    pub chassis_yaw_inertia: f64,
    /// Forward offset of the chassis mass centre from the middle-axle centre.
    #[serde(default)]
    pub chassis_com_offset: f64,
    pub wheel_count: usize,
    pub wheel_radius: f64,
    pub wheel_mass: f64,
    /// Moment of inertia of one wheel about its axle (spin).
    pub wheel_spin_inertia: f64,
    /// Moment of inertia of one wheel about a diameter (what platform yaw turns).
    pub wheel_diametral_inertia: f64,
    /// Distance between front and rear axles.
    pub wheelbase: f64,
    /// Half the distance between the left and right wheel planes.
    pub half_track: f64,
    /// Axles (1-based, front to rear) whose wheels carry a motor; the side torque is shared
    /// equally among that side's driven wheels.
    pub driven_axles: Vec<usize>,
    /// Viscous friction of one wheel bearing, b_w (torque per unit spin rate).
    #[serde(default)]
    pub wheel_friction: f64,
    /// Side torques [τ_R, τ_L] (each the sum over that side's driven wheels).
    pub drive: TorqueSchedule,
}

/// The platform as the equations of motion see it: the chassis and all its wheels composed
/// into one rigid body on the platform frame, plus the two wheel sides (each side's wheels
/// spin together).
#[derive(Debug, Clone, PartialEq)]
pub struct PlatformComposite {
    /// Total mass: chassis plus wheels.
    pub mass: f64,
    /// Forward offset of the composite mass centre from the middle-axle centre.
    pub com_offset: f64,
    /// Yaw inertia about the vertical axis through the composite mass centre: the chassis's own
    /// and its parallel-axis term, each wheel's point mass at its axle end (±`half_track`) and
    /// its diametral inertia.
    pub yaw_inertia: f64,
    pub wheel_radius: f64,
    pub half_track: f64,
    /// Spin inertia of one side's wheels.
    pub side_spin_inertia: f64,
    /// Viscous friction of one side's wheel bearings.
    pub side_friction: f64,
}

impl Platform {
    /// Number of axles (two wheels each).
    pub fn axles(&self) -> usize {
        self.wheel_count / 2
    }

    /// Forward positions of the axles from the middle-axle centre, front to rear: equally
    /// spaced over the wheelbase, symmetric about that centre (0 for a single axle).
    pub fn axle_positions(&self) -> Vec<f64> {
        let axles = self.axles();
        (0..axles)
            .map(|k| {
                if axles == 1 {
                    0.0
                } else {
                    self.wheelbase * (0.5 - k as f64 / (axles - 1) as f64)
                }
            })
            .collect()
    }

    /// The chassis and wheels composed about their common mass centre, and the wheel sides.
    pub fn composite(&self) -> PlatformComposite {
        let wheels_per_side = self.axles() as f64;
        let mw = self.wheel_mass;
        let mass = self.chassis_mass + self.wheel_count as f64 * mw;
        let xs = self.axle_positions();
        let com_offset = (self.chassis_mass * self.chassis_com_offset
            + 2.0 * mw * xs.iter().sum::<f64>())
            / mass;
        let mut yaw = self.chassis_yaw_inertia
            + self.chassis_mass * (self.chassis_com_offset - com_offset).powi(2);
        for &x in &xs {
            yaw += 2.0
                * (mw * ((x - com_offset).powi(2) + self.half_track.powi(2))
                    + self.wheel_diametral_inertia);
        }
        PlatformComposite {
            mass,
            com_offset,
            yaw_inertia: yaw,
            wheel_radius: self.wheel_radius,
            half_track: self.half_track,
            side_spin_inertia: wheels_per_side * self.wheel_spin_inertia,
            side_friction: wheels_per_side * self.wheel_friction,
        }
    }
}

/// A rigid body in its own frame: mass, centre of mass, inertia tensor about the centre of mass.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBody {
    pub mass: f64,
    /// Centre of mass in the body frame.
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass in body axes (symmetric, positive definite).
    pub inertia: [[f64; 3]; 3],
}

/// One pitch link: its length (joint to next joint along its x axis) and body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmLink {
    pub length: f64,
    pub mass: f64,
    /// Centre of mass in the link frame (origin at the joint, x along the link).
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass in link axes.
    pub inertia: [[f64; 3]; 3],
}

impl ArmLink {
    pub fn body(&self) -> RigidBody {
        RigidBody {
            mass: self.mass,
            com: self.com,
            inertia: self.inertia,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arm {
    /// Yaw-joint base point in the platform frame (or inertial when there is no platform).
    pub mount: [f64; 3],
    /// Height of the first pitch axis above the mount.
    pub base_height: f64,
    /// Turret (rotates with θ₁), frame at the mount.
    pub turret: RigidBody,
    /// The three pitch links, base to tip.
    pub links: Vec<ArmLink>,
    /// Gripper and payload as one rigid body in the last link's frame, origin at its tip.
    pub gripper: RigidBody,
    /// Viscous joint friction b₁…b₄ (Rayleigh D = ½ Σ bᵢ θ̇ᵢ²).
    pub joint_friction: [f64; 4],
    /// Joint torques [τ₁, τ₂, τ₃, τ₄].
    pub torques: TorqueSchedule,
}

/// Piecewise-constant torque inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum TorqueSchedule {
    /// Square pulses (seed 004's test input): bias + amplitude during the first half of each
    /// period, bias − amplitude during the second.
    Pulses {
        amplitude: Vec<f64>,
        period: f64,
        #[serde(default)]
        bias: Vec<f64>,
    },
    /// `values[k]` holds on `[times[k], times[k+1])` (the last one to the end); zero before
    /// `times[0]`. Accelerate–cruise–decelerate paths are written this way.
    Steps {
        times: Vec<f64>,
        values: Vec<Vec<f64>>,
    },
}

impl TorqueSchedule {
    /// Number of inputs per sample the schedule provides (None when it has no entries).
    pub fn width(&self) -> Option<usize> {
        match self {
            TorqueSchedule::Pulses { amplitude, .. } => Some(amplitude.len()),
            TorqueSchedule::Steps { values, .. } => values.first().map(Vec::len),
        }
    }

    /// Torque i at time t (inputs beyond the schedule's width are zero).
    pub fn torque(&self, i: usize, t: f64) -> f64 {
        match self {
            TorqueSchedule::Pulses {
                amplitude,
                period,
                bias,
            } => {
                let b = bias.get(i).copied().unwrap_or(0.0);
                let a = amplitude.get(i).copied().unwrap_or(0.0);
                let phase = (t / period).rem_euclid(1.0);
                if phase < 0.5 { b + a } else { b - a }
            }
            TorqueSchedule::Steps { times, values } => match times.iter().rposition(|&s| s <= t) {
                Some(k) => values[k].get(i).copied().unwrap_or(0.0),
                None => 0.0,
            },
        }
    }

    /// Discontinuities inside (0, t_end), sorted.
    pub fn breakpoints(&self, t_end: f64) -> Vec<f64> {
        let mut b: Vec<f64> = match self {
            TorqueSchedule::Pulses { period, .. } => {
                let half = 0.5 * period;
                let n = (t_end / half).ceil() as usize;
                (1..=n).map(|k| k as f64 * half).collect()
            }
            TorqueSchedule::Steps { times, .. } => times.clone(),
        };
        b.retain(|&t| t > 0.0 && t < t_end);
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
}

/// Initial configuration and rates. Platform velocity follows from the wheel rates (the
/// constraints leave no other choice).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialState {
    #[serde(default)]
    pub x: f64,
    #[serde(default)]
    pub y: f64,
    /// Platform heading ψ from the inertial x axis (seed: 0.7854).
    #[serde(default)]
    pub heading: f64,
    #[serde(default)]
    pub joint_angles: [f64; 4],
    #[serde(default)]
    pub joint_rates: [f64; 4],
    /// Side wheel spin rates [φ̇_R, φ̇_L].
    #[serde(default)]
    pub wheel_rates: [f64; 2],
}

/// A pitch link modelled as a beam bending in and out of the arm's plane: a uniform
/// Euler–Bernoulli beam of the link's mass clamped at its joint, plus the residual rigid inertia
/// J − diag(0, mL²/12, mL²/12) (validated: mass centre at (L/2, 0, 0), residual positive
/// semi-definite), so that EI → ∞ is the rigid link exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlexibleLink {
    /// Which pitch link (1..=3, base to tip).
    pub link: usize,
    /// Bending stiffness in the arm's plane (about the pitch axis).
    pub bending_stiffness_in_plane: f64,
    /// Bending stiffness out of the arm's plane (about the link's z axis).
    pub bending_stiffness_out_of_plane: f64,
}

impl MobileManipulator {
    /// Physics switched on, for `describe`.
    pub fn physics_flags(&self) -> Vec<(&'static str, bool)> {
        let arm = self.arm.as_ref();
        let platform = self.platform.as_ref();
        vec![
            ("platform", platform.is_some()),
            ("nonholonomic_constraints", platform.is_some()),
            (
                "wheel_friction",
                platform.is_some_and(|p| p.wheel_friction > 0.0),
            ),
            ("arm", arm.is_some()),
            ("gravity", arm.is_some() && self.gravity != 0.0),
            (
                "joint_friction",
                arm.is_some_and(|a| a.joint_friction.iter().any(|&b| b > 0.0)),
            ),
            ("payload", arm.is_some_and(|a| a.gripper.mass > 0.0)),
            ("flexible_link", self.flexible_link.is_some()),
        ]
    }
}
