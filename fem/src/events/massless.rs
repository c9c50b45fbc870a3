//! The exactly massless directions N of Timoshenko links without rotary inertia (every section
//! rotation ψ, and e_ψ(L) − e_θ for a tip section that carries a child on a free joint; see
//! [`Chain::exact_massless_directions`]): M(q) N = 0 and J N = 0 at every q, so their equations
//! of motion carry no inertia, Nᵀ(∂V/∂q + C q̇ − Q) = 0 — with Kelvin–Voigt a first-order
//! relaxation of ψ towards its quasi-static balance at rates κGA/(γk²) + EI/γ (k the
//! wavenumber), far above 1/dt (2.5e4 to 5e7 1/s on `barhorst-case1-timoshenko`).
//!
//! The energy-midpoint scheme ([`crate::method::energy_midpoint`]) solves these rows at the midpoint,
//! Nᵀ(∇V(q̄) + C v̄ − Q) = 0: an implicit-midpoint step of the relaxation, whose amplification
//! (1 − z/2)/(1 + z/2) tends to −1 for z = rate·h ≫ 1. A deviation of ψ from its balance is not
//! damped: the end value ψ₁ = 2ψ̄ − ψ₀ flips around the balance every step, and so does the
//! end rate v₁ = 2v̄ − v₀, which the step does not determine at all (M N = 0). Along a smooth
//! motion nothing excites this; impacts and releases do, and the shear force of the deviation
//! can drive the next free step into the surface (measurements: docs/contact.md, "fem contact:
//! the measurements behind the design").
//!
//! In runs with a unilateral contact the stepper therefore finishes every step with two
//! operations that change no mass point and no material velocity:
//!
//! * **Projection onto the static balance** of the coordinate directions (the ψ DOFs; not the
//!   pairs e_ψ(L) − e_θ, whose relaxation runs through the joint damper at rates
//!   K/D ~ 1e3..1e4 1/s that the step resolves): ψ₁ ← argmin_ψ V(q₁), one solve with the
//!   constant, positive definite K_ψψ (Nᵀ∇V is linear in q: strain energy quadratic in
//!   (v, ψ), gravity and every mass point independent of ψ). It removes the flipping deviation
//!   in one step (L-stable) and changes only the strain energy, by ΔV = V(ψ₁*) − V(ψ₁) ≤ 0:
//!   booked as the ledger dissipation `numerical_massless` (≥ 0 by construction). What it drops
//!   at the step end is the physical lag of ψ behind its balance, τ·ψ̇ with τ = 1/rate ≤ γ/EI
//!   = 4e-5 s (bending-dominated mesh-scale sections; κGA-dominated ones 1e-7 s), which the
//!   midpoint step restores inside the next step (ψ̄ carries it). That lag is the Kelvin–Voigt
//!   deformation of the section, so the projection moves dissipation from `kelvin_voigt` to
//!   `numerical_massless`, once per step: at steps above the lag time the moved share grows as
//!   the step falls, while the sum of the two with the impact losses and the contact episodes
//!   stay put (docs/contact.md, "Energy losses on `barhorst-case1-timoshenko`"). The split is
//!   not a converged quantity. Ending the step on the damped balance Nᵀ(∇V + C q̇) = 0 instead
//!   (a backward-Euler half step from the midpoint) is not a discrete gradient and feeds energy
//!   into the state; clamping that target so that the strain energy never rises makes the
//!   Newton iteration fail after contact episodes (both measured: docs/contact.md).
//! * **Consistent rates**: the end rates along every exact direction are set from the balances
//!   at the end state, Nᵀ(∇V(q₁) + C q̇₁ − Q) = 0, affine in q̇ (one solve with NᵀCN,
//!   [`Massless::make_consistent`]); the kinetic energy does not change (M N = 0). The
//!   predictor and the Newton matrix then see no alternating garbage, and the
//!   joint rate of a child joint (θ̇ along e_ψ(L) − e_θ) is the physical one.
//!
//! Solving the massless rows at the step end instead, Nᵀ(∇V(q₁) + C v̄) = 0, is likewise not a
//! discrete gradient and feeds energy into a kicked state (docs/contact.md).

use crate::band::DenseLu;
use crate::chain::{Chain, Parts};
use crate::error::FemError;

/// The exactly massless directions of a chain and their constant operators.
#[derive(Debug, Clone)]
pub struct Massless {
    /// Directions N (orthogonal, disjoint supports), by DOF: (index, coefficient).
    pub dirs: Vec<Vec<(usize, f64)>>,
    /// The single-coordinate directions (ψ DOFs) projected onto their balance, by DOF.
    proj: Vec<usize>,
    /// LU of K_ψψ over `proj` (constant), formed at the first use.
    stiffness: Option<DenseLu>,
    /// LU of NᵀCN (C the constant damping), None when singular (no Kelvin–Voigt: the balances
    /// are then algebraic and the rates are not reset).
    damping: Option<DenseLu>,
    /// Whether steps end with the projection and the consistent rates (unilateral contact
    /// runs; module docs).
    pub project: bool,
    formed: bool,
    z: Vec<f64>,
    zp: Vec<f64>,
    tmp: Vec<f64>,
    tmp2: Vec<f64>,
    unit: Vec<f64>,
    zero: Vec<f64>,
}

impl Massless {
    /// The chain's exactly massless directions (None without any; nothing is allocated then).
    pub fn new(chain: &Chain) -> Option<Self> {
        let dirs = chain.exact_massless_directions();
        if dirs.is_empty() {
            return None;
        }
        let n = chain.ndof;
        let nz = dirs.len();
        let proj: Vec<usize> = dirs
            .iter()
            .filter(|d| d.len() == 1)
            .map(|d| d[0].0)
            .collect();
        let np = proj.len();
        Some(Massless {
            dirs,
            proj,
            stiffness: None,
            damping: None,
            project: false,
            formed: false,
            z: vec![0.0; nz],
            zp: vec![0.0; np],
            tmp: vec![0.0; n],
            tmp2: vec![0.0; n],
            unit: vec![0.0; n],
            zero: vec![0.0; n],
        })
    }

    /// Forms K_ψψ (differences of ∇V, exact up to round-off: linear in ψ) and NᵀCN (differences
    /// of the damping forces, exact: affine in q̇) at (t, q). Once per run; allocates. Returns
    /// the residual passes used.
    pub fn form(&mut self, chain: &mut Chain, t: f64, q: &[f64]) -> usize {
        if self.formed {
            return 0;
        }
        self.formed = true;
        let nz = self.dirs.len();
        let np = self.proj.len();
        let mut passes = 0;
        // K_ψψ column by column: ∇V(q + δe_j) − ∇V(q − δe_j) over 2δ, rows ψ.
        let delta = 1e-3;
        let mut qp = q.to_vec();
        let mut kpp = DenseLu::new(np);
        let mut col = vec![0.0; np.max(nz)];
        for (l, &j) in self.proj.iter().enumerate() {
            qp[j] = q[j] + delta;
            chain.residual_parts(
                t,
                &qp,
                &self.zero,
                &self.zero,
                Parts::CONSERVATIVE,
                &mut self.tmp,
            );
            qp[j] = q[j] - delta;
            chain.residual_parts(
                t,
                &qp,
                &self.zero,
                &self.zero,
                Parts::CONSERVATIVE,
                &mut self.tmp2,
            );
            qp[j] = q[j];
            for (k, &i) in self.proj.iter().enumerate() {
                col[k] = (self.tmp[i] - self.tmp2[i]) / (2.0 * delta);
            }
            kpp.set_column(l, &col[..np]);
        }
        passes += 2 * np;
        self.stiffness = kpp.factorize().ok().map(|_| kpp);
        // NᵀCN column by column: C N e_k = R_nc(q, N e_k) − R_nc(q, 0).
        chain.residual_parts(
            t,
            q,
            &self.zero,
            &self.zero,
            Parts::NONCONSERVATIVE,
            &mut self.tmp,
        );
        let mut lu = DenseLu::new(nz);
        for k in 0..nz {
            for &(i, c) in &self.dirs[k] {
                self.unit[i] = c;
            }
            chain.residual_parts(
                t,
                q,
                &self.unit,
                &self.zero,
                Parts::NONCONSERVATIVE,
                &mut self.tmp2,
            );
            for &(i, _) in &self.dirs[k] {
                self.unit[i] = 0.0;
            }
            for (kk, d) in self.dirs.iter().enumerate() {
                col[kk] = d
                    .iter()
                    .map(|&(i, c)| c * (self.tmp2[i] - self.tmp[i]))
                    .sum();
            }
            lu.set_column(k, &col[..nz]);
        }
        passes += nz + 1;
        self.damping = lu.factorize().ok().map(|_| lu);
        passes
    }

    /// Whether the balances are damped (NᵀCN regular): the rates along N are then determined.
    pub fn damped(&mut self, chain: &mut Chain, t: f64, q: &[f64]) -> bool {
        self.form(chain, t, q);
        self.damping.is_some()
    }

    /// Projects the section rotations ψ of `q` onto their static balance ∂V/∂ψ = 0 (module
    /// docs) and returns the strain energy removed, V(q) − V(q*) ≥ 0, and the residual passes
    /// used. No change when K_ψψ is singular.
    pub fn project_balance(&mut self, chain: &mut Chain, t: f64, q: &mut [f64]) -> (f64, usize) {
        self.form(chain, t, q);
        let Some(kpp) = &self.stiffness else {
            return (0.0, 0);
        };
        let strain = |chain: &Chain, q: &[f64], zero: &[f64]| -> f64 {
            let [_, s, sp, g] = chain.energies(t, q, zero);
            s + sp + g
        };
        let v0 = strain(chain, q, &self.zero);
        chain.residual_parts(
            t,
            q,
            &self.zero,
            &self.zero,
            Parts::CONSERVATIVE,
            &mut self.tmp,
        );
        for (k, &i) in self.proj.iter().enumerate() {
            self.zp[k] = self.tmp[i];
        }
        kpp.solve_in_place(&mut self.zp);
        for (k, &i) in self.proj.iter().enumerate() {
            q[i] -= self.zp[k];
        }
        let v1 = strain(chain, q, &self.zero);
        (v0 - v1, 3)
    }

    /// Makes `qd` consistent with the massless balances Nᵀ R(q, q̇, 0) = 0 by changing it along
    /// N only (no kinetic energy, no material velocity changes: M N = 0, J N = 0). Nᵀ R has no
    /// inertial part and is affine in q̇ through the constant damping C, so one solve with
    /// NᵀCN is exact. Returns the residual passes used; an error when NᵀCN is singular.
    pub fn make_consistent(
        &mut self,
        chain: &mut Chain,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
    ) -> Result<usize, FemError> {
        let passes = self.form(chain, t, q) + 1;
        let Some(lu) = &self.damping else {
            return Err(FemError::unsupported(
                "fem: massless section rotations whose damping NᵀCN is singular (a massless \
                 direction without Kelvin–Voigt or joint damping): their rates are not \
                 determined by the balances (algebraic condensation not implemented)",
            ));
        };
        chain.residual(t, q, qd, &self.zero, &mut self.tmp);
        for (k, d) in self.dirs.iter().enumerate() {
            self.z[k] = d.iter().map(|&(i, c)| c * self.tmp[i]).sum();
        }
        lu.solve_in_place(&mut self.z);
        for (k, d) in self.dirs.iter().enumerate() {
            for &(i, c) in d {
                qd[i] -= c * self.z[k];
            }
        }
        Ok(passes)
    }
}
