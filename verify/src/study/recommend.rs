//! `recommend`: the cheapest measured discretization meeting a tolerance. In each backend's
//! ladder it picks the rung meeting the tolerance with the least work (the ladder's work
//! counter, so the pick inside a ladder never depends on the timer); across backends, the pick
//! with the smallest minimum wall time, unless the timings cannot separate them (the
//! runner-up's minimum within the winner's spread), in which case the one with fewer DOFs wins.
//! Only those picks' timings decide, so only the picks are timed with repeats; every other rung
//! keeps its one run's time (which also decides the rung budget).
//!
//! With a rung budget a ladder stops after its first rung dearer than the budget (the
//! full suite's rule, [`super::run::study_from_rungs`]); when no measured rung meets the
//! tolerance, the answer names the ladders the budget capped.

use data::{BackendKind, Scene, Settings};
use serde::Serialize;

use super::ladder::Refine;
use super::measure::{Timed, parse_study_quantity, retime};
use super::run::run_study;
use super::summary::{Ladder, Rung};
use crate::error::Error;
use crate::output::wrap;
use crate::progress::Progress;
use crate::suite::quantity::Quantity;
use crate::work::{Counters, work_counter_of};

/// The cheapest measured discretization meeting a tolerance.
#[derive(Debug, Clone, Serialize)]
pub struct Recommendation {
    pub scene: String,
    pub quantity: String,
    pub tolerance: f64,
    /// The chosen rung (see the module doc): per backend the least-work rung with
    /// error ≤ tolerance, across backends the smallest minimum wall time.
    pub rung: Rung,
    /// The other backends' picks, fastest first: how clearly the choice was made.
    pub runners_up: Vec<Rung>,
    /// Whether the timings could not separate the chosen rung from a runner-up (its minimum
    /// within the fastest pick's spread), so fewer DOFs decided.
    pub decided_by_dofs: bool,
    pub reference: f64,
    pub reference_label: String,
    /// The `flexverify` arguments that re-run the chosen discretization and print the quantity
    /// (e.g. `run spin-up --backend modal --modes 1 --t-end 15`).
    pub rerun: String,
    /// How many measured rungs meet the tolerance, of how many measured.
    pub meeting: usize,
    pub measured: usize,
}

/// Default wall-time budget per rung of `recommend` (seconds): a ladder's rungs grow 2–8× in
/// cost, so the rung after a 5 s one would take half a minute or more.
pub const DEFAULT_RUNG_BUDGET_S: f64 = 5.0;

/// The cheapest backend and discretization whose measured error on `quantity` is at most
/// `tol`, from a refinement study of `kinds` in space, in the time step at the base settings'
/// mesh, or in both together (`refine`; each ladder capped by `rung_budget_s`, if given).
#[allow(clippy::too_many_arguments)]
pub fn recommend(
    scene: &Scene,
    quantity: &str,
    tol: f64,
    refine: Refine,
    kinds: &[BackendKind],
    base: &Settings,
    rung_budget_s: Option<f64>,
    progress: &dyn Progress,
) -> Result<Recommendation, Error> {
    let mut study = run_study(
        scene,
        quantity,
        refine,
        kinds,
        base,
        rung_budget_s,
        Timed::Once,
        progress,
    )?;
    let capped: Vec<String> = study
        .ladders
        .iter()
        .filter(|l| l.capped_by_budget())
        .filter_map(|l| Some(format!("{} {}", l.backend, l.note.as_ref()?)))
        .collect();
    // Models that converge to answers further apart than the tolerance cannot both meet it,
    // and which one is right is not a question of discretization.
    if let Some(d) = study.disagreement
        && d.relative_difference > tol
    {
        return Err(Error::ModelsDisagree {
            quantity: quantity.to_string(),
            scene: scene.name.clone(),
            tolerance: tol,
            sentence: d.sentence(),
        });
    }
    if study.reference.is_none() && study.disagreement.is_none() {
        return Err(Error::NoReference {
            quantity: quantity.to_string(),
            scene: scene.name.clone(),
            why: study.reference_label + &crate::error::capped_sentence(&capped),
        });
    }
    let meeting = study
        .ladders
        .iter()
        .flat_map(|l| l.rungs.iter().filter(|r| meets(r, tol)))
        .count();
    // Per ladder (by index), its least-work rung meeting the tolerance and its reference (the
    // study's, or the ladder's own estimate when the models disagree by less than the
    // tolerance).
    let picked: Vec<(usize, usize, f64)> = study
        .ladders
        .iter()
        .enumerate()
        .filter_map(|(i, l)| {
            let reference = study.reference.or(l.estimate.map(|e| e.value))?;
            Some((i, least_work_meeting(l, tol)?, reference))
        })
        .collect();
    let q = parse_study_quantity(scene, quantity, base)?;
    progress.begin(picked.len(), "timings");
    for &(ladder, rung, _) in &picked {
        let r = &mut study.ladders[ladder].rungs[rung];
        progress.start(&format!(
            "{} {quantity}: timing {} {}",
            scene.name, r.backend, r.discretization
        ));
        // A repeat of a run that succeeded fails only if the machine does (out of memory):
        // then the one run's timing stands, and its `repeats` = 1 says so.
        if let Some(timing) = retime(scene, r.backend, &r.settings, &q, r.timing.min_s) {
            r.timing = timing;
            r.wall_time_s = timing.min_s;
        }
        progress.advance();
    }
    progress.finish();
    let mut picks: Vec<(&Rung, f64)> = picked
        .iter()
        .map(|&(ladder, rung, reference)| (&study.ladders[ladder].rungs[rung], reference))
        .collect();
    // Across backends: fastest minimum wall time, unless the timings cannot tell the picks
    // apart (within the fastest's spread): then fewer DOFs, then backend order.
    picks.sort_by(|a, b| a.0.wall_time_s.total_cmp(&b.0.wall_time_s));
    let chosen = picks.first().map(|&(fastest, _)| {
        let within = fastest.timing.min_s * (1.0 + fastest.timing.spread());
        let tied = picks.iter().filter(|(r, _)| r.wall_time_s <= within);
        let by_dofs = tied
            .enumerate()
            .min_by_key(|(i, (r, _))| (r.counters.dofs, *i))
            .map_or(0, |(i, _)| i);
        (
            by_dofs,
            picks
                .iter()
                .filter(|(r, _)| r.wall_time_s <= within)
                .count()
                > 1,
        )
    });
    let best = chosen.map(|(i, _)| picks[i]);
    let decided_by_dofs = chosen.is_some_and(|(_, tied)| tied);
    let Some((r, reference)) = best else {
        let best_err = study
            .ladders
            .iter()
            .flat_map(|l| l.rungs.iter())
            .filter_map(|r| Some((r.error?, r)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        return Err(Error::ToleranceNotMet {
            tolerance: tol,
            best: best_err.map(|(e, r)| (r.backend, r.discretization.clone(), e)),
            reference_label: study.reference_label,
            capped,
        });
    };
    // Ending the re-run at the quantity's time makes its final value the quantity.
    let until = match q {
        Quantity::At { t, .. } => Some(t),
        _ => None,
    };
    let flags = rerun_flags(&r.settings, until);
    let what = match q {
        Quantity::Frequency { .. } => "modes",
        Quantity::StaticTip => "statics",
        _ => "run",
    };
    Ok(Recommendation {
        scene: scene.name.clone(),
        quantity: quantity.to_string(),
        tolerance: tol,
        rung: r.clone(),
        reference,
        reference_label: match study.disagreement {
            Some(d) if study.reference.is_none() => format!(
                "{}'s own Richardson extrapolation (the backends converge {:.1e} apart, within \
                 the tolerance)",
                r.backend, d.relative_difference
            ),
            _ => study.reference_label.clone(),
        },
        rerun: format!("{what} {} --backend {}{flags}", scene.name, r.backend),
        runners_up: picks
            .iter()
            .filter(|(p, _)| !std::ptr::eq(*p, r))
            .map(|(p, _)| (*p).clone())
            .collect(),
        decided_by_dofs,
        meeting,
        measured: study.ladders.iter().map(|l| l.rungs.len()).sum(),
    })
}

fn meets(r: &Rung, tol: f64) -> bool {
    r.error.is_some_and(|e| e <= tol)
}

/// The ladder's rung meeting the tolerance with the least work (first on ties), by index.
fn least_work_meeting(l: &Ladder, tol: f64) -> Option<usize> {
    let counters: Vec<Counters> = l.rungs.iter().map(|r| r.counters).collect();
    let (_, work) = work_counter_of(&counters);
    l.rungs
        .iter()
        .enumerate()
        .filter(|(_, r)| meets(r, tol))
        .min_by_key(|(_, r)| work(&r.counters))
        .map(|(i, _)| i)
}

/// The command-line options that reproduce the settings of a rung (the refined parameter and
/// every option the study was given), ending at `until` when the quantity is a value at a time.
fn rerun_flags(s: &Settings, until: Option<f64>) -> String {
    let mut s = s.clone();
    s.time.t_end = until.or(s.time.t_end);
    s.command_line()
        .into_iter()
        .map(|flag| format!(" {flag}"))
        .collect()
}

impl Recommendation {
    fn counts(&self) -> String {
        format!(
            "({} of {} measured discretizations meet the tolerance)",
            self.meeting, self.measured
        )
    }

    fn cost(r: &Rung) -> String {
        let c = &r.counters;
        format!(
            "wall time {:.3e} s (minimum of {} repeat{}, spread {:.0}%); work: {} DOFs, {} steps, \
             {} RHS evaluations, {} factorizations",
            r.timing.min_s,
            r.timing.repeats,
            if r.timing.repeats == 1 { "" } else { "s" },
            100.0 * r.timing.spread(),
            c.dofs,
            c.steps,
            c.rhs_evaluations,
            c.factorizations
        )
    }

    /// How the choice was made against the other backends' picks.
    fn choice(&self) -> Option<String> {
        let next = self.runners_up.first()?;
        let ratio = next.wall_time_s / self.rung.wall_time_s;
        Some(if self.decided_by_dofs {
            format!(
                "timings too close to separate from {} with {} ({:.3e} s): fewer DOFs decided ({} vs {})",
                next.backend,
                next.discretization,
                next.wall_time_s,
                self.rung.counters.dofs,
                next.counters.dofs
            )
        } else {
            format!(
                "next cheapest: {} with {}, {:.3e} s ({ratio:.1}x)",
                next.backend, next.discretization, next.wall_time_s
            )
        })
    }

    /// The recommendation at full length, one fact per line.
    pub fn wide_text(&self) -> String {
        let r = &self.rung;
        let mut s = format!(
            "recommended: {} with {} — value {:.10e}, measured error {:.3e} ≤ {:.1e} against {} = {:.10e}\n{}\n",
            r.backend,
            r.discretization,
            r.value,
            r.error.unwrap_or(f64::NAN),
            self.tolerance,
            self.reference_label,
            self.reference,
            Self::cost(r),
        );
        if let Some(c) = self.choice() {
            s.push_str(&c);
            s.push('\n');
        }
        s.push_str(&format!(
            "re-run: flexverify {}\n{}\n",
            self.rerun,
            self.counts()
        ));
        s
    }

    /// The recommendation for a terminal of `width` columns: one fact per line.
    pub fn terminal_text(&self, width: usize) -> String {
        let r = &self.rung;
        let mut lines = vec![
            format!("recommended: {} with {}", r.backend, r.discretization),
            format!(
                "  value {:.10e}, measured error {:.3e} ≤ {:.1e}",
                r.value,
                r.error.unwrap_or(f64::NAN),
                self.tolerance
            ),
            format!(
                "  against {} = {:.10e}",
                self.reference_label, self.reference
            ),
            format!("  {}", Self::cost(r)),
        ];
        lines.extend(self.choice().map(|c| format!("  {c}")));
        lines.push(format!("re-run: flexverify {}", self.rerun));
        lines.push(self.counts());
        lines.iter().map(|l| wrap(l, width, 4) + "\n").collect()
    }
}
