//! The initial state every backend starts a scene from.

use data::{BackendKind, RunResult, Settings, load_scene};

fn first_sample(run: &RunResult, name: &str) -> f64 {
    run.observables
        .get(name)
        .unwrap_or_else(|| panic!("no channel {name}"))
        .values[0]
}

#[test]
fn cross_timoshenko_arm_starts_from_the_scenes_centre_lines_in_every_backend() {
    // The scene places the links' centre lines straight at the joint angles, at rest; the
    // massless cross-sections (Timoshenko without rotary inertia) take their static balance
    // from there, so the joint angles between sections start off the scene's by their turns.
    // Every backend must start from the same mass configuration: the tips at the straight
    // arm's points, computed here from the scene.
    let scene = load_scene("barhorst-case1-timoshenko").unwrap();
    let pc = scene.planar_chain().unwrap();
    let (l1, l2) = (pc.links[0].length, pc.links[1].length);
    let (q1, q2) = (
        pc.links[0].joint.initial_angle,
        pc.links[1].joint.initial_angle,
    );
    let tip1 = [l1 * q1.cos(), l1 * q1.sin()];
    let tip2 = [
        tip1[0] + l2 * (q1 + q2).cos(),
        tip1[1] + l2 * (q1 + q2).sin(),
    ];
    let mut settings = Settings::default();
    settings.time.t_end = Some(0.002);
    let mut elbow = Vec::new();
    for kind in [BackendKind::Fem, BackendKind::Fdm, BackendKind::Modal] {
        let run = verify::registry::backend(kind)
            .simulate(&scene, &settings)
            .unwrap();
        let at = |n: &str| first_sample(&run, n);
        let got = [
            at("link1.tip_x"),
            at("link1.tip_y"),
            at("link2.tip_x"),
            at("link2.tip_y"),
        ];
        let want = [tip1[0], tip1[1], tip2[0], tip2[1]];
        let off = got
            .iter()
            .zip(&want)
            .fold(0.0f64, |m, (g, w)| m.max((g - w).abs()));
        println!(
            "{kind:?}: tips {got:?}, straight arm {want:?}, off {off:.2e}; elbow angle {:.9e} \
             (scene {q2:.9e})",
            at("joint2.angle")
        );
        assert!(off < 1e-12 * l1, "{kind:?}: {got:?} against {want:?}");
        elbow.push(at("joint2.angle"));
    }
    // The sections turn with the elbow spring's moment, so the elbow angle between sections
    // starts below the scene's (K₂ pulls it towards its set-point 0) in every backend.
    assert!(elbow.iter().all(|&a| a < q2), "{elbow:?}");
}
