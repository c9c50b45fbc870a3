//! Equations of motion of the reduced rocket: M(q, t) z = Q(q, v, t) − h(q, v, t).
//!
//! Kinematics (body frame at the aft end of the undeformed axis, angle θ from the horizontal):
//!   case point x:     R = R_O + A(θ) r,   r = (x + u, w),      u = Σ a_k U_k(x), w = Σ b_k W_k(x)
//!   discrete mass j:  R_j = R_O + A(θ) r_j, r_j = (x_j + u_j, w_j)
//! Velocities are taken as quasi-velocities v = (V, ω, ȧ, ḃ, u̇_j, ẇ_j) with V = Aᵀ Ṙ_O the body
//! components of the origin's velocity, so the body-frame acceleration of a point is
//!   a = V̇ + ω̇ J r + r̈ + c,   c = ω J V + 2ω J ṙ − ω² r,   J = [[0, −1], [1, 0]].
//! The equations are d'Alembert's principle with the *current* mass m(x, t):
//!   ∫ m a·δr_b dx + Σ M_j a_j·δr_j = δW(thrust, pressure, jet Coriolis, gravity) − δV(strain, springs)
//!                                    − δ(dampers),
//! so burnt mass leaves with the local case velocity and exerts no force of its own (the report's
//! ṁ Ṙ_c terms cancel, eqs. 3.16–3.18, 3.43). Every mass integral is affine in the burnt fraction
//! (see [`super::integrals`]).
//!
//! The strain energy is V = ½∫EA u'² + ½∫EI w''² + ½∫P w'² with P = EA u' (report eq. 3.50):
//! the last term couples the axial force to bending (thrust compression softens bending). The
//! equations use the gradient of this V, so energy stays consistent.

use super::basis::Basis;
use super::body::{Body, Coupling, PointMass};
use super::integrals::{Moments, QuadTable};
use crate::linalg::{cholesky_factor, cholesky_substitute, dot, mat_vec};

/// Indices of the state vector y = [q | v | quadratures].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Modes per field.
    pub n: usize,
    /// Discrete masses.
    pub nm: usize,
}

/// Quadrature states appended to the ODE (cumulative balances, inertial components).
pub mod quad {
    pub const IMP_THRUST: usize = 0;
    pub const IMP_PRESSURE: usize = 2;
    pub const IMP_CORIOLIS: usize = 4;
    pub const IMP_GRAVITY: usize = 6;
    /// Momentum carried away by the burnt mass, ∫∫ ṁ Ṙ dx dt.
    pub const MOM_OUTFLOW: usize = 8;
    pub const W_THRUST: usize = 10;
    pub const W_PRESSURE: usize = 11;
    pub const W_CORIOLIS: usize = 12;
    /// Energy carried away by the burnt mass, ∫∫ ṁ (½|Ṙ|² + g R_Y) dx dt (≤ 0 while burning).
    pub const E_OUTFLOW: usize = 13;
    pub const W_DAMPING: usize = 14;
    pub const COUNT: usize = 15;
}

impl Layout {
    /// Generalized coordinates: X, Y, θ, n axial, n transverse, nm mass-axial, nm mass-transverse.
    pub fn dofs(&self) -> usize {
        3 + 2 * self.n + 2 * self.nm
    }
    pub fn a(&self) -> usize {
        3
    }
    pub fn b(&self) -> usize {
        3 + self.n
    }
    pub fn mu(&self) -> usize {
        3 + 2 * self.n
    }
    pub fn mw(&self) -> usize {
        3 + 2 * self.n + self.nm
    }
    /// Offset of the quadrature states in y.
    pub fn quad(&self) -> usize {
        2 * self.dofs()
    }
    pub fn state_len(&self) -> usize {
        2 * self.dofs() + quad::COUNT
    }
}

/// Mode values (U_k, W_k) at a station.
#[derive(Debug, Clone, PartialEq)]
pub struct StationModes {
    pub x: f64,
    pub u: Vec<f64>,
    pub w: Vec<f64>,
}

impl StationModes {
    pub fn new(basis: &Basis, x: f64) -> StationModes {
        let n = basis.modes();
        StationModes {
            x,
            u: (0..n)
                .map(|k| basis.axial.eval(&basis.mesh, k, x).0)
                .collect(),
            w: (0..n)
                .map(|k| basis.bending.eval(&basis.mesh, k, x).0)
                .collect(),
        }
    }
}

/// Axial-force / slope coupling ½∫EA u' w'² = ½ Σ G_klm a_k b_l b_m with the third-order
/// tensor G_klm = ∫EA U_k' W_l' W_m' dx, integrated at set-up with 3 Gauss points per element
/// (the integrand is a degree-5 polynomial there: exact). Evaluating the energy gradient then
/// costs 2n³ per right-hand side, independent of the fine mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricTensor {
    pub n: usize,
    /// G_klm at k·n² + l·n + m (symmetric in l, m).
    pub g: Vec<f64>,
}

impl GeometricTensor {
    fn new(basis: &Basis) -> GeometricTensor {
        let t3 = QuadTable::new(basis, 3);
        let n = t3.n;
        let mut g = vec![0.0; n * n * n];
        for p in 0..t3.points() {
            let wea = basis.mesh.elements[t3.element[p]].ea * t3.weight[p];
            let du = &t3.du[p * n..(p + 1) * n];
            let dw = &t3.dw[p * n..(p + 1) * n];
            for k in 0..n {
                for l in 0..n {
                    let c = wea * du[k] * dw[l];
                    for m in 0..n {
                        g[(k * n + l) * n + m] += c * dw[m];
                    }
                }
            }
        }
        GeometricTensor { n, g }
    }
}

/// Everything fixed at set-up.
#[derive(Debug, Clone)]
pub struct Model {
    pub body: Body,
    pub layout: Layout,
    /// Moments of the ignition case mass m₀(x).
    pub m0: Moments,
    /// Moments of the chamber indicator χ(x) (unit weight on 0 ≤ x ≤ L₁).
    pub chi: Moments,
    /// Moments of the internal-flow weight κ(x) = (1 − x/L₁) χ(x): m_f v = Q̇ κ(x) (eq. 5.18).
    pub kappa: Moments,
    pub ka: Vec<f64>,
    pub kb: Vec<f64>,
    pub geo: GeometricTensor,
    pub aft: StationModes,
    pub chamber_end: Option<StationModes>,
    pub at_mass: Vec<StationModes>,
    /// Elastic frequencies of the constant-mass case (rad/s), axial and bending.
    pub omega_axial: Vec<f64>,
    pub omega_bending: Vec<f64>,
    /// Modal coordinates b of the initial transverse shape (mass-weighted least squares).
    pub initial_b: Vec<f64>,
    /// ‖w₀ − Σ b_k W_k‖ / ‖w₀‖ in the m₀-weighted norm (0 for a straight body). What is left
    /// over is the rigid-body part of w₀ (with respect to m₀) and the higher modes.
    pub initial_shape_residual: f64,
    /// c_p = M_p (x_p − x_c) / I_c: the whole body's mean-axis angle relative to this frame is
    /// φ = Σ c_p w_p ([`Model::coupling_stretch_w`]).
    pub mass_tilt: Vec<f64>,
}

impl Model {
    pub fn new(body: Body, basis: &Basis) -> Model {
        let n = basis.modes();
        let nm = body.masses.len();
        let table = QuadTable::new(basis, 4);
        let mesh = &basis.mesh;
        let m0 = table.moments(|g, _| mesh.elements[table.element[g]].mass0);
        let chi = table.moments(|g, _| {
            if mesh.elements[table.element[g]].burning {
                1.0
            } else {
                0.0
            }
        });
        let l1 = body.burn.as_ref().map_or(0.0, |b| b.chamber_end);
        let kappa = table.moments(|g, x| {
            if mesh.elements[table.element[g]].burning {
                1.0 - x / l1
            } else {
                0.0
            }
        });
        let (ka, kb) = table.stiffness(basis);
        let (initial_b, initial_shape_residual) = project_initial_shape(&body, &table, basis, &m0);
        let geo = GeometricTensor::new(basis);
        let aft = StationModes::new(basis, 0.0);
        let chamber_end = body
            .burn
            .as_ref()
            .map(|b| StationModes::new(basis, b.chamber_end));
        let at_mass = body
            .masses
            .iter()
            .map(|m| StationModes::new(basis, m.x))
            .collect();
        let mass_tilt = whole_body_tilt(&m0, &body.masses);
        Model {
            mass_tilt,
            layout: Layout { n, nm },
            m0,
            chi,
            kappa,
            ka,
            kb,
            geo,
            aft,
            chamber_end,
            at_mass,
            omega_axial: basis.axial.omega.clone(),
            omega_bending: basis.bending.omega.clone(),
            initial_b,
            initial_shape_residual,
            body,
        }
    }

    /// Transverse stretch of a spring between masses, measured across the whole body's mean
    /// axis (report eqs. 3.50 and 5.37: the masses' displacements are body-axis ones and the
    /// body axes are weighted by case *and* masses): w_i − w_j − (x_i − x_j) φ,
    /// φ = Σ c_p w_p. This frame is the case's mean axis (∫m₀W_k = ∫m₀xW_k = 0), so the case
    /// adds nothing to φ. Also the rate of stretch when given the rates ẇ.
    pub fn coupling_stretch_w(&self, c: &Coupling, w: &[f64]) -> f64 {
        let phi = dot(&self.mass_tilt, w);
        let dx = self.body.masses[c.i].x - self.body.masses[c.j].x;
        w[c.i] - w[c.j] - dx * phi
    }

    /// ∂(stretch)/∂w_p of [`Model::coupling_stretch_w`] for every mass p.
    pub fn coupling_gradient_w(&self, c: &Coupling, p: usize) -> f64 {
        let dx = self.body.masses[c.i].x - self.body.masses[c.j].x;
        let unit = |m: usize| if p == m { 1.0 } else { 0.0 };
        unit(c.i) - unit(c.j) - dx * self.mass_tilt[p]
    }

    /// Burnt mass per length Δm·s(t) removed from the chamber.
    pub fn burnt_per_length(&self, t: f64) -> f64 {
        self.body
            .burn
            .as_ref()
            .map_or(0.0, |b| b.burnable * b.burnt_fraction(t))
    }
}

/// Mass-weighted least-squares projection of the scene's initial w(x, 0) onto the bending
/// modes: minimize ∫m₀ (w₀ − Σ b_k W_k)² dx, i.e. solve (∫m₀ W_k W_l) b = ∫m₀ w₀ W_k.
fn project_initial_shape(
    body: &Body,
    table: &QuadTable,
    basis: &Basis,
    m0: &Moments,
) -> (Vec<f64>, f64) {
    let n = table.n;
    let mesh = &basis.mesh;
    let mut rhs = vec![0.0; n];
    let mut norm2 = 0.0;
    for g in 0..table.points() {
        let x = table.x[g];
        let w0 = body.initial_shape.deflection(x, body.length);
        let r = mesh.elements[table.element[g]].mass0 * table.weight[g];
        norm2 += r * w0 * w0;
        for k in 0..n {
            rhs[k] += r * w0 * table.w[g * n + k];
        }
    }
    if norm2 == 0.0 {
        return (vec![0.0; n], 0.0);
    }
    let mut gram = m0.ww.clone();
    let mut b = rhs.clone();
    if cholesky_factor(&mut gram, n).is_ok() {
        cholesky_substitute(&gram, n, &mut b);
    } else {
        // The eigenfunctions are m₀-orthogonal, so the Gram matrix is diagonal and positive;
        // a failed factorization can only be round-off: use its diagonal.
        for k in 0..n {
            b[k] = rhs[k] / m0.ww[k * n + k];
        }
    }
    // ‖w₀ − P w₀‖² = ‖w₀‖² − bᵀ r for an orthogonal projection
    let res2 = (norm2 - dot(&b, &rhs)).max(0.0);
    (b, (res2 / norm2).sqrt())
}

/// Per-evaluation workspace (allocated once).
#[derive(Debug, Clone)]
pub struct Workspace {
    pub mom: Moments,
    pub mass: Vec<f64>,
    pub mass_chi: Vec<f64>,
    pub rhs: Vec<f64>,
    pub tmp: Vec<f64>,
    pub geo_grad: Vec<f64>,
    pub failed_pivot: Option<(f64, usize)>,
    pub phase: Phase,
}

impl Workspace {
    pub fn new(layout: Layout) -> Workspace {
        let nd = layout.dofs();
        Workspace {
            mom: Moments::zeros(layout.n),
            mass: vec![0.0; nd * nd],
            mass_chi: vec![0.0; nd * nd],
            rhs: vec![0.0; nd],
            tmp: vec![0.0; nd],
            geo_grad: vec![0.0; 2 * layout.n],
            failed_pivot: None,
            phase: Phase::ByTime,
        }
    }
}

fn mv(a: &[f64], n: usize, x: &[f64], k: usize) -> f64 {
    dot(&a[k * n..(k + 1) * n], &x[..n])
}
fn mtv(a: &[f64], n: usize, x: &[f64], l: usize) -> f64 {
    (0..n).map(|k| a[k * n + l] * x[k]).sum()
}

/// Body-frame geometric quantities of a configuration for a weight's moments.
struct Shape {
    /// ∫ρ(x+u), ∫ρw
    sx: f64,
    sy: f64,
    /// ∫ρ|r|²
    jrr: f64,
}

fn beam_shape(mom: &Moments, a: &[f64], b: &[f64]) -> Shape {
    let n = mom.n;
    let mut jrr = mom.second;
    for k in 0..n {
        jrr += 2.0 * mom.xu[k] * a[k] + a[k] * mv(&mom.uu, n, a, k) + b[k] * mv(&mom.ww, n, b, k);
    }
    Shape {
        sx: mom.first + dot(&mom.u, a),
        sy: dot(&mom.w, b),
        jrr,
    }
}

/// Fills the reduced mass matrix (row-major, full) for weight moments `mom`, optionally with the
/// discrete masses.
pub fn fill_mass_matrix(
    layout: Layout,
    body: &Body,
    mom: &Moments,
    q: &[f64],
    with_masses: bool,
    out: &mut [f64],
) {
    let nd = layout.dofs();
    let n = layout.n;
    out.iter_mut().for_each(|v| *v = 0.0);
    let a = &q[layout.a()..layout.a() + n];
    let b = &q[layout.b()..layout.b() + n];
    let sh = beam_shape(mom, a, b);
    let (mut mt, mut sx, mut sy, mut jrr) = (mom.total, sh.sx, sh.sy, sh.jrr);
    if with_masses {
        for (j, pm) in body.masses.iter().enumerate() {
            let (uj, wj) = (q[layout.mu() + j], q[layout.mw() + j]);
            mt += pm.mass;
            sx += pm.mass * (pm.x + uj);
            sy += pm.mass * wj;
            jrr += pm.mass * ((pm.x + uj).powi(2) + wj * wj);
            let (d, e) = (layout.mu() + j, layout.mw() + j);
            out[d * nd + d] = pm.mass;
            out[e * nd + e] = pm.mass;
            out[d] = pm.mass; // (0, D_j)
            out[nd + e] = pm.mass; // (1, E_j)
            out[2 * nd + d] = -pm.mass * wj;
            out[2 * nd + e] = pm.mass * (pm.x + uj);
        }
    }
    out[0] = mt;
    out[nd + 1] = mt;
    out[2] = -sy;
    out[nd + 2] = sx;
    out[2 * nd + 2] = jrr;
    let (ia, ib) = (layout.a(), layout.b());
    for k in 0..n {
        out[ia + k] = mom.u[k];
        out[nd + ib + k] = mom.w[k];
        // ω row: −∫ρ w U_k and ∫ρ (x+u) W_k
        out[2 * nd + ia + k] = -mv(&mom.uw, n, b, k);
        out[2 * nd + ib + k] = mom.xw[k] + mtv(&mom.uw, n, a, k);
        for l in 0..n {
            out[(ia + k) * nd + ia + l] = mom.uu[k * n + l];
            out[(ib + k) * nd + ib + l] = mom.ww[k * n + l];
        }
    }
    // symmetric completion of the first three rows
    for r in 0..3 {
        for c in r + 1..nd {
            out[c * nd + r] = out[r * nd + c];
        }
    }
}

/// Elastic displacement (u, w) and rates at a station from its mode values.
fn station_field(st: &StationModes, a: &[f64], b: &[f64]) -> (f64, f64) {
    (dot(&st.u, a), dot(&st.w, b))
}

/// Rotates body components to inertial ones.
pub fn to_inertial(theta: f64, f: (f64, f64)) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    (c * f.0 - s * f.1, s * f.0 + c * f.1)
}

/// Loads acting at time t (magnitudes).
#[derive(Debug, Clone, Copy)]
struct Loads {
    thrust: f64,
    chamber: f64,
    flow: f64,
    burn_rate: f64,
}

/// Whether the stage burns: thrust, chamber pressure and internal flow switch off together at
/// burn-out. The driver fixes the phase for each integration interval so that a step ending at
/// burn-out sees the burning forces at its end point and a step starting there sees none.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Burning iff t ≤ t_burnout (left-continuous), for callers integrating by themselves.
    ByTime,
    Burning,
    BurntOut,
}

fn loads(body: &Body, phase: Phase, t: f64) -> Loads {
    let burning = match (&body.burn, phase) {
        (None, _) => false,
        (Some(b), Phase::ByTime) => t <= b.burnout_time(),
        (Some(_), Phase::Burning) => true,
        (Some(_), Phase::BurntOut) => false,
    };
    match &body.burn {
        Some(b) if burning => Loads {
            thrust: b.mass_flow() * body.exhaust_velocity,
            chamber: body.pressure_force,
            flow: b.mass_flow(),
            burn_rate: b.rate,
        },
        _ => Loads {
            thrust: 0.0,
            chamber: 0.0,
            flow: 0.0,
            burn_rate: 0.0,
        },
    }
}

/// Accumulates a point force F (body components) at material station `st` into Q; returns its
/// power F·ṙ_point.
#[allow(clippy::too_many_arguments)]
fn point_force(
    layout: Layout,
    st: &StationModes,
    f: (f64, f64),
    q: &[f64],
    v: &[f64],
    rhs: &mut [f64],
) -> f64 {
    let n = layout.n;
    let (a, b) = (
        &q[layout.a()..layout.a() + n],
        &q[layout.b()..layout.b() + n],
    );
    let (ad, bd) = (
        &v[layout.a()..layout.a() + n],
        &v[layout.b()..layout.b() + n],
    );
    let (up, wp) = station_field(st, a, b);
    let (udp, wdp) = station_field(st, ad, bd);
    rhs[0] += f.0;
    rhs[1] += f.1;
    rhs[2] += -wp * f.0 + (st.x + up) * f.1;
    for k in 0..n {
        rhs[layout.a() + k] += st.u[k] * f.0;
        rhs[layout.b() + k] += st.w[k] * f.1;
    }
    let omega = v[2];
    let vx = v[0] - omega * wp + udp;
    let vy = v[1] + omega * (st.x + up) + wdp;
    f.0 * vx + f.1 * vy
}

/// Strain energy of the case: ½aᵀK_a a + ½bᵀK_b b + ½∫EA u'w'², and its gradient (if asked).
pub fn strain_energy(model: &Model, a: &[f64], b: &[f64], grad: Option<&mut [f64]>) -> f64 {
    let n = model.layout.n;
    let mut e = 0.0;
    for k in 0..n {
        e += 0.5 * a[k] * mv(&model.ka, n, a, k) + 0.5 * b[k] * mv(&model.kb, n, b, k);
    }
    let g3 = &model.geo.g;
    if let Some(g) = grad {
        for k in 0..n {
            g[k] = mv(&model.ka, n, a, k);
            g[n + k] = mv(&model.kb, n, b, k);
        }
        for k in 0..n {
            let mut s = 0.0; // bᵀ G_k b
            for l in 0..n {
                let row = &g3[(k * n + l) * n..(k * n + l + 1) * n];
                let t = dot(row, b);
                s += b[l] * t;
                g[n + l] += a[k] * t;
            }
            g[k] += 0.5 * s;
            e += 0.5 * a[k] * s;
        }
    } else {
        for k in 0..n {
            for l in 0..n {
                let row = &g3[(k * n + l) * n..(k * n + l + 1) * n];
                e += 0.5 * a[k] * b[l] * dot(row, b);
            }
        }
    }
    e
}

/// c_p = M_p (x_p − x_c) / I_c over the ignition case mass and the discrete masses.
fn whole_body_tilt(m0: &Moments, masses: &[PointMass]) -> Vec<f64> {
    let total = m0.total + masses.iter().map(|m| m.mass).sum::<f64>();
    let first = m0.first + masses.iter().map(|m| m.mass * m.x).sum::<f64>();
    let second = m0.second + masses.iter().map(|m| m.mass * m.x * m.x).sum::<f64>();
    let centre = first / total;
    let inertia = second - total * centre * centre;
    masses
        .iter()
        .map(|m| m.mass * (m.x - centre) / inertia)
        .collect()
}

/// Potential energy of the discrete springs (to the case and between masses).
pub fn spring_energy(model: &Model, q: &[f64]) -> f64 {
    let l = model.layout;
    let n = l.n;
    let (a, b) = (&q[l.a()..l.a() + n], &q[l.b()..l.b() + n]);
    let mut e = 0.0;
    for (j, pm) in model.body.masses.iter().enumerate() {
        let (uc, wc) = station_field(&model.at_mass[j], a, b);
        e +=
            0.5 * pm.ku * (q[l.mu() + j] - uc).powi(2) + 0.5 * pm.kw * (q[l.mw() + j] - wc).powi(2);
    }
    let w = &q[l.mw()..l.mw() + l.nm];
    for c in &model.body.couplings {
        e += 0.5 * c.ku * (q[l.mu() + c.i] - q[l.mu() + c.j]).powi(2)
            + 0.5 * c.kw * model.coupling_stretch_w(c, w).powi(2);
    }
    e
}

/// Evaluates dy/dt. Returns false if the mass matrix lost positive definiteness (then the
/// failure is recorded in the workspace and dydt is set to NaN so the integrator rejects it).
pub fn rhs(model: &Model, ws: &mut Workspace, t: f64, y: &[f64], dydt: &mut [f64]) -> bool {
    let l = model.layout;
    let (n, nm, nd) = (l.n, l.nm, l.dofs());
    let body = &model.body;
    let q = &y[..nd];
    let v = &y[nd..2 * nd];
    let ld = loads(body, ws.phase, t);
    ws.mom
        .set_affine(&model.m0, model.burnt_per_length(t), &model.chi);
    fill_mass_matrix(l, body, &ws.mom, q, true, &mut ws.mass);

    let theta = q[2];
    let (vx, vy, om) = (v[0], v[1], v[2]);
    let a = &q[l.a()..l.a() + n];
    let b = &q[l.b()..l.b() + n];
    let ad = &v[l.a()..l.a() + n];
    let bd = &v[l.b()..l.b() + n];
    let mom = &ws.mom;

    // Body-frame sums over case and discrete masses.
    let sh = beam_shape(mom, a, b);
    let (mut mt, mut sx, mut sy) = (mom.total, sh.sx, sh.sy);
    let (mut sud, mut swd) = (dot(&mom.u, ad), dot(&mom.w, bd)); // ∫μu̇, ∫μẇ
    // ∫μ w ẇ and ∫μ (x+u) u̇
    let mut wwd = 0.0;
    let mut xuud = dot(&mom.xu, ad);
    for k in 0..n {
        wwd += b[k] * mv(&mom.ww, n, bd, k);
        xuud += a[k] * mv(&mom.uu, n, ad, k);
    }
    for (j, pm) in body.masses.iter().enumerate() {
        let (uj, wj) = (q[l.mu() + j], q[l.mw() + j]);
        let (udj, wdj) = (v[l.mu() + j], v[l.mw() + j]);
        mt += pm.mass;
        sx += pm.mass * (pm.x + uj);
        sy += pm.mass * wj;
        sud += pm.mass * udj;
        swd += pm.mass * wdj;
        wwd += pm.mass * wj * wdj;
        xuud += pm.mass * (pm.x + uj) * udj;
    }

    // rhs = Q − h
    let r = &mut ws.rhs;
    r.iter_mut().for_each(|x| *x = 0.0);
    // velocity terms h (moved to the right-hand side with a minus sign)
    r[0] -= -om * vy * mt - 2.0 * om * swd - om * om * sx;
    r[1] -= om * vx * mt + 2.0 * om * sud - om * om * sy;
    r[2] -= om * vy * sy + 2.0 * om * wwd + om * vx * sx + 2.0 * om * xuud;
    for k in 0..n {
        r[l.a() + k] -= -om * vy * mom.u[k]
            - 2.0 * om * mv(&mom.uw, n, bd, k)
            - om * om * (mom.xu[k] + mv(&mom.uu, n, a, k));
        r[l.b() + k] -=
            om * vx * mom.w[k] + 2.0 * om * mtv(&mom.uw, n, ad, k) - om * om * mv(&mom.ww, n, b, k);
    }
    for (j, pm) in body.masses.iter().enumerate() {
        let (uj, wj) = (q[l.mu() + j], q[l.mw() + j]);
        let (udj, wdj) = (v[l.mu() + j], v[l.mw() + j]);
        r[l.mu() + j] -= pm.mass * (-om * vy - 2.0 * om * wdj - om * om * (pm.x + uj));
        r[l.mw() + j] -= pm.mass * (om * vx + 2.0 * om * udj - om * om * wj);
    }

    // gravity, body components g_b = Aᵀ (0, −g)
    let g = body.gravity;
    let (gx, gy) = (-g * theta.sin(), -g * theta.cos());
    r[0] += mt * gx;
    r[1] += mt * gy;
    r[2] += -gx * sy + gy * sx;
    for k in 0..n {
        r[l.a() + k] += gx * mom.u[k];
        r[l.b() + k] += gy * mom.w[k];
    }
    for (j, pm) in body.masses.iter().enumerate() {
        r[l.mu() + j] += pm.mass * gx;
        r[l.mw() + j] += pm.mass * gy;
    }

    // thrust (direction γ from the axis, at the nozzle x = 0) and chamber pressure
    let gam = body.nozzle_angle;
    let f_thrust = (ld.thrust * gam.cos(), ld.thrust * gam.sin());
    let p_thrust = point_force(l, &model.aft, f_thrust, q, v, r);
    let mut p_press = 0.0;
    let (p_aft, p_head) = (-ld.chamber, ld.chamber);
    if let Some(ce) = &model.chamber_end {
        p_press += point_force(l, &model.aft, (p_aft, 0.0), q, v, r);
        p_press += point_force(l, ce, (p_head, 0.0), q, v, r);
    }

    // jet Coriolis force f_y = 2ω m_f v = 2ω Q̇ κ(x) on the chamber (eq. 3.36)
    let cc = 2.0 * om * ld.flow;
    let kap = &model.kappa;
    let mut p_cor = 0.0;
    if cc != 0.0 {
        r[1] += cc * kap.total;
        r[2] += cc * (kap.first + dot(&kap.u, a));
        for k in 0..n {
            r[l.b() + k] += cc * kap.w[k];
        }
        p_cor = cc * (kap.total * vy + om * (kap.first + dot(&kap.u, a)) + dot(&kap.w, bd));
    }

    // strain (with the axial-force coupling) and springs/dampers
    let _ = strain_energy(model, a, b, Some(&mut ws.geo_grad));
    for k in 0..n {
        r[l.a() + k] -= ws.geo_grad[k];
        r[l.b() + k] -= ws.geo_grad[n + k];
    }
    let mut p_damp = 0.0;
    for (j, pm) in body.masses.iter().enumerate() {
        let st = &model.at_mass[j];
        let (uc, wc) = station_field(st, a, b);
        let (udc, wdc) = station_field(st, ad, bd);
        let du = q[l.mu() + j] - uc;
        let dw = q[l.mw() + j] - wc;
        let dud = v[l.mu() + j] - udc;
        let dwd = v[l.mw() + j] - wdc;
        let fu = pm.ku * du + pm.cu * dud;
        let fw = pm.kw * dw + pm.cw * dwd;
        p_damp += pm.cu * dud * dud + pm.cw * dwd * dwd;
        r[l.mu() + j] -= fu;
        r[l.mw() + j] -= fw;
        for k in 0..n {
            r[l.a() + k] += fu * st.u[k];
            r[l.b() + k] += fw * st.w[k];
        }
    }
    for c in &body.couplings {
        let (i, j) = (c.i, c.j);
        let dud = v[l.mu() + i] - v[l.mu() + j];
        let dwd = model.coupling_stretch_w(c, &v[l.mw()..l.mw() + nm]);
        let fu = c.ku * (q[l.mu() + i] - q[l.mu() + j]) + c.cu * dud;
        let fw = c.kw * model.coupling_stretch_w(c, &q[l.mw()..l.mw() + nm]) + c.cw * dwd;
        p_damp += c.cu * dud * dud + c.cw * dwd * dwd;
        r[l.mu() + i] -= fu;
        r[l.mu() + j] += fu;
        for p in 0..nm {
            r[l.mw() + p] -= fw * model.coupling_gradient_w(c, p);
        }
    }

    // quadratures (computed before the solve overwrites rhs): momentum and energy flows
    let qd = &mut dydt[l.quad()..];
    let it = to_inertial(theta, f_thrust);
    qd[quad::IMP_THRUST] = it.0;
    qd[quad::IMP_THRUST + 1] = it.1;
    // pressure resultant: −pA_f at x = 0 plus +pA_f at x = L₁, both along the body axis
    let ip = to_inertial(theta, (p_aft + p_head, 0.0));
    qd[quad::IMP_PRESSURE] = ip.0;
    qd[quad::IMP_PRESSURE + 1] = ip.1;
    let ic = to_inertial(theta, (0.0, cc * kap.total));
    qd[quad::IMP_CORIOLIS] = ic.0;
    qd[quad::IMP_CORIOLIS + 1] = ic.1;
    qd[quad::IMP_GRAVITY] = 0.0;
    qd[quad::IMP_GRAVITY + 1] = -g * mt;
    qd[quad::W_THRUST] = p_thrust;
    qd[quad::W_PRESSURE] = p_press;
    qd[quad::W_CORIOLIS] = p_cor;
    qd[quad::W_DAMPING] = p_damp;
    if ld.burn_rate > 0.0 {
        // burnt mass leaves with the local case velocity: ṁ = −rate on the chamber
        let chi = &model.chi;
        let csh = beam_shape(chi, a, b);
        let mx = chi.total * vx - om * csh.sy + dot(&chi.u, ad);
        let my = chi.total * vy + om * csh.sx + dot(&chi.w, bd);
        let mo = to_inertial(theta, (-ld.burn_rate * mx, -ld.burn_rate * my));
        qd[quad::MOM_OUTFLOW] = mo.0;
        qd[quad::MOM_OUTFLOW + 1] = mo.1;
        fill_mass_matrix(l, body, chi, q, false, &mut ws.mass_chi);
        mat_vec(&ws.mass_chi, nd, v, &mut ws.tmp);
        let kin = 0.5 * dot(v, &ws.tmp);
        let (s, c) = theta.sin_cos();
        let height = chi.total * q[1] + s * csh.sx + c * csh.sy;
        qd[quad::E_OUTFLOW] = -ld.burn_rate * (kin + g * height);
    } else {
        qd[quad::MOM_OUTFLOW] = 0.0;
        qd[quad::MOM_OUTFLOW + 1] = 0.0;
        qd[quad::E_OUTFLOW] = 0.0;
    }

    // kinematics
    let (s, c) = theta.sin_cos();
    dydt[0] = c * vx - s * vy;
    dydt[1] = s * vx + c * vy;
    dydt[2..nd].copy_from_slice(&v[2..nd]);
    // accelerations
    if let Err(p) = cholesky_factor(&mut ws.mass, nd).map_err(|e| e.pivot) {
        ws.failed_pivot = Some((t, p));
        dydt[nd..2 * nd].iter_mut().for_each(|x| *x = f64::NAN);
        return false;
    }
    cholesky_substitute(&ws.mass, nd, &mut ws.rhs);
    dydt[nd..2 * nd].copy_from_slice(&ws.rhs);
    true
}

/// Stored energies and momentum of a state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Snapshot {
    pub total_mass: f64,
    pub kinetic: f64,
    pub strain: f64,
    pub gravity: f64,
    pub springs: f64,
    /// Linear momentum, inertial components.
    pub momentum: (f64, f64),
    /// Mass-centre position, inertial.
    pub centre: (f64, f64),
}

pub fn snapshot(model: &Model, ws: &mut Workspace, t: f64, y: &[f64]) -> Snapshot {
    let l = model.layout;
    let (n, nd) = (l.n, l.dofs());
    let body = &model.body;
    let q = &y[..nd];
    let v = &y[nd..2 * nd];
    ws.mom
        .set_affine(&model.m0, model.burnt_per_length(t), &model.chi);
    fill_mass_matrix(l, body, &ws.mom, q, true, &mut ws.mass);
    mat_vec(&ws.mass, nd, v, &mut ws.tmp);
    let kinetic = 0.5 * dot(v, &ws.tmp);
    let pb = (ws.tmp[0], ws.tmp[1]);
    let mt = ws.mass[0];
    // first moments: row 1 col 2 is S_x, row 0 col 2 is −S_y
    let (sx, sy) = (ws.mass[nd + 2], -ws.mass[2]);
    let theta = q[2];
    let rc = to_inertial(theta, (sx / mt, sy / mt));
    let a = &q[l.a()..l.a() + n];
    let b = &q[l.b()..l.b() + n];
    let (s, c) = theta.sin_cos();
    Snapshot {
        total_mass: mt,
        kinetic,
        strain: strain_energy(model, a, b, None),
        gravity: body.gravity * (mt * q[1] + s * sx + c * sy),
        springs: spring_energy(model, q),
        momentum: to_inertial(theta, pb),
        centre: (q[0] + rc.0, q[1] + rc.1),
    }
}

#[cfg(test)]
mod tests;
