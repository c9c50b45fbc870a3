//! Free-free modes of the rocket at ignition mass (the `modes` command).

use std::time::Instant;

use data::scene::Rocket;
use data::{FemSettings, ModalResult, ModeShape, Scene};
use faer::Mat;

use crate::error::FemError;

use super::model::Model;

/// Free-free modes at ignition mass, discrete masses on their springs: K φ = ω² M(0) φ with K
/// the beam and spring stiffness (no thrust prestress). The three rigid-body modes are dropped.
pub struct RocketMode {
    pub omega: f64,
    pub kind: &'static str,
    pub vector: Vec<f64>,
}

pub fn rocket_modes(model: &Model, count: usize) -> Result<Vec<RocketMode>, FemError> {
    let n = model.n;
    let mut k = Mat::<f64>::zeros(n, n);
    let mut mm = Mat::<f64>::zeros(n, n);
    for &(i, j, v) in &model.k_beam.0 {
        k[(i, j)] += v;
    }
    for (i, j, v, _) in model.spring_entries() {
        k[(i, j)] += v;
    }
    for (i, j, v) in model.coupling_rotation_stiffness() {
        k[(i, j)] += v;
    }
    let mut e = vec![0.0; n];
    let mut col = vec![0.0; n];
    for j in 0..n {
        e[j] = 1.0;
        col.iter_mut().for_each(|x| *x = 0.0);
        model.mass_mul_add(model.m1_0, 1.0, &e, &mut col);
        for i in 0..n {
            mm[(i, j)] = col[i];
        }
        e[j] = 0.0;
    }
    // K is singular (three rigid modes): a Cholesky of K may still succeed on round-off pivots
    // and then ranks the rigid modes' 1/λ as the largest, pushing the elastic ones below the
    // solver's round-off floor. Solve the shifted pencil (K + σM, M), positive definite, and
    // shift back; σ of the order of the elastic spectrum (the smallest K_ii/M_ii) keeps the
    // relative accuracy of the lowest elastic λ near σ/λ·ε.
    let sigma = (0..n)
        .filter(|&i| k[(i, i)] > 0.0 && mm[(i, i)] > 0.0)
        .map(|i| k[(i, i)] / mm[(i, i)])
        .fold(f64::INFINITY, f64::min);
    if !sigma.is_finite() {
        return Err(FemError::Numerical {
            t: 0.0,
            message: "free-free rocket: no stiffness on any degree of freedom".into(),
        });
    }
    let mut k_shifted = k.clone();
    for j in 0..n {
        for i in 0..n {
            k_shifted[(i, j)] += sigma * mm[(i, j)];
        }
    }
    let (mut lam, x) = crate::modes::generalized_eigen(&k_shifted, &mm)?;
    lam.iter_mut().for_each(|l| *l -= sigma);
    const RIGID: usize = 3;
    if lam.len() <= RIGID || lam[..RIGID].iter().any(|l| l.abs() > 1e-6 * lam[RIGID]) {
        return Err(FemError::Numerical {
            t: 0.0,
            message: format!(
                "free-free rocket: the three rigid-body modes were not found (σ = {sigma:.3e}, \
                 lowest eigenvalues {:?})",
                &lam[..lam.len().min(5)]
            ),
        });
    }
    let mut out = Vec::new();
    for (jm, &l) in lam.iter().enumerate().skip(RIGID).take(count) {
        let v: Vec<f64> = (0..n).map(|i| x[(i, jm)]).collect();
        let mut axial = vec![0.0; n];
        for i in 0..n {
            if model.t_xi[i] != 0.0 {
                axial[i] = v[i];
            }
        }
        let total = model.mass_form(model.m1_0, &v, &v);
        let share = model.mass_form(model.m1_0, &axial, &axial) / total;
        out.push(RocketMode {
            omega: l.max(0.0).sqrt(),
            kind: if share > 0.5 { "axial" } else { "bending" },
            vector: v,
        });
    }
    Ok(out)
}

/// The free-free modes of `r`, the rocket of `scene`, at ignition mass.
pub fn modes(
    scene: &Scene,
    r: &Rocket,
    settings: &FemSettings,
    count: usize,
) -> Result<ModalResult, FemError> {
    let start = Instant::now();
    let model = super::build(r, settings)?;
    let modes = rocket_modes(&model, count)?;
    let stations = scene.simulation.field_stations.max(2);
    let shapes = modes
        .iter()
        .map(|md| {
            let x: Vec<f64> = (0..stations)
                .map(|k| k as f64 * model.length / (stations - 1) as f64)
                .collect();
            let w: Vec<f64> = x
                .iter()
                .map(|&xx| model.at(&model.point(xx), &md.vector).1)
                .collect();
            let scale = w.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            ModeShape {
                link: 1,
                x,
                transverse: w
                    .iter()
                    .map(|v| if scale > 0.0 { v / scale } else { 0.0 })
                    .collect(),
            }
        })
        .collect();
    Ok(crate::modes::modal_result(
        scene,
        settings,
        modes.iter().map(|m| (m.omega, m.kind.to_string())),
        shapes,
        model.n,
        start,
    ))
}
