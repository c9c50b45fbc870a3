//! The registry of observable channels: every channel name a backend (or verify's references)
//! writes, and its unit, defined once.
//!
//! Link, joint, contact and station indices are 1-based for links, joints, contacts and discrete
//! masses (as in the papers) and 0-based for field stations k of `simulation.field_stations`
//! (station 0 at the root). Name functions ([`joint_angle`], [`PAYLOAD_X`], …) address a
//! channel in a result; the [`spec`] functions give the (name, unit) pair a backend declares with
//! [`crate::Observables::with_channels`]. Planar chains, the rocket and the 3-D link write in
//! the scene's consistent units (`length`, `mass`, `time`, …); the mobile manipulator is given
//! in SI units ([`si`]).
//!
//! A channel exists only when the scene carries what it measures: a 3-D link without a field
//! writes no channel of that field ([`payload_link`]), so a check that asks for it fails on the
//! missing name instead of reading zeros.

use crate::scene::{LinkField, MobileManipulator};

/// A channel declaration: name and unit.
pub type Spec = (String, &'static str);

/// Units in the scene's consistent system.
pub mod unit {
    pub const LENGTH: &str = "length";
    pub const VELOCITY: &str = "length/time";
    pub const ANGLE: &str = "rad";
    pub const RATE: &str = "rad/time";
    pub const FORCE: &str = "force";
    /// Unit of every joint-torque channel (one spelling across backends).
    pub const TORQUE: &str = "force·length";
    pub const ENERGY: &str = "energy";
    pub const MASS: &str = "mass";
    pub const TIME: &str = "time";
    /// A dimensionless state code.
    pub const CODE: &str = "1";
}

/// SI units of the mobile-manipulator family.
pub mod si {
    pub const METRE: &str = "m";
    pub const METRE_PER_SECOND: &str = "m/s";
    pub const RADIAN: &str = "rad";
    pub const RADIAN_PER_SECOND: &str = "rad/s";
    pub const NEWTON_METRE: &str = "N m";
    /// A gap between two formulations of mixed coordinates (positions and angles).
    pub const METRE_OR_RADIAN: &str = "m or rad";
}

/// Unit of every joint-torque channel (one spelling across backends).
pub const TORQUE_UNIT: &str = unit::TORQUE;

// ---------------------------------------------------------------- planar link chains

/// Joint angle θᵢ (frame angle of link i relative to its parent) \[rad\].
pub fn joint_angle(i: usize) -> String {
    format!("joint{i}.angle")
}
/// Joint rate θ̇ᵢ.
pub fn joint_rate(i: usize) -> String {
    format!("joint{i}.rate")
}
/// Torque at the joint: a free joint's applied law plus its spring and damper,
/// τ(t) − K(θ − θ₀) − Dθ̇; a prescribed joint's torque that the motion needed.
pub fn joint_torque(i: usize) -> String {
    format!("joint{i}.torque")
}
/// Tip position of link i in inertial coordinates.
pub fn tip_x(i: usize) -> String {
    format!("link{i}.tip_x")
}
pub fn tip_y(i: usize) -> String {
    format!("link{i}.tip_y")
}
/// Transverse tip deflection of link i in its own floating frame.
pub fn tip_deflection(i: usize) -> String {
    format!("link{i}.tip_deflection")
}
/// Axial tip displacement of link i in its floating frame (extensible links).
pub fn tip_axial(i: usize) -> String {
    format!("link{i}.tip_axial")
}
/// Transverse deflection of link i at field station k (of `simulation.field_stations`).
pub fn field_deflection(i: usize, k: usize) -> String {
    format!("link{i}.v@{k}")
}

// ---------------------------------------------------------------- contact and friction

/// Contact phase of contact c: 0 free, 1 constrained and sliding (or frictionless), 2 sticking.
pub fn contact_phase(c: usize) -> String {
    format!("contact{c}.phase")
}
/// Normal force of contact c (positive pushes the tip to the free side).
pub fn contact_normal_force(c: usize) -> String {
    format!("contact{c}.normal_force")
}
/// Signed gap of contact c (positive on the free side).
pub fn contact_gap(c: usize) -> String {
    format!("contact{c}.gap")
}
/// Normal velocity of the contact point of contact c (d gap / dt).
pub fn contact_normal_velocity(c: usize) -> String {
    format!("contact{c}.normal_velocity")
}
/// Largest |gap| of contact c while constrained since the previous sample (drift monitor).
pub fn contact_max_gap(c: usize) -> String {
    format!("contact{c}.max_gap")
}
/// Largest |normal velocity| of contact c while constrained since the previous sample.
pub fn contact_max_normal_velocity(c: usize) -> String {
    format!("contact{c}.max_normal_velocity")
}
/// Tangential (slip) velocity of the contact point of contact c.
pub fn contact_slip_velocity(c: usize) -> String {
    format!("contact{c}.slip_velocity")
}
/// Coulomb friction force of contact c (along the surface tangent).
pub fn contact_friction_force(c: usize) -> String {
    format!("contact{c}.friction_force")
}
/// Cumulative friction work of contact c.
pub fn contact_friction_work(c: usize) -> String {
    format!("contact{c}.friction_work")
}

// ---------------------------------------------------------------- 3-D payload link

/// 3-D link (seed 002): vertical tip deflection w(L), twist φ(L) and the tip slopes v′(L),
/// w′(L) of link i in its turning frame. With `tip_axial` (u(L)), `tip_deflection` (v(L)) and
/// the base angle they fix the payload's orientation to second order (seed eq. 2).
pub fn tip_vertical(i: usize) -> String {
    format!("link{i}.tip_w")
}
pub fn tip_twist(i: usize) -> String {
    format!("link{i}.tip_twist")
}
pub fn tip_slope_horizontal(i: usize) -> String {
    format!("link{i}.tip_slope_v")
}
pub fn tip_slope_vertical(i: usize) -> String {
    format!("link{i}.tip_slope_w")
}
/// 3-D link: vertical deflection and twist at field station k.
pub fn field_vertical(i: usize, k: usize) -> String {
    format!("link{i}.w@{k}")
}
pub fn field_twist(i: usize, k: usize) -> String {
    format!("link{i}.phi@{k}")
}
/// 3-D link: inertial position of the payload's centre of mass (origin on the base axis at
/// the rod's root, Z up).
pub const PAYLOAD_X: &str = "payload.X";
pub const PAYLOAD_Y: &str = "payload.Y";
pub const PAYLOAD_Z: &str = "payload.Z";

/// One tip quantity of the 3-D link: the field it belongs to, its name and unit.
#[derive(Debug, Clone, Copy)]
pub struct TipQuantity {
    pub field: LinkField,
    pub name: fn(usize) -> String,
    pub unit: &'static str,
}

/// The 3-D link's tip quantities in channel order: u(L), v(L), w(L), φ(L), v′(L), w′(L).
/// A backend writes the value of entry j when the scene carries `PAYLOAD_LINK_TIP[j].field`.
pub const PAYLOAD_LINK_TIP: [TipQuantity; 6] = [
    TipQuantity {
        field: LinkField::Axial,
        name: tip_axial,
        unit: unit::LENGTH,
    },
    TipQuantity {
        field: LinkField::Horizontal,
        name: tip_deflection,
        unit: unit::LENGTH,
    },
    TipQuantity {
        field: LinkField::Vertical,
        name: tip_vertical,
        unit: unit::LENGTH,
    },
    TipQuantity {
        field: LinkField::Torsion,
        name: tip_twist,
        unit: unit::ANGLE,
    },
    TipQuantity {
        field: LinkField::Horizontal,
        name: tip_slope_horizontal,
        unit: unit::ANGLE,
    },
    TipQuantity {
        field: LinkField::Vertical,
        name: tip_slope_vertical,
        unit: unit::ANGLE,
    },
];

/// One sampled field of the 3-D link: the field, its station-channel name and unit.
#[derive(Debug, Clone, Copy)]
pub struct FieldProfile {
    pub field: LinkField,
    pub name: fn(usize, usize) -> String,
    pub unit: &'static str,
}

/// The 3-D link's sampled fields in channel order (all stations of v, then of w, then of φ).
pub const PAYLOAD_LINK_PROFILES: [FieldProfile; 3] = [
    FieldProfile {
        field: LinkField::Horizontal,
        name: field_deflection,
        unit: unit::LENGTH,
    },
    FieldProfile {
        field: LinkField::Vertical,
        name: field_vertical,
        unit: unit::LENGTH,
    },
    FieldProfile {
        field: LinkField::Torsion,
        name: field_twist,
        unit: unit::ANGLE,
    },
];

/// The channels of a 3-D payload-link run whose rod carries `fields`, with `stations` field
/// stations: base angle, rate and torque; payload position; the tip quantities of the carried
/// fields ([`PAYLOAD_LINK_TIP`] order); then the stations of each carried sampled field
/// ([`PAYLOAD_LINK_PROFILES`] order). A backend may append its own channels (step size, …).
pub fn payload_link(fields: &[LinkField], stations: usize) -> Vec<Spec> {
    let mut c = vec![
        spec::joint_angle(1),
        spec::joint_rate(1),
        spec::joint_torque(1),
        spec::payload_x(),
        spec::payload_y(),
        spec::payload_z(),
    ];
    for q in PAYLOAD_LINK_TIP
        .iter()
        .filter(|q| fields.contains(&q.field))
    {
        c.push(((q.name)(1), q.unit));
    }
    for p in PAYLOAD_LINK_PROFILES
        .iter()
        .filter(|p| fields.contains(&p.field))
    {
        for k in 0..stations {
            c.push(((p.name)(1, k), p.unit));
        }
    }
    c
}

/// The field a 3-D link channel measures, if it measures one field (`link1.tip_w` → vertical).
pub fn payload_link_field_of(name: &str) -> Option<LinkField> {
    let tip = PAYLOAD_LINK_TIP
        .iter()
        .find(|q| (q.name)(1) == name)
        .map(|q| q.field);
    tip.or_else(|| {
        let (stem, _) = name.split_once('@')?;
        PAYLOAD_LINK_PROFILES
            .iter()
            .find(|p| (p.name)(1, 0).split_once('@').map(|(s, _)| s) == Some(stem))
            .map(|p| p.field)
    })
}

// ---------------------------------------------------------------- rocket

/// Rocket: inertial position of the mass centre (aft end at the origin at launch), attitude θ
/// of the body axis from the horizontal, current mass.
pub const ROCKET_X: &str = "rocket.X";
pub const ROCKET_Y: &str = "rocket.Y";
pub const ROCKET_THETA: &str = "rocket.theta";
pub const ROCKET_MASS: &str = "rocket.mass";
/// Rocket: mass-averaged velocity of the material, linear momentum / mass (what the rocket
/// equation describes). It differs from d(rocket.X)/dt by the drift of the mass centre
/// through the body as stage 1 burns.
pub const ROCKET_VX: &str = "rocket.vX";
pub const ROCKET_VY: &str = "rocket.vY";
/// Rocket: elastic axial / transverse displacement at field station k (aft = 0 … nose).
pub fn rocket_axial(k: usize) -> String {
    format!("rocket.u@{k}")
}
pub fn rocket_transverse(k: usize) -> String {
    format!("rocket.w@{k}")
}
/// Rocket: displacement of discrete mass j (1-based) from its attachment station, in body
/// axes (u along, w across).
pub fn rocket_mass_axial(j: usize) -> String {
    format!("rocket.mass{j}.u")
}
pub fn rocket_mass_transverse(j: usize) -> String {
    format!("rocket.mass{j}.w")
}

// ---------------------------------------------------------------- mobile manipulator (SI)

/// Platform pose in the ground plane: position of the reference point and heading.
pub const PLATFORM_X: &str = "platform.x";
pub const PLATFORM_Y: &str = "platform.y";
pub const PLATFORM_HEADING: &str = "platform.heading";
/// Wheel angles and drive torques of the right and left wheel sets.
pub const WHEEL_RIGHT_ANGLE: &str = "wheel_right.angle";
pub const WHEEL_LEFT_ANGLE: &str = "wheel_left.angle";
pub const WHEEL_RIGHT_TORQUE: &str = "wheel_right.torque";
pub const WHEEL_LEFT_TORQUE: &str = "wheel_left.torque";
/// End-effector position in inertial axes.
pub const END_EFFECTOR_X: &str = "ee.x";
pub const END_EFFECTOR_Y: &str = "ee.y";
pub const END_EFFECTOR_Z: &str = "ee.z";
/// In-plane deflection w(L) of flexible pitch link k at its tip, in the link frame.
pub fn flexible_tip_in_plane(k: usize) -> String {
    format!("link{k}.tip_in_plane")
}
/// Out-of-plane deflection v(L) of flexible pitch link k at its tip, in the link frame.
pub fn flexible_tip_out_of_plane(k: usize) -> String {
    format!("link{k}.tip_out_of_plane")
}
/// Violation of the platform's velocity constraints.
pub const CONSTRAINT_DRIFT: &str = "constraint.drift";
/// Largest position / rate difference between two formulations of the same motion.
pub const FORMULATIONS_POSITION_GAP: &str = "formulations.position_gap";
pub const FORMULATIONS_RATE_GAP: &str = "formulations.rate_gap";
/// Residual of the inverse-dynamics torques against the forward run.
pub const INVERSE_TORQUE_RESIDUAL: &str = "inverse.torque_residual";
/// Residual of seed 004's closed-form arm equation (37).
pub const SEED_EQ37_RESIDUAL: &str = "seed_eq37.residual";

/// The channels of a mobile-manipulator run of `mm` whose model carries the scene's flexible
/// link as a beam: with a platform, its pose, the side wheel angles and the side drive torques;
/// with an arm, joint angle, rate and torque of θ₁…θ₄ and the end-effector position; with a
/// flexible link, its in-plane and out-of-plane tip deflections; then the constraint drift. A
/// backend may append its own channels.
pub fn mobile_manipulator(mm: &MobileManipulator) -> Vec<Spec> {
    let flexible = mm.flexible_link.as_ref().filter(|_| mm.arm.is_some());
    mobile_manipulator_with(mm, flexible.map(|f| f.link))
}

/// The channels of [`mobile_manipulator`] for a rigid model of `mm`, the EI → ∞ limit of a
/// flexible link (no tip deflections).
pub fn mobile_manipulator_rigid(mm: &MobileManipulator) -> Vec<Spec> {
    mobile_manipulator_with(mm, None)
}

/// The mobile manipulator's channels with the tip deflections of pitch link `flexible`.
fn mobile_manipulator_with(mm: &MobileManipulator, flexible: Option<usize>) -> Vec<Spec> {
    let mut c = Vec::new();
    if mm.platform.is_some() {
        c.extend([
            spec::platform_x(),
            spec::platform_y(),
            spec::platform_heading(),
            spec::wheel_right_angle(),
            spec::wheel_left_angle(),
            spec::wheel_right_torque(),
            spec::wheel_left_torque(),
        ]);
    }
    if mm.arm.is_some() {
        for i in 1..=4 {
            c.push(spec::arm_joint_angle(i));
            c.push(spec::arm_joint_rate(i));
            c.push(spec::arm_joint_torque(i));
        }
        c.extend([
            spec::end_effector_x(),
            spec::end_effector_y(),
            spec::end_effector_z(),
        ]);
    }
    if let Some(k) = flexible {
        c.push(spec::flexible_tip_in_plane(k));
        c.push(spec::flexible_tip_out_of_plane(k));
    }
    c.push(spec::constraint_drift());
    c
}

// ---------------------------------------------------------------- frame invariance

/// Whether an observable means the same thing in every backend, whatever floating frame,
/// shape basis or reference point a backend chooses:
/// * `linkN.tip_x`, `linkN.tip_y` — inertial tip position;
/// * `jointN.angle`, `jointN.rate`, `jointN.torque` — joint 1 is the hub angle from the inertial
///   X axis, joint N > 1 the motor angle between the tip tangent of link N−1 and the root
///   tangent of link N (scenes.md): rotations of rigid hubs and motors, not of a floating frame;
///   the torque is the actuator's;
/// * `contactC.normal_force` — a force on the tip;
/// * `rocket.X`, `rocket.Y`, `rocket.vX`, `rocket.vY` — inertial mass-centre position and
///   momentum / mass;
/// * `energy.NAME` — energy-ledger terms;
/// * `payload.X`, `payload.Y`, `payload.Z` — the 3-D link's payload position;
/// * `linkN.tip_w`, `linkN.tip_twist` — the 3-D link's vertical tip deflection and tip twist, in
///   the base's turning frame, which the clamped root fixes the same way in every backend.
///
/// * `rocket.massJ.u`, `rocket.massJ.w`, `rocket.u@K`, `rocket.w@K` — the rocket's elastic
///   displacements relative to the case's mean axis weighted by its ignition mass
///   (docs/rocket.md): a function of the deformed shape alone, not of a backend's body frame;
/// * `ee.x`, `ee.y`, `ee.z`, `platform.x`, `platform.y`, `platform.heading` — the mobile
///   manipulator's inertial end-effector position and platform pose.
///
/// Not invariant: tip deflections and axial displacements in a link's floating frame, field
/// deflections `linkN.v@K`, and the rocket's attitude `rocket.theta` (each backend's body
/// axis).
///
/// Built on the registry's own names: an indexed channel is recognized by rebuilding it.
pub fn frame_invariant(name: &str) -> bool {
    if name.starts_with(crate::cases::ENERGY_PREFIX) {
        return true;
    }
    if [
        ROCKET_X,
        ROCKET_Y,
        ROCKET_VX,
        ROCKET_VY,
        PAYLOAD_X,
        PAYLOAD_Y,
        PAYLOAD_Z,
        END_EFFECTOR_X,
        END_EFFECTOR_Y,
        END_EFFECTOR_Z,
        PLATFORM_X,
        PLATFORM_Y,
        PLATFORM_HEADING,
    ]
    .contains(&name)
    {
        return true;
    }
    let indexed: [fn(usize) -> String; 12] = [
        tip_x,
        tip_y,
        tip_vertical,
        tip_twist,
        joint_angle,
        joint_rate,
        joint_torque,
        contact_normal_force,
        rocket_axial,
        rocket_transverse,
        rocket_mass_axial,
        rocket_mass_transverse,
    ];
    indexed.iter().any(|build| built_by(name, build))
}

/// Whether `name` is `build(i)` for the index i its first run of digits spells.
fn built_by(name: &str, build: impl Fn(usize) -> String) -> bool {
    let Some(start) = name.find(|c: char| c.is_ascii_digit()) else {
        return false;
    };
    let digits = &name[start..];
    let end = digits
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(digits.len());
    digits[..end]
        .parse::<usize>()
        .is_ok_and(|i| build(i) == name)
}

// ---------------------------------------------------------------- integrator monitors

/// Time step in use (variable-step schemes).
pub const STEP_SIZE: &str = "step_size";
/// Stability bound on the step in force at that time (explicit schemes).
pub const STABILITY_BOUND: &str = "stability_bound";

/// (name, unit) declarations of every channel, the unit defined here once.
pub mod spec {
    use super::{Spec, si, unit};

    pub fn joint_angle(i: usize) -> Spec {
        (super::joint_angle(i), unit::ANGLE)
    }
    pub fn joint_rate(i: usize) -> Spec {
        (super::joint_rate(i), unit::RATE)
    }
    pub fn joint_torque(i: usize) -> Spec {
        (super::joint_torque(i), unit::TORQUE)
    }
    pub fn tip_x(i: usize) -> Spec {
        (super::tip_x(i), unit::LENGTH)
    }
    pub fn tip_y(i: usize) -> Spec {
        (super::tip_y(i), unit::LENGTH)
    }
    pub fn tip_deflection(i: usize) -> Spec {
        (super::tip_deflection(i), unit::LENGTH)
    }
    pub fn tip_axial(i: usize) -> Spec {
        (super::tip_axial(i), unit::LENGTH)
    }
    pub fn field_deflection(i: usize, k: usize) -> Spec {
        (super::field_deflection(i, k), unit::LENGTH)
    }
    pub fn contact_phase(c: usize) -> Spec {
        (super::contact_phase(c), unit::CODE)
    }
    pub fn contact_normal_force(c: usize) -> Spec {
        (super::contact_normal_force(c), unit::FORCE)
    }
    pub fn contact_gap(c: usize) -> Spec {
        (super::contact_gap(c), unit::LENGTH)
    }
    pub fn contact_normal_velocity(c: usize) -> Spec {
        (super::contact_normal_velocity(c), unit::VELOCITY)
    }
    pub fn contact_max_gap(c: usize) -> Spec {
        (super::contact_max_gap(c), unit::LENGTH)
    }
    pub fn contact_max_normal_velocity(c: usize) -> Spec {
        (super::contact_max_normal_velocity(c), unit::VELOCITY)
    }
    pub fn contact_slip_velocity(c: usize) -> Spec {
        (super::contact_slip_velocity(c), unit::VELOCITY)
    }
    pub fn contact_friction_force(c: usize) -> Spec {
        (super::contact_friction_force(c), unit::FORCE)
    }
    pub fn contact_friction_work(c: usize) -> Spec {
        (super::contact_friction_work(c), unit::ENERGY)
    }
    pub fn payload_x() -> Spec {
        (super::PAYLOAD_X.to_string(), unit::LENGTH)
    }
    pub fn payload_y() -> Spec {
        (super::PAYLOAD_Y.to_string(), unit::LENGTH)
    }
    pub fn payload_z() -> Spec {
        (super::PAYLOAD_Z.to_string(), unit::LENGTH)
    }
    pub fn rocket_x() -> Spec {
        (super::ROCKET_X.to_string(), unit::LENGTH)
    }
    pub fn rocket_y() -> Spec {
        (super::ROCKET_Y.to_string(), unit::LENGTH)
    }
    pub fn rocket_theta() -> Spec {
        (super::ROCKET_THETA.to_string(), unit::ANGLE)
    }
    pub fn rocket_mass() -> Spec {
        (super::ROCKET_MASS.to_string(), unit::MASS)
    }
    pub fn rocket_vx() -> Spec {
        (super::ROCKET_VX.to_string(), unit::VELOCITY)
    }
    pub fn rocket_vy() -> Spec {
        (super::ROCKET_VY.to_string(), unit::VELOCITY)
    }
    pub fn rocket_axial(k: usize) -> Spec {
        (super::rocket_axial(k), unit::LENGTH)
    }
    pub fn rocket_transverse(k: usize) -> Spec {
        (super::rocket_transverse(k), unit::LENGTH)
    }
    pub fn rocket_mass_axial(j: usize) -> Spec {
        (super::rocket_mass_axial(j), unit::LENGTH)
    }
    pub fn rocket_mass_transverse(j: usize) -> Spec {
        (super::rocket_mass_transverse(j), unit::LENGTH)
    }
    pub fn step_size() -> Spec {
        (super::STEP_SIZE.to_string(), unit::TIME)
    }
    pub fn stability_bound() -> Spec {
        (super::STABILITY_BOUND.to_string(), unit::TIME)
    }

    /// Mobile manipulator (SI).
    pub fn platform_x() -> Spec {
        (super::PLATFORM_X.to_string(), si::METRE)
    }
    pub fn platform_y() -> Spec {
        (super::PLATFORM_Y.to_string(), si::METRE)
    }
    pub fn platform_heading() -> Spec {
        (super::PLATFORM_HEADING.to_string(), si::RADIAN)
    }
    pub fn wheel_right_angle() -> Spec {
        (super::WHEEL_RIGHT_ANGLE.to_string(), si::RADIAN)
    }
    pub fn wheel_left_angle() -> Spec {
        (super::WHEEL_LEFT_ANGLE.to_string(), si::RADIAN)
    }
    pub fn wheel_right_torque() -> Spec {
        (super::WHEEL_RIGHT_TORQUE.to_string(), si::NEWTON_METRE)
    }
    pub fn wheel_left_torque() -> Spec {
        (super::WHEEL_LEFT_TORQUE.to_string(), si::NEWTON_METRE)
    }
    pub fn arm_joint_angle(i: usize) -> Spec {
        (super::joint_angle(i), si::RADIAN)
    }
    pub fn arm_joint_rate(i: usize) -> Spec {
        (super::joint_rate(i), si::RADIAN_PER_SECOND)
    }
    pub fn arm_joint_torque(i: usize) -> Spec {
        (super::joint_torque(i), si::NEWTON_METRE)
    }
    pub fn end_effector_x() -> Spec {
        (super::END_EFFECTOR_X.to_string(), si::METRE)
    }
    pub fn end_effector_y() -> Spec {
        (super::END_EFFECTOR_Y.to_string(), si::METRE)
    }
    pub fn end_effector_z() -> Spec {
        (super::END_EFFECTOR_Z.to_string(), si::METRE)
    }
    pub fn flexible_tip_in_plane(k: usize) -> Spec {
        (super::flexible_tip_in_plane(k), si::METRE)
    }
    pub fn flexible_tip_out_of_plane(k: usize) -> Spec {
        (super::flexible_tip_out_of_plane(k), si::METRE)
    }
    pub fn constraint_drift() -> Spec {
        (super::CONSTRAINT_DRIFT.to_string(), si::METRE_PER_SECOND)
    }
    pub fn formulations_position_gap() -> Spec {
        (
            super::FORMULATIONS_POSITION_GAP.to_string(),
            si::METRE_OR_RADIAN,
        )
    }
    pub fn formulations_rate_gap() -> Spec {
        (
            super::FORMULATIONS_RATE_GAP.to_string(),
            si::RADIAN_PER_SECOND,
        )
    }
    pub fn inverse_torque_residual() -> Spec {
        (super::INVERSE_TORQUE_RESIDUAL.to_string(), si::NEWTON_METRE)
    }
    pub fn seed_eq37_residual() -> Spec {
        (super::SEED_EQ37_RESIDUAL.to_string(), si::NEWTON_METRE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_frame_invariance_follows_the_registry_names() {
        for i in [1, 2, 12] {
            for name in [tip_x(i), tip_y(i), joint_angle(i), joint_torque(i)] {
                assert!(frame_invariant(&name), "{name}");
            }
            for name in [
                rocket_axial(i),
                rocket_mass_transverse(i),
                contact_normal_force(i),
            ] {
                assert!(frame_invariant(&name), "{name}");
            }
            for name in [tip_deflection(i), field_deflection(1, i), contact_gap(i)] {
                assert!(!frame_invariant(&name), "{name}");
            }
        }
        assert!(frame_invariant(END_EFFECTOR_Z) && frame_invariant(ROCKET_VY));
        assert!(!frame_invariant(ROCKET_THETA) && !frame_invariant("rocket.w@"));
        assert!(!frame_invariant("joint01.angle") && !frame_invariant("joint1.angles"));
    }

    #[test]
    fn payload_link_channels_omit_the_fields_the_rod_does_not_carry() {
        let all = payload_link(&LinkField::ALL, 3);
        assert_eq!(all.len(), 6 + 6 + 3 * 3);
        let names = |c: &[Spec]| c.iter().map(|s| s.0.clone()).collect::<Vec<_>>();
        let planar = payload_link(&[LinkField::Axial, LinkField::Horizontal], 3);
        let n = names(&planar);
        assert_eq!(planar.len(), 6 + 3 + 3);
        for absent in [
            tip_vertical(1),
            tip_twist(1),
            tip_slope_vertical(1),
            field_twist(1, 0),
        ] {
            assert!(!n.contains(&absent), "{absent} written for an absent field");
        }
        assert!(n.contains(&tip_slope_horizontal(1)) && n.contains(&field_deflection(1, 2)));
    }

    #[test]
    fn payload_link_channel_names_map_back_to_their_field() {
        for (name, _) in payload_link(&LinkField::ALL, 2).into_iter().skip(6) {
            assert!(payload_link_field_of(&name).is_some(), "{name}");
        }
        assert_eq!(
            payload_link_field_of("link1.phi@4"),
            Some(LinkField::Torsion)
        );
        assert_eq!(payload_link_field_of(PAYLOAD_X), None);
    }
}
