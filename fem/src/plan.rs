//! DOF plan: what the backend builds for a scene (reported by `describe`, asserted in tests).

use data::scene::PlanarChain;
use data::{DofPlan, FemElement};

use crate::element;
use crate::error::FemError;
use crate::support::check_planar;

/// DOFs per field and the physics built for the planar chain `pc` of scene `name`, for `n_el`
/// elements per link of the chosen element (interior DOFs of the quintic and Timoshenko
/// elements are counted: they are global DOFs).
pub fn dof_plan(
    name: &str,
    pc: &PlanarChain,
    n_el: usize,
    element: Option<FemElement>,
) -> Result<DofPlan, FemError> {
    check_planar(name, pc)?;
    let mut plan = DofPlan::default();
    for (i, l) in pc.links.iter().enumerate() {
        let li = i + 1;
        if l.joint.prescribed.is_none() {
            plan.add(format!("joint{li} angle"), 1);
        }
        let kind = element::for_link(l, element)?;
        for (field, per_element) in kind.plan_fields() {
            plan.add(format!("link{li} {field}"), per_element * n_el);
        }
        if l.axial {
            plan.add(format!("link{li} axial u"), n_el);
        }
        let beam = kind.description();
        let mut b = vec![format!(
            "link{li}: {beam}{}), {n_el} elements",
            if l.axial { ", linear u" } else { "" }
        )];
        if l.axial {
            b.push(format!("link{li}: von Kármán strain u′ + ½v′²"));
        }
        if l.foreshortening {
            b.push(format!("link{li}: foreshortening stiffening s = −½∫v′²"));
        }
        if !l.axial && !l.foreshortening {
            b.push(format!("link{li}: linear model (no geometric stiffening)"));
        }
        if l.rotary_inertia {
            b.push(format!("link{li}: rotary inertia ρI"));
        }
        if l.kelvin_voigt.is_some_and(|g| g > 0.0) {
            b.push(format!("link{li}: Kelvin–Voigt bending damping"));
        }
        if l.tip_mass.is_some_and(|m| m > 0.0) {
            b.push(format!("link{li}: tip mass"));
        }
        if l.tip_inertia.is_some_and(|j| j > 0.0) {
            b.push(format!("link{li}: tip inertia"));
        }
        let j = &l.joint;
        if j.hub_inertia.is_some_and(|x| x > 0.0) {
            b.push(format!("joint{li}: hub inertia"));
        }
        if j.stiffness.is_some_and(|x| x > 0.0) {
            b.push(format!("joint{li}: spring"));
        }
        if j.damping.is_some_and(|x| x > 0.0) {
            b.push(format!("joint{li}: damper"));
        }
        if j.torque.is_some() {
            b.push(format!("joint{li}: applied torque law"));
        }
        if j.prescribed.is_some() {
            b.push(format!(
                "joint{li}: prescribed motion (reports required torque)"
            ));
        }
        plan.builds.extend(b);
    }
    if pc.gravity.is_some() {
        plan.builds.push("gravity".into());
    }
    plan.builds
        .extend(crate::events::contact::friction::describe(&pc.contacts));
    Ok(plan)
}
