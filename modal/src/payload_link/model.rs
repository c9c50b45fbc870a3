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

use data::scene::{LinkField, PayloadLink, PrescribedMotion, TorqueLaw};
use nalgebra::{Matrix3, Vector3};

use super::basis::{Clamp, FieldBasis};
use crate::basis::quadrature::Quadrature;

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

    /// Builds every matrix for `modes` functions per carried field.
    pub fn build(
        link: &PayloadLink,
        modes: usize,
        basis: BasisChoice,
        field_stations: usize,
    ) -> Result<Self, crate::ModalError> {
        let l = link.length;
        let mut blocks = Vec::new();
        let mut n = 0;
        for field in LinkField::ALL {
            if !link.has(field) {
                continue;
            }
            let clamp = match field {
                LinkField::Axial | LinkField::Torsion => Clamp::Value,
                _ => Clamp::ValueAndSlope,
            };
            let fb = match basis {
                BasisChoice::Legendre => FieldBasis::legendre(l, modes, clamp),
                BasisChoice::ClampedFree => FieldBasis::clamped_free(l, modes, clamp)?,
            };
            blocks.push(FieldBlock {
                field,
                offset: n,
                basis: fb,
            });
            n += modes;
        }
        let mu = link.mass_per_length();
        let iota = link.density * link.second_moment();
        let (ea, ei, gj) = (
            link.axial_stiffness(),
            link.bending_stiffness(),
            link.torsional_stiffness(),
        );
        let g = link.gravity.filter(|g| *g != 0.0);
        let p = &link.payload;
        let (m, c) = (p.mass, p.offset);
        let reach = l + c;

        let mut mass = vec![0.0; n * n];
        let mut stiff = vec![0.0; n * n];
        let mut gyro = vec![0.0; n * n];
        let mut cent = vec![0.0; n * n];
        let mut fore = vec![0.0; n * n];
        let mut b = vec![0.0; n];
        let mut h = vec![0.0; n];
        let mut fg = vec![0.0; n];
        let mut j0 = link.base_inertia();
        let mut damped: Vec<DampedField> = blocks
            .iter()
            .filter_map(|blk| {
                link.kelvin_voigt_on(blk.field).map(|_| DampedField {
                    field: blk.field,
                    offset: blk.offset,
                    count: blk.count(),
                    matrix: vec![0.0; blk.count() * blk.count()],
                })
            })
            .collect();
        let kv_coef = |f: LinkField| -> f64 {
            link.kelvin_voigt_on(f).unwrap_or(0.0)
                * match f {
                    LinkField::Axial => link.area(),
                    LinkField::Horizontal | LinkField::Vertical => link.second_moment(),
                    LinkField::Torsion => link.polar_moment(),
                }
        };

        let quad = Quadrature::for_wavenumber(l, (modes as f64 + 2.0) * std::f64::consts::PI);
        let mut d0 = vec![0.0; modes];
        let mut d1 = vec![0.0; modes];
        let mut d2 = vec![0.0; modes];
        // Values at a point, laid out over all of q (zero outside a block).
        let mut val = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut der = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut curv = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let fill = |x: f64,
                    val: &mut [Vec<f64>; 4],
                    der: &mut [Vec<f64>; 4],
                    curv: &mut [Vec<f64>; 4],
                    d0: &mut [f64],
                    d1: &mut [f64],
                    d2: &mut [f64]| {
            for blk in &blocks {
                let k = field_index(blk.field);
                blk.basis.eval(x, 0, d0);
                blk.basis.eval(x, 1, d1);
                blk.basis.eval(x, 2, d2);
                let o = blk.offset;
                val[k][o..o + blk.count()].copy_from_slice(&d0[..blk.count()]);
                der[k][o..o + blk.count()].copy_from_slice(&d1[..blk.count()]);
                curv[k][o..o + blk.count()].copy_from_slice(&d2[..blk.count()]);
            }
        };
        const U: usize = 0;
        const V: usize = 1;
        const W: usize = 2;
        const T: usize = 3;
        for (&x, &wt) in quad.x.iter().zip(&quad.w) {
            fill(x, &mut val, &mut der, &mut curv, &mut d0, &mut d1, &mut d2);
            let pull = 0.5 * mu * (l * l - x * x);
            for i in 0..n {
                b[i] += wt * (mu * x * val[V][i] + iota * der[V][i]);
                h[i] += wt * mu * x * val[U][i];
                if let Some(g) = g {
                    fg[i] += wt * g * mu * val[W][i];
                }
                for j in 0..n {
                    let ij = i * n + j;
                    mass[ij] += wt
                        * (mu
                            * (val[U][i] * val[U][j]
                                + val[V][i] * val[V][j]
                                + val[W][i] * val[W][j])
                            + iota * (der[V][i] * der[V][j] + der[W][i] * der[W][j])
                            + 2.0 * iota * val[T][i] * val[T][j]);
                    stiff[ij] += wt
                        * (ea * der[U][i] * der[U][j]
                            + ei * (curv[V][i] * curv[V][j] + curv[W][i] * curv[W][j])
                            + gj * der[T][i] * der[T][j]);
                    gyro[ij] += wt
                        * (mu * (val[U][i] * val[V][j] - val[V][i] * val[U][j])
                            + 2.0 * iota * der[W][i] * val[T][j]);
                    let slopes = der[V][i] * der[V][j] + der[W][i] * der[W][j];
                    cent[ij] += wt
                        * (mu * (val[U][i] * val[U][j] + val[V][i] * val[V][j]) - pull * slopes
                            + iota * der[W][i] * der[W][j]);
                    fore[ij] += wt * slopes;
                }
            }
            j0 += wt * (mu * x * x + iota);
            for d in &mut damped {
                let k = field_index(d.field);
                let coef = kv_coef(d.field);
                let rows = match d.field {
                    LinkField::Horizontal | LinkField::Vertical => &curv[k],
                    _ => &der[k],
                };
                for i in 0..d.count {
                    for j in 0..d.count {
                        d.matrix[i * d.count + j] +=
                            wt * coef * rows[d.offset + i] * rows[d.offset + j];
                    }
                }
            }
        }

        // Tip rows.
        fill(l, &mut val, &mut der, &mut curv, &mut d0, &mut d1, &mut d2);
        let tip = TipRows {
            u: val[U].clone(),
            v: val[V].clone(),
            w: val[W].clone(),
            slope_v: der[V].clone(),
            slope_w: der[W].clone(),
            phi: val[T].clone(),
        };
        let pv: Vec<f64> = (0..n).map(|i| tip.v[i] + c * tip.slope_v[i]).collect();
        let pw: Vec<f64> = (0..n).map(|i| tip.w[i] + c * tip.slope_w[i]).collect();
        for i in 0..n {
            for j in 0..n {
                fore[i * n + j] +=
                    c * (tip.slope_v[i] * tip.slope_v[j] + tip.slope_w[i] * tip.slope_w[j]);
            }
        }
        for i in 0..n {
            b[i] += m * reach * pv[i];
            h[i] += m * reach * tip.u[i];
            if let Some(g) = g {
                fg[i] += g * m * pw[i];
            }
            for j in 0..n {
                let ij = i * n + j;
                mass[ij] += m * (tip.u[i] * tip.u[j] + pv[i] * pv[j] + pw[i] * pw[j]);
                gyro[ij] += m * (tip.u[i] * pv[j] - pv[i] * tip.u[j]);
                cent[ij] += m * (tip.u[i] * tip.u[j] + pv[i] * pv[j]) - m * reach * fore[ij];
            }
        }
        j0 += m * reach * reach;

        // Payload rotation: the quadratic form of ½AᵀI_pA in z = (v′_L, w′_L, φ_L), ż, W.
        let form = RotationForm::of(&p.inertia);
        let rows = [&tip.slope_v, &tip.slope_w, &tip.phi];
        j0 += form.j0;
        for i in 0..n {
            for a in 0..3 {
                b[i] += rows[a][i] * form.b[a];
                h[i] += rows[a][i] * form.h[a];
            }
            for j in 0..n {
                let mut mm = 0.0;
                let mut gg = 0.0;
                let mut nn = 0.0;
                for a in 0..3 {
                    for bb in 0..3 {
                        let r = rows[a][i] * rows[bb][j];
                        mm += r * form.m[a][bb];
                        gg += r * form.g[a][bb];
                        nn += r * form.n[a][bb];
                    }
                }
                mass[i * n + j] += mm;
                gyro[i * n + j] += gg;
                cent[i * n + j] += nn;
            }
        }

        let damping = if damped.is_empty() {
            None
        } else {
            let mut cm = vec![0.0; n * n];
            for d in &damped {
                for i in 0..d.count {
                    for j in 0..d.count {
                        cm[(d.offset + i) * n + d.offset + j] += d.matrix[i * d.count + j];
                    }
                }
            }
            Some(cm)
        };

        let ns = field_stations.max(2);
        let mut stations = Vec::with_capacity(ns);
        for s in 0..ns {
            let x = l * s as f64 / (ns - 1) as f64;
            for v in val.iter_mut().chain(der.iter_mut()).chain(curv.iter_mut()) {
                v.iter_mut().for_each(|e| *e = 0.0);
            }
            fill(x, &mut val, &mut der, &mut curv, &mut d0, &mut d1, &mut d2);
            stations.push([val[V].clone(), val[W].clone(), val[T].clone()]);
        }

        let base = &link.base;
        let spring = base
            .stiffness
            .filter(|k| *k > 0.0)
            .map(|k| (k, base.set_point.unwrap_or(0.0)));
        Ok(LinkModel {
            n,
            length: l,
            reach,
            blocks,
            mass,
            stiffness: stiff,
            damping,
            damped,
            b,
            gyro,
            j0,
            h,
            centrifugal: cent,
            gravity: g.map(|_| fg),
            pull_in: fore,
            tip,
            stations,
            base: Base {
                free: base.prescribed.is_none(),
                friction: link.motor_friction(),
                spring,
                torque: base.torque.clone(),
                prescribed: base.prescribed.clone(),
                initial_angle: base.initial_angle,
                initial_rate: base.initial_rate,
            },
        })
    }

    /// Kinetic energy T(W, q, q̇).
    pub fn kinetic(&self, w: f64, q: &[f64], qd: &[f64]) -> f64 {
        let n = self.n;
        let mut t = 0.0;
        for i in 0..n {
            let (mut mq, mut gq, mut nq) = (0.0, 0.0, 0.0);
            for j in 0..n {
                mq += self.mass[i * n + j] * qd[j];
                gq += self.gyro[i * n + j] * qd[j];
                nq += self.centrifugal[i * n + j] * q[j];
            }
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
        self.gravity
            .as_ref()
            .map_or(0.0, |f| f.iter().zip(q).map(|(a, b)| a * b).sum())
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
        let mut r = 0.0;
        for j in 0..n {
            r += a[i * n + j] * x[j];
        }
        s += x[i] * r;
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
