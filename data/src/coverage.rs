//! Known gaps in cross-check coverage (`data/cases/coverage-exceptions.toml`).
//!
//! `flexverify coverage` requires, for every catalog scene, that every pair of backends that
//! run it be linked by whole-history cross rows on a frame-invariant observable, and that every
//! backend that runs it have a convergence row. A gap is allowed only when it is listed here,
//! with its reason:
//!
//! ```toml
//! [[exception]]
//! scene = "rocket"
//! backends = ["fdm"]
//! missing = "cross-history"
//! reason = "fdm and modal converge to different rocket.X histories (issue 15): …"
//! ```
//!
//! `backends` names the backends the gap is about: a `cross-history` exception applies to every
//! pair of listed backends (a single listed backend: to every pair that contains it), a
//! `convergence` exception to each backend listed.
//! An exception that no longer matches a gap is an error of the coverage check (the list only
//! shrinks).

use serde::{Deserialize, Serialize};

use crate::backend::BackendKind;
use crate::error::SceneError;

/// The check kind an exception excuses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MissingCheck {
    /// No chain of whole-history cross rows on a frame-invariant observable links the pair.
    CrossHistory,
    /// No convergence (order / Richardson / monotone) row for the backend.
    Convergence,
}

impl MissingCheck {
    pub fn name(self) -> &'static str {
        match self {
            MissingCheck::CrossHistory => "cross-history",
            MissingCheck::Convergence => "convergence",
        }
    }
}

/// One listed gap.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoverageException {
    pub scene: String,
    pub backends: Vec<BackendKind>,
    pub missing: MissingCheck,
    /// Why the gap exists and what would close it.
    pub reason: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExceptionFile {
    #[serde(rename = "exception", default)]
    exceptions: Vec<CoverageException>,
}

const EXCEPTIONS_TOML: &str = include_str!("../cases/coverage-exceptions.toml");

/// The embedded exceptions, checked for form: a non-empty reason and at least one backend.
/// Whether the scene exists and the gap is real is checked by `verify`'s coverage analysis.
pub fn coverage_exceptions() -> Result<Vec<CoverageException>, SceneError> {
    parse_exceptions(EXCEPTIONS_TOML, "<cases>/coverage-exceptions.toml")
}

/// Parses an exceptions file with located errors.
pub fn parse_exceptions(
    text: &str,
    source_name: &str,
) -> Result<Vec<CoverageException>, SceneError> {
    let file: ExceptionFile = toml::from_str(text).map_err(|e| {
        let (line, column) = crate::error::line_column(text, e.span().map_or(0, |s| s.start));
        SceneError {
            source_name: source_name.to_string(),
            line,
            column,
            path: "exception".into(),
            message: e.message().trim().to_string(),
            expected: "an [[exception]] table as documented in data/src/coverage.rs".into(),
        }
    })?;
    for (i, x) in file.exceptions.iter().enumerate() {
        let problem = if x.reason.trim().is_empty() {
            Some(("reason", "is empty", "the reason for the gap"))
        } else if x.backends.is_empty() {
            Some(("backends", "is empty", "the backends the gap is about"))
        } else {
            None
        };
        if let Some((field, message, expected)) = problem {
            let needle = format!("scene = \"{}\"", x.scene);
            let (line, column) = crate::error::line_column(text, text.find(&needle).unwrap_or(0));
            return Err(SceneError {
                source_name: source_name.to_string(),
                line,
                column,
                path: format!("exception[{i}].{field}"),
                message: message.into(),
                expected: expected.into(),
            });
        }
    }
    Ok(file.exceptions)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sys_exceptions_parse_and_have_reasons() {
        let list = coverage_exceptions().unwrap();
        assert!(list.iter().all(|x| !x.reason.trim().is_empty()));
    }

    #[test]
    fn sys_empty_reason_is_refused_with_its_location() {
        let text = "[[exception]]\nscene = \"rocket\"\nbackends = [\"fdm\"]\n\
                    missing = \"convergence\"\nreason = \" \"\n";
        let e = parse_exceptions(text, "x.toml").unwrap_err();
        assert_eq!(e.path, "exception[0].reason");
        assert_eq!(e.line, 2);
        let bad_kind = text.replace("convergence", "frequency");
        assert!(parse_exceptions(&bad_kind, "x.toml").is_err());
    }
}
