//! Static normal force of the rigid two-link arm resting on its tip on a horizontal surface
//! (the rest state of `barhorst-case1-stiff-elbow`, scenes.md: N·x_tip = Σ Wᵢ x_cg,i ≈ 142).
//!
//! Assumptions (stated because the scene leaves them implicit):
//! * the hub is at the origin; gravity is (0, −g); the surface is the line y = h and only the
//!   tip of link 2 touches it, frictionless, so the contact force is N·ŷ;
//! * the arm is at rest on the branch with the tip to the right of the hub (x_tip > 0), which is
//!   where case 1 falls from q₁ = q₅ = 5°;
//! * no applied torque laws (a static state needs constant loads); the hub spring (if any)
//!   carries τ_hub = −K₁(q₁ − q̄₁).
//!
//! Equilibrium: moments about the hub of the whole arm and about the elbow of link 2,
//!
//! ```text
//! N x_tip − Σ Wᵢ x_i + τ_hub = 0
//! N (x_tip − x_e) − W₂ (x_cg2 − x_e) − W_M2 (x_tip − x_e) − K₂(q₅ − q̄₅) = 0
//! L₁ sin q₁ + L₂ sin(q₁ + q₅) = h
//! ```
//!
//! Two references are returned:
//! * `straight` — the elbow held at its set-point (q₅ = q̄₅), the rigid straight arm of
//!   scenes.md; the second equation then gives the elbow moment needed to hold it;
//! * `elbow_spring` — rigid links with the elbow spring deflecting under the load (q₅ solved by
//!   Brent); the flexible rest state should lie close to it when EI is large.
//!
//! Units: consistent (lbf, ft in the Barhorst scenes).

use serde::{Deserialize, Serialize};

use data::scene::{PlanarChain, Surface};

use super::reject;
use super::two_link::RigidTwoLink;
use crate::analytic::error::{AnalyticError, Result, finite};
use crate::analytic::numerics::roots::{RootOptions, brent};

/// One static rest state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RestingState {
    pub q1: f64,
    pub q5: f64,
    pub tip_x: f64,
    /// Normal force of the surface on the tip (> 0 pushes up).
    pub normal_force: f64,
    /// Moment the elbow joint exerts on link 2 in this state (−K₂(q₅ − q̄₅) when the spring
    /// alone holds it).
    pub elbow_moment: f64,
}

/// Both static references.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RestingArm {
    pub straight: RestingState,
    /// None when the elbow has no spring (K₂ = 0: the arm folds, no rest on the tip).
    pub elbow_spring: Option<RestingState>,
}

/// q₁ such that the tip is at height h with elbow angle q₅ (branch x_tip > 0).
fn q1_on_surface(arm: &RigidTwoLink, q5: f64, h: f64) -> Result<f64> {
    let (l1, l2) = (arm.links[0].length, arm.links[1].length);
    let half_pi = std::f64::consts::FRAC_PI_2;
    brent(
        |q1| l1 * q1.sin() + l2 * (q1 + q5).sin() - h,
        -half_pi,
        half_pi,
        RootOptions::default(),
    )
}

/// Normal force and elbow residual for elbow angle q₅.
fn statics_at(arm: &RigidTwoLink, g: f64, q5: f64, h: f64) -> Result<RestingState> {
    let [b1, b2] = &arm.links;
    let [j1, _] = &arm.joints;
    let q1 = q1_on_surface(arm, q5, h)?;
    let p2 = q1 + q5;
    let xe = b1.length * q1.cos();
    let xt = xe + b2.length * p2.cos();
    let (w1, w2) = (
        b1.mass_per_length * b1.length * g,
        b2.mass_per_length * b2.length * g,
    );
    let (wm1, wm2) = (b1.tip_mass * g, b2.tip_mass * g);
    let x_cg1 = 0.5 * xe;
    let x_cg2 = xe + 0.5 * b2.length * p2.cos();
    let moment_of_weights = w1 * x_cg1 + wm1 * xe + w2 * x_cg2 + wm2 * xt;
    let tau_hub = -j1.stiffness * (q1 - j1.set_point);
    let n = (moment_of_weights - tau_hub) / xt;
    // Moment the elbow must apply to link 2 for its equilibrium.
    let elbow = -(n * (xt - xe) - w2 * (x_cg2 - xe) - wm2 * (xt - xe));
    Ok(RestingState {
        q1,
        q5,
        tip_x: xt,
        normal_force: n,
        elbow_moment: elbow,
    })
}

/// Static rest states of `arm` with its tip on the surface y = h.
pub fn resting_on_tip(arm: &RigidTwoLink, h: f64) -> Result<RestingArm> {
    finite("surface height", h)?;
    reject(
        arm.gravity[0] != 0.0 || arm.gravity[1] >= 0.0,
        "resting arm: gravity must point along −y",
    )?;
    reject(
        arm.joints.iter().any(|j| j.torque.is_some()),
        "resting arm: applied torque laws (no static state)",
    )?;
    let reach = arm.links[0].length + arm.links[1].length;
    if h.abs() >= reach {
        return Err(AnalyticError::InvalidParameter {
            name: "surface height",
            value: h,
            why: "the arm cannot reach the surface",
        });
    }
    let g = -arm.gravity[1];
    let [_, j2] = &arm.joints;
    let straight = statics_at(arm, g, j2.set_point, h)?;
    let elbow_spring = if j2.stiffness > 0.0 {
        let resid = |q5: f64| {
            statics_at(arm, g, q5, h)
                .map(|s| s.elbow_moment + j2.stiffness * (q5 - j2.set_point))
                .unwrap_or(f64::NAN)
        };
        // Widen a bracket around the set-point until the residual changes sign.
        let mut d = 1e-3;
        let bracket = loop {
            let (a, b) = (j2.set_point - d, j2.set_point + d);
            let (ra, rb) = (resid(a), resid(b));
            if ra.is_finite() && rb.is_finite() && (ra > 0.0) != (rb > 0.0) {
                break Some((a, b));
            }
            d *= 2.0;
            if d > 1.5 {
                break None;
            }
        };
        match bracket {
            Some((a, b)) => {
                let q5 = brent(resid, a, b, RootOptions::default())?;
                Some(statics_at(arm, g, q5, h)?)
            }
            None => None,
        }
    } else {
        None
    };
    Ok(RestingArm {
        straight,
        elbow_spring,
    })
}

/// Rest states for a two-link scene with one unilateral horizontal line contact on link 2.
pub fn resting_from_chain(chain: &PlanarChain) -> Result<RestingArm> {
    let [contact] = chain.contacts.as_slice() else {
        return Err(AnalyticError::Unsupported(
            "resting arm: exactly one contact is required".into(),
        ));
    };
    let h = match contact.surface {
        Surface::Line { point, normal } if normal[0] == 0.0 && normal[1] != 0.0 => point[1],
        _ => {
            return Err(AnalyticError::Unsupported(
                "resting arm: the surface must be a horizontal line".into(),
            ));
        }
    };
    reject(
        chain.link_index(&contact.link) != Some(1),
        "resting arm: the contact must be on the tip of link 2",
    )?;
    let no_contact = PlanarChain {
        contacts: Vec::new(),
        ..chain.clone()
    };
    let arm = RigidTwoLink::from_chain(&no_contact)?;
    resting_on_tip(&arm, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ana_resting_stiff_elbow_normal_force() {
        let scene = data::load_scene("barhorst-case1-stiff-elbow").unwrap();
        let r = resting_from_chain(scene.planar_chain().unwrap()).unwrap();
        let s = r.straight;
        // Straight arm: N = (W₁ L₁/2 + W₂ (L₁ + L₂/2)) / (L₁ + L₂), the cos q₁ cancels.
        let g = 32.17;
        let (w1, w2) = (1.764 * 3.0 * g, 1.764 * 2.0 * g);
        let n = (w1 * 1.5 + w2 * 4.0) / 5.0;
        assert!((s.normal_force - n).abs() < 1e-12 * n);
        // scenes.md quotes ≈ 142 (loose).
        assert!((s.normal_force - 142.0).abs() < 1.0);
        assert!((s.q1 - (-1.0f64 / 5.0).asin()).abs() < 1e-14);
        // With the elbow spring K₂ = 5000 the elbow gives by ~ moment / K₂ (a few hundredths
        // of a radian) and N changes by about as much relatively.
        let e = r.elbow_spring.unwrap();
        assert!(e.q5.abs() > 1e-3 && e.q5.abs() < 0.1, "{e:?}");
        assert!((e.normal_force - n).abs() < 0.05 * n);
        // Residuals of the equilibrium equations at the returned state.
        assert!((e.elbow_moment + 5000.0 * e.q5).abs() < 1e-9 * 5000.0);
        let tip_y = 3.0 * e.q1.sin() + 2.0 * (e.q1 + e.q5).sin();
        assert!((tip_y + 1.0).abs() < 1e-13);
    }

    #[test]
    fn ana_resting_rejects_folding_elbow_and_bad_scenes() {
        // Case 1 (K₂ = 20): the spring-held equilibrium, if any, is far from straight; the
        // straight reference still exists.
        let scene = data::load_scene("barhorst-case1").unwrap();
        let r = resting_from_chain(scene.planar_chain().unwrap()).unwrap();
        assert!(r.straight.normal_force > 0.0);
        let scene = data::load_scene("two-link-free").unwrap();
        assert!(resting_from_chain(scene.planar_chain().unwrap()).is_err());
    }
}
