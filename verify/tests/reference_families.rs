//! The analytic references of one family refuse a scene of another family with the reference's
//! own message (the dispatch in `suite::reference` picks the family before any reference is
//! built).

use data::load_scene;
use verify::suite::quantity::Quantity;
use verify::suite::reference::{analytic_history, analytic_value};

fn refusal(id: &str, scene: &str, quantity: &str) -> String {
    let scene = load_scene(scene).expect("catalog scene");
    let q = Quantity::parse(quantity, &scene).expect("a quantity");
    analytic_value(id, &scene, &q).expect_err("a refusal")
}

#[test]
fn sys_references_refuse_other_families_with_their_own_message() {
    let cases = [
        (
            "spring-jointed-chain",
            "rocket",
            "freq1",
            "unsupported: the spring-jointed chain needs a planar link chain; `rocket` has no \
             [[link]]",
        ),
        (
            "rigid-single-link",
            "single-link-3d",
            "joint1.angle@0.1",
            "unsupported: rigid single-link reference: the scene must have exactly one link",
        ),
        (
            "rigid-two-link",
            "mobile-platform",
            "joint1.angle@0.1",
            "unsupported: rigid two-link reference: the scene must have exactly two links",
        ),
        (
            "constrained-rigid-link",
            "rocket",
            "joint1.angle@0.1",
            "unsupported: constrained rigid link: the scene must have exactly one link",
        ),
        (
            "rocket-translation",
            "cantilever",
            "rocket.vY@0.1",
            "unsupported: rocket translation: the scene has no [rocket]",
        ),
        (
            "rocket-free-free",
            "cantilever",
            "freq1",
            "unsupported: `cantilever` is not a rocket scene",
        ),
        (
            "clamped-free",
            "rocket",
            "freq1",
            "this analytic reference needs a single-link scene; `rocket` has 0 links",
        ),
        (
            "static-linear",
            "two-link-free",
            "tip_static",
            "this analytic reference needs a single-link scene; `two-link-free` has 2 links",
        ),
        (
            "payload-torsion",
            "cantilever",
            "torsion_freq1",
            "this analytic reference needs a [payload_link] scene; `cantilever` is not one",
        ),
    ];
    for (id, scene, quantity, message) in cases {
        assert_eq!(refusal(id, scene, quantity), message, "{id} on {scene}");
    }
    let cantilever = load_scene("cantilever").expect("catalog scene");
    assert_eq!(
        analytic_history("rocket-free-vibration", &cantilever, "rocket.w@1", &[0.0]),
        Err("unsupported: `cantilever` is not a rocket scene".to_string())
    );
}
