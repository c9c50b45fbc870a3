//! The finite-element rocket (fem/src/rocket): element operators against direct quadrature and
//! finite differences, DOF counts, free-free frequencies of a uniform case, the rocket equation
//! and the energy ledger.

use data::scene::InitialShape;
use data::{Backend, Settings};
use fem::FemBackend;
use fem::rocket::{self, model::DOFS_PER_NODE};

fn scene() -> data::Scene {
    data::load_scene("rocket").unwrap()
}

fn settings(elements: Option<usize>, t_end: Option<f64>) -> Settings {
    let mut s = Settings::default();
    s.discretization.elements = elements;
    s.time.t_end = t_end;
    s
}

/// Composite Simpson rule of f on [a, b] with n (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
    }
    s * h / 3.0
}

#[test]
fn elem_rocket_kinetic_energy_matches_direct_quadrature() {
    // Velocity fields the elements represent exactly (u̇ linear, ẇ cubic): ½vᵀM(t)v must equal
    // ½∫m(x, t)(u̇² + ẇ²)dx + ½ΣM_j(U̇² + Ẇ²) computed here from the scene by Simpson's rule
    // (stage by stage; error ~1e-15 relative at 20 000 intervals for these polynomials).
    let sc = scene();
    let r = sc.rocket().unwrap();
    let model = rocket::build(
        sc.rocket().unwrap(),
        &settings(Some(7), None).fem().unwrap(),
    )
    .unwrap();
    let ud = |x: f64| 3.0 - 0.02 * x;
    let wd = |x: f64| 0.5 + 0.01 * x - 3e-4 * x * x + 2e-6 * x * x * x;
    let wd1 = |x: f64| 0.01 - 6e-4 * x + 6e-6 * x * x;
    let mut v = vec![0.0; model.n];
    for i in 0..model.nodes {
        let x = i as f64 * model.h;
        v[DOFS_PER_NODE * i] = ud(x);
        v[DOFS_PER_NODE * i + 1] = wd(x);
        v[DOFS_PER_NODE * i + 2] = wd1(x);
    }
    let md: Vec<(f64, f64)> = vec![(1.5, -2.0), (0.25, 4.0), (-1.0, 0.5)];
    for (j, &(a, b)) in md.iter().enumerate() {
        let (iu, iw) = model.mass_dofs(j);
        v[iu] = a;
        v[iw] = b;
    }
    let t = 0.05;
    let g = r.gravity;
    let mut direct = 0.0;
    let mut x0 = 0.0;
    for (k, st) in r.stages.iter().enumerate() {
        let m = if k == 0 {
            (st.weight_per_length - st.burn_rate * t) / g
        } else {
            st.weight_per_length / g
        };
        direct += 0.5
            * m
            * simpson(
                |x| ud(x).powi(2) + wd(x).powi(2),
                x0,
                x0 + st.length,
                20_000,
            );
        x0 += st.length;
    }
    for (dm, &(a, b)) in r.discrete_masses.iter().zip(&md) {
        direct += 0.5 * dm.weight / g * (a * a + b * b);
    }
    let fe = rocket::kinetic(&model, t, &v);
    assert!(
        (fe - direct).abs() <= 1e-12 * direct,
        "kinetic energy {fe} vs direct quadrature {direct}"
    );
}

#[test]
fn elem_rocket_forces_are_minus_energy_gradient() {
    // Beam (linear + cubic ½EA u′w′²) and discrete springs at a fixed axis angle: the force
    // vector is −∂V/∂q, checked by central differences of the energies.
    let sc = scene();
    let model = rocket::build(
        sc.rocket().unwrap(),
        &settings(Some(9), None).fem().unwrap(),
    )
    .unwrap();
    let n = model.n;
    let q: Vec<f64> = (0..n)
        .map(|i| 1e-2 * ((i as f64) * 0.73).sin() + 2e-3 * ((i as f64) * 0.21).cos())
        .collect();
    let zero = vec![0.0; n];
    let phi = 0.3;
    let energy = |q: &[f64]| {
        let mut scratch = vec![0.0; n];
        model.strain_energy(q) + model.add_spring_forces(phi, q, &zero, &mut scratch).0
    };
    let mut f = vec![0.0; n];
    model.add_elastic_forces(&q, &mut f);
    model.add_spring_forces(phi, &q, &zero, &mut f);
    let scale = f.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for k in 0..n {
        let eps = 1e-6;
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[k] += eps;
        qm[k] -= eps;
        let d = (energy(&qp) - energy(&qm)) / (2.0 * eps);
        // Central difference of a cubic energy: truncation eps²·V‴ ≪ round-off
        // ε·V/eps ≈ 1e-16·1e6/1e-6 = 1e-4 against forces of order 1e6.
        assert!(
            (f[k] + d).abs() <= 1e-8 * scale,
            "dof {k}: force {} vs −dV/dq {}",
            f[k],
            -d
        );
    }
}

#[test]
fn sys_rocket_dof_counts() {
    let sc = scene();
    let nm = sc.rocket().unwrap().discrete_masses.len();
    for (elements, expect) in [(None, 3 * 31 + 2 * nm), (Some(10), 3 * 11 + 2 * nm)] {
        let plan = FemBackend
            .dof_plan(&sc, &settings(elements, None).discretization)
            .unwrap();
        assert_eq!(plan.total(), expect);
        let model = rocket::build(
            sc.rocket().unwrap(),
            &settings(elements, None).fem().unwrap(),
        )
        .unwrap();
        assert_eq!(model.n, expect);
    }
    let run = FemBackend
        .simulate(&sc, &settings(Some(10), Some(2e-4)))
        .unwrap();
    assert_eq!(run.cost.dofs, 3 * 11 + 2 * nm);
}

#[test]
fn sys_rocket_uniform_free_free_frequencies() {
    // A uniform case without discrete masses: first bending ω = (β₁L)²√(EI/(mL⁴)) with
    // β₁L = 4.730040745 (cosh βL cos βL = 1), first axial ω = π/L √(EA/m).
    let mut sc = scene();
    let r = sc.rocket_mut().unwrap();
    let s1 = r.stages[0].clone();
    r.stages[1].area = s1.area;
    r.stages[1].inertia = s1.inertia;
    r.stages[1].weight_per_length = s1.weight_per_length;
    r.discrete_masses.clear();
    r.springs.clear();
    let (l, e, m) = (
        r.length(),
        r.youngs_modulus,
        s1.weight_per_length / r.gravity,
    );
    let bend = 4.730_040_745_f64.powi(2) * (e * s1.inertia / (m * l.powi(4))).sqrt();
    let axial = std::f64::consts::PI / l * (e * s1.area / m).sqrt();
    let res = FemBackend.modes(&sc, &settings(Some(30), None), 4).unwrap();
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let first = |kind: &str| {
        res.kinds
            .iter()
            .position(|k| k == kind)
            .map(|i| res.frequencies_hz[i])
            .unwrap()
    };
    // Hermite cubics: bending error O(h⁴) ≈ 1e-7 at 30 elements. Linear axial elements with a
    // consistent mass overestimate ω by (kh)²/24 = (π/30)²/24 = 4.6e-4 to leading order.
    let eb = (first("bending") - hz(bend)).abs() / hz(bend);
    let ea = (first("axial") - hz(axial)) / hz(axial);
    assert!(eb < 1e-5, "bending {} vs {} Hz", first("bending"), hz(bend));
    let lead = (std::f64::consts::PI / 30.0).powi(2) / 24.0;
    assert!(
        (ea - lead).abs() < 0.05 * lead,
        "axial {} vs {} Hz: relative {ea:.3e}, leading-order error {lead:.3e}",
        first("axial"),
        hz(axial)
    );
}

#[test]
fn dyn_rocket_rigid_translation_follows_rocket_equation() {
    // Straight case at 90°: the momentum-averaged velocity obeys M dV/dt = Q̇v_e − Mg up to what
    // the burnt mass carries relative to the mean (its elastic axial velocity), so
    // V(t) = v_e ln(M₀/M(t)) − g t, with M(t) = M₀ − ṁL₁t from the scene.
    let mut sc = scene();
    let r = sc.rocket_mut().unwrap();
    r.initial_shape = InitialShape::Straight;
    let r = sc.rocket().unwrap();
    let g = r.gravity;
    let m0: f64 = r
        .stages
        .iter()
        .map(|s| s.weight_per_length * s.length)
        .sum::<f64>()
        / g
        + r.discrete_masses.iter().map(|d| d.weight).sum::<f64>() / g;
    let flow = r.stages[0].burn_rate / g * r.stages[0].length;
    let t_end = 0.02;
    let run = FemBackend
        .simulate(&sc, &settings(None, Some(t_end)))
        .unwrap();
    let obs = &run.observables;
    let vy = obs.value_at(data::channel::ROCKET_VY, t_end).unwrap();
    let mass = obs.value_at(data::channel::ROCKET_MASS, t_end).unwrap();
    let m_t = m0 - flow * t_end;
    let reference = r.exhaust_velocity * (m0 / m_t).ln() - g * t_end;
    assert!((mass - m_t).abs() <= 1e-13 * m0, "mass {mass} vs {m_t}");
    // The burnt stage-1 material leaves with its elastic axial velocity u̇ (≲ 1 in/s at the
    // thrust's step wave): a momentum defect of at most ṁL₁ t·|u̇|/M ≈ 3e-3 in/s of V ≈ 360 in/s
    // here, i.e. ≲ 1e-5 relative.
    assert!(
        (vy - reference).abs() <= 1e-5 * reference,
        "vY {vy} vs rocket equation {reference}: relative {:.3e}",
        (vy - reference).abs() / reference
    );
    let vx = obs.value_at(data::channel::ROCKET_VX, t_end).unwrap();
    assert!(
        vx.abs() <= 1e-12 * reference,
        "straight case drifts sideways: {vx}"
    );
}

#[test]
fn dyn_rocket_energy_ledger_closes() {
    // Implicit midpoint: kinetic and gravity balances are exact identities of the scheme with
    // the outflow booked from the mass change; strain energy's cubic term leaves O(h³) per step.
    let sc = scene();
    let run = FemBackend
        .simulate(&sc, &settings(Some(15), Some(5e-3)))
        .unwrap();
    let closure = run.ledger.relative_closure();
    assert!(closure < 1e-8, "ledger closure {closure:.3e}");
}

#[test]
fn elem_rocket_springs_between_masses_ride_with_the_body() {
    // The catalog rocket couples masses at 125, 130 and 135 in by transverse springs. Turned
    // rigidly by a finite angle and moved, the whole body (case and masses) stores no energy in
    // them and they exert no force; in launch axes they would be stretched by α(x_a − x_b).
    let sc = scene();
    let model = rocket::build(
        sc.rocket().unwrap(),
        &settings(Some(12), None).fem().unwrap(),
    )
    .unwrap();
    let n = model.n;
    let (alpha, shift) = (0.2_f64, (0.7, -1.3));
    let mut q = vec![0.0; n];
    let (c, s) = (alpha.cos(), alpha.sin());
    let rigid = |x: f64| (x * c - x + shift.0, x * s + shift.1);
    for node in 0..model.nodes {
        let x = model.x_ref[DOFS_PER_NODE * node];
        let (u, w) = rigid(x);
        q[DOFS_PER_NODE * node] = u;
        q[DOFS_PER_NODE * node + 1] = w;
        q[DOFS_PER_NODE * node + 2] = s;
    }
    for j in 0..model.masses.len() {
        let (iu, iw) = model.mass_dofs(j);
        let (u, w) = rigid(model.x_ref[iu]);
        q[iu] = u;
        q[iw] = w;
    }
    let mut only_couplings = model.clone();
    only_couplings.masses.iter_mut().for_each(|m| {
        m.ku = 0.0;
        m.kw = 0.0;
    });
    let mut f = vec![0.0; n];
    let (energy, _) = only_couplings.add_spring_forces(alpha, &q, &vec![0.0; n], &mut f);
    let k = model.couplings.iter().map(|c| c.kw).fold(0.0, f64::max);
    // the largest stretch the rotation would cause in launch axes: α |x_a − x_b|
    let spacing = model
        .couplings
        .iter()
        .map(|c| (model.x_ref[model.mass_dofs(c.a).0] - model.x_ref[model.mass_dofs(c.b).0]).abs())
        .fold(0.0, f64::max);
    assert!(
        spacing > 0.0,
        "the catalog rocket couples masses at different stations"
    );
    let launch_axis_stretch = alpha * spacing;
    assert!(
        energy <= 1e-20 * k * launch_axis_stretch.powi(2),
        "energy of a rigid motion: {energy:e}"
    );
    let fmax = f.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(fmax <= 1e-10 * k * launch_axis_stretch, "force {fmax:e}");
    // so the free-free eigenproblem keeps its three rigid-body modes (rocket_modes checks
    // them and fails otherwise)
    let modes = FemBackend.modes(&sc, &settings(Some(30), None), 4).unwrap();
    assert_eq!(modes.frequencies_hz.len(), 4);
}

#[test]
fn sys_rocket_mass_held_by_no_spring_is_refused() {
    // Case II's middle mass hangs on the mass-to-mass springs only; without their transverse
    // stiffness nothing holds it across the axis.
    let mut sc = data::load_scene("rocket-case2").unwrap();
    for s in &mut sc.rocket_mut().unwrap().springs {
        s.transverse_stiffness = 0.0;
    }
    for result in [
        FemBackend
            .modes(&sc, &settings(Some(30), None), 4)
            .map(|_| ()),
        FemBackend
            .simulate(&sc, &settings(Some(10), Some(1e-4)))
            .map(|_| ()),
    ] {
        match result {
            Err(data::BackendError::Unsupported(why)) => {
                assert!(
                    why.contains("discrete_mass[1]") && why.contains("drift"),
                    "{why}"
                )
            }
            other => panic!("expected a refusal, got {other:?}"),
        }
    }
    // with its springs it is a regular free-free body
    let sc = data::load_scene("rocket-case2").unwrap();
    assert!(FemBackend.modes(&sc, &settings(Some(30), None), 4).is_ok());
}
