//! `flexverify coverage`: which backends run each catalog scene and which checks cover it.
//!
//! Nothing here is a hand-typed table. Which backends run a scene is each backend's own answer
//! ([`capability`]): its [`data::Backend::dof_plan`] (what `describe` prints) and a run over the
//! first output interval, either of which says `unsupported` when the backend does not
//! integrate the scene. The check kind of a row of `data/cases/*.toml` is derived
//! from the row itself, its reference and its quantity ([`row_kinds`]); the rows of
//! `data/cases/stability.toml` are stability checks of the backends they list.
//!
//! # Enforced
//! * **Cross-history**: every pair of backends that run a scene is linked by a chain of rows
//!   comparing a *whole history* (`history:` or `lowpassF:history:`) of a frame-invariant
//!   observable ([`data::channel::frame_invariant`]) between two backends. A chain suffices: agreement of A
//!   with B and of B with C within their tolerances bounds A against C by the sum.
//! * **Convergence**: every backend that runs a scene has an order, Richardson or monotone row
//!   on it.
//!
//! Rows with `overrides` check a modified scene (a stiff limit, say): they are listed but do
//! not count for the two enforced kinds. A gap is allowed only when listed, with its reason, in
//! `data/cases/coverage-exceptions.toml` ([`data::coverage`]); an exception that names no
//! catalog scene, or that no longer matches a gap, is itself reported, so the list only shrinks.

use std::collections::{BTreeMap, BTreeSet};

use data::cases::{Case, Reference, StabilityCase};
use data::coverage::{CoverageException, MissingCheck};
use data::{BackendError, BackendKind, Discretization, Scene};
use serde::Serialize;

use crate::suite::quantity::Quantity;

/// What a verification row checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CheckKind {
    /// A value against a reference computed by code from the scene (limits, closed forms).
    Analytic,
    /// A whole history of a frame-invariant observable against another backend's.
    CrossHistory,
    /// A value at one time (or a frame-dependent history) against another backend's.
    CrossPoint,
    /// Observed order, Richardson extrapolation or Rayleigh–Ritz monotonicity over a ladder.
    Convergence,
    /// Energy-ledger closure of one run.
    LedgerClosure,
    /// An energy-ledger term's history against another backend's.
    LedgerTerms,
    /// Impact impulse, momentum balance, impact and contact-episode times.
    ImpactMomentum,
    /// Natural frequencies.
    Frequencies,
    /// A stiff or extreme case of `data/cases/stability.toml`.
    Stability,
}

impl CheckKind {
    pub const ALL: [CheckKind; 9] = [
        CheckKind::Analytic,
        CheckKind::CrossHistory,
        CheckKind::CrossPoint,
        CheckKind::Convergence,
        CheckKind::LedgerClosure,
        CheckKind::LedgerTerms,
        CheckKind::ImpactMomentum,
        CheckKind::Frequencies,
        CheckKind::Stability,
    ];

    /// The short column heading of the coverage table (the table fits 120 columns).
    pub fn column(self) -> &'static str {
        match self {
            CheckKind::Analytic => "analytic",
            CheckKind::CrossHistory => "x-hist",
            CheckKind::CrossPoint => "x-point",
            CheckKind::Convergence => "conv",
            CheckKind::LedgerClosure => "ledger",
            CheckKind::LedgerTerms => "terms",
            CheckKind::ImpactMomentum => "impact",
            CheckKind::Frequencies => "freq",
            CheckKind::Stability => "stab",
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            CheckKind::Analytic => "analytic",
            CheckKind::CrossHistory => "cross-history",
            CheckKind::CrossPoint => "cross-point",
            CheckKind::Convergence => "convergence",
            CheckKind::LedgerClosure => "ledger",
            CheckKind::LedgerTerms => "ledger-terms",
            CheckKind::ImpactMomentum => "impact",
            CheckKind::Frequencies => "frequencies",
            CheckKind::Stability => "stability",
        }
    }
}

/// The check kinds a row performs and, for each, the backends it covers (the row's backend,
/// and the reference backend for cross rows).
pub fn row_kinds(case: &Case, scene: &Scene) -> Vec<(CheckKind, Vec<BackendKind>)> {
    let q = Quantity::parse(&case.quantity, scene).ok();
    let own = vec![case.backend];
    let mut kinds = Vec::new();
    if matches!(q, Some(Quantity::Frequency { .. })) {
        let mut b = own.clone();
        if let Reference::Backend { backend, .. } = &case.reference {
            b.push(*backend);
        }
        kinds.push((CheckKind::Frequencies, b));
    }
    if matches!(
        q,
        Some(
            Quantity::MaxMomentumResidual
                | Quantity::Impulse { .. }
                | Quantity::ImpulseExcess { .. }
                | Quantity::ImpactTime { .. }
                | Quantity::ReleaseTime { .. }
                | Quantity::Episode { .. }
        )
    ) {
        let mut b = own.clone();
        if let Reference::Backend { backend, .. } = &case.reference {
            b.push(*backend);
        }
        kinds.push((CheckKind::ImpactMomentum, b));
    }
    if matches!(q, Some(Quantity::LedgerClosure)) {
        kinds.push((CheckKind::LedgerClosure, own.clone()));
    }
    match &case.reference {
        Reference::Analytic { .. } => kinds.push((CheckKind::Analytic, own)),
        Reference::Order { against, .. } => {
            kinds.push((CheckKind::Convergence, own.clone()));
            if against.is_some() {
                kinds.push((CheckKind::Analytic, own));
            }
        }
        Reference::Monotone { .. } => {
            kinds.push((CheckKind::Convergence, own.clone()));
            kinds.push((CheckKind::Analytic, own));
        }
        Reference::Richardson { .. } => kinds.push((CheckKind::Convergence, own)),
        // A run against the same backend on a variant of the scene (a decoupling claim) is no
        // cross-check between backends.
        Reference::Backend { overrides, .. } if !overrides.is_empty() => {}
        Reference::Backend { backend, .. } => {
            let pair = vec![case.backend, *backend];
            match &q {
                Some(Quantity::History { channel, .. })
                    if data::channel::frame_invariant(channel) =>
                {
                    if channel.starts_with(data::cases::ENERGY_PREFIX) {
                        kinds.push((CheckKind::LedgerTerms, pair.clone()));
                    }
                    kinds.push((CheckKind::CrossHistory, pair));
                }
                _ => kinds.push((CheckKind::CrossPoint, pair)),
            }
        }
        Reference::Zero { .. } => {}
    }
    kinds
}

/// What one backend answers about one scene.
#[derive(Debug, Clone, Serialize)]
pub struct Capability {
    pub backend: BackendKind,
    /// `None` when the backend runs the scene; otherwise its `unsupported` message.
    pub unsupported: Option<String>,
}

/// The rows covering one scene by one check kind, and the backends they cover.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Cell {
    /// (row id, backends covered, the row checks a modified scene).
    pub rows: Vec<(String, Vec<BackendKind>, bool)>,
}

/// A gap in the enforced checks of one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gap {
    pub scene: String,
    pub missing: MissingCheck,
    /// The backend pair (cross-history) or the single backend (convergence).
    pub backends: Vec<BackendKind>,
    /// The reason, when an exception lists the gap.
    pub excused_by: Option<String>,
}

/// Coverage of one catalog scene.
#[derive(Debug, Clone, Serialize)]
pub struct SceneCoverage {
    pub scene: String,
    pub capabilities: Vec<Capability>,
    pub cells: BTreeMap<CheckKind, Cell>,
    pub gaps: Vec<Gap>,
}

impl SceneCoverage {
    pub fn runners(&self) -> Vec<BackendKind> {
        self.capabilities
            .iter()
            .filter(|c| c.unsupported.is_none())
            .map(|c| c.backend)
            .collect()
    }
}

/// The whole analysis.
#[derive(Debug, Clone, Serialize)]
pub struct Coverage {
    pub scenes: Vec<SceneCoverage>,
    /// Exceptions that name no catalog scene or match no gap (each an error).
    pub stale_exceptions: Vec<(CoverageException, String)>,
}

impl Coverage {
    /// Gaps that no exception excuses.
    pub fn unexcused(&self) -> impl Iterator<Item = &Gap> {
        self.scenes
            .iter()
            .flat_map(|s| &s.gaps)
            .filter(|g| g.excused_by.is_none())
    }
}

/// Why coverage cannot be computed.
#[derive(Debug, thiserror::Error)]
pub enum CoverageError {
    #[error("error: {0}")]
    Cases(#[from] data::SceneError),
    #[error("error: {0}")]
    Scene(#[from] data::LoadError),
    #[error("error: {backend} cannot plan `{scene}`: {error}")]
    Backend {
        scene: String,
        backend: BackendKind,
        error: BackendError,
    },
}

/// Whether a backend runs (integrates in time) a scene, from its own answers: `dof_plan`, and
/// then a run over the first output interval only, since a backend may plan a scene's DOFs
/// (for `modes`, `statics`) yet not integrate it. Only `unsupported` means "does not run";
/// another error of the short probe is a matter of settings, not of capability.
pub fn capability(scene: &Scene, backend: BackendKind) -> Result<Capability, CoverageError> {
    let b = crate::registry::backend(backend);
    let unsupported = |why: String| {
        Ok(Capability {
            backend,
            unsupported: Some(why),
        })
    };
    match b.dof_plan(scene, &Discretization::default()) {
        Ok(_) => {}
        Err(BackendError::Unsupported(why)) => return unsupported(why),
        Err(error) => {
            return Err(CoverageError::Backend {
                scene: scene.name.clone(),
                backend,
                error,
            });
        }
    }
    let mut probe = data::Settings::default();
    probe.time.t_end = Some(scene.simulation.output_interval.min(scene.simulation.t_end));
    match b.simulate(scene, &probe) {
        Err(BackendError::Unsupported(why)) => unsupported(why),
        _ => Ok(Capability {
            backend,
            unsupported: None,
        }),
    }
}

/// Backend pairs of `runners` not linked by a chain of the given edges.
fn unlinked_pairs(
    runners: &[BackendKind],
    edges: &[(BackendKind, BackendKind)],
) -> Vec<(BackendKind, BackendKind)> {
    // Union–find over three backends at most: repeated relaxation is enough.
    let mut root: BTreeMap<BackendKind, BackendKind> = runners.iter().map(|b| (*b, *b)).collect();
    let mut changed = true;
    while changed {
        changed = false;
        for (a, b) in edges {
            let (Some(&ra), Some(&rb)) = (root.get(a), root.get(b)) else {
                continue;
            };
            if ra != rb {
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                for r in root.values_mut() {
                    if *r == hi {
                        *r = lo;
                        changed = true;
                    }
                }
            }
        }
    }
    let mut out = Vec::new();
    for (i, a) in runners.iter().enumerate() {
        for b in &runners[i + 1..] {
            if root[a] != root[b] {
                out.push((*a, *b));
            }
        }
    }
    out
}

/// Coverage of every catalog scene by the given rows and exceptions.
pub fn analyse(
    cases: &[Case],
    stability: &[StabilityCase],
    exceptions: &[CoverageException],
) -> Result<Coverage, CoverageError> {
    let mut scenes = Vec::new();
    let mut used = vec![false; exceptions.len()];
    for name in data::catalog_names() {
        let scene = data::load_scene(name)?;
        let capabilities = BackendKind::ALL
            .iter()
            .map(|b| capability(&scene, *b))
            .collect::<Result<Vec<_>, _>>()?;
        let mut cells: BTreeMap<CheckKind, Cell> = BTreeMap::new();
        for case in cases.iter().filter(|c| c.scene == name) {
            for (kind, backends) in row_kinds(case, &scene) {
                cells.entry(kind).or_default().rows.push((
                    case.id.clone(),
                    backends,
                    !case.overrides.is_empty(),
                ));
            }
        }
        for s in stability.iter().filter(|s| s.scene == name) {
            cells.entry(CheckKind::Stability).or_default().rows.push((
                s.id.clone(),
                s.backends.clone(),
                !s.overrides.is_empty(),
            ));
        }
        let mut cov = SceneCoverage {
            scene: name.to_string(),
            capabilities,
            cells,
            gaps: Vec::new(),
        };
        let runners = cov.runners();
        let counted = |kind: CheckKind| -> Vec<&Vec<BackendKind>> {
            cov.cells.get(&kind).map_or(Vec::new(), |c| {
                c.rows
                    .iter()
                    .filter(|(_, _, modified)| !modified)
                    .map(|(_, b, _)| b)
                    .collect()
            })
        };
        let edges: Vec<(BackendKind, BackendKind)> = counted(CheckKind::CrossHistory)
            .into_iter()
            .filter_map(|b| match b.as_slice() {
                [a, c] if a != c => Some((*a, *c)),
                _ => None,
            })
            .collect();
        let mut gaps: Vec<Gap> = unlinked_pairs(&runners, &edges)
            .into_iter()
            .map(|(a, b)| Gap {
                scene: name.to_string(),
                missing: MissingCheck::CrossHistory,
                backends: vec![a, b],
                excused_by: None,
            })
            .collect();
        let converging: BTreeSet<BackendKind> = counted(CheckKind::Convergence)
            .into_iter()
            .flatten()
            .copied()
            .collect();
        gaps.extend(
            runners
                .iter()
                .filter(|b| !converging.contains(b))
                .map(|b| Gap {
                    scene: name.to_string(),
                    missing: MissingCheck::Convergence,
                    backends: vec![*b],
                    excused_by: None,
                }),
        );
        for gap in &mut gaps {
            for (i, x) in exceptions.iter().enumerate() {
                let applies = x.scene == gap.scene
                    && x.missing == gap.missing
                    && match gap.missing {
                        MissingCheck::CrossHistory => match x.backends.as_slice() {
                            [one] => gap.backends.contains(one),
                            listed => gap.backends.iter().all(|b| listed.contains(b)),
                        },
                        MissingCheck::Convergence => x.backends.contains(&gap.backends[0]),
                    };
                if applies {
                    used[i] = true;
                    if gap.excused_by.is_none() {
                        gap.excused_by = Some(x.reason.clone());
                    }
                }
            }
        }
        cov.gaps = gaps;
        scenes.push(cov);
    }
    let stale_exceptions = exceptions
        .iter()
        .zip(&used)
        .filter(|(_, u)| !**u)
        .map(|(x, _)| {
            let why = if data::catalog_scene(&x.scene).is_none() {
                format!("`{}` is not a catalog scene", x.scene)
            } else {
                format!(
                    "no {} gap of {} on `{}` remains: remove the exception",
                    x.missing.name(),
                    names(&x.backends),
                    x.scene
                )
            };
            (x.clone(), why)
        })
        .collect();
    Ok(Coverage {
        scenes,
        stale_exceptions,
    })
}

/// The embedded rows, stability cases and exceptions.
pub fn analyse_embedded() -> Result<Coverage, CoverageError> {
    analyse(
        &data::cases::all_cases()?,
        &data::cases::stability_cases()?,
        &data::coverage::coverage_exceptions()?,
    )
}

fn names(b: &[BackendKind]) -> String {
    b.iter().map(|b| b.name()).collect::<Vec<_>>().join("+")
}

fn pad_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: Vec<String>| {
        let mut s = String::new();
        for (k, (c, w)) in cells.iter().zip(&width).enumerate() {
            if k > 0 {
                s.push_str("  ");
            }
            s.push_str(c);
            if k + 1 < cells.len() {
                s.push_str(&" ".repeat(w - c.chars().count()));
            }
        }
        s.push('\n');
        s
    };
    let mut out = line(header.iter().map(|h| h.to_string()).collect());
    for r in rows {
        out.push_str(&line(r.clone()));
    }
    out
}

/// The report: a summary table (scene × check kind: number of rows; `GAP` / `exc` on the
/// enforced kinds), the gaps with their exceptions, then every row id by scene and kind.
pub fn report(c: &Coverage) -> String {
    let mut header = vec!["scene", "runs"];
    header.extend(CheckKind::ALL.iter().map(|k| k.column()));
    let mut rows = Vec::new();
    for s in &c.scenes {
        let mut r = vec![s.scene.clone(), names(&s.runners())];
        for kind in CheckKind::ALL {
            let n = s.cells.get(&kind).map_or(0, |c| c.rows.len());
            let enforced = match kind {
                CheckKind::CrossHistory => Some(MissingCheck::CrossHistory),
                CheckKind::Convergence => Some(MissingCheck::Convergence),
                _ => None,
            };
            let gaps: Vec<&Gap> = s
                .gaps
                .iter()
                .filter(|g| Some(g.missing) == enforced)
                .collect();
            let mark = if gaps.iter().any(|g| g.excused_by.is_none()) {
                " GAP"
            } else if !gaps.is_empty() {
                " exc"
            } else {
                ""
            };
            r.push(if n == 0 && mark.is_empty() {
                "-".into()
            } else {
                format!("{n}{mark}")
            });
        }
        rows.push(r);
    }
    let mut out = pad_table(&header, &rows);
    let gaps: Vec<&Gap> = c.scenes.iter().flat_map(|s| &s.gaps).collect();
    let gap_line = |g: &Gap| {
        format!(
            "  {:<28} {:<13} {}\n",
            g.scene,
            g.missing.name(),
            names(&g.backends)
        )
    };
    let open: Vec<&&Gap> = gaps.iter().filter(|g| g.excused_by.is_none()).collect();
    if !open.is_empty() {
        out.push_str(
            "\nGAP: not covered by a row and not listed in data/cases/coverage-exceptions.toml\n",
        );
        for g in open {
            out.push_str(&gap_line(g));
        }
    }
    // Listed gaps grouped by their reason, each reason printed once.
    let mut reasons: Vec<&str> = Vec::new();
    for g in &gaps {
        if let Some(r) = g.excused_by.as_deref()
            && !reasons.contains(&r)
        {
            reasons.push(r);
        }
    }
    if !reasons.is_empty() {
        out.push_str("\nexc: listed gaps (data/cases/coverage-exceptions.toml), by reason\n");
    }
    for r in reasons {
        out.push_str(&format!("- {r}\n"));
        for g in gaps.iter().filter(|g| g.excused_by.as_deref() == Some(r)) {
            out.push_str(&gap_line(g));
        }
    }
    for (x, why) in &c.stale_exceptions {
        out.push_str(&format!(
            "  STALE exception {} {} {}: {why}\n",
            x.scene,
            x.missing.name(),
            names(&x.backends)
        ));
    }
    out.push_str(&format!(
        "\ncolumns: {}\n",
        CheckKind::ALL
            .iter()
            .filter(|k| k.column() != k.name())
            .map(|k| format!("{} = {}", k.column(), k.name()))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    out.push_str("\nrows by scene and kind (* = row on a modified scene, not counted for gaps)\n");
    for s in &c.scenes {
        out.push_str(&format!("{}\n", s.scene));
        for (kind, cell) in &s.cells {
            let ids: Vec<String> = cell
                .rows
                .iter()
                .map(|(id, _, modified)| format!("{id}{}", if *modified { "*" } else { "" }))
                .collect();
            out.push_str(&format!("  {:<14} {}\n", kind.name(), ids.join(", ")));
        }
        for cap in &s.capabilities {
            if let Some(why) = &cap.unsupported {
                out.push_str(&format!(
                    "  {:<14} {}\n",
                    format!("no {}", cap.backend),
                    why
                ));
            }
        }
    }
    out.lines()
        .map(|l| crate::output::wrap(l, crate::output::TERMINAL_WIDTH, 4) + "\n")
        .collect()
}
