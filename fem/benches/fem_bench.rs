//! Criterion benches: assembly (residual + Newton matrix; the exact augmented matrix of the
//! foreshortening arm with its factorization and a solve), one generalized-α step, the full
//! 20 s spin-up for 4–64 elements, and the full 3 s `single-link` run at default settings with
//! energy-midpoint (the default there) and generalized-α; whole default runs of the arms
//! (`two-link-free-undamped` 10 s, `barhorst-case1` 3 s) and the first second of
//! `two-link-free-undamped` (`arms-1s`); `barhorst-case1` over t ∈ [0, 0.5] s (`contact-0.5s`:
//! the drop, the first impact at 0.28 s and constrained sliding; the normal force's mass solve
//! per constrained step, refined against the last sparse factorization where it can be); `barhorst-case1-timoshenko` over t ∈ [0, 0.35] s
//! (`contact-timoshenko-0.35s`: its first impact and micro-bounces, bound by event location);
//! the forces of one energy-midpoint iteration at q̄ with and without the shared kinematic pass
//! (`midpoint-forces-at-qbar`); the band LU of the exact augmented matrix against faer's sparse
//! LU of the same matrix (`augmented-solver`); explicit central difference on the Kelvin–Voigt
//! arm at its default step (`central-difference-damped-arm-0.02s`).
//! Run: `cargo bench -p fem --bench fem_bench -- --quick` (one group: append its name, e.g. `arms`).

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use data::{Backend, Settings};
use fem::FemBackend;
use fem::band::BorderedBand;
use fem::chain::{Chain, NewtonCoefficients};
use fem::run::prepare;

const MESHES: [usize; 5] = [4, 8, 16, 32, 64];

fn settings(n: usize, dt: f64) -> Settings {
    let mut s = Settings::default();
    s.discretization.elements = Some(n);
    s.time.dt = Some(dt);
    s
}

/// The chain of `scene` with `n` elements per link at a generic state (small deflections,
/// uniform rates and accelerations): (chain, [q, q̇, q̈]).
fn chain_at_a_generic_state(scene: &data::Scene, n: usize) -> (Chain, [Vec<f64>; 3]) {
    let ch = Chain::new(scene.links(), None, n).unwrap();
    let nd = ch.ndof;
    let q: Vec<f64> = (0..nd).map(|i| 1e-3 * (i as f64).sin()).collect();
    (ch, [q, vec![0.1; nd], vec![0.2; nd]])
}

fn assembly(c: &mut Criterion) {
    let sc = data::load_scene("spin-up").unwrap();
    let mut g = c.benchmark_group("assembly");
    for n in MESHES {
        let (mut ch, [q, qd, qdd]) = chain_at_a_generic_state(&sc, n);
        let mut r = vec![0.0; ch.ndof];
        let mut s = ch.new_matrix();
        let coef = NewtonCoefficients {
            c_a: 1.0,
            c_v: 5e-3,
            c_q: 2.5e-5,
        };
        g.bench_with_input(BenchmarkId::new("residual+newton_matrix", n), &n, |b, _| {
            b.iter(|| {
                ch.residual(black_box(3.0), &q, &qd, &qdd, &mut r);
                ch.newton_matrix(&q, coef, &mut s);
                s.factorize().unwrap();
                black_box(&r);
            })
        });
    }
    g.finish();
}

fn one_step(c: &mut Criterion) {
    let sc = data::load_scene("spin-up").unwrap();
    let mut g = c.benchmark_group("step");
    for n in MESHES {
        let mut p = prepare(
            &sc,
            sc.planar_chain().expect("planar chain"),
            &settings(n, 1e-2).fem().expect("fem settings"),
        )
        .unwrap();
        p.driver.set_stop(1e9);
        g.bench_with_input(BenchmarkId::new("generalized-alpha", n), &n, |b, _| {
            b.iter(|| black_box(p.driver.step().unwrap()))
        });
    }
    g.finish();
}

fn spin_up(c: &mut Criterion) {
    let sc = data::load_scene("spin-up").unwrap();
    let mut g = c.benchmark_group("spin-up-20s-dt1e-2");
    g.sample_size(10);
    for n in MESHES {
        let st = settings(n, 1e-2);
        g.bench_with_input(BenchmarkId::new("simulate", n), &n, |b, _| {
            b.iter(|| black_box(FemBackend.simulate(&sc, &st).unwrap()))
        });
    }
    g.finish();
}

fn single_link(c: &mut Criterion) {
    let sc = data::load_scene("single-link").unwrap();
    let mut g = c.benchmark_group("single-link-3s-default");
    g.sample_size(10);
    for m in ["energy-midpoint", "generalized-alpha"] {
        let mut st = Settings::default();
        st.time.method = Some(m.parse().expect("a method name"));
        g.bench_function(m, |b| {
            b.iter(|| black_box(FemBackend.simulate(&sc, &st).unwrap()))
        });
    }
    g.finish();
}

/// The seed scenes at default settings, whole runs: the free two-link arm (10 s) and the
/// Barhorst impact case (3 s). These set the cost a user meets on the arms.
fn arms(c: &mut Criterion) {
    let mut g = c.benchmark_group("arms-default");
    g.sample_size(10);
    for name in ["two-link-free-undamped", "barhorst-case1"] {
        let sc = data::load_scene(name).unwrap();
        let st = Settings::default();
        g.bench_function(name, |b| {
            b.iter(|| black_box(FemBackend.simulate(&sc, &st).unwrap()))
        });
    }
    g.finish();
}

/// The contact scenes (3 s) at the resolution whose contact-episode boundaries lie within
/// 1e-3 s of the converged ones, with the ladder around it agreeing: a coarser mesh than the
/// default, at a step that divides the 1 ms output interval (docs/contact.md, "Run time at
/// switching times within 1e-3 s of converged", the stop-52 table).
fn contact_at_converged_switching(c: &mut Criterion) {
    let mut g = c.benchmark_group("contact-3s-converged-switching");
    g.sample_size(10);
    for (name, elements, dt) in [
        ("barhorst-case1", 5, 2.5e-4),
        ("barhorst-case1-timoshenko", 8, 1.25e-4),
    ] {
        let sc = data::load_scene(name).unwrap();
        let st = settings(elements, dt);
        g.bench_function(format!("{name} {elements} elements dt {dt:e}"), |b| {
            b.iter(|| black_box(FemBackend.simulate(&sc, &st).unwrap()))
        });
    }
    g.finish();
}

/// One scene at default settings shortened to `t_end`, as its own group: the per-step cost of
/// a phase without the whole run.
fn shortened_run(c: &mut Criterion, group: &str, scene: &str, t_end: f64) {
    let mut g = c.benchmark_group(group);
    g.sample_size(10);
    let sc = data::load_scene(scene).unwrap();
    let mut st = Settings::default();
    st.time.t_end = Some(t_end);
    g.bench_function(scene, |b| {
        b.iter(|| black_box(FemBackend.simulate(&sc, &st).unwrap()))
    });
    g.finish();
}

/// The free two-link arm over its first second (energy-midpoint, 16 elements per link, the
/// exact augmented Newton matrix reused across steps): the foreshortening chain's step cost.
fn arms_short(c: &mut Criterion) {
    shortened_run(c, "arms-1s", "two-link-free-undamped", 1.0);
}

/// `barhorst-case1` over 0.5 s: the free drop, the first impact (0.28 s) and the sliding phases
/// after it, each constrained step with its normal-force evaluation (one mass solve, refined
/// against the last sparse factorization, `events::contact`) and event location.
fn contact_short(c: &mut Criterion) {
    shortened_run(c, "contact-0.5s", "barhorst-case1", 0.5);
}

/// `barhorst-case1-timoshenko` over 0.35 s: the drop, the first impact (0.28 s) and the
/// micro-bounces after it, where located events (each trial a re-solved shortened step)
/// dominate the cost.
fn contact_timoshenko_short(c: &mut Criterion) {
    shortened_run(
        c,
        "contact-timoshenko-0.35s",
        "barhorst-case1-timoshenko",
        0.35,
    );
}

/// Explicit central difference on the Kelvin–Voigt arm (`two-link-free`, 0.02 s at its default
/// step, 0.9 × 2/ω_max: the damping is implicit at the end velocity, so it does not lower the
/// bound) for 4 and 16 elements per link: one factorization of M + (h/2)C and a few residual
/// passes per step.
fn central_difference_damped_arm(c: &mut Criterion) {
    let mut g = c.benchmark_group("central-difference-damped-arm-0.02s");
    g.sample_size(10);
    let sc = data::load_scene("two-link-free").unwrap();
    for n in [4, 16] {
        let mut st = Settings::default();
        st.discretization.elements = Some(n);
        st.time.t_end = Some(0.02);
        st.time.method = Some("central-difference".parse().expect("a method name"));
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| black_box(FemBackend.simulate(&sc, &st).unwrap()))
        });
    }
    g.finish();
}

/// The exact Newton matrix of the free two-link arm with foreshortening (residual pass,
/// augmented assembly, band LU with the border's Schur complement, one solve) for 4–64
/// elements per link: linear in the elements.
fn assembly_foreshortening(c: &mut Criterion) {
    let sc = data::load_scene("two-link-free-undamped").unwrap();
    let mut g = c.benchmark_group("assembly-foreshortening");
    for n in MESHES {
        let (mut ch, [q, qd, qdd]) = chain_at_a_generic_state(&sc, n);
        let mut r = vec![0.0; ch.ndof];
        let layout = ch.augmented_layout();
        let mut s = ch.new_augmented_matrix(&layout);
        let mut x = vec![0.0; layout.n];
        let coef = NewtonCoefficients {
            c_a: 1.0,
            c_v: 3.6e-4,
            c_q: 1.3e-7,
        };
        g.bench_with_input(
            BenchmarkId::new("residual+exact_matrix+solve", n),
            &n,
            |b, _| {
                b.iter(|| {
                    ch.residual(black_box(3.0), &q, &qd, &qdd, &mut r);
                    ch.exact_newton_matrix(&q, &qd, &qdd, coef, &layout, &mut s);
                    s.factorize().unwrap();
                    x.iter_mut().for_each(|v| *v = 1.0);
                    s.solve_in_place(&mut x);
                    black_box(&x);
                })
            },
        );
    }
    g.finish();
}

/// The hand-written band LU with a dense border Schur complement against faer's sparse LU
/// (COLAMD ordering, symbolic factorization reused) on the same exact augmented Newton matrix of
/// the free two-link arm, factorization and one solve, 4–64 elements per link: the band solver
/// stays only while it wins here.
fn augmented_solver(c: &mut Criterion) {
    let sc = data::load_scene("two-link-free-undamped").unwrap();
    let mut g = c.benchmark_group("augmented-solver");
    for n in MESHES {
        let (mut ch, [q, qd, qdd]) = chain_at_a_generic_state(&sc, n);
        let mut r = vec![0.0; ch.ndof];
        ch.residual(3.0, &q, &qd, &qdd, &mut r);
        let layout = ch.augmented_layout();
        let coef = NewtonCoefficients {
            c_a: 1.0,
            c_v: 3.6e-4,
            c_q: 1.3e-7,
        };
        let mut band = ch.new_augmented_matrix(&layout);
        ch.exact_newton_matrix(&q, &qd, &qdd, coef, &layout, &mut band);
        let mut sparse = BorderedBand::new(
            layout.n_interior,
            layout.n - layout.n_interior,
            layout.half_bandwidth,
        );
        ch.exact_newton_matrix(&q, &qd, &qdd, coef, &layout, &mut sparse);
        let mut x = vec![0.0; layout.n];
        for (label, m) in [("band-lu", &mut band), ("faer-sparse-lu", &mut sparse)] {
            g.bench_with_input(BenchmarkId::new(label, n), &n, |b, _| {
                b.iter(|| {
                    m.factorize().unwrap();
                    x.iter_mut().for_each(|v| *v = 1.0);
                    m.solve_in_place(&mut x);
                    black_box(&x);
                })
            });
        }
    }
    g.finish();
}

/// An arm at its default mesh (16 elements per link) in a deformed, moving state: (chain, q, v).
fn moving_arm(name: &str) -> (Chain, Vec<f64>, Vec<f64>) {
    let sc = data::load_scene(name).unwrap();
    let ch = Chain::new(sc.links(), sc.gravity(), 16).unwrap();
    let nd = ch.ndof;
    let (mut q, mut v) = (vec![0.0; nd], vec![0.0; nd]);
    ch.initial_state(&mut q, &mut v);
    for i in 0..nd {
        q[i] += 1e-3 * (i as f64).sin();
        v[i] = 0.1 * (i as f64).cos();
    }
    (ch, q, v)
}

/// The forces of one energy-midpoint iteration at q̄ (metric product M(q̄)Δq, ∇V, −Q) on the
/// arms at their default meshes: three full passes (kinematic and force pass each) against one
/// full pass and two force passes on its kinematics ([`Chain::residual_parts_at_last_q`], what
/// the scheme does; the outputs are equal).
fn midpoint_forces(c: &mut Criterion) {
    use fem::chain::Parts;
    let mut g = c.benchmark_group("midpoint-forces-at-qbar");
    for name in ["two-link-free-undamped", "barhorst-case1-timoshenko"] {
        let (mut ch, q, v) = moving_arm(name);
        let nd = ch.ndof;
        let dq: Vec<f64> = v.iter().map(|x| 5e-4 * x).collect();
        let zero = vec![0.0; nd];
        let (mut w, mut gv, mut mq) = (vec![0.0; nd], vec![0.0; nd], vec![0.0; nd]);
        g.bench_function(BenchmarkId::new("three-passes", name), |b| {
            b.iter(|| {
                ch.residual_parts(1.0, &q, &zero, &zero, Parts::CONSERVATIVE, &mut gv);
                ch.residual_parts(1.0, &q, &v, &zero, Parts::NONCONSERVATIVE, &mut mq);
                ch.residual_parts(1.0, &q, &zero, &dq, Parts::INERTIA, &mut w);
                black_box((&w, &gv, &mq));
            })
        });
        g.bench_function(BenchmarkId::new("one-pass-two-at-last-q", name), |b| {
            b.iter(|| {
                ch.residual_parts(1.0, &q, &zero, &dq, Parts::INERTIA, &mut w);
                ch.residual_parts_at_last_q(1.0, &q, &zero, Parts::CONSERVATIVE, &mut gv);
                ch.residual_parts_at_last_q(1.0, &q, &v, Parts::NONCONSERVATIVE, &mut mq);
                black_box((&w, &gv, &mq));
            })
        });
    }
    g.finish();
}

/// The end-point energies of one energy-midpoint iteration after its mass product M(q₁)q̇₁ on
/// the arms at their default meshes: the energies' own point walk against the potential on the
/// mass product's kinematics ([`Chain::potential_at_last_q`]) and T₁ = ½q̇₁ᵀM(q₁)q̇₁ (what the
/// scheme does; the potentials are equal bit for bit).
fn midpoint_end_energies(c: &mut Criterion) {
    use fem::chain::Parts;
    let mut g = c.benchmark_group("midpoint-end-energies");
    for name in ["two-link-free-undamped", "barhorst-case1-timoshenko"] {
        let (mut ch, q, v) = moving_arm(name);
        let nd = ch.ndof;
        let zero = vec![0.0; nd];
        let mut mv = vec![0.0; nd];
        g.bench_function(BenchmarkId::new("mass-product-and-energies", name), |b| {
            b.iter(|| {
                ch.residual_parts(1.0, &q, &zero, &v, Parts::INERTIA, &mut mv);
                black_box((&mv, ch.energies(1.0, &q, &v)));
            })
        });
        g.bench_function(
            BenchmarkId::new("mass-product-and-potential-at-last-q", name),
            |b| {
                b.iter(|| {
                    ch.residual_parts(1.0, &q, &zero, &v, Parts::INERTIA, &mut mv);
                    let kinetic = 0.5 * v.iter().zip(&mv).map(|(x, y)| x * y).sum::<f64>();
                    black_box((kinetic, ch.potential_at_last_q(1.0, &q)));
                })
            },
        );
    }
    g.finish();
}

criterion_group!(
    benches,
    midpoint_end_energies,
    assembly,
    assembly_foreshortening,
    augmented_solver,
    one_step,
    spin_up,
    single_link,
    arms,
    arms_short,
    contact_short,
    contact_timoshenko_short,
    central_difference_damped_arm,
    contact_at_converged_switching,
    midpoint_forces
);
criterion_main!(benches);
