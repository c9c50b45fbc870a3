//! The dynamics run: set-up, sampling of the channels and the ledger (module docs of
//! [`super`], "Dynamics").

use std::time::Instant;

use data::scene::{LinkField, LinkInitialShape, PayloadLink};
use data::{
    EnergyLedger, FemSettings, Observables, RunResult, Scene, StabilityVerdict, channel,
    ledger_term,
};

use super::driver::LinkDriver;
use super::model::Model;
use super::modes::slot_of;
use super::plan::{build, elements};
use super::statics::static_sag;
use super::step_rule::{default_step, fit};
use crate::band::BorderedBand;
use crate::driver::fixed_steps::QuarterRetries;
use crate::element::beam3d::{PHI, V, W};
use crate::error::FemError;
use crate::settings;
use crate::settings::Method;
use crate::system::System;

/// Everything `simulate` needs, built once (benches reuse it).
pub struct Prepared {
    pub stepper: LinkDriver,
    pub h: f64,
    pub t_end: f64,
    pub output_interval: f64,
    pub stations: usize,
}

/// The stepper, step and output settings of a run of `l`, the payload link of `scene`.
pub fn prepare(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
) -> Result<Prepared, FemError> {
    let n_el = elements(settings)?;
    let method = settings.method.unwrap_or(Method::ImplicitMidpoint);
    if settings.rtol.is_some() || settings.atol.is_some() {
        return Err(FemError::unsupported(
            "fem payload link: adaptive steps (`time.rtol`/`time.atol`); use --dt",
        ));
    }
    let dt_user = settings::positive("time.dt", settings.dt)?;
    let t_end = settings::positive("time.t_end", settings.t_end)?.unwrap_or(scene.simulation.t_end);
    let out = scene.simulation.output_interval;
    let md = build(l, n_el)?;
    let d = if l.initial_shape == LinkInitialShape::StaticSag {
        static_sag(&md)?
    } else {
        vec![0.0; md.n]
    };
    let rho_inf = default_rho_inf(&md);
    match method {
        Method::CentralDifference => {
            // Explicit: the step under its stability bound at the initial state (Kelvin–Voigt
            // damping of the kHz axial and torsion modes included).
            let mut driver = LinkDriver::new(md, &d, method, out, rho_inf)?;
            let mut res = vec![0.0; driver.steps.system.ndof()];
            let (bound, dof) = crate::method::central_difference::stability_bound(
                &mut driver.steps.system,
                &driver.steps.state,
                &mut res,
            )?;
            let h = match dt_user {
                Some(dt) if dt > bound => {
                    return Err(FemError::StabilityBound {
                        dt,
                        bound,
                        bound_kind: crate::method::central_difference::BOUND_KIND.into(),
                        location: describe_dof(&driver.steps.system.model, dof),
                    });
                }
                Some(dt) => dt,
                None => fit(crate::run::DEFAULT_SAFETY * bound, out),
            };
            driver.steps.h_nominal = h;
            Ok(Prepared {
                stepper: driver,
                h,
                t_end,
                output_interval: out,
                stations: scene.simulation.field_stations.max(2),
            })
        }
        _ => {
            let h = match dt_user {
                Some(h) => h,
                None => fit(default_step(&md, &d, t_end, out)?.min(out), out),
            };
            Ok(Prepared {
                stepper: LinkDriver::new(md, &d, method, h, rho_inf)?,
                h,
                t_end,
                output_interval: out,
                stations: scene.simulation.field_stations.max(2),
            })
        }
    }
}

/// Generalized-α's spectral radius for the link: 1 (no numerical damping, as the implicit
/// midpoint rule), or 0.9 when the rod carries the axial field, whose kHz modes the default
/// step does not resolve (the chain's rule, [`crate::run::default_rho_inf`]).
fn default_rho_inf(md: &Model) -> f64 {
    if md.fields.contains(&LinkField::Axial) {
        0.9
    } else {
        1.0
    }
}

/// A DOF of the link by name: the base angle or the slot and node of a field DOF.
fn describe_dof(md: &Model, dof: usize) -> String {
    if dof >= md.n {
        return "joint1 angle".into();
    }
    let node = dof / md.layout.per_node + 1;
    let slot = ["u", "v", "v′", "w", "w′", "φ"][slot_of(md, dof)];
    format!("link1 node {node} {slot}")
}

/// Torque of the base at the driver's state: the motor law of a free base; for a prescribed
/// base, the torque its motion needs, with d̈ from the field equations M d̈ = −R_d(t, d, ḋ, 0)
/// (`mass_lu`: M factorized once; `scratch`: two vectors of n).
fn state_torque(
    st: &mut LinkDriver,
    mass_lu: &mut BorderedBand,
    scratch: &mut [Vec<f64>; 2],
) -> f64 {
    let s = &st.steps.state;
    if st.steps.system.free_base() {
        return st.steps.system.model.motor_torque(s.t);
    }
    let [zero, acc] = scratch;
    st.steps.system.residual(s.t, &s.q, &s.qd, zero, acc);
    acc.iter_mut().for_each(|v| *v = -*v);
    mass_lu.solve_in_place(acc);
    st.steps.system.base_torque(s.t, &s.q, &s.qd, acc)
}

/// Samples the channels of [`channel::payload_link`] (the fields the rod carries) into `buf`.
fn sample(st: &LinkDriver, torque: f64, stations: usize, buf: &mut Vec<f64>) {
    buf.clear();
    let sys = &st.steps.system;
    let md = &sys.model;
    let s = &st.steps.state;
    let d = &s.q[..md.n];
    let (theta, rate, _) = sys.base(s.t, &s.q, &s.qd, &s.qdd);
    let [x, y, z] = md.payload_position(d);
    let (c, sn) = (theta.cos(), theta.sin());
    buf.extend([theta, rate, torque, c * x - sn * y, sn * x + c * y, z]);
    let has = |f| md.fields.contains(&f);
    let t = &md.tip;
    for (j, q) in channel::PAYLOAD_LINK_TIP.iter().enumerate() {
        if !has(q.field) {
            continue;
        }
        // Entries in the registry's order: u, v, w, φ, v′, w′ at the tip.
        let row = [&t.u, &t.v, &t.w, &t.phi, &t.v_slope, &t.w_slope][j];
        buf.push(row.dot(d));
    }
    for p in channel::PAYLOAD_LINK_PROFILES.iter() {
        let component = match p.field {
            LinkField::Horizontal => V,
            LinkField::Vertical => W,
            LinkField::Torsion => PHI,
            LinkField::Axial => continue,
        };
        if !has(p.field) {
            continue;
        }
        for k in 0..stations {
            let xk = md.length * k as f64 / (stations - 1) as f64;
            buf.push(md.field_at(d, component, xk));
        }
    }
}

/// Ledger layout: stored, inputs, dissipation names.
fn ledger_names(md: &Model) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
    let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
    if md.has_gravity {
        stored.push(ledger_term::GRAVITY);
    }
    if md.spring().0 > 0.0 {
        stored.push(ledger_term::JOINT_SPRING);
    }
    let inputs = if md.free_base() {
        vec![ledger_term::APPLIED_TORQUE]
    } else {
        vec![ledger_term::PRESCRIBED_MOTION]
    };
    let mut diss = Vec::new();
    if md.motor_friction > 0.0 {
        diss.push(ledger_term::JOINT_DAMPER);
    }
    for (f, _) in &md.c_field {
        diss.push(ledger_term::kelvin_voigt_of(*f));
    }
    (stored, inputs, diss)
}

fn push_ledger(st: &LinkDriver, ledger: &mut EnergyLedger) {
    let sys = &st.steps.system;
    let md = &sys.model;
    let s = &st.steps.state;
    let n = md.n;
    let (d, dd) = (&s.q[..n], &s.qd[..n]);
    let (theta, rate, _) = sys.base(s.t, &s.q, &s.qd, &s.qdd);
    let mut stored = [0.0; 4];
    let mut k = 0;
    stored[k] = md.kinetic(d, rate, dd);
    k += 1;
    stored[k] = md.strain(d);
    k += 1;
    if md.has_gravity {
        stored[k] = md.gravity(d);
        k += 1;
    }
    if md.spring().0 > 0.0 {
        stored[k] = md.joint_spring(theta);
        k += 1;
    }
    let w = &st.works;
    let input = [if md.free_base() {
        w.applied_torque
    } else {
        w.prescribed_motion
    }];
    let mut diss = [0.0; 5];
    let mut nd = 0;
    if md.motor_friction > 0.0 {
        diss[nd] = w.joint_damper;
        nd += 1;
    }
    for kv in &w.kelvin_voigt[..md.c_field.len()] {
        diss[nd] = *kv;
        nd += 1;
    }
    ledger.push(s.t, &stored[..k], &input, &diss[..nd]);
}

/// A run of `l`, the payload link of `scene`.
pub fn simulate(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        mut stepper,
        h,
        t_end,
        output_interval,
        stations,
    } = prepare(scene, l, settings)?;
    let md = &stepper.steps.system.model;
    let specs = channel::payload_link(&md.fields, stations);
    let mut obs = Observables::with_channels(&specs);
    let (s, i, d) = ledger_names(md);
    let mut ledger = EnergyLedger::new(&s, &i, &d);
    let n = md.n;
    let free = md.free_base();
    // Mass matrix factorized once: the torque a prescribed base needs at the output samples.
    let mut mass_lu = BorderedBand::new(n, 0, md.layout.half_bandwidth());
    if !free {
        for r in 0..n {
            for c in md.m.cols(r) {
                mass_lu.add(r, c, md.m.get(r, c));
            }
        }
        mass_lu.factorize()?;
    }
    let mut scratch = [vec![0.0; n], vec![0.0; n]];
    let mut buf = Vec::with_capacity(specs.len());
    let torque = state_torque(&mut stepper, &mut mass_lu, &mut scratch);
    sample(&stepper, torque, stations, &mut buf);
    obs.push(0.0, &buf);
    push_ledger(&stepper, &mut ledger);
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut verdict = StabilityVerdict::Completed;
    'outer: for k in 1..=n_out {
        let t_out = (k as f64 * output_interval).min(t_end);
        while stepper.steps.state.t < t_out - 1e-9 * h {
            // Steps of h onto the next output time or motor-law breakpoint (a shorter last
            // step only when h does not divide the stretch); the end is snapped to the stop
            // time against round-off.
            let t_stop = stepper.next_breakpoint().map_or(t_out, |b| b.min(t_out));
            let rest = t_stop - stepper.steps.state.t;
            let hk = if rest < h * (1.0 - 1e-9) { rest } else { h };
            let mut t1 = stepper.steps.state.t + hk;
            if (t1 - t_stop).abs() < 1e-9 * h {
                t1 = t_stop;
            }
            if let Err(e) = stepper.step(hk, t1) {
                verdict = StabilityVerdict::Stopped {
                    diagnostic: e.into_stop_diagnostic()?,
                };
                break 'outer;
            }
        }
        let torque = state_torque(&mut stepper, &mut mass_lu, &mut scratch);
        sample(&stepper, torque, stations, &mut buf);
        if buf.iter().any(|v| !v.is_finite()) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: crate::error::non_finite_state(stepper.steps.state.t),
            };
            break;
        }
        obs.push(stepper.steps.state.t, &buf);
        push_ledger(&stepper, &mut ledger);
    }
    Ok(crate::run::run_result(
        scene,
        settings,
        obs,
        ledger,
        Vec::new(),
        stepper.steps.counters.cost(n + usize::from(free), start),
        verdict,
    ))
}
