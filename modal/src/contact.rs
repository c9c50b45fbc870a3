//! Unilateral frictionless contact of a link tip with a fixed straight line (Barhorst's work
//! surface): gap, constraint row, impact map and the constrained (index-1) accelerations.
//!
//! With n̂ the unit normal (free side) and p₀ a point of the line, the gap is
//! g(q) = n̂·(r_tip(q) − p₀) and its Jacobian the normal row of the tip Jacobian, G = n̂ᵀ J(q)
//! (free coordinates only). Then
//!
//! * **impact** (perfectly plastic, no restitution coefficient): M(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0
//!   ⇒ Λ = −G q̇⁻ / (G M⁻¹ Gᵀ), q̇⁺ = q̇⁻ + M⁻¹Gᵀ Λ, positions unchanged;
//! * **constrained motion** (Lagrange multiplier, index reduction to acceleration level):
//!   M q̈ = f + Gᵀλ, G q̈ + Ġq̇ = 0 ⇒ λ = −(G M⁻¹f + Ġq̇) / (G M⁻¹ Gᵀ), where Ġq̇ = n̂·c(q, q̇) is
//!   the convective tip acceleration ([`crate::model::Chain::tip_convective_acceleration`]);
//!   drift control by projecting q onto g = 0 and q̇ onto G q̇ = 0 in the M⁻¹ metric after
//!   every accepted step;
//! * **release** when λ crosses zero from above (λ is the normal force, positive pushing the tip
//!   to the free side).

use data::Scene;
use data::scene::Surface;

use crate::error::ModalError;

/// Contact model and the quantities of the last evaluation.
#[derive(Debug, Clone)]
pub struct ContactState {
    /// Index of the link whose tip touches the surface.
    pub link: usize,
    pub normal: [f64; 2],
    pub point: [f64; 2],
    /// Constrained phase (tip on the surface, λ unknown) or free flight.
    pub constrained: bool,
    /// Normal force of the last evaluation (0 in free flight).
    pub lambda: f64,
    /// Gap, normal tip velocity G q̇ and G M⁻¹ Gᵀ of the last evaluation.
    pub gap: f64,
    pub normal_velocity: f64,
    pub gmg: f64,
    /// G (free columns) and M⁻¹Gᵀ of the last evaluation.
    pub g_row: Vec<f64>,
    pub minv_gt: Vec<f64>,
    /// Tip Jacobian (2 × N) work array.
    pub jac: Vec<f64>,
    /// Cumulative kinetic energy lost in impacts.
    pub impact_loss: f64,
}

impl ContactState {
    /// The single unilateral frictionless line contact of a planar chain scene.
    pub fn from_scene(scene: &Scene, n: usize, nf: usize) -> Result<Option<Self>, ModalError> {
        let Some(c) = scene.contacts.first() else {
            return Ok(None);
        };
        check(scene)?;
        let link = scene
            .links
            .iter()
            .position(|l| l.name == c.link)
            .ok_or_else(|| {
                ModalError::invalid("contact.link", format!("no link named `{}`", c.link))
            })?;
        let Surface::Line { point, normal } = c.surface else {
            unreachable!("checked above")
        };
        let len = normal[0].hypot(normal[1]);
        Ok(Some(ContactState {
            link,
            normal: [normal[0] / len, normal[1] / len],
            point,
            constrained: false,
            lambda: 0.0,
            gap: 0.0,
            normal_velocity: 0.0,
            gmg: 0.0,
            g_row: vec![0.0; nf],
            minv_gt: vec![0.0; nf],
            jac: vec![0.0; 2 * n],
            impact_loss: 0.0,
        }))
    }
}

/// Rejects the contact features this backend does not model, with a precise message.
pub fn check(scene: &Scene) -> Result<(), ModalError> {
    if scene.contacts.len() > 1 {
        return Err(ModalError::Unsupported(format!(
            "modal: {} contacts; only one tip contact is implemented",
            scene.contacts.len()
        )));
    }
    let Some(c) = scene.contacts.first() else {
        return Ok(());
    };
    if c.mode != data::scene::ContactMode::Unilateral {
        return Err(ModalError::Unsupported(format!(
            "modal: bilateral contact of link `{}` (only unilateral impact/sliding/release is \
             implemented)",
            c.link
        )));
    }
    if c.friction != 0.0 {
        return Err(ModalError::Unsupported(format!(
            "modal: Coulomb friction μ = {} on the contact of link `{}` (stick–slip is not \
             implemented; only frictionless contact)",
            c.friction, c.link
        )));
    }
    if !matches!(c.surface, Surface::Line { .. }) {
        return Err(ModalError::Unsupported(format!(
            "modal: circular contact surface for link `{}` (only straight lines)",
            c.link
        )));
    }
    if scene.links.iter().any(|l| l.joint.prescribed.is_some()) {
        return Err(ModalError::Unsupported(
            "modal: contact together with a prescribed joint motion".into(),
        ));
    }
    if scene.links.iter().any(|l| l.axial) {
        return Err(ModalError::Unsupported(
            "modal: contact of a chain with axial fields (only inextensible links)".into(),
        ));
    }
    Ok(())
}

/// Root of a scalar function on [a, b] with f(a) > 0 ≥ f(b) (Illinois regula falsi) to the
/// bracket width `tol`. Returns (t, f(t), final bracket width) with f(t) ≤ 0: the located time
/// is the first sampled point on the far side of the crossing.
pub fn locate_crossing(
    mut f: impl FnMut(f64) -> f64,
    mut a: f64,
    mut fa: f64,
    mut b: f64,
    mut fb: f64,
    tol: f64,
) -> (f64, f64, f64) {
    let mut side = 0i8;
    let mut fb_true = fb;
    for _ in 0..200 {
        if b - a <= tol || fb == 0.0 {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        // Keep the iterate strictly inside; fall back to bisection if regula falsi stalls.
        if !(c > a && c < b && c.is_finite()) {
            c = 0.5 * (a + b);
        }
        let fc = f(c);
        if fc > 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            fb_true = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    (b, fb_true, b - a)
}
