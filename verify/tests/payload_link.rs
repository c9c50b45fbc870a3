//! The payload-link (seed 002) rows and references: every row's analytic reference is computable
//! on its scene, the scene-variant reference (decoupling rows) really runs the variant, and the
//! reference numbers of the catalog scenes (printed with `--nocapture`).

use data::BackendKind;
use data::cases::{Case, CaseSettings, Norm, Reference, SuiteName, all_cases, stability_cases};
use verify::analytic::payload_link::{
    BendingPlane, RigidPayloadBase, axial_frequencies_hz, linear_sag, sag_elastica, sag_parameters,
    torsion_frequencies_hz,
};
use verify::suite::evaluate::{Status, case_scene, evaluate};
use verify::suite::quantity::Quantity;
use verify::suite::reference::analytic_value;
use verify::suite::run_cache::RunCache;

fn payload_rows() -> Vec<Case> {
    all_cases()
        .unwrap()
        .into_iter()
        .filter(|c| c.scene.starts_with("single-link-3d"))
        .collect()
}

#[test]
fn sys_every_payload_row_has_a_computable_reference() {
    let rows = payload_rows();
    assert!(rows.len() >= 40, "{} rows", rows.len());
    for c in &rows {
        let scene = case_scene(c, &Default::default()).unwrap();
        let q = Quantity::parse(&c.quantity, &scene).unwrap();
        let id = match &c.reference {
            Reference::Analytic { analytic } => Some(analytic),
            Reference::Order { against, .. } => against.as_ref(),
            _ => None,
        };
        if let Some(id) = id {
            let v = analytic_value(id, &scene, &q).unwrap_or_else(|e| panic!("{}: {e}", c.id));
            assert!(v.is_finite() && v != 0.0, "{}: {v}", c.id);
        }
        if let Reference::Backend { overrides, .. } = &c.reference
            && !overrides.is_empty()
        {
            // The variant must be a valid scene that differs from the case's own.
            let variant = case_scene(c, overrides).unwrap();
            assert_ne!(
                serde_json::to_string(&variant).unwrap(),
                serde_json::to_string(&scene).unwrap(),
                "{}",
                c.id
            );
        }
    }
}

#[test]
fn sys_products_of_inertia_need_the_override() {
    // single-link-3d's own payload couples the planes: its frequency references refuse it and
    // the rows use the diagonal override.
    let scene = data::load_scene("single-link-3d").unwrap();
    let q = Quantity::parse("bending-vertical_freq1", &scene).unwrap();
    let e = analytic_value("payload-vertical", &scene, &q).unwrap_err();
    assert!(e.contains("products of inertia"), "{e}");
    let q = Quantity::parse("bending-horizontal_freq1", &scene).unwrap();
    assert!(
        matches!(q, Quantity::Frequency { n: 1, ref kind } if kind.as_deref() == Some("bending-horizontal"))
    );
}

fn variant_case(overrides: &[(&str, toml::Value)], tolerance: f64) -> Case {
    let settings = CaseSettings {
        elements: Some(4),
        t_end: Some(0.05),
        ..Default::default()
    };
    Case {
        id: "variant".into(),
        check: "decoupling".into(),
        scene: "single-link".into(),
        overrides: Default::default(),
        backend: BackendKind::Fem,
        settings: settings.clone(),
        quantity: "history:joint1.angle".into(),
        reference: Reference::Backend {
            backend: BackendKind::Fem,
            settings,
            overrides: overrides
                .iter()
                .map(|(k, v)| (k.to_string(), v.clone()))
                .collect(),
        },
        norm: Norm::RelativeToPeak,
        tolerance,
        why: "test".into(),
        suite: SuiteName::Quick,
    }
}

#[test]
fn sys_variant_reference_runs_the_variant_scene() {
    let cache = RunCache::default();
    // A variant that changes nothing the run sees (the description) gives the same bits.
    let same = evaluate(
        &variant_case(&[("description", toml::Value::String("x".into()))], 1e-300),
        &cache,
    );
    assert_eq!(same.status, Status::Pass, "{}", same.message);
    assert_eq!(same.error, Some(0.0));
    // A variant with half the torque: the angle history halves, the row must fail.
    let half = evaluate(
        &variant_case(
            &[("link[0].joint.torque.amplitude", toml::Value::Float(0.5))],
            1e-3,
        ),
        &cache,
    );
    assert_eq!(half.status, Status::Fail, "{}", half.message);
    let err = half.error.unwrap();
    // Half the torque, half the angle — up to the link's geometric nonlinearity (~1e-3 here).
    assert!(
        (err - 1.0).abs() < 1e-2,
        "nearly linear in the torque: {err}"
    );
    assert!(
        half.reference_label.contains("amplitude"),
        "{}",
        half.reference_label
    );
}

#[test]
fn sys_stability_scenes_of_the_payload_link_load() {
    let ids: Vec<String> = stability_cases()
        .unwrap()
        .into_iter()
        .map(|c| c.id)
        .collect();
    for name in ["single-link-3d-thin", "single-link-3d-heavy-payload"] {
        let p = data::load_scene(name)
            .unwrap()
            .payload_link()
            .unwrap()
            .clone();
        assert!(
            !p.payload.is_diagonal(),
            "{name}: products of inertia excite torsion"
        );
        assert!(ids.iter().any(|i| i == name));
    }
    // The thin rod: torsion's explicit bound h/c_phi is below bending's h^2 sqrt(rhoA/4EI) for
    // a station spacing above ~1.6 R (at 41 stations h = 17 R).
    let p = data::load_scene("single-link-3d-thin")
        .unwrap()
        .payload_link()
        .unwrap()
        .clone();
    let h = p.length / 40.0;
    let torsion = h * (p.density * p.polar_moment() / p.torsional_stiffness()).sqrt();
    let bending = h * h * (p.mass_per_length() / (4.0 * p.bending_stiffness())).sqrt();
    assert!(torsion < bending, "{torsion} vs {bending}");
    // The heavy payload is ten times the rod.
    let p = data::load_scene("single-link-3d-heavy-payload")
        .unwrap()
        .payload_link()
        .unwrap()
        .clone();
    assert!(p.payload.mass >= 10.0 * p.mass_per_length() * p.length * 0.99);
}

#[test]
fn sys_reference_numbers_of_the_catalog_scenes() {
    // The numbers the report quotes (`cargo test --release -p verify --test payload_link
    // reference_numbers -- --nocapture`), with the structural facts they must satisfy.
    let diag = [[1.0e-4, 0.0, 0.0], [0.0, 1.5e-4, 0.0], [0.0, 0.0, 1.5e-4]];
    for name in [
        "single-link-3d",
        "single-link-3d-constant-rate",
        "single-link-3d-soft-sag",
        "single-link-3d-stiff",
    ] {
        let mut p = data::load_scene(name)
            .unwrap()
            .payload_link()
            .unwrap()
            .clone();
        if !p.payload.is_diagonal() {
            p.payload.inertia = diag;
        }
        let h = BendingPlane::horizontal(&p)
            .unwrap()
            .frequencies_hz(3)
            .unwrap();
        let v = BendingPlane::vertical(&p)
            .unwrap()
            .frequencies_hz(3)
            .unwrap();
        let t = torsion_frequencies_hz(&p, 1).unwrap()[0];
        let a = axial_frequencies_hz(&p, 1).unwrap()[0];
        println!(
            "{name}: horizontal {h:.6?} Hz, vertical {v:.6?} Hz, torsion {t:.6} Hz, axial {a:.6} Hz"
        );
        if p.gravity.is_some() {
            let (wl, sl) = linear_sag(&p).unwrap();
            let (al, be, ga) = sag_parameters(&p);
            let e = sag_elastica(al, be, ga).unwrap();
            println!(
                "  sag: linear w_L = {wl:.6e} m, w'_L = {sl:.6e}; elastica {:.6e} m",
                -e.tip_sag * p.length
            );
            assert!(wl < 0.0 && sl < 0.0);
            // The linear sag exceeds the elastica's (foreshortening shortens the arm).
            assert!(-wl > e.tip_sag * p.length);
        }
        if p.base.prescribed.is_none() {
            let r = RigidPayloadBase::from_link(&p).unwrap();
            let (th, om) = r
                .state(p.base.torque.as_ref().map_or(1.0, |_| 1.5))
                .unwrap();
            println!(
                "  rigid base: J = {:.6} kg m^2, theta(1.5) = {th:.6}, rate(1.5) = {om:.6}",
                r.inertia
            );
        }
        for k in 0..3 {
            assert!(h[k] > 0.0 && v[k] > 0.0);
        }
        // Torsion and axial are far above the first bending modes of these rods.
        assert!(t > h[0] && a > t.min(a));
    }
}
