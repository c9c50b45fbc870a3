//! Rayleigh–Ritz natural frequencies: K x = λ M x of the free coordinates, linearized about the
//! reference state (joints at their spring set-points, or initial angles without a spring;
//! elastic coordinates zero; a prescribed hub turning at its t = 0 rate, e.g. the constant Ω of
//! `rotating-beam`). K = −∂f/∂q by central differences of the force side, which is exact to
//! round-off here because every force is at most linear in the perturbed coordinate about this
//! state (elastic K_b b, joint springs, centrifugal Ω²(f Sₓ − M_φ) b), except the cubic von
//! Kármán terms whose O(h²) error is negligible with the step h = 1e-8 L; gyroscopic coupling is
//! left out (undamped, non-gyroscopic frequencies). The pencil is solved by Cholesky reduction
//! (faer self-adjoint eigensolver).

use std::time::Instant;

use data::scene::PlanarChain;
use data::{Cost, ModalResult, ModalSettings, ModeShape, Scene};
use faer::Mat;

use crate::error::ModalError;
use crate::pencil::{Pencil, PencilError};
use crate::setup::{Purpose, build_chain_for};

/// Natural frequencies \[Hz\] of `pc`, the chain of `scene`, ascending. A statically unstable
/// (divergent) mode is reported as −sqrt(−λ)/2π.
pub fn modes(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &ModalSettings,
    count: usize,
) -> Result<ModalResult, ModalError> {
    let wall = Instant::now();
    let mut chain = build_chain_for(pc, settings, Purpose::Modes)?;
    let n = chain.n;
    let mut q = vec![0.0; n];
    let mut qd = vec![0.0; n];
    for (i, j) in chain.joints.iter().enumerate() {
        let th = chain.links[i].theta;
        if let Some((a, r, _)) = j.prescribed_state(0.0) {
            q[th] = a;
            qd[th] = r;
        } else {
            q[th] = if j.stiffness > 0.0 {
                j.set_point
            } else {
                chain.initial_joint_coordinate(i).0
            };
        }
    }
    let free = chain.free.clone();
    let nf = free.len();
    chain.evaluate(0.0, &q, &qd);
    let mass = Mat::<f64>::from_fn(nf, nf, |r, c| chain.mass[free[r] * n + free[c]]);
    let l_max = chain
        .links
        .iter()
        .map(|l| l.ints.length)
        .fold(0.0, f64::max);
    let mut stiff = Mat::<f64>::zeros(nf, nf);
    for (c, &gc) in free.iter().enumerate() {
        let h = if chain.links.iter().any(|l| l.theta == gc) {
            1e-8
        } else {
            1e-8 * l_max
        };
        let q0 = q[gc];
        q[gc] = q0 + h;
        chain.evaluate(0.0, &q, &qd);
        let fp: Vec<f64> = free.iter().map(|&g| chain.force[g]).collect();
        q[gc] = q0 - h;
        chain.evaluate(0.0, &q, &qd);
        for (r, &g) in free.iter().enumerate() {
            stiff[(r, c)] = -(fp[r] - chain.force[g]) / (2.0 * h);
        }
        q[gc] = q0;
    }
    let stiff = Mat::<f64>::from_fn(nf, nf, |r, c| 0.5 * (stiff[(r, c)] + stiff[(c, r)]));
    let (lambda, vecs) = generalized_eigen(&stiff, &mass)?;

    let count = count.min(nf);
    let scale = lambda
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-300);
    let mut frequencies = Vec::with_capacity(count);
    let mut kinds = Vec::with_capacity(count);
    let mut shapes = Vec::new();
    let ns = scene.simulation.field_stations.max(2);
    for k in 0..count {
        let lam = lambda[k];
        let f = if lam.abs() < 1e-12 * scale {
            0.0
        } else {
            lam.signum() * lam.abs().sqrt() / (2.0 * std::f64::consts::PI)
        };
        frequencies.push(f);
        // Kind by where the mode's kinetic energy sits (M-orthonormal vectors: xᵀMx = 1).
        let mut axial_share = 0.0;
        for l in &chain.links {
            let is_axial = |g: usize| g >= l.a0 && g < l.a0 + l.na();
            for (r, _) in free.iter().enumerate().filter(|(_, g)| is_axial(**g)) {
                for (c, _) in free.iter().enumerate().filter(|(_, g)| is_axial(**g)) {
                    axial_share += vecs[(r, k)] * mass[(r, c)] * vecs[(c, k)];
                }
            }
        }
        kinds.push(if f == 0.0 {
            "rigid".to_string()
        } else if axial_share > 0.5 {
            "axial".to_string()
        } else {
            "bending".to_string()
        });
        let mut per_link = Vec::new();
        let mut vmax = 0.0f64;
        for (i, l) in chain.links.iter().enumerate() {
            let nb = l.nb();
            let mut phi = vec![0.0; nb];
            let mut x = Vec::with_capacity(ns);
            let mut v = Vec::with_capacity(ns);
            for s in 0..ns {
                let xs = l.ints.length * s as f64 / (ns - 1) as f64;
                l.transverse.eval(xs, 0, &mut phi);
                let mut val = 0.0;
                for (m, p) in phi.iter().enumerate() {
                    if let Some(r) = free.iter().position(|&g| g == l.b0 + m) {
                        val += p * vecs[(r, k)];
                    }
                }
                vmax = vmax.max(val.abs());
                x.push(xs);
                v.push(val);
            }
            per_link.push(ModeShape {
                link: i + 1,
                x,
                transverse: v,
            });
        }
        for mut s in per_link {
            if vmax > 0.0 {
                s.transverse.iter_mut().for_each(|v| *v /= vmax);
            }
            shapes.push(s);
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
            dofs: nf,
            ..Cost::default()
        },
    })
}

/// The same analysis with the hub joint turning at the constant rate Ω (overrides the scene's
/// hub law): rotating-beam frequencies \[Hz\] for the λ studies.
pub fn rotating_modes(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &ModalSettings,
    hub_rate: f64,
    count: usize,
) -> Result<ModalResult, ModalError> {
    let mut spinning = pc.clone();
    if let Some(l) = spinning.links.first_mut() {
        l.joint.prescribed = Some(data::scene::PrescribedMotion::ConstantRate { rate: hub_rate });
    }
    modes(scene, &spinning, settings, count)
}

/// K x = λ M x by Cholesky reduction ([`crate::pencil::Pencil`]): ascending λ and
/// M-orthonormal x (columns).
pub fn generalized_eigen(k: &Mat<f64>, m: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), ModalError> {
    let mut pencil = Pencil::new(m.nrows());
    pencil
        .solve(k.as_ref(), m.as_ref())
        .map_err(|e| ModalError::Numerical {
            t: 0.0,
            message: match e {
                PencilError::MassNotPositiveDefinite => {
                    "reduced mass matrix is not positive definite".into()
                }
                PencilError::NoConvergence => "eigen-decomposition did not converge".into(),
            },
        })?;
    Ok((pencil.eigenvalues().to_vec(), pencil.vectors().to_owned()))
}
