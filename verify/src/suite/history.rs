//! Whole-history comparison of two runs (`history:` and `lowpassF:history:` quantities).
//!
//! A history is an observable channel (`data::channel`) or an energy-ledger term addressed as
//! `energy.NAME` (a stored, input or dissipation term of `data::EnergyLedger`, e.g.
//! `energy.kinetic`, `energy.strain`, `energy.joint_damper`; `energy.total` is the sum of the
//! stored terms, and `energy.A+B` the sum of the named terms — e.g. `energy.impact+kelvin_voigt`,
//! the dissipation split between a plastic impact and the beam's damping, whose parts depend on
//! the resolution of the impact while their sum converges). The error of run `a` against run `b` is
//!
//! ```text
//! max_t |a(t) − b(t)| / max_t |b(t)|
//! ```
//!
//! over the output times of `a` (b linearly interpolated; an analytic reference history is
//! evaluated at those times). With a low-pass cut-off f_c both
//! histories are first interpolated onto one uniform grid of as many samples as `a` has over
//! a's span, then filtered by the zero-phase Butterworth of [`super::filter`], and compared on
//! that grid without one cut-off period at each end ([`super::filter::interior`]: the filtered
//! ends pass through the raw end samples).

use std::borrow::Cow;

use data::RunResult;
use data::cases::ENERGY_PREFIX;

use super::filter::{interior, lowpass_zero_phase, resample_uniform};

/// (times, values) of a channel or ledger term of a run.
pub fn series<'a>(r: &'a RunResult, channel: &str) -> Option<(&'a [f64], Cow<'a, [f64]>)> {
    if let Some(term) = channel.strip_prefix(ENERGY_PREFIX) {
        let l = &r.ledger;
        if term == "total" {
            let total: Vec<f64> = (0..l.time.len()).map(|k| l.total(k)).collect();
            return Some((&l.time, Cow::Owned(total)));
        }
        let find = |name: &str| {
            l.stored
                .iter()
                .chain(&l.inputs)
                .chain(&l.dissipation)
                .find(|t| t.name == name)
        };
        if term.contains('+') {
            let mut sum = vec![0.0; l.time.len()];
            for name in term.split('+') {
                for (s, v) in sum.iter_mut().zip(&find(name)?.values) {
                    *s += v;
                }
            }
            return Some((&l.time, Cow::Owned(sum)));
        }
        return find(term).map(|t| (l.time.as_slice(), Cow::Borrowed(t.values.as_slice())));
    }
    r.observables.get(channel).map(|c| {
        (
            r.observables.time.as_slice(),
            Cow::Borrowed(c.values.as_slice()),
        )
    })
}

/// Largest deviation of `a` from `b` and the peak |b| over the compared samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistoryDeviation {
    pub max_abs_diff: f64,
    pub reference_peak: f64,
}

/// Compares the histories of `channel` in two runs (see the module docs).
pub fn compare(
    a: &RunResult,
    b: &RunResult,
    channel: &str,
    lowpass_hz: Option<f64>,
) -> Result<HistoryDeviation, String> {
    let (ta, va) = series(a, channel).ok_or_else(|| format!("no channel `{channel}`"))?;
    let (tb, vb) = series(b, channel).ok_or_else(|| format!("no channel `{channel}`"))?;
    compare_series(ta, &va, tb, &vb, lowpass_hz)
}

/// The history of `channel` in run `a` against a reference function of time (an analytic
/// history), evaluated at a's output times.
pub fn compare_to_function(
    a: &RunResult,
    channel: &str,
    lowpass_hz: Option<f64>,
    reference: impl Fn(&[f64]) -> Result<Vec<f64>, String>,
) -> Result<HistoryDeviation, String> {
    let (ta, va) = series(a, channel).ok_or_else(|| format!("no channel `{channel}`"))?;
    let vb = reference(ta)?;
    compare_series(ta, &va, ta, &vb, lowpass_hz)
}

/// `max |a − b|` and the peak |b| of two sampled histories (module docs).
fn compare_series(
    ta: &[f64],
    va: &[f64],
    tb: &[f64],
    vb: &[f64],
    lowpass_hz: Option<f64>,
) -> Result<HistoryDeviation, String> {
    let Some(fc) = lowpass_hz else {
        let mut worst = 0.0f64;
        for (t, x) in ta.iter().zip(va.iter()) {
            if let Some(y) = data::results::interpolate(tb, vb, *t) {
                worst = worst.max((x - y).abs());
            }
        }
        return Ok(HistoryDeviation {
            max_abs_diff: worst,
            reference_peak: vb.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        });
    };
    // Common span: the filter needs both histories on one uniform grid.
    let t0 = ta[0].max(tb[0]);
    let t1 = ta[ta.len() - 1].min(tb[tb.len() - 1]);
    if t1 <= t0 {
        return Err("the two histories do not overlap in time".into());
    }
    let inside = ta.iter().filter(|t| **t >= t0 && **t <= t1).count().max(3);
    let on_grid = |t: &[f64], v: &[f64]| -> Result<(Vec<f64>, std::ops::Range<usize>), String> {
        let (ts, vs): (Vec<f64>, Vec<f64>) = span_points(t, v, t0, t1).into_iter().unzip();
        let (dt, _, uniform) = resample_uniform(&ts, &vs, inside).map_err(|e| e.to_string())?;
        low_passed(&uniform, dt, fc)
    };
    let (fa, keep) = on_grid(ta, va)?;
    let (fb, _) = on_grid(tb, vb)?;
    let max_abs_diff = fa[keep.clone()]
        .iter()
        .zip(&fb[keep])
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    // The scale is the whole filtered reference: its ends are values of the history too.
    let reference_peak = fb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    Ok(HistoryDeviation {
        max_abs_diff,
        reference_peak,
    })
}

/// The histories of `channel` in several runs (a refinement ladder) on one grid: `n` equal
/// steps over the span all runs cover, `n` the number of the first run's samples inside it, each
/// history linearly interpolated onto the grid and, with a cut-off, low-passed there as in
/// [`compare`]. Runs that write the same output times (a ladder of one backend) are sampled at
/// those times.
pub fn common_samples(
    runs: &[&RunResult],
    channel: &str,
    lowpass_hz: Option<f64>,
) -> Result<Vec<Vec<f64>>, String> {
    let all: Vec<_> = runs
        .iter()
        .map(|r| series(r, channel).ok_or_else(|| format!("no channel `{channel}`")))
        .collect::<Result<_, _>>()?;
    let (Some((first_t, _)), true) = (all.first(), all.iter().all(|(t, _)| !t.is_empty())) else {
        return Err("no history to compare".into());
    };
    let t0 = all.iter().map(|(t, _)| t[0]).fold(f64::MIN, f64::max);
    let t1 = all
        .iter()
        .map(|(t, _)| t[t.len() - 1])
        .fold(f64::MAX, f64::min);
    if t1 <= t0 {
        return Err("the histories do not overlap in time".into());
    }
    let inside = first_t
        .iter()
        .filter(|t| **t >= t0 && **t <= t1)
        .count()
        .max(3);
    all.iter()
        .map(|(t, v)| {
            let (pts_t, pts_v): (Vec<f64>, Vec<f64>) =
                span_points(t, v, t0, t1).into_iter().unzip();
            let (dt, _, uniform) =
                resample_uniform(&pts_t, &pts_v, inside).map_err(|e| e.to_string())?;
            match lowpass_hz {
                Some(fc) => low_passed(&uniform, dt, fc).map(|(f, keep)| f[keep].to_vec()),
                None => Ok(uniform),
            }
        })
        .collect()
}

/// Uniform samples low-passed at `fc`, and the range of them that comparisons use (all but
/// the ends, [`interior`]).
fn low_passed(
    uniform: &[f64],
    dt: f64,
    fc: f64,
) -> Result<(Vec<f64>, std::ops::Range<usize>), String> {
    let filtered = lowpass_zero_phase(uniform, dt, fc).map_err(|e| e.to_string())?;
    let keep = interior(filtered.len(), dt, fc).map_err(|e| e.to_string())?;
    Ok((filtered, keep))
}

/// The samples of (t, v) inside [t0, t1] with the span ends interpolated in, sorted by time,
/// one sample per time.
fn span_points(t: &[f64], v: &[f64], t0: f64, t1: f64) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = t
        .iter()
        .zip(v)
        .filter(|(s, _)| **s >= t0 && **s <= t1)
        .map(|(s, x)| (*s, *x))
        .chain(
            [t0, t1]
                .into_iter()
                .filter_map(|s| data::results::interpolate(t, v, s).map(|x| (s, x))),
        )
        .collect();
    pts.sort_by(|p, q| p.0.total_cmp(&q.0));
    pts.dedup_by(|p, q| p.0 == q.0);
    pts
}
