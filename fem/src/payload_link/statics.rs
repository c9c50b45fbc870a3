//! The linear gravity sag (module docs of [`super`], "Statics").

use std::time::Instant;

use data::scene::PayloadLink;
use data::{BackendKind, Cost, FemSettings, Scene, StaticResult};
use faer::Mat;
use faer::prelude::*;

use super::model::Model;
use super::plan::{build, elements};
use crate::error::FemError;

/// Linear gravity sag K_s d = −f_g (zero without gravity).
pub fn static_sag(md: &Model) -> Result<Vec<f64>, FemError> {
    let n = md.n;
    if !md.has_gravity {
        return Ok(vec![0.0; n]);
    }
    let k = md.ks.to_dense();
    let llt = k.llt(faer::Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "stiffness matrix of the payload link is not positive definite".into(),
    })?;
    let f = Mat::<f64>::from_fn(n, 1, |i, _| -md.fg[i]);
    let d = llt.solve(&f);
    Ok((0..n).map(|i| d[(i, 0)]).collect())
}

/// The gravity sag of `l`, the payload link of `scene`.
pub fn statics(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
) -> Result<StaticResult, FemError> {
    let start = Instant::now();
    let n_el = elements(settings)?;
    let md = build(l, n_el)?;
    let d = static_sag(&md)?;
    Ok(StaticResult {
        backend: BackendKind::Fem,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        tip_deflection: md.tip.w.dot(&d),
        tip_rotation: md.tip.w_slope.dot(&d),
        cost: Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs: md.n,
            factorizations: 1,
            ..Default::default()
        },
    })
}
