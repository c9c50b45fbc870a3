//! Every catalog scene parses, validates, and survives a serialize → parse round trip.

use data::{CATALOG, Family, catalog_scene, parse_scene};

#[test]
fn every_catalog_file_is_embedded() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
    let mut on_disk: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "toml")
                .then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    on_disk.sort();
    let mut embedded: Vec<String> = CATALOG.iter().map(|(n, _)| n.to_string()).collect();
    embedded.sort();
    assert_eq!(
        on_disk, embedded,
        "data/scenes/*.toml and the embedded CATALOG differ"
    );
}

#[test]
fn every_catalog_scene_parses_and_names_itself() {
    for (name, _) in CATALOG {
        let scene = catalog_scene(name)
            .unwrap()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.name, *name);
    }
}

#[test]
fn every_catalog_scene_round_trips() {
    for (name, _) in CATALOG {
        let scene = catalog_scene(name).unwrap().unwrap();
        let text = toml::to_string(&scene).unwrap_or_else(|e| panic!("{name}: serialize: {e}"));
        let again =
            parse_scene(&text, "round-trip").unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_eq!(scene, again, "{name} changed in the round trip");
    }
}

#[test]
fn catalog_covers_every_family() {
    let families: Vec<Family> = CATALOG
        .iter()
        .map(|(n, _)| catalog_scene(n).unwrap().unwrap().family())
        .collect();
    for f in [
        Family::PlanarChain,
        Family::Rocket,
        Family::PayloadLink,
        Family::MobileManipulator,
    ] {
        assert!(families.contains(&f), "no catalog scene of family {f}");
    }
}

#[test]
fn barhorst_case1_switches_on_gravity_contact_and_kelvin_voigt_only() {
    let scene = catalog_scene("barhorst-case1").unwrap().unwrap();
    let flags: std::collections::HashMap<_, _> = scene.physics_flags().into_iter().collect();
    assert!(flags["gravity"] && flags["contact"] && flags["kelvin_voigt"]);
    assert!(!flags["axial"] && !flags["shear"] && !flags["friction"]);
}
