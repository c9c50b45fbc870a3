//! One flexible link as a floating-frame body: kinetic energy T = ½ νᵀ 𝕄(e) ν in the body
//! velocities ν = (V_x, V_y, ω, ȧ, ḃ), its Lagrange terms h, and the gravity force.
//!
//! Local position of the material point x (frame axes): p = (x + u − f·s(x), v) with
//! u = ψᵀa, v = φᵀb, s(x) = ½ bᵀS(x)b (foreshortening, f = 1 when on, 0 otherwise). Its local
//! velocity is V + ω J p + ṗ (J = rotation by +90°). The distributed kinetic energy is
//! ½∫ρA |V + ωJp + ṗ|², expanded as
//!
//!   2T = m|V|² + 2ω[−V_x Φ₁ᵀb + V_y(c₀ + Ψ₁ᵀa − ½f bᵀS₁b)] + 2V_x(Ψ₁ᵀȧ − f bᵀS₁ḃ)
//!        + 2V_y Φ₁ᵀḃ + ω²[c₂ + 2Ψₓᵀa + aᵀM_ψa − f bᵀSₓb + bᵀM_φb]
//!        + 2ω[−(Cb)ᵀȧ + (Φₓ + Cᵀa)ᵀḃ] + ȧᵀM_ψȧ + ḃᵀM_φḃ  (+ 2ΔT + 2ΔT_us when f = 1)
//!
//! where ΔT = ½∫ρA[ω²s² + 2ω(vṡ − sv̇) + ṡ²] completes it to the exact kinetic energy of the
//! inextensible link (`exact_inextensible_terms`; needs the tensors ∫ρA S⊗S and ∫ρA φ⊗S,
//! contracted once with b per evaluation: n³(n+1)/2 products per link with foreshortening,
//! O(n²) otherwise), and ΔT_us = −∫ρA[u̇ṡ + ω²us] the coupling of an axial stretch field
//! with the foreshortening (`stretch_foreshortening_terms`). An extensible link (von Kármán
//! strain u_x + ½v'² of the axial displacement u_x) is modelled with f = 1 and the stretch
//! u = u_x + s as its axial field: its strain is u' exactly, so a truncated axial basis does
//! not have to represent ½v'² (which it cannot: membrane locking). The truncated form is not positive definite in the stiff direction "turn
//! an inertia-free hub frame and counter-bend the link".
//!
//! The −f ω² bᵀSₓb term is the centrifugal (geometric) stiffening; ω² bᵀM_φb the in-plane
//! softening. The tip mass is an exact point at p(L); the tip inertia rotates with α + v'(L);
//! a hub inertia rotates with the frame. Because the equations are Lagrange's equations of this
//! one energy, energy balance holds exactly for the discretized system.
//!
//! Lagrange terms in body velocities (ν̇ = (V̇, ω̇, ë), V̇ the derivative of the local V):
//! E = 𝕄 ν̇ + h with h = 𝕄̇ν + (ω J P, −(J P)·V, −∂T/∂e), P = ∂T/∂V.

use super::link::LinkModel;
use crate::linalg::{dot, mat_vec};
use inextensible::{exact_inextensible_terms, stretch_foreshortening_terms};

mod inextensible;

/// Work vectors and tip quantities of one body evaluation.
#[derive(Debug, Clone)]
pub struct BodyScratch {
    mphib: Vec<f64>,
    mphibd: Vec<f64>,
    s1b: Vec<f64>,
    s1bd: Vec<f64>,
    sxb: Vec<f64>,
    pub(crate) slb: Vec<f64>,
    pub(crate) slbd: Vec<f64>,
    mpsia: Vec<f64>,
    mpsiad: Vec<f64>,
    cb: Vec<f64>,
    cbd: Vec<f64>,
    cta: Vec<f64>,
    ctad: Vec<f64>,
    bl: Vec<f64>,
    // Exact-inextensible terms (see `exact_inextensible_terms`): C (n³), A (n²), D and E (n²),
    // and the vectors A b, Eq b, z, Rvd b, w.
    cq: Vec<f64>,
    amat: Vec<f64>,
    dr: Vec<f64>,
    er: Vec<f64>,
    ab: Vec<f64>,
    eqb: Vec<f64>,
    zv: Vec<f64>,
    t1: Vec<f64>,
    t2: Vec<f64>,
    // Stretch–foreshortening coupling (see `stretch_foreshortening_terms`): P_k b and P_k ḃ
    // (na × nb each).
    pb: Vec<f64>,
    pbd: Vec<f64>,
    /// Tip position p(L), its velocity ṗ(L) (both in frame axes) and the tip's full local
    /// velocity w = V + ωJp + ṗ.
    pub(crate) p_tip: [f64; 2],
    pub(crate) pd_tip: [f64; 2],
    pub(crate) w_tip: [f64; 2],
    /// ∫ρA p dx + M_tip p(L): first moment of mass in frame axes.
    pub(crate) p_bar: [f64; 2],
}

impl BodyScratch {
    pub fn new(na: usize, nb: usize, nc: usize) -> Self {
        let z = |k: usize| vec![0.0; k];
        BodyScratch {
            mphib: z(nb),
            mphibd: z(nb),
            s1b: z(nb),
            s1bd: z(nb),
            sxb: z(nb),
            slb: z(nb),
            slbd: z(nb),
            mpsia: z(na),
            mpsiad: z(na),
            cb: z(na),
            cbd: z(na),
            cta: z(nb),
            ctad: z(nb),
            bl: z(2 * (3 + na + nb + nc)),
            cq: z(nb * nb * nb),
            amat: z(nb * nb),
            dr: z(nb * nb),
            er: z(nb * nb),
            ab: z(nb),
            eqb: z(nb),
            zv: z(nb),
            t1: z(nb),
            t2: z(nb),
            pb: z(na * nb),
            pbd: z(na * nb),
            p_tip: [0.0; 2],
            pd_tip: [0.0; 2],
            w_tip: [0.0; 2],
            p_bar: [0.0; 2],
        }
    }
}

/// The state's scalar reductions shared by 𝕄, h and the gravity force: Φ₁ᵀb, Φ₁ᵀḃ, Ψ₁ᵀa,
/// Ψ₁ᵀȧ and, with foreshortening, bᵀS₁b, bᵀS₁ḃ, bᵀSₓb, ḃᵀSₓb, ḃᵀS₁ḃ (zero without).
#[derive(Debug, Clone, Copy)]
struct Reductions {
    phi1_b: f64,
    phi1_bd: f64,
    psi1_a: f64,
    psi1_ad: f64,
    bs1b: f64,
    bs1bd: f64,
    bsxb: f64,
    bsxbd: f64,
    bds1bd: f64,
}

/// Fills 𝕄 (d × d row-major), h and the gravity force Q_g (zero without gravity) for one link
/// at elastic state (a, b) and body velocities ν. `g_loc` is gravity in frame axes.
///
/// Phases: the matrix–vector contractions of the state (`contract_state`) and its scalar
/// reductions (`reductions`); 𝕄 and h of the distributed mass (`distributed_mass`,
/// `distributed_h`); the exact-inextensible and stretch–foreshortening completions; the tip
/// point (`tip_point`) and the tip mass on it (`tip_mass_terms`); the rotational inertias
/// of the tip body and the sections (`rotational_inertia`); the first moment of mass and the
/// gravity force (`first_moment_and_gravity`).
#[allow(clippy::too_many_arguments)]
pub fn body_terms(
    link: &LinkModel,
    a: &[f64],
    b: &[f64],
    nu: &[f64],
    g_loc: Option<[f64; 2]>,
    mb: &mut [f64],
    h: &mut [f64],
    qg: &mut [f64],
    s: &mut BodyScratch,
) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    let (ia, ib) = (3, 3 + na);
    let f = if link.foreshortening { 1.0 } else { 0.0 };
    let om = nu[2];
    let ad = &nu[ia..ia + na];
    let bd = &nu[ib..ib + nb];

    contract_state(link, a, b, ad, bd, s);
    let r = reductions(link, a, b, ad, bd, s);
    let m02 = -r.phi1_b;
    let m12 = it.c0 + r.psi1_a - 0.5 * f * r.bs1b;
    distributed_mass(link, a, b, &r, m02, m12, mb, s);
    distributed_h(link, a, b, nu, &r, m02, m12, h, s);

    if link.foreshortening {
        exact_inextensible_terms(it, b, bd, om, mb, h, s);
        if na > 0 {
            stretch_foreshortening_terms(it, a, ad, b, bd, om, mb, h, s);
        }
    }

    tip_point(link, a, b, nu, s);
    if link.tip_mass > 0.0 {
        tip_mass_terms(link, bd, om, mb, h, s);
    }
    rotational_inertia(link, mb);
    first_moment_and_gravity(link, &r, g_loc, qg, s);
}

/// The state's matrix–vector products into the scratch: M_φb, M_φḃ; with foreshortening S₁b,
/// S₁ḃ, Sₓb, S_Lb, S_Lḃ; with an axial field M_ψa, M_ψȧ, Cb, Cḃ, Cᵀa, Cᵀȧ.
#[inline]
fn contract_state(
    link: &LinkModel,
    a: &[f64],
    b: &[f64],
    ad: &[f64],
    bd: &[f64],
    s: &mut BodyScratch,
) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    mat_vec(&it.mphi, nb, b, &mut s.mphib);
    mat_vec(&it.mphi, nb, bd, &mut s.mphibd);
    if link.foreshortening {
        mat_vec(&it.s1, nb, b, &mut s.s1b);
        mat_vec(&it.s1, nb, bd, &mut s.s1bd);
        mat_vec(&it.sx, nb, b, &mut s.sxb);
        mat_vec(&it.sl, nb, b, &mut s.slb);
        mat_vec(&it.sl, nb, bd, &mut s.slbd);
    }
    if na > 0 {
        mat_vec(&it.mpsi, na, a, &mut s.mpsia);
        mat_vec(&it.mpsi, na, ad, &mut s.mpsiad);
        for k in 0..na {
            let row = &it.c[k * nb..(k + 1) * nb];
            s.cb[k] = dot(row, b);
            s.cbd[k] = dot(row, bd);
        }
        for l in 0..nb {
            let (mut x, mut y) = (0.0, 0.0);
            for k in 0..na {
                x += it.c[k * nb + l] * a[k];
                y += it.c[k * nb + l] * ad[k];
            }
            s.cta[l] = x;
            s.ctad[l] = y;
        }
    }
}

/// The scalar reductions of the state (after [`contract_state`]).
#[inline]
fn reductions(
    link: &LinkModel,
    a: &[f64],
    b: &[f64],
    ad: &[f64],
    bd: &[f64],
    s: &BodyScratch,
) -> Reductions {
    let it = &link.ints;
    let phi1_b = dot(&it.phi1, b);
    let phi1_bd = dot(&it.phi1, bd);
    let psi1_a = dot(&it.psi1, a);
    let psi1_ad = dot(&it.psi1, ad);
    let (bs1b, bs1bd, bsxb, bsxbd, bds1bd) = if link.foreshortening {
        (
            dot(b, &s.s1b),
            dot(b, &s.s1bd),
            dot(b, &s.sxb),
            dot(bd, &s.sxb),
            dot(bd, &s.s1bd),
        )
    } else {
        (0.0, 0.0, 0.0, 0.0, 0.0)
    };
    Reductions {
        phi1_b,
        phi1_bd,
        psi1_a,
        psi1_ad,
        bs1b,
        bs1bd,
        bsxb,
        bsxbd,
        bds1bd,
    }
}

/// 𝕄 of the distributed mass (overwrites `mb`): m on V, 𝕄_Vω = (−Φ₁ᵀb, c₀ + Ψ₁ᵀa − ½f bᵀS₁b),
/// 𝕄_ωω = c₂ + 2Ψₓᵀa + aᵀM_ψa − f bᵀSₓb + bᵀM_φb + J_hub, 𝕄_Va = Ψ₁, 𝕄_ωa = −Cb, 𝕄_aa = M_ψ,
/// 𝕄_Vb = (−f S₁b, Φ₁), 𝕄_ωb = Φₓ + Cᵀa, 𝕄_bb = M_φ (the ψ coordinates c, if any, only get
/// section and tip inertia later).
#[allow(clippy::too_many_arguments)]
#[inline]
fn distributed_mass(
    link: &LinkModel,
    a: &[f64],
    b: &[f64],
    r: &Reductions,
    m02: f64,
    m12: f64,
    mb: &mut [f64],
    s: &BodyScratch,
) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    let d = link.body_dim();
    let (ia, ib) = (3, 3 + na);
    let f = if link.foreshortening { 1.0 } else { 0.0 };
    let inertia = it.c2 + 2.0 * dot(&it.psix, a) + dot(a, &s.mpsia) - f * r.bsxb + dot(b, &s.mphib);
    mb.iter_mut().for_each(|v| *v = 0.0);
    mb[0] = it.m;
    mb[d + 1] = it.m;
    mb[2] = m02;
    mb[2 * d] = m02;
    mb[d + 2] = m12;
    mb[2 * d + 1] = m12;
    mb[2 * d + 2] = inertia + link.hub_inertia;
    for k in 0..na {
        mb[ia + k] = it.psi1[k];
        mb[(ia + k) * d] = it.psi1[k];
        mb[2 * d + ia + k] = -s.cb[k];
        mb[(ia + k) * d + 2] = -s.cb[k];
        for l in 0..na {
            mb[(ia + k) * d + ia + l] = it.mpsi[k * na + l];
        }
    }
    for k in 0..nb {
        let v0 = -f * s.s1b[k];
        mb[ib + k] = v0;
        mb[(ib + k) * d] = v0;
        mb[d + ib + k] = it.phi1[k];
        mb[(ib + k) * d + 1] = it.phi1[k];
        let v2 = it.phix[k] + if na > 0 { s.cta[k] } else { 0.0 };
        mb[2 * d + ib + k] = v2;
        mb[(ib + k) * d + 2] = v2;
        for l in 0..nb {
            mb[(ib + k) * d + ib + l] = it.mphi[k * nb + l];
        }
    }
}

/// h = 𝕄̇ν + (ω J P, −(J P)·V, −∂T/∂e) of the distributed mass (overwrites `h`), with the
/// momenta P = (m V_x + 𝕄_xω ω + Ψ₁ᵀȧ − f S₁b·ḃ, m V_y + 𝕄_yω ω + Φ₁ᵀḃ).
#[allow(clippy::too_many_arguments)]
#[inline]
fn distributed_h(
    link: &LinkModel,
    a: &[f64],
    b: &[f64],
    nu: &[f64],
    r: &Reductions,
    m02: f64,
    m12: f64,
    h: &mut [f64],
    s: &BodyScratch,
) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    let (ia, ib) = (3, 3 + na);
    let f = if link.foreshortening { 1.0 } else { 0.0 };
    let (vx, vy, om) = (nu[0], nu[1], nu[2]);
    let ad = &nu[ia..ia + na];
    let bd = &nu[ib..ib + nb];
    let Reductions {
        phi1_bd,
        psi1_ad,
        bs1bd,
        bsxbd,
        bds1bd,
        ..
    } = *r;
    h.iter_mut().for_each(|v| *v = 0.0);
    let px = it.m * vx + m02 * om + psi1_ad - f * dot(&s.s1b, bd);
    let py = it.m * vy + m12 * om + phi1_bd;
    let d_inertia = 2.0 * dot(&it.psix, ad) + 2.0 * dot(a, &s.mpsiad) - 2.0 * f * bsxbd
        + 2.0 * dot(b, &s.mphibd);
    h[0] = -om * phi1_bd - f * bds1bd - om * py;
    h[1] = om * (psi1_ad - f * bs1bd) + om * px;
    h[2] = -vx * phi1_bd + vy * (psi1_ad - f * bs1bd) + om * d_inertia + py * vx - px * vy;
    for k in 0..na {
        // 𝕄̇ν = −ω C ḃ;  ∂T/∂a = V_y ω Ψ₁ + ω²(Ψₓ + M_ψ a) + ω C ḃ.
        let dtda = vy * om * it.psi1[k] + om * om * (it.psix[k] + s.mpsia[k]) + om * s.cbd[k];
        h[ia + k] = -om * s.cbd[k] - dtda;
    }
    for k in 0..nb {
        let ctad = if na > 0 { s.ctad[k] } else { 0.0 };
        // 𝕄̇ν = −f V_x S₁ḃ + ω Cᵀȧ;
        // ∂T/∂b = −V_x ω Φ₁ − f V_y ω S₁b − f V_x S₁ḃ + ω²(−f Sₓb + M_φ b) − ω Cᵀȧ.
        let mdot = -f * vx * s.s1bd[k] + om * ctad;
        let dtdb = -vx * om * it.phi1[k] - f * vy * om * s.s1b[k] - f * vx * s.s1bd[k]
            + om * om * (-f * s.sxb[k] + s.mphib[k])
            - om * ctad;
        h[ib + k] = mdot - dtdb;
    }
}

/// Tip point p(L) = (L + ψ(L)ᵀa − ½f bᵀS_L b, φ(L)ᵀb), exact, its rate ṗ(L) and the tip's
/// local velocity w = V + ωJp + ṗ, into the scratch.
#[inline]
fn tip_point(link: &LinkModel, a: &[f64], b: &[f64], nu: &[f64], s: &mut BodyScratch) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    let (ia, ib) = (3, 3 + na);
    let f = if link.foreshortening { 1.0 } else { 0.0 };
    let (vx, vy, om) = (nu[0], nu[1], nu[2]);
    let ad = &nu[ia..ia + na];
    let bd = &nu[ib..ib + nb];
    let pl = [
        it.length + dot(&it.psi_l, a) - 0.5 * f * dot(b, &s.slb),
        dot(&it.phi_l, b),
    ];
    let pld = [dot(&it.psi_l, ad) - f * dot(&s.slb, bd), dot(&it.phi_l, bd)];
    let wl = [vx - om * pl[1] + pld[0], vy + om * pl[0] + pld[1]];
    s.p_tip = pl;
    s.pd_tip = pld;
    s.w_tip = wl;
}

/// The tip mass at p(L) (after [`tip_point`]): with w = B_L ν, 𝕄 += m_t B_Lᵀ B_L and
/// h += m_t B_Lᵀ(Ḃ_L ν + ω J w).
#[inline]
fn tip_mass_terms(
    link: &LinkModel,
    bd: &[f64],
    om: f64,
    mb: &mut [f64],
    h: &mut [f64],
    s: &mut BodyScratch,
) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    let d = link.body_dim();
    let (ia, ib) = (3, 3 + na);
    let f = if link.foreshortening { 1.0 } else { 0.0 };
    let (pl, pld, wl) = (s.p_tip, s.pd_tip, s.w_tip);
    let mt = link.tip_mass;
    // Columns of B_L (2 × d): w = B_L ν.
    let (bx, by) = s.bl.split_at_mut(d);
    bx.iter_mut().for_each(|v| *v = 0.0);
    by.iter_mut().for_each(|v| *v = 0.0);
    bx[0] = 1.0;
    by[1] = 1.0;
    bx[2] = -pl[1];
    by[2] = pl[0];
    bx[ia..ia + na].copy_from_slice(&it.psi_l[..na]);
    for k in 0..nb {
        bx[ib + k] = -f * s.slb[k];
        by[ib + k] = it.phi_l[k];
    }
    // Inertial acceleration (frame axes) minus B_L ν̇: Ḃ_L ν + ω J w.
    let bsb = if link.foreshortening {
        dot(bd, &s.slbd)
    } else {
        0.0
    };
    let cx = -om * pld[1] - bsb - om * wl[1];
    let cy = om * pld[0] + om * wl[0];
    for r in 0..d {
        h[r] += mt * (bx[r] * cx + by[r] * cy);
        for c in 0..d {
            mb[r * d + c] += mt * (bx[r] * bx[c] + by[r] * by[c]);
        }
    }
}

/// Constant rotational inertias: the tip body turning with the tip section, α + r(L)ᵀe,
/// T = ½J(ω + r(L)ᵀė)², and the sections' rotary inertia ½∫ρI(ω + r(x)ᵀė)² (no convective
/// terms).
#[inline]
fn rotational_inertia(link: &LinkModel, mb: &mut [f64]) {
    let d = link.body_dim();
    let ne = d - 3;
    let rot_l = &link.section.rot_l;
    if link.tip_inertia > 0.0 {
        let jt = link.tip_inertia;
        mb[2 * d + 2] += jt;
        for k in 0..ne {
            let ck = rot_l[k];
            if ck == 0.0 {
                continue;
            }
            mb[2 * d + 3 + k] += jt * ck;
            mb[(3 + k) * d + 2] += jt * ck;
            for l in 0..ne {
                mb[(3 + k) * d + 3 + l] += jt * ck * rot_l[l];
            }
        }
    }
    if let Some(rot) = &link.section.rotary {
        mb[2 * d + 2] += rot.j0;
        for k in 0..ne {
            mb[2 * d + 3 + k] += rot.r1[k];
            mb[(3 + k) * d + 2] += rot.r1[k];
            let row = &rot.rm[k * ne..(k + 1) * ne];
            for (l, v) in row.iter().enumerate() {
                mb[(3 + k) * d + 3 + l] += v;
            }
        }
    }
}

/// First moment of mass p̄ = ∫ρA p + m_t p(L) (frame axes, after [`tip_point`]) and the
/// generalized gravity force (overwrites `qg`; zero without gravity): Q_V = (m + m_t)g,
/// Q_ω = g_y p̄_x − g_x p̄_y, Q_a = g_x(Ψ₁ + m_t ψ(L)), Q_b = −f g_x(S₁b + m_t S_L b)
/// + g_y(Φ₁ + m_t φ(L)).
#[inline]
fn first_moment_and_gravity(
    link: &LinkModel,
    r: &Reductions,
    g_loc: Option<[f64; 2]>,
    qg: &mut [f64],
    s: &mut BodyScratch,
) {
    let it = &link.ints;
    let (na, nb) = (it.na, it.nb);
    let (ia, ib) = (3, 3 + na);
    let f = if link.foreshortening { 1.0 } else { 0.0 };
    let pl = s.p_tip;
    s.p_bar = [
        it.c0 + r.psi1_a - 0.5 * f * r.bs1b + link.tip_mass * pl[0],
        r.phi1_b + link.tip_mass * pl[1],
    ];
    qg.iter_mut().for_each(|v| *v = 0.0);
    if let Some(g) = g_loc {
        let mt = it.m + link.tip_mass;
        qg[0] = mt * g[0];
        qg[1] = mt * g[1];
        qg[2] = -g[0] * s.p_bar[1] + g[1] * s.p_bar[0];
        for k in 0..na {
            qg[ia + k] = g[0] * (it.psi1[k] + link.tip_mass * it.psi_l[k]);
        }
        for k in 0..nb {
            qg[ib + k] = g[0] * (-f * (s.s1b[k] + link.tip_mass * s.slb[k]))
                + g[1] * (it.phi1[k] + link.tip_mass * it.phi_l[k]);
        }
    }
}
