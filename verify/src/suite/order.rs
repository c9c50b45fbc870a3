//! Observed orders and Richardson extrapolation of refinement ladders.
//!
//! A ladder is a sequence of rung sizes h_k (step, element length, station spacing, 1/modes)
//! and the values or errors measured on each. The error model is e(h) ≈ C·h^p.

/// Least-squares slope of log|e| against log h.
pub fn fit_order(h: &[f64], e: &[f64]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = h
        .iter()
        .zip(e)
        .filter(|(h, e)| **h > 0.0 && e.abs() > 0.0 && e.is_finite())
        .map(|(h, e)| (h.ln(), e.abs().ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Number of leading rungs whose error keeps falling. Beyond it the ladder has reached the
/// round-off plateau (beam stiffness conditioning grows like (L/h)⁴) and those rungs would
/// bias the order fit.
pub fn falling_prefix(errors: &[f64]) -> usize {
    let mut n = errors.len().min(1);
    while n < errors.len() && errors[n].abs() < errors[n - 1].abs() {
        n += 1;
    }
    n
}

/// Richardson extrapolation from the last three rungs (observed order), or the last two with
/// the given order. Returns (extrapolated value, order used).
pub fn richardson(h: &[f64], q: &[f64], assumed_order: Option<f64>) -> Option<(f64, f64)> {
    let n = q.len();
    if n < 2 {
        return None;
    }
    let (h1, h2) = (h[n - 2], h[n - 1]);
    let r = h1 / h2;
    let p = if n >= 3 && assumed_order.is_none() {
        let (d1, d2) = (q[n - 2] - q[n - 3], q[n - 1] - q[n - 2]);
        if d1 == 0.0 || d2 == 0.0 || (d1 / d2) <= 0.0 {
            return None;
        }
        let r0 = h[n - 3] / h1;
        // Equal ratios assumed for the order estimate; ladders here are geometric.
        ((d1 / d2).ln() / r0.ln()).max(0.1)
    } else {
        assumed_order?
    };
    Some((q[n - 1] + (q[n - 1] - q[n - 2]) / (r.powf(p) - 1.0), p))
}
