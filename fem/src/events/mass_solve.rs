//! Solves with the (regularized) mass matrix M(q) + μ Σ_k N_k N_kᵀ of the contact maps: the
//! normal force, the impact map, the drift projection and the index-1 friction forces all need
//! x = M⁻¹b for a few right-hand sides b at one configuration q.
//!
//! **Assembly.** M = ∂R/∂q̈ is the Newton matrix with coefficients (c_a, c_v, c_q) = (1, 0, 0)
//! ([`Chain::newton_matrix`], exact without foreshortening). With foreshortening the
//! axial position of a point depends on every transverse DOF between the root and it, so M is
//! dense over a link; its dense part is semiseparable and [`Chain::exact_newton_matrix`] writes
//! it as a bordered band in the chain DOFs plus running-sum unknowns
//! ([`crate::chain::AugmentedLayout`]). Solving that augmented system with zero right-hand
//! sides in the auxiliary rows is an exact solve with M. One residual pass (the point data the
//! assembly reads) and one sparse factorization per configuration: O(n) work, against n mass
//! products and a dense LU (O(n²) passes' worth plus O(n³)) for M built column by column.
//!
//! **Regularization** μ N Nᵀ (massless directions, [`crate::events::contact`] module docs). A
//! direction whose support pairs all lie in the bordered-band pattern (a single section
//! rotation ψ; e_ψ(L) − e_θ(child), both border DOFs) is added entry by entry. A direction
//! that reaches across the band (the frame direction of a free joint without hub inertia: the
//! joint angle and every deflection DOF of its link) gets one more border unknown y = Nᵀx:
//! [M  μN; μNᵀ  −μ] [x; y] = [b; 0], whose Schur complement in x is M + μNNᵀ.
//!
//! **Reuse.** The factorization is kept with the (t, q) it was formed at; a request at the same
//! bits reuses it, and [`MassSolver::is_at`] tells whether it is of a given configuration (the
//! contact refines solves at nearby configurations against it, `crate::events::contact`). The
//! symbolic structure, the storage and the work vectors are allocated once.

use crate::band::BorderedBand;
use crate::chain::{AugmentedLayout, Chain, NewtonCoefficients};
use crate::error::FemError;

/// M(q) (+ μNNᵀ) assembled sparsely and factorized, for solves with few right-hand sides.
#[derive(Debug, Clone)]
pub(crate) struct MassSolver {
    /// Augmented layout of a chain with foreshortening (None: the chain DOFs themselves).
    layout: Option<AugmentedLayout>,
    matrix: BorderedBand,
    /// Unknowns of the chain (augmented) system, before the regularization's border unknowns.
    n_system: usize,
    /// Regularization entries (row, column, c_i c_j) inside the pattern, in system indices.
    direct: Vec<(usize, usize, f64)>,
    /// Regularization directions that need a border unknown, in system indices.
    bordered: Vec<Vec<(usize, f64)>>,
    /// Configuration of the current factorization.
    key_t: f64,
    key_q: Vec<f64>,
    key_mu: f64,
    factored: bool,
    /// Factorizations formed (diagnostic counter).
    pub factorizations: usize,
    x: Vec<f64>,
    zero: Vec<f64>,
    res: Vec<f64>,
}

impl MassSolver {
    /// The solver for `chain` with the regularization directions `reg_dirs` (chain DOFs).
    pub(crate) fn new(chain: &Chain, reg_dirs: &[Vec<(usize, f64)>]) -> Self {
        let n = chain.ndof;
        let layout = chain.has_foreshortening().then(|| chain.augmented_layout());
        let (ni, n_system, b) = match &layout {
            Some(l) => (l.n_interior, l.n, l.half_bandwidth),
            None => (chain.n_interior, n, chain.half_bandwidth),
        };
        let index = |i: usize| layout.as_ref().map_or(i, |l| l.map[i]);
        let in_pattern = |i: usize, j: usize| i >= ni || j >= ni || i.abs_diff(j) <= b;
        let mut direct = Vec::new();
        let mut bordered = Vec::new();
        for d in reg_dirs {
            let sys: Vec<(usize, f64)> = d.iter().map(|&(i, c)| (index(i), c)).collect();
            if sys
                .iter()
                .all(|&(i, _)| sys.iter().all(|&(j, _)| in_pattern(i, j)))
            {
                for &(i, ci) in &sys {
                    for &(j, cj) in &sys {
                        direct.push((i, j, ci * cj));
                    }
                }
            } else {
                bordered.push(sys);
            }
        }
        let nb = n_system - ni + bordered.len();
        let matrix = if layout.is_some() {
            BorderedBand::with_band_solver(ni, nb, b)
        } else {
            BorderedBand::new(ni, nb, b)
        };
        MassSolver {
            layout,
            matrix,
            n_system,
            direct,
            bordered,
            key_t: f64::NAN,
            key_q: vec![0.0; n],
            key_mu: f64::NAN,
            factored: false,
            factorizations: 0,
            x: vec![0.0; ni + nb],
            zero: vec![0.0; n],
            res: vec![0.0; n],
        }
    }

    /// Forms and factorizes M(q) + μNNᵀ at (t, q), unless the factorization at hand is of the
    /// same (t, q, μ). Returns the residual passes used (1 or 0).
    pub(crate) fn factor(
        &mut self,
        chain: &mut Chain,
        t: f64,
        q: &[f64],
        mu: f64,
    ) -> Result<usize, FemError> {
        if self.is_at(t, q, mu) {
            return Ok(0);
        }
        self.factored = false;
        // The assembly reads the point data of the last residual pass: one at (q, 0, 0).
        chain.residual(t, q, &self.zero, &self.zero, &mut self.res);
        let c = NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.0,
            c_q: 0.0,
        };
        match &self.layout {
            None => chain.newton_matrix(q, c, &mut self.matrix),
            Some(l) => chain.exact_newton_matrix(q, &self.zero, &self.zero, c, l, &mut self.matrix),
        }
        for &(i, j, c) in &self.direct {
            self.matrix.add(i, j, mu * c);
        }
        for (k, d) in self.bordered.iter().enumerate() {
            let p = self.n_system + k;
            for &(i, c) in d {
                self.matrix.add(i, p, mu * c);
                self.matrix.add(p, i, mu * c);
            }
            self.matrix.add(p, p, -mu);
        }
        self.matrix.factorize().map_err(|e| match e {
            FemError::Singular { pivot, .. } => FemError::Singular {
                what: "mass".into(),
                pivot,
                t,
            },
            other => other,
        })?;
        self.factorizations += 1;
        self.key_t = t;
        self.key_mu = mu;
        self.key_q.copy_from_slice(q);
        self.factored = true;
        Ok(1)
    }

    /// Whether a factorization is at hand, and whether it is of (t, q, μ) exactly.
    pub(crate) fn factored(&self) -> bool {
        self.factored
    }

    pub(crate) fn is_at(&self, t: f64, q: &[f64], mu: f64) -> bool {
        self.factored
            && self.key_t.to_bits() == t.to_bits()
            && self.key_mu.to_bits() == mu.to_bits()
            && self
                .key_q
                .iter()
                .zip(q)
                .all(|(a, b)| a.to_bits() == b.to_bits())
    }

    /// b ← (M + μNNᵀ)⁻¹ b with the current factorization (after [`MassSolver::factor`]).
    pub(crate) fn solve_in_place(&mut self, b: &mut [f64]) {
        debug_assert!(self.factored);
        self.x.iter_mut().for_each(|v| *v = 0.0);
        match &self.layout {
            None => self.x[..b.len()].copy_from_slice(b),
            Some(l) => {
                for (&i, &r) in l.map.iter().zip(b.iter()) {
                    self.x[i] = r;
                }
            }
        }
        self.matrix.solve_in_place(&mut self.x);
        match &self.layout {
            None => b.copy_from_slice(&self.x[..b.len()]),
            Some(l) => {
                for (&i, v) in l.map.iter().zip(b.iter_mut()) {
                    *v = self.x[i];
                }
            }
        }
    }
}
