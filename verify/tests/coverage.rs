//! Cross-check coverage is enforced: every scene that two backends run is compared over a whole
//! history of a frame-invariant observable, every backend that runs a scene has a convergence
//! row, and every listed exception is real and still needed.

use data::BackendKind;
use data::cases::{Case, CaseSettings, Norm, Reference, SuiteName, all_cases, stability_cases};
use data::channel::frame_invariant;
use data::coverage::{CoverageException, MissingCheck, coverage_exceptions};
use verify::coverage::{CheckKind, analyse, analyse_embedded, row_kinds};

fn listing(gaps: &[String]) -> String {
    gaps.join("\n  ")
}

#[test]
fn sys_coverage_every_gap_is_covered_or_listed() {
    let c = analyse_embedded().unwrap();
    let gaps: Vec<String> = c
        .unexcused()
        .map(|g| {
            let b: Vec<&str> = g.backends.iter().map(|b| b.name()).collect();
            format!("{} {} {}", g.scene, g.missing.name(), b.join("+"))
        })
        .collect();
    assert!(
        gaps.is_empty(),
        "{} gap(s) neither covered by a row nor listed in \
         data/cases/coverage-exceptions.toml:\n  {}",
        gaps.len(),
        listing(&gaps)
    );
}

#[test]
fn sys_coverage_exceptions_name_real_scenes_and_are_still_needed() {
    let c = analyse_embedded().unwrap();
    let stale: Vec<String> = c
        .stale_exceptions
        .iter()
        .map(|(x, why)| format!("{} {}: {why}", x.scene, x.missing.name()))
        .collect();
    assert!(stale.is_empty(), "stale exceptions:\n  {}", listing(&stale));
    for x in coverage_exceptions().unwrap() {
        assert!(
            x.reason.contains("issue") || x.reason.len() > 60,
            "{} {}: the reason must say why (measured disagreement, cost) and what closes it",
            x.scene,
            x.missing.name()
        );
    }
}

fn row(id: &str, scene: &str, backend: BackendKind, quantity: &str, reference: Reference) -> Case {
    Case {
        id: id.into(),
        check: "test".into(),
        scene: scene.into(),
        overrides: Default::default(),
        backend,
        settings: CaseSettings::default(),
        quantity: quantity.into(),
        reference,
        norm: Norm::RelativeToPeak,
        tolerance: 1e-3,
        why: "test".into(),
        suite: SuiteName::Quick,
    }
}

fn against(backend: BackendKind) -> Reference {
    Reference::Backend {
        backend,
        settings: CaseSettings::default(),
        overrides: Default::default(),
    }
}

#[test]
fn sys_coverage_row_kinds_are_derived_from_reference_and_quantity() {
    use BackendKind::{Fdm, Fem, Modal};
    let scene = data::load_scene("two-link-free").unwrap();
    let kinds =
        |c: &Case| -> Vec<CheckKind> { row_kinds(c, &scene).into_iter().map(|k| k.0).collect() };
    let tip = row("a", "two-link-free", Fem, "history:tip_x", against(Modal));
    assert_eq!(kinds(&tip), vec![CheckKind::CrossHistory]);
    assert_eq!(row_kinds(&tip, &scene)[0].1, vec![Fem, Modal]);
    let filtered = row(
        "b",
        "two-link-free",
        Fem,
        "lowpass20:history:joint1.angle",
        against(Fdm),
    );
    assert_eq!(kinds(&filtered), vec![CheckKind::CrossHistory]);
    // A deflection in the link's floating frame is not frame-invariant: a point check only.
    let frame = row(
        "c",
        "two-link-free",
        Fem,
        "history:tip_deflection",
        against(Modal),
    );
    assert_eq!(kinds(&frame), vec![CheckKind::CrossPoint]);
    let at = row("d", "two-link-free", Fem, "link2.tip_x@1", against(Modal));
    assert_eq!(kinds(&at), vec![CheckKind::CrossPoint]);
    let energy = row(
        "e",
        "two-link-free",
        Fem,
        "history:energy.kinetic",
        against(Modal),
    );
    assert_eq!(
        kinds(&energy),
        vec![CheckKind::LedgerTerms, CheckKind::CrossHistory]
    );
    let closure = row(
        "f",
        "two-link-free",
        Fdm,
        "ledger_closure",
        Reference::Zero { zero: true },
    );
    assert_eq!(kinds(&closure), vec![CheckKind::LedgerClosure]);
    let order = row(
        "g",
        "two-link-free",
        Modal,
        "joint1.angle@2",
        Reference::Richardson {
            richardson: vec![CaseSettings::default(); 3],
        },
    );
    assert_eq!(kinds(&order), vec![CheckKind::Convergence]);
    assert!(frame_invariant("link2.tip_y") && frame_invariant("joint2.angle"));
    assert!(frame_invariant("energy.strain") && frame_invariant("rocket.X"));
    assert!(!frame_invariant("link1.tip_deflection") && !frame_invariant("link1.v@3"));
    assert!(frame_invariant("rocket.mass1.u") && frame_invariant("rocket.w@3"));
    assert!(!frame_invariant("rocket.theta") && !frame_invariant("rocket.w@"));
}

#[test]
fn sys_coverage_detects_a_missing_cross_row_and_a_stale_exception() {
    let cases = all_cases().unwrap();
    let stability = stability_cases().unwrap();
    let exceptions = coverage_exceptions().unwrap();
    // Without the cross-history rows of a scene that three backends run, all its pairs that
    // no exception lists become gaps.
    let scene = "two-link-free";
    let without: Vec<Case> = cases
        .iter()
        .filter(|c| {
            let s = data::load_scene(&c.scene).unwrap();
            !(c.scene == scene
                && row_kinds(c, &s)
                    .iter()
                    .any(|k| k.0 == CheckKind::CrossHistory))
        })
        .cloned()
        .collect();
    let c = analyse(&without, &stability, &exceptions).unwrap();
    let gaps: Vec<_> = c
        .unexcused()
        .filter(|g| g.scene == scene && g.missing == MissingCheck::CrossHistory)
        .collect();
    assert!(!gaps.is_empty(), "removing the cross rows left no gap");
    // An exception for a gap that rows cover, and one for an unknown scene, are stale.
    let mut extra = exceptions.clone();
    extra.push(CoverageException {
        scene: "cantilever".into(),
        backends: vec![BackendKind::Fem],
        missing: MissingCheck::Convergence,
        reason: "covered".into(),
    });
    extra.push(CoverageException {
        scene: "no-such-scene".into(),
        backends: vec![BackendKind::Fem],
        missing: MissingCheck::Convergence,
        reason: "unknown".into(),
    });
    let c = analyse(&cases, &stability, &extra).unwrap();
    let stale: Vec<&str> = c
        .stale_exceptions
        .iter()
        .map(|(x, _)| x.scene.as_str())
        .collect();
    assert_eq!(stale, vec!["cantilever", "no-such-scene"]);
}

#[test]
fn sys_coverage_runners_are_the_backends_own_answers() {
    // The clamped cantilever is planned by fdm (for modes and statics) but not integrated in
    // time: its own `simulate` answer says so, and coverage follows it.
    let scene = data::load_scene("cantilever").unwrap();
    let fdm = verify::coverage::capability(&scene, BackendKind::Fdm).unwrap();
    let direct = verify::registry::backend(BackendKind::Fdm).simulate(&scene, &Default::default());
    assert_eq!(
        fdm.unsupported.is_some(),
        matches!(direct, Err(data::BackendError::Unsupported(_)))
    );
    let c = analyse_embedded().unwrap();
    for s in &c.scenes {
        let scene = data::load_scene(&s.scene).unwrap();
        for cap in &s.capabilities {
            let plan = verify::registry::backend(cap.backend)
                .dof_plan(&scene, &data::Discretization::default());
            if plan.is_err() {
                assert!(cap.unsupported.is_some(), "{} {}", s.scene, cap.backend);
            }
        }
    }
}
