//! Bending frequencies of a uniform cantilever on a hub spinning at constant Ω (hub radius 0).
//!
//! Flapwise (out of the plane of rotation) — Euler–Bernoulli beam with the centrifugal tension
//! T(x) = ½ρAΩ²(L² − x²):
//!
//! `EI w'''' − (T w')' + ρA ẅ = 0`,
//!
//! in ξ = x/L with μ = ω sqrt(ρAL⁴/EI) and λ = Ω sqrt(ρAL⁴/EI):
//!
//! `W'''' − (λ²/2) [(1 − ξ²) W']' − μ² W = 0`, W(0) = W'(0) = 0, W''(1) = W'''(1) = 0
//!
//! (at ξ = 1 the shear is EI W''' − T W' with T(1) = 0). Solved by the method of Frobenius
//! (Wright, Smith, Thompson & Worley 1982, J. Appl. Mech. 49, cited in seed 001 as ref. \[5\]):
//! ξ = 0 is an ordinary point and the coefficients are polynomials, so W = Σ a_k ξ^k is entire
//! with the recurrence (coefficient of ξ^k)
//!
//! `a_{k+4} = [ (λ²/2)((k+2)(k+1) a_{k+2} − k(k+1) a_k) + μ² a_k ] / ((k+4)(k+3)(k+2)(k+1))`,
//!
//! a₀ = a₁ = 0 (clamped) and the two solutions (a₂, a₃) = (1, 0), (0, 1). The frequency equation
//! is det \[\[W₁''(1), W₂''(1)\], \[W₁'''(1), W₂'''(1)\]\] = 0, with W''(1) = Σ k(k−1) a_k etc. The
//! series and the determinant are summed in double-double arithmetic: the products in the
//! determinant are O(e^{2√μ}) while their difference is O(e^{√μ}), which would cost
//! √μ/ln 10 digits in f64.
//!
//! In-plane (chordwise) bending of the inextensible (foreshortening) model, which is what the
//! planar scenes solve: the rotating frame adds −ρAΩ² w, so `μ_in² = μ_out² − λ²`.
//!
//! Units: nondimensional in, nondimensional out; [`rotating_frequencies_hz`] converts.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::analytic::beam::{BeamSupport, beam_eigenvalue};
use crate::analytic::error::{AnalyticError, Result, non_negative, positive};
use crate::analytic::numerics::ddouble::DD;
use crate::analytic::numerics::roots::{RootOptions, first_roots};

/// Bending plane of a rotating cantilever relative to its plane of rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RotatingPlane {
    /// Out of the plane of rotation (flapwise).
    Flapwise,
    /// In the plane of rotation (chordwise), inextensible model.
    InPlane,
}

/// The Frobenius frequency determinant at nondimensional speed λ and frequency μ.
///
/// Summation stops once k ≥ 8 + 4(√μ + λ) (past the largest term) and four consecutive terms
/// of both sums are below 1e-34 of the largest partial magnitude; the term cap 4000 + 8·k_min is
/// never reached for convergent sums (an error is returned, never a truncated value). The
/// double-double range limits the method to e^{2√μ} < 1e300, i.e. √μ ≲ 340.
pub fn flapwise_frequency_determinant(lambda: f64, mu: f64) -> Result<f64> {
    let half_l2 = 0.5 * lambda * lambda;
    let mu2 = mu * mu;
    let k_min = 8 + (4.0 * (mu.sqrt() + lambda)) as usize;
    // Two solutions: coefficient windows a_k, a_{k+1}, a_{k+2}, a_{k+3} for each.
    let mut a: [[DD; 4]; 2] = [
        [DD::ZERO, DD::ZERO, DD::from_f64(1.0), DD::ZERO],
        [DD::ZERO, DD::ZERO, DD::ZERO, DD::from_f64(1.0)],
    ];
    // Sums W''(1) = Σ k(k−1) a_k and W'''(1) = Σ k(k−1)(k−2) a_k.
    let mut d2 = [DD::ZERO; 2];
    let mut d3 = [DD::ZERO; 2];
    let mut largest = 0.0f64;
    let mut small_run = 0;
    let max_terms = 4000 + 8 * k_min;
    for k in 0..max_terms {
        let kf = k as f64;
        for j in 0..2 {
            let ak = a[j][0];
            let c2 = kf * (kf - 1.0);
            let c3 = c2 * (kf - 2.0);
            let t2 = ak.mul_f64(c2);
            let t3 = ak.mul_f64(c3);
            d2[j] = d2[j] + t2;
            d3[j] = d3[j] + t3;
            largest = largest
                .max(d2[j].hi.abs())
                .max(d3[j].hi.abs())
                .max(t3.hi.abs());
        }
        let tail = (0..2)
            .map(|j| a[j][0].hi.abs() * kf.powi(3))
            .fold(0.0, f64::max);
        if k >= k_min && tail <= 1e-34 * largest {
            small_run += 1;
            if small_run >= 4 {
                let det = d2[0] * d3[1] - d2[1] * d3[0];
                return Ok(det.to_f64());
            }
        } else {
            small_run = 0;
        }
        // a_{k+4} from a_k (window[0]) and a_{k+2} (window[2]).
        let denom = (kf + 4.0) * (kf + 3.0) * (kf + 2.0) * (kf + 1.0);
        for w in a.iter_mut() {
            let next = (w[2].mul_f64(half_l2 * (kf + 2.0) * (kf + 1.0))
                - w[0].mul_f64(half_l2 * kf * (kf + 1.0))
                + w[0].mul_f64(mu2))
            .div_f64(denom);
            *w = [w[1], w[2], w[3], next];
        }
        if !largest.is_finite() {
            break;
        }
    }
    Err(AnalyticError::NoConvergence {
        what: "Frobenius series of the rotating beam",
        iterations: max_terms,
    })
}

/// The first `n` nondimensional flapwise frequencies μ = ω sqrt(ρAL⁴/EI) at speed λ.
///
/// Search variable x = √μ (the βL of the non-rotating beam). The tension only stiffens, so
/// μ₁(λ) ≥ μ₁(0) = x_cf₁² and the scan starts at 0.95 x_cf₁. Roots in x are spaced by ≳ 2 (π at
/// λ = 0, wider with tension), so a 0.02 grid cannot hold two in one cell.
pub fn flapwise_frequencies(lambda: f64, n: usize) -> Result<Vec<f64>> {
    non_negative("lambda", lambda)?;
    let x1 = beam_eigenvalue(BeamSupport::ClampedFree, 1)?;
    // Failures inside the determinant are kept and reported (never turned into fake roots).
    let mut failure: Option<AnalyticError> = None;
    // Tension-dominated limit: μₙ ≲ λ·sqrt(2)·n, so √μₙ ≲ 1.2 sqrt(nλ); bending: x ≈ (n − ½)π.
    let limit = (n as f64 + 1.0) * PI + 1.5 * ((n as f64 + 1.0) * lambda).sqrt() + 10.0;
    let roots = first_roots(
        |x| match flapwise_frequency_determinant(lambda, x * x) {
            Ok(d) => d,
            Err(e) => {
                failure = Some(e);
                f64::NAN
            }
        },
        0.95 * x1,
        0.02,
        limit,
        n,
        "rotating beam (Frobenius)",
        RootOptions::default(),
    );
    if let Some(e) = failure {
        return Err(e);
    }
    Ok(roots?.into_iter().map(|x| x * x).collect())
}

/// The first `n` nondimensional frequencies μ in the given plane at speed λ
/// (in-plane: μ_in = sqrt(μ_out² − λ²)).
pub fn rotating_frequencies(plane: RotatingPlane, lambda: f64, n: usize) -> Result<Vec<f64>> {
    let out = flapwise_frequencies(lambda, n)?;
    match plane {
        RotatingPlane::Flapwise => Ok(out),
        RotatingPlane::InPlane => out
            .into_iter()
            .map(|mu| {
                let m2 = mu * mu - lambda * lambda;
                if m2 > 0.0 {
                    Ok(m2.sqrt())
                } else {
                    Err(AnalyticError::InvalidParameter {
                        name: "lambda",
                        value: lambda,
                        why: "in-plane frequency squared is not positive",
                    })
                }
            })
            .collect(),
    }
}

/// Rotating-beam frequencies \[Hz\] for a link with EI, ρA, L spinning at Ω \[rad/time\].
pub fn rotating_frequencies_hz(
    plane: RotatingPlane,
    ei: f64,
    rho_a: f64,
    length: f64,
    omega: f64,
    n: usize,
) -> Result<Vec<f64>> {
    positive("EI", ei)?;
    positive("rho A", rho_a)?;
    positive("L", length)?;
    let scale = (ei / (rho_a * length.powi(4))).sqrt(); // ω = μ · scale
    let lambda = omega.abs() / scale;
    Ok(rotating_frequencies(plane, lambda, n)?
        .into_iter()
        .map(|mu| mu * scale / (2.0 * PI))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::beam::beam_eigenvalues;
    use faer::{Mat, Side};

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn ana_rotating_zero_speed_is_clamped_free() {
        let mu = flapwise_frequencies(0.0, 6).unwrap();
        let x = beam_eigenvalues(BeamSupport::ClampedFree, 6).unwrap();
        for k in 0..6 {
            // Double-double series vs the scaled closed form, both to Brent's 1e-14: 1e-12.
            assert!(
                rel(mu[k], x[k] * x[k]) < 1e-12,
                "mode {}: {} vs {}",
                k + 1,
                mu[k],
                x[k]
            );
        }
    }

    #[test]
    fn ana_rotating_monotone_in_speed() {
        let mut prev = flapwise_frequencies(0.0, 3).unwrap();
        for lambda in [1.0, 2.0, 4.0, 8.0, 12.0] {
            let cur = flapwise_frequencies(lambda, 3).unwrap();
            let inp = rotating_frequencies(RotatingPlane::InPlane, lambda, 3).unwrap();
            for k in 0..3 {
                assert!(cur[k] > prev[k], "λ = {lambda} mode {}", k + 1);
                assert!(inp[k] < cur[k]);
                assert!(
                    (inp[k] * inp[k] - (cur[k] * cur[k] - lambda * lambda)).abs()
                        < 1e-12 * cur[k] * cur[k]
                );
            }
            prev = cur;
        }
    }

    #[test]
    fn ana_rotating_literature_loose() {
        // Loose sanity check only (the reference is the series itself): the widely tabulated
        // first flapwise value at λ = 12 is about 13.17 (e.g. Wright et al. 1982; Hodges &
        // Rutkowski 1981).
        let mu = flapwise_frequencies(12.0, 1).unwrap()[0];
        assert!((mu - 13.17).abs() < 0.01, "{mu}");
    }

    /// Gauss–Legendre nodes/weights on \[0, 1\].
    fn gauss01(n: usize) -> Vec<(f64, f64)> {
        crate::analytic::numerics::quadrature::gauss_legendre_nodes(n)
            .into_iter()
            .map(|(z, w)| (0.5 * (z + 1.0), 0.5 * w))
            .collect()
    }

    /// Independent Rayleigh–Ritz: basis φ_m = ξ² P_m(2ξ − 1) (clamped), stiffness
    /// ∫φ''φ'' + (λ²/2)∫(1 − ξ²)φ'φ', mass ∫φφ, solved by Cholesky reduction (faer).
    fn ritz(lambda: f64, nb: usize) -> Vec<f64> {
        let q = gauss01(3 * nb + 10);
        let basis = |xi: f64| {
            // Legendre P_m(z) and derivatives in z, z = 2ξ − 1.
            let z = 2.0 * xi - 1.0;
            let mut p = vec![0.0; nb + 1];
            let mut dp = vec![0.0; nb + 1];
            let mut ddp = vec![0.0; nb + 1];
            p[0] = 1.0;
            if nb > 0 {
                p[1] = z;
                dp[1] = 1.0;
            }
            for k in 1..nb {
                let kf = k as f64;
                p[k + 1] = ((2.0 * kf + 1.0) * z * p[k] - kf * p[k - 1]) / (kf + 1.0);
                dp[k + 1] = dp[k - 1] + (2.0 * kf + 1.0) * p[k];
                ddp[k + 1] = ddp[k - 1] + (2.0 * kf + 1.0) * dp[k];
            }
            (0..nb)
                .map(|m| {
                    let (pm, dpm, ddpm) = (p[m], 2.0 * dp[m], 4.0 * ddp[m]); // d/dξ = 2 d/dz
                    let f = xi * xi * pm;
                    let d1 = 2.0 * xi * pm + xi * xi * dpm;
                    let d2 = 2.0 * pm + 4.0 * xi * dpm + xi * xi * ddpm;
                    (f, d1, d2)
                })
                .collect::<Vec<_>>()
        };
        let mut k = Mat::<f64>::zeros(nb, nb);
        let mut m = Mat::<f64>::zeros(nb, nb);
        for &(xi, w) in &q {
            let b = basis(xi);
            for i in 0..nb {
                for j in 0..nb {
                    k[(i, j)] += w
                        * (b[i].2 * b[j].2
                            + 0.5 * lambda * lambda * (1.0 - xi * xi) * b[i].1 * b[j].1);
                    m[(i, j)] += w * b[i].0 * b[j].0;
                }
            }
        }
        let llt = m.llt(Side::Lower).expect("mass matrix SPD");
        let lm = llt.L();
        let mut t = k.clone();
        lm.solve_lower_triangular_in_place(&mut t);
        let mut c = t.transpose().to_owned();
        lm.solve_lower_triangular_in_place(&mut c);
        let ev = c.self_adjoint_eigenvalues(Side::Lower).unwrap();
        ev.into_iter().map(f64::sqrt).collect()
    }

    #[test]
    fn ana_rotating_matches_rayleigh_ritz() {
        for lambda in [0.0, 4.0, 12.0] {
            let mu = flapwise_frequencies(lambda, 3).unwrap();
            let r = ritz(lambda, 14);
            for k in 0..3 {
                // Ritz is an upper bound; with 14 polynomials the first three modes converge
                // spectrally (error ≲ 1e-8), limited by the conditioning of the reduction.
                assert!(r[k] >= mu[k] * (1.0 - 1e-10), "λ {lambda} mode {}", k + 1);
                assert!(
                    rel(r[k], mu[k]) < 1e-6,
                    "λ {lambda} mode {}: {} vs {}",
                    k + 1,
                    r[k],
                    mu[k]
                );
            }
        }
    }

    #[test]
    fn ana_rotating_hz_scales() {
        let scene = data::load_scene("spin-up").unwrap();
        let l = &scene.planar_chain().unwrap().links[0];
        let f = rotating_frequencies_hz(
            RotatingPlane::InPlane,
            l.bending_stiffness,
            l.mass_per_length,
            l.length,
            0.0,
            1,
        )
        .unwrap()[0];
        // Spin-up beam: ω₁ ≈ 3.80 rad/s (scenes.md), the clamped-free value.
        let w1 = 2.0 * PI * f;
        assert!((w1 - 3.80).abs() < 0.01, "{w1}");
    }
}
