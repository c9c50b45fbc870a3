//! Checks of the scene file as a whole, before it converts into a scene.

use super::issue::{Checker, Issue};
use super::limits::{MAX_FIELD_STATIONS, MAX_OUTPUT_SAMPLES, excess_output_samples};
use crate::locate::FieldPath;
use crate::scene::SceneFile;

/// Problems of the file as a whole, in document order: name, description, simulation, and
/// the model families (exactly one; planar-only tables only with links). A file without such
/// problems converts into a [`Scene`](crate::scene::Scene).
pub fn check_file(scene: &SceneFile) -> Vec<Issue> {
    let mut c = Checker { issues: Vec::new() };
    let root = FieldPath::root();

    if scene.name.trim().is_empty()
        || !scene
            .name
            .chars()
            .all(|ch| ch.is_ascii_lowercase() || ch.is_ascii_digit() || ch == '-')
    {
        c.fail(
            root.key("name"),
            format!("`{}` is not a kebab-case identifier", scene.name),
            "lower-case letters, digits and `-`, e.g. \"my-beam\"",
        );
    }
    if scene.description.trim().is_empty() {
        c.fail(
            root.key("description"),
            "is empty",
            "a one-line description",
        );
    }

    let sim = root.key("simulation");
    c.positive(sim.key("t_end"), scene.simulation.t_end);
    c.positive(sim.key("output_interval"), scene.simulation.output_interval);
    if let Some(samples) =
        excess_output_samples(scene.simulation.t_end, scene.simulation.output_interval)
    {
        c.fail(
            sim.key("output_interval"),
            format!(
                "t_end / output_interval = {samples:.3e} output samples is above the limit {MAX_OUTPUT_SAMPLES:.0e}"
            ),
            "a larger output_interval",
        );
    }
    let fs = scene.simulation.field_stations;
    if !(2..=MAX_FIELD_STATIONS).contains(&fs) {
        c.fail(
            sim.key("field_stations"),
            format!("{fs} stations is outside the supported range"),
            format!("an integer from 2 to {MAX_FIELD_STATIONS}"),
        );
    }

    let families = [
        ("link", !scene.links.is_empty()),
        ("rocket", scene.rocket.is_some()),
        ("payload_link", scene.payload_link.is_some()),
        ("mobile_manipulator", scene.mobile_manipulator.is_some()),
    ];
    let present: Vec<&str> = families.iter().filter(|f| f.1).map(|f| f.0).collect();
    match present.len() {
        0 => c.fail(
            root,
            "the scene defines no model",
            "one of: [[link]] tables, [rocket], [payload_link] or [mobile_manipulator]",
        ),
        1 => {}
        _ => c.fail(
            root.key(present[1]),
            format!(
                "contradictory model families: {} together",
                present.join(" and ")
            ),
            "exactly one model family per scene file",
        ),
    }
    let planar = present == ["link"];
    if !planar {
        for (key, on) in [
            ("gravity", scene.gravity.is_some()),
            ("contact", !scene.contacts.is_empty()),
            ("statics", scene.statics.is_some()),
            ("studies", scene.studies.is_some()),
        ] {
            if on {
                c.fail(
                    FieldPath::root().key(key),
                    format!("`{key}` applies only to planar link chains"),
                    "remove it, or use the family's own fields (e.g. rocket.gravity)",
                );
            }
        }
    }

    c.issues
}
