//! Implicit damping for the velocity form ([`crate::method::velocity_form`]): the chain's
//! Kelvin–Voigt and joint-damper forces are −C q̇ with a constant symmetric C ≥ 0 (D = ½q̇ᵀCq̇:
//! the ghost-node bending stencil on the rates, link 1's tip term, D₁e₁e₁ᵀ + D₂e₂e₂ᵀ with eⱼ
//! the constant gradients of the joint rates). The closing kick solves
//!
//! (M(q_{j+1}) + ½τC) a_{j+1} = F_rest(q_{j+1}, v_{j±½}) − C v_{j+½},  v_{j+1} = v_{j+½} + ½τa_{j+1},
//!
//! i.e. −½τM⁻¹C v_{j+1} in the closing kick beside −½τM⁻¹C v_j in the opening one:
//! Crank–Nicolson in the damping, stable for every κτ, so the step is the undamped bound (the
//! elastic h²√(ρA/4EI) and the ghost rotations) instead of the damped one, whose dampers on
//! the clamp half cells ρAh³/24 shrink it like h³–h⁴.
//!
//! **Solve.** M + ½τC is the lumped diagonal plus the full columns F = {θ, β, x₁, x₂, y} of M
//! (`chain::mass`) plus C. Outside F ("band": v₁…v_{r−1}, w₁…w_{r−1} in q order) C is
//! pentadiagonal — the bending stencil per link, and the elbow damper couples v_{r−1} with the
//! adjacent w₁ — so A_BB = D_B + ½τC_BB is SPD pentadiagonal and constant while τ is: its
//! LDLᵀ is computed once per step length. Per kick: Z = A_BB⁻¹A_BF (|F| columns, A_BF from the
//! current columns of M), the |F|×|F| Schur complement A_FF − A_BFᵀZ, back substitution, O(n),
//! no allocation. Only the θ and β columns of M depend on the state; the ghost columns
//! (x₁, x₂, y) are constant, so their Z columns and their block of the Schur complement are
//! computed with the factorization, once per step length: three banded solves per kick. C itself is read once from
//! `TwoLinkChain::add_damping_forces` by probing: each full column alone, the band columns
//! in five interleaved colours (bandwidth 2).
//!
//! **Ledger.** The powers are those of the level velocities (v_{j+1}ᵀCv_{j+1} and the joint
//! dampers' D θ̇², as in the explicit form), integrated by the driver's trapezoid rule.

// Index loops over band positions and full columns read like the formulas.
#![allow(clippy::needless_range_loop)]

use super::damping_matrix::{ImplicitDamping, STATE_COLUMNS};
use super::model::TwoLinkChain;
use super::schur::{MAX_FULL, solve_small};
use crate::system::{DriftVelocities, System};

impl TwoLinkChain {
    /// Switches the velocity form's closing kick to implicit damping (module docs) when the
    /// chain has damping, Euler links and no contact; returns whether it did.
    pub fn enable_implicit_damping(&mut self) -> bool {
        if self.timo.is_some() || self.contact.is_some() || !(self.any_kv() || self.any_damper()) {
            return false;
        }
        let n = self.dofs();
        let nf = self.nfull();
        let full = self.full();
        let band: Vec<usize> = (0..n).filter(|i| !full[..nf].contains(i)).collect();
        let nb = band.len();
        let mut e = vec![0.0; n];
        let mut y = vec![0.0; n];
        let mut cf: [Vec<f64>; MAX_FULL] = std::array::from_fn(|_| vec![0.0; n]);
        for c in 0..nf {
            e[full[c]] = 1.0;
            y.iter_mut().for_each(|x| *x = 0.0);
            self.add_damping_forces(&e, &mut y);
            e[full[c]] = 0.0;
            for i in 0..n {
                cf[c][i] = -y[i];
            }
        }
        let (mut c0, mut c1, mut c2) = (vec![0.0; nb], vec![0.0; nb], vec![0.0; nb]);
        for colour in 0..5 {
            e.iter_mut().for_each(|x| *x = 0.0);
            for b in (colour..nb).step_by(5) {
                e[band[b]] = 1.0;
            }
            y.iter_mut().for_each(|x| *x = 0.0);
            self.add_damping_forces(&e, &mut y);
            for b in (colour..nb).step_by(5) {
                c0[b] = -y[band[b]];
                if b + 1 < nb {
                    c1[b] = -y[band[b + 1]];
                }
                if b + 2 < nb {
                    c2[b] = -y[band[b + 2]];
                }
            }
        }
        self.implicit = Some(Box::new(ImplicitDamping {
            c0,
            c1,
            c2,
            cf,
            d: vec![0.0; nb],
            l1: vec![0.0; nb],
            l2: vec![0.0; nb],
            tau: f64::NAN,
            s_ghost: [[0.0; MAX_FULL]; MAX_FULL],
            abf: std::array::from_fn(|_| vec![0.0; nb]),
            z: std::array::from_fn(|_| vec![0.0; nb]),
            zb: vec![0.0; nb],
            vnew: vec![0.0; n],
            band,
        }));
        true
    }

    /// Whether the damping is implicit (the bound then leaves it out).
    pub fn implicit_damping(&self) -> bool {
        self.implicit.is_some()
    }

    /// The implicit closing kick (module docs): a_{j+1} into `a`, powers at v_{j+1}.
    pub(super) fn implicit_kick_solve(
        &mut self,
        t: f64,
        q: &[f64],
        drift: DriftVelocities,
        tau: f64,
        a: &mut [f64],
    ) {
        let mut rhs = std::mem::take(&mut self.rhs);
        self.chord(q, drift.current);
        self.skip_damping = true;
        self.forces(t, q, drift.current, &mut rhs);
        self.skip_damping = false;
        self.add_inertia_terms(1.0 + drift.w, a, &mut rhs);
        if drift.w != 0.0 {
            self.chord(q, drift.previous);
            self.add_inertia_terms(-drift.w, a, &mut rhs);
        }
        self.chord(q, drift.current);
        self.build_columns();
        self.add_damping_forces(drift.current, &mut rhs);
        self.solve_damped_mass(tau, &rhs, a);
        self.rhs = rhs;
        self.constraint.lambda = 0.0;
        let mut imp = self.implicit.take().expect("implicit damping");
        for i in 0..a.len() {
            imp.vnew[i] = drift.current[i] + 0.5 * tau * a[i];
        }
        let mut sink = [0.0; 4];
        self.powers_at(t, &imp.vnew, &mut sink);
        self.implicit = Some(imp);
    }

    /// out = (M + ½τC)⁻¹ rhs with the columns of the last `build_columns` (module
    /// docs). O(n), no allocation (the factorization is redone only when τ changes).
    pub fn solve_damped_mass(&mut self, tau: f64, rhs: &[f64], out: &mut [f64]) {
        let mut imp = self.implicit.take().expect("implicit damping");
        let nf = self.nfull();
        let refactor = imp.tau != tau;
        if refactor {
            imp.factor(|i| self.diag_mass(i), tau);
        }
        let ht = 0.5 * tau;
        let full = self.full();
        let nb = imp.band.len();
        let ImplicitDamping {
            band,
            cf,
            d,
            l1,
            l2,
            s_ghost,
            abf,
            z,
            zb,
            ..
        } = &mut *imp;
        let solved = if refactor { nf } else { STATE_COLUMNS };
        for c in 0..solved {
            for b in 0..nb {
                let i = band[b];
                abf[c][b] = self.cols[c][i] + ht * cf[c][i];
            }
            z[c].copy_from_slice(&abf[c]);
            ImplicitDamping::solve(d, l1, l2, &mut z[c]);
        }
        let schur = |r: usize, c: usize| {
            self.cols[c][full[r]] + ht * cf[c][full[r]]
                - (0..nb).map(|b| abf[r][b] * z[c][b]).sum::<f64>()
        };
        if refactor {
            for r in STATE_COLUMNS..nf {
                for c in STATE_COLUMNS..nf {
                    s_ghost[r][c] = schur(r, c);
                }
            }
        }
        for b in 0..nb {
            zb[b] = rhs[band[b]];
        }
        ImplicitDamping::solve(d, l1, l2, zb);
        let mut s = *s_ghost;
        let mut bf = [0.0; MAX_FULL];
        for r in 0..nf {
            let fr = full[r];
            bf[r] = rhs[fr] - (0..nb).map(|b| abf[r][b] * zb[b]).sum::<f64>();
            for c in 0..nf {
                if r < STATE_COLUMNS || c < STATE_COLUMNS {
                    s[r][c] = schur(r, c);
                }
            }
        }
        let x = solve_small(s, bf, nf);
        for c in 0..nf {
            out[full[c]] = x[c];
        }
        for b in 0..nb {
            out[band[b]] = zb[b] - (0..nf).map(|c| z[c][b] * x[c]).sum::<f64>();
        }
        self.implicit = Some(imp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::System;

    #[test]
    fn elem_implicit_kick_solves_the_damped_mass_system() {
        // (M + ½τC) x = r checked by M x (the chain's own product) and C x (the damping forces
        // themselves), at a deformed, moving state and a step far above the damped bound
        let scene = data::load_scene("two-link-free").unwrap();
        let mut sys =
            TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(9))
                .unwrap();
        assert!(sys.enable_implicit_damping());
        let n = sys.dofs();
        let q: Vec<f64> = (0..n)
            .map(|i| 0.3 + 0.02 * (0.9 * i as f64).sin())
            .collect();
        let v: Vec<f64> = (0..n).map(|i| 0.3 * (1.7 * i as f64).cos()).collect();
        sys.chord(&q, &v);
        sys.build_columns();
        let rhs: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).cos() + 0.1).collect();
        let tau = 1e-3;
        let mut x = vec![0.0; n];
        sys.solve_damped_mass(tau, &rhs, &mut x);
        let mut mx = vec![0.0; n];
        sys.mass_mul(&x, &mut mx);
        let mut cx = vec![0.0; n];
        sys.add_damping_forces(&x, &mut cx);
        let scale = rhs.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        for i in 0..n {
            let res = mx[i] - 0.5 * tau * cx[i] - rhs[i];
            assert!(res.abs() < 1e-10 * scale, "row {i}: residual {res:e}");
        }
        // C is symmetric and positive semi-definite: xᵀCx = −x·(damping forces) ≥ 0
        let d: f64 = -(0..n).map(|i| x[i] * cx[i]).sum::<f64>();
        assert!(d > 0.0, "{d}");
    }
}
