//! Assembled system: Rayleigh–Ritz frequencies, statics, DOF plans, unsupported features.

use data::{Backend, BackendError, Basis, Discretization, Settings, load_scene};
use modal::ModalBackend;
use modal::basis::{clamped_free_reference_roots, frequency_roots};
use modal::modes::rotating_modes;

fn settings(basis: Basis, modes: usize) -> Settings {
    Settings {
        discretization: Discretization {
            modes: Some(modes),
            basis: Some(basis),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// ωₖ = βₖ² sqrt(EI/(ρA L⁴)) in Hz.
fn beam_hz(beta: f64, ei: f64, rho_a: f64, l: f64) -> f64 {
    beta * beta * (ei / (rho_a * l.powi(4))).sqrt() / (2.0 * std::f64::consts::PI)
}

#[test]
fn sys_cantilever_clamped_free_basis_is_exact() {
    let scene = load_scene("cantilever").unwrap();
    let l = &scene.links()[0];
    let res = ModalBackend
        .modes(&scene, &settings(Basis::ClampedFree, 10), 10)
        .unwrap();
    let beta = clamped_free_reference_roots(10);
    for (k, f) in res.frequencies_hz.iter().enumerate() {
        let exact = beam_hz(beta[k], l.bending_stiffness, l.mass_per_length, l.length);
        // The basis is the exact solution: only quadrature and eigen-solver round-off remain.
        assert!(
            ((f - exact) / exact).abs() < 1e-10,
            "mode {}: {f} vs {exact}",
            k + 1
        );
    }
    assert_eq!(res.cost.dofs, 10);
}

#[test]
fn sys_rayleigh_ritz_poly_converges_monotonically_from_above() {
    let scene = load_scene("cantilever").unwrap();
    let l = &scene.links()[0];
    let beta = clamped_free_reference_roots(3);
    let exact: Vec<f64> = beta
        .iter()
        .map(|b| beam_hz(*b, l.bending_stiffness, l.mass_per_length, l.length))
        .collect();
    let mut prev = [f64::INFINITY; 3];
    for n in 3..=10 {
        let f = ModalBackend
            .modes(&scene, &settings(Basis::Poly, n), n)
            .unwrap()
            .frequencies_hz;
        for k in 0..3 {
            // Round-off floor of the symmetric eigen-solver: absolute error ≈ ε‖C‖ in λ = ω², i.e.
            // a relative error in fₖ of about ε·(f_max/fₖ)²/2; 100ε covers the Cholesky reduction.
            let slack = 100.0 * f64::EPSILON * (f[n - 1] / f[k]).powi(2);
            // Ritz upper bound (minimax).
            assert!(
                f[k] >= exact[k] * (1.0 - slack),
                "n = {n}, mode {}: {} < exact {}",
                k + 1,
                f[k],
                exact[k]
            );
            // Nested spaces: never increases with n.
            assert!(
                f[k] <= prev[k] * (1.0 + slack),
                "n = {n}, mode {}: {} > {}",
                k + 1,
                f[k],
                prev[k]
            );
            prev[k] = f[k];
        }
    }
    // 10 polynomials resolve the first frequency to 1e-10 and the third to 1e-5.
    assert!(
        (prev[0] - exact[0]) / exact[0] < 1e-10,
        "{} vs {}",
        prev[0],
        exact[0]
    );
    assert!(
        (prev[2] - exact[2]) / exact[2] < 1e-5,
        "{} vs {}",
        prev[2],
        exact[2]
    );
}

#[test]
fn sys_tip_mass_basis_is_exact_and_clamped_free_converges_from_above() {
    let scene = load_scene("cantilever-tip-mass").unwrap();
    let l = &scene.links()[0];
    let mu = l.tip_mass.unwrap() / l.beam_mass();
    let beta = frequency_roots(4, mu, 0.0).unwrap();
    let exact: Vec<f64> = beta
        .iter()
        .map(|b| beam_hz(*b, l.bending_stiffness, l.mass_per_length, l.length))
        .collect();
    let f = ModalBackend
        .modes(&scene, &settings(Basis::TipMass, 6), 4)
        .unwrap()
        .frequencies_hz;
    for k in 0..4 {
        assert!(
            ((f[k] - exact[k]) / exact[k]).abs() < 1e-10,
            "mode {}: {} vs {}",
            k + 1,
            f[k],
            exact[k]
        );
    }
    let mut prev = f64::INFINITY;
    for n in [2, 4, 8, 16] {
        let g = ModalBackend
            .modes(&scene, &settings(Basis::ClampedFree, n), 1)
            .unwrap()
            .frequencies_hz[0];
        assert!(
            g >= exact[0] * (1.0 - 1e-12) && g <= prev * (1.0 + 1e-12),
            "n = {n}: {g}"
        );
        prev = g;
    }
    // The clamped-free basis cannot represent the tip shear jump: slow convergence, but < 1e-3 at 16.
    assert!((prev - exact[0]) / exact[0] < 1e-3);
}

#[test]
fn sys_rotating_beam_in_plane_identity_and_convergence() {
    // In-plane bending with foreshortening: K_in = K + Ω²(Sₓ − M_φ). The rotating mode shapes
    // are analytic, so the polynomial Ritz basis converges spectrally: poly-14 vs poly-16 agree
    // to 1e-9 and serve as the reference. The clamped-free expansion of the stiffening operator
    // converges only algebraically: its error must fall monotonically 6 → 12 → 20 modes (from
    // above) and be below 1e-4 at 20 modes even at λ = 12 (measured 2e-5).
    let scene = load_scene("rotating-beam").unwrap();
    let l = &scene.links()[0];
    let lam_scale = (l.mass_per_length * l.length.powi(4) / l.bending_stiffness).sqrt();
    let beta = clamped_free_reference_roots(3);
    for lam in [0.0, 1.0, 4.0, 12.0] {
        let omega = lam / lam_scale;
        let at = |b: Basis, n: usize| {
            rotating_modes(
                &scene,
                scene.planar_chain().unwrap(),
                &settings(b, n).modal().unwrap(),
                omega,
                3,
            )
            .unwrap()
            .frequencies_hz
        };
        let (p14, p16) = (at(Basis::Poly, 14), at(Basis::Poly, 16));
        let (f6, f12, f20) = (
            at(Basis::ClampedFree, 6),
            at(Basis::ClampedFree, 12),
            at(Basis::ClampedFree, 20),
        );
        for k in 0..3 {
            let r = p16[k];
            assert!(
                ((p14[k] - r) / r).abs() < 1e-9,
                "λ = {lam}, mode {}: poly {} vs {}",
                k + 1,
                p14[k],
                r
            );
            let e = |f: &[f64]| (f[k] - r) / r;
            // Comparisons carry the reference's own 1e-9 accuracy.
            assert!(
                e(&f6) >= e(&f12) - 1e-9 && e(&f12) >= e(&f20) - 1e-9 && e(&f20) > -1e-9,
                "λ = {lam}, mode {}: {} {} {}",
                k + 1,
                e(&f6),
                e(&f12),
                e(&f20)
            );
            assert!(e(&f20) < 1e-4, "λ = {lam}, mode {}: {}", k + 1, e(&f20));
        }
        let f20 = p16;
        if lam == 0.0 {
            for k in 0..3 {
                let exact = beam_hz(beta[k], l.bending_stiffness, l.mass_per_length, l.length);
                assert!(((f20[k] - exact) / exact).abs() < 1e-10);
            }
        } else {
            // Stiffening dominates the −Ω² softening: in-plane frequencies rise with λ.
            let f0 = beam_hz(beta[0], l.bending_stiffness, l.mass_per_length, l.length);
            assert!(f20[0] > f0, "λ = {lam}: {} ≤ {f0}", f20[0]);
        }
    }
}

#[test]
fn sys_cantilever_statics_tip_load() {
    let scene = load_scene("cantilever").unwrap();
    let l = &scene.links()[0];
    let mut s = scene.clone();
    s.planar_chain_mut()
        .unwrap()
        .statics
        .as_mut()
        .unwrap()
        .distributed_load = None;
    // Poly basis with n ≥ 2 contains the exact cubic: PL³/3EI to round-off.
    let r = ModalBackend.statics(&s, &settings(Basis::Poly, 4)).unwrap();
    let p = s.statics().unwrap().tip_force.unwrap();
    let exact = p * l.length.powi(3) / (3.0 * l.bending_stiffness);
    assert!(
        ((r.tip_deflection - exact) / exact).abs() < 1e-12,
        "{} vs {exact}",
        r.tip_deflection
    );
    let rot = p * l.length.powi(2) / (2.0 * l.bending_stiffness);
    assert!(((r.tip_rotation - rot) / rot).abs() < 1e-12);
}

#[test]
fn sys_dof_plans_per_scene() {
    let disc = Discretization {
        modes: Some(4),
        ..Default::default()
    };
    let cases = [
        ("cantilever", 4),
        ("cantilever-tip-mass", 4),
        ("cantilever-axial", 8),
        ("rotating-beam", 4),
        ("spin-up", 4),
        ("spin-up-linear", 4),
        ("single-link", 5),
        ("two-link-free", 10),
        ("two-link-free-undamped", 10),
    ];
    for (name, total) in cases {
        let plan = ModalBackend
            .dof_plan(&load_scene(name).unwrap(), &disc)
            .unwrap();
        assert_eq!(plan.total(), total, "{name}: {plan:?}");
    }
    let plan = ModalBackend
        .dof_plan(&load_scene("spin-up").unwrap(), &disc)
        .unwrap();
    assert!(plan.builds.iter().any(|b| b.contains("foreshortening")));
    let plan = ModalBackend
        .dof_plan(&load_scene("spin-up-linear").unwrap(), &disc)
        .unwrap();
    assert!(!plan.builds.iter().any(|b| b.contains("foreshortening")));
    let plan = ModalBackend
        .dof_plan(&load_scene("single-link").unwrap(), &disc)
        .unwrap();
    assert!(plan.builds.iter().any(|b| b.contains("tip mass")));
    assert!(
        !plan
            .builds
            .iter()
            .any(|b| b.contains("gravity") || b.contains("Kelvin"))
    );
}

#[test]
fn sys_unsupported_and_invalid_requests_are_typed_errors() {
    let s = Settings::default();
    // Timoshenko links are supported since issue 7 (dyn_timoshenko.rs); a shear link without
    // its κGA is refused with a precise message.
    let mut scene = load_scene("barhorst-case1-timoshenko").unwrap();
    scene.planar_chain_mut().unwrap().links[1].shear_stiffness = None;
    match ModalBackend.simulate(&scene, &s) {
        Err(BackendError::Unsupported(msg)) => {
            assert!(
                msg.starts_with("modal:") && msg.contains("shear_stiffness"),
                "{msg}"
            )
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
    let scene = load_scene("cantilever").unwrap();
    for (basis, modes) in [
        (Basis::ClampedFree, 0),
        (Basis::ClampedFree, 41),
        (Basis::FreeFree, 4),
        (Basis::TipMass, 4),
    ] {
        let r = ModalBackend.modes(&scene, &settings(basis, modes), 3);
        assert!(
            matches!(r, Err(BackendError::InvalidSettings { .. })),
            "{basis:?}/{modes}: {r:?}"
        );
    }
    let mut bad = Settings::default();
    // A method of another backend.
    bad.time.method = Some(data::Method::Report);
    match ModalBackend.simulate(&load_scene("single-link").unwrap(), &bad) {
        Err(BackendError::InvalidSettings { field, message }) => {
            assert_eq!(field, "time.method");
            assert!(
                message.contains("`report`") && message.contains("dopri5"),
                "{message}"
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn sys_cantilever_axial_and_bending_frequencies_are_exact() {
    // Both bases are exact eigenfunctions here: axial √2 sin((2k−1)πx/2L) with
    // f = (2k−1)/(4L)·sqrt(EA/ρA), bending clamped-free. Only round-off remains.
    let scene = load_scene("cantilever-axial").unwrap();
    let l = &scene.links()[0];
    let n = 6;
    let res = ModalBackend
        .modes(&scene, &settings(Basis::ClampedFree, n), 2 * n)
        .unwrap();
    let beta = clamped_free_reference_roots(n);
    let c = (l.axial_stiffness.unwrap() / l.mass_per_length).sqrt();
    let (mut nb, mut na) = (0, 0);
    for (f, kind) in res.frequencies_hz.iter().zip(&res.kinds) {
        let exact = if kind == "axial" {
            na += 1;
            (2.0 * na as f64 - 1.0) * c / (4.0 * l.length)
        } else {
            assert_eq!(kind, "bending");
            nb += 1;
            beam_hz(
                beta[nb - 1],
                l.bending_stiffness,
                l.mass_per_length,
                l.length,
            )
        };
        assert!(((f - exact) / exact).abs() < 1e-10, "{kind} {f} vs {exact}");
    }
    assert_eq!((na, nb), (n, n));
    // Modes of the spinning extensible beam need the stretched steady state: not built. A run
    // integrates it, and `describe` plans what the run builds: n axial and n transverse
    // modes (the prescribed hub has no DOF).
    let spinning = load_scene("rotating-beam-axial").unwrap();
    assert!(matches!(
        ModalBackend.modes(&spinning, &Settings::default(), 3),
        Err(BackendError::Unsupported(_))
    ));
    let disc = Discretization {
        modes: Some(n),
        ..Default::default()
    };
    let plan = ModalBackend.dof_plan(&spinning, &disc).unwrap();
    assert_eq!(plan.total(), 2 * n);
}
