//! Cross-section model of one link: the section rotation ψ, rotary inertia, and the elastic and
//! Kelvin–Voigt matrices of the bending block.
//!
//! The elastic coordinates of a link are e = [a (axial), b (transverse v = φᵀb), c (rotation
//! ψ = χᵀc, Timoshenko links with section inertia only)], contiguous in q. Everything below is
//! written with the section rotation as a linear map ψ(x) = r(x)ᵀe:
//!
//! * **Euler–Bernoulli** (`shear` off): ψ = v', r = (0, φ', 0); U = ½∫EI v''² = ½bᵀK_b b,
//!   Kelvin–Voigt γ∫v̇''² (damping matrix γ∫φ''φ''ᵀ).
//! * **Timoshenko** (`shear` on, convention of the fem/modal helpers): independent fields
//!   v = φᵀb and ψ = χᵀc, clamped v(0) = ψ(0) = 0, shear strain v' − ψ, curvature ψ'.
//!   U = ½∫EI ψ'² + ½∫κGA (v' − ψ)², i.e. over [b, c]
//!
//!   K = [[κGA∫φ'φ'ᵀ, −κGA∫φ'χᵀ], [−κGA∫χφ'ᵀ, EI∫χ'χ'ᵀ + κGA∫χχᵀ]],
//!
//!   Kelvin–Voigt on ψ' only (moment EI ψ' + γ ψ̇', dissipation γ∫ψ̇'², no shear damping):
//!   D = [[0, 0], [0, γ∫χ'χ'ᵀ]].
//!
//!   Bases (n functions per field). The frame is the root cross-section (ψ(0) = 0), so the root
//!   shear strain is v'(0). With a prescribed joint or with section rotary inertia the v basis
//!   carries it: `poly` → φ, χ ∈ span{ξ, …, ξⁿ} (ξ·Pₖ(2ξ−1)); eigenfunction bases →
//!   φ ∈ {ξ, φ₁…φₙ₋₁}, χ ∈ {ξ, φ₁'…φₙ₋₁'} ([`crate::basis::ShapeSet::timoshenko_eigen_pair`]).
//!   With a free joint and massless sections the combination "turn the frame by ε, shear the
//!   root by −ε" moves no mass at all (every mass point keeps its velocity; only the massless
//!   sections turn), so M(q) would be singular — in the continuum that combination is a
//!   first-order relaxation through the joint damper, which M q̈ = f cannot carry. There the v
//!   basis keeps v'(0) = 0 (`poly` → v ∈ span{ξ², …, ξⁿ⁺¹}, χ ∈ span{ξ, …, ξⁿ};
//!   eigenfunction bases → φ ∈ {φ₁…φₙ}, χ ∈ {φ₁'…φₙ'}): the root shear is carried by the frame
//!   angle, an approximation of the clamp that converges with n (functions with v'(0) = 0 are
//!   dense in the shear energy space H¹) but is not exact at finite n: algebraically, measured
//!   on the stocky cantilever without rotary inertia (κGA L²/EI ≈ 385) as a mode-1 error of
//!   2.0e-4 / 5.7e-5 at n = 6 / 12 (`poly`) against the root-shear basis (test
//!   `conv_timoshenko_root_shear_basis_study`).
//!   In every case χ contains the derivative of every v shape except the root-shear ξ, so ψ = v'
//!   is representable and
//!   the κGA → ∞ limit is the Euler model on the v shapes without the root-shear function
//!   (no shear locking).
//! * **Rotary inertia** (`rotary_inertia`, ρI): ½∫ρI (ω + ψ̇)² adds to the body mass matrix
//!   ρI·L (ωω), ∫ρI r (ωe) and ∫ρI r rᵀ (ee) — constant, so no convective terms. With the
//!   Euler model r = φ'.
//! * **Massless rotation** (Timoshenko without `rotary_inertia`): c has no inertia, and its
//!   equation K_cc c + K_cb b + D_cc ċ = 0 is a first-order relaxation whose rates (the
//!   eigenvalues of D_cc⁻¹K_cc) are EI/γ + (κGA/γ)·∫χ²/∫χ'² > EI/γ (2.5·10⁴ s⁻¹ for
//!   barhorst-case1-timoshenko; most are far larger, ~κGA L²/γ). It is condensed on its slow
//!   manifold: c = T b with
//!   T = −K_cc⁻¹K_cb (exact without Kelvin–Voigt: the static condensation), giving
//!   K_eff = K_bb + K_cbᵀT and, to first order in ω/rate, the damping TᵀD_cc T: the relative
//!   error in a mode of frequency ω is O(ωγ/EI) at most, i.e. small wherever the Kelvin–Voigt
//!   model leaves the mode underdamped (ωγ/EI < 2); it is an approximation of the convention's
//!   Kelvin–Voigt on a massless ψ, exact without Kelvin–Voigt. ψ(L) = χ(L)ᵀT b.
//!   A tip inertia would give c inertia through ψ(L) only: refused in setup (not condensable
//!   exactly, and a singular ψ mass otherwise). This per-link condensation (T, `kbc`, `dbc`)
//!   holds where nothing else acts on ψ(L): at the last link and before a prescribed joint. Before
//!   a free joint the elbow spring, damper and applied torque act on link i's tip section, and
//!   the condensation includes them, with the frame-to-frame angle φ = ψᵢ(Lᵢ) + θᵢ₊₁ as the
//!   joint coordinate so that the child's inertia does not reach c ([`super::elbow`]; the
//!   blocks before condensation are kept in `blocks`).
//!
//! The joint convention (link i+1 clamped to the cross-section at the tip of link i:
//! αᵢ₊₁ = αᵢ + ψᵢ(Lᵢ) + θᵢ₊₁) and the tip inertia ½J(ω + ψ̇(L))² use r(L) = `rot_l`; behind an
//! elbow ([`super::elbow`]) the kinematics use φ = ψᵢ(Lᵢ) + θᵢ₊₁ instead.

use crate::basis::ShapeSet;
use crate::basis::quadrature::Quadrature;
use crate::linalg::cholesky_solve;

/// Which section model a link uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SectionKind {
    Euler,
    /// Timoshenko with ψ coordinates c (rotary inertia on).
    Timoshenko,
    /// Timoshenko with the massless ψ condensed: c = T b.
    TimoshenkoCondensed,
}

/// Rotary inertia of the sections: ρI·L, ∫ρI r (over e), ∫ρI r rᵀ (over e, row-major).
#[derive(Debug, Clone)]
pub struct Rotary {
    pub j0: f64,
    pub r1: Vec<f64>,
    pub rm: Vec<f64>,
}

/// The section data of one link (see the module docs).
#[derive(Debug, Clone)]
pub struct Section {
    pub kind: SectionKind,
    /// Number of ψ coordinates (0 unless `kind == Timoshenko`).
    pub nc: usize,
    /// ψ(L) = rot_lᵀ e, over the link's elastic coordinates e = [a, b, c].
    pub rot_l: Vec<f64>,
    pub rotary: Option<Rotary>,
    /// Stiffness of the bending block [b, c] ((nb + nc)², row-major).
    pub kbc: Vec<f64>,
    /// Kelvin–Voigt damping matrix of the bending block (empty without Kelvin–Voigt).
    pub dbc: Vec<f64>,
    /// Timoshenko only: the ψ shapes χ.
    pub psi_shapes: Option<ShapeSet>,
    /// Condensed Timoshenko only: T (nψ × nb, row-major), ψ = χᵀT b.
    pub condensation: Option<Vec<f64>>,
    /// Condensed Timoshenko only: the uncondensed blocks, for a condensation that includes the
    /// elbow of a child joint ([`super::elbow`]).
    pub blocks: Option<CondensedBlocks>,
}

/// The bending block of a condensed Timoshenko link before condensation: U = ½bᵀK_bb b +
/// bᵀK_bc c + ½cᵀK_cc c, Kelvin–Voigt ½ċᵀD_cc ċ, and ψ(L) = χ(L)ᵀc.
#[derive(Debug, Clone)]
pub struct CondensedBlocks {
    /// K_bb (nb × nb).
    pub kbb: Vec<f64>,
    /// K_bc (nb × nψ).
    pub kbc: Vec<f64>,
    /// K_cc (nψ × nψ).
    pub kcc: Vec<f64>,
    /// D_cc (nψ × nψ; empty without Kelvin–Voigt).
    pub dcc: Vec<f64>,
    /// χ(L).
    pub chi_l: Vec<f64>,
}

/// Section parameters of a link.
#[derive(Debug, Clone, Copy)]
pub struct SectionParams {
    pub ei: f64,
    /// κGA when `shear` is on.
    pub shear_stiffness: Option<f64>,
    /// ρI when `rotary_inertia` is on.
    pub rho_i: Option<f64>,
    /// Kelvin–Voigt γ.
    pub kelvin_voigt: Option<f64>,
}

/// The symmetric congruence JᵀDJ (n × n, row-major) of D (nc × nc, row-major) with the
/// nc × n map J given entrywise by `jac(k, j)`, each entry scaled by `scale` and the result
/// symmetrized (the damping of a condensed coordinate set).
pub(super) fn congruence(
    jac: impl Fn(usize, usize) -> f64,
    d: &[f64],
    nc: usize,
    n: usize,
    scale: f64,
) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let mut s = 0.0;
            for k in 0..nc {
                for m in 0..nc {
                    s += jac(k, i) * d[k * nc + m] * jac(m, j);
                }
            }
            out[i * n + j] = scale * s;
        }
    }
    symmetrize(&mut out, n);
    out
}

fn symmetrize(m: &mut [f64], n: usize) {
    for i in 0..n {
        for j in 0..i {
            let v = 0.5 * (m[i * n + j] + m[j * n + i]);
            m[i * n + j] = v;
            m[j * n + i] = v;
        }
    }
}

/// Gram-type integrals ∫ f_i g_j over the rule (row-major nf × ng).
fn gram(quad: &Quadrature, f: &ShapeSet, df: usize, g: &ShapeSet, dg: usize, out: &mut [f64]) {
    let (nf, ng) = (f.count(), g.count());
    let (mut fv, mut gv) = (vec![0.0; nf], vec![0.0; ng]);
    out.iter_mut().for_each(|v| *v = 0.0);
    for (&x, &w) in quad.x.iter().zip(&quad.w) {
        f.eval(x, df, &mut fv);
        g.eval(x, dg, &mut gv);
        for i in 0..nf {
            let a = w * fv[i];
            for j in 0..ng {
                out[i * ng + j] += a * gv[j];
            }
        }
    }
}

impl Section {
    /// Euler–Bernoulli section: `kb` = ∫EI φ''φ''ᵀ from the link integrals.
    pub fn euler(na: usize, phi: &ShapeSet, kb: &[f64], p: SectionParams) -> Self {
        let nb = phi.count();
        let ne = na + nb;
        let l = phi.length();
        let mut rot_l = vec![0.0; ne];
        phi.eval(l, 1, &mut rot_l[na..]);
        let rotary = p.rho_i.map(|rho_i| {
            let quad = Quadrature::for_wavenumber(l, phi.max_wavenumber());
            let mut g = vec![0.0; nb * nb];
            gram(&quad, phi, 1, phi, 1, &mut g);
            symmetrize(&mut g, nb);
            let mut r1 = vec![0.0; ne];
            // ∫φ' = φ(L) − φ(0) = φ(L) (φ(0) = 0).
            phi.eval(l, 0, &mut r1[na..]);
            r1.iter_mut().for_each(|v| *v *= rho_i);
            let mut rm = vec![0.0; ne * ne];
            for i in 0..nb {
                for j in 0..nb {
                    rm[(na + i) * ne + na + j] = rho_i * g[i * nb + j];
                }
            }
            Rotary {
                j0: rho_i * l,
                r1,
                rm,
            }
        });
        let dbc = p.kelvin_voigt.map_or_else(Vec::new, |gamma| {
            kb.iter().map(|k| k * gamma / p.ei).collect()
        });
        Section {
            kind: SectionKind::Euler,
            nc: 0,
            rot_l,
            rotary,
            kbc: kb.to_vec(),
            dbc,
            psi_shapes: None,
            condensation: None,
            blocks: None,
        }
    }

    /// Timoshenko section on the shape pair (φ for v, χ for ψ). `condense` selects the massless
    /// ψ model (requires `p.rho_i == None`).
    pub fn timoshenko(
        na: usize,
        phi: &ShapeSet,
        chi: &ShapeSet,
        p: SectionParams,
        kappa_ga: f64,
        condense: bool,
    ) -> Result<Self, &'static str> {
        let (nb, nc) = (phi.count(), chi.count());
        let l = phi.length();
        let quad = Quadrature::for_wavenumber(l, phi.max_wavenumber().max(chi.max_wavenumber()));
        let mut a_vv = vec![0.0; nb * nb];
        let mut a_vc = vec![0.0; nb * nc];
        let mut a_cc = vec![0.0; nc * nc];
        let mut a1_cc = vec![0.0; nc * nc];
        gram(&quad, phi, 1, phi, 1, &mut a_vv);
        gram(&quad, phi, 1, chi, 0, &mut a_vc);
        gram(&quad, chi, 0, chi, 0, &mut a_cc);
        gram(&quad, chi, 1, chi, 1, &mut a1_cc);
        symmetrize(&mut a_vv, nb);
        symmetrize(&mut a_cc, nc);
        symmetrize(&mut a1_cc, nc);
        let mut chi_l = vec![0.0; nc];
        chi.eval(l, 0, &mut chi_l);
        let kcc: Vec<f64> = a1_cc
            .iter()
            .zip(&a_cc)
            .map(|(k1, k0)| p.ei * k1 + kappa_ga * k0)
            .collect();
        let gamma = p.kelvin_voigt;
        if condense {
            // T = −K_cc⁻¹K_cb = κGA K_cc⁻¹ A_vcᵀ, column by column (one column per b_j).
            let mut t = vec![0.0; nc * nb];
            let mut col = vec![0.0; nc];
            let mut fac = vec![0.0; nc * nc];
            for j in 0..nb {
                for k in 0..nc {
                    col[k] = kappa_ga * a_vc[j * nc + k];
                }
                fac.copy_from_slice(&kcc);
                cholesky_solve(&mut fac, nc, &mut col)
                    .map_err(|_| "Timoshenko rotation stiffness K_cc is not positive definite")?;
                for k in 0..nc {
                    t[k * nb + j] = col[k];
                }
            }
            // K_eff = κGA A_vv + K_cbᵀ T = κGA (A_vv − A_vc T).
            let mut kbc = vec![0.0; nb * nb];
            for i in 0..nb {
                for j in 0..nb {
                    let mut s = a_vv[i * nb + j];
                    for k in 0..nc {
                        s -= a_vc[i * nc + k] * t[k * nb + j];
                    }
                    kbc[i * nb + j] = kappa_ga * s;
                }
            }
            symmetrize(&mut kbc, nb);
            // Tᵀ (γ A1_cc) T.
            let dbc = gamma.map_or_else(Vec::new, |g| {
                congruence(|k, j| t[k * nb + j], &a1_cc, nc, nb, g)
            });
            let mut rot_l = vec![0.0; na + nb];
            for j in 0..nb {
                rot_l[na + j] = (0..nc).map(|k| chi_l[k] * t[k * nb + j]).sum();
            }
            return Ok(Section {
                kind: SectionKind::TimoshenkoCondensed,
                nc: 0,
                rot_l,
                rotary: None,
                kbc,
                dbc,
                psi_shapes: Some(chi.clone()),
                condensation: Some(t),
                blocks: Some(CondensedBlocks {
                    kbb: a_vv.iter().map(|v| kappa_ga * v).collect(),
                    kbc: a_vc.iter().map(|v| -kappa_ga * v).collect(),
                    kcc,
                    dcc: gamma.map_or_else(Vec::new, |g| a1_cc.iter().map(|v| g * v).collect()),
                    chi_l,
                }),
            });
        }
        let n = nb + nc;
        let mut kbc = vec![0.0; n * n];
        for i in 0..nb {
            for j in 0..nb {
                kbc[i * n + j] = kappa_ga * a_vv[i * nb + j];
            }
            for k in 0..nc {
                let v = -kappa_ga * a_vc[i * nc + k];
                kbc[i * n + nb + k] = v;
                kbc[(nb + k) * n + i] = v;
            }
        }
        for k in 0..nc {
            for m in 0..nc {
                kbc[(nb + k) * n + nb + m] = kcc[k * nc + m];
            }
        }
        let dbc = gamma.map_or_else(Vec::new, |g| {
            let mut d = vec![0.0; n * n];
            for k in 0..nc {
                for m in 0..nc {
                    d[(nb + k) * n + nb + m] = g * a1_cc[k * nc + m];
                }
            }
            d
        });
        let ne = na + n;
        let mut rot_l = vec![0.0; ne];
        rot_l[na + nb..].copy_from_slice(&chi_l);
        let rotary = p.rho_i.map(|rho_i| {
            let mut r1 = vec![0.0; ne];
            let mut rm = vec![0.0; ne * ne];
            let mut v = vec![0.0; nc];
            for (&x, &w) in quad.x.iter().zip(&quad.w) {
                chi.eval(x, 0, &mut v);
                for k in 0..nc {
                    r1[na + nb + k] += w * rho_i * v[k];
                }
            }
            for k in 0..nc {
                for m in 0..nc {
                    rm[(na + nb + k) * ne + na + nb + m] = rho_i * a_cc[k * nc + m];
                }
            }
            Rotary {
                j0: rho_i * l,
                r1,
                rm,
            }
        });
        Ok(Section {
            kind: SectionKind::Timoshenko,
            nc,
            rot_l,
            rotary,
            kbc,
            dbc,
            psi_shapes: Some(chi.clone()),
            condensation: None,
            blocks: None,
        })
    }

    /// Size of the bending block [b, c].
    pub fn nbc(&self, nb: usize) -> usize {
        nb + self.nc
    }
}
