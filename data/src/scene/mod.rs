//! The scene model: what a problem *is*, independent of how it is discretized.
//!
//! A scene file is TOML. Exactly one model family is present:
//! * planar link chains — one or more `[[link]]` tables (each with its root `joint`), optional
//!   `[gravity]`, `[[contact]]`, `[statics]`, `[studies]`;
//! * `[rocket]` — the two-stage variable-mass free-free missile of seed 003;
//! * `[payload_link]` — the 3-D single link with a payload of seed 002;
//! * `[mobile_manipulator]` — the 8-DOF arm on a skid-steer platform of seed 004.
//!
//! Everything a scene does not switch on is off, and backends must not build it.

mod mobile;
mod payload;
mod planar;
mod rocket;

pub use mobile::{
    Arm, ArmLink, FlexibleLink, InitialState, MobileManipulator, Platform, RigidBody,
    TorqueSchedule,
};
pub use payload::{
    InitialShape as LinkInitialShape, KelvinVoigt3d, LinkField, Payload, PayloadLink,
};
pub use planar::{
    Contact, ContactMode, Gravity, Joint, Link, PrescribedMotion, Statics, Studies, Surface,
    TorqueLaw,
};
pub use rocket::{DiscreteMass, InitialShape, Rocket, RocketSpring, Stage};

use serde::{Deserialize, Serialize};

/// Output and run-length settings shared by every family.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    /// End time of a dynamic run (scene units of time).
    pub t_end: f64,
    /// Interval between stored output samples.
    pub output_interval: f64,
    /// Number of equally spaced stations (including both ends) at which elastic fields are
    /// sampled in the common observables.
    #[serde(default = "default_field_stations")]
    pub field_stations: usize,
}

fn default_field_stations() -> usize {
    11
}

/// One physical problem.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Catalog identifier (kebab-case).
    pub name: String,
    /// One-line description shown by `flexverify scenes`.
    pub description: String,
    /// The consistent unit system the numbers are written in, e.g. "SI (m, kg, s)".
    pub units: String,
    pub simulation: Simulation,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<Gravity>,
    #[serde(default, rename = "link", skip_serializing_if = "Vec::is_empty")]
    pub links: Vec<Link>,
    #[serde(default, rename = "contact", skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<Contact>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub statics: Option<Statics>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub studies: Option<Studies>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rocket: Option<Rocket>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub payload_link: Option<PayloadLink>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mobile_manipulator: Option<MobileManipulator>,
}

/// Which model family a scene belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    PlanarChain,
    Rocket,
    PayloadLink,
    MobileManipulator,
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Family::PlanarChain => "planar link chain",
            Family::Rocket => "variable-mass rocket",
            Family::PayloadLink => "3-D payload link",
            Family::MobileManipulator => "mobile manipulator",
        })
    }
}

impl Scene {
    /// The model family. Valid scenes (see [`crate::validate`]) have exactly one.
    pub fn family(&self) -> Family {
        if self.rocket.is_some() {
            Family::Rocket
        } else if self.payload_link.is_some() {
            Family::PayloadLink
        } else if self.mobile_manipulator.is_some() {
            Family::MobileManipulator
        } else {
            Family::PlanarChain
        }
    }

    /// Index of the link with the given name.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Physics switched on anywhere in the scene, as human-readable flags
    /// (used by `describe`; every entry is an effect a backend must build).
    pub fn physics_flags(&self) -> Vec<(&'static str, bool)> {
        if let Some(m) = &self.mobile_manipulator {
            let mut flags = m.physics_flags();
            flags.retain(|(_, on)| *on);
            return flags;
        }
        let any = |f: fn(&Link) -> bool| self.links.iter().any(f);
        let mut flags = vec![
            ("gravity", self.gravity.is_some()),
            ("axial", any(|l| l.axial)),
            ("foreshortening", any(|l| l.foreshortening)),
            ("shear", any(|l| l.shear)),
            ("rotary_inertia", any(|l| l.rotary_inertia)),
            ("kelvin_voigt", any(|l| l.kelvin_voigt.is_some())),
            ("tip_mass", any(|l| l.tip_mass.is_some())),
            ("tip_inertia", any(|l| l.tip_inertia.is_some())),
            ("hub_inertia", any(|l| l.joint.hub_inertia.is_some())),
            (
                "joint_spring",
                any(|l| l.joint.stiffness.is_some_and(|k| k > 0.0)),
            ),
            (
                "joint_damper",
                any(|l| l.joint.damping.is_some_and(|d| d > 0.0)),
            ),
            ("joint_torque", any(|l| l.joint.torque.is_some())),
            ("prescribed_motion", any(|l| l.joint.prescribed.is_some())),
            ("contact", !self.contacts.is_empty()),
            ("friction", self.contacts.iter().any(|c| c.friction > 0.0)),
        ];
        if let Some(p) = &self.payload_link {
            return p.physics_flags();
        }
        if self.family() != Family::PlanarChain {
            flags.retain(|(_, on)| *on);
        }
        flags
    }
}
