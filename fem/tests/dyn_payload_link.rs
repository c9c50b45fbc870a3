//! Dynamics of the 3-D payload link (seed 002): ledger closure with and without dissipation,
//! the rigid limit of the stiff variant, the seed's decoupling at constant rate, and frequency
//! convergence at the element orders (linear torsion O(h²) toward its transcendental equation,
//! Hermite bending O(h⁴) toward its own Richardson extrapolation).

use data::{Backend, RunResult, Scene, Settings};
use fem::FemBackend;
use fem::payload_link::link_modes;
use fem::payload_link::model::Model;

fn scene(name: &str) -> Scene {
    data::load_scene(name).expect("catalog scene")
}

fn run(sc: &Scene, elements: usize, t_end: f64) -> RunResult {
    run_dt(sc, elements, t_end, None)
}

fn run_dt(sc: &Scene, elements: usize, t_end: f64, dt: Option<f64>) -> RunResult {
    let mut s = Settings::default();
    s.discretization.elements = Some(elements);
    s.time.t_end = Some(t_end);
    s.time.dt = dt;
    let r = FemBackend.simulate(sc, &s).expect("run");
    assert_eq!(r.verdict, data::StabilityVerdict::Completed);
    r
}

fn history<'a>(r: &'a RunResult, name: &str) -> &'a [f64] {
    &r.observables.get(name).expect(name).values
}

#[test]
fn dyn_payload_ledger_closes_with_and_without_dissipation() {
    // Damped: motor friction and Kelvin–Voigt on every field, gravity, static-sag start.
    let damped = run(&scene("single-link-3d"), 8, 0.6);
    let c = damped.ledger.relative_closure();
    assert!(c < 1e-7, "damped closure {c:.3e}");
    // Undamped: the same scene without any dissipation; the bang-bang torque still works.
    let mut sc = scene("single-link-3d");
    let pl = sc.payload_link_mut().unwrap();
    pl.kelvin_voigt = None;
    pl.base.damping = None;
    let undamped = run(&sc, 8, 0.6);
    assert!(undamped.ledger.dissipation.is_empty());
    let c = undamped.ledger.relative_closure();
    assert!(c < 1e-7, "undamped closure {c:.3e}");
}

#[test]
fn dyn_payload_stiff_rod_follows_the_rigid_body() {
    // (I_B + ρAL³/3 + ρIL + m_p(L + c)² + I_zz) θ̈ = T_mot − b_m θ̇, solved piecewise in closed form.
    let sc = scene("single-link-3d-stiff");
    let l = sc.payload_link().cloned().unwrap();
    let inertia = l.base_inertia()
        + l.mass_per_length() * l.length.powi(3) / 3.0
        + l.density * l.second_moment() * l.length
        + l.payload.mass * (l.length + l.payload.offset).powi(2)
        + l.payload.inertia[2][2];
    let b = l.motor_friction();
    let law = l.base.torque.clone().unwrap();
    // A step of 1/8 of the output interval: the default rule resolves the stiff rod's 400 Hz
    // bending (3.1e-5 s), which the rigid motion does not need.
    let r = run_dt(&sc, 4, 1.5, Some(1.25e-4));
    let (mut th, mut w, mut t) = (0.0, 0.0, 0.0);
    let theta = history(&r, "joint1.angle");
    let times = &r.observables.time;
    let mut worst = 0.0f64;
    for (k, &tk) in times.iter().enumerate() {
        // Constant torque on each output interval (the law switches on the output grid).
        while t < tk - 1e-12 {
            let dt = tk - t;
            let tau = law.torque(t + 0.5 * dt);
            let (wf, e) = (tau / b, (-b * dt / inertia).exp());
            th += wf * dt + (w - wf) * inertia / b * (1.0 - e);
            w = wf + (w - wf) * e;
            t = tk;
        }
        worst = worst.max((theta[k] - th).abs());
    }
    // The flexible correction at E = 100 × steel: (ω_rigid/ω₁)² ≈ 1e-4 of the swing.
    assert!(
        worst < 1e-4 * theta.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        "{worst:.3e}"
    );
}

#[test]
fn dyn_payload_vertical_excitation_leaves_the_turning_plane_at_constant_rate() {
    // Seed 002's decoupling: diagonal I_p, centre of mass on the axis, constant rate. Gravity
    // drives (w, φ); the (u, v) histories must not change when gravity is switched off.
    // One step for both runs: the default step rule resolves the modes the loads excite, so
    // it picks a different step once gravity is off.
    let dt = Some(1e-4);
    let with = run_dt(&scene("single-link-3d-constant-rate"), 6, 0.2, dt);
    let mut sc = scene("single-link-3d-constant-rate");
    sc.payload_link_mut().unwrap().gravity = None;
    let without = run_dt(&sc, 6, 0.2, dt);
    let wmax = history(&with, "link1.tip_w")
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(wmax > 1e-3);
    for ch in [
        "link1.tip_deflection",
        "link1.tip_axial",
        "link1.tip_slope_v",
    ] {
        let diff = history(&with, ch)
            .iter()
            .zip(history(&without, ch))
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-12 * wmax, "{ch}: {diff:.3e}");
    }
    assert!(history(&without, "link1.tip_w").iter().all(|&w| w == 0.0));
}

fn first_of(md: &Model, kind: &str) -> f64 {
    link_modes(md, 40)
        .unwrap()
        .iter()
        .find(|m| m.kind.starts_with(kind))
        .map(|m| m.omega)
        .expect(kind)
}

#[test]
fn conv_payload_frequencies_converge_at_the_element_orders() {
    let sc = scene("single-link-3d-constant-rate");
    let l = sc.payload_link().cloned().unwrap();
    // Torsion with the payload's axial inertia: ζ tan ζ = ρJL/I_px, ω = (ζ/L)√(G/ρ) (the
    // diagonal payload and the circular section leave torsion uncoupled and rate-independent).
    let ratio = l.density * l.polar_moment() * l.length / l.payload.inertia[0][0];
    let (mut lo, mut hi) = (0.0, std::f64::consts::FRAC_PI_2 - 1e-12);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if m * m.tan() < ratio { lo = m } else { hi = m }
    }
    let exact = 0.5 * (lo + hi) / l.length * (l.shear_modulus / l.density).sqrt();
    let err: Vec<f64> = [8, 16, 32]
        .iter()
        .map(|&n| first_of(&Model::assemble(&l, n).unwrap(), "torsion") - exact)
        .collect();
    for k in 0..2 {
        let p = (err[k] / err[k + 1]).log2();
        assert!((1.9..=2.1).contains(&p), "torsion order {p:.3} ({err:?})");
    }
    // Vertical bending at the constant rate: Hermite cubics, order 4 by Richardson.
    let f: Vec<f64> = [4, 8, 16]
        .iter()
        .map(|&n| first_of(&Model::assemble(&l, n).unwrap(), "bending-vertical"))
        .collect();
    let p = ((f[0] - f[1]) / (f[1] - f[2])).log2();
    assert!((3.6..=4.4).contains(&p), "bending order {p:.3} ({f:?})");
    let richardson = f[2] + (f[2] - f[1]) / (2f64.powf(p) - 1.0);
    assert!((f[2] - richardson).abs() < 1e-6 * richardson);
}
