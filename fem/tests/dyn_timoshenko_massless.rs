//! Timoshenko links without rotary inertia and without Kelvin–Voigt, in a run without contact
//! (`barhorst-case1-timoshenko` free, Kelvin–Voigt removed, both joint dampers 5): the
//! energy-midpoint steps end on the algebraic balances of the massless sections
//! (`fem::events::massless`, `Balance::Algebraic`), which keeps the undamped, almost massless
//! turn of link 2's frame through link 1's tip section from growing at fine steps.

use data::{Backend, RunResult, Scene, Settings, StabilityVerdict};
use fem::FemBackend;

/// The catalog arm without its contact and without Kelvin–Voigt, both joints damped by 5.
fn free_undamped_sections() -> Scene {
    let mut sc = data::catalog::load_scene("barhorst-case1-timoshenko").unwrap();
    let pc = sc.planar_chain_mut().unwrap();
    pc.contacts.clear();
    for l in &mut pc.links {
        l.kelvin_voigt = None;
        l.joint.damping = Some(5.0);
    }
    sc
}

fn run(sc: &Scene, method: &str, dt: f64, t_end: f64) -> RunResult {
    let mut st = Settings::default();
    st.discretization.elements = Some(8);
    st.time.dt = Some(dt);
    st.time.t_end = Some(t_end);
    st.time.method = Some(method.parse().expect("a method name"));
    let r = FemBackend.simulate(sc, &st).unwrap();
    assert_eq!(
        r.verdict,
        StabilityVerdict::Completed,
        "{method}: {:?}",
        r.events.last()
    );
    r
}

/// max_t |a − b| / max_t |b| of a channel.
fn relative_difference(a: &RunResult, b: &RunResult, name: &str) -> f64 {
    let (x, y) = (
        &a.observables.get(name).unwrap().values,
        &b.observables.get(name).unwrap().values,
    );
    let diff = x
        .iter()
        .zip(y)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    diff / y.iter().fold(0.0f64, |m, q| m.max(q.abs()))
}

#[test]
fn dyn_energy_midpoint_steps_undamped_massless_sections_at_fine_steps() {
    // Without the algebraic balances the iteration stopped at t = 0.2497 s here (8 elements,
    // dt 2.5e-5): the step-to-step alternation of the child-frame direction grew
    // exponentially (e-folding ≈ 7 ms from t ≈ 0.15 s) until no Newton iteration converged.
    let sc = free_undamped_sections();
    let (dt, t_end) = (2.5e-5, 0.26);
    let em = run(&sc, "energy-midpoint", dt, t_end);
    let im = run(&sc, "implicit-midpoint", dt, t_end);
    // The ledger closes to the accumulated Newton tolerance (measured 2.4e-10 over 0.4 s).
    let closure = em.ledger.relative_closure();
    assert!(closure <= 2e-9, "ledger closure {closure:.3e}");
    // The two second-order schemes agree far within their time-discretization error
    // (measured 2.6e-10 and 2.2e-9 over 0.4 s; implicit-midpoint's own dt 2.5e-5 → 1.25e-5
    // difference is 2.8e-7 and 2.2e-6).
    for name in ["joint1.angle", "joint2.angle"] {
        let d = relative_difference(&em, &im, name);
        assert!(d <= 1e-7, "{name}: {d:.3e} of its peak");
    }
}
