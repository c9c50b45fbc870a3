//! The scene model: what a problem *is*, independent of how it is discretized.
//!
//! A scene file is TOML. Exactly one model family is present:
//! * planar link chains — one or more `[[link]]` tables (each with its root `joint`), optional
//!   `[gravity]`, `[[contact]]`, `[statics]`, `[studies]`;
//! * `[rocket]` — the two-stage variable-mass free-free missile of seed 003;
//! * `[payload_link]` — the 3-D single link with a payload of seed 002;
//! * `[mobile_manipulator]` — the 8-DOF arm on a skid-steer platform of seed 004.
//!
//! Reading checks the file's layout ([`SceneFile`]) and converts it into a [`Scene`]: shared
//! metadata and [`Simulation`] settings beside a [`Model`], the one family as a type
//! ([`PlanarChain`], [`Rocket`], [`PayloadLink`], [`MobileManipulator`]). Backends match on
//! the model at their entry point and pass the family down.
//!
//! Everything a scene does not switch on is off, and backends must not build it.

mod mobile;
mod payload;
mod planar;
mod rocket;

pub use mobile::{
    Arm, ArmLink, FlexibleLink, InitialState, MobileManipulator, Platform, PlatformComposite,
    RigidBody, TorqueSchedule,
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

/// One physical problem: shared metadata and run settings, and the model of one family.
///
/// Serialized with the scene-file layout ([`SceneFile`]): the family's tables sit at the top
/// level of the document (`[[link]]`, `[rocket]`, …), not under a `model` key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SceneFile", into = "SceneFile")]
pub struct Scene {
    /// Catalog identifier (kebab-case).
    pub name: String,
    /// One-line description shown by `flexverify scenes`.
    pub description: String,
    /// The consistent unit system the numbers are written in, e.g. "SI (m, kg, s)".
    pub units: String,
    pub simulation: Simulation,
    pub model: Model,
}

/// The model of a scene; exactly one family.
// A scene exists once per run and is never stored in bulk: the variants stay unboxed so that
// backends bind the family directly.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    /// A planar chain of flexible links joined at revolute joints.
    PlanarChain(PlanarChain),
    /// The two-stage variable-mass free-free missile of seed 003.
    Rocket(Rocket),
    /// The 3-D single flexible link carrying a payload of seed 002.
    PayloadLink(PayloadLink),
    /// The 8-DOF arm on a skid-steer platform of seed 004.
    MobileManipulator(MobileManipulator),
}

/// A planar chain of flexible links: the links (each with its root joint), and the effects and
/// studies that exist only for planar chains.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlanarChain {
    /// Uniform gravity in the plane of motion.
    pub gravity: Option<Gravity>,
    /// The links, root first; link `i + 1` is jointed to the tip of link `i`.
    pub links: Vec<Link>,
    /// Unilateral contacts of link points against fixed surfaces.
    pub contacts: Vec<Contact>,
    /// Static load cases.
    pub statics: Option<Statics>,
    /// Parameter studies (e.g. rotation speeds).
    pub studies: Option<Studies>,
}

impl PlanarChain {
    /// Index of the link with the given name.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Effects switched on in the chain, as human-readable flags (all listed, on or off).
    pub fn physics_flags(&self) -> Vec<(&'static str, bool)> {
        let any = |f: fn(&Link) -> bool| self.links.iter().any(f);
        vec![
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
        ]
    }
}

/// The layout of a scene file: every family's tables optional at the top level. Reading
/// checks it ([`crate::validate::scene_file::check_file`]: exactly one family, planar-only
/// tables only with links) and converts it into a [`Scene`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: String,
    pub description: String,
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

/// A scene file whose tables do not make exactly one model family.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ModelShapeError(pub String);

impl TryFrom<SceneFile> for Scene {
    type Error = ModelShapeError;

    fn try_from(f: SceneFile) -> Result<Self, Self::Error> {
        let planar_only = f.gravity.is_some()
            || !f.contacts.is_empty()
            || f.statics.is_some()
            || f.studies.is_some();
        let model = match (
            !f.links.is_empty(),
            f.rocket,
            f.payload_link,
            f.mobile_manipulator,
        ) {
            (true, None, None, None) => Model::PlanarChain(PlanarChain {
                gravity: f.gravity,
                links: f.links,
                contacts: f.contacts,
                statics: f.statics,
                studies: f.studies,
            }),
            (false, Some(r), None, None) if !planar_only => Model::Rocket(r),
            (false, None, Some(p), None) if !planar_only => Model::PayloadLink(p),
            (false, None, None, Some(m)) if !planar_only => Model::MobileManipulator(m),
            (false, None, None, None) => {
                return Err(ModelShapeError("the scene defines no model".into()));
            }
            _ => {
                return Err(ModelShapeError(
                    "a scene has exactly one model family; gravity, contact, statics and \
                     studies apply only to planar link chains"
                        .into(),
                ));
            }
        };
        Ok(Scene {
            name: f.name,
            description: f.description,
            units: f.units,
            simulation: f.simulation,
            model,
        })
    }
}

impl From<Scene> for SceneFile {
    fn from(s: Scene) -> Self {
        let mut f = SceneFile {
            name: s.name,
            description: s.description,
            units: s.units,
            simulation: s.simulation,
            gravity: None,
            links: Vec::new(),
            contacts: Vec::new(),
            statics: None,
            studies: None,
            rocket: None,
            payload_link: None,
            mobile_manipulator: None,
        };
        match s.model {
            Model::PlanarChain(c) => {
                f.gravity = c.gravity;
                f.links = c.links;
                f.contacts = c.contacts;
                f.statics = c.statics;
                f.studies = c.studies;
            }
            Model::Rocket(r) => f.rocket = Some(r),
            Model::PayloadLink(p) => f.payload_link = Some(p),
            Model::MobileManipulator(m) => f.mobile_manipulator = Some(m),
        }
        f
    }
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
    /// The model family.
    pub fn family(&self) -> Family {
        match &self.model {
            Model::PlanarChain(_) => Family::PlanarChain,
            Model::Rocket(_) => Family::Rocket,
            Model::PayloadLink(_) => Family::PayloadLink,
            Model::MobileManipulator(_) => Family::MobileManipulator,
        }
    }

    /// The planar chain, if the scene is one.
    pub fn planar_chain(&self) -> Option<&PlanarChain> {
        match &self.model {
            Model::PlanarChain(c) => Some(c),
            _ => None,
        }
    }

    /// The planar chain, mutably, if the scene is one.
    pub fn planar_chain_mut(&mut self) -> Option<&mut PlanarChain> {
        match &mut self.model {
            Model::PlanarChain(c) => Some(c),
            _ => None,
        }
    }

    /// The links of a planar chain (none for the other families).
    pub fn links(&self) -> &[Link] {
        self.planar_chain().map_or(&[], |c| c.links.as_slice())
    }

    /// The contacts of a planar chain (none for the other families).
    pub fn contacts(&self) -> &[Contact] {
        self.planar_chain().map_or(&[], |c| c.contacts.as_slice())
    }

    /// The gravity of a planar chain (the other families carry their own).
    pub fn gravity(&self) -> Option<&Gravity> {
        self.planar_chain().and_then(|c| c.gravity.as_ref())
    }

    /// The static load cases of a planar chain.
    pub fn statics(&self) -> Option<&Statics> {
        self.planar_chain().and_then(|c| c.statics.as_ref())
    }

    /// The parameter studies of a planar chain.
    pub fn studies(&self) -> Option<&Studies> {
        self.planar_chain().and_then(|c| c.studies.as_ref())
    }

    /// Index of the planar-chain link with the given name.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.planar_chain().and_then(|c| c.link_index(name))
    }

    /// The rocket, if the scene is one.
    pub fn rocket(&self) -> Option<&Rocket> {
        match &self.model {
            Model::Rocket(r) => Some(r),
            _ => None,
        }
    }

    /// The rocket, mutably, if the scene is one.
    pub fn rocket_mut(&mut self) -> Option<&mut Rocket> {
        match &mut self.model {
            Model::Rocket(r) => Some(r),
            _ => None,
        }
    }

    /// The payload link, if the scene is one.
    pub fn payload_link(&self) -> Option<&PayloadLink> {
        match &self.model {
            Model::PayloadLink(p) => Some(p),
            _ => None,
        }
    }

    /// The payload link, mutably, if the scene is one.
    pub fn payload_link_mut(&mut self) -> Option<&mut PayloadLink> {
        match &mut self.model {
            Model::PayloadLink(p) => Some(p),
            _ => None,
        }
    }

    /// The mobile manipulator, if the scene is one.
    pub fn mobile_manipulator(&self) -> Option<&MobileManipulator> {
        match &self.model {
            Model::MobileManipulator(m) => Some(m),
            _ => None,
        }
    }

    /// The mobile manipulator, mutably, if the scene is one.
    pub fn mobile_manipulator_mut(&mut self) -> Option<&mut MobileManipulator> {
        match &mut self.model {
            Model::MobileManipulator(m) => Some(m),
            _ => None,
        }
    }

    /// Physics switched on anywhere in the scene, as human-readable flags (used by
    /// `describe`; every entry is an effect a backend must build). A planar chain lists every
    /// flag, on or off; the other families list the effects they switch on.
    pub fn physics_flags(&self) -> Vec<(&'static str, bool)> {
        match &self.model {
            Model::PlanarChain(c) => c.physics_flags(),
            Model::Rocket(_) => Vec::new(),
            Model::PayloadLink(p) => p.physics_flags(),
            Model::MobileManipulator(m) => {
                let mut flags = m.physics_flags();
                flags.retain(|(_, on)| *on);
                flags
            }
        }
    }
}
