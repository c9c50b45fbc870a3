//! Convergence of whole histories over a refinement ladder (`history:` and
//! `lowpassF:history:` quantities with an `order` or `richardson` reference).
//!
//! A point value of an undamped flexible arm does not converge regularly: the elastic vibration
//! rings at every resolved frequency and the sign of the difference between rungs changes from
//! one output time to the next. The history as a whole (low-passed or raw) can still converge,
//! and that is what these checks measure. Rung k (size h_k, from `super::evaluate::ladder_rung_sizes`)
//! gives the samples H_k(t) on one common grid ([`super::history::common_samples`]).
//!
//! # Observed order
//! If H_k(t) = H(t) + C(t)·h_k^p, the successive differences
//!
//! ```text
//! d_k = max_t |H_k(t) − H_{k+1}(t)| = ‖C‖ · h_k^p · (1 − (h_{k+1}/h_k)^p)
//! ```
//!
//! fix p for any ladder, geometric or not: p minimizes the least-squares misfit of
//! log d_k − p log h_k − log(1 − ρ_k^p), ρ_k = h_{k+1}/h_k, around its mean (the constant log‖C‖
//! eliminated), found by a scan of p over [`P_RANGE`] refined by golden section. With two
//! differences (three rungs) the fit is exact. For a geometric ladder it is the least-squares
//! slope of log d_k against log h_k.
//!
//! # Richardson extrapolation of the history
//! With p from the ladder's differences, the last two rungs extrapolate pointwise,
//!
//! ```text
//! H_∞(t) = H_n(t) + (H_n(t) − H_{n−1}(t)) · h_n^p / (h_{n−1}^p − h_n^p),
//! ```
//!
//! and the case's own run is compared with H_∞ as max_t |H_case − H_∞| / max_t |H_∞|.

use super::order::fit_order;

/// Range of orders searched by [`difference_order`].
pub const P_RANGE: (f64, f64) = (0.05, 12.0);

/// max_t |a(t) − b(t)| of two sample vectors on one grid.
pub fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The successive differences d_k = max_t |H_k − H_{k+1}| of a ladder's histories.
pub fn successive_differences(histories: &[Vec<f64>]) -> Vec<f64> {
    histories
        .windows(2)
        .map(|w| max_abs_difference(&w[0], &w[1]))
        .collect()
}

/// Least-squares misfit of the model log d_k = c + p log h_k + log(1 − ρ_k^p), c eliminated.
fn misfit(h: &[f64], d: &[f64], p: f64) -> f64 {
    let r: Vec<f64> = d
        .iter()
        .enumerate()
        .map(|(k, dk)| {
            let rho = h[k + 1] / h[k];
            dk.ln() - p * h[k].ln() - (1.0 - rho.powf(p)).ln()
        })
        .collect();
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    r.iter().map(|x| (x - mean).powi(2)).sum()
}

/// Observed order p of a ladder from the successive differences `d` (d_k between rungs k and
/// k + 1) of rungs of sizes `h` (strictly decreasing); see the module docs. `None` when the
/// ladder is too short (fewer than two differences), a size does not decrease, or a difference
/// is zero or not finite.
pub fn difference_order(h: &[f64], d: &[f64]) -> Option<f64> {
    if d.len() < 2 || h.len() != d.len() + 1 {
        return None;
    }
    if h.windows(2).any(|w| !(w[1] < w[0] && w[1] > 0.0)) {
        return None;
    }
    if d.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return None;
    }
    let geometric = h
        .windows(2)
        .all(|w| ((w[1] / w[0]) / (h[1] / h[0]) - 1.0).abs() < 1e-12);
    if geometric {
        // The factor 1 − ρ^p is the same for every difference: a plain log-log slope.
        return fit_order(&h[..d.len()], d);
    }
    let (lo, hi) = P_RANGE;
    let steps = 2000;
    let at = |i: usize| lo + (hi - lo) * i as f64 / steps as f64;
    let best = (0..=steps)
        .min_by(|a, b| misfit(h, d, at(*a)).total_cmp(&misfit(h, d, at(*b))))
        .unwrap_or(0);
    // Golden section on the bracket around the best scanned point.
    let (mut a, mut b) = (at(best.saturating_sub(1)), at((best + 1).min(steps)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..100 {
        let (x1, x2) = (b - g * (b - a), a + g * (b - a));
        if misfit(h, d, x1) <= misfit(h, d, x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    Some(0.5 * (a + b))
}

/// The pointwise Richardson extrapolation of a ladder's histories (see the module docs) and the
/// order used, or `None` when no order can be observed.
pub fn extrapolated_history(h: &[f64], histories: &[Vec<f64>]) -> Option<(Vec<f64>, f64)> {
    let n = histories.len();
    if n < 3 || h.len() != n {
        return None;
    }
    let p = difference_order(h, &successive_differences(histories))?;
    let (fine, coarse) = (&histories[n - 1], &histories[n - 2]);
    let factor = h[n - 1].powf(p) / (h[n - 2].powf(p) - h[n - 1].powf(p));
    let ext = fine
        .iter()
        .zip(coarse)
        .map(|(f, c)| f + (f - c) * factor)
        .collect();
    Some((ext, p))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// H_k(t) = sin t + h_k^p (cos 3t + 0.2): an exact power-law ladder.
    fn ladder(h: &[f64], p: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
        let t: Vec<f64> = (0..500).map(|i| i as f64 * 0.02).collect();
        let limit: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let rungs = h
            .iter()
            .map(|hk| {
                t.iter()
                    .zip(&limit)
                    .map(|(t, l)| l + hk.powf(p) * ((3.0 * t).cos() + 0.2))
                    .collect()
            })
            .collect();
        (limit, rungs)
    }

    #[test]
    fn elem_history_order_of_a_geometric_ladder() {
        let h = [1.0 / 4.0, 1.0 / 8.0, 1.0 / 16.0, 1.0 / 32.0];
        for p in [1.0, 2.0, 4.0] {
            let (_, rungs) = ladder(&h, p);
            let d = successive_differences(&rungs);
            let observed = difference_order(&h, &d).unwrap();
            assert!((observed - p).abs() < 1e-9, "p = {p}: observed {observed}");
        }
    }

    #[test]
    fn elem_history_order_of_an_uneven_ladder() {
        // Mode counts 4, 6, 8, 12: ratios 1.5, 1.33, 1.5; a plain log-log slope of the
        // differences would be biased, the model fit is not.
        let h = [1.0 / 4.0, 1.0 / 6.0, 1.0 / 8.0, 1.0 / 12.0];
        for p in [1.5, 2.0, 3.0] {
            let (_, rungs) = ladder(&h, p);
            let d = successive_differences(&rungs);
            let observed = difference_order(&h, &d).unwrap();
            assert!((observed - p).abs() < 1e-6, "p = {p}: observed {observed}");
            let naive = fit_order(&h[..3], &d).unwrap();
            assert!((naive - p).abs() > 1e-3, "the naive slope is biased here");
        }
    }

    #[test]
    fn elem_history_richardson_recovers_the_limit() {
        for h in [
            vec![0.01, 0.005, 0.0025],
            vec![1.0 / 4.0, 1.0 / 6.0, 1.0 / 8.0],
        ] {
            let (limit, rungs) = ladder(&h, 2.0);
            let (ext, p) = extrapolated_history(&h, &rungs).unwrap();
            assert!((p - 2.0).abs() < 1e-6, "order {p}");
            let err = max_abs_difference(&ext, &limit);
            assert!(err < 1e-9, "extrapolation error {err:.3e}");
            // The finest rung itself is h_n^p · max|C| away from the limit.
            assert!(max_abs_difference(&rungs[2], &limit) > 5e-6);
        }
    }

    #[test]
    fn elem_history_ladder_refuses_what_it_cannot_fit() {
        let h = [0.1, 0.05, 0.025];
        assert_eq!(difference_order(&h[..2], &[1e-3]), None, "one difference");
        assert_eq!(difference_order(&h, &[1e-3, 0.0]), None, "zero difference");
        assert_eq!(
            difference_order(&[0.1, 0.2, 0.05], &[1e-3, 1e-4]),
            None,
            "sizes not decreasing"
        );
        let flat = vec![vec![1.0; 10]; 3];
        assert_eq!(extrapolated_history(&h, &flat), None);
    }
}
