//! Assumed-mode shape functions of one link, in the physical coordinate x ∈ [0, L].
//!
//! * `poly` — the span of (x/L)², (x/L)³, …, (x/L)ⁿ⁺¹ (seed 000 eq. 49), represented by the
//!   better-conditioned equivalent basis ξ²·Pₖ(2ξ − 1) (shifted Legendre polynomials), each
//!   normalized to ∫₀¹ φ² dξ = 1. Same Ritz space, so the same Rayleigh–Ritz frequencies.
//! * `clamped-free` / `tip-mass` — cantilever eigenfunctions (with tip mass M and tip inertia J
//!   for `tip-mass`) written as φ(ξ) = A e^{−βξ} + B e^{β(ξ−1)} + C cos βξ + D sin βξ: every term
//!   is bounded by 1 on [0, 1], so the evaluation keeps full precision for any n (the textbook
//!   cosh − cos − σ(sinh − sin) form cancels catastrophically, losing all digits by n ≈ 12).
//!   The roots β of the frequency determinant (4×4, entries bounded) are bracketed by a scan
//!   and bisected to machine precision; (A, B, C, D) is the adjugate null vector.
//!   Normalization: ∫₀¹ φ² dξ + μ φ(1)² + j φ'(1)² = 1 with μ = M/(ρAL), j = J/(ρAL³), φ(1) > 0.
//! * axial shapes: √2 sin((2k−1)πξ/2) (clamped-free bar modes) or ξ·Pₖ(2ξ − 1) for `poly`.

pub mod quadrature;

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum BasisError {
    #[error("eigenvalue search failed: found {found} of {wanted} roots of the frequency equation")]
    RootSearch { found: usize, wanted: usize },
}

#[derive(Debug, Clone)]
enum Kind {
    /// ξ²·Pₖ(2ξ−1) / norm.
    Poly { scale: Vec<f64> },
    /// ξ·Pₖ(2ξ−1) / norm (axial).
    AxialPoly { scale: Vec<f64> },
    /// √2 sin((2k−1)πξ/2).
    AxialSine,
    /// Beam eigenfunctions: β and (A, B, C, D) per mode.
    Eigen { beta: Vec<f64>, coef: Vec<[f64; 4]> },
    /// Timoshenko field built on an eigenfunction basis: with `linear`, shape 0 is √3·ξ (a root
    /// shear strain / linear rotation); the others are the base's φₖ, or with `derivative` its
    /// (L/βₖ)·φₖ'.
    Augmented {
        base: Box<ShapeSet>,
        derivative: bool,
        linear: bool,
    },
}

/// n shape functions on [0, L] with derivatives up to order 2 (3 for eigenfunctions).
#[derive(Debug, Clone)]
pub struct ShapeSet {
    length: f64,
    count: usize,
    kind: Kind,
}

impl ShapeSet {
    pub fn count(&self) -> usize {
        self.count
    }

    pub fn length(&self) -> f64 {
        self.length
    }

    /// Largest nondimensional wavenumber of the set (sets the quadrature density).
    pub fn max_wavenumber(&self) -> f64 {
        match &self.kind {
            Kind::Eigen { beta, .. } => beta.last().copied().unwrap_or(1.0),
            Kind::AxialSine => (2.0 * self.count as f64 - 1.0) * std::f64::consts::FRAC_PI_2,
            Kind::Augmented { base, .. } => base.max_wavenumber().max(1.0),
            // A polynomial of degree d oscillates like a wave of wavenumber ≈ d.
            Kind::Poly { .. } | Kind::AxialPoly { .. } => self.count as f64 + 2.0,
        }
    }

    /// Eigenvalue parameters βₖ (eigenfunction bases only): ωₖ = βₖ² sqrt(EI/(ρAL⁴)).
    pub fn betas(&self) -> Option<&[f64]> {
        match &self.kind {
            Kind::Eigen { beta, .. } => Some(beta),
            _ => None,
        }
    }

    pub fn poly(length: f64, count: usize) -> Self {
        let mut s = ShapeSet {
            length,
            count,
            kind: Kind::Poly {
                scale: vec![1.0; count],
            },
        };
        let scale = s.unit_norms();
        s.kind = Kind::Poly { scale };
        s
    }

    pub fn axial_poly(length: f64, count: usize) -> Self {
        let mut s = ShapeSet {
            length,
            count,
            kind: Kind::AxialPoly {
                scale: vec![1.0; count],
            },
        };
        let scale = s.unit_norms();
        s.kind = Kind::AxialPoly { scale };
        s
    }

    pub fn axial_sine(length: f64, count: usize) -> Self {
        ShapeSet {
            length,
            count,
            kind: Kind::AxialSine,
        }
    }

    pub fn clamped_free(length: f64, count: usize) -> Result<Self, BasisError> {
        Self::tip_mass(length, count, 0.0, 0.0)
    }

    /// Eigenfunctions of the cantilever carrying tip mass ratio μ = M/(ρAL) and tip inertia
    /// ratio j = J/(ρAL³).
    pub fn tip_mass(length: f64, count: usize, mu: f64, j: f64) -> Result<Self, BasisError> {
        let beta = frequency_roots(count, mu, j)?;
        let mut coef = Vec::with_capacity(count);
        for &b in &beta {
            coef.push(null_vector(&bc_matrix(b, mu, j)));
        }
        let mut s = ShapeSet {
            length,
            count,
            kind: Kind::Eigen {
                beta: beta.clone(),
                coef,
            },
        };
        // Normalize with the tip terms included, and fix the sign by φ(1) > 0.
        let quad = quadrature::Quadrature::for_wavenumber(1.0, s.max_wavenumber());
        let mut v = vec![0.0; count];
        let mut d = vec![0.0; count];
        let mut norms = vec![0.0; count];
        let unit = ShapeSet {
            length: 1.0,
            ..s.clone()
        };
        for (x, w) in quad.x.iter().zip(&quad.w) {
            unit.eval(*x, 0, &mut v);
            for k in 0..count {
                norms[k] += w * v[k] * v[k];
            }
        }
        unit.eval(1.0, 0, &mut v);
        unit.eval(1.0, 1, &mut d);
        if let Kind::Eigen { coef, .. } = &mut s.kind {
            for k in 0..count {
                let n2 = norms[k] + mu * v[k] * v[k] + j * d[k] * d[k];
                let sign = if v[k] < 0.0 { -1.0 } else { 1.0 };
                let f = sign / n2.sqrt();
                for c in coef[k].iter_mut() {
                    *c *= f;
                }
            }
        }
        Ok(s)
    }

    /// The (v, ψ) shape pair of a Timoshenko link built on a cantilever eigenfunction basis
    /// (`base`, n − 1 functions): v ∈ span{ξ, φ₁, …, φₙ₋₁}, ψ ∈ span{ξ, φ₁', …, φₙ₋₁'}.
    /// The ξ in v carries the root shear strain v'(0) = γ(0) ≠ 0 that every φₖ (φₖ'(0) = 0)
    /// lacks; ψ contains every φₖ', so the κGA → ∞ limit ψ = v' is the Euler model on
    /// {φ₁, …, φₙ₋₁} (no shear locking).
    ///
    /// Without `root_shear` the pair is v ∈ span{φ₁, …, φₙ}, ψ ∈ span{φ₁', …, φₙ'} (n = base
    /// count): the frame keeps v'(0) = 0 (see [`crate::model::section`] for when that is used).
    pub fn timoshenko_eigen_pair(base: ShapeSet, root_shear: bool) -> (ShapeSet, ShapeSet) {
        let length = base.length;
        let count = base.count + usize::from(root_shear);
        let make = |derivative: bool| ShapeSet {
            length,
            count,
            kind: Kind::Augmented {
                base: Box::new(base.clone()),
                derivative,
                linear: root_shear,
            },
        };
        let psi = make(true);
        (make(false), psi)
    }

    /// Writes d^deriv φₖ/dx^deriv at x for all k.
    pub fn eval(&self, x: f64, deriv: usize, out: &mut [f64]) {
        let l = self.length;
        let xi = x / l;
        let dscale = l.powi(-(deriv as i32));
        match &self.kind {
            Kind::Augmented {
                base,
                derivative,
                linear,
            } => {
                let first = usize::from(*linear);
                if *linear {
                    let s3 = 3f64.sqrt();
                    out[0] = match deriv {
                        0 => s3 * xi,
                        1 => s3 / l,
                        _ => 0.0,
                    };
                }
                if self.count > first {
                    let rest = &mut out[first..self.count];
                    if *derivative {
                        base.eval(x, deriv + 1, rest);
                        if let Kind::Eigen { beta, .. } = &base.kind {
                            for (o, b) in rest.iter_mut().zip(beta) {
                                *o *= l / b;
                            }
                        }
                    } else {
                        base.eval(x, deriv, rest);
                    }
                }
            }
            Kind::Eigen { beta, coef } => {
                for (k, o) in out.iter_mut().enumerate().take(self.count) {
                    let b = beta[k];
                    let [a, bb, c, d] = coef[k];
                    let em = (-b * xi).exp();
                    let ep = (b * (xi - 1.0)).exp();
                    let (s, co) = (b * xi).sin_cos();
                    let bm = b.powi(deriv as i32);
                    let sgn = if deriv.is_multiple_of(2) { 1.0 } else { -1.0 };
                    // d^m/dξ^m of cos and sin cycle with period 4.
                    let (tc, ts) = match deriv % 4 {
                        0 => (co, s),
                        1 => (-s, co),
                        2 => (-co, -s),
                        _ => (s, -co),
                    };
                    *o = bm * (a * sgn * em + bb * ep + c * tc + d * ts) * dscale;
                }
            }
            Kind::AxialSine => {
                for (k, o) in out.iter_mut().enumerate().take(self.count) {
                    let kk = (2.0 * k as f64 + 1.0) * std::f64::consts::FRAC_PI_2;
                    let (s, c) = (kk * xi).sin_cos();
                    let v = match deriv {
                        0 => s,
                        1 => kk * c,
                        2 => -kk * kk * s,
                        _ => -kk * kk * kk * c,
                    };
                    *o = std::f64::consts::SQRT_2 * v * dscale;
                }
            }
            Kind::Poly { scale } | Kind::AxialPoly { scale } => {
                let power = if matches!(self.kind, Kind::Poly { .. }) {
                    2
                } else {
                    1
                };
                // Shifted Legendre P(s), s = 2ξ − 1, with dP/dξ and d²P/dξ² by recurrence.
                let s = 2.0 * xi - 1.0;
                let (mut p0, mut p1) = (1.0, s);
                let (mut d0, mut d1) = (0.0, 2.0);
                let (mut dd0, mut dd1) = (0.0, 0.0);
                for (k, o) in out.iter_mut().enumerate().take(self.count) {
                    let (p, dp, ddp) = if k == 0 {
                        (p0, d0, dd0)
                    } else if k == 1 {
                        (p1, d1, dd1)
                    } else {
                        let kf = (k - 1) as f64;
                        let p2 = ((2.0 * kf + 1.0) * s * p1 - kf * p0) / (kf + 1.0);
                        let d2 = ((2.0 * kf + 1.0) * (2.0 * p1 + s * d1) - kf * d0) / (kf + 1.0);
                        let dd2 = ((2.0 * kf + 1.0) * (4.0 * d1 + s * dd1) - kf * dd0) / (kf + 1.0);
                        (p0, p1, d0, d1, dd0, dd1) = (p1, p2, d1, d2, dd1, dd2);
                        (p2, d2, dd2)
                    };
                    // ξ^m · P and its derivatives (Leibniz).
                    let v = if power == 2 {
                        match deriv {
                            0 => xi * xi * p,
                            1 => 2.0 * xi * p + xi * xi * dp,
                            _ => 2.0 * p + 4.0 * xi * dp + xi * xi * ddp,
                        }
                    } else {
                        match deriv {
                            0 => xi * p,
                            1 => p + xi * dp,
                            _ => 2.0 * dp + xi * ddp,
                        }
                    };
                    *o = scale[k] * v * dscale;
                }
            }
        }
    }

    /// 1/sqrt(∫₀¹ φ² dξ) per shape (for the polynomial bases).
    fn unit_norms(&self) -> Vec<f64> {
        let unit = ShapeSet {
            length: 1.0,
            ..self.clone()
        };
        let quad = quadrature::Quadrature::composite(1.0, 8, 16);
        let mut v = vec![0.0; self.count];
        let mut n = vec![0.0; self.count];
        for (x, w) in quad.x.iter().zip(&quad.w) {
            unit.eval(*x, 0, &mut v);
            for k in 0..self.count {
                n[k] += w * v[k] * v[k];
            }
        }
        n.iter().map(|v| 1.0 / v.sqrt()).collect()
    }
}

/// Boundary-condition matrix for (A, B, C, D), each row scaled to O(1).
fn bc_matrix(b: f64, mu: f64, j: f64) -> [[f64; 4]; 4] {
    let e = (-b).exp();
    let (s, c) = b.sin_cos();
    // Values at ξ = 1 of φ, φ'/β, φ''/β², φ'''/β³ for each basis term.
    let f0 = [e, 1.0, c, s];
    let f1 = [-e, 1.0, -s, c];
    let f2 = [e, 1.0, -c, -s];
    let f3 = [-e, 1.0, s, -c];
    let jb = j * b * b * b;
    let mb = mu * b;
    let mut m = [[1.0, e, 1.0, 0.0], [-1.0, e, 0.0, 1.0], [0.0; 4], [0.0; 4]];
    for k in 0..4 {
        // EI φ'' = ω² J φ'  →  f2 − jβ³ f1 = 0;   EI φ''' = −ω² M φ  →  f3 + μβ f0 = 0.
        m[2][k] = (f2[k] - jb * f1[k]) / (1.0 + jb);
        m[3][k] = (f3[k] + mb * f0[k]) / (1.0 + mb);
    }
    m
}

fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn minor(m: &[[f64; 4]; 4], r: usize, c: usize) -> f64 {
    let mut s = [[0.0; 3]; 3];
    let mut ii = 0;
    for (i, row) in m.iter().enumerate() {
        if i == r {
            continue;
        }
        let mut jj = 0;
        for (k, v) in row.iter().enumerate() {
            if k == c {
                continue;
            }
            s[ii][jj] = *v;
            jj += 1;
        }
        ii += 1;
    }
    det3(s)
}

fn det4(m: &[[f64; 4]; 4]) -> f64 {
    (0..4)
        .map(|c| {
            let sign = if c % 2 == 0 { 1.0 } else { -1.0 };
            sign * m[0][c] * minor(m, 0, c)
        })
        .sum()
}

/// Null vector of a (numerically) singular 4×4 matrix: the largest row of cofactors.
fn null_vector(m: &[[f64; 4]; 4]) -> [f64; 4] {
    let mut best = [0.0; 4];
    let mut best_norm = -1.0;
    for r in 0..4 {
        let mut v = [0.0; 4];
        for (c, vc) in v.iter_mut().enumerate() {
            let sign = if (r + c) % 2 == 0 { 1.0 } else { -1.0 };
            *vc = sign * minor(m, r, c);
        }
        let n: f64 = v.iter().map(|x| x * x).sum();
        if n > best_norm {
            best_norm = n;
            best = v;
        }
    }
    best
}

/// The first `count` positive roots β of the cantilever (tip mass/inertia) frequency equation.
pub fn frequency_roots(count: usize, mu: f64, j: f64) -> Result<Vec<f64>, BasisError> {
    let f = |b: f64| det4(&bc_matrix(b, mu, j));
    let mut roots = Vec::with_capacity(count);
    let mut b0 = 1e-2;
    let mut f0 = f(b0);
    let b_end = (count as f64 + 2.0) * std::f64::consts::PI + 10.0;
    while roots.len() < count && b0 < b_end {
        let db = if b0 < 3.0 { 0.01 } else { 0.05 };
        let b1 = b0 + db;
        let f1 = f(b1);
        if f0 == 0.0 {
            roots.push(b0);
        } else if f0 * f1 < 0.0 {
            roots.push(bisect(&f, b0, b1));
        }
        b0 = b1;
        f0 = f1;
    }
    if roots.len() < count {
        return Err(BasisError::RootSearch {
            found: roots.len(),
            wanted: count,
        });
    }
    Ok(roots)
}

/// Bisection to adjacent floating-point numbers (|Δβ| ≤ 1 ulp ≈ 1e-16 relative).
pub fn bisect(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let mut fa = f(a);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = f(m);
        if fm == 0.0 {
            return m;
        }
        if (fa < 0.0) == (fm < 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Reference cantilever roots from cos β cosh β + 1 = 0, written stably as
/// cos β + 1/cosh β = 0 (an independent path from the 4×4 determinant used by the basis).
pub fn clamped_free_reference_roots(count: usize) -> Vec<f64> {
    let f = |b: f64| b.cos() + 1.0 / b.cosh();
    (0..count)
        .map(|k| {
            // The k-th root lies in ((k + 1/2)π − 0.6, (k + 1/2)π + 0.6) … bracket around it.
            let c = (k as f64 + 0.5) * std::f64::consts::PI;
            let (mut a, mut b) = (c - 1.0, c + 1.0);
            if k == 0 {
                a = 1.0;
                b = 2.5;
            }
            if f(a) * f(b) > 0.0 {
                a = c - 1.5;
                b = c + 1.5;
            }
            bisect(&f, a, b)
        })
        .collect()
}
