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
//! In runs with a unilateral contact ([`Balance::Damped`]) the stepper therefore finishes every
//! step with two operations that change no mass point and no material velocity:
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
//!
//! ## Undamped sections in runs without contact ([`Balance::Algebraic`])
//! Without Kelvin–Voigt the ψ balances are algebraic, ∂V/∂ψ = 0, and the undetermined end
//! rates have nothing to decay through. Beside them sits an almost massless direction that no
//! damper reaches: the turn of a child link's frame through its parent's massless tip section
//! with the child's field counter-rotated ([`Chain::child_frame_directions`]; θ of the child
//! stays, so its joint damper does not act). Its mass is ∫ρA s² (s the foreshortening), its
//! stiffness that of the parent's tip and the child's root element, so its frequency is far
//! above 1/h and the midpoint rule maps it to an undamped step-to-step alternation. The
//! energy-midpoint step does not leave that alternation alone: its discrete kinetic gradient
//! ∂T/∂q(q̄, ½Δv) carries it into the massive equations, which modulate its mass in turn, and
//! at fine steps the loop is unstable (measured on `barhorst-case1-timoshenko` without contact
//! and Kelvin–Voigt, joint dampers 5, 8 elements, dt 2.5e-5: the alternation of link 2's tip
//! rate grew from 1e-3 to 3e3 between t = 0.1 and 0.24 s, e-folding ≈ 7 ms, until the Newton
//! iteration failed at t = 0.2497 s; implicit-midpoint, whose forces see v̄ only, kept it at
//! 1e-3). These runs (energy-midpoint) therefore end every step with:
//!
//! * the undamped ψ DOFs projected onto ∂V/∂ψ = 0 as above (the deviation flips exactly
//!   around a linear balance, so the strain energy removed is at round-off: 6e-11 over that
//!   run);
//! * the rates of the damped directions (e_ψ(L) − e_θ through the joint damper) from their
//!   balances as above;
//! * the rates along the algebraic directions N_a (the undamped ψ DOFs and undamped
//!   child-frame directions) from the time derivative of their balances,
//!   d/dt N_aᵀ∇V = N_aᵀK q̇ = 0: q̇ ← q̇ − N_a (N_aᵀKN_a)⁻¹N_aᵀK q̇, the singular-perturbation
//!   limit of a direction whose mass is negligible (exact for the ψ DOFs, whose balance is
//!   linear; along a child-frame direction K holds the shear and bending stiffness, formed at
//!   the start, against which its gravity and centrifugal terms are small). The child-frame
//!   directions carry mass, so this changes the kinetic energy, by −δq̇ᵀM(q̇ + ½δq̇), of either
//!   sign and at the Newton-tolerance level (2.4e-9 J added over 0.3 s at dt 1e-4): booked
//!   with the strain energy removed as `numerical_massless`, which is therefore not signed in
//!   these runs ([`Massless::end_rates`]).

use crate::band::DenseLu;
use crate::chain::{Chain, NONE, Parts};
use crate::error::FemError;

/// Perturbation of the coordinates by which the stiffness operators are differenced (the ψ
/// balances are linear in q, the damping forces affine in q̇: the differences are exact up to
/// round-off).
const DELTA: f64 = 1e-3;

/// Which balances the steps of a run end on (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Balance {
    /// Every exact direction damped (Kelvin–Voigt; unilateral contact runs): the ψ DOFs
    /// projected onto their static balance, every rate from the damped balances.
    Damped,
    /// Undamped directions (no Kelvin–Voigt; runs without contact): the undamped ψ DOFs
    /// projected onto their algebraic balance ∂V/∂ψ = 0, the rates along them and along the
    /// undamped child-frame directions from the time derivative of their balances, the rates
    /// of the damped directions from their balances.
    Algebraic,
}

/// The exactly massless directions of a chain and their constant operators.
#[derive(Debug, Clone)]
pub struct Massless {
    /// Directions N (orthogonal, disjoint supports), by DOF: (index, coefficient).
    pub dirs: Vec<Vec<(usize, f64)>>,
    /// The balances the steps end on.
    pub balance: Balance,
    /// The single-coordinate directions (ψ DOFs) projected onto their balance, by DOF: every
    /// one ([`Balance::Damped`]), the undamped ones ([`Balance::Algebraic`]).
    proj: Vec<usize>,
    /// The directions (indices into `dirs`) whose rates follow their damped balances: every
    /// one ([`Balance::Damped`]), the damped ones ([`Balance::Algebraic`]).
    rate_dirs: Vec<usize>,
    /// The undamped directions N_a whose rates follow the time derivative of their balances
    /// ([`Balance::Algebraic`]: the `proj` DOFs and the undamped child-frame directions of
    /// [`Chain::child_frame_directions`]; empty otherwise), by DOF.
    alg: Vec<Vec<(usize, f64)>>,
    /// LU of K_ψψ over `proj` (constant), formed at the first use.
    stiffness: Option<DenseLu>,
    /// LU of N_aᵀKN_a over `alg` (K the stiffness at the first use).
    alg_stiffness: Option<DenseLu>,
    /// LU of NᵀCN over `rate_dirs` (C the constant damping), None when singular (a direction
    /// of `rate_dirs` without Kelvin–Voigt or joint damping).
    damping: Option<DenseLu>,
    /// Whether steps end with the projection and the consistent rates (module docs).
    pub project: bool,
    formed: bool,
    z: Vec<f64>,
    zp: Vec<f64>,
    za: Vec<f64>,
    tmp: Vec<f64>,
    tmp2: Vec<f64>,
    unit: Vec<f64>,
    zero: Vec<f64>,
    qp: Vec<f64>,
    /// The rates before [`Massless::end_rates`] changed them.
    before: Vec<f64>,
}

impl Massless {
    /// The chain's exactly massless directions for a run whose steps end on the damped
    /// balances ([`Balance::Damped`]; None without any direction, nothing is allocated then).
    pub fn new(chain: &Chain) -> Option<Self> {
        let dirs = chain.exact_massless_directions();
        if dirs.is_empty() {
            return None;
        }
        let proj: Vec<usize> = dirs
            .iter()
            .filter(|d| d.len() == 1)
            .map(|d| d[0].0)
            .collect();
        let rate_dirs = (0..dirs.len()).collect();
        Some(Self::with(
            chain,
            dirs,
            Balance::Damped,
            proj,
            rate_dirs,
            Vec::new(),
        ))
    }

    /// The chain's exactly massless directions for a run whose steps end on the algebraic
    /// balances of its undamped ψ DOFs ([`Balance::Algebraic`]): None when no exact direction
    /// is undamped, or when an undamped one is not a single ψ DOF (an e_ψ(L) − e_θ pair whose
    /// link has no Kelvin–Voigt and whose child joint no damper: its balance carries the joint
    /// spring and torque law, which this projection does not book).
    pub fn algebraic(chain: &Chain) -> Option<Self> {
        let dirs = chain.exact_massless_directions();
        let damped_dof = damped_dofs(chain);
        let undamped = |d: &Vec<(usize, f64)>| d.iter().all(|&(i, _)| !damped_dof[i]);
        if !dirs.iter().any(undamped) || dirs.iter().any(|d| undamped(d) && d.len() > 1) {
            return None;
        }
        let proj: Vec<usize> = dirs
            .iter()
            .filter(|d| undamped(d))
            .map(|d| d[0].0)
            .collect();
        let rate_dirs = (0..dirs.len()).filter(|&k| !undamped(&dirs[k])).collect();
        let alg = proj
            .iter()
            .map(|&i| vec![(i, 1.0)])
            .chain(
                chain
                    .child_frame_directions()
                    .into_iter()
                    .filter(|d| undamped(d)),
            )
            .collect();
        Some(Self::with(
            chain,
            dirs,
            Balance::Algebraic,
            proj,
            rate_dirs,
            alg,
        ))
    }

    fn with(
        chain: &Chain,
        dirs: Vec<Vec<(usize, f64)>>,
        balance: Balance,
        proj: Vec<usize>,
        rate_dirs: Vec<usize>,
        alg: Vec<Vec<(usize, f64)>>,
    ) -> Self {
        let n = chain.ndof;
        Massless {
            dirs,
            balance,
            z: vec![0.0; rate_dirs.len()],
            zp: vec![0.0; proj.len()],
            za: vec![0.0; alg.len()],
            proj,
            rate_dirs,
            alg,
            stiffness: None,
            alg_stiffness: None,
            damping: None,
            project: false,
            formed: false,
            tmp: vec![0.0; n],
            tmp2: vec![0.0; n],
            unit: vec![0.0; n],
            zero: vec![0.0; n],
            qp: vec![0.0; n],
            before: vec![0.0; n],
        }
    }

    /// Forms K_ψψ (differences of ∇V, exact up to round-off: linear in ψ), N_aᵀKN_a over the
    /// algebraic directions (the same differences along them) and NᵀCN over the rate
    /// directions (differences of the damping forces, exact: affine in q̇) at (t, q). Once per
    /// run; allocates. Returns the residual passes used.
    pub fn form(&mut self, chain: &mut Chain, t: f64, q: &[f64]) -> usize {
        if self.formed {
            return 0;
        }
        self.formed = true;
        let nz = self.rate_dirs.len();
        let np = self.proj.len();
        let mut passes = 0;
        // K_ψψ column by column: ∇V(q + δe_j) − ∇V(q − δe_j) over 2δ, rows ψ.
        let mut qp = q.to_vec();
        let mut kpp = DenseLu::new(np);
        let mut col = vec![0.0; np.max(nz)];
        let rows: Vec<Vec<(usize, f64)>> = self.proj.iter().map(|&i| vec![(i, 1.0)]).collect();
        for (l, &j) in self.proj.iter().enumerate() {
            let place = |sign: f64, qp: &mut [f64]| qp[j] = q[j] + sign * DELTA;
            let grads = (&mut self.tmp, &mut self.tmp2);
            stiffness_along(
                chain, t, &rows, &self.zero, &mut qp, grads, DELTA, place, &mut col,
            );
            qp[j] = q[j];
            kpp.set_column(l, &col[..np]);
        }
        passes += 2 * np;
        self.stiffness = kpp.factorize().ok().map(|_| kpp);
        passes += self.form_algebraic(chain, t, q, &mut qp);
        if nz == 0 {
            return passes;
        }
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
        for (k, &dk) in self.rate_dirs.iter().enumerate() {
            for &(i, c) in &self.dirs[dk] {
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
            for &(i, _) in &self.dirs[dk] {
                self.unit[i] = 0.0;
            }
            for (kk, &dkk) in self.rate_dirs.iter().enumerate() {
                col[kk] = self.dirs[dkk]
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

    /// N_aᵀKN_a column by column, ∇V(q ± δN_a e_l) differenced and projected on N_a (`qp`
    /// holds q and is left so). Returns the residual passes used.
    fn form_algebraic(&mut self, chain: &mut Chain, t: f64, q: &[f64], qp: &mut [f64]) -> usize {
        let na = self.alg.len();
        if na == 0 {
            return 0;
        }
        let mut lu = DenseLu::new(na);
        let mut col = vec![0.0; na];
        for l in 0..na {
            let dir = &self.alg[l];
            let place = |sign: f64, qp: &mut [f64]| {
                for &(i, c) in dir {
                    qp[i] = q[i] + sign * DELTA * c;
                }
            };
            let grads = (&mut self.tmp, &mut self.tmp2);
            stiffness_along(
                chain, t, &self.alg, &self.zero, qp, grads, DELTA, place, &mut col,
            );
            for &(i, _) in dir {
                qp[i] = q[i];
            }
            lu.set_column(l, &col);
        }
        self.alg_stiffness = lu.factorize().ok().map(|_| lu);
        2 * na
    }

    /// Whether the steps can end on the balances: the rate directions' damping NᵀCN is regular
    /// (their rates are then determined), and with [`Balance::Algebraic`] K_ψψ and N_aᵀKN_a
    /// too.
    pub fn damped(&mut self, chain: &mut Chain, t: f64, q: &[f64]) -> bool {
        self.form(chain, t, q);
        let rates = self.rate_dirs.is_empty() || self.damping.is_some();
        rates
            && (self.balance == Balance::Damped
                || (self.stiffness.is_some() && self.alg_stiffness.is_some()))
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

    /// Makes `qd` consistent with the massless balances by changing it along the massless
    /// directions only. The damped ones, Nᵀ R(q, q̇, 0) = 0, have no inertial part and are
    /// affine in q̇ through the constant damping C, so one solve with NᵀCN is exact (no kinetic
    /// energy, no material velocity changes: M N = 0, J N = 0). With [`Balance::Algebraic`]
    /// the rates along N_a then follow from the time derivative of their balances,
    /// N_aᵀK(q̇ − N_a z) = 0 (module docs). Returns the residual passes used; an
    /// error when NᵀCN is singular.
    pub fn make_consistent(
        &mut self,
        chain: &mut Chain,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
    ) -> Result<usize, FemError> {
        let mut passes = self.form(chain, t, q);
        if !self.rate_dirs.is_empty() {
            passes += 1;
            let Some(lu) = &self.damping else {
                return Err(FemError::unsupported(
                    "fem: massless section rotations whose damping NᵀCN is singular (a massless \
                     direction without Kelvin–Voigt or joint damping): their rates are not \
                     determined by the balances (algebraic condensation not implemented)",
                ));
            };
            chain.residual(t, q, qd, &self.zero, &mut self.tmp);
            for (k, &dk) in self.rate_dirs.iter().enumerate() {
                self.z[k] = self.dirs[dk].iter().map(|&(i, c)| c * self.tmp[i]).sum();
            }
            lu.solve_in_place(&mut self.z);
            for (k, &dk) in self.rate_dirs.iter().enumerate() {
                for &(i, c) in &self.dirs[dk] {
                    qd[i] -= c * self.z[k];
                }
            }
        }
        passes += self.algebraic_rates(chain, t, q, qd);
        Ok(passes)
    }

    /// The end rates of a step ([`Self::make_consistent`]) and the kinetic energy that change
    /// removes, T(q̇) − T(q̇*) = −δq̇ᵀM(q)(q̇ + ½δq̇), δq̇ = q̇* − q̇, from one mass product (no
    /// difference of two energies: it is far below their round-off). Zero, and no pass, with
    /// [`Balance::Damped`], whose rates change along exactly massless directions only; with
    /// [`Balance::Algebraic`] the child-frame directions carry the mass ∫ρA s². Returns the
    /// kinetic energy removed and the residual passes used.
    pub fn end_rates(
        &mut self,
        chain: &mut Chain,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
    ) -> Result<(f64, usize), FemError> {
        if self.balance == Balance::Damped {
            return Ok((0.0, self.make_consistent(chain, t, q, qd)?));
        }
        self.before.copy_from_slice(qd);
        let passes = self.make_consistent(chain, t, q, qd)?;
        // qp ← q̇ + ½δq̇ = ½(q̇ + q̇*), unit ← δq̇ (restored to zero below).
        for i in 0..qd.len() {
            self.unit[i] = qd[i] - self.before[i];
            self.qp[i] = 0.5 * (self.before[i] + qd[i]);
        }
        chain.residual_parts(t, q, &self.zero, &self.qp, Parts::INERTIA, &mut self.tmp);
        let mut removed = 0.0;
        for i in 0..qd.len() {
            removed -= self.unit[i] * self.tmp[i];
            self.unit[i] = 0.0;
        }
        Ok((removed, passes + 1))
    }

    /// The rates along the algebraic directions N_a from the time derivative of their
    /// balances, N_aᵀK(q)q̇ = 0 (module docs): q̇ ← q̇ − N_a z, (N_aᵀKN_a) z = N_aᵀK q̇, K q̇ by
    /// a central difference of ∇V along q̇ at q (perturbing the coordinates by at most
    /// [`DELTA`], as N_aᵀKN_a was formed). Returns the residual passes used (none without
    /// algebraic directions or at rest).
    fn algebraic_rates(&mut self, chain: &mut Chain, t: f64, q: &[f64], qd: &mut [f64]) -> usize {
        let Some(ka) = &self.alg_stiffness else {
            return 0;
        };
        let big = qd.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if big == 0.0 {
            return 0;
        }
        let s = DELTA / big;
        let place = |sign: f64, qp: &mut [f64]| {
            for (i, x) in qp.iter_mut().enumerate() {
                *x = q[i] + sign * s * qd[i];
            }
        };
        let grads = (&mut self.tmp, &mut self.tmp2);
        let (alg, zero, qp) = (&self.alg, &self.zero, &mut self.qp);
        stiffness_along(chain, t, alg, zero, qp, grads, s, place, &mut self.za);
        ka.solve_in_place(&mut self.za);
        for (k, d) in self.alg.iter().enumerate() {
            for &(i, c) in d {
                qd[i] -= c * self.za[k];
            }
        }
        2
    }
}

/// The stiffness along a direction d by a central difference of ∇V, projected on each
/// direction N_k of `rows`: out_k = N_kᵀ[∇V(q + δd) − ∇V(q − δd)]/(2δ), `place(±1, qp)`
/// putting q ± δd in `qp`. Two residual passes.
#[allow(clippy::too_many_arguments)]
fn stiffness_along(
    chain: &mut Chain,
    t: f64,
    rows: &[Vec<(usize, f64)>],
    zero: &[f64],
    qp: &mut [f64],
    (plus, minus): (&mut Vec<f64>, &mut Vec<f64>),
    delta: f64,
    place: impl Fn(f64, &mut [f64]),
    out: &mut [f64],
) {
    for (sign, grad) in [(1.0, &mut *plus), (-1.0, &mut *minus)] {
        place(sign, qp);
        chain.residual_parts(t, qp, zero, zero, Parts::CONSERVATIVE, grad);
    }
    for (o, d) in out.iter_mut().zip(rows) {
        *o = d
            .iter()
            .map(|&(i, c)| c * (plus[i] - minus[i]))
            .sum::<f64>()
            / (2.0 * delta);
    }
}

/// Whether each DOF carries damping: the DOFs of a link with Kelvin–Voigt and the angle of a
/// joint with a damper. A direction is damped when one of its DOFs is (C is a sum of positive
/// semi-definite terms, each positive along such a DOF).
fn damped_dofs(chain: &Chain) -> Vec<bool> {
    let mut damped = vec![false; chain.ndof];
    for l in &chain.links {
        if l.kelvin_voigt > 0.0 {
            for &i in l.v_dof.iter().chain(&l.r_dof).chain(&l.int_dof) {
                if i != NONE {
                    damped[i] = true;
                }
            }
        }
        if l.joint.dof != NONE && l.joint.damping > 0.0 {
            damped[l.joint.dof] = true;
        }
    }
    damped
}
