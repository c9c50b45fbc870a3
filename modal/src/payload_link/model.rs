//! The Ritz matrices of the payload link: every term of the truncated Lagrangian of
//! docs/single-link-3d.md as a constant matrix or vector, integrated once by Gauss quadrature.
//!
//! With the field coordinates q (u, v, w, φ blocks) and the base rate W = θ̇:
//!
//! T = ½ q̇ᵀM q̇ + W (bᵀq̇ + qᵀG q̇) + ½ W² (J₀ + 2hᵀq + qᵀN q),
//! V = ½ qᵀK q + f_gᵀq (+ ½K_θ(θ − θ₀)²),  R = ½ q̇ᵀC q̇ + ½ b_m W²,
//!
//! with, per unit length (μ = ρA, ι = ρI, ρJ = 2ι) and s(x) = ½∫₀ˣ(v′² + w′²):
//! * translation ½μ|ṙ + W e_z × r|² truncated: μ(u̇² + v̇² + ẇ²) in M, μ x v̇ in b,
//!   μ(u v̇ − v u̇) in G, μ x² in J₀, μ x u in h, μ(u² + v²) − μ (L² − x²)/2 (v′² + w′²) in N
//!   (the last from −2x s after exchanging the order of integration);
//! * section rotation ½ρI(|Ω|² + (t·Ω)²) (J = 2I, t the tangent): ι(v̇′² + ẇ′²) + 2ιφ̇² in M,
//!   ι v′̇ in b, 2ι w′φ̇ in G, ι in J₀, ι w′² in N;
//! * payload translation, C at (L + c + u_L − s_C, p₂, p₃) with p₂ = v_L + c v′_L,
//!   p₃ = w_L + c w′_L, s_C = s_L + ½c(v′_L² + w′_L²): the same pattern at X = L + c;
//! * payload rotation ½AᵀI_pA, A = R_Lᵀ(W e_z + ω_L) expanded to second order
//!   ([`payload_rotation_energy`]); its quadratic form is read off exactly by polarization;
//! * strain EA u′², EI(v″² + w″²), GJ φ′²; Kelvin–Voigt the same with C_X A, C_Y I, C_Z I, C_Φ J;
//! * gravity g(μ w + m_p p₃).
//!
//! [`LinkModel::build`] (in the sibling `build` module) integrates them.

use data::scene::{LinkField, PrescribedMotion, TorqueLaw};
use nalgebra::{Matrix3, Vector3};

use super::basis::FieldBasis;
use crate::linalg::dot;

/// One carried field: its coordinates q[offset .. offset + count].
#[derive(Debug, Clone)]
pub struct FieldBlock {
    pub field: LinkField,
    pub offset: usize,
    pub basis: FieldBasis,
}

impl FieldBlock {
    pub fn count(&self) -> usize {
        self.basis.count
    }
}

/// Kelvin–Voigt damping of one field: its block of C.
#[derive(Debug, Clone)]
pub struct DampedField {
    pub field: LinkField,
    pub offset: usize,
    pub count: usize,
    /// count × count, row-major.
    pub matrix: Vec<f64>,
}

/// The base joint θ about Z.
#[derive(Debug, Clone)]
pub struct Base {
    /// θ is a coordinate (no prescribed motion).
    pub free: bool,
    pub friction: f64,
    /// (K_θ, θ₀).
    pub spring: Option<(f64, f64)>,
    pub torque: Option<TorqueLaw>,
    pub prescribed: Option<PrescribedMotion>,
    pub initial_angle: f64,
    pub initial_rate: f64,
}

impl Base {
    /// (θ, θ̇, θ̈) of a prescribed base at t.
    pub fn prescribed_state(&self, t: f64) -> (f64, f64, f64) {
        let (a, r, acc) = self
            .prescribed
            .as_ref()
            .map_or((0.0, 0.0, 0.0), |p| p.kinematics(t));
        (self.initial_angle + a, r, acc)
    }

    pub fn motor_torque(&self, t: f64) -> f64 {
        self.torque.as_ref().map_or(0.0, |l| l.torque(t))
    }

    /// Spring torque −K_θ(θ − θ₀) and its energy.
    pub fn spring(&self, theta: f64) -> (f64, f64) {
        self.spring.map_or((0.0, 0.0), |(k, t0)| {
            let d = theta - t0;
            (-k * d, 0.5 * k * d * d)
        })
    }
}

/// Rows mapping q to the tip quantities.
#[derive(Debug, Clone)]
pub struct TipRows {
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub w: Vec<f64>,
    pub slope_v: Vec<f64>,
    pub slope_w: Vec<f64>,
    pub phi: Vec<f64>,
}

/// The discretized link: every matrix of the Lagrangian (row-major n × n, n = field coordinates).
#[derive(Debug, Clone)]
pub struct LinkModel {
    pub n: usize,
    pub length: f64,
    /// Distance X = L + c of the payload's centre of mass from the axis, undeformed.
    pub reach: f64,
    pub blocks: Vec<FieldBlock>,
    pub mass: Vec<f64>,
    pub stiffness: Vec<f64>,
    /// Σ of the damped fields' blocks (None: no Kelvin–Voigt term on).
    pub damping: Option<Vec<f64>>,
    pub damped: Vec<DampedField>,
    pub b: Vec<f64>,
    pub gyro: Vec<f64>,
    pub j0: f64,
    pub h: Vec<f64>,
    pub centrifugal: Vec<f64>,
    /// f_g (None without gravity).
    pub gravity: Option<Vec<f64>>,
    /// s_C = ½ qᵀ S_C q: the payload's axial pull-in from bending.
    pub pull_in: Vec<f64>,
    pub tip: TipRows,
    /// Field values at the output stations: per station, rows of v, w, φ (empty when absent).
    pub stations: Vec<[Vec<f64>; 3]>,
    pub base: Base,
}

/// How the assumed modes are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BasisChoice {
    Legendre,
    ClampedFree,
}

impl LinkModel {
    pub fn block(&self, field: LinkField) -> Option<&FieldBlock> {
        self.blocks.iter().find(|b| b.field == field)
    }

    /// Kinetic energy T(W, q, q̇).
    pub fn kinetic(&self, w: f64, q: &[f64], qd: &[f64]) -> f64 {
        let n = self.n;
        let mut t = 0.0;
        for i in 0..n {
            let row = i * n..(i + 1) * n;
            let mq = dot(&self.mass[row.clone()], qd);
            let gq = dot(&self.gyro[row.clone()], qd);
            let nq = dot(&self.centrifugal[row], q);
            t += 0.5 * qd[i] * mq
                + w * (self.b[i] * qd[i] + q[i] * gq)
                + 0.5 * w * w * (2.0 * self.h[i] * q[i] + q[i] * nq);
        }
        t + 0.5 * w * w * self.j0
    }

    /// ½ qᵀK q.
    pub fn strain(&self, q: &[f64]) -> f64 {
        quad_form(&self.stiffness, self.n, q)
    }

    /// f_gᵀ q.
    pub fn gravity_energy(&self, q: &[f64]) -> f64 {
        self.gravity.as_ref().map_or(0.0, |f| dot(f, q))
    }

    /// Dissipation rate q̇ᵀC_f q̇ of one damped field.
    pub fn dissipation_rate(&self, d: &DampedField, qd: &[f64]) -> f64 {
        2.0 * quad_form(&d.matrix, d.count, &qd[d.offset..d.offset + d.count])
    }
}

/// ½ xᵀA x.
pub fn quad_form(a: &[f64], n: usize, x: &[f64]) -> f64 {
    let mut s = 0.0;
    for i in 0..n {
        s += x[i] * dot(&a[i * n..(i + 1) * n], x);
    }
    0.5 * s
}

/// Index of a field in the fixed order u, v, w, φ.
pub fn field_index(f: LinkField) -> usize {
    match f {
        LinkField::Axial => 0,
        LinkField::Horizontal => 1,
        LinkField::Vertical => 2,
        LinkField::Torsion => 3,
    }
}

/// ½AᵀI_pA to second order in z = (v′_L, w′_L, φ_L) and ż, exact in W (docs/single-link-3d.md):
/// A = R_xᵀ(φ) R_tᵀ(β) (W e_z + ω), β = (0, −w′, v′), ω = ω⁽¹⁾ + ω⁽²⁾ with
/// ω⁽¹⁾ = (φ̇, −ẇ′, v̇′), ω⁽²⁾ = (½(v′ẇ′ − w′v̇′), v′φ̇, w′φ̇), each factor to second order;
/// T = ½A₀ᵀIA₀ + A₀ᵀIA₁ + ½A₁ᵀIA₁ + A₀ᵀIA₂ (Aₖ of order k).
pub fn payload_rotation_energy(inertia: &[[f64; 3]; 3], w: f64, z: [f64; 3], zd: [f64; 3]) -> f64 {
    let [vs, ws, phi] = z;
    let [vsd, wsd, phid] = zd;
    let ip = Matrix3::from_fn(|i, j| inertia[i][j]);
    let beta = Vector3::new(0.0, -ws, vs);
    let (ex, ez) = (Vector3::x(), Vector3::z());
    let om1 = Vector3::new(phid, -wsd, vsd);
    let om2 = Vector3::new(0.5 * (vs * wsd - ws * vsd), vs * phid, ws * phid);
    let a0 = ez * w;
    let b_ez = beta.cross(&ez);
    let ex_ez = ex.cross(&ez);
    let inner = om1 - b_ez * w;
    let a1 = inner - ex_ez * (phi * w);
    let a2 = (om2 - beta.cross(&om1) + beta.cross(&b_ez) * (0.5 * w))
        + (ex.cross(&inner) * -phi + ex.cross(&ex_ez) * (0.5 * phi * phi * w));
    let ia0 = ip * a0;
    0.5 * a0.dot(&ia0) + ia0.dot(&a1) + 0.5 * a1.dot(&(ip * a1)) + ia0.dot(&a2)
}

/// The coefficients of [`payload_rotation_energy`] = ½żᵀMż + W(bᵀż + zᵀGż) + ½W²(J₀ + 2hᵀz + zᵀNz),
/// read off by polarization (exact for a polynomial of this form up to round-off).
#[derive(Debug, Clone, Copy)]
pub struct RotationForm {
    pub m: [[f64; 3]; 3],
    pub b: [f64; 3],
    pub g: [[f64; 3]; 3],
    pub j0: f64,
    pub h: [f64; 3],
    pub n: [[f64; 3]; 3],
}

impl RotationForm {
    pub fn of(inertia: &[[f64; 3]; 3]) -> Self {
        let f = |w: f64, z: Vector3<f64>, zd: Vector3<f64>| {
            payload_rotation_energy(inertia, w, z.into(), zd.into())
        };
        let e = |k: usize| Vector3::ith(k, 1.0);
        let o = Vector3::zeros();
        let f00 = f(1.0, o, o);
        let mut r = RotationForm {
            m: [[0.0; 3]; 3],
            b: [0.0; 3],
            g: [[0.0; 3]; 3],
            j0: 2.0 * f00,
            h: [0.0; 3],
            n: [[0.0; 3]; 3],
        };
        for a in 0..3 {
            r.b[a] = f(1.0, o, e(a)) - f00 - f(0.0, o, e(a));
            r.h[a] = 0.5 * (f(1.0, e(a), o) - f(1.0, -e(a), o));
            for c in 0..3 {
                r.m[a][c] = f(0.0, o, e(a) + e(c)) - f(0.0, o, e(a)) - f(0.0, o, e(c));
                if a == c {
                    r.m[a][c] = 2.0 * f(0.0, o, e(a));
                }
                r.g[a][c] = f(1.0, e(a), e(c)) - f(1.0, e(a), o) - f(1.0, o, e(c)) + f00;
                r.n[a][c] = if a == c {
                    f(1.0, e(a), o) + f(1.0, -e(a), o) - 2.0 * f00
                } else {
                    f(1.0, e(a) + e(c), o) - f(1.0, e(a), o) - f(1.0, e(c), o) + f00
                };
            }
        }
        // The differences leave round-off (~ε·max|I_p|) where a coefficient is exactly zero
        // (e.g. every coupling of v′ with w′, φ for a diagonal I_p): clear it, so that a
        // decoupled pair stays decoupled to the bit.
        let floor =
            64.0 * f64::EPSILON * inertia.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let chop = |v: &mut f64| {
            if v.abs() <= floor {
                *v = 0.0;
            }
        };
        chop(&mut r.j0);
        for a in 0..3 {
            chop(&mut r.b[a]);
            chop(&mut r.h[a]);
            for c in 0..3 {
                chop(&mut r.m[a][c]);
                chop(&mut r.g[a][c]);
                chop(&mut r.n[a][c]);
            }
        }
        r
    }
}
