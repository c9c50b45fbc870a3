//! Rigid two-link arm (Barhorst, seed 000 §2.1, with the links made rigid): the rigid limit of
//! `two-link-free` and its variants.
//!
//! Coordinates: q₁ = frame angle of link 1 from the inertial X axis, q₅ = elbow angle, so link 2
//! points along φ₂ = q₁ + q₅ (the slope of a rigid link 1 at its tip is 0). Work in absolute
//! angles φ₁ = q₁, φ₂ = q₁ + q₅, Δ = φ₂ − φ₁ = q₅. With uniform links (ρᵢ, Lᵢ, mᵢ = ρᵢLᵢ), tip
//! masses Mᵢ, tip inertias J_tᵢ and joint rotor inertias J_hᵢ (the elbow rotor turns with link 2):
//!
//! ```text
//! T = ½ A φ̇₁² + ½ B φ̇₂² + C cos Δ φ̇₁ φ̇₂
//!   A = J_h1 + m₁L₁²/3 + J_t1 + (M₁ + m₂ + M₂) L₁²
//!   B = J_h2 + m₂L₂²/3 + M₂L₂² + J_t2
//!   C = (m₂L₂/2 + M₂L₂) L₁
//! V = −G₁ g·e(φ₁) − G₂ g·e(φ₂) + ½K₁(q₁ − q̄₁)² + ½K₂(q₅ − q̄₅)²
//!   G₁ = m₁L₁/2 + (M₁ + m₂ + M₂) L₁,  G₂ = m₂L₂/2 + M₂L₂,  e(φ) = (cos φ, sin φ)
//! ```
//!
//! Lagrange's equations (τ₁, τ₅ joint torques: law − spring − damper; the elbow torque acts on
//! q₅ = φ₂ − φ₁, so its generalized forces are −τ₅ on φ₁ and +τ₅ on φ₂):
//!
//! ```text
//! A φ̈₁ + C cos Δ φ̈₂ = C sin Δ φ̇₂² + τ₁ − τ₅ + G₁ g·e⊥(φ₁)
//! C cos Δ φ̈₁ + B φ̈₂ = −C sin Δ φ̇₁² + τ₅ + G₂ g·e⊥(φ₂),   e⊥(φ) = (−sin φ, cos φ)
//! ```
//!
//! The state is augmented with the dissipated energy W_d = ∫(D₁q̇₁² + D₂q̇₅²)dt and the input work
//! W_in = ∫(τ₁,law q̇₁ + τ₅,law q̇₅)dt, so E − E₀ − W_in + W_d = 0 is checkable. Integrated by
//! Dormand–Prince 5(4) at rtol 1e-12, stepping exactly onto output times and torque-law
//! breakpoints (the laws are piecewise constant, so each step sees a smooth right-hand side).
//!
//! Units: consistent (ft, slug, s, lbf in the Barhorst scenes).

use serde::{Deserialize, Serialize};

use data::scene::{Link, PlanarChain, TorqueLaw};

use super::{law_breakpoints, reject};
use crate::analytic::error::{AnalyticError, Result, finite, non_negative, positive};
use crate::analytic::numerics::ode::{Dopri5, OdeStats};

/// One rigid uniform link with optional tip body and joint rotor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RigidBody {
    pub length: f64,
    pub mass_per_length: f64,
    pub tip_mass: f64,
    pub tip_inertia: f64,
    pub hub_inertia: f64,
}

/// Joint spring, damper, set-point and applied torque law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointModel {
    pub stiffness: f64,
    pub damping: f64,
    pub set_point: f64,
    pub torque: Option<TorqueLaw>,
    pub initial_angle: f64,
    pub initial_rate: f64,
}

/// The rigid two-link arm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigidTwoLink {
    pub links: [RigidBody; 2],
    pub joints: [JointModel; 2],
    /// Gravity vector \[gx, gy\] (zero if the scene has none).
    pub gravity: [f64; 2],
}

/// Sampled solution with the energy ledger.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TwoLinkHistory {
    pub time: Vec<f64>,
    pub q1: Vec<f64>,
    pub q5: Vec<f64>,
    pub rate1: Vec<f64>,
    pub rate5: Vec<f64>,
    /// Tip of link 2, inertial.
    pub tip_x: Vec<f64>,
    pub tip_y: Vec<f64>,
    pub kinetic: Vec<f64>,
    pub gravity_potential: Vec<f64>,
    pub spring_potential: Vec<f64>,
    pub input_work: Vec<f64>,
    pub dissipated: Vec<f64>,
    /// Integrator work counters.
    #[serde(skip)]
    pub stats: OdeStats,
}

/// Energy terms at one state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TwoLinkEnergy {
    pub kinetic: f64,
    pub gravity: f64,
    pub spring: f64,
}

fn body_from_link(link: &Link) -> RigidBody {
    RigidBody {
        length: link.length,
        mass_per_length: link.mass_per_length,
        tip_mass: link.tip_mass.unwrap_or(0.0),
        tip_inertia: link.tip_inertia.unwrap_or(0.0),
        hub_inertia: link.joint.hub_inertia.unwrap_or(0.0),
    }
}

fn joint_from_link(link: &Link) -> JointModel {
    let j = &link.joint;
    JointModel {
        stiffness: j.stiffness.unwrap_or(0.0),
        damping: j.damping.unwrap_or(0.0),
        set_point: j.set_point.unwrap_or(0.0),
        torque: j.torque.clone(),
        initial_angle: j.initial_angle,
        initial_rate: j.initial_rate,
    }
}

impl RigidTwoLink {
    /// Rigid limit of a two-link planar scene without contact (elastic fields, Kelvin–Voigt
    /// damping, foreshortening and shear vanish in the rigid limit and are ignored).
    pub fn from_chain(chain: &PlanarChain) -> Result<Self> {
        let [l1, l2] = chain.links.as_slice() else {
            return Err(AnalyticError::Unsupported(
                "rigid two-link reference: the scene must have exactly two links".into(),
            ));
        };
        reject(
            !chain.contacts.is_empty(),
            "rigid two-link reference: contact (use rigid::resting for the static limit)",
        )?;
        reject(
            chain.links.iter().any(|l| l.joint.prescribed.is_some()),
            "rigid two-link reference: prescribed joint motion",
        )?;
        let r = RigidTwoLink {
            links: [body_from_link(l1), body_from_link(l2)],
            joints: [joint_from_link(l1), joint_from_link(l2)],
            gravity: chain.gravity.as_ref().map_or([0.0, 0.0], |g| g.vector),
        };
        r.validate()?;
        Ok(r)
    }

    fn validate(&self) -> Result<()> {
        for b in &self.links {
            positive("link length", b.length)?;
            positive("mass per length", b.mass_per_length)?;
            non_negative("tip mass", b.tip_mass)?;
            non_negative("tip inertia", b.tip_inertia)?;
            non_negative("hub inertia", b.hub_inertia)?;
        }
        for j in &self.joints {
            non_negative("joint stiffness", j.stiffness)?;
            non_negative("joint damping", j.damping)?;
            finite("set point", j.set_point)?;
            finite("initial angle", j.initial_angle)?;
            finite("initial rate", j.initial_rate)?;
        }
        finite("gravity x", self.gravity[0])?;
        finite("gravity y", self.gravity[1])?;
        Ok(())
    }

    /// (A, B, C) of the kinetic energy.
    pub fn inertia_coefficients(&self) -> (f64, f64, f64) {
        let [l1, l2] = &self.links;
        let m1 = l1.mass_per_length * l1.length;
        let m2 = l2.mass_per_length * l2.length;
        let a = l1.hub_inertia
            + m1 * l1.length.powi(2) / 3.0
            + l1.tip_inertia
            + (l1.tip_mass + m2 + l2.tip_mass) * l1.length.powi(2);
        let b = l2.hub_inertia
            + m2 * l2.length.powi(2) / 3.0
            + l2.tip_mass * l2.length.powi(2)
            + l2.tip_inertia;
        let c = (0.5 * m2 * l2.length + l2.tip_mass * l2.length) * l1.length;
        (a, b, c)
    }

    /// First moments (G₁, G₂) of the gravity potential.
    fn gravity_moments(&self) -> (f64, f64) {
        let [l1, l2] = &self.links;
        let m2 = l2.mass_per_length * l2.length;
        let g1 = 0.5 * l1.mass_per_length * l1.length.powi(2)
            + (l1.tip_mass + m2 + l2.tip_mass) * l1.length;
        let g2 = 0.5 * m2 * l2.length + l2.tip_mass * l2.length;
        (g1, g2)
    }

    /// Mass matrix in (q₁, q₅).
    pub fn mass_matrix(&self, q5: f64) -> [[f64; 2]; 2] {
        let (a, b, c) = self.inertia_coefficients();
        let cc = c * q5.cos();
        // φ̇₁ = q̇₁, φ̇₂ = q̇₁ + q̇₅: T = ½[q̇₁ q̇₅] M [q̇₁ q̇₅]ᵀ
        [[a + b + 2.0 * cc, b + cc], [b + cc, b]]
    }

    /// Energy terms at (q, q̇).
    pub fn energy(&self, q: [f64; 2], qd: [f64; 2]) -> TwoLinkEnergy {
        let (a, b, c) = self.inertia_coefficients();
        let (g1, g2) = self.gravity_moments();
        let (p1, p2) = (q[0], q[0] + q[1]);
        let (w1, w2) = (qd[0], qd[0] + qd[1]);
        let g = self.gravity;
        let [j1, j2] = &self.joints;
        TwoLinkEnergy {
            kinetic: 0.5 * a * w1 * w1 + 0.5 * b * w2 * w2 + c * q[1].cos() * w1 * w2,
            gravity: -g1 * (g[0] * p1.cos() + g[1] * p1.sin())
                - g2 * (g[0] * p2.cos() + g[1] * p2.sin()),
            spring: 0.5 * j1.stiffness * (q[0] - j1.set_point).powi(2)
                + 0.5 * j2.stiffness * (q[1] - j2.set_point).powi(2),
        }
    }

    /// Tip of link 2 in inertial coordinates.
    pub fn tip_position(&self, q: [f64; 2]) -> [f64; 2] {
        let [l1, l2] = &self.links;
        let p2 = q[0] + q[1];
        [
            l1.length * q[0].cos() + l2.length * p2.cos(),
            l1.length * q[0].sin() + l2.length * p2.sin(),
        ]
    }

    /// Accelerations (q̈₁, q̈₅) at state (q, q̇) with applied law torques `law`.
    pub fn accelerations(&self, q: [f64; 2], qd: [f64; 2], law: [f64; 2]) -> [f64; 2] {
        let (a, b, c) = self.inertia_coefficients();
        let (g1, g2) = self.gravity_moments();
        let [j1, j2] = &self.joints;
        let tau1 = law[0] - j1.stiffness * (q[0] - j1.set_point) - j1.damping * qd[0];
        let tau5 = law[1] - j2.stiffness * (q[1] - j2.set_point) - j2.damping * qd[1];
        let (p1, p2) = (q[0], q[0] + q[1]);
        let (w1, w2) = (qd[0], qd[0] + qd[1]);
        let (s, co) = q[1].sin_cos();
        let g = self.gravity;
        let gperp = |p: f64| -g[0] * p.sin() + g[1] * p.cos();
        let r1 = c * s * w2 * w2 + tau1 - tau5 + g1 * gperp(p1);
        let r2 = -c * s * w1 * w1 + tau5 + g2 * gperp(p2);
        let m12 = c * co;
        let det = a * b - m12 * m12;
        let acc1 = (b * r1 - m12 * r2) / det;
        let acc2 = (a * r2 - m12 * r1) / det;
        [acc1, acc2 - acc1]
    }

    /// Integrates from the initial joint state and samples at `times` (ascending, ≥ 0).
    pub fn simulate(&self, times: &[f64]) -> Result<TwoLinkHistory> {
        self.validate()?;
        if times.windows(2).any(|w| w[1] < w[0]) || times.first().is_some_and(|&t| t < 0.0) {
            return Err(AnalyticError::InvalidParameter {
                name: "output times",
                value: times.first().copied().unwrap_or(0.0),
                why: "must be ascending and >= 0",
            });
        }
        let t_end = times.last().copied().unwrap_or(0.0);
        let mut stops: Vec<f64> = times.to_vec();
        for j in &self.joints {
            stops.extend(law_breakpoints(j.torque.as_ref(), t_end));
        }
        stops.sort_by(f64::total_cmp);
        stops.dedup();
        let [j1, j2] = &self.joints;
        let law = |j: &JointModel, t: f64| j.torque.as_ref().map_or(0.0, |l| l.torque(t));
        // state: q1, q5, q̇1, q̇5, W_d, W_in
        let mut y = [
            j1.initial_angle,
            j2.initial_angle,
            j1.initial_rate,
            j2.initial_rate,
            0.0,
            0.0,
        ];
        let mut t = 0.0;
        let mut ode = Dopri5::new(6, 1e-12, 1e-13);
        let mut hist = TwoLinkHistory::default();
        let mut next_out = 0;
        let record = |t: f64, y: &[f64; 6], hist: &mut TwoLinkHistory| {
            let q = [y[0], y[1]];
            let qd = [y[2], y[3]];
            let e = self.energy(q, qd);
            let tip = self.tip_position(q);
            hist.time.push(t);
            hist.q1.push(y[0]);
            hist.q5.push(y[1]);
            hist.rate1.push(y[2]);
            hist.rate5.push(y[3]);
            hist.tip_x.push(tip[0]);
            hist.tip_y.push(tip[1]);
            hist.kinetic.push(e.kinetic);
            hist.gravity_potential.push(e.gravity);
            hist.spring_potential.push(e.spring);
            hist.dissipated.push(y[4]);
            hist.input_work.push(y[5]);
        };
        for &stop in &stops {
            if stop > t {
                // The laws are constant on (t, stop): sample them at the midpoint.
                let tau = [law(j1, 0.5 * (t + stop)), law(j2, 0.5 * (t + stop))];
                let mut f = |_t: f64, s: &[f64], d: &mut [f64]| {
                    let acc = self.accelerations([s[0], s[1]], [s[2], s[3]], tau);
                    d[0] = s[2];
                    d[1] = s[3];
                    d[2] = acc[0];
                    d[3] = acc[1];
                    d[4] = j1.damping * s[2] * s[2] + j2.damping * s[3] * s[3];
                    d[5] = tau[0] * s[2] + tau[1] * s[3];
                };
                ode.advance(&mut f, &mut t, &mut y, stop)?;
            }
            while next_out < times.len() && times[next_out] <= t {
                record(times[next_out], &y, &mut hist);
                next_out += 1;
            }
        }
        hist.stats = ode.stats;
        Ok(hist)
    }
}

/// Output times 0, Δ, 2Δ, … ≤ t_end, with t_end appended when it is not on the grid.
pub fn output_times(t_end: f64, interval: f64) -> Vec<f64> {
    if !(t_end > 0.0 && interval > 0.0 && t_end.is_finite()) {
        return vec![0.0];
    }
    // Tolerate round-off in t_end / Δ so that an exact multiple does not lose its last sample.
    let n = (t_end / interval * (1.0 + 1e-12)).floor() as usize;
    let mut v: Vec<f64> = (0..=n).map(|i| (i as f64 * interval).min(t_end)).collect();
    let last = v[v.len() - 1];
    if t_end - last > 1e-9 * interval {
        v.push(t_end);
    } else {
        v[n] = t_end;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rigid arm of a scene, with any contact removed (the free-flight dynamics).
    fn arm(name: &str) -> RigidTwoLink {
        let scene = data::load_scene(name).unwrap();
        let chain = PlanarChain {
            contacts: Vec::new(),
            ..scene.planar_chain().unwrap().clone()
        };
        RigidTwoLink::from_chain(&chain).unwrap()
    }

    #[test]
    fn ana_two_link_mass_matrix_is_kinetic_hessian() {
        // M(q) must equal ∂²T/∂q̇² (central differences of the kinetic energy; T is quadratic
        // in q̇, so the only error is round-off ~ ε T / h² with h = 1e-3 → 1e-9 relative).
        let mut r = arm("barhorst-case1-tipmass");
        r.links[0].tip_mass = 0.3;
        r.links[0].tip_inertia = 0.05;
        r.links[1].tip_inertia = 0.02;
        r.links[1].hub_inertia = 0.01;
        let q = [0.4, 0.9];
        let m = r.mass_matrix(q[1]);
        let h = 1e-3;
        let t = |qd: [f64; 2]| r.energy(q, qd).kinetic;
        for i in 0..2 {
            for j in 0..2 {
                let mut pp = [0.3, -0.2];
                let mut pm = pp;
                let mut mp = pp;
                let mut mm = pp;
                pp[i] += h;
                pp[j] += h;
                pm[i] += h;
                pm[j] -= h;
                mp[i] -= h;
                mp[j] += h;
                mm[i] -= h;
                mm[j] -= h;
                let hess = (t(pp) - t(pm) - t(mp) + t(mm)) / (4.0 * h * h);
                assert!(
                    (hess - m[i][j]).abs() < 1e-8 * m[0][0],
                    "{i}{j}: {hess} vs {}",
                    m[i][j]
                );
            }
        }
    }

    #[test]
    fn ana_two_link_static_forces_are_energy_gradient() {
        // At rest (q̇ = 0, no law torque), M q̈ = −∂V/∂q: compare with central differences of
        // the potential (h = 1e-6, error O(h²) ≈ 1e-12 relative plus round-off).
        let r = arm("barhorst-case1-stiff-elbow");
        let q = [0.3, -0.4];
        let acc = r.accelerations(q, [0.0, 0.0], [0.0, 0.0]);
        let m = r.mass_matrix(q[1]);
        let f = [
            m[0][0] * acc[0] + m[0][1] * acc[1],
            m[1][0] * acc[0] + m[1][1] * acc[1],
        ];
        let v = |q: [f64; 2]| {
            let e = r.energy(q, [0.0, 0.0]);
            e.gravity + e.spring
        };
        let h = 1e-6;
        for i in 0..2 {
            let mut qp = q;
            let mut qm = q;
            qp[i] += h;
            qm[i] -= h;
            let grad = (v(qp) - v(qm)) / (2.0 * h);
            let scale = f[0].abs().max(f[1].abs());
            assert!(
                (f[i] + grad).abs() < 1e-7 * scale,
                "{i}: {} vs {}",
                f[i],
                -grad
            );
        }
    }

    #[test]
    fn ana_two_link_undamped_conserves_energy() {
        let r = arm("two-link-free-undamped");
        assert_eq!(r.joints[0].damping, 0.0);
        let times = output_times(10.0, 0.01);
        let h = r.simulate(&times).unwrap();
        let e = |i: usize| h.kinetic[i] + h.gravity_potential[i] + h.spring_potential[i];
        let e0 = e(0);
        let scale = (0..h.time.len())
            .map(|i| h.kinetic[i])
            .fold(e0.abs(), f64::max);
        for i in 0..h.time.len() {
            // rtol 1e-12 over ~1000 steps: drift ≲ 1e-9 of the energy scale.
            assert!(
                (e(i) - e0).abs() < 1e-9 * scale,
                "t = {}: {}",
                h.time[i],
                e(i) - e0
            );
        }
        assert_eq!(h.time.len(), 1001);
        assert_eq!(*h.time.last().unwrap(), 10.0);
    }

    #[test]
    fn ana_two_link_damped_ledger_closes() {
        let r = arm("two-link-free");
        let h = r.simulate(&output_times(10.0, 0.01)).unwrap();
        let e = |i: usize| h.kinetic[i] + h.gravity_potential[i] + h.spring_potential[i];
        let scale = e(0).abs();
        for i in 0..h.time.len() {
            let closure = e(i) - e(0) - h.input_work[i] + h.dissipated[i];
            // Same integration tolerance as above.
            assert!(closure.abs() < 1e-9 * scale, "t = {}: {closure}", h.time[i]);
        }
        // No input: the mechanical energy never increases (up to the integration error) and
        // the dampers have taken a sizeable part of it by 10 s.
        for i in 1..h.time.len() {
            assert!(e(i) <= e(i - 1) + 1e-9 * scale, "t = {}", h.time[i]);
        }
        let last = h.time.len() - 1;
        assert!(
            h.dissipated[last] > 0.5 * e(0),
            "{} of {}",
            h.dissipated[last],
            e(0)
        );
    }

    #[test]
    fn ana_two_link_small_motion_is_modal_superposition() {
        // Linearised about q = 0 without gravity and damping: M₀ q̈ + K q = 0. Exact solution by
        // the 2×2 generalized eigenproblem (closed form). Amplitude 1e-6 rad: the neglected
        // terms are O(amplitude) relative (~1e-12 absolute); the integrator's atol 1e-13 per
        // step accumulates to ≲ 1e-11 over 3 s. Check to 1e-10 = 1e-4 of the amplitude.
        let mut r = arm("two-link-free-undamped");
        r.joints[0].initial_angle = 1e-6;
        r.joints[1].initial_angle = -0.5e-6;
        let m = r.mass_matrix(0.0);
        let (k1, k2) = (r.joints[0].stiffness, r.joints[1].stiffness);
        // det(K − ω² M) = 0: (m00 m11 − m01²) ω⁴ − (k1 m11 + k2 m00) ω² + k1 k2 = 0
        let a = m[0][0] * m[1][1] - m[0][1] * m[0][1];
        let b = k1 * m[1][1] + k2 * m[0][0];
        let c = k1 * k2;
        let disc = (b * b - 4.0 * a * c).sqrt();
        let w2 = [(b - disc) / (2.0 * a), (b + disc) / (2.0 * a)];
        // mode shapes φ = (m01 ω², k1 − m00 ω²)ᵀ (first row of K − ω²M annihilated)
        let phi: Vec<[f64; 2]> = w2
            .iter()
            .map(|&w| [m[0][1] * w, k1 - m[0][0] * w])
            .collect();
        // modal amplitudes from q(0) = Φ c (released from rest)
        let q0 = [1e-6, -0.5e-6];
        let det = phi[0][0] * phi[1][1] - phi[1][0] * phi[0][1];
        let c0 = (q0[0] * phi[1][1] - q0[1] * phi[1][0]) / det;
        let c1 = (phi[0][0] * q0[1] - phi[0][1] * q0[0]) / det;
        let times = output_times(3.0, 0.05);
        let h = r.simulate(&times).unwrap();
        for (i, &t) in times.iter().enumerate() {
            let (a0, a1) = (c0 * (w2[0].sqrt() * t).cos(), c1 * (w2[1].sqrt() * t).cos());
            let q1 = a0 * phi[0][0] + a1 * phi[1][0];
            let q5 = a0 * phi[0][1] + a1 * phi[1][1];
            assert!((h.q1[i] - q1).abs() < 1e-10, "t {t}: {} vs {q1}", h.q1[i]);
            assert!((h.q5[i] - q5).abs() < 1e-10, "t {t}: {} vs {q5}", h.q5[i]);
        }
    }

    #[test]
    fn ana_two_link_output_grid() {
        let t = output_times(10.0, 0.01);
        assert_eq!(t.len(), 1001);
        assert_eq!(t[1000], 10.0);
        let t = output_times(1.0, 0.3);
        assert_eq!(t, vec![0.0, 0.3, 0.6, 0.8999999999999999, 1.0]);
        assert_eq!(output_times(0.0, 0.1), vec![0.0]);
    }

    #[test]
    fn ana_two_link_torque_law_work() {
        // A bang-bang law on the elbow: the ledger still closes across its breakpoints.
        let mut r = arm("two-link-free");
        r.joints[1].torque = Some(TorqueLaw::BangBang {
            amplitude: 5.0,
            switch: 0.333,
            off: 0.777,
        });
        let h = r.simulate(&output_times(2.0, 0.1)).unwrap();
        let e = |i: usize| h.kinetic[i] + h.gravity_potential[i] + h.spring_potential[i];
        let last = h.time.len() - 1;
        let closure = e(last) - e(0) - h.input_work[last] + h.dissipated[last];
        assert!(closure.abs() < 1e-9 * e(0).abs());
        assert!(h.input_work[last] != 0.0);
        assert!(
            RigidTwoLink::from_chain(
                data::load_scene("barhorst-case1")
                    .unwrap()
                    .planar_chain()
                    .unwrap()
            )
            .is_err()
        );
    }
}
