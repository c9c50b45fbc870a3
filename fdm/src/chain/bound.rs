//! The chain's step bound: 0.9 · 2/ω_max of the chain linearized at rest (power iteration,
//! once per run), the per-link 5.44 with the Kelvin–Voigt factor, the fastest damping rate
//! κ_max, and the Timoshenko links' shear bound (see [`super`]).

// Index loops over the power-iteration vectors read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::model::{SHEAR_SITE, TIP_SITE, TwoLinkChain};
use crate::system::{Bound, BoundKind, System, damped_step_factor};

impl TwoLinkChain {
    /// Highest ω of the chain linearized about its initial state at rest: power iteration on
    /// −∂a/∂q (columns by forward differences of the accelerations), and the bound site of
    /// that mode: a ghost's rotation mode when its ghost is the mode's largest component, else
    /// the coupled chain's. Once per run, O(n²).
    pub(super) fn top_frequency(&mut self) -> (f64, usize) {
        let (q0, _) = self.initial_state();
        let rest = vec![0.0; self.dofs()];
        let (omega2, largest) = self.top_eigen(0.0, &q0, &rest, false);
        let site = if let Some(k) = self.slots.iter().position(|&s| s == largest) {
            3 + k
        } else if self.tip_ghost == Some(largest) {
            TIP_SITE
        } else {
            2
        };
        // power iteration approaches the top eigenvalue from below: 2 % margin on ω
        (1.02 * omega2.sqrt(), site)
    }

    /// Fastest damping rate κ_max (largest |eigenvalue| of −∂a/∂q̇) at the initial state at
    /// rest, 2 % margin. The joint dampers act on the clamp rotations with their tiny
    /// half-cell inertia J_c: strongly overdamped modes whose velocity-form limit is τ ≤ 1/κ.
    pub(super) fn top_damping_rate(&mut self) -> f64 {
        let (q0, _) = self.initial_state();
        let rest = vec![0.0; self.dofs()];
        1.02 * self.top_eigen(0.0, &q0, &rest, true).0
    }

    /// Largest |eigenvalue| of −∂a/∂q (`wrt_v` false: ω²_max) or −∂a/∂q̇ (`wrt_v` true: the
    /// fastest damping rate κ = c/m) at (q, q̇), by power iteration on a forward-difference
    /// Jacobian (no margin), and the coordinate of its vector's largest component.
    pub(super) fn top_eigen(
        &mut self,
        t: f64,
        q0: &[f64],
        v0: &[f64],
        wrt_v: bool,
    ) -> (f64, usize) {
        let n = self.dofs();
        let (q0, v) = (q0, v0);
        let lambda = self.constraint.lambda;
        let mut a0 = vec![0.0; n];
        self.accel(t, q0, v, &mut a0);
        let mut jac = vec![0.0; n * n];
        let mut a = vec![0.0; n];
        let mut q = q0.to_vec();
        let mut vv = v.to_vec();
        for j in 0..n {
            let eps;
            if wrt_v {
                eps = 1e-7 * (1.0 + v[j].abs());
                vv[j] = v[j] + eps;
                self.accel(t, q0, &vv, &mut a);
                vv[j] = v[j];
            } else {
                eps = 1e-7 * (1.0 + q0[j].abs());
                q[j] = q0[j] + eps;
                self.accel(t, &q, v, &mut a);
                q[j] = q0[j];
            }
            for i in 0..n {
                jac[i * n + j] = -(a[i] - a0[i]) / eps;
            }
        }
        self.constraint.lambda = lambda;
        let mut x: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
        let mut y = vec![0.0; n];
        let mut lam = 0.0;
        for _ in 0..400 {
            for i in 0..n {
                y[i] = (0..n).map(|j| jac[i * n + j] * x[j]).sum();
            }
            lam = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if lam == 0.0 || !lam.is_finite() {
                break;
            }
            for i in 0..n {
                x[i] = y[i] / lam;
            }
        }
        let largest = (0..n).fold(0, |m, i| if x[i].abs() > x[m].abs() { i } else { m });
        (lam.max(0.0), largest)
    }

    /// The step bound σ of the chain (the [`System::bound`] of [`TwoLinkChain`]).
    pub(super) fn step_bound(&self) -> Bound {
        // implicit damping ([`super::implicit`]): the undamped bound (ζ = 0 throughout)
        self.step_bound_with(if self.implicit_damping() { 0.0 } else { 1.0 })
    }

    /// The step bound with the damping explicit (the damped bound), whatever the kick: the
    /// step that resolves the damping's own time scale.
    pub fn explicit_damping_bound(&self) -> f64 {
        self.step_bound_with(1.0).sigma
    }

    /// The step bound, the damping weighed by `explicit` (1: explicit, 0: implicit).
    fn step_bound_with(&self, explicit: f64) -> Bound {
        // 5.44 per link (σ² = h⁴ρA/(4EI)) with the Kelvin–Voigt factor of the shortest wave
        // (as for the single link); the smaller binds.
        // The measured top frequency of the coupled chain (clamp-rotation modes included),
        // with the Kelvin–Voigt ζ of that frequency; margin 0.9 for its drift with the
        // configuration (the inertia depends on the angles and deflections). Measured at rest,
        // it leaves out the centrifugal tension's string stiffness N/h² (see the single link's
        // bound); the 0.9 covers a 23 % rise of ω_max², the tension adds N h²/(4EI) ≈ 1e-2 at
        // the undamped scene's peak rate (θ̇₁ ≈ 22 rad/s, 21 stations).
        // ζ of the top mode: at least the Kelvin–Voigt ζ of that frequency, and at least
        // κ_max/(2ω_max) — the fastest damping rate as if it sat on the top frequency
        // (conservative: for ζ ≫ 1 the factor gives τ → 1/κ_max, the overdamped limit).
        if let Some(t) = &self.timo {
            // Timoshenko (chain::timoshenko): the coupled chain's ω_max with the fastest
            // damping rate, and per link the condensed operator's 2/ω_max = h√(ρA/κGA)
            let zeta = self.kappa_max / (2.0 * self.omega_max);
            let mut best = Bound {
                sigma: 0.9 * 2.0 / self.omega_max * damped_step_factor(zeta),
                kind: BoundKind::Transverse,
                site: self.omega_max_site,
            };
            for (k, lp) in self.links.iter().enumerate() {
                let s = t.shear_bound(k, lp.rho_a);
                if s < best.sigma {
                    best = Bound {
                        sigma: s,
                        kind: BoundKind::Transverse,
                        site: SHEAR_SITE + k,
                    };
                }
            }
            return best;
        }
        let zeta = self
            .links
            .iter()
            .map(|lp| explicit * lp.gamma * self.omega_max / (2.0 * lp.ei))
            .fold(explicit * self.kappa_max / (2.0 * self.omega_max), f64::max);
        let mut best = Bound {
            sigma: 0.9 * 2.0 / self.omega_max * damped_step_factor(zeta),
            kind: BoundKind::Transverse,
            site: self.omega_max_site,
        };
        // The clamp-rotation modes (ghost x against J_c/(4h²), stiffness EI/(2h³) + K/(4h²))
        // also carry the joint damper D/(4h²): ζ = c/(2√(k m)) can be large at tiny J_c.
        for (k, lp) in self.links.iter().enumerate() {
            let h = self.hs[k];
            let m = self.jc[k] / (4.0 * h * h);
            let stiff = lp.ei / (2.0 * h * h * h) + self.joints[k].stiffness / (4.0 * h * h);
            let damp =
                explicit * (lp.gamma / (2.0 * h * h * h) + self.joints[k].damping / (4.0 * h * h));
            let w = (stiff / m).sqrt();
            let zeta = damp / (2.0 * (stiff * m).sqrt());
            let sig = 0.9 * 2.0 / w * damped_step_factor(zeta);
            if sig < best.sigma {
                best = Bound {
                    sigma: sig,
                    kind: BoundKind::Transverse,
                    site: 3 + k,
                };
            }
        }
        // Link 1's tip ghost y against the tip half cell's J_t/(4h²): the elbow spring and
        // damper act on it as on link 2's clamp ghost.
        if self.tip_ghost.is_some() {
            let (h, lp, joint) = (self.hs[0], &self.links[0], &self.joints[1]);
            let m = self.jt / (4.0 * h * h);
            let stiff = lp.ei / (2.0 * h * h * h) + joint.stiffness / (4.0 * h * h);
            let damp = explicit * (lp.gamma / (2.0 * h * h * h) + joint.damping / (4.0 * h * h));
            let w = (stiff / m).sqrt();
            let zeta = damp / (2.0 * (stiff * m).sqrt());
            let sig = 0.9 * 2.0 / w * damped_step_factor(zeta);
            if sig < best.sigma {
                best = Bound {
                    sigma: sig,
                    kind: BoundKind::Transverse,
                    site: TIP_SITE,
                };
            }
        }
        for (k, lp) in self.links.iter().enumerate() {
            let h = if k == 0 {
                self.inertia.h1
            } else {
                self.inertia.h2
            };
            let sigma = (h.powi(4) * lp.rho_a / (4.0 * lp.ei)).sqrt();
            let zeta = explicit * lp.gamma * (2.0 / sigma) / (2.0 * lp.ei);
            let s = sigma * damped_step_factor(zeta);
            if s < best.sigma {
                best = Bound {
                    sigma: s,
                    kind: BoundKind::Transverse,
                    site: k,
                };
            }
        }
        best
    }
}
