//! The verification machinery itself: cases parse, checks can fail, orders are fitted right.

use data::BackendKind;
use data::cases::{Case, CaseSettings, Norm, Reference, SuiteName, all_cases, stability_cases};
use verify::suite::evaluate::{Status, evaluate};
use verify::suite::order::{fit_order, richardson};
use verify::suite::run_cache::RunCache;

#[test]
fn sys_every_embedded_case_file_parses() {
    let cases = all_cases().unwrap();
    assert!(cases.iter().any(|c| c.suite == SuiteName::Quick));
    for c in &cases {
        assert!(
            !c.why.trim().is_empty(),
            "{}: no reason for its tolerance",
            c.id
        );
    }
    stability_cases().unwrap();
}

#[test]
fn prop_order_fit_recovers_a_known_power_law() {
    let h = [0.5, 0.25, 0.125, 0.0625];
    for p in [1.0, 2.0, 4.0] {
        let e: Vec<f64> = h.iter().map(|h: &f64| 3.0 * h.powf(p)).collect();
        assert!((fit_order(&h, &e).unwrap() - p).abs() < 1e-12);
    }
}

#[test]
fn prop_richardson_extrapolates_a_known_limit() {
    let h = [0.2, 0.1, 0.05];
    let q: Vec<f64> = h.iter().map(|h: &f64| 7.0 + 0.3 * h * h).collect();
    let (ext, p) = richardson(&h, &q, None).unwrap();
    assert!(
        (p - 2.0).abs() < 1e-9 && (ext - 7.0).abs() < 1e-12,
        "{ext} {p}"
    );
}

fn case(
    backend: BackendKind,
    settings: CaseSettings,
    quantity: &str,
    reference: Reference,
    tol: f64,
) -> Case {
    Case {
        id: "negative-control".into(),
        check: "frequency vs analytic".into(),
        scene: "cantilever".into(),
        overrides: Default::default(),
        backend,
        settings,
        quantity: quantity.into(),
        reference,
        norm: Norm::Relative,
        tolerance: tol,
        why: "deliberately impossible: proves the check can fail".into(),
        suite: SuiteName::Quick,
    }
}

#[test]
fn cross_a_two_element_mesh_cannot_meet_1e_8() {
    let c = case(
        BackendKind::Fem,
        CaseSettings {
            elements: Some(2),
            ..Default::default()
        },
        "freq2",
        Reference::Analytic {
            analytic: "clamped-free".into(),
        },
        1e-8,
    );
    let o = evaluate(&c, &RunCache::default());
    assert_eq!(o.status, Status::Fail, "{o:?}");
    assert!(o.message.contains("exceeds tolerance"), "{}", o.message);
    // …while the same check with a fine mesh and an honest tolerance passes.
    let c = case(
        BackendKind::Fem,
        CaseSettings {
            elements: Some(16),
            ..Default::default()
        },
        "freq2",
        Reference::Analytic {
            analytic: "clamped-free".into(),
        },
        1e-5,
    );
    assert_eq!(evaluate(&c, &RunCache::default()).status, Status::Pass);
}

#[test]
fn cross_unknown_quantities_and_references_are_errors_not_passes() {
    let c = case(
        BackendKind::Fem,
        CaseSettings::default(),
        "freq0",
        Reference::Zero { zero: true },
        1.0,
    );
    assert_eq!(evaluate(&c, &RunCache::default()).status, Status::Error);
    let c = case(
        BackendKind::Fem,
        CaseSettings::default(),
        "freq1",
        Reference::Analytic {
            analytic: "no-such-reference".into(),
        },
        1.0,
    );
    assert_eq!(evaluate(&c, &RunCache::default()).status, Status::Error);
}

#[test]
fn cross_cache_distinguishes_overridden_scenes_of_the_same_name() {
    use data::cases::scene_with_overrides;
    use verify::suite::quantity::Analysis;
    use verify::suite::run_cache::Answer;
    let cache = RunCache::default();
    let plain = data::load_scene("cantilever").unwrap();
    let mut overrides = std::collections::BTreeMap::new();
    overrides.insert(
        "link[0].bending_stiffness".to_string(),
        toml::Value::Float(700.0),
    );
    let stiff = scene_with_overrides("cantilever", &overrides).unwrap();
    assert_eq!(plain.name, stiff.name);
    let settings = data::Settings::default();
    let f = |s: &data::Scene| match cache.get(s, BackendKind::Fem, &settings, Analysis::Modes, 4) {
        Answer::Modes(Ok(r)) => r.frequencies_hz[0],
        other => panic!("{other:?}"),
    };
    // EI × 4 doubles every bending frequency.
    assert!((f(&stiff) / f(&plain) - 2.0).abs() < 1e-9);
}

#[test]
fn prop_contact_quantities_read_the_events_and_refuse_missing_ones() {
    use data::{Event, RunResult};
    use verify::suite::quantity::Quantity;
    let scene = data::load_scene("barhorst-case1").unwrap();
    for bad in ["impulse0", "impulse", "release_time-1", "impact_timex"] {
        assert!(Quantity::parse(bad, &scene).is_err(), "{bad} parsed");
    }
    let impact = |t: f64, impulse: f64| Event::Impact {
        t,
        contact: 1,
        velocity_before: vec![],
        velocity_after: vec![],
        impulse,
        momentum_residual: 1e-16,
        normal_velocity_before: -1.0,
        normal_velocity_after: 0.0,
        kinetic_energy_lost: 1.0,
    };
    let mut run = RunResult {
        backend: BackendKind::Modal,
        scene: scene.name.clone(),
        settings: Default::default(),
        observables: Default::default(),
        ledger: data::EnergyLedger::new(&[], &[], &[]),
        events: vec![],
        cost: Default::default(),
        verdict: data::StabilityVerdict::Completed,
    };
    let q = |text: &str| Quantity::parse(text, &scene).unwrap();
    // No impact: neither a momentum residual of 0 nor an impulse.
    assert!(q("max_momentum_residual").from_run(&run).is_err());
    assert!(q("impulse1").from_run(&run).is_err());
    run.events = vec![
        impact(0.25, 7.0),
        Event::Release {
            t: 0.3,
            contact: 1,
            normal_force: 0.0,
            time_tolerance: 1e-12,
        },
        impact(0.34, 1.0),
    ];
    assert_eq!(q("impulse2").from_run(&run), Ok(1.0));
    assert_eq!(q("impact_time1").from_run(&run), Ok(0.25));
    assert_eq!(q("release_time1").from_run(&run), Ok(0.3));
    assert!(q("release_time2").from_run(&run).is_err());
    assert_eq!(q("max_momentum_residual").from_run(&run), Ok(1e-16));
}

/// The damped two-link arm over its first 0.5 s, fem 4 elements, refined in time.
fn history_ladder_case(quantity: &str, reference: Reference, tolerance: f64) -> Case {
    let rung = |dt: f64| CaseSettings {
        elements: Some(4),
        dt: Some(dt),
        t_end: Some(0.5),
        ..Default::default()
    };
    let reference = match reference {
        Reference::Order { order, against, .. } => Reference::Order {
            order,
            against,
            ladder: [4e-3, 2e-3, 1e-3, 5e-4].map(rung).to_vec(),
        },
        _ => Reference::Richardson {
            richardson: [2e-3, 1e-3, 5e-4].map(rung).to_vec(),
        },
    };
    Case {
        id: "history-ladder".into(),
        check: "convergence of a whole history".into(),
        scene: "two-link-free".into(),
        overrides: Default::default(),
        backend: BackendKind::Fem,
        settings: rung(5e-4),
        quantity: quantity.into(),
        reference,
        norm: Norm::RelativeToPeak,
        tolerance,
        why: "energy-midpoint rule: second order in dt on the whole history".into(),
        suite: SuiteName::Full,
    }
}

#[test]
fn conv_history_ladder_observes_the_time_order_and_can_fail() {
    let cache = RunCache::default();
    let order = |p: f64| Reference::Order {
        order: p,
        ladder: Vec::new(),
        against: None,
    };
    // The raw history: over 0.5 s a 20 Hz low-pass is dominated by its edges and the start
    // transient (differences 5.0e-4, 3.2e-4, 6.0e-5: no order), the raw history is not.
    let quantity = "history:joint1.angle";
    let o = evaluate(&history_ladder_case(quantity, order(2.0), 0.3), &cache);
    assert_eq!(o.status, Status::Pass, "{quantity}: {}", o.message);
    let observed = o.value.unwrap();
    // Negative control: the same ladder cannot pass as fourth order.
    let o = evaluate(&history_ladder_case(quantity, order(4.0), 0.3), &cache);
    assert_eq!(o.status, Status::Fail, "{quantity}: observed {observed}");
    // An analytic `against` has no meaning for a history ladder: an error, not a pass.
    let against = Reference::Order {
        order: 2.0,
        ladder: Vec::new(),
        against: Some("rigid-two-link".into()),
    };
    let o = evaluate(
        &history_ladder_case("history:joint1.angle", against, 0.3),
        &cache,
    );
    assert_eq!(o.status, Status::Error);
}

#[test]
fn conv_history_richardson_is_closer_than_the_rung_spacing_and_can_fail() {
    let cache = RunCache::default();
    let q = "lowpass20:history:joint1.angle";
    let richardson = || Reference::Richardson {
        richardson: Vec::new(),
    };
    // The finest rung against the extrapolation: about d/(2^p − 1) of the last difference.
    let o = evaluate(&history_ladder_case(q, richardson(), 1.0), &cache);
    assert_eq!(o.status, Status::Pass, "{}", o.message);
    let fine = o.error.unwrap();
    // A coarser run (dt 4e-3) lies much farther from the same limit: a tight tolerance fails.
    let mut coarse = history_ladder_case(q, richardson(), 2.0 * fine);
    coarse.settings.dt = Some(4e-3);
    let o = evaluate(&coarse, &cache);
    assert_eq!(o.status, Status::Fail, "coarse error {:?}", o.error);
    assert!(o.error.unwrap() > 10.0 * fine);
}

#[test]
fn prop_ladder_rung_sizes_follow_the_refined_parameter() {
    use verify::suite::evaluate::ladder_rung_sizes;
    let s = |elements: usize, dt: f64| CaseSettings {
        elements: Some(elements),
        dt: Some(dt),
        ..Default::default()
    };
    // A space ladder at one pinned step is sized by the elements, a time ladder by dt.
    let space = ladder_rung_sizes(&[s(4, 2.5e-4), s(8, 2.5e-4), s(16, 2.5e-4)]).unwrap();
    assert_eq!(space, vec![0.25, 0.125, 0.0625]);
    let time = ladder_rung_sizes(&[s(8, 1e-3), s(8, 5e-4), s(8, 2.5e-4)]).unwrap();
    assert_eq!(time, vec![1e-3, 5e-4, 2.5e-4]);
    assert!(ladder_rung_sizes(&[s(8, 1e-3), s(8, 1e-3)]).is_err());
}

#[test]
fn conv_point_value_space_ladder_at_one_pinned_step_is_sized_by_its_elements() {
    // A ladder that pins dt on every rung refines the mesh: its rungs are sized 1/elements,
    // as a history ladder's are. Sized by the pinned dt, every rung had one size and no
    // order could be fitted.
    let cache = RunCache::default();
    let rung = |elements: usize| CaseSettings {
        elements: Some(elements),
        dt: Some(1e-3),
        t_end: Some(0.3),
        ..Default::default()
    };
    let case = Case {
        id: "point-space-ladder".into(),
        check: "convergence: observed order in space".into(),
        scene: "two-link-free".into(),
        overrides: Default::default(),
        backend: BackendKind::Fem,
        settings: rung(8),
        quantity: "joint1.angle@0.3".into(),
        reference: Reference::Order {
            order: 4.0,
            against: None,
            ladder: [2, 4, 8].map(rung).to_vec(),
        },
        norm: Norm::Absolute,
        tolerance: 1.0,
        why: "Hermite cubics at one step: the mesh's order".into(),
        suite: SuiteName::Full,
    };
    // The point value's observed order lies near the elements' 4 (3.5 over 2/4/8 elements),
    // and the same ladder cannot pass as second order.
    let o = evaluate(&case, &cache);
    assert_eq!(o.status, Status::Pass, "{} {:?}", o.message, o.value);
    let second_order = Case {
        reference: Reference::Order {
            order: 2.0,
            against: None,
            ladder: [2, 4, 8].map(rung).to_vec(),
        },
        ..case
    };
    let o = evaluate(&second_order, &cache);
    assert_eq!(o.status, Status::Fail, "{:?}", o.value);
}
