//! Cost of the modal rocket: set-up (eigenfunctions + integrals) and a short run.
//!
//! Needs in modal/Cargo.toml:
//! ```toml
//! [[bench]]
//! name = "rocket"
//! harness = false
//! ```
//! Run: `CARGO_TARGET_DIR=/work/targets/rocketmodal cargo bench -p modal --bench rocket -- --quick`

use criterion::{Criterion, criterion_group, criterion_main};
use data::{Discretization, Settings, load_scene};

fn settings(modes: usize) -> Settings {
    Settings {
        discretization: Discretization {
            modes: Some(modes),
            ..Default::default()
        },
        ..Default::default()
    }
}

fn bench(c: &mut Criterion) {
    let scene = load_scene("rocket").unwrap();
    let mut short = scene.clone();
    short.simulation.t_end = 0.01;
    let mut g = c.benchmark_group("rocket");
    g.sample_size(10);
    for n in [4, 6, 12] {
        g.bench_function(format!("modes_n{n}"), |b| {
            b.iter(|| {
                modal::rocket::modes(
                    &scene,
                    scene.rocket().unwrap(),
                    &settings(n).modal().unwrap(),
                    6,
                )
                .unwrap()
            })
        });
        g.bench_function(format!("simulate_10ms_n{n}"), |b| {
            b.iter(|| {
                modal::rocket::simulate(
                    &short,
                    short.rocket().unwrap(),
                    &settings(n).modal().unwrap(),
                )
                .unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
