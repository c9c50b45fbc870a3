//! The mobile manipulator with a flexible pitch link (seed 004, issue 19 item 3) by assumed
//! modes: the reduced mass matrix against the kinetic energy of sampled material points, Kane's
//! equations against finite-difference Lagrange equations of T and V, DOF counts, and a short
//! run's ledger closure and constraint drift.

// Dense checks index several arrays with one loop variable on purpose.
#![allow(clippy::needless_range_loop)]

use data::{Backend, Discretization, Scene, Settings, TimeStepping, load_scene};
use modal::ModalBackend;
use modal::mobile::model::{MobileModel, ShapeChoice, Workspace};
use modal::mobile::set_up;
use nalgebra::Vector3;

fn disc(modes: usize) -> Discretization {
    Discretization {
        modes: Some(modes),
        ..Default::default()
    }
}

/// A bent, moving state (large elastic coordinates, so that the tip rotation's nonlinearity
/// and every coupling show): q, ν.
fn state(model: &MobileModel, scene: &Scene) -> (Vec<f64>, Vec<f64>) {
    let l = model.layout;
    let mm = scene.mobile_manipulator().unwrap();
    let mut q = vec![0.0; l.n];
    let mut nu = vec![0.0; l.m];
    let pseudo = |k: usize| ((k as f64 * 1.618_033_988_75 + 0.3).fract() - 0.5) * 2.0;
    if let Some(p) = l.platform {
        q[p] = 0.4;
        q[p + 1] = -0.2;
        q[p + 2] = mm.initial.heading + 0.3;
        q[p + 3] = 1.1;
        q[p + 4] = -0.7;
    }
    let a0 = l.arm.unwrap();
    q[a0..a0 + 4].copy_from_slice(&[0.4, -0.6, 0.5, -0.3]);
    if let Some(e0) = l.elastic {
        for i in 0..2 * l.modes {
            q[e0 + i] = 0.005 * pseudo(i + 7);
        }
    }
    // Rigid speeds ~1 rad/s; elastic rates of a ringing link (ω ~ 250 rad/s × 1e-4).
    let rigid = l.m - 2 * l.modes;
    for i in 0..l.m {
        nu[i] = if i < rigid { 1.5 } else { 0.05 } * pseudo(i + 19);
    }
    (q, nu)
}

/// ½ νᵀ M_r ν against T of the bodies and of the beam's material points, each velocity by a
/// central difference of its position along q̇ = S ν (positions only from the kinematics).
#[test]
fn sys_mobile_mass_matrix_is_the_kinetic_energy_of_sampled_points() {
    let scene = load_scene("mobile-manipulator-flexible").unwrap();
    for (modes, shapes) in [(3, ShapeChoice::Poly), (4, ShapeChoice::ClampedFree)] {
        let model = MobileModel::new(scene.mobile_manipulator().unwrap(), modes, shapes).unwrap();
        let l = model.layout;
        let (q, nu) = state(&model, &scene);
        let mut ws = Workspace::new(&model);
        let tau = vec![0.0; l.m];
        model.equations(&q, &nu, &tau, &mut ws);
        let mut quad = 0.0;
        for i in 0..l.m {
            for j in 0..l.m {
                quad += 0.5 * nu[i] * ws.mass[i * l.m + j] * nu[j];
            }
        }
        let mut qd = vec![0.0; l.n];
        let mut sdn = vec![0.0; l.n];
        model.velocities(&q, &nu, &mut qd, &mut sdn);
        let zeros = vec![0.0; l.n];
        let eps = 1e-5;
        let shifted = |s: f64| -> Vec<f64> { q.iter().zip(&qd).map(|(a, b)| a + s * b).collect() };
        // Fourth-order central stencil (p(2ε), p(ε), p(−ε), p(−2ε)).
        let mut nodes = [(); 4].map(|_| ws.nodes_mut().clone());
        let fr: Vec<_> = [2.0, 1.0, -1.0, -2.0]
            .iter()
            .zip(nodes.iter_mut())
            .map(|(&s, nk)| model.kinematics(&shifted(s * eps), &zeros, &zeros, Some(nk)))
            .collect();
        let f0 = model.kinematics(&q, &zeros, &zeros, None);
        let stencil = |v: [Vector3<f64>; 4]| -> Vector3<f64> {
            (8.0 * (v[1] - v[2]) - (v[0] - v[3])) / (12.0 * eps)
        };
        let mut t = 0.0;
        for b in &model.bodies {
            let pos = |f: &modal::mobile::model::Frames| f.o[b.frame] + f.r[b.frame] * b.com;
            let v = stencil(std::array::from_fn(|s| pos(&fr[s])));
            // ω from Ṙ Rᵀ (skew), Ṙ by the same stencil.
            let r0 = &f0.r[b.frame];
            let r = |s: usize| fr[s].r[b.frame];
            let rdot = (8.0 * (r(1) - r(2)) - (r(0) - r(3))) / (12.0 * eps);
            let w_skew = rdot * r0.transpose();
            let w = Vector3::new(w_skew[(2, 1)], w_skew[(0, 2)], w_skew[(1, 0)]);
            // ω·R J Rᵀ ω = (Rᵀω)·J(Rᵀω).
            let wb = r0.transpose() * w;
            t += 0.5 * b.mass * v.dot(&v) + 0.5 * wb.dot(&(b.inertia * wb));
        }
        let fl = model.flex.as_ref().unwrap();
        for g in 0..fl.nodes.len() {
            let v = stencil(std::array::from_fn(|s| nodes[s].p[g]));
            t += 0.5 * fl.density * fl.weights[g] * v.dot(&v);
        }
        let pl = model.platform.as_ref().unwrap();
        t += 0.5 * pl.side_spin_inertia * (nu[0] * nu[0] + nu[1] * nu[1]);
        let rel = (quad - t).abs() / t;
        assert!(
            rel < 1e-10,
            "{shapes:?}: ½νᵀMν = {quad:e}, T from points = {t:e}, rel {rel:e}"
        );
        // The analytic-velocity energy used by the ledger is the same quadratic form.
        let direct = model.kinetic_energy(&q, &qd, ws.nodes_mut());
        assert!(
            (direct - quad).abs() < 1e-13 * quad,
            "{direct:e} vs {quad:e}"
        );
    }
}

/// Kane's M_r ν̇ − (Q_r − bias) against Sᵀ(d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q − Q) with every
/// derivative of T and V by central differences.
#[test]
fn sys_mobile_forces_match_finite_difference_lagrange_equations() {
    let scene = load_scene("mobile-manipulator-flexible").unwrap();
    let mut model =
        MobileModel::new(scene.mobile_manipulator().unwrap(), 3, ShapeChoice::Poly).unwrap();
    // The stiffness force −K q would dominate every inertial term at this deflection; the
    // inertial, gravity and friction terms are checked with EI = 0 (K q against ∂U/∂q below).
    let strain_model = model.clone();
    {
        let fl = model.flex.as_mut().unwrap();
        fl.ei_in = 0.0;
        fl.ei_out = 0.0;
    }
    let l = model.layout;
    let (n, m) = (l.n, l.m);
    let (q, nu) = state(&model, &scene);
    let nud: Vec<f64> = (0..m).map(|i| 0.7 * ((i as f64 * 0.77).sin())).collect();
    let mut ws = Workspace::new(&model);
    let tau = vec![0.0; m];
    model.equations(&q, &nu, &tau, &mut ws);
    let kane: Vec<f64> = (0..m)
        .map(|i| (0..m).map(|j| ws.mass[i * m + j] * nud[j]).sum::<f64>() - ws.force[i])
        .collect();
    let mut nodes = ws.nodes_mut().clone();
    let mut qd = vec![0.0; n];
    let mut sdn = vec![0.0; n];
    model.velocities(&q, &nu, &mut qd, &mut sdn);
    let mut qdd = sdn.clone();
    let mut col = vec![0.0; n];
    let mut scratch = vec![0.0; n];
    let mut s_cols = vec![vec![0.0; n]; m];
    for i in 0..m {
        let mut e = vec![0.0; m];
        e[i] = 1.0;
        model.velocities(&q, &e, &mut col, &mut scratch);
        s_cols[i].copy_from_slice(&col);
        for a in 0..n {
            qdd[a] += col[a] * nud[i];
        }
    }
    let mut kin = |q: &[f64], qd: &[f64]| model.kinetic_energy(q, qd, &mut nodes);
    let mut nodes2 = ws.nodes_mut().clone();
    let mut pot = |q: &[f64]| model.gravity_energy(q, &mut nodes2) + model.strain_energy(q);
    // ∂T/∂q̇ₐ: T is quadratic in q̇, so the central difference is exact up to round-off.
    let mut dt_dqd = |q: &[f64], qd: &[f64], a: usize| -> f64 {
        let h = 1e-3;
        let (mut p, mut mi) = (qd.to_vec(), qd.to_vec());
        p[a] += h;
        mi[a] -= h;
        (kin(q, &p) - kin(q, &mi)) / (2.0 * h)
    };
    // O(ε²) truncation: 1e-4 leaves ~1e-7 of the force scale, 2e-5 ~4e-9.
    let eps = 2e-5;
    let mut lagrange = vec![0.0; n];
    for a in 0..n {
        let along = |s: f64| -> (Vec<f64>, Vec<f64>) {
            (
                (0..n)
                    .map(|k| q[k] + s * qd[k] + 0.5 * s * s * qdd[k])
                    .collect(),
                (0..n).map(|k| qd[k] + s * qdd[k]).collect(),
            )
        };
        let (q1, qd1) = along(eps);
        let (q0, qd0) = along(-eps);
        let ddt = (dt_dqd(&q1, &qd1, a) - dt_dqd(&q0, &qd0, a)) / (2.0 * eps);
        lagrange[a] = ddt;
    }
    let h = 1e-6;
    for a in 0..n {
        let (mut p, mut mi) = (q.clone(), q.clone());
        p[a] += h;
        mi[a] -= h;
        lagrange[a] -= (kin(&p, &qd) - kin(&mi, &qd)) / (2.0 * h);
        lagrange[a] += (pot(&p) - pot(&mi)) / (2.0 * h);
    }
    // Q = −D q̇ on the wheel and joint coordinates (no inputs).
    let pl = l.platform.unwrap();
    let side = model.platform.as_ref().unwrap().side_friction;
    lagrange[pl + 3] += side * qd[pl + 3];
    lagrange[pl + 4] += side * qd[pl + 4];
    let a0 = l.arm.unwrap();
    for i in 0..4 {
        lagrange[a0 + i] += model.joint_friction[i] * qd[a0 + i];
    }
    let scale = kane.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    for i in 0..m {
        let reduced: f64 = (0..n).map(|a| s_cols[i][a] * lagrange[a]).sum();
        assert!(
            (reduced - kane[i]).abs() < 1e-7 * scale,
            "speed {i}: Lagrange {reduced:e}, Kane {:e} (scale {scale:e})",
            kane[i]
        );
    }
    // Stiffness: the elastic rows of −(Q_r − bias) gain exactly ∂U/∂q.
    let mut ws_k = Workspace::new(&strain_model);
    strain_model.equations(&q, &nu, &tau, &mut ws_k);
    let e0 = l.elastic.unwrap();
    let s0 = e0 - l.speed_shift();
    for i in 0..2 * l.modes {
        let (mut p, mut mi) = (q.clone(), q.clone());
        let h = 1e-6;
        p[e0 + i] += h;
        mi[e0 + i] -= h;
        let du = (strain_model.strain_energy(&p) - strain_model.strain_energy(&mi)) / (2.0 * h);
        let kq = ws.force[s0 + i] - ws_k.force[s0 + i];
        assert!(
            (kq - du).abs() < 1e-8 * du.abs().max(1.0),
            "elastic {i}: K q {kq:e}, ∂U/∂q {du:e}"
        );
    }
}

#[test]
fn sys_mobile_dof_counts() {
    let backend = ModalBackend;
    for (name, modes, want) in [
        ("mobile-manipulator", 3, 6),
        ("mobile-platform", 3, 2),
        ("mobile-arm-fixed-base", 3, 4),
        ("mobile-manipulator-flexible", 3, 12),
        ("mobile-manipulator-flexible", 5, 16),
    ] {
        let scene = load_scene(name).unwrap();
        let plan = backend.dof_plan(&scene, &disc(modes)).unwrap();
        assert_eq!(plan.total(), want, "{name} at {modes} modes: {plan:?}");
        let (model, _) = set_up(
            scene.mobile_manipulator().unwrap(),
            &disc(modes).modal().unwrap(),
        )
        .unwrap();
        assert_eq!(model.layout.m, want, "{name}");
        let elastic = model.layout.elastic.is_some();
        assert_eq!(elastic, name.ends_with("flexible"), "{name}");
        if !elastic {
            assert_eq!(model.node_count(), 0, "a rigid scene builds no beam");
        }
    }
}

#[test]
fn dyn_mobile_short_run_closes_ledger_and_keeps_constraints() {
    let scene = load_scene("mobile-manipulator-flexible").unwrap();
    let settings = Settings {
        discretization: disc(2),
        time: TimeStepping {
            t_end: Some(0.2),
            ..Default::default()
        },
    };
    let run = ModalBackend.simulate(&scene, &settings).unwrap();
    assert!(matches!(run.verdict, data::StabilityVerdict::Completed));
    assert_eq!(run.cost.dofs, 10);
    let closure = run.ledger.relative_closure();
    assert!(closure < 1e-8, "ledger closure {closure:e}");
    let drift = run.observables.get("constraint.drift").unwrap();
    let peak = drift.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(peak <= 1e-10, "drift {peak:e}");
    // The link rings under gravity from its undeformed start: the tip moves.
    let w = run.observables.get("link2.tip_in_plane").unwrap();
    assert!(
        w.values.iter().any(|v| v.abs() > 1e-6),
        "no in-plane deflection"
    );
}

#[test]
fn sys_mobile_modes_are_the_held_links_bending_pairs() {
    let scene = load_scene("mobile-manipulator-flexible").unwrap();
    let settings = Settings {
        discretization: disc(4),
        ..Default::default()
    };
    let r = ModalBackend.modes(&scene, &settings, 4).unwrap();
    assert_eq!(r.frequencies_hz.len(), 4);
    // Equal EI in and out of plane: the first two modes (one per direction) have nearly
    // equal frequencies (they differ only through the distal arm's inertia at the tip).
    let (f1, f2) = (r.frequencies_hz[0], r.frequencies_hz[1]);
    assert!(f1 > 0.0 && (f2 - f1) / f1 < 0.05, "{f1} {f2}");
    assert_ne!(r.kinds[0], r.kinds[1]);
    // The rigid scene has no elastic modes: refused clearly.
    let rigid = load_scene("mobile-manipulator").unwrap();
    assert!(matches!(
        ModalBackend.modes(&rigid, &settings, 4),
        Err(data::BackendError::Unsupported(_))
    ));
}
