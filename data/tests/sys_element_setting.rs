//! `discretization.element` (case settings): accepted values round-trip, unknown values are
//! refused with the line, column and the accepted names.

use data::FemElement;
use data::cases::parse_cases;

fn case_text(element: &str) -> String {
    format!(
        r#"
[[case]]
id = "x"
check = "frequency vs analytic"
scene = "cantilever"
backend = "fem"
settings = {{ elements = 16, element = "{element}" }}
quantity = "freq1"
reference = {{ analytic = "clamped-free" }}
norm = "relative"
tolerance = 1e-5
why = "test"
suite = "quick"
"#
    )
}

#[test]
fn sys_element_names_parse_and_round_trip() {
    for (name, want) in [
        ("hermite-cubic", FemElement::HermiteCubic),
        ("hermite-quintic", FemElement::HermiteQuintic),
    ] {
        assert_eq!(want.name(), name);
        assert!(FemElement::NAMES.contains(&name));
        let cases = parse_cases(&case_text(name), "t.toml").unwrap();
        let s = cases[0].settings.to_settings();
        assert_eq!(s.discretization.element, Some(want));
        // Serialize → parse gives the same settings.
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.contains(name), "{json}");
        let back: data::Settings = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
    }
    // Absent field: not serialized, so results written before the field existed compare equal.
    let json = serde_json::to_string(&data::Settings::default()).unwrap();
    assert!(!json.contains("\"element\""), "{json}");
}

#[test]
fn sys_unknown_element_is_refused_with_location_and_accepted_names() {
    let err = parse_cases(&case_text("hermite-septic"), "t.toml").unwrap_err();
    let msg = err.to_string();
    // The value sits on line 7 of the text above.
    assert_eq!(err.line, 7, "{msg}");
    assert!(msg.contains("hermite-septic"), "{msg}");
    for name in FemElement::NAMES {
        assert!(msg.contains(name), "{msg}");
    }
}
