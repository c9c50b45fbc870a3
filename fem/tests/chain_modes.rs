//! Linearized modes of the two-link chain (`modes two-link-free`, `fem::chain::linearized`): the DOF
//! count, the linearized pieces against the residual, the single-beam limits K → ∞ (clamped–free
//! beam of length L₁ + L₂) and K₁ → 0 (pinned–free), computed here from the scene, and the
//! frequencies converging at order 4 with the elements.
//! Run: cargo test --release -p fem --test chain_modes -- --nocapture

#![allow(clippy::needless_range_loop)]

mod common;

use data::{Backend, Scene, Settings};
use fem::FemBackend;
use fem::chain::Chain;

fn settings(n: usize) -> Settings {
    let mut s = Settings::default();
    s.discretization.elements = Some(n);
    s
}

fn scene_with_springs(k1: f64, k2: f64) -> Scene {
    let mut sc = data::load_scene("two-link-free").unwrap();
    sc.planar_chain_mut().unwrap().links[0].joint.stiffness = Some(k1);
    sc.planar_chain_mut().unwrap().links[1].joint.stiffness = Some(k2);
    sc
}

fn omegas(scene: &Scene, n: usize, count: usize) -> (Vec<f64>, Vec<String>) {
    let r = FemBackend.modes(scene, &settings(n), count).unwrap();
    let w = r
        .frequencies_hz
        .iter()
        .map(|f| 2.0 * std::f64::consts::PI * f)
        .collect();
    (w, r.kinds)
}

/// The two links share EI and ρA (the limits below are single uniform beams).
fn section(scene: &Scene) -> (f64, f64, f64, f64) {
    let (a, b) = (&scene.links()[0], &scene.links()[1]);
    assert_eq!(a.bending_stiffness, b.bending_stiffness);
    assert_eq!(a.mass_per_length, b.mass_per_length);
    (
        a.bending_stiffness,
        a.mass_per_length,
        a.length + b.length,
        a.length.max(b.length),
    )
}

#[test]
fn sys_chain_modes_dof_count() {
    let sc = data::load_scene("two-link-free").unwrap();
    for n in [2usize, 8] {
        let r = FemBackend.modes(&sc, &settings(n), 4).unwrap();
        // v, v′ at the n nodes past the root of each link (the elbow node belongs to link 1)
        // and the two joint angles.
        assert_eq!(r.cost.dofs, 2 * 2 * n + 2);
        let plan = FemBackend
            .dof_plan(&sc, &settings(n).discretization)
            .unwrap();
        assert_eq!(r.cost.dofs, plan.total());
        assert_eq!(r.frequencies_hz.len(), 4);
        assert!(r.kinds.iter().all(|k| k == "bending"));
    }
}

#[test]
fn sys_chain_linearization_matches_the_residual() {
    // M = ∂R/∂q̈ and K = ∂R/∂q at rest: R is linear in q̈, and at rest without gravity linear
    // in q to O(q²) (the foreshortening couplings are quadratic), so central differences of
    // the residual reproduce the pieces to round-off plus O(step²).
    let sc = data::load_scene("two-link-free").unwrap();
    let mut chain = Chain::with_element(sc.links(), sc.gravity(), 4, None).unwrap();
    let lin = chain.linearize();
    let n = chain.ndof;
    let q0 = lin.reference.clone();
    let zero = vec![0.0; n];
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    let mass_scale = (0..n).map(|i| lin.mass[(i, i)]).fold(0.0, f64::max);
    let stiff_scale = (0..n).map(|i| lin.stiffness[(i, i)]).fold(0.0, f64::max);
    for j in 0..n {
        let mut a = zero.clone();
        a[j] = 1.0;
        chain.residual(0.0, &q0, &zero, &a, &mut rp);
        chain.residual(0.0, &q0, &zero, &zero, &mut rm);
        for i in 0..n {
            let d = (rp[i] - rm[i] - lin.mass[(i, j)]).abs();
            assert!(d < 1e-12 * mass_scale, "M[{i}][{j}]: {d}");
        }
        let step = 1e-6;
        let (mut qp, mut qm) = (q0.clone(), q0.clone());
        qp[j] += step;
        qm[j] -= step;
        chain.residual(0.0, &qp, &zero, &zero, &mut rp);
        chain.residual(0.0, &qm, &zero, &zero, &mut rm);
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * step);
            let d = (fd - lin.stiffness[(i, j)]).abs();
            assert!(
                d < 1e-7 * stiff_scale,
                "K[{i}][{j}]: {fd} vs {}",
                lin.stiffness[(i, j)]
            );
        }
    }
}

/// Hermite cubics: the relative frequency error of mode n is about (βₙh)⁴/1440 (cantilever
/// estimate); the bound allows twice that at the longest element.
fn discretization_bound(beta_l: f64, length: f64, h: f64) -> f64 {
    2.0 * (beta_l / length * h).powi(4) / 1440.0
}

#[test]
fn sys_chain_modes_stiff_joints_give_the_clamped_free_beam() {
    // K → ∞ on both joints: one clamped–free beam of length L₁ + L₂. The springs' compliance
    // shifts a frequency by O(EI/(K L)) = 1e-9 relative at K = 1e12 lbf·ft/rad.
    let sc = scene_with_springs(1e12, 1e12);
    let (ei, rho_a, length, longest) = section(&sc);
    let n = 16;
    let exact_beta = common::clamped_free_beta(3);
    let exact = common::clamped_free_omega(ei, rho_a, length, 3);
    let (w, kinds) = omegas(&sc, n, 3);
    for m in 0..3 {
        let err = (w[m] - exact[m]).abs() / exact[m];
        let bound = discretization_bound(exact_beta[m], length, longest / n as f64);
        println!(
            "clamped limit mode {}: {:.12e} vs {:.12e}, rel {err:.2e} (bound {bound:.2e})",
            m + 1,
            w[m],
            exact[m]
        );
        assert_eq!(kinds[m], "bending");
        assert!(
            err < bound + 1e-8,
            "mode {}: {err:.2e} > {bound:.2e}",
            m + 1
        );
    }
}

#[test]
fn sys_chain_modes_free_root_gives_the_pinned_free_beam() {
    // K₁ → 0 (a free joint) and K₂ → ∞: the pinned–free beam of length L₁ + L₂, a rigid
    // rotation (0) and then tan βL = tanh βL.
    let sc = scene_with_springs(0.0, 1e12);
    let (ei, rho_a, length, longest) = section(&sc);
    let n = 16;
    let betas = common::roots(|x| x.sin() - x.cos() * x.tanh(), 1.0, 14.0, 4000, 3);
    let (w, kinds) = omegas(&sc, n, 4);
    assert_eq!(w[0], 0.0);
    assert_eq!(kinds[0], "rigid");
    for m in 0..3 {
        let exact = betas[m] * betas[m] / (length * length) * (ei / rho_a).sqrt();
        let err = (w[m + 1] - exact).abs() / exact;
        let bound = discretization_bound(betas[m], length, longest / n as f64);
        println!(
            "pinned limit mode {}: {:.12e} vs {exact:.12e}, rel {err:.2e} (bound {bound:.2e})",
            m + 2,
            w[m + 1]
        );
        assert_eq!(kinds[m + 1], "bending");
        assert!(
            err < bound + 1e-8,
            "mode {}: {err:.2e} > {bound:.2e}",
            m + 2
        );
    }
    // Both joints free: two rigid modes (the rigid two-link mechanism).
    let (w, kinds) = omegas(&scene_with_springs(0.0, 0.0), n, 3);
    assert_eq!(&w[..2], &[0.0, 0.0]);
    assert_eq!(&kinds[..2], &["rigid", "rigid"]);
    assert!(w[2] > 0.0);
}

#[test]
fn conv_chain_modes_converge_at_order_four() {
    // The scene's own springs; the order from three meshes without a reference:
    // p = log₂((ω₄ − ω₈)/(ω₈ − ω₁₆)).
    let sc = data::load_scene("two-link-free").unwrap();
    let meshes = [4usize, 8, 16];
    let w: Vec<Vec<f64>> = meshes.iter().map(|&n| omegas(&sc, n, 5).0).collect();
    for m in 0..5 {
        let (d1, d2) = (w[0][m] - w[1][m], w[1][m] - w[2][m]);
        let p = (d1 / d2).log2();
        println!(
            "mode {}: {:.12e} {:.12e} {:.12e}, order {p:.3}",
            m + 1,
            w[0][m],
            w[1][m],
            w[2][m]
        );
        // Consistent mass: the frequencies converge from above.
        assert!(
            d1 > 0.0 && d2 > 0.0,
            "mode {}: not monotone from above",
            m + 1
        );
        assert!((p - 4.0).abs() < 0.3, "mode {}: order {p:.3}", m + 1);
    }
}
