//! Kinetic energy of the two-link chain, its momenta p = ∂T/∂q̇ and its gradient ∂T/∂q.
//!
//! Coordinates q = (θ, β, v₁…v_{r₁}, w₁…w_{r₂}): θ the frame angle of link 1, β the *absolute*
//! frame angle of link 2 (the elbow angle θ₂ = β − θ − ψ(v) is then a function of q, and the trig
//! functions depend on φ = β − θ only), v and w the transverse deflections at the stations of
//! links 1 and 2 (clamp excluded). A point of link ℓ sits at O_ℓ + R(α_ℓ)(x − s, v) with
//! s = ½∫₀ˣ v'² (foreshortening; s ≡ 0 when off). With the velocity of a link-2 point written in
//! the link-2 frame as (X₀ + X₁ + X₂, Y₀ + Y₁ + Y₂) by order in the deflections,
//!
//! X₀ = θ̇L₁ sin φ,          X₁ = −θ̇V cos φ + V̇ sin φ − β̇w,   X₂ = −Ṡ cos φ − θ̇S sin φ − σ̇,
//! Y₀ = θ̇L₁ cos φ + β̇ξ,     Y₁ = θ̇V sin φ + V̇ cos φ + ẇ,     Y₂ = Ṡ sin φ − θ̇S cos φ − β̇σ,
//!
//! (V = v_{r₁}, S = s₁(L₁)), the kinetic energy kept is the expansion to second order in the
//! deflections: ½m[(X₀+X₁)² + (Y₀+Y₁)²] + m(X₀X₂ + Y₀Y₂) per point. The chain leaves out the
//! third- and fourth-order remainder (m(X₁X₂ + Y₁Y₂) + ½m(X₂² + Y₂²) per point, and link 1's
//! ΔT of [`crate::link`]), which the single link, fem and modal keep. Summed over the lumped
//! masses:
//!
//! T = ½J₁θ̇² + Σᵢ ½mᵢ[θ̇²vᵢ² + (θ̇xᵢ + v̇ᵢ)²] − θ̇²Φ₁
//!   + ½M₂[(θ̇L₁ + V̇)² + θ̇²V²] + β̇(bQ₂ − aΣmw) + bΣmẇ + ½β̇²Σmw² + ½Σm(β̇ξ + ẇ)²
//!   + (−M₂θ̇²L₁S − θ̇L₁ sin φ Ψ̇ − θ̇β̇L₁ cos φ Ψ + β̇Q₂Ṡ sin φ − θ̇β̇Q₂S cos φ − β̇²Φ₂),
//!
//! a = sin φ (θ̇L₁ + V̇) − cos φ θ̇V, b = cos φ (θ̇L₁ + V̇) + sin φ θ̇V (the elbow velocity in the
//! link-2 frame to first order), M₂ = Σm, Q₂ = Σmξ, Ψ = Σmσ, Φ_ℓ = Σ m x s (sums over link 2 /
//! link ℓ). Every s-type sum is a weighted ½h Σ_seg c_seg g_seg², g = Δv/h, with c the outboard
//! mass (Ψ), outboard first moment (Φ) or 1 (S): O(n) with its gradient.
//!
//! T is a quadratic form in q̇, so Lagrange's equations conserve T + V exactly in continuous
//! time. It is positive definite only for moderate deflections: the second-order products of
//! the elbow's rigid velocity with the foreshortening rates, −θ̇L₁ sin φ Ψ̇ + β̇Q₂Ṡ sin φ, are
//! indefinite, and in the direction "turn the chords, counter-bend link 2" (the deflection
//! rates cancel each link-2 station's transverse velocity, so those masses barely move) they
//! outweigh the positive part once the link slopes reach ~0.2. The exact T adds terms such as ½Σmṡ², dense in the deflection
//! rates, which the chain's O(n) Schur-complement mass solve cannot carry; the contact driver
//! stops with a diagnostic when G M⁻¹ Gᵀ ≤ 0. Its mass matrix is diagonal in the deflections except for the full columns of θ, β
//! and V. The chain ([`super`]) uses tip-chord frames, V ≡ 0 there (and w_{r₂} ≡ 0).

use super::dual::{Dual, Number};

/// The chain's inertia data (lumped masses per station, segment weights).
#[derive(Debug, Clone)]
pub struct ChainInertia {
    /// hub rotor inertia J₁ (on θ̇)
    pub hub: f64,
    pub l1: f64,
    pub h1: f64,
    pub h2: f64,
    pub r1: usize,
    pub r2: usize,
    pub fs1: bool,
    pub fs2: bool,
    /// masses of stations 1…r (index k ↔ station k+1)
    pub m1: Vec<f64>,
    pub m2: Vec<f64>,
    /// W_seg = Σ_{i > seg} mᵢxᵢ (link 1) — Φ₁ weights
    pub w1: Vec<f64>,
    /// W_seg of link 2 — Φ₂ weights
    pub w2: Vec<f64>,
    /// outboard mass μ_seg = Σ_{j > seg} m_j of link 2 — Ψ weights
    pub mu2: Vec<f64>,
    pub sum_mx2_1: f64,
    pub mass2: f64,
    pub q2: f64,
    pub i2: f64,
}

pub const TH: usize = 0;
pub const BE: usize = 1;

/// Segment slope g_seg = (u_{seg+1} − u_seg)/h with u₀ = 0.
#[inline]
fn slope(u: &[f64], seg: usize, h: f64) -> f64 {
    let left = if seg == 0 { 0.0 } else { u[seg - 1] };
    (u[seg] - left) / h
}

#[inline]
fn slope_d<N: Number>(u: &[f64], du: &[f64], seg: usize, h: f64) -> N {
    let (l, ld) = if seg == 0 {
        (0.0, 0.0)
    } else {
        (u[seg - 1], du[seg - 1])
    };
    N::seed((u[seg] - l) / h, (du[seg] - ld) / h)
}

/// ½ h Σ c_seg g_seg² (c = None: weights 1).
pub fn seg_energy(u: &[f64], h: f64, c: Option<&[f64]>) -> f64 {
    (0..u.len())
        .map(|s| 0.5 * h * c.map_or(1.0, |c| c[s]) * slope(u, s, h).powi(2))
        .sum()
}

/// h Σ c_seg g_seg ġ_seg (time derivative of [`seg_energy`]).
pub fn seg_rate(u: &[f64], ud: &[f64], h: f64, c: Option<&[f64]>) -> f64 {
    (0..u.len())
        .map(|s| h * c.map_or(1.0, |c| c[s]) * slope(u, s, h) * slope(ud, s, h))
        .sum()
}

/// ∂/∂u_k of ½hΣ c g² = c_k g_k − c_{k+1} g_{k+1} (station k+1 ends segment k, starts k+1);
/// with `u` replaced by u̇ it is ∂/∂u_k of h Σ c g ġ.
#[inline]
pub fn seg_grad(u: &[f64], h: f64, c: Option<&[f64]>, k: usize) -> f64 {
    let w = |s: usize| c.map_or(1.0, |c| c[s]);
    let mut d = w(k) * slope(u, k, h);
    if k + 1 < u.len() {
        d -= w(k + 1) * slope(u, k + 1, h);
    }
    d
}

#[inline]
fn seg_grad_d<N: Number>(u: &[f64], du: &[f64], h: f64, c: Option<&[f64]>, k: usize) -> N {
    let w = |s: usize| c.map_or(1.0, |c| c[s]);
    let mut d = slope_d::<N>(u, du, k, h) * w(k);
    if k + 1 < u.len() {
        d = d - slope_d::<N>(u, du, k + 1, h) * w(k + 1);
    }
    d
}

impl ChainInertia {
    pub fn dofs(&self) -> usize {
        2 + self.r1 + self.r2
    }
    pub fn iv(&self) -> std::ops::Range<usize> {
        2..2 + self.r1
    }
    pub fn iw(&self) -> std::ops::Range<usize> {
        2 + self.r1..2 + self.r1 + self.r2
    }
    /// Index of the elbow deflection V = v_{r₁}.
    pub fn i_tip1(&self) -> usize {
        1 + self.r1
    }
    fn x1(&self, k: usize) -> f64 {
        (k + 1) as f64 * self.h1
    }
    fn xi2(&self, j: usize) -> f64 {
        (j + 1) as f64 * self.h2
    }

    /// Diagonal mass of coordinate i outside the full columns θ, β, V.
    pub fn diag_mass(&self, i: usize) -> f64 {
        if self.iv().contains(&i) {
            self.m1[i - 2]
        } else {
            self.m2[i - 2 - self.r1]
        }
    }

    /// Kinetic energy T(q, q̇) (module docs).
    pub fn kinetic(&self, q: &[f64], qd: &[f64]) -> f64 {
        let (v, vd) = (&q[self.iv()], &qd[self.iv()]);
        let (w, wd) = (&q[self.iw()], &qd[self.iw()]);
        let (thd, bed) = (qd[TH], qd[BE]);
        let (sn, c) = (q[BE] - q[TH]).sin_cos();
        let (vt, vtd) = (v[self.r1 - 1], vd[self.r1 - 1]);
        let l1 = self.l1;
        let mut t = 0.5 * self.hub * thd * thd;
        for k in 0..self.r1 {
            t += 0.5 * self.m1[k] * ((thd * v[k]).powi(2) + (thd * self.x1(k) + vd[k]).powi(2));
        }
        let (s, sd, phi1) = if self.fs1 {
            (
                seg_energy(v, self.h1, None),
                seg_rate(v, vd, self.h1, None),
                seg_energy(v, self.h1, Some(&self.w1)),
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        let (psi, psid, phi2) = if self.fs2 {
            (
                seg_energy(w, self.h2, Some(&self.mu2)),
                seg_rate(w, wd, self.h2, Some(&self.mu2)),
                seg_energy(w, self.h2, Some(&self.w2)),
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        t -= thd * thd * phi1;
        let a = sn * (thd * l1 + vtd) - c * thd * vt;
        let b = c * (thd * l1 + vtd) + sn * thd * vt;
        let (mut smw, mut smwd, mut smw2, mut rel) = (0.0, 0.0, 0.0, 0.0);
        for j in 0..self.r2 {
            let m = self.m2[j];
            smw += m * w[j];
            smwd += m * wd[j];
            smw2 += m * w[j] * w[j];
            rel += 0.5 * m * (bed * self.xi2(j) + wd[j]).powi(2);
        }
        t += 0.5 * self.mass2 * ((thd * l1 + vtd).powi(2) + (thd * vt).powi(2))
            + bed * (b * self.q2 - a * smw)
            + b * smwd
            + 0.5 * bed * bed * smw2
            + rel
            - self.mass2 * thd * thd * l1 * s
            - thd * l1 * sn * psid
            - thd * bed * l1 * c * psi
            + bed * self.q2 * sd * sn
            - thd * bed * self.q2 * s * c
            - bed * bed * phi2;
        t
    }

    /// p = ∂T/∂q̇ at (q + ε dq, q̇): `out[i].re` the momenta, `out[i].du` = (∂pᵢ/∂q)·dq.
    pub fn momenta(&self, q: &[f64], dq: &[f64], qd: &[f64], out: &mut [Dual]) {
        self.momenta_in(q, dq, qd, out);
    }

    /// p = ∂T/∂q̇ at (q, q̇), values only: the first [`Self::dofs`] entries of `out`.
    pub fn momenta_values(&self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.momenta_in(q, q, qd, out);
    }

    /// The momenta formula over `f64` or [`Dual`] (`dq` is read only by `Dual`).
    fn momenta_in<N: Number>(&self, q: &[f64], dq: &[f64], qd: &[f64], out: &mut [N]) {
        let (v, dv, vd) = (&q[self.iv()], &dq[self.iv()], &qd[self.iv()]);
        let (w, dw, wd) = (&q[self.iw()], &dq[self.iw()], &qd[self.iw()]);
        let (thd, bed) = (qd[TH], qd[BE]);
        let phi = N::seed(q[BE] - q[TH], dq[BE] - dq[TH]);
        let (sn, c) = (phi.sin(), phi.cos());
        let r1 = self.r1;
        let vt = N::seed(v[r1 - 1], dv[r1 - 1]);
        let vtd = vd[r1 - 1];
        let l1 = self.l1;
        let zero = N::default();
        // link-1 sums
        let mut smv2 = zero;
        let mut smxvd = 0.0;
        for k in 0..r1 {
            let vk = N::seed(v[k], dv[k]);
            smv2 = smv2 + vk * vk * self.m1[k];
            smxvd += self.m1[k] * self.x1(k) * vd[k];
        }
        let (mut s, mut sd, mut phi1) = (zero, zero, zero);
        if self.fs1 {
            for seg in 0..r1 {
                let g: N = slope_d(v, dv, seg, self.h1);
                let gd = slope(vd, seg, self.h1);
                s = s + g * g * (0.5 * self.h1);
                sd = sd + g * (self.h1 * gd);
                phi1 = phi1 + g * g * (0.5 * self.h1 * self.w1[seg]);
            }
        }
        // link-2 sums
        let (mut smw, mut smw2) = (zero, zero);
        let (mut smwd, mut smxiwd) = (0.0, 0.0);
        for j in 0..self.r2 {
            let wj = N::seed(w[j], dw[j]);
            smw = smw + wj * self.m2[j];
            smw2 = smw2 + wj * wj * self.m2[j];
            smwd += self.m2[j] * wd[j];
            smxiwd += self.m2[j] * self.xi2(j) * wd[j];
        }
        let (mut psi, mut psid, mut phi2) = (zero, zero, zero);
        if self.fs2 {
            for seg in 0..self.r2 {
                let g: N = slope_d(w, dw, seg, self.h2);
                let gd = slope(wd, seg, self.h2);
                psi = psi + g * g * (0.5 * self.h2 * self.mu2[seg]);
                psid = psid + g * (self.h2 * self.mu2[seg] * gd);
                phi2 = phi2 + g * g * (0.5 * self.h2 * self.w2[seg]);
            }
        }
        let a = sn * (thd * l1 + vtd) - c * vt * thd;
        let b = c * (thd * l1 + vtd) + sn * vt * thd;
        let (m2, q2) = (self.mass2, self.q2);
        out[TH] = N::constant(self.hub * thd + thd * self.sum_mx2_1 + smxvd) + smv2 * thd
            - phi1 * (2.0 * thd)
            + (vt * vt * thd + l1 * (thd * l1 + vtd)) * m2
            + ((c * l1 + sn * vt) * q2 - smw * (sn * l1 - c * vt)) * bed
            + (c * l1 + sn * vt) * smwd
            - s * (2.0 * m2 * thd * l1)
            - sn * psid * l1
            - c * psi * (bed * l1)
            - s * c * (bed * q2);
        out[BE] = b * q2 - a * smw + smw2 * bed + N::constant(bed * self.i2 + smxiwd)
            - c * psi * (thd * l1)
            + sd * sn * q2
            - s * c * (thd * q2)
            - phi2 * (2.0 * bed);
        let bq_sn = sn * (bed * q2);
        for k in 0..r1 {
            let mut p = N::constant(self.m1[k] * (thd * self.x1(k) + vd[k]));
            if self.fs1 {
                p = p + bq_sn * seg_grad_d::<N>(v, dv, self.h1, None, k);
            }
            out[2 + k] = p;
        }
        out[2 + r1 - 1] = out[2 + r1 - 1]
            + N::constant(m2 * (thd * l1 + vtd))
            + (c * q2 - sn * smw) * bed
            + c * smwd;
        for j in 0..self.r2 {
            let mut p = (b + bed * self.xi2(j) + wd[j]) * self.m2[j];
            if self.fs2 {
                p = p - sn * seg_grad_d::<N>(w, dw, self.h2, Some(&self.mu2), j) * (thd * l1);
            }
            out[2 + r1 + j] = p;
        }
    }

    /// ∂T/∂q (overwrites `out`).
    pub fn grad_q(&self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let (v, vd) = (&q[self.iv()], &qd[self.iv()]);
        let (w, wd) = (&q[self.iw()], &qd[self.iw()]);
        let (thd, bed) = (qd[TH], qd[BE]);
        let (sn, c) = (q[BE] - q[TH]).sin_cos();
        let r1 = self.r1;
        let (vt, vtd) = (v[r1 - 1], vd[r1 - 1]);
        let (l1, m2, q2) = (self.l1, self.mass2, self.q2);
        let (s, sd) = if self.fs1 {
            (seg_energy(v, self.h1, None), seg_rate(v, vd, self.h1, None))
        } else {
            (0.0, 0.0)
        };
        let (psi, psid) = if self.fs2 {
            (
                seg_energy(w, self.h2, Some(&self.mu2)),
                seg_rate(w, wd, self.h2, Some(&self.mu2)),
            )
        } else {
            (0.0, 0.0)
        };
        let (mut smw, mut smwd) = (0.0, 0.0);
        for j in 0..self.r2 {
            smw += self.m2[j] * w[j];
            smwd += self.m2[j] * wd[j];
        }
        let a = sn * (thd * l1 + vtd) - c * thd * vt;
        let b = c * (thd * l1 + vtd) + sn * thd * vt;
        let dphi = bed * (-a * q2 - b * smw) - a * smwd - thd * l1 * c * psid
            + thd * bed * l1 * sn * psi
            + bed * q2 * sd * c
            + thd * bed * q2 * s * sn;
        out[TH] = -dphi;
        out[BE] = dphi;
        let coef_s = -m2 * thd * thd * l1 - thd * bed * q2 * c;
        let coef_sd = bed * q2 * sn;
        for k in 0..r1 {
            let mut g = self.m1[k] * thd * thd * v[k];
            if self.fs1 {
                g += -thd * thd * seg_grad(v, self.h1, Some(&self.w1), k)
                    + coef_s * seg_grad(v, self.h1, None, k)
                    + coef_sd * seg_grad(vd, self.h1, None, k);
            }
            out[2 + k] = g;
        }
        out[1 + r1] += m2 * thd * thd * vt + bed * thd * (sn * q2 + c * smw) + sn * thd * smwd;
        for j in 0..self.r2 {
            let mut g = bed * self.m2[j] * (bed * w[j] - a);
            if self.fs2 {
                g += -thd * bed * l1 * c * seg_grad(w, self.h2, Some(&self.mu2), j)
                    - thd * l1 * sn * seg_grad(wd, self.h2, Some(&self.mu2), j)
                    - bed * bed * seg_grad(w, self.h2, Some(&self.w2), j);
            }
            out[2 + r1 + j] = g;
        }
    }
}
