//! Hand-made bad scene files: each gives one precise message (file, line, column, field path,
//! expected form) and never a panic.

use data::{SceneError, parse_scene};

const GOOD: &str = include_str!("../scenes/single-link.toml");

fn err(text: &str) -> SceneError {
    match parse_scene(text, "bad.toml") {
        Ok(_) => panic!("accepted a bad scene:\n{text}"),
        Err(e) => e,
    }
}

/// Line (1-based) of the first occurrence of `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .expect("needle")
        + 1
}

#[test]
fn unknown_key_is_named_with_its_line() {
    let text = GOOD.replace(
        "bending_stiffness = 10.0",
        "bending_stiffness = 10.0\nbending_stifness = 3.0",
    );
    let e = err(&text);
    assert_eq!(e.line, line_of(&text, "bending_stifness"), "{e}");
    assert!(e.message.contains("bending_stifness"), "{e}");
    assert!(e.expected.contains("bending_stiffness"), "{e}");
    assert!(e.to_string().starts_with("bad.toml:"), "{e}");
}

#[test]
fn missing_field_names_the_table() {
    let text = GOOD.replace("mass_per_length = 1.0\n", "");
    let e = err(&text);
    assert!(e.message.contains("mass_per_length"), "{e}");
    assert!(e.path.starts_with("link[0]"), "{e}");
}

#[test]
fn negative_length_points_at_the_value() {
    let text = GOOD.replace("length = 1.0", "length = -1.0");
    let e = err(&text);
    assert_eq!(e.path, "link[0].length");
    assert_eq!(e.line, line_of(&text, "length = -1.0"));
    assert_eq!(e.column, "length = ".len() + 1, "{e}");
    assert!(e.expected.contains("> 0"));
}

#[test]
fn zero_stiffness_is_rejected() {
    let e = err(&GOOD.replace("bending_stiffness = 10.0", "bending_stiffness = 0.0"));
    assert_eq!(e.path, "link[0].bending_stiffness");
}

#[test]
fn non_finite_number_is_rejected() {
    for bad in ["nan", "inf", "-inf", "+nan"] {
        let text = GOOD.replace("tip_mass = 0.5", &format!("tip_mass = {bad}"));
        let e = err(&text);
        assert_eq!(e.path, "link[0].tip_mass", "{e}");
        assert_eq!(e.line, line_of(&text, "tip_mass"));
    }
}

#[test]
fn malformed_toml_gives_position() {
    let text = GOOD.replace("length = 1.0", "length = = 1.0");
    let e = err(&text);
    assert_eq!(e.line, line_of(&text, "length = = 1.0"), "{e}");
    assert!(e.message.contains("malformed TOML"));
}

#[test]
fn wrong_type_names_expected_type() {
    let e = err(&GOOD.replace("length = 1.0", "length = \"one\""));
    assert_eq!(e.path, "link[0].length", "{e}");
    assert!(
        e.expected.contains("f64") || e.expected.contains("float"),
        "{e}"
    );
}

#[test]
fn axial_with_foreshortening_is_contradictory() {
    let text = GOOD.replace(
        "tip_mass = 0.5",
        "tip_mass = 0.5\naxial = true\nforeshortening = true\naxial_stiffness = 1e6",
    );
    let e = err(&text);
    assert!(e.message.contains("contradictory"), "{e}");
    assert_eq!(e.path, "link[0].foreshortening");
    assert_eq!(e.line, line_of(&text, "foreshortening = true"));
}

#[test]
fn axial_without_ea_asks_for_it() {
    let e = err(&GOOD.replace("tip_mass = 0.5", "tip_mass = 0.5\naxial = true"));
    assert_eq!(e.path, "link[0].axial_stiffness");
}

#[test]
fn contact_naming_a_missing_link_lists_the_names() {
    let text = format!(
        "{GOOD}\n[[contact]]\nlink = \"elbow\"\nsurface = {{ kind = \"line\", point = [0.0, -1.0], normal = [0.0, 1.0] }}\nmode = \"unilateral\"\n"
    );
    let e = err(&text);
    assert_eq!(e.path, "contact[0].link");
    assert!(
        e.message.contains("elbow") && e.expected.contains("link"),
        "{e}"
    );
    assert_eq!(e.line, line_of(&text, "link = \"elbow\""));
}

#[test]
fn absurd_sizes_are_refused() {
    let e = err(&GOOD.replace("output_interval = 0.005", "output_interval = 1e-12"));
    assert_eq!(e.path, "simulation.output_interval");
    let e = err(&GOOD.replace(
        "output_interval = 0.005",
        "output_interval = 0.005\nfield_stations = 100000000",
    ));
    assert_eq!(e.path, "simulation.field_stations");
    let huge = format!("{GOOD}\n# {}\n", "x".repeat(2 << 20));
    assert!(err(&huge).message.contains("bytes"));
}

#[test]
fn prescribed_motion_with_torque_is_contradictory() {
    let e = err(&GOOD.replace(
        "hub_inertia = 0.01",
        "hub_inertia = 0.01\nprescribed = { kind = \"constant-rate\", rate = 1.0 }",
    ));
    assert_eq!(e.path, "link[0].joint.torque");
}

#[test]
fn unknown_torque_law_kind_is_named() {
    let e = err(&GOOD.replace("kind = \"bang-bang\"", "kind = \"square-wave\""));
    assert!(e.message.contains("square-wave"), "{e}");
    assert!(e.path.starts_with("link[0].joint.torque"), "{e}");
}

#[test]
fn bang_bang_off_before_switch_is_rejected() {
    let e = err(&GOOD.replace("off = 1.0", "off = 0.2"));
    assert_eq!(e.path, "link[0].joint.torque.off");
}

#[test]
fn two_model_families_are_contradictory() {
    let rocket = include_str!("../scenes/rocket.toml");
    let body = rocket.split("[rocket]").nth(1).unwrap();
    let text = format!("{GOOD}\n[rocket]{body}");
    let e = err(&text);
    assert!(e.message.contains("contradictory"), "{e}");
}

#[test]
fn empty_file_says_what_is_missing() {
    let e = err("");
    assert!(e.message.contains("missing field"), "{e}");
}

const MOBILE: &str = include_str!("../scenes/mobile-manipulator.toml");

#[test]
fn mobile_asymmetric_inertia_names_the_tensor() {
    let text = MOBILE.replace(
        "inertia = [[0.0002, 0.00003, 0.0], [0.00003, 0.00025, 0.0], [0.0, 0.0, 0.00025]]",
        "inertia = [[0.0002, 0.00003, 0.0], [0.0, 0.00025, 0.0], [0.0, 0.0, 0.00025]]",
    );
    let e = err(&text);
    assert_eq!(e.path, "mobile_manipulator.arm.gripper.inertia", "{e}");
    assert!(e.message.contains("not symmetric"), "{e}");
}

#[test]
fn mobile_unphysical_inertia_is_rejected() {
    // Izz larger than Ixx + Iyy: no real body has it.
    let text = MOBILE.replace(
        "inertia = [[0.0002, 0.0, 0.0], [0.0, 0.0076, 0.0], [0.0, 0.0, 0.0076]]",
        "inertia = [[0.0002, 0.0, 0.0], [0.0, 0.0076, 0.0], [0.0, 0.0, 0.0176]]",
    );
    let e = err(&text);
    assert_eq!(e.path, "mobile_manipulator.arm.links[0].inertia", "{e}");
    assert!(
        e.expected.contains("triangle") || e.message.contains("triangle"),
        "{e}"
    );
}

#[test]
fn mobile_odd_wheels_and_missing_axle_are_named() {
    let e = err(&MOBILE.replace("wheel_count = 6", "wheel_count = 5"));
    assert_eq!(e.path, "mobile_manipulator.platform.wheel_count", "{e}");
    let e = err(&MOBILE.replace("driven_axles = [1, 2, 3]", "driven_axles = [1, 4]"));
    assert_eq!(e.path, "mobile_manipulator.platform.driven_axles[1]", "{e}");
    assert!(e.expected.contains("1 to 3"), "{e}");
}

#[test]
fn mobile_torque_schedule_width_is_checked() {
    let text = MOBILE.replace(
        "amplitude = [0.05, 0.3, 0.2, 0.05]",
        "amplitude = [0.05, 0.3, 0.2]",
    );
    let e = err(&text);
    assert_eq!(e.path, "mobile_manipulator.arm.torques.amplitude", "{e}");
    assert!(e.expected.contains("4 entries"), "{e}");
}
