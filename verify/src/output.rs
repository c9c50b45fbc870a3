//! Writing results: atomic files (temp file + rename) and table/JSON/CSV rendering.
//!
//! Terminal tables come in two widths: [`fitted_table`] fits [`TERMINAL_WIDTH`] columns (one
//! elastic column, e.g. a case id, gives way and is cut with `…` only when needed), and
//! [`text_table`] keeps every column at full width (`--format wide`).

use std::io::Write;
use std::path::{Path, PathBuf};

use data::{EnergyLedger, Event, Observables};

/// Output formats of the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Format {
    /// A table that fits a [`TERMINAL_WIDTH`]-column terminal.
    Table,
    /// Every column at full width.
    Wide,
    Json,
    Csv,
}

/// Width (characters) the default terminal output fits.
pub const TERMINAL_WIDTH: usize = 120;

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

/// Alignment of a [`Column`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    Left,
    Right,
}

/// A column of a [`fitted_table`].
#[derive(Debug, Clone, Copy)]
pub struct Column<'a> {
    pub header: &'a str,
    pub align: Align,
    /// The column that gives way when the table is wider than the limit (at most one per
    /// table; its cells are cut with `…`).
    pub elastic: bool,
}

impl<'a> Column<'a> {
    pub fn left(header: &'a str) -> Self {
        Column {
            header,
            align: Align::Left,
            elastic: false,
        }
    }
    pub fn right(header: &'a str) -> Self {
        Column {
            header,
            align: Align::Right,
            elastic: false,
        }
    }
    /// The same column, elastic.
    pub fn elastic(self) -> Self {
        Column {
            elastic: true,
            ..self
        }
    }
}

/// A table laid out for a width: the header, its rule and one line per row (so callers can
/// interleave group headings between rows that share the column widths).
#[derive(Debug, Clone)]
pub struct FittedTable {
    pub header: String,
    pub rule: String,
    pub rows: Vec<String>,
}

impl std::fmt::Display for FittedTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.header)?;
        writeln!(f, "{}", self.rule)?;
        for r in &self.rows {
            writeln!(f, "{r}")?;
        }
        Ok(())
    }
}

/// `s` cut to `width` characters, the last one `…` when anything was cut.
pub fn ellipsize(s: &str, width: usize) -> String {
    if s.chars().count() <= width {
        s.to_string()
    } else if width == 0 {
        String::new()
    } else {
        let mut out: String = s.chars().take(width - 1).collect();
        out.push('…');
        out
    }
}

/// Columns separated by two spaces, each as wide as its widest cell; if that exceeds
/// `max_width`, the elastic column shrinks (not below its header) and its long cells end in `…`.
/// Other columns are never cut.
pub fn fitted_table(columns: &[Column<'_>], rows: &[Vec<String>], max_width: usize) -> FittedTable {
    let n = columns.len();
    let mut width: Vec<usize> = columns.iter().map(|c| c.header.chars().count()).collect();
    for r in rows {
        for (i, c) in r.iter().enumerate().take(n) {
            width[i] = width[i].max(c.chars().count());
        }
    }
    let total = width.iter().sum::<usize>() + 2 * n.saturating_sub(1);
    if total > max_width
        && let Some(e) = columns.iter().position(|c| c.elastic)
    {
        let floor = columns[e].header.chars().count();
        width[e] = width[e].saturating_sub(total - max_width).max(floor);
    }
    let line = |cells: &mut dyn Iterator<Item = &str>| {
        let mut out = String::new();
        for (i, c) in cells.enumerate().take(n) {
            if i > 0 {
                out.push_str("  ");
            }
            let c = ellipsize(c, width[i]);
            match columns[i].align {
                Align::Left => out.push_str(&format!("{c:<w$}", w = width[i])),
                Align::Right => out.push_str(&format!("{c:>w$}", w = width[i])),
            }
        }
        out.trim_end().to_string()
    };
    FittedTable {
        header: line(&mut columns.iter().map(|c| c.header)),
        rule: width
            .iter()
            .map(|w| "-".repeat(*w))
            .collect::<Vec<_>>()
            .join("  "),
        rows: rows
            .iter()
            .map(|r| line(&mut r.iter().map(|s| s.as_str())))
            .collect(),
    }
}

/// `text` broken at spaces into lines of at most `width` characters, every continuation line
/// indented by `indent` spaces. Lines that fit are left exactly as they are (alignment
/// spaces included); a single word longer than a line stays whole.
pub fn wrap(text: &str, width: usize, indent: usize) -> String {
    let mut out = Vec::new();
    for (k, line) in text.split('\n').enumerate() {
        let mut rest: Vec<char> = line.chars().collect();
        let mut pad = if k > 0 { indent } else { 0 };
        loop {
            if pad + rest.len() <= width {
                out.push(format!(
                    "{}{}",
                    " ".repeat(pad),
                    rest.iter().collect::<String>()
                ));
                break;
            }
            // The last space that keeps the line within the width, else the first space.
            let limit = width.saturating_sub(pad);
            let lead = rest.iter().take_while(|c| **c == ' ').count();
            let cut = rest[..=limit.min(rest.len() - 1)]
                .iter()
                .rposition(|c| *c == ' ')
                .filter(|&p| p > lead)
                .or_else(|| {
                    rest.iter()
                        .skip(lead)
                        .position(|c| *c == ' ')
                        .map(|p| p + lead)
                });
            let Some(cut) = cut else {
                out.push(format!(
                    "{}{}",
                    " ".repeat(pad),
                    rest.iter().collect::<String>()
                ));
                break;
            };
            let head: String = rest[..cut].iter().collect();
            out.push(format!("{}{}", " ".repeat(pad), head.trim_end()));
            let skip = rest[cut..].iter().take_while(|c| **c == ' ').count();
            rest.drain(..cut + skip);
            pad = indent;
            if rest.is_empty() {
                break;
            }
        }
    }
    out.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_table_cuts_only_the_elastic_column() {
        let columns = [
            Column::left("status"),
            Column::left("case").elastic(),
            Column::right("error"),
        ];
        let long = "x".repeat(200);
        let rows = vec![
            vec!["FAIL".to_string(), long.clone(), "1.00e-3".to_string()],
            vec![
                "pass".to_string(),
                "short".to_string(),
                "2.00e-9".to_string(),
            ],
        ];
        let t = fitted_table(&columns, &rows, 40);
        for l in std::iter::once(&t.header).chain(&t.rows) {
            assert!(l.chars().count() <= 40, "{l}");
        }
        assert!(t.rows[0].starts_with("FAIL    xxx") && t.rows[0].ends_with("…  1.00e-3"));
        assert!(t.rows[1].ends_with("2.00e-9"));
        // A table that fits is not cut.
        let t = fitted_table(&columns, &rows[1..], 40);
        assert_eq!(t.rows[0], "pass    short  2.00e-9");
    }

    #[test]
    fn wrap_breaks_at_spaces_and_indents() {
        let w = wrap("aaa bbb ccc ddd", 9, 2);
        assert_eq!(w, "aaa bbb\n  ccc ddd");
        for l in w.lines() {
            assert!(l.chars().count() <= 9);
        }
        assert_eq!(wrap("one\ntwo", 80, 4), "one\n    two");
        assert_eq!(wrap("  lead kept", 9, 4), "  lead\n    kept");
        // A line that fits keeps its alignment spaces.
        assert_eq!(wrap("a    b", 80, 4), "a    b");
        // A word longer than the width stays whole.
        assert_eq!(wrap("x abcdefghij y", 5, 2), "x\n  abcdefghij\n  y");
    }
}
