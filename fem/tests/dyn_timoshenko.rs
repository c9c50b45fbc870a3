//! Timoshenko links in the floating-frame chain (dynamics): the residual is Lagrange's equations
//! of the reported energies, the Newton matrix its derivative, the linearization about rest is
//! the linear (modes/statics) Timoshenko model, stiff shear recovers the Euler–Bernoulli chain,
//! and whole runs close their energy ledgers.

// Index loops mirror the matrix formulas being checked.
#![allow(clippy::needless_range_loop)]

mod common;

use data::{Backend, RunResult, Scene, Settings, StabilityVerdict};
use fem::FemBackend;
use fem::chain::{Chain, NewtonCoefficients, Parts};
use fem::element::timoshenko::Timoshenko;
use fem::linear::LinearLink;

/// Switches Timoshenko shear on for every link: κGA = `ratio`·EI/L², ρI = `rho_i_ratio`·ρA L²
/// (rotary inertia on when > 0).
fn make_timoshenko(sc: &mut Scene, ratio: f64, rho_i_ratio: f64) {
    for l in sc.planar_chain_mut().unwrap().links.iter_mut() {
        l.shear = true;
        l.shear_stiffness = Some(ratio * l.bending_stiffness / (l.length * l.length));
        if rho_i_ratio > 0.0 {
            l.rotary_inertia = true;
            l.rotary_inertia_per_length =
                Some(rho_i_ratio * l.mass_per_length * l.length * l.length);
        }
    }
}

/// A Timoshenko chain with every effect on (tip masses and inertias, hub inertia, gravity,
/// rotary inertia, foreshortening as requested) at a generic state.
fn setup(
    name: &str,
    n_el: usize,
    foreshortening: bool,
    rho_i_ratio: f64,
) -> (Chain, Vec<f64>, Vec<f64>, Vec<f64>) {
    // "euler:<scene>": Euler–Bernoulli links with section rotary inertia ½∫ρI(φ̇ + v̇′)².
    let (name, shear) = match name.strip_prefix("euler:") {
        Some(n) => (n, false),
        None => (name, true),
    };
    let mut sc = data::load_scene(name).unwrap();
    if shear {
        make_timoshenko(&mut sc, 30.0, rho_i_ratio);
    } else {
        make_timoshenko(&mut sc, 30.0, rho_i_ratio);
        sc.planar_chain_mut()
            .unwrap()
            .links
            .iter_mut()
            .for_each(|l| l.shear = false);
    }
    for l in sc.planar_chain_mut().unwrap().links.iter_mut() {
        l.foreshortening = foreshortening && !l.axial;
        l.kelvin_voigt = None;
        l.tip_mass = Some(0.3);
        l.tip_inertia = Some(0.01);
        l.joint.hub_inertia = Some(0.02);
    }
    sc.planar_chain_mut().unwrap().gravity = Some(data::scene::Gravity {
        vector: [0.3, -9.0],
    });
    let ch = Chain::new(sc.links(), sc.gravity(), n_el).unwrap();
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

/// Free-joint chains (Lagrange's equations of the reported energies hold as checked below
/// only without explicitly time-dependent kinematics) plus the extensible spin-up link.
const CASES: [(&str, bool, f64); 7] = [
    ("euler:two-link-free-undamped", true, 1e-3),
    ("single-link", false, 0.0),
    ("single-link", true, 1e-3),
    ("two-link-free-undamped", false, 1e-3),
    ("two-link-free-undamped", true, 0.0),
    ("two-link-free-undamped", true, 1e-3),
    ("spin-up-axial", false, 1e-3),
];

#[test]
fn sys_timoshenko_residual_is_lagrange_of_the_reported_energies() {
    for (name, fs, rho_i) in CASES {
        let (mut ch, q, qd, qdd) = setup(name, 3, fs, rho_i);
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
            let lagrange = dpdt - dtdq + dvdq + joint;
            // Nested central differences: truncation O(h²)·T‴ and round-off ε·T/(e·hs) ≈ 1e-5
            // absolute; 1e-8 of the residual scale covers both, except with the stiff axial
            // link (EA = 2.8e7 amplifies round-off: 1e-6), as for the Euler chain.
            let tol = if name == "spin-up-axial" { 1e-6 } else { 1e-8 };
            assert!(
                (lagrange - r[i]).abs() < tol * scale,
                "{name} fs={fs} ρI={rho_i} {}: {lagrange} vs {}",
                ch.describe_dof(i),
                r[i]
            );
        }
    }
}

#[test]
fn sys_timoshenko_newton_matrix_is_the_residual_derivative() {
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.01,
        c_q: 1e-4,
    };
    // Exact without foreshortening (FD accuracy; the two-link case has larger ∂/∂q terms, as
    // for the Euler chain). With foreshortening the documented ∂s/∂q couplings (O(v′); free
    // chains then use the dense finite-difference Jacobian) are omitted: exact at v = 0.
    for (name, fs, rho_i, tol) in [
        ("single-link", false, 0.0, 1e-7),
        ("single-link", false, 1e-3, 1e-7),
        ("euler:single-link", false, 1e-3, 1e-7),
        ("two-link-free-undamped", false, 1e-3, 1e-4),
        ("spin-up-axial", false, 1e-3, 1e-7),
        ("spin-up", true, 1e-3, 1e-7),
    ] {
        let (mut ch, mut q, qd, qdd) = setup(name, 3, fs, rho_i);
        if fs {
            // The omitted foreshortening couplings are O(v′): at an undeformed configuration
            // (with rates and accelerations) the band matrix is exact.
            q.iter_mut().for_each(|x| *x = 0.0);
        }
        // Kelvin–Voigt on, for the c_v part.
        for l in ch.links.iter_mut() {
            l.kelvin_voigt = 0.2;
        }
        let (worst, scale) = common::newton_matrix_fd_error(&mut ch, &q, &qd, &qdd, c);
        eprintln!("{name} fs={fs} ρI={rho_i}: Newton matrix vs FD {worst:.3e} of {scale:.3e}");
        assert!(
            worst < tol * scale,
            "{name} fs={fs}: {worst:.3e} of {scale:.3e}"
        );
    }
}

#[test]
fn sys_timoshenko_mass_is_symmetric_and_kelvin_voigt_is_the_dissipation() {
    // Free joints only: with a prescribed joint the inertial pass also carries the prescribed
    // rates and accelerations, so it is not a pure product M x.
    for (name, fs, rho_i) in CASES.into_iter().filter(|c| c.0 != "spin-up-axial") {
        let (mut ch, q, qd, _) = setup(name, 3, fs, rho_i);
        let n = ch.ndof;
        let t = 0.3;
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mx = fem::method::energy_midpoint::mass_product(&mut ch, t, &q, &x);
        let mv = fem::method::energy_midpoint::mass_product(&mut ch, t, &q, &qd);
        let xmv: f64 = x.iter().zip(&mv).map(|(a, b)| a * b).sum();
        let vmx: f64 = qd.iter().zip(&mx).map(|(a, b)| a * b).sum();
        let vmv: f64 = qd.iter().zip(&mv).map(|(a, b)| a * b).sum();
        // xᵀMv = vᵀMx (symmetry) and vᵀMv = 2T (the mass is the kinetic energy's Hessian):
        // both sides are sums of the same products, equal to round-off.
        assert!(
            (xmv - vmx).abs() < 1e-12 * xmv.abs().max(vmx.abs()),
            "{name}"
        );
        let kin = ch.energies(t, &q, &qd)[0];
        assert!(
            (vmv - 2.0 * kin).abs() < 1e-12 * kin,
            "{name}: {vmv} vs {}",
            2.0 * kin
        );
        // Kelvin–Voigt on ψ′: the non-conservative residual's power is the booked dissipation.
        for l in ch.links.iter_mut() {
            l.kelvin_voigt = 0.2;
        }
        let mut r = vec![0.0; n];
        let zero = vec![0.0; n];
        ch.residual_parts(t, &q, &qd, &zero, Parts::NONCONSERVATIVE, &mut r);
        let power: f64 = r.iter().zip(&qd).map(|(a, b)| a * b).sum();
        let mut applied = 0.0;
        for li in 0..ch.links.len() {
            let l = &ch.links[li];
            if l.joint.dof != fem::chain::NONE {
                applied += l.joint.applied(t) * qd[l.joint.dof];
            }
        }
        let (pj, pkv) = ch.dissipation_power(t, &qd);
        assert!(pkv > 0.0);
        assert!(
            (power + applied - pj - pkv).abs() < 1e-12 * (pj + pkv),
            "{name}: {power} vs {}",
            pj + pkv - applied
        );
    }
}

/// Dense copy of the chain's Newton matrix with coefficients (c_a, 0, c_q) at rest.
fn chain_matrix(ch: &mut Chain, c_a: f64, c_q: f64) -> Vec<Vec<f64>> {
    let n = ch.ndof;
    let z = vec![0.0; n];
    let mut r = vec![0.0; n];
    ch.residual(0.0, &z, &z, &z, &mut r);
    let mut s = ch.new_matrix();
    ch.newton_matrix(&z, NewtonCoefficients { c_a, c_v: 0.0, c_q }, &mut s);
    (0..n)
        .map(|i| (0..n).map(|j| s.get(i, j)).collect())
        .collect()
}

#[test]
fn cross_timoshenko_chain_linearized_at_rest_is_the_linear_model() {
    // cantilever-timoshenko: fixed hub, shear and rotary inertia; with and without the axial
    // field. A single link has the same DOF order in both models (per element: interior DOFs,
    // then node e + 1: v, ψ, u), so M and K compare entry by entry.
    for axial in [false, true] {
        let mut sc = data::load_scene("cantilever-timoshenko").unwrap();
        sc.planar_chain_mut().unwrap().links[0].axial = axial;
        let n_el = 6;
        let mut ch = Chain::new(sc.links(), None, n_el).unwrap();
        let lin = LinearLink::assemble(&sc.links()[0], n_el, 0.0, &Timoshenko).unwrap();
        let n = ch.ndof;
        assert_eq!(n, lin.ndof());
        assert_eq!(n, n_el * (if axial { 6 } else { 5 }));
        let m = chain_matrix(&mut ch, 1.0, 0.0);
        let k = chain_matrix(&mut ch, 0.0, 1.0);
        let (mut mmax, mut kmax) = (0.0f64, 0.0f64);
        let (mut dm, mut dk) = (0.0f64, 0.0f64);
        for i in 0..n {
            for j in 0..n {
                mmax = mmax.max(lin.m[(i, j)].abs());
                kmax = kmax.max(lin.k[(i, j)].abs());
                dm = dm.max((m[i][j] - lin.m[(i, j)]).abs());
                dk = dk.max((k[i][j] - lin.k[(i, j)]).abs());
            }
        }
        eprintln!(
            "axial={axial}: |ΔM|/max|M| = {:.2e}, |ΔK|/max|K| = {:.2e}",
            dm / mmax,
            dk / kmax
        );
        // Same Gauss-4 integrals assembled in a different order: round-off only.
        assert!(dm < 1e-12 * mmax && dk < 1e-12 * kmax, "{dm} {dk}");
        // Hence the same frequencies as the modes backend (reported against the exact
        // Timoshenko ones for information; their O(h⁴) convergence is checked in
        // sys_modes_statics).
        let to_mat = |a: &Vec<Vec<f64>>| faer::Mat::from_fn(n, n, |i, j| a[i][j]);
        let (lam, _) = fem::modes::generalized_eigen(&to_mat(&k), &to_mat(&m)).unwrap();
        let modes = fem::modes::link_modes(&lin, 3).unwrap();
        let l = &sc.links()[0];
        let exact = common::timoshenko_omega(
            l.bending_stiffness,
            l.shear_stiffness.unwrap(),
            l.mass_per_length,
            l.rotary_inertia_per_length.unwrap(),
            l.length,
            2,
            3.0e5,
        );
        for (idx, md) in modes.iter().enumerate() {
            let w = lam[idx].sqrt();
            let rel = (w - md.omega).abs() / md.omega;
            let vs_exact = exact
                .iter()
                .map(|x| (x - w).abs() / x)
                .fold(f64::INFINITY, f64::min);
            eprintln!(
                "axial={axial} mode {} ({}): chain ω = {w:.8e}, vs modes {rel:.1e}, \
                 vs exact bending {vs_exact:.1e}",
                idx + 1,
                md.kind
            );
            // Same matrices up to 1e-16: eigenvalues agree to the solver's round-off.
            assert!(rel < 1e-10, "mode {}: {rel}", idx + 1);
        }
    }
}

fn settings(n: usize, dt: Option<f64>, t_end: f64, method: Option<&str>) -> Settings {
    let mut st = Settings::default();
    st.discretization.elements = Some(n);
    st.time.dt = dt;
    st.time.t_end = Some(t_end);
    st.time.method = method.map(|m| m.parse().expect("a method name"));
    st
}

fn sim(sc: &Scene, st: &Settings) -> RunResult {
    let r = FemBackend.simulate(sc, st).unwrap();
    assert_eq!(
        r.verdict,
        StabilityVerdict::Completed,
        "{}: {:?}",
        sc.name,
        r.events
    );
    r
}

fn channel<'a>(r: &'a RunResult, name: &str) -> &'a [f64] {
    &r.observables.get(name).unwrap().values
}

fn max_diff(a: &RunResult, b: &RunResult, name: &str) -> f64 {
    channel(a, name)
        .iter()
        .zip(channel(b, name))
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn conv_timoshenko_stiff_shear_recovers_the_euler_chain() {
    // two-link-free, 0.5 s: Timoshenko with κGA = r·EI/L² against the Euler chain on the same
    // mesh and steps. The shear compliance changes the response by O(EI/(κGA L²)) = O(1/r):
    // the difference must be small and fall ~10× per decade of r. At dt 5e-4: at 2e-3 the
    // stiff-shear runs retry Newton failures with quarter steps, and the difference (5e-5 of a
    // time error of 9e-4) then depended on where they fell — 6.4e-5 with one pattern of Newton
    // matrices, 2.6e-4 with a fresh matrix every step; at 5e-4 both give 5.391e-5, as dt
    // 1.25e-4 does.
    let base = data::load_scene("two-link-free").unwrap();
    let st = settings(4, Some(5e-4), 0.5, None);
    let euler = sim(&base, &st);
    let mut diffs = Vec::new();
    for ratio in [1e3, 1e4] {
        let mut sc = base.clone();
        make_timoshenko(&mut sc, ratio, 0.0);
        let r = sim(&sc, &st);
        let d = max_diff(&r, &euler, "link2.tip_y");
        let peak = channel(&euler, "link2.tip_y")
            .iter()
            .fold(0.0f64, |a, b| a.max(b.abs()));
        let dd = max_diff(&r, &euler, "link2.tip_deflection");
        let dpeak = channel(&euler, "link2.tip_deflection")
            .iter()
            .fold(0.0f64, |a, b| a.max(b.abs()));
        eprintln!(
            "κGA = {ratio:.0e}·EI/L²: tip_y_2 diff {d:.3e} of {peak:.3e}, deflection diff \
             {dd:.3e} of {dpeak:.3e}"
        );
        diffs.push(dd / dpeak);
        assert!(d < 1e-2 * peak);
    }
    let ratio = diffs[0] / diffs[1];
    eprintln!("deflection difference ratio per decade of κGA: {ratio:.2}");
    // First order in 1/κGA: ratio 10 (5..20 allows the O(1/κGA²) remainder).
    assert!((5.0..20.0).contains(&ratio), "ratio {ratio}");
    assert!(diffs[1] < 1e-2, "{}", diffs[1]);
}

#[test]
fn dyn_timoshenko_two_link_free_closes_its_ledger() {
    // Energy-midpoint (the default for free chains) with foreshortening, joint springs and
    // dampers and Kelvin–Voigt on ψ′, with and without rotary inertia.
    for rho_i in [0.0, 1e-3] {
        let mut sc = data::load_scene("two-link-free").unwrap();
        make_timoshenko(&mut sc, 100.0, rho_i);
        let start = std::time::Instant::now();
        let r = sim(&sc, &settings(4, None, 0.5, None));
        let c = r.ledger.relative_closure();
        eprintln!(
            "two-link-free Timoshenko ρI={rho_i}: closure {c:.3e}, {} steps, {:.2} s",
            r.cost.steps,
            start.elapsed().as_secs_f64()
        );
        assert!(c < 1e-9, "closure {c}");
        // Generalized-α (trapezoidal, ρ∞ = 1) runs the same chain and closes its ledger to
        // its O(h²) energy error.
        let g = sim(&sc, &settings(4, None, 0.5, Some("generalized-alpha")));
        let cg = g.ledger.relative_closure();
        eprintln!("  generalized-α at the default step: closure {cg:.3e}");
        assert!(cg < 1e-4, "generalized-α closure {cg}");
    }
}

#[test]
fn conv_timoshenko_massless_sections_keep_both_schemes_convergent() {
    // Without rotary inertia the ψ are algebraic variables. Both schemes converge to a
    // fine-step reference with errors of the same size, falling faster than first order.
    // Measured (two-link-free, κGA = 100 EI/L², reference dt = 1.25e-4):
    // midpoint 1.04e-4 → 3.72e-5, generalized-α 1.03e-4 → 3.64e-5 (ratios 2.8; the Euler chain
    // shows 2.5 for midpoint over the same steps). An inconsistent initial acceleration of the
    // massless directions had made generalized-α first order (7.9e-3 → 4.0e-3).
    let mut sc = data::load_scene("two-link-free").unwrap();
    make_timoshenko(&mut sc, 100.0, 0.0);
    let reference = sim(&sc, &settings(4, Some(1.25e-4), 0.5, None));
    let mut errs = [[0.0; 2]; 2];
    for (k, dt) in [2e-3, 1e-3].into_iter().enumerate() {
        for (m, method) in [None, Some("generalized-alpha")].into_iter().enumerate() {
            let r = sim(&sc, &settings(4, Some(dt), 0.5, method));
            errs[m][k] = max_diff(&r, &reference, "link2.tip_y");
        }
    }
    eprintln!("midpoint {:?}, generalized-α {:?}", errs[0], errs[1]);
    for m in 0..2 {
        assert!(errs[m][0] / errs[m][1] > 2.5, "{errs:?}");
    }
    for k in 0..2 {
        assert!(errs[1][k] < 1.5 * errs[0][k], "{errs:?}");
    }
}

#[test]
fn dyn_barhorst_case1_timoshenko_free_fall_closes_its_ledger() {
    // Free fall until just before the first contact (the contact itself is not part of this
    // backend yet: the `[[contact]]` table is removed).
    let mut sc = data::load_scene("barhorst-case1-timoshenko").unwrap();
    sc.planar_chain_mut().unwrap().contacts.clear();
    // DOFs: per link 3 interior (v(⅓), v(⅔), ψ(½)) per element and (v, ψ) per node, plus the
    // two joint angles: 2·(3·4 + 2·4) + 2 = 42 (the Euler chain: 2·2·4 + 2 = 18).
    let ch = Chain::new(sc.links(), sc.gravity(), 4).unwrap();
    assert_eq!(ch.ndof, 42);
    let mut euler = sc.clone();
    euler
        .planar_chain_mut()
        .unwrap()
        .links
        .iter_mut()
        .for_each(|l| l.shear = false);
    assert_eq!(Chain::new(euler.links(), None, 4).unwrap().ndof, 18);
    // Central difference cannot step the massless ψ: refused by name.
    let err = FemBackend
        .simulate(&sc, &settings(4, None, 0.15, Some("central-difference")))
        .unwrap_err();
    assert!(format!("{err}").contains("rotary_inertia"), "{err}");
    for method in [None, Some("generalized-alpha")] {
        let start = std::time::Instant::now();
        let r = sim(&sc, &settings(4, None, 0.15, method));
        let c = r.ledger.relative_closure();
        let y = channel(&r, "link2.tip_y");
        eprintln!(
            "barhorst-case1-timoshenko {method:?}: closure {c:.3e}, {} steps, tip y {:.4} → {:.4}, \
             {:.2} s",
            r.cost.steps,
            y[0],
            y[y.len() - 1],
            start.elapsed().as_secs_f64()
        );
        // The settled start (massless directions balanced: the tip section of link 1 carries
        // joint 2's spring moment 20·5° = 1.75, the root sections turn their frames against
        // v = −αx) moves the joint angles only by the root shear rotations, O(moment/κGA·L).
        for (k, l) in sc.links().iter().enumerate() {
            let a0 = channel(&r, &format!("joint{}.angle", k + 1))[0];
            let shift = a0 - l.joint.initial_angle;
            eprintln!(
                "  joint {} angle at t = 0 − initial_angle: {shift:.3e}",
                k + 1
            );
            assert!(shift.abs() < 1e-3 * l.joint.initial_angle);
        }
        // The arm falls (gravity) but has not reached the surface y = −1 yet.
        assert!(y[y.len() - 1] < y[0] && y[y.len() - 1] > -1.0);
        let tol = if method.is_none() { 1e-9 } else { 1e-3 };
        assert!(c < tol, "closure {c}");
    }
}

#[test]
fn dyn_timoshenko_undamped_massless_hub_defaults_to_generalized_alpha() {
    // two-link-free-undamped with shear and no rotary inertia: the frame-rotation direction of
    // each link is undamped and almost massless, which stalls the midpoint Newton iteration
    // (stopped at t = 0.32 s, measured); generalized-α is the default there and runs.
    let mut sc = data::load_scene("two-link-free-undamped").unwrap();
    make_timoshenko(&mut sc, 100.0, 0.0);
    assert_eq!(
        fem::run::default_method(sc.planar_chain().unwrap()),
        fem::settings::Method::GeneralizedAlpha
    );
    let r = sim(&sc, &settings(4, None, 0.5, None));
    let c = r.ledger.relative_closure();
    eprintln!("two-link-free-undamped Timoshenko, default method: closure {c:.2e}");
    // Trapezoidal rule: O(h²) energy error through M(q) (the Euler chain: 0.11 over 10 s).
    assert!(c < 1e-4, "closure {c}");
    // With a hub inertia (or rotary inertia, or damping) the midpoint scheme stays the default.
    for l in sc.planar_chain_mut().unwrap().links.iter_mut() {
        l.joint.hub_inertia = Some(1e-2);
    }
    assert_eq!(
        fem::run::default_method(sc.planar_chain().unwrap()),
        fem::settings::Method::EnergyMidpoint
    );
    let r = sim(&sc, &settings(4, None, 0.5, None));
    let c = r.ledger.relative_closure();
    eprintln!("  with hub inertia, energy-midpoint: closure {c:.2e}");
    assert!(c < 1e-9, "closure {c}");
}

#[test]
fn dyn_constrained_arm_timoshenko_axial_runs_without_contact() {
    // The extensible constrained arm with shear on, wall removed: torque-driven spin-up of an
    // axial + Timoshenko link (generalized-α, ρ∞ = 0.9 by default for extensible links). Its
    // ledger closes like the Euler arm's (same scheme), and the Timoshenko response tends to
    // the Euler one as O(EI/(κGA L²)): ~10× closer per decade of κGA.
    let base = {
        let mut sc = data::load_scene("constrained-arm").unwrap();
        sc.planar_chain_mut().unwrap().contacts.clear();
        sc
    };
    let euler = sim(&base, &settings(8, None, 0.5, None));
    let ce = euler.ledger.relative_closure();
    let peak = channel(&euler, "link1.tip_deflection")
        .iter()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let mut diffs = Vec::new();
    for ratio in [1e3, 1e4] {
        let mut sc = base.clone();
        make_timoshenko(&mut sc, ratio, 0.0);
        let start = std::time::Instant::now();
        let timo = sim(&sc, &settings(8, None, 0.5, None));
        let ct = timo.ledger.relative_closure();
        let d = max_diff(&euler, &timo, "link1.tip_deflection");
        eprintln!(
            "constrained-arm (no wall), κGA = {ratio:.0e}·EI/L²: closure Euler {ce:.2e}, \
             Timoshenko {ct:.2e}; tip deflection Timoshenko − Euler {d:.2e} of {peak:.2e}; \
             {} steps, {:.2} s",
            timo.cost.steps,
            start.elapsed().as_secs_f64()
        );
        assert!(ct < 2.0 * ce.max(1e-10), "closure {ct} vs Euler {ce}");
        diffs.push(d);
    }
    let r = diffs[0] / diffs[1];
    eprintln!("  difference ratio per decade of κGA: {r:.2}");
    assert!((5.0..20.0).contains(&r), "ratio {r}");
}

#[test]
fn sys_timoshenko_rigid_rotation_kinetic_energy_is_the_rigid_inertia() {
    // Undeformed link turning at ω: T = ½(J_hub + ρA L³/3 + m L² + J_tip + ρI L)ω², with the
    // section rotary inertia ρI L counted once (Timoshenko ψ = 0 and Euler v′ = 0 alike).
    for shear in [true, false] {
        let mut sc = data::load_scene("single-link").unwrap();
        make_timoshenko(&mut sc, 30.0, 1e-2);
        let l = &mut sc.planar_chain_mut().unwrap().links[0];
        l.shear = shear;
        l.tip_mass = Some(0.3);
        l.tip_inertia = Some(0.01);
        l.joint.hub_inertia = Some(0.02);
        let l = &sc.links()[0];
        let ch = Chain::new(sc.links(), None, 3).unwrap();
        let n = ch.ndof;
        let q = vec![0.0; n];
        let mut qd = vec![0.0; n];
        let w = 1.7;
        qd[ch.links[0].joint.dof] = w;
        let len = l.length;
        let inertia = 0.02
            + l.mass_per_length * len.powi(3) / 3.0
            + 0.3 * len * len
            + 0.01
            + l.rotary_inertia_per_length.unwrap() * len;
        let t = ch.energies(0.0, &q, &qd)[0];
        let exact = 0.5 * inertia * w * w;
        eprintln!("shear {shear}: T = {t:.15e}, rigid {exact:.15e}");
        // Gauss quadrature of polynomials of degree ≤ 2: exact to round-off.
        assert!((t - exact).abs() < 1e-13 * exact, "{t} vs {exact}");
    }
}

#[test]
fn dyn_cantilever_timoshenko_step_load_conserves_energy_and_peaks_at_twice_static() {
    // Fixed hub (prescribed), step tip load P: the linear Timoshenko cantilever oscillates
    // between 0 and about twice the static deflection P L³/3EI + P L/κGA (exact in the
    // element: end-loaded solution is cubic v, quadratic ψ). Trapezoidal rule on a linear
    // system: the ledger closes to round-off. With and without rotary inertia (massless ψ).
    for rot in [true, false] {
        let mut sc = data::load_scene("cantilever-timoshenko").unwrap();
        sc.planar_chain_mut().unwrap().links[0].rotary_inertia = rot;
        let l = &sc.links()[0];
        let p = sc.statics().unwrap().tip_force.unwrap();
        let stat = p * l.length.powi(3) / (3.0 * l.bending_stiffness)
            + p * l.length / l.shear_stiffness.unwrap();
        let r = sim(&sc, &settings(8, Some(2e-6), 1.3e-3, None));
        let c = r.ledger.relative_closure();
        let v = channel(&r, "link1.tip_deflection");
        let vmax = v.iter().fold(0.0f64, |a, b| a.max(*b));
        eprintln!(
            "rotary inertia {rot}: closure {c:.2e}, peak {vmax:.6e} = {:.4}× static {stat:.6e}",
            vmax / stat
        );
        assert!(c < 1e-9, "closure {c}");
        // The first mode carries ~all of the static shape: the peak is 2× static within the
        // higher modes' share (a few %).
        assert!((vmax / stat - 2.0).abs() < 0.1, "{}", vmax / stat);
    }
}

#[test]
fn dyn_spin_up_timoshenko_tends_to_the_euler_spin_up() {
    // Prescribed hub with foreshortening (centrifugal stiffening through s = −½∫v′²): the
    // Timoshenko spin-up tends to the Euler one as O(EI/(κGA L²)), ~10× per decade.
    let base = data::load_scene("spin-up").unwrap();
    let st = settings(8, None, 6.0, None);
    let euler = sim(&base, &st);
    let peak = channel(&euler, "link1.tip_deflection")
        .iter()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let mut diffs = Vec::new();
    for ratio in [1e3, 1e4] {
        let mut sc = base.clone();
        make_timoshenko(&mut sc, ratio, 0.0);
        let r = sim(&sc, &st);
        let d = max_diff(&r, &euler, "link1.tip_deflection");
        eprintln!(
            "spin-up κGA = {ratio:.0e}·EI/L²: tip deflection diff {d:.3e} of {peak:.3e}, closure \
             {:.2e} (Euler {:.2e})",
            r.ledger.relative_closure(),
            euler.ledger.relative_closure()
        );
        diffs.push(d);
    }
    let r = diffs[0] / diffs[1];
    eprintln!("  ratio per decade: {r:.2}");
    assert!((5.0..20.0).contains(&r), "ratio {r}");
}

#[test]
fn dyn_barhorst_timoshenko_contact_balances_momentum_with_and_without_section_inertia() {
    // Without rotary inertia the section rotations are massless: the impact map acts on the
    // massive block (tests/dyn_timoshenko_contact.rs); with a small section inertia
    // ρI = 1e-3 slug·ft the whole M is regular. Either way the first impacts obey the plastic
    // impulse–momentum balance to round-off and lose kinetic energy.
    let sc = data::load_scene("barhorst-case1-timoshenko").unwrap();
    let st = settings(4, None, 0.3, None);
    for with_inertia in [false, true] {
        let mut sc = sc.clone();
        for l in &mut sc.planar_chain_mut().unwrap().links {
            l.rotary_inertia = with_inertia;
            l.rotary_inertia_per_length = with_inertia.then_some(1e-3);
        }
        let r = sim(&sc, &st);
        let impacts: Vec<(f64, f64, f64)> = r
            .events
            .iter()
            .filter_map(|e| match e {
                data::Event::Impact {
                    momentum_residual,
                    kinetic_energy_lost,
                    normal_velocity_after,
                    ..
                } => Some((
                    *momentum_residual,
                    *kinetic_energy_lost,
                    *normal_velocity_after,
                )),
                _ => None,
            })
            .collect();
        assert!(!impacts.is_empty(), "no impact before t = 0.3");
        for (res, lost, vn) in impacts {
            assert!(res < 1e-10, "momentum residual {res:e}");
            assert!(lost >= 0.0, "kinetic energy gained {lost:e}");
            assert!(vn.abs() < 1e-10, "normal velocity after {vn:e}");
        }
        assert!(
            r.ledger.relative_closure() < 1e-5,
            "{:e}",
            r.ledger.relative_closure()
        );
    }
}
