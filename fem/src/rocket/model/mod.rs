//! The finite-element rocket: mesh, constant operators and the generalized forces.
//!
//! DOFs: per node (u, w, w′) — u linear, w Hermite cubic, displacements in the *launch axes*
//! (ξ along the body axis at launch, η across it), rigid motion included — then per discrete
//! mass (U_j, W_j) in the same axes. Every operator is integrated by 4-point Gauss quadrature
//! on each part of an element between breakpoints (stage junctions), which is exact for the
//! piecewise-constant sections (mass integrands are of degree 6). [`Model::new`] builds it in
//! phases (the `build` submodule).

use data::scene::InitialShape;

use crate::element::{bar_shapes, hermite_cubic};

mod build;

/// Nodal DOFs: axial u, transverse w, slope w′.
pub const DOFS_PER_NODE: usize = 3;

/// Symmetric matrix as unique triplets (i, j, value), sorted.
#[derive(Debug, Clone, Default)]
pub struct Triplets(pub Vec<(usize, usize, f64)>);

impl Triplets {
    fn from_map(map: std::collections::BTreeMap<(usize, usize), f64>) -> Self {
        Triplets(map.into_iter().map(|((i, j), v)| (i, j, v)).collect())
    }

    /// y += s·A x.
    pub fn mul_add(&self, s: f64, x: &[f64], y: &mut [f64]) {
        for &(i, j, v) in &self.0 {
            y[i] += s * v * x[j];
        }
    }

    /// xᵀ A y.
    pub fn form(&self, x: &[f64], y: &[f64]) -> f64 {
        self.0.iter().map(|&(i, j, v)| x[i] * v * y[j]).sum()
    }
}

/// Shape-function values of a point x on the mesh: u-DOFs with linear weights, w-DOFs (w, w′
/// of both nodes) with Hermite weights.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    pub x: f64,
    pub iu: [usize; 2],
    pub nu: [f64; 2],
    pub iw: [usize; 4],
    pub hw: [f64; 4],
}

/// One quadrature point: abscissa, weight, section (EA, EI), non-burning mass per length and
/// whether it lies in the burning stage.
#[derive(Debug, Clone, Copy)]
struct Quad {
    element: usize,
    s: f64,
    weight: f64,
    ea: f64,
    fixed_mass: f64,
    burning: bool,
    ei: f64,
    /// The x-derivatives of the axial (u₁, u₂) and transverse (w₁, w₁′, w₂, w₂′) shape
    /// functions at the point, tabulated for the force passes.
    slopes: ([f64; 2], [f64; 4]),
}

/// Discrete mass on springs (spring to the case at its attachment point).
#[derive(Debug, Clone)]
pub struct Attached {
    pub at: Point,
    pub mass: f64,
    pub ku: f64,
    pub kw: f64,
    pub cu: f64,
    pub cw: f64,
}

#[derive(Debug, Clone)]
pub struct Coupling {
    pub a: usize,
    pub b: usize,
    pub ku: f64,
    pub kw: f64,
    pub cu: f64,
    pub cw: f64,
}

/// Everything about the discretized rocket that does not change during a run.
#[derive(Debug, Clone)]
pub struct Model {
    pub elements: usize,
    pub nodes: usize,
    /// Total DOFs (3 per node + 2 per discrete mass).
    pub n: usize,
    pub h: f64,
    pub length: f64,
    pub l1: f64,
    pub theta0: f64,
    pub g: f64,
    pub gamma: f64,
    /// Stage-1 mass per length at ignition, casing floor, burn rate (mass / length / time).
    pub m1_0: f64,
    pub m1_casing: f64,
    pub burn_rate: f64,
    pub exhaust_velocity: f64,
    /// p·A_f.
    pub pressure_force: f64,
    /// Unit-mass matrix of the burning stage (times m₁(t)), non-burning case mass, both
    /// consistent; discrete masses are the diagonal `masses`.
    pub m_burn: Triplets,
    pub m_fixed: Triplets,
    /// Beam stiffness ∫EA u′δu′ + ∫EI w″δw″.
    pub k_beam: Triplets,
    quad: Vec<Quad>,
    pub masses: Vec<Attached>,
    pub couplings: Vec<Coupling>,
    pub pressure_point: Point,
    /// Reference positions (x on u-DOFs and U_j), unit translations along ξ and η (all
    /// material / case only).
    pub x_ref: Vec<f64>,
    pub t_xi: Vec<f64>,
    pub t_eta: Vec<f64>,
    /// Mean-axis functionals of the case with respect to its ignition mass m₀ (see
    /// [`Model::mean_axis`]).
    pub m0: f64,
    pub x_bar: f64,
    a_c_xi: Vec<f64>,
    a_c_eta: Vec<f64>,
    a_s_xi: Vec<f64>,
    a_s_eta: Vec<f64>,
    /// The whole body's (case and discrete masses, ignition mass) first moments about its
    /// centroid: ψ = atan2(b_s_η·q, b_s_ξ·(x_ref + q)) is the angle of the axes the springs
    /// between masses ride with ([`Model::add_spring_forces`]).
    b_s_xi: Vec<f64>,
    b_s_eta: Vec<f64>,
    /// Consistent load vectors of the unit jet-Coriolis distribution (1 − x/L₁)₊.
    pub cor_u: Vec<f64>,
    pub cor_w: Vec<f64>,
}

/// The whole body's mean axis at one state (springs between masses ride with it).
#[derive(Debug, Clone, Copy)]
struct BodyAxes {
    psi: f64,
    sx: f64,
    sy: f64,
}

/// A spring between masses in the body axes, and the reference distance Δx = x_a − x_b.
#[derive(Debug, Clone, Copy)]
struct Stretch {
    axial: f64,
    transverse: f64,
    dx: f64,
}

/// Mean axis of the case (ignition mass m₀): centroid c, angle φ from the launch axis, its rate.
#[derive(Debug, Clone, Copy)]
pub struct MeanAxis {
    pub c_xi: f64,
    pub c_eta: f64,
    pub phi: f64,
    pub rate: f64,
}

impl MeanAxis {
    /// Position of a material point (reference abscissa x, launch-axis position R) relative to
    /// the mean axis: (u, w) with r = A(φ)ᵀ(R − c) + (x̄, 0), u = r_ξ − x, w = r_η.
    pub fn relative(&self, x_bar: f64, x: f64, r_xi: f64, r_eta: f64) -> (f64, f64) {
        let (c, s) = (self.phi.cos(), self.phi.sin());
        let (dx, dy) = (r_xi - self.c_xi, r_eta - self.c_eta);
        (c * dx + s * dy + x_bar - x, -s * dx + c * dy)
    }
}

/// Linear shape functions and derivatives on an element of length h at s ∈ [0, 1].
/// The x-derivatives of the bar and Hermite-cubic shape functions at local coordinate `s` of an
/// element of length `h`.
fn slopes(s: f64, h: f64) -> ([f64; 2], [f64; 4]) {
    let (_, du) = bar_shapes(s, h);
    let dn = hermite_cubic().shapes(s, h).dn;
    (du, [dn[0], dn[1], dn[2], dn[3]])
}

fn dofs_of(e: usize) -> ([usize; 2], [usize; 4]) {
    let (a, b) = (DOFS_PER_NODE * e, DOFS_PER_NODE * (e + 1));
    ([a, b], [a + 1, a + 2, b + 1, b + 2])
}

/// The shape functions of the point x on a mesh of `elements` elements of length h (the last
/// element takes x = L).
fn mesh_point(x: f64, h: f64, elements: usize) -> Point {
    let el = ((x / h).floor() as usize).min(elements - 1);
    let s = x / h - el as f64;
    let (nu, _) = bar_shapes(s, h);
    let n = hermite_cubic().shapes(s, h).n;
    let hw = [n[0], n[1], n[2], n[3]];
    let (iu, iw) = dofs_of(el);
    Point { x, iu, nu, iw, hw }
}

impl Model {
    pub fn base(&self) -> usize {
        DOFS_PER_NODE * self.nodes
    }
    /// DOF of discrete mass j's U (axial) and W (transverse).
    pub fn mass_dofs(&self, j: usize) -> (usize, usize) {
        let nm = self.masses.len();
        (self.base() + j, self.base() + nm + j)
    }

    pub fn burnout_time(&self) -> f64 {
        if self.burn_rate > 0.0 {
            (self.m1_0 - self.m1_casing) / self.burn_rate
        } else {
            f64::INFINITY
        }
    }
    pub fn burning(&self, t: f64) -> bool {
        t < self.burnout_time()
    }
    /// Stage-1 mass per length m₁(t).
    pub fn m1(&self, t: f64) -> f64 {
        (self.m1_0 - self.burn_rate * t).max(self.m1_casing)
    }
    /// Mass flow through the nozzle Q̇ = ṁ L₁ (0 after burn-out).
    pub fn mass_flow(&self, t: f64) -> f64 {
        if self.burning(t) {
            self.burn_rate * self.l1
        } else {
            0.0
        }
    }
    pub fn total_mass(&self, t: f64) -> f64 {
        self.m1(t) * self.l1
            + self.m_fixed.form(&self.t_xi, &self.t_xi)
            + self.masses.iter().map(|m| m.mass).sum::<f64>()
    }

    /// y += s·M(m₁) x (case and discrete masses).
    pub fn mass_mul_add(&self, m1: f64, s: f64, x: &[f64], y: &mut [f64]) {
        self.m_fixed.mul_add(s, x, y);
        self.m_burn.mul_add(s * m1, x, y);
        for (j, m) in self.masses.iter().enumerate() {
            let (iu, iw) = self.mass_dofs(j);
            y[iu] += s * m.mass * x[iu];
            y[iw] += s * m.mass * x[iw];
        }
    }

    /// xᵀ M(m₁) y.
    pub fn mass_form(&self, m1: f64, x: &[f64], y: &[f64]) -> f64 {
        let mut v = self.m_fixed.form(x, y) + m1 * self.m_burn.form(x, y);
        for (j, m) in self.masses.iter().enumerate() {
            let (iu, iw) = self.mass_dofs(j);
            v += m.mass * (x[iu] * y[iu] + x[iw] * y[iw]);
        }
        v
    }

    /// Gravity in launch axes (ξ, η) = (−g sin θ₀, −g cos θ₀).
    pub fn gravity(&self) -> (f64, f64) {
        (-self.g * self.theta0.sin(), -self.g * self.theta0.cos())
    }

    /// Mean axis of the case with respect to its ignition mass m₀: the rigid placement that
    /// best fits the case's material points in the m₀-weighted least-squares sense — centroid
    /// c = ∫m₀R/m₀ and angle φ = atan2(∫m₀(x − x̄)R_η, ∫m₀(x − x̄)R_ξ) — and the angle's rate.
    pub fn mean_axis(&self, q: &[f64], v: &[f64]) -> MeanAxis {
        use crate::linalg::dot;
        let sx = dot(&self.a_s_xi, &self.x_ref) + dot(&self.a_s_xi, q);
        let sy = dot(&self.a_s_eta, q);
        let (dsx, dsy) = (dot(&self.a_s_xi, v), dot(&self.a_s_eta, v));
        MeanAxis {
            c_xi: dot(&self.a_c_xi, &self.x_ref) + dot(&self.a_c_xi, q),
            c_eta: dot(&self.a_c_eta, q),
            phi: sy.atan2(sx),
            rate: (sx * dsy - sy * dsx) / (sx * sx + sy * sy),
        }
    }

    /// Field values (u, w) at a point.
    pub fn at(&self, p: &Point, q: &[f64]) -> (f64, f64) {
        let u = p.nu[0] * q[p.iu[0]] + p.nu[1] * q[p.iu[1]];
        let w = (0..4).map(|a| p.hw[a] * q[p.iw[a]]).sum();
        (u, w)
    }

    /// Adds a point force (f_ξ, f_η) at p to the generalized force vector.
    pub fn add_point_force(&self, p: &Point, f: (f64, f64), out: &mut [f64]) {
        for a in 0..2 {
            out[p.iu[a]] += p.nu[a] * f.0;
        }
        for a in 0..4 {
            out[p.iw[a]] += p.hw[a] * f.1;
        }
    }

    /// Point on the mesh at x.
    pub fn point(&self, x: f64) -> Point {
        mesh_point(x, self.h, self.elements)
    }

    /// Strain energy V = ∫½EA u′² + ½EI w″² + ½EA u′w′² (report eq. 3.50, P = EA u′).
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        let mut v = 0.5 * self.k_beam.form(q, q);
        for qp in &self.quad {
            let (up, wp) = self.slopes(qp, q);
            v += qp.weight * 0.5 * qp.ea * up * wp * wp;
        }
        v
    }

    fn slopes(&self, qp: &Quad, q: &[f64]) -> (f64, f64) {
        let (iu, iw) = dofs_of(qp.element);
        let (du, hd) = qp.slopes;
        let up = du[0] * q[iu[0]] + du[1] * q[iu[1]];
        let wp = (0..4).map(|a| hd[a] * q[iw[a]]).sum::<f64>();
        (up, wp)
    }

    /// out −= ∂V/∂q (beam only).
    pub fn add_elastic_forces(&self, q: &[f64], out: &mut [f64]) {
        self.k_beam.mul_add(-1.0, q, out);
        for qp in &self.quad {
            let (up, wp) = self.slopes(qp, q);
            let (iu, iw) = dofs_of(qp.element);
            let (du, hd) = qp.slopes;
            let fu = qp.weight * 0.5 * qp.ea * wp * wp;
            let fw = qp.weight * qp.ea * up * wp;
            for a in 0..2 {
                out[iu[a]] -= fu * du[a];
            }
            for a in 0..4 {
                out[iw[a]] -= fw * hd[a];
            }
        }
    }

    /// Relative displacement and velocity of each spring (case→mass j, and coupling k), in
    /// launch axes.
    fn spring_gap(&self, j: usize, q: &[f64]) -> (f64, f64) {
        let (iu, iw) = self.mass_dofs(j);
        let (uc, wc) = self.at(&self.masses[j].at, q);
        (q[iu] - uc, q[iw] - wc)
    }

    /// Springs and dampers of the discrete masses: to the case axial / transverse along the
    /// case's mean axis at angle φ; between masses in the whole body's axes (report eqs. 3.50
    /// and 5.37: the masses' displacements are body-axis ones, and the body axes weight case
    /// and masses), so a rigid motion stretches none. Adds the forces to `out`; returns
    /// (spring energy, damper power).
    pub fn add_spring_forces(&self, phi: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> (f64, f64) {
        let (c, s) = (phi.cos(), phi.sin());
        let (mut energy, mut power) = (0.0, 0.0);
        // force on the "plus" side from gap d and rate dd: −k_a (d·e)e − k_t (d·n)n − damping
        let law = |d: (f64, f64), dd: (f64, f64), ku: f64, kw: f64, cu: f64, cw: f64| {
            let (da, dt) = (c * d.0 + s * d.1, -s * d.0 + c * d.1);
            let (ra, rt) = (c * dd.0 + s * dd.1, -s * dd.0 + c * dd.1);
            let (fa, ft) = (-ku * da - cu * ra, -kw * dt - cw * rt);
            let f = (c * fa - s * ft, s * fa + c * ft);
            (
                f,
                0.5 * ku * da * da + 0.5 * kw * dt * dt,
                cu * ra * ra + cw * rt * rt,
            )
        };
        for (j, m) in self.masses.iter().enumerate() {
            let (iu, iw) = self.mass_dofs(j);
            let d = self.spring_gap(j, q);
            let dd = self.spring_gap(j, v);
            let (f, e, p) = law(d, dd, m.ku, m.kw, m.cu, m.cw);
            out[iu] += f.0;
            out[iw] += f.1;
            self.add_point_force(&m.at, (-f.0, -f.1), out);
            energy += e;
            power += p;
        }
        if self.couplings.is_empty() {
            return (energy, power);
        }
        let body = self.body_axes(q);
        for cp in &self.couplings {
            let st = self.coupling_stretch(cp, &body, q);
            // d/dt of the stretch is its Jacobian applied to v
            let rate = self.coupling_rate(cp, &body, &st, v);
            let (ga, gt) = (
                cp.ku * st.axial + cp.cu * rate.0,
                cp.kw * st.transverse + cp.cw * rate.1,
            );
            self.add_coupling_force(cp, &body, &st, (-ga, -gt), out);
            energy += 0.5 * cp.ku * st.axial.powi(2) + 0.5 * cp.kw * st.transverse.powi(2);
            power += cp.cu * rate.0 * rate.0 + cp.cw * rate.1 * rate.1;
        }
        (energy, power)
    }

    /// Angle ψ of the whole body's mean axis and the sums (S_ξ, S_η) it is the atan2 of.
    fn body_axes(&self, q: &[f64]) -> BodyAxes {
        use crate::linalg::dot;
        let sx = dot(&self.b_s_xi, &self.x_ref) + dot(&self.b_s_xi, q);
        let sy = dot(&self.b_s_eta, q);
        BodyAxes {
            psi: sy.atan2(sx),
            sx,
            sy,
        }
    }

    /// A spring between masses a and b in the body axes: the gap D = R_a − R_b turned by −ψ,
    /// less its reference (x_a − x_b, 0). A rigid motion of the whole body leaves it at zero.
    fn coupling_stretch(&self, cp: &Coupling, body: &BodyAxes, q: &[f64]) -> Stretch {
        let (au, aw) = self.mass_dofs(cp.a);
        let (bu, bw) = self.mass_dofs(cp.b);
        let dx = self.x_ref[au] - self.x_ref[bu];
        let d = (dx + q[au] - q[bu], q[aw] - q[bw]);
        let (c, s) = (body.psi.cos(), body.psi.sin());
        Stretch {
            axial: c * d.0 + s * d.1 - dx,
            transverse: -s * d.0 + c * d.1,
            dx,
        }
    }

    /// J v for the stretch's Jacobian J: the gap's rate turned by −ψ, plus ψ̇ = ∇ψ·v times
    /// ∂(axial, transverse)/∂ψ = (transverse, −(axial + Δx)).
    fn coupling_rate(&self, cp: &Coupling, body: &BodyAxes, st: &Stretch, v: &[f64]) -> (f64, f64) {
        use crate::linalg::dot;
        let (au, aw) = self.mass_dofs(cp.a);
        let (bu, bw) = self.mass_dofs(cp.b);
        let dd = (v[au] - v[bu], v[aw] - v[bw]);
        let (c, s) = (body.psi.cos(), body.psi.sin());
        let psi_rate = (body.sx * dot(&self.b_s_eta, v) - body.sy * dot(&self.b_s_xi, v))
            / (body.sx * body.sx + body.sy * body.sy);
        (
            c * dd.0 + s * dd.1 + psi_rate * st.transverse,
            -s * dd.0 + c * dd.1 - psi_rate * (st.axial + st.dx),
        )
    }

    /// Adds Jᵀ(g_a, g_t) to `out` (J the stretch's Jacobian): `g` = (−∂E/∂axial, −∂E/∂transverse)
    /// gives the generalized spring (and damper) force.
    fn add_coupling_force(
        &self,
        cp: &Coupling,
        body: &BodyAxes,
        st: &Stretch,
        g: (f64, f64),
        out: &mut [f64],
    ) {
        let (au, aw) = self.mass_dofs(cp.a);
        let (bu, bw) = self.mass_dofs(cp.b);
        let (c, s) = (body.psi.cos(), body.psi.sin());
        let f = (c * g.0 - s * g.1, s * g.0 + c * g.1);
        out[au] += f.0;
        out[aw] += f.1;
        out[bu] -= f.0;
        out[bw] -= f.1;
        // through ψ: (g_a·transverse − g_t·(axial + Δx)) ∇ψ, ∇ψ = (S_ξ b_s_η − S_η b_s_ξ)/|S|²
        let along_psi = (g.0 * st.transverse - g.1 * (st.axial + st.dx))
            / (body.sx * body.sx + body.sy * body.sy);
        for ((o, e), x) in out.iter_mut().zip(&self.b_s_eta).zip(&self.b_s_xi) {
            *o += along_psi * (body.sx * e - body.sy * x);
        }
    }

    /// The body-axis springs' stiffness at the straight body at rest that the launch-axis
    /// entries of [`Model::spring_entries`] leave out. The transverse stretch's gradient there is
    /// g₀ + d, g₀ = e_{W_a} − e_{W_b} (launch axes) and d = −Δx ∇ψ (∇ψ = b_s_η / S_ξ), so the
    /// missing part of k_w g gᵀ is k_w(g₀dᵀ + d g₀ᵀ + d dᵀ). Dense in the case's transverse DOFs
    /// (through ∇ψ); used by the eigenproblem only (the time step's Newton matrix keeps the
    /// banded launch-axis part).
    pub fn coupling_rotation_stiffness(&self) -> Vec<(usize, usize, f64)> {
        let rest = self.body_axes(&vec![0.0; self.n]);
        let mut out = Vec::new();
        for cp in &self.couplings {
            let ((au, aw), (bu, bw)) = (self.mass_dofs(cp.a), self.mass_dofs(cp.b));
            let dx = self.x_ref[au] - self.x_ref[bu];
            let d: Vec<f64> = self.b_s_eta.iter().map(|e| -dx * e / rest.sx).collect();
            for (i, di) in d.iter().enumerate() {
                for (j, dj) in d.iter().enumerate() {
                    out.push((i, j, cp.kw * di * dj));
                }
                for (w, sign) in [(aw, 1.0), (bw, -1.0)] {
                    out.push((w, i, cp.kw * sign * di));
                    out.push((i, w, cp.kw * sign * di));
                }
            }
        }
        out.retain(|e| e.2 != 0.0);
        out
    }

    /// Spring (and damper) stiffness in launch axes (φ = 0): the linear part of
    /// [`Model::add_spring_forces`], as (i, j, k, c) entries.
    pub fn spring_entries(&self) -> Vec<(usize, usize, f64, f64)> {
        let mut e = Vec::new();
        let mut pair = |a: &[(usize, f64)], k: f64, c: f64| {
            for &(i, wi) in a {
                for &(j, wj) in a {
                    e.push((i, j, k * wi * wj, c * wi * wj));
                }
            }
        };
        for (j, m) in self.masses.iter().enumerate() {
            let (iu, iw) = self.mass_dofs(j);
            let mut au = vec![(iu, 1.0)];
            au.extend((0..2).map(|a| (m.at.iu[a], -m.at.nu[a])));
            pair(&au, m.ku, m.cu);
            let mut aw = vec![(iw, 1.0)];
            aw.extend((0..4).map(|a| (m.at.iw[a], -m.at.hw[a])));
            pair(&aw, m.kw, m.cw);
        }
        for cp in &self.couplings {
            let (au, aw) = self.mass_dofs(cp.a);
            let (bu, bw) = self.mass_dofs(cp.b);
            pair(&[(au, 1.0), (bu, -1.0)], cp.ku, cp.cu);
            pair(&[(aw, 1.0), (bw, -1.0)], cp.kw, cp.cw);
        }
        e
    }

    pub fn damped(&self) -> bool {
        self.masses.iter().any(|m| m.cu > 0.0 || m.cw > 0.0)
            || self.couplings.iter().any(|c| c.cu > 0.0 || c.cw > 0.0)
    }

    /// Initial nodal displacements: the scene's w(x, 0) (nodal values and slopes) minus its
    /// rigid part with respect to m₀ — the m₀-weighted least-squares line, so that the case's
    /// mean axis starts on the launch axis through the origin. Discrete masses start at rest
    /// at U = W = 0.
    pub fn initial_shape(&self, shape: &InitialShape) -> Vec<f64> {
        let mut q = vec![0.0; self.n];
        for i in 0..self.nodes {
            let x = i as f64 * self.h;
            q[DOFS_PER_NODE * i + 1] = shape.deflection(x, self.length);
            q[DOFS_PER_NODE * i + 2] = shape_slope(shape, x, self.length);
        }
        // Least-squares line c₀ + c₁(x − x̄) with M₀ of the case: ∫m₀(x − x̄) = 0 decouples.
        use crate::linalg::dot;
        let c0 = dot(&self.a_c_eta, &q);
        let mut lin_w = vec![0.0; self.n];
        for i in 0..self.nodes {
            lin_w[DOFS_PER_NODE * i + 1] = i as f64 * self.h - self.x_bar;
            lin_w[DOFS_PER_NODE * i + 2] = 1.0;
        }
        let c1 = dot(&self.a_s_eta, &q) / dot(&self.a_s_eta, &lin_w);
        for i in 0..self.nodes {
            q[DOFS_PER_NODE * i + 1] -= c0 + c1 * (i as f64 * self.h - self.x_bar);
            q[DOFS_PER_NODE * i + 2] -= c1;
        }
        q
    }
}

/// dw/dx of the scene's initial shape.
fn shape_slope(shape: &InitialShape, x: f64, length: f64) -> f64 {
    use std::f64::consts::PI;
    match *shape {
        InitialShape::Report { a1, a2 } => {
            a1 * PI / length * (PI * x / length).cos()
                + a2 * (-6.0 / (PI * length) - 2.0 * PI / length * (2.0 * PI * x / length).cos())
        }
        InitialShape::Straight => 0.0,
    }
}
