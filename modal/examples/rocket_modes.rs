//! Mode-count convergence study of the modal rocket (≈ 20 s in release): the observables at
//! 0.05 s for 4, 8 and 16 modes and the changes between the rungs (a converging modal series
//! changes less at the second refinement than at the first).
//!
//! `cargo run --release -p modal --example rocket_modes`

use data::{Discretization, Settings, load_scene};

fn main() {
    let scene = load_scene("rocket").expect("catalog scene");
    let channels = ["rocket.w@10", "rocket.u@10", "rocket.mass2.u", "rocket.vY"];
    let mut rows = Vec::new();
    for n in [4usize, 8, 16] {
        let s = Settings {
            discretization: Discretization {
                modes: Some(n),
                ..Default::default()
            },
            ..Default::default()
        };
        let r = modal::rocket::simulate(&scene, scene.rocket().unwrap(), &s.modal().unwrap())
            .expect("rocket run");
        let vals: Vec<f64> = channels
            .iter()
            .map(|c| r.observables.value_at(c, 0.05).unwrap_or(f64::NAN))
            .collect();
        println!(
            "modes {n:2}: {vals:?}  wall {:.2} s, steps {}",
            r.cost.wall_time_s, r.cost.steps
        );
        rows.push(vals);
    }
    for (c, name) in channels.iter().enumerate() {
        let d1 = (rows[1][c] - rows[0][c]).abs();
        let d2 = (rows[2][c] - rows[1][c]).abs();
        let verdict = if d2 < d1 {
            "settles"
        } else {
            "does NOT settle"
        };
        println!("{name}: |Δ(4→8)| = {d1:.3e}, |Δ(8→16)| = {d2:.3e} ({verdict})");
    }
}
