//! Linear statics of a clamped link: K d = f for a transverse tip force P, a uniform transverse
//! load q (consistent loads ∫q Nᵥ on every DOF of the element, interior ones included) and, when
//! the scene has gravity, the sag load ρA g⊥.

use data::scene::PlanarChain;
use faer::prelude::*;
use faer::{Mat, Side};

use crate::error::FemError;
use crate::linear::LinearLink;

/// (tip deflection, tip rotation) of the last link of `pc` under its static loads.
pub fn solve(pc: &PlanarChain, sys: &LinearLink) -> Result<(f64, f64), FemError> {
    let link = pc
        .links
        .last()
        .ok_or_else(|| FemError::unsupported("no links"))?;
    let statics = pc.statics.clone().unwrap_or_default();
    let n = sys.ndof();
    let mut f = Mat::<f64>::zeros(n, 1);
    let tip = sys.n_el;
    if let (Some(p), Some(vt)) = (statics.tip_force, sys.layout.v(tip)) {
        f[(vt, 0)] += p;
    }
    let mut q = statics.distributed_load.unwrap_or(0.0);
    if let Some(g) = &pc.gravity {
        // Frame y axis at the initial joint angle.
        let a = link.joint.initial_angle;
        q += link.mass_per_length * (-a.sin() * g.vector[0] + a.cos() * g.vector[1]);
    }
    if q != 0.0 {
        let mut fq = vec![0.0; n];
        sys.uniform_load(q, &mut fq);
        for (i, v) in fq.iter().enumerate() {
            f[(i, 0)] += v;
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
