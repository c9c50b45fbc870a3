//! Criterion benches of the chain right-hand side (issue 16): one evaluation y' = f(t, y) of
//! `two-link-free-undamped` (14 DOFs, two foreshortening links of 6 poly modes: the exact
//! inextensible kinetic terms dominate) at a deflected, moving state, and the first 0.1 s of
//! the run at the default settings (Dormand–Prince, ~1.1e4 right-hand sides).
//!
//! Run: `cargo bench -p modal --bench rhs`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use data::{Backend, ModalSettings, Settings, TimeStepping, load_scene};
use modal::ModalBackend;
use modal::integrate::OdeRhs;
use modal::rhs::ChainRhs;
use modal::setup::build_chain;

fn one_rhs(c: &mut Criterion) {
    let scene = load_scene("two-link-free-undamped").unwrap();
    let chain = build_chain(scene.planar_chain().unwrap(), &ModalSettings::default()).unwrap();
    let mut rhs = ChainRhs::new(chain);
    let mut y = rhs.initial_state();
    // A deflected, moving state: every coordinate and rate nonzero (no zero-skipping shortcut).
    let nf = rhs.chain.free.len();
    for (k, v) in y.iter_mut().enumerate().take(2 * nf) {
        let scale = if k < nf { 1e-3 } else { 1e-1 };
        *v += scale * (1.0 + k as f64).sin();
    }
    let mut dydt = vec![0.0; y.len()];
    let mut group = c.benchmark_group("two-link-free-undamped rhs");
    group.bench_function("one evaluation", |b| {
        b.iter(|| {
            rhs.eval(0.5, black_box(&y), &mut dydt);
            black_box(&dydt);
        })
    });
    group.finish();
}

fn short_run(c: &mut Criterion) {
    let scene = load_scene("two-link-free-undamped").unwrap();
    let settings = Settings {
        time: TimeStepping {
            t_end: Some(0.1),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut group = c.benchmark_group("two-link-free-undamped 0.1 s");
    group.sample_size(10);
    group.bench_function("default", |b| {
        b.iter(|| black_box(ModalBackend.simulate(&scene, &settings).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, one_rhs, short_run);
criterion_main!(benches);
