//! Where the seed's large-deflection sag formula holds: its tip sag and the linear one against
//! the elastica of a tip-loaded cantilever, over α = FL²/EI, then the catalog scenes' sag
//! (self-weight and payload offset included) against the linear model.
//!
//! `cargo run --release -p verify --example seed_sag`

use verify::analytic::payload_link::{linear_sag, sag_elastica, sag_parameters, seed_sag};
use verify::analytic::statics::cantilever_elastica;

fn main() {
    println!("tip load only: sag / L (elastica by shooting, seed 002's formula, linear α/3)");
    println!(
        "{:>8} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "alpha", "elastica", "seed", "seed err", "linear", "linear err"
    );
    for alpha in [
        0.01, 0.03, 0.1, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 10.0,
    ] {
        let e = cantilever_elastica(alpha).expect("elastica").tip_transverse;
        let lin = alpha / 3.0;
        let seed = match seed_sag(alpha) {
            Ok((_, s)) => format!("{s:>12.6} {:>12.2e}", (s - e) / e),
            Err(_) => format!("{:>12} {:>12}", "none", "-"),
        };
        println!(
            "{alpha:>8} {e:>12.6} {seed} {lin:>12.6} {:>12.2e}",
            (lin - e) / e
        );
    }
    println!("\ncatalog scenes: sag w_L / L with self-weight and offset (linear vs elastica)");
    for name in [
        "single-link-3d",
        "single-link-3d-constant-rate",
        "single-link-3d-soft-sag",
    ] {
        let p = data::load_scene(name)
            .unwrap()
            .payload_link()
            .unwrap()
            .clone();
        let (a, b, g) = sag_parameters(&p);
        let (wl, sl) = linear_sag(&p).unwrap();
        let e = sag_elastica(a, b, g).unwrap();
        println!(
            "{name:<30} alpha {a:.4e} beta {b:.4e}: linear w_L = {wl:.6e} m, w'_L = {sl:.6e}; \
             elastica {:.6e} m (linear error {:.2e})",
            -e.tip_sag * p.length,
            (wl + e.tip_sag * p.length) / (e.tip_sag * p.length)
        );
    }
}
