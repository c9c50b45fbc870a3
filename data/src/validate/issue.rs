//! One semantic problem ([`Issue`]: field, what is wrong, what to write instead), and the
//! checker that collects them with the field checks every family uses.

use crate::locate::FieldPath;

/// One semantic problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Issue {
    pub path: FieldPath,
    pub message: String,
    pub expected: String,
}

/// Collects the issues of one validation pass, in the order the checks run.
pub(super) struct Checker {
    pub(super) issues: Vec<Issue>,
}

impl Checker {
    pub(super) fn fail(
        &mut self,
        path: FieldPath,
        message: impl Into<String>,
        expected: impl Into<String>,
    ) {
        self.issues.push(Issue {
            path,
            message: message.into(),
            expected: expected.into(),
        });
    }

    pub(super) fn positive(&mut self, path: FieldPath, v: f64) {
        if !v.is_finite() || v <= 0.0 {
            self.fail(path, format!("{v} is not positive"), "a finite number > 0");
        }
    }

    pub(super) fn non_negative(&mut self, path: FieldPath, v: f64) {
        if !v.is_finite() || v < 0.0 {
            self.fail(path, format!("{v} is negative"), "a finite number ≥ 0");
        }
    }

    pub(super) fn finite(&mut self, path: FieldPath, v: f64) {
        if !v.is_finite() {
            self.fail(path, format!("{v} is not finite"), "a finite number");
        }
    }

    pub(super) fn opt_positive(&mut self, path: FieldPath, v: Option<f64>) {
        if let Some(v) = v {
            self.positive(path, v);
        }
    }
}
