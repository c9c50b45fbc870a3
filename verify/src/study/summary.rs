//! What a study found: each ladder's monotonicity, Richardson extrapolation and estimate of
//! its converged value; the study's reference (analytic when the scene has one, else the
//! Richardson value of the ladder that agrees best with itself); each rung's error and each
//! ladder's observed order against it; and whether two backends converge to different answers
//! (then each ladder is scored against its own estimate).

use data::{BackendKind, Scene, Settings};
use serde::{Deserialize, Serialize};

use super::ladder::Refine;
use crate::suite::order::{falling_prefix, fit_order, richardson};
use crate::suite::quantity::Quantity;
use crate::suite::reference::{analytic_value, default_analytic_id};
use crate::work::{Counters, Timing};

/// One rung of a refinement ladder.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Rung {
    pub backend: BackendKind,
    /// Human-readable discretization, e.g. "elements=8".
    pub discretization: String,
    /// Refinement parameter h (1/elements, 1/(stations−1), 1/modes or dt).
    pub h: f64,
    pub value: f64,
    /// |value − reference| / scale.
    pub error: Option<f64>,
    /// Minimum wall time over the repeats of [`Rung::timing`].
    pub wall_time_s: f64,
    /// Repeated timings: minimum, median, maximum and the number of repeats.
    pub timing: Timing,
    /// The backend's work counters of this rung.
    pub counters: Counters,
    #[serde(skip)]
    pub settings: Settings,
    /// Peak |channel| of this run, for time-history quantities.
    #[serde(skip)]
    pub peak: Option<f64>,
}

/// The study of one backend.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Ladder {
    pub backend: BackendKind,
    pub rungs: Vec<Rung>,
    /// Least-squares order over the rungs with a positive error.
    pub observed_order: Option<f64>,
    /// Richardson extrapolation of this ladder (value, order used).
    pub richardson: Option<(f64, f64)>,
    /// True if the values decrease monotonically with refinement (Rayleigh–Ritz bound).
    pub monotone_from_above: bool,
    /// First rung where the error stopped falling (round-off plateau), excluded from the fit.
    pub plateau_from: Option<String>,
    /// Why the ladder stopped early, if it did (unsupported, stopped run, …).
    pub note: Option<String>,
    /// The ladder's own estimate of the converged value: its Richardson extrapolation, when
    /// the order it rests on is at least [`MIN_ASYMPTOTIC_ORDER`].
    pub estimate: Option<Estimate>,
}

/// How the note of a ladder stopped by the rung budget begins.
pub const CAPPED: &str = "ladder capped";

impl Ladder {
    /// Whether the rung budget stopped this ladder before its last rung.
    pub fn capped_by_budget(&self) -> bool {
        self.note.as_deref().is_some_and(|n| n.starts_with(CAPPED))
    }
}

/// The smallest observed order at which a ladder's Richardson extrapolation is used as an
/// estimate or a reference. Below it the rungs are not in their asymptotic range: the
/// extrapolation divides the last difference by r^p − 1 (0.41 at p = 0.5 for halving, 0.07 at
/// the floor 0.1 that [`richardson`] applies to differences that do not fall), so it amplifies
/// noise instead of removing an error.
pub const MIN_ASYMPTOTIC_ORDER: f64 = 0.5;

/// Where a ladder says the quantity converges to: its Richardson extrapolation, with the
/// distance of its finest rung from that value as the uncertainty (the finest rung's own error
/// estimate, an upper bound on the extrapolation's once the ladder is asymptotic).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Estimate {
    pub backend: BackendKind,
    pub value: f64,
    pub uncertainty: f64,
}

/// Two ladders whose estimates differ by more than their uncertainties allow: the backends
/// converge to different answers, so neither may be scored against the other.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Disagreement {
    pub first: Estimate,
    pub second: Estimate,
    /// |first − second| over the quantity's scale (the same scale the rung errors use).
    pub relative_difference: f64,
}

impl Disagreement {
    /// One sentence with both values, for tables and error messages.
    pub fn sentence(&self) -> String {
        let (a, b) = (self.first, self.second);
        format!(
            "the models disagree: {} converges to {:.10e} (± {:.1e}), {} to {:.10e} (± {:.1e}); \
             the difference {:.3e} of the scale exceeds both error estimates",
            a.backend,
            a.value,
            a.uncertainty,
            b.backend,
            b.value,
            b.uncertainty,
            self.relative_difference
        )
    }
}

/// A refinement study of one quantity of one scene: every backend's ladder, the reference the
/// errors are measured against, and the backends' disagreement if they converge apart.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Study {
    pub scene: String,
    pub quantity: String,
    pub refine: String,
    pub reference: Option<f64>,
    pub reference_label: String,
    pub ladders: Vec<Ladder>,
    /// Set when no analytic value exists and two ladders converge to different answers; each
    /// ladder's errors are then measured against its own estimate.
    pub disagreement: Option<Disagreement>,
}

/// A measured ladder's own summary: whether its values fall monotonically, its Richardson
/// extrapolation and the estimate made of it. Errors and the observed order wait for the
/// study's reference ([`summarize`]).
pub fn summarize_ladder(kind: BackendKind, rungs: Vec<Rung>, note: Option<String>) -> Ladder {
    let values: Vec<f64> = rungs.iter().map(|r| r.value).collect();
    let hs: Vec<f64> = rungs.iter().map(|r| r.h).collect();
    let monotone_from_above =
        values.len() >= 2 && values.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-13));
    let extrapolation = richardson(&hs, &values, None);
    let estimate = extrapolation
        .filter(|&(_, p)| p >= MIN_ASYMPTOTIC_ORDER)
        .zip(rungs.last())
        .map(|((value, _), finest)| Estimate {
            backend: kind,
            value,
            uncertainty: (finest.value - value).abs(),
        });
    Ladder {
        backend: kind,
        richardson: extrapolation,
        rungs,
        observed_order: None,
        plateau_from: None,
        monotone_from_above,
        note,
        estimate,
    }
}

/// The study of the measured `ladders`: the reference, each rung's error against it (or
/// against its ladder's own estimate when the models disagree), plateaus and observed orders.
pub fn summarize(
    scene: &Scene,
    q: &Quantity,
    quantity: &str,
    refine: Refine,
    mut ladders: Vec<Ladder>,
) -> Study {
    let scale_of = |l: &Ladder, value: f64| match q {
        Quantity::At { .. } => l.rungs.last().and_then(|r| r.peak).unwrap_or(value.abs()),
        _ => value.abs(),
    };

    // Reference: analytic when the scene/quantity has one; else, unless two ladders converge
    // to different answers, the Richardson value of the ladder whose last two rungs agree best
    // (its own estimate of its error is smallest), among the ladders with an estimate.
    let analytic = default_analytic_id(scene, q)
        .and_then(|id| analytic_value(&id, scene, q).ok().map(|v| (v, id)));
    let disagreement = if analytic.is_none() {
        worst_disagreement(&ladders, scale_of)
    } else {
        None
    };
    let (reference, reference_label) = match analytic {
        Some((v, id)) => (Some(v), format!("analytic:{id}")),
        None if disagreement.is_some() => (
            None,
            "each ladder against its own Richardson extrapolation (the models disagree)".into(),
        ),
        None => {
            let best = ladders
                .iter()
                .filter_map(|l| {
                    l.estimate?;
                    let (ext, p) = l.richardson?;
                    let last = l.rungs.last()?.value;
                    Some(((last - ext).abs(), ext, p, l.backend))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match best {
                Some((_, ext, p, b)) => (
                    Some(ext),
                    format!("Richardson of the {b} ladder (p = {p:.2})"),
                ),
                None => {
                    let why: Vec<String> = ladders
                        .iter()
                        .filter(|l| !l.rungs.is_empty())
                        .map(|l| match l.richardson {
                            Some((_, p)) => format!(
                                "{} Richardson order {p:.2} (below {MIN_ASYMPTOTIC_ORDER})",
                                l.backend
                            ),
                            None if l.rungs.len() >= 3 => {
                                format!("{}'s last differences change sign", l.backend)
                            }
                            None => format!("{} has fewer than 3 rungs", l.backend),
                        })
                        .collect();
                    let why = if why.is_empty() {
                        String::new()
                    } else {
                        format!(": {}", why.join("; "))
                    };
                    (
                        None,
                        format!("none (no ladder reached the asymptotic range{why})"),
                    )
                }
            }
        }
    };
    for l in &mut ladders {
        let own = l.estimate.map(|e| e.value);
        let Some(r) = reference.or(disagreement.and(own)) else {
            continue;
        };
        let scale = scale_of(&*l, r);
        for rung in &mut l.rungs {
            rung.error = (scale > 0.0).then(|| (rung.value - r).abs() / scale);
        }
        let (h, e): (Vec<f64>, Vec<f64>) = l
            .rungs
            .iter()
            .filter_map(|r| Some((r.h, r.error?)))
            .filter(|(_, e)| *e > 1e-13)
            .unzip();
        let keep = falling_prefix(&e);
        if keep < e.len() {
            l.plateau_from = Some(l.rungs[keep].discretization.clone());
        }
        l.observed_order = fit_order(&h[..keep], &e[..keep]);
    }
    Study {
        scene: scene.name.clone(),
        quantity: quantity.to_string(),
        refine: refine.name().to_string(),
        reference,
        reference_label,
        ladders,
        disagreement,
    }
}

/// The pair of ladder estimates that differ most beyond their combined uncertainty (plus a
/// round-off allowance of 1e-10 of the scale), if any pair does.
fn worst_disagreement(
    ladders: &[Ladder],
    scale_of: impl Fn(&Ladder, f64) -> f64,
) -> Option<Disagreement> {
    let with_estimates: Vec<(&Ladder, Estimate)> = ladders
        .iter()
        .filter_map(|l| Some((l, l.estimate?)))
        .collect();
    let mut worst: Option<(f64, Disagreement)> = None;
    for (i, &(la, a)) in with_estimates.iter().enumerate() {
        for &(lb, b) in &with_estimates[i + 1..] {
            let scale = scale_of(la, a.value).max(scale_of(lb, b.value));
            if scale <= 0.0 {
                continue;
            }
            let difference = (a.value - b.value).abs();
            let excess = difference - a.uncertainty - b.uncertainty - 1e-10 * scale;
            if excess > 0.0 && worst.is_none_or(|(e, _)| excess > e) {
                worst = Some((
                    excess,
                    Disagreement {
                        first: a,
                        second: b,
                        relative_difference: difference / scale,
                    },
                ));
            }
        }
    }
    worst.map(|(_, d)| d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ladder of `value(h) = limit + c h²` on h = 1/4, 1/8, 1/16.
    fn ladder(backend: BackendKind, limit: f64, c: f64) -> Ladder {
        ladder_of_order(backend, limit, c, 2.0)
    }

    /// A ladder of `value(h) = limit + c hᵖ` on h = 1/4, 1/8, 1/16.
    fn ladder_of_order(backend: BackendKind, limit: f64, c: f64, p: f64) -> Ladder {
        let rungs: Vec<Rung> = [4.0, 8.0, 16.0]
            .iter()
            .map(|n: &f64| Rung {
                backend,
                discretization: format!("n={n}"),
                h: 1.0 / n,
                value: limit + c * n.powf(-p),
                error: None,
                wall_time_s: 1.0,
                timing: Timing {
                    min_s: 1.0,
                    median_s: 1.0,
                    max_s: 1.0,
                    repeats: 1,
                },
                counters: Counters {
                    dofs: 0,
                    steps: 0,
                    rhs_evaluations: 0,
                    factorizations: 0,
                    newton_iterations: 0,
                },
                settings: Settings::default(),
                peak: None,
            })
            .collect();
        summarize_ladder(backend, rungs, None)
    }

    fn scale(_: &Ladder, v: f64) -> f64 {
        v.abs()
    }

    #[test]
    fn cross_ladders_converging_apart_are_reported_with_both_limits() {
        // Two second-order ladders whose limits differ by 1e-3 relative, far beyond their
        // finest rungs' distance from their extrapolations (c/256 = 4e-6).
        let ladders = [
            ladder(BackendKind::Fem, 1.0, 1e-3),
            ladder(BackendKind::Fdm, 1.001, 1e-3),
        ];
        let d = worst_disagreement(&ladders, scale).expect("a disagreement");
        assert!((d.first.value - 1.0).abs() < 1e-12, "{d:?}");
        assert!((d.second.value - 1.001).abs() < 1e-12, "{d:?}");
        assert!((d.relative_difference - 1e-3 / 1.001).abs() < 1e-12);
        let sentence = d.sentence();
        assert!(
            sentence.contains("fem converges to 1.0000000000e0"),
            "{sentence}"
        );
        assert!(sentence.contains("fdm to 1.0010000000e0"), "{sentence}");
    }

    #[test]
    fn cross_ladders_within_their_estimates_are_not_flagged() {
        // Limits 1e-6 apart, but each ladder's finest rung is still 4e-5 from its limit.
        let ladders = [
            ladder(BackendKind::Fem, 1.0, 1e-2),
            ladder(BackendKind::Modal, 1.0 + 1e-6, -1e-2),
        ];
        assert!(worst_disagreement(&ladders, scale).is_none());
        // One ladder alone cannot disagree.
        assert!(worst_disagreement(&ladders[..1], scale).is_none());
    }

    #[test]
    fn conv_a_ladder_below_the_asymptotic_order_gives_no_estimate_and_no_reference() {
        for (p, estimated) in [(2.0, true), (0.6, true), (0.4, false)] {
            let l = ladder_of_order(BackendKind::Fem, 1.0, 1e-2, p);
            let (_, order) = l.richardson.expect("an extrapolation");
            assert!((order - p).abs() < 1e-9, "{order} vs {p}");
            assert_eq!(l.estimate.is_some(), estimated, "p = {p}");
        }
        // Differences that grow (order −1 here): the floor order 0.1, no estimate.
        let growing = ladder_of_order(BackendKind::Fdm, 1.0, 1e-2, -1.0);
        assert_eq!(growing.richardson.map(|r| r.1), Some(0.1));
        assert!(growing.estimate.is_none());
        // Without an estimate no ladder is scored, and the label says why.
        let scene = data::load_scene("two-link-free-undamped").unwrap();
        let quantity = "joint1.angle@10";
        let q = crate::study::measure::parse_quantity(&scene, quantity).unwrap();
        let study = summarize(&scene, &q, quantity, Refine::Space, vec![growing]);
        assert!(study.reference.is_none() && study.disagreement.is_none());
        assert!(
            study
                .reference_label
                .contains("no ladder reached the asymptotic range: fdm Richardson order 0.10"),
            "{}",
            study.reference_label
        );
        assert!(study.ladders[0].rungs.iter().all(|r| r.error.is_none()));
    }

    #[test]
    fn cross_the_worst_pair_is_reported() {
        let ladders = [
            ladder(BackendKind::Fem, 1.0, 1e-3),
            ladder(BackendKind::Fdm, 1.01, 1e-3),
            ladder(BackendKind::Modal, 1.0 + 1e-4, 1e-3),
        ];
        let d = worst_disagreement(&ladders, scale).unwrap();
        assert_eq!(d.first.backend, BackendKind::Fem);
        assert_eq!(d.second.backend, BackendKind::Fdm);
    }
}
