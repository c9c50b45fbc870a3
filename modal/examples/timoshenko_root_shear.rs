//! Cost of the v'(0) = 0 basis used with a free joint and massless sections: the stocky
//! cantilever without rotary inertia, clamped either by a prescribed joint (root-shear basis,
//! exponentially convergent reference, 16 poly modes) or by a free joint with a very stiff
//! spring (v'(0) = 0 basis); prints the relative frequency errors of the sprung model.
//!
//! `cargo run --release -p modal --example timoshenko_root_shear`

use data::scene::Scene;
use data::{Backend, Basis, Discretization, Settings, load_scene};
use modal::ModalBackend;

fn freqs(scene: &Scene, modes: usize, basis: Basis, count: usize) -> Vec<f64> {
    let s = Settings {
        discretization: Discretization {
            modes: Some(modes),
            basis: Some(basis),
            ..Default::default()
        },
        ..Default::default()
    };
    ModalBackend
        .modes(scene, &s, count)
        .expect("modes")
        .frequencies_hz
}

fn main() {
    let mut clamped = load_scene("cantilever-timoshenko").expect("catalog scene");
    clamped.planar_chain_mut().unwrap().links[0].rotary_inertia = false;
    let reference = freqs(&clamped, 16, Basis::Poly, 3);
    let mut sprung = clamped.clone();
    sprung.planar_chain_mut().unwrap().links[0].joint.prescribed = None;
    // Root compliance 1/K ≪ the beam's (L/EI ≈ 6e-4): the spring error is ~1e-7.
    sprung.planar_chain_mut().unwrap().links[0].joint.stiffness = Some(1e10);
    for basis in [Basis::Poly, Basis::ClampedFree] {
        for n in [2, 4, 6, 8, 12, 16] {
            // Eigenvalues below the solver's round-off floor (1e-12 λ_max, reported as 0) are
            // dropped: the stiff spring mode sets λ_max.
            let f: Vec<f64> = freqs(&sprung, n, basis, 6)
                .into_iter()
                .filter(|v| *v > 0.0)
                .collect();
            let e: Vec<f64> = f.iter().zip(&reference).map(|(a, b)| (a - b) / b).collect();
            println!("{basis:?} n={n:2}: v'(0) = 0 basis rel errors {e:?}");
        }
    }
}
