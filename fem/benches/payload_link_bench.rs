//! Criterion benches of the 3-D payload link (seed 002): one implicit-midpoint step of
//! `single-link-3d` for 8–32 elements, and the default run of `single-link-3d` over its first
//! second (default mesh and step).
//! Run: `cargo bench -p fem --bench payload_link_bench -- --quick`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use data::{Backend, Settings};
use fem::FemBackend;
use fem::driver::fixed_steps::QuarterRetries;
use fem::payload_link::prepare;

fn one_step(c: &mut Criterion) {
    let sc = data::load_scene("single-link-3d").unwrap();
    let mut g = c.benchmark_group("payload_link_step");
    for n in [8, 16, 32] {
        let mut s = Settings::default();
        s.discretization.elements = Some(n);
        let mut p = prepare(
            &sc,
            sc.payload_link().unwrap(),
            &s.fem().expect("fem settings"),
        )
        .unwrap();
        let h = p.h;
        g.bench_with_input(BenchmarkId::new("implicit_midpoint", n), &n, |b, _| {
            b.iter(|| {
                let t1 = p.stepper.steps.state.t + h;
                p.stepper.step(black_box(h), t1).unwrap()
            })
        });
    }
    g.finish();
}

fn default_run(c: &mut Criterion) {
    let sc = data::load_scene("single-link-3d").unwrap();
    let mut s = Settings::default();
    s.time.t_end = Some(1.0);
    let mut g = c.benchmark_group("payload_link_run");
    g.sample_size(10);
    g.bench_function("single-link-3d_1s", |b| {
        b.iter(|| FemBackend.simulate(black_box(&sc), &s).unwrap())
    });
    g.finish();
}

criterion_group!(benches, one_step, default_run);
criterion_main!(benches);
