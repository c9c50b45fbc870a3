//! Timoshenko links of the two-link chain (`shear = true`, e.g. `barhorst-case1-timoshenko`).
//!
//! **Fields.** Per link, the transverse deflection v and the cross-section rotation ψ at the
//! stations 0…r, both in the link's tip-chord frame (the chain's frames, [`super`]): v₀ = v_r = 0
//! (the chord), ψ₀…ψ_r all unknown. ψ is kept at the *stations* (not staggered at the
//! midpoints) because the two conditions that involve it sit at the ends: the clamp (the root
//! section is the joint's frame) and the joint convention (link 2 is clamped to the section at
//! link 1's tip), and the shear strain is evaluated at the cell midpoints with the average
//! ψ̄ = (ψᵢ + ψᵢ₊₁)/2 — the one-point rule that keeps the sawtooth of ψ out of the shear energy
//! and avoids shear locking (the κGA → ∞ limit is the Euler link, tested).
//!
//! **Frame.** Curvature ψ′ and shear strain v′ − ψ are unchanged by a small rotation of the
//! frame (v → v − εx, ψ → ψ − ε), so the convention's energies in the clamp frame (v(0) =
//! ψ(0) = 0) equal those in the chord frame; the clamp section's angle is the chord angle + ψ₀,
//! i.e. ψ₀ replaces the Euler chain's clamp ghost. Foreshortening uses the centre-line slope
//! v′ (the chord-frame Δv/h, as the Euler chain: equal to the clamp-frame value to the second
//! order the kinetic energy keeps).
//!
//! **Discrete energy** (per link, cells i = 0…r−1, κ = EI, S = κGA):
//!
//! U = Σᵢ ½EI h ((ψᵢ₊₁ − ψᵢ)/h)² + Σᵢ ½κGA h ((vᵢ₊₁ − vᵢ)/h − (ψᵢ + ψᵢ₊₁)/2)²
//!   + ½K₁(Θ₁ − Θ₁⁰)² + ½K₂(Θ₂ − Θ₂⁰)²,
//!
//! Θ₁ = θ + ψ¹₀ (the joint-1 angle: clamp section of link 1), Θ₂ = β + ψ²₀ − θ − ψ¹_r (the
//! elbow: link 2's clamp section against the section at link 1's tip, scenes.md's
//! φ₂ = φ₁ + ψ₁(L₁) + θ₂). Kelvin–Voigt and the joint dampers form the Rayleigh function
//! D = Σᵢ ½γ h ((ψ̇ᵢ₊₁ − ψ̇ᵢ)/h)² + ½D₁Θ̇₁² + ½D₂Θ̇₂² (dissipation ∫γψ̇′², no shear damping).
//! Forces are −∂U/∂q of this U (exact gradients, tested against finite differences).
//!
//! **Massless ψ.** Without rotary inertia ψ carries no mass. In the chord frames it does not
//! enter the kinetic energy at all: every mass point's position depends on θ, β and the
//! chord deflections only — in particular ψ¹_r (the section at link 1's tip, to which link 2
//! is clamped) moves no mass either: link 2's orientation is its chord angle β, and ψ¹_r enters
//! only through Θ₂ (spring/damper). Writing y for the massive coordinates (θ, β, interior v, w)
//! and z for all ψ, the equations are
//!
//! M(y)ÿ = f(y, ẏ) − ∂U/∂y − ∂D/∂ẏ,   0 = −∂U/∂z − ∂D/∂ż,
//!
//! and ∂U/∂z = K_zz z + K_zy y + b is linear (U is quadratic with *constant* matrices: the
//! strain and the joint springs are quadratic in the chord coordinates and the angles).
//! K_zz is symmetric positive definite and **tridiagonal** in the ordering ψ¹₀…ψ¹_r, ψ²₀…ψ²_r
//! (bending and ψ̄ couple neighbours; K₂ couples ψ¹_r with ψ²₀, adjacent; K₁ sits on ψ¹₀).
//! Without damping on z (γ = 0 and no joint dampers) z is algebraic: z = z₀(y) =
//! −K_zz⁻¹(K_zy y + b), one tridiagonal solve, and the condensed potential U_c(y) =
//! U(y, z₀(y)) has ∂U_c/∂y = ∂U/∂y at z₀ (the ∂U/∂z term vanishes): exact.
//! With damping, C ż = −∂U/∂z − (cross terms in ẏ) is a first-order relaxation whose rates are
//! the eigenvalues of C⁻¹K_zz (C the ψ block of D): the bending part of K_zz is (EI/γ)× the
//! Kelvin–Voigt part of C, so shapes with a curvature rate relax at ≥ EI/γ = 2.5·10⁴ s⁻¹
//! (barhorst-case1-timoshenko); shapes without one are damped by the joint dampers alone, and
//! are algebraic where C has no term. The slowest of these is not the uniform ψ but the
//! boundary layer at a joint, ψ decaying over √(EI/κGA) from the section the damper turns: a
//! damper D in series with that section's compliance 1/√(EI·κGA) relaxes at √(EI·κGA)/D ≈
//! 3.5·10³ s⁻¹ (D = 20), not far above the mechanics' frequencies, so the first-order manifold
//! below leaves an error linear in D at the joints: its forces take the dampers at the
//! quasi-static rates ż₀ (docs/limits.md, "Timoshenko two-link arm"). The other rates are ≳ 1/τ
//! (τ ≈ 3e-5 s):
//! explicit integration of z would need τ ≤ 2/rate_max (unbounded where C is singular), and an
//! implicit one-step of z breaks the exact ledger; z is instead
//! carried on its **slow manifold** (as the modal backend does): z = z₀(y) + z₁ with
//! z₁ = −K_zz⁻¹ ∂D/∂ż(ẏ, ż₀), ż₀ = Jẏ, J = −K_zz⁻¹K_zy. Substituting into the y equation,
//! −K_yz z₁ = −Jᵀ∂D/∂ż, so to first order in (frequency/relaxation rate)
//!
//! M(y)ÿ = f − ∂U_c/∂y − ∂D_c/∂ẏ,   D_c(ẏ) = D(ẏ, Jẏ),   ∂D_c/∂ẏ = ∂D/∂ẏ + Jᵀ∂D/∂ż,
//!
//! a Lagrangian system with the condensed Rayleigh function: exact without damping, error
//! O(ω/rate) relative in the damping forces only (≤ 1 % for ω ≤ 250 rad/s against
//! 2.5·10⁴ s⁻¹; the next term is −K_zz⁻¹C ż₁). It is *not* small at the top of the grid's
//! spectrum (ω_max ≈ 1.5·10⁴ rad/s at 21 stations, ∝ 1/h): there the true ψ lags (damping
//! factor ≈ 1/(1 + (ω/rate)²), 0.73 at ω_max) and the condensed Kelvin–Voigt over-damps those
//! modes. They carry energy only after impacts (the point impact excites the shortest waves):
//! measured on case 1 at 81 stations, the Kelvin–Voigt loss to 0.354 s is 16.7 J against
//! modal's 13.9 J (8 modes), with the impact loss 1.70 J against 3.53 J — the sum with the
//! joint dampers agrees to 0.35 J of 167 J; the impact/Kelvin–Voigt partition is resolution
//! dependent in both backends (fdm's impulse ∝ h: the struck lumped tip mass is ρAh/2). The ledger is exact in its own terms: strain U(y, z₀), joint springs at
//! Θ(y, z₀), dissipation 2D_c = Σγh(Δż₀/h)² + D₁Θ̇₁² + D₂Θ̇₂² at ż₀ = Jẏ. Jᵀg = −K_yz K_zz⁻¹g.
//! The reported joint angles are those of the sections at z₀ + z₁
//! ([`TimoFields::joint_angles_with_lag`]): z₁ is first order, the quasi-static turn of a
//! section under its damper's moment (D·Θ̇·ℓ/EI through the boundary layer, ℓ = √(EI/κGA)),
//! while U(y, z₀ + z₁) differs from U_c(y) only at second order (∂U/∂z = 0 at z₀).
//! Per force evaluation: three tridiagonal solves (z₀, ż₀, K_zz⁻¹∂D/∂ż) and four O(n) passes
//! of the energy gradient: linear cost, no allocation.
//!
//! **Step bound.** The v sawtooth vᵢ = (−1)ⁱa has an alternating Δv/h, while every ψ̄ of a
//! smooth or sawtooth ψ is smooth or zero, so ψ cannot relieve its shear; for the Fourier mode e^{ikx} the condensed operator is
//! ω²(k) = A⁴ EI κGA / (ρA(κGA c² + EI A²)), A = 2 sin(kh/2)/h, c = cos(kh/2), increasing
//! in sin²(kh/2) for every EI, κGA (its derivative ∝ u(2 + u(α − 1)) > 0, α = 4EI/(h²κGA)),
//! so ω²_max = 4κGA/(ρA h²) at kh = π: σ² = h² ρA/κGA (the condensed operator's 2/ω_max,
//! independent of EI). Enforced per link like the Euler chain's 5.44, together with the
//! coupled chain's power-iteration ω_max (0.9 · 2/ω_max) and its fastest damping rate.
//! (The Kelvin–Voigt factor of the Euler bound is not applied: the shear sawtooth has ψ ≈ 0
//! and no Kelvin–Voigt damping; the damping rates enter through κ_max.)

use data::scene::Link;

use crate::error::FdmError;
use crate::tridiagonal::TridiagonalLdl;

use super::kinetic::{BE, TH};

/// Coefficients of one quadratic form of the ψ/v/joint structure: the strain energy
/// (EI, κGA, K, set-points) or the Rayleigh function (γ, 0, D, no set-points).
#[derive(Debug, Clone, Copy)]
struct Coef {
    bend: [f64; 2],
    shear: [f64; 2],
    joint: [f64; 2],
    set: [f64; 2],
}

impl Coef {
    fn without_set(self) -> Self {
        Coef {
            set: [0.0; 2],
            ..self
        }
    }
}

/// Parts of a quadratic form's value.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Parts {
    /// Σ bending + shear over both links
    pub links: f64,
    /// the joint terms
    pub joints: f64,
}

#[derive(Debug, Clone)]
struct Scratch {
    z: Vec<f64>,
    zd: Vec<f64>,
    w: Vec<f64>,
    gz: Vec<f64>,
}

/// The condensed Timoshenko fields of the chain (module docs).
#[derive(Debug, Clone)]
pub struct TimoFields {
    /// stations per link minus one
    r: [usize; 2],
    h: [f64; 2],
    /// q-index of station 1 of each link
    first: [usize; 2],
    elastic: Coef,
    damping: Coef,
    /// LDLᵀ of the tridiagonal K_zz
    ldl: TridiagonalLdl,
    /// whether D has any term (γ or joint dampers)
    damped: bool,
    scratch: std::cell::RefCell<Scratch>,
}

/// The shear stiffness κGA of a Timoshenko link (validated).
pub fn shear_stiffness(scene: &str, l: &Link) -> Result<f64, FdmError> {
    match l.shear_stiffness {
        Some(s) if s.is_finite() && s > 0.0 => Ok(s),
        Some(s) => Err(FdmError::invalid(
            "shear_stiffness",
            format!("`{scene}` link `{}`: κGA must be positive, got {s}", l.name),
        )),
        None => Err(FdmError::invalid(
            "shear_stiffness",
            format!(
                "`{scene}` link `{}`: `shear = true` needs `shear_stiffness` (κGA)",
                l.name
            ),
        )),
    }
}

impl TimoFields {
    /// `links`: (r, h, EI, κGA, γ); `joints`: (K, D, set-point) of joint 1 and the elbow.
    pub fn new(
        links: [(usize, f64, f64, f64, f64); 2],
        joints: [(f64, f64, f64); 2],
    ) -> Result<Self, FdmError> {
        let r = [links[0].0, links[1].0];
        let h = [links[0].1, links[1].1];
        let elastic = Coef {
            bend: [links[0].2, links[1].2],
            shear: [links[0].3, links[1].3],
            joint: [joints[0].0, joints[1].0],
            set: [joints[0].2, joints[1].2],
        };
        let damping = Coef {
            bend: [links[0].4, links[1].4],
            shear: [0.0; 2],
            joint: [joints[0].1, joints[1].1],
            set: [0.0; 2],
        };
        let nz = r[0] + r[1] + 2;
        // tridiagonal K_zz: diagonal a, off-diagonal b (b[i] couples i and i + 1)
        let mut a = vec![0.0; nz];
        let mut b = vec![0.0; nz - 1];
        for l in 0..2 {
            let o = if l == 0 { 0 } else { r[0] + 1 };
            let (ei, s, hh) = (elastic.bend[l], elastic.shear[l], h[l]);
            for i in 0..r[l] {
                a[o + i] += ei / hh + s * hh / 4.0;
                a[o + i + 1] += ei / hh + s * hh / 4.0;
                b[o + i] += -ei / hh + s * hh / 4.0;
            }
        }
        a[0] += elastic.joint[0];
        a[r[0]] += elastic.joint[1];
        a[r[0] + 1] += elastic.joint[1];
        b[r[0]] -= elastic.joint[1];
        let mut ldl = TridiagonalLdl::new(nz);
        ldl.factor(|i| a[i], |i| b[i])
            .map_err(|i| FdmError::Numerical {
                t: 0.0,
                message: format!("Timoshenko ψ stiffness not positive definite (pivot {i})"),
            })?;
        let damped = damping.bend.iter().chain(&damping.joint).any(|&c| c != 0.0);
        let zeros = vec![0.0; nz];
        Ok(TimoFields {
            r,
            h,
            first: [2, 2 + r[0]],
            elastic,
            damping,
            ldl,
            damped,
            scratch: std::cell::RefCell::new(Scratch {
                z: zeros.clone(),
                zd: zeros.clone(),
                w: zeros.clone(),
                gz: zeros,
            }),
        })
    }

    /// Number of ψ unknowns (both links, stations 0…r).
    pub fn nz(&self) -> usize {
        self.r[0] + self.r[1] + 2
    }

    /// z-index of station 0 of link ℓ.
    fn zo(&self, l: usize) -> usize {
        if l == 0 { 0 } else { self.r[0] + 1 }
    }

    /// x ← K_zz⁻¹ x.
    fn solve(&self, x: &mut [f64]) {
        self.ldl.solve_in_place(x);
    }

    /// Deflection of link ℓ at station i of the chord-frame q (v₀ = v_r = 0).
    #[inline]
    fn v(&self, q: &[f64], l: usize, i: usize) -> f64 {
        if i == 0 || i == self.r[l] {
            0.0
        } else {
            q[self.first[l] + i - 1]
        }
    }

    /// Joint angles (Θ₁, Θ₂) = (θ + ψ¹₀, β + ψ²₀ − θ − ψ¹_r) of (q, z) — or their rates of
    /// (q̇, ż).
    pub fn joints_of(&self, q: &[f64], z: &[f64]) -> [f64; 2] {
        [q[TH] + z[0], q[BE] + z[self.zo(1)] - q[TH] - z[self.r[0]]]
    }

    /// Value of the quadratic form `c` at (q, z); adds `sign` × its gradients into `gq` (θ, β
    /// and the interior stations only) and `gz` when given.
    fn form(
        &self,
        c: &Coef,
        q: &[f64],
        z: &[f64],
        sign: f64,
        mut gq: Option<&mut [f64]>,
        mut gz: Option<&mut [f64]>,
    ) -> Parts {
        let mut parts = Parts::default();
        for l in 0..2 {
            let (h, eb, es) = (self.h[l], c.bend[l], c.shear[l]);
            let (o, r) = (self.zo(l), self.r[l]);
            for i in 0..r {
                let (z0, z1) = (z[o + i], z[o + i + 1]);
                let kap = (z1 - z0) / h;
                let gam = (self.v(q, l, i + 1) - self.v(q, l, i)) / h - 0.5 * (z0 + z1);
                parts.links += 0.5 * h * (eb * kap * kap + es * gam * gam);
                if let Some(gz) = gz.as_deref_mut() {
                    let s = 0.5 * h * es * gam;
                    gz[o + i] += sign * (-eb * kap - s);
                    gz[o + i + 1] += sign * (eb * kap - s);
                }
                if let Some(gq) = gq.as_deref_mut() {
                    let s = sign * es * gam;
                    if i + 1 < r {
                        gq[self.first[l] + i] += s;
                    }
                    if i > 0 {
                        gq[self.first[l] + i - 1] -= s;
                    }
                }
            }
        }
        let th = self.joints_of(q, z);
        let e = [
            c.joint[0] * (th[0] - c.set[0]),
            c.joint[1] * (th[1] - c.set[1]),
        ];
        parts.joints = 0.5 * (e[0] * (th[0] - c.set[0]) + e[1] * (th[1] - c.set[1]));
        if let Some(gq) = gq {
            gq[TH] += sign * (e[0] - e[1]);
            gq[BE] += sign * e[1];
        }
        if let Some(gz) = gz {
            gz[0] += sign * e[0];
            gz[self.zo(1)] += sign * e[1];
            gz[self.r[0]] -= sign * e[1];
        }
        parts
    }

    /// z₀(q) = −K_zz⁻¹ ∂U/∂z(q, 0) (with set-points) or, `rate`, ż₀ = Jq̇ (without).
    pub fn settle(&self, q: &[f64], rate: bool, z: &mut [f64]) {
        let c = if rate {
            self.elastic.without_set()
        } else {
            self.elastic
        };
        let mut sc = self.scratch.borrow_mut();
        let zero = &mut sc.w;
        zero.iter_mut().for_each(|x| *x = 0.0);
        z.iter_mut().for_each(|x| *x = 0.0);
        self.form(&c, q, zero, -1.0, None, Some(z));
        self.solve(z);
    }

    /// Joint angles at q (`rate` false) or rates at q̇ (`rate` true) on the condensed manifold.
    pub fn joint_angles(&self, x: &[f64], rate: bool) -> [f64; 2] {
        let mut z = std::mem::take(&mut self.scratch.borrow_mut().zd);
        self.settle(x, rate, &mut z);
        let th = self.joints_of(x, &z);
        self.scratch.borrow_mut().zd = z;
        th
    }

    /// The section rotations on the first-order slow manifold, z = z₀(q) + z₁(q, q̇) with
    /// z₁ = −K_zz⁻¹ ∂D/∂ż(q̇, ż₀) (module docs): the quasi-static turn of the sections under the
    /// dampers' moments, first order in D — the joint damper's moment D·Θ̇ turns the section it
    /// acts on by about D·Θ̇/√(EI·κGA) through the boundary layer at the joint, which the
    /// condensed forces already carry and the reported angles must carry too. Writes z into `z`.
    pub fn rotations_with_lag(&self, q: &[f64], v: &[f64], z: &mut [f64]) {
        self.settle(q, false, z);
        if !self.damped {
            return;
        }
        let mut zd = std::mem::take(&mut self.scratch.borrow_mut().zd);
        self.settle(v, true, &mut zd);
        let mut sc = self.scratch.borrow_mut();
        // gz = −∂D/∂ż at (q̇, ż₀); z₁ = −K⁻¹∂D/∂ż = K⁻¹ gz
        let gz = &mut sc.gz;
        gz.iter_mut().for_each(|x| *x = 0.0);
        self.form(&self.damping, v, &zd, -1.0, None, Some(gz));
        self.solve(gz);
        for (zi, g) in z.iter_mut().zip(gz.iter()) {
            *zi += g;
        }
        sc.zd = zd;
    }

    /// Joint angles (Θ₁, Θ₂) on the first-order manifold z₀ + z₁ ([`Self::rotations_with_lag`]).
    pub fn joint_angles_with_lag(&self, q: &[f64], v: &[f64]) -> [f64; 2] {
        let mut z = std::mem::take(&mut self.scratch.borrow_mut().z);
        self.rotations_with_lag(q, v, &mut z);
        let th = self.joints_of(q, &z);
        self.scratch.borrow_mut().z = z;
        th
    }

    /// ψ₀ of each link (the clamp section's turn from the chord) at q.
    pub fn clamp_turns(&self, q: &[f64]) -> [f64; 2] {
        let mut z = std::mem::take(&mut self.scratch.borrow_mut().zd);
        self.settle(q, false, &mut z);
        let out = [z[0], z[self.zo(1)]];
        self.scratch.borrow_mut().zd = z;
        out
    }

    /// The section rotations z₀(q) of both links (ψ¹₀…ψ¹_r, ψ²₀…ψ²_r), allocating.
    pub fn rotations(&self, q: &[f64]) -> Vec<f64> {
        let mut z = vec![0.0; self.nz()];
        self.settle(q, false, &mut z);
        z
    }

    /// Condensed (strain, joint springs) at q.
    pub fn energies(&self, q: &[f64]) -> Parts {
        let mut z = std::mem::take(&mut self.scratch.borrow_mut().zd);
        self.settle(q, false, &mut z);
        let p = self.form(&self.elastic, q, &z, 1.0, None, None);
        self.scratch.borrow_mut().zd = z;
        p
    }

    /// Strain + spring energy U(q, z) at any z (for gradient checks).
    pub fn energy_at(&self, q: &[f64], z: &[f64]) -> Parts {
        self.form(&self.elastic, q, z, 1.0, None, None)
    }

    /// ∂U/∂q and ∂U/∂z at (q, z), added into gq, gz (for gradient checks).
    pub fn gradient_at(&self, q: &[f64], z: &[f64], gq: &mut [f64], gz: &mut [f64]) {
        self.form(&self.elastic, q, z, 1.0, Some(gq), Some(gz));
    }

    /// Adds the condensed forces −∂U_c/∂q − ∂D_c/∂q̇ into `out` (module docs); returns the
    /// dissipation powers [joint dampers D₁Θ̇₁² + D₂Θ̇₂², Kelvin–Voigt Σγh(Δż/h)²] and the
    /// joint angles and rates [Θ, Θ̇]. O(n), no allocation.
    pub fn forces(&self, q: &[f64], v: &[f64], out: &mut [f64]) -> ([f64; 2], [[f64; 2]; 2]) {
        let mut sc = self.scratch.borrow_mut();
        let Scratch { z, zd, w, gz } = &mut *sc;
        w.iter_mut().for_each(|x| *x = 0.0);
        // z₀ = −K⁻¹ ∂U/∂z(q, 0)
        z.iter_mut().for_each(|x| *x = 0.0);
        self.form(&self.elastic, q, w, -1.0, None, Some(z));
        self.solve(z);
        // −∂U/∂q at (q, z₀) = −∂U_c/∂q (∂U/∂z = 0 there)
        self.form(&self.elastic, q, z, -1.0, Some(out), None);
        let angles = self.joints_of(q, z);
        // ż₀ = J q̇ = −K⁻¹ K_zy q̇
        zd.iter_mut().for_each(|x| *x = 0.0);
        self.form(&self.elastic.without_set(), v, w, -1.0, None, Some(zd));
        self.solve(zd);
        let rates = self.joints_of(v, zd);
        let mut powers = [0.0; 2];
        if self.damped {
            // −∂D/∂q̇ − Jᵀ∂D/∂ż at (q̇, ż₀), Jᵀg = −K_yz K⁻¹ g
            gz.iter_mut().for_each(|x| *x = 0.0);
            let parts = self.form(&self.damping, v, zd, -1.0, Some(out), Some(gz));
            // gz holds −∂D/∂ż: out += −Jᵀ∂D/∂ż = K_yz K⁻¹ ∂D/∂ż = −K_yz K⁻¹ gz
            self.solve(gz);
            gz.iter_mut().for_each(|x| *x = -*x);
            self.coupling_add(gz, out);
            powers = [2.0 * parts.joints, 2.0 * parts.links];
        }
        (powers, [angles, rates])
    }

    /// out += K_yz w (the q-gradient of the bilinear q–z part of U at (0, w)).
    fn coupling_add(&self, w: &[f64], out: &mut [f64]) {
        let c = &self.elastic;
        for l in 0..2 {
            let (o, r) = (self.zo(l), self.r[l]);
            for i in 0..r {
                // γ at q = 0 is −(w_i + w_{i+1})/2
                let s = -c.shear[l] * 0.5 * (w[o + i] + w[o + i + 1]);
                if i + 1 < r {
                    out[self.first[l] + i] += s;
                }
                if i > 0 {
                    out[self.first[l] + i - 1] -= s;
                }
            }
        }
        let e = [
            c.joint[0] * w[0],
            c.joint[1] * (w[self.zo(1)] - w[self.r[0]]),
        ];
        out[TH] += e[0] - e[1];
        out[BE] += e[1];
    }

    /// Dissipation powers (joint dampers, Kelvin–Voigt) at q̇ alone (ż₀ = Jq̇ needs no q).
    pub fn powers(&self, v: &[f64]) -> [f64; 2] {
        let mut zd = std::mem::take(&mut self.scratch.borrow_mut().zd);
        self.settle(v, true, &mut zd);
        let p = self.form(&self.damping, v, &zd, 1.0, None, None);
        self.scratch.borrow_mut().zd = zd;
        [2.0 * p.joints, 2.0 * p.links]
    }

    /// Per-link shear step bound σ = h √(ρA/κGA) (module docs).
    pub fn shear_bound(&self, link: usize, rho_a: f64) -> f64 {
        self.h[link] * (rho_a / self.elastic.shear[link]).sqrt()
    }

    /// Static tip response of a clamped Timoshenko cantilever (v₀ = ψ₀ = 0, free end) of the
    /// same discrete energy under a tip force P and a distributed load q (lumped: qh at the
    /// interior stations, qh/2 at the tip): the chain's cell energy on r cells, solved as a
    /// banded system (v, ψ interleaved, half-bandwidth 3). Returns (v(L), ψ(L)). Allocates
    /// (statics, not a step loop).
    pub fn cantilever_statics(
        length: f64,
        ei: f64,
        kga: f64,
        r: usize,
        tip: f64,
        dist: f64,
    ) -> (f64, f64) {
        let h = length / r as f64;
        // unknowns (v_i, ψ_i), i = 1…r ↦ 2(i−1), 2(i−1)+1
        let n = 2 * r;
        let bw = 3;
        let mut k = vec![vec![0.0; 2 * bw + 1]; n];
        let mut add = |i: Option<usize>, j: Option<usize>, val: f64| {
            if let (Some(i), Some(j)) = (i, j) {
                k[i][j + bw - i] += val;
            }
        };
        let vi = |i: usize| (i > 0).then(|| 2 * (i - 1));
        let zi = |i: usize| (i > 0).then(|| 2 * (i - 1) + 1);
        for c in 0..r {
            // bending EI/h (ψ_{c+1} − ψ_c)²/2
            let kb = ei / h;
            for (a, sa) in [(zi(c), -1.0), (zi(c + 1), 1.0)] {
                for (b, sb) in [(zi(c), -1.0), (zi(c + 1), 1.0)] {
                    add(a, b, kb * sa * sb);
                }
            }
            // shear κGA h (Δv/h − ψ̄)²/2: γ = gᵀx with g = (−1/h, 1/h, −½, −½)
            let dofs = [vi(c), vi(c + 1), zi(c), zi(c + 1)];
            let g = [-1.0 / h, 1.0 / h, -0.5, -0.5];
            for a in 0..4 {
                for b in 0..4 {
                    add(dofs[a], dofs[b], kga * h * g[a] * g[b]);
                }
            }
        }
        let mut f = vec![0.0; n];
        for i in 1..=r {
            f[2 * (i - 1)] = dist * h * if i == r { 0.5 } else { 1.0 };
        }
        f[2 * (r - 1)] += tip;
        // banded Gaussian elimination (SPD: no pivoting)
        for p in 0..n {
            let d = k[p][bw];
            for i in p + 1..(p + bw + 1).min(n) {
                let m = k[i][p + bw - i] / d;
                if m == 0.0 {
                    continue;
                }
                for j in p..(p + bw + 1).min(n) {
                    k[i][j + bw - i] -= m * k[p][j + bw - p];
                }
                f[i] -= m * f[p];
            }
        }
        let mut x = vec![0.0; n];
        for i in (0..n).rev() {
            let mut s = f[i];
            for j in i + 1..(i + bw + 1).min(n) {
                s -= k[i][j + bw - i] * x[j];
            }
            x[i] = s / k[i][bw];
        }
        (x[n - 2], x[n - 1])
    }
}
