//! The exact Newton matrix of chains with foreshortening — the augmented bordered band of
//! `fem::chain::AugmentedLayout`, reduced to the chain DOFs by eliminating its running-sum
//! unknowns — is the derivative S = ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q of the residual, checked
//! against central finite differences of the residual on generic and on real states.

// Index loops mirror the matrix formulas being checked.
#![allow(clippy::needless_range_loop)]

mod common;

use data::FemElement;
use fem::chain::{Chain, NewtonCoefficients};

const T: f64 = 0.3;

/// Dense n × n matrix of the chain DOFs: the Schur complement A_qq − A_qx A_xx⁻¹ A_xq of the
/// augmented matrix formed at (q, q̇, q̈) (Gaussian elimination of the auxiliary unknowns
/// with partial pivoting).
fn exact_matrix(
    ch: &mut Chain,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    c: NewtonCoefficients,
) -> Vec<Vec<f64>> {
    let n = ch.ndof;
    let mut r = vec![0.0; n];
    ch.residual(T, q, qd, qdd, &mut r);
    let lay = ch.augmented_layout();
    let mut s = ch.new_augmented_matrix(&lay);
    ch.exact_newton_matrix(q, qd, qdd, c, &lay, &mut s);
    let na = lay.n;
    // Order: chain DOFs first (in chain numbering), then the auxiliary unknowns.
    let mut order = lay.map.clone();
    let mut is_chain = vec![false; na];
    for &i in &lay.map {
        is_chain[i] = true;
    }
    order.extend((0..na).filter(|&i| !is_chain[i]));
    let mut a: Vec<Vec<f64>> = order
        .iter()
        .map(|&i| order.iter().map(|&j| s.get(i, j)).collect())
        .collect();
    // Eliminate the auxiliary block (rows/columns n..na) into the chain block.
    for k in (n..na).rev() {
        // Pivot within the remaining auxiliary rows n..=k.
        let p = (n..=k)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap();
        a.swap(p, k);
        let d = a[k][k];
        assert!(d != 0.0, "singular auxiliary block");
        for i in 0..k {
            let l = a[i][k] / d;
            if l != 0.0 {
                for j in 0..k {
                    a[i][j] -= l * a[k][j];
                }
            }
        }
    }
    a.truncate(n);
    a.iter_mut().for_each(|row| row.truncate(n));
    a
}

/// The combined derivative of the residual by central differences with step `eps`.
fn fd_matrix(
    ch: &mut Chain,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    c: NewtonCoefficients,
    eps: f64,
) -> Vec<Vec<f64>> {
    let n = ch.ndof;
    let mut s = vec![vec![0.0; n]; n];
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        for (k, coef) in [(0, c.c_a), (1, c.c_v), (2, c.c_q)] {
            let mut x = [q.to_vec(), qd.to_vec(), qdd.to_vec()];
            let slot = [2, 1, 0][k];
            x[slot][j] += eps;
            ch.residual(T, &x[0], &x[1], &x[2], &mut rp);
            x[slot][j] -= 2.0 * eps;
            ch.residual(T, &x[0], &x[1], &x[2], &mut rm);
            for i in 0..n {
                s[i][j] += coef * (rp[i] - rm[i]) / (2.0 * eps);
            }
        }
    }
    s
}

fn max_diff(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(u, v)| (u - v).abs()))
        .fold(0.0, f64::max)
}

/// Checks the exact matrix against finite differences at one state; the tolerance is the
/// finite-difference error itself, estimated from the steps ε and 2ε (central differences:
/// truncation ∝ ε², so FD(ε) is off by ≈ |FD(2ε) − FD(ε)|/3, plus round-off ε_mach|R|/ε),
/// with a factor 10 of margin. The bordered-band matrix without the foreshortening couplings
/// must miss it by far (the check can tell the two apart).
fn check(label: &str, ch: &mut Chain, q: &[f64], qd: &[f64], qdd: &[f64], c: NewtonCoefficients) {
    let n = ch.ndof;
    let exact = exact_matrix(ch, q, qd, qdd, c);
    let eps = 1e-6;
    let fd = fd_matrix(ch, q, qd, qdd, c, eps);
    let fd2 = fd_matrix(ch, q, qd, qdd, c, 2.0 * eps);
    let scale = fd.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let fd_error = max_diff(&fd, &fd2);
    let mut r = vec![0.0; n];
    ch.residual(T, q, qd, qdd, &mut r);
    let r_scale = r.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let tol = 10.0 * (fd_error + f64::EPSILON * r_scale / eps);
    let worst = max_diff(&exact, &fd);
    // The banded matrix of the chain DOFs omits the couplings.
    let mut band = ch.new_matrix();
    ch.residual(T, q, qd, qdd, &mut r);
    ch.newton_matrix(q, c, &mut band);
    let band_dense: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| band.get(i, j)).collect())
        .collect();
    let band_worst = max_diff(&band_dense, &fd);
    eprintln!(
        "{label}: n = {n}, |S − FD| = {worst:.2e}, tolerance {tol:.2e}, banded {band_worst:.2e}, \
         scale {scale:.2e}"
    );
    assert!(
        worst <= tol,
        "{label}: exact matrix off by {worst:.3e} > {tol:.3e} (scale {scale:.3e})"
    );
    assert!(
        band_worst > 100.0 * tol,
        "{label}: the banded matrix is as close ({band_worst:.3e}): the check cannot tell"
    );
}

/// A generic state of a scene with every effect on (tip masses and inertias, hub inertias,
/// gravity, foreshortening), as in `sys_chain`.
fn generic(name: &str, n_el: usize, element: Option<FemElement>) -> (Chain, [Vec<f64>; 3]) {
    let mut sc = data::load_scene(name).unwrap();
    for l in sc.planar_chain_mut().unwrap().links.iter_mut() {
        l.foreshortening = !l.axial;
        l.tip_mass = Some(0.3);
        l.tip_inertia = Some(0.01);
        l.joint.hub_inertia = Some(0.02);
    }
    sc.planar_chain_mut().unwrap().gravity = Some(data::scene::Gravity {
        vector: [0.3, -9.0],
    });
    let ch = Chain::with_element(sc.links(), sc.gravity(), n_el, element).unwrap();
    let n = ch.ndof;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    ch.initial_state(&mut q, &mut qd);
    let mut qdd = vec![0.0; n];
    for i in 0..n {
        q[i] += 0.05 * (i as f64 * 1.3).sin();
        qd[i] = 0.5 * (i as f64 * 0.7).cos();
        qdd[i] = 3.0 * (i as f64 * 2.1).sin();
    }
    (ch, [q, qd, qdd])
}

#[test]
fn sys_exact_matrix_is_the_residual_derivative_at_generic_states() {
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.01,
        c_q: 1e-4,
    };
    for (name, element) in [
        ("single-link", None),
        ("two-link-free-undamped", None),
        ("two-link-free-undamped", Some(FemElement::HermiteQuintic)),
        ("barhorst-case1-timoshenko", None),
        ("spin-up", None),
    ] {
        let (mut ch, [q, qd, qdd]) = generic(name, 3, element);
        check(&format!("{name} {element:?}"), &mut ch, &q, &qd, &qdd, c);
    }
}

/// The default run of `name` advanced to 0.25 s: its chain, (q, q̇, q̈) and the energy-midpoint
/// coefficients of its step (c_a = 1, c_v = h/2, c_q = h²/4).
fn real_state(name: &str) -> (Chain, [Vec<f64>; 3], NewtonCoefficients) {
    let p = common::advanced_default_run(name, 0.25);
    let h = p.h_nominal;
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.5 * h,
        c_q: 0.25 * h * h,
    };
    let st = &p.driver.state;
    (
        p.driver.chain.clone(),
        [st.q.clone(), st.qd.clone(), st.qdd.clone()],
        c,
    )
}

#[test]
fn sys_exact_matrix_is_the_residual_derivative_at_real_states() {
    // The default runs at 0.25 s ([`real_state`]).
    for name in ["two-link-free", "barhorst-case1"] {
        let (mut ch, [q, qd, qdd], c) = real_state(name);
        check(name, &mut ch, &q, &qd, &qdd, c);
    }
}

#[test]
fn sys_band_lu_solves_the_exact_matrix_as_faer_sparse_lu_at_real_states() {
    // The exact augmented matrix is factorized by the hand-written band LU with a dense border
    // Schur complement (`BorderedBand::with_band_solver`); faer's sparse LU of the same pattern
    // (`BorderedBand::new`) is the reference. Real states: the default runs at 0.25 s.
    for name in ["two-link-free", "barhorst-case1"] {
        let (mut ch, [q, qd, qdd], c) = real_state(name);
        let mut r = vec![0.0; ch.ndof];
        ch.residual(T, &q, &qd, &qdd, &mut r);
        let lay = ch.augmented_layout();
        let mut band = ch.new_augmented_matrix(&lay);
        ch.exact_newton_matrix(&q, &qd, &qdd, c, &lay, &mut band);
        let mut sparse = fem::band::BorderedBand::new(
            lay.n_interior,
            lay.n - lay.n_interior,
            lay.half_bandwidth,
        );
        ch.exact_newton_matrix(&q, &qd, &qdd, c, &lay, &mut sparse);
        band.factorize().unwrap();
        sparse.factorize().unwrap();
        let n = lay.n;
        // Right-hand sides: the residual on the chain rows, and a ramp over every unknown.
        let mut from_residual = vec![0.0; n];
        for (k, &i) in lay.map.iter().enumerate() {
            from_residual[i] = r[k];
        }
        let ramp: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).sin()).collect();
        for rhs in [from_residual, ramp] {
            let (mut x_band, mut x_sparse) = (rhs.clone(), rhs.clone());
            band.solve_in_place(&mut x_band);
            sparse.solve_in_place(&mut x_sparse);
            let norm = x_sparse.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = x_band
                .iter()
                .zip(&x_sparse)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            // Normwise backward error ‖A x − b‖ / (‖A‖ ‖x‖ + ‖b‖) of each solution against the
            // assembled matrix (∞-norms): a stable LU leaves a small multiple of ε.
            let a_norm = (0..n)
                .map(|i| (0..n).map(|j| band.get(i, j).abs()).sum::<f64>())
                .fold(0.0f64, f64::max);
            let rhs_norm = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let backward_error = |m: &fem::band::BorderedBand, x: &[f64]| {
                let mut ax = vec![0.0; n];
                m.matvec(x, &mut ax);
                let res = ax
                    .iter()
                    .zip(&rhs)
                    .fold(0.0f64, |acc, (a, b)| acc.max((a - b).abs()));
                let x_norm = x.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
                res / (a_norm * x_norm + rhs_norm)
            };
            let (eta_band, eta_sparse) = (
                backward_error(&band, &x_band),
                backward_error(&sparse, &x_sparse),
            );
            eprintln!(
                "{name}: n = {n}, |x_band − x_faer|/|x| = {:.2e}, backward error band {:.2e}, faer {:.2e}",
                diff / norm,
                eta_band,
                eta_sparse
            );
            // Partial pivoting: backward error within n·ε (no growth on these matrices).
            let bound = n as f64 * f64::EPSILON;
            assert!(
                eta_band <= bound,
                "{name}: band backward error {eta_band:e}"
            );
            assert!(
                eta_sparse <= bound,
                "{name}: faer backward error {eta_sparse:e}"
            );
            assert!(diff <= 1e-9 * norm, "{name}: {diff:e} against {norm:e}");
        }
    }
}
