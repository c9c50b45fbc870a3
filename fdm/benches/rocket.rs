//! 0.1 s of rocket flight with h = 2 in (76 stations), single-threaded.
//! Run: CARGO_TARGET_DIR=/work/targets/fdm cargo bench -p fdm --bench rocket -- --quick

use criterion::{Criterion, criterion_group, criterion_main};
use data::{Settings, load_scene};
use fdm::ValidatedSettings;

fn bench(c: &mut Criterion) {
    let scene = load_scene("rocket").expect("catalog scene");
    for (label, method) in [("report", "report"), ("velocity-form", "velocity-form")] {
        let mut settings = Settings::default();
        settings.time.method = Some(method.parse().expect("a method name"));
        let s = ValidatedSettings::from_settings(&settings.fdm().expect("fdm settings"))
            .expect("valid settings");
        c.bench_function(&format!("rocket_0.1s_76_stations_{label}"), |b| {
            b.iter(|| {
                let (_, out) =
                    fdm::runs::rocket_with(&scene, scene.rocket().unwrap(), &s, true).expect("run");
                std::hint::black_box(out.cost.steps)
            })
        });
    }
    for n in [151usize, 301] {
        let mut settings = Settings::default();
        settings.discretization.stations = Some(n);
        settings.time.t_end = Some(0.01);
        settings.time.method = Some("velocity-form".parse().expect("a method name"));
        let s = ValidatedSettings::from_settings(&settings.fdm().expect("fdm settings"))
            .expect("valid settings");
        c.bench_function(&format!("rocket_0.01s_{n}_stations_velocity-form"), |b| {
            b.iter(|| {
                let (_, out) =
                    fdm::runs::rocket_with(&scene, scene.rocket().unwrap(), &s, true).expect("run");
                std::hint::black_box(out.cost.steps)
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
