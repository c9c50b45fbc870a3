//! Two-stage variable-mass free-free flexible missile (seed 003, scenes.md `rocket`).
//!
//! x runs from the aft end (nozzle, x = 0) to the nose (x = L). Stage 1 occupies 0 ≤ x ≤ L₁ and
//! burns uniformly; stage 2 (instruments, constant mass) occupies L₁ ≤ x ≤ L. Masses are given as
//! *weights* per length (the report's m g), so the mass per length is weight / `gravity`.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rocket {
    /// Standard gravity g used both as the field strength and to turn weights into masses.
    pub gravity: f64,
    /// Launch angle θ₀ of the body axis from the horizontal \[deg\].
    pub launch_angle_deg: f64,
    /// Young's modulus E (same for both stages).
    pub youngs_modulus: f64,
    /// Effective exhaust velocity v_e.
    pub exhaust_velocity: f64,
    /// Chamber pressure p.
    pub chamber_pressure: f64,
    /// Exit pressure p_e (0 in vacuum).
    #[serde(default)]
    pub exit_pressure: f64,
    /// Port (flow) area A_f of the stage-1 grain.
    pub port_area: f64,
    /// Nozzle misalignment angle γ \[deg\] (0 = aligned).
    #[serde(default)]
    pub nozzle_angle_deg: f64,
    /// Stages from aft to nose; the first one burns.
    #[serde(rename = "stage")]
    pub stages: Vec<Stage>,
    /// Discrete masses (instrument packages) carried on springs.
    #[serde(
        default,
        rename = "discrete_mass",
        skip_serializing_if = "Vec::is_empty"
    )]
    pub discrete_masses: Vec<DiscreteMass>,
    /// Springs between discrete masses.
    #[serde(default, rename = "spring", skip_serializing_if = "Vec::is_empty")]
    pub springs: Vec<RocketSpring>,
    /// Initial transverse shape w(x, 0).
    pub initial_shape: InitialShape,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    pub length: f64,
    /// Load-carrying casing area A_c (for EA).
    pub area: f64,
    /// Second moment of area I (for EI).
    pub inertia: f64,
    /// Weight per length at ignition, m g.
    pub weight_per_length: f64,
    /// Burn rate as weight per length per time, ṁ g (0 for a non-burning stage).
    #[serde(default)]
    pub burn_rate: f64,
    /// Weight per length that cannot burn (casing); the burn stops when reached.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub casing_weight_per_length: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteMass {
    /// Station x of the attachment.
    pub position: f64,
    /// Weight M g.
    pub weight: f64,
    /// Axial spring to the case, k_u (force per length).
    pub axial_stiffness: f64,
    /// Transverse spring to the case, k_w.
    pub transverse_stiffness: f64,
    #[serde(default)]
    pub axial_damping: f64,
    #[serde(default)]
    pub transverse_damping: f64,
}

/// Spring between two discrete masses (indices into `discrete_mass`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RocketSpring {
    pub between: [usize; 2],
    pub axial_stiffness: f64,
    pub transverse_stiffness: f64,
    #[serde(default)]
    pub axial_damping: f64,
    #[serde(default)]
    pub transverse_damping: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum InitialShape {
    /// w(x,0) = a1 (sin πx/L − 2/π) + a2 (3/π − 6x/(πL) − sin 2πx/L), in length units.
    Report { a1: f64, a2: f64 },
    /// Straight body at rest.
    Straight,
}

impl InitialShape {
    /// w(x, 0) for a body of length `length`.
    pub fn deflection(&self, x: f64, length: f64) -> f64 {
        use std::f64::consts::PI;
        match *self {
            InitialShape::Report { a1, a2 } => {
                a1 * ((PI * x / length).sin() - 2.0 / PI)
                    + a2 * (3.0 / PI - 6.0 * x / (PI * length) - (2.0 * PI * x / length).sin())
            }
            InitialShape::Straight => 0.0,
        }
    }
}

impl Rocket {
    /// Total length Σ stage lengths.
    pub fn length(&self) -> f64 {
        self.stages.iter().map(|s| s.length).sum()
    }
}
