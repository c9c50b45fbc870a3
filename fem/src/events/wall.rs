//! Rigid wall geometry of a bilateral tip contact (seed 001's circular wall, and a straight
//! line): gap, unit normal, tangent and curvature at a tip position, and the constraint rows.
//!
//! **Circle** (centre c, radius R, free side inside): g(r) = R − |r − c|, the normalized form of
//! seed 001's Φ = X² + Y² − L² (so the multiplier is the normal force in force units):
//! ∇_r g = n̂ = −(r − c)/|r − c|, |n̂| = 1. The tangent t̂ = (n̂_y, −n̂_x) is the
//! counter-clockwise direction about c, and the curvature κ = 1/|r − c|. Along a motion,
//! ġ = n̂·ṙ and g̈ = n̂·r̈ + ṅ·ṙ with ṅ·ṙ = −(|ṙ|² − (ê·ṙ)²)/|r − c| = −κ v_t² (ê the
//! outward radial unit vector, v_t = t̂·ṙ), the convective term of the index-1 normal force.
//! **Line** (unit normal n̂ to the free side, point p₀): g = n̂·(r − p₀), t̂ as above, κ = 0.
//!
//! With the inertial tip Jacobian J = ∂r_tip/∂q the constraint rows are G = n̂ᵀJ (gap
//! gradient) and T = t̂ᵀJ (slip velocity v_t = T q̇), see [`rows`].

use data::scene::Surface;

use crate::chain::V2;
use crate::error::FemError;

/// A fixed rigid wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wall {
    /// Unit normal to the free side and a point of the line.
    Line { normal: V2, point: V2 },
    /// Centre and radius; the free side is inside.
    Circle { center: V2, radius: f64 },
}

/// The wall seen from a tip position: gap, unit normal (to the free side), tangent, curvature.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WallFrame {
    pub gap: f64,
    pub normal: V2,
    pub tangent: V2,
    pub curvature: f64,
}

impl Wall {
    /// The scene's surface, validated (non-zero normal, positive finite radius).
    pub fn from_surface(s: &Surface) -> Result<Self, FemError> {
        match *s {
            Surface::Line { point, normal } => {
                let len = normal[0].hypot(normal[1]);
                if !(len > 0.0 && len.is_finite()) {
                    return Err(FemError::InvalidSettings {
                        field: "contact.surface.normal".into(),
                        message: "the normal must be a non-zero vector".into(),
                    });
                }
                Ok(Wall::Line {
                    normal: V2::from(normal) / len,
                    point: V2::from(point),
                })
            }
            Surface::Circle { center, radius } => {
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(FemError::InvalidSettings {
                        field: "contact.surface.radius".into(),
                        message: format!("the radius must be positive and finite, got {radius}"),
                    });
                }
                Ok(Wall::Circle {
                    center: V2::from(center),
                    radius,
                })
            }
        }
    }

    /// Gap only.
    pub fn gap(&self, r: V2) -> f64 {
        match *self {
            // n̂ₓdₓ + n̂ᵧdᵧ in this order: nalgebra's 2-vector dot.
            Wall::Line { normal, point } => normal.dot(&(r - point)),
            Wall::Circle { center, radius } => {
                let d = r - center;
                radius - d.x.hypot(d.y)
            }
        }
    }

    /// Gap, normal, tangent and curvature at the tip position r.
    pub fn frame(&self, r: V2) -> WallFrame {
        let (gap, normal, curvature) = match *self {
            Wall::Line { normal, .. } => (self.gap(r), normal, 0.0),
            Wall::Circle { center, radius } => {
                let d = r - center;
                let rho = d.x.hypot(d.y);
                if rho > 0.0 {
                    (radius - rho, -d / rho, 1.0 / rho)
                } else {
                    // The tip at the centre has no normal; it is then a radius away from the
                    // wall, where no constraint or event is evaluated: keep the numbers finite.
                    (radius, V2::new(-1.0, 0.0), 0.0)
                }
            }
        };
        WallFrame {
            gap,
            normal,
            tangent: V2::new(normal.y, -normal.x),
            curvature,
        }
    }
}

/// Constraint rows from the tip Jacobian `jac` (x row `jac[..n]`, y row `jac[n..2n]`): G = n̂ᵀJ
/// into `g` and T = t̂ᵀJ into `t`.
pub fn rows(f: &WallFrame, jac: &[f64], g: &mut [f64], t: &mut [f64]) {
    let n = g.len();
    for i in 0..n {
        let j = V2::new(jac[i], jac[n + i]);
        g[i] = f.normal.dot(&j);
        t[i] = f.tangent.dot(&j);
    }
}

/// The row a^ᵀJ of a fixed direction a (the tangential stick constraint t̂_sᵀJ).
pub fn row_along(a: V2, jac: &[f64], out: &mut [f64]) {
    let n = out.len();
    for i in 0..n {
        out[i] = a.dot(&V2::new(jac[i], jac[n + i]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_circle_gradient_matches_finite_differences() {
        let w = Wall::Circle {
            center: V2::new(0.3, -0.2),
            radius: 1.1,
        };
        let r = V2::new(0.9, 0.7);
        let f = w.frame(r);
        let e = 1e-6;
        let dgx = (w.gap(V2::new(r[0] + e, r[1])) - w.gap(V2::new(r[0] - e, r[1]))) / (2.0 * e);
        let dgy = (w.gap(V2::new(r[0], r[1] + e)) - w.gap(V2::new(r[0], r[1] - e))) / (2.0 * e);
        assert!((dgx - f.normal[0]).abs() < 1e-9 && (dgy - f.normal[1]).abs() < 1e-9);
        assert!((f.normal[0].hypot(f.normal[1]) - 1.0).abs() < 1e-15);
        // Counter-clockwise tangent about the centre: z·(ê × t̂) = +1.
        let d = [r[0] - 0.3, r[1] + 0.2];
        assert!(d[0] * f.tangent[1] - d[1] * f.tangent[0] > 0.0);
        assert!((f.curvature - 1.0 / d[0].hypot(d[1])).abs() < 1e-15);
    }

    #[test]
    fn elem_circle_convective_term_is_minus_curvature_times_vt_squared() {
        // g(r(t)) along r(t) = r0 + v t + ½ a t²: g̈(0) = n̂·a − κ v_t² (module docs).
        let w = Wall::Circle {
            center: V2::zeros(),
            radius: 1.0,
        };
        let (r0, v, a) = ([0.6, 0.75], [-0.4, 1.3], [0.7, -0.2]);
        let at = |t: f64| {
            V2::new(
                r0[0] + v[0] * t + 0.5 * a[0] * t * t,
                r0[1] + v[1] * t + 0.5 * a[1] * t * t,
            )
        };
        let e = 1e-4;
        let gdd = (w.gap(at(e)) - 2.0 * w.gap(at(0.0)) + w.gap(at(-e))) / (e * e);
        let f = w.frame(V2::from(r0));
        let vt = f.tangent[0] * v[0] + f.tangent[1] * v[1];
        let expect = f.normal[0] * a[0] + f.normal[1] * a[1] - f.curvature * vt * vt;
        assert!((gdd - expect).abs() < 1e-6, "{gdd} vs {expect}");
    }
}
