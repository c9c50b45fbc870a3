//! One flexible link in a floating (rotating) frame, on the same finite-difference grid as the
//! cantilever: `spin-up`, `spin-up-linear`, `single-link`.
//!
//! Discrete Lagrangian (stations 0…r, v₀ = 0, clamped ghost v₋₁ = v₁, free-end ghosts as in the
//! report's 5.32; trapezoid-lumped masses m_i, tip mass at station r). Station i sits at
//! (X_i, v_i) = (x_i − s_i, v_i) in the hub frame, s_i = ½h Σ_{seg<i} g_seg², g = Δv/h, when
//! `foreshortening` is on (s ≡ 0 for the linear model); the kinetic energy is the exact one of
//! these points,
//!
//! T = ½Jθ̇² + ½ Σ m_i [(ṡ_i + θ̇ v_i)² + (v̇_i + θ̇ X_i)²],   ṡ = B v̇,  B = ∂s/∂v,
//! V = ½ Σ_{i=0}^{r−1} c_i h EI κ_i²  (c₀ = ½, κ₀ = 2v₁/h², κ_r = 0),
//! D = ½ Σ c_i h γ κ̇_i²  (Kelvin–Voigt).
//!
//! Lagrange's equations are Σ_i m_i a_i·∂r_i/∂q = Q with a_i the inertial acceleration of
//! point i; with s̈ = B v̈ + c, c_i = h Σ_{seg<i} ġ_seg² ([`crate::foreshortening`]) they read
//!
//!   A v̈ + θ̈ d = F ≡ Q + θ̇² m v + 2θ̇ m ṡ − Bᵀ m (c + 2θ̇ v̇ + θ̇² X),
//!   (J + Σ m (X² + v²)) θ̈ + dᵀ v̈ = τ − Σ m [v c + 2θ̇ v v̇ − 2θ̇ X ṡ],
//!
//! A = diag(m) + Bᵀ diag(m) B,  d = m X + Bᵀ m v,  Q = −∂V/∂v − ∂D/∂v̇. With a prescribed joint
//! v̈ = A⁻¹(F − θ̈ d) and the second line gives the torque the motor needed; a free hub is the
//! bordered solve v̈ = A⁻¹F − θ̈ A⁻¹d, θ̈ from the hub row. A⁻¹ costs O(r) per right-hand side
//! through the tridiagonal system of the constraint's axial forces
//! ([`crate::foreshortening::Foreshortening`]); without foreshortening A = diag(m).
//! To second order in v the model is the report's T = ½Jθ̇² + ½Σm[θ̇²v² + (v̇ + θ̇x)²] − θ̇²Φ,
//! Φ = Σ m x s = ½ Σ_seg h W_seg g_seg² (W_seg = Σ_{i > seg} m_i x_i, the centrifugal tension's
//! potential); the exact T adds ΔT = ½ Σ m [θ̇² s² + 2θ̇(v ṡ − s v̇) + ṡ²], as fem (½Σm|ṙ|²) and
//! modal (`exact_inextensible_terms`) do. On `spin-up` ΔT moves the peak tip deflection by
//! 1.1e-3 relative: fdm's Richardson limit of 11…161 stations (order 2.00) is 0.40076871 m
//! against modal's 0.4007687 m (`flexverify converge spin-up --quantity
//! peak:link1.tip_deflection --backend fdm`); the second-order model (ΔT dropped) converges
//! to 0.40032746 m.
//!
//! Step bound: θ̇²∂²Φ is the string stiffness of the centrifugal tension N = θ̇²W, so the
//! linearized operator is M⁻¹(K_b + θ̇²∂²Φ − θ̇²M); its Gershgorin discs give, per station,
//! ω_k² = bend_row_k + θ̇² geo_row_k − θ̇² (see `bound`), rather than the report's bending-only 5.44.

use std::ops::Range;

use data::scene::{PlanarChain, PrescribedMotion, TorqueLaw};
use data::{DofPlan, Scene};

use crate::error::FdmError;
use crate::foreshortening::Foreshortening;
use crate::system::{
    Bound, BoundKind, DeflectionModel, Overextension, System, law_jumps, law_torque,
};

mod outputs;

/// Default stations per link.
pub const DEFAULT_STATIONS: usize = 41;

#[derive(Debug, Clone)]
enum Drive {
    Prescribed(PrescribedMotion),
    Torque {
        law: Option<TorqueLaw>,
        stiffness: f64,
        damping: f64,
        set_point: f64,
    },
}

/// A single floating-frame link.
#[derive(Debug, Clone)]
pub struct FloatingLink {
    r: usize,
    h: f64,
    length: f64,
    ei: f64,
    gamma: f64,
    foreshortening: bool,
    hub: f64,
    theta0: f64,
    rate0: f64,
    drive: Drive,
    /// masses of stations 1…r (index 0 ↔ station 1)
    m: Vec<f64>,
    /// W_seg for segments 0…r−1
    wseg: Vec<f64>,
    field_stations: usize,
    /// Gershgorin row sums Σ_j |`K_b[k][j]`| / m_k of the bending operator (1/time²), per station.
    bend_row: Vec<f64>,
    /// Gershgorin row sums Σ_j |∂²Φ/∂v_k∂v_j| / m_k of the foreshortening (geometric) operator
    /// per unit θ̇² (zero without foreshortening): θ̇² ∂²Φ is the centrifugal tension
    /// N(x) = θ̇² W(x) acting as a string, N/h · [−1 2 −1].
    geo_row: Vec<f64>,
    /// foreshortening kinematics and the factorized mass operator diag(m) + Bᵀ m B
    fore: Foreshortening,
    // scratch
    f: Vec<f64>,
    /// hub–deflection coupling d = m X + Bᵀ m v
    coupling: Vec<f64>,
    /// axial loads per station, then A⁻¹d
    axial: Vec<f64>,
    power: [f64; 3],
    torque: f64,
    /// The jump the step being closed ends on ([`System::close_stretch_at`]).
    closing: Option<f64>,
    /// Hub rate of the latest force evaluation (the bound of a torque-driven hub uses it).
    last_rate: f64,
    /// Hub rate the latest bound was evaluated at (for its description).
    bound_rate: std::cell::Cell<f64>,
}

impl FloatingLink {
    /// The link model of `pc`, the planar chain of `scene`.
    pub fn from_planar_chain(
        scene: &Scene,
        pc: &PlanarChain,
        stations: Option<usize>,
    ) -> Result<Self, FdmError> {
        if pc.links.len() != 1 {
            return Err(FdmError::Unsupported(format!(
                "fdm: `{}` has {} links; chains of floating-frame links (joint coupling through the \
                 tip slope) are not implemented in fdm",
                scene.name,
                pc.links.len()
            )));
        }
        let l = &pc.links[0];
        FdmError::check_switches(
            &format!("`{}`", scene.name),
            "floating link",
            &[
                ("axial", l.axial),
                ("shear", l.shear),
                ("rotary_inertia", l.rotary_inertia),
                ("tip_inertia", l.tip_inertia.is_some()),
                ("gravity", pc.gravity.as_ref().is_some()),
                ("contact", !pc.contacts.is_empty()),
            ],
        )?;
        let j = &l.joint;
        let drive = match &j.prescribed {
            Some(PrescribedMotion::Fixed) => {
                return Err(FdmError::Unsupported(format!(
                    "fdm: `{}` is clamped to the ground: use `modes`/`statics` (free vibration of the cantilever is not run)",
                    scene.name
                )));
            }
            Some(p) => Drive::Prescribed(p.clone()),
            None => {
                let hub = j.hub_inertia.unwrap_or(0.0);
                if hub <= 0.0 {
                    return Err(FdmError::Unsupported(format!(
                        "fdm: `{}`: a torque-driven hub needs hub_inertia > 0 (the eliminated hub equation has J + Σ m v² − 2Φ as pivot)",
                        scene.name
                    )));
                }
                Drive::Torque {
                    law: j.torque.clone(),
                    stiffness: j.stiffness.unwrap_or(0.0),
                    damping: j.damping.unwrap_or(0.0),
                    set_point: j.set_point.unwrap_or(0.0),
                }
            }
        };
        let n = stations.unwrap_or(DEFAULT_STATIONS);
        let r = n - 1;
        let h = l.length / r as f64;
        let mut m = vec![l.mass_per_length * h; r];
        m[r - 1] = 0.5 * l.mass_per_length * h + l.tip_mass.unwrap_or(0.0);
        // W_seg = Σ_{i ≥ seg+1} m_i x_i
        let mut wseg = vec![0.0; r];
        let mut acc = 0.0;
        for seg in (0..r).rev() {
            let i = seg + 1;
            acc += m[i - 1] * i as f64 * h;
            wseg[seg] = acc;
        }
        let (bend_row, geo_row) =
            Self::gershgorin_rows(h, l.bending_stiffness, &m, &wseg, l.foreshortening);
        Ok(FloatingLink {
            bend_row,
            geo_row,
            last_rate: j.initial_rate,
            bound_rate: std::cell::Cell::new(j.initial_rate),
            r,
            h,
            length: l.length,
            ei: l.bending_stiffness,
            gamma: l.kelvin_voigt.unwrap_or(0.0),
            foreshortening: l.foreshortening,
            hub: j.hub_inertia.unwrap_or(0.0),
            theta0: j.initial_angle,
            rate0: j.initial_rate,
            drive,
            wseg,
            field_stations: scene.simulation.field_stations.max(2),
            fore: Foreshortening::new(h, &m),
            m,
            coupling: vec![0.0; r],
            axial: vec![0.0; r],
            f: vec![0.0; r],
            power: [0.0; 3],
            torque: 0.0,
            closing: None,
        })
    }

    /// Gershgorin row sums of M⁻¹K_b and M⁻¹∂²Φ, built by applying the force routines to unit
    /// vectors (once per run, O(r²)), so that the bound reads the very stencil that is integrated.
    /// Both operators have positive diagonals and non-positive nearest-neighbour entries, so the
    /// row sum of |K_b + θ̇²∂²Φ| is the sum of the two row sums.
    fn gershgorin_rows(
        h: f64,
        ei: f64,
        m: &[f64],
        wseg: &[f64],
        foreshortening: bool,
    ) -> (Vec<f64>, Vec<f64>) {
        let r = m.len();
        let mut bend = vec![0.0; r];
        let mut geo = vec![0.0; r];
        let mut unit = vec![0.0; r];
        let mut col = vec![0.0; r];
        for j in 0..r {
            unit[j] = 1.0;
            col.iter_mut().for_each(|x| *x = 0.0);
            Self::add_bending(h, ei, &unit, &mut col); // col = −K_b e_j
            for k in 0..r {
                bend[k] += col[k].abs() / m[k];
            }
            if foreshortening {
                col.iter_mut().for_each(|x| *x = 0.0);
                Self::add_phi_stencil(h, wseg, &unit, 1.0, &mut col); // col = ∂²Φ e_j
                for k in 0..r {
                    geo[k] += col[k].abs() / m[k];
                }
            }
            unit[j] = 0.0;
        }
        (bend, geo)
    }

    /// Highest ω² of the linearized transverse operator at hub rate `rate`, by Gershgorin per
    /// station k: ω_k² = bend_row_k + θ̇² geo_row_k − θ̇² (the diagonal centrifugal softening
    /// −θ̇² m_k v_k shifts every disc centre down). Returns the binding station (index into the
    /// elastic coordinates) and its σ_k = 2/ω_k × the Kelvin–Voigt factor, minimal over k.
    fn binding_station(&self, rate: f64) -> (usize, f64) {
        let w2 = rate * rate;
        let mut best = (0, f64::INFINITY);
        for k in 0..self.r {
            let om2 = (self.bend_row[k] + w2 * self.geo_row[k] - w2).max(0.0);
            if om2 <= 0.0 {
                continue;
            }
            let om = om2.sqrt();
            // Kelvin–Voigt: C = (γ/EI) K_b, so per station c/m = (γ/EI) bend_row and
            // ζ = c/(2mω) = γ bend_row/(2 EI ω) (= γω/(2EI) without tension, as before).
            let zeta = if self.ei > 0.0 {
                self.gamma * self.bend_row[k] / (2.0 * self.ei * om)
            } else {
                0.0
            };
            let sigma = 2.0 / om * crate::system::damped_step_factor(zeta);
            if sigma < best.1 {
                best = (k, sigma);
            }
        }
        best
    }

    fn prescribed(&self) -> bool {
        matches!(self.drive, Drive::Prescribed(_))
    }

    /// Offset of v₁ in q.
    fn v0(&self) -> usize {
        if self.prescribed() { 0 } else { 1 }
    }

    fn vrange(&self) -> Range<usize> {
        self.v0()..self.v0() + self.r
    }

    /// (θ, θ̇, θ̈ if prescribed).
    fn hub_state(&self, t: f64, q: &[f64], v: &[f64]) -> (f64, f64, Option<f64>) {
        match &self.drive {
            Drive::Prescribed(p) => {
                let (a, b, c) = p.kinematics(t);
                (self.theta0 + a, self.rate0 + b, Some(c))
            }
            Drive::Torque { .. } => (q[0], v[0], None),
        }
    }

    /// Station value with v₀ = 0 (index k = station).
    fn at(vs: &[f64], k: usize) -> f64 {
        if k == 0 { 0.0 } else { vs[k - 1] }
    }

    /// Adds −∂/∂v of ½ Σ c_i h c κ_i² (c = EI with v, or γ with v̇) into f; returns the energy.
    pub(crate) fn add_bending(h: f64, c: f64, vs: &[f64], f: &mut [f64]) -> f64 {
        Self::add_bending_forces(h, c, vs, f);
        Self::bending_energy(h, c, vs)
    }

    /// [`Self::add_bending`]'s forces alone (the energy costs a division per station).
    pub(crate) fn add_bending_forces(h: f64, c: f64, vs: &[f64], f: &mut [f64]) {
        let r = vs.len();
        let inv_h3 = 1.0 / (h * h * h);
        // clamped end: κ₀ = 2v₁/h², weight ½
        let m0 = c * 2.0 * vs[0] * inv_h3; // = c κ₀ / h
        f[0] -= m0;
        for i in 1..r {
            let k = Self::at(vs, i + 1) - 2.0 * Self::at(vs, i) + Self::at(vs, i - 1);
            let mb = c * k * inv_h3;
            if i >= 2 {
                f[i - 2] -= mb;
            }
            f[i - 1] += 2.0 * mb;
            f[i] -= mb;
        }
    }

    /// Adds scale · ∂Φ/∂v into f and returns Φ = ½ Σ_seg h W_seg g_seg² (W_seg = Σ_{i > seg} mᵢxᵢ):
    /// the geometric stiffness of the centrifugal tension, for the step bound.
    fn add_phi_stencil(h: f64, wseg: &[f64], vs: &[f64], scale: f64, f: &mut [f64]) -> f64 {
        let mut phi = 0.0;
        for seg in 0..wseg.len() {
            let g = (Self::at(vs, seg + 1) - Self::at(vs, seg)) / h;
            phi += 0.5 * h * wseg[seg] * g * g;
            let d = scale * wseg[seg] * g; // ∂Φ/∂v_{seg+1} = W g, ∂/∂v_seg = −W g
            f[seg] += d;
            if seg >= 1 {
                f[seg - 1] -= d;
            }
        }
        phi
    }

    /// ½ Σ c_i h c κ_i² without forces (output path: no scratch).
    pub(crate) fn bending_energy(h: f64, c: f64, vs: &[f64]) -> f64 {
        let r = vs.len();
        let mut e = 0.5 * 0.5 * h * c * (2.0 * vs[0] / (h * h)).powi(2);
        for i in 1..r {
            let k = Self::at(vs, i + 1) - 2.0 * Self::at(vs, i) + Self::at(vs, i - 1);
            e += 0.5 * h * c * (k / (h * h)).powi(2);
        }
        e
    }

    /// T = ½Jθ̇² + ½ Σ mᵢ [(ṡᵢ + θ̇vᵢ)² + (v̇ᵢ + θ̇(xᵢ − sᵢ))²] (s ≡ 0 without foreshortening).
    fn kinetic_energy(&self, rate: f64, vs: &[f64], vd: &[f64]) -> f64 {
        let (mut s, mut sd) = (0.0, 0.0);
        let mut ke = 0.5 * self.hub * rate * rate;
        for k in 0..self.r {
            if self.foreshortening {
                let g = (vs[k] - Self::at(vs, k)) / self.h;
                let gd = (vd[k] - Self::at(vd, k)) / self.h;
                s += 0.5 * self.h * g * g;
                sd += self.h * g * gd;
            }
            let x = (k + 1) as f64 * self.h;
            ke +=
                0.5 * self.m[k] * ((sd + rate * vs[k]).powi(2) + (vd[k] + rate * (x - s)).powi(2));
        }
        ke
    }

    /// out = A⁻¹ f: the foreshortening mass operator, or diag(m) without foreshortening.
    fn mass_solve(fs: &mut Foreshortening, on: bool, m: &[f64], f: &[f64], out: &mut [f64]) {
        if on {
            fs.solve(f, out);
        } else {
            for k in 0..m.len() {
                out[k] = f[k] / m[k];
            }
        }
    }

    /// Applied hub torque (law + spring + damper) and its parts for the ledger.
    fn applied(&self, t: f64, th: f64, rate: f64) -> (f64, f64, f64) {
        match &self.drive {
            Drive::Torque {
                law,
                stiffness,
                damping,
                set_point,
            } => {
                let ext = law_torque(law.as_ref(), t, self.closing);
                (ext, -stiffness * (th - set_point), -damping * rate)
            }
            Drive::Prescribed(_) => (0.0, 0.0, 0.0),
        }
    }

    /// The ledger terms the scene enables (the others are neither computed into the ledger nor
    /// stored): an input when the hub is prescribed or has a torque law, a joint spring and
    /// damper when their constants are non-zero, Kelvin–Voigt when γ > 0.
    fn input_enabled(&self) -> bool {
        match &self.drive {
            Drive::Prescribed(_) => true,
            Drive::Torque { law, .. } => law.is_some(),
        }
    }

    fn spring_enabled(&self) -> bool {
        matches!(self.drive, Drive::Torque { stiffness, .. } if stiffness != 0.0)
    }

    fn damper_enabled(&self) -> bool {
        matches!(self.drive, Drive::Torque { damping, .. } if damping != 0.0)
    }

    fn kelvin_voigt_enabled(&self) -> bool {
        self.gamma > 0.0
    }

    pub fn dof_plan(&self) -> DofPlan {
        let mut plan = DofPlan::default();
        if !self.prescribed() {
            plan.add("hub angle θ", 1);
        }
        plan.add("transverse v at stations (clamp excluded)", self.r);
        if self.foreshortening {
            plan.builds
                .push("foreshortening (centrifugal) stiffening".into());
        }
        if self.gamma > 0.0 {
            plan.builds.push("Kelvin–Voigt damping".into());
        }
        plan
    }

    pub fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.dofs();
        let mut q = vec![0.0; n];
        let mut v = vec![0.0; n];
        if !self.prescribed() {
            q[0] = self.theta0;
            v[0] = self.rate0;
        }
        (q, v)
    }
}

impl System for FloatingLink {
    fn dofs(&self) -> usize {
        self.r + self.v0()
    }

    fn jumps(&self) -> Vec<f64> {
        match &self.drive {
            Drive::Torque { law, .. } => law_jumps(law),
            Drive::Prescribed(_) => Vec::new(),
        }
    }

    fn close_stretch_at(&mut self, jump: Option<f64>) {
        self.closing = jump;
    }

    fn overextended(&self, q: &[f64]) -> Option<Overextension> {
        let tip = q[self.vrange()][self.r - 1];
        (tip.abs() > self.length).then_some(Overextension {
            link: 1,
            deflection: tip,
            length: self.length,
            model: if self.foreshortening {
                DeflectionModel::SmallStrain
            } else {
                DeflectionModel::Linear
            },
        })
    }

    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        let vr = self.vrange();
        let (th, rate, pres) = self.hub_state(t, q, v);
        self.last_rate = rate;
        let (vs, vd) = (&q[vr.clone()], &v[vr.clone()]);
        let mut f = std::mem::take(&mut self.f);
        let mut d = std::mem::take(&mut self.coupling);
        let mut y = std::mem::take(&mut self.axial);
        f.iter_mut().for_each(|x| *x = 0.0);
        Self::add_bending(self.h, self.ei, vs, &mut f);
        let mut p_kv = 0.0;
        if self.gamma > 0.0 {
            // −∂D/∂v̇ with D = ½ Σ c_i h γ κ̇_i² (the same stencil on v̇); dissipated power 2D.
            p_kv = 2.0 * Self::add_bending(self.h, self.gamma, vd, &mut f);
        }
        // f ← Q + θ̇² m v + 2θ̇ m ṡ − Bᵀ m (c + 2θ̇ v̇ + θ̇² X),  d = m X + Bᵀ m v,
        // a_θθ = J + Σ m (X² + v²),  r_θ = −Σ m [v c + 2θ̇ v v̇ − 2θ̇ X ṡ]   (module docs)
        let (ext, spring, damper) = self.applied(t, th, rate);
        let fs = &mut self.fore;
        if self.foreshortening {
            fs.set_state(vs, vd);
            fs.factor();
        }
        let (mut a_hub, mut r_hub) = (self.hub, 0.0);
        for k in 0..self.r {
            let x = (k + 1) as f64 * self.h;
            let m = self.m[k];
            let (s, sd, c) = if self.foreshortening {
                (fs.s[k], fs.sd[k], fs.c[k])
            } else {
                (0.0, 0.0, 0.0)
            };
            let big_x = x - s;
            f[k] += m * (rate * rate * vs[k] + 2.0 * rate * sd);
            y[k] = m * (c + 2.0 * rate * vd[k] + rate * rate * big_x);
            a_hub += m * (big_x * big_x + vs[k] * vs[k]);
            r_hub -= m * (vs[k] * c + 2.0 * rate * (vs[k] * vd[k] - big_x * sd));
            d[k] = m * big_x;
        }
        if self.foreshortening {
            fs.bt_mul_add(&y, -1.0, &mut f);
            for k in 0..self.r {
                y[k] = self.m[k] * vs[k];
            }
            fs.bt_mul_add(&y, 1.0, &mut d);
        }
        // A u = f − θ̈ d with A = diag(m) + Bᵀ m B (O(r) through `Foreshortening`)
        let vacc = &mut a[vr.clone()];
        let thdd = match pres {
            Some(acc) => {
                for k in 0..self.r {
                    f[k] -= acc * d[k];
                }
                Self::mass_solve(fs, self.foreshortening, &self.m, &f, vacc);
                let du: f64 = (0..self.r).map(|k| d[k] * vacc[k]).sum();
                self.torque = a_hub * acc + du - r_hub;
                acc
            }
            None => {
                let tau = ext + spring + damper;
                self.torque = ext;
                // bordered solve: u = A⁻¹f − θ̈ A⁻¹d, θ̈ from the hub row
                Self::mass_solve(fs, self.foreshortening, &self.m, &d, &mut y);
                Self::mass_solve(fs, self.foreshortening, &self.m, &f, vacc);
                let (mut dy1, mut dy2) = (0.0, 0.0);
                for k in 0..self.r {
                    dy1 += d[k] * vacc[k];
                    dy2 += d[k] * y[k];
                }
                let thdd = (tau + r_hub - dy1) / (a_hub - dy2);
                for k in 0..self.r {
                    vacc[k] -= thdd * y[k];
                }
                thdd
            }
        };
        if !self.prescribed() {
            a[0] = thdd;
        }
        // powers: input (applied or prescribed torque), joint damper, Kelvin–Voigt
        self.power = [self.torque * rate, damper * -rate, p_kv];
        self.f = f;
        self.coupling = d;
        self.axial = y;
    }

    fn powers(&self, out: &mut [f64]) {
        let enabled = [
            self.input_enabled(),
            self.damper_enabled(),
            self.kelvin_voigt_enabled(),
        ];
        let mut k = 0;
        for (p, on) in self.power.iter().zip(enabled) {
            if on {
                out[k] = *p;
                k += 1;
            }
        }
    }

    fn bound(&self, t: f64) -> Bound {
        // The report's 5.44, σ² = h⁴m/(4EI), is 2/ω_max of the bending stencil alone
        // (ω_max² = 16EI/(m h⁴), the sawtooth wave). A spinning link with foreshortening also
        // carries the centrifugal tension N(x) = θ̇² W(x) ≈ ρAθ̇²(L² − x²)/2, whose string stiffness
        // N/h² raises the sawtooth frequency to ω² ≈ (16EI/h⁴ + 4N/h²)/m − θ̇². The bound is
        // therefore taken per station from the Gershgorin discs of the assembled operator at the
        // current hub rate (prescribed: its kinematics at t; torque-driven: the rate of the
        // latest force evaluation, i.e. of the current state), σ = min_k 2/ω_k × KV factor.
        let rate = match &self.drive {
            Drive::Prescribed(p) => self.rate0 + p.kinematics(t).1,
            Drive::Torque { .. } => self.last_rate,
        };
        self.bound_rate.set(rate);
        let (site, sigma) = self.binding_station(rate);
        let tension = self.foreshortening && rate != 0.0 && self.geo_row[site] > 0.0;
        Bound {
            sigma,
            kind: if tension {
                BoundKind::TransverseTension
            } else {
                BoundKind::Transverse
            },
            site,
        }
    }

    fn stored_energies(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let (th, rate, _) = self.hub_state(t, q, v);
        let vr = self.vrange();
        let (vs, vd) = (&q[vr.clone()], &v[vr]);
        let ke = self.kinetic_energy(rate, vs, vd);
        let strain = Self::bending_energy(self.h, self.ei, vs);
        out[0] = ke;
        out[1] = strain;
        if let Drive::Torque {
            stiffness,
            set_point,
            ..
        } = &self.drive
            && self.spring_enabled()
        {
            out[2] = 0.5 * stiffness * (th - set_point).powi(2);
        }
    }

    fn monitored(&self) -> Range<usize> {
        self.vrange()
    }

    fn damped(&self) -> bool {
        // A free hub couples θ̇ to v̇ (İθ̇, θ̇² terms): velocity-dependent, like damping, for the
        // two-step scheme's computational mode.
        self.gamma > 0.0 || !self.prescribed()
    }
}

#[cfg(test)]
mod tests;
