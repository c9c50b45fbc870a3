//! The deflection block of the chain's mass matrix with the foreshortening rates: per link,
//!
//!   A = D + GᵀNG,   N = Lᵀ diag(W) L,
//!
//! D the lumped masses (with the section inertias' diagonal) of the stations that carry a
//! deflection unknown, G the segments' rates u_seg = g_seg(u̇_seg − u̇_{seg−1}) (g the segment
//! slopes: bidiagonal), L the running sum ṡ_k = Σ_{seg ≤ k} u_seg and W the mass that moves
//! with station k's axial rate (link 1's tip carries the elbow and all of link 2). N is dense
//! but N⁻¹ = L⁻¹W⁻¹L⁻ᵀ is tridiagonal, so Woodbury,
//!
//!   A⁻¹ = D⁻¹ − D⁻¹Gᵀ(N⁻¹ + GD⁻¹Gᵀ)⁻¹GD⁻¹,
//!
//! is one tridiagonal SPD factorization per state and O(r) per solve. [`MassFactors`] holds
//! both links' blocks with the rest of the mass solve's state-dependent factors.

use super::schur::{MAX_SMALL, SmallLu};
use crate::tridiagonal::TridiagonalLdl;

/// One link's A = D + GᵀNG (module docs) at the state of the last [`Self::set_state`],
/// factored by the first solve at that state (the implicit kick reads only G and W).
#[derive(Debug, Clone)]
pub struct LinkRates {
    /// station masses D (length r − 1)
    d: Vec<f64>,
    /// axial masses W (length r)
    w: Vec<f64>,
    /// segment slopes g (length r)
    g: Vec<f64>,
    /// N⁻¹ + GD⁻¹Gᵀ
    ldl: TridiagonalLdl,
    /// segment scratch (r rows of up to `MAX_SMALL` right-hand sides)
    u: Vec<f64>,
    foreshortening: bool,
    /// `ldl` holds the factor of the current state
    factored: bool,
    /// the factorization failed (a state that is not finite): solves give NaN
    failed: bool,
}

impl LinkRates {
    /// A link of r segments with axial masses `w` (length r); D is set by [`Self::set_masses`].
    pub fn new(w: Vec<f64>, foreshortening: bool) -> Self {
        let r = w.len();
        LinkRates {
            d: vec![0.0; r - 1],
            w,
            g: vec![0.0; r],
            ldl: TridiagonalLdl::new(r),
            u: vec![0.0; r * MAX_SMALL],
            foreshortening,
            factored: false,
            failed: false,
        }
    }

    /// Placeholder while a link's factors are borrowed out.
    pub fn empty() -> Self {
        LinkRates {
            d: Vec::new(),
            w: Vec::new(),
            g: Vec::new(),
            ldl: TridiagonalLdl::new(0),
            u: Vec::new(),
            foreshortening: false,
            factored: false,
            failed: false,
        }
    }

    /// The axial masses W (length r).
    pub fn weights(&self) -> &[f64] {
        &self.w
    }

    /// The segment slopes g of the last [`Self::set_state`] (length r).
    pub fn slopes(&self) -> &[f64] {
        &self.g
    }

    /// The tridiagonal N⁻¹ + GD⁻¹Gᵀ at the last [`Self::set_state`]: its diagonal (length r)
    /// and its off-diagonal A_{a,a+1} (length r − 1).
    pub fn block(&self) -> (Vec<f64>, Vec<f64>) {
        let r = self.w.len();
        let (diag, off) = rate_block(&self.d, &self.w, &self.g);
        ((0..r).map(diag).collect(), (0..r - 1).map(off).collect())
    }

    /// The station masses D (length r − 1; constant).
    pub fn set_masses(&mut self, d: impl Fn(usize) -> f64) {
        let r = self.w.len();
        for i in 0..r - 1 {
            self.d[i] = d(i);
        }
        self.factored = false;
    }

    /// The state: the segment slopes `g` (length r; read only with foreshortening) of the
    /// stations' deflections, the tip's included (0 in a chord frame, −Lψ in the clamp-tangent
    /// frame).
    pub fn set_state(&mut self, g: &[f64]) {
        let r = self.w.len();
        self.factored = false;
        if self.foreshortening {
            self.g.copy_from_slice(&g[..r]);
        }
    }

    /// Factors N⁻¹ + GD⁻¹Gᵀ (SPD for positive masses and a finite state; otherwise the
    /// solves give NaN and the run's watch stops it).
    fn factor(&mut self) {
        let (diag, off) = rate_block(&self.d, &self.w, &self.g);
        self.failed = self.ldl.factor(diag, off).is_err();
        self.factored = true;
    }

    /// x ← A⁻¹x (length r − 1).
    pub fn solve_in_place(&mut self, x: &mut [f64]) {
        self.solve_rows_in_place(x, 1);
    }

    /// X ← A⁻¹X for `m` right-hand sides stored by rows (X[i·m + c], r − 1 rows): one sweep
    /// of the tridiagonal factor for all.
    pub fn solve_rows_in_place(&mut self, x: &mut [f64], m: usize) {
        let r = self.w.len();
        for i in 0..r - 1 {
            x[i * m..i * m + m].iter_mut().for_each(|v| *v /= self.d[i]);
        }
        if !self.foreshortening {
            return;
        }
        if !self.factored {
            self.factor();
        }
        if self.failed {
            x[..(r - 1) * m].iter_mut().for_each(|v| *v = f64::NAN);
            return;
        }
        let u = &mut self.u[..r * m];
        for seg in 0..r {
            for c in 0..m {
                let right = if seg < r - 1 { x[seg * m + c] } else { 0.0 };
                let left = if seg == 0 { 0.0 } else { x[(seg - 1) * m + c] };
                u[seg * m + c] = self.g[seg] * (right - left);
            }
        }
        self.ldl.solve_rows_in_place(u, m);
        for i in 0..r - 1 {
            for c in 0..m {
                x[i * m + c] -=
                    (self.g[i] * u[i * m + c] - self.g[i + 1] * u[(i + 1) * m + c]) / self.d[i];
            }
        }
    }
}

/// The tridiagonal block N⁻¹ + GD⁻¹Gᵀ of a link's foreshortening rates (module docs) from its
/// station masses `d` (length r − 1), axial masses `w` and segment slopes `g` (length r): its
/// diagonal and its off-diagonal A_{a,a+1}, as functions of the segment index.
pub fn rate_block<'a>(
    d: &'a [f64],
    w: &'a [f64],
    g: &'a [f64],
) -> (
    impl Fn(usize) -> f64 + Copy + 'a,
    impl Fn(usize) -> f64 + Copy + 'a,
) {
    let r = w.len();
    let inv_d = move |i: usize| if i < r - 1 { 1.0 / d[i] } else { 0.0 };
    let diag = move |a: usize| {
        let mut t = 1.0 / w[a] + g[a] * g[a] * inv_d(a);
        if a > 0 {
            t += 1.0 / w[a - 1] + g[a] * g[a] * inv_d(a - 1);
        }
        t
    };
    let off = move |a: usize| -1.0 / w[a] - g[a + 1] * g[a] * inv_d(a);
    (diag, off)
}

/// The state-dependent factors of the mass solve ([`super::mass`] docs), allocated once.
#[derive(Debug, Clone)]
pub struct MassFactors {
    pub(super) links: [LinkRates; 2],
    /// U's columns f₁, f₂ in q indexing (zero outside their link's deflections)
    pub(super) u: [Vec<f64>; 2],
    /// number of U columns in use (2 with link 1's foreshortening, else 0)
    pub(super) nu: usize,
    /// Z = A⁻¹[M_RF U] in q indexing (zero on F), computed by the first solve at a state
    pub(super) z: [Vec<f64>; MAX_SMALL],
    pub(super) z_current: bool,
    /// the factored small system of the Schur solve at that state (valid with `z_current`)
    pub(super) small: SmallLu,
    /// A⁻¹b_R scratch
    pub(super) zb: Vec<f64>,
    /// the right-hand side in the solve's coordinates z
    pub(super) rz: Vec<f64>,
    /// the columns' deflection entries by rows (scratch of `solve_columns`)
    pub(super) rows: Vec<f64>,
}
