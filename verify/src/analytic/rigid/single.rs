//! One rigid link driven by a piecewise-constant hub torque in a horizontal plane.
//!
//! Energy: T = ½ J θ̇² with J = J_h + ρAL³/3 + M L² + J_tip (no potential: horizontal plane, no
//! joint spring). Lagrange: J θ̈ = τ(t). On each interval \[t_i, t_{i+1}) between the breakpoints
//! of the torque law τ = τ_i is constant and
//!
//! `θ(t) = θ_i + θ̇_i (t − t_i) + ½ (τ_i / J)(t − t_i)²`,
//!
//! so θ is piecewise quadratic and θ̇ piecewise linear. Input work ∫τθ̇ dt = T(t) − T(0).
//!
//! Units: consistent (N m, kg m², rad, s in the `single-link` scene).

use serde::{Deserialize, Serialize};

use data::scene::{PlanarChain, TorqueLaw};

use super::{law_breakpoints, link_inertia_about_root, reject};
use crate::analytic::error::{AnalyticError, Result, finite, positive};

/// Rigid link about a fixed hub.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigidLink {
    /// Total rotary inertia about the hub J.
    pub inertia: f64,
    /// Initial angle θ(0) \[rad\].
    pub angle0: f64,
    /// Initial rate θ̇(0).
    pub rate0: f64,
    /// Applied hub torque law (none = free rotation).
    pub torque: Option<TorqueLaw>,
}

/// State of a rigid link at time t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RigidLinkState {
    pub time: f64,
    pub angle: f64,
    pub rate: f64,
    pub torque: f64,
    pub kinetic_energy: f64,
    /// ∫₀ᵗ τ θ̇ dt.
    pub input_work: f64,
}

impl RigidLink {
    /// The rigid limit of a single-link planar scene (horizontal plane, torque-driven hub).
    pub fn from_chain(chain: &PlanarChain) -> Result<Self> {
        let link = super::torque_driven_single_link(chain, "rigid single-link reference")?;
        let j = &link.joint;
        reject(
            !chain.contacts.is_empty(),
            "rigid single-link reference: contact (see rigid::constrained for the circular wall)",
        )?;
        let r = RigidLink {
            inertia: link_inertia_about_root(link),
            angle0: j.initial_angle,
            rate0: j.initial_rate,
            torque: j.torque.clone(),
        };
        positive("rigid link inertia", r.inertia)?;
        Ok(r)
    }

    /// State at time t ≥ 0 (closed form).
    pub fn state(&self, t: f64) -> Result<RigidLinkState> {
        finite("t", t)?;
        if t < 0.0 {
            return Err(AnalyticError::InvalidParameter {
                name: "t",
                value: t,
                why: "must be >= 0",
            });
        }
        let j = self.inertia;
        let tau_at = |s: f64| self.torque.as_ref().map_or(0.0, |l| l.torque(s));
        let mut t0 = 0.0;
        let (mut th, mut om) = (self.angle0, self.rate0);
        let mut bounds = law_breakpoints(self.torque.as_ref(), t);
        bounds.push(t);
        for tb in bounds {
            // τ is constant on [t0, tb); sample it inside the interval, away from the switch.
            let tau = tau_at(0.5 * (t0 + tb));
            let h = tb - t0;
            th += om * h + 0.5 * tau / j * h * h;
            om += tau / j * h;
            t0 = tb;
        }
        let ke = 0.5 * j * om * om;
        Ok(RigidLinkState {
            time: t,
            angle: th,
            rate: om,
            torque: tau_at(t),
            kinetic_energy: ke,
            input_work: ke - 0.5 * j * self.rate0 * self.rate0,
        })
    }

    /// States at the given times.
    pub fn history(&self, times: &[f64]) -> Result<Vec<RigidLinkState>> {
        times.iter().map(|&t| self.state(t)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ana_rigid_single_link_bang_bang() {
        let scene = data::load_scene("single-link").unwrap();
        let r = RigidLink::from_chain(scene.planar_chain().unwrap()).unwrap();
        // J = 0.01 + 1·1³/3 + 0.5·1² = 0.843333…
        let j = 0.01 + 1.0 / 3.0 + 0.5;
        assert!((r.inertia - j).abs() < 1e-15);
        // Bang-bang ±1 N m for 0.5 s each: rest-to-rest, θ_final = τ t_s² / J.
        let s = r.state(3.0).unwrap();
        assert!(s.rate.abs() < 1e-15);
        assert!((s.angle - 0.25 / j).abs() < 1e-15);
        // Peak rate at the switch, τ t / J.
        let m = r.state(0.5).unwrap();
        assert!((m.rate - 0.5 / j).abs() < 1e-15);
        // Input work = ∫τθ̇ dt, checked by midpoint quadrature of τθ̇ (θ̇ linear per piece,
        // so the composite midpoint rule is exact up to round-off on each constant-τ piece).
        let n = 3000;
        let mut w = 0.0;
        for i in 0..n {
            let tm = (i as f64 + 0.5) * 1e-3;
            let st = r.state(tm).unwrap();
            w += st.torque * st.rate * 1e-3;
        }
        let at_1 = r.state(1.0).unwrap().input_work;
        assert!(at_1.abs() < 1e-14);
        assert!(w.abs() < 1e-12, "{w}");
        assert!(m.input_work > 0.0);
        assert!(r.state(-1.0).is_err());
    }

    #[test]
    fn ana_rigid_single_link_rejects_unmodelled_physics() {
        let scene = data::load_scene("two-link-free").unwrap();
        assert!(matches!(
            RigidLink::from_chain(scene.planar_chain().unwrap()),
            Err(AnalyticError::Unsupported(_))
        ));
        let scene = data::load_scene("constrained-arm").unwrap();
        assert!(RigidLink::from_chain(scene.planar_chain().unwrap()).is_err());
    }
}
