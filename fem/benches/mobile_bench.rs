//! Criterion benches of the flexible mobile manipulator (seed 004, issue 19): one
//! implicit-midpoint step of `mobile-manipulator-flexible` for 2–16 elements at the default
//! step of 4 elements, and the default run over its first second.
//! Run: `cargo bench -p fem --bench mobile_bench -- --quick`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use data::{Backend, Settings};
use fem::FemBackend;
use fem::mobile::prepare;

fn one_step(c: &mut Criterion) {
    let sc = data::load_scene("mobile-manipulator-flexible").unwrap();
    let mut g = c.benchmark_group("mobile_flex_step");
    for n in [2, 4, 8, 16] {
        let mut s = Settings::default();
        s.discretization.elements = Some(n);
        s.time.dt = Some(3.2e-4);
        let mut p = prepare(
            &sc,
            sc.mobile_manipulator().unwrap(),
            &s.fem().expect("fem settings"),
        )
        .unwrap();
        let h = p.h;
        g.bench_with_input(BenchmarkId::new("implicit_midpoint", n), &n, |b, _| {
            b.iter(|| p.run.step(black_box(h)).unwrap())
        });
    }
    g.finish();
}

fn default_run(c: &mut Criterion) {
    let sc = data::load_scene("mobile-manipulator-flexible").unwrap();
    let mut s = Settings::default();
    s.time.t_end = Some(1.0);
    let mut g = c.benchmark_group("mobile_flex_run");
    g.sample_size(10);
    g.bench_function("mobile-manipulator-flexible_1s", |b| {
        b.iter(|| FemBackend.simulate(black_box(&sc), &s).unwrap())
    });
    g.finish();
}

criterion_group!(benches, one_step, default_run);
criterion_main!(benches);
