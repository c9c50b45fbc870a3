//! Verification cases as data (`data/cases/*.toml`): each row names a scene, a backend with its
//! settings, a quantity, a reference, a norm, a tolerance and the reason for that tolerance.
//!
//! ```toml
//! [[case]]
//! id = "freq-cantilever-fem-16"
//! check = "frequency vs analytic"
//! scene = "cantilever"
//! backend = "fem"
//! settings = { elements = 16 }
//! quantity = "freq4"
//! reference = { analytic = "clamped-free" }
//! norm = "relative"
//! tolerance = 1e-5
//! why = "Hermite cubics converge at O(h^4) in frequency; mode 4 at 16 elements is ~4e-6."
//! suite = "quick"
//! ```
//!
//! Quantity grammar (evaluated by `verify`): `freqN` (N-th natural frequency, Hz),
//! `axial_freqN` / `bending_freqN` (N-th of that kind), `tip_static` (static tip deflection),
//! `CHANNEL@T` (observable at time T; `tip_deflection`, `tip_x`, `tip_y` alias the last link's
//! channel), `peak:CHANNEL` (max |value| over the run), `ledger_closure` (relative energy-ledger
//! residual), `max_momentum_residual` (impacts), `impulseN`, `impulse_excessN` (Λ/(m_tip|v_n⁻|) − 1, with a tip
//! mass), `impact_timeN`, `release_timeN`,
//! `episode_startN:F` / `episode_endN:F` (contact events), and whole histories compared with a
//! reference backend's over the run, error max_t |a(t) − b(t)| / max_t |b(t)|:
//! * `history:CHANNEL` — the raw history; CHANNEL is an observable or `energy.NAME`, a term of
//!   the energy ledger (`energy.kinetic`, `energy.strain`, `energy.joint_damper`, …;
//!   `energy.total` is the stored sum);
//! * `lowpassF:history:CHANNEL` — both histories first put on one uniform grid and low-passed
//!   at F Hz (e.g. `lowpass20:history:joint1.angle`) by a zero-phase forward–backward
//!   second-order Butterworth filter (filtfilt: gain 1 at 0 Hz, ½ at F, no lag; ends extended
//!   by odd reflection, constants kept exactly); F must lie below the Nyquist frequency of the
//!   output interval. Design and edge handling: `verify::suite::filter`.
//!
//! A history quantity (raw or low-passed) may also be refined over a ladder of the case's own
//! backend: with an `order` reference the observed order of the successive whole-history
//! differences max_t |H_k − H_{k+1}| must match `order` (no `against`); with a `richardson`
//! reference the case's run is compared (`relative-to-peak`) with the pointwise Richardson
//! extrapolation of the ladder's histories. Design: `verify::suite::ladder`.

use serde::{Deserialize, Serialize};

use crate::backend::{BackendKind, Basis, FemElement};
use crate::error::SceneError;

/// Prefix of a `history:` channel that names a term of the energy ledger (`energy.NAME`).
pub const ENERGY_PREFIX: &str = "energy.";

/// A whole case file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseFile {
    #[serde(rename = "case")]
    pub cases: Vec<Case>,
}

/// Backend settings as written in a case (all optional; backend defaults otherwise).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSettings {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stations: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub basis: Option<Basis>,
    /// FEM element (`hermite-cubic` / `hermite-quintic`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<FemElement>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_end: Option<f64>,
    /// Overrides the scene's output interval (rows that low-pass a ringing history).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_interval: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<crate::Method>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safety_factor: Option<f64>,
}

impl CaseSettings {
    pub fn to_settings(&self) -> crate::Settings {
        crate::Settings {
            discretization: crate::Discretization {
                elements: self.elements,
                stations: self.stations,
                modes: self.modes,
                basis: self.basis,
                element: self.element,
            },
            time: crate::TimeStepping {
                dt: self.dt,
                t_end: self.t_end,
                output_interval: self.output_interval,
                method: self.method,
                rtol: self.rtol,
                atol: self.atol,
                safety_factor: self.safety_factor,
            },
        }
    }
}

/// What the computed quantity is compared against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum Reference {
    /// A closed form / root-finding / shooting reference computed by code (id, see verify).
    Analytic { analytic: String },
    /// The same quantity from another backend (cross-check), or — with `overrides` — from a
    /// backend on a variant of the case's scene (e.g. the same backend without gravity: a
    /// decoupling claim checked run against run). The overrides apply on top of the case's own.
    Backend {
        backend: BackendKind,
        #[serde(default)]
        settings: CaseSettings,
        #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
        overrides: std::collections::BTreeMap<String, toml::Value>,
    },
    /// Observed order of convergence over a refinement ladder; `order` is the theoretical
    /// value the least-squares fit of log error against log h must match. Errors are taken
    /// against the analytic reference `against` when given, otherwise against the Richardson
    /// extrapolation of the ladder.
    Order {
        order: f64,
        ladder: Vec<CaseSettings>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        against: Option<String>,
    },
    /// Richardson extrapolation from a ladder (the case's own settings are compared against
    /// the extrapolated value).
    Richardson { richardson: Vec<CaseSettings> },
    /// Rayleigh–Ritz bound: over the ladder the value must never increase (relative increase
    /// above the tolerance fails) and must stay above the analytic reference `above`.
    Monotone {
        decreasing: Vec<CaseSettings>,
        above: String,
    },
    /// Zero (residual quantities such as the ledger closure).
    Zero { zero: bool },
}

/// How the error is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Norm {
    /// |value − reference| / |reference|.
    Relative,
    /// |value − reference|.
    Absolute,
    /// |value − reference| / max |reference channel| over the run (time histories).
    RelativeToPeak,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SuiteName {
    Quick,
    Full,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    pub id: String,
    /// Which check of verification.md this row belongs to.
    pub check: String,
    pub scene: String,
    /// Field path (as in error messages, e.g. `link[0].bending_stiffness`) → new value: a
    /// catalog scene modified for this check (e.g. a stiff limit), validated like a user file.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub overrides: std::collections::BTreeMap<String, toml::Value>,
    pub backend: BackendKind,
    #[serde(default)]
    pub settings: CaseSettings,
    pub quantity: String,
    pub reference: Reference,
    pub norm: Norm,
    pub tolerance: f64,
    /// Why this tolerance: the discretization argument behind it.
    pub why: String,
    /// `quick` cases run in CI; `full` adds every rung of the refinement ladders.
    pub suite: SuiteName,
}

/// How a case row spells `field` in a refusal (`method = NAME` for the method).
fn case_key(field: crate::SettingField) -> &'static str {
    match field {
        crate::SettingField::Method => "method =",
        other => other.key(),
    }
}

impl Case {
    /// Every settings table of the row with the backend that runs it: the row's own, its
    /// ladders' rungs (run by the row's backend) and a reference backend's.
    pub fn settings_for_backends(&self) -> Vec<(String, BackendKind, &CaseSettings)> {
        let mut out = vec![("settings".to_string(), self.backend, &self.settings)];
        let (name, rungs): (&str, &[CaseSettings]) = match &self.reference {
            Reference::Backend {
                backend, settings, ..
            } => {
                out.push(("reference.settings".to_string(), *backend, settings));
                ("", &[])
            }
            Reference::Order { ladder, .. } => ("ladder", ladder),
            Reference::Richardson { richardson } => ("richardson", richardson),
            Reference::Monotone { decreasing, .. } => ("decreasing", decreasing),
            Reference::Analytic { .. } | Reference::Zero { .. } => ("", &[]),
        };
        out.extend(
            rungs
                .iter()
                .enumerate()
                .map(|(k, rung)| (format!("reference.{name}[{k}]"), self.backend, rung)),
        );
        out
    }
}

macro_rules! case_files {
    ($($name:literal),* $(,)?) => {
        /// (file name, TOML text) of every embedded case file.
        pub const CASE_FILES: &[(&str, &str)] = &[
            $(($name, include_str!(concat!("../cases/", $name, ".toml")))),*
        ];
    };
}

case_files!(
    "frequencies",
    "chain_modes",
    "statics",
    "dynamics",
    "rocket",
    "rocket_layers",
    "rocket_free_vibration",
    "convergence",
    "friction",
    "contact",
    "histories",
    "payload_link",
    "mobile",
    "mobile_flex",
    "mobile_flex_fem",
    "convergence_scenes",
    "contact_coverage",
    "two_link_rows"
);

/// Parses a case file with located errors.
pub fn parse_cases(text: &str, source_name: &str) -> Result<Vec<Case>, SceneError> {
    let file: CaseFile = toml::from_str(text).map_err(|e| {
        let (line, column) = crate::error::line_column(text, e.span().map_or(0, |s| s.start));
        SceneError {
            source_name: source_name.to_string(),
            line,
            column,
            path: "case".into(),
            message: e.message().trim().to_string(),
            expected: "a [[case]] table as documented in data/src/cases.rs".into(),
        }
    })?;
    for (i, c) in file.cases.iter().enumerate() {
        let bad = |path: &str, message: String, expected: &str| {
            let needle = format!("id = \"{}\"", c.id);
            let offset = text.find(&needle).unwrap_or(0);
            let (line, column) = crate::error::line_column(text, offset);
            SceneError {
                source_name: source_name.to_string(),
                line,
                column,
                path: format!("case[{i}].{path}"),
                message,
                expected: expected.into(),
            }
        };
        if !(c.tolerance.is_finite() && c.tolerance > 0.0) {
            return Err(bad(
                "tolerance",
                format!("{} is not positive", c.tolerance),
                "a finite number > 0",
            ));
        }
        if c.why.trim().is_empty() {
            return Err(bad(
                "why",
                "is empty".into(),
                "a sentence justifying the tolerance",
            ));
        }
        if crate::catalog::catalog_scene(&c.scene).is_none() {
            return Err(bad(
                "scene",
                format!("`{}` is not a catalog scene", c.scene),
                "a name from `flexverify scenes`",
            ));
        }
        for (path, backend, settings) in c.settings_for_backends() {
            let settings = settings.to_settings();
            if let Some(&field) = settings.unread_by(&[backend]).first() {
                let subject = format!("the row's backend {backend}");
                return Err(bad(
                    &format!("{path}.{field}"),
                    format!(
                        "row `{}`: {}",
                        c.id,
                        settings.refusal(field, case_key(field), &subject, false)
                    ),
                    "only settings the backend reads (see data::SettingField::readers)",
                ));
            }
        }
        if file.cases[..i].iter().any(|o| o.id == c.id) {
            return Err(bad(
                "id",
                format!("duplicate case id `{}`", c.id),
                "a unique id",
            ));
        }
    }
    Ok(file.cases)
}

/// All embedded cases, in file order.
pub fn all_cases() -> Result<Vec<Case>, SceneError> {
    let mut out = Vec::new();
    for (name, text) in CASE_FILES {
        out.extend(parse_cases(text, &format!("<cases>/{name}.toml"))?);
    }
    Ok(out)
}

/// A stiff or extreme case of verification.md §9: a catalog scene, optionally modified by
/// field overrides, run by each backend; the verdict is what is checked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StabilityCase {
    pub id: String,
    /// What makes this case hard.
    pub what: String,
    pub scene: String,
    /// Field path (as in error messages, e.g. `link[0].axial_stiffness`) → new value.
    #[serde(default)]
    pub overrides: std::collections::BTreeMap<String, toml::Value>,
    pub backends: Vec<BackendKind>,
    #[serde(default)]
    pub settings: CaseSettings,
    /// Also probe explicit schemes just below and just above their own stability bound.
    #[serde(default)]
    pub probe_bound: bool,
    /// The physics must diverge (e.g. spin-up without geometric stiffening): a small bounded
    /// answer is then wrong, while growth beyond `divergence_threshold` of `divergence_channel`
    /// (or a stop that reports it) is right.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expect_divergence: Option<Divergence>,
    pub suite: SuiteName,
}

/// What divergence looks like for a case that must diverge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Divergence {
    pub channel: String,
    /// Growth beyond this |value| counts as divergence (e.g. the link length).
    pub threshold: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StabilityFile {
    #[serde(rename = "stability")]
    cases: Vec<StabilityCase>,
}

/// The embedded stability cases (`data/cases/stability.toml`).
pub fn stability_cases() -> Result<Vec<StabilityCase>, SceneError> {
    let text = include_str!("../cases/stability.toml");
    let file: StabilityFile = toml::from_str(text).map_err(|e| {
        let (line, column) = crate::error::line_column(text, e.span().map_or(0, |s| s.start));
        SceneError {
            source_name: "<cases>/stability.toml".into(),
            line,
            column,
            path: "stability".into(),
            message: e.message().trim().to_string(),
            expected: "a [[stability]] table as documented in data/src/cases.rs".into(),
        }
    })?;
    for (i, c) in file.cases.iter().enumerate() {
        let settings = c.settings.to_settings();
        if let Some(&field) = settings.unread_by(&c.backends).first() {
            let names: Vec<&str> = c.backends.iter().map(|b| b.name()).collect();
            let subject = format!("the row's backends ({})", names.join(", "));
            let offset = text.find(&format!("id = \"{}\"", c.id)).unwrap_or(0);
            let (line, column) = crate::error::line_column(text, offset);
            return Err(SceneError {
                source_name: "<cases>/stability.toml".into(),
                line,
                column,
                path: format!("stability[{i}].settings.{field}"),
                message: format!(
                    "row `{}`: {}",
                    c.id,
                    settings.refusal(field, case_key(field), &subject, true)
                ),
                expected: "only settings one of the backends reads".into(),
            });
        }
    }
    Ok(file.cases)
}

/// Applies `path = value` overrides to a scene's TOML text and parses the result, so that a
/// modified scene is validated exactly like a user's file.
pub fn scene_with_overrides(
    name: &str,
    overrides: &std::collections::BTreeMap<String, toml::Value>,
) -> Result<crate::Scene, String> {
    let (_, text) = crate::CATALOG
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| format!("`{name}` is not a catalog scene"))?;
    let mut doc: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
    for (path, value) in overrides {
        set_path(&mut doc, path, value.clone())?;
    }
    let text = toml::to_string(&doc).map_err(|e| e.to_string())?;
    crate::parse_scene(&text, &format!("<catalog>/{name}.toml with overrides"))
        .map_err(|e| e.to_string())
}

fn set_path(doc: &mut toml::Table, path: &str, value: toml::Value) -> Result<(), String> {
    let mut segments: Vec<(String, Option<usize>)> = Vec::new();
    for part in path.split('.') {
        match part.split_once('[') {
            Some((key, idx)) => {
                let i: usize = idx
                    .trim_end_matches(']')
                    .parse()
                    .map_err(|_| format!("bad index in override path `{path}`"))?;
                segments.push((key.to_string(), Some(i)));
            }
            None => segments.push((part.to_string(), None)),
        }
    }
    let mut table = doc;
    let last = segments.len() - 1;
    for (k, (key, idx)) in segments.into_iter().enumerate() {
        if k == last && idx.is_none() {
            table.insert(key, value);
            return Ok(());
        }
        let entry = table
            .entry(key.clone())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let next = match idx {
            Some(i) => entry
                .as_array_mut()
                .and_then(|a| a.get_mut(i))
                .ok_or_else(|| format!("override path `{path}`: no element {key}[{i}]"))?,
            None => entry,
        };
        table = next
            .as_table_mut()
            .ok_or_else(|| format!("override path `{path}`: `{key}` is not a table"))?;
    }
    Ok(())
}
