//! Foreshortening of an inextensible lumped link and its exact inertia, in O(n).
//!
//! A link of stations 1…r (spacing h, clamp at station 0, v₀ = 0) with lumped masses mᵢ keeps
//! its arc length: station i sits at (xᵢ − sᵢ, vᵢ) in its frame, with
//!
//!   sᵢ = ½h Σ_{seg<i} g_seg²,   g_seg = (v_{seg+1} − v_seg)/h,
//!   ṡᵢ = (B v̇)ᵢ = Σ_{seg<i} g_seg (v̇_{seg+1} − v̇_seg),   B = ∂s/∂v = C G E,
//!   s̈ᵢ = (B v̈)ᵢ + cᵢ,   cᵢ = h Σ_{seg<i} ġ_seg²,
//!
//! where E is the bidiagonal difference (E u)_seg = u_{seg+1} − u_seg, G = diag(g) and C the
//! cumulative sum (C z)ᵢ = Σ_{seg<i} z_seg. The axial velocity ṡ makes the kinetic energy
//! ½Σm(ṡ² + …) carry the mass operator
//!
//!   A = diag(m) + Bᵀ diag(m) B = diag(m) + Pᵀ S P,   P = G E,   S = Cᵀ diag(m) C,
//!
//! dense in v (S_{ab} = Σ_{i ≥ max(a,b)} mᵢ, the outboard mass). Since E = C⁻¹,
//! S⁻¹ = E diag(m)⁻¹ Eᵀ =: T is tridiagonal, and with λ = S P u the system A u = f reads
//!
//!   diag(m) u + Pᵀ λ = f,   P u − T λ = 0   ⇒   (T + G T G) λ = G E diag(m)⁻¹ f,
//!   u = diag(m)⁻¹ (f − Eᵀ G λ).
//!
//! K = T + G T G (entries T_ab (1 + g_a g_b)) is tridiagonal and symmetric positive definite
//! (T is), so one LDLᵀ per state (O(r)) and O(r) per right-hand side solve A u = f exactly;
//! λ is the axial force the inextensibility constraint carries at each segment. No allocation
//! after construction.

// Index loops run over the slopes, the masses and the right-hand side together.
#![allow(clippy::needless_range_loop)]

use crate::tridiagonal::TridiagonalLdl;

/// The foreshortening kinematics of one link at one state, and the factorized mass operator A.
#[derive(Debug, Clone)]
pub struct Foreshortening {
    h: f64,
    /// station masses mᵢ (index k ↔ station k+1)
    m: Vec<f64>,
    /// g_seg
    pub g: Vec<f64>,
    /// ġ_seg
    pub gd: Vec<f64>,
    /// sᵢ
    pub s: Vec<f64>,
    /// ṡᵢ
    pub sd: Vec<f64>,
    /// cᵢ = h Σ_{seg<i} ġ² (the velocity part of s̈)
    pub c: Vec<f64>,
    /// LDLᵀ of K
    ldl: TridiagonalLdl,
    /// scratch of a solve
    lam: Vec<f64>,
}

impl Foreshortening {
    /// A link with spacing `h` and station masses `m` (all positive).
    pub fn new(h: f64, m: &[f64]) -> Self {
        let r = m.len();
        Foreshortening {
            h,
            m: m.to_vec(),
            g: vec![0.0; r],
            gd: vec![0.0; r],
            s: vec![0.0; r],
            sd: vec![0.0; r],
            c: vec![0.0; r],
            ldl: TridiagonalLdl::new(r),
            lam: vec![0.0; r],
        }
    }

    fn at(u: &[f64], station: usize) -> f64 {
        if station == 0 { 0.0 } else { u[station - 1] }
    }

    /// g, ġ, s, ṡ and c at deflections `v` and rates `vd`.
    pub fn set_state(&mut self, v: &[f64], vd: &[f64]) {
        let h = self.h;
        let (mut s, mut sd, mut c) = (0.0, 0.0, 0.0);
        for seg in 0..self.m.len() {
            let g = (v[seg] - Self::at(v, seg)) / h;
            let gd = (vd[seg] - Self::at(vd, seg)) / h;
            self.g[seg] = g;
            self.gd[seg] = gd;
            s += 0.5 * h * g * g;
            sd += h * g * gd;
            c += h * gd * gd;
            self.s[seg] = s;
            self.sd[seg] = sd;
            self.c[seg] = c;
        }
    }

    /// out = Bᵀ y (B at the last [`Self::set_state`]): the generalized force of axial loads y.
    pub fn bt_mul(&self, y: &[f64], out: &mut [f64]) {
        // (Cᵀ y)_seg = Σ_{i > seg} yᵢ (suffix sum), then Eᵀ G: out_k = g_k z_k − g_{k+1} z_{k+1}
        let r = self.m.len();
        let mut z_next = 0.0; // g_{k+1} z_{k+1}
        let mut suffix = 0.0;
        for k in (0..r).rev() {
            suffix += y[k];
            let gz = self.g[k] * suffix;
            out[k] = gz - z_next;
            z_next = gz;
        }
    }

    /// out += scale · Bᵀ y.
    pub fn bt_mul_add(&self, y: &[f64], scale: f64, out: &mut [f64]) {
        let r = self.m.len();
        let mut z_next = 0.0;
        let mut suffix = 0.0;
        for k in (0..r).rev() {
            suffix += y[k];
            let gz = self.g[k] * suffix;
            out[k] += scale * (gz - z_next);
            z_next = gz;
        }
    }

    /// Factorizes K = T + G T G at the slopes of the last [`Self::set_state`].
    pub fn factor(&mut self) {
        let (m, g) = (&self.m, &self.g);
        // T_kk = 1/m_k + 1/m_{k−1} (k ≥ 1), T_00 = 1/m_0; T_{k−1,k} = −1/m_{k−1}
        let diag = |k: usize| {
            let mut t_kk = 1.0 / m[k];
            if k > 0 {
                t_kk += 1.0 / m[k - 1];
            }
            t_kk * (1.0 + g[k] * g[k])
        };
        let off = |k: usize| -(1.0 + g[k] * g[k + 1]) / m[k];
        // T is positive definite for positive masses and G T G semi-definite: a pivot fails
        // only on non-finite slopes, which the run's finiteness checks report.
        let _ = self.ldl.factor(diag, off);
    }

    /// out = A⁻¹ f with the factor of the last [`Self::factor`].
    pub fn solve(&mut self, f: &[f64], out: &mut [f64]) {
        let r = self.m.len();
        // b = G E diag(m)⁻¹ f
        let mut w_prev = 0.0;
        for k in 0..r {
            let w = f[k] / self.m[k];
            self.lam[k] = self.g[k] * (w - w_prev);
            w_prev = w;
        }
        self.ldl.solve_in_place(&mut self.lam);
        // u = diag(m)⁻¹ (f − Eᵀ G λ),  (Eᵀ G λ)_k = g_k λ_k − g_{k+1} λ_{k+1}
        for k in 0..r {
            let mut egl = self.g[k] * self.lam[k];
            if k + 1 < r {
                egl -= self.g[k + 1] * self.lam[k + 1];
            }
            out[k] = (f[k] - egl) / self.m[k];
        }
    }

    /// out = A x (for checks; O(r)).
    pub fn mass_mul(&self, x: &[f64], out: &mut [f64]) {
        // B x = C G E x, then Bᵀ diag(m) B x
        let r = self.m.len();
        let mut acc = 0.0;
        let mut mbx = vec![0.0; r];
        for k in 0..r {
            acc += self.g[k] * (x[k] - Self::at(x, k));
            mbx[k] = self.m[k] * acc;
        }
        self.bt_mul(&mbx, out);
        for k in 0..r {
            out[k] += self.m[k] * x[k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A u = f solved through the tridiagonal λ system equals a dense solve of
    /// diag(m) + Bᵀ diag(m) B built from B = ∂s/∂v by central differences of s(v).
    #[test]
    fn elem_foreshortening_mass_solve_matches_dense() {
        use faer::Mat;
        use faer::prelude::Solve;
        let r = 12;
        let h = 0.25;
        let mut m: Vec<f64> = (0..r).map(|k| 0.7 + 0.05 * k as f64).collect();
        m[r - 1] = 0.35 + 2.0; // half station + tip mass
        let v: Vec<f64> = (1..=r)
            .map(|i| 0.3 * (0.4 * i as f64).sin() + 0.02 * (i * i) as f64)
            .collect();
        let vd = vec![0.0; r];
        let mut fs = Foreshortening::new(h, &m);
        fs.set_state(&v, &vd);
        fs.factor();
        let s_of = |v: &[f64]| {
            let mut probe = Foreshortening::new(h, &m);
            probe.set_state(v, &vec![0.0; r]);
            probe.s.clone()
        };
        // B by central differences (s is quadratic in v: exact to round-off)
        let eps = 1e-4;
        let mut b = Mat::<f64>::zeros(r, r);
        for j in 0..r {
            let (mut p, mut q) = (v.clone(), v.clone());
            p[j] += eps;
            q[j] -= eps;
            let (sp, sq) = (s_of(&p), s_of(&q));
            for i in 0..r {
                b[(i, j)] = (sp[i] - sq[i]) / (2.0 * eps);
            }
        }
        let mut a = Mat::<f64>::zeros(r, r);
        for i in 0..r {
            for j in 0..r {
                a[(i, j)] = (0..r).map(|k| b[(k, i)] * m[k] * b[(k, j)]).sum::<f64>();
            }
            a[(i, i)] += m[i];
        }
        let f: Vec<f64> = (0..r).map(|k| (1.3 * k as f64).cos() + 0.1).collect();
        let fm = Mat::<f64>::from_fn(r, 1, |i, _| f[i]);
        let dense = a.partial_piv_lu().solve(&fm);
        let mut u = vec![0.0; r];
        fs.solve(&f, &mut u);
        let scale = (0..r).map(|i| dense[(i, 0)].abs()).fold(0.0, f64::max);
        for i in 0..r {
            assert!(
                (u[i] - dense[(i, 0)]).abs() < 1e-10 * scale,
                "{i}: {} vs {}",
                u[i],
                dense[(i, 0)]
            );
        }
        // and the O(r) product is the dense one
        let mut au = vec![0.0; r];
        fs.mass_mul(&u, &mut au);
        for i in 0..r {
            assert!((au[i] - f[i]).abs() < 1e-10 * (1.0 + f[i].abs()));
        }
        // the coupling is real: A differs from diag(m) by far more than round-off
        let off: f64 = (0..r)
            .map(|i| (u[i] - f[i] / m[i]).abs())
            .fold(0.0, f64::max);
        assert!(off > 1e-3 * scale, "{off}");
    }
}
