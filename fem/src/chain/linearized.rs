//! Natural frequencies of a planar chain linearized about its reference configuration: every
//! free joint at its spring set point (at its initial angle where it has no spring), a `fixed`
//! joint at its initial angle, every elastic DOF zero, at rest — the configuration the fdm and
//! modal backends linearize about.
//!
//! At rest the velocity-quadratic inertia terms vanish, so Lagrange's equations
//! R(q, q̇, q̈) = 0 ([`Chain::residual`]) linearize about the reference q₀ to
//!   M δq̈ + K δq = 0,  M = ∂R/∂q̈,  K = ∂R/∂q  at (q₀, 0, 0),
//! and the frequencies solve K x = ω² M x. Both matrices are the chain's own Newton-matrix
//! pieces ([`Chain::newton_matrix`] with the coefficients (c_a, c_v, c_q) = (1, 0, 0) and
//! (0, 0, 1)): the element mass and tangent, hub, tip and section inertias, joint springs and,
//! with gravity, its geometric stiffness about q₀ — one element path shared with the dynamics.
//! The couplings that `newton_matrix` leaves out for foreshortening links are O(v′) and vanish at
//! v = 0, so the pieces are exact here. Dampers (joint and Kelvin–Voigt) enter only C and are
//! left out: these are the undamped frequencies.
//!
//! The pencil is solved shifted, (K + σM) x = (ω² + σ) M x with σ = ω_s², ω_s = min over links of
//! √(EI/ρAL⁴): K + σM is positive definite even with free joints (rigid modes, K singular), so
//! [`crate::modes::generalized_eigen`] reduces with its Cholesky factor and the lowest ω² + σ come
//! out to relative round-off (a reduction with M would put the rigid and low modes at an absolute
//! error ε·λ_max, which grows as h⁻⁴). A mode below 1 % of ω_s is a rigid mode, reported as 0
//! with kind "rigid" (as fdm does); a mode whose kinetic energy sits mostly in axial DOFs is
//! "axial", every other "bending"; a statically unstable mode (ω² < 0, possible about a
//! configuration that gravity does not hold) as −√|ω²|.

use data::scene::{PlanarChain, PrescribedMotion};
use data::{FemSettings, ModalResult, ModeShape, Scene};
use faer::Mat;

use crate::chain::{Chain, NONE, NewtonCoefficients};
use crate::error::FemError;

/// The linearized chain: M and K (dense, symmetric) at the reference configuration.
#[derive(Debug, Clone)]
pub struct LinearizedChain {
    pub mass: Mat<f64>,
    pub stiffness: Mat<f64>,
    /// The reference configuration q₀.
    pub reference: Vec<f64>,
}

/// One linearized mode: ω (rad/s, negative for a statically unstable mode), its kind and its
/// M-orthonormal vector over the chain's DOFs.
#[derive(Debug, Clone)]
pub struct ChainMode {
    pub omega: f64,
    pub kind: &'static str,
    pub vector: Vec<f64>,
}

impl Chain {
    /// The reference configuration q₀ (module docs).
    pub fn reference_configuration(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.ndof];
        for l in &self.links {
            let j = &l.joint;
            if j.dof != NONE {
                q[j.dof] = if j.stiffness != 0.0 {
                    j.set_point
                } else {
                    j.initial_angle
                };
            }
        }
        q
    }

    /// M and K of the chain linearized about [`Chain::reference_configuration`].
    pub fn linearize(&mut self) -> LinearizedChain {
        let n = self.ndof;
        let q = self.reference_configuration();
        let zero = vec![0.0; n];
        let mut res = vec![0.0; n];
        // The Newton matrix is evaluated at the state of the last residual.
        self.residual(0.0, &q, &zero, &zero, &mut res);
        let mut s = self.new_matrix();
        let mut dense = |c: NewtonCoefficients| {
            self.newton_matrix(&q, c, &mut s);
            Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (s.get(i, j) + s.get(j, i)))
        };
        let mass = dense(NewtonCoefficients {
            c_a: 1.0,
            c_v: 0.0,
            c_q: 0.0,
        });
        let stiffness = dense(NewtonCoefficients {
            c_a: 0.0,
            c_v: 0.0,
            c_q: 1.0,
        });
        LinearizedChain {
            mass,
            stiffness,
            reference: q,
        }
    }

    /// ω_s = min over links of √(EI/ρAL⁴): the bending scale that sets the eigen shift and the
    /// rigid-mode threshold.
    fn slowest_bending_scale(&self) -> f64 {
        self.links
            .iter()
            .map(|l| (l.ei / l.rho_a).sqrt() / (l.length * l.length))
            .fold(f64::INFINITY, f64::min)
    }

    /// The lowest `count` linearized modes (module docs), ascending.
    pub(crate) fn linearized_modes(&mut self, count: usize) -> Result<Vec<ChainMode>, FemError> {
        let lin = self.linearize();
        let n = self.ndof;
        let omega_s = self.slowest_bending_scale();
        let shift = omega_s * omega_s;
        let shifted = Mat::<f64>::from_fn(n, n, |i, j| {
            lin.stiffness[(i, j)] + shift * lin.mass[(i, j)]
        });
        let (lambda, vectors) = crate::modes::generalized_eigen(&shifted, &lin.mass)?;
        let axial: Vec<bool> = (0..n).map(|i| self.is_axial_dof(i)).collect();
        let mut out = Vec::with_capacity(count.min(lambda.len()));
        for (j, &l) in lambda.iter().enumerate().take(count) {
            let w2 = l - shift;
            let w = w2.signum() * w2.abs().sqrt();
            let vector: Vec<f64> = (0..n).map(|i| vectors[(i, j)]).collect();
            let (mut axial_share, mut total) = (0.0, 0.0);
            for a in 0..n {
                let mv: f64 = (0..n).map(|b| lin.mass[(a, b)] * vector[b]).sum();
                total += vector[a] * mv;
                if axial[a] {
                    axial_share += vector[a] * mv;
                }
            }
            let (omega, kind) = if w.abs() < 1e-2 * omega_s {
                (0.0, "rigid")
            } else if total > 0.0 && axial_share > 0.5 * total {
                (w, "axial")
            } else {
                (w, "bending")
            };
            out.push(ChainMode {
                omega,
                kind,
                vector,
            });
        }
        Ok(out)
    }

    fn is_axial_dof(&self, dof: usize) -> bool {
        self.links.iter().any(|l| l.u_dof.contains(&dof))
    }

    /// Transverse displacement off the reference line of each link at `stations` equally spaced
    /// points for mode vector `x` (first order): link i moves by δRᵢ·nᵢ + δφᵢ x + δv(x), with
    /// nᵢ the reference normal, δφᵢ = δφᵢ₋₁ + δβᵢ₋₁(L) + δθᵢ and δRᵢ the parent tip's
    /// displacement δRᵢ₋₁ + (δφᵢ₋₁L + δv(L)) nᵢ₋₁ + δu(L) tᵢ₋₁.
    pub(crate) fn mode_displacement(
        &self,
        reference: &[f64],
        x: &[f64],
        stations: usize,
    ) -> Vec<(Vec<f64>, Vec<f64>)> {
        let st = stations.max(2);
        let at = |v: &[f64], i: usize| if i == NONE { 0.0 } else { v[i] };
        let (mut phi0, mut dphi, mut dr) = (0.0, 0.0, [0.0f64; 2]);
        let mut parent_tip_slope = 0.0;
        let mut out = Vec::with_capacity(self.links.len());
        for (li, l) in self.links.iter().enumerate() {
            let j = &l.joint;
            let theta0 = if j.dof != NONE {
                reference[j.dof]
            } else {
                j.initial_angle
            };
            phi0 += theta0;
            dphi += parent_tip_slope + at(x, j.dof);
            let normal = [-phi0.sin(), phi0.cos()];
            let tangent = [phi0.cos(), phi0.sin()];
            let base = dr[0] * normal[0] + dr[1] * normal[1];
            let xs: Vec<f64> = (0..st)
                .map(|k| l.length * k as f64 / (st - 1) as f64)
                .collect();
            let w: Vec<f64> = xs
                .iter()
                .map(|&s| base + dphi * s + self.deflection(li, x, s))
                .collect();
            let k = l.n_el;
            let across = dphi * l.length + at(x, l.v_dof[k]);
            let along = at(x, l.u_dof[k]);
            for c in 0..2 {
                dr[c] += across * normal[c] + along * tangent[c];
            }
            parent_tip_slope = at(x, l.r_dof[k]);
            out.push((xs, w));
        }
        out
    }
}

/// Whether a planar chain is one that [`modes`] linearizes: more than one link, or a link on a
/// free joint (a single link on a fixed or constant-rate hub is the linear link of
/// [`crate::linear`]).
pub fn applies(pc: &PlanarChain) -> bool {
    pc.links.len() > 1 || pc.links.iter().any(|l| l.joint.prescribed.is_none())
}

/// `modes` of the planar chain `pc` of `scene`: the lowest `count` linearized frequencies and
/// their shapes.
pub fn modes(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &FemSettings,
    count: usize,
) -> Result<ModalResult, FemError> {
    let start = std::time::Instant::now();
    let mut chain = Chain::from_planar_chain(&scene.name, pc, settings)?;
    for (i, l) in pc.links.iter().enumerate() {
        match l.joint.prescribed {
            None | Some(PrescribedMotion::Fixed) => {}
            Some(_) => {
                return Err(FemError::unsupported(format!(
                    "fem modes of a chain: joint {} moves by prescription (only free and fixed \
                     joints have a rest configuration to linearize about)",
                    i + 1
                )));
            }
        }
    }
    let modes = chain.linearized_modes(count)?;
    let reference = chain.reference_configuration();
    let stations = scene.simulation.field_stations;
    let mut shapes = Vec::new();
    for m in &modes {
        let parts = chain.mode_displacement(&reference, &m.vector, stations);
        let peak = parts
            .iter()
            .flat_map(|(_, w)| w.iter())
            .fold(0.0f64, |a, &v| if v.abs() > a.abs() { v } else { a });
        for (link, (x, mut transverse)) in parts.into_iter().enumerate() {
            if peak != 0.0 {
                transverse.iter_mut().for_each(|v| *v /= peak);
            }
            shapes.push(ModeShape {
                link: link + 1,
                x,
                transverse,
            });
        }
    }
    Ok(crate::modes::modal_result(
        scene,
        settings,
        modes.iter().map(|m| (m.omega, m.kind.to_string())),
        shapes,
        chain.ndof,
        start,
    ))
}
