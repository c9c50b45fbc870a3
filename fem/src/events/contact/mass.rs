//! The contact's solves with the regularized mass M(q) + μNNᵀ: its sparse factorization (with
//! the mass scale μ found once per run) and M⁻¹Gᵀ for the gradient row G, kept at the same
//! configuration and otherwise refined against a factorization at hand (module docs of the
//! parent, constants `REFINE_*`).

use super::{Contact, FAR_REFINE, MAX_REFINE, REFINE_RATE, REFINE_TOL, SLOW_REFINE};
use crate::chain::{Chain, Parts};
use crate::error::FemError;
use crate::linalg::max_abs;

impl Contact {
    /// Forms and factorizes M(q) + μNNᵀ sparsely ([`crate::events::mass_solve`]; reused at
    /// the same (t, q)). Returns the residual passes used.
    fn factor_mass(&mut self, chain: &mut Chain, t: f64, q: &[f64]) -> Result<usize, FemError> {
        let n = chain.ndof;
        let mut passes = 0;
        if !self.solve.reg_dirs.is_empty() && self.solve.mass_scale == 0.0 {
            // μ: the largest diagonal mass (any positive scale works on the exact directions;
            // module docs), from n mass products once per run.
            for j in 0..n {
                self.solve.unit[j] = 1.0;
                chain.residual_parts(
                    t,
                    q,
                    &self.solve.zero,
                    &self.solve.unit,
                    Parts::INERTIA,
                    &mut self.solve.col,
                );
                self.solve.unit[j] = 0.0;
                self.solve.mass_scale = self.solve.mass_scale.max(self.solve.col[j].abs());
            }
            passes += n;
        }
        Ok(passes + self.solve.mass.factor(chain, t, q, self.solve.mass_scale)?)
    }

    /// `minv_gt` ← (M(q) + μNNᵀ)⁻¹ `g_row` (G at (t, q)); returns the residual passes used.
    ///
    /// Kept while (t, q) is unchanged (the normal force at a step end, then its drift
    /// projection). Otherwise, with a factorization at hand from an earlier configuration
    /// (the previous step end: M moves by O(h·q̇) between them), iterative refinement against
    /// the current matrix, x ← x + M₀⁻¹(Gᵀ − M(q)x) with the exact mass product of one
    /// inertial residual pass, replaces a new assembly and factorization (one pass and one
    /// solve each, against an assembly of the exact Newton matrix, a factorization with its
    /// border solves and a pass). It stops at a correction within [`REFINE_TOL`] of x (the
    /// round-off floor of the refinement, measured 1e-14..1e-13 relative); a first correction
    /// beyond [`FAR_REFINE`], a contraction slower than [`REFINE_RATE`] per iteration, or
    /// [`MAX_REFINE`] iterations without reaching the tolerance form and factorize M(q) and
    /// solve directly, as does the solve after one that needed [`SLOW_REFINE`] iterations
    /// (the factorization at hand has fallen too far behind). Not with massless section
    /// rotations (Timoshenko links without rotary inertia): there the residual R carries the
    /// stiff shear forces, which amplify the refinement's tolerance into the normal force
    /// (measured: a release located with λ = −2.7e-2 lbf at a bracket of 9e-13 s on
    /// `barhorst-case1-timoshenko`, 8 elements) — those runs factorize at every configuration.
    pub(super) fn solve_gradient(
        &mut self,
        chain: &mut Chain,
        t: f64,
        q: &[f64],
        g_row: &[f64],
        fresh: bool,
    ) -> Result<(usize, bool), FemError> {
        let sv = &self.solve;
        if !fresh
            && sv.minv_key_t.is_some_and(|k| k.to_bits() == t.to_bits())
            && sv
                .minv_key_q
                .iter()
                .zip(q)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        {
            return Ok((0, self.solve.minv_refined));
        }
        self.solve.minv_key_t = None;
        let mut passes = 0;
        let mu = self.solve.mass_scale;
        let stale = !fresh
            && !chain.has_massless_dofs()
            && self.solve.mass.factored()
            && !self.solve.refactor_next
            && !self.solve.mass.is_at(t, q, mu);
        let mut refined = false;
        if stale {
            self.solve.minv_gt.copy_from_slice(g_row);
            self.solve.mass.solve_in_place(&mut self.solve.minv_gt);
            let mut last = f64::INFINITY;
            for k in 0..MAX_REFINE {
                passes += 1;
                self.mass_product(chain, t, q);
                for i in 0..g_row.len() {
                    self.solve.dx[i] = g_row[i] - self.solve.col[i];
                }
                self.solve.mass.solve_in_place(&mut self.solve.dx);
                let dn = max_abs(&self.solve.dx);
                for i in 0..g_row.len() {
                    self.solve.minv_gt[i] += self.solve.dx[i];
                }
                let xn = max_abs(&self.solve.minv_gt);
                if dn <= REFINE_TOL * xn {
                    refined = true;
                    self.solve.refactor_next = k + 1 >= SLOW_REFINE;
                    break;
                }
                // A NaN correction is no contraction either.
                let contracting = dn <= REFINE_RATE * last;
                if !contracting || (k == 0 && dn > FAR_REFINE * xn) {
                    break;
                }
                last = dn;
            }
        }
        if !refined {
            self.solve.refactor_next = false;
            passes += self.factor_mass(chain, t, q)?;
            self.solve.minv_gt.copy_from_slice(g_row);
            self.solve.mass.solve_in_place(&mut self.solve.minv_gt);
        }
        self.solve.minv_key_t = Some(t);
        self.solve.minv_key_q.copy_from_slice(q);
        self.solve.minv_refined = refined;
        Ok((passes, refined))
    }

    /// `col` ← (M(q) + μNNᵀ)·`minv_gt`: one inertial residual pass and the regularization.
    fn mass_product(&mut self, chain: &mut Chain, t: f64, q: &[f64]) {
        let sv = &mut self.solve;
        chain.residual_parts(t, q, &sv.zero, &sv.minv_gt, Parts::INERTIA, &mut sv.col);
        for d in &sv.reg_dirs {
            let w: f64 = d.iter().map(|&(i, c)| c * sv.minv_gt[i]).sum();
            for &(i, c) in d {
                sv.col[i] += sv.mass_scale * c * w;
            }
        }
    }
}
