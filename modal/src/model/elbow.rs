//! A free joint i+1 whose parent link i is a condensed Timoshenko link (massless section
//! rotations ψ = χᵀc, [`super::section`]): the condensation of c that includes the elbow.
//!
//! The joint acts on link i's tip cross-section: with θ the joint angle (between the tip
//! section and link i+1), the elbow spring ½K(θ − θ₀)², damper ½Dθ̇² and applied torque τ
//! turn that section. If θ stayed the coordinate, link i+1's frame angle αᵢ + ψᵢ(Lᵢ) + θ would
//! depend on c, c would carry link i+1's inertia and could not be condensed. The coordinate
//! is therefore the angle between the two link frames, φ = ψᵢ(Lᵢ) + θ, so that αᵢ₊₁ = αᵢ + φ
//! is free of c, c stays massless, and θ = φ − χᵀc (χ = χ(L) below). At t = 0 the centre
//! lines are straight at the scene's angles, so φ(0) = θ(0) and the sections settle from
//! there. Everything that reports or books the joint (angle, rate, torque channels, spring
//! energy, damper and applied power) uses θ, θ̇. With s = φ − θ₀ the potential is
//!
//!   V = ½bᵀK_bb b + bᵀK_bc c + ½cᵀK_cc c + ½K(s − χᵀc)² − τ(φ − χᵀc),
//!
//! and c minimizes it: A c = −K_cb b + Kχ s − χτ, A = K_cc + Kχχᵀ, i.e.
//! c = T b + t s + g τ with T = −A⁻¹K_cb, t = K A⁻¹χ, g = −A⁻¹χ (τ is piecewise constant in
//! time, so ċ = T ḃ + t φ̇ almost everywhere; at its jumps c jumps and the ledger books the
//! jump's work and loss, [`Elbow::book_torque_steps`]). By the envelope theorem the generalized forces
//! are those of V at fixed c: f_b = −(K_bb b + K_bc c), f_φ = τ − K(θ − θ₀); the stiffness over
//! x = (b, φ) is the Schur complement H = [[K_bb + K_bc T, K_bc t], [·, K(1 − χᵀt)]], exact.
//!
//! Dampers (Kelvin–Voigt D_cc on ψ', joint damper D on θ) are taken to first order, as the
//! per-link condensation takes Kelvin–Voigt: the dissipation is evaluated on the condensed
//! rates ċ = J ẋ, J = [T, t], θ̇ = wᵀẋ, w = e_φ − Jᵀχ, giving the damping matrix
//! D_eff = JᵀD_cc J + D w wᵀ. This is the first term of the slow-manifold expansion of the damped
//! balance (D_cc + Dχχᵀ)ċ + A c = −K_cb b + Kχ s + Dχφ̇ − χτ: its correction
//! c₁ = A⁻¹[Dχφ̇ − (D_cc + Dχχᵀ)J ẋ] enters the forces as JᵀA c₁, which with the dampers' own
//! forces sums to −D_eff ẋ; the terms left out are smaller by ω/r, r the relaxation rates of c
//! (eigenvalues of (D_cc + Dχχᵀ)⁻¹A; for the joint damper r ≈ √(EI·κGA)/D, 3.5·10³ s⁻¹ at
//! D = 20 on `barhorst-case1-timoshenko`). Without dampers the condensation is exact. The
//! reported joint angle includes the first-order lag −χᵀc₁ ([`Elbow::angle_lag`]): the section's
//! quasi-static turn under the damper's moment, which fem's integrated sections show.
//!
//! A prescribed joint after a condensed Timoshenko link keeps the per-link condensation
//! (θ the coordinate, αᵢ₊₁ = αᵢ + χᵀT b + θ): its actuator moment does not enter c's
//! balance.

use super::section::{CondensedBlocks, congruence};
use crate::linalg::{cholesky_factor, cholesky_substitute, dot};

/// The condensation of link `parent`'s ψ with the elbow of joint `parent + 1`.
#[derive(Debug, Clone)]
pub struct Elbow {
    pub parent: usize,
    pub nb: usize,
    pub nc: usize,
    /// K_bb, K_bc, K_cc, D_cc, χ(L) of the parent's bending block.
    pub blocks: CondensedBlocks,
    /// Elbow spring K, set point θ₀, damper D.
    pub stiffness: f64,
    pub set_point: f64,
    pub damping: f64,
    /// T (nc × nb), t (nc), g (nc): c = T b + t (φ − θ₀) + g τ.
    pub t_b: Vec<f64>,
    pub t_s: Vec<f64>,
    pub t_g: Vec<f64>,
    /// Condensed stiffness H over x = (b, φ) ((nb+1)², row-major).
    pub h: Vec<f64>,
    /// JᵀD_cc J over x ((nb+1)²; empty without Kelvin–Voigt).
    pub d_kv: Vec<f64>,
    /// θ̇ = wᵀẋ.
    pub w: Vec<f64>,
    /// c at the last evaluation.
    pub c: Vec<f64>,
    /// Steps of the applied torque law: (time, work τ₊Δθ, loss ½χᵀA⁻¹χ Δτ²) of each jump
    /// ([`Self::book_torque_steps`]).
    pub torque_steps: Vec<(f64, f64, f64)>,
}

impl Elbow {
    /// Builds the condensation (errors if A = K_cc + Kχχᵀ is not positive definite).
    pub fn new(
        parent: usize,
        nb: usize,
        blocks: &CondensedBlocks,
        stiffness: f64,
        set_point: f64,
        damping: f64,
    ) -> Result<Self, &'static str> {
        let nc = blocks.chi_l.len();
        let chi = &blocks.chi_l;
        let mut a = blocks.kcc.clone();
        for r in 0..nc {
            for c in 0..nc {
                a[r * nc + c] += stiffness * chi[r] * chi[c];
            }
        }
        cholesky_factor(&mut a, nc).map_err(|_| {
            "Timoshenko rotation stiffness with the elbow spring K_cc + Kχχᵀ is not positive definite"
        })?;
        let mut t_b = vec![0.0; nc * nb];
        let mut col = vec![0.0; nc];
        for j in 0..nb {
            // Column j of T: −A⁻¹ (K_cb)_{·j}, K_cb = K_bcᵀ.
            for k in 0..nc {
                col[k] = -blocks.kbc[j * nc + k];
            }
            cholesky_substitute(&a, nc, &mut col);
            for k in 0..nc {
                t_b[k * nb + j] = col[k];
            }
        }
        let mut t_g: Vec<f64> = chi.iter().map(|v| -v).collect();
        cholesky_substitute(&a, nc, &mut t_g);
        let t_s: Vec<f64> = t_g.iter().map(|v| -stiffness * v).collect();
        let nx = nb + 1;
        let mut h = vec![0.0; nx * nx];
        for r in 0..nb {
            for c in 0..nb {
                let mut s = blocks.kbb[r * nb + c];
                for k in 0..nc {
                    s += blocks.kbc[r * nc + k] * t_b[k * nb + c];
                }
                h[r * nx + c] = s;
            }
            let hs = dot(&blocks.kbc[r * nc..(r + 1) * nc], &t_s);
            h[r * nx + nb] = hs;
            h[nb * nx + r] = hs;
        }
        h[nb * nx + nb] = stiffness * (1.0 - dot(chi, &t_s));
        for r in 0..nb {
            for c in 0..r {
                let v = 0.5 * (h[r * nx + c] + h[c * nx + r]);
                h[r * nx + c] = v;
                h[c * nx + r] = v;
            }
        }
        // J = [T, t] (nc × nx); w = e_φ − Jᵀχ.
        let jac = |k: usize, j: usize| if j < nb { t_b[k * nb + j] } else { t_s[k] };
        let mut w = vec![0.0; nx];
        for (j, wj) in w.iter_mut().enumerate() {
            *wj =
                if j == nb { 1.0 } else { 0.0 } - (0..nc).map(|k| chi[k] * jac(k, j)).sum::<f64>();
        }
        let d_kv = if blocks.dcc.is_empty() {
            Vec::new()
        } else {
            congruence(jac, &blocks.dcc, nc, nx, 1.0)
        };
        Ok(Elbow {
            parent,
            nb,
            nc,
            blocks: blocks.clone(),
            stiffness,
            set_point,
            damping,
            t_b,
            t_s,
            t_g,
            h,
            d_kv,
            w,
            c: vec![0.0; nc],
            torque_steps: Vec::new(),
        })
    }

    /// The tip section's compliance at the joint with b held, s = χᵀA⁻¹χ = −χᵀg: the turn of
    /// θ per unit moment (the boundary layer in parallel with the elbow spring).
    pub fn compliance(&self) -> f64 {
        -dot(&self.blocks.chi_l, &self.t_g)
    }

    /// Records the jumps of a piecewise-constant torque law. At a jump Δτ the condensed c jumps
    /// by gΔτ at fixed (b, φ), so θ jumps by Δθ = χᵀA⁻¹χ Δτ; the torque after the jump does the
    /// work τ₊Δθ and, since c minimizes the new potential, the stored energy changes by
    /// τ₊Δθ − ½ΔcᵀAΔc: the difference ½χᵀA⁻¹χ Δτ² is what the section's relaxation through
    /// its dampers dissipates (the split between joint damper and Kelvin–Voigt is not
    /// resolved).
    pub fn book_torque_steps(&mut self, law: &data::scene::TorqueLaw) {
        let s = self.compliance();
        let mut prev = 0.0;
        for tb in law.breakpoints() {
            if tb <= prev {
                continue;
            }
            let (before, after) = (law.torque(0.5 * (prev + tb)), law.torque(tb));
            let d = after - before;
            self.torque_steps.push((tb, after * s * d, 0.5 * s * d * d));
            prev = tb;
        }
    }

    /// Work and loss of the torque jumps at times ≤ t.
    pub fn torque_step_books(&self, t: f64) -> (f64, f64) {
        self.torque_steps
            .iter()
            .filter(|st| st.0 <= t)
            .fold((0.0, 0.0), |(w, l), st| (w + st.1, l + st.2))
    }

    /// c = T b + t (φ − θ₀) + g τ, stored.
    pub fn condense(&mut self, b: &[f64], phi: f64, tau: f64) {
        let s = phi - self.set_point;
        for k in 0..self.nc {
            self.c[k] = dot(&self.t_b[k * self.nb..(k + 1) * self.nb], b)
                + self.t_s[k] * s
                + self.t_g[k] * tau;
        }
    }

    /// Joint angle θ = φ − χ(L)ᵀc (after [`Self::condense`]).
    pub fn angle(&self, phi: f64) -> f64 {
        phi - dot(&self.blocks.chi_l, &self.c)
    }

    /// First-order lag of θ behind its quasi-static value: −χᵀc₁ with
    /// c₁ = A⁻¹[Dχφ̇ − (D_cc + Dχχᵀ)Jẋ] (module docs), i.e. −s·Dθ̇ − gᵀD_cc Jẋ with
    /// s the [`Self::compliance`].
    pub fn angle_lag(&self, bd: &[f64], phid: f64) -> f64 {
        let s = self.compliance();
        let mut lag = -s * self.damping * self.rate(bd, phid);
        if !self.blocks.dcc.is_empty() {
            let nc = self.nc;
            for k in 0..nc {
                // ċ₀ₖ = (J ẋ)ₖ, and gᵀD_cc ċ₀ column by column (no allocation)
                let cdk = dot(&self.t_b[k * self.nb..(k + 1) * self.nb], bd) + self.t_s[k] * phid;
                let gd: f64 = (0..nc)
                    .map(|r| self.t_g[r] * self.blocks.dcc[r * nc + k])
                    .sum();
                lag -= gd * cdk;
            }
        }
        lag
    }

    /// Joint rate θ̇ = wᵀẋ.
    pub fn rate(&self, bd: &[f64], phid: f64) -> f64 {
        dot(&self.w[..self.nb], bd) + self.w[self.nb] * phid
    }

    /// Kelvin–Voigt power ẋᵀJᵀD_cc J ẋ (0 without Kelvin–Voigt) and its row (D_kv ẋ)_r.
    pub fn kv_row(&self, r: usize, bd: &[f64], phid: f64) -> f64 {
        if self.d_kv.is_empty() {
            return 0.0;
        }
        let nx = self.nb + 1;
        let row = &self.d_kv[r * nx..(r + 1) * nx];
        dot(&row[..self.nb], bd) + row[self.nb] * phid
    }

    /// Strain energy ½bᵀK_bb b + bᵀK_bc c + ½cᵀK_cc c of the parent's bending block.
    pub fn strain(&self, b: &[f64]) -> f64 {
        let (nb, nc) = (self.nb, self.nc);
        let k = &self.blocks;
        let mut e = 0.0;
        for r in 0..nb {
            e += b[r]
                * (0.5 * dot(&k.kbb[r * nb..(r + 1) * nb], b)
                    + dot(&k.kbc[r * nc..(r + 1) * nc], &self.c));
        }
        for r in 0..nc {
            e += 0.5 * self.c[r] * dot(&k.kcc[r * nc..(r + 1) * nc], &self.c);
        }
        e
    }
}
