//! The one-step velocity (kick–drift–kick) form: v_{½} = v_j + ½τ a_j, q_{j+1} = q_j + τ v_{½},
//! a_{j+1} = a(t_{j+1}, q_{j+1}, v_{½} + ½τ a_j) (predicted velocity for velocity-dependent
//! forces), v_{j+1} = v_{½} + ½τ a_{j+1}. No computational mode; one force evaluation per step;
//! stable to the model's σ = 2/ω_max (factor 1).
//!
//! **Inertia terms from the drift velocities** ([`VelocityForm::drift_split`], the default).
//! Systems whose kinetic energy depends on q (the two-link chain) evaluate the inertia terms
//! quadratic in q̇, Γ(q)[q̇, q̇] = (∂p/∂q)q̇ − ∂T/∂q, from the drift velocities
//! ([`System::accel_split`]): Γ_{j+1} = (1 + w)Γ(q_{j+1})[v_{j+½}] − wΓ(q_{j+1})[v_{j−½}],
//! w = τ_{j+1}/(τ_{j+1} + τ_j) (linear extrapolation from the half-step times to t_{j+1}:
//! second order for resolved motion; the weights sum to 1, so the mean over an oscillation is
//! that of Γ[v_{½}]). Why: a mode x = A cos Ωt of the scheme (sin(Ωτ/2) = ωτ/2) has
//! ⟨v_{½}²⟩ = ω²⟨x²⟩ exactly — the virial balance of the continuous motion — whereas the
//! full-step and predicted velocities give ⟨v²⟩ = ω²⟨x²⟩(1 − ω²τ²/4) and less. A quadratic
//! form such as the foreshortening rate Ψ̈ = ∂Ψ·q̈ + q̇ᵀHq̇ then averages to zero over the
//! unresolved grid-scale bending waves as it does in continuous time; with the predicted
//! velocity every such wave leaves a mean bias ∝ (ωτ)² on the slow equations, and their sum
//! grows like the number of stations (measured on `two-link-free-undamped`: the joint angles
//! then move away from the converged answer as the grid is refined).
//!
//! **Time-symmetric inertia terms** (undamped systems). The extrapolation is not symmetric in
//! time: Γ_{j+1} differs from ½(Γ[v_{j+½}] + Γ[v_{j+3/2}]), the rule that is, by O(τ²). Where
//! the inertia depends strongly on the configuration (the two-link chain's clamp rotations,
//! whose inertia J_c + Σm(s^t)² changes with the deflections) this defect pumps energy out of
//! the unresolved top modes steadily: a secular drift of the ledger, with a rate ∝ τ³. So a
//! system with such terms ([`System::has_velocity_quadratic_inertia`]) takes one corrector
//! pass: v_{j+3/2} ≈ v_{j+½} + τ_{j+1}a⁰_{j+1} from the extrapolated a⁰, then a_{j+1} with
//! ½Γ[v_{j+½}] + ½Γ[v_{j+3/2}] — both drift velocities, so the virial balance above holds, and
//! the symmetry defect drops to O(τ³) (a second pass changes nothing measurable). Measured on
//! `two-link-free-undamped`, 11 stations, 10 s at the bound: the largest ledger residual per
//! tenth went 4.24e-2 → 8.25e-2 J without the pass and 4.16e-2 → 3.86e-2 J with it (the mean
//! per tenth flat at −2.6e-2 J). The pass repeats `accel_split` at the same level with other
//! drift velocities; a system may keep what does not change (the chain keeps its other forces,
//! Γ[v_{j+½}] and its mass matrix's columns), so the pass costs one Γ evaluation and one mass
//! solve. With implicit damping the pass is not taken: the damping removes the top
//! modes the defect acts on (`two-link-free`, same grid: 2.38e-2 → 2.36e-2 J without it).
//!
//! **Implicit damping** ([`System::implicit_kick`]). A system may take the closing kick with
//! its (linear, constant) damping C implicit: (M + ½τC)a_{j+1} = F(q_{j+1}, v_{j+½}), so the
//! step applies −½τM⁻¹C at v_j (opening kick, explicit) and at v_{j+1} (closing kick): Crank–
//! Nicolson in the damping, stable for every κτ, and the step stays at the undamped bound.
//!
//! **Jumps of applied laws.** The opening and the closing kick at a level are separate, so a
//! step can end on a torque switch with its closing kick at the law's left limit and the next
//! opening kick at the new value; the driver lands on the switches (`crate::driver`'s jumps
//! module) and the scheme keeps its second order through them.
//!
//! **Restartable steps** ([`VelocityForm::predicted`]). With every force at the predicted
//! velocity a step depends on level j alone, so a step can be re-taken from the same level with
//! another length (event location: [`crate::chain::contact`]) and the drift positions
//! q_j + s v_j + ½s² a_j of any length s need no force evaluation. A system with implicit
//! damping takes its implicit kick there too, with the damping at v_{j+½} and the other
//! velocity-dependent forces at the predicted velocity (both fixed by level j; the inertia
//! terms at v_{j+½} alone, without the extrapolation from v_{j−½}, would be first order: the
//! ledger closure of `barhorst-case1`'s free fall halved per halving of the step).

// Index loops run over several parallel level buffers at once.
#![allow(clippy::needless_range_loop)]

use super::{AtJumps, Capabilities, MethodParams, StepState, Stepper};
use crate::system::{DriftVelocities, System};

/// The velocity form; where the velocity-quadratic inertia terms are evaluated.
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityForm {
    /// inertia terms from the drift velocities (else at the predicted velocity)
    split: bool,
    /// v_{j−½}, the previous step's drift velocity (valid once `have_drift_prev`)
    drift_prev: Vec<f64>,
    /// v_{j+3/2} estimated for the symmetric corrector pass
    drift_next: Vec<f64>,
    have_drift_prev: bool,
}

impl VelocityForm {
    /// Inertia terms from the drift velocities v_{j±½} (module docs).
    pub fn drift_split() -> Self {
        VelocityForm {
            split: true,
            drift_prev: Vec::new(),
            drift_next: Vec::new(),
            have_drift_prev: false,
        }
    }

    /// Every force at the predicted velocity: a step depends on level j alone.
    pub fn predicted() -> Self {
        VelocityForm {
            split: false,
            drift_prev: Vec::new(),
            drift_next: Vec::new(),
            have_drift_prev: false,
        }
    }

    /// Restartable ([`VelocityForm::predicted`]), with implicit damping, and onto jumps: the
    /// closing and the opening kick at a level are separate (module docs).
    pub const CAPABILITIES: Capabilities = Capabilities {
        restarts_at_events: true,
        implicit_damping: true,
        at_jumps: AtJumps::SplitsKicks,
    };
}

impl From<MethodParams> for VelocityForm {
    /// [`VelocityForm::predicted`] for a run that re-takes steps, else
    /// [`VelocityForm::drift_split`].
    fn from(params: MethodParams) -> Self {
        if params.restartable {
            VelocityForm::predicted()
        } else {
            VelocityForm::drift_split()
        }
    }
}

impl Stepper for VelocityForm {
    fn bound_factor(&self) -> f64 {
        1.0
    }

    fn has_computational_mode(&self) -> bool {
        false
    }

    /// 2(1 − cos ωτ) at the limit ωτ = 2, plus margin.
    fn parasitic_threshold(&self) -> f64 {
        4.5
    }

    fn start(&mut self, _sys: &mut dyn System, _t: f64, _tau: f64, st: &mut StepState) -> usize {
        self.drift_prev = vec![0.0; st.acc.len()];
        self.drift_next = vec![0.0; st.acc.len()];
        self.have_drift_prev = false;
        0
    }

    fn predict(&mut self, _tau_prev: f64, tau: f64, st: &mut StepState) {
        let (cur, next) = (&st.cur, &mut st.next);
        for i in 0..st.acc.len() {
            let vh = cur.v[i] + 0.5 * tau * st.acc[i];
            next.q[i] = cur.q[i] + tau * vh;
            next.v[i] = vh; // half-step velocity until the kick of `complete`
            st.pred[i] = vh + 0.5 * tau * st.acc[i]; // predicted v_{j+1}
        }
    }

    fn predicted_velocity<'a>(&self, st: &'a StepState) -> &'a [f64] {
        &st.pred
    }

    /// The drift q_j + s v_j + ½s² a_j (the kick–drift positions, level j alone).
    fn step_positions(&self, st: &StepState, _tau_prev: f64, s: f64, q: &mut [f64]) {
        for i in 0..q.len() {
            q[i] = st.cur.q[i] + s * st.cur.v[i] + 0.5 * s * s * st.acc[i];
        }
    }

    fn complete(
        &mut self,
        sys: &mut dyn System,
        t_new: f64,
        tau_prev: f64,
        tau: f64,
        st: &mut StepState,
    ) {
        if self.split {
            // next.v holds the drift velocity v_{j+½}
            let drift = DriftVelocities {
                current: &st.next.v,
                previous: if self.have_drift_prev {
                    &self.drift_prev
                } else {
                    &st.next.v
                },
                w: if self.have_drift_prev {
                    tau / (tau + tau_prev)
                } else {
                    0.0
                },
                predicted: &st.pred,
            };
            if !sys.implicit_kick(t_new, &st.next.q, drift, tau, &mut st.acc_next) {
                sys.accel_split(t_new, &st.next.q, &st.pred, drift, &mut st.acc_next);
                if sys.has_velocity_quadratic_inertia() {
                    for i in 0..st.acc.len() {
                        self.drift_next[i] = st.next.v[i] + tau * st.acc_next[i];
                    }
                    let symmetric = DriftVelocities {
                        current: &st.next.v,
                        previous: &self.drift_next,
                        w: -0.5,
                        predicted: &st.pred,
                    };
                    sys.accel_split(t_new, &st.next.q, &st.pred, symmetric, &mut st.acc_next);
                }
            }
            self.drift_prev.copy_from_slice(&st.next.v);
            self.have_drift_prev = true;
        } else {
            // restartable: the implicit kick takes its damping at v_{j+½} and the inertia terms
            // at the predicted velocity (w = −1 weighs `previous` alone), both fixed by level j
            let drift = DriftVelocities {
                current: &st.next.v,
                previous: &st.pred,
                w: -1.0,
                predicted: &st.pred,
            };
            if !sys.implicit_kick(t_new, &st.next.q, drift, tau, &mut st.acc_next) {
                sys.accel(t_new, &st.next.q, &st.pred, &mut st.acc_next);
            }
        }
        sys.powers(&mut st.p_new);
        for i in 0..st.acc.len() {
            st.next.v[i] += 0.5 * tau * st.acc_next[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_step_positions_are_the_positions_the_step_predicts() {
        let n = 5;
        let mut st = StepState::new(n, 0);
        for i in 0..n {
            let x = i as f64 + 1.0;
            st.cur.q[i] = 0.1 * x;
            st.cur.v[i] = -0.7 * x + 2.0;
            st.acc[i] = 30.0 * x.sin();
        }
        let mut q = vec![0.0; n];
        for (mut method, s) in [
            (VelocityForm::predicted(), 1e-6),
            (VelocityForm::predicted(), 3.7e-4),
            (VelocityForm::drift_split(), 2e-2),
        ] {
            method.step_positions(&st, 0.0, s, &mut q);
            method.predict(0.0, s, &mut st);
            for i in 0..n {
                let scale = st.cur.q[i].abs() + s * st.cur.v[i].abs() + s * s * st.acc[i].abs();
                assert!(
                    (q[i] - st.next.q[i]).abs() <= 4.0 * f64::EPSILON * scale,
                    "s = {s}, dof {i}: {} against the step's {}",
                    q[i],
                    st.next.q[i]
                );
            }
        }
    }
}
