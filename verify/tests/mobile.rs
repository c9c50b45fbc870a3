//! The rigid reference of the mobile manipulator (seed 004): equations against the energies,
//! the two formulations, inverse dynamics, the ledger, and the scene family's DOF counts.

use data::{Backend, BackendError, RunResult, Scene, Settings, TimeStepping, load_scene};
use verify::analytic::rigid::mobile::model::MAX_Q;
use verify::analytic::rigid::mobile::{Reference, Tolerances};
use verify::registry::ReferenceBackend;

/// A reference run through the backend entry (which picks the family).
fn simulate(scene: &Scene, settings: &Settings) -> Result<RunResult, BackendError> {
    ReferenceBackend.simulate(scene, settings)
}

fn reference(name: &str) -> Reference {
    let scene = load_scene(name).expect("catalog scene");
    Reference::from_scene(scene.mobile_manipulator().expect("mobile scene")).expect("rigid model")
}

/// A deterministic, non-special state (q, q̇) with q̇ consistent with the constraints.
fn state(r: &Reference, seed: f64) -> ([f64; MAX_Q], [f64; MAX_Q]) {
    let (n, m) = (r.model.layout.n, r.model.layout.m);
    let mut q = [0.0; MAX_Q];
    let mut nu = [0.0; MAX_Q];
    for (i, v) in q.iter_mut().enumerate().take(n) {
        *v = 0.3 + 0.7 * ((i as f64 + 1.0) * seed).sin();
    }
    for (i, v) in nu.iter_mut().enumerate().take(m) {
        *v = 1.5 * ((i as f64 + 2.0) * seed * 1.3).cos();
    }
    let mut qd = [0.0; MAX_Q];
    let mut scratch = [0.0; MAX_Q];
    r.model.velocities(&q[..n], &nu[..m], &mut qd, &mut scratch);
    (q, qd)
}

#[test]
fn sys_mobile_dof_counts_per_variant() {
    for (name, n, m) in [
        ("mobile-manipulator", 9, 6),
        ("mobile-platform", 5, 2),
        ("mobile-arm-fixed-base", 4, 4),
    ] {
        let r = reference(name);
        assert_eq!((r.model.layout.n, r.model.layout.m), (n, m), "{name}");
    }
}

#[test]
fn sys_mobile_mass_matrix_is_the_kinetic_energy() {
    let r = reference("mobile-manipulator");
    let n = r.model.layout.n;
    for seed in [0.37, 1.1, 2.9] {
        let (q, _) = state(&r, seed);
        // Any q̇ (not only constraint-consistent ones): T is a quadratic form in all of q̇.
        let qd: Vec<f64> = (0..n).map(|i| (i as f64 * seed + 0.2).sin()).collect();
        let mut mm = [[0.0; MAX_Q]; MAX_Q];
        r.model.mass_matrix(&q[..n], &mut mm);
        let quad: f64 = (0..n)
            .map(|i| (0..n).map(|j| qd[i] * mm[i][j] * qd[j]).sum::<f64>())
            .sum();
        let t = r.model.kinetic_energy(&q[..n], &qd);
        assert!(
            (0.5 * quad - t).abs() <= 1e-13 * t,
            "½q̇ᵀMq̇ = {} vs T = {t}",
            0.5 * quad
        );
        for (i, row) in mm.iter().enumerate().take(n) {
            for (j, v) in row.iter().enumerate().take(n) {
                assert_eq!(*v, mm[j][i]);
            }
        }
    }
}

/// h(q, q̇) = Ṁ q̇ − ∂T/∂q + ∂V/∂q by central differences of T and V from the body velocities
/// (Ṁ q̇ = ∂/∂ε [∂T/∂q̇](q + ε q̇)); Newton–Euler with q̈ = 0 must match.
#[test]
fn sys_mobile_generalized_forces_match_lagrangian_gradients() {
    for name in [
        "mobile-manipulator",
        "mobile-arm-fixed-base",
        "mobile-platform",
    ] {
        let r = reference(name);
        let n = r.model.layout.n;
        let eps = 1e-5;
        for seed in [0.37, 1.9] {
            let (q, qd) = state(&r, seed);
            let (q, qd) = (&q[..n], &qd[..n]);
            let t = |q: &[f64], qd: &[f64]| r.model.kinetic_energy(q, qd);
            let v = |q: &[f64]| r.model.potential_energy(q);
            // p_i(q, q̇) = ∂T/∂q̇_i by central differences (T is quadratic in q̇: exact up to
            // round-off).
            let p = |q: &[f64], i: usize| {
                let (mut a, mut b) = (qd.to_vec(), qd.to_vec());
                a[i] += 1.0;
                b[i] -= 1.0;
                (t(q, &a) - t(q, &b)) / 2.0
            };
            let mut h = vec![0.0; n];
            let zeros = vec![0.0; n];
            r.model.inverse_dynamics(q, qd, &zeros, true, &mut h);
            let mut scale = 0.0f64;
            for i in 0..n {
                let shifted =
                    |s: f64| -> Vec<f64> { q.iter().zip(qd).map(|(a, b)| a + s * b).collect() };
                let mdot_qd = (p(&shifted(eps), i) - p(&shifted(-eps), i)) / (2.0 * eps);
                let (mut qa, mut qb) = (q.to_vec(), q.to_vec());
                qa[i] += eps;
                qb[i] -= eps;
                let dt_dq = (t(&qa, qd) - t(&qb, qd)) / (2.0 * eps);
                let dv_dq = (v(&qa) - v(&qb)) / (2.0 * eps);
                let expected = mdot_qd - dt_dq + dv_dq;
                scale = scale.max(expected.abs());
                assert!(
                    (h[i] - expected).abs() <= 1e-7 * (1.0 + expected.abs()),
                    "{name} coordinate {i}: Newton–Euler {} vs Lagrange {expected}",
                    h[i]
                );
            }
            assert!(
                scale > 1e-4,
                "{name}: the check must see non-zero forces ({scale:e})"
            );
        }
    }
}

#[test]
fn sys_mobile_null_space_annihilates_constraints() {
    let r = reference("mobile-manipulator");
    let (n, m) = (r.model.layout.n, r.model.layout.m);
    let (q, qd) = state(&r, 0.8);
    let (a, adot_qd) = r.model.constraints(&q[..n], &qd[..n]).expect("platform");
    let mut col = [0.0; MAX_Q];
    for i in 0..m {
        r.model.null_space_column(&q[..n], i, &mut col);
        for row in &a {
            let s: f64 = (0..n).map(|j| row[j] * col[j]).sum();
            assert!(s.abs() < 1e-15, "A S column {i}: {s}");
        }
    }
    // Ȧ q̇ against a central difference of A along q̇.
    let eps = 1e-6;
    let shifted = |s: f64| -> Vec<f64> { (0..n).map(|j| q[j] + s * qd[j]).collect() };
    let (ap, _) = r.model.constraints(&shifted(eps), &qd[..n]).unwrap();
    let (am, _) = r.model.constraints(&shifted(-eps), &qd[..n]).unwrap();
    for c in 0..3 {
        let fd: f64 = (0..n)
            .map(|j| (ap[c][j] - am[c][j]) / (2.0 * eps) * qd[j])
            .sum();
        assert!(
            (fd - adot_qd[c]).abs() < 1e-8,
            "row {c}: {fd} vs {}",
            adot_qd[c]
        );
    }
}

/// The two formulations, the constraint drift, the round trip τ → q → τ and the ledger over
/// the accelerate–cruise–turn part of the scene's path.
#[test]
fn dyn_mobile_formulations_round_trip_and_ledger() {
    let r = reference("mobile-manipulator");
    let h = r.run(4.0, 0.05, Tolerances::default()).expect("run");
    let (mut gap, mut drift, mut residual, mut tau_scale) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for s in &h.samples {
        gap = gap.max(s.position_gap);
        drift = drift.max(s.drift);
        for (a, b) in s.tau.iter().zip(&s.tau_inverse) {
            residual = residual.max((a - b).abs());
            tau_scale = tau_scale.max(a.abs());
        }
    }
    assert!(gap <= 1e-9, "formulations differ by {gap:e}");
    assert!(drift <= 1e-10, "constraint drift {drift:e}");
    assert!(residual <= 1e-11 * tau_scale, "round trip {residual:e}");
    // Something happened: the platform moved and the arm swung.
    let last = h.samples.last().unwrap();
    assert!(last.q[0].hypot(last.q[1]) > 0.5, "platform travel");
    let e0 = h.samples[0].kinetic + h.samples[0].potential;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for s in &h.samples {
        let e = s.kinetic + s.potential;
        let r = e - e0 - s.work[0] - s.work[1] + s.work[2] + s.work[3];
        worst = worst.max(r.abs());
        scale = scale.max(s.work[0].abs() + s.work[1].abs());
    }
    assert!(
        worst <= 1e-10 * scale,
        "ledger residual {worst:e} of {scale:e}"
    );
}

#[test]
fn dyn_mobile_reference_backend_run() {
    let scene = load_scene("mobile-arm-fixed-base").unwrap();
    let settings = Settings {
        time: TimeStepping {
            t_end: Some(1.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let run = simulate(&scene, &settings).expect("reference run");
    assert!(run.ledger.relative_closure() < 1e-10);
    let residual = run
        .observables
        .get("seed_eq37.residual")
        .expect("closed form applies");
    let tau1 = run.observables.get("joint1.torque").unwrap();
    let peak = tau1.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let worst = residual.values.iter().fold(0.0f64, |a, v| a.max(*v));
    assert!(
        worst <= 1e-10 * peak,
        "corrected eq. 37 vs inverse dynamics: {worst:e}"
    );
    assert_eq!(run.cost.dofs, 4);
}

#[test]
fn dyn_mobile_flexible_variant_runs_as_its_rigid_limit() {
    // The reference ignores the flexible link: the flexible scene's reference run is the rigid
    // scene's, bit for bit (the two scene files differ only in that table).
    let flexible = load_scene("mobile-manipulator-flexible").unwrap();
    let mut rigid = flexible.clone();
    rigid.mobile_manipulator_mut().unwrap().flexible_link = None;
    let settings = Settings {
        time: TimeStepping {
            t_end: Some(0.5),
            ..Default::default()
        },
        ..Default::default()
    };
    let a = simulate(&flexible, &settings).unwrap();
    let b = simulate(&rigid, &settings).unwrap();
    for name in ["ee.x", "ee.y", "ee.z", "platform.heading", "joint2.angle"] {
        let (ca, cb) = (
            a.observables.get(name).unwrap(),
            b.observables.get(name).unwrap(),
        );
        assert_eq!(ca.values, cb.values, "{name}");
    }
}

#[test]
fn sys_reference_refuses_what_it_does_not_read_and_records_what_it_ran() {
    let scene = load_scene("mobile-platform").expect("catalog scene");
    let mut s = Settings::default();
    s.discretization.elements = Some(4);
    match simulate(&scene, &s) {
        Err(data::BackendError::InvalidSettings { field, message }) => {
            assert_eq!(field, "discretization.elements");
            assert!(
                message.contains("the reference backend does not read it"),
                "{message}"
            );
        }
        other => panic!("expected a refusal, got {:?}", other.map(|r| r.settings)),
    }
    let mut s = Settings::default();
    s.time.method = Some("dopri5".parse().expect("a method name"));
    let Err(data::BackendError::InvalidSettings { message, .. }) = simulate(&scene, &s) else {
        panic!("a method is refused");
    };
    assert!(
        message.contains("always adaptive Dormand–Prince"),
        "{message}"
    );
    let s = Settings {
        time: TimeStepping {
            t_end: Some(0.05),
            rtol: Some(1e-9),
            ..TimeStepping::default()
        },
        ..Settings::default()
    };
    let run = simulate(&scene, &s).expect("runs");
    assert_eq!(run.settings, s);
}
