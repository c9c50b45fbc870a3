//! Elastic modes of the mobile manipulator linearized about its initial pose (module doc of
//! [`super`]: K x = ω² M_ee x with the platform and every joint held).

use data::scene::MobileManipulator;
use data::{ModalResult, ModalSettings, ModeShape, Scene};
use faer::Mat;

use super::model::Workspace;
use super::run;
use super::set_up;
use crate::error::ModalError;
use crate::modes::generalized_eigen;

/// Elastic modes of `mm`, the manipulator of `scene`, about the initial pose with the platform
/// and all joints held.
pub fn modes(
    scene: &Scene,
    mm: &MobileManipulator,
    settings: &ModalSettings,
    count: usize,
) -> Result<ModalResult, ModalError> {
    let start = std::time::Instant::now();
    let (model, inputs) = set_up(mm, settings)?;
    let (Some(fl), Some(e0)) = (&model.flex, model.layout.elastic) else {
        return Err(ModalError::Unsupported(
            "modes of the mobile manipulator: the scene has no flexible link (the rigid \
             manipulator has no elastic modes)"
                .into(),
        ));
    };
    let l = model.layout;
    let (n, m, nm) = (l.n, l.m, l.modes);
    let mut y = vec![0.0; n + m + run::N_WORK];
    run::initial_state(&model, mm, &mut y);
    let mut ws = Workspace::new(&model);
    let nu = vec![0.0; m];
    let mut tau = vec![0.0; m.max(6)];
    inputs.at(0.0, &mut tau);
    model.equations(&y[..n], &nu, &tau, &mut ws);
    let s0 = e0 - l.speed_shift();
    let ne = 2 * nm;
    let mass = Mat::<f64>::from_fn(ne, ne, |i, j| ws.mass[(s0 + i) * m + s0 + j]);
    let stiff = Mat::<f64>::from_fn(ne, ne, |i, j| {
        let (di, dj) = (i / nm, j / nm);
        if di != dj {
            return 0.0;
        }
        let ei = if di == 0 { fl.ei_out } else { fl.ei_in };
        ei * fl.curvature[(i % nm) * nm + j % nm]
    });
    let (lambda, vectors) = generalized_eigen(&stiff, &mass)?;
    let take = count.min(ne);
    let mut frequencies_hz = Vec::with_capacity(take);
    let mut kinds = Vec::with_capacity(take);
    let mut shapes = Vec::with_capacity(take);
    for k in 0..take {
        frequencies_hz.push(lambda[k].max(0.0).sqrt() / std::f64::consts::TAU);
        let (out, inp): (f64, f64) = (
            (0..nm).map(|i| vectors[(i, k)].powi(2)).sum(),
            (nm..ne).map(|i| vectors[(i, k)].powi(2)).sum(),
        );
        kinds.push(if out >= inp {
            "bending out of plane".to_string()
        } else {
            "bending in plane".to_string()
        });
        // The dominant direction's deflection at the quadrature nodes, unit maximum.
        let dir = if out >= inp { 0 } else { nm };
        let ng = fl.nodes.len();
        let mut transverse: Vec<f64> = (0..ng)
            .map(|g| {
                (0..nm)
                    .map(|i| fl.phi[g * nm + i] * vectors[(dir + i, k)])
                    .sum()
            })
            .collect();
        let peak = transverse.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if peak > 0.0 {
            transverse.iter_mut().for_each(|v| *v /= peak);
        }
        shapes.push(ModeShape {
            link: fl.link,
            x: fl.nodes.clone(),
            transverse,
        });
    }
    Ok(ModalResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        frequencies_hz,
        kinds,
        shapes,
        cost: data::Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs: ne,
            ..data::Cost::default()
        },
    })
}
