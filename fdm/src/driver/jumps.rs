//! Steps onto the jumps of the applied laws (torque switches, burn-out: [`System::jumps`]);
//! how the method carries on from there is its [`crate::method::AtJumps`].
//!
//! A law that jumps inside a step is read at the step's levels only, so the step takes the
//! jump's impulse wrong by (t_jump − t_mid)·Δτ: an error first order in the step, which on
//! `single-link` (bang-bang hub torque) dwarfs the second-order error of the smooth stretches
//! by two to three orders. Instead a step that would pass a jump ends on it (the step before
//! it halves the remaining gap when it is below two steps, so that no sliver is left), the
//! closing kick reads the laws' left limits there ([`System::close_stretch_at`]), and the next
//! opening kick their new values: the level's acceleration and the ledger's powers there gain
//! the jump's response a(jump⁺) − a(jump⁻) and P(jump⁺) − P(jump⁻), each pair evaluated at the
//! landed state, so that everything but the law cancels. Two more force evaluations per jump.
//! A two-step method then starts again from the landed level
//! ([`crate::method::AtJumps::Restarts`]: the level's acceleration is the law's new value).

use crate::events::Events;
use crate::method::StepState;
use crate::output::Outputs;
use crate::system::System;

/// The jump times ahead and the scratch of the level's one-sided accelerations and powers.
pub(super) struct Jumps {
    times: Vec<f64>,
    next: usize,
    left: Vec<f64>,
    right: Vec<f64>,
    powers_left: Vec<f64>,
    powers_right: Vec<f64>,
}

impl Jumps {
    /// The system's jumps (none: nothing is allocated). Those at or after the run's end are
    /// kept too: the last step must not pass one either, since the samples it records up to
    /// the end are read on it (a step past a jump takes the new law's power at its far level).
    pub(super) fn new<S: System + Outputs + ?Sized>(sys: &S) -> Self {
        let times: Vec<f64> = sys.jumps();
        let (n, np) = if times.is_empty() {
            (0, 0)
        } else {
            let (_, inputs, dissipations) = sys.ledger_names();
            (sys.dofs(), inputs.len() + dissipations.len())
        };
        Jumps {
            times,
            next: 0,
            left: vec![0.0; n],
            right: vec![0.0; n],
            powers_left: vec![0.0; np],
            powers_right: vec![0.0; np],
        }
    }

    /// The step from t instead of `tau`, and the jump it lands on: the gap to the next jump
    /// when that is at most `tau`, half the gap when it is below 2`tau`, else `tau`.
    pub(super) fn toward(&mut self, t: f64, tau: f64) -> (f64, Option<f64>) {
        while self.times.get(self.next).is_some_and(|&jump| jump <= t) {
            self.next += 1;
        }
        let Some(&jump) = self.times.get(self.next) else {
            return (tau, None);
        };
        let gap = jump - t;
        if gap <= tau {
            (gap, Some(jump))
        } else if gap < 2.0 * tau {
            (0.5 * gap, None)
        } else {
            (tau, None)
        }
    }

    /// Opens the stretch after `jump`, on which the step has just landed (level j in `st`):
    /// adds the jump's response to the level's acceleration and takes its powers anew (module
    /// docs). Returns the force evaluations made.
    pub(super) fn open<S: System + ?Sized, E: Events<S>>(
        &mut self,
        sys: &mut S,
        events: &mut E,
        jump: f64,
        st: &mut StepState,
    ) -> usize {
        sys.close_stretch_at(Some(jump));
        sys.accel(jump, &st.cur.q, &st.cur.v, &mut self.left);
        sys.powers(&mut self.powers_left);
        sys.close_stretch_at(None);
        sys.accel(jump, &st.cur.q, &st.cur.v, &mut self.right);
        sys.powers(&mut self.powers_right);
        for i in 0..st.acc.len() {
            st.acc[i] += self.right[i] - self.left[i];
        }
        // the level's powers as the method took them, with the jump's change
        for k in 0..st.p_cur.len() {
            st.p_cur[k] += self.powers_right[k] - self.powers_left[k];
        }
        events.level_powers(sys, jump, &st.cur.v, &mut st.p_cur);
        2
    }
}
