//! What a backend returns (verification.md, "What every backend run returns").
//!
//! Backends fill these types; `verify` compares them. Observables are addressed by name (see
//! [`crate::channel`]) so that backends are compared through physical quantities, never raw DOF vectors.

use serde::{Deserialize, Serialize};

use crate::settings::{BackendKind, Settings};

/// Standard energy-ledger term names (see [`EnergyLedger`]).
pub mod ledger_term {
    use crate::scene::LinkField;

    // Stored energies.
    pub const KINETIC: &str = "kinetic";
    pub const STRAIN: &str = "strain";
    pub const GRAVITY: &str = "gravity";
    pub const JOINT_SPRING: &str = "joint_spring";
    /// Springs of the rocket's discrete masses.
    pub const DISCRETE_SPRING: &str = "discrete_spring";

    // Cumulative input work.
    pub const APPLIED_TORQUE: &str = "applied_torque";
    /// Work of the scene's transverse step/tip load and distributed load.
    pub const APPLIED_LOAD: &str = "applied_load";
    pub const PRESCRIBED_MOTION: &str = "prescribed_motion";
    /// Rocket: work of the thrust and of the nozzle-exit pressure.
    pub const THRUST: &str = "thrust";
    pub const PRESSURE: &str = "pressure";
    /// Rocket: work of the internal-flow Coriolis force (modal: the Coriolis terms of the
    /// variable-mass equations).
    pub const CORIOLIS: &str = "coriolis";
    /// Rocket (fdm): work of the Coriolis force of the internal flow as the report writes it.
    pub const CORIOLIS_FLOW: &str = "coriolis_flow";
    /// Rocket: energy carried off by burnt propellant (an input in modal's ledger, a
    /// dissipation in fdm's, each with the matching sign).
    pub const MASS_OUTFLOW: &str = "mass_outflow";

    // Cumulative dissipation.
    pub const JOINT_DAMPER: &str = "joint_damper";
    pub const KELVIN_VOIGT: &str = "kelvin_voigt";
    /// Dampers of the rocket's discrete masses.
    pub const DISCRETE_DAMPER: &str = "discrete_damper";
    pub const FRICTION: &str = "friction";
    pub const IMPACT: &str = "impact";
    /// FEM contact: energy removed by projecting the state back onto the contact constraint.
    pub const CONTACT_PROJECTION: &str = "contact_projection";
    /// FEM contact with a massless tip: energy removed by the massless-node projection.
    pub const NUMERICAL_MASSLESS: &str = "numerical_massless";

    // Mobile manipulator (verify's rigid reference).
    /// Work of the wheel drive torques.
    pub const WHEEL_TORQUE: &str = "wheel_torque";
    /// Work of the arm's joint torques.
    pub const JOINT_TORQUE: &str = "joint_torque";
    /// Dissipation in the wheel and joint friction.
    pub const WHEEL_FRICTION: &str = "wheel_friction";
    pub const JOINT_FRICTION: &str = "joint_friction";

    /// Kelvin–Voigt dissipation of one field of the 3-D link, booked separately per field.
    pub fn kelvin_voigt_of(field: LinkField) -> &'static str {
        match field {
            LinkField::Axial => "kelvin_voigt_axial",
            LinkField::Horizontal => "kelvin_voigt_horizontal",
            LinkField::Vertical => "kelvin_voigt_vertical",
            LinkField::Torsion => "kelvin_voigt_torsion",
        }
    }
}

/// Sampled time series of named channels on a common time grid.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Observables {
    pub time: Vec<f64>,
    pub channels: Vec<Channel>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Channel {
    pub name: String,
    pub unit: String,
    pub values: Vec<f64>,
}

impl Observables {
    /// Creates empty channels with the given names and units.
    pub fn with_channels(specs: &[(String, &str)]) -> Self {
        Observables {
            time: Vec::new(),
            channels: specs
                .iter()
                .map(|(name, unit)| Channel {
                    name: name.clone(),
                    unit: (*unit).to_string(),
                    values: Vec::new(),
                })
                .collect(),
        }
    }

    /// Appends one sample; `values` in channel order.
    pub fn push(&mut self, t: f64, values: &[f64]) {
        debug_assert_eq!(values.len(), self.channels.len());
        self.time.push(t);
        for (c, v) in self.channels.iter_mut().zip(values) {
            c.values.push(*v);
        }
    }

    pub fn get(&self, name: &str) -> Option<&Channel> {
        self.channels.iter().find(|c| c.name == name)
    }

    /// Linear interpolation of a channel at time t (None outside the sampled range).
    pub fn value_at(&self, name: &str, t: f64) -> Option<f64> {
        let c = self.get(name)?;
        interpolate(&self.time, &c.values, t)
    }

    /// First non-finite sample, if any: (channel, time).
    pub fn first_non_finite(&self) -> Option<(String, f64)> {
        for c in &self.channels {
            if let Some(k) = c.values.iter().position(|v| !v.is_finite()) {
                return Some((c.name.clone(), self.time[k]));
            }
        }
        None
    }
}

/// Piecewise-linear interpolation on a sorted grid.
pub fn interpolate(time: &[f64], values: &[f64], t: f64) -> Option<f64> {
    if time.is_empty() || t < time[0] - 1e-12 * time[0].abs().max(1.0) {
        return None;
    }
    let last = *time.last()?;
    if t > last + 1e-12 * last.abs().max(1.0) {
        return None;
    }
    let k = time.partition_point(|&s| s <= t);
    if k == 0 {
        return Some(values[0]);
    }
    if k >= time.len() {
        return Some(values[time.len() - 1]);
    }
    let (t0, t1) = (time[k - 1], time[k]);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    Some(values[k - 1] * (1.0 - w) + values[k] * w)
}

/// One named energy contribution sampled at the ledger times.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyTerm {
    pub name: String,
    pub values: Vec<f64>,
}

/// The energy ledger: stored energies, cumulative input work and cumulative dissipation.
///
/// Closure: E(t) − E(0) − W_in(t) + W_diss(t) = 0, where E is the sum of `stored`.
/// Standard names — stored: `kinetic`, `strain`, `gravity`, `joint_spring`, `discrete_spring`;
/// inputs: `applied_torque`, `prescribed_motion`, `thrust`, `pressure`, `coriolis` (internal
/// flow), `mass_outflow` (energy carried off by burnt propellant); dissipation: `joint_damper`,
/// `kelvin_voigt`, `discrete_damper`, `friction`, `impact`. Backends may add terms with other
/// names; the closure sums whatever is present.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyLedger {
    pub time: Vec<f64>,
    pub stored: Vec<EnergyTerm>,
    pub inputs: Vec<EnergyTerm>,
    pub dissipation: Vec<EnergyTerm>,
}

impl EnergyLedger {
    pub fn new(stored: &[&str], inputs: &[&str], dissipation: &[&str]) -> Self {
        let mk = |names: &[&str]| {
            names
                .iter()
                .map(|n| EnergyTerm {
                    name: (*n).to_string(),
                    values: Vec::new(),
                })
                .collect()
        };
        EnergyLedger {
            time: Vec::new(),
            stored: mk(stored),
            inputs: mk(inputs),
            dissipation: mk(dissipation),
        }
    }

    /// Appends one sample; each slice in the order given to [`EnergyLedger::new`].
    pub fn push(&mut self, t: f64, stored: &[f64], inputs: &[f64], dissipation: &[f64]) {
        self.time.push(t);
        for (term, v) in self.stored.iter_mut().zip(stored) {
            term.values.push(*v);
        }
        for (term, v) in self.inputs.iter_mut().zip(inputs) {
            term.values.push(*v);
        }
        for (term, v) in self.dissipation.iter_mut().zip(dissipation) {
            term.values.push(*v);
        }
    }

    fn sum(terms: &[EnergyTerm], k: usize) -> f64 {
        terms.iter().map(|t| t.values[k]).sum()
    }

    /// Total stored energy E at sample k.
    pub fn total(&self, k: usize) -> f64 {
        Self::sum(&self.stored, k)
    }

    /// E(t_k) − E(0) − W_in(t_k) + W_diss(t_k).
    pub fn residual(&self, k: usize) -> f64 {
        self.total(k) - self.total(0) - Self::sum(&self.inputs, k) + Self::sum(&self.dissipation, k)
    }

    /// max_k |residual| / scale, with scale = max over the run of |E|, |W_in| and |W_diss|
    /// (so that a driven run starting from rest is measured against the energy that flowed).
    pub fn relative_closure(&self) -> f64 {
        let n = self.time.len();
        if n == 0 {
            return 0.0;
        }
        let mut scale = 0.0f64;
        let mut worst = 0.0f64;
        for k in 0..n {
            scale = scale
                .max(self.total(k).abs())
                .max(Self::sum(&self.inputs, k).abs())
                .max(Self::sum(&self.dissipation, k).abs());
            worst = worst.max(self.residual(k).abs());
        }
        if scale > 0.0 { worst / scale } else { worst }
    }
}

/// Something that happened at a definite time during a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Event {
    /// The gap function of a contact crossed zero (located to `time_tolerance`).
    ContactStart {
        t: f64,
        contact: usize,
        time_tolerance: f64,
    },
    /// Generalized impulse–momentum jump M(q̇⁺ − q̇⁻) = Gᵀ Λ with G q̇⁺ = 0.
    Impact {
        t: f64,
        contact: usize,
        velocity_before: Vec<f64>,
        velocity_after: Vec<f64>,
        impulse: f64,
        /// ‖M(q̇⁺ − q̇⁻) − GᵀΛ‖ / ‖M(q̇⁺ − q̇⁻)‖.
        momentum_residual: f64,
        /// Normal tip velocity G q̇⁻ just before the jump (negative: approaching the surface).
        /// With a tip mass the impulse tends to m_tip·|v_n⁻| as the beam is refined (the rest of
        /// the beam takes no part in an instantaneous point impact).
        normal_velocity_before: f64,
        /// Normal tip velocity after the jump.
        normal_velocity_after: f64,
        kinetic_energy_lost: f64,
    },
    /// The normal force crossed zero: the tip leaves the surface.
    Release {
        t: f64,
        contact: usize,
        normal_force: f64,
        time_tolerance: f64,
    },
    /// Friction state change.
    StickSlip {
        t: f64,
        contact: usize,
        sticking: bool,
    },
    /// The step size changed for a stated reason (e.g. a stability bound moved).
    StepSizeChange {
        t: f64,
        from: f64,
        to: f64,
        reason: String,
    },
    /// The integrator rejected a step.
    StepRejected { t: f64, dt: f64, reason: String },
}

impl Event {
    pub fn time(&self) -> f64 {
        match self {
            Event::ContactStart { t, .. }
            | Event::Impact { t, .. }
            | Event::Release { t, .. }
            | Event::StickSlip { t, .. }
            | Event::StepSizeChange { t, .. }
            | Event::StepRejected { t, .. } => *t,
        }
    }
}

/// Contact episodes `(start, end)` of a run's events (`end` None: in contact at the end).
/// A contact phase starts at an `Impact` or `ContactStart` and ends at the next `Release`; a
/// start followed by another start without a release in between (an impact immediately
/// followed by free flight, which backends do not record as a release) is a phase of zero
/// length. Phases separated by a free flight shorter than `min_flight` form one episode.
pub fn contact_episodes(events: &[Event], min_flight: f64) -> Vec<(f64, Option<f64>)> {
    let mut phases: Vec<(f64, Option<f64>)> = Vec::new();
    let mut open: Option<f64> = None;
    let mut times: Vec<(f64, bool)> = events
        .iter()
        .filter_map(|e| match e {
            Event::Impact { t, .. } | Event::ContactStart { t, .. } => Some((*t, false)),
            Event::Release { t, .. } => Some((*t, true)),
            _ => None,
        })
        .collect();
    times.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (t, release) in times {
        match (release, open) {
            (false, None) => open = Some(t),
            // The impact of a contact start at the same instant, or a silent release.
            (false, Some(s)) => {
                if t > s {
                    phases.push((s, Some(s)));
                    open = Some(t);
                }
            }
            (true, Some(s)) => {
                phases.push((s, Some(t)));
                open = None;
            }
            (true, None) => {}
        }
    }
    if let Some(s) = open {
        phases.push((s, None));
    }
    let mut episodes: Vec<(f64, Option<f64>)> = Vec::new();
    for (s, e) in phases {
        match episodes.last_mut() {
            Some(last) if last.1.is_some_and(|prev_end| s - prev_end < min_flight) => last.1 = e,
            _ => episodes.push((s, e)),
        }
    }
    episodes
}

/// Work counters reported with every result.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    pub wall_time_s: f64,
    pub dofs: usize,
    pub steps: usize,
    pub rejected_steps: usize,
    pub rhs_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub factorizations: usize,
    pub newton_iterations: usize,
}

/// A backend's own account of why it stopped early.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnostic {
    /// Simulation time at which the problem was detected.
    pub t: f64,
    /// What went wrong (e.g. "transverse displacement grew without bound").
    pub what: String,
    /// Where (DOF, station, link), if it is localized.
    pub location: Option<String>,
    /// Why, as far as the backend can tell.
    pub why: String,
    /// What the user can change.
    pub remedy: String,
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "at t = {:.6e}: {}", self.t, self.what)?;
        if let Some(loc) = &self.location {
            write!(f, " ({loc})")?;
        }
        write!(f, "; why: {}; remedy: {}", self.why, self.remedy)
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "kebab-case")]
pub enum StabilityVerdict {
    /// Reached t_end with finite, bounded output.
    Completed,
    /// Stopped early with a diagnostic; output up to `diagnostic.t` is kept.
    Stopped { diagnostic: Diagnostic },
}

/// Result of a dynamic run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    pub backend: BackendKind,
    pub scene: String,
    pub settings: Settings,
    pub observables: Observables,
    pub ledger: EnergyLedger,
    pub events: Vec<Event>,
    pub cost: Cost,
    pub verdict: StabilityVerdict,
}

/// A natural mode sampled at common stations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModeShape {
    /// Link index (1-based) and station coordinate x along it.
    pub link: usize,
    pub x: Vec<f64>,
    /// Transverse component (normalized to unit maximum magnitude).
    pub transverse: Vec<f64>,
}

/// Result of a modal analysis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModalResult {
    pub backend: BackendKind,
    pub scene: String,
    pub settings: Settings,
    /// Natural frequencies in Hz, ascending.
    pub frequencies_hz: Vec<f64>,
    /// What kind of motion each mode is ("bending", "axial", "shear", ...), when known.
    pub kinds: Vec<String>,
    pub shapes: Vec<ModeShape>,
    pub cost: Cost,
}

/// Result of a linear static analysis of the scene's `[statics]` loads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticResult {
    pub backend: BackendKind,
    pub scene: String,
    pub settings: Settings,
    /// Transverse tip deflection of the last link.
    pub tip_deflection: f64,
    /// Tip slope (rotation) of the last link.
    pub tip_rotation: f64,
    pub cost: Cost,
}
