//! Clamped–free Timoshenko beam frequencies (shear deformation and rotary inertia).
//!
//! Equations (Timoshenko 1921; frequency equation as in Huang 1961, J. Appl. Mech. 28, and
//! Han, Benaroya & Wei 1999, J. Sound Vib. 225): deflection v(x,t), section rotation ψ(x,t),
//!
//! ```text
//! ρA v̈ = κGA (v'' − ψ')
//! ρI ψ̈ = EI ψ'' + κGA (v' − ψ)
//! ```
//!
//! clamped at x = 0 (v = ψ = 0), free at x = L (moment EI ψ' = 0, shear κGA(v' − ψ) = 0).
//! With harmonic motion at ω and e^{kx} dependence the wavenumbers satisfy, for p = k²,
//!
//! `κGA·EI p² + ω²(κGA ρI + ρA EI) p + ρAω²(ρIω² − κGA) = 0`,
//!
//! one root p₂ < 0 always (oscillatory, cos/sin), the other p₁ > 0 below the cut-off
//! ω_c = sqrt(κGA/ρI) (cosh/sinh) and p₁ < 0 above it (a second oscillatory branch). Both
//! branches are handled by one basis that is analytic in p (so nothing is singular at the
//! cut-off):
//!
//! `C(p,x) = cosh(√p x)` (= cos(√−p x)), `S(p,x) = sinh(√p x)/√p` (= sin(√−p x)/√−p),
//!
//! with the two solutions per root: (v, ψ) = (C, (p+s) S) and (p S/(p+s), C), s = ρAω²/κGA
//! (the first field equation gives ψ' = v'' + s v; p + s ≠ 0 for ω > 0). When √p₁·L > 1 the
//! hyperbolic pair is replaced by the decaying/growing pair e^{−√p x}, e^{−√p(L−x)} (bounded on
//! \[0, L\]) and the 4×4 boundary determinant is divided by the exact change-of-basis determinant
//! 2r e^{−√p L} (r = (p+s)/√p); the function is then the same analytic function, continuous in ω,
//! without the e^{2√p L} cancellation of cosh² − sinh². Lengths are scaled by L inside.
//!
//! Units: consistent; κGA \[force\], EI \[force·length²\], ρA \[mass/length\], ρI \[mass·length\],
//! L \[length\] → Hz.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::analytic::beam::{BeamSupport, beam_eigenvalue};
use crate::analytic::error::{Result, non_negative, positive};
use crate::analytic::numerics::roots::{RootOptions, first_roots};

/// Section and length of a uniform Timoshenko beam.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TimoshenkoBeam {
    /// Shear stiffness κGA.
    pub kappa_ga: f64,
    /// Bending stiffness EI.
    pub ei: f64,
    /// Mass per length ρA.
    pub rho_a: f64,
    /// Rotary inertia per length ρI.
    pub rho_i: f64,
    /// Length L.
    pub length: f64,
}

impl TimoshenkoBeam {
    fn validate(&self) -> Result<()> {
        positive("kappa G A", self.kappa_ga)?;
        positive("EI", self.ei)?;
        positive("rho A", self.rho_a)?;
        non_negative("rho I", self.rho_i)?;
        positive("L", self.length)?;
        Ok(())
    }

    /// Cut-off circular frequency ω_c = sqrt(κGA/ρI) \[rad/time\] (∞ without rotary inertia).
    pub fn cutoff_rad_s(&self) -> f64 {
        if self.rho_i > 0.0 {
            (self.kappa_ga / self.rho_i).sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// From a planar scene link with `shear` on (needs `shear_stiffness`); ρI is taken from
    /// `rotary_inertia_per_length` when `rotary_inertia` is on and is 0 otherwise (shear-only
    /// beam: no cut-off, p₁ > 0 at every frequency).
    pub fn from_link(link: &data::scene::Link) -> Result<Self> {
        let missing = |what: &str| {
            crate::analytic::error::AnalyticError::Unsupported(format!(
                "Timoshenko reference needs `{what}` on link `{}`",
                link.name
            ))
        };
        let b = TimoshenkoBeam {
            kappa_ga: link
                .shear_stiffness
                .ok_or_else(|| missing("shear_stiffness"))?,
            ei: link.bending_stiffness,
            rho_a: link.mass_per_length,
            rho_i: if link.rotary_inertia {
                link.rotary_inertia_per_length
                    .ok_or_else(|| missing("rotary_inertia_per_length"))?
            } else {
                0.0
            },
            length: link.length,
        };
        b.validate()?;
        Ok(b)
    }
}

/// Values at ξ of the two solution columns for one wavenumber root p (nondimensional):
/// returns \[v, v', ψ, ψ'\] for each column.
fn analytic_pair(p: f64, s: f64, xi: f64) -> [[f64; 4]; 2] {
    // C = cosh(√p ξ), S = sinh(√p ξ)/√p, continued analytically to p ≤ 0.
    let (c, sn) = if p > 0.0 {
        let a = p.sqrt();
        ((a * xi).cosh(), (a * xi).sinh() / a)
    } else if p < 0.0 {
        let b = (-p).sqrt();
        ((b * xi).cos(), (b * xi).sin() / b)
    } else {
        (1.0, xi)
    };
    let ps = p + s;
    // column 1: v = C, v' = pS, ψ = (p+s)S, ψ' = (p+s)C
    // column 2: v = pS/(p+s), v' = pC/(p+s), ψ = C, ψ' = pS
    [
        [c, p * sn, ps * sn, ps * c],
        [p * sn / ps, p * c / ps, c, p * sn],
    ]
}

/// Exponential pair for p > 0 with √p > 1: columns e^{−αξ} and e^{−α(1−ξ)} (with their ψ),
/// as \[v, v', ψ, ψ'\].
fn exponential_pair(p: f64, s: f64, xi: f64) -> [[f64; 4]; 2] {
    let a = p.sqrt();
    let r = (p + s) / a;
    let em = (-a * xi).exp();
    let ep = (-a * (1.0 - xi)).exp();
    [
        [em, -a * em, -r * em, r * a * em],
        [ep, a * ep, r * ep, r * a * ep],
    ]
}

fn det4(mut m: [[f64; 4]; 4]) -> f64 {
    // LU with partial pivoting.
    let mut det = 1.0;
    for col in 0..4 {
        let piv = (col..4)
            .max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))
            .unwrap_or(col);
        if m[piv][col] == 0.0 {
            return 0.0;
        }
        if piv != col {
            m.swap(piv, col);
            det = -det;
        }
        det *= m[col][col];
        let pivot_row = m[col];
        for row in m.iter_mut().skip(col + 1) {
            let f = row[col] / pivot_row[col];
            for (x, p) in row.iter_mut().zip(pivot_row.iter()).skip(col) {
                *x -= f * p;
            }
        }
    }
    det
}

/// Nondimensional parameters: (p₁, p₂, s) at circular frequency ω, lengths scaled by L.
fn wavenumbers(beam: &TimoshenkoBeam, omega: f64) -> (f64, f64, f64) {
    let l2 = beam.length * beam.length;
    let w2 = omega * omega;
    let a = beam.kappa_ga * beam.ei;
    let b = w2 * (beam.kappa_ga * beam.rho_i + beam.rho_a * beam.ei);
    let c = beam.rho_a * w2 * (beam.rho_i * w2 - beam.kappa_ga);
    let disc = (b * b - 4.0 * a * c).max(0.0);
    // Stable quadratic roots (b > 0): q = −(b + √disc)/2; p₂ = q/a < 0, p₁ = c/q.
    let q = -0.5 * (b + disc.sqrt());
    let p2 = q / a;
    let p1 = if q != 0.0 { c / q } else { 0.0 };
    let s = beam.rho_a * w2 / beam.kappa_ga;
    (p1 * l2, p2 * l2, s * l2)
}

/// The scaled clamped–free frequency determinant at circular frequency ω (zero at the natural
/// frequencies; continuous in ω across the cut-off).
pub fn timoshenko_frequency_function(beam: &TimoshenkoBeam, omega: f64) -> f64 {
    let (p1, p2, s) = wavenumbers(beam, omega);
    let use_exp = p1 > 1.0;
    let pair1 = |xi: f64| {
        if use_exp {
            exponential_pair(p1, s, xi)
        } else {
            analytic_pair(p1, s, xi)
        }
    };
    let cols0 = [pair1(0.0), analytic_pair(p2, s, 0.0)];
    let cols1 = [pair1(1.0), analytic_pair(p2, s, 1.0)];
    let mut m = [[0.0; 4]; 4];
    for (j, (c0, c1)) in cols0
        .iter()
        .flatten()
        .zip(cols1.iter().flatten())
        .enumerate()
    {
        m[0][j] = c0[0]; // v(0) = 0
        m[1][j] = c0[2]; // ψ(0) = 0
        m[2][j] = c1[3]; // ψ'(L) = 0 (moment)
        m[3][j] = c1[1] - c1[2]; // v'(L) − ψ(L) = 0 (shear)
    }
    let d = det4(m);
    if use_exp {
        let a = p1.sqrt();
        d / (2.0 * (p1 + s) / a)
    } else {
        d * (-p1.max(0.0).sqrt()).exp()
    }
}

/// The first `n` natural frequencies \[Hz\] of a clamped–free Timoshenko beam.
///
/// Scan variable x = (ω² ρA L⁴/EI)^{1/4} (the Euler–Bernoulli βL): Timoshenko frequencies lie
/// below the Euler–Bernoulli ones, and in x the roots of either branch are separated by
/// O(1); a grid of 0.01 in x resolves them (the test against ODE shooting above the cut-off
/// confirms no root is skipped there).
pub fn timoshenko_clamped_free_hz(beam: &TimoshenkoBeam, n: usize) -> Result<Vec<f64>> {
    beam.validate()?;
    let l = beam.length;
    let omega_of = |x: f64| x * x / (l * l) * (beam.ei / beam.rho_a).sqrt();
    let x_eb = beam_eigenvalue(BeamSupport::ClampedFree, n)?;
    let roots = first_roots(
        |x| timoshenko_frequency_function(beam, omega_of(x)),
        0.5,
        0.01,
        x_eb + 2.0,
        n,
        "Timoshenko clamped-free",
        RootOptions::default(),
    )?;
    Ok(roots
        .into_iter()
        .map(|x| omega_of(x) / (2.0 * PI))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::beam::bending_frequencies_hz;
    use crate::analytic::numerics::ode::Dopri5;
    use crate::analytic::numerics::roots::brent;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// Independent check: shoot the first-order system (v, v', ψ, ψ') from the clamped end
    /// with the two unit initial slopes and return the free-end 2×2 determinant.
    fn shooting_determinant(beam: &TimoshenkoBeam, omega: f64) -> f64 {
        let (kga, ei, ra, ri) = (beam.kappa_ga, beam.ei, beam.rho_a, beam.rho_i);
        let w2 = omega * omega;
        let mut f = |_x: f64, y: &[f64], d: &mut [f64]| {
            for k in 0..2 {
                let (v, dv, psi, dpsi) = (y[4 * k], y[4 * k + 1], y[4 * k + 2], y[4 * k + 3]);
                d[4 * k] = dv;
                d[4 * k + 1] = dpsi - ra * w2 / kga * v;
                d[4 * k + 2] = dpsi;
                d[4 * k + 3] = -(kga * (dv - psi) + ri * w2 * psi) / ei;
            }
        };
        let mut y = [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0 / beam.length];
        let mut t = 0.0;
        let mut ode = Dopri5::new(8, 1e-13, 1e-16);
        ode.advance(&mut f, &mut t, &mut y, beam.length).unwrap();
        let shear = |k: usize| y[4 * k + 1] - y[4 * k + 2];
        let moment = |k: usize| y[4 * k + 3] * beam.length;
        moment(0) * shear(1) - moment(1) * shear(0)
    }

    fn scene_beam() -> TimoshenkoBeam {
        let scene = data::load_scene("cantilever-timoshenko").unwrap();
        TimoshenkoBeam::from_link(&scene.planar_chain().unwrap().links[0]).unwrap()
    }

    #[test]
    fn ana_timoshenko_slender_limit_is_euler_bernoulli() {
        // Scene section (10 mm square steel) on a 10 m beam: slenderness L/r ≈ 3500, so the
        // shear/rotary corrections are O((r/L)²·(βL)²) ≈ 1e-7·(βL)²; mode 4 (βL ≈ 11) ⇒ < 3e-5.
        let mut b = scene_beam();
        b.length = 10.0;
        let t = timoshenko_clamped_free_hz(&b, 4).unwrap();
        let e =
            bending_frequencies_hz(BeamSupport::ClampedFree, b.ei, b.rho_a, b.length, 4).unwrap();
        for k in 0..4 {
            assert!(t[k] < e[k], "Timoshenko must be below Euler-Bernoulli");
            assert!(
                rel(t[k], e[k]) < 3e-5,
                "mode {}: {} vs {}",
                k + 1,
                t[k],
                e[k]
            );
        }
        // and the correction shrinks as slenderness grows (quadratically in r/L).
        b.length = 100.0;
        let t100 = timoshenko_clamped_free_hz(&b, 1).unwrap()[0];
        let e100 =
            bending_frequencies_hz(BeamSupport::ClampedFree, b.ei, b.rho_a, 100.0, 1).unwrap()[0];
        let d10 = rel(t[0], e[0]);
        let d100 = rel(t100, e100);
        // (10/100)² = 1e-2; allow [0.5e-2, 2e-2] for the higher-order terms and round-off.
        assert!(d100 / d10 > 0.5e-2 && d100 / d10 < 2e-2, "{d10:e} {d100:e}");
    }

    #[test]
    fn ana_timoshenko_scene_matches_ode_shooting() {
        let b = scene_beam();
        let f = timoshenko_clamped_free_hz(&b, 5).unwrap();
        let e =
            bending_frequencies_hz(BeamSupport::ClampedFree, b.ei, b.rho_a, b.length, 5).unwrap();
        for k in 0..5 {
            // Shear lowers every frequency; stocky L/r = 35: the effect grows with mode number.
            assert!(f[k] < e[k]);
            if k > 0 {
                assert!(f[k] / e[k] < f[k - 1] / e[k - 1]);
            }
            // Independent root of the shot determinant, bracketed ±0.1 % around the closed form.
            let w = 2.0 * PI * f[k];
            let ws = brent(
                |om| shooting_determinant(&b, om),
                0.999 * w,
                1.001 * w,
                RootOptions::default(),
            )
            .unwrap();
            // Shooting at rtol 1e-13 over a stocky beam (growth e^{√p L} ≤ e^4) gives ≤ 1e-10.
            assert!(rel(ws, w) < 1e-10, "mode {}: {ws} vs {w}", k + 1);
        }
        // First mode of the stocky beam sits a few percent below Euler–Bernoulli.
        assert!(f[0] / e[0] > 0.95 && f[0] / e[0] < 0.999);
    }

    #[test]
    fn ana_timoshenko_shear_only_matches_shooting() {
        // ρI = 0 (shear deformation without rotary inertia): no cut-off; still below
        // Euler–Bernoulli and equal to the shot determinant's roots.
        let mut b = scene_beam();
        b.rho_i = 0.0;
        assert!(b.cutoff_rad_s().is_infinite());
        let f = timoshenko_clamped_free_hz(&b, 4).unwrap();
        let full = timoshenko_clamped_free_hz(&scene_beam(), 4).unwrap();
        for k in 0..4 {
            // Rotary inertia adds kinetic energy only: removing it raises every frequency.
            assert!(f[k] > full[k]);
            let w = 2.0 * PI * f[k];
            let ws = brent(
                |om| shooting_determinant(&b, om),
                0.999 * w,
                1.001 * w,
                RootOptions::default(),
            )
            .unwrap();
            // Same tolerance reasoning as for the full Timoshenko beam.
            assert!(rel(ws, w) < 1e-10, "{ws} vs {w}");
        }
    }

    #[test]
    fn ana_timoshenko_above_cutoff_matches_shooting() {
        // A very stocky beam (L = 0.02 m, L/r ≈ 7) so that the cut-off lies among the first
        // modes: both branches are exercised and the determinant must be continuous there.
        let mut b = scene_beam();
        b.length = 0.02;
        let wc = b.cutoff_rad_s();
        let f = timoshenko_clamped_free_hz(&b, 6).unwrap();
        let above = f.iter().filter(|&&fk| 2.0 * PI * fk > wc).count();
        assert!(above >= 1, "no mode above the cut-off: {f:?}, wc = {wc}");
        for fk in &f {
            let w = 2.0 * PI * fk;
            let ws = brent(
                |om| shooting_determinant(&b, om),
                0.999 * w,
                1.001 * w,
                RootOptions::default(),
            )
            .unwrap();
            // Same tolerance reasoning as above.
            assert!(rel(ws, w) < 1e-10, "{ws} vs {w} (wc {wc})");
        }
        // No sign change is produced by the basis itself at the cut-off: evaluating at ω_c
        // gives a finite, non-zero value unless ω_c happens to be a root.
        let v = timoshenko_frequency_function(&b, wc);
        assert!(v.is_finite());
    }
}
