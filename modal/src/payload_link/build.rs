//! Building [`LinkModel`]: the Ritz matrices of [`super::model`] integrated in named phases —
//! the field blocks and their bases, the rod's Gauss quadrature (inertia, strain, coupling,
//! centrifugal and foreshortening terms, gravity, Kelvin–Voigt blocks), the payload's
//! translation and rotation at the tip, the assembled damping, the output station rows and the
//! base joint. Each phase adds its terms in the order of the original sums, so the matrices are
//! the same to the bit however the phases are cut.

use data::scene::{LinkField, PayloadLink};

use super::basis::{Clamp, FieldBasis};
use super::model::{
    Base, BasisChoice, DampedField, FieldBlock, LinkModel, RotationForm, TipRows, field_index,
};
use crate::basis::quadrature::Quadrature;

const U: usize = 0;
const V: usize = 1;
const W: usize = 2;
const T: usize = 3;

/// Basis values, slopes and curvatures at one point, laid out over all of q (zero outside a
/// block), per field in the order u, v, w, φ; with the per-block scratch.
struct Sampler {
    val: [Vec<f64>; 4],
    der: [Vec<f64>; 4],
    curv: [Vec<f64>; 4],
    d0: Vec<f64>,
    d1: Vec<f64>,
    d2: Vec<f64>,
}

impl Sampler {
    fn new(n: usize, modes: usize) -> Self {
        let z = || [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        Sampler {
            val: z(),
            der: z(),
            curv: z(),
            d0: vec![0.0; modes],
            d1: vec![0.0; modes],
            d2: vec![0.0; modes],
        }
    }

    /// Evaluates every block's basis and its first two derivatives at x.
    fn fill(&mut self, blocks: &[FieldBlock], x: f64) {
        for blk in blocks {
            let k = field_index(blk.field);
            blk.basis.eval(x, 0, &mut self.d0);
            blk.basis.eval(x, 1, &mut self.d1);
            blk.basis.eval(x, 2, &mut self.d2);
            let o = blk.offset;
            let c = blk.count();
            self.val[k][o..o + c].copy_from_slice(&self.d0[..c]);
            self.der[k][o..o + c].copy_from_slice(&self.d1[..c]);
            self.curv[k][o..o + c].copy_from_slice(&self.d2[..c]);
        }
    }

    /// Clears the point rows, then fills them at x.
    fn refill(&mut self, blocks: &[FieldBlock], x: f64) {
        for v in self
            .val
            .iter_mut()
            .chain(self.der.iter_mut())
            .chain(self.curv.iter_mut())
        {
            v.iter_mut().for_each(|e| *e = 0.0);
        }
        self.fill(blocks, x);
    }
}

/// The rod's section constants per unit length: μ = ρA, ι = ρI, EA, EI, GJ.
struct Section {
    mu: f64,
    iota: f64,
    ea: f64,
    ei: f64,
    gj: f64,
}

/// The accumulating terms of T = ½q̇ᵀMq̇ + W(bᵀq̇ + qᵀGq̇) + ½W²(J₀ + 2hᵀq + qᵀNq),
/// V = ½qᵀKq + f_gᵀq, and the foreshortening form S_C (all n × n row-major).
struct Terms {
    n: usize,
    mass: Vec<f64>,
    stiff: Vec<f64>,
    gyro: Vec<f64>,
    cent: Vec<f64>,
    fore: Vec<f64>,
    b: Vec<f64>,
    h: Vec<f64>,
    fg: Vec<f64>,
    j0: f64,
}

impl LinkModel {
    /// Builds every matrix for `modes` functions per carried field.
    pub fn build(
        link: &PayloadLink,
        modes: usize,
        basis: BasisChoice,
        field_stations: usize,
    ) -> Result<Self, crate::ModalError> {
        let l = link.length;
        let (blocks, n) = field_blocks(link, modes, basis)?;
        let sec = Section {
            mu: link.mass_per_length(),
            iota: link.density * link.second_moment(),
            ea: link.axial_stiffness(),
            ei: link.bending_stiffness(),
            gj: link.torsional_stiffness(),
        };
        let g = link.gravity.filter(|g| *g != 0.0);
        let p = &link.payload;
        let reach = l + p.offset;

        let mut terms = Terms {
            n,
            mass: vec![0.0; n * n],
            stiff: vec![0.0; n * n],
            gyro: vec![0.0; n * n],
            cent: vec![0.0; n * n],
            fore: vec![0.0; n * n],
            b: vec![0.0; n],
            h: vec![0.0; n],
            fg: vec![0.0; n],
            j0: link.base_inertia(),
        };
        let mut damped = damped_fields(link, &blocks);
        let mut at = Sampler::new(n, modes);
        terms.add_rod(link, &sec, g, &blocks, &mut damped, &mut at);

        at.fill(&blocks, l);
        let tip = TipRows {
            u: at.val[U].clone(),
            v: at.val[V].clone(),
            w: at.val[W].clone(),
            slope_v: at.der[V].clone(),
            slope_w: at.der[W].clone(),
            phi: at.val[T].clone(),
        };
        terms.add_payload_translation(&tip, p.mass, p.offset, reach, g);
        terms.add_payload_rotation(&tip, &RotationForm::of(&p.inertia));
        let damping = assembled_damping(&damped, n);
        let stations = station_rows(&mut at, &blocks, l, field_stations);

        let Terms {
            mass,
            stiff,
            gyro,
            cent,
            fore,
            b,
            h,
            fg,
            j0,
            ..
        } = terms;
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
            base: base_joint(link),
        })
    }
}

/// One block of `modes` functions per carried field, in the order u, v, w, φ: u and φ clamped
/// in value, v and w in value and slope. Returns the blocks and n, the field coordinates.
fn field_blocks(
    link: &PayloadLink,
    modes: usize,
    basis: BasisChoice,
) -> Result<(Vec<FieldBlock>, usize), crate::ModalError> {
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
    Ok((blocks, n))
}

/// An empty C_f block for every carried field with a Kelvin–Voigt coefficient.
fn damped_fields(link: &PayloadLink, blocks: &[FieldBlock]) -> Vec<DampedField> {
    blocks
        .iter()
        .filter_map(|blk| {
            link.kelvin_voigt_on(blk.field).map(|_| DampedField {
                field: blk.field,
                offset: blk.offset,
                count: blk.count(),
                matrix: vec![0.0; blk.count() * blk.count()],
            })
        })
        .collect()
}

/// The Kelvin–Voigt section coefficient: C_X A, C_Y I, C_Z I or C_Φ J.
fn kv_coef(link: &PayloadLink, f: LinkField) -> f64 {
    link.kelvin_voigt_on(f).unwrap_or(0.0)
        * match f {
            LinkField::Axial => link.area(),
            LinkField::Horizontal | LinkField::Vertical => link.second_moment(),
            LinkField::Torsion => link.polar_moment(),
        }
}

impl Terms {
    /// The rod's integrals by Gauss quadrature (exact for the basis' wavenumber + 2π/L):
    /// per point, [`Self::add_rod_point`], J₀ += μx² + ι, and the Kelvin–Voigt blocks
    /// C_f += c_f ψ′ψ′ᵀ (ψ″ for bending).
    fn add_rod(
        &mut self,
        link: &PayloadLink,
        sec: &Section,
        g: Option<f64>,
        blocks: &[FieldBlock],
        damped: &mut [DampedField],
        at: &mut Sampler,
    ) {
        let l = link.length;
        let modes = at.d0.len();
        let quad = Quadrature::for_wavenumber(l, (modes as f64 + 2.0) * std::f64::consts::PI);
        for (&x, &wt) in quad.x.iter().zip(&quad.w) {
            at.fill(blocks, x);
            self.add_rod_point(sec, g, l, x, wt, at);
            self.j0 += wt * (sec.mu * x * x + sec.iota);
            for d in damped.iter_mut() {
                let k = field_index(d.field);
                let coef = kv_coef(link, d.field);
                let rows = match d.field {
                    LinkField::Horizontal | LinkField::Vertical => &at.curv[k],
                    _ => &at.der[k],
                };
                for i in 0..d.count {
                    for j in 0..d.count {
                        d.matrix[i * d.count + j] +=
                            wt * coef * rows[d.offset + i] * rows[d.offset + j];
                    }
                }
            }
        }
    }

    /// One quadrature point x (weight wt) of the rod: translation μ|ṙ|² and section rotation
    /// ι(v̇′² + ẇ′²) + 2ιφ̇² in M, strain in K, μx v̇ + ιv̇′ in b, μ(uv̇ − vu̇) + 2ιw′φ̇ in G,
    /// μx u in h, μ(u² + v²) − ½μ(L² − x²)(v′² + w′²) + ιw′² in N, v′² + w′² in S_C, gμw in f_g.
    fn add_rod_point(
        &mut self,
        sec: &Section,
        g: Option<f64>,
        l: f64,
        x: f64,
        wt: f64,
        at: &Sampler,
    ) {
        let n = self.n;
        let Section {
            mu,
            iota,
            ea,
            ei,
            gj,
        } = *sec;
        let (val, der, curv) = (&at.val, &at.der, &at.curv);
        let pull = 0.5 * mu * (l * l - x * x);
        for i in 0..n {
            self.b[i] += wt * (mu * x * val[V][i] + iota * der[V][i]);
            self.h[i] += wt * mu * x * val[U][i];
            if let Some(g) = g {
                self.fg[i] += wt * g * mu * val[W][i];
            }
            for j in 0..n {
                let ij = i * n + j;
                self.mass[ij] += wt
                    * (mu
                        * (val[U][i] * val[U][j] + val[V][i] * val[V][j] + val[W][i] * val[W][j])
                        + iota * (der[V][i] * der[V][j] + der[W][i] * der[W][j])
                        + 2.0 * iota * val[T][i] * val[T][j]);
                self.stiff[ij] += wt
                    * (ea * der[U][i] * der[U][j]
                        + ei * (curv[V][i] * curv[V][j] + curv[W][i] * curv[W][j])
                        + gj * der[T][i] * der[T][j]);
                self.gyro[ij] += wt
                    * (mu * (val[U][i] * val[V][j] - val[V][i] * val[U][j])
                        + 2.0 * iota * der[W][i] * val[T][j]);
                let slopes = der[V][i] * der[V][j] + der[W][i] * der[W][j];
                self.cent[ij] += wt
                    * (mu * (val[U][i] * val[U][j] + val[V][i] * val[V][j]) - pull * slopes
                        + iota * der[W][i] * der[W][j]);
                self.fore[ij] += wt * slopes;
            }
        }
    }

    /// The payload's translation at (X + u_L − s_C, p₂, p₃), X = L + c, p₂ = v_L + c v′_L,
    /// p₃ = w_L + c w′_L: S_C += c(v′_L v′_Lᵀ + w′_L w′_Lᵀ), then m(u_L² + p₂² + p₃²) in M,
    /// mX p₂ in b, mX u_L in h, m(u_L p₂ − p₂ u_L) in G, m(u_L² + p₂²) − mX S_C in N,
    /// g m p₃ in f_g, mX² in J₀.
    fn add_payload_translation(
        &mut self,
        tip: &TipRows,
        m: f64,
        c: f64,
        reach: f64,
        g: Option<f64>,
    ) {
        let n = self.n;
        let pv: Vec<f64> = (0..n).map(|i| tip.v[i] + c * tip.slope_v[i]).collect();
        let pw: Vec<f64> = (0..n).map(|i| tip.w[i] + c * tip.slope_w[i]).collect();
        for i in 0..n {
            for j in 0..n {
                self.fore[i * n + j] +=
                    c * (tip.slope_v[i] * tip.slope_v[j] + tip.slope_w[i] * tip.slope_w[j]);
            }
        }
        for i in 0..n {
            self.b[i] += m * reach * pv[i];
            self.h[i] += m * reach * tip.u[i];
            if let Some(g) = g {
                self.fg[i] += g * m * pw[i];
            }
            for j in 0..n {
                let ij = i * n + j;
                self.mass[ij] += m * (tip.u[i] * tip.u[j] + pv[i] * pv[j] + pw[i] * pw[j]);
                self.gyro[ij] += m * (tip.u[i] * pv[j] - pv[i] * tip.u[j]);
                self.cent[ij] +=
                    m * (tip.u[i] * tip.u[j] + pv[i] * pv[j]) - m * reach * self.fore[ij];
            }
        }
        self.j0 += m * reach * reach;
    }

    /// The payload's rotation: the quadratic form of ½AᵀI_pA in z = (v′_L, w′_L, φ_L), ż, W
    /// ([`RotationForm`]) mapped through the tip rows z = R q.
    fn add_payload_rotation(&mut self, tip: &TipRows, form: &RotationForm) {
        let n = self.n;
        let rows = [&tip.slope_v, &tip.slope_w, &tip.phi];
        self.j0 += form.j0;
        for i in 0..n {
            for a in 0..3 {
                self.b[i] += rows[a][i] * form.b[a];
                self.h[i] += rows[a][i] * form.h[a];
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
                self.mass[i * n + j] += mm;
                self.gyro[i * n + j] += gg;
                self.cent[i * n + j] += nn;
            }
        }
    }
}

/// C = Σ_f C_f placed at each damped block (None without a Kelvin–Voigt term).
fn assembled_damping(damped: &[DampedField], n: usize) -> Option<Vec<f64>> {
    if damped.is_empty() {
        return None;
    }
    let mut cm = vec![0.0; n * n];
    for d in damped {
        for i in 0..d.count {
            for j in 0..d.count {
                cm[(d.offset + i) * n + d.offset + j] += d.matrix[i * d.count + j];
            }
        }
    }
    Some(cm)
}

/// Rows of v, w, φ at `field_stations` (at least 2) equally spaced output stations.
fn station_rows(
    at: &mut Sampler,
    blocks: &[FieldBlock],
    l: f64,
    field_stations: usize,
) -> Vec<[Vec<f64>; 3]> {
    let ns = field_stations.max(2);
    let mut stations = Vec::with_capacity(ns);
    for s in 0..ns {
        let x = l * s as f64 / (ns - 1) as f64;
        at.refill(blocks, x);
        stations.push([at.val[V].clone(), at.val[W].clone(), at.val[T].clone()]);
    }
    stations
}

/// The base joint: free unless prescribed, motor friction, the spring (K_θ, θ₀) when K_θ > 0,
/// the torque law and the initial state.
fn base_joint(link: &PayloadLink) -> Base {
    let base = &link.base;
    let spring = base
        .stiffness
        .filter(|k| *k > 0.0)
        .map(|k| (k, base.set_point.unwrap_or(0.0)));
    Base {
        free: base.prescribed.is_none(),
        friction: link.motor_friction(),
        spring,
        torque: base.torque.clone(),
        prescribed: base.prescribed.clone(),
        initial_angle: base.initial_angle,
        initial_rate: base.initial_rate,
    }
}
