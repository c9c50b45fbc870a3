//! Seed 001 eq. 71: rigid link whose tip slides on a circular wall with Coulomb friction.
//!
//! Setting: a uniform link (ρA, L) pinned at a hub (rotor inertia J_h) with a tip mass M (and tip
//! inertia J_tip), horizontal plane, hub torque τ(t); the tip must stay on the circle of radius L
//! about the hub (bilateral), friction coefficient μ against sliding.
//!
//! **Why the wall load is not given by rigid-body dynamics.** For a rigid pinned link the circle
//! constraint is redundant with the pin: the radial forces at the pin and at the wall are
//! statically indeterminate. The flexible model fixes them: with the axial field on and both
//! ends held radially (u(0) = 0 at the hub, u(L) = 0 at the wall), quasi-static axial
//! equilibrium in the frame rotating at θ̇ (axial inertia ü → 0 as EA → ∞, v → 0 as EI → ∞) is
//!
//! `EA u'' = −ρA θ̇² x`  ⇒  `u = ρAθ̇²(L²x − x³)/(6EA)`,  `N(x) = EA u' = ρAθ̇²(L² − 3x²)/6`,
//!
//! independent of EA. The root carries N(0) = ρAL²θ̇²/6; at the tip N(L) = −ρAL²θ̇²/3
//! (compression). Radial balance of the tip mass, −M L θ̇² = −N(L) − R, gives the inward wall
//! load
//!
//! `R = (M + ρAL/3) L θ̇²`
//!
//! (the tip mass's centripetal force plus two thirds of the beam's). Friction μR acts
//! tangentially against the sliding velocity Lθ̇, i.e. a hub moment −μ R L sign θ̇; the normal
//! load has no moment about the hub. Seed 001 eq. 71 with Φ = X² + Y² − L² (b = 2X, c = 2Y) is
//! `J θ̈ = τ − λ μ sign(λ)·2L²`, |λ|·|∇Φ| = |λ|·2L = R, which is the same statement; its printed
//! inertia "I(⅓M* + M)" is garbled OCR of J = J_h + ρAL³/3 + ML² (+ J_tip). Hence
//!
//! `θ̈ = a − b θ̇|θ̇|`, `a = τ/J`, `b = μ (M + ρAL/3) L² / J`.
//!
//! Closed form for constant a > 0 (k = sqrt(a/b), c = sqrt(ab)):
//! * 0 ≤ θ̇₀ < k: θ̇ = k tanh(u₀ + ct), θ = θ₀ + ln(cosh(u₀ + ct)/cosh u₀)/b, u₀ = atanh(θ̇₀/k);
//! * θ̇₀ > k: θ̇ = k coth(v₀ + ct), θ = θ₀ + ln(sinh(v₀ + ct)/sinh v₀)/b, v₀ = atanh(k/θ̇₀);
//! * θ̇₀ < 0 (moving against the torque): θ̇ = −k tan(φ₀ − ct), φ₀ = atan(|θ̇₀|/k), until θ̇ = 0
//!   at t = φ₀/c, θ = θ₀ − ln(cos(φ₀ − ct)/cos φ₀)/b; then the first case from rest.
//! * a = 0: θ̇ = θ̇₀/(1 + b|θ̇₀|t), θ = θ₀ + sign(θ̇₀) ln(1 + b|θ̇₀|t)/b; a < 0 by symmetry.
//!
//! There is no stick phase: the normal load, hence friction, vanishes with θ̇.
//! Energy: input work ∫τθ̇ = ΣΔθ_i τ_i, friction work W_f = W_in − (T − T₀) ≥ 0.
//!
//! Units: consistent (SI in the `constrained-arm` scene).

use serde::{Deserialize, Serialize};

use data::scene::{ContactMode, PlanarChain, Surface, TorqueLaw};

use super::{law_breakpoints, link_inertia_about_root, reject};
use crate::analytic::error::{AnalyticError, Result, finite, non_negative, positive};

/// Parameters of the friction-constrained rigid link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConstrainedRigidLink {
    /// Mass per length ρA.
    pub mass_per_length: f64,
    /// Length L (= wall radius).
    pub length: f64,
    /// Tip mass M.
    pub tip_mass: f64,
    /// Total rotary inertia about the hub J.
    pub inertia: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    pub angle0: f64,
    pub rate0: f64,
    pub torque: Option<TorqueLaw>,
}

/// State of the constrained link at time t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConstrainedState {
    pub time: f64,
    pub angle: f64,
    pub rate: f64,
    pub torque: f64,
    /// Inward wall load R = (M + ρAL/3) L θ̇² (the normal-force magnitude).
    pub normal_force: f64,
    /// Tangential friction force μR (magnitude).
    pub friction_force: f64,
    pub kinetic_energy: f64,
    /// ∫₀ᵗ τθ̇ dt.
    pub input_work: f64,
    /// Energy dissipated by friction ∫₀ᵗ μR L|θ̇| dt.
    pub friction_work: f64,
}

/// ln cosh x without overflow.
fn ln_cosh(x: f64) -> f64 {
    let a = x.abs();
    a + (-2.0 * a).exp().ln_1p() - std::f64::consts::LN_2
}

/// ln sinh x for x > 0 without overflow.
fn ln_sinh(x: f64) -> f64 {
    if x < 1.0 {
        x.sinh().ln()
    } else {
        x + (-(-2.0 * x).exp()).ln_1p() - std::f64::consts::LN_2
    }
}

/// Exact solution of θ̈ = a − b θ̇|θ̇| (b ≥ 0, constant a) from (θ₀, θ̇₀) after time h ≥ 0.
pub fn evolve_quadratic_friction(a: f64, b: f64, theta0: f64, rate0: f64, h: f64) -> (f64, f64) {
    // Symmetry θ → −θ maps a → −a: reduce to a > 0, or a = 0 with θ̇₀ ≥ 0.
    if a < 0.0 || (a == 0.0 && rate0 < 0.0) {
        let (th, om) = evolve_quadratic_friction(-a, b, -theta0, -rate0, h);
        return (-th, -om);
    }
    if b == 0.0 {
        return (theta0 + rate0 * h + 0.5 * a * h * h, rate0 + a * h);
    }
    if a == 0.0 {
        let g = b * rate0 * h;
        return (theta0 + g.ln_1p() / b, rate0 / (1.0 + g));
    }
    let k = (a / b).sqrt();
    let c = (a * b).sqrt();
    if rate0 < 0.0 {
        let phi0 = (-rate0 / k).atan();
        let t_stop = phi0 / c;
        if h <= t_stop {
            let phi = phi0 - c * h;
            return (theta0 - (phi.cos() / phi0.cos()).ln() / b, -k * phi.tan());
        }
        let theta_stop = theta0 + phi0.cos().ln() / b;
        return evolve_quadratic_friction(a, b, theta_stop, 0.0, h - t_stop);
    }
    if rate0 < k {
        let u0 = (rate0 / k).atanh();
        let u = u0 + c * h;
        (theta0 + (ln_cosh(u) - ln_cosh(u0)) / b, k * u.tanh())
    } else if rate0 > k {
        let v0 = (k / rate0).atanh();
        let v = v0 + c * h;
        (theta0 + (ln_sinh(v) - ln_sinh(v0)) / b, k / v.tanh())
    } else {
        (theta0 + k * h, k)
    }
}

impl ConstrainedRigidLink {
    /// Rigid limit of a one-link scene whose tip is held on a circle of radius L about the hub.
    pub fn from_chain(chain: &PlanarChain) -> Result<Self> {
        let link = super::torque_driven_single_link(chain, "constrained rigid link")?;
        let j = &link.joint;
        let [contact] = chain.contacts.as_slice() else {
            return Err(AnalyticError::Unsupported(
                "constrained rigid link: exactly one contact is required".into(),
            ));
        };
        reject(
            contact.mode != ContactMode::Bilateral,
            "constrained rigid link: the wall contact must be bilateral",
        )?;
        match contact.surface {
            Surface::Circle { center, radius } => {
                let tol = 1e-12 * link.length;
                reject(
                    center[0].abs() > tol
                        || center[1].abs() > tol
                        || (radius - link.length).abs() > tol,
                    "constrained rigid link: the wall must be the circle of radius L about the hub",
                )?;
            }
            Surface::Line { .. } => {
                return Err(AnalyticError::Unsupported(
                    "constrained rigid link: only a circular wall".into(),
                ));
            }
        }
        let r = ConstrainedRigidLink {
            mass_per_length: link.mass_per_length,
            length: link.length,
            tip_mass: link.tip_mass.unwrap_or(0.0),
            inertia: link_inertia_about_root(link),
            friction: contact.friction,
            angle0: j.initial_angle,
            rate0: j.initial_rate,
            torque: j.torque.clone(),
        };
        positive("inertia", r.inertia)?;
        non_negative("friction", r.friction)?;
        Ok(r)
    }

    /// Wall-load coefficient: R = wall_load_factor · θ̇², i.e. (M + ρAL/3) L.
    pub fn wall_load_factor(&self) -> f64 {
        (self.tip_mass + self.mass_per_length * self.length / 3.0) * self.length
    }

    /// b in θ̈ = a − b θ̇|θ̇|.
    pub fn friction_coefficient_b(&self) -> f64 {
        self.friction * self.wall_load_factor() * self.length / self.inertia
    }

    /// Terminal speed sqrt(a/b) under a constant torque τ (∞ without friction).
    pub fn terminal_rate(&self, tau: f64) -> f64 {
        (tau.abs() / self.inertia / self.friction_coefficient_b()).sqrt()
    }

    /// State at time t ≥ 0 (closed form, piecewise over the torque law's breakpoints).
    pub fn state(&self, t: f64) -> Result<ConstrainedState> {
        finite("t", t)?;
        if t < 0.0 {
            return Err(AnalyticError::InvalidParameter {
                name: "t",
                value: t,
                why: "must be >= 0",
            });
        }
        let b = self.friction_coefficient_b();
        let tau_at = |s: f64| self.torque.as_ref().map_or(0.0, |l| l.torque(s));
        let (mut th, mut om) = (self.angle0, self.rate0);
        let mut t0 = 0.0;
        let mut work = 0.0;
        let mut bounds = law_breakpoints(self.torque.as_ref(), t);
        bounds.push(t);
        for tb in bounds {
            let tau = tau_at(0.5 * (t0 + tb));
            let (th1, om1) = evolve_quadratic_friction(tau / self.inertia, b, th, om, tb - t0);
            work += tau * (th1 - th);
            th = th1;
            om = om1;
            t0 = tb;
        }
        let ke = 0.5 * self.inertia * om * om;
        let normal = self.wall_load_factor() * om * om;
        Ok(ConstrainedState {
            time: t,
            angle: th,
            rate: om,
            torque: tau_at(t),
            normal_force: normal,
            friction_force: self.friction * normal,
            kinetic_energy: ke,
            input_work: work,
            friction_work: work - (ke - 0.5 * self.inertia * self.rate0 * self.rate0),
        })
    }

    /// States at the given times.
    pub fn history(&self, times: &[f64]) -> Result<Vec<ConstrainedState>> {
        times.iter().map(|&t| self.state(t)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::numerics::ode::Dopri5;

    fn integrate(
        a_of: &dyn Fn(f64) -> f64,
        b: f64,
        y0: [f64; 2],
        t_end: f64,
        brk: &[f64],
    ) -> [f64; 3] {
        // [θ, θ̇, friction work]; piecewise-constant a, integration restarted at breakpoints.
        let mut y = [y0[0], y0[1], 0.0];
        let mut t = 0.0;
        let mut ode = Dopri5::new(3, 1e-13, 1e-15);
        let mut ends: Vec<f64> = brk.iter().copied().filter(|&s| s < t_end).collect();
        ends.push(t_end);
        for e in ends {
            let a = a_of(0.5 * (t + e));
            let mut f = |_t: f64, y: &[f64], d: &mut [f64]| {
                d[0] = y[1];
                d[1] = a - b * y[1] * y[1].abs();
                d[2] = b * y[1].abs().powi(3);
            };
            ode.advance(&mut f, &mut t, &mut y, e).unwrap();
        }
        y
    }

    #[test]
    fn ana_constrained_closed_form_matches_integration_all_branches() {
        let b = 0.7;
        // (a, θ̇₀): below / above / at terminal speed, against the torque, a = 0, a < 0.
        for &(a, w0) in &[
            (2.0, 0.0),
            (2.0, 0.5),
            (2.0, 5.0),
            (2.0, (2.0f64 / 0.7).sqrt()),
            (2.0, -3.0),
            (0.0, 2.0),
            (0.0, -2.0),
            (-1.5, 1.0),
        ] {
            for &h in &[0.1, 1.0, 4.0] {
                let (th, om) = evolve_quadratic_friction(a, b, 0.3, w0, h);
                let y = integrate(&|_| a, b, [0.3, w0], h, &[]);
                // RK at rtol 1e-13: ≤ 1e-11 absolute on O(1) values.
                assert!(
                    (th - y[0]).abs() < 1e-10,
                    "a {a} w0 {w0} h {h}: {th} vs {}",
                    y[0]
                );
                assert!(
                    (om - y[1]).abs() < 1e-10,
                    "a {a} w0 {w0} h {h}: {om} vs {}",
                    y[1]
                );
            }
        }
    }

    #[test]
    fn ana_constrained_scene_terminal_speed_and_ledger() {
        let scene = data::load_scene("constrained-arm").unwrap();
        let r = ConstrainedRigidLink::from_chain(scene.planar_chain().unwrap()).unwrap();
        // J = 0.01 + 1/3 + 0.5; wall factor (0.5 + 1/3)·1.
        assert!((r.inertia - (0.01 + 1.0 / 3.0 + 0.5)).abs() < 1e-15);
        assert!((r.wall_load_factor() - (0.5 + 1.0 / 3.0)).abs() < 1e-15);
        let s = r.state(2.0).unwrap();
        let k = r.terminal_rate(2.0);
        assert!(s.rate > 0.0 && s.rate < k);
        // tanh approach from rest: θ̇(t) = k tanh(ct).
        let c = (2.0 / r.inertia * r.friction_coefficient_b()).sqrt();
        assert!((s.rate - k * (c * 2.0).tanh()).abs() < 1e-14 * k);
        // Against direct integration of the ODE including the friction work.
        let b = r.friction_coefficient_b();
        let y = integrate(&|_| 2.0 / r.inertia, b, [0.0, 0.0], 2.0, &[]);
        assert!((s.angle - y[0]).abs() < 1e-10);
        // friction work from the ODE is ∫ b J |θ̇|³ dt (= μ R L |θ̇|).
        assert!(
            (s.friction_work - r.inertia * y[2]).abs() < 1e-10,
            "{} vs {}",
            s.friction_work,
            r.inertia * y[2]
        );
        assert!(s.friction_work > 0.0);
        // Normal force = (M + ρAL/3) L θ̇².
        assert!((s.normal_force - r.wall_load_factor() * s.rate * s.rate).abs() < 1e-14);
    }

    #[test]
    fn ana_constrained_piecewise_torque() {
        // Torque switched off at 1 s: afterwards θ̇ decays as 1/(1 + b θ̇₁ t).
        let mut r = ConstrainedRigidLink::from_chain(
            data::load_scene("constrained-arm")
                .unwrap()
                .planar_chain()
                .unwrap(),
        )
        .unwrap();
        r.torque = Some(TorqueLaw::Constant {
            value: 2.0,
            until: Some(1.0),
        });
        r.rate0 = -1.0; // start moving against the torque: exercises the tan branch
        let b = r.friction_coefficient_b();
        let a = 2.0 / r.inertia;
        let y = integrate(
            &|t| if t < 1.0 { a } else { 0.0 },
            b,
            [0.0, -1.0],
            3.0,
            &[1.0],
        );
        let s = r.state(3.0).unwrap();
        assert!((s.angle - y[0]).abs() < 1e-10);
        assert!((s.rate - y[1]).abs() < 1e-10);
        assert!((s.friction_work - r.inertia * y[2]).abs() < 1e-10);
    }

    #[test]
    fn ana_constrained_wall_load_from_axial_equilibrium() {
        // Independent check of R = (M + ρAL/3) L θ̇²: solve the axial two-point problem
        // EA u'' = −ρA θ̇² x, u(0) = u(L) = 0 by shooting on u'(0) (linear: one shot plus a
        // correction), then R = M L θ̇² − N(L) with N = EA u'.
        let (ea, ra, l, m, w) = (1e6, 1.0, 1.0, 0.5, 3.0);
        let shoot = |du0: f64| {
            let mut f = |x: f64, y: &[f64], d: &mut [f64]| {
                d[0] = y[1];
                d[1] = -ra * w * w * x / ea;
            };
            let mut y = [0.0, du0];
            let mut x = 0.0;
            let mut ode = Dopri5::new(2, 1e-13, 1e-20);
            ode.advance(&mut f, &mut x, &mut y, l).unwrap();
            y
        };
        let y0 = shoot(0.0);
        let y1 = shoot(1e-6);
        let du0 = -y0[0] / ((y1[0] - y0[0]) / 1e-6);
        let y = shoot(du0);
        let r_wall = m * l * w * w - ea * y[1];
        let r = ConstrainedRigidLink {
            mass_per_length: ra,
            length: l,
            tip_mass: m,
            inertia: 1.0,
            friction: 0.2,
            angle0: 0.0,
            rate0: 0.0,
            torque: None,
        };
        // Linear problem, RK exact for a cubic u up to round-off: 1e-9 relative.
        let expected = r.wall_load_factor() * w * w;
        assert!(
            (r_wall - expected).abs() < 1e-9 * expected,
            "{r_wall} vs {expected}"
        );
    }
}
