//! The rocket's outputs: the channels (definitions of docs/rocket.md, module docs of
//! [`super`]) sampled from a state, and the energy ledger's rows.

use data::EnergyLedger;
use data::channel::spec;

use super::driver::RocketDriver;
use super::model::Model;

/// Channel list (the same names and order as the other backends).
pub fn channel_specs(model: &Model, stations: usize) -> Vec<(String, &'static str)> {
    let mut c = vec![
        spec::rocket_x(),
        spec::rocket_y(),
        spec::rocket_theta(),
        spec::rocket_mass(),
        spec::rocket_vx(),
        spec::rocket_vy(),
    ];
    c.extend((0..stations).map(spec::rocket_axial));
    c.extend((0..stations).map(spec::rocket_transverse));
    for j in 1..=model.masses.len() {
        c.push(spec::rocket_mass_axial(j));
        c.push(spec::rocket_mass_transverse(j));
    }
    c
}

/// Samples the channels of [`channel_specs`].
pub fn observe(model: &Model, t: f64, q: &[f64], v: &[f64], stations: usize, out: &mut Vec<f64>) {
    out.clear();
    let m1 = model.m1(t);
    let mass = model.mass_form(m1, &model.t_xi, &model.t_xi);
    let pos: Vec<f64> = (0..model.n).map(|i| model.x_ref[i] + q[i]).collect();
    let cm = (
        model.mass_form(m1, &model.t_xi, &pos) / mass,
        model.mass_form(m1, &model.t_eta, &pos) / mass,
    );
    let vel = (
        model.mass_form(m1, &model.t_xi, v) / mass,
        model.mass_form(m1, &model.t_eta, v) / mass,
    );
    let (c, s) = (model.theta0.cos(), model.theta0.sin());
    let axis = model.mean_axis(q, v);
    out.push(c * cm.0 - s * cm.1);
    out.push(s * cm.0 + c * cm.1);
    out.push(model.theta0 + axis.phi);
    out.push(mass);
    out.push(c * vel.0 - s * vel.1);
    out.push(s * vel.0 + c * vel.1);
    let rel: Vec<(f64, f64)> = (0..stations)
        .map(|k| {
            let x = k as f64 * model.length / (stations - 1) as f64;
            let (u, w) = model.at(&model.point(x), q);
            axis.relative(model.x_bar, x, x + u, w)
        })
        .collect();
    out.extend(rel.iter().map(|r| r.0));
    out.extend(rel.iter().map(|r| r.1));
    for (j, dm) in model.masses.iter().enumerate() {
        let (iu, iw) = model.mass_dofs(j);
        let (u, w) = axis.relative(model.x_bar, dm.at.x, dm.at.x + q[iu], q[iw]);
        out.push(u);
        out.push(w);
    }
}

/// The ledger's row at the driver's state.
pub fn push_ledger(st: &RocketDriver, ledger: &mut EnergyLedger) {
    let w = st.works;
    ledger.push(
        st.steps.state.t,
        &st.stored(),
        &[w.thrust, w.pressure, w.coriolis],
        &[w.damper, w.outflow],
    );
}

/// Momentum P = T_ξᵀM v, T_ηᵀM v (launch axes) — used by tests.
pub fn momentum(model: &Model, t: f64, v: &[f64]) -> (f64, f64) {
    let m1 = model.m1(t);
    (
        model.mass_form(m1, &model.t_xi, v),
        model.mass_form(m1, &model.t_eta, v),
    )
}

/// Kinetic energy ½vᵀM(t)v — used by tests.
pub fn kinetic(model: &Model, t: f64, v: &[f64]) -> f64 {
    0.5 * model.mass_form(model.m1(t), v, v)
}
