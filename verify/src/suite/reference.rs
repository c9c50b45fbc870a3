//! Analytic reference values by id, computed from the scene's parameters by `crate::analytic`.

use data::Scene;

use super::quantity::Quantity;

/// The analytic value of a quantity for a scene.
pub fn analytic_value(id: &str, _scene: &Scene, _q: &Quantity) -> Result<f64, String> {
    Err(format!(
        "unsupported: analytic reference `{id}` is not available yet"
    ))
}

/// The analytic reference that naturally applies to a quantity on a scene, if any.
pub fn default_analytic_id(_scene: &Scene, _q: &Quantity) -> Option<String> {
    None
}
