//! Euler–Bernoulli bending and axial natural frequencies of uniform beams.
//!
//! Bending: `EI w'''' + ρA ẅ = 0` on 0 ≤ x ≤ L. With w = W(x) sin ωt and β⁴ = ω² ρA / EI the
//! boundary conditions give a transcendental equation in βL (Blevins, "Formulas for Natural
//! Frequency and Mode Shape", table 8-1; Meirovitch, "Fundamentals of Vibrations", §8.7):
//!
//! | support | equation | rigid modes excluded |
//! |---|---|---|
//! | clamped–free | 1 + cos βL cosh βL = 0 | – |
//! | free–free | cos βL cosh βL = 1 | βL = 0 (two) |
//! | pinned–free | tan βL = tanh βL | βL = 0 (one) |
//! | clamped–pinned | tan βL = tanh βL | – |
//!
//! Each is divided by cosh βL before root finding (sech x = 2e^{−x}/(1 + e^{−2x})), so no
//! exponential overflows or cancels for high modes. Frequencies follow from
//! `f = (βL)² / (2π L²) · sqrt(EI / ρA)` \[Hz\].
//!
//! Tip mass M and tip rotary inertia J on a cantilever (derived in [`cantilever_tip_mass_roots`]).
//!
//! Axial: `EA u'' = ρA ü`, clamped–free `fₙ = (2n − 1)/(4L) · sqrt(EA/ρA)`; with a tip mass the
//! roots of `z tan z = ρAL / M` (derived in [`axial_tip_mass_frequencies_hz`]).
//!
//! Units: any consistent system; EI \[force·length²\], ρA \[mass/length\], L \[length\] → Hz.

use std::f64::consts::{FRAC_PI_2, PI};

use serde::{Deserialize, Serialize};

use crate::analytic::error::{Result, non_negative, positive};
use crate::analytic::numerics::roots::{RootOptions, brent, first_roots};

/// Supports of a uniform Euler–Bernoulli beam (root end – far end).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BeamSupport {
    ClampedFree,
    FreeFree,
    PinnedFree,
    ClampedPinned,
}

/// sech x computed without overflow.
fn sech(x: f64) -> f64 {
    let e = (-x.abs()).exp();
    2.0 * e / (1.0 + e * e)
}

/// The frequency equation of `kind`, divided by cosh x: zero exactly at the eigenvalues x = βL.
pub fn frequency_function(kind: BeamSupport, x: f64) -> f64 {
    match kind {
        // (1 + cos x cosh x) / cosh x
        BeamSupport::ClampedFree => x.cos() + sech(x),
        // (cos x cosh x − 1) / cosh x
        BeamSupport::FreeFree => x.cos() - sech(x),
        // (sin x cosh x − cos x sinh x) / cosh x  ⇔  tan x = tanh x
        BeamSupport::PinnedFree | BeamSupport::ClampedPinned => x.sin() - x.cos() * x.tanh(),
    }
}

/// The n-th elastic eigenvalue βₙL (n ≥ 1).
///
/// Brackets (each contains exactly one root because the bounded term sech x or tanh x changes
/// the sign pattern of cos/sin by less than 1):
/// * clamped–free: \[(n−1)π, nπ\];
/// * free–free: \[nπ, (n+1)π\] (the double root x = 0 is the rigid-body pair);
/// * tan x = tanh x: \[nπ, nπ + π/2\] (x = 0 is the pinned–free rigid rotation).
pub fn beam_eigenvalue(kind: BeamSupport, n: usize) -> Result<f64> {
    if n == 0 {
        return Err(crate::analytic::error::AnalyticError::InvalidParameter {
            name: "mode number n",
            value: 0.0,
            why: "modes are numbered from 1",
        });
    }
    let nf = n as f64;
    let (a, b) = match kind {
        BeamSupport::ClampedFree => ((nf - 1.0) * PI, nf * PI),
        BeamSupport::FreeFree => (nf * PI, (nf + 1.0) * PI),
        BeamSupport::PinnedFree | BeamSupport::ClampedPinned => (nf * PI, nf * PI + FRAC_PI_2),
    };
    brent(
        |x| frequency_function(kind, x),
        a,
        b,
        RootOptions::default(),
    )
}

/// β₁L … β_nL.
pub fn beam_eigenvalues(kind: BeamSupport, n: usize) -> Result<Vec<f64>> {
    (1..=n).map(|k| beam_eigenvalue(kind, k)).collect()
}

/// Natural frequency \[Hz\] for an eigenvalue x = βL: x² / (2π L²) · sqrt(EI/ρA).
pub fn frequency_hz_from_eigenvalue(x: f64, ei: f64, rho_a: f64, length: f64) -> f64 {
    x * x / (2.0 * PI * length * length) * (ei / rho_a).sqrt()
}

/// The first `n` bending frequencies \[Hz\] of a uniform beam with supports `kind`.
pub fn bending_frequencies_hz(
    kind: BeamSupport,
    ei: f64,
    rho_a: f64,
    length: f64,
    n: usize,
) -> Result<Vec<f64>> {
    positive("EI", ei)?;
    positive("rho A", rho_a)?;
    positive("L", length)?;
    Ok(beam_eigenvalues(kind, n)?
        .into_iter()
        .map(|x| frequency_hz_from_eigenvalue(x, ei, rho_a, length))
        .collect())
}

/// Frequency function of a cantilever with tip mass ratio η = M/(ρAL) and tip rotary-inertia
/// ratio j = J/(ρAL³), divided by cosh x (x = βL).
///
/// Derivation (energy → boundary conditions): T = ½∫ρA ẇ² + ½M ẇ(L)² + ½J ẇ'(L)²,
/// V = ½∫EI w''². Hamilton's principle gives at x = L
/// `EI w''(L) = J ω² w'(L)` and `EI w'''(L) = −M ω² w(L)`; in ξ = x/L with
/// W = A(cosh − cos)(xξ) + B(sinh − sin)(xξ) (clamped at ξ = 0) these read
/// `W'' − j x⁴ W' = 0`, `W''' + η x⁴ W = 0`. The 2×2 determinant, simplified with
/// cosh² − sinh² = 1 and cos² + sin² = 1 and divided by 2x⁵, is
///
/// `1 + c C + η x (S c − C s) − j x³ (C s + S c) + η j x⁴ (1 − c C) = 0`
///
/// (c = cos x, s = sin x, C = cosh x, S = sinh x; To 1982, J. Sound Vib. 83, for the same
/// equation). η = j = 0 recovers 1 + cos cosh = 0.
pub fn tip_mass_frequency_function(x: f64, eta: f64, j: f64) -> f64 {
    let (s, c) = x.sin_cos();
    let sh = sech(x);
    let th = x.tanh();
    let x3 = x * x * x;
    sh + c + eta * x * (c * th - s) - j * x3 * (s + c * th) + eta * j * x3 * x * (sh - c)
}

/// The first `n` eigenvalues βL of a cantilever with tip mass ratio η = M/(ρAL) ≥ 0 and tip
/// rotary-inertia ratio j = J/(ρAL³) ≥ 0 (equation in [`tip_mass_frequency_function`]).
///
/// Root search: Dunkerley's bound 1/ω₁² ≤ 1/ω_beam² + 1/ω_M² + 1/ω_J² (ω_M² = 3EI/(ML³),
/// ω_J² = EI/(JL), both for a massless cantilever) gives the lower limit
/// x₁ ≥ (1/x_cf⁴ + η/3 + j)^(−1/4); the scan starts at 0.9 of it. Eigenvalues of this
/// Sturm–Liouville problem are simple and separated by at least ~π/2 in x beyond the first one
/// (they interlace with the clamped–clamped and clamped–free spectra), so a grid of
/// min(0.05, x₁/10) cannot hold two roots in one cell.
pub fn cantilever_tip_mass_roots(eta: f64, j: f64, n: usize) -> Result<Vec<f64>> {
    non_negative("tip mass ratio eta", eta)?;
    non_negative("tip inertia ratio j", j)?;
    let x_cf = beam_eigenvalue(BeamSupport::ClampedFree, 1)?;
    let x_low = (1.0 / x_cf.powi(4) + eta / 3.0 + j).powf(-0.25);
    let start = 0.9 * x_low;
    let step = (0.05f64).min(x_low / 10.0);
    let limit = (n as f64 + 2.0) * PI + 10.0;
    first_roots(
        |x| tip_mass_frequency_function(x, eta, j),
        start,
        step,
        limit,
        n,
        "cantilever with tip mass",
        RootOptions::default(),
    )
}

/// Bending frequencies \[Hz\] of a uniform cantilever with tip mass M and tip rotary inertia J
/// (about the tip, per unit of the beam's bending plane).
pub fn cantilever_tip_mass_frequencies_hz(
    ei: f64,
    rho_a: f64,
    length: f64,
    tip_mass: f64,
    tip_inertia: f64,
    n: usize,
) -> Result<Vec<f64>> {
    positive("EI", ei)?;
    positive("rho A", rho_a)?;
    positive("L", length)?;
    non_negative("tip mass", tip_mass)?;
    non_negative("tip inertia", tip_inertia)?;
    let eta = tip_mass / (rho_a * length);
    let j = tip_inertia / (rho_a * length.powi(3));
    Ok(cantilever_tip_mass_roots(eta, j, n)?
        .into_iter()
        .map(|x| frequency_hz_from_eigenvalue(x, ei, rho_a, length))
        .collect())
}

/// Axial frequencies \[Hz\] of a uniform clamped–free bar: fₙ = (2n − 1)/(4L) · sqrt(EA/ρA).
pub fn axial_frequencies_hz(ea: f64, rho_a: f64, length: f64, n: usize) -> Result<Vec<f64>> {
    positive("EA", ea)?;
    positive("rho A", rho_a)?;
    positive("L", length)?;
    let c = (ea / rho_a).sqrt();
    Ok((1..=n)
        .map(|k| (2.0 * k as f64 - 1.0) / (4.0 * length) * c)
        .collect())
}

/// Axial frequencies \[Hz\] of a clamped–free bar with a tip mass M.
///
/// u = sin(kx) satisfies u(0) = 0; the tip balance EA u'(L) = M ω² u(L) with ω = k·sqrt(EA/ρA)
/// gives, for z = kL and η = M/(ρAL), `z tan z = 1/η`, solved as
/// `h(z) = η z sin z − cos z = 0` (no poles). Root n lies in \[(n−1)π, (n−1)π + π/2\], where h
/// changes sign; η = 0 recovers z = (2n − 1)π/2.
pub fn axial_tip_mass_frequencies_hz(
    ea: f64,
    rho_a: f64,
    length: f64,
    tip_mass: f64,
    n: usize,
) -> Result<Vec<f64>> {
    positive("EA", ea)?;
    positive("rho A", rho_a)?;
    positive("L", length)?;
    non_negative("tip mass", tip_mass)?;
    if tip_mass == 0.0 {
        return axial_frequencies_hz(ea, rho_a, length, n);
    }
    let eta = tip_mass / (rho_a * length);
    let c = (ea / rho_a).sqrt();
    (1..=n)
        .map(|k| {
            let a = (k as f64 - 1.0) * PI;
            // The upper end is nudged past (n − ½)π so that the rounding of cos there cannot
            // hide the sign change when η z is tiny; the next root is ~π/2 further on.
            let z = brent(
                |z| eta * z * z.sin() - z.cos(),
                a,
                a + FRAC_PI_2 + 1e-6,
                RootOptions::default(),
            )?;
            Ok(z / length * c / (2.0 * PI))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative error.
    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn ana_beam_eigenvalues_satisfy_unscaled_equations() {
        // The scaled and unscaled equations have the same roots; check the unscaled residual
        // relative to its own scale cosh(x) (round-off of cos·cosh ~ ε cosh x).
        for n in 1..=6 {
            let x = beam_eigenvalue(BeamSupport::ClampedFree, n).unwrap();
            assert!((1.0 + x.cos() * x.cosh()).abs() < 1e-13 * x.cosh());
            let x = beam_eigenvalue(BeamSupport::FreeFree, n).unwrap();
            assert!((x.cos() * x.cosh() - 1.0).abs() < 1e-13 * x.cosh());
            let x = beam_eigenvalue(BeamSupport::PinnedFree, n).unwrap();
            assert!((x.tan() - x.tanh()).abs() < 1e-12 * (1.0 + x.tan().abs()));
        }
    }

    #[test]
    fn ana_beam_eigenvalues_approach_asymptotes() {
        // For high n the sech/tanh corrections vanish like e^{-x}: βₙL → (2n−1)π/2 (clamped–free),
        // (2n+1)π/2 (free–free), (4n+1)π/4 (tan = tanh). At n = 30, e^{-x} ~ 1e-41: the
        // eigenvalue must equal the asymptote to round-off (~1e-14 relative), proving the scaled
        // form is robust where the unscaled one overflows nothing but cancels everything.
        let n = 30;
        let nf = n as f64;
        let cf = beam_eigenvalue(BeamSupport::ClampedFree, n).unwrap();
        assert!(rel(cf, (2.0 * nf - 1.0) * FRAC_PI_2) < 1e-14);
        let ff = beam_eigenvalue(BeamSupport::FreeFree, n).unwrap();
        assert!(rel(ff, (2.0 * nf + 1.0) * FRAC_PI_2) < 1e-14);
        let pf = beam_eigenvalue(BeamSupport::PinnedFree, n).unwrap();
        assert!(rel(pf, (4.0 * nf + 1.0) * PI / 4.0) < 1e-14);
        // Low modes differ from the asymptote by the O(e^{-x}) term: clamped–free n = 1 is
        // noticeably above π/2 (1.875 vs 1.571).
        let cf1 = beam_eigenvalue(BeamSupport::ClampedFree, 1).unwrap();
        assert!(cf1 > 1.8 && cf1 < 1.9);
    }

    #[test]
    fn ana_beam_eigenvalues_are_increasing_and_interlace() {
        // Sturm–Liouville interlacing: clamped–free < clamped–pinned (adds a constraint) and
        // free–free roots equal clamped–clamped ones (same equation), which lie above
        // clamped–pinned ones.
        let cf = beam_eigenvalues(BeamSupport::ClampedFree, 8).unwrap();
        let cp = beam_eigenvalues(BeamSupport::ClampedPinned, 8).unwrap();
        let ff = beam_eigenvalues(BeamSupport::FreeFree, 8).unwrap();
        for k in 0..8 {
            assert!(cf[k] < cp[k] && cp[k] < ff[k]);
            if k > 0 {
                assert!(cf[k] > cf[k - 1]);
            }
        }
        assert!(beam_eigenvalue(BeamSupport::ClampedFree, 0).is_err());
    }

    #[test]
    fn ana_bending_frequency_of_scene_cantilever() {
        let scene = data::load_scene("cantilever").unwrap();
        let link = &scene.planar_chain().unwrap().links[0];
        let f = bending_frequencies_hz(
            BeamSupport::ClampedFree,
            link.bending_stiffness,
            link.mass_per_length,
            link.length,
            3,
        )
        .unwrap();
        let x1 = beam_eigenvalue(BeamSupport::ClampedFree, 1).unwrap();
        let expected =
            x1 * x1 / (2.0 * PI) * (link.bending_stiffness / link.mass_per_length).sqrt();
        // Same formula, same operations: exact up to the last bit or two.
        assert!(rel(f[0], expected) < 1e-15);
        // f₂/f₁ = (β₂/β₁)² ≈ 6.27: a property of the clamped–free spectrum.
        assert!((f[1] / f[0] - 6.267).abs() < 1e-3);
        assert!(bending_frequencies_hz(BeamSupport::ClampedFree, -1.0, 1.0, 1.0, 1).is_err());
    }

    #[test]
    fn ana_tip_mass_zero_recovers_clamped_free() {
        let r = cantilever_tip_mass_roots(0.0, 0.0, 6).unwrap();
        let cf = beam_eigenvalues(BeamSupport::ClampedFree, 6).unwrap();
        for (a, b) in r.iter().zip(&cf) {
            // Same equation, Brent to 1e-14: agreement ~1e-14.
            assert!(rel(*a, *b) < 1e-13, "{a} vs {b}");
        }
    }

    #[test]
    fn ana_tip_mass_roots_satisfy_unscaled_determinant() {
        // Check the closed form against the 2×2 boundary determinant built directly from the
        // mode-shape derivatives (independent of the algebraic simplification).
        for &(eta, j) in &[(1.0, 0.0), (1.0, 0.1), (5.0, 0.02), (0.2, 1.0)] {
            for x in cantilever_tip_mass_roots(eta, j, 4).unwrap() {
                let (s, c) = x.sin_cos();
                let (sh, ch) = (x.sinh(), x.cosh());
                let f1 = [ch - c, x * (sh + s), x * x * (ch + c), x.powi(3) * (sh - s)];
                let f2 = [sh - s, x * (ch - c), x * x * (sh + s), x.powi(3) * (ch + c)];
                let r1 = |f: &[f64; 4]| f[2] - j * x.powi(4) * f[1];
                let r2 = |f: &[f64; 4]| f[3] + eta * x.powi(4) * f[0];
                let det = r1(&f1) * r2(&f2) - r1(&f2) * r2(&f1);
                let scale = (r1(&f1) * r2(&f2)).abs() + (r1(&f2) * r2(&f1)).abs();
                // Products of size `scale` cancel; round-off ~ 1e-15·scale, allow 1e-12.
                assert!(
                    det.abs() < 1e-12 * scale,
                    "eta {eta} j {j} x {x}: {det} / {scale}"
                );
            }
        }
    }

    #[test]
    fn ana_tip_mass_large_mass_approaches_single_dof() {
        // Loose sanity check only: for M ≫ ρAL the first frequency tends to the Rayleigh
        // single-DOF value ω² = 3EI / ((M + 33/140 ρAL) L³) (33/140 ≈ 0.2357).
        for &eta in &[10.0, 100.0] {
            let x = cantilever_tip_mass_roots(eta, 0.0, 1).unwrap()[0];
            let omega2 = x.powi(4); // ω² ρA L⁴ / EI
            let rayleigh = 3.0 / (eta + 33.0 / 140.0);
            // Rayleigh's quotient with the static shape is an upper bound, accurate to ~1e-4
            // relative at η = 10.
            assert!(omega2 <= rayleigh * (1.0 + 1e-12));
            assert!(
                rel(omega2, rayleigh) < 1e-3,
                "eta {eta}: {omega2} vs {rayleigh}"
            );
        }
        // Monotone: more tip mass or inertia lowers every frequency (Rayleigh).
        let a = cantilever_tip_mass_roots(1.0, 0.0, 4).unwrap();
        let b = cantilever_tip_mass_roots(2.0, 0.0, 4).unwrap();
        let c = cantilever_tip_mass_roots(2.0, 0.05, 4).unwrap();
        for k in 0..4 {
            assert!(b[k] < a[k] && c[k] < b[k]);
        }
    }

    #[test]
    fn ana_tip_mass_scene_frequency() {
        let scene = data::load_scene("cantilever-tip-mass").unwrap();
        let link = &scene.planar_chain().unwrap().links[0];
        let f = cantilever_tip_mass_frequencies_hz(
            link.bending_stiffness,
            link.mass_per_length,
            link.length,
            link.tip_mass.unwrap_or(0.0),
            link.tip_inertia.unwrap_or(0.0),
            3,
        )
        .unwrap();
        let f0 = bending_frequencies_hz(
            BeamSupport::ClampedFree,
            link.bending_stiffness,
            link.mass_per_length,
            link.length,
            1,
        )
        .unwrap()[0];
        // Mass ratio 1: the first frequency drops to roughly half of the bare cantilever's.
        assert!(f[0] < 0.6 * f0 && f[0] > 0.3 * f0, "{} vs {f0}", f[0]);
    }

    #[test]
    fn ana_axial_frequencies() {
        let f = axial_frequencies_hz(2.1e7, 0.785, 1.0, 3).unwrap();
        let c = (2.1e7f64 / 0.785).sqrt();
        assert!(rel(f[0], c / 4.0) < 1e-15);
        assert!(rel(f[2], 5.0 * c / 4.0) < 1e-15);
        // A vanishing tip mass tends to the closed form: z − (n−½)π = O(η).
        let g = axial_tip_mass_frequencies_hz(2.1e7, 0.785, 1.0, 1e-12, 3).unwrap();
        for k in 0..3 {
            assert!(rel(g[k], f[k]) < 1e-11);
        }
        // Tip mass: z tan z = ρAL/M holds at the roots; large M → single-DOF sqrt(EA/(M L)).
        let m = 0.785 * 1.0;
        let h = axial_tip_mass_frequencies_hz(2.1e7, 0.785, 1.0, m, 3).unwrap();
        for fk in &h {
            let z = 2.0 * PI * fk / c;
            assert!((z * z.tan() - 1.0).abs() < 1e-11 * (1.0 + z.tan().abs() * z));
        }
        let big = 1e4 * m;
        let w = 2.0 * PI * axial_tip_mass_frequencies_hz(2.1e7, 0.785, 1.0, big, 1).unwrap()[0];
        let w_sdof2 = 2.1e7 / ((big + m / 3.0) * 1.0);
        // Rayleigh with the linear shape (mass M + ρAL/3): error O(η⁻²) ~ 1e-9 at η = 1e4.
        assert!(rel(w * w, w_sdof2) < 1e-6);
    }
}
