//! Shape functions and quadrature alone (`elem_` layer).

use modal::basis::quadrature::{Quadrature, gauss_legendre};
use modal::basis::{ShapeSet, clamped_free_reference_roots, frequency_roots};

#[test]
fn elem_gauss_legendre_exact_for_polynomials() {
    let (x, w) = gauss_legendre(10);
    // Exact for degree ≤ 19: ∫₋₁¹ t^k = 2/(k+1) for even k.
    for k in 0..20 {
        let exact = if k % 2 == 0 {
            2.0 / (k as f64 + 1.0)
        } else {
            0.0
        };
        let q: f64 = x.iter().zip(&w).map(|(t, wi)| wi * t.powi(k)).sum();
        assert!((q - exact).abs() < 1e-14, "degree {k}: {q} vs {exact}");
    }
    let quad = Quadrature::composite(2.0, 3, 5);
    assert!((quad.integrate(|x| x * x) - 8.0 / 3.0).abs() < 1e-14);
}

#[test]
fn elem_clamped_free_roots_match_the_classical_equation() {
    // Basis roots come from a 4×4 determinant of the exponential/trigonometric form; the
    // reference solves cos β + 1/cosh β = 0 by bisection — two independent paths.
    let n = 40;
    let basis = frequency_roots(n, 0.0, 0.0).unwrap();
    let reference = clamped_free_reference_roots(n);
    for (k, (b, r)) in basis.iter().zip(&reference).enumerate() {
        // Both bisected to ~1 ulp; 1e-12 relative leaves room for the determinant's rounding.
        assert!(((b - r) / r).abs() < 1e-12, "mode {}: {b} vs {r}", k + 1);
    }
}

/// Mass- and stiffness-orthogonality with the tip terms: ∫φᵢφⱼ dξ + μφᵢφⱼ(1) + jφᵢ'φⱼ'(1) = δᵢⱼ
/// and ∫φᵢ''φⱼ'' dξ = βᵢ⁴ δᵢⱼ (unit length).
fn check_orthogonality(n: usize, mu: f64, j: f64, tol: f64) {
    let s = ShapeSet::tip_mass(1.0, n, mu, j).unwrap();
    let beta = s.betas().unwrap().to_vec();
    let quad = Quadrature::for_wavenumber(1.0, beta[n - 1]);
    let (mut v, mut d2) = (vec![0.0; n], vec![0.0; n]);
    let mut m = vec![0.0; n * n];
    let mut k = vec![0.0; n * n];
    for (x, w) in quad.x.iter().zip(&quad.w) {
        s.eval(*x, 0, &mut v);
        s.eval(*x, 2, &mut d2);
        for a in 0..n {
            for b in 0..n {
                m[a * n + b] += w * v[a] * v[b];
                k[a * n + b] += w * d2[a] * d2[b];
            }
        }
    }
    let mut d1 = vec![0.0; n];
    s.eval(1.0, 0, &mut v);
    s.eval(1.0, 1, &mut d1);
    for a in 0..n {
        for b in 0..n {
            let mm = m[a * n + b] + mu * v[a] * v[b] + j * d1[a] * d1[b];
            let target = if a == b { 1.0 } else { 0.0 };
            assert!(
                (mm - target).abs() < tol,
                "M[{a},{b}] = {mm} (μ = {mu}, j = {j})"
            );
            let kk = k[a * n + b] / (beta[a] * beta[b]).powi(2);
            assert!(
                (kk - target).abs() < tol,
                "K[{a},{b}]/β⁴ = {kk} (μ = {mu}, j = {j})"
            );
        }
    }
}

#[test]
fn elem_clamped_free_orthonormal_up_to_forty_modes() {
    // Quadrature (≥ 4 panels × 10 points per wavelength) and the bounded form keep ~1e-12;
    // 1e-10 allows for the conditioning of the 40-mode Gram matrix.
    check_orthogonality(40, 0.0, 0.0, 1e-10);
}

#[test]
fn elem_tip_mass_eigenfunctions_orthonormal() {
    check_orthogonality(20, 1.0, 0.0, 1e-10);
    check_orthogonality(12, 1.0, 0.05, 1e-10);
    check_orthogonality(8, 100.0, 0.0, 1e-10);
}

#[test]
fn elem_tip_mass_roots_satisfy_classical_frequency_equation() {
    // Without tip inertia: 1 + cos β cosh β + μβ(cos β sinh β − sin β cosh β) = 0; divided by
    // cosh β for stability. Residual relative to the size of the individual terms.
    for mu in [0.1, 1.0, 10.0] {
        for b in frequency_roots(10, mu, 0.0).unwrap() {
            let r = 1.0 / b.cosh() + b.cos() + mu * b * (b.cos() * b.tanh() - b.sin());
            let scale = 1.0 + mu * b;
            assert!((r / scale).abs() < 1e-12, "μ = {mu}, β = {b}: residual {r}");
        }
    }
}

#[test]
fn elem_clamped_free_boundary_conditions_hold_at_high_n() {
    let n = 30;
    let l = 2.5;
    let s = ShapeSet::clamped_free(l, n).unwrap();
    let beta = s.betas().unwrap().to_vec();
    let mut v = vec![0.0; n];
    for (deriv, x) in [(0, 0.0), (1, 0.0), (2, l), (3, l)] {
        s.eval(x, deriv, &mut v);
        for k in 0..n {
            // Relative to the derivative's natural size (β/L)^deriv · O(1).
            let size = (beta[k] / l).powi(deriv as i32);
            assert!(
                (v[k] / size).abs() < 1e-12,
                "mode {} d{deriv} at {x}: {}",
                k + 1,
                v[k]
            );
        }
    }
    // Unit-normalized shapes of a clamped-free beam have |φ(L)| = 2.
    s.eval(l, 0, &mut v);
    for (k, vk) in v.iter().enumerate() {
        assert!((vk - 2.0).abs() < 1e-10, "mode {}: φ(L) = {vk}", k + 1);
    }
}

#[test]
fn elem_naive_cosh_cos_form_loses_digits_where_stable_form_does_not() {
    // The textbook form at mode 14 (β ≈ 42.4) against the stable one at the tip.
    let n = 14;
    let s = ShapeSet::clamped_free(1.0, n).unwrap();
    let b = s.betas().unwrap()[n - 1];
    let sigma = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
    let naive = b.cosh() - b.cos() - sigma * (b.sinh() - b.sin());
    let mut v = vec![0.0; n];
    s.eval(1.0, 0, &mut v);
    assert!((v[n - 1] - 2.0).abs() < 1e-12);
    // The naive value is off by far more than round-off (cancellation of ~e^β/2 ≈ 1e18 terms).
    assert!(
        (naive.abs() - 2.0).abs() > 1e-3,
        "naive form unexpectedly accurate: {naive}"
    );
}

#[test]
fn elem_poly_basis_spans_the_monomials() {
    // The Legendre-based representation spans ξ², …, ξ^{n+1}: fit ξ⁵ exactly with n = 4.
    let n = 4;
    let s = ShapeSet::poly(1.0, n);
    let quad = Quadrature::composite(1.0, 4, 10);
    let mut v = vec![0.0; n];
    let mut g = vec![0.0; n * n];
    let mut rhs = vec![0.0; n];
    for (x, w) in quad.x.iter().zip(&quad.w) {
        s.eval(*x, 0, &mut v);
        for a in 0..n {
            rhs[a] += w * v[a] * x.powi(5);
            for b in 0..n {
                g[a * n + b] += w * v[a] * v[b];
            }
        }
    }
    // Solve the 4×4 normal equations by Gaussian elimination.
    for c in 0..n {
        for r in c + 1..n {
            let f = g[r * n + c] / g[c * n + c];
            for k in c..n {
                g[r * n + k] -= f * g[c * n + k];
            }
            rhs[r] -= f * rhs[c];
        }
    }
    let mut coef = vec![0.0; n];
    for r in (0..n).rev() {
        let mut acc = rhs[r];
        for k in r + 1..n {
            acc -= g[r * n + k] * coef[k];
        }
        coef[r] = acc / g[r * n + r];
    }
    for x in [0.1, 0.37, 0.8, 1.0] {
        s.eval(x, 0, &mut v);
        let fit: f64 = v.iter().zip(&coef).map(|(a, b)| a * b).sum();
        assert!((fit - x.powi(5)).abs() < 1e-12, "x = {x}: {fit}");
    }
    // Derivatives against central differences.
    let (mut d1, mut vp, mut vm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let h = 1e-5;
    s.eval(0.6, 1, &mut d1);
    s.eval(0.6 + h, 0, &mut vp);
    s.eval(0.6 - h, 0, &mut vm);
    for k in 0..n {
        let fd = (vp[k] - vm[k]) / (2.0 * h);
        // Central difference truncation h²φ'''/6 ≈ 1e-9 for these O(10) derivatives.
        assert!((fd - d1[k]).abs() < 1e-7, "φ'_{k}: {} vs {fd}", d1[k]);
    }
}
