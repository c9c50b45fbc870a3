//! Criterion bench of the 3-D payload link (seed 002): `single-link-3d` over its first second
//! (bang-bang torque through both switches, from the static sag) at the default settings
//! (6 `poly` modes per field, 25 coordinates, adaptive TR-BDF2 with the analytic Jacobian), and
//! its modes and statics.
//!
//! Run: `cargo bench -p modal --bench payload_link`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use data::{Backend, Settings, TimeStepping, load_scene};
use modal::ModalBackend;

fn payload_link(c: &mut Criterion) {
    let scene = load_scene("single-link-3d").unwrap();
    let mut group = c.benchmark_group("single-link-3d");
    group.sample_size(10);
    let one_second = Settings {
        time: TimeStepping {
            t_end: Some(1.0),
            ..Default::default()
        },
        ..Default::default()
    };
    group.bench_function("run 1 s default", |b| {
        b.iter(|| black_box(ModalBackend.simulate(&scene, &one_second).unwrap()))
    });
    group.bench_function("modes 6", |b| {
        b.iter(|| black_box(ModalBackend.modes(&scene, &Settings::default(), 6).unwrap()))
    });
    group.bench_function("statics", |b| {
        b.iter(|| black_box(ModalBackend.statics(&scene, &Settings::default()).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, payload_link);
criterion_main!(benches);
