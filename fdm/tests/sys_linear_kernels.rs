//! The hand-written solver of the chain's implicit kick (`fdm::band_ldl::BandLdl`, LDLᵀ without
//! pivoting of a quasi-definite band) against faer's sparse LU with partial pivoting, on the
//! saddle systems the chain assembles at deformed, moving states (its bench:
//! `cargo bench -p fdm --bench chain -- implicit-kick-saddle`).

use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use fdm::chain::TwoLinkChain;

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
            let norm_a = triplets.iter().fold(0.0f64, |s, t| s.max(t.val.abs()));
            for c in 0..m {
                let x_norm = (0..n).fold(0.0f64, |s, i| s.max(rows[i * m + c].abs()));
                let b_norm = (0..n).fold(0.0f64, |s, i| s.max(rhs[(i, c)].abs()));
                // backward error of the band solution, ‖b − A x‖ / (‖A‖‖x‖ + ‖b‖), against n·ε
                let mut r: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
                for t in &triplets {
                    r[t.row] -= t.val * rows[t.col * m + c];
                }
                let backward =
                    r.iter().fold(0.0f64, |s, v| s.max(v.abs())) / (norm_a * x_norm + b_norm);
                assert!(
                    backward < f64::EPSILON * n as f64,
                    "{stations} stations, τ {tau}, column {c}: backward error {backward:e}"
                );
                for i in 0..n {
                    let (x, y) = (rows[i * m + c], reference[(i, c)]);
                    assert!(
                        (x - y).abs() <= 1e-11 * x_norm,
                        "{stations} stations, τ {tau}: x[{i}, {c}] {x:e} against faer's {y:e}"
                    );
                }
            }
        }
    }
}
