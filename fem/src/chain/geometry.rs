//! Small planar vector helpers.

#[inline]
pub fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}
#[inline]
pub fn rot(phi: f64, a: [f64; 2]) -> [f64; 2] {
    let (s, c) = phi.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}
#[inline]
pub fn rot_t(phi: f64, a: [f64; 2]) -> [f64; 2] {
    rot(-phi, a)
}
#[inline]
pub fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
#[inline]
pub fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
#[inline]
pub fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}
#[inline]
pub fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline]
pub fn scale(s: f64, a: [f64; 2]) -> [f64; 2] {
    [s * a[0], s * a[1]]
}
