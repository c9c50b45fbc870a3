//! The mobile manipulator with a flexible pitch link (fem::mobile): element, system and short
//! dynamic checks. Energies and generalized forces are checked against the model's own
//! definitions (material-point kinematics, T and V) by finite differences.
#![allow(clippy::needless_range_loop)]

use data::{Backend, Discretization, Scene, Settings};
use fem::FemBackend;
use fem::mobile::model::{Model, Workspace};
use fem::mobile::{self, Inputs, Run};
use nalgebra::{Matrix3, Vector3};

fn scene() -> Scene {
    data::catalog::catalog_scene("mobile-manipulator-flexible")
        .expect("catalog scene")
        .expect("valid scene")
}

fn model(elements: usize) -> Model {
    let s = scene();
    Model::new(s.mobile_manipulator().unwrap(), elements).unwrap()
}

/// A generic state: joints bent, platform turned and moving, the beam deflected in both planes
/// by more than a realistic amount (so the tip rotations' nonlinearity shows).
fn generic_state(md: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let l = md.layout;
    let mut q = vec![0.0; l.n];
    let mut nu = vec![0.0; l.m];
    let mut nudot = vec![0.0; l.m];
    q[0] = 0.3;
    q[1] = -0.2;
    q[2] = 0.7;
    q[3] = 1.1;
    q[4] = -0.4;
    q[l.q_arm..l.q_arm + 4].copy_from_slice(&[0.4, -0.5, 0.3, -0.6]);
    nu[0] = 2.0;
    nu[1] = 1.3;
    nu[l.nu_arm..l.nu_arm + 4].copy_from_slice(&[0.7, -0.9, 1.2, 0.5]);
    nudot[0] = 0.4;
    nudot[1] = -0.7;
    nudot[l.nu_arm..l.nu_arm + 4].copy_from_slice(&[1.5, -0.8, 2.0, -1.1]);
    for i in 0..l.ne {
        let k = i as f64;
        q[l.q_el + i] = 0.01 * (0.3 + 0.1 * k).sin() * if i % 2 == 1 { 4.0 } else { 1.0 };
        nu[l.nu_el + i] = 0.2 * (1.0 + 0.7 * k).cos();
        nudot[l.nu_el + i] = 3.0 * (0.5 * k).sin();
    }
    (q, nu, nudot)
}

fn reduced_mass(md: &Model, q: &[f64]) -> Vec<f64> {
    let m = md.layout.m;
    let mut mass = vec![0.0; m * m];
    let mut force = vec![0.0; m];
    let zeros = vec![0.0; m];
    let mut ws = Workspace::new(md.layout.n);
    md.evaluate(q, &zeros, &zeros, &mut ws, Some(&mut mass), &mut force);
    mass
}

fn s_times(md: &Model, q: &[f64], nu: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = md.layout.n;
    let (mut qd, mut sdn) = (vec![0.0; n], vec![0.0; n]);
    md.velocities(q, nu, &mut qd, &mut sdn);
    (qd, sdn)
}

#[test]
fn elem_mobile_beam_stiffness_tip_load_exact() {
    // K e = P at the tip v DOF (and separately at w): the Hermite cubic is nodally exact for a
    // cantilever under a tip load, v(L) = P L³/(3 EI), v′(L) = P L²/(2 EI).
    for n_el in [1, 3, 7] {
        let md = model(n_el);
        let fl = md.flex.as_ref().unwrap();
        let ne = fl.ne;
        for (field, ei) in [(0, fl.ei_out), (1, fl.ei_in)] {
            let mut k = fem::linalg::DenseLlt::new(ne);
            let mut rhs = vec![0.0; ne];
            let p = 3.0;
            rhs[ne - 4 + 2 * field] = p;
            k.factor(&fl.stiffness).unwrap();
            k.solve(&mut rhs);
            let l = fl.length;
            let tip = p * l.powi(3) / (3.0 * ei);
            let slope = p * l * l / (2.0 * ei);
            assert!(
                (rhs[ne - 4 + 2 * field] - tip).abs() < 1e-12 * tip,
                "{n_el} {field}"
            );
            assert!((rhs[ne - 3 + 2 * field] - slope).abs() < 1e-12 * slope);
            // The other plane stays unloaded.
            assert!(rhs[ne - 4 + 2 * (1 - field)].abs() < 1e-15);
        }
    }
}

#[test]
fn sys_mobile_dof_counts() {
    let s = scene();
    for n_el in [2, 4, 9] {
        let disc = Discretization {
            elements: Some(n_el),
            ..Default::default()
        };
        let plan = FemBackend.dof_plan(&s, &disc).unwrap();
        let total: usize = plan.groups.iter().map(|g| g.count).sum();
        assert_eq!(total, 2 + 4 + 4 * n_el);
        assert_eq!(plan.groups.len(), 4);
        assert_eq!(plan.groups[2].count, 2 * n_el);
        assert!(plan.groups[2].what.contains("link2"));
        assert_eq!(model(n_el).layout.m, total);
        assert_eq!(model(n_el).layout.n, total + 3);
    }
    // Default mesh.
    let plan = FemBackend.dof_plan(&s, &Discretization::default()).unwrap();
    let total: usize = plan.groups.iter().map(|g| g.count).sum();
    assert_eq!(total, 6 + 4 * mobile::DEFAULT_ELEMENTS);
}

#[test]
fn sys_mobile_rigid_scene_refused_and_bad_settings() {
    let rigid = data::catalog::catalog_scene("mobile-manipulator")
        .unwrap()
        .unwrap();
    let e = FemBackend
        .simulate(&rigid, &Settings::default())
        .unwrap_err();
    assert!(matches!(e, data::BackendError::Unsupported(_)), "{e:?}");
    let mut st = Settings::default();
    st.discretization.elements = Some(0);
    let e = FemBackend.simulate(&scene(), &st).unwrap_err();
    assert!(
        matches!(e, data::BackendError::InvalidSettings { .. }),
        "{e:?}"
    );
    let mut st = Settings::default();
    st.time.dt = Some(-1.0);
    let e = FemBackend.simulate(&scene(), &st).unwrap_err();
    assert!(
        matches!(e, data::BackendError::InvalidSettings { .. }),
        "{e:?}"
    );
    // a second-order method cannot step the reduced system: refused, naming the one that can
    let mut st = Settings::default();
    st.time.method = Some("bathe".parse().expect("a method name"));
    let e = FemBackend.simulate(&scene(), &st).unwrap_err();
    match e {
        data::BackendError::Unsupported(why) => assert!(
            why.contains("`bathe`") && why.contains("`implicit-midpoint`"),
            "{why}"
        ),
        other => panic!("{other:?}"),
    }
}

/// Skew part of Ṙ Rᵀ as a vector.
fn omega_of(r0: &Matrix3<f64>, r1: &Matrix3<f64>, rm: &Matrix3<f64>, dt: f64) -> Vector3<f64> {
    // Ṙ Rᵀ = [ω]×
    let w = (r1 - r0) / dt * rm.transpose();
    0.5 * Vector3::new(
        w[(2, 1)] - w[(1, 2)],
        w[(0, 2)] - w[(2, 0)],
        w[(1, 0)] - w[(0, 1)],
    )
}

#[test]
fn sys_mobile_kinetic_energy_matches_material_points() {
    // ½ νᵀ M̄ ν against T from the velocities of every mass element obtained by central
    // differences of their positions and orientations along q ± ε S ν.
    let md = model(3);
    let (q, nu, _) = generic_state(&md);
    let m = md.layout.m;
    let mass = reduced_mass(&md, &q);
    let mut t_matrix = 0.0;
    for i in 0..m {
        for j in 0..m {
            t_matrix += 0.5 * nu[i] * mass[i * m + j] * nu[j];
        }
    }
    let (qd, _) = s_times(&md, &q, &nu);
    let t_recursive = md.kinetic_energy(&q, &qd);
    let eps = 1e-6;
    let shifted = |s: f64| -> Vec<f64> { q.iter().zip(&qd).map(|(a, b)| a + s * b).collect() };
    let (pp, pm, p0) = (
        md.material_points(&shifted(eps)),
        md.material_points(&shifted(-eps)),
        md.material_points(&q),
    );
    let mut t_points = 0.0;
    for ((a, b), c) in pp.iter().zip(&pm).zip(&p0) {
        let v: Vec<f64> = (0..3).map(|k| (a.1[k] - b.1[k]) / (2.0 * eps)).collect();
        t_points += 0.5 * c.0 * v.iter().map(|x| x * x).sum::<f64>();
        let w = omega_of(&b.2, &a.2, &c.2, 2.0 * eps);
        // ½ ωᵀ R J Rᵀ ω.
        let r = &c.2;
        let wb: Vec<f64> = (0..3)
            .map(|k| (0..3).map(|i| r[(i, k)] * w[i]).sum())
            .collect();
        for i in 0..3 {
            for j in 0..3 {
                t_points += 0.5 * wb[i] * c.3[(i, j)] * wb[j];
            }
        }
    }
    if let Some(p) = &md.platform {
        t_points += 0.5 * p.side_spin_inertia * (nu[0] * nu[0] + nu[1] * nu[1]);
    }
    assert!(t_matrix > 0.1, "{t_matrix}");
    assert!(
        (t_matrix - t_recursive).abs() < 1e-12 * t_matrix,
        "{t_matrix} {t_recursive}"
    );
    assert!(
        (t_matrix - t_points).abs() < 1e-8 * t_matrix,
        "{t_matrix} {t_points}"
    );
}

#[test]
fn sys_mobile_generalized_forces_match_lagrange() {
    // Sᵀ(d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q) by finite differences of T(q, q̇) and V(q) (any q̇; the
    // constraint forces drop out under Sᵀ) against the model's M̄ ν̇ + b at q̇ = S ν,
    // q̈ = S ν̇ + Ṡ ν.
    let md = model(3);
    let (q, nu, nudot) = generic_state(&md);
    let (n, m) = (md.layout.n, md.layout.m);
    let (qd, sdn) = s_times(&md, &q, &nu);
    let (snd, _) = s_times(&md, &q, &nudot);
    let qdd: Vec<f64> = snd.iter().zip(&sdn).map(|(a, b)| a + b).collect();
    let t = |q: &[f64], qd: &[f64]| md.kinetic_energy(q, qd);
    let v = |q: &[f64]| md.gravity_energy(q) + md.strain_energy(q);
    // ∂T/∂q̇_a: T is quadratic in q̇, so the central difference is exact up to round-off.
    let momentum = |q: &[f64], qd: &[f64], a: usize| {
        let e = 1e-3;
        let mut p = qd.to_vec();
        p[a] += e;
        let tp = t(q, &p);
        p[a] -= 2.0 * e;
        (tp - t(q, &p)) / (2.0 * e)
    };
    let dt = 1e-4;
    let along = |s: f64| -> (Vec<f64>, Vec<f64>) {
        (
            (0..n)
                .map(|i| q[i] + s * qd[i] + 0.5 * s * s * qdd[i])
                .collect(),
            (0..n).map(|i| qd[i] + s * qdd[i]).collect(),
        )
    };
    let (qp, qdp) = along(dt);
    let (qm, qdm) = along(-dt);
    let mut lhs = vec![0.0; n];
    for a in 0..n {
        let dp = (momentum(&qp, &qdp, a) - momentum(&qm, &qdm, a)) / (2.0 * dt);
        let h = 1e-6;
        let mut x = q.clone();
        x[a] += h;
        let (tp, vp) = (t(&x, &qd), v(&x));
        x[a] -= 2.0 * h;
        let (tm, vm) = (t(&x, &qd), v(&x));
        lhs[a] = dp - (tp - tm) / (2.0 * h) + (vp - vm) / (2.0 * h);
    }
    // Project with the columns of S.
    let mut expected = vec![0.0; m];
    for i in 0..m {
        let mut e = vec![0.0; m];
        e[i] = 1.0;
        let (col, _) = s_times(&md, &q, &e);
        expected[i] = (0..n).map(|a| col[a] * lhs[a]).sum();
    }
    let mut force = vec![0.0; m];
    let mut ws = Workspace::new(n);
    md.evaluate(&q, &nu, &nudot, &mut ws, None, &mut force);
    let scale = expected.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(scale > 1.0);
    for i in 0..m {
        assert!(
            (force[i] - expected[i]).abs() < 1e-6 * scale,
            "speed {i}: {} vs {} (scale {scale})",
            force[i],
            expected[i]
        );
    }
}

fn run_short(settings: &Settings) -> data::RunResult {
    FemBackend.simulate(&scene(), settings).unwrap()
}

fn channel<'a>(r: &'a data::RunResult, name: &str) -> &'a [f64] {
    &r.observables
        .channels
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("channel {name}"))
        .values
}

#[test]
fn dyn_mobile_drift_and_ledger_closure() {
    // 1 s of the scene (acceleration phase, the arm swinging, the link ringing from its
    // undeformed start): constraint drift at round-off. The ledger residual is the midpoint
    // rule's bounded modified-energy offset, set within the first 0.05 s by the start's shock
    // to the link's unresolved modes; after it the residual must not drift (no secular
    // energy error: the scheme is symmetric and the works are booked with its own quadrature).
    let mut st = Settings::default();
    st.time.t_end = Some(1.0);
    st.time.dt = Some(2.5e-4);
    let r = run_short(&st);
    assert_eq!(r.verdict, data::StabilityVerdict::Completed);
    let drift = channel(&r, "constraint.drift")
        .iter()
        .fold(0.0f64, |a, b| a.max(*b));
    assert!(drift <= 1e-10, "drift {drift}");
    let ledger = &r.ledger;
    let closure = ledger.relative_closure();
    assert!(closure < 2e-8, "relative closure {closure}");
    let n = ledger.time.len();
    let settled = ledger.time.iter().position(|&t| t >= 0.05).unwrap();
    let scale = (0..n).fold(0.0f64, |a, k| a.max(ledger.total(k).abs()));
    let spread = (settled..n).fold(0.0f64, |a, k| {
        a.max((ledger.residual(k) - ledger.residual(settled)).abs())
    });
    assert!(
        spread < 1e-9 * scale,
        "residual drift {spread} (scale {scale})"
    );
}

/// The ee position history of a run of `md` with step h over [0, t_end].
fn ee_history(md: Model, h: f64, t_end: f64) -> Vec<Vector3<f64>> {
    let s = scene();
    let mm = s.mobile_manipulator().unwrap();
    let inputs = Inputs {
        drive: mm.platform.as_ref().map(|p| p.drive.clone()),
        arm: mm.arm.as_ref().unwrap().torques.clone(),
    };
    let (q, nu) = mobile::initial_state(&md, mm);
    let mut run = Run::new(md, inputs, q, nu, data::FemMethod::ImplicitMidpoint).unwrap();
    let bp = run.system.inputs.breakpoints(t_end);
    let out = 0.01;
    let mut hist = Vec::new();
    let n_out = (t_end / out).round() as usize;
    for k in 1..=n_out {
        mobile::advance(&mut run, h, k as f64 * out, &bp).unwrap();
        hist.push(run.system.model.end_effector(&run.state.q));
    }
    hist
}

fn max_gap(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn conv_mobile_rigid_limit_rate() {
    // fem's own rigid model (the flexible link replaced by the scene's rigid link) is the
    // EI → ∞ limit of the flexible one: the end-effector gap falls ∝ 1/EI. Same step for
    // both, so the time-discretization error of the rigid motion cancels.
    let s = scene();
    let mut rigid_scene = s.mobile_manipulator().cloned().unwrap();
    rigid_scene.flexible_link = None;
    let (h, t_end) = (1e-3, 1.0);
    let rigid = ee_history(Model::new(&rigid_scene, 1).unwrap(), h, t_end);
    let mut gaps = Vec::new();
    for factor in [10.0, 100.0] {
        let mut mm = s.mobile_manipulator().cloned().unwrap();
        let f = mm.flexible_link.as_mut().unwrap();
        f.bending_stiffness_in_plane *= factor;
        f.bending_stiffness_out_of_plane *= factor;
        let flex = ee_history(Model::new(&mm, 2).unwrap(), h, t_end);
        gaps.push(max_gap(&flex, &rigid));
    }
    let rate = (gaps[0] / gaps[1]).log10();
    assert!(
        (0.85..1.15).contains(&rate),
        "gaps {gaps:?}: observed rate EI^-{rate}"
    );
}
