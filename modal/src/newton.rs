//! Structured Newton linear algebra of the chain for the implicit integrator
//! ([`crate::integrate::Sdirk`] through [`crate::integrate::OdeRhs::newton_linearize`]).
//!
//! The state is y = (q, v, w) (free coordinates, their rates, cumulative works) and the
//! linearization kept is that of [`crate::rhs::ChainRhs`]'s structured Jacobian:
//! q' = v, M(q) v' = F(q, v) + Wλ with the stiff tangents K = −∂F/∂q, D = −∂F/∂v
//! ([`crate::model::Chain::elastic_tangent`]), the contact rows A (A v' = −convective terms;
//! W = Aᵀ, or Gᵀ − μsσTᵀ with sliding friction), and the power rows w' = P(v) with
//! Π = ∂P/∂v. Solving (I − cJ)x = r for x = (x_q, x_v, x_w) never forms M⁻¹K: with
//! x_q = r_q + c x_v,
//!
//! ```text
//!   S x_v − c W μ = M r_v − c K r_q,    A x_v = A r_v,    S = M + cD + c²K (SPD),
//!   x_w = r_w + c Π x_v,
//! ```
//!
//! i.e. one Cholesky factorization of S (N_free³/3) and a ≤ 2 × 2 Schur complement for the
//! contact rows. This matters in the polynomial coordinates: M(q) has condition numbers
//! 10¹³–10¹⁷ at 12–24 modes per link (the hub angle is nearly expressible by clamped
//! polynomials, so a rigid rotation undone by the elastic coordinates carries almost no kinetic
//! energy) and M⁻¹K entries reach 10¹⁴–10¹⁵, so the dense iteration matrix I − cM⁻¹K is
//! strongly non-normal and its LU solve inaccurate (simplified Newton was seen stalling in
//! period-2 cycles at 24 modes), while S is assembled from the same well-scaled M, D, K that
//! the model itself factors.

use crate::linalg::{cholesky_factor, cholesky_substitute, dot, solve2};

/// The linearization of one point and the factorization of one c (see the module docs).
#[derive(Debug, Clone)]
pub struct ChainNewton {
    nf: usize,
    /// Number of power rows (cumulative works in the state).
    ns: usize,
    /// M, K, D over the free coordinates (nf × nf row-major).
    pub(crate) m: Vec<f64>,
    pub(crate) k: Vec<f64>,
    pub(crate) d: Vec<f64>,
    /// Active contact rows (0, 1 or 2): A (rows × nf) and the force directions W.
    pub(crate) rows: usize,
    pub(crate) a: Vec<f64>,
    pub(crate) w: Vec<f64>,
    /// Power rows Π (ns × nf).
    pub(crate) p: Vec<f64>,
    c: f64,
    /// Cholesky factor of S = M + cD + c²K.
    s: Vec<f64>,
    /// S⁻¹ W (rows × nf) and the Schur complement A S⁻¹ W (row-major 2 × 2).
    sw: Vec<f64>,
    schur: [f64; 4],
    tmp: Vec<f64>,
}

impl ChainNewton {
    pub fn new(nf: usize, ns: usize) -> Self {
        ChainNewton {
            nf,
            ns,
            m: vec![0.0; nf * nf],
            k: vec![0.0; nf * nf],
            d: vec![0.0; nf * nf],
            rows: 0,
            a: vec![0.0; 2 * nf],
            w: vec![0.0; 2 * nf],
            p: vec![0.0; ns * nf],
            c: f64::NAN,
            s: vec![0.0; nf * nf],
            sw: vec![0.0; 2 * nf],
            schur: [0.0; 4],
            tmp: vec![0.0; nf],
        }
    }

    /// Factors I − cJ; `false` if S is not positive definite (or the Schur complement of the
    /// contact rows vanishes).
    pub fn factor(&mut self, c: f64) -> bool {
        let nf = self.nf;
        let c2 = c * c;
        for i in 0..nf * nf {
            self.s[i] = self.m[i] + c * self.d[i] + c2 * self.k[i];
        }
        if cholesky_factor(&mut self.s, nf).is_err() {
            self.c = f64::NAN;
            return false;
        }
        for r in 0..self.rows {
            let sw = &mut self.sw[r * nf..(r + 1) * nf];
            sw.copy_from_slice(&self.w[r * nf..(r + 1) * nf]);
            cholesky_substitute(&self.s, nf, sw);
        }
        for r in 0..self.rows {
            for q in 0..self.rows {
                self.schur[r * 2 + q] = dot(
                    &self.a[r * nf..(r + 1) * nf],
                    &self.sw[q * nf..(q + 1) * nf],
                );
            }
        }
        let ok = match self.rows {
            0 => true,
            1 => self.schur[0] != 0.0 && self.schur[0].is_finite(),
            _ => {
                let det = self.schur[0] * self.schur[3] - self.schur[1] * self.schur[2];
                det != 0.0 && det.is_finite()
            }
        };
        self.c = if ok { c } else { f64::NAN };
        ok
    }

    /// x ← (I − cJ)⁻¹ x for x = (x_q, x_v, x_w) with the last factorization.
    pub fn solve(&mut self, x: &mut [f64]) {
        let nf = self.nf;
        let c = self.c;
        let (xq, rest) = x.split_at_mut(nf);
        let (xv, xw) = rest.split_at_mut(nf);
        // tmp = M r_v − c K r_q.
        for i in 0..nf {
            let row = i * nf..(i + 1) * nf;
            self.tmp[i] = dot(&self.m[row.clone()], xv) - c * dot(&self.k[row], xq);
        }
        // Contact residuals A r_v (before x_v is overwritten).
        let mut ar = [0.0; 2];
        for (r, v) in ar.iter_mut().enumerate().take(self.rows) {
            *v = dot(&self.a[r * nf..(r + 1) * nf], xv);
        }
        cholesky_substitute(&self.s, nf, &mut self.tmp);
        if self.rows > 0 {
            // μ' = (A S⁻¹ W)⁻¹ (A r_v − A S⁻¹ tmp), x_v = S⁻¹ tmp + S⁻¹W μ'.
            let mut g = [0.0; 2];
            for (r, v) in g.iter_mut().enumerate().take(self.rows) {
                *v = ar[r] - dot(&self.a[r * nf..(r + 1) * nf], &self.tmp);
            }
            let mu = if self.rows == 1 {
                [g[0] / self.schur[0], 0.0]
            } else {
                solve2(&self.schur, g)
            };
            for r in 0..self.rows {
                let sw = &self.sw[r * nf..(r + 1) * nf];
                for i in 0..nf {
                    self.tmp[i] += sw[i] * mu[r];
                }
            }
        }
        xv.copy_from_slice(&self.tmp);
        for (q, v) in xq.iter_mut().zip(&self.tmp) {
            *q += c * v;
        }
        for (r, v) in xw.iter_mut().enumerate().take(self.ns) {
            *v += c * dot(&self.p[r * nf..(r + 1) * nf], xv);
        }
    }
}
