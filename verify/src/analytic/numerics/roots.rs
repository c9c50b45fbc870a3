//! Brent's method (Brent 1973, "Algorithms for Minimization without Derivatives", ch. 4; the
//! `zeroin` algorithm): inverse quadratic interpolation and secant steps, safeguarded by
//! bisection so that the bracket always shrinks, plus a scanner that brackets the first `n` sign
//! changes of a function on a grid.
//!
//! Accuracy: the bracket is shrunk until its half-width is below
//! `2 ε |x| + ½ (abs_tol + rel_tol |x|)`; with the default `rel_tol = 1e-14` every root is
//! located to better than 1e-12 relative, as the project conventions require.

use crate::analytic::error::{AnalyticError, Result};

/// Stopping rule of [`brent`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootOptions {
    /// Relative tolerance on the root.
    pub rel_tol: f64,
    /// Absolute tolerance on the root (for roots at or near zero).
    pub abs_tol: f64,
    /// Iteration budget (Brent needs at most ~ (log2 of the bracket / tolerance)² iterations).
    pub max_iter: usize,
}

impl Default for RootOptions {
    fn default() -> Self {
        RootOptions {
            rel_tol: 1e-14,
            abs_tol: 0.0,
            max_iter: 300,
        }
    }
}

fn checked(what: &'static str, x: f64, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(AnalyticError::NonFinite { what, x, value: v })
    }
}

/// Root of `f` in `[a, b]`, where `f(a)` and `f(b)` must not have the same sign.
pub fn brent<F: FnMut(f64) -> f64>(mut f: F, a: f64, b: f64, opts: RootOptions) -> Result<f64> {
    const WHAT: &str = "function in root finder";
    let (mut a, mut b) = (a, b);
    let mut fa = checked(WHAT, a, f(a))?;
    let mut fb = checked(WHAT, b, f(b))?;
    if fa == 0.0 {
        return Ok(a);
    }
    if fb == 0.0 {
        return Ok(b);
    }
    if (fa > 0.0) == (fb > 0.0) {
        return Err(AnalyticError::NotBracketed { a, b, fa, fb });
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..opts.max_iter {
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * (opts.abs_tol + opts.rel_tol * b.abs());
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return Ok(b);
        }
        if e.abs() < tol || fa.abs() <= fb.abs() {
            d = m;
            e = m;
        } else {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                // secant step
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                // inverse quadratic interpolation
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = checked(WHAT, b, f(b))?;
    }
    Err(AnalyticError::NoConvergence {
        what: "Brent root finder",
        iterations: opts.max_iter,
    })
}

/// The first `n` roots of `f` in `(start, limit]`, bracketed by sign changes on a grid of spacing
/// `step` and refined by [`brent`]. A root that falls exactly on a grid point is kept once.
///
/// The grid must be fine enough that no two roots share a grid cell; callers choose `step` from
/// the known minimum root spacing of their equation and document why.
pub fn first_roots<F: FnMut(f64) -> f64>(
    mut f: F,
    start: f64,
    step: f64,
    limit: f64,
    n: usize,
    what: &'static str,
    opts: RootOptions,
) -> Result<Vec<f64>> {
    let mut roots = Vec::with_capacity(n);
    if n == 0 {
        return Ok(roots);
    }
    let mut x0 = start;
    let mut f0 = checked(what, x0, f(x0))?;
    while x0 < limit {
        let x1 = (x0 + step).min(limit);
        let f1 = checked(what, x1, f(x1))?;
        if f1 == 0.0 {
            roots.push(x1);
            if roots.len() == n {
                return Ok(roots);
            }
            // Continue just past the exact root so that it is not bracketed twice.
            x0 = x1 + 1e-6 * step;
            f0 = checked(what, x0, f(x0))?;
            continue;
        }
        if f0 != 0.0 && (f0 > 0.0) != (f1 > 0.0) {
            roots.push(brent(&mut f, x0, x1, opts)?);
            if roots.len() == n {
                return Ok(roots);
            }
        }
        x0 = x1;
        f0 = f1;
    }
    Err(AnalyticError::TooFewRoots {
        what,
        found: roots.len(),
        wanted: n,
        limit,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ana_brent_finds_cos_root_to_round_off() {
        let r = brent(f64::cos, 1.0, 2.0, RootOptions::default()).unwrap();
        // Brent stops at 2ε|x| + 0.5e-14|x|: the root is good to ~1e-14 relative.
        assert!((r - std::f64::consts::FRAC_PI_2).abs() < 1e-14 * r);
    }

    #[test]
    fn ana_brent_handles_multiple_root_of_odd_order() {
        // (x - 1)^3 has a triple root: bisection fallback must still converge.
        let r = brent(|x| (x - 1.0).powi(3), 0.0, 3.0, RootOptions::default()).unwrap();
        // A triple root is determined only to cbrt(ε) in x by the function values; the bracket
        // still shrinks to the tolerance, so the error is bounded by ~1e-5 here.
        assert!((r - 1.0).abs() < 1e-5, "r = {r}");
    }

    #[test]
    fn ana_brent_rejects_unbracketed_interval() {
        let e = brent(|x| x * x + 1.0, -1.0, 1.0, RootOptions::default()).unwrap_err();
        assert!(matches!(e, AnalyticError::NotBracketed { .. }));
    }

    #[test]
    fn ana_brent_rejects_nan() {
        let e = brent(|_| f64::NAN, 0.0, 1.0, RootOptions::default()).unwrap_err();
        assert!(matches!(e, AnalyticError::NonFinite { .. }));
    }

    #[test]
    fn ana_first_roots_of_sine() {
        let r = first_roots(f64::sin, 0.5, 0.1, 20.0, 5, "sin", RootOptions::default()).unwrap();
        for (k, x) in r.iter().enumerate() {
            let exact = (k + 1) as f64 * std::f64::consts::PI;
            // ~1e-14 relative from the Brent tolerance.
            assert!((x - exact).abs() < 1e-13 * exact, "{x} vs {exact}");
        }
        let e = first_roots(f64::sin, 0.5, 0.1, 7.0, 5, "sin", RootOptions::default());
        assert!(matches!(
            e,
            Err(AnalyticError::TooFewRoots { found: 2, .. })
        ));
    }
}
