//! Building [`PayloadLinkModel`] from a `[payload_link]` scene, one phase per block of the
//! discrete Lagrangian of the parent module: the base drive, the station grid and its
//! finite-difference functionals ([`Grid`]), the field mass M_ff, the coupling M_θf = c + Bq,
//! the base inertia M_θθ = M₀ + 2gᵀq + qᵀHq, the stiffness and Kelvin–Voigt damping per field,
//! and the gravity load. Each phase adds its terms in the order the sums are written, so the
//! assembled triplets (and every result) do not depend on how the phases are cut.

use data::scene::{LinkField, PayloadLink};

use super::spd::Triplets;
use super::{BaseDrive, DEFAULT_STATIONS, Lin, PayloadLinkModel, combine};
use crate::error::FdmError;

use LinkField::{Axial as U, Horizontal as V, Torsion as P, Vertical as W};

/// The station grid x_i = ih, h = L/r, stations 1…r carrying `fields` (interleaved per
/// station), and the linear functionals the Lagrangian is written in.
struct Grid {
    r: usize,
    h: f64,
    fields: Vec<LinkField>,
    nf: usize,
    rho: f64,
    area: f64,
}

impl Grid {
    fn slot(&self, f: LinkField) -> Option<usize> {
        self.fields.iter().position(|x| *x == f)
    }

    /// f_i (empty for the clamped root and for a field not carried).
    fn st(&self, f: LinkField, i: usize) -> Lin {
        match self.slot(f) {
            Some(k) if i >= 1 => vec![((i - 1) * self.nf + k, 1.0)],
            _ => Lin::new(),
        }
    }

    /// Segment slope g_s = (f_{s+1} − f_s)/h.
    fn seg(&self, f: LinkField, s: usize) -> Lin {
        combine(&[
            (&self.st(f, s + 1), 1.0 / self.h),
            (&self.st(f, s), -1.0 / self.h),
        ])
    }

    /// Tip slope f′_L = (3f_r − 4f_{r−1} + f_{r−2})/(2h).
    fn tip_slope(&self, f: LinkField) -> Lin {
        let (r, h) = (self.r, self.h);
        combine(&[
            (&self.st(f, r), 1.5 / h),
            (&self.st(f, r - 1), -2.0 / h),
            (&self.st(f, r - 2), 0.5 / h),
        ])
    }

    /// Curvature κ_i at station i (0 ≤ i < r) and its quadrature weight: κ_0 = 2f_1/h² with
    /// weight ½ (clamped fictitious station f_{−1} = f_1), κ_i = Δ²f_i/h² inside.
    fn curv(&self, f: LinkField, i: usize) -> (Lin, f64) {
        let h2 = self.h * self.h;
        if i == 0 {
            (combine(&[(&self.st(f, 1), 2.0 / h2)]), 0.5)
        } else {
            (
                combine(&[
                    (&self.st(f, i + 1), 1.0 / h2),
                    (&self.st(f, i), -2.0 / h2),
                    (&self.st(f, i - 1), 1.0 / h2),
                ]),
                1.0,
            )
        }
    }

    /// Trapezoid-lumped mass m_i = ρAh (ρAh/2 at the tip).
    fn mass_at(&self, i: usize) -> f64 {
        let (rho, area, h) = (self.rho, self.area, self.h);
        if i == self.r {
            0.5 * rho * area * h
        } else {
            rho * area * h
        }
    }

    fn x(&self, i: usize) -> f64 {
        i as f64 * self.h
    }
}

/// The tip functionals: displacements, slopes, and the payload's y = v_L + c v′_L,
/// z = w_L + c w′_L.
struct Tip {
    eu: Lin,
    ev: Lin,
    ew: Lin,
    ephi: Lin,
    sv: Lin,
    sw: Lin,
    ly: Lin,
    lz: Lin,
}

/// M_θθ = M₀ + 2gᵀq + qᵀHq, and the segment slopes of v and w its foreshortening terms use.
struct ThetaInertia {
    m0: f64,
    g_theta: Vec<f64>,
    h_theta: Triplets,
    seg_v: Vec<Lin>,
    seg_w: Vec<Lin>,
}

/// The stiffness K_f per carried field and the Kelvin–Voigt ratios C_f = (γ_f/modulus_f) K_f.
type FieldStiffness = (Vec<(LinkField, Triplets)>, Vec<(LinkField, usize, f64)>);

fn add_lin(out: &mut [f64], l: &Lin, s: f64) {
    for &(k, v) in l {
        out[k] += s * v;
    }
}

impl PayloadLinkModel {
    pub(super) fn build(
        p: &PayloadLink,
        stations: Option<usize>,
        field_stations: usize,
        name: &str,
    ) -> Result<Self, FdmError> {
        let base = &p.base;
        let drive = base_drive(p, name)?;
        let n_st = stations.unwrap_or(DEFAULT_STATIONS);
        let r = n_st - 1;
        let h = p.length / r as f64;
        let mut fields: Vec<LinkField> = LinkField::ALL
            .iter()
            .copied()
            .filter(|f| p.has(*f))
            .collect();
        fields.dedup();
        let nf = fields.len();
        let n = r * nf;
        let g = Grid {
            r,
            h,
            fields,
            nf,
            rho: p.density,
            area: p.area(),
        };
        let c = p.payload.offset;
        let (sv, sw) = (g.tip_slope(V), g.tip_slope(W));
        let (ev, ew) = (g.st(V, r), g.st(W, r));
        let tip = Tip {
            eu: g.st(U, r),
            ly: combine(&[(&ev, 1.0), (&sv, c)]),
            lz: combine(&[(&ew, 1.0), (&sw, c)]),
            ev,
            ew,
            ephi: g.st(P, r),
            sv,
            sw,
        };

        let (mff, lumped) = field_mass(&g, p, &tip, n);
        let (c_theta, b_theta) = coupling(&g, p, &tip, n);
        let th = theta_inertia(&g, p, &tip, n);
        let (stiffness, damping) = field_stiffness(&g, p);
        let f_gravity = gravity_load(&g, p, &tip, n);

        let Tip {
            eu,
            ev,
            ew,
            ephi,
            sv,
            sw,
            ..
        } = tip;
        Ok(PayloadLinkModel {
            r,
            h,
            length: p.length,
            offset: c,
            n,
            drive,
            theta0: base.initial_angle,
            rate0: base.initial_rate,
            mff,
            c_theta,
            b_theta,
            m0: th.m0,
            g_theta: th.g_theta,
            h_theta: th.h_theta,
            stiffness,
            damping,
            f_gravity,
            lumped,
            field_stations,
            tip: [eu, ev, ew, ephi],
            slope_v: sv,
            slope_w: sw,
            seg_v: th.seg_v,
            seg_w: th.seg_w,
            fields: g.fields,
        })
    }
}

/// The base: prescribed (then no torque law, spring or motor friction) or free under its
/// torque law, spring K_θ and motor friction b_m.
fn base_drive(p: &PayloadLink, name: &str) -> Result<BaseDrive, FdmError> {
    let base = &p.base;
    Ok(match &base.prescribed {
        Some(m) => {
            if base.torque.is_some()
                || base.stiffness.is_some_and(|k| k != 0.0)
                || base.damping.is_some_and(|d| d != 0.0)
            {
                return Err(FdmError::Unsupported(format!(
                    "fdm: `{name}`: a prescribed base with a torque law, spring or motor \
                     friction (the prescribed motion already fixes θ)"
                )));
            }
            BaseDrive::Prescribed(m.clone())
        }
        None => BaseDrive::Free {
            law: base.torque.clone(),
            stiffness: base.stiffness.unwrap_or(0.0),
            damping: p.motor_friction(),
            set_point: base.set_point.unwrap_or(0.0),
        },
    })
}

/// The constant field mass M_ff: lumped masses m_i and torsional inertias ρJh, the sections'
/// rotary inertia ρI Σ_s h(g_v² + g_w²), the payload's m_p(u_L² + y² + z²) and b₁ᵀI_p b₁ with
/// b₁ = (φ_L, −w′_L, v′_L); also the lumped (rod only) diagonal for the step bound.
fn field_mass(g: &Grid, p: &PayloadLink, tip: &Tip, n: usize) -> (Triplets, Vec<f64>) {
    let (r, h, rho) = (g.r, g.h, g.rho);
    let (i2, jp) = (p.second_moment(), p.polar_moment());
    let (mp, d) = (p.payload.mass, p.payload.inertia);
    let mut mff = Triplets::default();
    let mut lumped = vec![0.0; n];
    for i in 1..=r {
        for f in [U, V, W] {
            let l = g.st(f, i);
            mff.outer(g.mass_at(i), &l, &l);
            for &(k, _) in &l {
                lumped[k] = g.mass_at(i);
            }
        }
        let l = g.st(P, i);
        let jm = rho * jp * if i == r { 0.5 * h } else { h };
        mff.outer(jm, &l, &l);
        for &(k, _) in &l {
            lumped[k] = jm;
        }
    }
    for s in 0..r {
        for f in [V, W] {
            let gs = g.seg(f, s);
            mff.outer(rho * i2 * h, &gs, &gs);
        }
    }
    mff.outer(mp, &tip.eu, &tip.eu);
    mff.outer(mp, &tip.ly, &tip.ly);
    mff.outer(mp, &tip.lz, &tip.lz);
    let b1 = [
        tip.ephi.clone(),
        combine(&[(&tip.sw, -1.0)]),
        tip.sv.clone(),
    ];
    for a in 0..3 {
        for b in 0..3 {
            mff.outer(d[a][b], &b1[a], &b1[b]);
        }
    }
    (mff, lumped)
}

/// The coupling M_θf = c + Bq: transport x_i v̇_i and Coriolis m(u v̇ − v u̇) of the stations,
/// the sections' ρ(I v̇′ + J w′φ̇), the payload's m_p((L + c + u_L)ẏ − y u̇_L) and its aᵀI_p b
/// to second order (a = Rᵀe_z, b = Rᵀω).
fn coupling(g: &Grid, p: &PayloadLink, tip: &Tip, n: usize) -> (Vec<f64>, Triplets) {
    let (r, h, rho) = (g.r, g.h, g.rho);
    let (i2, jp) = (p.second_moment(), p.polar_moment());
    let (mp, d) = (p.payload.mass, p.payload.inertia);
    let lc = p.length + p.payload.offset;
    let Tip {
        eu,
        ev,
        ephi,
        sv,
        sw,
        ly,
        ..
    } = tip;
    let mut c_theta = vec![0.0; n];
    let mut b_theta = Triplets::default();
    for i in 1..=r {
        let m = g.mass_at(i);
        add_lin(&mut c_theta, &g.st(V, i), m * g.x(i));
        b_theta.outer(-m, &g.st(U, i), &g.st(V, i));
        b_theta.outer(m, &g.st(V, i), &g.st(U, i));
    }
    // sections: ρ∫(I v̇′ + J w′ φ̇) = ρI v̇_L + Σ_s h ρJ g_w,s (φ̇_s + φ̇_{s+1})/2
    add_lin(&mut c_theta, ev, rho * i2);
    for s in 0..r {
        let phibar = combine(&[(&g.st(P, s), 0.5), (&g.st(P, s + 1), 0.5)]);
        b_theta.outer(rho * jp * h, &phibar, &g.seg(W, s));
    }
    // payload translation: m_p[(L_c + u_L) ẏ − y u̇_L]
    add_lin(&mut c_theta, ly, mp * lc);
    b_theta.outer(mp, ly, eu);
    b_theta.outer(-mp, eu, ly);
    // payload rotation: aᵀ I_p b to second order
    let msw = combine(&[(sw, -1.0)]);
    add_lin(&mut c_theta, ephi, d[2][0]);
    add_lin(&mut c_theta, &msw, d[2][1]);
    add_lin(&mut c_theta, sv, d[2][2]);
    b_theta.outer(-0.5 * d[2][0], sw, sv);
    b_theta.outer(0.5 * d[2][0], sv, sw);
    b_theta.outer(d[2][1], sv, ephi);
    b_theta.outer(d[2][2], sw, ephi);
    b_theta.outer(d[0][0], ephi, sw);
    b_theta.outer(-d[0][1], sw, sw);
    b_theta.outer(d[0][2], sv, sw);
    b_theta.outer(d[1][0], ephi, ephi);
    b_theta.outer(-d[1][1], sw, ephi);
    b_theta.outer(d[1][2], sv, ephi);
    (c_theta, b_theta)
}

/// M_θθ = M₀ + 2gᵀq + qᵀHq: the rigid inertias, the axial shift 2x u, the foreshortening
/// −2x s, u² + v², the sections' (J − I)w′², the payload's
/// 2(L+c)(u_L − s_L − ½c(v′_L² + w′_L²)) + u_L² + y² and aᵀI_p a.
fn theta_inertia(g: &Grid, p: &PayloadLink, tip: &Tip, n: usize) -> ThetaInertia {
    let (r, h, rho) = (g.r, g.h, g.rho);
    let (i2, jp) = (p.second_moment(), p.polar_moment());
    let (mp, c, d) = (p.payload.mass, p.payload.offset, p.payload.inertia);
    let lc = p.length + c;
    let Tip {
        eu,
        ephi,
        sv,
        sw,
        ly,
        ..
    } = tip;
    let mut m0 = p.base_inertia() + mp * lc * lc + rho * i2 * p.length + d[2][2];
    let mut g_theta = vec![0.0; n];
    let mut h_theta = Triplets::default();
    for i in 1..=r {
        let m = g.mass_at(i);
        m0 += m * g.x(i) * g.x(i);
        add_lin(&mut g_theta, &g.st(U, i), m * g.x(i));
        h_theta.outer(m, &g.st(U, i), &g.st(U, i));
        h_theta.outer(m, &g.st(V, i), &g.st(V, i));
    }
    // −2 Σ m_i x_i s_i = −Σ_s h W_s (g_v² + g_w²), W_s = Σ_{i>s} m_i x_i;
    // payload −2 L_c s_L = −L_c Σ_s h (g_v² + g_w²); sections ρ(J − I)Σ_s h g_w²
    let mut wseg = 0.0;
    let mut wsegs = vec![0.0; r];
    for s in (0..r).rev() {
        wseg += g.mass_at(s + 1) * g.x(s + 1);
        wsegs[s] = wseg;
    }
    let mut seg_v = Vec::with_capacity(r);
    let mut seg_w = Vec::with_capacity(r);
    for (s, wseg_s) in wsegs.iter().enumerate() {
        let (gv, gw) = (g.seg(V, s), g.seg(W, s));
        let k = -h * (wseg_s + mp * lc);
        h_theta.outer(k, &gv, &gv);
        h_theta.outer(k, &gw, &gw);
        h_theta.outer(rho * (jp - i2) * h, &gw, &gw);
        seg_v.push(gv);
        seg_w.push(gw);
    }
    add_lin(&mut g_theta, eu, mp * lc);
    h_theta.outer(-mp * lc * c, sv, sv);
    h_theta.outer(-mp * lc * c, sw, sw);
    h_theta.outer(mp, eu, eu);
    h_theta.outer(mp, ly, ly);
    // aᵀ I_p a
    add_lin(&mut g_theta, sw, d[2][0]);
    add_lin(&mut g_theta, ephi, d[2][1]);
    h_theta.sym_outer(-0.5 * d[2][1], sv, sw);
    h_theta.outer(-d[2][2], sw, sw);
    h_theta.outer(-d[2][2], ephi, ephi);
    h_theta.outer(d[0][0], sw, sw);
    h_theta.sym_outer(d[0][1], sw, ephi);
    h_theta.outer(d[1][1], ephi, ephi);
    ThetaInertia {
        m0,
        g_theta,
        h_theta,
        seg_v,
        seg_w,
    }
}

/// K_f per carried field: axial ½Σ_s h EA g_u², torsion ½Σ_s h GJ g_φ², bending
/// ½Σ_i c_i h EI κ_i² (c_0 = ½); a Kelvin–Voigt field gets C_f = (γ_f/modulus_f) K_f.
fn field_stiffness(g: &Grid, p: &PayloadLink) -> FieldStiffness {
    let (r, h) = (g.r, g.h);
    let mut stiffness = Vec::new();
    let mut damping = Vec::new();
    for &f in &g.fields {
        let mut k = Triplets::default();
        let modulus = match f {
            U => {
                for s in 0..r {
                    let gs = g.seg(U, s);
                    k.outer(h * p.axial_stiffness(), &gs, &gs);
                }
                p.youngs_modulus
            }
            P => {
                for s in 0..r {
                    let gs = g.seg(P, s);
                    k.outer(h * p.torsional_stiffness(), &gs, &gs);
                }
                p.shear_modulus
            }
            V | W => {
                for i in 0..r {
                    let (kap, wt) = g.curv(f, i);
                    k.outer(wt * h * p.bending_stiffness(), &kap, &kap);
                }
                p.youngs_modulus
            }
        };
        if let Some(cf) = p.kelvin_voigt_on(f) {
            damping.push((f, stiffness.len(), cf / modulus));
        }
        stiffness.push((f, k));
    }
    (stiffness, damping)
}

/// f_g = −g(Σ m_i ∂w_i + m_p ∂z) (none without gravity or without the vertical field).
fn gravity_load(g: &Grid, p: &PayloadLink, tip: &Tip, n: usize) -> Option<Vec<f64>> {
    let mp = p.payload.mass;
    p.gravity.filter(|gr| *gr != 0.0).and_then(|gr| {
        g.slot(W)?;
        let mut fg = vec![0.0; n];
        for i in 1..=g.r {
            for &(k, v) in &g.st(W, i) {
                fg[k] -= gr * g.mass_at(i) * v;
            }
        }
        for &(k, v) in &tip.lz {
            fg[k] -= gr * mp * v;
        }
        Some(fg)
    })
}
