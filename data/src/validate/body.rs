//! Mass properties of the mobile manipulator's bodies: a rigid body's mass, centre and inertia
//! tensor, and the flexible link's split into a uniform beam plus a rigid residual.

use super::inertia::{leading_minors_positive, positive_semidefinite};
use super::issue::Checker;
use crate::locate::FieldPath;
use crate::scene::{ArmLink, RigidBody};

/// The flexible link is a uniform beam of the link's mass plus a residual rigid inertia
/// J_res = J − diag(0, mL²/12, mL²/12) carried by its frame: its mass centre must be the
/// beam's, (L/2, 0, 0) within 1e-12·L, and J_res must be positive semi-definite.
pub(super) fn check_flexible_body(c: &mut Checker, p: &FieldPath, l: &ArmLink) {
    if !(l.length > 0.0 && l.mass > 0.0) {
        return; // reported by the link's own checks
    }
    let tol = 1e-12 * l.length;
    let want = [0.5 * l.length, 0.0, 0.0];
    if l.com
        .iter()
        .zip(&want)
        .any(|(a, b)| !a.is_finite() || (a - b).abs() > tol)
    {
        c.fail(
            p.key("com"),
            format!(
                "[{}, {}, {}] is not the middle of a flexible link of length {}",
                l.com[0], l.com[1], l.com[2], l.length
            ),
            format!(
                "[{}, 0.0, 0.0] (the uniform beam's mass centre, within 1e-12·L)",
                want[0]
            ),
        );
        return;
    }
    let rod = l.mass * l.length * l.length / 12.0;
    let mut j = l.inertia;
    j[1][1] -= rod;
    j[2][2] -= rod;
    if !positive_semidefinite(&j) {
        c.fail(
            p.key("inertia"),
            format!(
                "is smaller than the slender rod's (J − diag(0, mL²/12, mL²/12) with mL²/12 = \
                 {rod:e} is not positive semi-definite)"
            ),
            "an inertia of at least the uniform rod's about both transverse axes (the beam \
             carries mL²/12; the rest is a rigid residual)",
        );
    }
}

/// Mass ≥ 0 (> 0 when `massive`), finite centre of mass, and an inertia tensor that is
/// symmetric and positive definite (or all zero, a point mass, when not `massive`) with
/// diagonal moments that satisfy the triangle inequality of a real body.
pub(super) fn check_body(c: &mut Checker, p: &FieldPath, body: &RigidBody, massive: bool) {
    if massive {
        c.positive(p.key("mass"), body.mass);
    } else {
        c.non_negative(p.key("mass"), body.mass);
    }
    for (k, v) in body.com.iter().enumerate() {
        c.finite(p.key("com").index(k), *v);
    }
    let j = &body.inertia;
    if j.iter().flatten().any(|v| !v.is_finite()) {
        c.fail(p.key("inertia"), "has a non-finite entry", "finite numbers");
        return;
    }
    let scale = j.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
    let asym = (0..3)
        .flat_map(|r| (0..3).map(move |k| (r, k)))
        .fold(0.0f64, |s, (r, k)| s.max((j[r][k] - j[k][r]).abs()));
    if asym > 1e-12 * scale {
        c.fail(
            p.key("inertia"),
            format!("is not symmetric (largest |I_ij − I_ji| = {asym:e})"),
            "a symmetric 3×3 tensor [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]]",
        );
        return;
    }
    let definite = leading_minors_positive(j);
    let zero = scale == 0.0;
    if !definite && (massive || !zero) {
        c.fail(
            p.key("inertia"),
            "is not positive definite",
            "principal moments > 0 (a body's inertia tensor about its mass centre)",
        );
        return;
    }
    let (a, bb, cc) = (j[0][0], j[1][1], j[2][2]);
    let slack = 1e-12 * scale;
    if !zero && (a > bb + cc + slack || bb > a + cc + slack || cc > a + bb + slack) {
        c.fail(
            p.key("inertia"),
            format!("diagonal moments {a}, {bb}, {cc} violate the triangle inequality"),
            "each of Ixx, Iyy, Izz at most the sum of the other two (a real body)",
        );
    }
}
