//! The 3-D payload link (seed 002) in fdm: DOF counts per scene, refusal of a step above the
//! per-field bound, ledger closure, frequencies and static sag against closed forms computed
//! here from the scene, O(h²) convergence, the constant-rate decoupling.
//! Run: cargo test --release -p fdm --test payload_link -- --nocapture

use data::scene::{LinkField, PrescribedMotion};
use data::{Backend, BackendError, RunResult, Scene, Settings, StabilityVerdict, load_scene};
use fdm::FdmBackend;
use fdm::payload_link::PayloadLinkModel;

fn scene(name: &str, f: impl Fn(&mut data::scene::PayloadLink)) -> Scene {
    let mut s = load_scene(name).unwrap();
    f(s.payload_link_mut().unwrap());
    s
}

fn settings(stations: Option<usize>, t_end: Option<f64>, dt: Option<f64>) -> Settings {
    let mut s = Settings::default();
    s.discretization.stations = stations;
    s.time.t_end = t_end;
    s.time.dt = dt;
    s
}

fn channel<'a>(r: &'a RunResult, name: &str) -> &'a [f64] {
    &r.observables
        .channels
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("channel {name}"))
        .values
}

/// Root of f on [a, b] by bisection (f(a), f(b) of opposite signs).
fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let fa = f(a);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if (f(m) > 0.0) == (fa > 0.0) {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

#[test]
fn sys_payload_link_dof_counts_per_scene() {
    let d = data::Discretization::default();
    let total = |s: &Scene| FdmBackend.dof_plan(s, &d).unwrap().total();
    // 21 stations by default: 20 per field; a torque-driven base adds θ
    assert_eq!(total(&load_scene("single-link-3d").unwrap()), 4 * 20 + 1);
    assert_eq!(
        total(&load_scene("single-link-3d-stiff").unwrap()),
        4 * 20 + 1
    );
    assert_eq!(
        total(&load_scene("single-link-3d-constant-rate").unwrap()),
        4 * 20
    );
    assert_eq!(
        total(&load_scene("single-link-3d-soft-sag").unwrap()),
        4 * 20
    );
    let two = scene("single-link-3d", |p| {
        p.fields = vec![LinkField::Vertical, LinkField::Torsion]
    });
    assert_eq!(total(&two), 2 * 20 + 1);
    let m = PayloadLinkModel::from_payload_link(&two, two.payload_link().unwrap(), None).unwrap();
    let (stored, inputs, diss) = m.ledger_names();
    assert_eq!(stored, ["kinetic", "strain", "gravity"]);
    assert_eq!(inputs, ["applied_torque"]);
    assert_eq!(
        diss,
        [
            "joint_damper",
            "kelvin_voigt_vertical",
            "kelvin_voigt_torsion"
        ]
    );
    // no vertical field: gravity has nothing to act on in this model and is not built
    let flat = scene("single-link-3d", |p| {
        p.fields = vec![LinkField::Axial, LinkField::Horizontal];
        p.kelvin_voigt = None;
        p.base.damping = None;
    });
    let plan = FdmBackend.dof_plan(&flat, &d).unwrap();
    assert_eq!(plan.total(), 2 * 20 + 1);
    assert!(
        !plan
            .builds
            .iter()
            .any(|b| b.contains("gravity") || b.contains("Kelvin"))
    );
    let (stored, _, diss) =
        PayloadLinkModel::from_payload_link(&flat, flat.payload_link().unwrap(), None)
            .unwrap()
            .ledger_names();
    assert_eq!(stored, ["kinetic", "strain"]);
    assert!(diss.is_empty());
    // soft sag: clamped base, KV on the two bending fields only
    let soft_sag = load_scene("single-link-3d-soft-sag").unwrap();
    let soft =
        PayloadLinkModel::from_payload_link(&soft_sag, soft_sag.payload_link().unwrap(), None)
            .unwrap();
    let (stored, inputs, diss) = soft.ledger_names();
    assert_eq!(stored, ["kinetic", "strain", "gravity"]);
    assert_eq!(inputs, ["prescribed_motion"]);
    assert_eq!(diss, ["kelvin_voigt_horizontal", "kelvin_voigt_vertical"]);
    // stiff: no gravity
    let stiff_scene = load_scene("single-link-3d-stiff").unwrap();
    let stiff = PayloadLinkModel::from_payload_link(
        &stiff_scene,
        stiff_scene.payload_link().unwrap(),
        None,
    )
    .unwrap();
    assert_eq!(stiff.ledger_names().0, ["kinetic", "strain"]);
}

#[test]
fn dyn_payload_link_refuses_a_step_above_the_bound_naming_the_field() {
    let s = load_scene("single-link-3d").unwrap();
    let m = PayloadLinkModel::from_payload_link(&s, s.payload_link().unwrap(), None).unwrap();
    let bounds = m.field_bounds();
    let axial = bounds.iter().find(|b| b.0 == LinkField::Axial).unwrap().1;
    match FdmBackend.simulate(&s, &settings(None, Some(1e-3), Some(1.01 * axial))) {
        Err(BackendError::StabilityBound {
            bound_kind, bound, ..
        }) => {
            assert!(bound_kind.contains("axial"), "{bound_kind}");
            assert_eq!(bound, axial);
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    // without the axial field torsion binds (h√(ρJ/GJ) < h²√(ρA/4EI) for this rod)
    let s2 = scene("single-link-3d", |p| {
        p.fields = vec![LinkField::Vertical, LinkField::Torsion]
    });
    let m2 = PayloadLinkModel::from_payload_link(&s2, s2.payload_link().unwrap(), None).unwrap();
    let torsion = m2
        .field_bounds()
        .iter()
        .map(|b| b.1)
        .fold(f64::INFINITY, f64::min);
    match FdmBackend.simulate(&s2, &settings(None, Some(1e-3), Some(1.01 * torsion))) {
        Err(BackendError::StabilityBound { bound_kind, .. }) => {
            assert!(bound_kind.contains("torsion"), "{bound_kind}")
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    let r = FdmBackend
        .simulate(&s2, &settings(None, Some(1e-2), Some(0.99 * torsion)))
        .unwrap();
    assert_eq!(r.verdict, StabilityVerdict::Completed);
    // Channels of the carried fields only, in the registry's order, then the step monitors.
    let written: Vec<&str> = r
        .observables
        .channels
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    let stations = written.iter().filter(|n| n.starts_with("link1.w@")).count();
    let mut expected: Vec<String> =
        data::channel::payload_link(&[LinkField::Vertical, LinkField::Torsion], stations)
            .into_iter()
            .map(|(n, _)| n)
            .collect();
    expected.extend(["step_size".to_string(), "stability_bound".to_string()]);
    assert!(stations >= 2);
    assert_eq!(written, expected);
    assert!(r.observables.get("link1.tip_axial").is_none());
    assert!(r.observables.get("link1.tip_slope_v").is_none());
}

#[test]
fn dyn_payload_link_ledger_closes_damped_and_undamped() {
    let damped = load_scene("single-link-3d").unwrap();
    let undamped = scene("single-link-3d", |p| {
        p.kelvin_voigt = None;
        p.base.damping = None;
    });
    for (label, s, t_end) in [("damped", damped, 0.6), ("undamped", undamped, 0.6)] {
        let r = FdmBackend
            .simulate(&s, &settings(None, Some(t_end), None))
            .unwrap();
        assert_eq!(r.verdict, StabilityVerdict::Completed);
        let closure = r.ledger.relative_closure();
        let diss: f64 = r
            .ledger
            .dissipation
            .iter()
            .map(|t| *t.values.last().unwrap())
            .sum();
        println!(
            "{label}: {} steps, closure {closure:.3e}, dissipated {diss:.3e}",
            r.cost.steps
        );
        assert!(closure < 1e-6, "{label}: {closure}");
        if label == "damped" {
            assert!(diss > 0.0);
        } else {
            assert!(r.ledger.dissipation.is_empty());
        }
    }
}

#[test]
fn conv_payload_link_static_sag_against_the_closed_form() {
    // linear cantilever under self-weight q, payload weight P and offset moment P c
    let s = load_scene("single-link-3d").unwrap();
    let p = s.payload_link().cloned().unwrap();
    let (l, ei, g) = (p.length, p.bending_stiffness(), p.gravity.unwrap());
    let (q, pw) = (p.mass_per_length() * g, p.payload.mass * g);
    let mc = pw * p.payload.offset;
    let w_exact =
        -(pw * l.powi(3) / (3.0 * ei) + mc * l * l / (2.0 * ei) + q * l.powi(4) / (8.0 * ei));
    let slope_exact = -(pw * l * l / (2.0 * ei) + mc * l / ei + q * l.powi(3) / (6.0 * ei));
    let mut errs = Vec::new();
    for n in [11, 21, 41] {
        let r = FdmBackend
            .statics(&s, &settings(Some(n), None, None))
            .unwrap();
        let e = (r.tip_deflection - w_exact) / w_exact;
        let es = (r.tip_rotation - slope_exact) / slope_exact;
        println!(
            "{n} stations: w_L = {:.9e} (exact {w_exact:.9e}, rel {e:.2e}), w′_L rel {es:.2e}",
            r.tip_deflection
        );
        errs.push(e);
    }
    let order = (errs[1] / errs[2]).log2();
    println!("observed order {order:.3}");
    assert!((order - 2.0).abs() < 0.1, "{order}");
    assert!(errs[2].abs() < 1e-3);
}

/// Frequencies (Hz) and kinds at `n` stations.
fn spectrum(s: &Scene, n: usize) -> (Vec<f64>, Vec<String>) {
    let sp = PayloadLinkModel::from_payload_link(s, s.payload_link().unwrap(), Some(n))
        .unwrap()
        .spectrum()
        .unwrap();
    (
        sp.omega
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect(),
        sp.kinds,
    )
}

fn first_of(s: &Scene, n: usize, kind: &str) -> f64 {
    let (f, k) = spectrum(s, n);
    f[k.iter()
        .position(|x| x == kind)
        .unwrap_or_else(|| panic!("no {kind} mode"))]
}

#[test]
fn conv_payload_link_torsion_and_axial_frequencies_against_the_closed_forms() {
    // clamped base, diagonal payload inertia on the axis: torsion and axial decouple.
    // torsion: ζ tan ζ = ρJL/I_px, ω = ζ/L √(G/ρ); axial: ζ tan ζ = ρAL/m_p, ω = ζ/L √(E/ρ)
    let s = scene("single-link-3d-constant-rate", |p| {
        p.base.prescribed = Some(PrescribedMotion::Fixed)
    });
    let p = s.payload_link().cloned().unwrap();
    let l = p.length;
    let root = |ratio: f64| {
        bisect(
            |z| z * z.tan() - ratio,
            1e-9,
            std::f64::consts::FRAC_PI_2 - 1e-12,
        )
    };
    let two_pi = 2.0 * std::f64::consts::PI;
    let f_t = root(p.density * p.polar_moment() * l / p.payload.inertia[0][0]) / l
        * (p.shear_modulus / p.density).sqrt()
        / two_pi;
    let f_a = root(p.mass_per_length() * l / p.payload.mass) / l
        * (p.youngs_modulus / p.density).sqrt()
        / two_pi;
    for (kind, exact) in [("torsion", f_t), ("axial", f_a)] {
        let f: Vec<f64> = [11, 21, 41]
            .iter()
            .map(|&n| first_of(&s, n, kind))
            .collect();
        let errs: Vec<f64> = f.iter().map(|x| (x - exact) / exact).collect();
        let order = (errs[1] / errs[2]).log2();
        println!("{kind}: exact {exact:.6e} Hz, fdm {f:?}, rel errors {errs:?}, order {order:.3}");
        assert!((order - 2.0).abs() < 0.1, "{kind}: order {order}");
        assert!(errs[2].abs() < 1e-3, "{kind}: {}", errs[2]);
    }
}

#[test]
fn conv_payload_link_bending_frequencies_converge_at_second_order() {
    for name in ["single-link-3d", "single-link-3d-constant-rate"] {
        let s = load_scene(name).unwrap();
        for kind in ["bending-vertical", "bending-horizontal"] {
            let f: Vec<f64> = [11, 21, 41]
                .iter()
                .map(|&n| first_of(&s, n, kind))
                .collect();
            let order = ((f[1] - f[0]) / (f[2] - f[1])).log2();
            let richardson = f[2] + (f[2] - f[1]) / (2f64.powf(order) - 1.0);
            println!("{name} {kind}: {f:?} Hz, order {order:.3}, Richardson {richardson:.6e}");
            assert!((order - 2.0).abs() < 0.15, "{name} {kind}: order {order}");
            assert!(((f[2] - richardson) / richardson).abs() < 2e-3);
        }
    }
}

#[test]
fn dyn_payload_link_constant_rate_gravity_does_not_reach_the_horizontal_pair() {
    // Seed 002's decoupling: at constant Ω with a diagonal payload inertia on the axis the
    // (u, v) and (w, φ) equations decouple, boundary terms included; gravity drives w (and φ)
    // only, so v and u are the same with and without it (to round-off).
    let with = load_scene("single-link-3d-constant-rate").unwrap();
    let without = scene("single-link-3d-constant-rate", |p| p.gravity = None);
    let st = settings(None, Some(0.05), None);
    let a = FdmBackend.simulate(&with, &st).unwrap();
    let b = FdmBackend.simulate(&without, &st).unwrap();
    let w = channel(&a, "link1.tip_w");
    let w_peak = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(w_peak > 1e-4, "gravity moves w: {w_peak}");
    for name in ["link1.tip_deflection", "link1.tip_axial"] {
        let (x, y) = (channel(&a, name), channel(&b, name));
        let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(y)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        println!("{name}: peak {peak:.3e}, gravity's effect {diff:.3e} (w peak {w_peak:.3e})");
        assert!(diff <= 1e-12 * w_peak, "{name}: {diff}");
    }
    let wb = channel(&b, "link1.tip_w");
    assert!(wb.iter().all(|x| *x == 0.0), "without gravity w stays zero");
}

/// The payload link is a `System` the backend's driver steps: its coordinates are the field
/// DOFs (plus θ with a free base), the step matrix is factored once per step length, and a
/// short run through `driver::run` with the velocity form books a ledger that closes, with the
/// Kelvin–Voigt dissipation positive — on a free base with a torque law and on a prescribed one.
#[test]
fn sys_payload_link_is_a_system_stepped_by_the_driver() {
    use fdm::driver::{StepControl, run};
    use fdm::events::NoEvents;
    use fdm::method::VelocityForm;
    use fdm::payload_link::system::PayloadLinkSystem;
    use fdm::system::{BoundKind, System};

    for (name, free) in [
        ("single-link-3d", true),
        ("single-link-3d-constant-rate", false),
    ] {
        let s = load_scene(name).unwrap();
        let p = s.payload_link().unwrap();
        let model = PayloadLinkModel::from_payload_link(&s, p, None).unwrap();
        let n = model.field_coordinates();
        let bounds = model.field_bounds();
        let mut sys = PayloadLinkSystem::new(model).unwrap();
        let off = usize::from(free);
        assert_eq!(sys.dofs(), n + off, "{name}");
        assert_eq!(sys.monitored(), off..n + off, "{name}");
        // the binding bound is the smallest field bound, named by its field
        let b = sys.bound(0.0);
        let (field, sigma, station) = bounds
            .iter()
            .copied()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        assert_eq!(
            (b.kind, b.sigma, b.site),
            (BoundKind::LinkField(field), sigma, station)
        );

        let tau = 0.9 * sigma;
        sys.set_step(tau).unwrap();
        sys.set_step(tau).unwrap();
        assert_eq!(
            sys.factorizations(),
            1,
            "{name}: one factorization per step length"
        );
        let ctl = StepControl {
            method: fdm::Method::VelocityForm,
            safety: 0.9,
            forced_dt: None,
            t_end: 0.05,
            output_interval: 1e-3,
            log_change: f64::INFINITY,
            lookahead: false,
            enforce_bound: true,
        };
        let sag = p.initial_shape == data::scene::LinkInitialShape::StaticSag;
        let (q0, v0) = sys.initial_state(sag).unwrap();
        let out = run(
            &mut sys,
            &mut VelocityForm::drift_split(),
            &mut NoEvents,
            &q0,
            &v0,
            &ctl,
        )
        .unwrap();
        assert_eq!(out.verdict, StabilityVerdict::Completed, "{name}");
        assert_eq!(out.cost.dofs, n + off, "{name}");
        assert_eq!(out.tau_min, tau, "{name}");
        assert_eq!(out.tau_max, tau, "{name}");
        assert_eq!(
            sys.factorizations(),
            1,
            "{name}: no refactorization in the loop"
        );
        assert_eq!(out.observables.time.len(), 51, "{name}");
        let closure = out.ledger.relative_closure();
        let diss: f64 = out
            .ledger
            .dissipation
            .iter()
            .map(|t| *t.values.last().unwrap())
            .sum();
        let input: f64 = out
            .ledger
            .inputs
            .iter()
            .map(|t| t.values.last().unwrap().abs())
            .sum();
        println!("{name}: closure {closure:.3e}, dissipated {diss:.3e}, |input| {input:.3e}");
        assert!(closure < 1e-6, "{name}: {closure}");
        assert!(diss > 0.0, "{name}");
        assert!(input > 0.0, "{name}: the base does work on the link");
        if !free {
            // θ is no coordinate here: the observable follows the prescribed constant rate
            let rate = 2.0 * std::f64::consts::PI;
            let angle = &out
                .observables
                .channels
                .iter()
                .find(|c| c.name == "joint1.angle")
                .unwrap()
                .values;
            for (t, a) in out.observables.time.iter().zip(angle) {
                assert!((a - rate * t).abs() <= 1e-13 * (1.0 + rate * t), "{t}: {a}");
            }
        }
    }
}

#[test]
fn sys_payload_link_refuses_the_two_step_methods() {
    let s = load_scene("single-link-3d").unwrap();
    for m in [
        data::Method::Report,
        data::Method::RobertAsselin { nu: None },
    ] {
        let mut st = settings(None, Some(1e-3), None);
        st.time.method = Some(m);
        match FdmBackend.simulate(&s, &st) {
            Err(BackendError::Unsupported(msg)) => {
                assert!(msg.contains("velocity-form"), "{msg}")
            }
            other => panic!("expected a refusal of {m:?}, got {other:?}"),
        }
    }
    let mut st = settings(None, Some(1e-3), None);
    st.time.method = Some(data::Method::VelocityForm);
    assert_eq!(
        FdmBackend.simulate(&s, &st).unwrap().verdict,
        StabilityVerdict::Completed
    );
}
