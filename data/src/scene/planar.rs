//! Planar chains of floating-frame beams (seeds 000, 001; scenes.md "common physics vocabulary").
//!
//! Link `i` is clamped at its root to a frame that rotates with joint `i`. Link 1's joint is the
//! hub (frame angle q₁ from the inertial X axis); link `i+1`'s joint sits at the tip of link `i`
//! and its frame angle is (frame angle of link i) + (slope of link i at its tip) + (joint angle).
//! On a Timoshenko link (`shear`) "slope" means the cross-section rotation ψ: its frame is its
//! root cross-section (ψ(0) = 0, while the root may shear: v'(0) = v'(0) − ψ(0) is the root
//! shear strain), and link `i+1` turns with the section at link `i`'s tip, ψᵢ(Lᵢ), so each joint
//! angle, and the spring and damper on it, are measured between cross-sections.
//!
//! Initial state: the links' centre lines start straight at the joints' `initial_angle`s, with
//! the `initial_rate`s and the elastic fields at rest. Cross-sections without rotary inertia
//! carry no mass, so they take their static balance at once: on such Timoshenko links the joint
//! angles between sections start off `initial_angle` by the sections' turns under the joint
//! springs' moments (4.9e-5 rad at the elbow of `barhorst-case1-timoshenko`), while every mass
//! point is where the scene puts it — the same start in every backend.

use serde::{Deserialize, Serialize};

/// Uniform gravity field, inertial components (planar: [gx, gy]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    pub vector: [f64; 2],
}

/// One flexible (or, with huge stiffness, nearly rigid) link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Link {
    /// Name used by contacts and outputs.
    pub name: String,
    /// Undeformed length L.
    pub length: f64,
    /// Mass per unit length ρA.
    pub mass_per_length: f64,
    /// Bending stiffness EI.
    pub bending_stiffness: f64,
    /// Axial stiffness EA. Required when `axial` is on; informative otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_stiffness: Option<f64>,
    /// Shear stiffness κGA. Required when `shear` is on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_stiffness: Option<f64>,
    /// Rotary inertia per unit length ρI. Required when `rotary_inertia` is on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotary_inertia_per_length: Option<f64>,
    /// Extensible link: u(x,t) is a field, strain ε = u' + ½v'².
    #[serde(default, skip_serializing_if = "is_false")]
    pub axial: bool,
    /// Inextensible link with geometric stiffening (axial position x − ½∫v'²).
    #[serde(default, skip_serializing_if = "is_false")]
    pub foreshortening: bool,
    /// Timoshenko shear deformation (needs `shear_stiffness`).
    #[serde(default, skip_serializing_if = "is_false")]
    pub shear: bool,
    /// Rotary inertia of the cross-sections (needs `rotary_inertia_per_length`).
    #[serde(default, skip_serializing_if = "is_false")]
    pub rotary_inertia: bool,
    /// Kelvin–Voigt coefficient γ: bending moment EI v'' + γ v̇''.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kelvin_voigt: Option<f64>,
    /// Point mass at the free end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_mass: Option<f64>,
    /// Rotary inertia of the tip body about the tip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_inertia: Option<f64>,
    /// The joint at this link's root.
    pub joint: Joint,
}

fn is_false(b: &bool) -> bool {
    !*b
}

impl Link {
    /// Total distributed mass ρA·L (without tip mass).
    pub fn beam_mass(&self) -> f64 {
        self.mass_per_length * self.length
    }
}

/// Joint at the root of a link: hub (link 1) or elbow (link i > 1).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Joint {
    /// Rotary inertia of the hub/motor rotor carried by this joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hub_inertia: Option<f64>,
    /// Torsional spring K: torque −K(θ − θ₀).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Torsional damper D: torque −D θ̇.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Spring set-point θ₀ \[rad\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set_point: Option<f64>,
    /// Initial joint angle \[rad\].
    #[serde(default)]
    pub initial_angle: f64,
    /// Initial joint rate [rad/time].
    #[serde(default)]
    pub initial_rate: f64,
    /// Applied torque law (in addition to spring and damper).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque: Option<TorqueLaw>,
    /// Prescribed joint motion; the backend reports the torque it needs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prescribed: Option<PrescribedMotion>,
}

/// Applied joint torque τ(t).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum TorqueLaw {
    /// τ = value for 0 ≤ t < until (forever if `until` is absent), then 0.
    Constant {
        value: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        until: Option<f64>,
    },
    /// τ = +amplitude on [0, switch), −amplitude on [switch, off), 0 afterwards.
    BangBang {
        amplitude: f64,
        switch: f64,
        off: f64,
    },
}

impl TorqueLaw {
    /// Torque at time t.
    pub fn torque(&self, t: f64) -> f64 {
        self.stretch_value(t, false)
    }

    /// Torque just before time t, the left limit lim_{s↑t} τ(s): equal to [`Self::torque`]
    /// except at a breakpoint, where it is the value of the stretch that ends there. A step
    /// that ends on a jump integrates that stretch and reads its end with this.
    pub fn torque_before(&self, t: f64) -> f64 {
        self.stretch_value(t, true)
    }

    /// The value on the stretch that holds t: the one that starts at t when t is a breakpoint
    /// (right-continuous), or with `left` the one that ends there.
    fn stretch_value(&self, t: f64, left: bool) -> f64 {
        let before = |b: f64| if left { t <= b } else { t < b };
        match *self {
            TorqueLaw::Constant { value, until } => {
                if until.is_none_or(before) {
                    value
                } else {
                    0.0
                }
            }
            TorqueLaw::BangBang {
                amplitude,
                switch,
                off,
            } => {
                if before(switch) {
                    amplitude
                } else if before(off) {
                    -amplitude
                } else {
                    0.0
                }
            }
        }
    }

    /// Times at which the law is discontinuous (integrators should step onto them).
    pub fn breakpoints(&self) -> Vec<f64> {
        match *self {
            TorqueLaw::Constant { until, .. } => until.into_iter().collect(),
            TorqueLaw::BangBang { switch, off, .. } => vec![switch, off],
        }
    }
}

/// Prescribed joint angle θ(t) (relative to `initial_angle`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum PrescribedMotion {
    /// θ = 0: the root is clamped to the ground (cantilever).
    Fixed,
    /// θ = (ωs/Ts)[t²/2 + (Ts/2π)²(cos(2πt/Ts) − 1)] for t < Ts, then ωs(t − Ts/2).
    SpinUp { omega_s: f64, t_s: f64 },
    /// θ = rate · t (a hub spinning at constant Ω).
    ConstantRate { rate: f64 },
}

impl PrescribedMotion {
    /// (θ, θ̇, θ̈) at time t, measured from the joint's initial angle.
    pub fn kinematics(&self, t: f64) -> (f64, f64, f64) {
        match *self {
            PrescribedMotion::SpinUp { omega_s, t_s } => {
                if t < t_s {
                    let w = 2.0 * std::f64::consts::PI / t_s;
                    let c = (t_s / (2.0 * std::f64::consts::PI)).powi(2);
                    let theta = omega_s / t_s * (0.5 * t * t + c * ((w * t).cos() - 1.0));
                    let rate = omega_s / t_s * (t - (w * t).sin() / w);
                    let acc = omega_s / t_s * (1.0 - (w * t).cos());
                    (theta, rate, acc)
                } else {
                    (omega_s * (t - 0.5 * t_s), omega_s, 0.0)
                }
            }
            PrescribedMotion::ConstantRate { rate } => (rate * t, rate, 0.0),
            PrescribedMotion::Fixed => (0.0, 0.0, 0.0),
        }
    }
}

/// Geometry of a rigid contact surface in the inertial plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Surface {
    /// The line through `point` with unit `normal` pointing to the free side.
    Line { point: [f64; 2], normal: [f64; 2] },
    /// Circle of `radius` about `center`; the free side is inside.
    Circle { center: [f64; 2], radius: f64 },
}

impl Surface {
    /// Signed gap g(p): positive on the free side, zero on the surface.
    pub fn gap(&self, p: [f64; 2]) -> f64 {
        match *self {
            Surface::Line { point, normal } => {
                let n = (normal[0].hypot(normal[1])).max(f64::MIN_POSITIVE);
                ((p[0] - point[0]) * normal[0] + (p[1] - point[1]) * normal[1]) / n
            }
            Surface::Circle { center, radius } => {
                radius - (p[0] - center[0]).hypot(p[1] - center[1])
            }
        }
    }
}

/// Whether the tip may leave the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactMode {
    /// The tip may hit, slide on and leave the surface.
    Unilateral,
    /// The tip must follow the surface at all times.
    Bilateral,
}

/// The tip of a named link against a rigid surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// Name of the link whose tip touches the surface.
    pub link: String,
    pub surface: Surface,
    pub mode: ContactMode,
    /// Coulomb friction coefficient μ (0 = frictionless).
    #[serde(default)]
    pub friction: f64,
}

/// Static load cases (applied to the last link of the chain).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Statics {
    /// Transverse tip force P (positive along the frame's +y axis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_force: Option<f64>,
    /// Uniform transverse load q per unit length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distributed_load: Option<f64>,
    /// Large-deflection study: load parameters P L² / EI.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub elastica_load_parameters: Vec<f64>,
}

/// Parameter sweeps the scene asks for.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Studies {
    /// Rotating beam: nondimensional speeds λ = Ω·sqrt(ρAL⁴/EI).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rotation_speeds: Vec<f64>,
}
