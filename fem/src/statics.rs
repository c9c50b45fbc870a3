//! Linear statics of a clamped link: K d = f for a transverse tip force P, a uniform transverse
//! load q (consistent nodal loads ∫q N) and, when the scene has gravity, the sag load ρA g⊥.

use data::Scene;
use faer::prelude::*;
use faer::{Mat, Side};

use crate::element::hermite::hermite;
use crate::element::quadrature::gauss01;
use crate::error::FemError;
use crate::linear::LinearLink;

/// (tip deflection, tip rotation) of the last link under the scene's static loads.
pub fn solve(scene: &Scene, sys: &LinearLink) -> Result<(f64, f64), FemError> {
    let link = scene
        .links
        .last()
        .ok_or_else(|| FemError::unsupported("no links"))?;
    let statics = scene.statics.clone().unwrap_or_default();
    let n = sys.ndof();
    let mut f = Mat::<f64>::zeros(n, 1);
    let tip = sys.n_el;
    if let (Some(p), Some(vt)) = (statics.tip_force, sys.layout.v(tip)) {
        f[(vt, 0)] += p;
    }
    let mut q = statics.distributed_load.unwrap_or(0.0);
    if let Some(g) = &scene.gravity {
        // Frame y axis at the initial joint angle.
        let a = link.joint.initial_angle;
        q += link.mass_per_length * (-a.sin() * g.vector[0] + a.cos() * g.vector[1]);
    }
    if q != 0.0 {
        let h = sys.length / sys.n_el as f64;
        let (pts, wts) = gauss01(4);
        for e in 0..sys.n_el {
            let dofs = [
                sys.layout.v(e),
                sys.layout.rot(e),
                sys.layout.v(e + 1),
                sys.layout.rot(e + 1),
            ];
            let mut fe = [0.0; 4];
            for (xi, w) in pts.iter().zip(wts) {
                let nv = if link.shear {
                    // IIE v-interpolation (cubic): use the element's own shapes.
                    let el = crate::element::timoshenko::TimoshenkoElement::new(
                        h,
                        link.bending_stiffness,
                        link.shear_stiffness.unwrap_or(f64::INFINITY),
                    );
                    let s = el.shapes(xi * h);
                    [s[0][0], s[1][0], s[2][0], s[3][0]]
                } else {
                    hermite(*xi, h).n
                };
                for k in 0..4 {
                    fe[k] += w * h * q * nv[k];
                }
            }
            for k in 0..4 {
                if let Some(i) = dofs[k] {
                    f[(i, 0)] += fe[k];
                }
            }
        }
    }
    let llt = sys.k.llt(Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "stiffness matrix is not positive definite (unsupported link?)".into(),
    })?;
    let d = llt.solve(&f);
    let get = |o: Option<usize>| o.map_or(0.0, |i| d[(i, 0)]);
    Ok((get(sys.layout.v(tip)), get(sys.layout.rot(tip))))
}
