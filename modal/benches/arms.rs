//! Criterion benches of the Barhorst arm (issue 16). Without contact, 10 s each, at the default
//! settings (basis, modes, method and step chosen by the backend) and, for the undamped arm,
//! at other methods: Dormand–Prince at rtol 1e-8 (the explicit method, bound by the top Ritz
//! mode: ~1.8e5 steps per simulated second, about a minute a run on an idle 2-core machine, so
//! its 10 samples take ~10 minutes), the exponential method at h = 2.5e-4 (1.5e-4 rad from
//! Dormand–Prince on the 20 Hz low-passed hub angle over 10 s), and fixed-step TR-BDF2 at
//! h = 2.5e-4. The undamped default is the exponential method at its default step (2/ω_max,
//! ~8 000 steps per simulated second, 6.1e-6 rad from Dormand–Prince; docs/backends.md, "The
//! exponential method on the undamped arm"). The fixed step is a cost reference, not an
//! equivalent answer: it damps the ringing high modes, and its 20 Hz low-passed joint angles lie
//! 5.3e-3 rad (joint 1) and 8.5e-3 rad (joint 2) from Dormand–Prince at rtol 1e-6 over the 10 s
//! (2.1e-3 and 3.6e-3 rad within the first second, against rtol 1e-8).
//!
//! Run: `cargo bench -p modal --bench arms`. The group `arm 1 s` runs the first simulated second
//! of the undamped arm only (`cargo bench -p modal --bench arms -- 'arm 1 s'`).
//!
//! With contact, the group `contact 3 s converged switching` runs `barhorst-case1` and
//! `barhorst-case1-timoshenko` (3 s) at the resolution whose contact-episode boundaries lie
//! within 1e-3 s of the converged ones (10 modes, adaptive TR-BDF2 at rtol 1e-3, atol 1e-5;
//! the distances and the converged reference are in docs/contact.md):
//! `cargo bench -p modal --bench arms -- 'contact 3 s'`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use data::{Backend, Discretization, Settings, TimeStepping, load_scene};
use modal::ModalBackend;

fn arms(c: &mut Criterion) {
    let mut group = c.benchmark_group("arm 10 s");
    group.sample_size(10);
    let damped = load_scene("two-link-free").unwrap();
    group.bench_function("two-link-free default", |b| {
        b.iter(|| {
            black_box(
                ModalBackend
                    .simulate(&damped, &Settings::default())
                    .unwrap(),
            )
        })
    });
    let undamped = load_scene("two-link-free-undamped").unwrap();
    let fixed = Settings {
        time: TimeStepping {
            method: Some("trbdf2-fixed".parse().expect("a method name")),
            dt: Some(2.5e-4),
            ..Default::default()
        },
        ..Default::default()
    };
    group.bench_function("two-link-free-undamped trbdf2-fixed 2.5e-4", |b| {
        b.iter(|| black_box(ModalBackend.simulate(&undamped, &fixed).unwrap()))
    });
    group.bench_function("two-link-free-undamped default", |b| {
        b.iter(|| {
            black_box(
                ModalBackend
                    .simulate(&undamped, &Settings::default())
                    .unwrap(),
            )
        })
    });
    for (method, dt, label) in [
        ("dopri5", None, "dopri5"),
        ("exponential", Some(2.5e-4), "exponential 2.5e-4"),
    ] {
        let settings = Settings {
            time: TimeStepping {
                method: Some(method.parse().expect("a method name")),
                dt,
                ..Default::default()
            },
            ..Default::default()
        };
        group.bench_function(format!("two-link-free-undamped {label}"), |b| {
            b.iter(|| black_box(ModalBackend.simulate(&undamped, &settings).unwrap()))
        });
    }
    group.finish();
}

/// The first second of the undamped arm: the same configurations at a tenth of the cost, so
/// that a before/after comparison of the integrator fits in a couple of minutes.
fn arm_first_second(c: &mut Criterion) {
    let mut group = c.benchmark_group("arm 1 s");
    group.sample_size(10);
    let undamped = load_scene("two-link-free-undamped").unwrap();
    let over_one_second = |method: Option<&str>, dt: Option<f64>| Settings {
        time: TimeStepping {
            method: method.map(|m| m.parse().expect("a method name")),
            dt,
            t_end: Some(1.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let default = over_one_second(None, None);
    group.bench_function("two-link-free-undamped default", |b| {
        b.iter(|| black_box(ModalBackend.simulate(&undamped, &default).unwrap()))
    });
    let fixed = over_one_second(Some("trbdf2-fixed"), Some(2.5e-4));
    group.bench_function("two-link-free-undamped trbdf2-fixed 2.5e-4", |b| {
        b.iter(|| black_box(ModalBackend.simulate(&undamped, &fixed).unwrap()))
    });
    for (method, dt, label) in [
        ("dopri5", None, "dopri5"),
        ("exponential", Some(2.5e-4), "exponential 2.5e-4"),
    ] {
        let settings = over_one_second(Some(method), dt);
        group.bench_function(format!("two-link-free-undamped {label}"), |b| {
            b.iter(|| black_box(ModalBackend.simulate(&undamped, &settings).unwrap()))
        });
    }
    group.finish();
}

/// The contact scenes at the resolution whose switching times are within 1e-3 s of converged
/// (docs/contact.md, "Run time at switching times within 1e-3 s of converged").
fn contact_at_converged_switching(c: &mut Criterion) {
    let mut group = c.benchmark_group("contact 3 s converged switching");
    group.sample_size(10);
    let settings = Settings {
        discretization: Discretization {
            modes: Some(10),
            ..Default::default()
        },
        time: TimeStepping {
            method: Some("trbdf2".parse().expect("a method name")),
            rtol: Some(1e-3),
            atol: Some(1e-5),
            ..Default::default()
        },
    };
    for name in ["barhorst-case1", "barhorst-case1-timoshenko"] {
        let scene = load_scene(name).unwrap();
        group.bench_function(format!("{name} 10 modes trbdf2 rtol 1e-3"), |b| {
            b.iter(|| black_box(ModalBackend.simulate(&scene, &settings).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    arms,
    arm_first_second,
    contact_at_converged_switching
);
criterion_main!(benches);
