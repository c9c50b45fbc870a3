//! The crate's dense Cholesky (`modal::linalg`, kept because `benches/dense_cholesky.rs` shows it
//! faster than faer's LLᵀ at these sizes) against faer's LLᵀ on the reduced mass matrices M(q)
//! of real states: the end states of short default runs.

use data::{Settings, load_scene};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::{MatMut, Par};
use modal::linalg::cholesky_solve;
use modal::setup::build_chain;
use modal::simulate::simulate_detailed;

/// x = M⁻¹ b by faer's LLᵀ (row-major symmetric M: its lower triangle is the same).
fn faer_llt_solve(mass: &[f64], n: usize, rhs: &[f64]) -> Vec<f64> {
    let (mut a, mut b) = (mass.to_vec(), rhs.to_vec());
    let mut mem = MemBuffer::new(
        llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default())
            .or(llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq)),
    );
    let stack = MemStack::new(&mut mem);
    llt::factor::cholesky_in_place(
        MatMut::from_row_major_slice_mut(&mut a, n, n),
        Default::default(),
        Par::Seq,
        stack,
        Default::default(),
    )
    .unwrap();
    llt::solve::solve_in_place(
        faer::MatRef::from_row_major_slice(&a, n, n),
        MatMut::from_column_major_slice_mut(&mut b, n, 1),
        Par::Seq,
        MemStack::new(&mut mem),
    );
    b
}

/// ‖M x − b‖∞ / (‖M‖∞ ‖x‖∞ + ‖b‖∞).
fn backward_error(mass: &[f64], n: usize, x: &[f64], b: &[f64]) -> f64 {
    let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    let mut res = 0.0f64;
    let mut m_norm = 0.0f64;
    for i in 0..n {
        let row = &mass[i * n..(i + 1) * n];
        let ax: f64 = row.iter().zip(x).map(|(m, x)| m * x).sum();
        res = res.max((ax - b[i]).abs());
        m_norm = m_norm.max(row.iter().map(|m| m.abs()).sum());
    }
    res / (m_norm * inf(x) + inf(b))
}

#[test]
fn sys_cholesky_solves_real_mass_matrices_as_faer_llt() {
    for (name, modes) in [
        ("two-link-free", 4),
        ("two-link-free", 8),
        ("barhorst-case1", 6),
        ("barhorst-case1-tipmass", 10),
    ] {
        let scene = load_scene(name).unwrap();
        let pc = scene.planar_chain().unwrap();
        let mut settings = Settings::default();
        settings.discretization.modes = Some(modes);
        settings.time.t_end = Some(0.3);
        let modal_settings = settings.modal().unwrap();
        let (_, end) = simulate_detailed(&scene, pc, &modal_settings).unwrap();
        let mut chain = build_chain(pc, &modal_settings).unwrap();
        chain.evaluate(0.3, &end.q, &end.qd);
        let n = chain.n;
        let mass = chain.mass_matrix().to_vec();
        let rhs: Vec<f64> = (0..n).map(|k| (k as f64 + 0.5).cos()).collect();
        let mut ours = rhs.clone();
        let mut factor = mass.clone();
        cholesky_solve(&mut factor, n, &mut ours).unwrap();
        let theirs = faer_llt_solve(&mass, n, &rhs);
        let (eta_ours, eta_faer) = (
            backward_error(&mass, n, &ours, &rhs),
            backward_error(&mass, n, &theirs, &rhs),
        );
        eprintln!(
            "{name}, {modes} modes (n = {n}): backward error ours {eta_ours:.2e}, faer {eta_faer:.2e}"
        );
        // Cholesky is backward stable without pivoting: a small multiple of n·ε.
        let bound = n as f64 * f64::EPSILON;
        assert!(eta_ours <= bound, "{name} {modes}: {eta_ours:e}");
        assert!(eta_faer <= bound, "{name} {modes}: {eta_faer:e}");
    }
}
