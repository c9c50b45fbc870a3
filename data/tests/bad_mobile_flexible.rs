//! Bad flexible-link mobile-manipulator scenes (seed 004, issue 19): the beam carries the
//! link's mass uniformly, so its mass centre must be the link's middle and its inertia at least
//! the slender rod's; each refusal names the field.

use data::{SceneError, parse_scene};

const GOOD: &str = include_str!("../scenes/mobile-manipulator-flexible.toml");

/// Link 2 (the flexible one) as written in the catalog scene.
const LINK2_COM: &str = "com = [0.125, 0.0, 0.0]";
const LINK2_INERTIA: &str =
    "inertia = [[0.00012, 0.0, 0.0], [0.0, 0.0042, 0.0], [0.0, 0.0, 0.0042]]";

fn err(text: &str) -> SceneError {
    match parse_scene(text, "bad.toml") {
        Ok(_) => panic!("accepted a bad scene:\n{text}"),
        Err(e) => e,
    }
}

#[test]
fn the_catalog_scene_is_good() {
    let scene = parse_scene(GOOD, "good.toml").expect("catalog scene parses");
    let m = scene.mobile_manipulator().expect("mobile manipulator");
    assert_eq!(m.flexible_link.as_ref().expect("flexible link").link, 2);
    assert!(GOOD.contains(LINK2_COM) && GOOD.contains(LINK2_INERTIA));
}

#[test]
fn an_off_centre_mass_centre_is_refused() {
    let e = err(&GOOD.replace(LINK2_COM, "com = [0.13, 0.0, 0.0]"));
    assert_eq!(e.path, "mobile_manipulator.arm.links[1].com", "{e}");
    let e = err(&GOOD.replace(LINK2_COM, "com = [0.125, 0.001, 0.0]"));
    assert_eq!(e.path, "mobile_manipulator.arm.links[1].com", "{e}");
}

#[test]
fn the_same_offset_on_a_rigid_link_is_accepted() {
    // Only the flexible link is a uniform beam.
    let text = GOOD.replace(
        "com = [0.15, 0.0, 0.0]\ninertia = [[0.0002",
        "com = [0.16, 0.0, 0.0]\ninertia = [[0.0002",
    );
    assert_ne!(text, GOOD);
    parse_scene(&text, "good.toml").expect("a rigid link's mass centre is free");
}

#[test]
fn an_inertia_below_the_slender_rods_is_refused() {
    // m L² / 12 = 0.8 · 0.25² / 12 = 4.1667e-3 > 4.1e-3.
    let e = err(&GOOD.replace(
        LINK2_INERTIA,
        "inertia = [[0.00012, 0.0, 0.0], [0.0, 0.0041, 0.0], [0.0, 0.0, 0.0042]]",
    ));
    assert_eq!(e.path, "mobile_manipulator.arm.links[1].inertia", "{e}");
    assert!(e.message.contains("semi-definite"), "{e}");
}

#[test]
fn a_residual_with_large_products_is_refused() {
    // Each diagonal entry exceeds the rod's, but the residual's yz minor is negative.
    let e = err(&GOOD.replace(
        LINK2_INERTIA,
        "inertia = [[0.00012, 0.0, 0.0], [0.0, 0.0042, 0.0001], [0.0, 0.0001, 0.0042]]",
    ));
    assert_eq!(e.path, "mobile_manipulator.arm.links[1].inertia", "{e}");
}

#[test]
fn a_zero_stiffness_is_refused() {
    let e = err(&GOOD.replace(
        "bending_stiffness_in_plane = 784.0",
        "bending_stiffness_in_plane = 0.0",
    ));
    assert_eq!(
        e.path, "mobile_manipulator.flexible_link.bending_stiffness_in_plane",
        "{e}"
    );
}
