//! Single floating-frame link: spin-up (with and without geometric stiffening), torque-driven
//! single link. Run: CARGO_TARGET_DIR=/work/targets/fdm cargo test --release -p fdm --test link -- --nocapture

use data::{Backend, RunResult, Settings, StabilityVerdict, load_scene};
use fdm::FdmBackend;

fn run(name: &str, f: impl Fn(&mut data::Scene), settings: &Settings) -> RunResult {
    let mut scene = load_scene(name).unwrap();
    f(&mut scene);
    FdmBackend.simulate(&scene, settings).expect("runs")
}

fn maxabs(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

#[test]
fn sys_link_dof_plans() {
    let d = Default::default();
    // prescribed hub: no hub DOF; 41 stations minus the clamp
    assert_eq!(
        FdmBackend
            .dof_plan(&load_scene("spin-up").unwrap(), &d)
            .unwrap()
            .total(),
        40
    );
    assert_eq!(
        FdmBackend
            .dof_plan(&load_scene("spin-up-linear").unwrap(), &d)
            .unwrap()
            .total(),
        40
    );
    let p = FdmBackend
        .dof_plan(&load_scene("spin-up-linear").unwrap(), &d)
        .unwrap();
    assert!(
        p.builds.is_empty(),
        "linear model builds no stiffening: {:?}",
        p.builds
    );
    // torque-driven: hub angle + 40
    assert_eq!(
        FdmBackend
            .dof_plan(&load_scene("single-link").unwrap(), &d)
            .unwrap()
            .total(),
        41
    );
}

/// (stored, inputs, dissipation) term names of a run's ledger.
fn ledger_terms(r: &RunResult) -> [Vec<&str>; 3] {
    fn names(t: &[data::EnergyTerm]) -> Vec<&str> {
        t.iter().map(|x| x.name.as_str()).collect()
    }
    [
        names(&r.ledger.stored),
        names(&r.ledger.inputs),
        names(&r.ledger.dissipation),
    ]
}

#[test]
fn sys_link_ledger_books_only_the_scene_terms() {
    // Only what the scene enables is booked: `single-link` has no joint spring, damper or
    // Kelvin–Voigt (as fem/modal: kinetic, strain, applied_torque).
    let mut s = Settings::default();
    s.time.t_end = Some(0.05);
    let r = run("single-link", |_| {}, &s);
    assert_eq!(
        ledger_terms(&r),
        [vec!["kinetic", "strain"], vec!["applied_torque"], vec![]]
    );
    assert_eq!(r.cost.dofs, 41, "hub angle + 40 stations");
    // prescribed hub: the motion is the input, no hub DOF
    let r = run("spin-up", |_| {}, &s);
    assert_eq!(
        ledger_terms(&r),
        [vec!["kinetic", "strain"], vec!["prescribed_motion"], vec![]]
    );
    assert_eq!(r.cost.dofs, 40);
    // every term switched on, and the ledger still closes with them
    let all = |sc: &mut data::Scene| {
        let j = &mut sc.planar_chain_mut().unwrap().links[0].joint;
        j.stiffness = Some(2.0);
        j.damping = Some(0.05);
        j.set_point = Some(0.3);
        sc.planar_chain_mut().unwrap().links[0].kelvin_voigt = Some(1e-4);
    };
    let r = run("single-link", all, &s);
    assert_eq!(
        ledger_terms(&r),
        [
            vec!["kinetic", "strain", "joint_spring"],
            vec!["applied_torque"],
            vec!["joint_damper", "kelvin_voigt"]
        ]
    );
    for t in r.ledger.stored.iter().chain(&r.ledger.dissipation) {
        assert!(
            t.values.iter().any(|v| *v != 0.0),
            "{} is booked and non-zero",
            t.name
        );
    }
    assert!(r.ledger.relative_closure() < 1e-4);
    // a torque-driven hub without a torque law has no input term
    let r = run(
        "single-link",
        |sc| {
            all(sc);
            sc.planar_chain_mut().unwrap().links[0].joint.torque = None;
        },
        &s,
    );
    assert_eq!(ledger_terms(&r)[1], Vec::<&str>::new());
}

#[test]
fn dyn_spin_up_stays_bounded_with_foreshortening_and_diverges_without() {
    let s = Settings::default();
    let fs = run("spin-up", |_| {}, &s);
    let lin = run("spin-up-linear", |_| {}, &s);
    let tip_fs = &fs.observables.get("link1.tip_deflection").unwrap().values;
    let tip_lin = &lin.observables.get("link1.tip_deflection").unwrap().values;
    let (a, b) = (maxabs(tip_fs), maxabs(tip_lin));
    eprintln!(
        "spin-up: max |tip| {a:.4} m (foreshortening), {b:.4e} m (linear); verdicts {:?} / {:?}",
        fs.verdict, lin.verdict
    );
    eprintln!(
        "spin-up: steps {}, wall {:.3} s, ledger closure {:.3e}",
        fs.cost.steps,
        fs.cost.wall_time_s,
        fs.ledger.relative_closure()
    );
    assert!(matches!(fs.verdict, StabilityVerdict::Completed));
    // bounded: a 10 m beam at 4 rad/s deflects by a small fraction of its length
    assert!(a < 1.0);
    // linear model: ω_s = 4 > ω₁ ≈ 3.8 rad/s, the in-plane effective stiffness ω₁² − Ω² < 0
    assert!(b > 10.0 * a, "linear {b} vs foreshortening {a}");
    // Energy: stored energy = prescribed-motion work (undamped); second-order scheme.
    assert!(
        fs.ledger.relative_closure() < 1e-3,
        "{}",
        fs.ledger.relative_closure()
    );
}

#[test]
fn dyn_single_link_report_scheme_parasitic_velocity_form_closes_energy() {
    // The free hub couples θ̇ and v̇ (İθ̇ and θ̇² terms): velocity-dependent forces on which the
    // two-step scheme's computational mode grows even without damping, at a rate per unit
    // time that does not fall with the step. It is detected… (grown from the start-up's
    // O(τ³) seed it passes the watch's threshold after the scene's 3 s, at 4.4 s: the run
    // goes on to 6 s)
    let mut report = Settings::default();
    report.time.method = Some("report".parse().expect("a method name"));
    report.time.t_end = Some(6.0);
    let out = run("single-link", |_| {}, &report);
    match &out.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            eprintln!("single-link, report: {diagnostic}");
            assert!(diagnostic.what.contains("parasitic"));
        }
        v => panic!("expected the computational mode to be caught: {v:?}"),
    }
    // …and the one-step velocity form runs the scene with a closed ledger.
    let mut s = Settings::default();
    s.time.method = Some("velocity-form".parse().expect("a method name"));
    let out = run("single-link", |_| {}, &s);
    assert!(
        matches!(out.verdict, StabilityVerdict::Completed),
        "{:?}",
        out.verdict
    );
    let c = out.ledger.relative_closure();
    eprintln!(
        "single-link, velocity-form: steps {}, ledger closure {c:.3e}",
        out.cost.steps
    );
    // …which is the default for this scene (velocity-dependent forces): the same bits.
    let default = run("single-link", |_| {}, &Settings::default());
    assert_eq!(
        default.observables.get("joint1.angle").unwrap().values,
        out.observables.get("joint1.angle").unwrap().values
    );
    // second-order scheme, torque switches inside steps (one O(τ²) energy error per switch)
    assert!(c < 1e-4);
    // Rigid limit: EI × 1e3; θ(t) = τ t² / (2 I), I = J + ρA L³/3 + M L² for t < 0.5 s.
    s.time.t_end = Some(0.4);
    let stiff = run(
        "single-link",
        |sc| sc.planar_chain_mut().unwrap().links[0].bending_stiffness *= 1e3,
        &s,
    );
    let scene = load_scene("single-link").unwrap();
    let l = &scene.links()[0];
    let i = l.joint.hub_inertia.unwrap()
        + l.mass_per_length * l.length.powi(3) / 3.0
        + l.tip_mass.unwrap() * l.length.powi(2);
    let th = &stiff.observables.get("joint1.angle").unwrap().values;
    let mut worst = 0.0f64;
    for (t, v) in stiff.observables.time.iter().zip(th) {
        let exact = t * t / (2.0 * i);
        worst = worst.max((v - exact).abs() / (0.16 / (2.0 * i)));
    }
    eprintln!("rigid limit: max relative hub-angle error {worst:.3e}");
    // trapezoid inertia error h²/(2L²)·(ρAL³/3)/I ≈ 1e-4; residual flexibility (EI = 1e4)
    // ≈ 1e-3
    assert!(worst < 3e-3);
}

#[test]
fn dyn_single_link_kelvin_voigt_dissipation_in_ledger() {
    // γ such that the shortest wave is strongly damped (ζ_max ≈ 1): the step bound shrinks
    // and the velocity form must still close the ledger with the dissipation term.
    let mut s = Settings::default();
    s.time.method = Some("velocity-form".parse().expect("a method name"));
    s.time.t_end = Some(1.5);
    let out = run(
        "single-link",
        |sc| sc.planar_chain_mut().unwrap().links[0].kelvin_voigt = Some(1e-4),
        &s,
    );
    assert!(
        matches!(out.verdict, StabilityVerdict::Completed),
        "{:?}",
        out.verdict
    );
    let kv = out
        .ledger
        .dissipation
        .iter()
        .find(|t| t.name == "kelvin_voigt")
        .unwrap();
    let c = out.ledger.relative_closure();
    eprintln!(
        "single-link + KV: dissipated {:.3e} J, closure {c:.3e}, steps {}",
        kv.values.last().unwrap(),
        out.cost.steps
    );
    assert!(*kv.values.last().unwrap() > 0.0);
    // second order; the dissipation integral is trapezoidal in time
    assert!(c < 1e-3);
}

#[test]
fn dyn_spin_up_at_lambda_12_completes_with_the_tension_bound() {
    // The stability suite's finding: spin-up to ω_s = 12.96 rad/s (λ = 12) with the default
    // method stopped at t ≈ 8.5 s when the step sat at the report's bending-only limit; the
    // centrifugal tension N(x) raises ω_max by ≈ 0.6 % there.
    let omega_s = 12.96;
    let out = run(
        "spin-up",
        |sc| {
            sc.planar_chain_mut().unwrap().links[0].joint.prescribed =
                Some(data::scene::PrescribedMotion::SpinUp { omega_s, t_s: 15.0 })
        },
        &Settings::default(),
    );
    assert!(
        matches!(out.verdict, StabilityVerdict::Completed),
        "{:?}",
        out.verdict
    );
    let scene = load_scene("spin-up").unwrap();
    let l = &scene.links()[0];
    let tip = maxabs(&out.observables.get("link1.tip_deflection").unwrap().values);
    // bounded: the tip deflection stays a small part of the link length
    assert!(tip < l.length, "tip {tip}");
    // the step follows the bound down as the rate grows: below the report's bending-only
    // ½σ = ½√(h⁴ρA/(4EI)) at the end (41 stations), never above the recorded bound
    let steps = &out.observables.get("step_size").unwrap().values;
    let bounds = &out.observables.get("stability_bound").unwrap().values;
    assert!(steps.iter().zip(bounds).all(|(s, b)| s <= b));
    let h = l.length / 40.0;
    let report = 0.5 * (h.powi(4) * l.mass_per_length / (4.0 * l.bending_stiffness)).sqrt();
    let last = *bounds.last().unwrap();
    assert!(last < report, "{last} vs {report}");
    // Energy: undamped, the prescribed-motion work must equal the stored energy. The scheme is
    // second order with τ at the bound; its energy error per unit energy is O((Ω τ)²) for the
    // motion the hub drives (the elastic response follows the rate at ω₁ ~ Ω), so
    // (ω_s τ_max)² is the justified scale.
    let tau_max = steps.iter().fold(0.0f64, |m, &v| m.max(v));
    let closure = out.ledger.relative_closure();
    let allowed = (omega_s * tau_max).powi(2);
    eprintln!(
        "spin-up λ = 12: max |tip| {tip:.4e} m, steps {}, τ {:.4e}…{tau_max:.4e} (report ½σ {report:.4e}), \
         wall {:.3} s, ledger closure {closure:.3e} (allowed {allowed:.3e})",
        out.cost.steps,
        steps.iter().fold(f64::INFINITY, |m, &v| m.min(v)),
        out.cost.wall_time_s
    );
    assert!(closure < allowed, "{closure} vs {allowed}");
}

#[test]
fn dyn_single_link_deflected_beyond_its_length_stops_with_a_diagnostic() {
    // EI 1000 times lower: the bang-bang torque spins the linear link above its first bending
    // frequency, where it has no centrifugal stiffness left; the tip passes the link length.
    let s = Settings::default();
    let out = run(
        "single-link",
        |sc| sc.planar_chain_mut().unwrap().links[0].bending_stiffness *= 1e-3,
        &s,
    );
    let length = load_scene("single-link").unwrap().links()[0].length;
    match &out.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            assert!(
                diagnostic.what.contains("beyond the link length"),
                "{diagnostic:?}"
            );
            assert!(
                diagnostic.remedy.contains("foreshortening"),
                "{diagnostic:?}"
            );
        }
        v => panic!("expected a stop, got {v:?}"),
    }
    // the results up to the stop are kept, all within the model's range
    let tip = &out.observables.get("link1.tip_deflection").unwrap().values;
    assert!(!tip.is_empty());
    assert!(maxabs(tip) <= length, "{}", maxabs(tip));
    assert!(maxabs(tip) > 0.5 * length, "{}", maxabs(tip));
}

/// The order of `single-link`'s hub angle over both torque switches (0.5 s and 1.0 s) on a
/// step ladder (21 stations, `method` None: the default), from the whole history to 1.3 s.
fn order_through_torque_switches(method: Option<data::Method>, steps: [f64; 3]) -> f64 {
    let hub = |dt: f64| {
        let mut s = Settings::default();
        s.discretization.stations = Some(21);
        s.time.dt = Some(dt);
        s.time.t_end = Some(1.3);
        s.time.method = method;
        let r = run("single-link", |_| {}, &s);
        assert!(
            matches!(r.verdict, StabilityVerdict::Completed),
            "{:?}",
            r.verdict
        );
        r.observables.get("joint1.angle").unwrap().values.clone()
    };
    let rungs: Vec<Vec<f64>> = steps.into_iter().map(hub).collect();
    let peak = maxabs(&rungs[2]);
    let diff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / peak
    };
    let (d1, d2) = (diff(&rungs[0], &rungs[1]), diff(&rungs[1], &rungs[2]));
    let order = (d1 / d2).log2();
    eprintln!(
        "{method:?}: hub angle's successive differences {d1:.3e}, {d2:.3e} of the peak, order \
         {order:.2}"
    );
    order
}

#[test]
fn dyn_velocity_form_keeps_its_order_through_torque_switches() {
    // `single-link`'s bang-bang torque jumps at 0.5 s and 1.0 s. A step that passes a jump
    // takes its impulse wrong by (t_jump − t_mid)·Δτ, first order in the step; the driver
    // steps onto the jumps instead (closing kick at the left limit, opening kick at the new
    // value). Steps that do not divide the switch times, so that no rung lands on them by
    // chance: the hub angle's whole history over both switches must converge at second order.
    let order = order_through_torque_switches(None, [1.7e-4, 8.5e-5, 4.25e-5]);
    assert!(order > 1.7, "order {order:.2}");
}

#[test]
fn dyn_two_step_keeps_its_order_through_torque_switches() {
    // The report's scheme takes a level's force over the half steps on both sides of it, so a
    // switch between levels is first order too (and its sawtooth excites the scheme's
    // computational mode). It lands a level on each switch and starts again there (one Heun
    // step with the new torque). Half the velocity form's steps (its bound is half). Taking
    // the switches at the levels gives order 1.70 on this ladder, landing on them 2.03.
    let order =
        order_through_torque_switches(Some(data::Method::Report), [8.5e-5, 4.25e-5, 2.125e-5]);
    assert!(order > 1.9, "order {order:.2}");
}

#[test]
fn dyn_a_sample_between_levels_closes_the_ledger_as_the_levels_do() {
    // single-link from rest under its torque law: a run that ends inside its first step samples
    // the end between the levels t = 0 and τ. The stored energies there are those of the dense
    // state (growing like s²), so the works must be the integral of the interpolated power,
    // not the linear interpolant of the works (which left a residual of (1 − s) of the energy
    // that flowed: closure 0.90 at s = 0.1). The sample must close as the level after it does.
    let at = |t_end: f64| {
        let mut s = Settings::default();
        s.time.t_end = Some(t_end);
        run("single-link", |_| {}, &s)
    };
    let first = at(1e-9);
    let tau = first
        .observables
        .get("step_size")
        .expect("step_size")
        .values[0];
    let level = at(tau).ledger.relative_closure();
    for s in [0.1, 0.5, 0.9] {
        let between = at(s * tau).ledger.relative_closure();
        assert!(
            between <= 1.5 * level,
            "s = {s}: closure {between:e} against {level:e} at the level"
        );
    }
}

#[test]
fn dyn_a_run_ending_on_a_torque_switch_lands_on_it() {
    // single-link's bang-bang law switches at t_s: a run ending there lands its last step on
    // the switch like any other (a step past it would read the new law's power at its far
    // level, and the end sample would take a torque the law never has between ±amplitude).
    // The end sample is the level at the switch: the law's value on the stretch it opens, and
    // the ledger closes there as on the levels before it.
    let scene = load_scene("single-link").unwrap();
    let law = scene.planar_chain().unwrap().links[0]
        .joint
        .torque
        .clone()
        .expect("single-link has a torque law");
    let switch = law.breakpoints()[0];
    let mut s = Settings::default();
    s.time.t_end = Some(switch);
    let out = run("single-link", |_| {}, &s);
    let torque = &out
        .observables
        .get("joint1.torque")
        .expect("joint1.torque")
        .values;
    let (t, last) = (
        *out.observables.time.last().unwrap(),
        *torque.last().unwrap(),
    );
    assert_eq!(t, switch);
    assert_eq!(last, law.torque(switch), "torque at the switch {last}");
    let n = out.ledger.time.len();
    let before = (0..n - 1).fold(0.0f64, |m, k| m.max(out.ledger.residual(k).abs()));
    let end = out.ledger.residual(n - 1).abs();
    assert!(
        end <= 1.5 * before,
        "end residual {end:e} against {before:e} before it"
    );
}
