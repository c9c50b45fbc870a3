//! The floating-frame chain alone: the residual is Lagrange's equations of the energies it
//! reports, and the Newton matrix is the derivative of the residual.

// Index loops mirror the matrix formulas being checked.
#![allow(clippy::needless_range_loop)]

mod common;

use data::FemElement;
use fem::chain::{Chain, NewtonCoefficients};

/// The default element (Hermite cubic; Timoshenko on `shear` links).
const CUBIC: Option<FemElement> = None;
const QUINTIC: Option<FemElement> = Some(FemElement::HermiteQuintic);

/// A chain with every effect switched on (tip masses and inertias, hub inertia, gravity,
/// foreshortening as requested) at a generic state.
fn setup(
    name: &str,
    n_el: usize,
    foreshortening: bool,
    element: Option<FemElement>,
) -> (Chain, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut sc = data::load_scene(name).unwrap();
    for l in sc.planar_chain_mut().unwrap().links.iter_mut() {
        l.foreshortening = foreshortening && !l.axial;
        l.tip_mass = Some(0.3);
        l.tip_inertia = Some(0.01);
        l.joint.hub_inertia = Some(0.02);
    }
    sc.planar_chain_mut().unwrap().gravity = Some(data::scene::Gravity {
        vector: [0.3, -9.0],
    });
    let ch = Chain::with_element(sc.links(), sc.gravity(), n_el, element).unwrap();
    let n = ch.ndof;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    ch.initial_state(&mut q, &mut qd);
    let mut qdd = vec![0.0; n];
    for i in 0..n {
        q[i] += 0.05 * (i as f64 * 1.3).sin();
        qd[i] = 0.5 * (i as f64 * 0.7).cos();
        qdd[i] = 3.0 * (i as f64 * 2.1).sin();
    }
    (ch, q, qd, qdd)
}

#[test]
fn sys_residual_is_lagrange_of_the_reported_energies() {
    for (name, fs, element) in [
        ("single-link", false, CUBIC),
        ("single-link", true, CUBIC),
        ("two-link-free-undamped", true, CUBIC),
        ("spin-up-axial", false, CUBIC),
        ("single-link", true, QUINTIC),
        ("two-link-free-undamped", true, QUINTIC),
        ("spin-up-axial", false, QUINTIC),
    ] {
        let (mut ch, q, qd, qdd) = setup(name, 3, fs, element);
        let n = ch.ndof;
        let t = 0.3;
        let mut r = vec![0.0; n];
        ch.residual(t, &q, &qd, &qdd, &mut r);
        let kinetic = |q: &[f64], qd: &[f64]| ch.energies(t, q, qd)[0];
        let potential = |q: &[f64]| {
            let e = ch.energies(t, q, &vec![0.0; q.len()]);
            e[1] + e[2] + e[3]
        };
        let e = 1e-5;
        let p = |q: &[f64], qd: &[f64], i: usize| {
            let (mut a, mut b) = (qd.to_vec(), qd.to_vec());
            a[i] += e;
            b[i] -= e;
            (kinetic(q, &a) - kinetic(q, &b)) / (2.0 * e)
        };
        let scale = r.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for i in 0..n {
            // d/dt ∂T/∂q̇ by a central difference along the trajectory direction (q̇, q̈).
            let hs = 1e-4;
            let qp: Vec<f64> = (0..n).map(|k| q[k] + hs * qd[k]).collect();
            let qm: Vec<f64> = (0..n).map(|k| q[k] - hs * qd[k]).collect();
            let vp: Vec<f64> = (0..n).map(|k| qd[k] + hs * qdd[k]).collect();
            let vm: Vec<f64> = (0..n).map(|k| qd[k] - hs * qdd[k]).collect();
            let dpdt = (p(&qp, &vp, i) - p(&qm, &vm, i)) / (2.0 * hs);
            let (mut a, mut b) = (q.clone(), q.clone());
            a[i] += e;
            b[i] -= e;
            let dtdq = (kinetic(&a, &qd) - kinetic(&b, &qd)) / (2.0 * e);
            let dvdq = (potential(&a) - potential(&b)) / (2.0 * e);
            let mut joint = 0.0;
            for l in &ch.links {
                if l.joint.dof == i {
                    joint += l.joint.damping * qd[i] - l.joint.applied(t);
                }
            }
            let kv = 0.0; // Kelvin–Voigt is off in these scenes (undamped or single link).
            let lagrange = dpdt - dtdq + dvdq + joint + kv;
            // Nested central differences: truncation O(h²)·T‴ and round-off ε·T/(e·hs)
            // ≈ 1e-16·1e2/1e-9 = 1e-5 absolute; 1e-8 of the residual scale (≥ 1e2) covers both
            // except for the stiff axial link where EA = 2.8e7 amplifies round-off (1e-6).
            let tol = if name == "spin-up-axial" { 1e-6 } else { 1e-8 };
            assert!(
                (lagrange - r[i]).abs() < tol * scale,
                "{name} fs={fs} {}: {lagrange} vs {}",
                ch.describe_dof(i),
                r[i]
            );
        }
    }
}

#[test]
fn sys_newton_matrix_is_the_residual_derivative() {
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.01,
        c_q: 1e-4,
    };
    // Without foreshortening the bordered-band matrix is exact (FD error ~1e-9 relative). With
    // foreshortening the omitted terms — ∂s/∂q couplings, dense over a link — are O(v′) in the
    // joint rows and O(v′²) elsewhere: at this state (v′ ≈ 0.1) they are ≈ 6 % of the scale,
    // which is why chains with foreshortening use the exact augmented matrix
    // (`sys_foreshortening_tangent`).
    for (name, fs, tol, element) in [
        ("single-link", false, 1e-7, CUBIC),
        ("two-link-free-undamped", false, 1e-7, CUBIC),
        ("spin-up-axial", false, 1e-7, CUBIC),
        ("single-link", true, 0.1, CUBIC),
        ("single-link", false, 1e-7, QUINTIC),
        ("two-link-free-undamped", false, 1e-7, QUINTIC),
        ("spin-up-axial", false, 1e-7, QUINTIC),
    ] {
        let (mut ch, q, qd, qdd) = setup(name, 3, fs, element);
        let (worst, scale) = common::newton_matrix_fd_error(&mut ch, &q, &qd, &qdd, c);
        assert!(
            worst < tol * scale,
            "{name} fs={fs}: {worst:.3e} of {scale:.3e}"
        );
    }
}

#[test]
fn sys_mass_product_and_kinetic_gradient_match_the_reported_kinetic_energy() {
    // The energy-midpoint ingredients against finite differences of `energies()`' kinetic term
    // T(q, x) = ½xᵀM(q)x: M(q)x = ∂T/∂x (T is quadratic in x: central differences are exact up
    // to round-off), ½xᵀM(q)x = T, and the analytic ∂T/∂q.
    for (name, fs, element) in [
        ("single-link", false, CUBIC),
        ("single-link", true, CUBIC),
        ("two-link-free-undamped", true, CUBIC),
        ("two-link-free-undamped", true, QUINTIC),
    ] {
        let (mut ch, q, x, _) = setup(name, 3, fs, element);
        let n = ch.ndof;
        let t = 0.3;
        let mx = fem::method::energy_midpoint::mass_product(&mut ch, t, &q, &x);
        let dtdq = fem::method::energy_midpoint::kinetic_gradient(&mut ch, t, &q, &x);
        let kinetic = |q: &[f64], x: &[f64]| ch.energies(t, q, x)[0];
        let t0 = kinetic(&q, &x);
        let half_xmx = 0.5 * x.iter().zip(&mx).map(|(a, b)| a * b).sum::<f64>();
        assert!(
            (half_xmx - t0).abs() <= 1e-13 * t0,
            "{name}: ½xᵀMx {half_xmx} vs T {t0}"
        );
        let (mscale, gscale) = (
            mx.iter().fold(0.0f64, |a, b| a.max(b.abs())),
            dtdq.iter().fold(0.0f64, |a, b| a.max(b.abs())),
        );
        let e = 1e-4;
        let (mut worst_m, mut worst_g) = (0.0f64, 0.0f64);
        for i in 0..n {
            let (mut a, mut b) = (x.clone(), x.clone());
            a[i] += e;
            b[i] -= e;
            let fd = (kinetic(&q, &a) - kinetic(&q, &b)) / (2.0 * e);
            worst_m = worst_m.max((fd - mx[i]).abs() / mscale);
            // ∂T/∂q: fourth-order central difference (truncation ~h⁴ = 1e-12 relative, far
            // below the tolerance).
            let h = 1e-3;
            let tq = |s: f64| {
                let mut p = q.clone();
                p[i] += s * h;
                kinetic(&p, &x)
            };
            let fd = (8.0 * (tq(1.0) - tq(-1.0)) - (tq(2.0) - tq(-2.0))) / (12.0 * h);
            worst_g = worst_g.max((fd - dtdq[i]).abs() / gscale);
        }
        eprintln!("{name} (fs {fs}): M x error {worst_m:.2e}, ∂T/∂q error {worst_g:.2e}");
        assert!(worst_m < 1e-9, "{name}: M x error {worst_m}");
        assert!(worst_g < 1e-7, "{name}: ∂T/∂q error {worst_g}");
    }
}

#[test]
fn sys_residual_parts_sum_to_the_residual_and_conservative_part_is_grad_v() {
    use fem::chain::Parts;
    for (name, fs, element) in [
        ("single-link", true, CUBIC),
        ("two-link-free", true, CUBIC),
        ("two-link-free", true, QUINTIC),
    ] {
        let (mut ch, q, qd, qdd) = setup(name, 3, fs, element);
        let n = ch.ndof;
        let t = 0.7;
        let mut full = vec![0.0; n];
        ch.residual(t, &q, &qd, &qdd, &mut full);
        let mut sum = vec![0.0; n];
        let mut part = vec![0.0; n];
        for p in [Parts::INERTIA, Parts::CONSERVATIVE, Parts::NONCONSERVATIVE] {
            ch.residual_parts(t, &q, &qd, &qdd, p, &mut part);
            for i in 0..n {
                sum[i] += part[i];
            }
        }
        let scale = full.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for i in 0..n {
            assert!(
                (sum[i] - full[i]).abs() <= 1e-12 * scale,
                "{name}: dof {i}: {} vs {}",
                sum[i],
                full[i]
            );
        }
        let zero = vec![0.0; n];
        let mut grad = vec![0.0; n];
        ch.residual_parts(t, &q, &zero, &zero, Parts::CONSERVATIVE, &mut grad);
        let potential = |q: &[f64]| {
            let e = ch.energies(t, q, &zero);
            e[1] + e[2] + e[3]
        };
        let gscale = grad.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let h = 1e-5;
        for i in 0..n {
            let (mut a, mut b) = (q.clone(), q.clone());
            a[i] += h;
            b[i] -= h;
            let fd = (potential(&a) - potential(&b)) / (2.0 * h);
            assert!(
                (fd - grad[i]).abs() <= 1e-6 * gscale,
                "{name}: ∂V/∂q[{i}] {} vs {fd}",
                grad[i]
            );
        }
    }
}

/// The chains of the last-kinematic-pass tests: foreshortening, quintic, Timoshenko, axial
/// links and a prescribed joint (name, foreshortening, element).
const LOADED_CHAINS: [(&str, bool, Option<FemElement>); 5] = [
    ("single-link", true, CUBIC),
    ("two-link-free", true, QUINTIC),
    ("barhorst-case1-timoshenko", true, CUBIC),
    ("rotating-beam-axial", false, CUBIC),
    ("spin-up", false, CUBIC),
];

/// The chain and state of `setup` (3 elements per link) with gravity, tip masses, joint
/// springs and dampers, Kelvin–Voigt and applied loads added: (chain, q, q̇, q̈).
fn loaded_chain(
    name: &str,
    fs: bool,
    element: Option<FemElement>,
) -> (Chain, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (_, q, qd, qdd) = setup(name, 3, fs, element);
    let mut sc = data::load_scene(name).unwrap();
    sc.planar_chain_mut().unwrap().gravity = Some(data::scene::Gravity {
        vector: [0.3, -9.0],
    });
    for l in sc.planar_chain_mut().unwrap().links.iter_mut() {
        l.foreshortening = fs && !l.axial;
        l.tip_mass = Some(0.3);
        l.joint.damping = Some(0.3);
        l.joint.stiffness = Some(2.0);
        l.kelvin_voigt = Some(1e-3);
    }
    let mut ch = Chain::with_element(sc.links(), sc.gravity(), 3, element).unwrap();
    ch.distributed_load = 0.7;
    ch.tip_load = 0.4;
    (ch, q, qd, qdd)
}

/// The force groups without inertia on the last kinematic pass (the energy-midpoint
/// iteration's forces at q̄) equal the full passes exactly (`==`: up to the sign of zeros), with
/// gravity, joint springs and dampers, Kelvin–Voigt, applied loads, foreshortening, axial and
/// Timoshenko links and a prescribed joint.
#[test]
fn sys_residual_parts_at_last_q_equal_the_full_passes() {
    use fem::chain::Parts;
    for (name, fs, element) in LOADED_CHAINS {
        let (mut ch, q, qd, qdd) = loaded_chain(name, fs, element);
        let n = ch.ndof;
        let zero = vec![0.0; n];
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        let t = 0.7;
        ch.residual(t, &q, &qd, &qdd, &mut a);
        for p in [Parts::CONSERVATIVE, Parts::NONCONSERVATIVE] {
            ch.residual_parts_at_last_q(t, &q, &qd, p, &mut a);
            ch.residual_parts(t, &q, &qd, &zero, p, &mut b);
            assert!(a.iter().any(|v| *v != 0.0), "{name}: {p:?} is zero");
            for i in 0..n {
                assert!(a[i] == b[i], "{name}: {p:?} dof {i}: {} vs {}", a[i], b[i]);
            }
        }
    }
}

/// The potential on the last kinematic pass (the energy-midpoint iteration's V(q₁) after its
/// mass product) equals the energies' own walk bit for bit on [`LOADED_CHAINS`] (a prescribed
/// joint takes the walk). The iteration's T₁ = ½q̇ᵀ(M q̇) is checked against the energies by
/// `sys_mass_product_and_kinetic_gradient_match_the_reported_kinetic_energy`.
#[test]
fn sys_potential_at_last_q_equals_the_energies() {
    use fem::chain::Parts;
    for (name, fs, element) in LOADED_CHAINS {
        let (mut ch, q, qd, _) = loaded_chain(name, fs, element);
        let mut mv = vec![0.0; ch.ndof];
        let zero = vec![0.0; ch.ndof];
        let t = 0.7;
        ch.residual_parts(t, &q, &zero, &qd, Parts::INERTIA, &mut mv);
        let [strain, spring, gravity] = ch.potential_at_last_q(t, &q);
        let [_, e_strain, e_spring, e_gravity] = ch.energies(t, &q, &qd);
        assert!(strain != 0.0 && spring != 0.0 && gravity != 0.0, "{name}");
        assert!(
            strain == e_strain && spring == e_spring && gravity == e_gravity,
            "{name}: {:?} vs {:?}",
            [strain, spring, gravity],
            [e_strain, e_spring, e_gravity]
        );
    }
}

#[test]
fn sys_newton_solve_of_real_chain_matrices_is_backward_stable() {
    // The Newton matrices of the arms at their default meshes, with the coefficients of a
    // generalized-α step (ρ∞ = 0.9, h = 1e-3): the sparse LU solve leaves a residual at
    // round-off, ‖S x − r‖ ≤ n ε ‖S‖∞ ‖x‖∞ (a backward error of a few ulps per row).
    let n_el = fem::settings::elements(&data::FemSettings::default()).unwrap();
    for name in [
        "two-link-free",
        "barhorst-case1-timoshenko",
        "spin-up-axial",
    ] {
        let sc = data::load_scene(name).unwrap();
        let mut ch = Chain::new(sc.links(), sc.gravity(), n_el).unwrap();
        let n = ch.ndof;
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        ch.initial_state(&mut q, &mut qd);
        for i in 0..n {
            q[i] += 1e-3 * (i as f64 * 1.3).sin();
            qd[i] += 0.1 * (i as f64 * 0.7).cos();
        }
        let mut r = vec![0.0; n];
        ch.residual(0.2, &q, &qd, &vec![0.0; n], &mut r);
        let (rho, h) = (0.9, 1e-3);
        let (am, af) = ((2.0 * rho - 1.0) / (rho + 1.0), rho / (rho + 1.0));
        let beta = 0.25 * (1.0 - am + af) * (1.0 - am + af);
        let gamma = 0.5 - am + af;
        let c = NewtonCoefficients {
            c_a: (1.0 - am) / (beta * h * h),
            c_v: (1.0 - af) * gamma / (beta * h),
            c_q: 1.0 - af,
        };
        let mut s = ch.new_matrix();
        ch.newton_matrix(&q, c, &mut s);
        let norm_s = (0..n)
            .map(|i| (0..n).map(|j| s.get(i, j).abs()).sum::<f64>())
            .fold(0.0f64, f64::max);
        let unfactored = s.clone();
        s.factorize().unwrap();
        let mut x = r.clone();
        s.solve_in_place(&mut x);
        let mut sx = vec![0.0; n];
        unfactored.matvec(&x, &mut sx);
        let res = sx
            .iter()
            .zip(&r)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let norm_x = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let bound = n as f64 * f64::EPSILON * norm_s * norm_x;
        eprintln!("{name}: n = {n}, ‖Sx − r‖ = {res:.2e}, bound {bound:.2e}");
        assert!(res <= bound, "{name}: ‖Sx − r‖ = {res:e} > {bound:e}");
    }
}

#[test]
fn sys_analytic_kinetic_gradient_matches_the_finite_difference_identity_at_real_states() {
    // ∂T/∂q(q, x) of the analytic sweep against Ṁ(x)x − R_in(q, x, 0) with Ṁ(x)x by central
    // differences of M(q)x (an independent route through the residual's inertial pass), at the
    // default runs advanced to 0.25 s with x = the run's velocity and x = ½hq̈ (the two vectors
    // the energy-midpoint step uses). The central difference errs relative to the terms it
    // differences, ‖x‖∞‖M(q)x‖∞ (links of order 1): truncation ~(ε‖x‖∞)² = FD_STEP² = 1e-10,
    // round-off ~1e-16/FD_STEP = 1e-11; 1e-8 of that scale leaves a factor 100 for the third
    // derivatives. (∂T/∂q itself can be far smaller where x is mostly elastic.)
    use fem::method::energy_midpoint::{
        FD_STEP, kinetic_gradient, kinetic_gradient_fd, mass_product,
    };
    for name in ["two-link-free", "barhorst-case1"] {
        let p = common::advanced_default_run(name, 0.25);
        let h = p.h_nominal;
        let st = &p.driver.state;
        let (t, q) = (st.t, st.q.clone());
        let half_dv: Vec<f64> = st.qdd.iter().map(|a| 0.5 * h * a).collect();
        let mut ch = p.driver.chain.clone();
        for (label, x) in [("velocity", st.qd.clone()), ("½hq̈", half_dv)] {
            let exact = kinetic_gradient(&mut ch, t, &q, &x);
            let oracle = kinetic_gradient_fd(&mut ch, t, &q, &x, FD_STEP);
            let norm = |v: &[f64]| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let scale = norm(&x) * norm(&mass_product(&mut ch, t, &q, &x));
            let worst = exact
                .iter()
                .zip(&oracle)
                .fold(0.0f64, |a, (e, o)| a.max((e - o).abs()));
            eprintln!(
                "{name} x = {label}: |∂T/∂q| {:.3e}, ‖x‖‖Mx‖ {scale:.3e}, analytic − FD {worst:.2e}",
                norm(&exact)
            );
            assert!(
                norm(&exact) > 0.0,
                "{name}: zero kinetic gradient at a moving state"
            );
            assert!(
                worst < 1e-8 * scale,
                "{name} x = {label}: {worst:.3e} of {scale:.3e}"
            );
        }
    }
}
