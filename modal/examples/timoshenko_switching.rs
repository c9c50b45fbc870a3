//! Switching times (impacts I, releases R) of a contact scene in its first 0.5 s against the
//! number of modes per field, for the polynomial and clamped-free bases (issue 7).
//!
//! `cargo run --release -p modal --example timoshenko_switching [SCENE] [MODES,…]`, by default
//! `barhorst-case1-timoshenko 2,3,4,6` (`barhorst-case1` gives the Euler comparison). Long.

use data::{Basis, Discretization, Event, RunResult, Settings, TimeStepping, load_scene};
use modal::simulate::simulate_detailed;

fn switching(r: &RunResult) -> Vec<(f64, &'static str)> {
    r.events
        .iter()
        .filter_map(|e| match e {
            Event::Impact { t, .. } => Some((*t, "I")),
            Event::Release { t, .. } => Some((*t, "R")),
            _ => None,
        })
        .collect()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args
        .next()
        .unwrap_or_else(|| "barhorst-case1-timoshenko".to_string());
    let ladder: Vec<usize> = args
        .next()
        .unwrap_or_else(|| "2,3,4,6".to_string())
        .split(',')
        .map(|v| {
            v.trim()
                .parse()
                .expect("mode counts: comma-separated integers")
        })
        .collect();
    let scene = load_scene(&name).expect("scene");
    println!("{name}");
    for basis in [Basis::Poly, Basis::ClampedFree] {
        for &n in &ladder {
            let settings = Settings {
                discretization: Discretization {
                    modes: Some(n),
                    basis: Some(basis),
                    ..Default::default()
                },
                time: TimeStepping {
                    rtol: Some(1e-8),
                    atol: Some(1e-11),
                    t_end: Some(0.5),
                    ..Default::default()
                },
            };
            let (r, _) = simulate_detailed(
                &scene,
                scene.planar_chain().unwrap(),
                &settings.modal().unwrap(),
            )
            .expect("run");
            let sw: Vec<String> = switching(&r)
                .iter()
                .map(|(t, k)| format!("{k}{t:.6}"))
                .collect();
            println!(
                "{basis:?} n={n}: {} | closure {:.2e} steps {} wall {:.2}s",
                sw.join(" "),
                r.ledger.relative_closure(),
                r.cost.steps,
                r.cost.wall_time_s
            );
        }
    }
}
