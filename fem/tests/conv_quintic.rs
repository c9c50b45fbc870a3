//! Hermite-quintic Euler–Bernoulli element (`discretization.element = "hermite-quintic"`):
//! frequencies against the analytic transcendental equations, observed order, statics, and the
//! settings it refuses.

// Index loops mirror the formulas being checked.
#![allow(clippy::needless_range_loop)]

mod common;

use common::max_diff;
use data::{Backend, BackendError, FemElement, Settings};
use fem::FemBackend;

fn settings(n: usize, element: Option<FemElement>) -> Settings {
    let mut s = Settings::default();
    s.discretization.elements = Some(n);
    s.discretization.element = element;
    s
}

const QUINTIC: Option<FemElement> = Some(FemElement::HermiteQuintic);

fn omegas(scene: &data::Scene, n: usize, count: usize) -> Vec<f64> {
    FemBackend
        .modes(scene, &settings(n, QUINTIC), count)
        .unwrap()
        .frequencies_hz
        .iter()
        .map(|f| 2.0 * std::f64::consts::PI * f)
        .collect()
}

fn rel_errors(w: &[f64], exact: &[f64]) -> Vec<f64> {
    w.iter().zip(exact).map(|(w, e)| (w - e) / e).collect()
}

fn sci(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.3e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn conv_quintic_cantilever_frequencies_converge_at_order_eight() {
    let sc = data::load_scene("cantilever").unwrap();
    let l = &sc.links()[0];
    let exact = common::clamped_free_omega(l.bending_stiffness, l.mass_per_length, l.length, 4);
    let meshes = [1usize, 2, 4, 8, 16];
    let errs: Vec<Vec<f64>> = meshes
        .iter()
        .map(|&n| rel_errors(&omegas(&sc, n, 4), &exact))
        .collect();
    for (n, e) in meshes.iter().zip(&errs) {
        eprintln!("quintic n={n}: {}", sci(e));
    }
    for k in 0..4 {
        // The bar: 1e-5 at 16 elements for the first four modes.
        assert!(
            errs[4][k].abs() < 1e-5,
            "mode {} at 16: {}",
            k + 1,
            errs[4][k]
        );
        // Rayleigh–Ritz from above while the error is above round-off (~1e-13 here).
        for e in &errs {
            assert!(
                e[k] > -1e-12,
                "mode {} below the exact value: {}",
                k + 1,
                e[k]
            );
        }
    }
    // Observed order: least-squares slope of log error against log n over the meshes whose
    // error is ≥ 1e-10, i.e. ≥ 50× the round-off floor of the eigen-solve (≈ 2e-12 measured at
    // 16 elements), and ≤ 1e-2 (above 1 % a mode has about one element per half-wave: not yet
    // asymptotic). Theory 2(p − 1) = 8 for p = 5; the band [7, 9.5] allows the pre-asymptotic
    // wobble of the higher modes (single rungs measured between 6.6 and 9.3).
    for k in 0..4 {
        let pts: Vec<(f64, f64)> = meshes
            .iter()
            .zip(&errs)
            .filter(|(_, e)| (1e-10..=1e-2).contains(&e[k]))
            .map(|(&n, e)| ((n as f64).ln(), e[k].ln()))
            .collect();
        assert!(
            pts.len() >= 2,
            "mode {}: fewer than two measurable meshes",
            k + 1
        );
        let m = pts.len() as f64;
        let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
        let (mx, my) = (sx / m, sy / m);
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
        let order = -sxy / sxx;
        eprintln!(
            "mode {}: observed order {order:.2} over {} meshes",
            k + 1,
            pts.len()
        );
        assert!((7.0..9.5).contains(&order), "mode {}: order {order}", k + 1);
    }
}

#[test]
fn sys_quintic_tip_mass_frequencies_match_transcendental_equation() {
    let mut sc = data::load_scene("cantilever-tip-mass").unwrap();
    for tip_inertia in [None, Some(2e-3)] {
        sc.planar_chain_mut().unwrap().links[0].tip_inertia = tip_inertia;
        let l = &sc.links()[0];
        let exact = common::tip_mass_omega(
            l.bending_stiffness,
            l.mass_per_length,
            l.length,
            l.tip_mass.unwrap(),
            tip_inertia.unwrap_or(0.0),
            4,
        );
        let e = rel_errors(&omegas(&sc, 16, 4), &exact);
        eprintln!("tip mass J={tip_inertia:?} quintic 16: {}", sci(&e));
        for k in 0..4 {
            // Tip bodies attach to the nodal DOFs unchanged: same O(h⁸) accuracy as the bare
            // cantilever, well inside 1e-6 at 16 elements (the reference root-finder is good to
            // ~1e-12).
            assert!(
                e[k].abs() < 1e-6,
                "J={tip_inertia:?} mode {}: {}",
                k + 1,
                e[k]
            );
        }
    }
}

#[test]
fn sys_quintic_statics_exact_for_tip_and_uniform_load() {
    let sc = data::load_scene("cantilever").unwrap();
    let l = &sc.links()[0];
    let st = sc.statics().cloned().unwrap();
    let (p, q) = (st.tip_force.unwrap(), st.distributed_load.unwrap());
    let (ei, len) = (l.bending_stiffness, l.length);
    let exact = p * len.powi(3) / (3.0 * ei) + q * len.powi(4) / (8.0 * ei);
    let exact_rot = p * len * len / (2.0 * ei) + q * len.powi(3) / (6.0 * ei);
    for n in [1usize, 3, 16] {
        let r = FemBackend.statics(&sc, &settings(n, QUINTIC)).unwrap();
        // The exact deflection (a quartic) lies in the quintic space: round-off only,
        // amplified by the conditioning ≈ n⁴ (tol = 4·ε·n⁴, floor 1e-13).
        let tol = (4.0 * f64::EPSILON * (n as f64).powi(4)).max(1e-13);
        assert!((r.tip_deflection - exact).abs() < tol * exact, "n={n}");
        assert!(
            (r.tip_rotation - exact_rot).abs() < tol * exact_rot,
            "n={n}"
        );
    }
}

#[test]
fn sys_quintic_rotating_beam_agrees_with_extrapolated_cubic() {
    // The quintic geometric stiffness (centrifugal force, quadratic in x) and rotating-frame
    // softening against the independent cubic assembly, Richardson-extrapolated.
    let sc = data::load_scene("rotating-beam").unwrap();
    let q = omegas(&sc, 16, 3);
    let cubic = |n: usize| -> Vec<f64> {
        FemBackend
            .modes(&sc, &settings(n, None), 3)
            .unwrap()
            .frequencies_hz
            .iter()
            .map(|f| 2.0 * std::f64::consts::PI * f)
            .collect()
    };
    let (c32, c64) = (cubic(32), cubic(64));
    for k in 0..3 {
        // O(h⁴) cubic: (16 c₆₄ − c₃₂)/15 leaves O(h⁶) ≈ 1e-9 on mode 3 (cubic errors 2.5e-6 and
        // 1.6e-7 on the cantilever); quintic at 16 elements ≈ 7e-11.
        let ext = (16.0 * c64[k] - c32[k]) / 15.0;
        let d = (q[k] - ext) / ext;
        eprintln!(
            "rotating mode {}: quintic16 vs extrapolated cubic {d:.2e}",
            k + 1
        );
        assert!(d.abs() < 1e-8, "mode {}: {d}", k + 1);
    }
}

#[test]
fn sys_quintic_dof_count_in_modes_and_dynamics_and_shear_refusal() {
    let sc = data::load_scene("cantilever").unwrap();
    let n = 8;
    let plan = FemBackend
        .dof_plan(&sc, &settings(n, QUINTIC).discretization)
        .unwrap();
    // v, v′ per free node + two bubble amplitudes per element.
    assert_eq!(plan.total(), 4 * n);
    let m = FemBackend.modes(&sc, &settings(n, QUINTIC), 2).unwrap();
    assert_eq!(m.cost.dofs, plan.total());
    // Dynamics builds the same element: the run's DOFs are the plan's.
    let run = FemBackend.simulate(&sc, &settings(n, QUINTIC)).unwrap();
    assert_eq!(run.cost.dofs, plan.total());
    // A shear link uses the Timoshenko element: asking for the quintic is a settings error.
    let tim = data::load_scene("cantilever-timoshenko").unwrap();
    match FemBackend.modes(&tim, &settings(n, QUINTIC), 2) {
        Err(BackendError::InvalidSettings { field, message }) => {
            assert_eq!(field, "discretization.element");
            assert!(message.contains("Timoshenko"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn sys_quintic_is_refused_by_the_families_built_from_cubics() {
    // The rocket, the 3-D payload link and the mobile manipulator's flexible link are Hermite
    // cubics only: asking for the quintic there is refused, in the DOF plan and in a run,
    // instead of running cubics under the quintic's name.
    for (scene, family) in [
        ("rocket", "fem rocket"),
        ("single-link-3d", "fem 3-D payload link"),
        ("mobile-manipulator-flexible", "fem mobile manipulator"),
    ] {
        let sc = data::load_scene(scene).unwrap();
        let quintic = settings(4, QUINTIC);
        for result in [
            FemBackend
                .dof_plan(&sc, &quintic.discretization)
                .map(|_| ()),
            FemBackend.simulate(&sc, &quintic).map(|_| ()),
        ] {
            match result {
                Err(BackendError::Unsupported(message)) => {
                    assert!(message.starts_with(family), "{scene}: {message}");
                    assert!(message.contains("hermite-quintic"), "{scene}: {message}");
                }
                other => panic!("{scene}: {other:?}"),
            }
        }
        // The cubic (named or by default) still builds.
        let cubic = settings(4, Some(FemElement::HermiteCubic));
        assert!(
            FemBackend.dof_plan(&sc, &cubic.discretization).is_ok(),
            "{scene}"
        );
    }
}

/// Hub angle history θ(tᵢ) of `single-link` with `n` elements of `element`, all runs at the same
/// fixed step so that they share one time discretization and differ only in space.
fn hub_angle_history(n: usize, element: Option<FemElement>, dt: f64) -> Vec<f64> {
    let sc = data::load_scene("single-link").unwrap();
    let mut s = settings(n, element);
    s.time.dt = Some(dt);
    let run = FemBackend.simulate(&sc, &s).unwrap();
    run.observables.get("joint1.angle").unwrap().values.clone()
}

#[test]
fn conv_quintic_dynamics_converges_to_the_refined_cubic_hub_angle_history() {
    // One step for every run, T₁/400 of the scene's first flexible period
    // (clamped–free β₁L = 1.8751: ω₁ = β₁² √(EI/ρA)); the comparison is spatial only.
    let sc = data::load_scene("single-link").unwrap();
    let l = &sc.links()[0];
    let beta1 = 1.875_104_068_711_961 / l.length;
    let omega1 = beta1 * beta1 * (l.bending_stiffness / l.mass_per_length).sqrt();
    let dt = 2.0 * std::f64::consts::PI / omega1 / 400.0;
    eprintln!("dt = {dt:.3e}");
    let (c4, c8, c16) = (
        hub_angle_history(4, None, dt),
        hub_angle_history(8, None, dt),
        hub_angle_history(16, None, dt),
    );
    let (q4, q8) = (
        hub_angle_history(4, QUINTIC, dt),
        hub_angle_history(8, QUINTIC, dt),
    );
    // The cubic converges at O(h⁴) in the history too, so Richardson's estimate of the error
    // of the 16-element cubic is |c8 − c16|/(2⁴ − 1).
    let (d48, d816) = (max_diff(&c4, &c8), max_diff(&c8, &c16));
    let order = (d48 / d816).log2();
    let e16 = d816 / 15.0;
    let (dq4, dq8, dq48) = (max_diff(&q4, &c16), max_diff(&q8, &c16), max_diff(&q4, &q8));
    eprintln!(
        "cubic order {order:.2}, cubic-16 error ≈ {e16:.2e}; |q4 − c16| {dq4:.2e}, \
         |q8 − c16| {dq8:.2e}, |q4 − q8| {dq48:.2e}"
    );
    assert!(order > 3.5, "cubic history order {order}");
    // The quintic (O(h⁸)) at 4 and 8 elements is at least as accurate as the cubic at 16: it
    // differs from it by no more than the two errors, ≤ 2·e16, and its own refinement changes
    // the history by less than the cubic-16 error.
    assert!(
        dq4 <= 2.0 * e16,
        "|q4 − c16| = {dq4} vs 2·e16 = {}",
        2.0 * e16
    );
    assert!(
        dq8 <= 2.0 * e16,
        "|q8 − c16| = {dq8} vs 2·e16 = {}",
        2.0 * e16
    );
    assert!(dq48 <= e16, "|q4 − q8| = {dq48} vs e16 = {e16}");
}
