//! The 3-D flexible link with an offset payload (seed 002, `[payload_link]`) on the report's
//! station grid: the fields u (axial), v (horizontal), w (vertical) and φ (twist) at stations
//! 1…r (station 0 clamped), the base angle θ free or prescribed.
//!
//! ## Discrete Lagrangian (docs/single-link-3d.md, truncated at second order in the fields)
//! Stations x_i = ih, h = L/r; trapezoid-lumped masses m_i = ρAh (m_r = ρAh/2), torsional
//! inertias ρJh (ρJh/2 at the tip); segment slopes g_s = (f_{s+1} − f_s)/h; curvatures
//! κ_0 = 2f_1/h² (clamped fictitious station f_{−1} = f_1, weight ½), κ_i = Δ²f_i/h² inside, and
//! κ_r = 0 (the report's free-end fictitious station f_{r+1} = 2f_r − f_{r−1}); tip slope
//! f′_L = (3f_r − 4f_{r−1} + f_{r−2})/(2h); foreshortening s_i = ½Σ_{s<i} h(g_v² + g_w²).
//!
//! * V = ½Σ_s h(EA g_u² + GJ g_φ²) + ½Σ_i c_i h EI(κ_v,i² + κ_w,i²) (c_0 = ½),
//!   V_g = g(Σ m_i w_i + m_p(w_L + c w′_L)), Rayleigh D = the same sums with E → C_X, C_Y, C_Z,
//!   G → C_Φ on the rates.
//! * T = ½ ż ᵀ M(q) ż with ż = (θ̇, q̇): the field block M_ff is constant (lumped masses, the
//!   sections' rotary inertia ρI Σ_s h(ġ_v² + ġ_w²), the payload's m_p(u̇_L² + ẏ² + ż²) with
//!   y = v_L + c v′_L, z = w_L + c w′_L, and its b₁ᵀ I_p b₁, b₁ = (φ̇_L, −ẇ′_L, v̇′_L)); the
//!   coupling M_θf = c + Bq is affine (transport x_i v̇_i, Coriolis m(u v̇ − v u̇), the sections'
//!   ρ(I v̇′ + J w′φ̇), the payload's m_p((L + c + u_L)ẏ − y u̇_L) and its aᵀI_p b to second
//!   order, a = Rᵀe_z, b = Rᵀω); M_θθ = M₀ + 2gᵀq + qᵀHq (rigid inertias, the axial shift
//!   2x u, the foreshortening −2x s, u² + v², the sections' (J − I)w′², the payload's
//!   2(L+c)(u_L − s_L − ½c(v′_L² + w′_L²)) + u_L² + y² and aᵀI_p a).
//!
//! Lagrange's equations (M_θf = m, F the field forces):
//!   M_ff q̈ + m θ̈ = −θ̇(B − Bᵀ)q̇ + θ̇²(g + Hq) − Kq − Cq̇ + f_g,
//!   M_θθ θ̈ + m·q̈ = T_mot − b_m θ̇ − K_θ(θ − θ₀) − Ṁ_θθ θ̇ − (Bq̇)·q̇,  Ṁ_θθ = 2gᵀq̇ + 2q̇ᵀHq,
//! θ̈ eliminated by a Schur complement on the banded M_ff (stations interleaved: u, v, w, φ per
//! station, half-bandwidth ≤ 3 × fields). With a prescribed base the second line gives the
//! torque the base needs.
//!
//! ## Time stepping ([`system`], run by [`crate::runs::payload_link`])
//! The model is a [`crate::system::System`] ([`system::PayloadLinkSystem`]) stepped by the
//! report's central difference in its one-step velocity form ([`crate::method::velocity_form`],
//! kick–drift–kick, stable to 2/ω_max) inside the backend's driver, step τ = safety × min over
//! the carried fields of the Gershgorin bound of the lumped operator — axial h√(ρA/EA), bending
//! h²√(ρA/4EI), torsion h√(ρJ/GJ) inside the rod (rotary and payload inertia only lower ω_max,
//! so the lumped bound is safe). A forced `--dt` above it is refused naming the field.
//! **Kelvin–Voigt implicitly**: explicit, the strain-rate damping bounds the step by ≈ ρh²/(4C)
//! (axial, 2.5e-7 s for the catalog rod at 21 stations, 40× below the elastic bound), so the
//! closing kick takes the damping force at the step-end velocity,
//! (M_ff + ½τC) q̈_{j+1} = F(q_{j+1}, v_pred) − C v_{j+½}, one sparse factorization per step
//! length; the remaining velocity terms (Coriolis, motor friction) at the predicted velocity.
//! A requested two-step method is refused: explicit, the damping would need the damped bound,
//! and the scheme's computational mode grows under the Kelvin–Voigt and Coriolis forces.
//!
//! Not built: the centrifugal tension's share of the step bound (the base rates of the catalog
//! add < 1e-4 of ω_max²), the gyroscopic term in `modes` (K − Ω²H against M_ff, undamped).

mod build;
pub mod spd;
pub mod system;

use data::ledger_term;
use data::scene::{LinkField, PayloadLink, PrescribedMotion, TorqueLaw};
use data::{DofPlan, Scene};

use crate::error::FdmError;
use crate::linalg::dot;
use spd::Triplets;

/// Default stations (including the clamped root).
pub const DEFAULT_STATIONS: usize = 21;

/// A linear functional of the field coordinates: (index, coefficient).
pub type Lin = Vec<(usize, f64)>;

fn combine(parts: &[(&Lin, f64)]) -> Lin {
    let mut out = Lin::new();
    for (l, s) in parts {
        for &(i, c) in l.iter() {
            out.push((i, s * c));
        }
    }
    out
}

fn apply(l: &Lin, q: &[f64]) -> f64 {
    l.iter().map(|&(i, c)| c * q[i]).sum()
}

/// How the base angle moves.
#[derive(Debug, Clone)]
pub enum BaseDrive {
    Prescribed(PrescribedMotion),
    Free {
        law: Option<TorqueLaw>,
        stiffness: f64,
        damping: f64,
        set_point: f64,
    },
}

/// The discrete model of one `[payload_link]` scene.
#[derive(Debug, Clone)]
pub struct PayloadLinkModel {
    pub(crate) r: usize,
    pub(crate) h: f64,
    pub(crate) length: f64,
    pub(crate) offset: f64,
    pub(crate) fields: Vec<LinkField>,
    /// field coordinates (stations 1…r × carried fields)
    pub(crate) n: usize,
    pub(crate) drive: BaseDrive,
    pub(crate) theta0: f64,
    pub(crate) rate0: f64,
    pub(crate) mff: Triplets,
    pub(crate) c_theta: Vec<f64>,
    /// M_θf += B q: entries (f, g) with f the velocity index, g the position index
    pub(crate) b_theta: Triplets,
    pub(crate) m0: f64,
    pub(crate) g_theta: Vec<f64>,
    pub(crate) h_theta: Triplets,
    /// stiffness per carried field
    pub(crate) stiffness: Vec<(LinkField, Triplets)>,
    /// Kelvin–Voigt: (field, index into `stiffness`, C/modulus): C_f = ratio K_f
    pub(crate) damping: Vec<(LinkField, usize, f64)>,
    pub(crate) f_gravity: Option<Vec<f64>>,
    /// lumped diagonal (rod only) per coordinate, for the step bound
    pub(crate) lumped: Vec<f64>,
    pub(crate) field_stations: usize,
    // output functionals
    pub(crate) tip: [Lin; 4],
    pub(crate) slope_v: Lin,
    pub(crate) slope_w: Lin,
    pub(crate) seg_v: Vec<Lin>,
    pub(crate) seg_w: Vec<Lin>,
}

impl PayloadLinkModel {
    /// Number of field coordinates (stations 1…r × carried fields).
    pub fn field_coordinates(&self) -> usize {
        self.n
    }

    /// C = Σ_f (γ_f / modulus_f) K_f: the Kelvin–Voigt damping of the carried fields.
    pub fn damping_matrix(&self) -> Triplets {
        let mut c = Triplets::default();
        for &(_, k, ratio) in &self.damping {
            for &(i, j, v) in &self.stiffness[k].1.entries {
                c.entries.push((i, j, ratio * v));
            }
        }
        c
    }

    /// The matrix A = M_ff + ½τC of the step with implicit Kelvin–Voigt damping, as the scaled
    /// parts [`spd::SpdFactor::factor`] sums (`c` from [`Self::damping_matrix`]).
    pub fn step_matrix_parts<'a>(&'a self, c: &'a Triplets, tau: f64) -> [(&'a Triplets, f64); 2] {
        [(&self.mff, 1.0), (c, 0.5 * tau)]
    }

    /// The model of `p`, the payload link of `scene` (whose field stations it samples).
    pub fn from_payload_link(
        scene: &Scene,
        p: &PayloadLink,
        stations: Option<usize>,
    ) -> Result<Self, FdmError> {
        Self::build(
            p,
            stations,
            scene.simulation.field_stations.max(2),
            &scene.name,
        )
    }

    pub fn free_base(&self) -> bool {
        matches!(self.drive, BaseDrive::Free { .. })
    }

    /// The base's (θ, θ̇, θ̈) when prescribed.
    pub(crate) fn prescribed_at(&self, t: f64) -> Option<(f64, f64, f64)> {
        match &self.drive {
            BaseDrive::Prescribed(m) => {
                let (a, b, c) = m.kinematics(t);
                Some((self.theta0 + a, self.rate0 + b, c))
            }
            BaseDrive::Free { .. } => None,
        }
    }

    /// Coordinate index of field f at station i (1…r).
    pub fn index(&self, f: LinkField, i: usize) -> Option<usize> {
        let k = self.fields.iter().position(|x| *x == f)?;
        (1..=self.r)
            .contains(&i)
            .then(|| (i - 1) * self.fields.len() + k)
    }

    pub fn dof_plan(&self) -> DofPlan {
        let mut plan = DofPlan::default();
        if self.free_base() {
            plan.add("base angle θ", 1);
        }
        for &f in &self.fields {
            plan.add(
                format!(
                    "{} {} at stations 1…{} (root clamped)",
                    f.name(),
                    f.symbol(),
                    self.r
                ),
                self.r,
            );
        }
        plan.builds
            .push("payload (mass, offset, full inertia) at the tip".into());
        if self.fields.contains(&LinkField::Horizontal)
            || self.fields.contains(&LinkField::Vertical)
        {
            plan.builds.push("foreshortening".into());
        }
        if self.f_gravity.is_some() {
            plan.builds.push("gravity".into());
        }
        for (f, _, _) in &self.damping {
            plan.builds.push(format!("Kelvin–Voigt {}", f.name()));
        }
        plan
    }

    /// Mass coupling m = c + Bq into `out`.
    pub(crate) fn m_theta(&self, q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.c_theta);
        self.b_theta.mul_add(q, out);
    }

    /// M_θθ(q).
    pub(crate) fn m_thth(&self, q: &[f64]) -> f64 {
        self.m0 + 2.0 * dot(&self.g_theta, q) + self.h_theta.form(q, q)
    }

    /// Kinetic energy ½M_θθθ̇² + θ̇ m·q̇ + ½q̇ᵀM_ff q̇ (`m`: scratch).
    pub(crate) fn kinetic(&self, q: &[f64], v: &[f64], rate: f64, m: &mut [f64]) -> f64 {
        self.m_theta(q, m);
        0.5 * self.m_thth(q) * rate * rate + rate * dot(m, v) + 0.5 * self.mff.form(v, v)
    }

    pub(crate) fn strain(&self, q: &[f64]) -> f64 {
        self.stiffness.iter().map(|(_, k)| 0.5 * k.form(q, q)).sum()
    }

    pub(crate) fn gravity_energy(&self, q: &[f64]) -> f64 {
        self.f_gravity.as_ref().map_or(0.0, |f| -dot(f, q))
    }

    /// Field forces without the Kelvin–Voigt and the θ̈ terms:
    /// F0 = −θ̇(B − Bᵀ)q̇ + θ̇²(g + Hq) − Kq + f_g, written into `out`.
    pub(crate) fn field_forces(&self, q: &[f64], v: &[f64], rate: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        for (_, k) in &self.stiffness {
            k.mul_add(q, out);
        }
        out.iter_mut().for_each(|x| *x = -*x);
        if let Some(fg) = &self.f_gravity {
            for (o, f) in out.iter_mut().zip(fg) {
                *o += f;
            }
        }
        if rate != 0.0 {
            let w2 = rate * rate;
            for (o, g) in out.iter_mut().zip(&self.g_theta) {
                *o += w2 * g;
            }
            for &(i, j, c) in &self.h_theta.entries {
                out[i] += w2 * c * q[j];
            }
            // −θ̇ (B − Bᵀ) q̇
            for &(i, j, c) in &self.b_theta.entries {
                out[i] -= rate * c * v[j];
                out[j] += rate * c * v[i];
            }
        }
    }

    /// The θ equation's velocity terms Ṁ_θθ θ̇ + (Bq̇)·q̇.
    pub(crate) fn theta_velocity_terms(&self, q: &[f64], v: &[f64], rate: f64) -> f64 {
        let mdot = 2.0 * dot(&self.g_theta, v) + 2.0 * self.h_theta.form(v, q);
        mdot * rate + self.b_theta.form(v, v)
    }

    /// The linear static deflection under gravity, K q = f_g (zero without gravity).
    pub fn static_sag(&self) -> Result<Vec<f64>, FdmError> {
        let Some(fg) = &self.f_gravity else {
            return Ok(vec![0.0; self.n]);
        };
        let parts: Vec<(&Triplets, f64)> = self.stiffness.iter().map(|(_, k)| (k, 1.0)).collect();
        let mut chol = spd::SpdFactor::factor(self.n, &parts, "the stiffness matrix")?;
        let mut q = fg.clone();
        chol.solve_in_place(&mut q);
        Ok(q)
    }

    /// The step bound per carried field: (field, σ = min_k 2/√(Σ_j |K_kj| / m_k), station).
    pub fn field_bounds(&self) -> Vec<(LinkField, f64, usize)> {
        let mut out = Vec::new();
        for (f, k) in &self.stiffness {
            // entries of one coordinate pair can come from several cells: sum them first
            let dense_rows = {
                let mut acc = std::collections::BTreeMap::new();
                for &(i, j, c) in &k.entries {
                    *acc.entry((i, j)).or_insert(0.0) += c;
                }
                let mut rows = vec![0.0; self.n];
                for ((i, _), c) in acc {
                    rows[i] += f64::abs(c);
                }
                rows
            };
            let mut best = (f64::INFINITY, 0);
            for i in 1..=self.r {
                let Some(ix) = self.index(*f, i) else {
                    continue;
                };
                let w2 = dense_rows[ix] / self.lumped[ix];
                if w2 > 0.0 {
                    let s = 2.0 / w2.sqrt();
                    if s < best.0 {
                        best = (s, i);
                    }
                }
            }
            out.push((*f, best.0, best.1));
        }
        out
    }

    /// Ledger term names: stored, inputs, dissipation.
    pub fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
        if self.f_gravity.is_some() {
            stored.push(ledger_term::GRAVITY);
        }
        let mut inputs = Vec::new();
        let mut diss = Vec::new();
        match &self.drive {
            BaseDrive::Prescribed(_) => inputs.push(ledger_term::PRESCRIBED_MOTION),
            BaseDrive::Free {
                law,
                stiffness,
                damping,
                ..
            } => {
                if *stiffness != 0.0 {
                    stored.push(ledger_term::JOINT_SPRING);
                }
                if law.is_some() {
                    inputs.push(ledger_term::APPLIED_TORQUE);
                }
                if *damping != 0.0 {
                    diss.push(ledger_term::JOINT_DAMPER);
                }
            }
        }
        diss.extend(self.kv_names());
        (stored, inputs, diss)
    }

    /// The ledger's Kelvin–Voigt term names, in the order of `damping`.
    pub(crate) fn kv_names(&self) -> Vec<&'static str> {
        self.damping
            .iter()
            .map(|(f, _, _)| ledger_term::kelvin_voigt_of(*f))
            .collect()
    }
}

pub mod analysis;

#[cfg(test)]
mod tests;
