//! Building the mobile manipulator [`Model`] from its scene in named phases: the refusals, the
//! platform lumped into one body with its wheel sides, the rigid bodies per frame, the flexible
//! link (its residual rigid inertia and its Hermite-cubic beam) and the coordinate layout.

use data::scene::{ArmLink, FlexibleLink, MobileManipulator, Platform, RigidBody};
use nalgebra::{Matrix3, Vector3};

use super::{Body, FlexLink, GAUSS, Layout, Model, positive_semidefinite, residual_inertia};
use crate::element::hermite_cubic;
use crate::element::quadrature::gauss01;
use crate::error::FemError;

impl Model {
    /// Builds the model with `elements` Hermite-cubic elements on the flexible link (ignored
    /// without one: then the model is the rigid system, used by the tests).
    pub fn new(m: &MobileManipulator, elements: usize) -> Result<Self, FemError> {
        let arm = m.arm.as_ref().ok_or_else(|| {
            FemError::unsupported(
                "fem mobile manipulator: a scene without an arm (the platform alone has no \
                 flexible part; use the reference)",
            )
        })?;
        if arm.links.len() != 3 {
            return Err(FemError::unsupported(format!(
                "fem mobile manipulator: {} pitch links (the model has three)",
                arm.links.len()
            )));
        }
        let platform = m.platform.as_ref().map(Platform::composite);
        let mut bodies = Vec::new();
        if let Some(p) = &platform {
            bodies.push(Body {
                frame: 0,
                mass: p.mass,
                com: Vector3::new(p.com_offset, 0.0, 0.0),
                inertia: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, p.yaw_inertia),
            });
        }
        bodies.push(rigid_body(1, &arm.turret));
        let mut flex = None;
        let mut lengths = [0.0; 3];
        for (k, l) in arm.links.iter().enumerate() {
            lengths[k] = l.length;
            let frame = 2 + k;
            match &m.flexible_link {
                Some(f) if f.link == k + 1 => {
                    let (residual, fl) = flexible_link(k, l, f, elements)?;
                    bodies.push(residual);
                    flex = Some(fl);
                }
                _ => bodies.push(rigid_body(frame, &l.body())),
            }
        }
        if let Some(f) = &m.flexible_link
            && !(1..=3).contains(&f.link)
        {
            return Err(FemError::unsupported(format!(
                "fem mobile manipulator: flexible_link.link = {} (pitch links are 1..=3)",
                f.link
            )));
        }
        bodies.push(rigid_body(5, &arm.gripper));
        let layout = layout(platform.is_some(), flex.as_ref().map_or(0, |f| f.ne));
        Ok(Model {
            layout,
            gravity: m.gravity,
            platform,
            ground_pose: [m.initial.x, m.initial.y, m.initial.heading],
            mount: Vector3::from(arm.mount),
            base_height: arm.base_height,
            lengths,
            bodies,
            flex,
            joint_friction: arm.joint_friction,
        })
    }
}

/// A scene rigid body carried by `frame` (the scene's inertia matrix is row-major).
fn rigid_body(frame: usize, b: &RigidBody) -> Body {
    Body {
        frame,
        mass: b.mass,
        com: Vector3::from(b.com),
        inertia: Matrix3::from(b.inertia).transpose(),
    }
}

/// Pitch link k (0…2) as the flexible link: refused unless its mass centre is the uniform
/// beam's, its inertia minus the slender rod's m L²/12 is positive semi-definite and both
/// bending stiffnesses are positive. Returns the massless body carrying that residual inertia
/// and the beam of `elements` Hermite-cubic elements (stiffness assembled).
fn flexible_link(
    k: usize,
    l: &ArmLink,
    f: &FlexibleLink,
    elements: usize,
) -> Result<(Body, FlexLink), FemError> {
    let frame = 2 + k;
    let half = 0.5 * l.length;
    let off = (l.com[0] - half).abs() + l.com[1].abs() + l.com[2].abs();
    if off > 1e-12 * l.length {
        return Err(FemError::unsupported(format!(
            "fem mobile manipulator: flexible link {} has its mass centre at \
             {:?}; the uniform beam needs ({half}, 0, 0)",
            k + 1,
            l.com
        )));
    }
    let j_res = residual_inertia(l.mass, l.length, &Matrix3::from(l.inertia).transpose());
    if !positive_semidefinite(&j_res, 1e-12) {
        return Err(FemError::unsupported(format!(
            "fem mobile manipulator: flexible link {}: its inertia minus the \
             slender rod's m L²/12 is not positive semi-definite",
            k + 1
        )));
    }
    for (what, v) in [
        ("bending_stiffness_in_plane", f.bending_stiffness_in_plane),
        (
            "bending_stiffness_out_of_plane",
            f.bending_stiffness_out_of_plane,
        ),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(FemError::unsupported(format!(
                "fem mobile manipulator: flexible_link.{what} = {v} (must be \
                 positive)"
            )));
        }
    }
    let residual = Body {
        frame,
        mass: 0.0,
        com: Vector3::new(half, 0.0, 0.0),
        inertia: j_res,
    };
    let (xs, ws) = gauss01(GAUSS);
    let le = l.length / elements as f64;
    let mut fl = FlexLink {
        link: k,
        frame,
        length: l.length,
        elements,
        le,
        mu: l.mass / l.length,
        ei_in: f.bending_stiffness_in_plane,
        ei_out: f.bending_stiffness_out_of_plane,
        ne: 4 * elements,
        stiffness: Vec::new(),
        shapes: std::array::from_fn(|g| hermite_cubic().shapes(xs[g], le)),
        gauss_xi: std::array::from_fn(|g| xs[g]),
        gauss_w: std::array::from_fn(|g| ws[g] * le),
    };
    fl.assemble_stiffness();
    Ok((residual, fl))
}

/// Coordinates (x, y, ψ, φ_R, φ_L | θ₁…θ₄ | e) and speeds (φ̇_R, φ̇_L | θ̇₁…θ̇₄ | ė), the
/// platform blocks only with a platform, `ne` elastic DOFs.
fn layout(platform: bool, ne: usize) -> Layout {
    let np = if platform { 5 } else { 0 };
    let mp = if platform { 2 } else { 0 };
    Layout {
        platform,
        q_arm: np,
        nu_arm: mp,
        q_el: np + 4,
        nu_el: mp + 4,
        ne,
        n: np + 4 + ne,
        m: mp + 4 + ne,
    }
}
