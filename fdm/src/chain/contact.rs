//! Unilateral frictionless contact of link 2's tip with a fixed line (`barhorst-case1`,
//! `barhorst-case2`, `barhorst-case1-tipmass`, `barhorst-case1-stiff-elbow`; seed 000).
//!
//! **Gap.** In the kernel's coordinates ([`TwoLinkChain::to_kinetic`]: the clamp-tangent
//! frames α_ℓ, tip deflections V_ℓ = −L_ℓψ_ℓ) the tip of link 2 sits at
//! r_tip = R(α₁)(L₁ − S₁, V₁) + R(α₂)(L₂ − S₂, V₂), S_ℓ = ½h Σ_seg g_seg² the foreshortening of
//! link ℓ (0 when it is off) — the positions the kinetic energy uses. With the unit normal n̂ to
//! the free side and p₀ on the line, g = n̂·(r_tip − p₀), and with nc(α) = n̂·(cos α, sin α),
//! ns(α) = n̂·(−sin α, cos α), X = L − S, Y = V:
//!
//! G' = ∂g/∂(kernel coordinates): G'_α = ns(α)X − nc(α)Y, G'_u = −nc(α) ∂S/∂u, G'_V += ns(α);
//! G = PᵀG' (P constant);
//! Ġq̇ = Σ_ℓ [−α̇²(nc(α)X + ns(α)Y) − 2α̇(ns(α)Ṡ + nc(α)Ẏ) − nc(α) h Σ ġ²] (differentiate g
//! twice, drop G q̈).
//!
//! **Phases** (the velocity form, one step = kick–drift–kick; when each phase starts and ends
//! is decided by the event object [`crate::events::tip_contact::TipContactEvents`]):
//! * free flight: M q̈ = f, until a contact start located inside a step;
//! * impact (positions unchanged): M(q)(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0 ⇒ Λ = −Gq̇⁻/(GM⁻¹Gᵀ),
//!   q̇⁺ = q̇⁻ + M⁻¹GᵀΛ with the chain's own M (lumped diagonal + four full columns, the Schur
//!   solve of [`super`]). The kinetic energy lost, ½(Gq̇⁻)²/(GM⁻¹Gᵀ) ≥ 0, is booked in the
//!   ledger term `impact`. The next phase follows from the sign of the would-be normal force;
//! * constrained sliding: M q̈ = f + Gᵀλ, G q̈ + Ġq̇ = 0 (index 1 at acceleration level), λ =
//!   −(G M⁻¹f + Ġq̇)/(GM⁻¹Gᵀ): one more solve with the same M. Drift control after every step:
//!   q projected onto g = 0 (Newton along M⁻¹Gᵀ, the M⁻¹ metric) *before* the force evaluation
//!   of the step end, q̇ projected onto Gq̇ = 0 along M⁻¹Gᵀ after the final kick. The velocity
//!   projection removes ½(Gq̇)²/(GM⁻¹Gᵀ) of kinetic energy: not booked in the ledger (it is
//!   integration error and shows in the closure), reported in
//!   [`crate::events::tip_contact::ContactReport`]. The
//!   projections are the chain's [`System::project_position`] and
//!   [`System::project_velocity`], active while the tip is held;
//! * release when λ crosses zero from above, then free flight.
//!
//! The step bound of the free chain also covers the constrained phases: adding a constraint
//! can only lower the highest frequency (Rayleigh quotient on a subspace), and located steps are
//! shorter than the bound.
//!
//! Unsupported: friction ≠ 0, circles (any non-line surface), bilateral mode, contact of link
//! 1, more than one contact, the two-step report scheme (its second level cannot be restarted
//! at an event without a start-up step).

// Index loops over parallel buffers (q, v, a, G, M⁻¹Gᵀ) read like the formulas.
#![allow(clippy::needless_range_loop)]

use data::Event;
use faer::Mat;
use faer::prelude::Solve;

use super::kinetic::{BE, TH, seg_energy, seg_grad, seg_rate};
use super::model::TwoLinkChain;
use super::surface::TipContact;
use crate::error::FdmError;
use crate::linalg::dot;
use crate::output::Outputs;
use crate::system::System;

/// Relative gap (× L₁ + L₂) at which the contact-start location stops, and the tolerance of
/// the position projection.
pub(crate) const GAP_TOLERANCE: f64 = 1e-13;

impl TwoLinkChain {
    /// Whether the scene has a tip contact.
    pub fn has_contact(&self) -> bool {
        self.contact.is_some()
    }

    /// Whether the tip is held on the surface (the constrained phase).
    pub fn is_constrained(&self) -> bool {
        self.constraint.constrained
    }

    /// Switches the constraint g = 0 on (sliding) or off (free flight).
    pub(crate) fn set_constrained(&mut self, on: bool) {
        self.constraint.constrained = on;
    }

    /// Normal force λ of the last constrained `accel` (0 in free flight).
    pub fn normal_force(&self) -> f64 {
        self.constraint.lambda
    }

    /// (|g| before the position projection, |Gq̇| before the velocity projection, kinetic
    /// energy the latter removed) of the last constrained step.
    pub(crate) fn last_projection(&self) -> [f64; 3] {
        self.constraint.last_projection
    }

    /// L₁ + L₂.
    pub(crate) fn total_length(&self) -> f64 {
        self.links[0].length + self.links[1].length
    }

    /// g(q) of full coordinates (the kernel coordinates in the observation scratch; no
    /// `&mut`, for the contact-start location).
    pub(crate) fn gap_of(&self, q: &[f64]) -> f64 {
        let mut qk = self.obs_scratch.borrow_mut();
        self.to_kinetic(q, &mut qk);
        self.gap_on(self.contact.as_ref().expect("contact"), &qk)
    }

    /// g of kernel coordinates `qk` ([`Self::to_kinetic`]) against the surface `ct`.
    pub(super) fn gap_on(&self, ct: &TipContact, qk: &[f64]) -> f64 {
        let (s1, s2) = self.shortenings(qk);
        ct.gap(
            [qk[TH], qk[BE]],
            [self.links[0].length - s1, self.links[1].length - s2],
            [qk[self.slots[0]], qk[self.slots[1]]],
        )
    }

    /// Foreshortenings S₁, S₂ (0 where off) of the kernel coordinates `qk`.
    fn shortenings(&self, qk: &[f64]) -> (f64, f64) {
        let ine = &self.inertia;
        let s1 = if ine.fs1 {
            seg_energy(&qk[ine.iv()], ine.h1, None)
        } else {
            0.0
        };
        let s2 = if ine.fs2 {
            seg_energy(&qk[ine.iw()], ine.h2, None)
        } else {
            0.0
        };
        (s1, s2)
    }

    /// Fills `grow` with G = ∂g/∂q at the kernel coordinates `self.qk` (G' on the kernel's
    /// coordinates, then Pᵀ) and returns g.
    fn gap_row(&mut self) -> f64 {
        let ct = self.contact.clone().expect("contact");
        let ine = &self.inertia;
        let qk = &self.qk;
        let (s1, s2) = self.shortenings(qk);
        let (l1, l2) = (self.links[0].length, self.links[1].length);
        let (y1, y2) = (qk[self.slots[0]], qk[self.slots[1]]);
        let mut g = std::mem::take(&mut self.constraint.grow);
        g.iter_mut().for_each(|x| *x = 0.0);
        // ∂/∂α n̂·R(α)(X, Y) = ns(α)X − nc(α)Y; ∂/∂V = ns(α)
        g[TH] = ct.ns(qk[TH]) * (l1 - s1) - ct.nc(qk[TH]) * y1;
        g[BE] = ct.ns(qk[BE]) * (l2 - s2) - ct.nc(qk[BE]) * y2;
        if ine.fs1 {
            let (v, c) = (&qk[ine.iv()], ct.nc(qk[TH]));
            for k in 0..ine.r1 {
                g[2 + k] = -c * seg_grad(v, ine.h1, None, k);
            }
        }
        if ine.fs2 {
            let (w, c) = (&qk[ine.iw()], ct.nc(qk[BE]));
            for j in 0..ine.r2 {
                g[2 + ine.r1 + j] = -c * seg_grad(w, ine.h2, None, j);
            }
        }
        g[self.slots[0]] += ct.ns(qk[TH]);
        g[self.slots[1]] += ct.ns(qk[BE]);
        self.kinetic_transpose(&mut g);
        self.constraint.grow = g;
        self.gap_on(&ct, &self.qk)
    }

    /// Ġq̇ at the kernel coordinates (`self.qk`, `self.vk`) (module docs).
    fn gap_curvature(&self) -> f64 {
        let ct = self.contact.as_ref().expect("contact");
        let ine = &self.inertia;
        let (qk, vk) = (&self.qk, &self.vk);
        let mut out = 0.0;
        for (l, (alpha, range, h, fs)) in [
            (TH, ine.iv(), ine.h1, ine.fs1),
            (BE, ine.iw(), ine.h2, ine.fs2),
        ]
        .into_iter()
        .enumerate()
        {
            let (a, ad) = (qk[alpha], vk[alpha]);
            let (s, sd, sdd) = if fs {
                let (u, ud) = (&qk[range.clone()], &vk[range]);
                (
                    seg_energy(u, h, None),
                    seg_rate(u, ud, h, None),
                    2.0 * seg_energy(ud, h, None),
                )
            } else {
                (0.0, 0.0, 0.0)
            };
            let (y, yd) = (qk[self.slots[l]], vk[self.slots[l]]);
            out += -ct.nc(a) * ad * ad * (self.links[l].length - s)
                - 2.0 * ct.ns(a) * ad * sd
                - ct.nc(a) * sdd
                - (ct.ns(a) * ad * ad * y + 2.0 * ct.nc(a) * ad * yd);
        }
        out
    }

    /// With `qk`, `vk` and the mass columns current: G into `grow`, M⁻¹Gᵀ into `minv_g`;
    /// returns (GM⁻¹Gᵀ, Ġq̇).
    pub(super) fn constraint_solve(&mut self) -> (f64, f64) {
        self.gap_row();
        let grow = std::mem::take(&mut self.constraint.grow);
        let mut mg = std::mem::take(&mut self.constraint.minv_g);
        self.solve_mass(&grow, &mut mg);
        let gmg = dot(&grow, &mg);
        self.constraint.grow = grow;
        self.constraint.minv_g = mg;
        (gmg, self.gap_curvature())
    }

    /// g(q) of full coordinates (uses the kernel scratch `qk`).
    pub fn gap(&mut self, q: &[f64]) -> f64 {
        self.set_kinetic_q(q);
        let ct = self.contact.clone().expect("contact");
        self.gap_on(&ct, &self.qk)
    }

    /// G = ∂g/∂q at q into `out` (for checks); returns g.
    pub fn gap_gradient(&mut self, q: &[f64], out: &mut [f64]) -> f64 {
        self.set_kinetic_q(q);
        let g = self.gap_row();
        out.copy_from_slice(&self.constraint.grow);
        g
    }

    /// Projects q onto g = 0 along M⁻¹Gᵀ (Newton, at most 3 passes); returns |g| before.
    pub(super) fn project_onto_surface(&mut self, q: &mut [f64]) -> f64 {
        let tol = GAP_TOLERANCE * (self.links[0].length + self.links[1].length);
        let mut first = None;
        for _ in 0..3 {
            self.set_kinetic_q(q);
            let g = self.gap_row();
            first.get_or_insert(g.abs());
            if g.abs() <= tol {
                break;
            }
            self.build_columns();
            let grow = std::mem::take(&mut self.constraint.grow);
            let mut mg = std::mem::take(&mut self.constraint.minv_g);
            self.solve_mass(&grow, &mut mg);
            let gmg = dot(&grow, &mg);
            for i in 0..q.len() {
                q[i] -= mg[i] * g / gmg;
            }
            self.constraint.grow = grow;
            self.constraint.minv_g = mg;
        }
        first.unwrap_or(0.0)
    }

    /// Projects q̇ onto Gq̇ = 0 along M⁻¹Gᵀ with G, M⁻¹Gᵀ of the last constrained `accel`;
    /// returns (|Gq̇| before, kinetic energy removed).
    pub(super) fn remove_normal_velocity(&self, v: &mut [f64]) -> (f64, f64) {
        let c = &self.constraint;
        let gv = dot(&c.grow, v);
        let gmg = dot(&c.grow, &c.minv_g);
        for i in 0..v.len() {
            v[i] -= c.minv_g[i] * gv / gmg;
        }
        (gv.abs(), 0.5 * gv * gv / gmg)
    }

    fn kinetic_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let mut e = [0.0; 4];
        let k = self.ledger_names().0.len();
        self.stored_energies(0.0, q, v, &mut e[..k]);
        e[0]
    }

    /// The impact at (q, q̇⁻): q̇ ← q̇⁺. Allocates (once per impact, outside the step loop).
    /// `None` (q̇ untouched) when GM⁻¹Gᵀ is not a positive number (a failed mass solve).
    pub(crate) fn impact(&mut self, t: f64, q: &[f64], v: &mut [f64]) -> Option<Event> {
        let n = q.len();
        let ke_before = self.kinetic_energy(q, v);
        let before = v.to_vec();
        self.frames(q, v);
        self.build_columns();
        let (gmg, _) = self.constraint_solve();
        if !(gmg > 0.0 && gmg.is_finite()) {
            return None;
        }
        let gv = dot(&self.constraint.grow[..n], &v[..n]);
        let impulse = -gv / gmg;
        let mut dv = vec![0.0; n];
        for i in 0..n {
            dv[i] = self.constraint.minv_g[i] * impulse;
            v[i] += dv[i];
        }
        // ‖M(q̇⁺ − q̇⁻) − GᵀΛ‖ / ‖M(q̇⁺ − q̇⁻)‖ with the product M·Δq̇ formed independently
        let mut mdv = vec![0.0; n];
        self.mass_mul(&dv, &mut mdv);
        let (mut res2, mut mom2) = (0.0, 0.0);
        for i in 0..n {
            res2 += (mdv[i] - self.constraint.grow[i] * impulse).powi(2);
            mom2 += mdv[i] * mdv[i];
        }
        let momentum_residual = if mom2 > 0.0 {
            (res2 / mom2).sqrt()
        } else {
            res2.sqrt()
        };
        let normal_velocity_after = dot(&self.constraint.grow[..n], &v[..n]);
        let kinetic_energy_lost = ke_before - self.kinetic_energy(q, v);

        Some(Event::Impact {
            t,
            contact: 1,
            velocity_before: before,
            velocity_after: v.to_vec(),
            impulse,
            momentum_residual,
            normal_velocity_before: gv,
            normal_velocity_after,
            kinetic_energy_lost,
        })
    }

    /// Static equilibrium resting on the surface: −∂V/∂q + Gᵀλ = 0, g = 0 (V: strain, joint
    /// springs, gravity), by Newton's method with a central-difference Jacobian (faer's
    /// partial-pivoting LU) from `q_guess`.
    /// Returns (q, λ). Allocates: for checks, not for the step loop.
    pub fn rest_on_surface(&mut self, q_guess: &[f64]) -> Result<(Vec<f64>, f64), FdmError> {
        if self.contact.is_none() {
            return Err(FdmError::Unsupported(
                "fdm: rest on the surface needs a contact".into(),
            ));
        }
        let n = self.dofs();
        let zeros = vec![0.0; n];
        let mut f = vec![0.0; n];
        let mut resid = |sys: &mut Self, x: &[f64], out: &mut [f64]| {
            let q = &x[..n];
            sys.frames(q, &zeros);
            sys.forces(0.0, q, &zeros, &mut f);
            let g = sys.gap_row();
            for i in 0..n {
                out[i] = f[i] + sys.constraint.grow[i] * x[n];
            }
            out[n] = g;
        };
        let mut x: Vec<f64> = q_guess.iter().copied().chain([0.0]).collect();
        let m = n + 1;
        let (mut r, mut rp, mut rm) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut jac = Mat::<f64>::zeros(m, m);
        for _ in 0..50 {
            resid(self, &x, &mut r);
            for j in 0..m {
                let e = 1e-6 * (1.0 + x[j].abs());
                let x0 = x[j];
                x[j] = x0 + e;
                resid(self, &x, &mut rp);
                x[j] = x0 - e;
                resid(self, &x, &mut rm);
                x[j] = x0;
                for i in 0..m {
                    jac[(i, j)] = (rp[i] - rm[i]) / (2.0 * e);
                }
            }
            let rhs = Mat::from_fn(m, 1, |i, _| -r[i]);
            let sol = jac.partial_piv_lu().solve(&rhs);
            let dx: Vec<f64> = (0..m).map(|i| sol[(i, 0)]).collect();
            if !dx.iter().all(|v| v.is_finite()) {
                return Err(FdmError::Numerical {
                    t: 0.0,
                    message: "singular Jacobian of the resting equilibrium".into(),
                });
            }
            let step = dx.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for i in 0..m {
                x[i] += dx[i];
            }
            if step <= 1e-11 * (1.0 + x[n].abs()) {
                let lam = x[n];
                x.truncate(n);
                return Ok((x, lam));
            }
        }
        Err(FdmError::Numerical {
            t: 0.0,
            message: "Newton on the resting equilibrium did not converge in 50 iterations".into(),
        })
    }
}
