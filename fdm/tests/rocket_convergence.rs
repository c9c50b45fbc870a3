//! Spatial convergence of the rocket scheme (transverse field, smooth initial shape).
//! Run: CARGO_TARGET_DIR=/work/targets/fdm cargo test --release -p fdm --test rocket_convergence -- --nocapture

use data::{Settings, load_scene};
use fdm::ValidatedSettings;

fn field(stations: usize, prefix: &str, t_end: f64, method: &str) -> Vec<f64> {
    let scene = load_scene("rocket").unwrap();
    let mut s = Settings::default();
    s.discretization.stations = Some(stations);
    s.time.t_end = Some(t_end);
    s.time.method = Some(method.parse().expect("a method name"));
    let f = ValidatedSettings::from_settings(&s.fdm().unwrap()).unwrap();
    let (_, out) = fdm::runs::rocket_with(&scene, scene.rocket().unwrap(), &f, true).unwrap();
    let o = &out.observables;
    (0..scene.simulation.field_stations)
        .map(|k| {
            *o.get(&format!("{prefix}{k}"))
                .unwrap()
                .values
                .last()
                .unwrap()
        })
        .collect()
}

fn maxdiff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn conv_rocket_transverse_field_spatial_order() {
    // h = 5, 2.5, 1.25, 0.625 in (stage junction on a station in each); τ follows h² (5.44),
    // so the temporal error falls with the spatial one.
    let t = 0.004;
    for prefix in ["rocket.w@", "rocket.u@"] {
        let f: Vec<Vec<f64>> = [31usize, 61, 121, 241]
            .iter()
            .map(|&n| field(n, prefix, t, "velocity-form"))
            .collect();
        let d: Vec<f64> = (0..3).map(|i| maxdiff(&f[i], &f[i + 1])).collect();
        let p1 = (d[0] / d[1]).log2();
        let p2 = (d[1] / d[2]).log2();
        eprintln!("{prefix}: successive differences {d:?}, observed orders {p1:.3}, {p2:.3}");
        if prefix == "rocket.w@" {
            // smooth field: central differences, second order
            assert!((p2 - 2.0).abs() < 0.3, "{p2}");
        }
    }
}
