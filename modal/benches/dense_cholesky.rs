//! Criterion bench: the crate's Cholesky solve (`modal::linalg`) against faer's LLᵀ
//! (`faer::linalg::cholesky::llt`, sequential, scratch preallocated) on real reduced mass
//! matrices M(q) of `two-link-free` with n `poly` modes per link, one factorization plus one
//! solve each (what a right-hand side evaluation does).
//! Run: `cargo bench -p modal --bench dense_cholesky -- --quick`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use data::{Discretization, load_scene};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::{MatMut, Par};
use modal::linalg::{cholesky_factor, cholesky_substitute};
use modal::setup::build_chain;

fn mass_matrices(c: &mut Criterion) {
    let scene = load_scene("two-link-free").unwrap();
    let mut group = c.benchmark_group("reduced mass matrix: factor + solve");
    for modes in [4usize, 8, 16, 24] {
        let disc = Discretization {
            modes: Some(modes),
            ..Default::default()
        };
        let mut chain = build_chain(scene.planar_chain().unwrap(), &disc.modal().unwrap()).unwrap();
        let n = chain.n;
        let q: Vec<f64> = (0..n).map(|k| 1e-2 * (k as f64 + 1.0).sin()).collect();
        let qd: Vec<f64> = (0..n).map(|k| 1e-1 * (k as f64 + 2.0).cos()).collect();
        chain.evaluate(0.5, &q, &qd);
        let mass = chain.mass_matrix().to_vec();
        let rhs: Vec<f64> = (0..n).map(|k| (k as f64 + 0.5).cos()).collect();
        let (mut a, mut b) = (mass.clone(), rhs.clone());
        group.bench_with_input(BenchmarkId::new("modal::linalg", n), &n, |bench, _| {
            bench.iter(|| {
                a.copy_from_slice(&mass);
                b.copy_from_slice(&rhs);
                cholesky_factor(&mut a, n).unwrap();
                cholesky_substitute(&a, n, &mut b);
                black_box(&b);
            })
        });
        let mut mem = MemBuffer::new(
            llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default())
                .or(llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq)),
        );
        group.bench_with_input(BenchmarkId::new("faer llt", n), &n, |bench, _| {
            bench.iter(|| {
                a.copy_from_slice(&mass);
                b.copy_from_slice(&rhs);
                // Row-major storage of a symmetric matrix: its lower triangle is the same.
                let stack = MemStack::new(&mut mem);
                llt::factor::cholesky_in_place(
                    MatMut::from_row_major_slice_mut(&mut a, n, n),
                    Default::default(),
                    Par::Seq,
                    stack,
                    Default::default(),
                )
                .unwrap();
                llt::solve::solve_in_place(
                    faer::MatRef::from_row_major_slice(&a, n, n),
                    MatMut::from_column_major_slice_mut(&mut b, n, 1),
                    Par::Seq,
                    MemStack::new(&mut mem),
                );
                black_box(&b);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, mass_matrices);
criterion_main!(benches);
