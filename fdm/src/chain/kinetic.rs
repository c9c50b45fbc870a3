//! Kinetic energy of the two-link chain, T = ½J₁θ̇² + ½Σ m|ṙ|² of its lumped points, its
//! momenta p = M q̇ and its inertia forces.
//!
//! Kernel coordinates q = (θ, β, v₁…v_{r₁}, w₁…w_{r₂}): θ the frame angle of link 1, β the
//! *absolute* frame angle of link 2 (the trig functions depend on φ = β − θ only), v and w the
//! transverse deflections at the stations of links 1 and 2 in their frames, the tip's included
//! (V = v_{r₁}). The chain feeds the kernel its clamp-tangent frames (tip −Lψ; Timoshenko links
//! their tip chords, V = 0) through a constant linear map of its own coordinates
//! ([`super::TwoLinkChain::to_kinetic`]). The foreshortening s_k = ½h Σ_{seg ≤ k} g_seg², g the
//! segment slopes (s ≡ 0 when off).
//!
//! Every point's velocity is written in its link frame. Link 1's station k sits at
//! (x_k − s_k, v_k) in link 1's frame, the elbow E at (L₁ − S, V) (link 1's tip, carrying link 2's clamp half cell), link 2's
//! station j at E + R(φ)(ξ_j − σ_j, w_j), φ = β − θ; s, S, σ the foreshortenings ½h Σ g².
//!
//! Velocity components (X, Y), link 1 point: X = −θ̇v − ṡ, Y = θ̇(x − s) + v̇; elbow (link-1
//! frame): (E_x, E_y) = (−θ̇V − Ṡ, θ̇(L₁ − S) + V̇); link 2 point (link-2 frame): X = cE_x + sE_y
//! − β̇w − σ̇, Y = −sE_x + cE_y + β̇(ξ − σ) + ẇ (c, s of φ). They are linear in q̇: ṙ = B(q)q̇.
//! The equations of motion in Kane's form, M = Σ m BᵀB,
//!
//!   M q̈ = Q − Σ m Bᵀ[(∂(Bq̇)/∂q) q̇ + α̇ J(X, Y)],   J(X, Y) = (−Y, X),
//!
//! α̇ the rate of the point's frame (θ̇ on link 1 and at E, β̇ on link 2): the bracket is the
//! point's acceleration at q̈ = 0 in frame components, its first term one forward-mode dual pass
//! over the velocities with q seeded along q̇. Bᵀ applied to per-point forces is O(n): the
//! foreshortening rates are running sums ṡ_k = Σ_{seg ≤ k} g_seg(u̇_seg − u̇_{seg−1}), whose
//! transpose is the outboard sum of the forces.
//!
//! T is exact in the deflections, so it is a positive definite quadratic form in q̇ at every
//! configuration the frames can describe: M stays positive definite however far the
//! links bend (a truncation of T to second order in the deflections is indefinite once the
//! link slopes reach ~0.2: its products of the elbow's rigid velocity with the foreshortening
//! rates outweigh the rest in the direction that turns the chords against link 2's
//! deflection rates). The structure of M and its O(n) solve: [`super::mass`].

// Index loops over parallel per-point buffers read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::dual::{Dual, Number};

/// The chain's inertia data: lumped masses per station and the sums the forces use.
#[derive(Debug, Clone)]
pub struct ChainInertia {
    /// hub rotor inertia J₁ (on the kernel's θ̇: the clamp angle's rate when the chain feeds its
    /// clamp-tangent frames)
    pub hub: f64,
    pub l1: f64,
    pub h1: f64,
    pub h2: f64,
    pub r1: usize,
    pub r2: usize,
    pub fs1: bool,
    pub fs2: bool,
    /// abscissae ξ_k = (k+1)h of stations 1…r (index k ↔ station k+1)
    pub x1: Vec<f64>,
    pub x2: Vec<f64>,
    /// masses of stations 1…r (index k ↔ station k+1)
    pub m1: Vec<f64>,
    pub m2: Vec<f64>,
    /// outboard mass μ_seg = Σ_{j ≥ seg} m_j of link 2 (the weights of link 2's
    /// foreshortening in gravity and in the mass solve)
    pub mu2: Vec<f64>,
    /// link 2's mass with its clamp half cell, and its first moment about the elbow
    pub mass2: f64,
    pub q2: f64,
    /// link 2's clamp half cell ρA₂h₂/2, riding on the elbow
    pub elbow_mass: f64,
}

pub const TH: usize = 0;
pub const BE: usize = 1;

/// Segment slope g_seg = (u_{seg+1} − u_seg)/h with u₀ = 0.
#[inline]
pub(super) fn slope(u: &[f64], seg: usize, h: f64) -> f64 {
    let left = if seg == 0 { 0.0 } else { u[seg - 1] };
    (u[seg] - left) / h
}

#[inline]
pub(super) fn slope_d<N: Number>(u: &[f64], du: &[f64], seg: usize, h: f64) -> N {
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

/// [`seg_grad`] from the slopes `g` already taken (weights `c`).
#[inline]
fn seg_grad_at(g: &[f64], c: &[f64], k: usize) -> f64 {
    let mut d = c[k] * g[k];
    if k + 1 < g.len() {
        d -= c[k + 1] * g[k + 1];
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
    /// Diagonal mass of coordinate i outside the full columns θ, β, V.
    pub fn diag_mass(&self, i: usize) -> f64 {
        if self.iv().contains(&i) {
            self.m1[i - 2]
        } else {
            self.m2[i - 2 - self.r1]
        }
    }
}

/// The configuration's part of every product with B or Bᵀ at q: each link's segment slopes g
/// and its points' axial positions x_k − s_k in the link frame, s_k = ½h Σ_{seg ≤ k} g_seg² the
/// running foreshortening (zero without foreshortening). One step evaluates B and Bᵀ at one q
/// several times (M's columns, Γ at two drift velocities), and the slopes' divisions dominated
/// each pass.
#[derive(Debug, Clone)]
pub struct Shape {
    pub g1: Vec<f64>,
    pub g2: Vec<f64>,
    pub a1: Vec<f64>,
    pub a2: Vec<f64>,
}

/// Per-point scratch of the kinetic energy: velocity components (with their derivative along
/// q̇, or values only), per-point forces, the outboard sums of the transpose and the
/// [`Shape`] of the configuration the `_at` products read.
#[derive(Debug, Clone)]
pub struct PointScratch {
    pub x: Vec<Dual>,
    pub y: Vec<Dual>,
    pub xv: Vec<f64>,
    pub yv: Vec<f64>,
    pub fx: Vec<f64>,
    pub fy: Vec<f64>,
    pub c1: Vec<f64>,
    pub c2: Vec<f64>,
    pub shape: Shape,
}

impl PointScratch {
    pub fn new(ine: &ChainInertia) -> Self {
        let n = ine.points();
        PointScratch {
            x: vec![Dual::default(); n],
            y: vec![Dual::default(); n],
            xv: vec![0.0; n],
            yv: vec![0.0; n],
            fx: vec![0.0; n],
            fy: vec![0.0; n],
            c1: vec![0.0; ine.r1],
            c2: vec![0.0; ine.r2],
            shape: Shape {
                g1: vec![0.0; ine.r1],
                g2: vec![0.0; ine.r2],
                a1: vec![0.0; ine.r1],
                a2: vec![0.0; ine.r2],
            },
        }
    }
}

/// Per-point scratch of `C` products with B or Bᵀ at one configuration taken together (M's
/// full columns, the inertia terms at two velocities): the per-point forces and the outboard
/// sums, one lane per product. The products' chains of sums over the stations then overlap.
#[derive(Debug, Clone)]
pub struct Lanes<const C: usize> {
    pub fx: Vec<[f64; C]>,
    pub fy: Vec<[f64; C]>,
    pub c1: Vec<[f64; C]>,
    pub c2: Vec<[f64; C]>,
}

impl<const C: usize> Lanes<C> {
    pub fn new(ine: &ChainInertia) -> Self {
        let n = ine.points();
        Lanes {
            fx: vec![[0.0; C]; n],
            fy: vec![[0.0; C]; n],
            c1: vec![[0.0; C]; ine.r1],
            c2: vec![[0.0; C]; ine.r2],
        }
    }
}

/// The deflection rates of `C` velocities and their segment slopes
/// ([`ChainInertia::rate_slopes`]) lane by lane, per station (link 1's, then link 2's): what
/// [`ChainInertia::momenta_lanes`] reads per station, in one place (read from `C` vectors, the
/// compiler kept each lane's products scalar).
#[derive(Debug, Clone, Default)]
pub struct RateLanes<const C: usize> {
    pub rates: Vec<[f64; C]>,
    pub slopes: Vec<[f64; C]>,
}

impl<const C: usize> RateLanes<C> {
    pub fn new(ine: &ChainInertia, qds: [&[f64]; C]) -> Self {
        let n = ine.r1 + ine.r2;
        let mut lanes = RateLanes {
            rates: vec![[0.0; C]; n],
            slopes: vec![[0.0; C]; n],
        };
        let mut slopes = vec![0.0; n];
        for c in 0..C {
            ine.rate_slopes(qds[c], &mut slopes);
            for (k, i) in ine.iv().chain(ine.iw()).enumerate() {
                lanes.rates[k][c] = qds[c][i];
                lanes.slopes[k][c] = slopes[k];
            }
        }
        lanes
    }

    /// Station-by-station lanes of `n` stations, all zero (to be [`Self::set`]).
    pub fn zeroed(n: usize) -> Self {
        RateLanes {
            rates: vec![[0.0; C]; n],
            slopes: vec![[0.0; C]; n],
        }
    }

    /// Interleaves the deflection rates of `qds` and their segment slopes `slopes` (as
    /// [`ChainInertia::rate_slopes`] gives them) into these lanes, which hold
    /// `ine.r1 + ine.r2` stations.
    pub fn set(&mut self, ine: &ChainInertia, qds: [&[f64]; C], slopes: [&[f64]; C]) {
        let n = ine.r1 + ine.r2;
        let (rates, slo) = (&mut self.rates[..n], &mut self.slopes[..n]);
        for (k, i) in ine.iv().chain(ine.iw()).enumerate() {
            rates[k] = std::array::from_fn(|c| qds[c][i]);
            slo[k] = std::array::from_fn(|c| slopes[c][k]);
        }
    }
}

impl ChainInertia {
    /// Number of lumped points: link 1's stations, the elbow, link 2's stations.
    pub fn points(&self) -> usize {
        self.r1 + 1 + self.r2
    }

    /// Mass of point p (order of [`Self::points`]).
    pub fn point_mass(&self, p: usize) -> f64 {
        if p < self.r1 {
            self.m1[p]
        } else if p == self.r1 {
            self.elbow_mass
        } else {
            self.m2[p - self.r1 - 1]
        }
    }

    /// Velocity components of every point in its link frame at (q + ε dq, q̇).
    pub fn point_velocities<N: Number>(
        &self,
        q: &[f64],
        dq: &[f64],
        qd: &[f64],
        xs: &mut [N],
        ys: &mut [N],
    ) {
        let (v, dv, vd) = (&q[self.iv()], &dq[self.iv()], &qd[self.iv()]);
        let (w, dw, wd) = (&q[self.iw()], &dq[self.iw()], &qd[self.iw()]);
        let (thd, bed) = (qd[TH], qd[BE]);
        let (r1, h1, h2) = (self.r1, self.h1, self.h2);
        let zero = N::default();
        let (mut s, mut sd) = (zero, zero);
        for k in 0..r1 {
            if self.fs1 {
                let g: N = slope_d(v, dv, k, h1);
                s = s + g * g * (0.5 * h1);
                sd = sd + g * (h1 * slope(vd, k, h1));
            }
            let vk = N::seed(v[k], dv[k]);
            xs[k] = -(vk * thd) - sd;
            ys[k] = (N::constant(self.x1[k]) - s) * thd + vd[k];
        }
        let (ex, ey) = (xs[r1 - 1], ys[r1 - 1]);
        xs[r1] = ex;
        ys[r1] = ey;
        let phi = N::seed(q[BE] - q[TH], dq[BE] - dq[TH]);
        let (sn, c) = (phi.sin(), phi.cos());
        let (xe, ye) = (c * ex + sn * ey, c * ey - sn * ex);
        let (mut sg, mut sgd) = (zero, zero);
        for j in 0..self.r2 {
            if self.fs2 {
                let g: N = slope_d(w, dw, j, h2);
                sg = sg + g * g * (0.5 * h2);
                sgd = sgd + g * (h2 * slope(wd, j, h2));
            }
            let wj = N::seed(w[j], dw[j]);
            xs[r1 + 1 + j] = xe - wj * bed - sgd;
            ys[r1 + 1 + j] = ye + (N::constant(self.x2[j]) - sg) * bed + wd[j];
        }
    }

    /// The [`Shape`] of q into `sc.shape`: what the `_at` products read (the slopes and
    /// axial positions [`Self::point_velocities`] and the transpose compute, the same
    /// operations in the same order, so the values are those bits).
    pub fn set_shape(&self, q: &[f64], sc: &mut PointScratch) {
        let sh = &mut sc.shape;
        for (u, x, h, fs, g, a) in [
            (
                &q[self.iv()],
                &self.x1,
                self.h1,
                self.fs1,
                &mut sh.g1,
                &mut sh.a1,
            ),
            (
                &q[self.iw()],
                &self.x2,
                self.h2,
                self.fs2,
                &mut sh.g2,
                &mut sh.a2,
            ),
        ] {
            let mut acc = 0.0;
            for k in 0..u.len() {
                if fs {
                    let gk = slope(u, k, h);
                    g[k] = gk;
                    acc += 0.5 * h * gk.powi(2);
                } else {
                    g[k] = 0.0;
                }
                a[k] = x[k] - acc;
            }
        }
    }

    /// out = Bᵀ f: the generalized forces of per-point forces (fx, fy) in the link frames.
    pub fn apply_transpose(&self, q: &[f64], sc: &mut PointScratch, out: &mut [f64]) {
        self.set_shape(q, sc);
        self.apply_transpose_at(q, sc, out);
    }

    /// [`Self::apply_transpose`] with the shape of q already in `sc` ([`Self::set_shape`]).
    pub fn apply_transpose_at(&self, q: &[f64], sc: &mut PointScratch, out: &mut [f64]) {
        let (v, w) = (&q[self.iv()], &q[self.iw()]);
        let (r1, r2) = (self.r1, self.r2);
        let (sn, c) = (q[BE] - q[TH]).sin_cos();
        let PointScratch {
            fx,
            fy,
            c1,
            c2,
            shape,
            ..
        } = sc;
        let (fx, fy) = (&fx[..r1 + 1 + r2], &fy[..r1 + 1 + r2]);
        let (g1, a1) = (&shape.g1[..r1], &shape.a1[..r1]);
        let (g2, a2) = (&shape.g2[..r2], &shape.a2[..r2]);
        let (c1, c2) = (&mut c1[..r1], &mut c2[..r2]);
        let off = 2 + r1;
        let out = &mut out[..off + r2];
        // link 2: β, the rates ẇ, the outboard sums of −fx for σ̇, the elbow force
        let (mut qb, mut gx, mut gy) = (0.0, fx[r1], fy[r1]);
        let mut acc = 0.0;
        for j in 0..r2 {
            let (a, b) = (fx[r1 + 1 + j], fy[r1 + 1 + j]);
            qb += -a * w[j] + b * a2[j];
            out[off + j] = b;
            gx += c * a - sn * b;
            gy += sn * a + c * b;
        }
        if self.fs2 {
            for j in (0..r2).rev() {
                acc -= fx[r1 + 1 + j];
                c2[j] = acc;
            }
            for j in 0..r2 {
                out[off + j] += seg_grad_at(g2, c2, j);
            }
        }
        // link 1 with the elbow force at its tip station
        let mut qt = 0.0;
        for k in 0..r1 {
            let (mut a, mut b) = (fx[k], fy[k]);
            if k == r1 - 1 {
                a += gx;
                b += gy;
            }
            qt += -a * v[k] + b * a1[k];
            out[2 + k] = b;
        }
        if self.fs1 {
            let mut acc = -gx;
            for k in (0..r1).rev() {
                acc -= fx[k];
                c1[k] = acc;
            }
            for k in 0..r1 {
                out[2 + k] += seg_grad_at(g1, c1, k);
            }
        }
        out[TH] = qt;
        out[BE] = qb;
    }

    /// Kinetic energy T(q, q̇) (module docs).
    pub fn kinetic(&self, q: &[f64], qd: &[f64], sc: &mut PointScratch) -> f64 {
        self.point_velocities(q, q, qd, &mut sc.xv, &mut sc.yv);
        let mut t = 0.5 * self.hub * qd[TH] * qd[TH];
        for p in 0..self.points() {
            t += 0.5 * self.point_mass(p) * (sc.xv[p].powi(2) + sc.yv[p].powi(2));
        }
        t
    }

    /// p = ∂T/∂q̇ = M q̇ into the first [`Self::dofs`] entries of `out`.
    pub fn momenta_values(&self, q: &[f64], qd: &[f64], sc: &mut PointScratch, out: &mut [f64]) {
        self.set_shape(q, sc);
        self.momenta_at(q, qd, sc, out);
    }

    /// The segment slopes of `qd`'s deflection rates into `out`, link 1's then link 2's (what
    /// the `_lanes` products take): those of a link without foreshortening are not read, and
    /// left as they are.
    pub fn rate_slopes(&self, qd: &[f64], out: &mut [f64]) {
        let (vd, wd) = (&qd[self.iv()], &qd[self.iw()]);
        let (r1, r2) = (self.r1, self.r2);
        if self.fs1 {
            for k in 0..r1 {
                out[k] = slope(vd, k, self.h1);
            }
        }
        if self.fs2 {
            for j in 0..r2 {
                out[r1 + j] = slope(wd, j, self.h2);
            }
        }
    }

    /// [`Self::momenta_values`] with the shape of q already in `sc` ([`Self::set_shape`]):
    /// [`Self::point_velocities`]' values from the shape's slopes.
    pub fn momenta_at(&self, q: &[f64], qd: &[f64], sc: &mut PointScratch, out: &mut [f64]) {
        let (v, vd) = (&q[self.iv()], &qd[self.iv()]);
        let (w, wd) = (&q[self.iw()], &qd[self.iw()]);
        let (thd, bed) = (qd[TH], qd[BE]);
        let (r1, r2, h1, h2) = (self.r1, self.r2, self.h1, self.h2);
        let PointScratch {
            xv,
            yv,
            fx,
            fy,
            shape,
            ..
        } = &mut *sc;
        let np = r1 + 1 + r2;
        let (xs, ys) = (&mut xv[..np], &mut yv[..np]);
        let (fx, fy) = (&mut fx[..np], &mut fy[..np]);
        let (g1, a1) = (&shape.g1[..r1], &shape.a1[..r1]);
        let (g2, a2) = (&shape.g2[..r2], &shape.a2[..r2]);
        let mut sd = 0.0;
        for k in 0..r1 {
            if self.fs1 {
                sd += g1[k] * (h1 * slope(vd, k, h1));
            }
            xs[k] = -(v[k] * thd) - sd;
            ys[k] = a1[k] * thd + vd[k];
        }
        let (ex, ey) = (xs[r1 - 1], ys[r1 - 1]);
        xs[r1] = ex;
        ys[r1] = ey;
        let phi = q[BE] - q[TH];
        let (sn, c) = (phi.sin(), phi.cos());
        let (xe, ye) = (c * ex + sn * ey, c * ey - sn * ex);
        let mut sgd = 0.0;
        for j in 0..r2 {
            if self.fs2 {
                sgd += g2[j] * (h2 * slope(wd, j, h2));
            }
            xs[r1 + 1 + j] = xe - w[j] * bed - sgd;
            ys[r1 + 1 + j] = ye + a2[j] * bed + wd[j];
        }
        for p in 0..np {
            let m = self.point_mass(p);
            fx[p] = m * xs[p];
            fy[p] = m * ys[p];
        }
        self.apply_transpose_at(q, sc, out);
        out[TH] += self.hub * qd[TH];
    }

    /// out = −Σ m Bᵀ[(∂(Bq̇)/∂q)q̇ + α̇J(X, Y)]: the inertia forces at q̈ = 0 (module docs).
    pub fn inertia_forces(&self, q: &[f64], qd: &[f64], sc: &mut PointScratch, out: &mut [f64]) {
        self.set_shape(q, sc);
        self.inertia_forces_at(q, qd, sc, out);
    }

    /// [`Self::inertia_forces`] with the shape of q already in `sc` ([`Self::set_shape`]):
    /// [`Self::point_velocities`]' dual pass along q̇ with the values of the slopes and of the
    /// axial positions from the shape and the slope of q̇ (the derivative part and the rate)
    /// taken once.
    pub fn inertia_forces_at(&self, q: &[f64], qd: &[f64], sc: &mut PointScratch, out: &mut [f64]) {
        let (v, vd) = (&q[self.iv()], &qd[self.iv()]);
        let (w, wd) = (&q[self.iw()], &qd[self.iw()]);
        let (thd, bed) = (qd[TH], qd[BE]);
        let (r1, r2, h1, h2) = (self.r1, self.r2, self.h1, self.h2);
        let PointScratch {
            x,
            y,
            fx,
            fy,
            shape,
            ..
        } = &mut *sc;
        let np = r1 + 1 + r2;
        let (xs, ys) = (&mut x[..np], &mut y[..np]);
        let (fx, fy) = (&mut fx[..np], &mut fy[..np]);
        let (g1, a1) = (&shape.g1[..r1], &shape.a1[..r1]);
        let (g2, a2) = (&shape.g2[..r2], &shape.a2[..r2]);
        let zero = Dual::default();
        let (mut s, mut sd) = (zero, zero);
        for k in 0..r1 {
            if self.fs1 {
                let gd = slope(vd, k, h1);
                let g = Dual::new(g1[k], gd);
                s = s + g * g * (0.5 * h1);
                sd = sd + g * (h1 * gd);
            }
            let vk = Dual::new(v[k], vd[k]);
            xs[k] = -(vk * thd) - sd;
            ys[k] = Dual::new(a1[k], 0.0 - s.du) * thd + vd[k];
        }
        let (ex, ey) = (xs[r1 - 1], ys[r1 - 1]);
        xs[r1] = ex;
        ys[r1] = ey;
        let phi = Dual::new(q[BE] - q[TH], qd[BE] - qd[TH]);
        let (sn, c) = (phi.sin(), phi.cos());
        let (xe, ye) = (c * ex + sn * ey, c * ey - sn * ex);
        let (mut sg, mut sgd) = (zero, zero);
        for j in 0..r2 {
            if self.fs2 {
                let gd = slope(wd, j, h2);
                let g = Dual::new(g2[j], gd);
                sg = sg + g * g * (0.5 * h2);
                sgd = sgd + g * (h2 * gd);
            }
            let wj = Dual::new(w[j], wd[j]);
            xs[r1 + 1 + j] = xe - wj * bed - sgd;
            ys[r1 + 1 + j] = ye + Dual::new(a2[j], 0.0 - sg.du) * bed + wd[j];
        }
        for p in 0..np {
            let rate = if p <= r1 { thd } else { bed };
            let m = self.point_mass(p);
            let (x, y) = (xs[p], ys[p]);
            fx[p] = -m * (x.du - rate * y.re);
            fy[p] = -m * (y.du + rate * x.re);
        }
        self.apply_transpose_at(q, sc, out);
    }

    /// [`Self::momenta_at`] of `C` velocities at once into `out` (its operations per lane):
    /// `rates` holds their deflection rates and slopes (the divisions
    /// [`Self::point_velocities`] takes, here supplied), `qds` the frame rates.
    pub fn momenta_lanes<const C: usize>(
        &self,
        q: &[f64],
        shape: &Shape,
        qds: [&[f64]; C],
        rates: &RateLanes<C>,
        lanes: &mut Lanes<C>,
        out: [&mut [f64]; C],
    ) {
        let (v, w) = (&q[self.iv()], &q[self.iw()]);
        let (r1, r2, h1, h2) = (self.r1, self.r2, self.h1, self.h2);
        let (vd, wd) = rates.rates[..r1 + r2].split_at(r1);
        let (gd1, gd2) = rates.slopes[..r1 + r2].split_at(r1);
        let thd: [f64; C] = std::array::from_fn(|c| qds[c][TH]);
        let bed: [f64; C] = std::array::from_fn(|c| qds[c][BE]);
        let np = r1 + 1 + r2;
        let (fx, fy) = (&mut lanes.fx[..np], &mut lanes.fy[..np]);
        let (g1, a1) = (&shape.g1[..r1], &shape.a1[..r1]);
        let (g2, a2) = (&shape.g2[..r2], &shape.a2[..r2]);
        let mut sd = [0.0; C];
        let (mut ex, mut ey) = ([0.0; C], [0.0; C]);
        for k in 0..r1 {
            let m = self.m1[k];
            if self.fs1 {
                for c in 0..C {
                    sd[c] += g1[k] * (h1 * gd1[k][c]);
                }
            }
            for c in 0..C {
                ex[c] = -(v[k] * thd[c]) - sd[c];
                ey[c] = a1[k] * thd[c] + vd[k][c];
                fx[k][c] = m * ex[c];
                fy[k][c] = m * ey[c];
            }
        }
        let m = self.elbow_mass;
        for c in 0..C {
            fx[r1][c] = m * ex[c];
            fy[r1][c] = m * ey[c];
        }
        let phi = q[BE] - q[TH];
        let (sn, cs) = (phi.sin(), phi.cos());
        let xe: [f64; C] = std::array::from_fn(|c| cs * ex[c] + sn * ey[c]);
        let ye: [f64; C] = std::array::from_fn(|c| cs * ey[c] - sn * ex[c]);
        let mut sgd = [0.0; C];
        for j in 0..r2 {
            let m = self.m2[j];
            if self.fs2 {
                for c in 0..C {
                    sgd[c] += g2[j] * (h2 * gd2[j][c]);
                }
            }
            for c in 0..C {
                let x = xe[c] - w[j] * bed[c] - sgd[c];
                let y = ye[c] + a2[j] * bed[c] + wd[j][c];
                fx[r1 + 1 + j][c] = m * x;
                fy[r1 + 1 + j][c] = m * y;
            }
        }
        let mut out = out;
        self.apply_transpose_lanes(q, shape, lanes, &mut out);
        for c in 0..C {
            out[c][TH] += self.hub * thd[c];
        }
    }

    /// [`Self::inertia_forces_at`] at `C` velocities at once into `out` (its operations per
    /// lane): `rates` holds their deflection rates and [`Self::rate_slopes`] lane by lane (the
    /// divisions [`Self::inertia_forces_at`] takes, here supplied), `qds` the frame rates.
    pub fn inertia_forces_lanes<const C: usize>(
        &self,
        q: &[f64],
        shape: &Shape,
        qds: [&[f64]; C],
        rates: &RateLanes<C>,
        lanes: &mut Lanes<C>,
        out: [&mut [f64]; C],
    ) {
        let (v, w) = (&q[self.iv()], &q[self.iw()]);
        let (r1, r2, h1, h2) = (self.r1, self.r2, self.h1, self.h2);
        let (vd, wd) = rates.rates[..r1 + r2].split_at(r1);
        let (gd1, gd2) = rates.slopes[..r1 + r2].split_at(r1);
        let thd: [f64; C] = std::array::from_fn(|c| qds[c][TH]);
        let bed: [f64; C] = std::array::from_fn(|c| qds[c][BE]);
        let np = r1 + 1 + r2;
        let (fx, fy) = (&mut lanes.fx[..np], &mut lanes.fy[..np]);
        let (g1, a1) = (&shape.g1[..r1], &shape.a1[..r1]);
        let (g2, a2) = (&shape.g2[..r2], &shape.a2[..r2]);
        // the dual numbers' parts lane by lane (re, du): s's real part is never read
        let (mut s_du, mut sd_re, mut sd_du) = ([0.0; C], [0.0; C], [0.0; C]);
        let (mut ex_re, mut ex_du, mut ey_re, mut ey_du) = ([0.0; C], [0.0; C], [0.0; C], [0.0; C]);
        for k in 0..r1 {
            let m = self.m1[k];
            if self.fs1 {
                foreshortening_lanes(g1[k], gd1[k], h1, &mut s_du, &mut sd_re, &mut sd_du);
            }
            let vdk = vd[k];
            ex_re = std::array::from_fn(|c| -(v[k] * thd[c]) - sd_re[c]);
            ex_du = std::array::from_fn(|c| -(vdk[c] * thd[c]) - sd_du[c]);
            ey_re = std::array::from_fn(|c| a1[k] * thd[c] + vdk[c]);
            ey_du = std::array::from_fn(|c| (0.0 - s_du[c]) * thd[c]);
            fx[k] = std::array::from_fn(|c| -m * (ex_du[c] - thd[c] * ey_re[c]));
            fy[k] = std::array::from_fn(|c| -m * (ey_du[c] + thd[c] * ex_re[c]));
        }
        let ex: [Dual; C] = std::array::from_fn(|c| Dual::new(ex_re[c], ex_du[c]));
        let ey: [Dual; C] = std::array::from_fn(|c| Dual::new(ey_re[c], ey_du[c]));
        let m = self.elbow_mass;
        for c in 0..C {
            let (x, y) = (ex[c], ey[c]);
            fx[r1][c] = -m * (x.du - thd[c] * y.re);
            fy[r1][c] = -m * (y.du + thd[c] * x.re);
        }
        let (mut xe_re, mut xe_du, mut ye_re, mut ye_du) = ([0.0; C], [0.0; C], [0.0; C], [0.0; C]);
        for c in 0..C {
            let phi = Dual::new(q[BE] - q[TH], qds[c][BE] - qds[c][TH]);
            let (sn, cs) = (phi.sin(), phi.cos());
            let xe = cs * ex[c] + sn * ey[c];
            let ye = cs * ey[c] - sn * ex[c];
            (xe_re[c], xe_du[c], ye_re[c], ye_du[c]) = (xe.re, xe.du, ye.re, ye.du);
        }
        let (mut sg_du, mut sgd_re, mut sgd_du) = ([0.0; C], [0.0; C], [0.0; C]);
        for j in 0..r2 {
            let m = self.m2[j];
            if self.fs2 {
                foreshortening_lanes(g2[j], gd2[j], h2, &mut sg_du, &mut sgd_re, &mut sgd_du);
            }
            let wdj = wd[j];
            let x_re: [f64; C] = std::array::from_fn(|c| xe_re[c] - w[j] * bed[c] - sgd_re[c]);
            let x_du: [f64; C] = std::array::from_fn(|c| xe_du[c] - wdj[c] * bed[c] - sgd_du[c]);
            let y_re: [f64; C] = std::array::from_fn(|c| ye_re[c] + a2[j] * bed[c] + wdj[c]);
            let y_du: [f64; C] = std::array::from_fn(|c| ye_du[c] + (0.0 - sg_du[c]) * bed[c]);
            fx[r1 + 1 + j] = std::array::from_fn(|c| -m * (x_du[c] - bed[c] * y_re[c]));
            fy[r1 + 1 + j] = std::array::from_fn(|c| -m * (y_du[c] + bed[c] * x_re[c]));
        }
        let mut out = out;
        self.apply_transpose_lanes(q, shape, lanes, &mut out);
    }

    /// [`Self::apply_transpose_at`] of `C` lanes of per-point forces at once.
    pub fn apply_transpose_lanes<const C: usize>(
        &self,
        q: &[f64],
        shape: &Shape,
        lanes: &mut Lanes<C>,
        out: &mut [&mut [f64]; C],
    ) {
        let (v, w) = (&q[self.iv()], &q[self.iw()]);
        let (r1, r2) = (self.r1, self.r2);
        let (sn, cs) = (q[BE] - q[TH]).sin_cos();
        let Lanes { fx, fy, c1, c2 } = lanes;
        let np = r1 + 1 + r2;
        let (fx, fy) = (&fx[..np], &fy[..np]);
        let (g1, a1) = (&shape.g1[..r1], &shape.a1[..r1]);
        let (g2, a2) = (&shape.g2[..r2], &shape.a2[..r2]);
        let (c1, c2) = (&mut c1[..r1], &mut c2[..r2]);
        let off = 2 + r1;
        let out: [&mut [f64]; C] = out.each_mut().map(|o| &mut o[..off + r2]);
        // link 2: β, the rates ẇ, the outboard sums of −fx for σ̇, the elbow force
        let mut qb = [0.0; C];
        let (mut gx, mut gy) = (fx[r1], fy[r1]);
        for j in 0..r2 {
            let (a, b) = (fx[r1 + 1 + j], fy[r1 + 1 + j]);
            let arm = a2[j];
            for c in 0..C {
                qb[c] += -a[c] * w[j] + b[c] * arm;
                out[c][off + j] = b[c];
                gx[c] += cs * a[c] - sn * b[c];
                gy[c] += sn * a[c] + cs * b[c];
            }
        }
        if self.fs2 {
            let mut acc = [0.0; C];
            for j in (0..r2).rev() {
                for c in 0..C {
                    acc[c] -= fx[r1 + 1 + j][c];
                }
                c2[j] = acc;
            }
            for j in 0..r2 {
                for c in 0..C {
                    let mut d = c2[j][c] * g2[j];
                    if j + 1 < r2 {
                        d -= c2[j + 1][c] * g2[j + 1];
                    }
                    out[c][off + j] += d;
                }
            }
        }
        // link 1 with the elbow force at its tip station
        let mut qt = [0.0; C];
        for k in 0..r1 {
            let (mut a, mut b) = (fx[k], fy[k]);
            if k == r1 - 1 {
                for c in 0..C {
                    a[c] += gx[c];
                    b[c] += gy[c];
                }
            }
            let arm = a1[k];
            for c in 0..C {
                qt[c] += -a[c] * v[k] + b[c] * arm;
                out[c][2 + k] = b[c];
            }
        }
        if self.fs1 {
            let mut acc: [f64; C] = std::array::from_fn(|c| -gx[c]);
            for k in (0..r1).rev() {
                for c in 0..C {
                    acc[c] -= fx[k][c];
                }
                c1[k] = acc;
            }
            for k in 0..r1 {
                for c in 0..C {
                    let mut d = c1[k][c] * g1[k];
                    if k + 1 < r1 {
                        d -= c1[k + 1][c] * g1[k + 1];
                    }
                    out[c][2 + k] += d;
                }
            }
        }
        for c in 0..C {
            out[c][TH] = qt[c];
            out[c][BE] = qb[c];
        }
    }
}

/// One segment's terms of the foreshortening sums lane by lane, slope g and slope rates gd
/// over a segment of length h: the rate part of s = ½h Σ g², and the value and rate parts of
/// ṡ = h Σ g ġ ([`ChainInertia::inertia_forces_lanes`]).
#[inline(always)]
fn foreshortening_lanes<const C: usize>(
    g: f64,
    gd: [f64; C],
    h: f64,
    s_du: &mut [f64; C],
    sd_re: &mut [f64; C],
    sd_du: &mut [f64; C],
) {
    for c in 0..C {
        s_du[c] += (g * gd[c] + gd[c] * g) * (0.5 * h);
        sd_re[c] += g * (h * gd[c]);
        sd_du[c] += gd[c] * (h * gd[c]);
    }
}
