//! 3-D single flexible link carrying an offset payload (seed 002).
//!
//! A base turns about the inertial vertical Z by the angle θ (joint 1). A circular rod of radius R
//! and length L is clamped to it along the turning frame's x axis. Its fields, functions of the
//! arc length x ∈ [0, L]:
//! * u — axial stretch (strain energy ½EA∫u′²),
//! * v — deflection in the turning plane (frame y; ½EI∫v″²),
//! * w — vertical deflection (frame z; ½EI∫w″²),
//! * φ — torsion about the rod axis (½GJ∫φ′²), with A = πR², I = πR⁴/4, J = πR⁴/2.
//!
//! The deformation field is the seed's second-order one: the section at x sits at
//! (x + u − ½∫₀ˣ(v′² + w′²), v, w) in the turning frame (foreshortening) and its orientation is the
//! seed's second-order rotation matrix. The payload is a rigid body whose centre of mass lies at
//! distance `offset` (c) beyond the tip along the tip section's axis; its inertia matrix is given
//! about its centre of mass in the tip section's axes (x along the rod, y in the turning plane, z
//! up). Gravity acts along −Z. Kelvin–Voigt damping adds C·ε̇ to each stress (C_X on u′, C_Y on
//! v″, C_Z on w″, C_Φ on φ′); the motor adds viscous friction b_m θ̇ (the base joint's `damping`).

use serde::{Deserialize, Serialize};

use super::planar::Joint;

/// One elastic field of the 3-D link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinkField {
    /// u: axial stretch.
    Axial,
    /// v: bending in the turning plane.
    Horizontal,
    /// w: bending out of the turning plane (along Z).
    Vertical,
    /// φ: twist about the rod axis.
    Torsion,
}

impl LinkField {
    pub const ALL: [LinkField; 4] = [
        LinkField::Axial,
        LinkField::Horizontal,
        LinkField::Vertical,
        LinkField::Torsion,
    ];

    pub fn name(self) -> &'static str {
        match self {
            LinkField::Axial => "axial",
            LinkField::Horizontal => "horizontal",
            LinkField::Vertical => "vertical",
            LinkField::Torsion => "torsion",
        }
    }

    /// The symbol the seed uses for the field.
    pub fn symbol(self) -> &'static str {
        match self {
            LinkField::Axial => "u",
            LinkField::Horizontal => "v",
            LinkField::Vertical => "w",
            LinkField::Torsion => "phi",
        }
    }
}

fn all_fields() -> Vec<LinkField> {
    LinkField::ALL.to_vec()
}

/// Rigid payload at the tip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Payload {
    /// Mass m_p.
    pub mass: f64,
    /// Distance c of the centre of mass beyond the tip along the tip section's axis.
    #[serde(default)]
    pub offset: f64,
    /// Inertia matrix I_p about the centre of mass in the tip section's axes,
    /// [[I₁, I₄, I₅], [I₄, I₂, I₆], [I₅, I₆, I₃]] (the seed's numbering). Must be symmetric and
    /// positive definite, and satisfy the triangle inequalities of a physical body.
    pub inertia: [[f64; 3]; 3],
}

impl Payload {
    /// Whether the payload's principal axes are the tip section's axes (no products of inertia).
    pub fn is_diagonal(&self) -> bool {
        let i = &self.inertia;
        i[0][1] == 0.0 && i[0][2] == 0.0 && i[1][2] == 0.0
    }
}

/// Kelvin–Voigt coefficients of the rod material (seed eq. 13), each optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KelvinVoigt3d {
    /// C_X: axial, σ = C_X u̇′.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial: Option<f64>,
    /// C_Y: bending in the turning plane, σ = C_Y y v̇″.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub horizontal: Option<f64>,
    /// C_Z: vertical bending, σ = C_Z z ẇ″.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertical: Option<f64>,
    /// C_Φ: torsion, τ = C_Φ r φ̇′.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torsion: Option<f64>,
}

impl KelvinVoigt3d {
    /// The coefficient acting on a field (None when off).
    pub fn of(&self, field: LinkField) -> Option<f64> {
        match field {
            LinkField::Axial => self.axial,
            LinkField::Horizontal => self.horizontal,
            LinkField::Vertical => self.vertical,
            LinkField::Torsion => self.torsion,
        }
        .filter(|c| *c > 0.0)
    }
}

/// The rod's state at t = 0.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InitialShape {
    /// Straight and at rest relative to the base.
    #[default]
    Undeformed,
    /// The linear static deflection under gravity (payload weight, its offset moment and the
    /// rod's self-weight), at rest relative to the base.
    StaticSag,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadLink {
    /// Undeformed length L.
    pub length: f64,
    /// Cross-section radius R (circular section).
    pub radius: f64,
    /// Young's modulus E.
    pub youngs_modulus: f64,
    /// Shear modulus G.
    pub shear_modulus: f64,
    /// Density ρ.
    pub density: f64,
    /// The elastic fields the rod carries (all four when absent). A field left out is held at zero
    /// and never built.
    #[serde(default = "all_fields")]
    pub fields: Vec<LinkField>,
    pub payload: Payload,
    /// The base joint θ about Z: `hub_inertia` is I_B, `damping` the motor friction b_m, `torque`
    /// the motor torque T_mot or `prescribed` the base motion; `initial_angle`/`initial_rate` θ(0),
    /// θ̇(0).
    pub base: Joint,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kelvin_voigt: Option<KelvinVoigt3d>,
    /// Gravitational acceleration g (acting along −Z); no gravity when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<f64>,
    #[serde(default)]
    pub initial_shape: InitialShape,
}

impl PayloadLink {
    /// Cross-section area A = πR².
    pub fn area(&self) -> f64 {
        std::f64::consts::PI * self.radius * self.radius
    }
    /// Second moment of area about either bending axis, I = πR⁴/4.
    pub fn second_moment(&self) -> f64 {
        std::f64::consts::PI * self.radius.powi(4) / 4.0
    }
    /// Polar moment of area J = πR⁴/2.
    pub fn polar_moment(&self) -> f64 {
        std::f64::consts::PI * self.radius.powi(4) / 2.0
    }
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.area()
    }
    pub fn axial_stiffness(&self) -> f64 {
        self.youngs_modulus * self.area()
    }
    pub fn bending_stiffness(&self) -> f64 {
        self.youngs_modulus * self.second_moment()
    }
    pub fn torsional_stiffness(&self) -> f64 {
        self.shear_modulus * self.polar_moment()
    }
    /// Whether the rod carries a field.
    pub fn has(&self, field: LinkField) -> bool {
        self.fields.contains(&field)
    }
    /// The Kelvin–Voigt coefficient on a carried field (None when off or the field is absent).
    pub fn kelvin_voigt_on(&self, field: LinkField) -> Option<f64> {
        if !self.has(field) {
            return None;
        }
        self.kelvin_voigt.as_ref().and_then(|k| k.of(field))
    }
    /// Motor friction b_m (0 when absent).
    pub fn motor_friction(&self) -> f64 {
        self.base.damping.unwrap_or(0.0)
    }
    /// Base inertia I_B (0 when absent).
    pub fn base_inertia(&self) -> f64 {
        self.base.hub_inertia.unwrap_or(0.0)
    }
}

impl PayloadLink {
    /// Physics the scene switches on, as `describe` lists it (every entry is something a backend
    /// must build).
    pub fn physics_flags(&self) -> Vec<(&'static str, bool)> {
        let kv = |f| self.kelvin_voigt_on(f).is_some();
        vec![
            ("axial", self.has(LinkField::Axial)),
            ("horizontal_bending", self.has(LinkField::Horizontal)),
            ("vertical_bending", self.has(LinkField::Vertical)),
            ("torsion", self.has(LinkField::Torsion)),
            ("foreshortening", true),
            ("gravity", self.gravity.is_some_and(|g| g != 0.0)),
            ("payload_offset", self.payload.offset != 0.0),
            ("payload_products_of_inertia", !self.payload.is_diagonal()),
            ("kelvin_voigt_axial", kv(LinkField::Axial)),
            ("kelvin_voigt_horizontal", kv(LinkField::Horizontal)),
            ("kelvin_voigt_vertical", kv(LinkField::Vertical)),
            ("kelvin_voigt_torsion", kv(LinkField::Torsion)),
            ("hub_inertia", self.base_inertia() > 0.0),
            ("joint_damper", self.motor_friction() > 0.0),
            ("joint_spring", self.base.stiffness.is_some_and(|k| k > 0.0)),
            ("joint_torque", self.base.torque.is_some()),
            ("prescribed_motion", self.base.prescribed.is_some()),
            (
                "static_sag_start",
                self.initial_shape == InitialShape::StaticSag,
            ),
        ]
    }
}
