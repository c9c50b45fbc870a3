//! References for the 3-D link with an offset payload (seed 002, `docs/single-link-3d.md`).
//!
//! All derived here from the model's energies, linearized about the undeformed rod at a constant
//! base rate Ω (0 at rest); A = πR², I = πR⁴/4, J = πR⁴/2, payload mass m at offset c beyond the
//! tip with inertia I_p = \[\[I₁, I₄, I₅\], \[I₄, I₂, I₆\], \[I₅, I₆, I₃\]\] about its centre of
//! mass in the tip axes.
//!
//! # Bending in one plane ([`BendingPlane`])
//! With a diagonal I_p (the products I₅ couple v with φ, I₆ v with w, I₄ w with φ) and c on the
//! rod axis, each plane is a Rayleigh beam (the sections' rotary inertia ρI is kept, as the
//! model's rod kinetic energy has it) carrying a rigid body. For a mode W(x)·cos ωt the
//! Lagrangian is
//!
//! `½∫(a W² + b W′² − EI W″²) dx + ½P (W_L + cW′_L)² + ½Q W′_L²` (+ the base, below), with
//!
//! * a = ρA(ω² + σΩ²): σ = 1 in the turning plane (v: ½Ω²ρA v² from |e_z × r|²), 0 for w;
//! * b(x) = ω²ρI − T(x) + κΩ²: tension T(x) = ½ρAΩ²(L² − x²) + mΩ²(L + c) from the
//!   foreshortening s in ½Ω²ρA(x − s)² and ½mΩ²(L + c − s_L)²; κ = ρ(J − I) for w (the tilted
//!   sections' ½Ω² e_zᵀRρdiag(J, I, I)Rᵀe_z), 0 for v (a rotation about the spin axis);
//! * P = m(ω² + σΩ²): the payload's translation of its centre, W_L + cW′_L;
//! * Q = ω²I_c − mΩ²(L + c)c + Ω²ΔI: I_c = I₃ (v) or I₂ (w) about the centre of mass, the
//!   foreshortening of the offset −½c W′_L², and ΔI = I₁ − I₃ for w (0 for v).
//!
//! Euler–Lagrange: `EI W'''' + (b W′)′ − a W = 0`; free end:
//! `EI W‴ + b W′ + P(W + cW′) = 0`, `EI W″ = Pc(W + cW′) + Q W′`; root clamped (W = W′ = 0), or
//! for the turning plane of a free base at rest W(0) = 0 with the base angle θ = W′(0) (absolute
//! transverse motion xθ + v) and `EI W″(0) = (K − ω²I_B) W′(0)` (hub inertia I_B, joint spring
//! K). At Ω = 0, m = 0, ρI = 0 these are the cantilever, the tip-mass cantilever
//! ([`crate::analytic::beam`]) and the pinned–free beam (I_B = 0); with Ω and no payload the
//! rotating beam of [`crate::analytic::rotating`]; the tests check every limit.
//!
//! The mode shape is integrated from the root (two independent initial vectors, Dormand–Prince
//! at rtol 1e-12 in the scaled variables y_k = L^k W^(k)) and the 2×2 determinant of the free-end
//! conditions is bracketed on a grid of x = sqrt(ω/ω₀), ω₀ = sqrt(EI/ρAL⁴) (roots are simple and
//! at least ~2 apart in x beyond the first), then refined by Brent. The solutions grow like
//! e^{x}, so the determinant loses ~x/ln 10 digits: ~1e-9 relative at mode 4 (x ≈ 11), enough
//! for the first four modes of each plane.
//!
//! Neglected, each a relative frequency effect stated for the catalog rods: the Coriolis coupling
//! of u and v at Ω ≠ 0 (2Ω u̇ against axial modes 100× the bending ones: ~(Ω/ω_u)² < 1e-6) and
//! the gyroscopic w–φ coupling through ρJ and the payload (~(Ω/ω_φ)² < 1e-5).
//!
//! # Torsion and axial
//! `GJ φ″ = ρJ φ̈` with `GJ φ′(L) = ω²I₁ φ_L` (plus Ω²(I₂ − I₃)φ_L at a rate; only I₂ = I₃ is
//! supported there): ζ tan ζ = ρJL/I₁, ζ = ωL sqrt(ρJ/GJ). `EA u″ = ρA(ü − Ω²u)` with
//! `EA u′(L) = m(ω² + Ω²)u_L`: ζ tan ζ = ρAL/m for ω̃² = ω² + Ω². Both solved by
//! [`crate::analytic::beam::axial_tip_mass_frequencies_hz`] (same equation).
//!
//! # Statics
//! Linear sag of the clamped rod: self-weight q = ρAg, the payload's weight P = mg at the tip and
//! its offset moment M = mgc: `w_L = −(qL⁴/8 + PL³/3 + ML²/2)/EI`,
//! `w′_L = −(qL³/6 + PL²/2 + ML)/EI` ([`linear_sag`]).
//!
//! The seed's large-deflection formula (its §2, after Carrillo 2006):
//! `w̃′(x) = tan(x(2a − x)/(2b))`, b = EI/F, a = L − δ, δ the foreshortening ([`seed_sag`]).
//! The exact elastica of a tip-loaded cantilever has sin θ = X(2a − X)/(2b) at the horizontal
//! coordinate X (integrate EIκ = F(a − X) once), so the seed's tan(·) = tan θ is the elastica
//! only to first order in the argument: the formula is exact to O((FL²/EI)²) relative, against
//! the shooting solution of the elastica with tip load, payload offset and self-weight
//! ([`sag_elastica`]; the error table is in docs/single-link-3d.md).
//! δ is taken as the second-order foreshortening ½∫₀ᵃ w̃′² dx (the seed prints −½∫ w̃′², whose
//! sign would make a > L), with a + δ(a) = L solved by Brent.
//!
//! # Rigid limit
//! E, G → ∞: `(I_B + ρAL³/3 + ρIL + m(L + c)² + I₃) θ̈ = T_mot(t) − b_m θ̇` ([`RigidPayloadBase`]),
//! in closed form on each interval of constant torque.

use std::f64::consts::PI;

use data::scene::{PayloadLink, PrescribedMotion, TorqueLaw};
use serde::{Deserialize, Serialize};

use crate::analytic::beam::axial_tip_mass_frequencies_hz;
use crate::analytic::error::{AnalyticError, Result, finite, non_negative, positive};
use crate::analytic::numerics::ode::Dopri5;
use crate::analytic::numerics::quadrature::gauss_legendre;
use crate::analytic::numerics::roots::{RootOptions, brent, first_roots};
use crate::analytic::rigid::law_breakpoints;

/// The base rate Ω about which `modes` linearizes: 0 for a free or fixed base, the rate of a
/// `constant-rate` base. A spin-up has no constant reference rate.
pub fn reference_rate(p: &PayloadLink) -> Result<f64> {
    match &p.base.prescribed {
        None | Some(PrescribedMotion::Fixed) => Ok(0.0),
        Some(PrescribedMotion::ConstantRate { rate }) => finite("base rate", *rate),
        Some(PrescribedMotion::SpinUp { .. }) => Err(AnalyticError::Unsupported(
            "a spin-up base has no constant rate to linearize about".into(),
        )),
    }
}

/// The payload's inertia about its centre of mass, checked diagonal where a reference needs it.
fn require_no_products(p: &PayloadLink, which: &[(usize, usize)], plane: &str) -> Result<()> {
    let i = &p.payload.inertia;
    if which.iter().any(|&(r, c)| i[r][c] != 0.0) {
        return Err(AnalyticError::Unsupported(format!(
            "{plane}: the payload's products of inertia couple it to another field \
             (I4 couples w-phi, I5 v-phi, I6 v-w); set them to zero (an override) for this reference"
        )));
    }
    Ok(())
}

/// How the root of a bending plane is held.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PlaneRoot {
    /// W(0) = W′(0) = 0.
    Clamped,
    /// W(0) = 0, EI W″(0) = (K − ω² I_B) W′(0): a free base of inertia I_B with spring K.
    Hub { inertia: f64, stiffness: f64 },
}

/// One bending plane of the rod with its payload (equations in the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BendingPlane {
    pub ei: f64,
    pub rho_a: f64,
    /// Rotary inertia of the sections ρI (per length).
    pub rho_i: f64,
    pub length: f64,
    /// Constant base rate Ω.
    pub rate: f64,
    /// σ: 1 for the turning plane (centrifugal softening of the translation), 0 otherwise.
    pub softening: f64,
    /// κ: coefficient of ½Ω²W′² per length from the sections' tilt (ρ(J − I) for w).
    pub section_spin: f64,
    pub tip_mass: f64,
    pub offset: f64,
    /// Payload inertia about its centre of mass for rotations in this plane.
    pub tip_inertia: f64,
    /// ΔI: coefficient of ½Ω²W′_L² from the payload's tilt (I₁ − I₃ for w).
    pub tip_spin: f64,
    pub root: PlaneRoot,
}

impl BendingPlane {
    /// Bending in the turning plane (v, rotations about z, I₃).
    pub fn horizontal(p: &PayloadLink) -> Result<Self> {
        require_no_products(p, &[(0, 2), (1, 2)], "horizontal bending reference")?;
        let rate = reference_rate(p)?;
        let root = match &p.base.prescribed {
            Some(_) => PlaneRoot::Clamped,
            None => {
                if rate != 0.0 || p.base.initial_rate != 0.0 {
                    return Err(AnalyticError::Unsupported(
                        "a free base is linearized at rest only".into(),
                    ));
                }
                PlaneRoot::Hub {
                    inertia: p.base_inertia(),
                    stiffness: p.base.stiffness.unwrap_or(0.0),
                }
            }
        };
        Ok(Self::with(
            p,
            rate,
            1.0,
            0.0,
            p.payload.inertia[2][2],
            0.0,
            root,
        ))
    }

    /// Bending out of the turning plane (w, rotations about y, I₂). A free base does not move w
    /// at rest, so the root is clamped in every case.
    pub fn vertical(p: &PayloadLink) -> Result<Self> {
        require_no_products(p, &[(0, 1), (1, 2)], "vertical bending reference")?;
        let rate = reference_rate(p)?;
        let rho = p.density;
        let i = &p.payload.inertia;
        Ok(Self::with(
            p,
            rate,
            0.0,
            rho * (p.polar_moment() - p.second_moment()),
            i[1][1],
            i[0][0] - i[2][2],
            PlaneRoot::Clamped,
        ))
    }

    fn with(
        p: &PayloadLink,
        rate: f64,
        softening: f64,
        section_spin: f64,
        tip_inertia: f64,
        tip_spin: f64,
        root: PlaneRoot,
    ) -> Self {
        BendingPlane {
            ei: p.bending_stiffness(),
            rho_a: p.mass_per_length(),
            rho_i: p.density * p.second_moment(),
            length: p.length,
            rate,
            softening,
            section_spin,
            tip_mass: p.payload.mass,
            offset: p.payload.offset,
            tip_inertia,
            tip_spin,
            root,
        }
    }

    fn check(&self) -> Result<()> {
        positive("EI", self.ei)?;
        positive("rho A", self.rho_a)?;
        non_negative("rho I", self.rho_i)?;
        positive("L", self.length)?;
        finite("rate", self.rate)?;
        non_negative("tip mass", self.tip_mass)?;
        finite("offset", self.offset)?;
        non_negative("tip inertia", self.tip_inertia)?;
        finite("section spin", self.section_spin)?;
        finite("tip spin", self.tip_spin)?;
        if let PlaneRoot::Hub { inertia, stiffness } = self.root {
            non_negative("hub inertia", inertia)?;
            non_negative("joint stiffness", stiffness)?;
        }
        Ok(())
    }

    /// ω₀ = sqrt(EI/(ρA L⁴)): ω = x² ω₀ on the search grid.
    pub fn omega_scale(&self) -> f64 {
        (self.ei / (self.rho_a * self.length.powi(4))).sqrt()
    }

    /// The free-end determinant at circular frequency ω (zero at the natural frequencies).
    pub fn determinant(&self, omega: f64) -> Result<f64> {
        let (l, ei, om2, r2) = (self.length, self.ei, omega * omega, self.rate * self.rate);
        let a = self.rho_a * (om2 + self.softening * r2);
        let tension_tip = self.tip_mass * r2 * (l + self.offset);
        let b = |x: f64| {
            om2 * self.rho_i - (0.5 * self.rho_a * r2 * (l * l - x * x) + tension_tip)
                + self.section_spin * r2
        };
        let db = |x: f64| self.rho_a * r2 * x;
        let ca = l.powi(4) * a / ei;
        let mut f = |xi: f64, y: &[f64], d: &mut [f64]| {
            let x = xi * l;
            d[0] = y[1];
            d[1] = y[2];
            d[2] = y[3];
            d[3] = ca * y[0] - l.powi(3) * db(x) / ei * y[1] - l * l * b(x) / ei * y[2];
        };
        let starts: [[f64; 4]; 2] = match self.root {
            PlaneRoot::Clamped => [[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
            PlaneRoot::Hub { inertia, stiffness } => [
                [0.0, 1.0, (stiffness - om2 * inertia) * l / ei, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ],
        };
        let p = self.tip_mass * (om2 + self.softening * r2);
        let q = om2 * self.tip_inertia - self.tip_mass * r2 * (l + self.offset) * self.offset
            + r2 * self.tip_spin;
        let gamma = self.offset / l;
        let mut res = [[0.0; 2]; 2];
        for (k, y0) in starts.iter().enumerate() {
            let mut y = *y0;
            let mut xi = 0.0;
            let mut ode = Dopri5::new(4, 1e-12, 1e-14);
            ode.advance(&mut f, &mut xi, &mut y, 1.0)?;
            let centre = y[0] + gamma * y[1];
            res[k] = [
                y[3] + l * l * b(l) / ei * y[1] + p * l.powi(3) / ei * centre,
                y[2] - p * self.offset * l * l / ei * centre - q * l / ei * y[1],
            ];
        }
        let det = res[0][0] * res[1][1] - res[1][0] * res[0][1];
        if det.is_finite() {
            Ok(det)
        } else {
            Err(AnalyticError::NonFinite {
                what: "bending-plane determinant",
                x: omega,
                value: det,
            })
        }
    }

    /// The first `n` natural circular frequencies (rad/time) of the plane, above 0 (a free
    /// base's rigid rotation at ω = 0 is not counted).
    pub fn frequencies(&self, n: usize) -> Result<Vec<f64>> {
        self.check()?;
        let w0 = self.omega_scale();
        let mut failure: Option<AnalyticError> = None;
        // Grid in x = sqrt(ω/ω₀): roots lie ≳ 2 apart beyond the first (≈ π for a clamped
        // beam), and the first is above 0.05 for any tip body below 10⁵ rod masses
        // (Dunkerley: x₁⁴ ≥ 3/(m/ρAL + …)); the step 0.01 cannot hold two roots.
        let limit = (n as f64 + 2.0) * PI + 2.0 * (self.rate.abs() / w0).sqrt() + 10.0;
        let roots = first_roots(
            |x| match self.determinant(x * x * w0) {
                Ok(d) => d,
                Err(e) => {
                    failure = Some(e);
                    f64::NAN
                }
            },
            0.02,
            0.01,
            limit,
            n,
            "bending plane with payload",
            RootOptions {
                rel_tol: 1e-13,
                ..RootOptions::default()
            },
        );
        if let Some(e) = failure {
            return Err(e);
        }
        Ok(roots?.into_iter().map(|x| x * x * w0).collect())
    }

    /// The first `n` natural frequencies in Hz.
    pub fn frequencies_hz(&self, n: usize) -> Result<Vec<f64>> {
        Ok(self
            .frequencies(n)?
            .into_iter()
            .map(|w| w / (2.0 * PI))
            .collect())
    }
}

/// Torsion frequencies \[Hz\]: ζ tan ζ = ρJL/I₁ (module docs).
pub fn torsion_frequencies_hz(p: &PayloadLink, n: usize) -> Result<Vec<f64>> {
    require_no_products(p, &[(0, 1), (0, 2)], "torsion reference")?;
    let rate = reference_rate(p)?;
    let i = &p.payload.inertia;
    if rate != 0.0 && i[1][1] != i[2][2] {
        return Err(AnalyticError::Unsupported(
            "torsion at a constant rate with I2 != I3 (the payload's centrifugal twisting \
             moment) is not modelled"
                .into(),
        ));
    }
    axial_tip_mass_frequencies_hz(
        p.torsional_stiffness(),
        p.density * p.polar_moment(),
        p.length,
        i[0][0],
        n,
    )
}

/// Axial frequencies \[Hz\] with the payload's mass at the tip, softened by the rate:
/// ω² = ω̃² − Ω² with ω̃ from ζ tan ζ = ρAL/m (module docs).
pub fn axial_frequencies_hz(p: &PayloadLink, n: usize) -> Result<Vec<f64>> {
    let rate = reference_rate(p)?;
    let still = axial_tip_mass_frequencies_hz(
        p.axial_stiffness(),
        p.mass_per_length(),
        p.length,
        p.payload.mass,
        n,
    )?;
    still
        .into_iter()
        .map(|f| {
            let w2 = (2.0 * PI * f).powi(2) - rate * rate;
            if w2 > 0.0 {
                Ok(w2.sqrt() / (2.0 * PI))
            } else {
                Err(AnalyticError::InvalidParameter {
                    name: "base rate",
                    value: rate,
                    why: "above an axial frequency: the rod flies apart",
                })
            }
        })
        .collect()
}

/// Linear static sag of the clamped rod under gravity: (w_L, w′_L), negative downwards.
pub fn linear_sag(p: &PayloadLink) -> Result<(f64, f64)> {
    let g = p.gravity.unwrap_or(0.0);
    non_negative("gravity", g)?;
    let (l, ei) = (p.length, p.bending_stiffness());
    positive("EI", ei)?;
    let q = p.mass_per_length() * g;
    let f = p.payload.mass * g;
    let m = f * p.payload.offset;
    Ok((
        -(q * l.powi(4) / 8.0 + f * l.powi(3) / 3.0 + m * l * l / 2.0) / ei,
        -(q * l.powi(3) / 6.0 + f * l * l / 2.0 + m * l) / ei,
    ))
}

/// The seed's large-deflection sag of a cantilever with a tip load only, in units of L, for
/// α = FL²/EI: (a/L, sag/L) with sag = ∫₀ᵃ tan(x(2a − x)/(2b)) dx, a + ½∫₀ᵃ w̃′² = L.
///
/// The argument α ξ(2â − ξ)/2 peaks at ξ = â; as α â²/2 → π/2 the foreshortening integral
/// diverges, so a + δ(a) = L always has a root below that point (Brent on \[0, â_max)). Near the
/// peak the integrand is sharp: the quadrature is composite Gauss–Legendre on panels graded
/// geometrically toward ξ = â (ratio 0.7, down to 1e-7 â).
pub fn seed_sag(alpha: f64) -> Result<(f64, f64)> {
    non_negative("alpha = F L^2 / EI", alpha)?;
    if alpha == 0.0 {
        return Ok((1.0, 0.0));
    }
    let slope = |ah: f64, xi: f64| (alpha * xi * (2.0 * ah - xi) / 2.0).tan();
    let integrate = |ah: f64, g: &dyn Fn(f64) -> f64| {
        let mut edges = vec![0.0];
        let mut gap = 0.5 * ah;
        while gap > 1e-7 * ah {
            edges.push(ah - gap);
            gap *= 0.7;
        }
        edges.push(ah);
        edges
            .windows(2)
            .map(|w| gauss_legendre(w[0], w[1], 16, g))
            .sum::<f64>()
    };
    let closure = |ah: f64| ah + 0.5 * integrate(ah, &|xi| slope(ah, xi).powi(2)) - 1.0;
    let a_max = (PI / alpha).sqrt();
    let hi = if a_max <= 1.0 {
        a_max * (1.0 - 1e-6)
    } else {
        1.0
    };
    let ah = brent(closure, 0.0, hi, RootOptions::default())?;
    Ok((ah, integrate(ah, &|xi| slope(ah, xi))))
}

/// Large-deflection sag of a cantilever (inextensible, unshearable) under a dead tip load F at
/// offset c beyond the tip along the tip tangent and its own weight q, in units of L.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SagElastica {
    /// Downward tip deflection / L.
    pub tip_sag: f64,
    /// Horizontal tip position / L.
    pub tip_reach: f64,
    /// Tip rotation (rad, downwards positive).
    pub tip_rotation: f64,
}

/// Elastica with α = FL²/EI (tip load), β = qL³/EI (self-weight), γ = c/L (load offset).
///
/// With θ the downward section angle and s the arc length in units of L, moment equilibrium of
/// the part beyond s, EIθ′ = F(X_C − X) + ∫ₛ q(X(σ) − X(s))dσ, differentiates to
/// `θ″ = −(α + β(1 − s)) cos θ`, θ(0) = 0, and at the tip `θ′(1) = αγ cos θ(1)` (the offset
/// load's arm). Shooting on κ₀ = θ′(0) ∈ \[0, α(1 + γ) + β/2\]: at 0 the residual θ′(1) − αγ cos θ(1)
/// is < 0; at the upper end, where every moment arm is its largest, it is ≥ 0.
pub fn sag_elastica(alpha: f64, beta: f64, gamma: f64) -> Result<SagElastica> {
    non_negative("alpha", alpha)?;
    non_negative("beta", beta)?;
    non_negative("gamma", gamma)?;
    if alpha == 0.0 && beta == 0.0 {
        return Ok(SagElastica {
            tip_sag: 0.0,
            tip_reach: 1.0,
            tip_rotation: 0.0,
        });
    }
    let shoot = |k0: f64| -> Result<[f64; 4]> {
        let mut f = |s: f64, y: &[f64], d: &mut [f64]| {
            d[0] = y[1];
            d[1] = -(alpha + beta * (1.0 - s)) * y[0].cos();
            d[2] = y[0].cos();
            d[3] = y[0].sin();
        };
        let mut y = [0.0, k0, 0.0, 0.0];
        let mut s = 0.0;
        let mut ode = Dopri5::new(4, 1e-13, 1e-15);
        ode.advance(&mut f, &mut s, &mut y, 1.0)?;
        Ok(y)
    };
    let mut failure: Option<AnalyticError> = None;
    let residual = |k0: f64| match shoot(k0) {
        Ok(y) => y[1] - alpha * gamma * y[0].cos(),
        Err(e) => {
            failure = Some(e);
            f64::NAN
        }
    };
    let k_max = alpha * (1.0 + gamma) + 0.5 * beta;
    let k0 = brent(residual, 0.0, k_max * (1.0 + 1e-12), RootOptions::default());
    if let Some(e) = failure {
        return Err(e);
    }
    let y = shoot(k0?)?;
    Ok(SagElastica {
        tip_sag: y[3],
        tip_reach: y[2],
        tip_rotation: y[0],
    })
}

/// The scene's sag parameters (α = mgL²/EI, β = ρAgL³/EI, γ = c/L).
pub fn sag_parameters(p: &PayloadLink) -> (f64, f64, f64) {
    let g = p.gravity.unwrap_or(0.0);
    let (l, ei) = (p.length, p.bending_stiffness());
    (
        p.payload.mass * g * l * l / ei,
        p.mass_per_length() * g * l.powi(3) / ei,
        p.payload.offset / l,
    )
}

/// Rigid limit of the turning base: J θ̈ = T_mot(t) − b_m θ̇ with
/// J = I_B + ρAL³/3 + ρIL + m(L + c)² + I₃.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigidPayloadBase {
    pub inertia: f64,
    pub damping: f64,
    pub angle0: f64,
    pub rate0: f64,
    pub torque: Option<TorqueLaw>,
}

impl RigidPayloadBase {
    pub fn from_link(p: &PayloadLink) -> Result<Self> {
        if p.base.prescribed.is_some() {
            return Err(AnalyticError::Unsupported(
                "the rigid-base reference needs a torque-driven (free) base".into(),
            ));
        }
        if p.base.stiffness.is_some_and(|k| k != 0.0) {
            return Err(AnalyticError::Unsupported(
                "the rigid-base reference has no joint spring".into(),
            ));
        }
        let (l, c, m) = (p.length, p.payload.offset, p.payload.mass);
        let inertia = p.base_inertia()
            + p.mass_per_length() * l.powi(3) / 3.0
            + p.density * p.second_moment() * l
            + m * (l + c).powi(2)
            + p.payload.inertia[2][2];
        positive("rigid inertia", inertia)?;
        Ok(RigidPayloadBase {
            inertia,
            damping: non_negative("motor friction", p.motor_friction())?,
            angle0: p.base.initial_angle,
            rate0: p.base.initial_rate,
            torque: p.base.torque.clone(),
        })
    }

    /// (θ, θ̇) at time t ≥ 0: on an interval of constant torque τ, with λ = b/J,
    /// θ̇ = τ/b + (θ̇ᵢ − τ/b)e^{−λs}, θ = θᵢ + (τ/b)s + (θ̇ᵢ − τ/b)(1 − e^{−λs})/λ
    /// (b = 0: θ̇ = θ̇ᵢ + (τ/J)s, θ = θᵢ + θ̇ᵢs + ½(τ/J)s²).
    pub fn state(&self, t: f64) -> Result<(f64, f64)> {
        finite("t", t)?;
        if t < 0.0 {
            return Err(AnalyticError::InvalidParameter {
                name: "t",
                value: t,
                why: "must be >= 0",
            });
        }
        let (j, b) = (self.inertia, self.damping);
        let mut bounds = law_breakpoints(self.torque.as_ref(), t);
        bounds.push(t);
        let (mut t0, mut th, mut om) = (0.0, self.angle0, self.rate0);
        for t1 in bounds {
            // The law is constant on (t0, t1): sample it at the midpoint.
            let tau = self
                .torque
                .as_ref()
                .map_or(0.0, |l| l.torque(0.5 * (t0 + t1)));
            let s = t1 - t0;
            if b > 0.0 {
                let lam = b / j;
                let w_inf = tau / b;
                // (1 − e^{−λs})/λ without cancellation for small λs.
                let decay = -(-lam * s).exp_m1() / lam;
                th += w_inf * s + (om - w_inf) * decay;
                om = w_inf + (om - w_inf) * (-lam * s).exp();
            } else {
                th += om * s + 0.5 * tau / j * s * s;
                om += tau / j * s;
            }
            t0 = t1;
        }
        Ok((th, om))
    }
}

#[cfg(test)]
mod tests;
