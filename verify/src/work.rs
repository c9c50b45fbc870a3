//! Work–precision measurements of the report: the error of each rung of a case's ladder
//! against its cost, the cost measured two ways so a curve does not hinge on timer noise:
//!
//! - wall time as the minimum over repeated sequential runs (rungs dearer than
//!   [`MAX_SPENT_S`] keep their one run, and say so: `repeats` = 1) (the minimum is the run least
//!   disturbed by the machine), with the median and maximum beside it and the spread
//!   (median − min)/min;
//! - work counters from the backend's own `Cost` (DOFs, steps, right-hand-side evaluations,
//!   factorizations, Newton iterations), which are exact and machine independent.
//!
//! A Pareto front per scene and quantity keeps the measurements no other measurement beats in
//! both cost (minimum wall time) and error: the discretizations `recommend` chooses among.

use std::path::Path;

use data::Cost;
use serde::{Deserialize, Serialize};

/// Repeated timings of one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub min_s: f64,
    pub median_s: f64,
    pub max_s: f64,
    pub repeats: usize,
}

impl Timing {
    /// The timing of one run, not repeated.
    pub fn once(seconds: f64) -> Timing {
        timing_of(&mut [seconds])
    }

    /// (median − min) / min: how far a typical repeat is from the fastest. The maximum is
    /// reported beside it but not used: on a shared machine one preempted repeat makes it
    /// arbitrarily large.
    pub fn spread(&self) -> f64 {
        if self.min_s > 0.0 {
            (self.median_s - self.min_s) / self.min_s
        } else {
            0.0
        }
    }
}

/// At least this many repeats, so that a spread exists…
pub const MIN_REPEATS: usize = 5;
/// …and repeats until this much time is spent (sub-millisecond runs get many repeats)…
pub const MIN_SPENT_S: f64 = 0.2;
/// …but never more than this many, nor (after three) beyond [`MAX_SPENT_S`].
pub const MAX_REPEATS: usize = 50;
pub const MAX_SPENT_S: f64 = 3.0;

/// Times `run` (which returns the backend's own wall time of one run, or `None` when it
/// fails) repeatedly: at least [`MIN_REPEATS`] runs and [`MIN_SPENT_S`] seconds, at most
/// [`MAX_REPEATS`] runs, and no more than three once [`MAX_SPENT_S`] is spent.
pub fn time_repeats(run: impl FnMut() -> Option<f64>) -> Option<Timing> {
    repeat_after(Vec::new(), run)
}

/// [`time_repeats`] counting the timings already in `times` as repeats.
fn repeat_after(mut times: Vec<f64>, mut run: impl FnMut() -> Option<f64>) -> Option<Timing> {
    let mut spent: f64 = times.iter().sum();
    while times.len() < MAX_REPEATS {
        let enough = times.len() >= MIN_REPEATS && spent >= MIN_SPENT_S;
        let too_long = times.len() >= 3 && spent >= MAX_SPENT_S;
        if enough || too_long {
            break;
        }
        let t = run()?;
        times.push(t);
        spent += t;
    }
    Some(timing_of(&mut times))
}

/// Whether a rung's first run (the one that gave its value) is one of its timing repeats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FirstRun {
    /// It ran alone (a study's sequential ladder): it is a repeat like the others.
    Alone,
    /// It shared the cores with other cases (the suite's parallel run): it only decides
    /// whether the rung is repeated.
    Shared,
}

/// The timing of a rung whose first run took `first` seconds: repeated with
/// [`time_repeats`] when it is cheaper than [`MAX_SPENT_S`], else that one run alone
/// (`repeats` = 1, reported as such): a rung of seconds is not worth repeating for a plot,
/// its timer noise is small relative to its cost, and its work counters are exact.
pub fn time_rung(
    first: f64,
    first_run: FirstRun,
    run: impl FnMut() -> Option<f64>,
) -> Option<Timing> {
    if first > MAX_SPENT_S {
        return Some(Timing::once(first));
    }
    match first_run {
        FirstRun::Alone => repeat_after(vec![first], run),
        FirstRun::Shared => time_repeats(run),
    }
}

fn timing_of(times: &mut [f64]) -> Timing {
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median = if n % 2 == 1 {
        times[n / 2]
    } else {
        0.5 * (times[n / 2 - 1] + times[n / 2])
    };
    Timing {
        min_s: times[0],
        median_s: median,
        max_s: times[n - 1],
        repeats: n,
    }
}

/// The machine-independent work of one run, from the backend's `Cost`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counters {
    pub dofs: usize,
    pub steps: usize,
    pub rhs_evaluations: usize,
    pub factorizations: usize,
    pub newton_iterations: usize,
}

impl From<&Cost> for Counters {
    fn from(c: &Cost) -> Self {
        Counters {
            dofs: c.dofs,
            steps: c.steps,
            rhs_evaluations: c.rhs_evaluations,
            factorizations: c.factorizations,
            newton_iterations: c.newton_iterations,
        }
    }
}

/// Reads one counter.
pub type CounterOf = fn(&Counters) -> usize;

/// Which counter measures the work of a ladder: the first of RHS evaluations, steps,
/// factorizations that is non-zero on every rung and changes along the ladder; DOFs otherwise
/// (eigen- and static solves: one factorization each, work growing with the system size).
pub fn work_counter(points: &[WorkPoint]) -> (&'static str, CounterOf) {
    let counters: Vec<Counters> = points.iter().map(|p| p.counters).collect();
    work_counter_of(&counters)
}

/// [`work_counter`] of the counters of a ladder's rungs.
pub fn work_counter_of(counters: &[Counters]) -> (&'static str, CounterOf) {
    let choices: [(&'static str, CounterOf); 3] = [
        ("RHS evaluations", |c| c.rhs_evaluations),
        ("steps", |c| c.steps),
        ("factorizations", |c| c.factorizations),
    ];
    for (name, f) in choices {
        let first = counters.first().map(f);
        if counters.iter().all(|c| f(c) > 0) && counters.iter().any(|c| Some(f(c)) != first) {
            return (name, f);
        }
    }
    ("DOFs", |c| c.dofs)
}

/// One measured rung.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkPoint {
    pub backend: String,
    /// The rung's settings, e.g. "stations=41" or "elements=4,element=hermite-quintic".
    pub discretization: String,
    pub value: f64,
    /// |value − reference| / |reference|; |value − reference| where the reference is 0 (the
    /// case's `reference_label` then says so).
    pub error: f64,
    pub timing: Timing,
    pub counters: Counters,
}

/// The work–precision measurements of one ladder case (written as `work-<case>.json`, so
/// that `merge` can rebuild the scene fronts from shards).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseWork {
    pub case: String,
    pub scene: String,
    /// Whether the case modifies the catalog scene (then it is a different problem).
    pub modified: bool,
    pub quantity: String,
    pub backend: String,
    /// What the errors are measured against.
    pub reference_label: String,
    pub points: Vec<WorkPoint>,
}

impl CaseWork {
    pub fn file_name(case: &str) -> String {
        format!("work-{case}.json")
    }
}

/// Indices of the points on the Pareto front of (cost, error), both minimized, in order of
/// increasing cost: a point is on the front when no other point is at most as costly and at
/// most as wrong, and strictly better in one of the two. Ties keep the first.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_finite() && points[i].1.is_finite())
        .collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
            .then(a.cmp(&b))
    });
    let mut front = Vec::new();
    let mut best_error = f64::INFINITY;
    for i in order {
        if points[i].1 < best_error {
            best_error = points[i].1;
            front.push(i);
        }
    }
    front
}

/// Every `work-*.json` in `dir`, sorted by case id (unreadable files are skipped with a note).
pub fn read_all(dir: &Path) -> (Vec<CaseWork>, Vec<String>) {
    let mut out = Vec::new();
    let mut notes = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return (out, notes);
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !(name.starts_with("work-") && name.ends_with(".json")) {
            continue;
        }
        match std::fs::read_to_string(e.path())
            .map_err(|e| e.to_string())
            .and_then(|s| serde_json::from_str::<CaseWork>(&s).map_err(|e| e.to_string()))
        {
            Ok(w) => out.push(w),
            Err(why) => notes.push(format!("{name}: {why}")),
        }
    }
    out.sort_by(|a, b| a.case.cmp(&b.case));
    (out, notes)
}

/// Copies the `work-*.json` files of shard directories into `out` (for `merge`).
pub fn copy_work_files(dirs: &[std::path::PathBuf], out: &Path) -> std::io::Result<usize> {
    let mut copied = 0;
    for dir in dirs {
        for entry in std::fs::read_dir(dir)? {
            let path = entry?.path();
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
            if let Some(name) = name
                && name.starts_with("work-")
                && name.ends_with(".json")
            {
                std::fs::copy(&path, out.join(&name))?;
                copied += 1;
            }
        }
    }
    Ok(copied)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_keeps_the_undominated_points_in_cost_order() {
        let pts = [
            (1.0, 1e-2),
            (2.0, 1e-3),
            (1.5, 5e-2),
            (3.0, 1e-3),
            (4.0, 1e-5),
            (0.5, 1.0),
        ];
        assert_eq!(pareto_front(&pts), vec![5, 0, 1, 4]);
        assert!(pareto_front(&[]).is_empty());
    }

    #[test]
    fn timing_repeats_until_a_spread_exists() {
        let mut k = 0;
        let t = time_repeats(|| {
            k += 1;
            Some(1e-3 * (1.0 + (k % 3) as f64))
        })
        .unwrap();
        // 2 ms on average: the cap of repeats comes before MIN_SPENT_S.
        assert_eq!(t.repeats, MAX_REPEATS);
        assert_eq!(t.min_s, 1e-3);
        assert_eq!(t.max_s, 3e-3);
        assert_eq!(t.median_s, 2e-3);
        assert!((t.spread() - 1.0).abs() < 1e-12);
        // Long runs stop after three repeats.
        let t = time_repeats(|| Some(2.0)).unwrap();
        assert_eq!(t.repeats, 3);
        assert!(time_repeats(|| None).is_none());
        // A rung dearer than the budget keeps its one run.
        for first_run in [FirstRun::Alone, FirstRun::Shared] {
            let t = time_rung(2.0 * MAX_SPENT_S, first_run, || {
                panic!("must not run again")
            })
            .unwrap();
            assert_eq!(
                (t.repeats, t.min_s, t.spread()),
                (1, 2.0 * MAX_SPENT_S, 0.0)
            );
        }
        // A study's first run (alone on the machine) is one of the repeats; the suite's
        // (shared with parallel cases) is not.
        let mut calls = 0;
        let t = time_rung(0.5, FirstRun::Alone, || {
            calls += 1;
            Some(1.0)
        })
        .unwrap();
        // 0.5 + 1 + 1 + 1 s: four repeats, three of them new, spend more than MAX_SPENT_S.
        assert_eq!((t.repeats, calls, t.min_s), (4, 3, 0.5));
        let mut calls = 0;
        let t = time_rung(0.5, FirstRun::Shared, || {
            calls += 1;
            Some(1.0)
        })
        .unwrap();
        assert_eq!((t.repeats, calls, t.min_s), (3, 3, 1.0));
    }
}
