//! What the FEM backend can build, checked on the scene alone before any model is made:
//! precise `unsupported` (or invalid-setting) messages for everything else.
//!
//! Model-level: it reads only the scene's [`PlanarChain`] (and the scene's name for the
//! messages), so the chain ([`crate::chain::Chain::from_planar_chain`]), the plan and the run
//! call it without depending on the methods or the contact objects that implement the accepted
//! features ([`crate::events::contact`], its `friction`).

use data::Scene;
use data::scene::{ContactMode, PlanarChain, Surface};

use crate::error::FemError;

/// The refusal of a family this backend does not solve for the operation asked.
pub fn unsupported_family(scene: &Scene) -> FemError {
    FemError::unsupported(format!(
        "fem: the {} family (scene `{}`) is not implemented; only planar link chains",
        scene.family(),
        scene.name
    ))
}

/// Planar chains (with one tip contact) of scene `name`; every other feature is refused by name.
pub fn check_planar(name: &str, pc: &PlanarChain) -> Result<(), FemError> {
    // Unilateral frictionless line contact and the bilateral wall are implemented
    // (`crate::events::contact`); the rest is refused by name ([`check_contact`]).
    check_contact(name, pc)?;
    if pc.links.is_empty() {
        return Err(FemError::unsupported("fem: scene has no links".to_string()));
    }
    for (i, l) in pc.links.iter().enumerate() {
        if l.axial && l.foreshortening {
            return Err(FemError::unsupported(format!(
                "fem: link {} has both `axial` and `foreshortening`; choose one stiffening model",
                i + 1
            )));
        }
        if l.axial && l.axial_stiffness.is_none() {
            return Err(FemError::unsupported(format!(
                "fem: link {} has `axial` without `axial_stiffness`",
                i + 1
            )));
        }
        if l.shear && l.shear_stiffness.is_none() {
            return Err(FemError::unsupported(format!(
                "fem: link {} has `shear` without `shear_stiffness`",
                i + 1
            )));
        }
        if l.rotary_inertia && l.rotary_inertia_per_length.is_none() {
            return Err(FemError::unsupported(format!(
                "fem: link {} has `rotary_inertia` without `rotary_inertia_per_length`",
                i + 1
            )));
        }
    }
    Ok(())
}

/// Refuses contact features this backend does not model, with a precise message.
pub fn check_contact(name: &str, pc: &PlanarChain) -> Result<(), FemError> {
    if pc.contacts.len() > 1 {
        return Err(FemError::unsupported(format!(
            "fem: {} contacts in scene `{name}`; one tip contact is implemented",
            pc.contacts.len(),
        )));
    }
    let Some(c) = pc.contacts.first() else {
        return Ok(());
    };
    // Bilateral contacts (line or circle, with or without friction): `crate::events::contact::friction`.
    let bilateral = c.mode == ContactMode::Bilateral;
    check_bilateral_contact(pc)?;
    if let (false, Surface::Circle { .. }) = (bilateral, &c.surface) {
        return Err(FemError::unsupported(format!(
            "fem: unilateral contact with a circular surface (scene `{name}`) is not \
             implemented; unilateral contact is implemented for a straight line, circles for \
             bilateral contacts"
        )));
    }
    if !bilateral && c.friction != 0.0 {
        return Err(FemError::unsupported(format!(
            "fem: Coulomb friction (μ = {}) in a unilateral contact (scene `{name}`) is not \
             implemented (impacts with friction); friction is implemented for bilateral contacts",
            c.friction
        )));
    }
    if let Some(i) = pc.links.iter().position(|l| l.joint.prescribed.is_some()) {
        return Err(FemError::unsupported(format!(
            "fem: contact combined with prescribed joint motion (link {}) is not implemented",
            i + 1
        )));
    }
    if let Some(i) = pc
        .links
        .iter()
        .position(|l| l.shear && !l.rotary_inertia && l.kelvin_voigt.unwrap_or(0.0) <= 0.0)
    {
        return Err(FemError::unsupported(format!(
            "fem: contact with Timoshenko link {} (`{}`) without `rotary_inertia` and without \
             Kelvin–Voigt damping: its section rotations are then algebraic (∂V/∂ψ = 0) and ψ̇ \
             jumps with the massive velocities at an impact; that condensation is not \
             implemented (only the damped case, where ψ̇ follows the massless balance \
             Nᵀ(∂V/∂q + C q̇) = 0); set `kelvin_voigt` > 0 or `rotary_inertia`",
            i + 1,
            pc.links[i].name
        )));
    }
    if !pc.links.iter().any(|l| l.name == c.link) {
        return Err(FemError::InvalidSettings {
            field: "contact.link".into(),
            message: format!("no link named `{}`", c.link),
        });
    }
    Ok(())
}

/// Refuses what the bilateral contact does not model (part of [`check_contact`]).
pub fn check_bilateral_contact(pc: &PlanarChain) -> Result<(), FemError> {
    let Some(c) = pc.contacts.first() else {
        return Ok(());
    };
    if c.mode != ContactMode::Bilateral {
        return Ok(());
    }
    if !(c.friction >= 0.0 && c.friction.is_finite()) {
        return Err(FemError::InvalidSettings {
            field: "contact.friction".into(),
            message: format!("the friction coefficient must be ≥ 0, got {}", c.friction),
        });
    }
    if let Some(i) = pc.links.iter().position(|l| l.shear && !l.rotary_inertia) {
        // The index-1 normal and held-tip forces and the Coulomb test use M⁻¹; the unilateral
        // contact's condensation of massless sections is not carried over to the bilateral
        // wall.
        return Err(FemError::unsupported(format!(
            "fem: bilateral (friction) contact with Timoshenko link {} (`{}`) without \
             `rotary_inertia`: its section rotations carry no mass, so M is singular and the \
             index-1 wall forces (G M⁻¹Gᵀ, G M⁻¹Tᵀ, T M⁻¹Tᵀ) are undefined; set \
             `rotary_inertia = true` with `rotary_inertia_per_length`",
            i + 1,
            pc.links[i].name
        )));
    }
    if let (Some(l), Surface::Circle { center, radius }) =
        (pc.links.iter().find(|l| l.name == c.link), &c.surface)
    {
        let first = pc.links.first().is_some_and(|f| f.name == l.name);
        let tol = 1e-12 * l.length;
        if first
            && !l.axial
            && center[0].hypot(center[1]) <= tol
            && (radius - l.length).abs() <= tol
        {
            return Err(FemError::unsupported(format!(
                "fem: bilateral circle of radius L about the hub for the inextensible link `{}` \
                 (simple flexure): its tip can stay at radius L only while the link is straight, \
                 so the model degenerates to the rigid link (constraint gradient zero, normal \
                 force undetermined); use `axial = true` (Euler model) or the rigid closed form",
                l.name
            )));
        }
    }
    Ok(())
}
