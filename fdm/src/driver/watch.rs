//! The driver's watch on each predicted level: the scan of the monitored coordinates for the
//! computational mode (|Δ²v| of the predicted velocities against the peak |v|), runaway growth
//! and non-finite values, and the diagnostics a stopped run carries (growth, overextension, an
//! energy ledger that opened).

use data::Diagnostic;

use crate::method::StepState;
use crate::output::Outputs;
use crate::system::{DeflectionModel, Overextension, System};

/// The watch's scan of a new level over the monitored coordinates: max |Δ²v| of the predicted
/// velocities, max |v|, max |q|, whether they are finite, and where the maxima sit.
pub(super) struct Watch {
    pub(super) d2: f64,
    pub(super) vmax: f64,
    pub(super) qmax: f64,
    pub(super) finite: bool,
    pub(super) worst_d2: usize,
    pub(super) worst_q: usize,
}

impl Watch {
    /// The maxima only, and whether every Δ²v and q was finite (then they equal [`Watch::scan`]'s;
    /// a finite Δ²v has finite terms). The worst coordinates are left at the range's start.
    pub(super) fn maxima(
        mon: std::ops::Range<usize>,
        new_v: &[f64],
        st: &StepState,
    ) -> (Self, bool) {
        let (prev, cur, next) = (&st.prev.v[mon.clone()], &st.cur.v[mon.clone()], &st.next.q);
        let (nv, q) = (&new_v[mon.clone()], &next[mon.clone()]);
        // four independent lanes: the maxima's dependency chains overlap
        const L: usize = 4;
        let (mut d2, mut vmax, mut qmax) = ([0.0f64; L], [0.0f64; L], [0.0f64; L]);
        let mut clean = [true; L];
        let mut lane = |l: usize, i: usize| {
            let d = (nv[i] - 2.0 * cur[i] + prev[i]).abs();
            let (v, x) = (nv[i].abs(), q[i].abs());
            clean[l] &= d.is_finite() & x.is_finite();
            d2[l] = if d > d2[l] { d } else { d2[l] };
            vmax[l] = if v > vmax[l] { v } else { vmax[l] };
            qmax[l] = if x > qmax[l] { x } else { qmax[l] };
        };
        let m = nv.len();
        for c in 0..m / L {
            for l in 0..L {
                lane(l, c * L + l);
            }
        }
        for i in m / L * L..m {
            lane(0, i);
        }
        let max = |a: [f64; L]| a.into_iter().fold(0.0f64, |m, x| if x > m { x } else { m });
        let clean = clean.into_iter().all(|c| c);
        let w = Watch {
            d2: max(d2),
            vmax: max(vmax),
            qmax: max(qmax),
            finite: clean,
            worst_d2: mon.start,
            worst_q: mon.start,
        };
        (w, clean)
    }

    /// The full scan: non-finite values propagate into the maxima and name their coordinate.
    pub(super) fn scan(mon: std::ops::Range<usize>, new_v: &[f64], st: &StepState) -> Self {
        let (prev, cur, next) = (&st.prev, &st.cur, &st.next);
        let mut w = Watch {
            d2: 0.0,
            vmax: 0.0,
            qmax: 0.0,
            finite: true,
            worst_d2: mon.start,
            worst_q: mon.start,
        };
        for i in mon {
            let nv = new_v[i];
            w.finite &= nv.is_finite() && next.q[i].is_finite();
            let d = (nv - 2.0 * cur.v[i] + prev.v[i]).abs();
            if d > w.d2 || d.is_nan() {
                w.d2 = d;
                w.worst_d2 = i;
            }
            w.vmax = w.vmax.max(nv.abs());
            if next.q[i].abs() > w.qmax || next.q[i].is_nan() {
                w.qmax = next.q[i].abs();
                w.worst_q = i;
            }
        }
        w
    }
}

/// What the watch saw when it stopped the run.
pub(super) struct Growth {
    pub(super) t: f64,
    pub(super) tau: f64,
    pub(super) limit: f64,
    /// the sign-alternating velocity grew (else q ran away or went non-finite)
    pub(super) parasitic: bool,
    pub(super) finite: bool,
    /// damping or velocity coupling on under a method with a computational mode
    pub(super) computational_mode: bool,
    pub(super) worst_d2: usize,
    pub(super) worst_q: usize,
    pub(super) d2: f64,
    pub(super) peak_v: f64,
}

/// Relative ledger residual at which a run stops: the energy balance of the discrete
/// equations is lost. Catalog runs close to 1e-3 or better at their default steps (the
/// stability suite's `bounded` verdict); a residual of 5 % means the step no longer resolves
/// the motion, and the results past it are not a solution.
pub(crate) const LEDGER_LOST: f64 = 5e-2;
/// Steps before the ledger watch judges: a run that starts from rest measures its first
/// steps' residual against the little energy that has flowed (spin-up at 11 stations: 16 %
/// after 5 steps, 6e-6 at the end).
pub(crate) const LEDGER_SETTLED_STEPS: usize = 50;

/// The energy balance lost (`LEDGER_LOST`): the step is too long for the motion.
pub(super) fn ledger_diagnostic(t: f64, closure: f64, tau: f64) -> Diagnostic {
    Diagnostic {
        t,
        what: format!(
            "the energy ledger's residual reached {closure:.2e} of the energy that flowed"
        ),
        location: None,
        why: format!(
            "the step {tau:.3e} does not resolve the motion: the stability bound is taken on the \
             system linearized at t = 0, and large deflections or fast joint motion change its \
             time scales"
        ),
        remedy: "a smaller --dt".into(),
    }
}

/// A link deflected beyond its length: outside the beam model, whatever the step.
pub(super) fn overextension_diagnostic(t: f64, o: Overextension) -> Diagnostic {
    let (why, remedy) = match o.model {
        DeflectionModel::SmallStrain => (
            "the deflection is outside the small-strain floating-frame model",
            "reduce the load",
        ),
        DeflectionModel::Linear => (
            "the linear model (no geometric stiffening) has lost its centrifugal stiffness: \
             spinning above the first bending frequency it grows without bound",
            "switch on `foreshortening` (geometric stiffening)",
        ),
        DeflectionModel::ChordFrames => (
            "the finite-difference chain measures deflections from each link's tip chord and \
             holds only while the clamp slope against the chord stays well below 1",
            "stiffer links, smaller initial angles or joint loads, or the fem or modal backend",
        ),
    };
    Diagnostic {
        t,
        what: format!(
            "tip deflection of link {} grew to {:.3e}, beyond the link length {}",
            o.link, o.deflection, o.length
        ),
        location: Some(format!("link {} tip", o.link)),
        why: why.into(),
        remedy: remedy.into(),
    }
}

pub(super) fn growth_diagnostic<S: System + Outputs + ?Sized>(sys: &S, g: Growth) -> Diagnostic {
    let Growth {
        t,
        tau,
        limit,
        parasitic,
        finite,
        computational_mode,
        worst_d2,
        worst_q,
        d2,
        peak_v,
    } = g;
    let bound_b = sys.bound(t);
    let location = if parasitic {
        format!(
            "largest sign-alternating velocity in {}",
            sys.dof_name(worst_d2)
        )
    } else {
        format!(
            "largest growth in {}; binding bound at {}",
            sys.dof_name(worst_q),
            sys.describe(&bound_b)
        )
    };
    let (what, why, remedy) = if computational_mode && finite {
        (
            "computational (parasitic) mode of the two-step central difference grew".to_string(),
            format!(
                "damping or velocity-coupled forces are on: the two-step scheme's spurious root \
                 ξ ≈ −(1 + cτ/m) has modulus > 1 for any step, so the sign-alternating mode grows \
                 (|Δ²v| = {d2:.3e} vs peak |v| = {peak_v:.3e})"
            ),
            "use --method robert-asselin (filtered two-step, limit ½(1 − ν)σ) or --method velocity-form (one-step, limit σ)".to_string(),
        )
    } else {
        (
            if finite {
                "elastic response grew without bound".to_string()
            } else {
                "non-finite state".to_string()
            },
            format!(
                "step {tau:.3e} against the method's limit {limit:.3e} ({} bound); \
                 the report's σ (5.43–5.44) is the limit of the one-step form, the two-step form needs σ/2",
                bound_b.kind.name()
            ),
            "omit --dt (the scheme then picks a stable step) or lower the safety factor"
                .to_string(),
        )
    };
    Diagnostic {
        t,
        what,
        location: Some(location),
        why,
        remedy,
    }
}

#[cfg(test)]
mod tests {
    use super::Watch;
    use crate::method::StepState;

    /// The lane-wise maxima of the common case are the full scan's, for every range length
    /// (lanes and remainder); a non-finite Δ²v or q is flagged so that the full scan decides.
    #[test]
    fn elem_watch_maxima_are_the_full_scans() {
        let n = 23;
        let mut st = StepState::new(n, 0);
        let val = |k: usize, s: f64| ((k as f64 * 0.7 + s).sin() * 1e3).round() / 7.0;
        for i in 0..n {
            st.prev.v[i] = val(i, 0.1);
            st.cur.v[i] = val(i, 1.3);
            st.next.q[i] = val(i, 2.9);
            st.pred[i] = val(i, 4.1);
        }
        for start in [0, 1, 2] {
            for end in start..=n {
                let (fast, clean) = Watch::maxima(start..end, &st.pred, &st);
                let full = Watch::scan(start..end, &st.pred, &st);
                assert!(clean && full.finite);
                assert_eq!(
                    (fast.d2, fast.vmax, fast.qmax),
                    (full.d2, full.vmax, full.qmax),
                    "{start}..{end}"
                );
            }
        }
        for bad in [f64::NAN, f64::INFINITY] {
            let mut s2 = StepState::new(n, 0);
            s2.pred.copy_from_slice(&st.pred);
            s2.next.q[n - 1] = bad;
            assert!(!Watch::maxima(0..n, &s2.pred, &s2).1);
            let mut s3 = StepState::new(n, 0);
            s3.cur.v[n - 2] = bad;
            assert!(!Watch::maxima(0..n, &s3.pred, &s3).1);
        }
    }
}
