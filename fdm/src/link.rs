//! One flexible link in a floating (rotating) frame, on the same finite-difference grid as the
//! cantilever: `spin-up`, `spin-up-linear`, `single-link`.
//!
//! Discrete Lagrangian (stations 0…r, v₀ = 0, clamped ghost v₋₁ = v₁, free-end ghosts as in the
//! report's 5.32; trapezoid-lumped masses m_i, tip mass at station r):
//!
//! T = ½Jθ̇² + ½ Σ m_i [θ̇² v_i² + (v̇_i + θ̇ x_i)²] − θ̇² Φ(v),
//! Φ = Σ m_i x_i s_i = ½ Σ_seg h W_seg g_seg²,  W_seg = Σ_{i > seg} m_i x_i,  g = Δv/h,
//! V = ½ Σ_{i=0}^{r−1} c_i h EI κ_i²  (c₀ = ½, κ₀ = 2v₁/h², κ_r = 0),
//! D = ½ Σ c_i h γ κ̇_i²  (Kelvin–Voigt).
//!
//! T is the kinetic energy of the point (x − s, v) of the rotating frame to second order in v,
//! with s = ½∫₀ˣ v'² when `foreshortening` is on (Φ ≡ 0 for the linear model, which then has
//! only the centrifugal softening −θ̇² m v and must diverge above the first frequency).
//! Lagrange's equations give, per station,
//!   m_k (v̈_k + θ̈ x_k) = F_k ≡ θ̇² (m_k v_k − ∂Φ/∂v_k) − ∂V/∂v_k − ∂D/∂v̇_k,
//! and for the hub, with p_θ = I θ̇ + Σ m_i x_i v̇_i, I = J + Σ m_i (x_i² + v_i²) − 2Φ,
//!   (J + Σ m_i v_i² − 2Φ) θ̈ = τ − İ θ̇ − Σ x_i F_i      (v̈ eliminated, as in 5.38/5.40).
//! With a prescribed joint the second line gives the torque the motor needed.
//!
//! Step bound: θ̇²∂²Φ is the string stiffness of the centrifugal tension N = θ̇²W, so the
//! linearized operator is M⁻¹(K_b + θ̇²∂²Φ − θ̇²M); its Gershgorin discs give, per station,
//! ω_k² = bend_row_k + θ̇² geo_row_k − θ̇² (see `bound`), rather than the report's bending-only 5.44.

use std::ops::Range;

use data::scene::{PrescribedMotion, TorqueLaw};
use data::{DofPlan, RunResult, Scene, Settings, channel};

use crate::driver::{StepControl, integrate};
use crate::error::FdmError;
use crate::output::Outputs;
use crate::settings::FdmSettings;
use crate::system::{Bound, BoundKind, System};

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
    /// Gershgorin row sums Σ_j |K_b[k][j]| / m_k of the bending operator (1/time²), per station.
    bend_row: Vec<f64>,
    /// Gershgorin row sums Σ_j |∂²Φ/∂v_k∂v_j| / m_k of the foreshortening (geometric) operator
    /// per unit θ̇² (zero without foreshortening): θ̇² ∂²Φ is the centrifugal tension
    /// N(x) = θ̇² W(x) acting as a string, N/h · [−1 2 −1].
    geo_row: Vec<f64>,
    // scratch
    f: Vec<f64>,
    power: [f64; 3],
    torque: f64,
    /// Hub rate of the latest force evaluation (the bound of a torque-driven hub uses it).
    last_rate: f64,
    /// Hub rate the latest bound was evaluated at (for its description).
    bound_rate: std::cell::Cell<f64>,
}

impl FloatingLink {
    pub fn from_scene(scene: &Scene, stations: Option<usize>) -> Result<Self, FdmError> {
        if scene.links.len() != 1 {
            return Err(FdmError::Unsupported(format!(
                "fdm: `{}` has {} links; chains of floating-frame links (joint coupling through the \
                 tip slope) are not implemented in fdm",
                scene.name,
                scene.links.len()
            )));
        }
        let l = &scene.links[0];
        FdmError::check_switches(
            &format!("`{}`", scene.name),
            "floating link",
            &[
                ("axial", l.axial),
                ("shear", l.shear),
                ("rotary_inertia", l.rotary_inertia),
                ("tip_inertia", l.tip_inertia.is_some()),
                ("gravity", scene.gravity.is_some()),
                ("contact", !scene.contacts.is_empty()),
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
            m,
            wseg,
            field_stations: scene.simulation.field_stations.max(2),
            f: vec![0.0; r],
            power: [0.0; 3],
            torque: 0.0,
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
        let r = vs.len();
        let inv_h3 = 1.0 / (h * h * h);
        // clamped end: κ₀ = 2v₁/h², weight ½
        let m0 = c * 2.0 * vs[0] * inv_h3; // = c κ₀ / h
        f[0] -= m0;
        let mut e = 0.5 * 0.5 * h * c * (2.0 * vs[0] / (h * h)).powi(2);
        for i in 1..r {
            let k = Self::at(vs, i + 1) - 2.0 * Self::at(vs, i) + Self::at(vs, i - 1);
            let mb = c * k * inv_h3;
            if i >= 2 {
                f[i - 2] -= mb;
            }
            f[i - 1] += 2.0 * mb;
            f[i] -= mb;
            e += 0.5 * h * c * (k / (h * h)).powi(2);
        }
        e
    }

    /// Φ and its gradient added (times `scale`) into f.
    fn add_phi(&self, vs: &[f64], scale: f64, f: &mut [f64]) -> f64 {
        Self::add_phi_stencil(self.h, &self.wseg, vs, scale, f)
    }

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

    fn phi(&self, vs: &[f64]) -> f64 {
        (0..self.r)
            .map(|seg| {
                let g = (Self::at(vs, seg + 1) - Self::at(vs, seg)) / self.h;
                0.5 * self.h * self.wseg[seg] * g * g
            })
            .sum()
    }

    fn phi_dot(&self, vs: &[f64], vd: &[f64]) -> f64 {
        let mut s = 0.0;
        for seg in 0..self.r {
            let g = (Self::at(vs, seg + 1) - Self::at(vs, seg)) / self.h;
            let gd = (Self::at(vd, seg + 1) - Self::at(vd, seg)) / self.h;
            s += self.h * self.wseg[seg] * g * gd;
        }
        s
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
                let ext = law.as_ref().map_or(0.0, |l| l.torque(t));
                (ext, -stiffness * (th - set_point), -damping * rate)
            }
            Drive::Prescribed(_) => (0.0, 0.0, 0.0),
        }
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

    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        let vr = self.vrange();
        let (th, rate, pres) = self.hub_state(t, q, v);
        self.last_rate = rate;
        let (vs, vd) = (&q[vr.clone()], &v[vr.clone()]);
        let mut f = std::mem::take(&mut self.f);
        f.iter_mut().for_each(|x| *x = 0.0);
        Self::add_bending(self.h, self.ei, vs, &mut f);
        let mut p_kv = 0.0;
        if self.gamma > 0.0 {
            // −∂D/∂v̇ with D = ½ Σ c_i h γ κ̇_i² (the same stencil on v̇); dissipated power 2D.
            p_kv = 2.0 * Self::add_bending(self.h, self.gamma, vd, &mut f);
        }
        let mut phi = 0.0;
        if self.foreshortening {
            phi = self.add_phi(vs, -rate * rate, &mut f);
        }
        let mut sum_mv2 = 0.0;
        let mut sum_mvvd = 0.0;
        for k in 0..self.r {
            f[k] += rate * rate * self.m[k] * vs[k];
            sum_mv2 += self.m[k] * vs[k] * vs[k];
            sum_mvvd += self.m[k] * vs[k] * vd[k];
        }
        let phid = if self.foreshortening {
            self.phi_dot(vs, vd)
        } else {
            0.0
        };
        let idot = 2.0 * sum_mvvd - 2.0 * phid;
        let xf: f64 = (0..self.r).map(|k| (k + 1) as f64 * self.h * f[k]).sum();
        let jeff = self.hub + sum_mv2 - 2.0 * phi;
        let (ext, spring, damper) = self.applied(t, th, rate);
        let thdd = match pres {
            Some(acc) => {
                self.torque = jeff * acc + idot * rate + xf;
                acc
            }
            None => {
                let tau = ext + spring + damper;
                self.torque = ext;
                (tau - idot * rate - xf) / jeff
            }
        };
        if !self.prescribed() {
            a[0] = thdd;
        }
        for k in 0..self.r {
            a[vr.start + k] = f[k] / self.m[k] - thdd * (k + 1) as f64 * self.h;
        }
        // powers: input (applied or prescribed torque), joint damper, Kelvin–Voigt
        self.power = [self.torque * rate, damper * -rate, p_kv];
        self.f = f;
    }

    fn powers(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.power);
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
        let mut ke = 0.5 * self.hub * rate * rate;
        for k in 0..self.r {
            let x = (k + 1) as f64 * self.h;
            ke += 0.5 * self.m[k] * ((rate * vs[k]).powi(2) + (vd[k] + rate * x).powi(2));
        }
        if self.foreshortening {
            ke -= rate * rate * self.phi(vs);
        }
        let strain = Self::bending_energy(self.h, self.ei, vs);
        let spring = match &self.drive {
            Drive::Torque {
                stiffness,
                set_point,
                ..
            } => 0.5 * stiffness * (th - set_point).powi(2),
            Drive::Prescribed(_) => 0.0,
        };
        out.copy_from_slice(&[ke, strain, spring]);
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

impl Outputs for FloatingLink {
    fn describe(&self, b: &Bound) -> String {
        let rate = self.bound_rate.get();
        let k = b.site;
        let w2 = rate * rate;
        let tension = if self.foreshortening {
            w2 * self.wseg[k]
        } else {
            0.0
        };
        format!(
            "station {} (x = {:.4}), hub rate {:.4}: ω² = {:.4e} bending + {:.4e} tension (N = {:.4e}) − {:.4e} softening",
            k + 1,
            (k + 1) as f64 * self.h,
            rate,
            self.bend_row[k],
            w2 * self.geo_row[k],
            tension,
            w2
        )
    }

    fn channels(&self) -> Vec<(String, &'static str)> {
        let mut c = vec![
            (channel::joint_angle(1), "rad"),
            (channel::joint_rate(1), "rad/time"),
            (channel::joint_torque(1), "torque"),
            (channel::tip_x(1), "length"),
            (channel::tip_y(1), "length"),
            (channel::tip_deflection(1), "length"),
        ];
        for k in 0..self.field_stations {
            c.push((channel::field_deflection(1, k), "length"));
        }
        c
    }

    fn observe(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let (th, rate, _) = self.hub_state(t, q, v);
        let vs = &q[self.vrange()];
        let tip = vs[self.r - 1];
        let s_tip = if self.foreshortening {
            (0..self.r)
                .map(|seg| {
                    0.5 * self.h * ((Self::at(vs, seg + 1) - Self::at(vs, seg)) / self.h).powi(2)
                })
                .sum()
        } else {
            0.0
        };
        let (c, s) = (th.cos(), th.sin());
        let xt = self.length - s_tip;
        out[0] = th;
        out[1] = rate;
        // torque of the latest force evaluation (level t_{j+1}; within one step of t)
        out[2] = self.torque;
        out[3] = c * xt - s * tip;
        out[4] = s * xt + c * tip;
        out[5] = tip;
        let nf = self.field_stations;
        sample_field(
            self.length,
            self.h,
            self.r,
            |i| Self::at(vs, i),
            &mut out[6..6 + nf],
        );
    }

    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        let input = if self.prescribed() {
            "prescribed_motion"
        } else {
            "applied_torque"
        };
        (
            vec!["kinetic", "strain", "joint_spring"],
            vec![input],
            vec!["joint_damper", "kelvin_voigt"],
        )
    }

    fn dof_name(&self, i: usize) -> String {
        if !self.prescribed() && i == 0 {
            "hub angle θ".into()
        } else {
            let k = i - self.v0() + 1;
            format!("transverse v at station {k} (x = {:.4})", k as f64 * self.h)
        }
    }
}

/// Samples a link's deflection at `out.len()` equally spaced points over its `length`, linearly
/// between the stations 0…r of step `h` (`at(i)`: deflection of station i).
pub(crate) fn sample_field(
    length: f64,
    h: f64,
    r: usize,
    at: impl Fn(usize) -> f64,
    out: &mut [f64],
) {
    let nf = out.len();
    for (k, o) in out.iter_mut().enumerate() {
        let x = k as f64 * length / (nf - 1) as f64;
        let pos = (x / h).clamp(0.0, r as f64);
        let i = (pos.floor() as usize).min(r - 1);
        let al = pos - i as f64;
        *o = at(i) * (1.0 - al) + at(i + 1) * al;
    }
}

pub fn simulate(
    scene: &Scene,
    settings: &Settings,
    s: &FdmSettings,
) -> Result<RunResult, FdmError> {
    let mut sys = FloatingLink::from_scene(scene, s.stations)?;
    let (q0, v0) = sys.initial_state();
    let ctl = StepControl::for_scene(scene, s, s.method, false, true);
    Ok(integrate(&mut sys, &q0, &v0, &ctl)?.into_run_result(scene, settings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elem_link_forces_are_minus_energy_gradients() {
        let scene = data::load_scene("spin-up").unwrap();
        let link = FloatingLink::from_scene(&scene, Some(9)).unwrap();
        let h = link.h;
        let vs: Vec<f64> = (1..=8)
            .map(|i| 0.01 * (0.7 * i as f64).sin() + 0.002 * i as f64)
            .collect();
        let mut fb = vec![0.0; 8];
        FloatingLink::add_bending(h, 3.0, &vs, &mut fb);
        let mut fp = vec![0.0; 8];
        link.add_phi(&vs, 1.0, &mut fp);
        let eps = 1e-6;
        for k in 0..8 {
            let (mut a, mut b) = (vs.clone(), vs.clone());
            a[k] += eps;
            b[k] -= eps;
            let db = (FloatingLink::bending_energy(h, 3.0, &a)
                - FloatingLink::bending_energy(h, 3.0, &b))
                / (2.0 * eps);
            let dp = (link.phi(&a) - link.phi(&b)) / (2.0 * eps);
            // quadratic energies: central differences are exact up to round-off (≈ 1e-10 here)
            assert!(
                (fb[k] + db).abs() < 1e-6 * (1.0 + db.abs()),
                "bending {k}: {} vs {}",
                fb[k],
                -db
            );
            assert!(
                (fp[k] - dp).abs() < 1e-6 * (1.0 + dp.abs()),
                "phi {k}: {} vs {}",
                fp[k],
                dp
            );
        }
        // and the bending energy equals the cantilever's ½ vᵀKv
        let c =
            crate::beam::Cantilever::from_scene(&data::load_scene("cantilever").unwrap(), Some(9))
                .unwrap();
        let k = c.stiffness();
        let quad: f64 = (0..8)
            .map(|i| (0..8).map(|j| 0.5 * vs[i] * k[(i, j)] * vs[j]).sum::<f64>())
            .sum();
        let e = FloatingLink::bending_energy(c.h, c.ei, &vs);
        assert!(
            (quad - e).abs() < 1e-12 * e.abs().max(1e-30),
            "{quad} vs {e}"
        );
    }

    /// The link of `spin-up` spun to a constant rate Ω after a 0.2 s ramp (the ramp's θ̈x load
    /// seeds every wave, the sawtooth by round-off), with `stations` stations.
    fn spinning(omega: f64, stations: usize) -> (FloatingLink, Scene) {
        let mut scene = data::load_scene("spin-up").unwrap();
        scene.links[0].joint.prescribed = Some(PrescribedMotion::SpinUp {
            omega_s: omega,
            t_s: 0.2,
        });
        let link = FloatingLink::from_scene(&scene, Some(stations)).unwrap();
        (link, scene)
    }

    /// Top eigenvalue ω² of the linearized transverse operator −∂a/∂v at hub rate Ω (prescribed,
    /// θ̈ = 0 after the ramp): dense M^{½}(−∂a/∂v)M^{−½}, symmetric, by faer.
    fn top_omega2(link: &mut FloatingLink, t: f64) -> f64 {
        use faer::{Mat, Side};
        let n = link.dofs();
        let zero = vec![0.0; n];
        let (mut a0, mut a) = (vec![0.0; n], vec![0.0; n]);
        link.accel(t, &zero, &zero, &mut a0);
        let mut s = Mat::<f64>::zeros(n, n);
        let mut q = zero.clone();
        for j in 0..n {
            q[j] = 1.0; // the forces are linear in v: unit columns are exact
            link.accel(t, &q, &zero, &mut a);
            q[j] = 0.0;
            for i in 0..n {
                s[(i, j)] = -(a[i] - a0[i]) * (link.m[i] / link.m[j]).sqrt();
            }
        }
        let vals = s.self_adjoint_eigenvalues(Side::Lower).unwrap();
        vals.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v))
    }

    #[test]
    fn elem_link_bound_includes_centrifugal_tension_and_is_tight() {
        // Ω = 60 rad/s on the 41-station spin-up link: the tension term 4N/(m h²) is ≈ 25 % of
        // the bending term 16EI/(m h⁴) at the root, so the report's bending-only bound is wrong
        // by ≈ 10 % in τ.
        let omega = 60.0;
        let (mut link, _) = spinning(omega, 41);
        let t = 0.5; // after the ramp: θ̇ = Ω, θ̈ = 0
        let b = link.bound(t);
        assert_eq!(b.kind, BoundKind::TransverseTension);
        let w_true = top_omega2(&mut link, t).sqrt();
        let w_bound = 2.0 / b.sigma;
        let rho_a = link.m[0] / link.h;
        let w_report = (16.0 * link.ei / (rho_a * link.h.powi(4))).sqrt();
        // closed form at the binding interior station: (16EI/h⁴ + 2(W_{k−1} + W_k)Ω²/h²)/ρA − Ω²
        let k = b.site;
        let w2_closed = (16.0 * link.ei / link.h.powi(4)
            + 2.0 * (link.wseg[k] + link.wseg[k + 1]) * omega * omega / (link.h * link.h))
            / rho_a
            - omega * omega;
        eprintln!(
            "Ω = {omega}: ω_max true {w_true:.6e}, bound {w_bound:.6e} (station {}), bending-only {w_report:.6e}",
            k + 1
        );
        // Gershgorin is a rigorous upper bound: ω_true ≤ ω_bound up to eigen-solver round-off
        assert!(w_true <= w_bound * (1.0 + 1e-12), "{w_true} > {w_bound}");
        // ...and tight: the sawtooth wave under a slowly varying N sits within 2 % of it (its
        // envelope costs O((π/r)²) of the bending symbol and averages N over the wave)
        assert!(w_bound < 1.02 * w_true, "{w_bound} vs {w_true}");
        // the report's bending-only value misses the tension: below the true frequency
        assert!(w_report < 0.95 * w_true, "{w_report} vs {w_true}");
        // the per-station Gershgorin row at an interior station equals the closed form (same
        // arithmetic up to summation order: 1e-12); stations 2…r−2 carry the full bending stencil
        assert!((1..link.r - 2).contains(&k), "binding station {}", k + 1);
        assert!(((w_bound * w_bound) / w2_closed - 1.0).abs() < 1e-12);
        // at rest the bound is the report's 5.44 (the interior bending row is 16EI/(m h⁴))
        let rest = link.bound(0.0);
        assert_eq!(rest.kind, BoundKind::Transverse);
        assert!((2.0 / rest.sigma / w_report - 1.0).abs() < 1e-12);
    }

    /// Runs the spinning link with a forced step `ratio` × the method's limit at full rate,
    /// bypassing the forced-step check, and returns the verdict.
    fn forced_run(omega: f64, ratio: f64) -> (data::StabilityVerdict, f64) {
        let (mut link, _) = spinning(omega, 41);
        let method = crate::settings::Method::Report;
        let limit = crate::method::stepper(method).bound_factor() * link.bound(1.0).sigma;
        let (q0, v0) = link.initial_state();
        let ctl = StepControl {
            method,
            safety: 1.0,
            forced_dt: Some(ratio * limit),
            t_end: 0.4,
            output_interval: 0.01,
            log_change: 1.0,
            lookahead: false,
            enforce_bound: false,
        };
        (
            integrate(&mut link, &q0, &v0, &ctl).unwrap().verdict,
            ratio * limit,
        )
    }

    #[test]
    fn dyn_link_tension_bound_is_sharp() {
        // The two-step scheme is stable for ω_max τ ≤ 1 and the new limit (½σ) overestimates
        // the true ω_max by < 2 % (elem_ test above): 0.95 × the limit at full rate runs to the
        // end, 1.05 × grows without bound once the ramp brings the rate near Ω = 60 rad/s.
        let omega = 60.0;
        let (stable, _) = forced_run(omega, 0.95);
        assert!(
            matches!(stable, data::StabilityVerdict::Completed),
            "0.95 × bound: {stable:?}"
        );
        let (unstable, dt) = forced_run(omega, 1.05);
        match &unstable {
            data::StabilityVerdict::Stopped { diagnostic } => {
                eprintln!("1.05 × bound: {diagnostic}");
                // it diverged only where the forced step exceeds the limit at the current rate
                let (link, _) = spinning(omega, 41);
                assert!(
                    dt > 0.5 * link.bound(diagnostic.t).sigma,
                    "t = {}",
                    diagnostic.t
                );
            }
            v => panic!("1.05 × bound should diverge: {v:?}"),
        }
        // The report's bending-only limit lies above 1.05 × the new one here, so a step it
        // allows diverges: the test discriminates the two bounds.
        let (link, _) = spinning(omega, 41);
        let rho_a = link.m[0] / link.h;
        let report = (link.h.powi(4) * rho_a / (4.0 * link.ei)).sqrt();
        assert!(report > 1.05 * link.bound(1.0).sigma);
        // Through the public path, the forced step is refused when the rate has grown enough,
        // with the new kind and the station in the error.
        let (_, scene) = spinning(omega, 41);
        let mut s = Settings::default();
        s.time.dt = Some(1.05 * 0.5 * link.bound(1.0).sigma);
        s.time.t_end = Some(0.4);
        let fs = crate::settings::FdmSettings::from_settings(&s).unwrap();
        match simulate(&scene, &s, &fs) {
            Err(FdmError::StabilityBound {
                t, kind, location, ..
            }) => {
                eprintln!("refused at t = {t}: {kind} at {location}");
                assert!(kind.contains("tension"));
                assert!(location.contains("station"));
                assert!(t > 0.0 && t <= 0.2);
            }
            other => panic!("expected a refusal: {other:?}"),
        }
    }
}
