//! Timoshenko links in the two-link chain (`barhorst-case1-timoshenko`, shear variants).
//! Run: CARGO_TARGET_DIR=/work/targets/fdmtimo cargo test --release -p fdm --test timoshenko -- --nocapture

use data::{Backend, Settings, StabilityVerdict, load_scene};
use fdm::FdmBackend;
use fdm::chain::contact::simulate;
use fdm::settings::FdmSettings;

fn settings(stations: usize, t_end: f64) -> Settings {
    let mut s = Settings::default();
    s.discretization.stations = Some(stations);
    s.time.t_end = Some(t_end);
    s
}

#[test]
#[ignore]
fn explore() {
    let scene = load_scene("barhorst-case1-timoshenko").unwrap();
    for sf in [1.0, 0.5, 0.25] {
        let mut s = settings(21, 0.4);
        s.time.safety_factor = Some(sf);
        let (r, rep) = simulate(&scene, &s, &FdmSettings::from_settings(&s).unwrap()).unwrap();
        assert_eq!(r.verdict, StabilityVerdict::Completed);
        println!("sf {sf}: closure {:.3e} projection energy {:.3e} steps {} {:?}", r.ledger.relative_closure(), rep.projection_energy, r.cost.steps, rep);
    }
    let _ = FdmBackend.kind();
}
