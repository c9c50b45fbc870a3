//! Rigid-body translation of the variable-mass rocket (seed 003, report eqs. 3.54 and 5.16 with
//! the elastic terms and the rotation set to zero).
//!
//! Along the body axis (launch angle θ₀ from the horizontal, gravity (0, −g)) the rigid-body
//! equation is `m(t) dv/dt = F_T − m g sin θ₀` with the thrust resultant (report eq. 5.16,
//! vacuum, aligned nozzle)
//!
//! `F_T = ṁ v_e − p A_f (at x = 0) + p A_f (at x = L₁) = ṁ v_e`:
//!
//! the chamber-pressure forces at the two ends of the port cancel in the resultant (they only
//! load the case axially), and the steady internal flow contributes nothing (eq. 5.17). Hence the
//! rocket equation with gravity,
//!
//! `v(t) = v_e ln(m₀/m(t)) − g sin θ₀ t`,
//!
//! valid for any burn law because ∫ṁ/m dt = ln(m₀/m). Across the body axis gravity alone acts:
//! `v_⊥(t) = −g cos θ₀ t`. With no moment about the mass centre (all loads on the axis), θ stays
//! θ₀. Position: on each interval of constant ṁ starting at (t_i, m_i, s_i, v_i),
//!
//! `s(t) = s_i + (v_i + g sin θ₀ t_i − v_e ln(m₀/m_i))(t − t_i) + v_e[(t − t_i) − (m/ṁ) ln(m_i/m)]
//!  − ½ g sin θ₀ (t² − t_i²)`
//!
//! from ∫ ln(m_i/(m_i − ṁτ)) dτ = τ − (m/ṁ) ln(m_i/m). After burn-out (ṁ = 0) the motion is
//! ballistic.
//!
//! Mass: weights per length → masses via the scene's g; each burning stage loses ṁg/g per
//! length and time until its casing weight is reached (burn-out), so m(t) is piecewise linear.
//! The mass centre moves along the body as stage 1 burns; its station x_cg(t) (from the aft end)
//! is reported, and the inertial mass-centre position is aft-end position + x_cg e_axis.
//!
//! Units: those of the scene (in, lbf, s; masses in lbf s²/in).

use serde::{Deserialize, Serialize};

use data::scene::Rocket;

use crate::analytic::error::{AnalyticError, Result, finite, non_negative, positive};

/// Rigid-body data of the rocket derived from the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RocketTranslation {
    pub gravity: f64,
    pub launch_angle_rad: f64,
    pub exhaust_velocity: f64,
    /// Mass at ignition m₀.
    pub initial_mass: f64,
    /// Piecewise-linear mass law: (start time, mass at start, burn rate ṁ ≥ 0) per interval;
    /// the last interval extends to infinity.
    pub burn_segments: Vec<(f64, f64, f64)>,
    /// Burn-out time of the last burning stage.
    pub burnout_time: f64,
    /// Constant first moment of the non-burning mass about the aft end and of each burning
    /// stage: Σ m x = static_moment + Σ_stages (burning mass per length)·length·centroid.
    static_moment: f64,
    /// Per burning stage: (centroid station, length, burnable mass per length at ignition,
    /// burn rate per length, burn-out time).
    burning: Vec<(f64, f64, f64, f64, f64)>,
}

/// Rigid-body state at time t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RocketState {
    pub time: f64,
    pub mass: f64,
    /// Mass flow ṁ (≥ 0).
    pub mass_rate: f64,
    /// Velocity of the body (material points) along / across the launch axis.
    pub axial_velocity: f64,
    pub transverse_velocity: f64,
    /// Displacement of the body along / across the launch axis.
    pub axial_displacement: f64,
    pub transverse_displacement: f64,
    /// Axial acceleration of the body (ṁ v_e / m − g sin θ₀).
    pub axial_acceleration: f64,
    /// Mass-centre station from the aft end, and its rate of change.
    pub cg_station: f64,
    pub cg_station_rate: f64,
    /// Inertial position of the mass centre (aft end at the origin at t = 0).
    pub cg_x: f64,
    pub cg_y: f64,
    /// Inertial velocity of the mass centre, d/dt of (cg_x, cg_y): includes the drift of the
    /// mass-centre station as stage 1 burns.
    pub cg_vx: f64,
    pub cg_vy: f64,
    /// Inertial velocity of the body's material points = linear momentum / mass.
    pub body_vx: f64,
    pub body_vy: f64,
}

impl RocketTranslation {
    /// From a scene's `[rocket]` table.
    pub fn from_rocket(r: &Rocket) -> Result<Self> {
        let g = positive("gravity", r.gravity)?;
        let ve = positive("exhaust velocity", r.exhaust_velocity)?;
        finite("launch angle", r.launch_angle_deg)?;
        if r.nozzle_angle_deg != 0.0 {
            return Err(AnalyticError::Unsupported(
                "rocket translation: a misaligned nozzle (γ ≠ 0) makes the body rotate".into(),
            ));
        }
        if r.exit_pressure != 0.0 {
            return Err(AnalyticError::Unsupported(
                "rocket translation: exit pressure ≠ 0 needs the nozzle exit area".into(),
            ));
        }
        let mut x0 = 0.0;
        let mut mass0 = 0.0;
        let mut static_moment = 0.0;
        let mut burning = Vec::new();
        for s in &r.stages {
            positive("stage length", s.length)?;
            positive("stage weight per length", s.weight_per_length)?;
            non_negative("burn rate", s.burn_rate)?;
            let centroid = x0 + 0.5 * s.length;
            let m_len = s.weight_per_length / g;
            mass0 += m_len * s.length;
            if s.burn_rate > 0.0 {
                let casing = s.casing_weight_per_length.unwrap_or(0.0);
                non_negative("casing weight per length", casing)?;
                if casing > s.weight_per_length {
                    return Err(AnalyticError::InvalidParameter {
                        name: "casing weight per length",
                        value: casing,
                        why: "exceeds the stage weight per length",
                    });
                }
                let burnable = (s.weight_per_length - casing) / g;
                let rate = s.burn_rate / g;
                static_moment += casing / g * s.length * centroid;
                burning.push((centroid, s.length, burnable, rate, burnable / rate));
            } else {
                static_moment += m_len * s.length * centroid;
            }
            x0 += s.length;
        }
        for d in &r.discrete_masses {
            let m = d.weight / g;
            mass0 += m;
            static_moment += m * d.position;
        }
        // Mass law: breakpoints at each stage's burn-out.
        let mut times: Vec<f64> = burning.iter().map(|b| b.4).collect();
        times.push(0.0);
        times.sort_by(f64::total_cmp);
        times.dedup();
        let mut segments = Vec::new();
        for &t in &times {
            let rate: f64 = burning.iter().filter(|b| b.4 > t).map(|b| b.3 * b.1).sum();
            let burnt: f64 = burning.iter().map(|b| b.3 * b.1 * t.min(b.4)).sum();
            segments.push((t, mass0 - burnt, rate));
        }
        let burnout_time = burning.iter().map(|b| b.4).fold(0.0, f64::max);
        Ok(RocketTranslation {
            gravity: g,
            launch_angle_rad: r.launch_angle_deg.to_radians(),
            exhaust_velocity: ve,
            initial_mass: mass0,
            burn_segments: segments,
            burnout_time,
            static_moment,
            burning,
        })
    }

    /// State at time t ≥ 0 (closed form).
    pub fn state(&self, t: f64) -> Result<RocketState> {
        finite("t", t)?;
        if t < 0.0 {
            return Err(AnalyticError::InvalidParameter {
                name: "t",
                value: t,
                why: "must be >= 0",
            });
        }
        let g = self.gravity;
        let (sin0, cos0) = self.launch_angle_rad.sin_cos();
        let ve = self.exhaust_velocity;
        let m0 = self.initial_mass;
        // March over the constant-rate intervals up to t.
        let mut s = 0.0;
        let (mut mass, mut rate) = (m0, 0.0);
        for (k, &(ti, mi, mdot)) in self.burn_segments.iter().enumerate() {
            if ti > t {
                break;
            }
            let t_next = self.burn_segments.get(k + 1).map_or(f64::INFINITY, |n| n.0);
            let te = t.min(t_next);
            let tau = te - ti;
            let m_end = mi - mdot * tau;
            // Body velocity at ti from the rocket equation.
            let vi = ve * (m0 / mi).ln() - g * sin0 * ti;
            let thrust_part = if mdot > 0.0 {
                ve * (tau - m_end / mdot * (mi / m_end).ln())
            } else {
                0.0
            };
            s += vi * tau + thrust_part - 0.5 * g * sin0 * tau * tau;
            mass = m_end;
            rate = if te < t_next { mdot } else { 0.0 };
            if te < t_next {
                break;
            }
        }
        let v = ve * (m0 / mass).ln() - g * sin0 * t;
        let v_perp = -g * cos0 * t;
        let s_perp = -0.5 * g * cos0 * t * t;
        // Mass centre station and its rate.
        let mut moment = self.static_moment;
        let mut moment_rate = 0.0;
        for &(xc, len, burnable, r, t_out) in &self.burning {
            let remaining = (burnable - r * t.min(t_out)).max(0.0);
            moment += remaining * len * xc;
            if t < t_out {
                moment_rate -= r * len * xc;
            }
        }
        let x_cg = moment / mass;
        // d/dt (Σ m x / m) = (Ṁ_x m − Σmx ṁ_mass) / m², with dm/dt = −rate.
        let x_cg_rate = (moment_rate * mass + moment * rate) / (mass * mass);
        let (ex, ey) = (cos0, sin0); // axis
        let (nx, ny) = (-sin0, cos0); // across the axis
        let body_x = s * ex + s_perp * nx;
        let body_y = s * ey + s_perp * ny;
        let body_vx = v * ex + v_perp * nx;
        let body_vy = v * ey + v_perp * ny;
        Ok(RocketState {
            time: t,
            mass,
            mass_rate: rate,
            axial_velocity: v,
            transverse_velocity: v_perp,
            axial_displacement: s,
            transverse_displacement: s_perp,
            axial_acceleration: rate * ve / mass - g * sin0,
            cg_station: x_cg,
            cg_station_rate: x_cg_rate,
            cg_x: body_x + x_cg * ex,
            cg_y: body_y + x_cg * ey,
            cg_vx: body_vx + x_cg_rate * ex,
            cg_vy: body_vy + x_cg_rate * ey,
            body_vx,
            body_vy,
        })
    }

    /// States at the given times.
    pub fn history(&self, times: &[f64]) -> Result<Vec<RocketState>> {
        times.iter().map(|&t| self.state(t)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::numerics::ode::Dopri5;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    #[test]
    fn ana_rocket_mass_law_of_scene() {
        let scene = data::load_scene("rocket").unwrap();
        let r = RocketTranslation::from_rocket(scene.rocket().unwrap()).unwrap();
        let g = 386.09;
        let m0 = (4.25 * 100.0 + 3.0 * 50.0 + 18.0) / g;
        assert!(rel(r.initial_mass, m0) < 1e-15);
        // burn-out when 3 lb/in of 4.25 have burnt at 1.57 lb/in/s
        assert!(rel(r.burnout_time, 3.0 / 1.57) < 1e-15);
        let s = r.state(0.05).unwrap();
        assert!(rel(s.mass, m0 - 157.0 / g * 0.05) < 1e-14);
        let after = r.state(3.0).unwrap();
        assert!(rel(after.mass, (1.25 * 100.0 + 150.0 + 18.0) / g) < 1e-14);
        assert_eq!(after.mass_rate, 0.0);
    }

    #[test]
    fn ana_rocket_translation_matches_integration() {
        // Integrate m v̇ = ṁ v_e − m g sin θ₀, ṡ = v, and the mass law through burn-out; compare
        // velocity, displacement and the mass-centre motion (RK rtol 1e-13 ⇒ ≤ 1e-10 relative).
        for name in ["rocket", "rocket-launch-60"] {
            let scene = data::load_scene(name).unwrap();
            let r = RocketTranslation::from_rocket(scene.rocket().unwrap()).unwrap();
            let (sin0, _) = r.launch_angle_rad.sin_cos();
            let t_end = 2.5; // past burn-out at 1.91 s
            let tb = r.burnout_time;
            let mut y = [0.0, 0.0, r.initial_mass];
            let mut t = 0.0;
            let mut ode = Dopri5::new(3, 1e-13, 1e-12);
            for (end, mdot) in [(tb, r.burn_segments[0].2), (t_end, 0.0)] {
                let mut f = |_t: f64, y: &[f64], d: &mut [f64]| {
                    d[0] = mdot * r.exhaust_velocity / y[2] - r.gravity * sin0;
                    d[1] = y[0];
                    d[2] = -mdot;
                };
                ode.advance(&mut f, &mut t, &mut y, end).unwrap();
            }
            let s = r.state(t_end).unwrap();
            assert!(
                rel(s.axial_velocity, y[0]) < 1e-10,
                "{} vs {}",
                s.axial_velocity,
                y[0]
            );
            assert!(
                rel(s.axial_displacement, y[1]) < 1e-10,
                "{} vs {}",
                s.axial_displacement,
                y[1]
            );
            assert!(rel(s.mass, y[2]) < 1e-12);
            // Mass-centre velocity = finite difference of its position (h = 1e-5, O(h²)).
            for &tt in &[0.05, 1.0, 2.2] {
                let h = 1e-5;
                let (a, b) = (r.state(tt - h).unwrap(), r.state(tt + h).unwrap());
                let st = r.state(tt).unwrap();
                let vx = (b.cg_x - a.cg_x) / (2.0 * h);
                let vy = (b.cg_y - a.cg_y) / (2.0 * h);
                let scale = st.cg_vx.hypot(st.cg_vy).max(1.0);
                assert!((vx - st.cg_vx).abs() < 1e-6 * scale, "{vx} vs {}", st.cg_vx);
                assert!((vy - st.cg_vy).abs() < 1e-6 * scale, "{vy} vs {}", st.cg_vy);
            }
        }
    }

    #[test]
    fn ana_rocket_momentum_balance() {
        // Momentum of the remaining matter P = m v_body (material points). The gas leaves the
        // body with velocity v_body − v_e e_axis, so dP/dt = F_ext − ṁ (v_body − v_e e_axis):
        // checked by central differences of P (h = 1e-5, O(h²) ≈ 1e-10 relative, round-off
        // ~1e-16·P/h ≈ 1e-9 relative to dP/dt). θ₀ = 90°: axis = +y.
        let scene = data::load_scene("rocket").unwrap();
        let r = RocketTranslation::from_rocket(scene.rocket().unwrap()).unwrap();
        let h = 1e-5;
        for &t in &[0.02, 0.5, 1.5, 2.5] {
            let p = |t: f64| {
                let s = r.state(t).unwrap();
                s.mass * s.body_vy
            };
            let s = r.state(t).unwrap();
            let dp = (p(t + h) - p(t - h)) / (2.0 * h);
            let expected = -s.mass * r.gravity - s.mass_rate * (s.body_vy - r.exhaust_velocity);
            assert!(rel(dp, expected) < 1e-6, "t {t}: {dp} vs {expected}");
            // Across the axis only gravity acts (θ₀ = 90°: nothing across).
            assert!(s.body_vx.abs() < 1e-9 * s.body_vy.abs().max(1.0));
        }
    }
}
