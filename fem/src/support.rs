//! What the FEM backend can build: precise `unsupported` messages for everything else.

use data::{Family, Scene};

use crate::error::FemError;

/// Planar chains (with unilateral line contact); every other family or feature is refused by name.
pub fn check_planar(scene: &Scene) -> Result<(), FemError> {
    match scene.family() {
        Family::PlanarChain => {}
        other => {
            return Err(FemError::unsupported(format!(
                "fem: the {other} family (scene `{}`) is not implemented; only planar link chains",
                scene.name
            )));
        }
    }
    // Unilateral frictionless line contact is implemented (`crate::events::contact`); the rest is
    // refused there by name.
    crate::events::contact::check(scene)?;
    if scene.links().is_empty() {
        return Err(FemError::unsupported("fem: scene has no links".to_string()));
    }
    for (i, l) in scene.links().iter().enumerate() {
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
