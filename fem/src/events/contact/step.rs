//! The contact as a step constraint of the methods ([`StepConstraint`]).

use super::Contact;
use crate::chain::{AugmentedLayout, Chain};
use crate::linalg::dot;
use crate::method::{ConstraintView, NewtonSystem, ProjectionRows, StepConstraint};

/// The contact held in a constrained phase, as the method sees it: the force ∇̄g λ with ∇̄g
/// the Gonzalez discrete gradient of the gap (metric W = M(q̄), as for the potential, so
/// Δqᵀ∇̄g = g(q₁) − g(q₀) and the constraint does no work), friction and the stick constraint
/// of a bilateral wall ([`crate::events::contact::friction`]), and the bordered Newton update.
impl StepConstraint<Chain> for Contact {
    fn value(&self, chain: &Chain, t: f64, q: &[f64]) -> f64 {
        self.gap_at(chain, t, q)
    }

    fn gradient(&mut self, chain: &Chain, t: f64, q: &[f64], out: &mut [f64]) -> f64 {
        Contact::gradient(self, chain, t, q, out)
    }

    /// The gap row; on the bilateral wall also sliding friction's share of the normal
    /// multiplier's force, or the stick row (`crate::events::contact::friction`).
    fn projection_rows(&mut self, chain: &Chain, t: f64, q: &[f64], rows: &mut ProjectionRows) {
        let gap = Contact::gradient(self, chain, t, q, &mut rows.gradient[0]);
        rows.hold_one(gap);
        if self.bilateral.is_some() {
            crate::events::contact::friction::projection_rows(self, chain, t, q, rows);
        }
    }

    fn commit_projection(
        &mut self,
        chain: &Chain,
        t: [f64; 2],
        q: [&[f64]; 2],
        start: [f64; 2],
        end: [f64; 2],
    ) {
        if self.bilateral.is_some() {
            crate::events::contact::friction::commit_projection(self, chain, t, q, start, end);
        } else {
            self.set_multiplier(end[0]);
        }
    }

    fn multiplier(&self) -> f64 {
        self.constraint.step_lambda
    }

    fn set_multiplier(&mut self, lambda: f64) {
        self.constraint.step_lambda = lambda;
    }

    fn start_sub_step(&mut self, first: bool) {
        if let Some(b) = self.bilateral.as_deref_mut() {
            b.constraint.work_before = if first {
                0.0
            } else {
                b.constraint.pending_work
            };
        }
    }

    fn add_force(&mut self, chain: &Chain, v: &ConstraintView<'_>, res: &mut [f64]) -> f64 {
        let c = self;
        let n = res.len();
        let [_, t_mid, t1] = v.t;
        let (lambda, denom, g0) = (v.lambda, v.denom, v.g0);
        c.constraint.iteration = v.it;
        // Constraint force ∇̄g λ with ∇̄g the discrete gradient of the gap in the same
        // metric: Δqᵀ∇̄g = g(q₁) − g(q₀), so the constraint does no work.
        let mut g_mid = std::mem::take(&mut c.constraint.g_mid);
        let mut g_end = std::mem::take(&mut c.constraint.g_end);
        c.gradient(chain, t_mid, v.qbar, &mut g_mid);
        let gap1 = c.gradient(chain, t1, v.q1, &mut g_end);
        let gd = dot(&g_mid, v.dq);
        let corr_g = if denom > 0.0 {
            (gap1 - g0 - gd) / denom
        } else {
            0.0
        };
        for i in 0..n {
            c.constraint.g_bar[i] = g_mid[i] + corr_g * v.w_dq[i];
            res[i] -= lambda * c.constraint.g_bar[i];
        }
        c.constraint.g_mid = g_mid;
        c.constraint.g_end = g_end;
        if c.bilateral.is_some() {
            // Friction (sliding) or the tangential stick constraint: crate::events::contact::friction.
            return crate::events::contact::friction::midpoint_terms(c, chain, v, gap1, res);
        }
        gap1
    }

    fn newton_update(
        &mut self,
        newton: &mut NewtonSystem<AugmentedLayout>,
        res: &[f64],
        dq1_da: f64,
        gap1: f64,
        gap_target: f64,
    ) -> f64 {
        let c = self;
        if crate::events::contact::friction::sticking(c) {
            // Sticking friction contact: two multipliers (crate::events::contact::friction).
            return crate::events::contact::friction::stick_newton_update(newton, c, res, dq1_da);
        }
        let n = res.len();
        // Bordered Newton on (a, λ): S δa − ∇̄g δλ = F, (∂q₁/∂a) ∇g(q₁)·δa = g(q₁) − target,
        // by the Schur complement with two solves of S.
        // S⁻¹∇̄g of the step's first iterate serves its later iterates while S is the same
        // factorization: ∇̄g moves by O(update) between them, and a quasi-Newton update
        // only changes the path, not the solution (the residual and the gap are exact).
        // Not across steps: kept while S is (up to 8 steps), it cost more iterations and
        // matrix refreshes than it saved solves (`barhorst-case1`, 5 elements, dt 2.5e-4:
        // 40 221 iterations and 2 983 matrices against 39 624 and 2 066).
        if c.constraint.iteration == 0 || c.constraint.s_inv_g_of != Some(newton.formed) {
            newton.delta.copy_from_slice(&c.constraint.g_bar);
            newton.solve();
            c.constraint.s_inv_g.copy_from_slice(&newton.delta);
            c.constraint.s_inv_g_of = Some(newton.formed);
        }
        newton.delta.copy_from_slice(res);
        newton.solve();
        let cx = dq1_da * dot(&c.constraint.g_end, &newton.delta);
        let cy = dq1_da * dot(&c.constraint.g_end, &c.constraint.s_inv_g);
        let dlambda = (gap1 - gap_target - cx) / cy;
        for i in 0..n {
            newton.delta[i] += c.constraint.s_inv_g[i] * dlambda;
        }
        dlambda
    }
}
