//! Free transverse vibration of the rocket at ignition from the scene's initial shape, by
//! superposition of the exact free-free modes of [`FreeFreeRocket`].
//!
//! Linear theory about the straight body at rest with no loads (mass flow, thrust and chamber
//! pressure off; a uniform gravity field accelerates the body without straining it). With
//! y = (w(x), q₁ … q_J) the case's transverse displacement and the discrete masses',
//!
//! ```text
//! y(x, t) = Σₖ aₖ φₖ(x) cos ωₖt,   aₖ = ⟨φₖ, y₀⟩ / ⟨φₖ, φₖ⟩,   ⟨a, b⟩ = ∫ m₀ a_w b_w dx + Σⱼ Mⱼ a_j b_j,
//! ```
//!
//! started at rest from y₀ = (w₀, 0): w₀ the scene's w(x, 0) less its m₀-weighted
//! least-squares line (docs/rocket.md § initial state), the masses at zero displacement. y₀ is
//! then ⟨·⟩-orthogonal to both rigid motions (1 and x), so only elastic modes appear.
//!
//! Mode k: without springs between masses, the node values (w, w′ at every node, q at every
//! mass) are the null vector of the dynamic stiffness K(ωₖ) at the bisected root (eigenvector
//! of the smallest |eigenvalue| of the equilibrated matrix; coincident roots give an
//! eigenspace, orthogonalized in ⟨·⟩), and each member's interior is the exact solution through
//! its end values. With them (body-axis springs, parent module) the mode solves
//! K₀y − λMy = μMr on rᵀMy = 0, so y ∝ z − r with K(ωₖ)z = g: z's members are exact
//! homogeneous solutions through its end values and r is the rigid line x − x_c. The inner
//! products are Gauss–Legendre integrals over sub-intervals of each member short against its
//! wavelength.
//!
//! Observables follow the common definition (docs/rocket.md): positions relative to the case's
//! mean axis, to first order in the displacements c = ∫m₀w / ∫m₀ and
//! φ = ∫m₀(x − x̄)w / ∫m₀(x − x̄)², so `rocket.w@k` = w(x_k) − c − φ(x_k − x̄) and
//! `rocket.mass{j}.w` = q_j − c − φ(x_j − x̄).

use super::{FreeFreeRocket, Motion, basis_end_values, solve4};
use crate::analytic::error::{AnalyticError, Result};
use crate::analytic::numerics::quadrature::gauss_legendre_nodes;
use data::scene::Rocket;

/// Gauss points per sub-interval of a member.
const GAUSS_POINTS: usize = 12;
/// Roots closer than this (relative) form one eigenspace.
const COINCIDENT: f64 = 1e-9;

/// One elastic mode: its shape on every member and at every discrete mass.
#[derive(Debug, Clone)]
struct ModeShape {
    omega: f64,
    /// Exact member solution: coefficients of cos βξ, sin βξ, e^{−βξ}, e^{−β(L−ξ)}.
    members: Vec<[f64; 4]>,
    betas: Vec<f64>,
    /// Coefficient of the rigid line x − x_c added on the case.
    tilt: f64,
    masses: Vec<f64>,
}

/// The free vibration y(t) of the body from its initial shape.
#[derive(Debug, Clone)]
pub struct FreeVibration {
    body: FreeFreeRocket,
    modes: Vec<ModeShape>,
    amplitudes: Vec<f64>,
    /// Mean-axis offset c and tilt φ of each mode (per unit amplitude).
    mean_axis: Vec<(f64, f64)>,
    x_bar: f64,
    /// ‖y₀ − Σ aₖφₖ‖ / ‖y₀‖ in the ⟨·⟩ norm: the truncation of the expansion.
    residual: f64,
}

/// Positions relative to the mean axis at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct TransverseState {
    /// At the requested case abscissae.
    pub stations: Vec<f64>,
    /// At each discrete mass, in scene order.
    pub masses: Vec<f64>,
}

impl FreeVibration {
    /// The rocket's free vibration on its first `modes` elastic transverse modes. The rocket
    /// must have no mass flow, chamber pressure or dampers (the rows switch them off by
    /// overrides).
    pub fn from_rocket(r: &Rocket, modes: usize) -> Result<Self> {
        if r.stages.iter().any(|s| s.burn_rate != 0.0) || r.chamber_pressure != 0.0 {
            return Err(AnalyticError::Unsupported(
                "free vibration needs burn_rate = 0 and chamber_pressure = 0 (override them)"
                    .into(),
            ));
        }
        let damped = r
            .discrete_masses
            .iter()
            .any(|m| m.axial_damping != 0.0 || m.transverse_damping != 0.0)
            || r.springs
                .iter()
                .any(|s| s.axial_damping != 0.0 || s.transverse_damping != 0.0);
        if damped {
            return Err(AnalyticError::Unsupported(
                "free vibration of the undamped body: the scene has dampers".into(),
            ));
        }
        let body = FreeFreeRocket::from_rocket(r)?;
        let length = r.length();
        let shape = |x: f64| r.initial_shape.deflection(x, length);
        Self::new(body, &shape, modes)
    }

    /// Free vibration of `body` from the case shape `shape` (rigid part removed here), masses at
    /// rest at zero displacement.
    pub fn new(body: FreeFreeRocket, shape: &dyn Fn(f64) -> f64, modes: usize) -> Result<Self> {
        let omegas =
            body.omegas_after(Motion::Transverse, Motion::Transverse.rigid_modes(), modes)?;
        let shapes = mode_shapes(&body, &omegas)?;
        let points = quadrature_points(&body, &shapes);
        let m0: f64 = points.iter().map(|p| p.weight).sum();
        let x_bar = points.iter().map(|p| p.weight * p.x).sum::<f64>() / m0;
        let i0: f64 = points
            .iter()
            .map(|p| p.weight * (p.x - x_bar).powi(2))
            .sum();
        let line = |f: &dyn Fn(usize) -> f64| {
            let c = points
                .iter()
                .enumerate()
                .map(|(i, p)| p.weight * f(i))
                .sum::<f64>()
                / m0;
            let tilt = points
                .iter()
                .enumerate()
                .map(|(i, p)| p.weight * (p.x - x_bar) * f(i))
                .sum::<f64>()
                / i0;
            (c, tilt)
        };
        let raw: Vec<f64> = points.iter().map(|p| shape(p.x)).collect();
        let (c0, t0) = line(&|i| raw[i]);
        let w0: Vec<f64> = points
            .iter()
            .zip(&raw)
            .map(|(p, w)| w - c0 - t0 * (p.x - x_bar))
            .collect();
        let norm0: f64 = points.iter().zip(&w0).map(|(p, w)| p.weight * w * w).sum();
        if norm0 <= 0.0 {
            return Err(AnalyticError::Unsupported(
                "the initial shape has no elastic part: nothing vibrates".into(),
            ));
        }
        let mut amplitudes = Vec::with_capacity(shapes.len());
        let mut mean_axis = Vec::with_capacity(shapes.len());
        let mut fitted = vec![0.0; points.len()];
        let mut fitted_masses = vec![0.0; body.masses.len()];
        for (k, mode) in shapes.iter().enumerate() {
            let phi: Vec<f64> = points.iter().map(|p| p.mode_values[k]).collect();
            let self_case: f64 = points.iter().zip(&phi).map(|(p, v)| p.weight * v * v).sum();
            let self_masses: f64 = body
                .masses
                .iter()
                .zip(&mode.masses)
                .map(|((_, m), q)| m.mass * q * q)
                .sum();
            let projection: f64 = points
                .iter()
                .zip(&phi)
                .zip(&w0)
                .map(|((p, v), w)| p.weight * v * w)
                .sum();
            let a = projection / (self_case + self_masses);
            for (f, v) in fitted.iter_mut().zip(&phi) {
                *f += a * v;
            }
            for (f, q) in fitted_masses.iter_mut().zip(&mode.masses) {
                *f += a * q;
            }
            amplitudes.push(a);
            mean_axis.push(line(&|i| phi[i]));
        }
        let miss_case: f64 = points
            .iter()
            .zip(w0.iter().zip(&fitted))
            .map(|(p, (w, f))| p.weight * (w - f).powi(2))
            .sum();
        let miss_masses: f64 = body
            .masses
            .iter()
            .zip(&fitted_masses)
            .map(|((_, m), f)| m.mass * f * f)
            .sum();
        let residual = ((miss_case + miss_masses) / norm0).sqrt();
        Ok(FreeVibration {
            body,
            modes: shapes,
            amplitudes,
            mean_axis,
            x_bar,
            residual,
        })
    }

    /// ‖y₀ − Σ aₖφₖ‖ / ‖y₀‖: how much of the initial state the kept modes miss.
    pub fn truncation(&self) -> f64 {
        self.residual
    }

    /// Natural frequencies [rad/s] of the kept modes.
    pub fn omegas(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.omega).collect()
    }

    /// Positions relative to the mean axis at time `t`, at the case abscissae `stations`.
    pub fn state(&self, t: f64, stations: &[f64]) -> TransverseState {
        let mut out = TransverseState {
            stations: vec![0.0; stations.len()],
            masses: vec![0.0; self.body.masses.len()],
        };
        for ((mode, a), (c, tilt)) in self.modes.iter().zip(&self.amplitudes).zip(&self.mean_axis) {
            let g = a * (mode.omega * t).cos();
            for (o, x) in out.stations.iter_mut().zip(stations) {
                *o += g * (self.case_value(mode, *x) - c - tilt * (x - self.x_bar));
            }
            for ((o, q), (_, m)) in out
                .masses
                .iter_mut()
                .zip(&mode.masses)
                .zip(&self.body.masses)
            {
                *o += g * (q - c - tilt * (m.position - self.x_bar));
            }
        }
        out
    }

    fn case_value(&self, mode: &ModeShape, x: f64) -> f64 {
        let nodes = &self.body.nodes;
        let e = (0..self.body.members.len())
            .rev()
            .find(|&e| x >= nodes[e])
            .unwrap_or(0);
        case_value(&self.body, mode, e, x - nodes[e])
    }
}

/// w of `mode` at ξ along member `e`.
fn case_value(body: &FreeFreeRocket, mode: &ModeShape, e: usize, xi: f64) -> f64 {
    let (c, beta, length) = (&mode.members[e], mode.betas[e], body.members[e].length);
    c[0] * (beta * xi).cos()
        + c[1] * (beta * xi).sin()
        + c[2] * (-beta * xi).exp()
        + c[3] * (-beta * (length - xi)).exp()
        + mode.tilt * (body.nodes[e] + xi - body.centre)
}

/// The shapes of the modes at `omegas` (ascending; coincident roots share an eigenspace).
fn mode_shapes(body: &FreeFreeRocket, omegas: &[f64]) -> Result<Vec<ModeShape>> {
    let mut out: Vec<ModeShape> = Vec::with_capacity(omegas.len());
    let mut k = 0;
    while k < omegas.len() {
        let mut group = 1;
        while k + group < omegas.len()
            && omegas[k + group] - omegas[k] <= COINCIDENT * omegas[k + group]
        {
            group += 1;
        }
        let omega = omegas[k..k + group].iter().sum::<f64>() / group as f64;
        let mut shapes: Vec<ModeShape> = if body.has_rotation_springs() {
            if group > 1 {
                return Err(AnalyticError::Unsupported(format!(
                    "{group} coincident body-frame modes at {omega} rad/s: the rotation \
                     constraint's eigenspace is not built"
                )));
            }
            vec![constrained_shape(body, omega)?]
        } else {
            null_space(body, omega, group)?
                .iter()
                .map(|v| shape_from_nodes(body, omega, v))
                .collect::<Result<_>>()?
        };
        orthogonalize(body, &mut shapes);
        for (s, w) in shapes.iter_mut().zip(&omegas[k..k + group]) {
            s.omega = *w;
        }
        out.extend(shapes);
        k += group;
    }
    Ok(out)
}

/// The `dim` eigenvectors of the equilibrated K(ω) with the smallest |eigenvalue|, scaled back
/// to node values.
fn null_space(body: &FreeFreeRocket, omega: f64, dim: usize) -> Result<Vec<Vec<f64>>> {
    let (k, n, _) = body.dynamic_stiffness(Motion::Transverse, omega)?;
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let a = k[i * n + i].abs();
            if a > 0.0 { 1.0 / a.sqrt() } else { 1.0 }
        })
        .collect();
    let m = faer::Mat::<f64>::from_fn(n, n, |i, j| k[i * n + j] * d[i] * d[j]);
    let evd =
        m.self_adjoint_eigen(faer::Side::Lower)
            .map_err(|_| AnalyticError::NoConvergence {
                what: "symmetric eigensolver on the dynamic stiffness at a root",
                iterations: 0,
            })?;
    let s = evd.S().column_vector();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| s[a].abs().total_cmp(&s[b].abs()));
    let u = evd.U();
    Ok(order[..dim]
        .iter()
        .map(|&col| (0..n).map(|i| u[(i, col)] * d[i]).collect())
        .collect())
}

/// A mode from its node values: members solved through their end values (w, w′).
fn shape_from_nodes(body: &FreeFreeRocket, omega: f64, v: &[f64]) -> Result<ModeShape> {
    let nn = 2 * body.nodes.len();
    let mut members = Vec::with_capacity(body.members.len());
    let mut betas = Vec::with_capacity(body.members.len());
    for (e, m) in body.members.iter().enumerate() {
        let beta = (m.rho_a * omega * omega / m.ei).powf(0.25);
        let (at0, at_l) = basis_end_values(beta, m.length);
        let d = [at0[0], at0[1], at_l[0], at_l[1]];
        let ends = [v[2 * e], v[2 * e + 1], v[2 * e + 2], v[2 * e + 3]];
        let mut rhs = [[0.0; 4]; 4];
        for (row, value) in rhs.iter_mut().zip(ends) {
            row[0] = value;
        }
        let c = solve4(d, rhs)?;
        members.push([c[0][0], c[1][0], c[2][0], c[3][0]]);
        betas.push(beta);
    }
    Ok(ModeShape {
        omega,
        members,
        betas,
        tilt: 0.0,
        masses: v[nn..].to_vec(),
    })
}

/// The body-frame mode at a root of the constrained count: z − r with K(ω)z = g.
fn constrained_shape(body: &FreeFreeRocket, omega: f64) -> Result<ModeShape> {
    let (k, n, _) = body.dynamic_stiffness(Motion::Transverse, omega)?;
    let g = body.rotation_spring_forces(n);
    let z = body.rotation_response(&k, n, &g)?;
    let r = body.rotation_dofs(n);
    let mut shape = shape_from_nodes(body, omega, &z)?;
    shape.tilt = -1.0;
    let nn = n - body.masses.len();
    for (q, rj) in shape.masses.iter_mut().zip(&r[nn..]) {
        *q -= rj;
    }
    Ok(shape)
}

/// Gram–Schmidt in ⟨·⟩ within one eigenspace (a no-op for a simple root). The shapes share ω,
/// hence β, so a combination of coefficient sets is the shape of the combined node values.
fn orthogonalize(body: &FreeFreeRocket, shapes: &mut [ModeShape]) {
    if shapes.len() < 2 {
        return;
    }
    let points = quadrature_points(body, shapes);
    let mut values: Vec<Vec<f64>> = (0..shapes.len())
        .map(|k| points.iter().map(|p| p.mode_values[k]).collect())
        .collect();
    let inner = |va: &[f64], vb: &[f64], qa: &[f64], qb: &[f64]| -> f64 {
        let case: f64 = points
            .iter()
            .zip(va.iter().zip(vb))
            .map(|(p, (x, y))| p.weight * x * y)
            .sum();
        let masses: f64 = body
            .masses
            .iter()
            .zip(qa.iter().zip(qb))
            .map(|((_, m), (x, y))| m.mass * x * y)
            .sum();
        case + masses
    };
    for b in 1..shapes.len() {
        for a in 0..b {
            let r = inner(&values[a], &values[b], &shapes[a].masses, &shapes[b].masses)
                / inner(&values[a], &values[a], &shapes[a].masses, &shapes[a].masses);
            let (head, tail) = shapes.split_at_mut(b);
            let (sa, sb) = (&head[a], &mut tail[0]);
            for (cb, ca) in sb.members.iter_mut().zip(&sa.members) {
                for (x, y) in cb.iter_mut().zip(ca) {
                    *x -= r * y;
                }
            }
            sb.tilt -= r * sa.tilt;
            for (x, y) in sb.masses.iter_mut().zip(&sa.masses) {
                *x -= r * y;
            }
            let (vhead, vtail) = values.split_at_mut(b);
            for (x, y) in vtail[0].iter_mut().zip(&vhead[a]) {
                *x -= r * y;
            }
        }
    }
}

/// A case quadrature point: abscissa, weight m₀ dx and the value of every mode there.
#[derive(Debug, Clone)]
struct Point {
    x: f64,
    weight: f64,
    mode_values: Vec<f64>,
}

fn quadrature_points(body: &FreeFreeRocket, shapes: &[ModeShape]) -> Vec<Point> {
    let rule = gauss_legendre_nodes(GAUSS_POINTS);
    let mut out = Vec::new();
    for (e, m) in body.members.iter().enumerate() {
        let beta_max = shapes.iter().map(|s| s.betas[e]).fold(0.0, f64::max);
        let pieces = ((beta_max * m.length).ceil() as usize).max(2);
        let h = m.length / pieces as f64;
        for piece in 0..pieces {
            for &(z, w) in &rule {
                let xi = h * (piece as f64 + 0.5 * (z + 1.0));
                out.push(Point {
                    x: body.nodes[e] + xi,
                    weight: 0.5 * h * w * m.rho_a,
                    mode_values: shapes.iter().map(|s| case_value(body, s, e, xi)).collect(),
                });
            }
        }
    }
    out
}
