//! The chain's hand-written solvers against faer, on the matrices the chain assembles at
//! deformed, moving states:
//! - the implicit kick's (`fdm::band_ldl::BandLdl`, LDLᵀ without pivoting of a quasi-definite
//!   band) against faer's sparse LU with partial pivoting (bench:
//!   `cargo bench -p fdm --bench chain -- implicit-kick-saddle`);
//! - the mass solve's foreshortening-rate blocks (`fdm::tridiagonal::TridiagonalLdl`) against
//!   faer's sparse Cholesky (bench: `cargo bench -p fdm --bench chain -- link-rates-tridiagonal`);
//! - the implicit kick's small Schur system (`fdm::chain::schur::SmallLu`, Gaussian elimination
//!   with partial pivoting) against faer's dense LU (bench:
//!   `cargo bench -p fdm --bench chain -- small-schur-lu`).

use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use fdm::chain::TwoLinkChain;
use fdm::chain::schur::{MAX_SMALL, SmallLu};
use fdm::tridiagonal::TridiagonalLdl;

/// The two-link-free chain with `stations` per link, implicit damping on, and a deformed,
/// moving state (q, q̇) of it.
fn chain_at_a_state(stations: usize) -> (TwoLinkChain, Vec<f64>, Vec<f64>) {
    let scene = data::load_scene("two-link-free").expect("catalog scene");
    let mut chain =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(stations))
            .expect("chain");
    assert!(chain.enable_implicit_damping());
    let n = fdm::system::System::dofs(&chain);
    let q = (0..n)
        .map(|i| 0.3 + 0.02 * (0.9 * i as f64).sin())
        .collect();
    let qd = (0..n).map(|i| 0.3 * (1.7 * i as f64).cos()).collect();
    (chain, q, qd)
}

#[test]
fn sys_band_ldl_solves_the_implicit_kick_saddle_as_faer_sparse_lu() {
    for stations in [11usize, 21, 41, 81] {
        for tau in [1e-5, 1e-3] {
            let (mut chain, q, qd) = chain_at_a_state(stations);
            let mut band = chain.implicit_kick_saddle(&q, &qd, tau);
            let n = band.n();
            let triplets: Vec<Triplet<usize, usize, f64>> = band
                .entries()
                .map(|(i, j, v)| Triplet::new(i, j, v))
                .collect();
            let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets).unwrap();
            // it is a saddle system: both signs on the diagonal
            let diag: Vec<f64> = (0..n)
                .map(|i| {
                    triplets
                        .iter()
                        .filter(|t| t.row == i && t.col == i)
                        .map(|t| t.val)
                        .sum()
                })
                .collect();
            assert!(diag.iter().any(|&d| d > 0.0) && diag.iter().any(|&d| d < 0.0));
            let m = 8;
            let rhs = Mat::<f64>::from_fn(n, m, |i, c| {
                (0.37 * (i + 3 * c) as f64).cos() + if i % (c + 2) == 0 { 1.0 } else { 0.0 }
            });
            let reference = a.sp_lu().expect("faer sparse LU").solve(&rhs);
            band.factor().expect("quasi-definite: the LDLᵀ exists");
            let mut rows: Vec<f64> = (0..n * m).map(|k| rhs[(k / m, k % m)]).collect();
            band.solve_rows_in_place(&mut rows, m);
            for c in 0..m {
                let x: Vec<f64> = (0..n).map(|i| rows[i * m + c]).collect();
                let b: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
                let x_norm = x.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                let backward = backward_error(&triplets, &x, &b);
                assert!(
                    backward < f64::EPSILON * n as f64,
                    "{stations} stations, τ {tau}, column {c}: backward error {backward:e}"
                );
                for i in 0..n {
                    let y = reference[(i, c)];
                    assert!(
                        (x[i] - y).abs() <= 1e-11 * x_norm,
                        "{stations} stations, τ {tau}: x[{i}, {c}] {:e} against faer's {y:e}",
                        x[i]
                    );
                }
            }
        }
    }
}

/// Backward error ‖b − A x‖∞ / (‖A‖max ‖x‖∞ + ‖b‖∞) of one solution column, held to n·ε.
fn backward_error(triplets: &[Triplet<usize, usize, f64>], x: &[f64], b: &[f64]) -> f64 {
    let mut r = b.to_vec();
    for t in triplets {
        r[t.row] -= t.val * x[t.col];
    }
    let norm = |v: &[f64]| v.iter().fold(0.0f64, |s, e| s.max(e.abs()));
    let norm_a = triplets.iter().fold(0.0f64, |s, t| s.max(t.val.abs()));
    norm(&r) / (norm_a * norm(x) + norm(b))
}

#[test]
fn sys_tridiagonal_ldl_solves_the_link_rate_blocks_as_faer_sparse_cholesky() {
    for stations in [11usize, 21, 41, 81] {
        let (mut chain, q, qd) = chain_at_a_state(stations);
        for link in 0..2 {
            let (diag, off) = chain.link_rate_block(&q, &qd, link);
            let r = diag.len();
            assert_eq!(off.len(), r - 1);
            // the deformed state gives the block its slope terms: off-diagonals that differ
            // from the undeformed −1/W
            assert!(off.windows(2).any(|p| p[0] != p[1]));
            let mut triplets = Vec::new();
            for a in 0..r {
                triplets.push(Triplet::new(a, a, diag[a]));
                if a + 1 < r {
                    triplets.push(Triplet::new(a + 1, a, off[a]));
                    triplets.push(Triplet::new(a, a + 1, off[a]));
                }
            }
            let a = SparseColMat::<usize, f64>::try_new_from_triplets(r, r, &triplets).unwrap();
            // the mass solve's seven right-hand sides, stored by rows
            let m = 7;
            let rhs = Mat::<f64>::from_fn(r, m, |i, c| {
                (0.37 * (i + 3 * c) as f64).cos() + if i % (c + 2) == 0 { 1.0 } else { 0.0 }
            });
            let reference = a
                .sp_cholesky(faer::Side::Lower)
                .expect("SPD: faer's sparse Cholesky exists")
                .solve(&rhs);
            let mut ldl = TridiagonalLdl::new(r);
            ldl.factor(|i| diag[i], |i| off[i])
                .expect("SPD: the LDLᵀ exists");
            let mut rows: Vec<f64> = (0..r * m).map(|k| rhs[(k / m, k % m)]).collect();
            ldl.solve_rows_in_place(&mut rows, m);
            for c in 0..m {
                let x: Vec<f64> = (0..r).map(|i| rows[i * m + c]).collect();
                let b: Vec<f64> = (0..r).map(|i| rhs[(i, c)]).collect();
                let backward = backward_error(&triplets, &x, &b);
                assert!(
                    backward < f64::EPSILON * r as f64,
                    "{stations} stations, link {link}, column {c}: backward error {backward:e}"
                );
                let x_norm = x.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                for i in 0..r {
                    let y = reference[(i, c)];
                    assert!(
                        (x[i] - y).abs() <= 1e-11 * x_norm,
                        "{stations} stations, link {link}: x[{i}, {c}] {:e} against faer's {y:e}",
                        x[i]
                    );
                }
            }
        }
    }
}

#[test]
fn sys_small_lu_solves_the_implicit_kick_schur_system_as_faer_dense_lu() {
    for stations in [11usize, 21, 41, 81] {
        for tau in [1e-5, 1e-3] {
            let (mut chain, q, qd) = chain_at_a_state(stations);
            let (s, n) = chain.implicit_kick_schur(&q, &qd, tau);
            // the full columns θ, β, ψ₁, ψ₂, y and the two foreshortening columns
            assert_eq!(n, MAX_SMALL);
            let a = Mat::<f64>::from_fn(n, n, |i, j| s[i][j]);
            let lu = a.partial_piv_lu();
            let triplets: Vec<Triplet<usize, usize, f64>> = (0..n)
                .flat_map(|i| (0..n).map(move |j| Triplet::new(i, j, s[i][j])))
                .collect();
            let small = SmallLu::factor(s, n);
            for c in 0..3 {
                let b: [f64; MAX_SMALL] = std::array::from_fn(|i| {
                    (0.37 * (i + 3 * c) as f64).cos() + if i % (c + 2) == 0 { 1.0 } else { 0.0 }
                });
                let reference = lu.solve(Mat::<f64>::from_fn(n, 1, |i, _| b[i]));
                let x = small.solve(b);
                let backward = backward_error(&triplets, &x[..n], &b[..n]);
                assert!(
                    backward < f64::EPSILON * n as f64,
                    "{stations} stations, τ {tau}, right-hand side {c}: backward error {backward:e}"
                );
                let x_norm = x[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for i in 0..n {
                    let y = reference[(i, 0)];
                    assert!(
                        (x[i] - y).abs() <= 1e-11 * x_norm,
                        "{stations} stations, τ {tau}: x[{i}] {:e} against faer's {y:e}",
                        x[i]
                    );
                }
            }
        }
    }
}
