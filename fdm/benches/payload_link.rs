//! 1 s of `single-link-3d` (u, v, w, φ at 21 stations, free base, gravity, implicit
//! Kelvin–Voigt; ≈ 101 000 steps), single-threaded.
//! Run: cargo bench -p fdm --bench payload_link -- --quick

use criterion::{Criterion, criterion_group, criterion_main};
use data::{Backend, Settings, load_scene};
use fdm::FdmBackend;

fn bench(c: &mut Criterion) {
    let scene = load_scene("single-link-3d").expect("catalog scene");
    let mut settings = Settings::default();
    settings.time.t_end = Some(1.0);
    let mut group = c.benchmark_group("payload_link");
    group.sample_size(10);
    group.bench_function("single-link-3d_1s_21_stations", |b| {
        b.iter(|| {
            let r = FdmBackend.simulate(&scene, &settings).expect("run");
            std::hint::black_box(r.cost.steps)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
