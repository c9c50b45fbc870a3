//! Planar vectors (nalgebra's `Vector2`) and the two turns the chain needs.

use nalgebra::{Rotation2, Vector2};

pub type V2 = Vector2<f64>;

/// `a` turned by +90°.
#[inline]
pub fn perp(a: V2) -> V2 {
    V2::new(-a.y, a.x)
}
/// `a` turned by φ.
#[inline]
pub fn rot(phi: f64, a: V2) -> V2 {
    Rotation2::new(phi) * a
}
/// `a` turned by −φ.
#[inline]
pub fn rot_t(phi: f64, a: V2) -> V2 {
    rot(-phi, a)
}
