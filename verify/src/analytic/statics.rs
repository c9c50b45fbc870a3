//! Cantilever statics: linear Euler–Bernoulli closed forms and the large-deflection elastica.
//!
//! Linear (Timoshenko & Gere, "Mechanics of Materials", cantilever tables): tip load P gives tip
//! deflection PL³/(3EI) and slope PL²/(2EI); a uniform load q gives qL⁴/(8EI) and qL³/(6EI).
//!
//! Elastica (Euler 1744; Bisshopp & Drucker 1945, Q. Appl. Math. 3): inextensible, unshearable
//! cantilever under a dead transverse tip load P (direction fixed, along the frame's +y). With
//! arc length s ∈ \[0, L\] scaled by L and θ the section angle, moment equilibrium
//! EI θ'(s) = P (x_tip − x(s)) differentiates to
//!
//! `θ'' = −α cos θ`, `θ(0) = 0`, `θ'(1) = 0`, `α = PL²/EI`,
//!
//! solved by shooting on κ₀ = θ'(0) ∈ \[0, sqrt(2α)\] (the first integral
//! ½θ'² + α sin θ = α sin θ_tip bounds κ₀² = 2α sin θ_tip ≤ 2α; at κ₀ = 0, θ'(1) < 0 and at
//! κ₀ = sqrt(2α), θ' > 0 throughout), with Dormand–Prince at rtol 1e-13 and Brent on θ'(1).
//! Tip position x_tip/L = ∫cos θ, y_tip/L = ∫sin θ integrated along.
//!
//! Units: consistent (P \[force\], q \[force/length\], EI \[force·length²\], L \[length\]).

use serde::{Deserialize, Serialize};

use crate::analytic::error::{AnalyticError, Result, finite, non_negative, positive};
use crate::analytic::numerics::ode::Dopri5;
use crate::analytic::numerics::roots::{RootOptions, brent};

/// Linear tip response of a cantilever.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TipResponse {
    /// Transverse tip deflection \[length\].
    pub deflection: f64,
    /// Tip slope \[rad\].
    pub slope: f64,
}

/// Tip load P: deflection PL³/(3EI), slope PL²/(2EI).
pub fn cantilever_tip_load(p: f64, ei: f64, length: f64) -> Result<TipResponse> {
    finite("P", p)?;
    positive("EI", ei)?;
    positive("L", length)?;
    Ok(TipResponse {
        deflection: p * length.powi(3) / (3.0 * ei),
        slope: p * length.powi(2) / (2.0 * ei),
    })
}

/// Uniform load q: deflection qL⁴/(8EI), slope qL³/(6EI).
pub fn cantilever_uniform_load(q: f64, ei: f64, length: f64) -> Result<TipResponse> {
    finite("q", q)?;
    positive("EI", ei)?;
    positive("L", length)?;
    Ok(TipResponse {
        deflection: q * length.powi(4) / (8.0 * ei),
        slope: q * length.powi(3) / (6.0 * ei),
    })
}

/// Large-deflection cantilever under a dead tip load, nondimensional by L.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Elastica {
    /// Load parameter α = PL²/EI.
    pub alpha: f64,
    /// Transverse tip displacement / L (along the load).
    pub tip_transverse: f64,
    /// Axial tip displacement / L, i.e. x_tip/L − 1 (≤ 0: the tip moves towards the root).
    pub tip_axial: f64,
    /// Tip rotation θ(1) \[rad\].
    pub tip_rotation: f64,
    /// Root curvature θ'(0) = M(0) L / EI.
    pub root_curvature: f64,
}

/// Integrates θ'' = −α cos θ over s ∈ \[0, 1\] from θ(0) = 0, θ'(0) = κ₀;
/// returns \[θ, θ', x, y\] at s = 1.
fn shoot(alpha: f64, kappa0: f64, rtol: f64) -> Result<[f64; 4]> {
    let mut f = |_s: f64, y: &[f64], d: &mut [f64]| {
        d[0] = y[1];
        d[1] = -alpha * y[0].cos();
        d[2] = y[0].cos();
        d[3] = y[0].sin();
    };
    let mut y = [0.0, kappa0, 0.0, 0.0];
    let mut s = 0.0;
    let mut ode = Dopri5::new(4, rtol, rtol * 1e-2);
    ode.advance(&mut f, &mut s, &mut y, 1.0)?;
    Ok(y)
}

/// The elastica of a cantilever under a dead transverse tip load with α = PL²/EI ≥ 0.
pub fn cantilever_elastica(alpha: f64) -> Result<Elastica> {
    non_negative("alpha = P L^2 / EI", alpha)?;
    if alpha == 0.0 {
        return Ok(Elastica {
            alpha,
            tip_transverse: 0.0,
            tip_axial: 0.0,
            tip_rotation: 0.0,
            root_curvature: 0.0,
        });
    }
    const RTOL: f64 = 1e-13;
    // Any failure of the integrator inside the root search is kept and reported.
    let mut failure: Option<AnalyticError> = None;
    let mut residual = |k: f64| match shoot(alpha, k, RTOL) {
        Ok(y) => y[1],
        Err(e) => {
            failure = Some(e);
            f64::NAN
        }
    };
    let k_max = (2.0 * alpha).sqrt();
    let kappa0 = brent(&mut residual, 0.0, k_max, RootOptions::default());
    if let Some(e) = failure {
        return Err(e);
    }
    let kappa0 = kappa0?;
    let y = shoot(alpha, kappa0, RTOL)?;
    Ok(Elastica {
        alpha,
        tip_transverse: y[3],
        tip_axial: y[2] - 1.0,
        tip_rotation: y[0],
        root_curvature: kappa0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn ana_linear_statics_closed_forms() {
        let t = cantilever_tip_load(2.0, 3.0, 1.5).unwrap();
        assert_eq!(t.deflection, 2.0 * 1.5f64.powi(3) / 9.0);
        assert_eq!(t.slope, 2.0 * 1.5f64.powi(2) / 6.0);
        let q = cantilever_uniform_load(2.0, 3.0, 1.5).unwrap();
        assert_eq!(q.deflection, 2.0 * 1.5f64.powi(4) / 24.0);
        assert_eq!(q.slope, 2.0 * 1.5f64.powi(3) / 18.0);
        assert!(cantilever_tip_load(1.0, 0.0, 1.0).is_err());
        assert!(cantilever_uniform_load(f64::NAN, 1.0, 1.0).is_err());
    }

    #[test]
    fn ana_elastica_small_load_is_linear() {
        // y/L = α/3 (1 − O(α²)), θ_tip = α/2 (1 − O(α²)): the relative deviation from the
        // linear limit must be small and shrink by 4 when α halves (observed order 2 ± 0.05).
        let e = cantilever_elastica(1e-3).unwrap();
        let e2 = cantilever_elastica(0.5e-3).unwrap();
        let d1 = rel(e.tip_transverse, 1e-3 / 3.0);
        let d2 = rel(e2.tip_transverse, 0.5e-3 / 3.0);
        assert!(d1 < 1e-6, "{e:?}");
        let order = (d1 / d2).log2();
        assert!((order - 2.0).abs() < 0.05, "order {order}");
        assert!(rel(e.tip_rotation, 1e-3 / 2.0) < 1e-6);
        // shortening is second order: ∫(1 − cos θ) ≈ ½∫θ² = α²/15 (θ = α(s − s²/2)).
        assert!(rel(-e.tip_axial, 1e-6 / 15.0) < 1e-5);
    }

    #[test]
    fn ana_elastica_first_integrals_hold() {
        // Exact relations of the elastica, independent of the shooting: x_tip = θ'(0)/α
        // (integrate θ'' = −α cos θ) and θ'(0)² = 2α sin θ_tip (first integral).
        for &alpha in &[0.5, 2.0, 5.0, 10.0] {
            let e = cantilever_elastica(alpha).unwrap();
            let x_tip = 1.0 + e.tip_axial;
            // Integration at rtol 1e-13: relations hold to ~1e-11.
            assert!(rel(x_tip, e.root_curvature / alpha) < 1e-11);
            assert!(rel(e.root_curvature.powi(2), 2.0 * alpha * e.tip_rotation.sin()) < 1e-11);
        }
    }

    #[test]
    fn ana_elastica_matches_elliptic_quadrature() {
        // Independent route: from the first integral, ds = dθ / sqrt(2α(sin θ₀ − sin θ)); with
        // θ = θ₀ − w² the integrand is smooth. θ₀ solves ∫ ds = 1; then y = ∫ sin θ ds.
        // Gauss–Legendre (n = 40, nodes by Newton) on w ∈ [0, sqrt(θ₀)].
        let nodes = crate::analytic::numerics::quadrature::gauss_legendre_nodes(40);
        let quad = |alpha: f64, th0: f64, g: &dyn Fn(f64) -> f64| {
            let b = th0.sqrt();
            nodes
                .iter()
                .map(|&(z, wgt)| {
                    let w = 0.5 * b * (z + 1.0);
                    let th = th0 - w * w;
                    let den = (2.0 * alpha * (th0.sin() - th.sin())).sqrt();
                    // dθ = 2w dw; the ratio 2w/den stays finite as w → 0.
                    0.5 * b * wgt * g(th) * 2.0 * w / den
                })
                .sum::<f64>()
        };
        for &alpha in &[1.0, 10.0] {
            let th0 = brent(
                |t| quad(alpha, t, &|_| 1.0) - 1.0,
                1e-6,
                std::f64::consts::FRAC_PI_2 - 1e-9,
                RootOptions::default(),
            )
            .unwrap();
            let y = quad(alpha, th0, &|t: f64| t.sin());
            let e = cantilever_elastica(alpha).unwrap();
            // 40-point Gauss on a smooth integrand: ~1e-12; shooting ~1e-12.
            assert!(
                rel(e.tip_rotation, th0) < 1e-9,
                "{} vs {th0}",
                e.tip_rotation
            );
            assert!(
                rel(e.tip_transverse, y) < 1e-9,
                "{} vs {y}",
                e.tip_transverse
            );
        }
    }

    #[test]
    fn ana_elastica_bisshopp_drucker_loose() {
        // Loose sanity check only (not the reference): Bisshopp & Drucker's table gives, for
        // PL²/EI = 10, a vertical tip deflection of about 0.81 L and a horizontal one of about
        // 0.56 L (their figure reads x_tip ≈ 0.44 L).
        let e = cantilever_elastica(10.0).unwrap();
        assert!((e.tip_transverse - 0.81).abs() < 0.01, "{e:?}");
        assert!((-e.tip_axial - 0.56).abs() < 0.02, "{e:?}");
        // Monotone in the load and bounded by L.
        let mut last = 0.0;
        for a in [0.5, 1.0, 2.0, 5.0, 10.0] {
            let y = cantilever_elastica(a).unwrap().tip_transverse;
            assert!(y > last && y < 1.0);
            last = y;
        }
        assert!(cantilever_elastica(-1.0).is_err());
    }
}
