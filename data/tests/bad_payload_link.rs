//! Bad 3-D payload-link scenes (seed 002): each names the field and what to change.

use data::{SceneError, parse_scene};

const GOOD: &str = include_str!("../scenes/single-link-3d.toml");

fn err(text: &str) -> SceneError {
    match parse_scene(text, "bad.toml") {
        Ok(_) => panic!("accepted a bad scene:\n{text}"),
        Err(e) => e,
    }
}

const INERTIA: &str =
    "inertia = [[1.0e-4, 1.0e-5, 5.0e-6], [1.0e-5, 1.5e-4, 0.0], [5.0e-6, 0.0, 1.5e-4]]";

#[test]
fn the_catalog_scene_is_good() {
    let scene = parse_scene(GOOD, "good.toml").expect("catalog scene parses");
    let p = scene.payload_link().expect("payload link");
    assert_eq!(p.fields.len(), 4, "all four fields by default");
    assert!(!p.payload.is_diagonal());
}

#[test]
fn asymmetric_inertia_names_the_entry() {
    assert!(GOOD.contains(INERTIA));
    let e = err(&GOOD.replace(
        INERTIA,
        "inertia = [[1.0e-4, 2.0e-5, 5.0e-6], [1.0e-5, 1.5e-4, 0.0], [5.0e-6, 0.0, 1.5e-4]]",
    ));
    assert_eq!(e.path, "payload_link.payload.inertia[0][1]", "{e}");
    assert!(e.message.contains("symmetric"), "{e}");
}

#[test]
fn an_impossible_body_is_rejected() {
    // principal moments 1, 1, 3: the third exceeds the sum of the other two
    let e = err(&GOOD.replace(
        INERTIA,
        "inertia = [[1.0e-4, 0.0, 0.0], [0.0, 1.0e-4, 0.0], [0.0, 0.0, 3.0e-4]]",
    ));
    assert_eq!(e.path, "payload_link.payload.inertia", "{e}");
    assert!(e.expected.contains("triangle"), "{e}");
    // not positive definite
    let e = err(&GOOD.replace(
        INERTIA,
        "inertia = [[1.0e-4, 2.0e-4, 0.0], [2.0e-4, 1.0e-4, 0.0], [0.0, 0.0, 1.5e-4]]",
    ));
    assert_eq!(e.path, "payload_link.payload.inertia", "{e}");
}

#[test]
fn a_physical_body_on_the_triangle_edge_is_accepted() {
    // a thin disc in the y–z plane: I₁ = I₂ + I₃ exactly
    let text = GOOD.replace(
        INERTIA,
        "inertia = [[2.0e-4, 0.0, 0.0], [0.0, 1.0e-4, 0.0], [0.0, 0.0, 1.0e-4]]",
    );
    parse_scene(&text, "disc.toml").expect("a thin disc is a rigid body");
}

#[test]
fn gravity_needs_the_vertical_field() {
    let text = GOOD.replace(
        "initial_shape = \"static-sag\"",
        "initial_shape = \"static-sag\"\nfields = [\"axial\", \"horizontal\", \"torsion\"]",
    );
    let text = text.replace("vertical = 2.0e7\n", "");
    let e = err(&text);
    assert_eq!(e.path, "payload_link.gravity", "{e}");
    assert!(e.expected.contains("vertical"), "{e}");
}

#[test]
fn damping_on_an_absent_field_is_named() {
    let text = GOOD.replace(
        "initial_shape = \"static-sag\"",
        "initial_shape = \"static-sag\"\nfields = [\"axial\", \"horizontal\", \"vertical\"]",
    );
    let e = err(&text);
    assert_eq!(e.path, "payload_link.kelvin_voigt.torsion", "{e}");
}

#[test]
fn static_sag_needs_gravity() {
    let e = err(&GOOD.replace("gravity = 9.81\n", ""));
    assert_eq!(e.path, "payload_link.initial_shape", "{e}");
}

#[test]
fn a_fat_rod_is_refused() {
    let e = err(&GOOD.replace("radius = 0.01", "radius = 0.2"));
    assert_eq!(e.path, "payload_link.radius", "{e}");
}

#[test]
fn unknown_field_name_lists_the_accepted_ones() {
    let text = GOOD.replace(
        "initial_shape = \"static-sag\"",
        "initial_shape = \"static-sag\"\nfields = [\"axial\", \"twist\"]",
    );
    let e = err(&text);
    assert!(e.message.contains("twist"), "{e}");
    assert!(e.expected.contains("torsion"), "{e}");
}
