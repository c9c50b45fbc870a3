//! Tip contact of the two-link chain (`barhorst-case1`, `-tipmass`, `-stiff-elbow`, `case2`).
//! Run: CARGO_TARGET_DIR=/work/targets/fdm cargo test --release -p fdm --test contact -- --nocapture

use data::{Backend, BackendError, Event, RunResult, Settings, StabilityVerdict, load_scene};
use fdm::FdmBackend;
use fdm::chain::TwoLinkChain;
use fdm::events::tip_contact::{ContactReport, EVENT_TIME_TOLERANCE};
use fdm::output::Outputs;
use fdm::runs::two_link_chain_with_contact as simulate;
use fdm::settings::ValidatedSettings;

mod common;
use common::channel;

fn settings(stations: usize, t_end: f64) -> Settings {
    let mut s = Settings::default();
    s.discretization.stations = Some(stations);
    s.time.t_end = Some(t_end);
    s
}

fn run(scene: &str, stations: usize, t_end: f64) -> (RunResult, ContactReport) {
    let scene = load_scene(scene).unwrap();
    let s = settings(stations, t_end);
    let (r, rep) = simulate(
        &scene,
        scene.planar_chain().unwrap(),
        &ValidatedSettings::from_settings(&s.fdm().unwrap()).unwrap(),
    )
    .unwrap();
    assert_eq!(r.verdict, StabilityVerdict::Completed, "{:?}", r.verdict);
    (r, rep)
}

fn impacts(r: &RunResult) -> Vec<(f64, f64, f64, f64, f64)> {
    r.events
        .iter()
        .filter_map(|e| match e {
            Event::Impact {
                t,
                impulse,
                momentum_residual,
                normal_velocity_after,
                kinetic_energy_lost,
                ..
            } => Some((
                *t,
                *impulse,
                *momentum_residual,
                *normal_velocity_after,
                *kinetic_energy_lost,
            )),
            _ => None,
        })
        .collect()
}

#[test]
fn dyn_contact_case1_impacts_balance_momentum_and_lose_energy() {
    let (r, _) = run("barhorst-case1", 11, 0.45);
    let imp = impacts(&r);
    // the loss is a difference of two kinetic energies: exact to their round-off
    let ke_peak = r
        .ledger
        .stored
        .iter()
        .find(|t| t.name == "kinetic")
        .expect("kinetic energy in the ledger")
        .values
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let round_off = 16.0 * f64::EPSILON * ke_peak;
    assert!(imp.len() >= 2, "{} impacts", imp.len());
    for &(t, lam, res, vn, lost) in &imp {
        println!(
            "impact t = {t:.6}: Λ = {lam:.5}, residual {res:.1e}, v_n+ = {vn:.1e}, ΔKE = {lost:.4e}"
        );
        assert!(res <= 1e-10, "momentum residual {res:e} at t = {t}");
        assert!(vn.abs() <= 1e-10, "normal velocity after {vn:e} at t = {t}");
        // Λ ≥ 0: pushes the tip off (a grazing re-contact gives Λ ≈ 0 to round-off)
        assert!(
            lam > -1e-9,
            "impulse {lam} must push the tip off the surface"
        );
        // ΔKE = ½(Gq̇⁻)²/(GM⁻¹Gᵀ) ≥ 0; at a grazing re-contact (Λ ≈ 0) it is zero up to the
        // round-off of the kinetic energies it is the difference of
        assert!(
            lost >= -round_off,
            "kinetic energy gained {lost:e} at t = {t} (round-off {round_off:e})"
        );
    }
    // the first impact is a real hit: a loss of order the kinetic energy of the fall
    assert!(imp[0].4 > 1.0, "first impact lost {}", imp[0].4);
}

#[test]
fn dyn_contact_events_are_located_and_releases_have_small_force() {
    let (r, rep) = run("barhorst-case1", 11, 0.45);
    let mut starts = 0;
    let mut releases = 0;
    let len = 5.0;
    for e in &r.events {
        match e {
            Event::ContactStart {
                time_tolerance: tol,
                ..
            } => {
                starts += 1;
                assert!(*tol <= EVENT_TIME_TOLERANCE, "contact tolerance {tol:e}");
            }
            Event::Release {
                normal_force,
                time_tolerance: tol,
                ..
            } => {
                releases += 1;
                assert!(*tol <= EVENT_TIME_TOLERANCE, "release tolerance {tol:e}");
                // λ of the contact phase is ~1e2 lbf; at the located release it is ~0
                assert!(normal_force.abs() < 1e-3, "|λ| at release {normal_force:e}");
            }
            _ => {}
        }
    }
    println!("{starts} contact starts, {releases} releases; {rep:?}");
    assert!(
        starts >= 2 && releases >= 1,
        "{starts} starts, {releases} releases"
    );
    // the state lands on the event: |g| at the located contact start ≪ one step of approach
    // (a grazing re-contact after a release stops on the 1e-10 s bracket with |g| ~ 1e-11)
    assert!(
        rep.max_gap_at_event <= 1e-10 * len,
        "{:e}",
        rep.max_gap_at_event
    );
    // drift control of the constrained phase
    assert!(rep.max_gap_violation <= 1e-9, "{:e}", rep.max_gap_violation);
    assert!(
        rep.max_normal_velocity_violation <= 1e-5,
        "{:e}",
        rep.max_normal_velocity_violation
    );
    // the recorded gap never goes measurably negative: free flight that leaves the surface at
    // a release may dip by up to 1e-9 (L₁ + L₂) before a contact is declared, and samples
    // interpolate linearly between step ends (the tip path is curved)
    let gap = channel(&r, "contact1.gap");
    let worst = gap.iter().fold(0.0f64, |m, g| m.min(*g));
    println!("most negative recorded gap {worst:.2e}");
    assert!(worst > -1e-9 * len, "penetration {worst:e}");
}

#[test]
fn dyn_contact_case1_ledger_closes_through_impact_and_sliding() {
    let (r, rep) = run("barhorst-case1", 21, 0.4);
    let phase = channel(&r, "contact1.phase");
    assert!(phase.contains(&1.0), "no constrained phase");
    let names: Vec<&str> = r
        .ledger
        .dissipation
        .iter()
        .map(|t| t.name.as_str())
        .collect();
    assert!(names.contains(&"impact"), "{names:?}");
    let stored: Vec<&str> = r.ledger.stored.iter().map(|t| t.name.as_str()).collect();
    assert!(stored.contains(&"gravity"), "{stored:?}");
    let impact = r
        .ledger
        .dissipation
        .iter()
        .find(|t| t.name == "impact")
        .unwrap();
    assert!(*impact.values.last().unwrap() > 1.0);
    let closure = r.ledger.relative_closure();
    println!(
        "closure {closure:.3e}, projection energy {:.1e}, steps {}",
        rep.projection_energy, r.cost.steps
    );
    assert!(closure < 1e-5, "ledger closure {closure:e}");
}

#[test]
fn sys_contact_chain_steps_above_the_damped_bound_with_implicit_damping() {
    // `barhorst-case1` (Kelvin–Voigt links, joint dampers), 21 stations: the implicit kick, the
    // held tip's force included, steps at the undamped bound (times the contact runs' accuracy
    // safety factor) through the impacts and held phases, far above the bound the explicit
    // damping would impose.
    use fdm::runs::IMPLICIT_CONTACT_SAFETY;
    use fdm::system::System;
    let scene = load_scene("barhorst-case1").unwrap();
    let mut chain =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(21)).unwrap();
    let damped = chain.bound(0.0).sigma;
    assert!(chain.enable_implicit_damping());
    let undamped = chain.bound(0.0).sigma;
    println!("bound: damped {damped:.3e} s, undamped {undamped:.3e} s");
    let (r, rep) = run("barhorst-case1", 21, 0.4);
    assert!(
        (rep.tau_max - IMPLICIT_CONTACT_SAFETY * undamped).abs() <= 1e-9 * undamped,
        "largest step {:e}, bound {undamped:e}",
        rep.tau_max
    );
    // beyond the explicit damping's bound, where its kick would diverge
    assert!(rep.tau_max > damped, "{:e} vs {damped:e}", rep.tau_max);
    assert!(r.ledger.relative_closure() < 1e-5);
    assert!(r.observables.first_non_finite().is_none());
}

#[test]
fn dyn_contact_stiff_elbow_rests_on_the_tip_at_the_static_force() {
    let stations = 11;
    // the scene's 10 s: the arm rocks on its sliding tip (hub free, D₁ = 20) and settles
    let (r, _) = run("barhorst-case1-stiff-elbow", stations, 10.0);
    let lam = channel(&r, "contact1.normal_force");
    let phase = channel(&r, "contact1.phase");
    let n = lam.len();
    // resting: in contact over the last second, force nearly steady
    let last_s = &lam[n - 1000..];
    assert!(phase[n - 1000..].iter().all(|&p| p == 1.0));
    let (lo, hi) = last_s
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    let resting = last_s.iter().sum::<f64>() / last_s.len() as f64;
    println!(
        "resting normal force (mean of 9–10 s) {resting:.4}, spread {:.2e}, at 10 s {:.4}",
        hi - lo,
        lam[n - 1]
    );
    assert!(hi - lo < 1e-2 * resting);
    // the static equilibrium of the same discrete model, from the final state as a guess
    let scene = load_scene("barhorst-case1-stiff-elbow").unwrap();
    let mut sys =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(stations))
            .unwrap();
    let (q0, _) = sys.initial_state();
    let (q, stat) = sys.rest_on_surface(&q0).unwrap();
    assert!(sys.gap(&q).abs() < 1e-12);
    println!("static equilibrium: λ = {stat:.6}, rigid arm 141.87");
    assert!((resting - stat).abs() < 2e-3 * stat, "{resting} vs {stat}");
    // rigid straight arm: N·x_tip = Σ W x_cg with the arm resting on y = −1
    let rigid = 141.87;
    assert!((stat - rigid).abs() < 0.02 * rigid, "{stat} vs {rigid}");
}

#[test]
fn conv_contact_tipmass_first_impulse_converges_at_first_order() {
    // The tip's lumped mass is the tip mass plus ρA h/2: the first impulse carries an O(h)
    // error. Stations 6, 11, 21 halve h. Measured: 6.770, 4.622, 3.542 (41 stations: 3.000).
    let mut out = Vec::new();
    for stations in [6, 11, 21] {
        let (r, _) = run("barhorst-case1-tipmass", stations, 0.3);
        let first = impacts(&r)[0];
        println!(
            "{stations} stations: first impact t = {:.6}, Λ = {:.5}",
            first.0, first.1
        );
        out.push(first.1);
    }
    let order = ((out[0] - out[1]) / (out[1] - out[2])).log2();
    let richardson = 2.0 * out[2] - out[1];
    println!("observed order {order:.3}, first-order Richardson limit {richardson:.4}");
    assert!((order - 1.0).abs() < 0.1, "observed order {order}");
    // The modal study (2…16 modes: 7.10 … 3.13) extrapolates to ≈ 2.456 like 1/n: the two
    // independent discretizations meet in the limit.
    assert!((richardson - 2.456).abs() < 0.01 * 2.456, "{richardson}");
}

#[test]
fn prop_contact_unsupported_settings_are_typed_errors() {
    let mut scene = load_scene("barhorst-case1").unwrap();
    let s = settings(11, 0.1);
    scene.planar_chain_mut().unwrap().contacts[0].friction = 0.3;
    let e = FdmBackend.simulate(&scene, &s).unwrap_err();
    assert!(
        matches!(&e, BackendError::Unsupported(m) if m.contains("friction")),
        "{e}"
    );
    let mut scene = load_scene("barhorst-case1").unwrap();
    scene.planar_chain_mut().unwrap().contacts[0].mode = data::scene::ContactMode::Bilateral;
    let e = FdmBackend.simulate(&scene, &s).unwrap_err();
    assert!(
        matches!(&e, BackendError::Unsupported(m) if m.contains("bilateral")),
        "{e}"
    );
    let mut scene = load_scene("barhorst-case1").unwrap();
    scene.planar_chain_mut().unwrap().contacts[0].surface = data::scene::Surface::Circle {
        center: [0.0, 0.0],
        radius: 6.0,
    };
    let e = FdmBackend.simulate(&scene, &s).unwrap_err();
    assert!(
        matches!(&e, BackendError::Unsupported(m) if m.contains("non-line")),
        "{e}"
    );
    let scene = load_scene("barhorst-case1").unwrap();
    let mut s2 = s.clone();
    s2.time.method = Some("report".parse().expect("a method name"));
    let e = FdmBackend.simulate(&scene, &s2).unwrap_err();
    assert!(matches!(&e, BackendError::Unsupported(_)), "{e}");
}

#[test]
fn elem_contact_gravity_force_is_minus_the_potential_gradient() {
    // the free chain under gravity conserves T + V_g + strain + springs when undamped: the
    // gravity force is −∂V_g/∂q of the stored `gravity` term (foreshortening included)
    let mut scene = load_scene("barhorst-case1").unwrap();
    scene.planar_chain_mut().unwrap().contacts.clear();
    for l in &mut scene.planar_chain_mut().unwrap().links {
        l.kelvin_voigt = None;
        l.joint.damping = None;
    }
    let s = settings(11, 0.2);
    let r = FdmBackend.simulate(&scene, &s).unwrap();
    let closure = r.ledger.relative_closure();
    println!("undamped free fall under gravity: closure {closure:.2e}");
    assert!(closure < 1e-5, "{closure:e}");
    let grav = r
        .ledger
        .stored
        .iter()
        .find(|t| t.name == "gravity")
        .unwrap();
    // the arm falls: gravity potential drops by more than the initial kinetic energy
    assert!(grav.values.last().unwrap() < &(grav.values[0] - 1.0));
    let sys =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(11)).unwrap();
    assert!(sys.ledger_names().0.contains(&"gravity"));
}
