//! The `verify` library used without its command line: cases, studies and errors through the
//! public API, results inspected as values.

use std::sync::atomic::{AtomicUsize, Ordering};

use data::{BackendKind, Settings, load_scene};
use verify::Error;
use verify::output::TERMINAL_WIDTH;
use verify::progress::{Progress, Silent};
use verify::study::ladder::{Refine, rung_specs};
use verify::study::measure::Timed;
use verify::study::recommend::recommend;
use verify::study::run::{converge, run_study};
use verify::suite::evaluate::Status;
use verify::suite::{Suite, report, run_cases, run_cases_with_progress};

/// Counts what a library call reports.
#[derive(Default)]
struct Counter {
    total: AtomicUsize,
    started: AtomicUsize,
    advanced: AtomicUsize,
    finished: AtomicUsize,
}

impl Progress for Counter {
    fn begin(&self, total: usize, _unit: &str) {
        self.total.fetch_add(total, Ordering::Relaxed);
    }
    fn start(&self, _item: &str) {
        self.started.fetch_add(1, Ordering::Relaxed);
    }
    fn advance(&self) {
        self.advanced.fetch_add(1, Ordering::Relaxed);
    }
    fn finish(&self) {
        self.finished.fetch_add(1, Ordering::Relaxed);
    }
}

#[test]
fn lib_one_quick_case_runs_and_its_outcome_is_inspected() {
    let id = "freq-cantilever-fem16-mode1";
    let progress = Counter::default();
    let (cases, outcomes, _cache) =
        run_cases_with_progress(Suite::Quick, Some(id), &progress).expect("the case runs");
    assert_eq!(cases.len(), 1);
    assert_eq!(outcomes.len(), 1);
    let o = &outcomes[0];
    assert_eq!(o.id, id);
    assert_eq!(o.status, Status::Pass, "{}", o.message);
    assert!(
        o.reference_label.starts_with("analytic:"),
        "{}",
        o.reference_label
    );
    // The outcome's error is what its value and reference say, and within its tolerance.
    let (value, reference) = (o.value.unwrap(), o.reference.unwrap());
    let error = o.error.unwrap();
    assert!(((value - reference).abs() / reference.abs() - error).abs() <= 1e-12 * error);
    assert!(error <= o.tolerance);
    // One case: one begin of one item, one start, one advance, one finish.
    assert_eq!(progress.total.load(Ordering::Relaxed), 1);
    assert_eq!(progress.started.load(Ordering::Relaxed), 1);
    assert_eq!(progress.advanced.load(Ordering::Relaxed), 1);
    assert_eq!(progress.finished.load(Ordering::Relaxed), 1);
}

#[test]
fn lib_bad_requests_are_typed_errors() {
    assert!(matches!(
        run_cases(Suite::Quick, Some("no-such-case")),
        Err(Error::NoCaseMatches { .. })
    ));
    let scene = load_scene("cantilever").unwrap();
    let kinds = [BackendKind::Fem];
    let settings = Settings::default();
    assert!(matches!(
        converge(&scene, "freq0x", Refine::Space, &kinds, &settings, &Silent),
        Err(Error::InvalidQuantity { .. })
    ));
    assert!(matches!(
        load_scene("no-such-scene").map_err(Error::from),
        Err(Error::Scene(_))
    ));
    // A tolerance no discretization meets names the best one measured.
    match recommend(
        &scene,
        "freq1",
        1e-30,
        Refine::Space,
        &[BackendKind::Fdm],
        &settings,
        None,
        &Silent,
    ) {
        Err(Error::ToleranceNotMet {
            best: Some((backend, _, error)),
            ..
        }) => {
            assert_eq!(backend, BackendKind::Fdm);
            assert!(error > 1e-30);
        }
        other => panic!("expected ToleranceNotMet, got {other:?}"),
    }
}

#[test]
fn lib_recommend_repeats_the_timings_of_its_picks_only() {
    // The choice across backends compares the picks' minimum wall times and spreads, so the
    // picks are timed with repeats; the other rungs keep their one run's time.
    let scene = load_scene("cantilever").unwrap();
    let kinds = [BackendKind::Fem, BackendKind::Modal];
    let settings = Settings::default();
    let r = recommend(
        &scene,
        "freq1",
        1e-4,
        Refine::Space,
        &kinds,
        &settings,
        None,
        &Silent,
    )
    .unwrap();
    assert_eq!(r.runners_up.len(), 1, "{r:?}");
    for pick in std::iter::once(&r.rung).chain(&r.runners_up) {
        assert!(
            pick.timing.repeats >= verify::work::MIN_REPEATS,
            "{} {}: {:?}",
            pick.backend,
            pick.discretization,
            pick.timing
        );
        assert_eq!(pick.wall_time_s, pick.timing.min_s);
    }
    let once = run_study(
        &scene,
        "freq1",
        Refine::Space,
        &kinds,
        &settings,
        None,
        Timed::Once,
        &Silent,
    )
    .unwrap();
    for rung in once.ladders.iter().flat_map(|l| &l.rungs) {
        assert_eq!(rung.timing.repeats, 1, "{}", rung.discretization);
    }
}

#[test]
fn lib_converge_reports_every_rung_and_the_fem_order() {
    let scene = load_scene("cantilever").unwrap();
    let progress = Counter::default();
    let study = converge(
        &scene,
        "freq1",
        Refine::Space,
        &[BackendKind::Fem],
        &Settings::default(),
        &progress,
    )
    .unwrap();
    let rungs = study.ladders[0].rungs.len();
    assert!(rungs >= 4);
    assert_eq!(progress.total.load(Ordering::Relaxed), rungs);
    assert_eq!(progress.advanced.load(Ordering::Relaxed), rungs);
    // Hermite cubics: frequency error O(h⁴).
    let order = study.ladders[0].observed_order.unwrap();
    assert!((order - 4.0).abs() < 0.3, "{order}");
}

#[test]
fn lib_space_time_ladder_scales_each_rungs_step_like_its_spacing() {
    let scene = load_scene("barhorst-case1").unwrap();
    let out = scene.simulation.output_interval;
    let kinds = [BackendKind::Fem, BackendKind::Fdm, BackendKind::Modal];
    let ladders = rung_specs(&scene, Refine::SpaceTime, &kinds, &Settings::default());
    let space = rung_specs(&scene, Refine::Space, &kinds, &Settings::default());
    for ((kind, rungs), (_, space_rungs)) in ladders.iter().zip(&space) {
        // the space ladder's meshes and spacings, rung for rung
        assert_eq!(rungs.len(), space_rungs.len(), "{kind:?}");
        for ((s, h, _), (s0, h0, _)) in rungs.iter().zip(space_rungs) {
            assert_eq!(h, h0);
            assert_eq!(s.discretization, s0.discretization);
        }
        let h_first = rungs[0].1;
        for (s, h, label) in rungs {
            match kind {
                // fixed steps: the coarsest rung at the output interval, dt ∝ h after it
                BackendKind::Fem => {
                    let dt = s.time.dt.unwrap();
                    assert!((dt - out * h / h_first).abs() <= 1e-15 * out, "{label}");
                    assert!(label.contains("dt="), "{label}");
                }
                // fdm's stability step and modal's adaptive step stay the backend's own
                _ => assert_eq!(s.time.dt, None, "{kind:?} {label}"),
            }
        }
    }
    // A requested fdm step is scaled like h², the way its stability bound falls.
    let mut base = Settings::default();
    base.time.dt = Some(1e-5);
    let fdm = &rung_specs(&scene, Refine::SpaceTime, &[BackendKind::Fdm], &base)[0].1;
    let h_first = fdm[0].1;
    for (s, h, label) in fdm {
        let expected = 1e-5 * (h / h_first).powi(2);
        assert!(
            (s.time.dt.unwrap() - expected).abs() <= 1e-15 * expected,
            "{label}"
        );
    }
}

#[test]
fn lib_terminal_table_cuts_only_long_case_ids() {
    let (_, outcomes, _) = run_cases(Suite::Quick, Some("static-cantilever")).unwrap();
    let mut long = outcomes[0].clone();
    long.id = format!("{}-{}", long.id, "x".repeat(150));
    long.status = Status::Fail;
    let mut all = outcomes.clone();
    all.push(long.clone());
    let table = report::terminal_table(&all, TERMINAL_WIDTH);
    let row = table
        .lines()
        .find(|l| l.starts_with("FAIL ") && l.contains('…'))
        .unwrap_or_else(|| panic!("no cut FAIL row:\n{table}"));
    assert!(row.chars().count() <= TERMINAL_WIDTH, "{row}");
    // The error, tolerance and wall time survive the cut.
    assert!(
        row.contains(&format!("{:.2e}", long.error.unwrap())),
        "{row}"
    );
    assert!(row.contains(&format!("{:.1e}", long.tolerance)), "{row}");
    // Short ids are not cut, and the failing group comes first.
    for o in &outcomes {
        assert!(table.contains(&o.id), "{} cut:\n{table}", o.id);
    }
    let first_group = table.lines().nth(3).unwrap();
    assert!(first_group.contains("1 FAILED"), "{table}");
}

#[test]
fn lib_ledger_terms_are_point_and_peak_quantities() {
    use verify::suite::quantity::Quantity;
    let scene = load_scene("single-link").unwrap();
    let mut settings = Settings::default();
    settings.time.t_end = Some(0.5);
    let run = verify::registry::backend(BackendKind::Fem)
        .simulate(&scene, &settings)
        .unwrap();
    let ledger = &run.ledger;
    let kinetic = ledger
        .stored
        .iter()
        .find(|t| t.name == "kinetic")
        .expect("a kinetic term");
    // At a ledger sample the point quantity is that sample; between two it interpolates.
    let k = ledger.time.len() / 2;
    let at = |t: f64| {
        Quantity::parse(&format!("energy.kinetic@{t}"), &scene)
            .unwrap()
            .from_run(&run)
            .unwrap()
    };
    assert_eq!(at(ledger.time[k]), kinetic.values[k]);
    let mid = 0.5 * (ledger.time[k] + ledger.time[k + 1]);
    let expected = 0.5 * (kinetic.values[k] + kinetic.values[k + 1]);
    assert!((at(mid) - expected).abs() <= 1e-15 * expected.abs());
    let peak = Quantity::parse("peak:energy.kinetic", &scene)
        .unwrap()
        .from_run(&run)
        .unwrap();
    assert_eq!(
        peak,
        kinetic.values.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    );
    // A term the scene does not build is named as missing, not read as zero.
    let err = Quantity::parse("energy.impact@0.1", &scene)
        .unwrap()
        .from_run(&run)
        .unwrap_err();
    assert!(
        err.contains("no ledger term `energy.impact`") && err.contains("energy.kinetic"),
        "{err}"
    );
}
