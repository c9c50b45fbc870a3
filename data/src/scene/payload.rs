//! 3-D single flexible link carrying an offset payload (seed 002).
//! Fields u (axial), v, w (bending), φ (torsion) of a circular rod on a rotating base.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadLink {
    pub length: f64,
    pub radius: f64,
    pub youngs_modulus: f64,
    pub shear_modulus: f64,
    pub density: f64,
    pub payload_mass: f64,
    /// Payload centre-of-mass offset c beyond the tip along the link axis.
    pub payload_offset: f64,
    /// Payload principal inertias about its centre of mass.
    pub payload_inertia: [f64; 3],
    pub base_inertia: f64,
    /// Viscous motor friction b_m.
    pub motor_friction: f64,
    /// Kelvin–Voigt coefficients [C_X, C_Y, C_Z, C_Φ].
    pub kelvin_voigt: [f64; 4],
    /// Gravity vector [gx, gy, gz].
    pub gravity: [f64; 3],
}
