//! The velocity jumps of the contact: the perfectly plastic impact map at the contact start and
//! the plastic projection onto G q̇ = 0 after a constrained step (parent module docs).

use data::Event;

use super::Contact;
use super::force::make_consistent;
use crate::chain::{Chain, Parts};
use crate::error::FemError;
use crate::events::massless::Massless;
use crate::linalg::dot;

impl Contact {
    /// Perfectly plastic impact at (q, q̇⁻) (module docs), the chain's exactly massless
    /// directions `massless` (if any) at rates consistent with their balances before and after:
    /// updates `qd` to q̇⁺ and returns the event (None when the tip does not move into the
    /// surface, G q̇⁻ ≥ 0).
    pub fn impact(
        &mut self,
        chain: &mut Chain,
        mut massless: Option<&mut Massless>,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
    ) -> Result<Option<Event>, FemError> {
        let n = chain.ndof;
        // Massless directions (module docs): q̇⁻ consistent with their balances first (changes
        // neither the kinetic energy nor G q̇).
        make_consistent(massless.as_deref_mut(), chain, t, q, qd)?;
        let mut g_row = std::mem::take(&mut self.constraint.g_end);
        self.phase.gap = self.gradient(chain, t, q, &mut g_row);
        let v_before = dot(&g_row, qd);
        // A normal velocity at the round-off level of G q̇ is no impact.
        let roundoff = 1e-14
            * g_row
                .iter()
                .zip(qd.iter())
                .map(|(g, v)| (g * v).abs())
                .sum::<f64>();
        if v_before >= -roundoff {
            self.constraint.g_end = g_row;
            return Ok(None);
        }
        if let Err(e) = self.solve_gradient(chain, t, q, &g_row, false) {
            self.constraint.g_end = g_row;
            return Err(e);
        }
        let gmg = dot(&g_row, &self.solve.minv_gt);
        let impulse = -v_before / gmg;
        let velocity_before = qd.to_vec();
        for i in 0..n {
            qd[i] += self.solve.minv_gt[i] * impulse;
        }
        // The massless balances hold after the jump too: Nᵀ C Δq̇ = 0 fixes its N-component
        // (zero kinetic energy, no mass product, no normal velocity).
        make_consistent(massless, chain, t, q, qd)?;
        // Independent mass product of the velocity jump (not the factorized matrix). The jump
        // is the increment applied, M⁻¹GᵀΛ: the difference of the stored velocities would add
        // their rounding (|q̇|·1e-16), which dominates for grazing impacts with tiny Λ.
        for i in 0..n {
            self.solve.unit[i] = self.solve.minv_gt[i] * impulse;
        }
        chain.residual_parts(
            t,
            q,
            &self.solve.zero,
            &self.solve.unit,
            Parts::INERTIA,
            &mut self.solve.col,
        );
        // Massive-block balance: M Δq̇ − GᵀΛ ∈ span N, the N-part being −μN NᵀΔq̇ (module
        // docs; zero along the exactly massless directions).
        self.solve.tmp.copy_from_slice(&self.solve.col);
        for d in &self.solve.reg_dirs {
            let w: f64 = d.iter().map(|&(i, c)| c * self.solve.unit[i]).sum();
            for &(i, c) in d {
                self.solve.tmp[i] += self.solve.mass_scale * c * w;
            }
        }
        self.solve.unit.iter_mut().for_each(|x| *x = 0.0);
        let (mut res2, mut mom2) = (0.0, 0.0);
        for i in 0..n {
            let r = self.solve.tmp[i] - g_row[i] * impulse;
            res2 += r * r;
            mom2 += self.solve.col[i] * self.solve.col[i];
        }
        let momentum_residual = if mom2 > 0.0 {
            (res2 / mom2).sqrt()
        } else {
            res2.sqrt()
        };
        // The kinetic energy lost, booked as the difference of the evaluated kinetic energies
        // (the ledger then closes exactly). For the massive block alone it is the loss of the
        // plastic map ½Λ²(G M⁻¹Gᵀ) ≥ 0; the reaction that keeps the frame directions' velocity
        // (module docs) does work where they move, which the formula omits (measured up to
        // 3e-3 ft·lbf of 0.45 at the fifth impact of 4 elements, which broke the ledger
        // closure to 4.7e-5 when the formula was booked).
        let ke_before = chain.energies(t, q, &velocity_before)[0];
        let loss = ke_before - chain.energies(t, q, qd)[0];
        self.record.impact_loss += loss;
        self.phase.normal_velocity = dot(&g_row, qd);
        self.constraint.g_end = g_row;
        Ok(Some(Event::Impact {
            t,
            contact: 1,
            velocity_before,
            velocity_after: qd.to_vec(),
            impulse,
            momentum_residual,
            normal_velocity_before: v_before,
            normal_velocity_after: self.phase.normal_velocity,
            kinetic_energy_lost: loss,
        }))
    }

    /// Plastic projection of the velocity onto G q̇ = 0 (q̇ ← q̇ − M⁻¹Gᵀ(G q̇)/(G M⁻¹Gᵀ)),
    /// only when `inward_only` is false or G q̇ < 0; returns the kinetic energy it removes,
    /// ½(G q̇)²/(G M⁻¹Gᵀ) ≥ 0, and the residual passes of the mass factorization. Records the
    /// gap and the drift G q̇ before the projection. The rates along `massless` are made
    /// consistent with their balances after it.
    pub(crate) fn project(
        &mut self,
        chain: &mut Chain,
        massless: Option<&mut Massless>,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
        inward_only: bool,
    ) -> Result<(f64, usize), FemError> {
        let mut g_row = std::mem::take(&mut self.constraint.g_end);
        self.phase.gap = self.gradient(chain, t, q, &mut g_row);
        let vn = dot(&g_row, qd);
        self.phase.drift_velocity = vn;
        let mut loss = 0.0;
        let mut passes = 0;
        if !inward_only || vn < 0.0 {
            passes = match self.solve_gradient(chain, t, q, &g_row, false) {
                Ok((p, _)) => p,
                Err(e) => {
                    self.constraint.g_end = g_row;
                    return Err(e);
                }
            };
            let gmg = dot(&g_row, &self.solve.minv_gt);
            let ke0 = chain.energies(t, q, qd)[0];
            for i in 0..qd.len() {
                qd[i] -= self.solve.minv_gt[i] * vn / gmg;
            }
            make_consistent(massless, chain, t, q, qd)?;
            loss = ke0 - chain.energies(t, q, qd)[0];
        }
        self.phase.normal_velocity = dot(&g_row, qd);
        self.constraint.g_end = g_row;
        Ok((loss, passes))
    }
}
