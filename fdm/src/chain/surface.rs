//! The tip contact's data ([`super::contact`] operates on them): the surface, a fixed line
//! n̂·(p − p₀) = 0 with the unit normal n̂ to the free side, checked against what the chain's
//! contact carries; and the state of the constraint g = 0 (phase, normal force, the constraint
//! row and its mass solve, the residuals of the last drift projections).

use data::scene::{ContactMode, PlanarChain, Surface};

use crate::error::FdmError;

/// The tip of link 2 against the line n̂·(p − p₀) = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct TipContact {
    /// unit normal to the free side
    normal: [f64; 2],
    /// n̂·p₀
    offset: f64,
}

impl TipContact {
    /// The contact of `pc` (the chain of scene `name`), if any; `unsupported: …` for what this
    /// model does not carry.
    pub fn from_planar_chain(name: &str, pc: &PlanarChain) -> Result<Option<Self>, FdmError> {
        let Some(c) = pc.contacts.first() else {
            return Ok(None);
        };
        let unsupported = |what: String| {
            Err(FdmError::Unsupported(format!(
                "fdm: `{name}`: {what} (the finite-difference chain carries one frictionless \
                 unilateral contact of link 2's tip with a line)"
            )))
        };
        if pc.contacts.len() > 1 {
            return unsupported(format!("{} contacts", pc.contacts.len()));
        }
        if pc.link_index(&c.link) != Some(1) {
            return unsupported(format!("contact of link `{}`", c.link));
        }
        if c.friction != 0.0 {
            return unsupported(format!("friction μ = {}", c.friction));
        }
        if c.mode == ContactMode::Bilateral {
            return unsupported("bilateral contact".into());
        }
        let Surface::Line { point, normal } = c.surface else {
            return unsupported("a non-line contact surface".into());
        };
        let len = normal[0].hypot(normal[1]);
        if !(len > 0.0 && len.is_finite()) {
            return Err(FdmError::invalid("contact.surface.normal", "zero normal"));
        }
        let normal = [normal[0] / len, normal[1] / len];
        Ok(Some(TipContact {
            normal,
            offset: normal[0] * point[0] + normal[1] * point[1],
        }))
    }

    pub(super) fn nc(&self, a: f64) -> f64 {
        self.normal[0] * a.cos() + self.normal[1] * a.sin()
    }
    pub(super) fn ns(&self, a: f64) -> f64 {
        -self.normal[0] * a.sin() + self.normal[1] * a.cos()
    }

    /// g from the frame angles α₁, α₂ and the tips of links 1 and 2 in their frames,
    /// (L_ℓ − S_ℓ, V_ℓ): n̂·R(α)(X, Y) = nc(α)X + ns(α)Y.
    pub fn gap(&self, alpha: [f64; 2], lengths: [f64; 2], tips: [f64; 2]) -> f64 {
        self.nc(alpha[0]) * lengths[0] + self.nc(alpha[1]) * lengths[1] - self.offset
            + (self.ns(alpha[0]) * tips[0] + self.ns(alpha[1]) * tips[1])
    }
}

/// The state of the contact constraint g(q) = 0 (free flight, λ = 0 without a contact).
#[derive(Debug, Clone)]
pub(super) struct TipConstraint {
    /// whether the tip is held on the surface (constrained phase)
    pub(super) constrained: bool,
    /// normal force λ of the last constrained `accel` (0 in free flight)
    pub(super) lambda: f64,
    /// scratch of the constraint: G = ∂g/∂q and M⁻¹Gᵀ
    pub(super) grow: Vec<f64>,
    pub(super) minv_g: Vec<f64>,
    /// (|g|, |Gq̇|, energy removed) of the last constrained step's projections
    pub(super) last_projection: [f64; 3],
}
