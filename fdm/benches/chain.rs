//! `two-link-free` (joint dampers + Kelvin–Voigt), 1 s, single-threaded: the default (damping
//! implicit in the velocity form's closing kick, the undamped step bound) at 21 and 41
//! stations per link, and the explicit damping (the damped step bound) at 21 stations over
//! 0.1 s for comparison (×10 for the same simulated time); `two-link-free-undamped`, 1 s at
//! 21 stations: the velocity form with its time-symmetric corrector pass (one more Γ
//! evaluation and mass solve per step, the rest kept from the first pass); `barhorst-case1`,
//! 0.5 s at 21 stations (the drop, the first impacts and the held phases): the contact run's
//! default, damping implicit with the held tip's force in the kick.
//! Run: cargo bench -p fdm --bench chain -- --quick

use criterion::{Criterion, criterion_group, criterion_main};
use data::load_scene;
use fdm::ValidatedSettings;
use fdm::chain::TwoLinkChain;
use fdm::driver::{StepControl, integrate};

fn settings(stations: usize, t_end: f64) -> ValidatedSettings {
    let requested = data::FdmSettings {
        stations: Some(stations),
        t_end: Some(t_end),
        ..Default::default()
    };
    ValidatedSettings::from_settings(&requested).expect("valid settings")
}

fn bench(c: &mut Criterion) {
    let scene = load_scene("two-link-free").expect("catalog scene");
    let mut group = c.benchmark_group("two_link_free");
    group.sample_size(10);
    for n in [21usize, 41] {
        let s = settings(n, 1.0);
        group.bench_function(format!("1s_{n}_stations_implicit_damping"), |b| {
            b.iter(|| {
                let out = fdm::runs::two_link_chain(&scene, scene.planar_chain().unwrap(), &s)
                    .expect("run");
                std::hint::black_box(out.cost.steps)
            })
        });
    }
    let s = settings(21, 0.1);
    group.bench_function("0.1s_21_stations_explicit_damping", |b| {
        b.iter(|| {
            let mut sys =
                TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), s.stations)
                    .expect("chain");
            let (q0, v0) = sys.initial_state();
            let ctl = StepControl {
                method: fdm::Method::VelocityForm,
                safety: s.safety,
                forced_dt: None,
                t_end: 0.1,
                output_interval: scene.simulation.output_interval,
                log_change: s.step_log_change,
                lookahead: false,
                enforce_bound: true,
            };
            let out = integrate(&mut sys, &q0, &v0, &ctl).expect("run");
            std::hint::black_box(out.cost.steps)
        })
    });
    group.finish();
    let undamped = load_scene("two-link-free-undamped").expect("catalog scene");
    let mut group = c.benchmark_group("two_link_free_undamped");
    group.sample_size(10);
    let s = settings(21, 1.0);
    group.bench_function("1s_21_stations_symmetric_inertia", |b| {
        b.iter(|| {
            let out = fdm::runs::two_link_chain(&undamped, undamped.planar_chain().unwrap(), &s)
                .expect("run");
            std::hint::black_box(out.cost.steps)
        })
    });
    group.finish();
}

fn contact(c: &mut Criterion) {
    let scene = load_scene("barhorst-case1").expect("catalog scene");
    let mut group = c.benchmark_group("barhorst_case1");
    group.sample_size(10);
    let s = settings(21, 0.5);
    group.bench_function("0.5s_21_stations_implicit_damping", |b| {
        b.iter(|| {
            let (out, _) =
                fdm::runs::two_link_chain_with_contact(&scene, scene.planar_chain().unwrap(), &s)
                    .expect("run");
            std::hint::black_box(out.cost.steps)
        })
    });
    group.finish();
}

criterion_group!(benches, bench, contact);
criterion_main!(benches);
