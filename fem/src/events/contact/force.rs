//! The normal force of the constrained dynamics at a state (index-1 value, parent module docs):
//! λ = (G M⁻¹R(q, q̇_c, 0) − n̂·a_conv)/(G M⁻¹Gᵀ) at the velocity q̇_c projected onto G q̇ = 0
//! and made consistent with the massless balances.

use super::{Contact, REFINE_MARGIN, REFINE_TOL};
use crate::chain::Chain;
use crate::error::FemError;
use crate::events::massless::Massless;
use crate::linalg::{dot, max_abs};

/// Makes `qd` consistent with the massless balances Nᵀ R(q, q̇, 0) = 0 by changing it along N
/// only (no kinetic energy, no tip velocity changes: M N = 0, G N = 0); see
/// [`Massless::make_consistent`]. Returns the residual passes used. No-op without massless
/// directions (`massless` None).
pub(super) fn make_consistent(
    massless: Option<&mut Massless>,
    chain: &mut Chain,
    t: f64,
    q: &[f64],
    qd: &mut [f64],
) -> Result<usize, FemError> {
    match massless {
        Some(ml) => ml.make_consistent(chain, t, q, qd),
        None => Ok(0),
    }
}

impl Contact {
    /// Normal force of the constrained dynamics at (q, q̇) (module docs), the chain's exactly
    /// massless directions `massless` (if any) at rates consistent with their balances; also
    /// sets G (in `g_end`), M⁻¹Gᵀ, the gap and the normal velocity. Returns (λ, G M⁻¹Gᵀ,
    /// passes).
    pub fn state_force(
        &mut self,
        chain: &mut Chain,
        massless: Option<&mut Massless>,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(f64, f64, usize), FemError> {
        let mut g_row = std::mem::take(&mut self.constraint.g_end);
        self.phase.gap = self.gradient(chain, t, q, &mut g_row);
        let mut qd_c = std::mem::take(&mut self.solve.qd_c);
        let out = self.state_force_with(chain, massless, t, q, qd, &g_row, &mut qd_c);
        self.constraint.g_end = g_row;
        self.solve.qd_c = qd_c;
        out
    }

    /// [`Contact::state_force`] with G in `g_row`; `qd_c` receives the consistent velocity.
    #[allow(clippy::too_many_arguments)]
    fn state_force_with(
        &mut self,
        chain: &mut Chain,
        mut massless: Option<&mut Massless>,
        t: f64,
        q: &[f64],
        qd: &[f64],
        g_row: &[f64],
        qd_c: &mut [f64],
    ) -> Result<(f64, f64, usize), FemError> {
        let mut n = 0;
        let mut fresh = false;
        loop {
            let (passes, refined) = self.solve_gradient(chain, t, q, g_row, fresh)?;
            n += passes;
            let gmg = dot(g_row, &self.solve.minv_gt);
            // The force of the constrained dynamics at the velocity it allows: q̇ projected onto
            // G q̇ = 0 (the plastic projection applied after every constrained step, module
            // docs), and, with massless directions, made consistent with their balances (the
            // stepper's end rate there is not determined by its equations). The drift
            // G q̇ = O(h²) of a step end otherwise entered λ through the velocity terms:
            // measured up to 9.6 lbf between the end of a step and its projected state
            // (`barhorst-case1-tipmass`), a jump that the release location then met at a
            // bracket of 4e-14 s.
            qd_c.copy_from_slice(qd);
            let vn = dot(g_row, qd_c);
            for i in 0..qd_c.len() {
                qd_c[i] -= self.solve.minv_gt[i] * vn / gmg;
            }
            n += make_consistent(massless.as_deref_mut(), chain, t, q, qd_c)?;
            // R(q, q̇, 0): everything but the inertia of q̈; G M⁻¹R = (M⁻¹Gᵀ)ᵀR (M symmetric).
            chain.residual(t, q, qd_c, &self.solve.zero, &mut self.solve.tmp);
            let [_, _, a] = chain.tip_motion(t, self.constraint.link, q, qd_c, &self.solve.zero);
            // The normal velocity of the state itself (the drift, before any projection).
            self.phase.normal_velocity = vn;
            let conv = self.constraint.normal.dot(&a);
            let sv = &mut self.solve;
            let g_minv_r = if refined {
                dot(&sv.minv_gt, &sv.tmp)
            } else {
                sv.dx.copy_from_slice(&sv.tmp);
                sv.mass.solve_in_place(&mut sv.dx);
                dot(g_row, &sv.dx)
            };
            let lambda = (g_minv_r - conv) / gmg;
            n += 2;
            if refined {
                // A refined M⁻¹Gᵀ is exact to REFINE_TOL·‖x‖∞ only, which large elastic forces
                // in R amplify: near zero — where the release is decided and located, and λ(h)
                // must be continuous in h — the force is evaluated again with a factorization
                // at q (and G M⁻¹R by a second solve, as without refinement).
                let sum_abs = |v: &[f64]| v.iter().map(|x| x.abs()).sum::<f64>();
                let bound = REFINE_TOL
                    * max_abs(&self.solve.minv_gt)
                    * (sum_abs(&self.solve.tmp) + lambda.abs() * sum_abs(g_row))
                    / gmg.abs();
                let clear_of_zero = lambda.abs() > REFINE_MARGIN * bound;
                if !clear_of_zero {
                    fresh = true;
                    continue;
                }
            }
            return Ok((lambda, gmg, n));
        }
    }
}
