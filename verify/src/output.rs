//! Writing results: atomic files (temp file + rename) and table/JSON/CSV rendering.

use std::io::Write;
use std::path::{Path, PathBuf};

use data::{EnergyLedger, Event, Observables};

/// Output formats of the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum Format {
    Table,
    Json,
    Csv,
}

/// Writes `bytes` to `dir/name` atomically: a reader sees the old file or the complete new one,
/// never a partial write, even if the process dies mid-way.
pub fn write_atomic(dir: &Path, name: &str, bytes: &[u8]) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let target = dir.join(name);
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
    }
    std::fs::rename(&tmp, &target)?;
    Ok(target)
}

/// Observables as CSV: `time,<channel>...`.
pub fn observables_csv(obs: &Observables) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["time".to_string()];
    header.extend(obs.channels.iter().map(|c| c.name.clone()));
    w.write_record(&header).expect("in-memory csv");
    for (k, t) in obs.time.iter().enumerate() {
        let mut row = vec![format!("{t:.9e}")];
        row.extend(obs.channels.iter().map(|c| format!("{:.9e}", c.values[k])));
        w.write_record(&row).expect("in-memory csv");
    }
    String::from_utf8(w.into_inner().expect("in-memory csv")).expect("utf8")
}

/// Header of [`switching_rows`].
pub const SWITCHING_HEADER: [&str; 8] = [
    "t",
    "event",
    "contact",
    "impulse",
    "kinetic energy lost",
    "momentum residual",
    "normal force",
    "time tolerance",
];

/// The contact switching history (contact start, impact, release, stick/slip), one row per
/// event in time order; columns that do not apply to an event are `-`.
pub fn switching_rows(events: &[Event]) -> Vec<Vec<String>> {
    let dash = || "-".to_string();
    let e = |x: f64| format!("{x:.9e}");
    events
        .iter()
        .filter_map(|ev| match ev {
            Event::ContactStart {
                t,
                contact,
                time_tolerance,
            } => Some(vec![
                e(*t),
                "contact".into(),
                contact.to_string(),
                dash(),
                dash(),
                dash(),
                dash(),
                format!("{time_tolerance:.1e}"),
            ]),
            Event::Impact {
                t,
                contact,
                impulse,
                momentum_residual,
                kinetic_energy_lost,
                ..
            } => Some(vec![
                e(*t),
                "impact".into(),
                contact.to_string(),
                e(*impulse),
                e(*kinetic_energy_lost),
                format!("{momentum_residual:.2e}"),
                dash(),
                dash(),
            ]),
            Event::Release {
                t,
                contact,
                normal_force,
                time_tolerance,
            } => Some(vec![
                e(*t),
                "release".into(),
                contact.to_string(),
                dash(),
                dash(),
                dash(),
                format!("{normal_force:.2e}"),
                format!("{time_tolerance:.1e}"),
            ]),
            Event::StickSlip {
                t,
                contact,
                sticking,
            } => Some(vec![
                e(*t),
                if *sticking { "stick" } else { "slip" }.into(),
                contact.to_string(),
                dash(),
                dash(),
                dash(),
                dash(),
                dash(),
            ]),
            Event::StepSizeChange { .. } | Event::StepRejected { .. } => None,
        })
        .collect()
}

/// The energy ledger as CSV with the closure residual in the last column.
pub fn ledger_csv(ledger: &EnergyLedger) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["time".to_string()];
    header.extend(ledger.stored.iter().map(|t| format!("stored:{}", t.name)));
    header.extend(ledger.inputs.iter().map(|t| format!("input:{}", t.name)));
    header.extend(
        ledger
            .dissipation
            .iter()
            .map(|t| format!("dissipated:{}", t.name)),
    );
    header.push("residual".into());
    w.write_record(&header).expect("in-memory csv");
    for (k, t) in ledger.time.iter().enumerate() {
        let mut row = vec![format!("{t:.9e}")];
        for terms in [&ledger.stored, &ledger.inputs, &ledger.dissipation] {
            row.extend(terms.iter().map(|term| format!("{:.9e}", term.values[k])));
        }
        row.push(format!("{:.3e}", ledger.residual(k)));
        w.write_record(&row).expect("in-memory csv");
    }
    String::from_utf8(w.into_inner().expect("in-memory csv")).expect("utf8")
}

/// A plain text table with right-aligned columns.
pub fn text_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let n = header.len();
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (i, c) in r.iter().enumerate().take(n) {
            width[i] = width[i].max(c.chars().count());
        }
    }
    let fmt_row = |cells: Vec<&str>| {
        cells
            .iter()
            .enumerate()
            .map(|(i, c)| format!("{:>w$}", c, w = width[i]))
            .collect::<Vec<_>>()
            .join("  ")
    };
    let mut out = fmt_row(header.to_vec());
    out.push('\n');
    out.push_str(
        &width
            .iter()
            .map(|w| "-".repeat(*w))
            .collect::<Vec<_>>()
            .join("  "),
    );
    out.push('\n');
    for r in rows {
        out.push_str(&fmt_row(r.iter().map(|s| s.as_str()).collect()));
        out.push('\n');
    }
    out
}

/// CSV text of a header and rows.
pub fn csv_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(header).expect("in-memory csv");
    for r in rows {
        w.write_record(r).expect("in-memory csv");
    }
    String::from_utf8(w.into_inner().expect("in-memory csv")).expect("utf8")
}
