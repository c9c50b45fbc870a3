//! The Newton system of the implicit methods: S = c_a M + c_v C + c_q K at a trial point,
//! formed analytically by the [`System`] and factorized once per formation by a sparse LU
//! whose symbolic factorization is built once per run ([`crate::band::BorderedBand`]). A
//! system whose band matrix is exact (chains without foreshortening) uses the bordered-band
//! matrix of its DOFs; one with an [`Augmentation`] (chains with foreshortening: the dense
//! ∂s/∂q couplings through running-sum unknowns) uses the exact matrix as an augmented
//! bordered band, solved with zero auxiliary right-hand sides. Both cost O(n) per formation
//! and solve for the chains.

use crate::band::BorderedBand;
use crate::error::FemError;
use crate::method::{Counters, StepState};
use crate::system::{Augmentation, NewtonCoefficients, System};

/// How the Newton matrix is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JacobianKind {
    /// Bordered-band matrix of the system DOFs (exact without an augmentation).
    Banded,
    /// Exact matrix augmented with the system's auxiliary unknowns (a chain with
    /// foreshortening: the running sums of the foreshortening and its tail load).
    Augmented,
}

/// The augmented system of [`JacobianKind::Augmented`]: layout, matrix and solve vector.
#[derive(Debug, Clone)]
pub struct AugmentedSystem<A> {
    pub layout: A,
    pub matrix: BorderedBand,
    x: Vec<f64>,
}

/// The Newton matrix, its factorization, and the residual and update vectors, for a system
/// whose exact matrix has the augmentation `A` ([`System::Augmented`]).
#[derive(Debug, Clone)]
pub struct NewtonSystem<A> {
    /// The bordered-band matrix of the system DOFs (also the mass/stiffness estimates of the
    /// explicit method and the regularized start use it).
    pub matrix: BorderedBand,
    pub jacobian: JacobianKind,
    pub augmented: Option<AugmentedSystem<A>>,
    /// Step size the current matrix was formed with, and whether it must be refreshed.
    pub matrix_h: f64,
    pub slow_convergence: bool,
    /// Matrices formed so far: identifies the factorization that [`NewtonSystem::solve`] uses
    /// (solves with it may be kept while it is the same).
    pub formed: u64,
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

impl<A: Augmentation> NewtonSystem<A> {
    /// The Newton system of `system` (`length_scale`: the longest link, scales the tolerance).
    pub fn new<S: System<Augmented = A> + ?Sized>(system: &S, length_scale: f64) -> Self {
        let n = system.ndof();
        let augmented = system.exact_layout().map(|layout| {
            let matrix = system.new_augmented_matrix(&layout);
            let x = vec![0.0; layout.size()];
            AugmentedSystem { layout, matrix, x }
        });
        NewtonSystem {
            matrix: system.new_matrix(),
            jacobian: if augmented.is_some() {
                JacobianKind::Augmented
            } else {
                JacobianKind::Banded
            },
            augmented,
            matrix_h: f64::NAN,
            formed: 0,
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
    pub fn form_if_due<S: System<Augmented = A> + ?Sized>(
        &mut self,
        it: usize,
        h: f64,
        system: &mut S,
        st: &StepState,
        counters: &mut Counters,
        c: NewtonCoefficients,
        t: f64,
    ) -> Result<(), FemError> {
        if it == 0 || it == 6 || it == 12 || it == 18 {
            self.form(system, st, counters, c, t)?;
            self.matrix_h = h;
            self.slow_convergence = false;
        }
        Ok(())
    }

    /// Forms and factorizes the Newton matrix at (q1, q̇1, q̈1) after a full residual
    /// evaluation there (the matrix reads the system's data of that pass).
    pub fn form<S: System<Augmented = A> + ?Sized>(
        &mut self,
        system: &mut S,
        st: &StepState,
        counters: &mut Counters,
        c: NewtonCoefficients,
        t: f64,
    ) -> Result<(), FemError> {
        counters.jacobians += 1;
        counters.factorizations += 1;
        self.formed += 1;
        match self.augmented.as_mut() {
            None => {
                system.newton_matrix(&st.q1, c, &mut self.matrix);
                self.matrix.factorize().map_err(|e| with_time(e, t))
            }
            Some(aug) => {
                system.exact_newton_matrix(
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
                // System rows carry the right-hand side, the auxiliary rows zero.
                aug.x.iter_mut().for_each(|v| *v = 0.0);
                for (&i, &r) in aug.layout.map().iter().zip(&self.delta) {
                    aug.x[i] = r;
                }
                aug.matrix.solve_in_place(&mut aug.x);
                for (&i, d) in aug.layout.map().iter().zip(self.delta.iter_mut()) {
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
