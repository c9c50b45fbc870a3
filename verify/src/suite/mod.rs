//! The verification suite of `data/cases/*.toml` (`flexverify verify`).
//!
//! Every row names its reference and tolerance; cases run in parallel (rayon) and outcomes are
//! returned in case order, so results are identical with or without threads.

pub mod evaluate;
pub mod filter;
pub mod history;
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
    let cache = RunCache::default();
    progress.begin(selected.len(), "cases");
    let outcomes: Vec<Outcome> = selected
        .par_iter()
        .map(|c| {
            progress.start(&c.id);
            let o = evaluate(c, &cache);
            progress.advance();
            o
        })
        .collect();
    progress.finish();
    Ok((selected, outcomes, cache))
}
