//! Rayleigh–Ritz frequencies and the gravity sag of the payload link (see the module doc of
//! [`super`] for what the linearization keeps).

use std::time::Instant;

use data::scene::{LinkField, PayloadLink};
use data::{Cost, ModalResult, ModalSettings, ModeShape, Scene, StaticResult};
use faer::Mat;

use super::model::LinkModel;
use super::{set_up, static_sag};
use crate::error::ModalError;
use crate::linalg::dot;
use crate::modes::generalized_eigen;

/// Name of a mode whose kinetic energy sits mostly in a field.
pub fn kind_name(field: LinkField) -> &'static str {
    match field {
        LinkField::Axial => "axial",
        LinkField::Horizontal => "bending-horizontal",
        LinkField::Vertical => "bending-vertical",
        LinkField::Torsion => "torsion",
    }
}

/// The linearized pencil (K_eff, M) over (θ if free, q) at the base's reference rate.
pub fn linear_pencil(model: &LinkModel) -> (Mat<f64>, Mat<f64>, f64) {
    let n = model.n;
    let base = &model.base;
    let o = usize::from(base.free);
    let rate = if base.free {
        base.initial_rate
    } else {
        base.prescribed_state(0.0).1
    };
    let nd = n + o;
    let mut k = Mat::<f64>::zeros(nd, nd);
    let mut m = Mat::<f64>::zeros(nd, nd);
    for i in 0..n {
        for j in 0..n {
            m[(o + i, o + j)] = model.mass[i * n + j];
            k[(o + i, o + j)] =
                model.stiffness[i * n + j] - rate * rate * model.centrifugal[i * n + j];
        }
    }
    if base.free {
        m[(0, 0)] = model.j0;
        for i in 0..n {
            m[(0, 1 + i)] = model.b[i];
            m[(1 + i, 0)] = model.b[i];
        }
        k[(0, 0)] = base.spring.map_or(0.0, |(ks, _)| ks);
    }
    (k, m, rate)
}

pub fn modes(
    scene: &Scene,
    link: &PayloadLink,
    settings: &ModalSettings,
    count: usize,
) -> Result<ModalResult, ModalError> {
    let wall = Instant::now();
    let s = set_up(scene, link, settings)?;
    let model = &s.model;
    let (k, m, rate) = linear_pencil(model);
    // At a prescribed constant rate the gyroscopic coupling stays in (its modes' velocity
    // shapes give kinds and shapes); otherwise the symmetric pencil.
    let (lambda, vecs) = if !model.base.free && rate != 0.0 {
        gyroscopic_modes(model)?
    } else {
        generalized_eigen(&k, &m)?
    };
    let nd = k.nrows();
    let o = usize::from(model.base.free);
    let count = count.min(nd);
    let scale = lambda
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(1e-300);
    let ns = scene.simulation.field_stations.max(2);
    let mut frequencies = Vec::with_capacity(count);
    let mut kinds = Vec::with_capacity(count);
    let mut shapes = Vec::with_capacity(count);
    for c in 0..count {
        let lam = lambda[c];
        let f = if lam.abs() < 1e-12 * scale {
            0.0
        } else {
            lam.signum() * lam.abs().sqrt() / std::f64::consts::TAU
        };
        frequencies.push(f);
        // Kinetic share of each block (x is M-orthonormal).
        let share = |r0: usize, len: usize| {
            let mut s = 0.0;
            for r in r0..r0 + len {
                for cc in r0..r0 + len {
                    s += vecs[(r, c)] * m[(r, cc)] * vecs[(cc, c)];
                }
            }
            s
        };
        let dominant = model
            .blocks
            .iter()
            .map(|b| (b, share(o + b.offset, b.count())))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let theta_share = if o == 1 { share(0, 1) } else { 0.0 };
        kinds.push(match dominant {
            _ if f == 0.0 => "rigid".to_string(),
            Some((b, s)) if s >= theta_share => kind_name(b.field).to_string(),
            _ => "rigid".to_string(),
        });
        if let Some((b, _)) = dominant {
            let mut phi = vec![0.0; b.count()];
            let mut x = Vec::with_capacity(ns);
            let mut v = Vec::with_capacity(ns);
            for st in 0..ns {
                let xs = model.length * st as f64 / (ns - 1) as f64;
                b.basis.eval(xs, 0, &mut phi);
                let val: f64 = phi
                    .iter()
                    .enumerate()
                    .map(|(j, p)| p * vecs[(o + b.offset + j, c)])
                    .sum();
                x.push(xs);
                v.push(val);
            }
            let vmax = v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            if vmax > 0.0 {
                v.iter_mut().for_each(|e| *e /= vmax);
            }
            shapes.push(ModeShape {
                link: 1,
                x,
                transverse: v,
            });
        }
    }
    Ok(ModalResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        frequencies_hz: frequencies,
        kinds,
        shapes,
        cost: Cost {
            wall_time_s: wall.elapsed().as_secs_f64(),
            dofs: nd,
            ..Cost::default()
        },
    })
}

/// The linear gravity sag: `tip_deflection` = w(L), `tip_rotation` = w′(L).
pub fn statics(
    scene: &Scene,
    link: &PayloadLink,
    settings: &ModalSettings,
) -> Result<StaticResult, ModalError> {
    let wall = Instant::now();
    let s = set_up(scene, link, settings)?;
    let q = static_sag(&s.model)?;
    Ok(StaticResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        tip_deflection: dot(&s.model.tip.w, &q),
        tip_rotation: dot(&s.model.tip.slope_w, &q),
        cost: Cost {
            wall_time_s: wall.elapsed().as_secs_f64(),
            dofs: s.model.n,
            ..Cost::default()
        },
    })
}

/// Frequencies \[Hz\] with the gyroscopic coupling at the reference rate Ω (prescribed
/// base), ascending, `count` of them ([`gyroscopic_modes`]).
pub fn gyroscopic_frequencies(
    scene: &Scene,
    link: &PayloadLink,
    settings: &ModalSettings,
    count: usize,
) -> Result<Vec<f64>, ModalError> {
    let s = set_up(scene, link, settings)?;
    let (w2, _) = gyroscopic_modes(&s.model)?;
    Ok(w2
        .iter()
        .take(count)
        .map(|v| v.max(0.0).sqrt() / std::f64::consts::TAU)
        .collect())
}

/// ω² and velocity shapes of M q̈ + Ω(Gᵀ − G) q̇ + K_eff q = 0 (prescribed base; K_eff = K − Ω²N
/// must be positive definite). With z = (q̇, q), A = diag(M, K_eff) and the skew
/// B = [[Ω(Gᵀ − G), K_eff], [−K_eff, 0]], A ż + B z = 0; for A = LLᵀ, S = L⁻¹BL⁻ᵀ is skew, its
/// eigenvalues ±iω, and the ω² are the eigenvalues of the symmetric SᵀS, each twice. Per mode
/// (ascending): ω² and the velocity part q̇ of the first of its two eigenvectors z = L⁻ᵀy,
/// scaled to unit kinetic energy q̇ᵀMq̇ = 1 (columns of the returned matrix).
pub fn gyroscopic_modes(model: &LinkModel) -> Result<(Vec<f64>, Mat<f64>), ModalError> {
    if model.base.free {
        return Err(ModalError::Unsupported(
            "gyroscopic frequencies of a free base (the base angle is not a coordinate of \
             this analysis)"
                .into(),
        ));
    }
    let (k, m, rate) = linear_pencil(model);
    let n = model.n;
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    let mut b = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = m[(i, j)];
            a[(n + i, n + j)] = k[(i, j)];
            b[(i, j)] = rate * (model.gyro[j * n + i] - model.gyro[i * n + j]);
            b[(i, n + j)] = k[(i, j)];
            b[(n + i, j)] = -k[(i, j)];
        }
    }
    let llt = a
        .llt(faer::Side::Lower)
        .map_err(|_| ModalError::Numerical {
            t: 0.0,
            message: "K − Ω²N is not positive definite: no gyroscopic frequencies".into(),
        })?;
    let l = llt.L();
    let mut t = b.clone();
    l.solve_lower_triangular_in_place(&mut t);
    let mut sk = t.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut sk);
    // sk = (L⁻¹ B L⁻ᵀ)ᵀ = −S; SᵀS is the same from either sign.
    let c = sk.transpose() * &sk;
    let c = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let ev = c
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| ModalError::Numerical {
            t: 0.0,
            message: "eigen-decomposition did not converge".into(),
        })?;
    let s2 = ev.S().column_vector();
    let mut z = ev.U().to_owned();
    l.transpose().solve_upper_triangular_in_place(&mut z);
    let w2: Vec<f64> = (0..n).map(|p| 0.5 * (s2[2 * p] + s2[2 * p + 1])).collect();
    let mut vel = Mat::<f64>::zeros(n, n);
    for p in 0..n {
        // The pair's vector with the larger kinetic energy (the other may be nearly all q).
        let kin = |j: usize| {
            let mut e = 0.0;
            for r in 0..n {
                for q in 0..n {
                    e += z[(r, j)] * m[(r, q)] * z[(q, j)];
                }
            }
            e
        };
        let (e0, e1) = (kin(2 * p), kin(2 * p + 1));
        let (j, e) = if e0 >= e1 {
            (2 * p, e0)
        } else {
            (2 * p + 1, e1)
        };
        let scale = if e > 0.0 { 1.0 / e.sqrt() } else { 0.0 };
        for r in 0..n {
            vel[(r, p)] = z[(r, j)] * scale;
        }
    }
    Ok((w2, vel))
}
