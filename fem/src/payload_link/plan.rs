//! The link's DOF plan and its model build for a number of elements (module docs of
//! [`super`]).

use data::DofPlan;
use data::scene::{LinkField, LinkInitialShape, PayloadLink};

use super::model::{self, Model};
use crate::error::FemError;
use crate::settings;

fn field_dofs(f: LinkField) -> (&'static str, usize) {
    match f {
        LinkField::Axial => ("axial u", 1),
        LinkField::Horizontal => ("horizontal v, v′", 2),
        LinkField::Vertical => ("vertical w, w′", 2),
        LinkField::Torsion => ("torsion φ", 1),
    }
}

/// Elements of the 3-D link (Hermite cubics only).
pub fn elements(settings: &data::FemSettings) -> Result<usize, FemError> {
    settings::cubic_elements_or(
        settings,
        settings::DEFAULT_ELEMENTS,
        "3-D payload link",
        "the link",
    )
}

/// DOFs and physics built for the payload link `l` with `n_el` elements.
pub fn dof_plan(l: &PayloadLink, n_el: usize) -> Result<DofPlan, FemError> {
    let md = Model::assemble(l, n_el)?;
    let mut plan = DofPlan::default();
    if md.free_base() {
        plan.add("joint1 angle", 1);
    }
    for &f in &md.fields {
        let (what, per_node) = field_dofs(f);
        plan.add(format!("link1 {what}"), per_node * n_el);
    }
    let b = &mut plan.builds;
    b.push(format!(
        "link1: 3-D beam elements (linear u, φ; Hermite-cubic v, w), {n_el} elements"
    ));
    b.push("link1: second-order kinematics in the turning frame (foreshortening, centrifugal stiffening, Coriolis and θ̈ couplings, rotary inertia of sections)".into());
    b.push("payload: rigid body at the tip (mass, offset, full inertia matrix)".into());
    for (f, _) in &md.c_field {
        b.push(format!(
            "link1: Kelvin–Voigt damping of the {} field",
            f.name()
        ));
    }
    if md.has_gravity {
        b.push("gravity".into());
    }
    match &md.base {
        model::Base::Free {
            torque, stiffness, ..
        } => {
            if l.base_inertia() > 0.0 {
                b.push("joint1: hub inertia".into());
            }
            if *stiffness > 0.0 {
                b.push("joint1: spring".into());
            }
            if torque.is_some() {
                b.push("joint1: applied torque law".into());
            }
        }
        model::Base::Prescribed(_) => {
            b.push("joint1: prescribed motion (reports required torque)".into())
        }
    }
    if md.motor_friction > 0.0 {
        b.push("joint1: motor friction".into());
    }
    if l.initial_shape == LinkInitialShape::StaticSag {
        b.push("initial static sag".into());
    }
    Ok(plan)
}

/// The link model of `n_el` elements, the hub inertia I_B part of J₀.
pub(super) fn build(l: &PayloadLink, n_el: usize) -> Result<Model, FemError> {
    let mut md = Model::assemble(l, n_el)?;
    md.j0 += l.base_inertia();
    Ok(md)
}
