//! The energy-consistent midpoint scheme (`energy-midpoint`) on whole scenes: closure with a
//! heavy tip mass, temporal order, agreement with generalized-α, adaptive steps, defaults and
//! refusals, the predictor's saving. (Default-settings closure and undamped conservation: `dyn_runs`.)

use data::{Backend, BackendError, RunResult, Scene, Settings, StabilityVerdict};
use fem::FemBackend;
use fem::chain::Chain;
use fem::method::energy_midpoint::{EnergyMidpoint, Predictor};
use fem::method::{Counters, NewtonSystem, StepContext, StepState, Stepper, Trial, Works, start};
use fem::settings::Method;

fn settings(n: Option<usize>, dt: Option<f64>, t_end: Option<f64>, method: &str) -> Settings {
    let mut st = Settings::default();
    st.discretization.elements = n;
    st.time.dt = dt;
    st.time.t_end = t_end;
    st.time.method = Some(method.parse().expect("a method name"));
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

/// Largest difference between two runs' histories of `name` (same output times).
fn max_diff(a: &RunResult, b: &RunResult, name: &str) -> f64 {
    channel(a, name)
        .iter()
        .zip(channel(b, name))
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn dyn_midpoint_is_the_default_for_free_chains_only() {
    for name in ["single-link", "two-link-free", "two-link-free-undamped"] {
        let sc = data::load_scene(name).unwrap();
        assert_eq!(
            fem::run::default_method(sc.planar_chain().unwrap()),
            Method::EnergyMidpoint,
            "{name}"
        );
    }
    for name in ["spin-up", "spin-up-axial", "cantilever", "rotating-beam"] {
        let sc = data::load_scene(name).unwrap();
        assert_eq!(
            fem::run::default_method(sc.planar_chain().unwrap()),
            Method::GeneralizedAlpha,
            "{name}"
        );
    }
    // Prescribed motion is refused with a typed `unsupported` error, not a panic.
    let sc = data::load_scene("spin-up").unwrap();
    match FemBackend.simulate(&sc, &settings(Some(4), None, Some(0.1), "energy-midpoint")) {
        Err(BackendError::Unsupported(msg)) => assert!(msg.contains("prescribed"), "{msg}"),
        other => panic!("expected unsupported, got {other:?}"),
    }
}

#[test]
fn dyn_midpoint_ledger_closes_with_a_heavy_tip_mass() {
    // single-link with 100× the tip mass (50 kg on a 1 kg link): M(q) varies strongly with the
    // deflection; generalized-α at the default step closes only to 7.7e-2 here. Measured with
    // energy-midpoint at default settings: 4.0e-12.
    let mut sc = data::load_scene("single-link").unwrap();
    let m = sc.links()[0].tip_mass.unwrap();
    sc.planar_chain_mut().unwrap().links[0].tip_mass = Some(100.0 * m);
    let r = sim(&sc, &Settings::default());
    let c = r.ledger.relative_closure();
    eprintln!("100x tip mass: closure {c:.3e}, {} steps", r.cost.steps);
    assert!(c < 1e-9, "closure {c}");
}

#[test]
fn conv_midpoint_is_second_order_in_time() {
    // Self-convergence on the joint angle and tip deflection histories of single-link over
    // 1 s (through the torque switch at 0.5 s): successive differences fall by 4 per halving.
    let sc = data::load_scene("single-link").unwrap();
    let runs: Vec<RunResult> = [4e-3, 2e-3, 1e-3]
        .iter()
        .map(|&dt| {
            sim(
                &sc,
                &settings(Some(8), Some(dt), Some(1.0), "energy-midpoint"),
            )
        })
        .collect();
    for name in ["joint1.angle", "link1.tip_deflection"] {
        let (e1, e2) = (
            max_diff(&runs[0], &runs[1], name),
            max_diff(&runs[1], &runs[2], name),
        );
        let order = (e1 / e2).log2();
        eprintln!("{name}: differences {e1:.3e}, {e2:.3e}, observed order {order:.3}");
        assert!(
            (1.8..=2.2).contains(&order),
            "{name}: observed order {order}"
        );
    }
}

#[test]
fn cross_midpoint_and_generalized_alpha_converge_to_the_same_solution() {
    // Both schemes are second order: their difference is O(h²) and falls by ~4 per halving.
    for (name, channel_name, t_end) in [
        ("single-link", "link1.tip_deflection", 1.0),
        ("two-link-free", "joint2.angle", 0.5),
    ] {
        let sc = data::load_scene(name).unwrap();
        let d: Vec<f64> = [4e-4, 2e-4]
            .iter()
            .map(|&dt| {
                let a = sim(
                    &sc,
                    &settings(Some(8), Some(dt), Some(t_end), "energy-midpoint"),
                );
                let b = sim(
                    &sc,
                    &settings(Some(8), Some(dt), Some(t_end), "generalized-alpha"),
                );
                max_diff(&a, &b, channel_name)
            })
            .collect();
        eprintln!(
            "{name} {channel_name}: midpoint − generalized-α {:.3e} → {:.3e}",
            d[0], d[1]
        );
        // Measured ratios 0.26 (single-link) and 0.09 (two-link-free); absolute differences
        // 2.3e-6 m and 8.7e-7 rad at dt = 2e-4.
        assert!(d[1] < 0.35 * d[0], "{name}: {d:?}");
        assert!(d[1] < 1e-5, "{name}: {d:?}");
    }
}

#[test]
fn dyn_midpoint_adaptive_step_meets_its_tolerance() {
    let sc = data::load_scene("single-link").unwrap();
    let mut st = settings(Some(8), None, Some(1.0), "energy-midpoint");
    st.time.rtol = Some(1e-5);
    let r = sim(&sc, &st);
    let reference = sim(
        &sc,
        &settings(Some(8), Some(1e-4), Some(1.0), "energy-midpoint"),
    );
    let diff = max_diff(&r, &reference, "link1.tip_deflection");
    let peak = channel(&reference, "link1.tip_deflection")
        .iter()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let c = r.ledger.relative_closure();
    eprintln!(
        "adaptive: {} steps, {} rejected, deviation {diff:.3e} of peak {peak:.3e}, closure {c:.2e}",
        r.cost.steps, r.cost.rejected_steps
    );
    assert!(diff < 1e-3 * peak, "{diff}");
    // Variable steps keep the exact energy balance (measured 3.3e-10 with 5360 accepted and
    // 1414 rejected steps; the step controller is generalized-α's, which rejects as often).
    assert!(c < 1e-9, "closure {c}");
}

/// Steps `scene`'s chain (16 elements a link, the default) over [0, t_end] at step h with the midpoint scheme
/// and `predictor`; returns the Newton iterations per step, the joint angles at every step end
/// and the Newton tolerance.
fn midpoint_steps(
    scene: &str,
    predictor: Predictor,
    h: f64,
    t_end: f64,
) -> (f64, Vec<Vec<f64>>, f64) {
    let sc = data::load_scene(scene).unwrap();
    let mut chain = Chain::new(sc.links(), sc.gravity(), 16).unwrap();
    let n = chain.ndof;
    let length_scale = chain.links.iter().fold(0.0f64, |a, l| a.max(l.length));
    let mut state = StepState::new(n);
    chain.initial_state(&mut state.q, &mut state.qd);
    let mut newton = NewtonSystem::new(&chain, length_scale);
    let tol = newton.tol;
    let mut counters = Counters::default();
    let mut method = EnergyMidpoint::new(n);
    method.work.predictor = predictor;
    let mut cx = StepContext {
        system: &mut chain,
        state: &mut state,
        newton: &mut newton,
        counters: &mut counters,
        adaptive: None,
        h_nominal: h,
        length_scale,
        method_works: true,
    };
    start::consistent_acceleration(&mut cx, h, 0.0).unwrap();
    let steps = (t_end / h).round() as usize;
    let mut works = Works::default();
    let mut angles = Vec::new();
    let newton_before = cx.counters.newton;
    for k in 0..steps {
        let t1 = (k + 1) as f64 * h;
        let trial = method.step(&mut cx, None, h, t1, t1).unwrap();
        assert_eq!(trial, Trial::Converged { error: None }, "step {k}");
        Stepper::<Chain>::commit(&mut method, h, &mut works);
        cx.state.swap_in(t1);
        angles.push(
            (0..cx.system.links.len())
                .map(|li| cx.system.joint_state(li, t1, &cx.state.q, &cx.state.qd).0)
                .collect(),
        );
    }
    let iterations = (cx.counters.newton - newton_before) as f64 / steps as f64;
    (iterations, angles, tol)
}

#[test]
fn dyn_midpoint_extrapolated_predictor_saves_newton_iterations() {
    // Free arms at their default mesh and step (16 elements, 10 s / 14000), 2 s. The
    // extrapolation from three mean accelerations (module docs of
    // `fem::method::energy_midpoint`; its exactness: the unit test in `work.rs`) starts the
    // Newton iteration closer to the solution than the previous step's mean acceleration:
    // measured 4.08 → 3.36 and 6.94 → 6.66 iterations per step. Linear extrapolation from the
    // last two steps doubles the error of the stiff modes' sawtooth component and raises
    // them (4.21 and 7.35).
    let h = 10.0 / 14000.0;
    const T_END: f64 = 2.0;
    for (scene, min_saving) in [("two-link-free", 0.5), ("two-link-free-undamped", 0.15)] {
        let (it_prev, prev, tol) = midpoint_steps(scene, Predictor::Previous, h, T_END);
        let (it_extr, extr, _) = midpoint_steps(scene, Predictor::Extrapolated, h, T_END);
        // The two runs solve the same equations to the Newton tolerance: each step's end
        // differs by at most about the update tolerance (in q), and such differences carry
        // over into later steps at most linearly in their number over a stretch this short
        // (measured: ≤ 5e-14 rad per step, against the tolerance 3e-11).
        let mut diff = 0.0f64;
        for (k, (a, b)) in prev.iter().zip(&extr).enumerate() {
            for (x, y) in a.iter().zip(b) {
                let d = (x - y).abs();
                diff = diff.max(d / (k + 1) as f64);
            }
        }
        eprintln!(
            "{scene}: Newton iterations per step {it_prev:.3} (previous ā) → {it_extr:.3} \
             (extrapolated); largest angle difference per step so far {diff:.2e} rad \
             (tolerance {tol:.1e})"
        );
        assert!(
            it_extr <= it_prev - min_saving,
            "{scene}: {it_prev} → {it_extr}"
        );
        assert!(diff <= tol, "{scene}: {diff:e} against {tol:e}");
    }
}
