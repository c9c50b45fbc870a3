//! Settings a backend does not read are refused at the case-file boundary (naming the file,
//! the row and the field), and the per-backend view and resolution accessors keep exactly the
//! fields each backend reads.

use data::cases::{all_cases, parse_cases, stability_cases};
use data::{BackendKind, SettingField, Settings};

fn case_text(backend: &str, settings: &str, reference: &str) -> String {
    format!(
        r#"
[[case]]
id = "row-under-test"
check = "frequency vs analytic"
scene = "cantilever"
backend = "{backend}"
settings = {{ {settings} }}
quantity = "freq1"
reference = {reference}
norm = "relative"
tolerance = 1e-5
why = "test"
suite = "quick"
"#
    )
}

const ANALYTIC: &str = r#"{ analytic = "clamped-free" }"#;

#[test]
fn sys_case_row_with_a_foreign_field_is_refused_naming_file_row_and_field() {
    for (backend, settings, field, readers) in [
        ("fem", "modes = 8", "modes", "modal"),
        ("fem", r#"basis = "poly""#, "basis", "modal"),
        ("modal", "elements = 16", "elements", "fem"),
        ("fdm", "rtol = 1e-6", "rtol", "fem, modal and reference"),
        (
            "modal",
            "safety_factor = 0.5",
            "safety_factor",
            "fem and fdm",
        ),
        ("reference", "dt = 0.001", "dt", "fem, fdm and modal"),
    ] {
        let err = parse_cases(&case_text(backend, settings, ANALYTIC), "rows.toml").unwrap_err();
        let text = err.to_string();
        assert_eq!(err.source_name, "rows.toml");
        assert_eq!(err.path, format!("case[0].settings.{field}"), "{text}");
        assert!(text.contains("row `row-under-test`"), "{text}");
        assert!(
            text.contains(&format!(
                "`{field}` applies to {readers}; the row's backend {backend} does not read it"
            )),
            "{text}"
        );
    }
}

#[test]
fn sys_case_row_with_a_method_its_backend_does_not_implement_is_refused() {
    for (backend, method, implementers) in [
        ("fem", "dopri5", "modal"),
        ("modal", "report", "fdm"),
        ("fdm", "generalized-alpha", "fem"),
        ("reference", "dopri5", "modal"),
    ] {
        let settings = format!(r#"method = "{method}""#);
        let err = parse_cases(&case_text(backend, &settings, ANALYTIC), "m.toml").unwrap_err();
        assert_eq!(err.path, "case[0].settings.method", "{err}");
        assert!(
            err.to_string().contains(&format!(
                "row `row-under-test`: `method = {method}` applies to {implementers}; the row's \
                 backend {backend} does not implement it"
            )),
            "{err}"
        );
    }
    // central-difference is implemented by fem and fdm both.
    for backend in ["fem", "fdm"] {
        let settings = r#"method = "central-difference""#;
        parse_cases(&case_text(backend, settings, ANALYTIC), "m.toml").unwrap();
    }
}

#[test]
fn sys_for_backend_passes_a_method_only_to_the_backends_implementing_it() {
    let mut s = Settings::default();
    s.time.method = Some(data::Method::Dopri5);
    assert_eq!(s.for_backend(BackendKind::Modal).time.method, s.time.method);
    assert_eq!(s.for_backend(BackendKind::Fem).time.method, None);
    assert!(s.unread_by(&BackendKind::ALL).is_empty());
    assert_eq!(
        s.unread_by(&[BackendKind::Fem, BackendKind::Fdm]),
        vec![SettingField::Method]
    );
    s.time.method = Some(data::Method::CentralDifference);
    assert!(s.unread_by(&[BackendKind::Fem]).is_empty());
    assert!(s.unread_by(&[BackendKind::Fdm]).is_empty());
    assert_eq!(
        s.unread_by(&[BackendKind::Modal]),
        vec![SettingField::Method]
    );
}

#[test]
fn sys_case_ladder_and_reference_settings_are_checked_against_their_backend() {
    let ladder = r#"{ order = 4.0, ladder = [{ elements = 4 }, { modes = 8 }] }"#;
    let err = parse_cases(&case_text("fem", "elements = 4", ladder), "l.toml").unwrap_err();
    assert_eq!(err.path, "case[0].reference.ladder[1].modes", "{err}");

    let other = r#"{ backend = "modal", settings = { elements = 16 } }"#;
    let err = parse_cases(&case_text("fem", "elements = 4", other), "r.toml").unwrap_err();
    assert_eq!(err.path, "case[0].reference.settings.elements", "{err}");
    assert!(
        err.to_string().contains("backend modal does not read it"),
        "{err}"
    );

    // The same fields where their backends read them are accepted.
    let good = r#"{ backend = "modal", settings = { modes = 8, basis = "poly" } }"#;
    parse_cases(&case_text("fem", "elements = 4, dt = 0.01", good), "g.toml").unwrap();
}

#[test]
fn sys_embedded_case_and_stability_rows_set_only_fields_their_backends_read() {
    let cases = all_cases().unwrap();
    assert!(!cases.is_empty());
    for c in &cases {
        for (path, backend, s) in c.settings_for_backends() {
            assert!(
                s.to_settings().unread_by(&[backend]).is_empty(),
                "{} {path}",
                c.id
            );
        }
    }
    for c in stability_cases().unwrap() {
        assert!(
            c.settings.to_settings().unread_by(&c.backends).is_empty(),
            "{}",
            c.id
        );
    }
}

fn every_field_set() -> Settings {
    let mut s = Settings::default();
    let (d, t) = (&mut s.discretization, &mut s.time);
    d.elements = Some(8);
    d.element = Some(data::FemElement::HermiteQuintic);
    d.stations = Some(21);
    d.modes = Some(4);
    d.basis = Some(data::Basis::Poly);
    t.dt = Some(1e-3);
    t.t_end = Some(0.5);
    t.output_interval = Some(1e-3);
    t.method = Some(data::Method::Trapezoid);
    t.rtol = Some(1e-6);
    t.atol = Some(1e-9);
    t.safety_factor = Some(0.5);
    s
}

#[test]
fn sys_for_backend_keeps_exactly_the_fields_the_backend_reads() {
    let all = every_field_set();
    assert_eq!(all.set_fields(), SettingField::ALL.to_vec());
    for kind in BackendKind::ALL.into_iter().chain([BackendKind::Reference]) {
        let own = all.for_backend(kind);
        let kept = own.set_fields();
        for f in SettingField::ALL {
            assert_eq!(kept.contains(&f), all.read_by(f, kind), "{kind} {f}");
            // Only the method depends on the value (trapezoid: modal's alone).
            let method_of_another = f == SettingField::Method && kind != BackendKind::Modal;
            assert_eq!(all.read_by(f, kind), f.read_by(kind) && !method_of_another);
        }
        assert!(own.unread_by(&[kind]).is_empty());
        // Clearing is the only change: what is kept keeps its value.
        assert_eq!(own.for_backend(kind), own);
    }
    assert_eq!(
        all.for_backend(BackendKind::Fem).discretization.elements,
        Some(8)
    );
    assert_eq!(
        all.for_backend(BackendKind::Fdm).time.safety_factor,
        Some(0.5)
    );
    assert!(all.unread_by(&BackendKind::ALL).is_empty());
    assert_eq!(
        all.for_backend(BackendKind::Modal).time.method,
        Some(data::Method::Trapezoid)
    );
}

#[test]
fn sys_resolution_accessor_sets_each_backends_own_field() {
    let base = Settings::default();
    for kind in BackendKind::ALL {
        let s = base.with_resolution(kind, 12);
        assert_eq!(s.resolution(kind), Some(12));
        let field = Settings::resolution_field(kind).unwrap();
        assert_eq!(s.set_fields(), vec![field]);
        assert!(field.read_by(kind));
    }
    assert_eq!(
        base.with_resolution(BackendKind::Reference, 12),
        Settings::default()
    );
    assert_eq!(Settings::resolution_field(BackendKind::Reference), None);
}

#[test]
fn sys_command_line_gives_each_set_field_once_with_its_flag() {
    let mut s = Settings::default();
    assert!(s.command_line().is_empty(), "defaults need no flag");
    s.discretization.elements = Some(4);
    s.time.dt = Some(5e-4);
    s.time.t_end = Some(2.0);
    s.time.method = Some("implicit-midpoint".parse().unwrap());
    let flags = s.command_line();
    assert_eq!(
        flags,
        [
            "--elements 4",
            "--method implicit-midpoint",
            "--dt 0.0005",
            "--t-end 2"
        ]
    );
}

#[test]
fn sys_output_interval_replaces_the_scenes_and_refuses_what_cannot_be_stored() {
    use std::borrow::Cow;
    let scene = data::load_scene("single-link").unwrap();
    assert!(matches!(
        data::sampled_as(&scene, None, None),
        Ok(Cow::Borrowed(_))
    ));
    let fine = data::sampled_as(&scene, Some(1e-4), None).unwrap();
    assert_eq!(fine.simulation.output_interval, 1e-4);
    let mut back = fine.into_owned();
    back.simulation.output_interval = scene.simulation.output_interval;
    assert_eq!(back, scene, "only the output interval changes");

    let refused =
        |interval: f64, t_end: Option<f64>| match data::sampled_as(&scene, Some(interval), t_end) {
            Err(data::BackendError::InvalidSettings { field, message }) => {
                assert_eq!(field, "time.output_interval");
                message
            }
            other => panic!("{interval} (t_end {t_end:?}) was not refused: {other:?}"),
        };
    for bad in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        assert!(refused(bad, None).contains("finite number > 0"));
    }
    // The sample count is counted to the run's end: the end-time override moves the limit.
    let limit = data::validate::limits::MAX_OUTPUT_SAMPLES;
    assert!(data::sampled_as(&scene, Some(1.0), Some(limit)).is_ok());
    let message = refused(1.0, Some(2.0 * limit));
    assert!(message.contains("above the limit"), "{message}");
    let message = refused(scene.simulation.t_end / (2.0 * limit), None);
    assert!(
        message.contains("give a larger output interval"),
        "{message}"
    );
    // An end-time override alone is held to the same limit, at the scene's spacing.
    let far = 2.0 * limit * scene.simulation.output_interval;
    match data::sampled_as(&scene, None, Some(far)) {
        Err(data::BackendError::InvalidSettings { field, message }) => {
            assert_eq!(field, "time.t_end");
            assert!(message.contains("above the limit"), "{message}");
        }
        other => panic!("t_end {far} was not refused: {other:?}"),
    }
    let near = 0.5 * limit * scene.simulation.output_interval;
    assert!(matches!(
        data::sampled_as(&scene, None, Some(near)),
        Ok(Cow::Borrowed(_))
    ));
}
