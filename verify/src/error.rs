//! The library's error type: every way a verification, study, stability or comparison request can fail
//! before it produces results. A failed *check* is not an error — it is an [`Outcome`] or a
//! [`Verdict`] with its status — and neither is a run that stopped early (its result carries
//! the diagnostic).
//!
//! [`Outcome`]: crate::suite::evaluate::Outcome
//! [`Verdict`]: crate::stability::Verdict

use thiserror::Error;

/// Why a library call produced no result.
#[derive(Debug, Error)]
pub enum Error {
    /// A scene name or file could not be loaded (unknown name, malformed or invalid file).
    #[error(transparent)]
    Scene(#[from] data::LoadError),
    /// The embedded case files do not parse (a defect of the build, reported with its place).
    #[error(transparent)]
    Cases(#[from] data::SceneError),
    /// A backend refused the request or failed numerically.
    #[error(transparent)]
    Backend(#[from] data::BackendError),
    /// No verification case is selected by the suite and filter.
    #[error("no verification case matches (suite {suite}, filter {filter:?})")]
    NoCaseMatches {
        /// The suite's name (`Quick`, `Full`).
        suite: String,
        filter: Option<String>,
    },
    /// A quantity expression does not parse or does not exist in the scene.
    #[error("quantity `{quantity}`: {reason}")]
    InvalidQuantity { quantity: String, reason: String },
    /// No backend could measure the quantity on any rung of its ladder.
    #[error("no backend produced `{quantity}`:\n{}", notes.join("\n"))]
    QuantityNotProduced {
        quantity: String,
        /// Each ladder's reason for ending (unsupported, stopped run, …).
        notes: Vec<String>,
    },
    /// Neither an analytic value nor a converged ladder gives a reference.
    #[error("no reference could be established for `{quantity}` on `{scene}`: {why}")]
    NoReference {
        quantity: String,
        scene: String,
        why: String,
    },
    /// No measured discretization meets a requested tolerance.
    #[error("{}", tolerance_not_met(*tolerance, best.as_ref(), reference_label, capped))]
    ToleranceNotMet {
        tolerance: f64,
        /// The most accurate measured rung: (backend, discretization, error).
        best: Option<(data::BackendKind, String, f64)>,
        reference_label: String,
        /// The ladders the rung budget stopped, each with its note (finer rungs were not
        /// measured).
        capped: Vec<String>,
    },
    /// The backends converge to answers further apart than the requested tolerance: no
    /// discretization can be recommended until the model difference is explained.
    #[error(
        "no recommendation for `{quantity}` on `{scene}` at {tolerance:.1e}: {sentence}; \
         compare the backends' models, or restrict --backend to one of them for its own \
         convergence"
    )]
    ModelsDisagree {
        quantity: String,
        scene: String,
        tolerance: f64,
        sentence: String,
    },
    /// A run result to compare could not be read: a missing or unreadable file, a file that is
    /// not a run result, or a folder holding none or several.
    #[error("{}: {reason}", path.display())]
    RunFile {
        path: std::path::PathBuf,
        reason: String,
    },
    /// Two run results that cannot be compared (different scenes, a run without output).
    #[error("cannot compare the runs: {reason}")]
    RunsNotComparable { reason: String },
    /// An option of a request is out of its range or names something that does not exist.
    #[error("{option}: {reason}")]
    InvalidOption {
        /// The option's field name in the library's request (e.g. `min_flight`).
        option: &'static str,
        reason: String,
    },
    /// A result file could not be written.
    #[error("cannot write output: {0}")]
    Io(#[from] std::io::Error),
}

fn tolerance_not_met(
    tol: f64,
    best: Option<&(data::BackendKind, String, f64)>,
    reference_label: &str,
    capped: &[String],
) -> String {
    let mut s = match best {
        Some((backend, discretization, e)) => format!(
            "no measured discretization meets {tol:.1e}: the best is {backend} {discretization} \
             with error {e:.3e} (against {reference_label})"
        ),
        None => "no discretization could be measured".into(),
    };
    s.push_str(&capped_sentence(capped));
    s
}

/// "; finer rungs were not measured (…)" for the ladders a rung budget capped (empty if none).
pub(crate) fn capped_sentence(capped: &[String]) -> String {
    if capped.is_empty() {
        return String::new();
    }
    format!(
        "; finer rungs were not measured ({}): a larger rung budget measures them",
        capped.join("; ")
    )
}
