//! `two-link-free` (joint dampers + Kelvin–Voigt), 1 s, single-threaded: the default (damping
//! implicit in the velocity form's closing kick, the undamped step bound) at 21 and 41
//! stations per link, and the explicit damping (the damped step bound) at 21 stations over
//! 0.1 s for comparison (×10 for the same simulated time); `two-link-free-undamped`, 1 s at
//! 21 stations: the velocity form with its time-symmetric corrector pass (one more Γ
//! evaluation and mass solve per step, the rest kept from the first pass); `barhorst-case1`,
//! 0.5 s at 21 stations (the drop, the first impacts and the held phases): the contact run's
//! default, damping implicit with the held tip's force in the kick.
//!
//! `implicit-kick-saddle`: the kick's linear solve alone — the saddle system the chain assembles
//! at a deformed, moving state of `two-link-free` (21 / 41 / 81 stations, τ = 1e-5), factored
//! and solved for eight right-hand sides over both links' blocks (the kick solves each block
//! alone, with 7 and 6) — by the hand-written band LDLᵀ the chain uses (`fdm::band_ldl`), by
//! faer's sparse LU and by faer's sparse LDLᵀ (AMD ordering, no pivoting, as the band solver),
//! each with its symbolic factorization reused and its storage allocated once (the contenders
//! a hand-written kernel has to beat).
//!
//! `link-rates-tridiagonal`: the tridiagonal solve of a link's foreshortening-rate block
//! N⁻¹ + GD⁻¹Gᵀ in the chain's mass solve (factor once per state, seven right-hand sides), by
//! the hand-written LDLᵀ (`fdm::tridiagonal`) and by faer's sparse LLᵀ (AMD ordering, symbolic
//! factorization reused, storage allocated once), 20 / 40 / 80 segments, the masses of
//! `two-link-free`'s link 1 and the slopes of a bent link.
//!
//! `small-schur-lu`: the dense small system of the kick's Schur solve (seven unknowns at
//! `two-link-free`'s state above, 41 stations), factored and solved for one right-hand side by
//! the hand-written elimination (`fdm::chain::schur::SmallLu`) and by faer's dense LU with
//! partial pivoting (`lu_in_place`, workspace allocated once, then the two triangular solves).
//! Run: cargo bench -p fdm --bench chain -- --quick

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main};
use data::load_scene;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
use faer::linalg::triangular_solve::{
    solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::sparse::linalg::cholesky::{SymmetricOrdering, factorize_symbolic_cholesky};
use faer::sparse::linalg::lu::{LuRef, NumericLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMat, SparseColMatRef, Triplet};
use faer::{Conj, Mat, MatMut, Par, Side};
use fdm::ValidatedSettings;
use fdm::chain::schur::{MAX_SMALL, SmallLu};
use fdm::chain::{TwoLinkChain, rate_block};
use fdm::driver::{StepControl, integrate};
use fdm::tridiagonal::TridiagonalLdl;

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

/// The sparse symmetric factorizations faer offers, as contenders of the hand-written solvers.
#[derive(Clone, Copy)]
enum Cholesky {
    /// LDLᵀ without pivoting (a quasi-definite matrix needs none in any order)
    Ldlt,
    /// LLᵀ (positive definite)
    Llt,
}

/// Right-hand sides stored by rows (X[i·m + c]) as faer's column-major storage.
fn by_columns(rows: &[f64], n: usize, m: usize) -> Vec<f64> {
    (0..n * m).map(|k| rows[(k % n) * m + k / n]).collect()
}

/// Benches faer's sparse `kind` factorization of `a` (AMD ordering, symbolic factorization
/// reused, storage allocated once) plus the solve of the `m` right-hand sides `rows` (by rows).
fn bench_faer_cholesky(
    group: &mut BenchmarkGroup<'_, WallTime>,
    id: BenchmarkId,
    a: &SparseColMat<usize, f64>,
    rows: &[f64],
    m: usize,
    kind: Cholesky,
) {
    let n = a.nrows();
    let symbolic = factorize_symbolic_cholesky(
        a.symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        Default::default(),
    )
    .unwrap();
    let factor_scratch = match kind {
        Cholesky::Ldlt => {
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
        }
        Cholesky::Llt => {
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
        }
    };
    let mut mem =
        MemBuffer::new(factor_scratch.or(symbolic.solve_in_place_scratch::<f64>(m, Par::Seq)));
    let mut l_values = vec![0.0; symbolic.len_val()];
    let cols = by_columns(rows, n, m);
    let mut y = cols.clone();
    group.bench_function(id, |b| {
        b.iter(|| {
            let a = SparseColMatRef::new(a.symbolic(), a.val());
            y.copy_from_slice(&cols);
            let rhs = MatMut::from_column_major_slice_mut(&mut y, n, m);
            match kind {
                Cholesky::Ldlt => symbolic
                    .factorize_numeric_ldlt(
                        &mut l_values,
                        a,
                        Side::Lower,
                        LdltRegularization::default(),
                        Par::Seq,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .expect("numeric LDLᵀ")
                    .solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(&mut mem)),
                Cholesky::Llt => symbolic
                    .factorize_numeric_llt(
                        &mut l_values,
                        a,
                        Side::Lower,
                        LltRegularization::default(),
                        Par::Seq,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .expect("numeric LLᵀ")
                    .solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(&mut mem)),
            }
            std::hint::black_box(y[0])
        })
    });
}

fn implicit_kick_saddle(c: &mut Criterion) {
    let scene = load_scene("two-link-free").expect("catalog scene");
    let mut group = c.benchmark_group("implicit-kick-saddle");
    let m = 8;
    for stations in [21usize, 41, 81] {
        let mut chain =
            TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(stations))
                .expect("chain");
        assert!(chain.enable_implicit_damping());
        let n_q = fdm::system::System::dofs(&chain);
        let q: Vec<f64> = (0..n_q)
            .map(|i| 0.3 + 0.02 * (0.9 * i as f64).sin())
            .collect();
        let qd: Vec<f64> = (0..n_q).map(|i| 0.3 * (1.7 * i as f64).cos()).collect();
        let assembled = chain.implicit_kick_saddle(&q, &qd, 1e-5);
        let n = assembled.n();
        let rhs: Vec<f64> = (0..n * m).map(|k| (0.37 * k as f64).cos()).collect();

        let mut x = rhs.clone();
        group.bench_with_input(BenchmarkId::new("band ldl", stations), &stations, |b, _| {
            b.iter(|| {
                let mut band = assembled.clone();
                band.factor().expect("quasi-definite");
                x.copy_from_slice(&rhs);
                band.solve_rows_in_place(&mut x, m);
                std::hint::black_box(x[0])
            })
        });

        let triplets: Vec<Triplet<usize, usize, f64>> = assembled
            .entries()
            .map(|(i, j, v)| Triplet::new(i, j, v))
            .collect();
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets).unwrap();
        let symbolic = factorize_symbolic_lu(a.symbolic(), Default::default()).unwrap();
        let scratch = symbolic
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(m, Par::Seq));
        let mut mem = MemBuffer::new(scratch);
        let mut numeric = NumericLu::new();
        let rhs_cols = by_columns(&rhs, n, m);
        let mut y = rhs_cols.clone();
        group.bench_with_input(
            BenchmarkId::new("faer sparse lu", stations),
            &stations,
            |b, _| {
                b.iter(|| {
                    let a = SparseColMatRef::new(a.symbolic(), a.val());
                    symbolic
                        .factorize_numeric_lu(
                            &mut numeric,
                            a,
                            Par::Seq,
                            MemStack::new(&mut mem),
                            Default::default(),
                        )
                        .expect("numeric LU");
                    y.copy_from_slice(&rhs_cols);
                    let lu = LuRef::new_unchecked(&symbolic, &numeric);
                    lu.solve_in_place_with_conj(
                        Conj::No,
                        MatMut::from_column_major_slice_mut(&mut y, n, m),
                        Par::Seq,
                        MemStack::new(&mut mem),
                    );
                    std::hint::black_box(y[0])
                })
            },
        );

        // LDLᵀ without pivoting, as the band solver
        bench_faer_cholesky(
            &mut group,
            BenchmarkId::new("faer sparse ldlt", stations),
            &a,
            &rhs,
            m,
            Cholesky::Ldlt,
        );
    }
    group.finish();
}

fn link_rates_tridiagonal(c: &mut Criterion) {
    let mut group = c.benchmark_group("link-rates-tridiagonal");
    let m = 7;
    let (length, mass_per_length) = (3.0, 1.764);
    for r in [20usize, 40, 80] {
        // N⁻¹ + GD⁻¹Gᵀ (`fdm::chain` rates): station masses d, outboard axial masses w of the
        // segments, slopes g of a link bent to 1 % of its length
        let h = length / r as f64;
        let d: Vec<f64> = (0..r - 1).map(|_| mass_per_length * h).collect();
        let w: Vec<f64> = (0..r)
            .map(|seg| mass_per_length * (length - seg as f64 * h))
            .collect();
        let g: Vec<f64> = (0..r)
            .map(|seg| 0.01 * (std::f64::consts::PI * (seg as f64 + 0.5) / r as f64).cos())
            .collect();
        let (diag, off) = rate_block(&d, &w, &g);
        let rhs: Vec<f64> = (0..r * m).map(|k| (0.37 * k as f64).cos()).collect();

        let mut ldl = TridiagonalLdl::new(r);
        let mut x = rhs.clone();
        group.bench_with_input(BenchmarkId::new("tridiagonal ldl", r), &r, |b, _| {
            b.iter(|| {
                ldl.factor(diag, off).expect("SPD");
                x.copy_from_slice(&rhs);
                ldl.solve_rows_in_place(&mut x, m);
                std::hint::black_box(x[0])
            })
        });

        let mut triplets = Vec::new();
        for a in 0..r {
            triplets.push(Triplet::new(a, a, diag(a)));
            if a + 1 < r {
                triplets.push(Triplet::new(a + 1, a, off(a)));
                triplets.push(Triplet::new(a, a + 1, off(a)));
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(r, r, &triplets).unwrap();
        bench_faer_cholesky(
            &mut group,
            BenchmarkId::new("faer sparse llt", r),
            &a,
            &rhs,
            m,
            Cholesky::Llt,
        );
    }
    group.finish();
}

fn small_schur_lu(c: &mut Criterion) {
    let scene = load_scene("two-link-free").expect("catalog scene");
    let mut chain =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(41))
            .expect("chain");
    assert!(chain.enable_implicit_damping());
    let n_q = fdm::system::System::dofs(&chain);
    let q: Vec<f64> = (0..n_q)
        .map(|i| 0.3 + 0.02 * (0.9 * i as f64).sin())
        .collect();
    let qd: Vec<f64> = (0..n_q).map(|i| 0.3 * (1.7 * i as f64).cos()).collect();
    let (s, n) = chain.implicit_kick_schur(&q, &qd, 1e-5);
    let b: [f64; MAX_SMALL] = std::array::from_fn(|i| (0.37 * i as f64).cos());
    let mut group = c.benchmark_group("small-schur-lu");
    group.bench_function(BenchmarkId::new("small lu", n), |bench| {
        bench.iter(|| {
            let lu = SmallLu::factor(s, n);
            std::hint::black_box(lu.solve(b)[0])
        })
    });
    let req = lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default());
    let mut mem = MemBuffer::new(req);
    let mut a = Mat::<f64>::zeros(n, n);
    let (mut perm, mut perm_inv) = (vec![0usize; n], vec![0usize; n]);
    let mut x = vec![0.0; n];
    group.bench_function(BenchmarkId::new("faer dense lu", n), |bench| {
        bench.iter(|| {
            for j in 0..n {
                for i in 0..n {
                    a[(i, j)] = s[i][j];
                }
            }
            lu_in_place(
                a.as_mut(),
                &mut perm,
                &mut perm_inv,
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            );
            for k in 0..n {
                x[k] = b[perm[k]];
            }
            let mut rhs = MatMut::from_column_major_slice_mut(&mut x, n, 1);
            solve_unit_lower_triangular_in_place(a.as_ref(), rhs.as_mut(), Par::Seq);
            solve_upper_triangular_in_place(a.as_ref(), rhs, Par::Seq);
            std::hint::black_box(x[0])
        })
    });
    // both solve the same system (checked once, outside the timing)
    let mine = SmallLu::factor(s, n).solve(b);
    for k in 0..n {
        assert!(
            (mine[k] - x[k]).abs() <= 1e-9 * mine[k].abs().max(1e-300),
            "x[{k}]"
        );
    }
    group.finish();
}

criterion_group!(
    benches,
    bench,
    contact,
    implicit_kick_saddle,
    link_rates_tridiagonal,
    small_schur_lu
);
criterion_main!(benches);
