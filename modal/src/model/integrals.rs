//! Spatial integrals of one link, computed once by Gauss quadrature at set-up.
//!
//! With transverse shapes φₖ, axial shapes ψₖ, mass per length ρA (uniform), bending stiffness
//! EI and axial stiffness EA, and the foreshortening kernel S(x) = ∫₀ˣ φ'φ'ᵀ:
//!
//! | symbol | integral |
//! | --- | --- |
//! | m, c₀, c₂ | ∫ρA, ∫ρA x, ∫ρA x² |
//! | Φ₁, Φₓ | ∫ρA φ, ∫ρA x φ |
//! | M_φ, K_b | ∫ρA φφᵀ, ∫EI φ''φ''ᵀ |
//! | S₁ | ∫ρA S(x) dx = ∫ φ'φ'ᵀ ρA (L − x) dx |
//! | Sₓ | ∫ρA x S(x) dx = ∫ φ'φ'ᵀ ρA (L² − x²)/2 dx (centrifugal-load weighted) |
//! | S_L | S(L) = ∫ φ'φ'ᵀ |
//! | Ψ₁, Ψₓ, M_ψ, K_a | ∫ρA ψ, ∫ρA x ψ, ∫ρA ψψᵀ, ∫EA ψ'ψ'ᵀ |
//! | C | ∫ρA ψ φᵀ |
//! | Q, R, P (foreshortening) | ∫ρA S⊗S, ∫ρA φ⊗S, ∫ρA ψ⊗S (the last with the axial field) |
//!
//! (S₁ and Sₓ follow from ∫₀ᴸ f(x) S(x) dx = ∫₀ᴸ φ'φ'ᵀ(ξ) ∫_ξᴸ f dx dξ, integration by parts.)

use crate::basis::ShapeSet;
use crate::basis::quadrature::Quadrature;

#[derive(Debug, Clone)]
pub struct LinkIntegrals {
    pub length: f64,
    pub m: f64,
    pub c0: f64,
    pub c2: f64,
    pub nb: usize,
    pub phi1: Vec<f64>,
    pub phix: Vec<f64>,
    pub mphi: Vec<f64>,
    pub kb: Vec<f64>,
    /// Foreshortening integrals (empty when foreshortening is off).
    pub s1: Vec<f64>,
    pub sx: Vec<f64>,
    pub sl: Vec<f64>,
    /// Exact-inextensible kinetic terms (foreshortening only): Q_ijkl = ∫ρA S_ij S_kl (n⁴) and
    /// R_mij = ∫ρA φ_m S_ij (n³), with S(x) = ∫₀ˣ φ'φ'ᵀ at the quadrature nodes.
    pub q4: Vec<f64>,
    pub r3: Vec<f64>,
    pub phi_l: Vec<f64>,
    pub dphi_l: Vec<f64>,
    pub na: usize,
    pub psi1: Vec<f64>,
    pub psix: Vec<f64>,
    pub mpsi: Vec<f64>,
    pub ka: Vec<f64>,
    /// na × nb, row-major.
    pub c: Vec<f64>,
    pub psi_l: Vec<f64>,
    /// P_kij = ∫ρA ψ_k S_ij (na × nb × nb; axial field with foreshortening): the kinetic
    /// coupling of the stretch u = ψᵀa with the foreshortening s = ½bᵀS b.
    pub p3: Vec<f64>,
}

impl LinkIntegrals {
    pub fn new(
        length: f64,
        rho_a: f64,
        ei: f64,
        ea: f64,
        transverse: &ShapeSet,
        axial: Option<&ShapeSet>,
        foreshortening: bool,
    ) -> Self {
        let nb = transverse.count();
        let na = axial.map_or(0, |a| a.count());
        let beta_max = transverse
            .max_wavenumber()
            .max(axial.map_or(0.0, |a| a.max_wavenumber()));
        let quad = Quadrature::for_wavenumber(length, beta_max);
        let l = length;
        let mut s = LinkIntegrals {
            length,
            m: rho_a * l,
            c0: rho_a * l * l / 2.0,
            c2: rho_a * l * l * l / 3.0,
            nb,
            phi1: vec![0.0; nb],
            phix: vec![0.0; nb],
            mphi: vec![0.0; nb * nb],
            kb: vec![0.0; nb * nb],
            s1: if foreshortening {
                vec![0.0; nb * nb]
            } else {
                vec![]
            },
            sx: if foreshortening {
                vec![0.0; nb * nb]
            } else {
                vec![]
            },
            sl: if foreshortening {
                vec![0.0; nb * nb]
            } else {
                vec![]
            },
            q4: vec![],
            r3: vec![],
            phi_l: vec![0.0; nb],
            dphi_l: vec![0.0; nb],
            na,
            psi1: vec![0.0; na],
            psix: vec![0.0; na],
            mpsi: vec![0.0; na * na],
            ka: vec![0.0; na * na],
            c: vec![0.0; na * nb],
            psi_l: vec![0.0; na],
            p3: vec![],
        };
        let (mut p, mut dp, mut ddp) = (vec![0.0; nb], vec![0.0; nb], vec![0.0; nb]);
        let (mut u, mut du) = (vec![0.0; na], vec![0.0; na]);
        for (&x, &w) in quad.x.iter().zip(&quad.w) {
            transverse.eval(x, 0, &mut p);
            transverse.eval(x, 1, &mut dp);
            transverse.eval(x, 2, &mut ddp);
            for i in 0..nb {
                s.phi1[i] += w * rho_a * p[i];
                s.phix[i] += w * rho_a * x * p[i];
                for j in 0..nb {
                    s.mphi[i * nb + j] += w * rho_a * p[i] * p[j];
                    s.kb[i * nb + j] += w * ei * ddp[i] * ddp[j];
                    if foreshortening {
                        let g = w * dp[i] * dp[j];
                        s.s1[i * nb + j] += g * rho_a * (l - x);
                        s.sx[i * nb + j] += g * rho_a * 0.5 * (l * l - x * x);
                        s.sl[i * nb + j] += g;
                    }
                }
            }
            if let Some(ax) = axial {
                ax.eval(x, 0, &mut u);
                ax.eval(x, 1, &mut du);
                for i in 0..na {
                    s.psi1[i] += w * rho_a * u[i];
                    s.psix[i] += w * rho_a * x * u[i];
                    for j in 0..na {
                        s.mpsi[i * na + j] += w * rho_a * u[i] * u[j];
                        s.ka[i * na + j] += w * ea * du[i] * du[j];
                    }
                    for j in 0..nb {
                        s.c[i * nb + j] += w * rho_a * u[i] * p[j];
                    }
                }
            }
        }
        transverse.eval(l, 0, &mut s.phi_l);
        transverse.eval(l, 1, &mut s.dphi_l);
        if let Some(ax) = axial {
            ax.eval(l, 0, &mut s.psi_l);
        }
        if foreshortening {
            let (q4, r3, p3) = foreshortening_tensors(length, rho_a, transverse, axial, &quad);
            s.q4 = q4;
            s.r3 = r3;
            s.p3 = p3;
        }
        // Exact symmetry (the quadrature sums are symmetric up to round-off order of addition).
        for mat in [&mut s.mphi, &mut s.kb, &mut s.s1, &mut s.sx, &mut s.sl] {
            symmetrize(mat, nb);
        }
        for mat in [&mut s.mpsi, &mut s.ka] {
            symmetrize(mat, na);
        }
        s
    }
}

fn symmetrize(m: &mut [f64], n: usize) {
    if m.len() != n * n {
        return;
    }
    for i in 0..n {
        for j in 0..i {
            let v = 0.5 * (m[i * n + j] + m[j * n + i]);
            m[i * n + j] = v;
            m[j * n + i] = v;
        }
    }
}

/// Q_ijkl = ∫ρA S_ij S_kl, R_mij = ∫ρA φ_m S_ij and, with an axial field, P_kij = ∫ρA ψ_k S_ij
/// on the rule `quad` (composite Gauss with equal panels). S at the nodes is accumulated panel by panel; inside a panel ∫_a^x φ'φ'ᵀ uses
/// a 10-point Gauss rule on [a, x] (panels are a quarter wavelength or less).
fn foreshortening_tensors(
    length: f64,
    rho_a: f64,
    shapes: &ShapeSet,
    axial: Option<&ShapeSet>,
    quad: &Quadrature,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = shapes.count();
    let na = axial.map_or(0, |a| a.count());
    let nq = quad.x.len();
    let points = 10;
    let panels = nq / points;
    let h = length / panels as f64;
    let (gx, gw) = crate::basis::quadrature::gauss_legendre(points);
    let mut s_acc = vec![0.0; n * n];
    let mut s_nodes = vec![0.0; nq * n * n];
    let mut d = vec![0.0; n];
    let mut add = |a: f64, b: f64, target: &mut [f64]| {
        for (xi, wi) in gx.iter().zip(&gw) {
            let x = a + 0.5 * (b - a) * (xi + 1.0);
            let w = 0.5 * (b - a) * wi;
            shapes.eval(x, 1, &mut d);
            for i in 0..n {
                for j in 0..n {
                    target[i * n + j] += w * d[i] * d[j];
                }
            }
        }
    };
    for p in 0..panels {
        let a = p as f64 * h;
        for k in 0..points {
            let q = p * points + k;
            let node = &mut s_nodes[q * n * n..(q + 1) * n * n];
            node.copy_from_slice(&s_acc);
            add(a, quad.x[q], node);
        }
        add(a, a + h, &mut s_acc);
    }
    let mut q4 = vec![0.0; n * n * n * n];
    let mut r3 = vec![0.0; n * n * n];
    let mut p3 = vec![0.0; na * n * n];
    let mut phi = vec![0.0; n];
    let mut psi = vec![0.0; na];
    let nn = n * n;
    for q in 0..nq {
        let w = quad.w[q] * rho_a;
        let sq = &s_nodes[q * nn..(q + 1) * nn];
        shapes.eval(quad.x[q], 0, &mut phi);
        for m in 0..n {
            for ij in 0..nn {
                r3[m * nn + ij] += w * phi[m] * sq[ij];
            }
        }
        if let Some(ax) = axial {
            ax.eval(quad.x[q], 0, &mut psi);
            for k in 0..na {
                for ij in 0..nn {
                    p3[k * nn + ij] += w * psi[k] * sq[ij];
                }
            }
        }
        // Unique (ij) ≤ (kl) pairs only; mirrored below.
        for ij in 0..nn {
            let a = w * sq[ij];
            if a == 0.0 {
                continue;
            }
            let row = &mut q4[ij * nn..(ij + 1) * nn];
            for kl in ij..nn {
                row[kl] += a * sq[kl];
            }
        }
    }
    for ij in 0..nn {
        for kl in 0..ij {
            q4[ij * nn + kl] = q4[kl * nn + ij];
        }
    }
    (q4, r3, p3)
}
