//! The two-stage variable-mass rocket of the 1969 NASA report (seed 003 §5).

pub mod model;
pub mod operators;
pub mod system;

use data::scene::Rocket;
use data::{DofPlan, Scene};

use crate::error::FdmError;
use crate::settings::ValidatedSettings;
use model::RocketModel;
use system::RocketSystem;

/// Default stations: h = 2 in over 150 in, as in the report.
pub const DEFAULT_STATIONS: usize = 76;

/// The system of `r`, the rocket of `scene` (whose field stations it samples).
pub fn build(scene: &Scene, r: &Rocket, s: &ValidatedSettings) -> Result<RocketSystem, FdmError> {
    let n = s.stations.unwrap_or(DEFAULT_STATIONS);
    let model = RocketModel::new(r, n)?;
    Ok(RocketSystem::new(model, scene.simulation.field_stations))
}

pub fn dof_plan(r: &Rocket, stations: Option<usize>) -> Result<DofPlan, FdmError> {
    let n = stations.unwrap_or(DEFAULT_STATIONS);
    let mut plan = DofPlan::default();
    plan.add("rigid body (X, Y, θ)", 3);
    plan.add("axial u at stations", n);
    plan.add("transverse w at stations", n);
    plan.add("discrete-mass axial U", r.discrete_masses.len());
    plan.add("discrete-mass transverse W", r.discrete_masses.len());
    plan.builds = vec![
        "variable mass (stage-1 burn)".into(),
        "thrust, chamber pressure, internal-flow Coriolis".into(),
        "gravity at launch angle".into(),
        "geometric stiffness P w'".into(),
    ];
    if r.discrete_masses
        .iter()
        .any(|m| m.axial_damping > 0.0 || m.transverse_damping > 0.0)
        || r.springs
            .iter()
            .any(|m| m.axial_damping > 0.0 || m.transverse_damping > 0.0)
    {
        plan.builds.push("discrete dampers".into());
    }
    Ok(plan)
}
