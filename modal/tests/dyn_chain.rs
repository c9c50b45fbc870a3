//! Equations of motion against the energy (finite differences), time integration, ledger.

use data::{
    Backend, Basis, Discretization, RunResult, Settings, StabilityVerdict, TimeStepping, channel,
    load_scene,
};
use modal::ModalBackend;
use modal::linalg::dot;
use modal::model::Chain;
use modal::setup::build_chain;

fn energies(chain: &mut Chain, q: &[f64], qd: &[f64]) -> (f64, f64) {
    chain.evaluate(0.3, q, qd);
    let e = chain.energy(q);
    (e.kinetic, e.strain + e.joint_spring + e.gravity)
}

/// Checks M(q) against the polarization of T and f(q, q̇) against
/// −Ṁq̇ + ∂T/∂q − ∂V/∂q (Lagrange's equations of the energy functions, no dissipation).
fn check_lagrange(chain: &mut Chain, q: &[f64], qd: &[f64]) {
    let n = chain.n;
    chain.evaluate(0.3, q, qd);
    let m = chain.mass_matrix().to_vec();
    let f = chain.force().to_vec();
    // M from T(q, ·), exactly quadratic in q̇: relative round-off only.
    let mscale = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut e = vec![0.0; n];
    for i in 0..n {
        for j in 0..n {
            e.iter_mut().for_each(|v| *v = 0.0);
            e[i] += 1.0;
            e[j] += 1.0;
            let tij = energies(chain, q, &e).0;
            e.iter_mut().for_each(|v| *v = 0.0);
            e[i] = 1.0;
            let ti = energies(chain, q, &e).0;
            e.iter_mut().for_each(|v| *v = 0.0);
            e[j] = 1.0;
            let tj = energies(chain, q, &e).0;
            let mij = if i == j { 2.0 * ti } else { tij - ti - tj };
            assert!(
                (mij - m[i * n + j]).abs() < 1e-11 * mscale,
                "M[{i},{j}] = {} vs {mij}",
                m[i * n + j]
            );
        }
    }
    // Force side by central differences (step ε: truncation ε²·f''' ≈ 1e-10, round-off
    // 1e-16·E/ε ≈ 1e-10 relative): 1e-7 of the largest entry.
    let eps = 1e-5;
    let mut expected = vec![0.0; n];
    let mut qp = q.to_vec();
    // −Ṁ q̇ = −d/dε [M(q + ε q̇)] q̇.
    for (k, v) in qp.iter_mut().enumerate() {
        *v = q[k] + eps * qd[k];
    }
    chain.evaluate(0.3, &qp, qd);
    let mp = chain.mass_matrix().to_vec();
    for (k, v) in qp.iter_mut().enumerate() {
        *v = q[k] - eps * qd[k];
    }
    chain.evaluate(0.3, &qp, qd);
    let mm = chain.mass_matrix().to_vec();
    for r in 0..n {
        for c in 0..n {
            expected[r] -= (mp[r * n + c] - mm[r * n + c]) / (2.0 * eps) * qd[c];
        }
    }
    for j in 0..n {
        qp.copy_from_slice(q);
        qp[j] = q[j] + eps;
        let (tp, vp) = energies(chain, &qp, qd);
        qp[j] = q[j] - eps;
        let (tm, vm) = energies(chain, &qp, qd);
        expected[j] += (tp - tm) / (2.0 * eps) - (vp - vm) / (2.0 * eps);
    }
    let scale = expected.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for j in 0..n {
        assert!(
            (f[j] - expected[j]).abs() < 1e-7 * scale,
            "f[{j}] = {} vs {} (scale {scale})",
            f[j],
            expected[j]
        );
    }
}

fn state(n: usize, seed: f64, amp_q: f64, amp_qd: f64) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n)
        .map(|k| amp_q * ((k as f64 + 1.0) * seed).sin())
        .collect();
    let qd = (0..n)
        .map(|k| amp_qd * ((k as f64 + 2.0) * seed * 1.3).cos())
        .collect();
    (q, qd)
}

/// Builds the chain of `scene` with `disc` and checks its equations of motion against the
/// energy at the state [`state`]`(n, seed, amp_q, amp_qd)`.
fn check_lagrange_scene(
    scene: &data::Scene,
    disc: &Discretization,
    seed: f64,
    amp_q: f64,
    amp_qd: f64,
) {
    let mut chain = build_chain(scene.planar_chain().unwrap(), &disc.modal().unwrap()).unwrap();
    let (q, qd) = state(chain.n, seed, amp_q, amp_qd);
    check_lagrange(&mut chain, &q, &qd);
}

/// A discretization with `modes` clamped-free modes per link (the basis these tests were
/// measured with; multi-link scenes default to `poly`).
fn with_modes(modes: usize) -> Discretization {
    Discretization {
        modes: Some(modes),
        basis: Some(Basis::ClampedFree),
        ..Default::default()
    }
}

#[test]
fn dyn_equations_of_motion_match_the_energy_two_link_with_everything() {
    let mut scene = load_scene("two-link-free-undamped").unwrap();
    scene.planar_chain_mut().unwrap().gravity = Some(data::scene::Gravity {
        vector: [0.3, -32.17],
    });
    scene.planar_chain_mut().unwrap().links[0].joint.hub_inertia = Some(0.2);
    scene.planar_chain_mut().unwrap().links[0].tip_mass = Some(0.3);
    scene.planar_chain_mut().unwrap().links[1].tip_mass = Some(0.2);
    scene.planar_chain_mut().unwrap().links[1].tip_inertia = Some(0.01);
    for basis in [Basis::ClampedFree, Basis::Poly] {
        let disc = Discretization {
            modes: Some(3),
            basis: Some(basis),
            ..Default::default()
        };
        check_lagrange_scene(&scene, &disc, 0.7, 0.05, 2.0);
    }
    // Linear model (no foreshortening) too.
    for l in &mut scene.planar_chain_mut().unwrap().links {
        l.foreshortening = false;
    }
    check_lagrange_scene(&scene, &with_modes(3), 1.1, 0.05, 2.0);
}

#[test]
fn dyn_equations_of_motion_match_the_energy_extensible_links() {
    // Axial fields with von Kármán strain: the stretch beside the foreshortening, exact
    // kinetic energy of p = (x + u − s, v) (crate::model::body).
    let mut scene = load_scene("two-link-free-undamped").unwrap();
    scene.planar_chain_mut().unwrap().gravity = Some(data::scene::Gravity {
        vector: [0.0, -32.17],
    });
    scene.planar_chain_mut().unwrap().links[1].tip_mass = Some(0.2);
    for l in &mut scene.planar_chain_mut().unwrap().links {
        l.foreshortening = false;
        l.axial = true;
        l.axial_stiffness = Some(1e5);
    }
    check_lagrange_scene(&scene, &with_modes(3), 0.9, 0.05, 2.0);
    // Timoshenko links with the axial field (the foreshortening follows the centre line v'),
    // with and without rotary inertia (massless section rotations condensed).
    for rotary in [true, false] {
        for l in &mut scene.planar_chain_mut().unwrap().links {
            l.shear = true;
            l.shear_stiffness = Some(2e5);
            l.rotary_inertia = rotary;
            l.rotary_inertia_per_length = Some(1e-4);
        }
        check_lagrange_scene(&scene, &with_modes(3), 0.7, 0.05, 2.0);
    }
}

#[test]
fn sys_extensible_link_kinetic_energy_is_the_continuum_integral() {
    // The extensible link is modelled by a stretch field beside the foreshortening; its
    // kinetic energy must be ½∫ρA|ωJp + ṗ|² of p = (x + ψᵀa − ½bᵀS(x)b, φᵀb),
    // S(x) = ∫₀ˣφ'φ'ᵀ, evaluated here by nested Gauss quadrature of the shapes alone
    // (free hub joint at the origin: V = 0, ω = θ̇).
    let mut scene = load_scene("spin-up-axial").unwrap();
    scene.planar_chain_mut().unwrap().links[0].joint.prescribed = None;
    let mut chain = build_chain(
        scene.planar_chain().unwrap(),
        &with_modes(3).modal().unwrap(),
    )
    .unwrap();
    let n = chain.n;
    let link = chain.links[0].clone();
    let (na, nb) = (link.na(), link.nb());
    assert_eq!((na, nb), (3, 3));
    // Amplitudes where every coupling is visible: ~1 m deflection of a 10 m link, a stretch
    // far beyond the physical one so that the stretch–foreshortening terms are not round-off.
    let (mut q, mut qd) = state(n, 0.83, 0.3, 2.0);
    q[link.theta] = 0.4;
    qd[link.theta] = 1.7;
    for k in 0..na {
        q[link.a0 + k] *= 0.3;
        qd[link.a0 + k] *= 0.3;
    }
    chain.evaluate(0.0, &q, &qd);
    let t_model = chain.energy(&q).kinetic;

    let (a, ad) = (&q[link.a0..link.a0 + na], &qd[link.a0..link.a0 + na]);
    let (b, bd) = (&q[link.b0..link.b0 + nb], &qd[link.b0..link.b0 + nb]);
    let om = qd[link.theta];
    let len = scene.links()[0].length;
    let rho_a = scene.links()[0].mass_per_length;
    let axial = link.axial.as_ref().unwrap();
    let (gx, gw) = modal::basis::quadrature::gauss_legendre(12);
    let panels = 40;
    let h = len / panels as f64;
    let (mut psi, mut phi, mut dphi) = (vec![0.0; na], vec![0.0; nb], vec![0.0; nb]);
    // s(x) = ½ bᵀS(x)b and ṡ = bᵀS(x)ḃ: ∫₀ˣ of ½(φ'ᵀb)² and (φ'ᵀb)(φ'ᵀḃ).
    let mut s_of = |x: f64| {
        let (mut s, mut sd) = (0.0, 0.0);
        let sub = 8;
        let hs = x / sub as f64;
        for p in 0..sub {
            for (xi, wi) in gx.iter().zip(&gw) {
                let xx = (p as f64 + 0.5 * (xi + 1.0)) * hs;
                link.transverse.eval(xx, 1, &mut dphi);
                let (vb, vbd) = (dot(&dphi, b), dot(&dphi, bd));
                s += 0.5 * hs * wi * 0.5 * vb * vb;
                sd += 0.5 * hs * wi * vb * vbd;
            }
        }
        (s, sd)
    };
    let mut t_quad = 0.0;
    for p in 0..panels {
        for (xi, wi) in gx.iter().zip(&gw) {
            let x = (p as f64 + 0.5 * (xi + 1.0)) * h;
            let w = 0.5 * h * wi * rho_a;
            axial.eval(x, 0, &mut psi);
            link.transverse.eval(x, 0, &mut phi);
            let (s, sd) = s_of(x);
            let px = x + dot(&psi, a) - s;
            let py = dot(&phi, b);
            let vx = -om * py + dot(&psi, ad) - sd;
            let vy = om * px + dot(&phi, bd);
            t_quad += 0.5 * w * (vx * vx + vy * vy);
        }
    }
    let rel = (t_model - t_quad).abs() / t_quad;
    println!("T model {t_model:.12e}, quadrature {t_quad:.12e}, relative {rel:.2e}");
    assert!(rel < 1e-10, "relative difference {rel:.3e}");
}

#[test]
fn dyn_equations_of_motion_match_the_energy_spin_up() {
    let scene = load_scene("spin-up").unwrap();
    check_lagrange_scene(&scene, &with_modes(4), 0.4, 0.2, 3.0);
}

fn run(name: &str, modes: usize, rtol: f64, method: Option<&str>) -> RunResult {
    run_to(name, modes, rtol, method, None)
}

fn run_to(
    name: &str,
    modes: usize,
    rtol: f64,
    method: Option<&str>,
    t_end: Option<f64>,
) -> RunResult {
    let scene = load_scene(name).unwrap();
    let settings = Settings {
        // The clamped-free basis these tests were measured with (multi-link scenes default to
        // `poly`, see modal::setup::default_basis).
        discretization: Discretization {
            modes: Some(modes),
            basis: Some(Basis::ClampedFree),
            ..Default::default()
        },
        time: TimeStepping {
            rtol: Some(rtol),
            atol: Some(rtol * 1e-3),
            method: method.map(|m| m.parse().expect("a method name")),
            t_end,
            ..Default::default()
        },
    };
    ModalBackend.simulate(&scene, &settings).unwrap()
}

#[test]
fn dyn_ledger_closes_single_link() {
    let r = run("single-link", 6, 1e-11, None);
    assert_eq!(r.verdict, StabilityVerdict::Completed);
    let c = r.ledger.relative_closure();
    println!("single-link closure {c:.3e}");
    // Tight tolerances: closure limited by the integrator (rtol 1e-11) — well below 1e-6.
    assert!(c < 1e-6, "closure {c}");
    let w = &r.ledger.inputs[0];
    assert_eq!(w.name, "applied_torque");
    assert!(w.values.last().unwrap().abs() > 0.1);
}

#[test]
fn dyn_ledger_closes_two_link_free_damped_and_undamped() {
    // 4 modes per link (the 6-mode run takes ~10 s: its highest mode, "turn the inertia-free
    // hub frame and counter-bend the link", is near 1e4 rad/s).
    let r = run("two-link-free", 4, 1e-9, None);
    assert_eq!(r.verdict, StabilityVerdict::Completed);
    let c = r.ledger.relative_closure();
    println!("two-link-free closure {c:.3e}");
    assert!(c < 1e-6, "damped closure {c}");
    let names: Vec<&str> = r
        .ledger
        .dissipation
        .iter()
        .map(|t| t.name.as_str())
        .collect();
    assert_eq!(names, ["joint_damper", "kelvin_voigt"]);
    // Energy was actually dissipated (not a vacuous closure).
    let e0 = r.ledger.total(0);
    assert!(r.ledger.total(r.ledger.time.len() - 1) < 0.5 * e0);

    // Undamped, that stiff mode is never damped out: 2 modes, first 3 s (see the ignored test
    // below for the full run).
    let r = run_to("two-link-free-undamped", 2, 1e-10, None, Some(3.0));
    assert_eq!(r.verdict, StabilityVerdict::Completed);
    assert!(r.ledger.inputs.is_empty() && r.ledger.dissipation.is_empty());
    let c = r.ledger.relative_closure();
    // Conservative system: drift of E only from the integrator.
    assert!(c < 1e-6, "undamped closure {c}");
}

#[test]
fn dyn_trbdf2_agrees_with_dopri5() {
    let a = run("single-link", 4, 1e-9, None);
    let b = run("single-link", 4, 1e-7, Some("trbdf2"));
    let ca = a.observables.get(&channel::tip_deflection(1)).unwrap();
    let cb = b.observables.get(&channel::tip_deflection(1)).unwrap();
    let peak = ca.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = ca
        .values
        .iter()
        .zip(&cb.values)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    // A 2nd-order method at rtol 1e-7: global error a few 1e-5 of the peak at most.
    assert!(diff < 1e-3 * peak, "diff {diff}, peak {peak}");
    assert!(b.cost.factorizations > 0 && b.cost.newton_iterations > 0);
}

fn peak_and_history(r: &RunResult) -> (f64, Vec<f64>) {
    let c = r.observables.get(&channel::tip_deflection(1)).unwrap();
    (
        c.values.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        c.values.clone(),
    )
}

#[test]
fn dyn_spin_up_bounded_with_stiffening_and_divergent_without() {
    let stiff = run("spin-up", 4, 1e-8, None);
    assert_eq!(stiff.verdict, StabilityVerdict::Completed);
    let (peak, _) = peak_and_history(&stiff);
    // Bounded: the classic benchmark's tip deflection stays well below 1 m of a 10 m beam.
    assert!(peak > 1e-3 && peak < 1.0, "peak {peak}");
    let c = stiff.ledger.relative_closure();
    assert!(c < 1e-5, "spin-up ledger closure {c}");

    let linear = run("spin-up-linear", 4, 1e-8, None);
    match &linear.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            assert!(diagnostic.t > 5.0 && diagnostic.t < 20.0, "{diagnostic}");
            assert!(diagnostic.remedy.contains("foreshortening"));
        }
        StabilityVerdict::Completed => panic!("spin-up-linear should diverge"),
    }
    assert!(linear.observables.first_non_finite().is_none());
    let (lpeak, _) = peak_and_history(&linear);
    assert!(lpeak > 10.0 * peak);
}

#[test]
fn dyn_spin_up_modal_refinement_study() {
    // 6 vs 10 clamped-free modes at tight tolerance: the 6-mode history is within 1 % of the
    // peak of the refined one (the fem cross-check uses the same 1 % criterion).
    let (p12, h12) = peak_and_history(&run("spin-up", 10, 1e-9, None));
    let (_, h6) = peak_and_history(&run("spin-up", 6, 1e-9, None));
    let d6 = h6
        .iter()
        .zip(&h12)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d6 < 1e-2 * p12, "6 modes: {d6} vs peak {p12}");
    // The 20-ms target configuration (4 modes, rtol 1e-6): within a few 1e-4 of the peak of
    // the 4-mode tight-tolerance solution (time-integration error) and 1 % of the refined one.
    let (_, h4t) = peak_and_history(&run("spin-up", 4, 1e-10, None));
    let fast = run("spin-up", 4, 1e-6, None);
    let (_, h4) = peak_and_history(&fast);
    let dt = h4
        .iter()
        .zip(&h4t)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(dt < 5e-4 * p12, "time error {dt} vs peak {p12}");
    let d4 = h4
        .iter()
        .zip(&h12)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "spin-up: peak {p12:.6e}; 6-mode error {:.3e}·peak; 4-mode rtol 1e-6 time error {:.3e}·peak, \
         total {:.3e}·peak; wall {:.1} ms, {} steps, {} rhs",
        d6 / p12,
        dt / p12,
        d4 / p12,
        fast.cost.wall_time_s * 1e3,
        fast.cost.steps,
        fast.cost.rhs_evaluations
    );
    assert!(d4 < 1e-2 * p12, "4 modes: {d4} vs peak {p12}");
}

#[test]
fn dyn_spin_up_axial_converges_to_the_inextensible_model() {
    // Extensible link (von Kármán strain), first 5 s. With EA/(ρA Ω² L²) ≈ 1.5e4 the extensible
    // response differs from the inextensible (foreshortening) one only at the relative order
    // ε = ρA Ω² L²/EA of the stretch. The axial field is a stretch beside the foreshortening,
    // so the axial basis does not have to represent u' = −½v'² (a basis that has to locks the
    // membrane, and its tip deflection stays far below the inextensible one); the tip
    // deflection must match the inextensible one to within ε at every basis size.
    let at = |name: &str, n: usize| run_to(name, n, 1e-6, None, Some(5.0));
    let inext = peak_and_history(&at("spin-up", 8)).1;
    let (r4, r8) = (at("spin-up-axial", 4), at("spin-up-axial", 8));
    for r in [&r4, &r8] {
        assert_eq!(r.verdict, StabilityVerdict::Completed);
        let c = r.ledger.relative_closure();
        // rtol 1e-6 over ~3e4 stability-limited steps.
        assert!(c < 1e-5, "closure {c}");
    }
    let scene = load_scene("spin-up-axial").unwrap();
    let l = &scene.links()[0];
    let omega_s = match l.joint.prescribed {
        Some(data::scene::PrescribedMotion::SpinUp { omega_s, .. }) => omega_s,
        ref other => panic!("spin-up-axial is a spin-up, got {other:?}"),
    };
    let eps = l.mass_per_length * omega_s.powi(2) * l.length.powi(2) / l.axial_stiffness.unwrap();
    let (h4, h8) = (peak_and_history(&r4).1, peak_and_history(&r8).1);
    let end = inext.len() - 1;
    let (e4, e8) = (
        (h4[end] - inext[end]).abs() / inext[end].abs(),
        (h8[end] - inext[end]).abs() / inext[end].abs(),
    );
    println!(
        "spin-up-axial at 5 s: 4 modes {:.7}, 8 modes {:.7}, inextensible {:.7}; eps {eps:.2e}",
        h4[end], h8[end], inext[end]
    );
    assert!(e8 < eps, "8 modes: {e8:.3e} vs eps {eps:.3e}");
    assert!(e4 < eps, "4 modes: {e4:.3e} vs eps {eps:.3e}");
    // The stiff axial modes (up to ~8e3 rad/s) are what TR-BDF2 is for: ~600 steps instead of
    // ~26 000, and the same history to the 2nd-order method's accuracy at rtol 1e-6.
    let tr = run_to("spin-up-axial", 4, 1e-6, Some("trbdf2"), Some(5.0));
    assert_eq!(tr.verdict, StabilityVerdict::Completed);
    let ht = peak_and_history(&tr).1;
    let peak = h4.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = ht
        .iter()
        .zip(&h4)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "trbdf2 vs dopri5: {:.2e}·peak, {} vs {} steps",
        d / peak,
        tr.cost.steps,
        r4.cost.steps
    );
    assert!(d < 1e-4 * peak, "{d} vs peak {peak}");
    assert!(tr.cost.steps * 10 < r4.cost.steps);
}

#[test]
fn sys_default_method_per_chain_kelvin_voigt_trbdf2_undamped_exponential_contact_dopri5() {
    use modal::integrate::{DOPRI5, EXPONENTIAL, TRBDF2};
    use modal::simulate::{STEPS_PER_PERIOD, default_method, default_step};
    let plain = Settings::default();
    let with_rtol = Settings {
        time: TimeStepping {
            rtol: Some(1e-6),
            ..Default::default()
        },
        ..Default::default()
    };
    let damped = load_scene("two-link-free").unwrap();
    for name in [
        "two-link-free",
        "barhorst-case1",
        "barhorst-case1-timoshenko",
    ] {
        let scene = load_scene(name).unwrap();
        assert_eq!(
            default_method(scene.planar_chain().unwrap(), &plain.modal().unwrap()),
            &TRBDF2,
            "{name}"
        );
        assert_eq!(
            default_method(scene.planar_chain().unwrap(), &with_rtol.modal().unwrap()),
            &DOPRI5,
            "{name}"
        );
    }
    // Undamped chains without contact take the exponential method, unless a tolerance is given;
    // a contact scene without Kelvin–Voigt keeps the explicit method.
    for (name, method) in [
        ("two-link-free-undamped", &EXPONENTIAL),
        ("single-link", &EXPONENTIAL),
        ("spin-up", &EXPONENTIAL),
        ("constrained-arm", &DOPRI5),
    ] {
        let scene = load_scene(name).unwrap();
        let chain = scene.planar_chain().unwrap();
        assert_eq!(
            default_method(chain, &plain.modal().unwrap()),
            method,
            "{name}"
        );
        assert_eq!(
            default_method(chain, &with_rtol.modal().unwrap()),
            &DOPRI5,
            "{name}"
        );
    }
    // Step of the fixed-step methods when asked for by name: T₁/STEPS_PER_PERIOD of the faster
    // link (the 2 ft link 2): cantilever β₁ = 1.8751.
    let l = &damped.links()[1];
    let omega1 = 1.875_104_068_711_961f64.powi(2)
        * (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt();
    let h = std::f64::consts::TAU / omega1 / STEPS_PER_PERIOD;
    assert!((default_step(damped.planar_chain().unwrap()) - h).abs() <= 1e-15 * h);
}

/// The Kelvin–Voigt work of the default method through the step release at t = 0 of
/// `two-link-free` (every mode rings, the high ones overdamped) against Dormand–Prince at a
/// tight tolerance, which resolves every mode: the same model, so the same work to the
/// tolerance. The fixed step T₁/128 books 15 % too much here (6.12e-2 vs 5.31e-2 at 0.1 s) and
/// leaves a ledger residual of 3.7e-2; both must be at the tolerance level.
#[test]
fn dyn_kelvin_voigt_work_through_the_release_transient_matches_resolved_integration() {
    let scene = load_scene("two-link-free").unwrap();
    let run = |method: Option<&str>, rtol: Option<f64>, atol: Option<f64>| {
        let settings = Settings {
            time: TimeStepping {
                t_end: Some(0.1),
                method: method.map(|m| m.parse().expect("a method name")),
                rtol,
                atol,
                ..Default::default()
            },
            ..Default::default()
        };
        ModalBackend.simulate(&scene, &settings).unwrap()
    };
    let kv_work = |r: &RunResult| {
        let term = r
            .ledger
            .dissipation
            .iter()
            .find(|d| d.name == "kelvin_voigt")
            .unwrap();
        *term.values.last().unwrap()
    };
    let default = run(None, None, None);
    let resolved = run(Some("dopri5"), Some(1e-9), Some(1e-11));
    let fixed = run(Some("trbdf2-fixed"), None, None);
    let (w_def, w_ref, w_fix) = (kv_work(&default), kv_work(&resolved), kv_work(&fixed));
    println!("KV work at 0.1 s: default {w_def:.6e}, dopri5 {w_ref:.6e}, fixed {w_fix:.6e}");
    assert!((w_def - w_ref).abs() < 1e-3 * w_ref, "{w_def} vs {w_ref}");
    let residual = |r: &RunResult| r.ledger.residual(r.ledger.time.len() - 1).abs();
    println!(
        "residual: default {:.2e}, fixed {:.2e}",
        residual(&default),
        residual(&fixed)
    );
    assert!(residual(&default) < 1e-3 * w_ref);
    // The fixed step is the defect this guards against: it must stay detectable here.
    assert!(w_fix > 1.05 * w_ref, "{w_fix} vs {w_ref}");
}

/// Mean of `v` over windows of `w` samples (a low-pass that keeps the slow joint motion).
fn window_means(v: &[f64], w: usize) -> Vec<f64> {
    v.chunks(w)
        .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        .collect()
}

#[test]
fn dyn_two_link_free_fixed_step_and_default_follow_the_resolved_method() {
    // Fixed-step TR-BDF2 at T₁/128 (6 poly modes; the default before the release transient's
    // Kelvin–Voigt work showed it under-resolved, see
    // dyn_kelvin_voigt_work_through_the_release_transient_matches_resolved_integration) and the
    // default (adaptive TR-BDF2) against Dormand–Prince at rtol 1e-9 on the same model, first
    // 2 s: the joint angles averaged over 0.05 s windows (the Kelvin–Voigt-damped high modes are
    // gone within a few periods) agree to 1e-4 rad (fixed step measured on 10 s, 20 Hz
    // low-pass: 3.1e-5), the fixed step in ~10× fewer steps.
    let scene = load_scene("two-link-free").unwrap();
    let t_end = Some(2.0);
    let fixed_step = Settings {
        time: TimeStepping {
            t_end,
            method: Some("trbdf2-fixed".parse().expect("a method name")),
            ..Default::default()
        },
        ..Default::default()
    };
    let default = Settings {
        time: TimeStepping {
            t_end,
            ..Default::default()
        },
        ..Default::default()
    };
    let reference = Settings {
        discretization: Discretization {
            basis: Some(Basis::Poly),
            ..Default::default()
        },
        time: TimeStepping {
            t_end,
            rtol: Some(1e-9),
            atol: Some(1e-12),
            method: Some("dopri5".parse().expect("a method name")),
            ..Default::default()
        },
    };
    let fixed = ModalBackend.simulate(&scene, &fixed_step).unwrap();
    let by_default = ModalBackend.simulate(&scene, &default).unwrap();
    let adaptive = ModalBackend.simulate(&scene, &reference).unwrap();
    for run in [&fixed, &by_default] {
        assert_eq!(run.verdict, StabilityVerdict::Completed);
        for k in [1, 2] {
            let ch = channel::joint_angle(k);
            let a = window_means(&run.observables.get(&ch).unwrap().values, 5);
            let b = window_means(&adaptive.observables.get(&ch).unwrap().values, 5);
            let d = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            println!(
                "{ch}: {d:.3e} rad; steps {} vs {}",
                run.cost.steps, adaptive.cost.steps
            );
            assert!(d < 1e-4, "{ch}: {d:e}");
        }
    }
    assert!(fixed.cost.steps * 3 < adaptive.cost.steps);
}

/// The scene's defaults but for the method, t_end, the step and the tolerance (atol rtol/1000).
fn method_settings(method: &str, t_end: f64, dt: Option<f64>, rtol: Option<f64>) -> Settings {
    Settings {
        time: TimeStepping {
            t_end: Some(t_end),
            dt,
            rtol,
            atol: rtol.map(|r| r * 1e-3),
            method: Some(method.parse().expect("a method name")),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// The exponential integrator on the undamped arm, whose every mode rings: its whole 0.3 s
/// joint-angle histories converge at fourth order once the step resolves the remainder's
/// coupling of the top mode (ω_max·h ≤ 2; the default step is there), to Dormand–Prince's
/// answer at a tight tolerance.
#[test]
fn dyn_exponential_converges_on_the_undamped_arm() {
    let scene = load_scene("two-link-free-undamped").unwrap();
    let settings =
        |method: &str, dt: Option<f64>, rtol: Option<f64>| method_settings(method, 0.3, dt, rtol);
    let simulate = |s: &Settings| {
        let r = ModalBackend.simulate(&scene, s).unwrap();
        assert_eq!(r.verdict, StabilityVerdict::Completed);
        r
    };
    let distance = |a: &RunResult, b: &RunResult| {
        [1, 2]
            .iter()
            .map(|&k| {
                let ch = channel::joint_angle(k);
                let x = &a.observables.get(&ch).unwrap().values;
                let y = &b.observables.get(&ch).unwrap().values;
                assert_eq!(x.len(), y.len());
                x.iter()
                    .zip(y)
                    .map(|(p, q)| (p - q).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    };
    // ω_max·h ≈ 4, 2, 1, 0.5 (ω_max = 1.58e4 rad/s at the start); measured differences
    // 3.3e-6, 3.7e-7, 3.0e-8 rad (orders 3.17, 3.61). A fifth rung (h = 1.5625e-5) differs by
    // 5.7e-9 rad, the round-off floor of the steps' modal transforms in `poly` coordinates.
    let runs: Vec<RunResult> = [2.5e-4, 1.25e-4, 6.25e-5, 3.125e-5]
        .iter()
        .map(|&h| simulate(&settings("exponential", Some(h), None)))
        .collect();
    let diffs: Vec<f64> = runs.windows(2).map(|w| distance(&w[0], &w[1])).collect();
    let orders: Vec<f64> = diffs.windows(2).map(|d| (d[0] / d[1]).log2()).collect();
    println!("successive differences {diffs:?}, orders {orders:?}");
    assert!(orders[1] > orders[0], "{orders:?}");
    assert!(orders[1] > 3.5 && orders[1] < 4.3, "{orders:?}");
    let reference = simulate(&settings("dopri5", None, Some(1e-10)));
    let agreement = distance(&runs[3], &reference);
    println!("finest rung against dopri5 at rtol 1e-10: {agreement:.3e}");
    assert!(agreement < diffs[2], "{agreement:e} vs {diffs:?}");
    let default = simulate(&settings("exponential", None, None));
    let steps = default.cost.steps;
    println!(
        "default: {steps} steps, {:.3e} from the finest rung",
        distance(&default, &runs[3])
    );
    assert!((2300..=2500).contains(&steps), "{steps}");
}

/// The fixed-step methods keep their order through the discontinuities of a torque law:
/// `single-link`'s bang-bang torque jumps at 0.5 s and 1 s, onto which the driver steps. A
/// stage that lands on a jump reads the law's left limit there ([`modal::integrate::Stretch`]);
/// read at the jump's own time, a right-continuous law hands the next stretch's torque to the
/// last stage of the step before it, and the step integrates the jump over part of its
/// length: an error of order h·Δτ, first order in h. Over 1.2 s (both jumps) the trapezoidal
/// rule must show order 2 and the exponential method order 4 on the joint angle's whole
/// history, against Dormand–Prince at rtol 1e-11.
#[test]
fn dyn_fixed_step_methods_keep_their_order_through_torque_jumps() {
    let scene = load_scene("single-link").unwrap();
    let settings =
        |method: &str, dt: Option<f64>, rtol: Option<f64>| method_settings(method, 1.2, dt, rtol);
    let angle = |s: &Settings| {
        let r = ModalBackend.simulate(&scene, s).unwrap();
        assert_eq!(r.verdict, StabilityVerdict::Completed);
        r.observables
            .get(&channel::joint_angle(1))
            .unwrap()
            .values
            .clone()
    };
    let reference = angle(&settings("dopri5", None, Some(1e-11)));
    let error = |method: &str, h: f64| {
        let x = angle(&settings(method, Some(h), None));
        assert_eq!(x.len(), reference.len());
        x.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    for (method, steps, order) in [
        ("trapezoid", [2e-3, 1e-3, 5e-4], 2.0),
        ("exponential", [2e-3, 1e-3, 5e-4], 4.0),
    ] {
        let errors: Vec<f64> = steps.iter().map(|&h| error(method, h)).collect();
        let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
        println!("{method}: errors {errors:?}, orders {orders:.2?}");
        for p in orders {
            assert!((p - order).abs() < 0.5, "{method}: {p}");
        }
    }
}
