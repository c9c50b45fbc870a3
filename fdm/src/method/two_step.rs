//! The report's two-step central difference (eq. 5.21 and 5.24–5.30), optionally filtered.
//!
//! * `report` — y_{j+1} = y_{j−1} + (τ_j + τ_{j+1}) ẏ(t_j, y_j) for y = (q, v), with unequal
//!   steps τ. Start-up: the scheme needs y₁ besides y₀. It takes y₁ from one step of Heun's
//!   explicit trapezoidal rule (second order): its O(τ³) local error neither lowers the global
//!   order nor excites the scheme's computational mode by more than O(τ³) — a forward-Euler
//!   start would plant an O(τ²) parasitic oscillation of amplitude comparable to the global
//!   error.
//! * `robert-asselin=ν` — the same with the middle level filtered after each step,
//!   ȳ_j = y_j + ν(ȳ_{j−1} − 2y_j + y_{j+1}): the computational mode (sign alternating from step
//!   to step) is damped by ≈ (1 − 4ν) per step, the physical mode by ≈ ν(ωτ)² per step
//!   (first-order amplitude error: the accuracy cost, measured in the tests).
//!
//! **Stability.** The model's σ equals 2/ω_max of the discrete operator (the limit of the
//! one-step second-order form). The two-step form 5.21 has amplification roots
//! ξ = iωτ ± √(1 − ω²τ²), |ξ| = 1 only for ωτ ≤ 1: it needs half of σ. The Robert–Asselin
//! filter shrinks the limit further: the filtered scheme's characteristic equation
//! ξ² − 2(ν + iωτ)ξ − (1 − 2ν − 2iνωτ) = 0 has both roots in the unit disc only for
//! ωτ ≲ 1 − ν (ν = 0.01: 0.99004; ν = 0.1: 0.9045), so its factor is ½(1 − ν).

// Index loops run over several parallel level buffers at once.
#![allow(clippy::needless_range_loop)]

use super::{AtJumps, Capabilities, Method, MethodParams, StepState, Stepper};
use crate::system::System;

/// The two-step central difference, with the Robert–Asselin coefficient ν if filtered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoStep {
    filter: Option<f64>,
}

impl TwoStep {
    /// The report's unfiltered scheme.
    pub fn central_difference() -> Self {
        TwoStep { filter: None }
    }

    /// The scheme with the middle level filtered by ν.
    pub fn robert_asselin(nu: f64) -> Self {
        TwoStep { filter: Some(nu) }
    }

    /// A step needs the level before it (no restart at an event) and its damping is explicit.
    /// A level's force acts over the half steps on both sides of it at once, so the scheme
    /// meets a jump of an applied law by landing a level on it and starting again there: the
    /// landing step's force lies before the jump, the start-up step's after it.
    pub const CAPABILITIES: Capabilities = Capabilities {
        restarts_at_events: false,
        implicit_damping: false,
        at_jumps: AtJumps::Restarts,
    };
}

impl From<MethodParams> for TwoStep {
    /// `robert-asselin=ν` filtered by ν; the report's scheme otherwise.
    fn from(params: MethodParams) -> Self {
        match params.method {
            Method::RobertAsselin { nu } => TwoStep::robert_asselin(nu),
            _ => TwoStep::central_difference(),
        }
    }
}

impl Stepper for TwoStep {
    fn bound_factor(&self) -> f64 {
        match self.filter {
            None => 0.5,
            Some(nu) => 0.5 * (1.0 - nu),
        }
    }

    fn has_computational_mode(&self) -> bool {
        true
    }

    /// 2(1 − cos ωτ) at the limit ωτ = 1, plus margin.
    fn parasitic_threshold(&self) -> f64 {
        1.5
    }

    /// One Heun step gives level 1.
    fn start(&mut self, sys: &mut dyn System, t: f64, tau: f64, st: &mut StepState) -> usize {
        let n = st.acc.len();
        let (cur, next) = (&st.cur, &mut st.next);
        // predictor
        for i in 0..n {
            next.q[i] = cur.q[i] + tau * cur.v[i];
            next.v[i] = cur.v[i] + tau * st.acc[i];
        }
        sys.accel(t + tau, &next.q, &next.v, &mut st.acc_next);
        for i in 0..n {
            next.q[i] = cur.q[i] + 0.5 * tau * (cur.v[i] + next.v[i]);
            next.v[i] = cur.v[i] + 0.5 * tau * (st.acc[i] + st.acc_next[i]);
        }
        sys.accel(t + tau, &next.q, &next.v, &mut st.acc_next);
        sys.powers(&mut st.p_new);
        2
    }

    fn predict(&mut self, tau_prev: f64, tau: f64, st: &mut StepState) {
        let n = st.acc.len();
        let span = tau_prev + tau;
        let (prev, cur, next) = (&st.prev, &mut st.cur, &mut st.next);
        for i in 0..n {
            next.q[i] = prev.q[i] + span * cur.v[i];
            next.v[i] = prev.v[i] + span * st.acc[i];
        }
        if let Some(nu) = self.filter {
            for i in 0..n {
                cur.q[i] += nu * (prev.q[i] - 2.0 * cur.q[i] + next.q[i]);
                cur.v[i] += nu * (prev.v[i] - 2.0 * cur.v[i] + next.v[i]);
            }
        }
    }

    /// q_{j−1} + (τ_j + s) v_j (level j before its filter).
    fn step_positions(&self, st: &StepState, tau_prev: f64, s: f64, q: &mut [f64]) {
        let span = tau_prev + s;
        for i in 0..q.len() {
            q[i] = st.prev.q[i] + span * st.cur.v[i];
        }
    }

    fn predicted_velocity<'a>(&self, st: &'a StepState) -> &'a [f64] {
        &st.next.v
    }

    fn complete(
        &mut self,
        sys: &mut dyn System,
        t_new: f64,
        _tau_prev: f64,
        _tau: f64,
        st: &mut StepState,
    ) {
        sys.accel(t_new, &st.next.q, &st.next.v, &mut st.acc_next);
        sys.powers(&mut st.p_new);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_step_positions_are_the_positions_the_step_predicts() {
        let n = 4;
        let mut st = StepState::new(n, 0);
        for i in 0..n {
            let x = i as f64 + 1.0;
            st.prev.q[i] = 0.1 * x - 1e-3;
            st.cur.q[i] = 0.1 * x;
            st.cur.v[i] = 2.0 - 0.7 * x;
            st.acc[i] = 30.0 * x.sin();
        }
        let mut q = vec![0.0; n];
        for (mut method, tau_prev, s) in [
            (TwoStep::central_difference(), 1e-4, 1e-4),
            (TwoStep::central_difference(), 1e-4, 3e-5),
            (TwoStep::robert_asselin(0.01), 2e-4, 1e-4),
        ] {
            method.step_positions(&st, tau_prev, s, &mut q);
            let mut taken = StepState::new(n, 0);
            taken.prev.q.copy_from_slice(&st.prev.q);
            taken.cur.q.copy_from_slice(&st.cur.q);
            taken.cur.v.copy_from_slice(&st.cur.v);
            taken.acc.copy_from_slice(&st.acc);
            method.predict(tau_prev, s, &mut taken);
            assert_eq!(q, taken.next.q, "τ_prev = {tau_prev}, s = {s}");
        }
    }
}
