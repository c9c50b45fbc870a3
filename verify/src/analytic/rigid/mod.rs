//! Rigid-link limits of the planar scenes (what every flexible model must approach as
//! EI, EA → ∞).
//!
//! * [`single`] — one rigid link with hub inertia and tip mass under a piecewise-constant torque
//!   law in a horizontal plane: θ(t) piecewise quadratic (scene `single-link`).
//! * [`constrained`] — seed 001 eq. 71: a rigid link whose tip slides on a circular wall with
//!   Coulomb friction, θ̈ = a − b θ̇|θ̇|, closed form (scene `constrained-arm`).
//! * [`two_link`] — the rigid two-link Barhorst arm with joint springs, dampers and gravity,
//!   integrated by Dormand–Prince at tight tolerance (scene `two-link-free` and variants).
//! * [`resting`] — the static normal force of the rigid arm resting on its tip
//!   (scene `barhorst-case1-stiff-elbow`).
//! * [`mobile`] — the rigid mobile manipulator of seed 004 (platform with nonholonomic
//!   constraints, four-joint arm), two formulations and inverse dynamics (backend `reference`).

pub mod constrained;
pub mod mobile;
pub mod resting;
pub mod single;
pub mod two_link;

use data::scene::{Link, PlanarChain, TorqueLaw};

use crate::analytic::error::{AnalyticError, Result};

/// Rotary inertia of a rigid uniform link about its root joint, including the hub rotor and the
/// tip body: J_h + ρA L³/3 + M L² + J_tip.
pub fn link_inertia_about_root(link: &Link) -> f64 {
    link.joint.hub_inertia.unwrap_or(0.0)
        + link.mass_per_length * link.length.powi(3) / 3.0
        + link.tip_mass.unwrap_or(0.0) * link.length.powi(2)
        + link.tip_inertia.unwrap_or(0.0)
}

/// Breakpoints of an optional torque law inside (0, t_end), sorted.
pub(crate) fn law_breakpoints(law: Option<&TorqueLaw>, t_end: f64) -> Vec<f64> {
    let mut b: Vec<f64> = law
        .map(|l| l.breakpoints())
        .unwrap_or_default()
        .into_iter()
        .filter(|&t| t > 0.0 && t < t_end && t.is_finite())
        .collect();
    b.sort_by(f64::total_cmp);
    b.dedup();
    b
}

/// Rejects a joint/link feature that a rigid single-link closed form does not model.
pub(crate) fn reject(cond: bool, what: &str) -> Result<()> {
    if cond {
        Err(AnalyticError::Unsupported(what.to_string()))
    } else {
        Ok(())
    }
}

/// The one link of a horizontal-plane scene driven only by a torque law at its hub (no gravity,
/// joint spring/damper or prescribed motion): what the single-link rigid limits require.
pub(crate) fn torque_driven_single_link<'a>(chain: &'a PlanarChain, who: &str) -> Result<&'a Link> {
    let [link] = chain.links.as_slice() else {
        return Err(AnalyticError::Unsupported(format!(
            "{who}: the scene must have exactly one link"
        )));
    };
    let j = &link.joint;
    reject(
        chain.gravity.is_some(),
        &format!("{who}: gravity (only the horizontal plane is modelled)"),
    )?;
    reject(
        j.stiffness.is_some_and(|k| k != 0.0) || j.damping.is_some_and(|d| d != 0.0),
        &format!("{who}: joint spring/damper"),
    )?;
    reject(
        j.prescribed.is_some(),
        &format!("{who}: prescribed joint motion"),
    )?;
    Ok(link)
}
