//! Mode-count convergence study of the modal rocket (slow: ≈ 20 s in release).
//!
//! Run: `CARGO_TARGET_DIR=/work/targets/rocketmodal cargo test --release -p modal --test rocket_study -- --ignored --nocapture`

use data::{Discretization, Settings, load_scene};

#[test]
#[ignore = "study: ~20 s; run with --ignored"]
fn conv_observables_settle_as_modes_grow() {
    let scene = load_scene("rocket").unwrap();
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
        let r = modal::rocket::simulate(&scene, &s).unwrap();
        let vals: Vec<f64> = channels
            .iter()
            .map(|c| r.observables.value_at(c, 0.05).unwrap())
            .collect();
        println!(
            "modes {n:2}: {:?}  wall {:.2} s, steps {}",
            vals, r.cost.wall_time_s, r.cost.steps
        );
        rows.push(vals);
    }
    for (c, name) in channels.iter().enumerate() {
        let d1 = (rows[1][c] - rows[0][c]).abs();
        let d2 = (rows[2][c] - rows[1][c]).abs();
        println!("{name}: |Δ(4→8)| = {d1:.3e}, |Δ(8→16)| = {d2:.3e}");
        // a converging modal series: the second refinement changes less than the first
        assert!(d2 < d1, "{name} does not settle: {d1:e} then {d2:e}");
    }
}
