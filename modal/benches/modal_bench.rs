//! Criterion benches: one right-hand-side evaluation of the spin-up chain and a full 20 s
//! spin-up run, both against the number of clamped-free modes.
//! Run: `CARGO_TARGET_DIR=/work/targets/modal cargo bench -p modal --bench modal_bench -- --quick`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use data::{Backend, Discretization, Settings, TimeStepping, load_scene};
use modal::ModalBackend;
use modal::setup::build_chain;

fn rhs(c: &mut Criterion) {
    let scene = load_scene("spin-up").unwrap();
    let mut group = c.benchmark_group("spin-up rhs evaluation");
    for n in [2usize, 4, 6, 8, 12] {
        let disc = Discretization {
            modes: Some(n),
            ..Default::default()
        };
        let mut chain = build_chain(scene.planar_chain().unwrap(), &disc.modal().unwrap()).unwrap();
        let q: Vec<f64> = (0..chain.n)
            .map(|k| 1e-2 * (k as f64 + 1.0).sin())
            .collect();
        let qd: Vec<f64> = (0..chain.n)
            .map(|k| 1e-1 * (k as f64 + 2.0).cos())
            .collect();
        let mut qdd = vec![0.0; chain.n];
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                chain.evaluate(3.0, black_box(&q), black_box(&qd));
                chain.accelerations(3.0, &mut qdd).unwrap();
                black_box(&qdd);
            })
        });
    }
    group.finish();
}

fn full_run(c: &mut Criterion) {
    let scene = load_scene("spin-up").unwrap();
    let mut group = c.benchmark_group("spin-up 20 s run (rtol 1e-6)");
    group.sample_size(10);
    for n in [2usize, 4, 6, 8] {
        let settings = Settings {
            discretization: Discretization {
                modes: Some(n),
                ..Default::default()
            },
            time: TimeStepping {
                rtol: Some(1e-6),
                atol: Some(1e-9),
                ..Default::default()
            },
        };
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| black_box(ModalBackend.simulate(&scene, &settings).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(benches, rhs, full_run);
criterion_main!(benches);
