//! The Newton system of the implicit methods: S = c_a M + c_v C + c_q K at a trial point,
//! formed analytically and factorized once per formation by a sparse LU whose symbolic
//! factorization is built once per run ([`crate::band::BorderedBand`]). Chains without
//! foreshortening use the bordered-band matrix of the chain DOFs; chains with foreshortening
//! use the exact matrix as an augmented bordered band ([`crate::chain::AugmentedLayout`]: the
//! dense ∂s/∂q couplings through running-sum unknowns), solved with zero auxiliary right-hand
//! sides. Both cost O(n) per formation and solve.

use crate::band::BorderedBand;
use crate::chain::{AugmentedLayout, Chain, NewtonCoefficients};
use crate::error::FemError;
use crate::method::{Counters, StepState};

/// How the Newton matrix is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JacobianKind {
    /// Bordered-band matrix of the chain DOFs (exact without foreshortening).
    Banded,
    /// Exact matrix of a chain with foreshortening, augmented with the running-sum unknowns
    /// of the foreshortening and its tail load.
    Augmented,
}

/// The augmented system of [`JacobianKind::Augmented`]: layout, matrix and solve vector.
#[derive(Debug, Clone)]
pub struct AugmentedSystem {
    pub layout: AugmentedLayout,
    pub matrix: BorderedBand,
    x: Vec<f64>,
}

/// The Newton matrix, its factorization, and the residual and update vectors.
#[derive(Debug, Clone)]
pub struct NewtonSystem {
    /// The bordered-band matrix of the chain DOFs (also the mass/stiffness estimates of the
    /// explicit method and the regularized start use it).
    pub matrix: BorderedBand,
    pub jacobian: JacobianKind,
    pub augmented: Option<AugmentedSystem>,
    /// Step size the current matrix was formed with, and whether it must be refreshed.
    pub matrix_h: f64,
    pub slow_convergence: bool,
    /// Residual at the trial point (input of [`NewtonSystem::form`]).
    pub res: Vec<f64>,
    /// Right-hand side and solution of [`NewtonSystem::solve`].
    pub delta: Vec<f64>,
    /// Newton displacement tolerance.
    pub tol: f64,
    /// A unilateral tip contact is stepped (impacts, releases, grazing): the energy-midpoint
    /// iteration refreshes stale matrices ([`crate::method::energy_midpoint`]).
    pub unilateral_contact: bool,
}

impl NewtonSystem {
    /// The Newton system of `chain` (`length_scale`: the longest link, scales the tolerance).
    pub fn new(chain: &Chain, length_scale: f64) -> Self {
        let n = chain.ndof;
        let augmented = chain.has_foreshortening().then(|| {
            let layout = chain.augmented_layout();
            let matrix = chain.new_augmented_matrix(&layout);
            let x = vec![0.0; layout.n];
            AugmentedSystem { layout, matrix, x }
        });
        NewtonSystem {
            matrix: chain.new_matrix(),
            jacobian: if augmented.is_some() {
                JacobianKind::Augmented
            } else {
                JacobianKind::Banded
            },
            augmented,
            matrix_h: f64::NAN,
            slow_convergence: true,
            res: vec![0.0; n],
            delta: vec![0.0; n],
            tol: 1e-11 * length_scale.max(1e-3),
            unilateral_contact: false,
        }
    }

    /// Re-forms and factors the matrix in Newton iteration `it` of a step of size `h`: at the
    /// first iteration (the matrix is cheap; near-quadratic convergence keeps the iteration
    /// error far below the tolerance, which the tight ledger checks need) and every 6th.
    #[allow(clippy::too_many_arguments)]
    pub fn form_if_due(
        &mut self,
        it: usize,
        h: f64,
        chain: &mut Chain,
        st: &StepState,
        counters: &mut Counters,
        c: NewtonCoefficients,
        t: f64,
    ) -> Result<(), FemError> {
        if it == 0 || it == 6 || it == 12 || it == 18 {
            self.form(chain, st, counters, c, t)?;
            self.matrix_h = h;
            self.slow_convergence = false;
        }
        Ok(())
    }

    /// Forms and factorizes the Newton matrix at (q1, q̇1, q̈1) after a full residual
    /// evaluation there (the matrix reads the chain's point data of that pass).
    pub fn form(
        &mut self,
        chain: &mut Chain,
        st: &StepState,
        counters: &mut Counters,
        c: NewtonCoefficients,
        t: f64,
    ) -> Result<(), FemError> {
        counters.jacobians += 1;
        counters.factorizations += 1;
        match self.augmented.as_mut() {
            None => {
                chain.newton_matrix(&st.q1, c, &mut self.matrix);
                self.matrix.factorize().map_err(|e| with_time(e, t))
            }
            Some(aug) => {
                chain.exact_newton_matrix(
                    &st.q1,
                    &st.qd1,
                    &st.qdd1,
                    c,
                    &aug.layout,
                    &mut aug.matrix,
                );
                aug.matrix.factorize().map_err(|e| with_time(e, t))
            }
        }
    }

    /// Solves S x = `delta` in place.
    pub fn solve(&mut self) {
        match self.augmented.as_mut() {
            None => self.matrix.solve_in_place(&mut self.delta),
            Some(aug) => {
                // Chain rows carry the right-hand side, the running-sum rows zero.
                aug.x.iter_mut().for_each(|v| *v = 0.0);
                for (&i, &r) in aug.layout.map.iter().zip(&self.delta) {
                    aug.x[i] = r;
                }
                aug.matrix.solve_in_place(&mut aug.x);
                for (&i, d) in aug.layout.map.iter().zip(self.delta.iter_mut()) {
                    *d = aug.x[i];
                }
            }
        }
    }
}

/// Stamps a singular-matrix error with the time.
pub fn with_time(e: FemError, t: f64) -> FemError {
    match e {
        FemError::Singular { what, pivot, .. } => FemError::Singular { what, pivot, t },
        other => other,
    }
}
