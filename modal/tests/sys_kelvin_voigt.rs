//! The Kelvin–Voigt operator of a built chain against an independent quadrature: the
//! dissipation power ẋᵀDẋ that the ledger books (D = (γ/EI)K_b, the damping matrix of the
//! bending block) for a given transverse velocity field v̇(x) must equal γ∫v̇''² dx, in any
//! number of `poly` modes that represents the field.

use data::{Basis, Discretization, load_scene};
use modal::setup::build_chain;

/// v̇(ξ) = ξ² − 0.7ξ³ + 0.3ξ⁵ (ξ = x/L): clamped (v̇(0) = v̇'(0) = 0), degree 5, in the span
/// of 6 or more `poly` functions. Returns v̇ (deriv 0) or v̇'' (deriv 2).
fn field(x: f64, l: f64, deriv: usize) -> f64 {
    let s = x / l;
    match deriv {
        0 => s * s - 0.7 * s.powi(3) + 0.3 * s.powi(5),
        2 => (2.0 - 4.2 * s + 6.0 * s.powi(3)) / (l * l),
        _ => unreachable!(),
    }
}

/// Solves A x = b (dense, row-major n×n) by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap();
        for j in 0..n {
            a.swap(k * n + j, p * n + j);
        }
        b.swap(k, p);
        for i in k + 1..n {
            let m = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= m * a[k * n + j];
            }
            b[i] -= m * b[k];
        }
    }
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * b[j]).sum();
        b[k] = (b[k] - s) / a[k * n + k];
    }
    b
}

#[test]
fn sys_kelvin_voigt_power_of_a_velocity_field_matches_quadrature_in_6_and_12_poly_modes() {
    let scene = load_scene("two-link-free").unwrap();
    let mut powers = Vec::new();
    for modes in [6, 12] {
        let disc = Discretization {
            modes: Some(modes),
            basis: Some(Basis::Poly),
            ..Default::default()
        };
        let chain = build_chain(scene.planar_chain().unwrap(), &disc.modal().unwrap()).unwrap();
        for (link, spec) in chain.links.iter().zip(scene.links()) {
            let (n, l) = (link.nbc(), spec.length);
            assert_eq!(n, modes);
            // Coefficients of the field: collocation at ξ = i/n, i = 1..n (exact: the field
            // is in the span).
            let mut a = vec![0.0; n * n];
            let mut rhs = vec![0.0; n];
            for i in 0..n {
                let x = l * (i + 1) as f64 / n as f64;
                link.transverse.eval(x, 0, &mut a[i * n..(i + 1) * n]);
                rhs[i] = field(x, l, 0);
            }
            let bd = solve(a, rhs);
            // The represented field is the target everywhere, not only at the nodes.
            let mut phi = vec![0.0; n];
            for k in 0..=50 {
                let x = l * k as f64 / 50.0;
                link.transverse.eval(x, 0, &mut phi);
                let v: f64 = phi.iter().zip(&bd).map(|(p, b)| p * b).sum();
                assert!(
                    (v - field(x, l, 0)).abs() < 1e-9,
                    "{modes} modes: field at {x}"
                );
            }
            let d = &link.section.dbc;
            let booked: f64 = (0..n)
                .map(|r| bd[r] * (0..n).map(|c| d[r * n + c] * bd[c]).sum::<f64>())
                .sum();
            // γ∫v̇''² dx by composite Simpson on 2000 intervals of the analytic v̇''.
            let gamma = spec.kelvin_voigt.unwrap();
            let m = 2000;
            let h = l / m as f64;
            let simpson: f64 = (0..=m)
                .map(|k| {
                    let w = if k == 0 || k == m {
                        1.0
                    } else if k % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * field(k as f64 * h, l, 2).powi(2)
                })
                .sum::<f64>()
                * h
                / 3.0;
            let reference = gamma * simpson;
            println!(
                "{modes} modes, {}: booked {booked:.12e}, quadrature {reference:.12e}",
                spec.name
            );
            assert!(
                (booked - reference).abs() < 1e-9 * reference,
                "{modes} modes, {}: {booked} vs {reference}",
                spec.name
            );
            powers.push(booked);
        }
    }
    // The same physical field in 6 and in 12 modes: the same power, link by link.
    for k in 0..2 {
        let (p6, p12) = (powers[k], powers[k + 2]);
        assert!((p6 - p12).abs() < 1e-9 * p6, "link {k}: {p6} vs {p12}");
    }
}
