//! The payload link as a [`System`] of the backend's integrators, with its [`Outputs`].
//!
//! **Coordinates.** q = (θ, q_f) with a free base, q = q_f with a prescribed one (θ(t), θ̇(t),
//! θ̈(t) are then the motion's kinematics at the evaluation time, not coordinates); v likewise.
//! The field coordinates q_f are those of [`PayloadLinkModel`] (stations 1…r × carried fields).
//!
//! **Forces with the damping implicit** ([`System::implicit_kick`], the velocity form's closing
//! kick): the Schur elimination of θ̈ (module docs of [`super`]) on the step matrix
//! A = M_ff + ½τC instead of M_ff,
//!
//!   A q̈ + m θ̈ = F(q, θ̇_pred, v_pred) − C v_{j+½},
//!
//! with the Kelvin–Voigt damping C at the drift velocity v_{j+½} and the other velocity terms
//! (Coriolis, the θ equation's Ṁ_θθθ̇ + (Bq̇)·q̇, motor friction) at the predicted velocity
//! v_pred = v_{j+½} + ½τa_j: v_{j+1} = v_{j+½} + ½τq̈ then carries −½τM_ff⁻¹C v_{j+1}
//! (Crank–Nicolson in the damping). A is factored once per step length ([`SpdFactor`]; its
//! solve workspace is allocated with the factor, so a step allocates nothing). The start level
//! ([`System::accel`]) is evaluated the same way with v_{j+½} = v_0, so the damping is implicit
//! in the first opening kick too.
//!
//! **Base observables.** The torque (applied, or needed by a prescribed motion) comes out of
//! the θ equation with the accelerations, and a prescribed θ, θ̇ are no coordinates: the system
//! keeps them for the last two force evaluations and the observables interpolate them linearly
//! in t between those two levels, as the driver's recorder does with q and v (it samples only
//! inside the step just taken).

// Index loops run over several parallel level buffers at once.
#![allow(clippy::needless_range_loop)]

use std::cell::RefCell;

use data::channel;

use super::spd::{SpdFactor, Triplets};
use super::{BaseDrive, PayloadLinkModel, apply};
use crate::error::FdmError;
use crate::linalg::dot;
use crate::output::{Outputs, sample_field};
use crate::system::{Bound, BoundKind, DriftVelocities, System, law_jumps, law_torque};

/// The base's state at one force evaluation (what the coordinates do not carry).
#[derive(Debug, Clone, Copy, Default)]
struct BaseLevel {
    t: f64,
    th: f64,
    rate: f64,
    torque: f64,
}

impl BaseLevel {
    /// θ, θ̇ and the torque at t ∈ [a.t, b.t], linear between the levels.
    fn lerp(a: &BaseLevel, b: &BaseLevel, t: f64) -> (f64, f64, f64) {
        let s = if b.t > a.t {
            ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let l = |x: f64, y: f64| x + s * (y - x);
        (l(a.th, b.th), l(a.rate, b.rate), l(a.torque, b.torque))
    }
}

/// The payload link stepped by the backend's methods (module docs).
#[derive(Debug)]
pub struct PayloadLinkSystem {
    model: PayloadLinkModel,
    /// index of the first field coordinate in q: 1 with a free base (`q[0]` = θ), else 0
    off: usize,
    /// the binding field bound (kind [`BoundKind::LinkField`], site = station)
    bound: Bound,
    /// C = Σ ratio_f K_f
    c: Triplets,
    /// (τ, the factor of A = M_ff + ½τC)
    step: Option<(f64, SpdFactor)>,
    factorizations: usize,
    f: Vec<f64>,
    m: Vec<f64>,
    y: Vec<f64>,
    /// the level velocities the powers are taken at
    v_end: Vec<f64>,
    power: Vec<f64>,
    /// base states of the previous and the latest force evaluation
    levels: [BaseLevel; 2],
    /// scratch of the stored energies (`&self`)
    scratch: RefCell<Vec<f64>>,
    /// the jump the step being closed ends on ([`System::close_stretch_at`])
    closing: Option<f64>,
}

impl PayloadLinkSystem {
    /// The system of `model`; the step matrix is factored by [`Self::set_step`].
    pub fn new(model: PayloadLinkModel) -> Result<Self, FdmError> {
        let (field, sigma, station) = model
            .field_bounds()
            .into_iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .ok_or_else(|| {
                FdmError::Unsupported("fdm: a payload link without any elastic field".into())
            })?;
        let n = model.n;
        let off = usize::from(model.free_base());
        let (_, inputs, diss) = model.ledger_names();
        Ok(PayloadLinkSystem {
            off,
            bound: Bound {
                sigma,
                kind: BoundKind::LinkField(field),
                site: station,
            },
            c: model.damping_matrix(),
            step: None,
            factorizations: 0,
            f: vec![0.0; n],
            m: vec![0.0; n],
            y: vec![0.0; n],
            v_end: vec![0.0; n + off],
            power: vec![0.0; inputs.len() + diss.len()],
            levels: [BaseLevel::default(); 2],
            scratch: RefCell::new(vec![0.0; n]),
            closing: None,
            model,
        })
    }

    /// Factors A = M_ff + ½τC for the step τ (nothing to do if it already is).
    pub fn set_step(&mut self, tau: f64) -> Result<(), FdmError> {
        if self.step.as_ref().is_some_and(|(t, _)| *t == tau) {
            return Ok(());
        }
        let a = SpdFactor::factor(
            self.model.n,
            &self.model.step_matrix_parts(&self.c, tau),
            "the field mass matrix",
        )?;
        self.step = Some((tau, a));
        self.factorizations += 1;
        Ok(())
    }

    /// Factorizations of the step matrix so far.
    pub fn factorizations(&self) -> usize {
        self.factorizations
    }

    /// (q, v) at t = 0: θ(0), θ̇(0) for a free base; the fields straight or in the static sag,
    /// at rest relative to the base.
    pub fn initial_state(&self, sag: bool) -> Result<(Vec<f64>, Vec<f64>), FdmError> {
        let md = &self.model;
        let mut q = Vec::with_capacity(md.n + self.off);
        let mut v = vec![0.0; md.n + self.off];
        if self.off == 1 {
            q.push(md.theta0);
            v[0] = md.rate0;
        }
        if sag {
            q.extend(md.static_sag()?);
        } else {
            q.resize(md.n + self.off, 0.0);
        }
        Ok((q, v))
    }

    /// Accelerations at t from the positions q, the damping at `v_half` and the other velocity
    /// terms at `v` (module docs); returns the base state of this level.
    fn evaluate(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_half: &[f64],
        a: &mut [f64],
    ) -> BaseLevel {
        let o = self.off;
        let closing = self.closing;
        let PayloadLinkSystem {
            model: md,
            c,
            step,
            f,
            m,
            y,
            ..
        } = self;
        let (qf, vf) = (&q[o..], &v[o..]);
        let (th, rate, prescribed) = match md.prescribed_at(t) {
            Some((th, rate, thdd)) => (th, rate, Some(thdd)),
            None => (q[0], v[0], None),
        };
        let Some((_, factor)) = step.as_mut() else {
            // no step matrix: no accelerations (the driver stops on the non-finite state)
            a.fill(f64::NAN);
            return BaseLevel {
                t,
                th,
                rate,
                torque: f64::NAN,
            };
        };
        md.field_forces(qf, vf, rate, f);
        y.fill(0.0);
        c.mul_add(&v_half[o..], y);
        for i in 0..md.n {
            f[i] -= y[i];
        }
        md.m_theta(qf, m);
        let mtt = md.m_thth(qf);
        let vel = md.theta_velocity_terms(qf, vf, rate);
        let torque = match &md.drive {
            BaseDrive::Free {
                law,
                stiffness,
                damping,
                set_point,
            } => {
                let ext = law_torque(law.as_ref(), t, closing);
                let rhs = ext - damping * rate - stiffness * (th - set_point) - vel;
                let acc = &mut a[o..];
                acc.copy_from_slice(f);
                factor.solve_in_place(acc);
                y.copy_from_slice(m);
                factor.solve_in_place(y);
                let thdd = (rhs - dot(m, acc)) / (mtt - dot(m, y));
                for i in 0..md.n {
                    acc[i] -= y[i] * thdd;
                }
                a[0] = thdd;
                ext
            }
            BaseDrive::Prescribed(_) => {
                // θ̈ of the motion (`prescribed_at` is Some for a prescribed drive)
                let thdd = prescribed.unwrap_or(f64::NAN);
                let acc = &mut a[o..];
                for i in 0..md.n {
                    acc[i] = f[i] - m[i] * thdd;
                }
                factor.solve_in_place(acc);
                mtt * thdd + dot(m, acc) + vel
            }
        };
        BaseLevel {
            t,
            th,
            rate,
            torque,
        }
    }

    /// Powers at a level with velocities `self.v_end`, base rate `rate` and torque `torque`:
    /// input, joint damper (if on), each Kelvin–Voigt field.
    fn store_powers(&mut self, rate: f64, torque: f64) {
        let md = &self.model;
        let out = &mut self.power;
        let vf = &self.v_end[self.off..];
        let mut k = 0;
        match &md.drive {
            BaseDrive::Prescribed(_) => {
                out[k] = torque * rate;
                k += 1;
            }
            BaseDrive::Free { law, damping, .. } => {
                if law.is_some() {
                    out[k] = torque * rate;
                    k += 1;
                }
                if *damping != 0.0 {
                    out[k] = damping * rate * rate;
                    k += 1;
                }
            }
        }
        for &(_, kf, ratio) in &md.damping {
            out[k] = ratio * md.stiffness[kf].1.form(vf, vf);
            k += 1;
        }
    }

    /// The base's (θ, θ̇, torque) at t: θ and θ̇ from the coordinates with a free base, else
    /// interpolated between the last two levels like the torque (module docs).
    fn base_at(&self, t: f64, q: &[f64], v: &[f64]) -> (f64, f64, f64) {
        let (th, rate, torque) = BaseLevel::lerp(&self.levels[0], &self.levels[1], t);
        if self.off == 1 {
            (q[0], v[0], torque)
        } else {
            (th, rate, torque)
        }
    }
}

impl System for PayloadLinkSystem {
    fn dofs(&self) -> usize {
        self.model.n + self.off
    }

    fn jumps(&self) -> Vec<f64> {
        match &self.model.drive {
            BaseDrive::Free { law, .. } => law_jumps(law),
            BaseDrive::Prescribed(_) => Vec::new(),
        }
    }

    fn close_stretch_at(&mut self, jump: Option<f64>) {
        self.closing = jump;
    }

    /// The start level: the accelerations with the step matrix and the damping at `v` (module
    /// docs); begins the base's level history.
    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        let level = self.evaluate(t, q, v, v, a);
        self.levels = [level; 2];
        self.v_end.copy_from_slice(v);
        self.store_powers(level.rate, level.torque);
    }

    fn implicit_kick(
        &mut self,
        t: f64,
        q: &[f64],
        inertia: DriftVelocities,
        tau: f64,
        a: &mut [f64],
    ) -> bool {
        if self.set_step(tau).is_err() {
            // A = M_ff + ½τC lost definiteness: no accelerations (the driver stops)
            self.step = None;
        }
        let level = self.evaluate(t, q, inertia.predicted, inertia.current, a);
        self.levels = [self.levels[1], level];
        for i in 0..self.v_end.len() {
            self.v_end[i] = inertia.current[i] + 0.5 * tau * a[i];
        }
        let rate = if self.off == 1 {
            self.v_end[0]
        } else {
            level.rate
        };
        self.store_powers(rate, level.torque);
        true
    }

    fn powers(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.power);
    }

    /// The lumped operator's bound per carried field (constant: the centrifugal tension's share
    /// is not built, module docs of [`super`]).
    fn bound(&self, _t: f64) -> Bound {
        self.bound
    }

    fn stored_energies(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let md = &self.model;
        let (th, rate, _) = self.base_at(t, q, v);
        let (qf, vf) = (&q[self.off..], &v[self.off..]);
        out[0] = md.kinetic(qf, vf, rate, &mut self.scratch.borrow_mut());
        out[1] = md.strain(qf);
        let mut k = 2;
        if md.f_gravity.is_some() {
            out[k] = md.gravity_energy(qf);
            k += 1;
        }
        if let BaseDrive::Free {
            stiffness,
            set_point,
            ..
        } = &md.drive
            && *stiffness != 0.0
        {
            out[k] = 0.5 * stiffness * (th - set_point).powi(2);
        }
    }

    fn monitored(&self) -> std::ops::Range<usize> {
        self.off..self.dofs()
    }

    /// The Coriolis force −θ̇(B − Bᵀ)q̇ couples the field velocities whenever the base turns,
    /// besides the Kelvin–Voigt damping and the motor friction.
    fn damped(&self) -> bool {
        true
    }
}

impl Outputs for PayloadLinkSystem {
    fn channels(&self) -> Vec<(String, &'static str)> {
        channel::payload_link(&self.model.fields, self.model.field_stations)
    }

    /// Base angle, rate and torque, the inertial payload position (X, Y, Z), the tip
    /// quantities and the field profiles of the carried fields.
    fn observe(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let md = &self.model;
        let (th, rate, torque) = self.base_at(t, q, v);
        let q = &q[self.off..];
        let [u, v, w, phi] = [0, 1, 2, 3].map(|k| apply(&md.tip[k], q));
        let (sv, sw) = (apply(&md.slope_v, q), apply(&md.slope_w, q));
        let s_l: f64 = (0..md.r)
            .map(|s| 0.5 * md.h * (apply(&md.seg_v[s], q).powi(2) + apply(&md.seg_w[s], q).powi(2)))
            .sum();
        let c = md.offset;
        let x1 = md.length + u - s_l + c * (1.0 - 0.5 * (sv * sv + sw * sw));
        let y1 = v + c * sv;
        let z = w + c * sw;
        let (cs, sn) = (th.cos(), th.sin());
        out[..6].copy_from_slice(&[th, rate, torque, cs * x1 - sn * y1, sn * x1 + cs * y1, z]);
        let mut k = 6;
        // Tip quantities of the carried fields, in the registry's order (u, v, w, φ, v′, w′).
        for (value, tq) in [u, v, w, phi, sv, sw]
            .iter()
            .zip(&channel::PAYLOAD_LINK_TIP)
        {
            if md.fields.contains(&tq.field) {
                out[k] = *value;
                k += 1;
            }
        }
        let nf = md.field_stations;
        for f in channel::PAYLOAD_LINK_PROFILES.iter().map(|p| p.field) {
            if md.fields.contains(&f) {
                sample_field(
                    md.length,
                    md.h,
                    md.r,
                    |i| md.index(f, i).map_or(0.0, |ix| q[ix]),
                    &mut out[k..k + nf],
                );
                k += nf;
            }
        }
    }

    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        self.model.ledger_names()
    }

    fn describe(&self, b: &Bound) -> String {
        format!(
            "station {} (x = {:.4}) of {} stations",
            b.site,
            b.site as f64 * self.model.h,
            self.model.r + 1
        )
    }

    fn dof_name(&self, i: usize) -> String {
        let md = &self.model;
        if i < self.off {
            return "base angle θ".into();
        }
        let k = i - self.off;
        let nf = md.fields.len();
        let f = md.fields[k % nf];
        format!("{} {} at station {}", f.name(), f.symbol(), k / nf + 1)
    }
}
