//! Dynamics of the payload link: the central difference in its velocity form with implicit
//! Kelvin–Voigt damping (module docs of [`super`]), sampled outputs and the energy ledger.

// Index loops run over several parallel level buffers at once.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use data::scene::{LinkField, PayloadLink};
use data::{
    Cost, Diagnostic, EnergyLedger, Observables, RunResult, Scene, StabilityVerdict, channel,
    ledger_term,
};

use super::spd::{SpdFactor, Triplets};
use super::{BaseDrive, PayloadLinkModel, apply, dot};
use crate::error::FdmError;
use crate::output::sample_field;
use crate::settings::ValidatedSettings;

/// The step of a run: τ, the bound σ and the binding (field, station).
pub fn choose_step(
    model: &PayloadLinkModel,
    s: &ValidatedSettings,
) -> Result<(f64, f64, LinkField, usize), FdmError> {
    let (field, sigma, station) = model
        .field_bounds()
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or_else(|| {
            FdmError::Unsupported("fdm: a payload link without any elastic field".into())
        })?;
    let tau = match s.dt {
        Some(dt) => {
            if dt > sigma * (1.0 + 1e-12) {
                return Err(FdmError::StabilityBound {
                    t: 0.0,
                    dt,
                    bound: sigma,
                    kind: format!("{} ({})", field.name(), field.symbol()),
                    location: format!(
                        "station {station} (x = {:.4}) of {} stations",
                        station as f64 * model.h,
                        model.r + 1
                    ),
                });
            }
            dt
        }
        None => s.safety * sigma,
    };
    Ok((tau, sigma, field, station))
}

/// State of one time level.
#[derive(Clone)]
struct Level {
    th: f64,
    rate: f64,
    q: Vec<f64>,
    v: Vec<f64>,
    torque: f64,
}

/// The stepping machinery of one run (factorization and scratch reused every step).
struct Stepper<'a> {
    model: &'a PayloadLinkModel,
    /// A = M_ff + ½τC
    a: SpdFactor,
    /// C = Σ ratio_f K_f
    c: Triplets,
    f: Vec<f64>,
    m: Vec<f64>,
    y: Vec<f64>,
}

impl<'a> Stepper<'a> {
    fn new(model: &'a PayloadLinkModel, tau: f64) -> Result<Self, FdmError> {
        let c = model.damping_matrix();
        let a = SpdFactor::factor(
            model.n,
            &model.step_matrix_parts(&c, tau),
            "the field mass matrix",
        )?;
        let n = model.n;
        Ok(Stepper {
            model,
            a,
            c,
            f: vec![0.0; n],
            m: vec![0.0; n],
            y: vec![0.0; n],
        })
    }

    /// Accelerations (θ̈, q̈) at t for positions (θ, q), velocity-dependent forces at the
    /// predicted (rate, v), Kelvin–Voigt at the step-end velocity v_half + ½τq̈. Sets the torque
    /// of `lvl` (applied or needed).
    fn accel(&mut self, t: f64, lvl: &mut Level, v_half: &[f64], acc: &mut [f64]) -> f64 {
        let md = self.model;
        md.field_forces(&lvl.q, &lvl.v, lvl.rate, &mut self.f);
        self.y.fill(0.0);
        self.c.mul_add(v_half, &mut self.y);
        for i in 0..md.n {
            self.f[i] -= self.y[i];
        }
        md.m_theta(&lvl.q, &mut self.m);
        let mtt = md.m_thth(&lvl.q);
        let vel = md.theta_velocity_terms(&lvl.q, &lvl.v, lvl.rate);
        match &md.drive {
            BaseDrive::Prescribed(_) => {
                let (_, _, thdd) = md.prescribed_at(t).expect("prescribed");
                for i in 0..md.n {
                    acc[i] = self.f[i] - self.m[i] * thdd;
                }
                self.a.solve_in_place(acc);
                lvl.torque = mtt * thdd + dot(&self.m, acc) + vel;
                thdd
            }
            BaseDrive::Free {
                law,
                stiffness,
                damping,
                set_point,
            } => {
                let ext = law.as_ref().map_or(0.0, |l| l.torque(t));
                lvl.torque = ext;
                let rhs = ext - damping * lvl.rate - stiffness * (lvl.th - set_point) - vel;
                acc.copy_from_slice(&self.f);
                self.a.solve_in_place(acc);
                self.y.copy_from_slice(&self.m);
                self.a.solve_in_place(&mut self.y);
                let thdd = (rhs - dot(&self.m, acc)) / (mtt - dot(&self.m, &self.y));
                for i in 0..md.n {
                    acc[i] -= self.y[i] * thdd;
                }
                thdd
            }
        }
    }

    /// Powers at a level: input, joint damper (if on), each Kelvin–Voigt field.
    fn powers(&self, lvl: &Level, out: &mut [f64]) {
        let md = self.model;
        let mut k = 0;
        match &md.drive {
            BaseDrive::Prescribed(_) => {
                out[k] = lvl.torque * lvl.rate;
                k += 1;
            }
            BaseDrive::Free { law, damping, .. } => {
                if law.is_some() {
                    out[k] = lvl.torque * lvl.rate;
                    k += 1;
                }
                if *damping != 0.0 {
                    out[k] = damping * lvl.rate * lvl.rate;
                    k += 1;
                }
            }
        }
        for &(_, kf, ratio) in &md.damping {
            out[k] = ratio * md.stiffness[kf].1.form(&lvl.v, &lvl.v);
            k += 1;
        }
    }
}

impl PayloadLinkModel {
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

    fn stored(&self, lvl: &Level, scratch: &mut [f64], out: &mut [f64]) {
        out[0] = self.kinetic(&lvl.q, &lvl.v, lvl.rate, scratch);
        out[1] = self.strain(&lvl.q);
        let mut k = 2;
        if self.f_gravity.is_some() {
            out[k] = self.gravity_energy(&lvl.q);
            k += 1;
        }
        if let BaseDrive::Free {
            stiffness,
            set_point,
            ..
        } = &self.drive
            && *stiffness != 0.0
        {
            out[k] = 0.5 * stiffness * (lvl.th - set_point).powi(2);
        }
    }

    /// Observable channels (name, unit).
    pub fn channels(&self) -> Vec<(String, &'static str)> {
        let mut c = channel::payload_link(&self.fields, self.field_stations);
        c.push(channel::spec::step_size());
        c.push(channel::spec::stability_bound());
        c
    }

    /// Inertial payload position (X, Y, Z) and the tip quantities.
    fn observe(&self, lvl: &Level, tau: f64, sigma: f64, out: &mut [f64]) {
        let q = &lvl.q;
        let [u, v, w, phi] = [0, 1, 2, 3].map(|k| apply(&self.tip[k], q));
        let (sv, sw) = (apply(&self.slope_v, q), apply(&self.slope_w, q));
        let s_l: f64 = (0..self.r)
            .map(|s| {
                0.5 * self.h * (apply(&self.seg_v[s], q).powi(2) + apply(&self.seg_w[s], q).powi(2))
            })
            .sum();
        let c = self.offset;
        let x1 = self.length + u - s_l + c * (1.0 - 0.5 * (sv * sv + sw * sw));
        let y1 = v + c * sv;
        let z = w + c * sw;
        let (cs, sn) = (lvl.th.cos(), lvl.th.sin());
        out[..6].copy_from_slice(&[
            lvl.th,
            lvl.rate,
            lvl.torque,
            cs * x1 - sn * y1,
            sn * x1 + cs * y1,
            z,
        ]);
        let mut k = 6;
        // Tip quantities of the carried fields, in the registry's order (u, v, w, φ, v′, w′).
        for (value, tq) in [u, v, w, phi, sv, sw]
            .iter()
            .zip(&channel::PAYLOAD_LINK_TIP)
        {
            if self.fields.contains(&tq.field) {
                out[k] = *value;
                k += 1;
            }
        }
        let nf = self.field_stations;
        for f in channel::PAYLOAD_LINK_PROFILES.iter().map(|p| p.field) {
            if self.fields.contains(&f) {
                sample_field(
                    self.length,
                    self.h,
                    self.r,
                    |i| self.index(f, i).map_or(0.0, |ix| q[ix]),
                    &mut out[k..k + nf],
                );
                k += nf;
            }
        }
        out[k] = tau;
        out[k + 1] = sigma;
    }

    /// The state at t = 0: θ(0), θ̇(0); straight or the static sag, at rest relative to the base.
    fn initial_level(&self, sag: bool) -> Result<Level, FdmError> {
        let (th, rate) = match self.prescribed_at(0.0) {
            Some((a, b, _)) => (a, b),
            None => (self.theta0, self.rate0),
        };
        Ok(Level {
            th,
            rate,
            q: if sag {
                self.static_sag()?
            } else {
                vec![0.0; self.n]
            },
            v: vec![0.0; self.n],
            torque: 0.0,
        })
    }
}

/// Runs the scene.
pub fn simulate(
    scene: &Scene,
    p: &PayloadLink,
    s: &ValidatedSettings,
) -> Result<RunResult, FdmError> {
    let clock = Instant::now();
    let model = PayloadLinkModel::from_payload_link(scene, p, s.stations)?;
    let sag = p.initial_shape == data::scene::LinkInitialShape::StaticSag;
    let t_end = s.t_end.unwrap_or(scene.simulation.t_end);
    let interval = scene.simulation.output_interval;
    let (tau, sigma, _, _) = choose_step(&model, s)?;
    let mut stepper = Stepper::new(&model, tau)?;
    let n = model.n;

    let specs = model.channels();
    let mut obs = Observables::with_channels(&specs);
    let (st_names, in_names, dis_names) = model.ledger_names();
    let mut ledger = EnergyLedger::new(&st_names, &in_names, &dis_names);
    let n_in = in_names.len();
    let np = n_in + dis_names.len();
    let n_out = (t_end / interval - 1e-9).ceil().max(0.0) as usize;
    let times: Vec<f64> = (0..=n_out)
        .map(|k| (k as f64 * interval).min(t_end))
        .collect();
    obs.time.reserve(times.len());
    ledger.time.reserve(times.len());

    let free = model.free_base();
    let mut cur = model.initial_level(sag)?;
    let mut acc = vec![0.0; n];
    let v0 = cur.v.clone();
    let mut thdd = stepper.accel(0.0, &mut cur, &v0, &mut acc);
    let mut p_cur = vec![0.0; np];
    stepper.powers(&cur, &mut p_cur);
    let mut w_cur = vec![0.0; np];
    let mut w_new = vec![0.0; np];
    let mut p_new = vec![0.0; np];
    let mut next = cur.clone();
    let mut v_half = vec![0.0; n];
    let mut acc_new = vec![0.0; n];
    let mut interp = cur.clone();
    let mut row = vec![0.0; specs.len()];
    let mut stored = vec![0.0; st_names.len()];
    let mut work = vec![0.0; np];
    let mut scratch = vec![0.0; n];
    let mut cost = Cost {
        dofs: n + usize::from(free),
        factorizations: 1,
        rhs_evaluations: 1,
        ..Cost::default()
    };
    let mut verdict = StabilityVerdict::Completed;
    let mut t = 0.0;
    let mut next_out = 0;
    let peak0 = cur
        .q
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()))
        .max(model.length * 1e-12);
    let mut peak = peak0;

    let mut record = |ta: f64,
                      a: &Level,
                      wa: &[f64],
                      tb: f64,
                      b: &Level,
                      wb: &[f64],
                      next_out: &mut usize,
                      interp: &mut Level| {
        while *next_out < times.len() && times[*next_out] <= tb + 1e-12 * tb.abs().max(1e-30) {
            let tt = times[*next_out];
            let sfac = if tb > ta {
                ((tt - ta) / (tb - ta)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let lerp = |x: f64, y: f64| x + sfac * (y - x);
            interp.th = lerp(a.th, b.th);
            interp.rate = lerp(a.rate, b.rate);
            interp.torque = lerp(a.torque, b.torque);
            for i in 0..n {
                interp.q[i] = lerp(a.q[i], b.q[i]);
                interp.v[i] = lerp(a.v[i], b.v[i]);
            }
            for k in 0..np {
                work[k] = lerp(wa[k], wb[k]);
            }
            model.observe(interp, tau, sigma, &mut row);
            obs.push(tt, &row);
            model.stored(interp, &mut scratch, &mut stored);
            ledger.push(tt, &stored, &work[..n_in], &work[n_in..]);
            *next_out += 1;
        }
    };
    record(
        0.0,
        &cur,
        &w_cur,
        0.0,
        &cur,
        &w_cur,
        &mut next_out,
        &mut interp,
    );

    while next_out < times.len() {
        let t_new = t + tau;
        // kick–drift
        let rate_half = cur.rate + 0.5 * tau * thdd;
        for i in 0..n {
            v_half[i] = cur.v[i] + 0.5 * tau * acc[i];
            next.q[i] = cur.q[i] + tau * v_half[i];
            next.v[i] = v_half[i] + 0.5 * tau * acc[i];
        }
        match model.prescribed_at(t_new) {
            Some((th, rate, _)) => {
                next.th = th;
                next.rate = rate;
            }
            None => {
                next.th = cur.th + tau * rate_half;
                next.rate = rate_half + 0.5 * tau * thdd;
            }
        }
        let qmax = next.q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if !(qmax.is_finite() && next.th.is_finite()) || qmax > 1e8 * peak {
            verdict = StabilityVerdict::Stopped {
                diagnostic: Diagnostic {
                    t,
                    what: if qmax.is_finite() {
                        "elastic response grew without bound".into()
                    } else {
                        "non-finite state".into()
                    },
                    location: None,
                    why: format!("step {tau:.3e} against the bound {sigma:.3e}"),
                    remedy: "omit --dt or lower the safety factor".into(),
                },
            };
            break;
        }
        peak = peak.max(qmax);
        let thdd_new = stepper.accel(t_new, &mut next, &v_half, &mut acc_new);
        cost.rhs_evaluations += 1;
        for i in 0..n {
            next.v[i] = v_half[i] + 0.5 * tau * acc_new[i];
        }
        if free {
            next.rate = rate_half + 0.5 * tau * thdd_new;
        }
        stepper.powers(&next, &mut p_new);
        for k in 0..np {
            w_new[k] = w_cur[k] + 0.5 * tau * (p_cur[k] + p_new[k]);
        }
        record(
            t,
            &cur,
            &w_cur,
            t_new,
            &next,
            &w_new,
            &mut next_out,
            &mut interp,
        );
        cost.steps += 1;
        std::mem::swap(&mut cur, &mut next);
        std::mem::swap(&mut acc, &mut acc_new);
        std::mem::swap(&mut p_cur, &mut p_new);
        std::mem::swap(&mut w_cur, &mut w_new);
        thdd = thdd_new;
        t = t_new;
    }
    cost.wall_time_s = clock.elapsed().as_secs_f64();
    Ok(RunResult {
        backend: data::BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: s.request(),
        observables: obs,
        ledger,
        events: Vec::new(),
        cost,
        verdict,
    })
}
