//! Timoshenko links (issue 7): section matrices, Rayleigh–Ritz frequencies of the stocky
//! cantilever, the κGA → ∞ (Euler) limit, barhorst-case1-timoshenko impacts and ledger, and the
//! constrained arm approaching the Euler model as the section gets slender.

use data::scene::Scene;
use data::{
    Backend, BackendError, Basis, Discretization, Event, RunResult, Settings, StabilityVerdict,
    TimeStepping, load_scene,
};
use modal::ModalBackend;
use modal::basis::quadrature::Quadrature;
use modal::model::{Chain, SectionKind};
use modal::setup::build_chain;
use modal::simulate::simulate_detailed;

/// Clamped–free Timoshenko frequencies [Hz] of `cantilever-timoshenko` (shear + rotary inertia)
/// from the independent analytic frequency equation in verify/src/analytic/timoshenko.rs, as
/// printed by `flexverify verify --filter freq-timoshenko --out DIR` (DIR/verification.json,
/// field "reference").
const TIMOSHENKO_HZ: [f64; 4] = [
    828.9436269332228,
    4968.145316089089,
    13066.980729838524,
    23703.08405743314,
];

fn disc(modes: usize, basis: Basis) -> Discretization {
    Discretization {
        modes: Some(modes),
        basis: Some(basis),
        ..Default::default()
    }
}

fn run_settings(modes: usize, basis: Option<Basis>, rtol: f64, t_end: Option<f64>) -> Settings {
    Settings {
        discretization: Discretization {
            modes: Some(modes),
            basis,
            ..Default::default()
        },
        time: TimeStepping {
            rtol: Some(rtol),
            atol: Some(rtol * 1e-3),
            t_end,
            ..Default::default()
        },
    }
}

fn freqs(scene: &Scene, modes: usize, basis: Basis, count: usize) -> Vec<f64> {
    let s = Settings {
        discretization: disc(modes, basis),
        ..Default::default()
    };
    ModalBackend.modes(scene, &s, count).unwrap().frequencies_hz
}

/// Deterministic pseudo-random numbers in (−1, 1).
fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

fn random_state(chain: &Chain, scale: f64, seed: u64) -> Vec<f64> {
    let mut s = seed;
    let mut q = vec![0.0; chain.n];
    for l in &chain.links {
        q[l.theta] = 0.1 * lcg(&mut s);
        for k in 0..l.ne() {
            q[l.a0 + k] = scale * lcg(&mut s) / (1 + k) as f64;
        }
    }
    q
}

/// Symmetric positive definite, by faer's Cholesky factorization of the row-major n × n `m`.
/// The chain's force side at (q, q̇ = 0) against −∇ of `potential` by central differences
/// (step 1e-6): returns max |f + ∇V| / max |f| and max |f|.
fn force_against_potential_gradient(
    chain: &mut Chain,
    q: &mut [f64],
    potential: impl Fn(&mut Chain, &[f64]) -> f64,
) -> (f64, f64) {
    let qd = vec![0.0; chain.n];
    chain.evaluate(0.0, q, &qd);
    let f = chain.force().to_vec();
    let fmax = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for k in 0..chain.n {
        let h = 1e-6;
        let q0 = q[k];
        q[k] = q0 + h;
        let up = potential(chain, q);
        q[k] = q0 - h;
        let um = potential(chain, q);
        q[k] = q0;
        worst = worst.max((-(up - um) / (2.0 * h) - f[k]).abs() / fmax);
    }
    (worst, fmax)
}

fn is_spd(m: &[f64], n: usize) -> bool {
    let a = faer::Mat::<f64>::from_fn(n, n, |i, j| m[i * n + j]);
    a.llt(faer::Side::Lower).is_ok()
}

/// ½∫EI ψ'² + ½∫κGA (v' − ψ)² of link i evaluated from the fields (independent of the
/// assembled matrices): v = φᵀb, ψ = χᵀc or χᵀT b (or the elbow condensation's c).
fn field_strain_energy(scene: &Scene, chain: &Chain, i: usize, q: &[f64]) -> f64 {
    let l = &chain.links[i];
    let sl = &scene.links()[i];
    let (ei, kga) = (sl.bending_stiffness, sl.shear_stiffness.unwrap());
    let chi = l.section.psi_shapes.as_ref().unwrap();
    let (nb, nc) = (l.nb(), chi.count());
    let b = &q[l.b0..l.b0 + nb];
    let c: Vec<f64> = match (&l.section.condensation, chain.elbows.get(i + 1)) {
        // Condensed with the child's elbow: the c of the last evaluation.
        (Some(_), Some(Some(e))) => e.c.clone(),
        (Some(t), _) => (0..nc)
            .map(|k| (0..nb).map(|j| t[k * nb + j] * b[j]).sum())
            .collect(),
        (None, _) => q[l.b0 + nb..l.b0 + nb + nc].to_vec(),
    };
    let quad = Quadrature::composite(sl.length, 64, 12);
    let (mut dp, mut x0, mut x1) = (vec![0.0; nb], vec![0.0; nc], vec![0.0; nc]);
    let mut u = 0.0;
    for (&x, &w) in quad.x.iter().zip(&quad.w) {
        l.transverse.eval(x, 1, &mut dp);
        chi.eval(x, 0, &mut x0);
        chi.eval(x, 1, &mut x1);
        let vp: f64 = dp.iter().zip(b).map(|(a, b)| a * b).sum();
        let psi: f64 = x0.iter().zip(&c).map(|(a, b)| a * b).sum();
        let psip: f64 = x1.iter().zip(&c).map(|(a, b)| a * b).sum();
        u += w * 0.5 * (ei * psip * psip + kga * (vp - psi) * (vp - psi));
    }
    u
}

#[test]
fn elem_timoshenko_strain_energy_from_fields_and_spd_matrices() {
    // Full model (rotary inertia on: ψ coordinates) and condensed model (massless ψ), both
    // bases. The assembled strain energy must equal the field integral, K and M must be SPD.
    let cases = [
        (
            "cantilever-timoshenko",
            Basis::Poly,
            SectionKind::Timoshenko,
        ),
        (
            "cantilever-timoshenko",
            Basis::ClampedFree,
            SectionKind::Timoshenko,
        ),
        (
            "barhorst-case1-timoshenko",
            Basis::Poly,
            SectionKind::TimoshenkoCondensed,
        ),
        (
            "barhorst-case1-timoshenko",
            Basis::ClampedFree,
            SectionKind::TimoshenkoCondensed,
        ),
    ];
    for (name, basis, kind) in cases {
        let scene = load_scene(name).unwrap();
        let mut chain = build_chain(
            scene.planar_chain().unwrap(),
            &disc(5, basis).modal().unwrap(),
        )
        .unwrap();
        let q = random_state(&chain, 1e-3 * scene.links()[0].length, 7);
        let qd = random_state(&chain, 1e-1, 11);
        chain.evaluate(0.0, &q, &qd);
        let e = chain.energy(&q);
        let mut u_fields = 0.0;
        for (i, l) in chain.links.iter().enumerate() {
            assert_eq!(l.section.kind, kind, "{name}");
            let nbc = l.nbc();
            assert!(is_spd(&l.section.kbc, nbc), "{name}: K not SPD");
            for r in 0..nbc {
                for c in 0..r {
                    let (a, b) = (l.section.kbc[r * nbc + c], l.section.kbc[c * nbc + r]);
                    assert!(
                        (a - b).abs() <= 1e-14 * a.abs().max(b.abs()),
                        "{name}: K asym"
                    );
                }
            }
            u_fields += field_strain_energy(&scene, &chain, i, &q);
        }
        let rel = (e.strain - u_fields).abs() / u_fields;
        println!(
            "{name} {basis:?}: U = {:.12e}, fields {u_fields:.12e}, rel {rel:.2e}",
            e.strain
        );
        assert!(rel < 1e-10, "{name} {basis:?}: strain energy {rel:.2e}");
        // Free-coordinate mass matrix SPD; kinetic energy ½q̇ᵀMq̇ > 0.
        let m = chain.mass_matrix();
        let free = chain.free.clone();
        let nf = free.len();
        let mff: Vec<f64> = (0..nf * nf)
            .map(|k| m[free[k / nf] * chain.n + free[k % nf]])
            .collect();
        assert!(is_spd(&mff, nf), "{name} {basis:?}: M not SPD");
        assert!(e.kinetic > 0.0);
    }
}

#[test]
fn elem_timoshenko_force_is_minus_energy_gradient() {
    // At q̇ = 0 every velocity term vanishes, so the force side must be −∂(U + V_spring +
    // V_gravity)/∂q: checks the shear/bending stiffness, the condensation, the foreshortening
    // kinematics and the joint chaining through ψ₁(L) (link 2's gravity potential depends on it).
    for basis in [Basis::Poly, Basis::ClampedFree] {
        let scene = load_scene("barhorst-case1-timoshenko").unwrap();
        let mut chain = build_chain(
            scene.planar_chain().unwrap(),
            &disc(4, basis).modal().unwrap(),
        )
        .unwrap();
        let mut q = random_state(&chain, 2e-2, 3);
        let qd = vec![0.0; chain.n];
        let potential = |chain: &mut Chain, q: &[f64]| {
            chain.evaluate(0.0, q, &qd);
            let e = chain.energy(q);
            e.strain + e.joint_spring + e.gravity
        };
        let (worst, fmax) = force_against_potential_gradient(&mut chain, &mut q, potential);
        println!("{basis:?}: max |f + ∇V| / max|f| = {worst:.2e} (max|f| = {fmax:.3e})");
        assert!(worst < 1e-7, "{basis:?}: {worst:.2e}");
    }
}

#[test]
fn conv_timoshenko_cantilever_frequencies_fall_to_analytic() {
    // Rayleigh–Ritz: from above, error falling with the number of modes per field, to the
    // analytic Timoshenko frequencies (shear + rotary inertia).
    let scene = load_scene("cantilever-timoshenko").unwrap();
    for basis in [Basis::Poly, Basis::ClampedFree] {
        let mut prev = [f64::INFINITY; 4];
        for n in [3, 4, 6, 8, 10, 12] {
            let f = freqs(&scene, n, basis, 4);
            let mut errs = [0.0; 4];
            for k in 0..4 {
                errs[k] = (f[k] - TIMOSHENKO_HZ[k]) / TIMOSHENKO_HZ[k];
                // From above (up to the eigen-solver round-off).
                assert!(
                    errs[k] > -1e-9,
                    "{basis:?} n={n} mode {}: {:.3e}",
                    k + 1,
                    errs[k]
                );
                assert!(
                    errs[k] <= prev[k] + 1e-9,
                    "{basis:?} n={n} mode {}: {:.3e} after {:.3e}",
                    k + 1,
                    errs[k],
                    prev[k]
                );
            }
            println!("{basis:?} n={n:2}: rel errors {errs:?}");
            prev = errs;
        }
        // Polynomials converge exponentially (measured at n = 12: ≤ 5e-8 on modes 1–4); the
        // eigenfunction pair algebraically (measured ≤ 2.5e-4).
        let tol = if basis == Basis::Poly { 1e-6 } else { 1e-3 };
        assert!(prev.iter().all(|e| *e < tol), "{basis:?}: {prev:?}");
    }
}

fn scaled_shear(scene: &Scene, factor: f64) -> Scene {
    let mut s = scene.clone();
    for l in &mut s.planar_chain_mut().unwrap().links {
        *l.shear_stiffness.as_mut().unwrap() *= factor;
    }
    s
}

fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) / y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn prop_timoshenko_stiff_shear_limit_is_the_euler_model() {
    // (a) Clamped stocky beam with rotary inertia: Timoshenko on n polynomial functions per
    //     field → the Euler (Rayleigh, ρI on v') model on span{ξ², …, ξⁿ}, i.e. `poly` n − 1.
    // (b) barhorst-case1-timoshenko (free joints, massless ψ condensed): → barhorst-case1's
    //     Euler model with the same n. The gap must shrink like 1/κGA: no locking.
    let timo = load_scene("cantilever-timoshenko").unwrap();
    let mut rayleigh = timo.clone();
    rayleigh.planar_chain_mut().unwrap().links[0].shear = false;
    let n = 6;
    let euler = freqs(&rayleigh, n - 1, Basis::Poly, 3);
    let mut gaps = Vec::new();
    for factor in [1e2, 1e3, 1e4] {
        let f = freqs(&scaled_shear(&timo, factor), n, Basis::Poly, 3);
        gaps.push(max_rel_diff(&f, &euler));
    }
    println!("clamped: gaps {gaps:?}");
    assert!(gaps.windows(2).all(|p| p[1] < 0.2 * p[0]), "{gaps:?}");
    assert!(gaps[2] < 1e-4, "{gaps:?}");

    let timo = load_scene("barhorst-case1-timoshenko").unwrap();
    let plain = load_scene("barhorst-case1").unwrap();
    for basis in [Basis::Poly, Basis::ClampedFree] {
        let euler = freqs(&plain, 4, basis, 6);
        let mut gaps = Vec::new();
        for factor in [1.0, 1e2, 1e4] {
            let f = freqs(&scaled_shear(&timo, factor), 4, basis, 6);
            gaps.push(max_rel_diff(&f[1..], &euler[1..]));
        }
        println!("free chain {basis:?}: gaps {gaps:?}");
        assert!(gaps.windows(2).all(|p| p[1] < 0.05 * p[0]), "{gaps:?}");
        assert!(gaps[2] < 1e-5, "{basis:?}: {gaps:?}");
    }
}

#[test]
fn sys_timoshenko_tip_inertia_without_rotary_inertia_is_refused() {
    let mut scene = load_scene("barhorst-case1-timoshenko").unwrap();
    scene.planar_chain_mut().unwrap().links[1].tip_inertia = Some(0.01);
    let err = ModalBackend
        .simulate(&scene, &run_settings(3, None, 1e-6, Some(0.01)))
        .unwrap_err();
    assert!(
        matches!(&err, BackendError::Unsupported(m) if m.contains("tip inertia")),
        "{err:?}"
    );
}

/// (t, kind) of impacts ("I") and releases ("R").
/// A modal run of `scene` at `st` that must complete.
fn completed_run(scene: &Scene, st: &Settings) -> RunResult {
    let (r, _) =
        simulate_detailed(scene, scene.planar_chain().unwrap(), &st.modal().unwrap()).unwrap();
    assert_eq!(r.verdict, StabilityVerdict::Completed, "{}", scene.name);
    r
}

fn switching(r: &RunResult) -> Vec<(f64, &'static str)> {
    r.events
        .iter()
        .filter_map(|e| match e {
            Event::Impact { t, .. } => Some((*t, "I")),
            Event::Release { t, .. } => Some((*t, "R")),
            _ => None,
        })
        .collect()
}

#[test]
fn dyn_timoshenko_barhorst_impacts_and_ledger() {
    let scene = load_scene("barhorst-case1-timoshenko").unwrap();
    let r = completed_run(&scene, &run_settings(3, None, 1e-8, Some(0.3)));
    let mut n_impacts = 0;
    for e in &r.events {
        if let Event::Impact {
            t,
            momentum_residual,
            kinetic_energy_lost,
            normal_velocity_after,
            ..
        } = e
        {
            n_impacts += 1;
            println!(
                "impact t={t:.9} res={momentum_residual:.2e} dKE={kinetic_energy_lost:.3e} vn+={normal_velocity_after:.1e}"
            );
            assert!(*momentum_residual <= 1e-10, "{momentum_residual:e}");
            assert!(*kinetic_energy_lost >= 0.0, "{kinetic_energy_lost:e}");
            assert!(
                normal_velocity_after.abs() <= 1e-10,
                "{normal_velocity_after:e}"
            );
        }
    }
    println!(
        "switching {:?}; closure {:.3e}; steps {} wall {:.2}s",
        switching(&r),
        r.ledger.relative_closure(),
        r.cost.steps,
        r.cost.wall_time_s
    );
    assert!(n_impacts >= 1, "no impact in 0.3 s");
    let closure = r.ledger.relative_closure();
    assert!(closure <= 1e-5, "ledger closure {closure:.3e}");
}

/// constrained-arm with a Timoshenko link of slenderness λ = L/r (EI and EA kept, κGA =
/// (κG/E)·EI/r² with the steel-like κG/E = (5/6)/2.6): section radius of gyration r = L/λ.
fn timoshenko_arm(lambda: f64) -> Scene {
    let mut s = load_scene("constrained-arm").unwrap();
    let l = &mut s.planar_chain_mut().unwrap().links[0];
    let r = l.length / lambda;
    l.shear = true;
    l.shear_stiffness = Some((5.0 / 6.0) / 2.6 * l.bending_stiffness / (r * r));
    s
}

fn channel<'a>(r: &'a RunResult, name: &str) -> &'a [f64] {
    &r.observables.get(name).unwrap().values
}

#[test]
fn dyn_timoshenko_arm_approaches_euler_as_slenderness_grows() {
    let st = {
        let mut s = run_settings(3, Some(Basis::Poly), 1e-8, Some(0.5));
        s.time.atol = Some(1e-10);
        s
    };
    let euler = load_scene("constrained-arm").unwrap();
    let re = completed_run(&euler, &st);
    let th_e = channel(&re, "joint1.angle").to_vec();
    let mut diffs = Vec::new();
    // Measured (3 poly modes, 0.5 s): λ = 5, 10, 20, 40 → 2.8e-2, 1.8e-2, 9.2e-3, 4.6e-3 rad
    // (stick–slip phases shift at small λ); at λ ≥ 40 the gap falls ~ 1/λ² (shear compliance).
    for lambda in [10.0, 40.0, 160.0] {
        let arm = timoshenko_arm(lambda);
        let r = completed_run(&arm, &st);
        assert!(r.ledger.relative_closure() < 1e-6);
        let th = channel(&r, "joint1.angle");
        assert_eq!(th.len(), th_e.len());
        let d = th
            .iter()
            .zip(&th_e)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "λ = {lambda}: max |θ_T − θ_E| = {d:.3e} rad (θ_E(end) = {:.4}), closure {:.2e}, wall {:.2}s",
            th_e.last().unwrap(),
            r.ledger.relative_closure(),
            r.cost.wall_time_s
        );
        diffs.push(d);
    }
    assert!(
        diffs.windows(2).all(|p| p[1] < p[0]),
        "Timoshenko − Euler must fall with slenderness: {diffs:?}"
    );
}

#[test]
fn dyn_timoshenko_rotary_inertia_chain_impact_and_ledger() {
    // With section rotary inertia (ρI chosen: 1e-2 slug·ft) ψ is a set of true coordinates
    // (no condensation) carrying the Kelvin–Voigt damping on ψ̇' and the joint chaining
    // through ψ₁(L): the ledger must close through free flight and the first impact.
    let mut scene = load_scene("barhorst-case1-timoshenko").unwrap();
    for l in &mut scene.planar_chain_mut().unwrap().links {
        l.rotary_inertia = true;
        l.rotary_inertia_per_length = Some(1e-2);
    }
    let plan = ModalBackend
        .dof_plan(&scene, &disc(3, Basis::ClampedFree))
        .unwrap();
    assert_eq!(plan.total(), 2 + 2 * (3 + 3));
    let r = completed_run(&scene, &run_settings(3, None, 1e-8, Some(0.3)));
    let sw = switching(&r);
    println!(
        "switching {sw:?}; closure {:.3e}; steps {} wall {:.2}s",
        r.ledger.relative_closure(),
        r.cost.steps,
        r.cost.wall_time_s
    );
    assert!(sw.first().is_some_and(|(_, k)| *k == "I"), "{sw:?}");
    for e in &r.events {
        if let Event::Impact {
            momentum_residual,
            kinetic_energy_lost,
            ..
        } = e
        {
            assert!(*momentum_residual <= 1e-10 && *kinetic_energy_lost >= 0.0);
        }
    }
    assert!(r.ledger.relative_closure() <= 1e-5);
}

#[test]
fn sys_timoshenko_tip_load_statics_is_exact() {
    // Tip load P on the clamped Timoshenko beam: ψ = (P/EI)(Lx − x²/2),
    // v = (P/EI)(Lx²/2 − x³/6) + P x/κGA, so v(L) = PL³/3EI + PL/κGA and ψ(L) = PL²/2EI.
    // The root-shear polynomial pair (n ≥ 3) contains both fields: exact to round-off. The
    // eigenfunction pair approximates them (measured at n = 8: 5.6e-5 on v(L), 8.0e-4 on ψ(L)).
    let scene = load_scene("cantilever-timoshenko").unwrap();
    let l = &scene.links()[0];
    let p = scene.statics().unwrap().tip_force.unwrap();
    let (len, ei, kga) = (l.length, l.bending_stiffness, l.shear_stiffness.unwrap());
    let v_exact = p * len.powi(3) / (3.0 * ei) + p * len / kga;
    let psi_exact = p * len * len / (2.0 * ei);
    for (basis, n, tol) in [
        (Basis::Poly, 3, 1e-12),
        (Basis::Poly, 8, 1e-11),
        (Basis::ClampedFree, 8, 2e-3),
    ] {
        let s = Settings {
            discretization: disc(n, basis),
            ..Default::default()
        };
        let r = ModalBackend.statics(&scene, &s).unwrap();
        let ev = (r.tip_deflection - v_exact) / v_exact;
        let ep = (r.tip_rotation - psi_exact) / psi_exact;
        println!("{basis:?} n={n}: v(L) error {ev:.2e}, ψ(L) error {ep:.2e}");
        assert!(
            ev.abs() < tol && ep.abs() < tol,
            "{basis:?} n={n}: {ev:e} {ep:e}"
        );
    }
}

/// barhorst-case1-timoshenko as an elastic chain for modes: no gravity, no contact, no
/// Kelvin–Voigt, hub spring K₁ = 120, elbow spring K₂ = 2000 (the issue-15 copy).
fn timoshenko_elbow_scene() -> Scene {
    let mut s = load_scene("barhorst-case1-timoshenko").unwrap();
    let pc = s.planar_chain_mut().unwrap();
    pc.gravity = None;
    pc.contacts.clear();
    for l in &mut pc.links {
        l.kelvin_voigt = None;
    }
    pc.links[0].joint.stiffness = Some(120.0);
    pc.links[1].joint.stiffness = Some(2000.0);
    s
}

#[test]
fn elem_timoshenko_elbow_condensation_minimizes_over_c() {
    // Link 1 is condensed with joint 2's elbow: at any (b, φ) the condensed c must minimize
    // U = ½bᵀK_bb b + bᵀK_bc c + ½cᵀK_cc c + ½K(φ − χᵀc − θ₀)² (solved here densely with faer),
    // the condensed form ½xᵀHx must equal that minimum, and its φ-gradient the joint torque
    // K(θ − θ₀), θ = φ − χᵀc, that the chain applies and reports.
    use faer::linalg::solvers::Solve;
    for basis in [Basis::Poly, Basis::ClampedFree] {
        let scene = timoshenko_elbow_scene();
        let mut chain = build_chain(
            scene.planar_chain().unwrap(),
            &disc(6, basis).modal().unwrap(),
        )
        .unwrap();
        assert!(chain.elbows[0].is_none() && chain.elbows[1].is_some());
        let q = random_state(&chain, 2e-2, 5);
        let qd = vec![0.0; chain.n];
        chain.evaluate(0.0, &q, &qd);
        let l1 = &chain.links[0];
        let e = chain.elbows[1].as_ref().unwrap();
        let (nb, nc) = (e.nb, e.nc);
        let k = &e.blocks;
        let (kj, th0) = (e.stiffness, e.set_point);
        let b = &q[l1.b0..l1.b0 + nb];
        let phi = q[chain.links[1].theta];
        let a = faer::Mat::<f64>::from_fn(nc, nc, |r, c| {
            k.kcc[r * nc + c] + kj * k.chi_l[r] * k.chi_l[c]
        });
        let rhs = faer::Mat::<f64>::from_fn(nc, 1, |r, _| {
            -(0..nb).map(|j| k.kbc[j * nc + r] * b[j]).sum::<f64>() + kj * k.chi_l[r] * (phi - th0)
        });
        let c = a.partial_piv_lu().solve(&rhs);
        let u = |c: &dyn Fn(usize) -> f64| {
            let mut u = 0.0;
            for r in 0..nb {
                for s in 0..nb {
                    u += 0.5 * b[r] * k.kbb[r * nb + s] * b[s];
                }
                for s in 0..nc {
                    u += b[r] * k.kbc[r * nc + s] * c(s);
                }
            }
            for r in 0..nc {
                for s in 0..nc {
                    u += 0.5 * c(r) * k.kcc[r * nc + s] * c(s);
                }
            }
            let th = phi - (0..nc).map(|r| k.chi_l[r] * c(r)).sum::<f64>();
            u + 0.5 * kj * (th - th0).powi(2)
        };
        let u_min = u(&|r| c[(r, 0)]);
        let c_err = (0..nc).fold(0.0f64, |m, r| m.max((e.c[r] - c[(r, 0)]).abs()))
            / (0..nc).fold(0.0f64, |m, r| m.max(c[(r, 0)].abs()));
        // ½xᵀHx over x = (b, φ − θ₀).
        let nx = nb + 1;
        let x: Vec<f64> = (0..nx)
            .map(|r| if r < nb { b[r] } else { phi - th0 })
            .collect();
        let hx: Vec<f64> = (0..nx)
            .map(|r| (0..nx).map(|s| e.h[r * nx + s] * x[s]).sum())
            .collect();
        let u_h = 0.5 * x.iter().zip(&hx).map(|(a, b)| a * b).sum::<f64>();
        let theta = phi - (0..nc).map(|r| k.chi_l[r] * c[(r, 0)]).sum::<f64>();
        let torque = kj * (theta - th0);
        println!(
            "{basis:?}: c rel {c_err:.2e}, U {u_min:.12e} vs ½xᵀHx {u_h:.12e}, ∂U/∂φ {:.12e} vs K(θ−θ₀) {torque:.12e}",
            hx[nb]
        );
        assert!(c_err < 1e-10, "{basis:?}: c {c_err:.2e}");
        assert!((u_h - u_min).abs() < 1e-10 * u_min, "{basis:?}: U");
        assert!(
            (hx[nb] - torque).abs() < 1e-9 * torque.abs(),
            "{basis:?}: ∂U/∂φ"
        );
        // The minimum is a minimum: any perturbation of c raises U.
        for r in 0..nc {
            let dc = 1e-6 * (1.0 + c[(r, 0)].abs());
            assert!(u(&|s| c[(s, 0)] + if s == r { dc } else { 0.0 }) > u_min);
        }
        // The chain reports θ = φ − χᵀc and applies the torque −K(θ − θ₀) on φ (q̇ = 0, no
        // gravity: the force on φ is the elastic one only).
        let th_chain = chain.joint_angle(1, &q);
        assert!((th_chain - theta).abs() < 1e-12, "{basis:?}: θ");
        let f_phi = chain.force()[chain.links[1].theta];
        assert!(
            (f_phi + torque).abs() < 1e-9 * torque.abs(),
            "{basis:?}: joint force {f_phi} vs {}",
            -torque
        );
    }
}

#[test]
fn sys_timoshenko_elbow_modes_converge_from_above() {
    // With the elbow in the condensation (exact without dampers) the modal model is a
    // Rayleigh–Ritz model on nested polynomial spaces: every frequency falls monotonically
    // with the number of modes and the steps shrink. (Without the elbow, mode 2 rose with n:
    // 3.9797 / 3.9834 / 3.9846 Hz at 6 / 8 / 12, away from fem's 3.9593 Hz.)
    let scene = timoshenko_elbow_scene();
    let ns = [4, 6, 8, 10, 12];
    let f: Vec<Vec<f64>> = ns
        .iter()
        .map(|&n| freqs(&scene, n, Basis::Poly, 4))
        .collect();
    for (k, n) in ns.iter().enumerate() {
        println!("n = {n}: {:?}", f[k]);
    }
    for m in 0..4 {
        let col: Vec<f64> = f.iter().map(|fr| fr[m]).collect();
        for k in 1..ns.len() {
            assert!(
                col[k] <= col[k - 1] * (1.0 + 1e-12),
                "mode {}: n = {} {} > n = {} {}",
                m + 1,
                ns[k],
                col[k],
                ns[k - 1],
                col[k - 1]
            );
        }
        for k in 2..ns.len() {
            assert!(
                col[k - 1] - col[k] < col[k - 2] - col[k - 1],
                "mode {}: steps do not shrink at n = {}",
                m + 1,
                ns[k]
            );
        }
    }
    // Mode 2 (the elbow mode) settles: 10 → 12 moves it by less than 1e-5 relative.
    let d = (f[3][1] - f[4][1]) / f[4][1];
    assert!(d < 1e-5, "mode 2 step 10 → 12: {d:.2e}");
}

#[test]
fn elem_timoshenko_elbow_force_with_applied_torque_is_minus_potential_gradient() {
    // An applied elbow torque τ also turns link 1's massless tip section (c = T b + t s + g τ):
    // at q̇ = 0 and without gravity the force side must be −∂V/∂q with
    // V = U + ½K(θ − θ₀)² − τθ, θ = φ − χᵀc, over every coordinate (central differences).
    let mut scene = timoshenko_elbow_scene();
    scene.planar_chain_mut().unwrap().links[1].joint.torque =
        Some(data::scene::TorqueLaw::Constant {
            value: 150.0,
            until: None,
        });
    let mut chain = build_chain(
        scene.planar_chain().unwrap(),
        &disc(5, Basis::Poly).modal().unwrap(),
    )
    .unwrap();
    let mut q = random_state(&chain, 2e-2, 9);
    let qd = vec![0.0; chain.n];
    let potential = |chain: &mut Chain, q: &[f64]| {
        chain.evaluate(0.0, q, &qd);
        let e = chain.energy(q);
        e.strain + e.joint_spring - 150.0 * chain.joint_angle(1, q)
    };
    let (worst, fmax) = force_against_potential_gradient(&mut chain, &mut q, potential);
    println!("max |f + ∇V| / max|f| = {worst:.2e} (max|f| = {fmax:.3e})");
    assert!(worst < 1e-7, "{worst:.2e}");
    // The torque moves c: the same state without it reports another joint angle.
    chain.evaluate(0.0, &q, &qd);
    let th_tau = chain.joint_angle(1, &q);
    chain.joints[1].torque = None;
    chain.evaluate(0.0, &q, &qd);
    assert!((chain.joint_angle(1, &q) - th_tau).abs() > 1e-6);
}

#[test]
fn dyn_timoshenko_elbow_torque_steps_close_the_ledger() {
    // A bang-bang elbow torque on barhorst-case1-timoshenko in free flight: at each jump the
    // massless tip section turns at once (θ jumps by χᵀA⁻¹χ Δτ); the ledger books the torque's
    // work on that jump and the section relaxation's loss. Without that booking the closure is
    // 4.5e-5 here; with it, the integrator's own error (measured 5.4e-13).
    let mut scene = load_scene("barhorst-case1-timoshenko").unwrap();
    let pc = scene.planar_chain_mut().unwrap();
    pc.contacts.clear();
    pc.links[1].joint.torque = Some(data::scene::TorqueLaw::BangBang {
        amplitude: 30.0,
        switch: 0.05,
        off: 0.1,
    });
    let r = completed_run(&scene, &run_settings(4, None, 1e-8, Some(0.15)));
    let closure = r.ledger.relative_closure();
    println!("closure {closure:.3e}");
    assert!(closure <= 1e-6, "ledger closure {closure:.3e}");
}

#[test]
fn sys_timoshenko_elbow_angle_carries_the_dampers_boundary_layer_lag() {
    // The elbow damper's moment m = D·θ̇ turns link 1's massless tip section through the
    // boundary layer ψ ∝ sinh(x/ℓ), ℓ = √(EI/κGA): with b held the section yields by m·s,
    // s = s₀/(1 + K s₀), s₀ = ℓ·tanh(L/ℓ)/EI (root section clamped to the frame, the elbow
    // spring K in parallel). The reported angle lies on the first-order manifold c₀ + c₁, so
    // for the frames turning apart at φ̇ = ω (b = ḃ = 0, no Kelvin–Voigt) it lags the
    // quasi-static angle by −s·D·θ̇. The Ritz compliance of the polynomial χ converges to s
    // from below (a Ritz solution is stiffer) and falls monotonically with n.
    let mut scene = timoshenko_elbow_scene();
    let kga = 1.0e4; // ℓ ≈ 0.71 ft, L/ℓ ≈ 4.2: a layer the polynomials resolve
    for l in &mut scene.planar_chain_mut().unwrap().links {
        l.shear_stiffness = Some(kga);
    }
    let pc = scene.planar_chain().unwrap();
    let (ei, length) = (pc.links[0].bending_stiffness, pc.links[0].length);
    let (k, d) = (
        pc.links[1].joint.stiffness.unwrap(),
        pc.links[1].joint.damping.unwrap(),
    );
    let ell = (ei / kga).sqrt();
    let s0 = ell * (length / ell).tanh() / ei;
    let exact = s0 / (1.0 + k * s0);
    let omega = 0.7;
    let mut errors = Vec::new();
    for modes in [4, 6, 8] {
        let chain = build_chain(pc, &disc(modes, Basis::Poly).modal().unwrap()).unwrap();
        let e = chain.elbows[1].as_ref().unwrap();
        let bd = vec![0.0; e.nb];
        let lag = e.angle_lag(&bd, omega);
        let s = -lag / (d * e.rate(&bd, omega));
        println!("{modes} modes: compliance {s:.12e} against {exact:.12e}");
        errors.push(1.0 - s / exact);
    }
    assert!(errors.iter().all(|&e| e > -1e-12), "{errors:?}");
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
    assert!(errors[2] < 1e-6, "{errors:?}");
}
