//! Unilateral tip contact in the `energy-midpoint` scheme (issue 7, seed 000): the tip
//! Jacobian, located events, the impact map, the constrained phase and its ledger, the resting
//! normal force against statics computed from the same model, impulse convergence.

use data::{Backend, Event, RunResult, Scene, Settings, StabilityVerdict};
use fem::FemBackend;
use fem::chain::Chain;

fn scene(name: &str) -> Scene {
    data::catalog::load_scene(name).unwrap()
}

fn settings(n: Option<usize>, t_end: Option<f64>) -> Settings {
    let mut st = Settings::default();
    st.discretization.elements = n;
    st.time.t_end = t_end;
    st
}

fn sim(sc: &Scene, st: &Settings) -> RunResult {
    let r = FemBackend.simulate(sc, st).unwrap();
    assert_eq!(r.verdict, StabilityVerdict::Completed, "{}", sc.name);
    r
}

fn channel<'a>(r: &'a RunResult, name: &str) -> &'a [f64] {
    &r.observables.get(name).unwrap().values
}

/// A deflected, rotated state of the barhorst chain (every DOF non-zero).
fn bent_state(chain: &Chain) -> Vec<f64> {
    (0..chain.ndof)
        .map(|i| 0.02 * ((i as f64 * 1.7).sin() + 0.3))
        .collect()
}

#[test]
fn elem_tip_jacobian_matches_finite_differences_and_forward_velocity() {
    let sc = scene("barhorst-case1");
    let mut chain = Chain::new(&sc.links, sc.gravity.as_ref(), 6).unwrap();
    let n = chain.ndof;
    let q = bent_state(&chain);
    let mut jac = vec![0.0; 2 * n];
    let r = chain.tip_jacobian(0.0, 1, &q, &mut jac);
    let mut tips = [[0.0; 2]; 2];
    chain.tip_positions(0.0, &q, &mut tips);
    assert!((r[0] - tips[1][0]).abs() < 1e-15 && (r[1] - tips[1][1]).abs() < 1e-15);
    // Central differences of the tip position (truncation ~ε², round-off ~1e-16/ε).
    let eps = 1e-6;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for j in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += eps;
        qm[j] -= eps;
        let (mut tp, mut tm) = ([[0.0; 2]; 2], [[0.0; 2]; 2]);
        chain.tip_positions(0.0, &qp, &mut tp);
        chain.tip_positions(0.0, &qm, &mut tm);
        for d in 0..2 {
            let fd = (tp[1][d] - tm[1][d]) / (2.0 * eps);
            worst = worst.max((fd - jac[d * n + j]).abs());
            scale = scale.max(fd.abs());
        }
    }
    assert!(worst <= 1e-8 * scale, "J vs FD: {worst:.3e} (scale {scale})");
    // J q̇ is the tip velocity of the residual's forward kinematic pass (to round-off).
    let qd: Vec<f64> = (0..n).map(|i| ((i as f64) * 0.37).cos()).collect();
    let zero = vec![0.0; n];
    let [_, v, _] = chain.tip_motion(0.0, 1, &q, &qd, &zero);
    for d in 0..2 {
        let jv: f64 = (0..n).map(|j| jac[d * n + j] * qd[j]).sum();
        assert!((jv - v[d]).abs() <= 1e-12 * v[d].abs().max(1.0), "{jv} vs {}", v[d]);
    }
    // The convective term n̂·J̇q̇: d/dt (J q̇) along q(t) = q + t q̇ at fixed q̇ is J̇q̇.
    let dt = 1e-5;
    let mut jv = [[0.0; 2]; 2];
    for (k, s) in [1.0, -1.0].into_iter().enumerate() {
        let qs: Vec<f64> = (0..n).map(|i| q[i] + s * dt * qd[i]).collect();
        let [_, vs, _] = chain.tip_motion(0.0, 1, &qs, &qd, &zero);
        jv[k] = vs;
    }
    let [_, _, a] = chain.tip_motion(0.0, 1, &q, &qd, &zero);
    for d in 0..2 {
        let fd = (jv[0][d] - jv[1][d]) / (2.0 * dt);
        assert!((fd - a[d]).abs() <= 1e-6 * a[d].abs().max(1.0), "J̇q̇ {fd} vs {}", a[d]);
    }
}

#[test]
#[ignore]
fn explore() {
    let sc = scene(&std::env::var("SC").unwrap_or("barhorst-case1-tipmass".into()));
    let te: f64 = std::env::var("TE").map(|s| s.parse().unwrap()).unwrap_or(0.5);
    let ne: Option<usize> = std::env::var("NE").ok().map(|s| s.parse().unwrap());
    let t0 = std::time::Instant::now();
    let r = FemBackend.simulate(&sc, &settings(ne, Some(te))).unwrap();
    println!("wall {:.2}s verdict {:?} steps {}", t0.elapsed().as_secs_f64(), r.verdict, r.cost.steps);
    for e in &r.events {
        match e {
            Event::Impact { t, impulse, momentum_residual, normal_velocity_after, kinetic_energy_lost, velocity_before, .. } => {
                let _ = velocity_before;
                println!("impact t={t:.9} L={impulse:.6e} res={momentum_residual:.2e} vn+={normal_velocity_after:.2e} dKE={kinetic_energy_lost:.4e}")
            }
            other => println!("{other:?}"),
        }
    }
    println!("closure {:.3e}", r.ledger.relative_closure());
    for c in ["contact1.max_gap", "contact1.max_normal_velocity", "contact1.normal_force"] {
        let v = channel(&r, c);
        println!("{c} last {:.4e}", v[v.len() - 1]);
    }
}
