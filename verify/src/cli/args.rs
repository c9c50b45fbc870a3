//! Argument definitions (clap derive). The library's selectors ([`Format`], [`Suite`],
//! [`Refine`]) know nothing of clap; their command-line spellings are defined here.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand, ValueEnum};
use data::{BackendKind, Settings};

use super::CliError;

pub use crate::output::Format;
pub use crate::study::ladder::Refine;
pub use crate::suite::Suite;

#[derive(Debug, Parser)]
#[command(
    name = "flexverify",
    version,
    about = "Verify discretizations of flexible multibody dynamics: FEM, the 1969 NASA \
             finite-difference scheme and assumed modes, cross-checked against each other and \
             against analytic limits."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the embedded scene catalog.
    Scenes {
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Show the physics a scene switches on and the DOFs each backend would build.
    Describe {
        /// Catalog name or path to a scene .toml file.
        scene: String,
        #[command(flatten)]
        opts: CommonOpts,
    },
    /// Natural frequencies (Hz) of a scene.
    Modes {
        scene: String,
        /// Number of frequencies to report.
        #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=200))]
        count: u32,
        #[command(flatten)]
        opts: CommonOpts,
    },
    /// Linear static response to the scene's `[statics]` loads.
    Statics {
        scene: String,
        #[command(flatten)]
        opts: CommonOpts,
    },
    /// Integrate a scene in time; print a summary and write observables, ledger and events.
    Run {
        scene: String,
        #[command(flatten)]
        opts: CommonOpts,
    },
    /// Compare two run outputs of one scene: contact-episode boundaries and whole histories.
    Compare {
        /// The run: a result JSON written by `run --out`, or the --out folder holding it.
        run: std::path::PathBuf,
        /// The reference it is measured against (same scene, any backend), given the same way.
        reference: std::path::PathBuf,
        /// Free flights shorter than this (seconds) merge two contact phases into one episode.
        #[arg(long, allow_hyphen_values = true, value_parser = positive_f64,
              default_value_t = crate::compare::DEFAULT_MIN_FLIGHT)]
        min_flight: f64,
        /// Compare only this history (repeatable): an observable channel, or a ledger term
        /// energy.NAME.
        #[arg(long)]
        channel: Vec<String>,
        /// Low-pass both histories at this cut-off (Hz; zero-phase Butterworth on one uniform
        /// grid) before comparing them, without one cut-off period at each end (the filtered
        /// ends pass through the raw end samples). Runs that ring above their samples' Nyquist
        /// frequency need a finer `run --output-interval` first.
        #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
        lowpass: Option<f64>,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Run the verification suite (checks declared as data in data/cases/).
    Verify {
        #[arg(long, value_enum, default_value_t = Suite::Quick)]
        suite: Suite,
        /// Run only cases whose id contains this text; in the full suite also only the
        /// refinement ladders whose id `ladder-<scene>` contains it (`--filter ladder-` runs
        /// the ladders alone).
        #[arg(long)]
        filter: Option<String>,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Run only shard I of N (I/N, 1 <= I <= N) of the selected cases and ladders and write its
        /// partial result (shard-I-of-N.json, plots) into --out; `flexverify merge` combines
        /// the N parts into the report of one unsharded run.
        #[arg(long, allow_hyphen_values = true, value_parser = parse_shard)]
        shard: Option<crate::shard::Shard>,
    },
    /// Combine the outputs of `verify --shard I/N` or `converge --shard I/N` (every shard
    /// exactly once) into what one unsharded run writes; exit 1 if any check failed.
    Merge {
        /// Folders holding shard-I-of-N.json files (one folder may hold several).
        #[arg(required = true)]
        dirs: Vec<std::path::PathBuf>,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        #[arg(long)]
        out: std::path::PathBuf,
    },
    /// Refinement study of one quantity: observed order, Richardson reference, work-precision.
    Converge {
        scene: String,
        /// e.g. freq1, tip_static, tip_deflection@15, joint1.angle@2.5, impulse1
        #[arg(long)]
        quantity: String,
        /// Refine space (elements/stations/modes), time (dt), or both together (space-time:
        /// each space rung with its step scaled like its spacing).
        #[arg(long, value_enum, default_value_t = Refine::Space)]
        refine: Refine,
        /// Measure only shard I of N of the rungs (all ladders, flattened) and write them
        /// (shard-I-of-N.json) into --out; `flexverify merge` builds the study from the N parts.
        #[arg(long, allow_hyphen_values = true, value_parser = parse_shard)]
        shard: Option<crate::shard::Shard>,
        #[command(flatten)]
        opts: CommonOpts,
    },
    /// Cheapest backend + discretization meeting a tolerance on a quantity.
    Recommend {
        scene: String,
        #[arg(long)]
        quantity: String,
        /// Relative tolerance the quantity must meet.
        #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
        tol: f64,
        /// Refine space (elements/stations/modes), time (dt, at the mesh given or the
        /// backend's default) or both together (space-time): switching times of contact scenes
        /// are set by the step, which a space ladder keeps fixed.
        #[arg(long, value_enum, default_value_t = Refine::Space)]
        refine: Refine,
        /// Wall-time budget per rung in seconds: a backend's ladder stops after the first rung
        /// that took longer (the next would cost several times more), and the answer says so.
        #[arg(long, value_parser = positive_f64, default_value_t = crate::study::recommend::DEFAULT_RUNG_BUDGET_S)]
        rung_budget: f64,
        #[command(flatten)]
        opts: CommonOpts,
    },
    /// Which backends run each catalog scene and which checks (row ids) cover it; fails on a
    /// gap not listed in data/cases/coverage-exceptions.toml.
    Coverage {
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Stiff and extreme cases: each backend's verdict.
    Stability {
        #[arg(long, value_enum, default_value_t = Suite::Quick)]
        suite: Suite,
        /// Run only cases whose id or scene contains this text.
        #[arg(long)]
        filter: Option<String>,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
}

impl ValueEnum for Format {
    fn value_variants<'a>() -> &'a [Self] {
        &[Format::Table, Format::Wide, Format::Json, Format::Csv]
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(match self {
            Format::Table => PossibleValue::new("table").help("a table that fits 120 columns"),
            Format::Wide => PossibleValue::new("wide").help("every column at full width"),
            Format::Json => PossibleValue::new("json"),
            Format::Csv => PossibleValue::new("csv"),
        })
    }
}

impl ValueEnum for Suite {
    fn value_variants<'a>() -> &'a [Self] {
        &[Suite::Quick, Suite::Full]
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(match self {
            Suite::Quick => "quick",
            Suite::Full => "full",
        }))
    }
}

impl ValueEnum for Refine {
    fn value_variants<'a>() -> &'a [Self] {
        &[Refine::Space, Refine::Time, Refine::SpaceTime]
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.name()))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BackendChoice {
    Fem,
    Fdm,
    Modal,
    /// verify's rigid reference (mobile manipulator scenes).
    Reference,
    All,
}

impl CommonOpts {
    /// The chosen backends, each once, in catalog order (`all` means the three
    /// discretizations; the reference only when named).
    pub fn kinds(&self) -> Vec<data::BackendKind> {
        self.chosen_kinds(false)
    }

    /// The chosen backends for a scene: `all` also takes verify's rigid reference when the
    /// scene's family has one (the mobile manipulator).
    pub fn kinds_for(&self, scene: &data::Scene) -> Vec<data::BackendKind> {
        self.chosen_kinds(scene.family() == data::Family::MobileManipulator)
    }

    fn chosen_kinds(&self, all_takes_reference: bool) -> Vec<data::BackendKind> {
        use data::BackendKind as K;
        let chosen = |k: K| {
            self.backend.iter().any(|&c| {
                (c == BackendChoice::All && (k != K::Reference || all_takes_reference))
                    || matches!(
                        (c, k),
                        (BackendChoice::Fem, K::Fem)
                            | (BackendChoice::Fdm, K::Fdm)
                            | (BackendChoice::Modal, K::Modal)
                            | (BackendChoice::Reference, K::Reference)
                    )
            })
        };
        K::ALL
            .into_iter()
            .chain([K::Reference])
            .filter(|&k| chosen(k))
            .collect()
    }
}

/// Options shared by the scene commands.
#[derive(Debug, Clone, Args)]
pub struct CommonOpts {
    /// One backend, a comma-separated list (`fem,modal`) or `all`.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "all")]
    pub backend: Vec<BackendChoice>,
    /// FEM: elements per link.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub elements: Option<u32>,
    /// FEM: Euler–Bernoulli element (default hermite-cubic; hermite-quintic: frequency error O(h⁸)).
    #[arg(long, value_parser = PossibleValuesParser::new(data::FemElement::NAMES)
        .try_map(|name| name.parse::<data::FemElement>()))]
    pub element: Option<data::FemElement>,
    /// FDM: stations per link/body (both ends included).
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=1_000_000))]
    pub stations: Option<u32>,
    /// Modal: assumed modes per link and field.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub modes: Option<u32>,
    /// Modal: basis functions.
    #[arg(long, value_parser = PossibleValuesParser::new(data::Basis::NAMES)
        .try_map(|name| name.parse::<data::Basis>()))]
    pub basis: Option<data::Basis>,
    /// Time step (fixed step, or first step of adaptive methods).
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
    pub dt: Option<f64>,
    /// End time (overrides the scene).
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
    pub t_end: Option<f64>,
    /// Interval between stored output samples (overrides the scene). A low-passed history
    /// (`lowpassF:`, `compare --lowpass`) needs samples that resolve the signal: undamped
    /// links ring at high frequency, and coarse samples alias that ringing into the pass band.
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
    pub output_interval: Option<f64>,
    /// Integration method (backend-specific; the help lists each backend's from the method
    /// table, `method_help`).
    #[arg(long, value_parser = parse_method, help = method_help())]
    pub method: Option<data::Method>,
    /// Relative tolerance of adaptive integrators.
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
    pub rtol: Option<f64>,
    /// Absolute tolerance of adaptive integrators.
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
    pub atol: Option<f64>,
    /// Factor (0, 1] applied to a stability bound when the scheme chooses its own step.
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64)]
    pub safety_factor: Option<f64>,
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Write result files (atomically) into this folder.
    #[arg(long)]
    pub out: Option<std::path::PathBuf>,
}

/// `--shard I/N`.
fn parse_shard(s: &str) -> Result<crate::shard::Shard, String> {
    s.parse()
        .map_err(|e: crate::shard::ShardParseError| e.to_string())
}

/// A finite number > 0.
pub fn positive_f64(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number; expected a finite number > 0"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{s} is not allowed; expected a finite number > 0"))
    }
}

impl CommonOpts {
    /// Backend settings from the options for the backends `kinds`; a flag that none of them
    /// reads is refused (each backend then takes its own fields, [`data::Settings::for_backend`]).
    pub fn settings_for(&self, kinds: &[data::BackendKind]) -> Result<data::Settings, String> {
        let settings = self.settings();
        match settings.unread_by(kinds).first() {
            None => Ok(settings),
            Some(&field) => {
                let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
                let subject = match names.as_slice() {
                    [one] => format!("the requested backend {one}"),
                    many => format!("the requested backends {}", many.join(", ")),
                };
                let mut message = settings.refusal(field, field.flag(), &subject, kinds.len() > 1);
                if field == data::SettingField::Method {
                    for &kind in kinds {
                        message += &format!("; {kind} offers {}", data::Method::names_for(kind));
                    }
                }
                Err(message)
            }
        }
    }

    /// Backend settings from the options, unchecked.
    fn settings(&self) -> data::Settings {
        data::Settings {
            discretization: data::Discretization {
                elements: self.elements.map(|n| n as usize),
                stations: self.stations.map(|n| n as usize),
                modes: self.modes.map(|n| n as usize),
                basis: self.basis,
                element: self.element,
            },
            time: data::TimeStepping {
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

/// `--method`'s help: each backend's spellings, from the method table.
fn method_help() -> String {
    let lists: Vec<String> = [BackendKind::Fem, BackendKind::Fdm, BackendKind::Modal]
        .into_iter()
        .map(|b| format!("{} ({b})", data::Method::names_for(b)))
        .collect();
    format!(
        "Integration method (backend-specific; see `flexverify describe`): {}",
        lists.join("; ")
    )
}

/// `--method`: one of [`data::Method::names`].
fn parse_method(text: &str) -> Result<data::Method, String> {
    text.parse()
}

/// The options' settings for `kinds`; a flag none of them reads is bad input (exit 2).
pub(crate) fn checked_settings(
    opts: &CommonOpts,
    kinds: &[BackendKind],
) -> Result<Settings, CliError> {
    opts.settings_for(kinds)
        .map_err(|e| CliError::Input(format!("error: {e}")))
}
