//! The verification table and its JSON/CSV forms (the HTML pages: [`crate::report`]).

use super::evaluate::{Outcome, Status};
use crate::output::{Column, csv_table, fitted_table, text_table, wrap};

const HEADER: [&str; 11] = [
    "check",
    "case",
    "scene",
    "backend",
    "quantity",
    "value",
    "reference",
    "error",
    "tolerance",
    "result",
    "wall [s]",
];

fn norm_name(n: data::cases::Norm) -> &'static str {
    match n {
        data::cases::Norm::Relative => "relative",
        data::cases::Norm::Absolute => "absolute",
        data::cases::Norm::RelativeToPeak => "rel. to peak",
    }
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |x| format!("{x:.6e}"))
}

fn status_name(s: Status) -> &'static str {
    match s {
        Status::Pass => "pass",
        Status::Fail => "FAIL",
        Status::Error => "ERROR",
    }
}

fn error_cell(o: &Outcome) -> String {
    o.error.map_or("-".into(), |e| format!("{e:.2e}"))
}

fn tolerance_cell(o: &Outcome) -> String {
    format!("{:.1e} {}", o.tolerance, norm_name(o.norm))
}

fn rows(outcomes: &[Outcome]) -> Vec<Vec<String>> {
    outcomes
        .iter()
        .map(|o| {
            vec![
                o.check.clone(),
                o.id.clone(),
                o.scene.clone(),
                o.backend.clone(),
                o.quantity.clone(),
                fmt_opt(o.value),
                format!("{} [{}]", fmt_opt(o.reference), o.reference_label),
                error_cell(o),
                tolerance_cell(o),
                status_name(o.status).into(),
                format!("{:.3}", o.wall_time_s),
            ]
        })
        .collect()
}

/// Every column at full width, in case order, and the message of each failure below.
pub fn wide_table(outcomes: &[Outcome]) -> String {
    let mut s = text_table(&HEADER, &rows(outcomes));
    for o in outcomes.iter().filter(|o| o.status != Status::Pass) {
        s.push_str(&format!("  {}: {}\n", o.id, o.message));
    }
    s
}

/// The table for a terminal of `width` columns: status, case, error, tolerance and wall time,
/// grouped by check kind (groups with failures first, each under a summary line), failures
/// first within a group, then the failure messages wrapped to the width. Only case ids are
/// ever cut (with `…`), and only when the table would not fit otherwise.
pub fn terminal_table(outcomes: &[Outcome], width: usize) -> String {
    let columns = [
        Column::left("status"),
        Column::left("case").elastic(),
        Column::right("error"),
        Column::left("tolerance"),
        Column::right("wall [s]"),
    ];
    let failed = |o: &Outcome| o.status != Status::Pass;
    // Check kinds in order of first appearance, those with a failure first.
    let mut kinds: Vec<&str> = Vec::new();
    for o in outcomes {
        if !kinds.contains(&o.check.as_str()) {
            kinds.push(&o.check);
        }
    }
    let mut groups: Vec<Vec<&Outcome>> = kinds
        .iter()
        .map(|k| {
            let members = || outcomes.iter().filter(move |o| o.check == *k);
            members()
                .filter(|o| failed(o))
                .chain(members().filter(|o| !failed(o)))
                .collect()
        })
        .collect();
    groups.sort_by_key(|members| !members.iter().any(|o| failed(o)));
    let ordered: Vec<&Outcome> = groups.iter().flatten().copied().collect();
    let cells: Vec<Vec<String>> = ordered
        .iter()
        .map(|o| {
            vec![
                status_name(o.status).into(),
                o.id.clone(),
                error_cell(o),
                tolerance_cell(o),
                format!("{:.3}", o.wall_time_s),
            ]
        })
        .collect();
    let table = fitted_table(&columns, &cells, width);
    let mut s = format!("{}\n{}\n", table.header, table.rule);
    let mut lines = table.rows.iter();
    for members in &groups {
        let n_failed = members.iter().filter(|o| failed(o)).count();
        let summary = format!(
            "{}: {} passed{}",
            members[0].check,
            members.len() - n_failed,
            if n_failed > 0 {
                format!(", {n_failed} FAILED")
            } else {
                String::new()
            }
        );
        s.push_str(&format!(
            "\n{}\n",
            crate::output::ellipsize(&summary, width)
        ));
        for line in lines.by_ref().take(members.len()) {
            s.push_str(line);
            s.push('\n');
        }
    }
    let failures: Vec<&&Outcome> = ordered.iter().filter(|o| failed(o)).collect();
    if !failures.is_empty() {
        s.push('\n');
        for o in failures {
            let text = format!("{} {}: {}", status_name(o.status), o.id, o.message);
            s.push_str(&wrap(&text, width, 4));
            s.push('\n');
        }
    }
    s
}

pub fn csv(outcomes: &[Outcome]) -> String {
    let mut header = HEADER.to_vec();
    header.push("why");
    header.push("message");
    let rows: Vec<Vec<String>> = rows(outcomes)
        .into_iter()
        .zip(outcomes)
        .map(|(mut r, o)| {
            r.push(o.why.clone());
            r.push(o.message.clone());
            r
        })
        .collect();
    csv_table(&header, &rows)
}

pub fn json(outcomes: &[Outcome]) -> String {
    serde_json::to_string_pretty(outcomes).expect("serializable outcomes")
}
