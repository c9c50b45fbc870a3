//! Four-joint arm on a six-wheel skid-steer platform (seed 004, 8 DOF, rigid model with the
//! paper's errors corrected; optional flexible link 2).

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MobileManipulator {
    /// Arm link lengths l₂, l₃, l₄ (pitch links).
    pub link_lengths: [f64; 3],
    pub link_masses: [f64; 3],
    pub gripper_mass: f64,
    pub base_disc_mass: f64,
    pub base_disc_radius: f64,
    pub platform_mass: f64,
    pub wheel_count: usize,
    pub wheel_mass: f64,
    pub wheel_radius: f64,
    pub half_track: f64,
    pub initial_heading: f64,
    /// Arm joint torque pulses ±amplitude with this period.
    pub arm_torque_amplitude: f64,
    pub arm_torque_period: f64,
    /// Wheel-side torque of the platform drive.
    pub platform_torque: f64,
    /// Flexible variant: bending stiffness EI of link 2 (rigid when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flexible_link2_bending_stiffness: Option<f64>,
}
