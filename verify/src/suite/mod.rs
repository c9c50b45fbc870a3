//! The verification suite of `data/cases/*.toml` (`flexverify verify`).
//!
//! Every row names its reference and tolerance; cases run in parallel (rayon) and outcomes are
//! returned in case order, so results are identical with or without threads.

pub mod evaluate;
pub mod filter;
pub mod history;
pub mod ladder;
pub mod order;
pub mod plots;
pub mod quantity;
pub mod reference;
pub mod report;
pub mod run_cache;

use data::cases::{SuiteName, all_cases};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::progress::{Progress, Silent};
use evaluate::{Outcome, evaluate};
use run_cache::RunCache;

/// Which cases run: `quick` (the CI set) or `full` (everything, including the long ladders).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Suite {
    Quick,
    Full,
}

impl Suite {
    /// Whether a case or stability row declared for `suite` belongs to this suite.
    pub fn includes(self, suite: SuiteName) -> bool {
        self == Suite::Full || suite == SuiteName::Quick
    }
}

/// Runs the selected cases and returns them with their outcomes in case order, and the cache
/// of backend answers (for the report's plots).
pub fn run_cases(
    suite: Suite,
    filter: Option<&str>,
) -> Result<(Vec<data::cases::Case>, Vec<Outcome>, RunCache), Error> {
    run_cases_with_progress(suite, filter, &Silent)
}

/// [`run_cases`], reporting each case to `progress` as it starts and finishes.
pub fn run_cases_with_progress(
    suite: Suite,
    filter: Option<&str>,
    progress: &dyn Progress,
) -> Result<(Vec<data::cases::Case>, Vec<Outcome>, RunCache), Error> {
    let selected = select_cases(suite, filter)?;
    let (outcomes, cache) = run_selected(&selected, progress);
    Ok((selected, outcomes, cache))
}

/// The cases of `suite` whose id contains `filter`, in catalog order; an empty selection is
/// an error (a typo in `--filter` must not pass as an empty success).
pub fn select_cases(suite: Suite, filter: Option<&str>) -> Result<Vec<data::cases::Case>, Error> {
    let cases = all_cases()?;
    let selected: Vec<_> = cases
        .into_iter()
        .filter(|c| suite.includes(c.suite))
        .filter(|c| filter.is_none_or(|f| c.id.contains(f)))
        .collect();
    if selected.is_empty() {
        return Err(Error::NoCaseMatches {
            suite: format!("{suite:?}"),
            filter: filter.map(str::to_string),
        });
    }
    Ok(selected)
}

/// Evaluates `cases` in parallel; outcomes come back in the order of `cases`. Each outcome
/// depends only on its own case (the cache memoizes deterministic backend runs), so a case
/// gives the same row whichever other cases run beside it — what makes sharding exact.
pub fn run_selected(
    cases: &[data::cases::Case],
    progress: &dyn Progress,
) -> (Vec<Outcome>, RunCache) {
    let cache = RunCache::default();
    progress.begin(cases.len(), "cases");
    let outcomes: Vec<Outcome> = cases
        .par_iter()
        .map(|c| {
            progress.start(&c.id);
            let o = evaluate(c, &cache);
            progress.advance();
            o
        })
        .collect();
    progress.finish();
    (outcomes, cache)
}
