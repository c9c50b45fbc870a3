//! Exploration of the constrained arm (seed 001, bilateral circular wall with Coulomb friction):
//! one run with scene variations chosen by environment variables, printing the final state, a
//! history against the rigid closed form, the friction work, the stick–slip events and the cost.
//!
//! `MODES=3 SCALE=10 GRAVITY=1 TEND=2 cargo run --release -p modal --example friction_explore`
//!
//! Variables: `MODES` (default 3), `TEND`, `RTOL` (default 1e-8), `SCALE` (multiplies EI and EA),
//! `FLEXURE` (inextensible link with foreshortening instead of the axial field), `GRAVITY`
//! (vertical pendulum without hub torque), `KV` (Kelvin–Voigt γ), `METHOD`, `POLY` (polynomial
//! basis instead of clamped-free).

use data::scene::{Gravity, TorqueLaw};
use data::{Discretization, Event, RunResult, Scene, Settings, TimeStepping, load_scene};
use modal::simulate::{
    FRICTION_FORCE_CHANNEL, FinalState, SLIP_VELOCITY_CHANNEL, simulate_detailed,
};

fn arm() -> Scene {
    load_scene("constrained-arm").expect("catalog scene")
}

fn stick_slips(r: &RunResult) -> Vec<(f64, bool)> {
    r.events
        .iter()
        .filter_map(|e| match e {
            Event::StickSlip { t, sticking, .. } => Some((*t, *sticking)),
            _ => None,
        })
        .collect()
}

fn print_summary(r: &RunResult, f: &FinalState) {
    let ch = |name: &str| r.observables.get(name).unwrap();
    let last = |name: &str| *ch(name).values.last().unwrap();
    println!(
        "θ(T) {:.9} θ̇(T) {:.9} λ(T) {:.6e} λt(T) {:.6e} vt(T) {:.6e}",
        last("joint1.angle"),
        last("joint1.rate"),
        last("contact1.normal_force"),
        last(FRICTION_FORCE_CHANNEL),
        last(SLIP_VELOCITY_CHANNEL)
    );
    let rigid = rigid_closed_form(&arm());
    for i in (0..ch("joint1.angle").values.len()).step_by(50) {
        let t = r.observables.time[i];
        println!(
            "t {t:.3} θ {:.6} rigid {:.6} θ̇ {:.5} λ {:.4} vt {:.4} v(L) {:.3e}",
            ch("joint1.angle").values[i],
            rigid(t).0,
            ch("joint1.rate").values[i],
            ch("contact1.normal_force").values[i],
            ch(SLIP_VELOCITY_CHANNEL).values[i],
            ch("link1.tip_deflection").values[i],
        );
    }
    let k = r
        .ledger
        .dissipation
        .iter()
        .position(|d| d.name == "friction");
    println!(
        "friction work {:?} closure {:.3e}",
        k.map(|k| *r.ledger.dissipation[k].values.last().unwrap()),
        r.ledger.relative_closure()
    );
    let ev = stick_slips(r);
    println!(
        "{} stick-slip events, first {:?}, last {:?}",
        ev.len(),
        &ev[..ev.len().min(8)],
        ev.last()
    );
    println!("{:?}", f.contact);
    println!(
        "steps {} rejected {} rhs {} wall {:.3}s verdict {:?}",
        r.cost.steps, r.cost.rejected_steps, r.cost.rhs_evaluations, r.cost.wall_time_s, r.verdict
    );
}

/// The arm in a vertical plane without hub torque, released from rest 0.5 rad beside the
/// bottom: a pendulum whose tip slides on the wall with friction until it sticks.
fn pendulum(scene: &mut Scene) {
    scene.gravity = Some(Gravity {
        vector: [0.0, -9.81],
    });
    scene.links[0].joint.torque = Some(TorqueLaw::Constant {
        value: 0.0,
        until: None,
    });
    scene.links[0].joint.initial_angle = -std::f64::consts::FRAC_PI_2 + 0.5;
}

/// Seed 001 eq. 71 from rest: θ = ln cosh(√(ab) t)/b, θ̇ = √(a/b) tanh(√(ab) t), with
/// a = τ/J, b = μ(M + ρAL/3)L²/J, J = J_h + ρAL³/3 + ML² (derivation in verify's
/// `ConstrainedRigidLink`; recomputed here so that modal's tests do not depend on verify).
fn rigid_closed_form(scene: &Scene) -> impl Fn(f64) -> (f64, f64) + use<> {
    let l = &scene.links[0];
    let (len, ra, m) = (l.length, l.mass_per_length, l.tip_mass.unwrap_or(0.0));
    let j = l.joint.hub_inertia.unwrap_or(0.0) + ra * len.powi(3) / 3.0 + m * len * len;
    let tau = l.joint.torque.as_ref().unwrap().torque(0.0);
    let mu = scene.contacts[0].friction;
    let (a, b) = (tau / j, mu * (m + ra * len / 3.0) * len * len / j);
    let c = (a * b).sqrt();
    move |t: f64| ((c * t).cosh().ln() / b, (a / b).sqrt() * (c * t).tanh())
}

fn main() {
    let env = |k: &str| std::env::var(k).ok();
    let parse = |k: &str| -> Option<f64> {
        env(k).map(|s| {
            s.parse()
                .unwrap_or_else(|_| panic!("{k}={s}: not a number"))
        })
    };
    let modes = parse("MODES").map_or(3, |v| v as usize);
    let rtol = parse("RTOL").unwrap_or(1e-8);
    let mut scene = arm();
    if let Some(s) = parse("SCALE") {
        scene.links[0].bending_stiffness *= s;
        if let Some(ea) = scene.links[0].axial_stiffness.as_mut() {
            *ea *= s;
        }
    }
    if env("FLEXURE").is_some() {
        scene.links[0].axial = false;
        scene.links[0].foreshortening = true;
    }
    if env("GRAVITY").is_some() {
        pendulum(&mut scene);
    }
    if let Some(kv) = parse("KV") {
        scene.links[0].kelvin_voigt = Some(kv);
    }
    let settings = Settings {
        discretization: Discretization {
            modes: Some(modes),
            basis: Some(if env("POLY").is_some() {
                data::Basis::Poly
            } else {
                data::Basis::ClampedFree
            }),
            ..Default::default()
        },
        time: TimeStepping {
            rtol: Some(rtol),
            atol: Some(rtol * 1e-2),
            t_end: parse("TEND"),
            method: env("METHOD"),
            ..Default::default()
        },
    };
    match simulate_detailed(&scene, &settings) {
        Ok((r, f)) => print_summary(&r, &f),
        Err(e) => eprintln!("{e}"),
    }
}
