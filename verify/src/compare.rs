//! Two run results of one scene side by side (`flexverify compare RUN REFERENCE`): the contact
//! episodes' boundaries and the whole histories, over the span both runs cover.
//!
//! # Common span
//! `t_common = min(t_run, t_ref)`, each `t` the run's last output time (a run that stopped early
//! ends before the scene's end).
//!
//! # Contact episodes
//! Compared when either run recorded an impact, contact start or release. Each run's episodes
//! are [`data::results::contact_episodes`] with flights shorter than `min_flight` merged; only
//! those starting before `t_common` take part. Equal counts pair them in order, episode k with
//! episode k, and give for each
//!
//! ```text
//! |Δ start_k| = |start_k(run) − start_k(ref)|,   |Δ end_k| = |end_k(run) − end_k(ref)|
//! ```
//!
//! an end only when both runs have one at or before `t_common`; the largest of these is the
//! comparison's boundary difference. Different counts pair nothing (a boundary of one run has no
//! counterpart in the other), and both lists are returned instead.
//!
//! # Histories
//! Every observable channel the two runs share (or the chosen ones, which may also be ledger
//! terms `energy.NAME`), by [`history::compare`] with the run as `a` and the reference as `b`:
//! `max_t |a(t) − b(t)|` over the run's output times inside the reference's span (the reference
//! linearly interpolated), the reference's peak `max_t |b(t)|`, and their ratio. With a low-pass
//! cut-off both are first put on one uniform grid and filtered there (zero phase).

use std::path::{Path, PathBuf};

use data::{BackendKind, Diagnostic, Event, RunResult, Settings, StabilityVerdict};
use serde::Serialize;

use crate::error::Error;
use crate::suite::history;

/// Free flights shorter than this (seconds) merge two contact phases into one episode, unless
/// [`CompareOptions::min_flight`] says otherwise: the micro-bounces after an impact then do not
/// change how many episodes a run has.
pub const DEFAULT_MIN_FLIGHT: f64 = 0.01;

/// What [`compare_runs`] compares and how.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    /// Free flights shorter than this (seconds, finite and > 0) do not end a contact episode.
    pub min_flight: f64,
    /// The histories to compare; empty: every observable channel both runs have.
    pub channels: Vec<String>,
    /// Zero-phase low-pass cut-off (Hz, finite and > 0) applied to both histories first.
    pub lowpass_hz: Option<f64>,
}

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            min_flight: DEFAULT_MIN_FLIGHT,
            channels: Vec::new(),
            lowpass_hz: None,
        }
    }
}

/// The comparison of two runs of one scene (module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    pub scene: String,
    pub run: RunSummary,
    pub reference: RunSummary,
    /// End of the span both runs cover: the earlier of their last output times.
    pub common_end: f64,
    /// None when neither run has contact events.
    pub episodes: Option<EpisodeComparison>,
    pub lowpass_hz: Option<f64>,
    pub histories: Vec<HistoryRow>,
    /// Channels of one run only, left out of the default selection (empty when channels were
    /// chosen).
    pub only_in_run: Vec<String>,
    pub only_in_reference: Vec<String>,
}

/// How one of the two runs was made and how it ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    pub backend: BackendKind,
    /// The settings the run was asked for (absent fields: the backend's defaults).
    pub settings: Settings,
    /// Last output time.
    pub t_reached: f64,
    /// `completed`, or `stopped` with the backend's diagnostic (its `t` is the stop time).
    #[serde(flatten)]
    pub verdict: StabilityVerdict,
    pub wall_time_s: f64,
    pub dofs: usize,
}

impl RunSummary {
    /// The stop diagnostic of a run that ended early.
    pub fn stopped(&self) -> Option<&Diagnostic> {
        match &self.verdict {
            StabilityVerdict::Stopped { diagnostic } => Some(diagnostic),
            StabilityVerdict::Completed => None,
        }
    }
}

/// A contact episode: first contact to last release (`end` None: in contact at the run's end).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Episode {
    pub start: f64,
    pub end: Option<f64>,
}

/// The contact episodes of both runs that start before the common end, paired when their
/// counts agree.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeComparison {
    pub min_flight: f64,
    pub run: Vec<Episode>,
    pub reference: Vec<Episode>,
    /// None when the runs have different numbers of episodes.
    pub pairs: Option<Vec<EpisodePair>>,
    /// The largest boundary difference of the pairs (None: not paired, or no episode).
    pub largest: Option<LargestDifference>,
}

/// Episode k of both runs and the differences of its boundaries.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EpisodePair {
    /// 1-based.
    pub episode: usize,
    pub run_start: f64,
    pub reference_start: f64,
    pub start_diff: f64,
    pub run_end: Option<f64>,
    pub reference_end: Option<f64>,
    /// None unless both ends exist and lie within the common span.
    pub end_diff: Option<f64>,
}

/// Which boundary of an episode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Boundary {
    Start,
    End,
}

impl std::fmt::Display for Boundary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Boundary::Start => "start",
            Boundary::End => "end",
        })
    }
}

/// The largest |Δ| over the compared episode boundaries, and where it is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LargestDifference {
    pub abs_diff: f64,
    /// 1-based.
    pub episode: usize,
    pub boundary: Boundary,
}

/// One channel's whole-history difference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HistoryRow {
    pub channel: String,
    /// max_t |run − reference|.
    pub max_abs_diff: f64,
    /// max_t |reference|.
    pub reference_peak: f64,
    /// `max_abs_diff / reference_peak`; None when the peak is 0.
    pub relative: Option<f64>,
}

/// Reads a run result: `path` is the JSON `flexverify run --out` writes, or a folder holding
/// exactly one such JSON (the `-events.json` lists beside it are skipped). Returns the file read
/// and its result.
pub fn load_run(path: &Path) -> Result<(PathBuf, RunResult), Error> {
    let file_error = |path: &Path, reason: String| Error::RunFile {
        path: path.to_path_buf(),
        reason,
    };
    if !path.is_dir() {
        return read_run_file(path).map(|r| (path.to_path_buf(), r));
    }
    let entries = std::fs::read_dir(path)
        .map_err(|e| file_error(path, format!("cannot list the folder: {e}")))?;
    let mut candidates: Vec<PathBuf> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            // `.name.tmp` files are writes in progress (`output::write_atomic`).
            name.ends_with(".json") && !name.starts_with('.') && !is_event_list(p)
        })
        .collect();
    candidates.sort();
    let mut found = Vec::new();
    let mut rejected = Vec::new();
    for file in candidates {
        match read_run_file(&file) {
            Ok(r) => found.push((file, r)),
            Err(e) => rejected.push(e.to_string()),
        }
    }
    match found.len() {
        1 => Ok(found.pop().expect("one result")),
        0 => {
            let mut reason = "the folder holds no run result (the <scene>-<backend>.json that \
                              `flexverify run --out` writes)"
                .to_string();
            if !rejected.is_empty() {
                reason += &format!("; not run results: {}", rejected.join("; "));
            }
            Err(file_error(path, reason))
        }
        n => {
            let names: Vec<String> = found.iter().map(|(f, _)| f.display().to_string()).collect();
            Err(file_error(
                path,
                format!(
                    "the folder holds {n} run results ({}); name one of the files",
                    names.join(", ")
                ),
            ))
        }
    }
}

/// `run --out` writes each run's events beside its result as `<scene>-<backend>-events.json`.
fn is_event_list(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.ends_with("-events.json"))
}

fn read_run_file(path: &Path) -> Result<RunResult, Error> {
    let file_error = |reason: String| Error::RunFile {
        path: path.to_path_buf(),
        reason,
    };
    let bytes = std::fs::read(path).map_err(|e| file_error(format!("cannot read: {e}")))?;
    serde_json::from_slice(&bytes).map_err(|e| {
        file_error(if is_event_list(path) {
            "this is a run's event list, not its result; name the <scene>-<backend>.json beside it"
                .into()
        } else {
            format!("not a run result written by `flexverify run --out`: {e}")
        })
    })
}

/// Compares `run` against `reference` (module docs).
pub fn compare_runs(
    run: &RunResult,
    reference: &RunResult,
    opts: &CompareOptions,
) -> Result<Comparison, Error> {
    let positive = |option: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidOption {
                option,
                reason: format!("{v} is not allowed; expected a finite number > 0"),
            })
        }
    };
    positive("min_flight", opts.min_flight)?;
    if let Some(fc) = opts.lowpass_hz {
        positive("lowpass_hz", fc)?;
    }
    if run.scene != reference.scene {
        return Err(Error::RunsNotComparable {
            reason: format!(
                "they are runs of different scenes: the run is of `{}`, the reference of `{}`",
                run.scene, reference.scene
            ),
        });
    }
    let run_summary = summary(run, "the run")?;
    let reference_summary = summary(reference, "the reference")?;
    let common_end = run_summary.t_reached.min(reference_summary.t_reached);
    let episodes = (has_contact_events(run) || has_contact_events(reference))
        .then(|| compare_episodes(run, reference, opts.min_flight, common_end));

    let names = |r: &RunResult| -> Vec<String> {
        r.observables
            .channels
            .iter()
            .map(|c| c.name.clone())
            .collect()
    };
    let (run_names, reference_names) = (names(run), names(reference));
    let shared: Vec<String> = run_names
        .iter()
        .filter(|n| reference_names.contains(n))
        .cloned()
        .collect();
    let (channels, only_in_run, only_in_reference) = if opts.channels.is_empty() {
        let only = |of: &[String]| -> Vec<String> {
            of.iter().filter(|n| !shared.contains(n)).cloned().collect()
        };
        (shared.clone(), only(&run_names), only(&reference_names))
    } else {
        let mut chosen: Vec<String> = Vec::new();
        for c in &opts.channels {
            if history::series(run, c).is_none() || history::series(reference, c).is_none() {
                return Err(Error::InvalidOption {
                    option: "channels",
                    reason: format!(
                        "no channel `{c}` in both runs; available: {} (or a ledger term \
                         energy.NAME both runs book)",
                        shared.join(", ")
                    ),
                });
            }
            if !chosen.contains(c) {
                chosen.push(c.clone());
            }
        }
        (chosen, Vec::new(), Vec::new())
    };

    let histories = channels
        .into_iter()
        .map(|channel| {
            let deviation =
                history::compare(run, reference, &channel, opts.lowpass_hz).map_err(|reason| {
                    let reason = format!("channel `{channel}`: {reason}");
                    // Unfiltered, a shared channel always compares; only the filter can refuse.
                    match opts.lowpass_hz {
                        Some(_) => Error::InvalidOption {
                            option: "lowpass_hz",
                            reason,
                        },
                        None => Error::RunsNotComparable { reason },
                    }
                })?;
            Ok(HistoryRow {
                channel,
                max_abs_diff: deviation.max_abs_diff,
                reference_peak: deviation.reference_peak,
                relative: (deviation.reference_peak > 0.0)
                    .then(|| deviation.max_abs_diff / deviation.reference_peak),
            })
        })
        .collect::<Result<Vec<_>, Error>>()?;

    Ok(Comparison {
        scene: run.scene.clone(),
        run: run_summary,
        reference: reference_summary,
        common_end,
        episodes,
        lowpass_hz: opts.lowpass_hz,
        histories,
        only_in_run,
        only_in_reference,
    })
}

fn summary(r: &RunResult, which: &str) -> Result<RunSummary, Error> {
    let t_reached = *r
        .observables
        .time
        .last()
        .ok_or_else(|| Error::RunsNotComparable {
            reason: format!("{which} has no output samples"),
        })?;
    Ok(RunSummary {
        backend: r.backend,
        settings: r.settings.clone(),
        t_reached,
        verdict: r.verdict.clone(),
        wall_time_s: r.cost.wall_time_s,
        dofs: r.cost.dofs,
    })
}

fn has_contact_events(r: &RunResult) -> bool {
    r.events.iter().any(|e| {
        matches!(
            e,
            Event::Impact { .. } | Event::ContactStart { .. } | Event::Release { .. }
        )
    })
}

fn compare_episodes(
    run: &RunResult,
    reference: &RunResult,
    min_flight: f64,
    common_end: f64,
) -> EpisodeComparison {
    let within = |r: &RunResult| -> Vec<Episode> {
        data::results::contact_episodes(&r.events, min_flight)
            .into_iter()
            .filter(|(start, _)| *start < common_end)
            .map(|(start, end)| Episode { start, end })
            .collect()
    };
    let (run_episodes, reference_episodes) = (within(run), within(reference));
    let pairs = (run_episodes.len() == reference_episodes.len()).then(|| {
        run_episodes
            .iter()
            .zip(&reference_episodes)
            .enumerate()
            .map(|(k, (a, b))| {
                let comparable = |end: Option<f64>| end.filter(|t| *t <= common_end);
                EpisodePair {
                    episode: k + 1,
                    run_start: a.start,
                    reference_start: b.start,
                    start_diff: (a.start - b.start).abs(),
                    run_end: a.end,
                    reference_end: b.end,
                    end_diff: comparable(a.end)
                        .zip(comparable(b.end))
                        .map(|(x, y)| (x - y).abs()),
                }
            })
            .collect::<Vec<_>>()
    });
    let largest = pairs.as_deref().and_then(|pairs| {
        pairs
            .iter()
            .flat_map(|p| {
                [
                    Some((p.start_diff, p.episode, Boundary::Start)),
                    p.end_diff.map(|d| (d, p.episode, Boundary::End)),
                ]
            })
            .flatten()
            // The first of equal differences: the earliest place it occurs.
            .fold(
                None,
                |best: Option<LargestDifference>, (abs_diff, episode, boundary)| match best {
                    Some(b) if b.abs_diff >= abs_diff => Some(b),
                    _ => Some(LargestDifference {
                        abs_diff,
                        episode,
                        boundary,
                    }),
                },
            )
    });
    EpisodeComparison {
        min_flight,
        run: run_episodes,
        reference: reference_episodes,
        pairs,
        largest,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use data::{Cost, EnergyLedger, Observables};

    fn contact_start(t: f64) -> Event {
        Event::ContactStart {
            t,
            contact: 1,
            time_tolerance: 0.0,
        }
    }
    fn impact(t: f64) -> Event {
        Event::Impact {
            t,
            contact: 1,
            velocity_before: vec![],
            velocity_after: vec![],
            impulse: 1.0,
            momentum_residual: 0.0,
            normal_velocity_before: -1.0,
            normal_velocity_after: 0.0,
            kinetic_energy_lost: 0.0,
        }
    }
    fn release(t: f64) -> Event {
        Event::Release {
            t,
            contact: 1,
            normal_force: 0.0,
            time_tolerance: 0.0,
        }
    }

    /// The events of contact phases `(start, end)`, each start a contact start with its impact.
    fn phases(list: &[(f64, Option<f64>)]) -> Vec<Event> {
        let mut events = Vec::new();
        for &(start, end) in list {
            events.push(contact_start(start));
            events.push(impact(start));
            if let Some(end) = end {
                events.push(release(end));
            }
        }
        events
    }

    /// A run of `scene` sampled every `step` over [0, t_end], one channel per (name, f(t)).
    fn run_of(
        scene: &str,
        step: f64,
        t_end: f64,
        channels: &[(&str, &dyn Fn(f64) -> f64)],
        events: Vec<Event>,
    ) -> RunResult {
        let specs: Vec<(String, &str)> =
            channels.iter().map(|(n, _)| (n.to_string(), "")).collect();
        let mut observables = Observables::with_channels(&specs);
        let samples = (t_end / step).round() as usize;
        for k in 0..=samples {
            let t = k as f64 * step;
            let values: Vec<f64> = channels.iter().map(|(_, f)| f(t)).collect();
            observables.push(t, &values);
        }
        RunResult {
            backend: BackendKind::Fem,
            scene: scene.into(),
            settings: Settings::default(),
            observables,
            ledger: EnergyLedger::default(),
            events,
            cost: Cost::default(),
            verdict: StabilityVerdict::Completed,
        }
    }

    fn zero(_: f64) -> f64 {
        0.0
    }

    /// Binary-fraction output step: sample times are exact, so a coarser run's times are
    /// reference sample times.
    const STEP: f64 = 1.0 / 128.0;

    fn episode_run(episodes: &[(f64, Option<f64>)], t_end: f64) -> RunResult {
        run_of("arm", STEP, t_end, &[("x", &zero)], phases(episodes))
    }

    #[test]
    fn sys_compare_largest_episode_difference_is_the_built_in_shift() {
        let reference = [(0.1, Some(0.2)), (0.5, None)];
        let (shift_start_1, shift_end_1, shift_start_2) = (1e-3, 4e-3, 2e-3);
        let run = [
            (0.1 + shift_start_1, Some(0.2 + shift_end_1)),
            (0.5 + shift_start_2, None),
        ];
        let c = compare_runs(
            &episode_run(&run, 1.0),
            &episode_run(&reference, 1.0),
            &CompareOptions::default(),
        )
        .unwrap();
        let e = c.episodes.expect("contact events give episodes");
        let pairs = e.pairs.expect("equal counts pair");
        assert_eq!(pairs.len(), 2);
        assert_eq!(pairs[0].start_diff, ((0.1 + shift_start_1) - 0.1f64).abs());
        assert_eq!(
            pairs[0].end_diff,
            Some(((0.2 + shift_end_1) - 0.2f64).abs())
        );
        assert_eq!(pairs[1].start_diff, ((0.5 + shift_start_2) - 0.5f64).abs());
        // In contact at the end of both runs: no end to compare.
        assert_eq!(pairs[1].end_diff, None);
        let largest = e.largest.unwrap();
        assert_eq!(
            (largest.abs_diff, largest.episode, largest.boundary),
            (((0.2 + shift_end_1) - 0.2f64).abs(), 1, Boundary::End)
        );
        assert!((largest.abs_diff - shift_end_1).abs() < 1e-15);
    }

    #[test]
    fn sys_compare_a_run_that_stopped_early_is_compared_over_the_common_span_only() {
        // The reference goes on to episodes the stopped run never reached. Both end their
        // second episode after the run's last output: the run released between that output and
        // the step on which it stopped.
        let stop = 0.375;
        let stopped_at = stop + 6e-3;
        let reference = [(0.1, Some(0.2)), (0.3, Some(0.4)), (0.6, Some(0.7))];
        let run_episodes = [(0.1, Some(0.2 + 1e-3)), (0.3 + 2e-3, Some(stop + 5e-3))];
        let x_run = |t: f64| t;
        // Far apart after the stop: not part of the comparison.
        let x_ref = |t: f64| if t <= stop { t } else { 100.0 };
        let mut run = run_of("arm", STEP, stop, &[("x", &x_run)], phases(&run_episodes));
        run.verdict = StabilityVerdict::Stopped {
            diagnostic: Diagnostic {
                t: stopped_at,
                what: "diverged".into(),
                location: None,
                why: "test".into(),
                remedy: "none".into(),
            },
        };
        let reference = run_of("arm", STEP, 1.0, &[("x", &x_ref)], phases(&reference));
        let c = compare_runs(&run, &reference, &CompareOptions::default()).unwrap();
        assert_eq!(c.common_end, stop);
        assert_eq!(c.run.stopped().map(|d| d.t), Some(stopped_at));
        let e = c.episodes.unwrap();
        assert_eq!((e.run.len(), e.reference.len()), (2, 2));
        let pairs = e.pairs.unwrap();
        // Both second ends lie after the common end: not compared.
        assert_eq!(
            (pairs[1].run_end, pairs[1].reference_end),
            (Some(stop + 5e-3), Some(0.4))
        );
        assert_eq!(pairs[1].end_diff, None);
        let largest = e.largest.unwrap();
        assert_eq!(
            (largest.abs_diff, largest.episode, largest.boundary),
            (((0.3 + 2e-3) - 0.3f64).abs(), 2, Boundary::Start)
        );
        assert_eq!(c.histories[0].max_abs_diff, 0.0);

        // Swapped: the run goes on past the reference's end, where the run's samples find no
        // reference to compare with.
        let c = compare_runs(&reference, &run, &CompareOptions::default()).unwrap();
        assert_eq!(c.common_end, stop);
        assert_eq!(c.reference.stopped().map(|d| d.t), Some(stopped_at));
        assert_eq!(c.histories[0].max_abs_diff, 0.0);
    }

    #[test]
    fn sys_compare_different_episode_counts_are_not_paired() {
        let reference = [(0.1, Some(0.2)), (0.5, Some(0.6))];
        let run = [(0.1, Some(0.2)), (0.3, Some(0.35)), (0.5, Some(0.6))];
        let c = compare_runs(
            &episode_run(&run, 1.0),
            &episode_run(&reference, 1.0),
            &CompareOptions::default(),
        )
        .unwrap();
        let e = c.episodes.unwrap();
        assert_eq!((e.run.len(), e.reference.len()), (3, 2));
        assert_eq!(
            e.run[1],
            Episode {
                start: 0.3,
                end: Some(0.35)
            }
        );
        assert!(e.pairs.is_none() && e.largest.is_none());
    }

    #[test]
    fn sys_compare_a_micro_flight_shorter_than_min_flight_merges_two_phases() {
        let flight = 2e-3;
        let reference = [(0.1, Some(0.2))];
        let run = [(0.1, Some(0.15)), (0.15 + flight, Some(0.2))];
        let (run, reference) = (episode_run(&run, 1.0), episode_run(&reference, 1.0));
        let merged = CompareOptions {
            min_flight: 5.0 * flight,
            ..CompareOptions::default()
        };
        let e = compare_runs(&run, &reference, &merged)
            .unwrap()
            .episodes
            .unwrap();
        assert_eq!(
            e.run,
            vec![Episode {
                start: 0.1,
                end: Some(0.2)
            }]
        );
        assert_eq!(e.largest.unwrap().abs_diff, 0.0);
        let separate = CompareOptions {
            min_flight: 0.5 * flight,
            ..CompareOptions::default()
        };
        let e = compare_runs(&run, &reference, &separate)
            .unwrap()
            .episodes
            .unwrap();
        assert_eq!((e.run.len(), e.reference.len()), (2, 1));
        assert!(e.pairs.is_none());
    }

    #[test]
    fn sys_compare_history_difference_is_the_analytic_difference_at_the_samples() {
        // run − reference = a t², largest at the last run sample t = 1; the reference's peak is
        // sin(1) (sin increases on [0, 1]).
        let a = 0.5;
        let reference_x = |t: f64| t.sin();
        let run_x = move |t: f64| t.sin() + a * t * t;
        let run = run_of(
            "arm",
            2.0 * STEP,
            1.0,
            &[("x", &run_x), ("still", &zero), ("run.only", &zero)],
            vec![],
        );
        let reference = run_of(
            "arm",
            STEP,
            1.0,
            &[("still", &zero), ("x", &reference_x), ("ref.only", &zero)],
            vec![],
        );
        let c = compare_runs(&run, &reference, &CompareOptions::default()).unwrap();
        assert!(c.episodes.is_none(), "no contact events, no episodes");
        let channels: Vec<&str> = c.histories.iter().map(|h| h.channel.as_str()).collect();
        assert_eq!(channels, ["x", "still"]);
        assert_eq!(
            (c.only_in_run.as_slice(), c.only_in_reference.as_slice()),
            (&["run.only".to_string()][..], &["ref.only".to_string()][..])
        );
        let x = &c.histories[0];
        let expected = a * 1.0f64 * 1.0;
        assert!((x.max_abs_diff - expected).abs() < 1e-14, "{x:?}");
        assert!((x.reference_peak - 1.0f64.sin()).abs() < 1e-15, "{x:?}");
        assert_eq!(x.relative, Some(x.max_abs_diff / x.reference_peak));
        let still = &c.histories[1];
        assert_eq!((still.max_abs_diff, still.relative), (0.0, None));

        // Chosen channels: only those, each once.
        let only_x = CompareOptions {
            channels: vec!["x".into(), "x".into()],
            ..CompareOptions::default()
        };
        let c = compare_runs(&run, &reference, &only_x).unwrap();
        assert_eq!(c.histories.len(), 1);
        assert!(c.only_in_run.is_empty());

        // Low-passed far above the content, the difference stays close to the raw one over
        // the compared interior, which ends one cut-off period (0.05 s, rounded up to whole run
        // samples of 2·STEP) before t = 1.
        let filtered = CompareOptions {
            lowpass_hz: Some(20.0),
            ..only_x
        };
        let c = compare_runs(&run, &reference, &filtered).unwrap();
        let interior_end = 1.0 - (1.0 / (20.0 * 2.0 * STEP)).ceil() * 2.0 * STEP;
        let expected = a * interior_end * interior_end;
        assert!(
            (c.histories[0].max_abs_diff - expected).abs() < 1e-2 * expected,
            "{} against {expected}",
            c.histories[0].max_abs_diff
        );
    }

    #[test]
    fn sys_compare_refuses_bad_options_and_different_scenes() {
        let run = episode_run(&[], 1.0);
        let bad = [
            CompareOptions {
                min_flight: 0.0,
                ..CompareOptions::default()
            },
            CompareOptions {
                min_flight: f64::NAN,
                ..CompareOptions::default()
            },
            CompareOptions {
                lowpass_hz: Some(-1.0),
                ..CompareOptions::default()
            },
            CompareOptions {
                lowpass_hz: Some(f64::INFINITY),
                ..CompareOptions::default()
            },
            // Above the Nyquist frequency of the 1/128 s sampling.
            CompareOptions {
                lowpass_hz: Some(1000.0),
                ..CompareOptions::default()
            },
        ];
        for opts in bad {
            let e = compare_runs(&run, &run, &opts).unwrap_err();
            assert!(matches!(e, Error::InvalidOption { .. }), "{opts:?}: {e}");
        }
        let unknown = CompareOptions {
            channels: vec!["nope".into()],
            ..CompareOptions::default()
        };
        let e = compare_runs(&run, &run, &unknown).unwrap_err().to_string();
        assert!(e.contains("`nope`") && e.contains("available: x"), "{e}");

        let mut other = run.clone();
        other.scene = "other-scene".into();
        let e = compare_runs(&run, &other, &CompareOptions::default()).unwrap_err();
        assert!(matches!(e, Error::RunsNotComparable { .. }), "{e}");
        assert!(e.to_string().contains("`other-scene`"), "{e}");
    }

    #[test]
    fn sys_compare_loads_the_one_result_of_a_folder_and_refuses_two() {
        let dir = std::env::temp_dir().join(format!("flexverify-compare-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let run = episode_run(&[(0.1, Some(0.2))], 0.5);
        let write = |name: &str, bytes: Vec<u8>| std::fs::write(dir.join(name), bytes).unwrap();
        write("arm-fem.json", serde_json::to_vec(&run).unwrap());
        write(
            "arm-fem-events.json",
            serde_json::to_vec(&run.events).unwrap(),
        );
        let (file, loaded) = load_run(&dir).unwrap();
        assert_eq!((file, loaded), (dir.join("arm-fem.json"), run.clone()));

        let e = load_run(&dir.join("arm-fem-events.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("event list"), "{e}");
        write("arm-modal.json", serde_json::to_vec(&run).unwrap());
        let e = load_run(&dir).unwrap_err().to_string();
        assert!(
            e.contains("arm-fem.json") && e.contains("arm-modal.json"),
            "{e}"
        );
        let missing = dir.join("missing.json");
        let e = load_run(&missing).unwrap_err().to_string();
        assert!(e.contains(&missing.display().to_string()), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
