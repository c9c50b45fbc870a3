//! Natural frequencies of the two-link chain linearized about its reference configuration:
//! joints at their spring set points (the initial angle where a joint has no spring), links
//! straight, at rest.
//!
//! At rest the velocity-quadratic inertia terms and the dampers vanish, so the station equations
//! M(q) q̈ = F(q, 0) linearize at an equilibrium q₀ (F(q₀, 0) = 0) to M(q₀) δq̈ = −K δq with
//! K = −∂F/∂q: the generalized eigenproblem K x = ω² M x of the same discretization that is
//! integrated (ghost-node bending, joint springs on the clamp tangents and the elbow, the clamp
//! half-cell rotary inertias; Kelvin–Voigt and joint dampers left out: undamped frequencies).
//! M's columns are the momenta p = M(q₀) e_j (exact); K's by central differences of F, which is
//! affine in q at rest without gravity (bending, springs), so the differences are exact to
//! round-off; with gravity they give its geometric stiffness about the reference. The pencil is
//! solved by Cholesky reduction (faer self-adjoint eigensolver). A free joint (no spring, no
//! gravity) gives a zero frequency (a rigid mode), reported as 0 with kind "rigid" (any mode
//! below 1 % of the slowest link's √(EI/ρAL⁴)).

use data::scene::PlanarChain;
use data::{BackendKind, Cost, ModalResult, ModeShape, Scene};
use faer::{Mat, Side};

use super::kinetic::{BE, TH};
use super::model::TwoLinkChain;
use crate::error::FdmError;
use crate::settings::ValidatedSettings;

/// Undamped linearized frequencies ω (rad/time, ascending; a statically unstable mode as −√|λ|)
/// and the M-orthonormal mode vectors (columns over q).
pub struct ChainModes {
    pub omega: Vec<f64>,
    pub vectors: Mat<f64>,
}

impl TwoLinkChain {
    /// The reference configuration: joint angles at the spring set points (initial angles where
    /// a joint has no spring), deflections zero.
    pub fn reference_state(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.dofs_total()];
        let angle = |k: usize| {
            if self.joints[k].stiffness != 0.0 {
                self.joints[k].set_point
            } else {
                self.init[k].0
            }
        };
        q[TH] = angle(0);
        q[BE] = angle(0) + angle(1);
        q
    }

    fn dofs_total(&self) -> usize {
        crate::system::System::dofs(self)
    }

    /// The linearized modes about [`TwoLinkChain::reference_state`].
    pub fn linearized_modes(&mut self) -> Result<ChainModes, FdmError> {
        if self.timo.is_some() {
            return Err(FdmError::Unsupported(
                "fdm modes of a Timoshenko chain: the condensed section rotations are not \
                 linearized (Euler–Bernoulli chains only)"
                    .into(),
            ));
        }
        let n = self.dofs_total();
        let mut q = self.reference_state();
        let zeros = vec![0.0; n];
        let mut unit = vec![0.0; n];
        let mut col = vec![0.0; n];
        let mut mass = Mat::<f64>::zeros(n, n);
        for j in 0..n {
            unit[j] = 1.0;
            self.momenta(&q, &unit, &mut col);
            for i in 0..n {
                mass[(i, j)] = col[i];
            }
            unit[j] = 0.0;
        }
        let scale = self.links[0].length.max(self.links[1].length);
        let mut f_plus = vec![0.0; n];
        let mut stiff = Mat::<f64>::zeros(n, n);
        for j in 0..n {
            // angles are dimensionless, deflections lengths
            let step = if j == TH || j == BE {
                1e-6
            } else {
                1e-6 * scale
            };
            let q0 = q[j];
            q[j] = q0 + step;
            self.frames(&q, &zeros);
            self.forces(0.0, &q, &zeros, &mut f_plus);
            q[j] = q0 - step;
            self.frames(&q, &zeros);
            self.forces(0.0, &q, &zeros, &mut col);
            q[j] = q0;
            for i in 0..n {
                stiff[(i, j)] = -(f_plus[i] - col[i]) / (2.0 * step);
            }
        }
        let sym = |a: &Mat<f64>| Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        // the slowest link's bending scale √(EI/ρAL⁴): the shift of the eigensolve is its
        // square, and a mode below 1 % of it is reported as rigid (0) — the zero eigenvalues
        // of free joints come out at round-off
        let bending_scale = self
            .links
            .iter()
            .map(|l| (l.ei / l.rho_a).sqrt() / (l.length * l.length))
            .fold(f64::INFINITY, f64::min);
        let (lambda, vectors) =
            generalized_eigen(&sym(&stiff), &sym(&mass), bending_scale * bending_scale)?;
        let rigid_below = 1e-2 * bending_scale;
        let omega = lambda
            .iter()
            .map(|&l| {
                let w = l.signum() * l.abs().sqrt();
                if w.abs() < rigid_below { 0.0 } else { w }
            })
            .collect();
        Ok(ChainModes { omega, vectors })
    }

    /// Transverse displacement of each link's stations off its reference line for mode vector
    /// `x` (linear order): link 1 δθ·x + v(x); link 2 the elbow's displacement δθ·L₁ projected
    /// on link 2's normal (cos θ₂) plus δβ·ξ + w(ξ).
    fn mode_shape(&self, x: &[f64], elbow_ref: f64) -> [(Vec<f64>, Vec<f64>); 2] {
        let ine = &self.inertia;
        let (r1, r2) = (ine.r1, ine.r2);
        let link1: Vec<f64> = (0..=r1)
            .map(|k| {
                let v = if k == 0 || k == r1 { 0.0 } else { x[1 + k] };
                x[TH] * k as f64 * ine.h1 + v
            })
            .collect();
        let elbow = x[TH] * self.links[0].length * elbow_ref.cos();
        let link2: Vec<f64> = (0..=r2)
            .map(|j| {
                let w = if j == 0 || j == r2 {
                    0.0
                } else {
                    x[1 + r1 + j]
                };
                elbow + x[BE] * j as f64 * ine.h2 + w
            })
            .collect();
        let xs = |r: usize, h: f64| (0..=r).map(|k| k as f64 * h).collect::<Vec<_>>();
        [(xs(r1, ine.h1), link1), (xs(r2, ine.h2), link2)]
    }
}

/// The pencil K x = λ M x, ascending, with M-orthonormal vectors, shifted and inverted:
/// M x = μ (K + σM) x, λ = 1/μ − σ. The eigensolver's absolute error ε‖·‖ then falls on μ,
/// whose largest values are the slowest modes, so those keep their relative accuracy even
/// when λ_max (∝ h⁻⁴) is 10¹¹ times λ₁; Cholesky reduction on M instead leaves λ₁ an
/// absolute error ε λ_max. A statically unstable reference (K + σM not positive definite)
/// falls back to that reduction.
fn generalized_eigen(
    k: &Mat<f64>,
    m: &Mat<f64>,
    sigma: f64,
) -> Result<(Vec<f64>, Mat<f64>), FdmError> {
    let n = k.nrows();
    let shifted = Mat::<f64>::from_fn(n, n, |i, j| k[(i, j)] + sigma * m[(i, j)]);
    if let Ok((mu, x)) = reduced_eigen(m, &shifted) {
        // μ descending ↔ λ ascending; x is (K + σM)-orthonormal: xᵀMx = μ
        let lambda = (0..n).rev().map(|i| 1.0 / mu[i] - sigma).collect();
        let vectors = Mat::<f64>::from_fn(n, n, |r, c| x[(r, n - 1 - c)] / mu[n - 1 - c].sqrt());
        return Ok((lambda, vectors));
    }
    reduced_eigen(k, m)
}

/// The pencil A x = λ B x (B positive definite) by Cholesky reduction: ascending λ,
/// B-orthonormal vectors.
fn reduced_eigen(a: &Mat<f64>, b: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), FdmError> {
    let numerical = |message: String| FdmError::Numerical { t: 0.0, message };
    let llt = b
        .llt(Side::Lower)
        .map_err(|e| numerical(format!("chain mass matrix not positive definite: {e:?}")))?;
    let l = llt.L();
    let mut t = a.clone();
    l.solve_lower_triangular_in_place(&mut t);
    let mut c = t.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut c);
    let n = c.nrows();
    let c = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let ev = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| numerical(format!("eigen decomposition failed: {e:?}")))?;
    let s = ev.S().column_vector();
    let lambda = (0..n).map(|i| s[i]).collect();
    let mut x = ev.U().to_owned();
    l.transpose().solve_upper_triangular_in_place(&mut x);
    Ok((lambda, x))
}

/// `modes` of a two-link chain `pc` (of `scene`): the lowest `count` linearized frequencies.
pub fn modes(
    scene: &Scene,
    pc: &PlanarChain,
    s: &ValidatedSettings,
    count: usize,
) -> Result<ModalResult, FdmError> {
    let clock = std::time::Instant::now();
    let mut chain = TwoLinkChain::from_planar_chain(scene, pc, s.stations)?;
    let m = chain.linearized_modes()?;
    let n = m.omega.len();
    let count = count.min(n);
    let q_ref = chain.reference_state();
    let elbow_ref = q_ref[BE] - q_ref[TH];
    let mut shapes = Vec::new();
    for j in 0..count {
        let x: Vec<f64> = (0..n).map(|i| m.vectors[(i, j)]).collect();
        let parts = chain.mode_shape(&x, elbow_ref);
        let peak = parts
            .iter()
            .flat_map(|(_, w)| w.iter())
            .fold(0.0f64, |a, v| if v.abs() > a.abs() { *v } else { a });
        for (link, (xs, mut w)) in parts.into_iter().enumerate() {
            if peak != 0.0 {
                w.iter_mut().for_each(|v| *v /= peak);
            }
            shapes.push(ModeShape {
                link: link + 1,
                x: xs,
                transverse: w,
            });
        }
    }
    Ok(ModalResult {
        backend: BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        frequencies_hz: m.omega[..count]
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect(),
        kinds: m.omega[..count]
            .iter()
            .map(|&w| if w == 0.0 { "rigid" } else { "bending" }.to_string())
            .collect(),
        shapes,
        cost: Cost {
            wall_time_s: clock.elapsed().as_secs_f64(),
            dofs: n,
            factorizations: 1,
            ..Cost::default()
        },
    })
}
