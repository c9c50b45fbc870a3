//! Modes of the link linearized about the undeformed rod (module docs of [`super`], "Modes").

use std::time::Instant;

use data::scene::PayloadLink;
use data::{FemSettings, ModalResult, ModeShape, Scene};
use faer::{Mat, c64};

use super::model::{self, Model};
use super::plan::{build, elements};
use crate::element::beam3d::{PHI, U, V, W};
use crate::error::FemError;

/// Reference rate of the eigenproblem.
fn reference_rate(md: &Model) -> f64 {
    match &md.base {
        model::Base::Prescribed(data::scene::PrescribedMotion::ConstantRate { rate }) => *rate,
        _ => 0.0,
    }
}

/// One mode of the linearized link: ω, kind, eigenvector (d first, then θ for a free base).
#[derive(Debug, Clone)]
pub struct Mode3d {
    pub omega: f64,
    pub kind: String,
    pub field: Option<usize>,
    pub vector: Vec<f64>,
}

/// Dense (K, M) of the link linearized about the undeformed rod at the reference rate Ω:
/// K = K_s − Ω²K_c, M; a free base adds θ (mass row J₀, b₀; stiffness the joint spring) last.
pub(super) fn linearized(md: &Model) -> (Mat<f64>, Mat<f64>) {
    let n = md.n;
    let free = md.free_base();
    let nn = n + usize::from(free);
    let omega_ref = reference_rate(md);
    let mut k = Mat::<f64>::zeros(nn, nn);
    let mut m = Mat::<f64>::zeros(nn, nn);
    for i in 0..n {
        for j in md.m.cols(i) {
            m[(i, j)] = md.m.get(i, j);
            k[(i, j)] = md.ks.get(i, j) - omega_ref * omega_ref * md.kc.get(i, j);
        }
    }
    if free {
        m[(n, n)] = md.j0;
        for i in 0..n {
            m[(i, n)] = md.b0[i];
            m[(n, i)] = md.b0[i];
        }
        k[(n, n)] = md.spring().0;
    }
    (k, m)
}

/// The lowest `count` flexible modes.
pub fn link_modes(md: &Model, count: usize) -> Result<Vec<Mode3d>, FemError> {
    let n = md.n;
    let free = md.free_base();
    let nn = n + usize::from(free);
    let (k, m) = linearized(md);
    // Shift σM (σ > 0) makes K + σM definite with a free base's rigid rotation; λ = μ − σ.
    let tr_k: f64 = (0..nn).map(|i| k[(i, i)].abs()).sum();
    let tr_m: f64 = (0..nn).map(|i| m[(i, i)]).sum();
    let sigma = if free { 1e-8 * tr_k / tr_m } else { 0.0 };
    let mut ks = k.clone();
    for i in 0..nn {
        for j in 0..nn {
            ks[(i, j)] += sigma * m[(i, j)];
        }
    }
    let (lam, x) = crate::modes::generalized_eigen(&ks, &m)?;
    let mut out = Vec::new();
    for (j, &l) in lam.iter().enumerate() {
        if out.len() >= count {
            break;
        }
        let l = l - sigma;
        if free && l.abs() <= 1e-6 * sigma {
            continue; // rigid rotation of the base
        }
        if l < 0.0 {
            return Err(FemError::Numerical {
                t: 0.0,
                message: format!(
                    "mode {} has ω² = {l:.3e} < 0: the linearized link is unstable at the \
                     reference rate",
                    j + 1
                ),
            });
        }
        let v: Vec<f64> = (0..nn).map(|i| x[(i, j)]).collect();
        // Kinetic-energy share per slot (u, v/v′, w/w′, φ) and of θ.
        let mut share = [0.0; 5];
        for a in 0..nn {
            let mv: f64 = (0..nn).map(|b| m[(a, b)] * v[b]).sum();
            let group = if a == n { 4 } else { group_of(md, a) };
            share[group] += v[a] * mv;
        }
        let (kind, field) = kind_of(&share);
        out.push(Mode3d {
            omega: l.sqrt(),
            kind: kind.to_string(),
            field,
            vector: v,
        });
    }
    Ok(out)
}

/// Kind of a mode from the kinetic-energy share of each group (u, v/v′, w/w′, φ, θ).
fn kind_of(share: &[f64; 5]) -> (&'static str, Option<usize>) {
    let (g, _) = share
        .iter()
        .enumerate()
        .fold((0, f64::MIN), |b, (i, &s)| if s > b.1 { (i, s) } else { b });
    match g {
        0 => ("axial", Some(U)),
        1 => ("bending-horizontal", Some(V)),
        2 => ("bending-vertical", Some(W)),
        3 => ("torsion", Some(PHI)),
        _ => ("rigid", None),
    }
}

/// Group (0 u, 1 v/v′, 2 w/w′, 3 φ) of field DOF i.
fn group_of(md: &Model, i: usize) -> usize {
    match slot_of(md, i) {
        U => 0,
        PHI => 3,
        s if s <= 2 => 1,
        _ => 2,
    }
}

/// The lowest `count` modes of a rod turning at the prescribed constant rate Ω with the
/// gyroscopic coupling: M q̈ + Ω(Gᵀ − G) q̇ + (K_s − Ω²K_c) q = 0. With z = (q̇, q),
/// A = diag(M, K) and the skew B = [[Ω(Gᵀ − G), K], [−K, 0]], A ż + B z = 0; for A = LLᵀ the
/// matrix S = L⁻¹BL⁻ᵀ is skew with eigenvalues ±iω: the ω are the positive eigenvalues of the
/// Hermitian iS, and the real and imaginary parts y of an eigenvector span the mode's real
/// plane (z = L⁻ᵀy). Kinds from the kinetic energy ½q̇ᵀMq̇ of both; the shape is the
/// displacement part q of the one with the larger one. (The eigenvalues of the symmetric SᵀS,
/// the ω² twice, are not accurate enough: with ω_max² ~ 1e11 the squared matrix split the
/// horizontal pair of `single-link-3d-constant-rate` by 5e-4 relative and gave one of them as
/// the mode.)
pub fn gyroscopic_modes(md: &Model, count: usize) -> Result<Vec<Mode3d>, FemError> {
    let n = md.n;
    if md.free_base() {
        return Err(FemError::unsupported(
            "fem payload link: gyroscopic modes need a prescribed base",
        ));
    }
    let rate = reference_rate(md);
    let (k, m) = linearized(md);
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    let mut b = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = m[(i, j)];
            a[(n + i, n + j)] = k[(i, j)];
            b[(i, j)] = rate * (md.g.get(j, i) - md.g.get(i, j));
            b[(i, n + j)] = k[(i, j)];
            b[(n + i, j)] = -k[(i, j)];
        }
    }
    let llt = a.llt(faer::Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "K_s − Ω²K_c is not positive definite: the linearized link is unstable at the \
                  reference rate"
            .into(),
    })?;
    let l = llt.L();
    let mut t = b;
    l.solve_lower_triangular_in_place(&mut t);
    let mut sk = t.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut sk);
    // sk = (L⁻¹BL⁻ᵀ)ᵀ = −S, skew up to round-off; i·sk is Hermitian with eigenvalues ∓ω, and
    // its lower triangle (all the eigensolver reads) is that of the skew part.
    let h = Mat::<c64>::from_fn(2 * n, 2 * n, |i, j| {
        c64::new(0.0, 0.5 * (sk[(i, j)] - sk[(j, i)]))
    });
    let ev = h
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| FemError::Numerical {
            t: 0.0,
            message: "eigensolver did not converge".into(),
        })?;
    // Ascending: the n positive eigenvalues are the upper half (A is definite, so none is 0).
    let values = ev.S().column_vector();
    let vectors = ev.U();
    let modes = n.min(count);
    let mut omega = Vec::with_capacity(modes);
    let mut z = Mat::<f64>::zeros(2 * n, 2 * modes);
    for p in 0..modes {
        let j = n + p;
        omega.push(values[j].re.max(0.0));
        for r in 0..2 * n {
            z[(r, 2 * p)] = vectors[(r, j)].re;
            z[(r, 2 * p + 1)] = vectors[(r, j)].im;
        }
    }
    l.transpose().solve_upper_triangular_in_place(&mut z);
    let mut out = Vec::new();
    for p in 0..modes {
        let (j0, j1) = (2 * p, 2 * p + 1);
        let mut share = [0.0; 5];
        let mut best = (f64::MIN, j0);
        for j in [j0, j1] {
            for r in 0..n {
                let mv: f64 = md.m.cols(r).map(|q| m[(r, q)] * z[(q, j)]).sum();
                share[group_of(md, r)] += z[(r, j)] * mv;
            }
            let disp: f64 = (0..n).map(|r| z[(n + r, j)] * z[(n + r, j)]).sum();
            if disp > best.0 {
                best = (disp, j);
            }
        }
        let (kind, field) = kind_of(&share);
        out.push(Mode3d {
            omega: omega[p],
            kind: kind.to_string(),
            field,
            vector: (0..n).map(|r| z[(n + r, best.1)]).collect(),
        });
    }
    Ok(out)
}

/// Slot (U, V, V_SLOPE, W, W_SLOPE, PHI) of field DOF i.
pub(super) fn slot_of(md: &Model, i: usize) -> usize {
    let node = i / md.layout.per_node + 1;
    (0..6)
        .find(|&s| md.layout.dof(node, s) == Some(i))
        .unwrap_or(U)
}

/// The modes of `l`, the payload link of `scene`.
pub fn modes(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
    count: usize,
) -> Result<ModalResult, FemError> {
    let start = Instant::now();
    let n_el = elements(settings)?;
    let md = build(l, n_el)?;
    // A free base without spring turns rigidly (ω = 0, kind `rigid`), listed first as by the
    // other backends; a base at a prescribed constant rate keeps the gyroscopic coupling.
    let rigid = md.free_base() && md.spring().0 == 0.0 && count > 0;
    let mut modes = Vec::with_capacity(count);
    if rigid {
        modes.push(Mode3d {
            omega: 0.0,
            kind: "rigid".into(),
            field: None,
            vector: vec![0.0; md.n + 1],
        });
    }
    let flexible = count - usize::from(rigid);
    if reference_rate(&md) != 0.0 && !md.free_base() {
        modes.extend(gyroscopic_modes(&md, flexible)?);
    } else {
        modes.extend(link_modes(&md, flexible)?);
    }
    let st = scene.simulation.field_stations.max(2);
    let xs: Vec<f64> = (0..st)
        .map(|k| md.length * k as f64 / (st - 1) as f64)
        .collect();
    let shapes = modes
        .iter()
        .map(|m| {
            let mut y: Vec<f64> = match m.field {
                Some(slot) => xs
                    .iter()
                    .map(|&x| md.field_at(&m.vector[..md.n], slot, x))
                    .collect(),
                None => vec![0.0; st],
            };
            let big = y
                .iter()
                .fold(0.0f64, |a, &b| if b.abs() > a.abs() { b } else { a });
            if big != 0.0 {
                y.iter_mut().for_each(|v| *v /= big);
            }
            ModeShape {
                link: 1,
                x: xs.clone(),
                transverse: y,
            }
        })
        .collect();
    Ok(crate::modes::modal_result(
        scene,
        settings,
        modes.iter().map(|m| (m.omega, m.kind.clone())),
        shapes,
        md.n + usize::from(md.free_base()),
        start,
    ))
}
