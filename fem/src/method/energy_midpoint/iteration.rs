//! The Newton iteration's control: the measures of an update and the verdict on it
//! (convergence, failure, matrix refresh) — the rules of the module docs.

/// Newton iterations at most before the step is retried shorter.
pub(super) const MAX_ITERATIONS: usize = 30;
/// Energy defect h v̄ᵀ(residual) accepted per step, relative to the step's energy scale
/// (kinetic + |potential parts| at both ends + |work of the step|). Where round-off (of the
/// momentum difference) keeps the defect above this, the
/// iteration stops once the defect no longer falls (measured floor ≈ 1e-13 on `single-link`).
pub(super) const ENERGY_TOL: f64 = 1e-14;

/// The outcome of one Newton update ([`Iteration::judge`]).
pub(super) enum Verdict {
    /// The iterate where the residual was evaluated is the solution.
    Converged,
    /// Not finite or diverging: the step fails (the driver retries shorter).
    Failed,
    /// A stale matrix let the update grow: re-form it at the same iterate, update not applied.
    Refresh,
    /// Apply the update and iterate.
    Apply,
}

/// The size of one Newton update and the tests it is measured by.
pub(super) struct Measured {
    /// c_q‖δa‖∞: the update of the positions.
    pub(super) dq: f64,
    /// Absolute tolerance, floored at the round-off level of the update itself.
    pub(super) tol: f64,
    /// Energy defect |h v̄ᵀ(residual)| and the step's energy scale it is measured against.
    pub(super) defect: f64,
    pub(super) e_scale: f64,
    /// Whether g(q₁) is at its target within the Newton tolerance (true without constraint).
    pub(super) on_surface: bool,
}

/// The control state of a step's Newton iteration: the last update, when the matrix was formed
/// and the forced refreshes of a stale one.
pub(super) struct Iteration {
    pub(super) converged: bool,
    /// The last applied update (∞ before the first).
    pub(super) last: f64,
    /// Iteration at which the Newton matrix was last formed in this solve, and the forced
    /// refreshes (a stale matrix that stops contracting or diverges).
    pub(super) formed_it: Option<usize>,
    pub(super) force_refresh: bool,
    pub(super) forced: usize,
    pub(super) forced_now: bool,
    /// The tolerance of the last update, and its energy defect while within it (∞ otherwise).
    pub(super) polish_tol: f64,
    pub(super) last_defect: f64,
    pub(super) iterations: usize,
    /// The largest contraction θ measured in this solve (0 when none was).
    pub(super) max_theta: f64,
}

impl Iteration {
    pub(super) fn new() -> Self {
        Iteration {
            converged: false,
            last: f64::INFINITY,
            formed_it: None,
            force_refresh: false,
            forced: 0,
            forced_now: false,
            polish_tol: 0.0,
            last_defect: f64::INFINITY,
            iterations: 0,
            max_theta: 0.0,
        }
    }

    /// Whether iteration `it` forms the Newton matrix: at the first iteration unless an earlier
    /// step's matrix is reused (`reuse`); every 6th iteration while the update is above
    /// tolerance (once it is within tolerance and only the energy defect is being polished,
    /// the matrix still contracts, 1e-2..1e-3 per iteration, and a new one only costs — with a
    /// unilateral contact it also added noise); every iteration with `refresh`; and where a
    /// stale matrix was found ([`Self::judge`]).
    pub(super) fn wants_matrix(&self, it: usize, reuse: bool, refresh: bool) -> bool {
        let periodic = (it == 6 || it == 12 || it == 18) && self.last > self.polish_tol;
        (it == 0 && !reuse) || periodic || refresh || self.force_refresh
    }

    /// Records that the matrix is formed at iteration `it`.
    pub(super) fn formed(&mut self, it: usize) {
        self.formed_it = Some(it);
        self.forced_now = self.force_refresh;
        self.force_refresh = false;
    }

    /// Judges the update `m` of iteration `it`. Converged: the update is settled — within
    /// tolerance, or with contraction θ = dq/last > ½ under an unchanged matrix (remaining error
    /// ≈ dq/(1 − θ)) within 2(1 − θ)·tol — the constraint is on its target and the energy
    /// defect is below `ENERGY_TOL`·scale, no longer falls, or the update is far below
    /// tolerance. With a unilateral contact (`robust`) also when the previous update was within
    /// tolerance and this one grows (round-off noise). Failed: not finite, growing tenfold, or
    /// (`robust`) larger than `length_scale`.
    pub(super) fn judge(
        &mut self,
        it: usize,
        m: &Measured,
        robust: bool,
        length_scale: f64,
    ) -> Verdict {
        let Measured {
            dq,
            tol,
            defect,
            e_scale,
            on_surface,
        } = *m;
        if !dq.is_finite() {
            return Verdict::Failed;
        }
        self.iterations = it + 1;
        // The iterate's remaining error is about dq/(1 − θ), θ the contraction of the
        // update under an unchanged matrix: a reused or stale matrix (stiff shear, after an
        // impact) contracts slowly, and a small update alone would stop the iteration
        // short of the tolerance. Up to θ = ½ the update test stands as is.
        let last = self.last;
        let theta = if it >= 1 && self.formed_it != Some(it) && last.is_finite() && last > 0.0 {
            dq / last
        } else {
            0.0
        };
        self.max_theta = self.max_theta.max(theta);
        let settled = if theta <= 0.5 {
            dq <= tol
        } else {
            theta < 1.0 && dq <= 2.0 * (1.0 - theta) * tol
        };
        // The energy balance of the step is off by exactly the defect: demand it small too,
        // unless it has reached its round-off floor (no longer falls) or the update is far
        // below tolerance.
        if settled
            && on_surface
            && (defect <= ENERGY_TOL * e_scale
                || defect >= 0.5 * self.last_defect
                || dq <= 1e-4 * tol
                || it + 1 == MAX_ITERATIONS)
        {
            return Verdict::Converged;
        }
        self.last_defect = if dq <= tol { defect } else { f64::INFINITY };
        // A matrix formed at an earlier iterate (or step) that no longer contracts: form it
        // at the current iterate. Where the update grows, it is not applied (the residual
        // is re-evaluated at the same point with the new matrix); where it contracts
        // poorly, it is applied and the next iteration uses a fresh matrix. The matrix
        // changes along the almost massless frame directions (mass O(s²)) and with the
        // velocity-dependent foreshortening terms after impacts, where a reused matrix
        // failed (measured: free flight at dt = 2.5e-5, 8 elements, 33 rejected steps
        // before the first impact).
        if robust && dq > last && last <= self.polish_tol {
            // The previous update was within tolerance (only the energy defect was being
            // reduced) and this one is round-off noise: the current iterate, where the
            // residual was just evaluated, is the converged one.
            return Verdict::Converged;
        }
        self.polish_tol = tol;
        let stale = robust && self.formed_it != Some(it) && self.forced < 4 && it >= 1;
        if stale && dq > last {
            self.force_refresh = true;
            self.forced += 1;
            return Verdict::Refresh;
        }
        if (it > 2 && dq > 10.0 * last && !(self.forced_now && self.formed_it == Some(it)))
            || (robust && dq > length_scale)
        {
            // Diverging: give up early, the caller retries with a shorter step. (Not on
            // the iteration of a refresh forced by a stalled stale matrix: its updates
            // were too small, a larger first update of the fresh matrix is no
            // divergence. Never an update of a link length.)
            return Verdict::Failed;
        }
        if stale && dq > 0.2 * last {
            self.force_refresh = true;
            self.forced += 1;
        }
        self.last = dq;
        Verdict::Apply
    }
}
