//! The 3-D payload link stepped by every implicit method of the registry (implicit midpoint,
//! generalized-α, energy-midpoint), on a free base under the bang-bang torque
//! (`single-link-3d`) and on a base turning at a prescribed constant rate
//! (`single-link-3d-constant-rate`). All three are second order: each differs from the
//! converged motion by C h² + O(h³), so any two differ from each other by
//! (C_a − C_b) h² + O(h³), and halving the step must divide their difference by 4 (observed order 2, within
//! the same ±0.2 as the oscillator of `sys_system_trait.rs`). A scheme that lost an order
//! anywhere (a law sampled at the wrong time, a Newton matrix inconsistent with its residual
//! that stops early, a wrong restart at the torque switch) would leave an O(h) difference.
//!
//! On the prescribed base the field equations are linear in d with the constant mass M, and V
//! is quadratic: energy-midpoint's discrete gradient is then the midpoint gradient and the two
//! midpoint schemes are the same map. Their difference there is held to what their Newton
//! iterations leave: per step at most the update tolerance 1e-11·L
//! ([`fem::method::NewtonSystem`]), summed over the steps.

use data::{Backend, RunResult, Scene, Settings};
use fem::FemBackend;
use fem::settings::Method;

fn run(sc: &Scene, method: Method, t_end: f64, dt: f64) -> RunResult {
    let mut s = Settings::default();
    s.discretization.elements = Some(6);
    s.time.t_end = Some(t_end);
    s.time.dt = Some(dt);
    s.time.method = Some(method.into());
    let r = FemBackend.simulate(sc, &s).expect("run");
    assert_eq!(r.verdict, data::StabilityVerdict::Completed, "{method:?}");
    r
}

/// Largest distance between the payload positions of two runs over their common samples.
fn payload_difference(a: &RunResult, b: &RunResult) -> f64 {
    let ch = |r: &'_ RunResult, c: &str| r.observables.get(c).expect(c).values.clone();
    let (pa, pb) = (
        ["payload.X", "payload.Y", "payload.Z"].map(|c| ch(a, c)),
        ["payload.X", "payload.Y", "payload.Z"].map(|c| ch(b, c)),
    );
    (0..pa[0].len())
        .map(|k| {
            (0..3)
                .map(|c| (pa[c][k] - pb[c][k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn dyn_payload_implicit_methods_agree_to_second_order() {
    let methods = [
        Method::ImplicitMidpoint,
        Method::GeneralizedAlpha,
        Method::EnergyMidpoint,
    ];
    // Steps well inside the resolved range of the bending modes that move the payload (the
    // six-element rod's first bending modes are tens of Hz); the stretch crosses the torque
    // switch of single-link-3d at 0.5 s.
    for (name, t_end, dt) in [
        ("single-link-3d", 0.6, 1e-3),
        ("single-link-3d-constant-rate", 0.2, 1e-3),
    ] {
        let sc = data::load_scene(name).expect("catalog scene");
        let runs: Vec<[RunResult; 3]> = [dt, dt / 2.0, dt / 4.0]
            .iter()
            .map(|&h| methods.map(|m| run(&sc, m, t_end, h)))
            .collect();
        let prescribed = sc
            .payload_link()
            .expect("payload link")
            .base
            .prescribed
            .is_some();
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            let diff: Vec<f64> = runs
                .iter()
                .map(|r| payload_difference(&r[a], &r[b]))
                .collect();
            if prescribed && (a, b) == (0, 2) {
                let length = sc.payload_link().expect("payload link").length;
                let steps = (t_end / (dt / 4.0)).round();
                let bound = steps * 1e-11 * length;
                assert!(
                    diff.iter().all(|&d| d <= bound),
                    "{name}: the midpoint schemes differ by {diff:?} > {bound:.3e}"
                );
                continue;
            }
            for pair in diff.windows(2) {
                let order = (pair[0] / pair[1]).log2();
                assert!(
                    (1.8..=2.2).contains(&order),
                    "{name}: {:?} vs {:?}: observed order {order:.3} (differences {diff:?})",
                    methods[a],
                    methods[b]
                );
            }
        }
    }
}
