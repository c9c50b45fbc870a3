//! 1 s of `single-link-3d` (u, v, w, φ at 21 stations, free base, gravity, implicit
//! Kelvin–Voigt; ≈ 101 000 steps), single-threaded.
//! Also faer's sparse Cholesky of the step matrix against a banded Cholesky
//! (`payload-link-step-matrix`).
//! Run: cargo bench -p fdm --bench payload_link -- --quick

// The band kernel indexes the factor and the right-hand side together.
#![allow(clippy::needless_range_loop)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use data::{Backend, Settings, load_scene};
use fdm::FdmBackend;
use fdm::payload_link::PayloadLinkModel;
use fdm::payload_link::spd::{SpdFactor, Triplets};

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

/// The banded Cholesky the 3-D link's step matrix A = M_ff + ½τC was factorized with before
/// (kept here as the bench's contender) against faer's sparse Cholesky (AMD ordering) that
/// replaced it ([`SpdFactor`]), at 11–81 stations: the factorization (once per run) and one
/// solve (two or three per step).
fn step_matrix_solver(c: &mut Criterion) {
    let scene = load_scene("single-link-3d").expect("catalog scene");
    let link = scene.payload_link().expect("a payload link");
    let mut group = c.benchmark_group("payload-link-step-matrix");
    for stations in [11usize, 21, 41, 81] {
        let model = PayloadLinkModel::from_payload_link(&scene, link, Some(stations)).unwrap();
        let n = model.field_coordinates();
        let damping = model.damping_matrix();
        let parts = model.step_matrix_parts(&damping, 1e-5);
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5).cos()).collect();
        group.bench_with_input(BenchmarkId::new("band-cholesky factor", n), &n, |b, _| {
            b.iter(|| black_box(BandCholesky::factor(n, &parts)))
        });
        group.bench_with_input(BenchmarkId::new("faer sparse llt factor", n), &n, |b, _| {
            b.iter(|| black_box(SpdFactor::factor(n, &parts, "bench").unwrap()))
        });
        let band = BandCholesky::factor(n, &parts);
        let mut faer = SpdFactor::factor(n, &parts, "bench").unwrap();
        let mut x = rhs.clone();
        group.bench_with_input(BenchmarkId::new("band-cholesky solve", n), &n, |b, _| {
            b.iter(|| {
                x.copy_from_slice(&rhs);
                band.solve_in_place(&mut x);
                black_box(&x);
            })
        });
        group.bench_with_input(BenchmarkId::new("faer sparse llt solve", n), &n, |b, _| {
            b.iter(|| {
                x.copy_from_slice(&rhs);
                faer.solve_in_place(&mut x);
                black_box(&x);
            })
        });
    }
    group.finish();
}

/// Banded Cholesky factor L (A = L Lᵀ, lower band of half-width b, row-major band storage):
/// the hand-written kernel faer's sparse Cholesky replaced, kept as the bench's contender.
struct BandCholesky {
    b: usize,
    l: Vec<f64>,
}

impl BandCholesky {
    fn factor(n: usize, parts: &[(&Triplets, f64)]) -> Self {
        let b = parts.iter().map(|(t, _)| t.bandwidth()).max().unwrap_or(0);
        let w = b + 1;
        let mut l = vec![0.0; n * w];
        for (t, s) in parts {
            for &(i, j, c) in &t.entries {
                if j <= i {
                    l[i * w + (i - j)] += s * c;
                }
            }
        }
        for j in 0..n {
            let mut d = l[j * w];
            for k in j.saturating_sub(b)..j {
                d -= l[j * w + (j - k)] * l[j * w + (j - k)];
            }
            let djj = d.sqrt();
            l[j * w] = djj;
            for i in j + 1..(j + b + 1).min(n) {
                let mut s = l[i * w + (i - j)];
                for k in i.saturating_sub(b)..j {
                    s -= l[i * w + (i - k)] * l[j * w + (j - k)];
                }
                l[i * w + (i - j)] = s / djj;
            }
        }
        BandCholesky { b, l }
    }

    fn solve_in_place(&self, x: &mut [f64]) {
        let (n, b, w) = (x.len(), self.b, self.b + 1);
        for i in 0..n {
            let mut s = x[i];
            for k in i.saturating_sub(b)..i {
                s -= self.l[i * w + (i - k)] * x[k];
            }
            x[i] = s / self.l[i * w];
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..(i + b + 1).min(n) {
                s -= self.l[k * w + (k - i)] * x[k];
            }
            x[i] = s / self.l[i * w];
        }
    }
}

criterion_group!(benches, bench, step_matrix_solver);
criterion_main!(benches);
