//! Two-link chain (`two-link-free`, `two-link-free-undamped`).
//! Run: CARGO_TARGET_DIR=/work/targets/fdm cargo test --release -p fdm --test chain -- --nocapture

#![allow(clippy::needless_range_loop)]

use data::{Backend, RunResult, Settings, StabilityVerdict, load_scene};
use fdm::FdmBackend;
use fdm::chain::TwoLinkChain;
use fdm::chain::kinetic::ChainInertia;
use fdm::chain::kinetic::{Lanes, PointScratch, RateLanes};
use fdm::system::System;

mod common;

/// One link's points in its clamp-tangent frame, written from the geometry alone: `u` holds
/// the chord-frame deflections of stations 1…r−1 and, last, the clamp ghost x (the tip sits on
/// the chord); the clamp tangent turns by ψ = (u₁ − x)/(2h) from the chord, so the
/// tangent-frame deflection of station k is u_k − ξ_kψ (tip −Lψ) and its axial position
/// ξ_k − ½∫₀^ξ_k (v^t′)² (segment slopes). Returns (ψ, points (x, y) of stations 1…r).
fn tangent_link(u: &[f64], h: f64, foreshortening: bool) -> (f64, Vec<[f64; 2]>) {
    let r = u.len();
    let psi = (u[0] - u[r - 1]) / (2.0 * h);
    let (mut s, mut prev) = (0.0, 0.0);
    let mut out = Vec::new();
    for k in 0..r {
        let xi = (k + 1) as f64 * h;
        let chord = if k + 1 < r { u[k] } else { 0.0 };
        let vt = chord - xi * psi;
        if foreshortening {
            s += 0.5 * h * ((vt - prev) / h).powi(2);
        }
        prev = vt;
        out.push([xi - s, vt]);
    }
    (psi, out)
}

/// Inertial positions of the chain's lumped points (link 1's stations, the elbow, link 2's
/// stations) in the clamp-tangent frames (the scene's model), written from the geometry alone,
/// independently of the kinetic-energy kernel and of the chain's coordinate map; and the hub
/// angle (link 1's clamp tangent α₁ = θ + ψ₁, on which the rotor turns).
fn point_positions(ine: &ChainInertia, q: &[f64]) -> (Vec<[f64; 2]>, f64) {
    let (v, w) = (&q[ine.iv()], &q[ine.iw()]);
    let (psi1, p1) = tangent_link(v, ine.h1, ine.fs1);
    let (psi2, p2) = tangent_link(w, ine.h2, ine.fs2);
    let (a1, a2) = (q[0] + psi1, q[1] + psi2);
    let rot = |a: f64, p: [f64; 2]| {
        [
            a.cos() * p[0] - a.sin() * p[1],
            a.sin() * p[0] + a.cos() * p[1],
        ]
    };
    let mut out: Vec<[f64; 2]> = p1.iter().map(|p| rot(a1, *p)).collect();
    let e = *out.last().unwrap();
    out.push(e);
    for p in &p2 {
        let r = rot(a2, *p);
        out.push([e[0] + r[0], e[1] + r[1]]);
    }
    (out, a1)
}

/// Central difference of f along coordinate i of x with step eps.
fn central_difference(mut f: impl FnMut(&[f64]) -> f64, x: &[f64], i: usize, eps: f64) -> f64 {
    let (mut xa, mut xb) = (x.to_vec(), x.to_vec());
    xa[i] += eps;
    xb[i] -= eps;
    (f(&xa) - f(&xb)) / (2.0 * eps)
}

/// The chain's kinetic energy of the lumped points and the hub at chain coordinates: the
/// kernel at the mapped coordinates P q, P q̇.
fn chain_kinetic(sys: &TwoLinkChain, sc: &mut PointScratch, q: &[f64], v: &[f64]) -> f64 {
    let n = q.len();
    let (mut qk, mut vk) = (vec![0.0; n], vec![0.0; n]);
    sys.to_kinetic(q, &mut qk);
    sys.to_kinetic(v, &mut vk);
    sys.inertia.kinetic(&qk, &vk, sc)
}

#[test]
fn elem_chain_kinetic_lanes_give_each_single_products_bits() {
    // M q̇ and the inertia forces at several velocities in one pass (a lane each, as the mass
    // columns and the implicit kick's two drift velocities take them) against one velocity at
    // a time: the same operations per lane, so the same bits
    let scene = load_scene("two-link-free").unwrap();
    let sys =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(9)).unwrap();
    let ine = &sys.inertia;
    let n = sys.dofs();
    let (q, v) = common::moving_chain_state(n);
    let mut qk = vec![0.0; n];
    sys.to_kinetic(&q, &mut qk);
    let rates: Vec<Vec<f64>> = (0..4)
        .map(|c| {
            let mut vk = vec![0.0; n];
            let vc: Vec<f64> = (0..n)
                .map(|i| v[i] * (1.0 + 0.3 * c as f64) + 0.01 * ((c + i) as f64).sin())
                .collect();
            sys.to_kinetic(&vc, &mut vk);
            vk
        })
        .collect();
    // the segment slopes of each velocity's deflection rates, link 1's then link 2's
    let slopes: Vec<Vec<f64>> = rates
        .iter()
        .map(|r| {
            let slope = |u: &[f64], k: usize, h: f64| {
                let left = if k == 0 { 0.0 } else { u[k - 1] };
                (u[k] - left) / h
            };
            let (a, b) = (&r[ine.iv()], &r[ine.iw()]);
            (0..ine.r1)
                .map(|k| slope(a, k, ine.h1))
                .chain((0..ine.r2).map(|j| slope(b, j, ine.h2)))
                .collect()
        })
        .collect();
    let mut sc = PointScratch::new(ine);
    ine.set_shape(&qk, &mut sc);
    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let mut single = vec![vec![0.0; n]; 4];
    for c in 0..4 {
        ine.momenta_at(&qk, &rates[c], &mut sc, &mut single[c]);
    }
    let mut lanes = Lanes::<4>::new(ine);
    let mut many = vec![vec![0.0; n]; 4];
    let [m0, m1, m2, m3] = &mut many[..] else {
        unreachable!()
    };
    ine.momenta_lanes(
        &qk,
        &sc.shape,
        std::array::from_fn(|c| &rates[c][..]),
        &RateLanes::new(ine, std::array::from_fn(|c| &rates[c][..])),
        &mut lanes,
        [&mut m0[..], &mut m1[..], &mut m2[..], &mut m3[..]],
    );
    for c in 0..4 {
        assert_eq!(bits(&many[c]), bits(&single[c]), "momenta, lane {c}");
    }
    let mut single = vec![vec![0.0; n]; 2];
    for c in 0..2 {
        ine.inertia_forces_at(&qk, &rates[c], &mut sc, &mut single[c]);
    }
    let mut lanes = Lanes::<2>::new(ine);
    let mut drift = RateLanes::<2>::zeroed(ine.r1 + ine.r2);
    drift.set(
        ine,
        [&rates[0][..], &rates[1][..]],
        [&slopes[0][..], &slopes[1][..]],
    );
    let mut many = vec![vec![0.0; n]; 2];
    let [f0, f1] = &mut many[..] else {
        unreachable!()
    };
    ine.inertia_forces_lanes(
        &qk,
        &sc.shape,
        [&rates[0][..], &rates[1][..]],
        &drift,
        &mut lanes,
        [&mut f0[..], &mut f1[..]],
    );
    for c in 0..2 {
        assert_eq!(bits(&many[c]), bits(&single[c]), "inertia forces, lane {c}");
    }
}

#[test]
fn elem_chain_kinetic_energy_is_that_of_the_moving_lumped_points() {
    // T = ½J₁α̇₁² + ½Σm|ṙ|² with ṙ a central difference of the clamp-tangent-frame positions
    // along q̇; p = ∂T/∂q̇ (Pᵀ of the kernel's momenta) and the inertia forces
    // ∂T/∂q − (∂p/∂q)q̇ against central differences of T and p
    let scene = load_scene("two-link-free").unwrap();
    let sys =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(9)).unwrap();
    let ine = &sys.inertia;
    let n = sys.dofs();
    let (q, v) = common::moving_chain_state(n);
    let mut sc = PointScratch::new(ine);
    let t0 = chain_kinetic(&sys, &mut sc, &q, &v);
    let eps = 1e-6;
    let shifted = |s: f64| -> Vec<f64> { (0..n).map(|i| q[i] + s * v[i]).collect() };
    let ((ra, ha), (rb, hb)) = (
        point_positions(ine, &shifted(eps)),
        point_positions(ine, &shifted(-eps)),
    );
    let hub_rate = (ha - hb) / (2.0 * eps);
    let mut t_points = 0.5 * ine.hub * hub_rate * hub_rate;
    for p in 0..ine.points() {
        let d = [0, 1].map(|c| (ra[p][c] - rb[p][c]) / (2.0 * eps));
        t_points += 0.5 * ine.point_mass(p) * (d[0] * d[0] + d[1] * d[1]);
    }
    // central difference of smooth positions: O(ε²) truncation, round-off ≈ 1e-16/ε relative
    assert!((t_points - t0).abs() < 1e-8 * t0, "{t_points} vs {t0}");
    let (mut qk, mut vk) = (vec![0.0; n], vec![0.0; n]);
    let mut momenta = |sc: &mut PointScratch, q: &[f64], out: &mut [f64]| {
        sys.to_kinetic(q, &mut qk);
        sys.to_kinetic(&v, &mut vk);
        out.iter_mut().for_each(|x| *x = 0.0);
        ine.momenta_values(&qk, &vk, sc, out);
        sys.kinetic_transpose(out);
    };
    let mut p = vec![0.0; n];
    momenta(&mut sc, &q, &mut p);
    let half: f64 = 0.5 * (0..n).map(|i| v[i] * p[i]).sum::<f64>();
    assert!((half - t0).abs() < 1e-12 * t0, "{half} vs {t0}");
    let (mut pa, mut pb) = (vec![0.0; n], vec![0.0; n]);
    momenta(&mut sc, &shifted(eps), &mut pa);
    momenta(&mut sc, &shifted(-eps), &mut pb);
    let mut f = vec![0.0; n];
    let (mut qk, mut vk) = (vec![0.0; n], vec![0.0; n]);
    sys.to_kinetic(&q, &mut qk);
    sys.to_kinetic(&v, &mut vk);
    ine.inertia_forces(&qk, &vk, &mut sc, &mut f);
    sys.kinetic_transpose(&mut f);
    for i in 0..n {
        let dp = central_difference(|va| chain_kinetic(&sys, &mut sc, &q, va), &v, i, eps);
        let dg = central_difference(|qa| chain_kinetic(&sys, &mut sc, qa, &v), &q, i, eps);
        let dd = (pa[i] - pb[i]) / (2.0 * eps);
        // central differences: truncation O(ε²·T''') ≈ 1e-12 relative, round-off
        // ≈ 1e-16·T/ε ≈ 1e-10 relative to the scale of T
        let tol = 1e-7 * (1.0 + t0);
        assert!((p[i] - dp).abs() < tol, "p[{i}] {} vs {dp}", p[i]);
        assert!(
            (f[i] - (dg - dd)).abs() < tol,
            "inertia force [{i}] {} vs {}",
            f[i],
            dg - dd
        );
    }
}

#[test]
fn elem_chain_forces_are_minus_potential_gradients() {
    // accelerations with q̇ = 0 and no dampers: M a = −∂V/∂q; check M a against FD of V.
    let mut scene = load_scene("two-link-free-undamped").unwrap();
    scene.planar_chain_mut().unwrap().links[1].joint.set_point = Some(0.3);
    let mut sys =
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(9)).unwrap();
    let n = sys.dofs();
    let (q, _) = common::moving_chain_state(sys.dofs());
    let v = vec![0.0; n];
    let mut a = vec![0.0; n];
    sys.accel(0.0, &q, &v, &mut a);
    // M a via momenta at velocity a
    let mut ma = vec![0.0; n];
    sys.momenta(&q, &a, &mut ma);
    // and the chain's momenta are ∂T/∂q̇ of its kinetic energy (ghost slots, clamp inertias)
    let (qm, vm) = common::moving_chain_state(sys.dofs());
    let mut pm = vec![0.0; n];
    sys.momenta(&qm, &vm, &mut pm);
    let ke = |v: &[f64]| {
        let mut e = [0.0; 3];
        sys.stored_energies(0.0, &qm, v, &mut e);
        e[0]
    };
    for i in 0..n {
        let (mut va, mut vb) = (vm.clone(), vm.clone());
        va[i] += 1e-6;
        vb[i] -= 1e-6;
        let d = (ke(&va) - ke(&vb)) / 2e-6;
        // quadratic in q̇: central difference exact up to round-off ≈ 1e-16·T/ε
        assert!(
            (pm[i] - d).abs() < 1e-7 * (1.0 + d.abs()),
            "p[{i}] {} vs {d}",
            pm[i]
        );
    }
    let pot = |q: &[f64]| {
        let mut e = [0.0; 3];
        sys.stored_energies(0.0, q, &v, &mut e);
        e[1] + e[2]
    };
    assert_inertia_balances_potential(&ma, pot, &q);
}

/// M a = −∂V/∂q at rest, against a central difference of V (V ≈ 1e2 in these tests: the
/// difference's round-off ≈ 1e-16·V/ε, its truncation O(ε²) — exact for a V quadratic in the
/// deflections).
fn assert_inertia_balances_potential(
    ma: &[f64],
    mut potential: impl FnMut(&[f64]) -> f64,
    q: &[f64],
) {
    for i in 0..q.len() {
        let dv = central_difference(&mut potential, q, i, 1e-6);
        assert!(
            (ma[i] + dv).abs() < 1e-6 * (1.0 + dv.abs()),
            "{i}: M a = {} vs −∂V/∂q = {}",
            ma[i],
            -dv
        );
    }
}

fn run(name: &str, f: impl Fn(&mut data::Scene), settings: &Settings) -> RunResult {
    let mut scene = load_scene(name).unwrap();
    f(&mut scene);
    FdmBackend.simulate(&scene, settings).expect("runs")
}

fn with(stations: usize, t_end: f64) -> Settings {
    let mut s = Settings::default();
    s.discretization.stations = Some(stations);
    s.time.t_end = Some(t_end);
    s
}

#[test]
fn sys_chain_dof_plans() {
    let d = Default::default();
    for name in ["two-link-free", "two-link-free-undamped"] {
        let p = FdmBackend.dof_plan(&load_scene(name).unwrap(), &d).unwrap();
        // θ, β, two clamp ghosts, link 1's tip ghost + stations 1…r−1 of each link (21
        // stations by default: the clamp and, in the tip-chord frame, the tip are not
        // unknowns): 2 + 3 + 19 + 19
        assert_eq!(p.total(), 43, "{name}");
        let p = FdmBackend
            .dof_plan(
                &load_scene(name).unwrap(),
                &data::Discretization {
                    stations: Some(11),
                    ..Default::default()
                },
            )
            .unwrap();
        assert_eq!(p.total(), 2 + 3 + 9 + 9, "{name}");
        assert!(p.builds.iter().any(|b| b.contains("velocity-form")));
        let kv = p.builds.iter().any(|b| b.contains("Kelvin"));
        assert_eq!(kv, name == "two-link-free", "{name}: {:?}", p.builds);
    }
}

#[test]
fn sys_chain_of_linear_links_is_refused() {
    // The chain supports links with foreshortening only (build.rs): a link without it is
    // refused by name, in `run` and in `dof_plan` alike.
    for k in 0..2 {
        let mut scene = load_scene("two-link-free").unwrap();
        let link = &mut scene.planar_chain_mut().unwrap().links[k];
        link.foreshortening = false;
        let name = link.name.clone();
        let err = FdmBackend
            .simulate(&scene, &with(11, 0.01))
            .expect_err("a linear link in the chain must be refused");
        let text = err.to_string();
        assert!(matches!(err, data::BackendError::Unsupported(_)), "{text}");
        assert!(
            text.contains(&format!("link `{name}`")) && text.contains("foreshortening"),
            "{text}"
        );
        assert!(FdmBackend.dof_plan(&scene, &Default::default()).is_err());
    }
}

#[test]
fn dyn_chain_short_window_closes_the_ledger_at_small_steps() {
    // 80 steps of τ = 1e-6 s from the scenes' initial state (elbow spring loaded by 60°).
    // This checks that the assembled equations (Lagrange of T − V with D) keep the ledger:
    // second-order scheme, local energy error O(τ³ω³)·E per step with ω ≈ 2.6e4 rad/s the
    // top frequency ⇒ ≲ 1e-5 of the spring energy over the window.
    for name in ["two-link-free-undamped", "two-link-free"] {
        let mut s = with(11, 8.0e-5);
        s.time.dt = Some(1e-6);
        let out = run(name, |sc| sc.simulation.output_interval = 1e-5, &s);
        let c = out.ledger.relative_closure();
        eprintln!("{name}: verdict {:?}, closure {c:.3e}", out.verdict);
        assert!(matches!(out.verdict, StabilityVerdict::Completed));
        assert!(c < 1e-5, "{name}: {c}");
    }
}

/// max |E − E0 − W_in + W_diss| over the k-th tenth of the run.
fn residual_tenth(out: &RunResult, k: usize) -> f64 {
    let n = out.ledger.time.len();
    (k * n / 10..(k + 1) * n / 10)
        .map(|i| out.ledger.residual(i).abs())
        .fold(0.0, f64::max)
}

#[test]
fn dyn_chain_undamped_conserves_energy_without_drift() {
    // 10 s of two-link-free-undamped at 11 stations per link, velocity form (default).
    let mut coarse = with(11, 10.0);
    coarse.time.safety_factor = Some(1.0);
    let mut fine = coarse.clone();
    fine.time.safety_factor = Some(0.5);
    let a = run("two-link-free-undamped", |_| {}, &coarse);
    let b = run("two-link-free-undamped", |_| {}, &fine);
    for out in [&a, &b] {
        assert!(
            matches!(out.verdict, StabilityVerdict::Completed),
            "{:?}",
            out.verdict
        );
    }
    let (first, last) = (residual_tenth(&a, 0), residual_tenth(&a, 9));
    let (ca, cb) = (a.ledger.relative_closure(), b.ledger.relative_closure());
    eprintln!(
        "undamped 10 s: closure {ca:.3e} (τ = safety·bound, {} steps, {:.2} s) / {cb:.3e} (½τ); \
         residual first tenth {first:.3e}, last tenth {last:.3e} J",
        a.cost.steps, a.cost.wall_time_s
    );
    // No secular drift: the energy error of the one-step velocity form oscillates with the
    // high modes the impulsive start excites; its envelope over the last tenth stays within
    // 1.5× the first tenth (a drift would grow linearly: ×10 over the run).
    assert!(last < 1.5 * first, "drift: {first:e} → {last:e}");
    // Second order: the error is O((ωτ)²) — halving τ divides it by ≈ 4 (measured 3.69, with
    // the inertia terms from the extrapolated drift velocities); at least 3 rules out first
    // order (drift velocity alone, unextrapolated: 1.68).
    assert!(ca / cb > 3.0 && ca / cb < 5.0, "{ca} / {cb}");
    // Size: O((ω_max τ)²) times the energy of the excited top modes: measured 8.2e-4 at
    // ω_max τ = 1.8 (3.4e-3 with the inertia terms at the predicted velocity, whose bias
    // `conv_chain_undamped_mean_joint_angles_converge_under_refinement` covers).
    assert!(ca < 1.2e-3, "{ca}");
}

/// Time average of a channel over the whole run (trapezoid over the samples): a smooth
/// functional of the history, insensitive to the unresolved high-frequency content of the
/// massless-hub joint angles that a point value at the output rate would alias.
fn time_mean(out: &RunResult, name: &str) -> f64 {
    let t = &out.observables.time;
    let y = common::channel(out, name);
    let area: f64 = (1..t.len())
        .map(|i| 0.5 * (y[i] + y[i - 1]) * (t[i] - t[i - 1]))
        .sum();
    area / (t[t.len() - 1] - t[0])
}

#[test]
fn conv_chain_undamped_mean_joint_angles_converge_under_refinement() {
    // two-link-free-undamped over 1 s at 11, 21, 41 stations per link, the default step (0.9 ×
    // the bound, τ ∝ h²). The impulsive start (springs loaded, links straight) excites every
    // bending wave; foreshortening couples their velocities quadratically into the joint
    // equations (Ψ̈ ∋ q̇ᵀHq̇). Evaluated at the predicted step-end velocity, each unresolved
    // wave left a mean bias ∝ (ωτ)² and the sum grew with the number of stations: the 1 s
    // mean of joint 2 went 0.68137, 0.66542, 0.63554 at 21/41/81 stations, away from fem's
    // 0.69676. With the drift-velocity inertia terms (integrator docs) the means must settle:
    // joint 2's successive differences shrink by at least 2 (first order or better) and its
    // 41-station value sits within twice the last difference of fdm's own Richardson limit.
    // Joint 1's mean carries no such bias: it is settled at the coarsest grid, its differences
    // (2e-5 of 0.62 rad) the size of the runs' 1 s averaging of undamped oscillation, without a
    // sign pattern; it must stay within a tenth of joint 2's first difference at every grid.
    let means: Vec<[f64; 2]> = [11, 21, 41]
        .iter()
        .map(|&n| {
            let out = run("two-link-free-undamped", |_| {}, &with(n, 1.0));
            assert!(matches!(out.verdict, StabilityVerdict::Completed));
            [
                time_mean(&out, "joint1.angle"),
                time_mean(&out, "joint2.angle"),
            ]
        })
        .collect();
    let differences = |j: usize| (means[1][j] - means[0][j], means[2][j] - means[1][j]);
    let (d1, d2) = differences(1);
    let p = (d1 / d2).abs().log2();
    let limit = means[2][1] + d2 / (2f64.powf(p) - 1.0);
    for j in 0..2 {
        eprintln!(
            "joint{} 1 s mean: {:.7} {:.7} {:.7}",
            j + 1,
            means[0][j],
            means[1][j],
            means[2][j]
        );
    }
    eprintln!("joint2: observed order {p:.2}, Richardson limit {limit:.7}");
    assert!(d2.abs() < 0.5 * d1.abs(), "joint2: {d1:e} then {d2:e}");
    assert!((means[2][1] - limit).abs() <= 2.0 * d2.abs());
    let (e1, e2) = differences(0);
    for e in [e1, e2, e1 + e2] {
        assert!(
            e.abs() < 0.1 * d1.abs(),
            "joint1: {e1:e}, {e2:e} against {d1:e}"
        );
    }
}

#[test]
fn dyn_chain_undamped_energy_error_falls_under_refinement() {
    // The same 1 s at the default step, 21 and 41 stations: the largest ledger residual must
    // fall as the grid is refined (measured 4.1e-4 → 2.1e-4 of the 48 J; with the predicted-
    // velocity inertia terms it rose 6.5e-3 → 1.3e-2, the bias of the test above).
    let res: Vec<f64> = [21, 41]
        .iter()
        .map(|&n| {
            let out = run("two-link-free-undamped", |_| {}, &with(n, 1.0));
            let e0 = out.ledger.stored.iter().map(|t| t.values[0]).sum::<f64>();
            let worst = (0..out.ledger.time.len())
                .map(|i| out.ledger.residual(i).abs())
                .fold(0.0, f64::max);
            worst / e0
        })
        .collect();
    eprintln!(
        "undamped 1 s: max |residual|/E₀ {:.3e} (21), {:.3e} (41)",
        res[0], res[1]
    );
    assert!(res[1] < 0.75 * res[0], "{res:?}");
    assert!(res[0] < 1e-3, "{res:?}");
}

#[test]
fn dyn_chain_damped_ledger_closes() {
    // two-link-free (joint dampers + Kelvin–Voigt, implicit in the closing kick), 10 s, 11
    // stations, half and a quarter of the bound. The closure is the velocity form's O(τ²)
    // energy error (a one-off at the loaded start, as in the undamped scene): measured
    // 1.24e-4 and 3.10e-5 (ratio 4.0). A dissipation booked inconsistently with the implicit
    // update would leave an error that does not fall with τ.
    let closure = |safety: f64| {
        let mut s = with(11, 10.0);
        s.time.safety_factor = Some(safety);
        let out = run("two-link-free", |_| {}, &s);
        assert!(
            matches!(out.verdict, StabilityVerdict::Completed),
            "{:?}",
            out.verdict
        );
        let c = out.ledger.relative_closure();
        let diss: Vec<f64> = out
            .ledger
            .dissipation
            .iter()
            .map(|t| *t.values.last().unwrap())
            .collect();
        eprintln!(
            "damped 10 s, safety {safety}: closure {c:.3e}, dissipated (joint_damper, \
             kelvin_voigt) {diss:?} J, {} steps, {:.2} s",
            out.cost.steps, out.cost.wall_time_s
        );
        // Both mechanisms dissipate; together they remove most of the 48 J spring energy.
        assert!(diss.iter().all(|d| *d > 0.0));
        c
    };
    let (c_half, c_quarter) = (closure(0.5), closure(0.25));
    assert!(c_half / c_quarter > 3.0, "{c_half} → {c_quarter}");
    assert!(c_quarter < 6e-5, "{c_quarter}");
}

#[test]
fn sys_chain_step_bound_names_the_clamp_rotation_mode_that_sets_it() {
    // The chain's fastest mode is link 2's clamp rotation (its ghost against the clamp
    // section's O(h³) rotary inertia, √3 above the bending waves' limit (4/h²)√(EI/ρA): chain
    // docs), so a step above the bound is refused naming that mode, not the chain at large.
    let stations = 21;
    let scene = load_scene("two-link-free").unwrap();
    let links = &scene.planar_chain().unwrap().links;
    let h2 = links[1].length / (stations - 1) as f64;
    let interior =
        (4.0 / (h2 * h2)) * (links[1].bending_stiffness / links[1].mass_per_length).sqrt();
    let run_at = with(stations, 0.01);
    let tau = common::channel(&run("two-link-free", |_| {}, &run_at), "step_size")[0];
    // 0.9 · 2/ω_max with ω_max 1.02 × the power iteration's: the top mode lies above 1.5 ×
    // the interior's limit
    assert!(0.9 * 2.0 / 1.02 / tau > 1.5 * interior, "step {tau:e}");
    let mut s = run_at;
    s.time.dt = Some(1.2 * tau);
    match FdmBackend.simulate(&scene, &s) {
        Err(data::BackendError::StabilityBound { location, .. }) => {
            assert!(
                location.contains("clamp-rotation mode of link 2"),
                "{location}"
            )
        }
        other => panic!("expected a refused step, got {other:?}"),
    }
}

#[test]
fn sys_chain_implicit_damping_keeps_the_undamped_step() {
    // The damped scene steps at the undamped bound (same grid, same stiffness): the explicit
    // dampers' bound (their rates over the clamp half cells ρAh³/24) took 10× more steps.
    let steps = |name: &str| run(name, |_| {}, &with(21, 0.2)).cost.steps;
    let (damped, undamped) = (steps("two-link-free"), steps("two-link-free-undamped"));
    assert_eq!(damped, undamped);
}

#[test]
fn conv_chain_joint_angles_second_order_in_space() {
    // two-link-free at t = 2 s with 6, 11, 21 stations per link (h halves). The step follows
    // the bound, τ ∝ h², so the time error O(τ²) = O(h⁴) does not pollute the spatial order.
    let vals: Vec<[f64; 2]> = [6, 11, 21]
        .iter()
        .map(|&n| {
            let out = run("two-link-free", |_| {}, &with(n, 2.0));
            assert!(matches!(out.verdict, StabilityVerdict::Completed));
            let a = |c: &str| *out.observables.get(c).unwrap().values.last().unwrap();
            [a("joint1.angle"), a("joint2.angle")]
        })
        .collect();
    for j in 0..2 {
        let (d1, d2) = (vals[1][j] - vals[0][j], vals[2][j] - vals[1][j]);
        let p = (d1 / d2).abs().log2();
        eprintln!(
            "joint{} at t = 2 s: {:.8} {:.8} {:.8}, observed order {p:.3}",
            j + 1,
            vals[0][j],
            vals[1][j],
            vals[2][j]
        );
        // trapezoid masses, ghost-node stencils and the one-sided tip slope are O(h²)
        assert!((p - 2.0).abs() < 0.3, "joint{}: order {p}", j + 1);
    }
}

/// Rigid two-link arm (uniform rods, joint springs/dampers): RK4 on (θ₁, θ₂, θ̇₁, θ̇₂).
fn rigid_two_link(scene: &data::Scene, t_end: f64, dt: f64, samples: &[f64]) -> Vec<[f64; 2]> {
    let (l1, l2) = (&scene.links()[0], &scene.links()[1]);
    let (m1, m2) = (
        l1.mass_per_length * l1.length,
        l2.mass_per_length * l2.length,
    );
    let (a, b) = (l1.length, l2.length);
    let i1 = m1 * a * a / 3.0;
    let i2c = m2 * b * b / 12.0;
    let k = [
        l1.joint.stiffness.unwrap_or(0.0),
        l2.joint.stiffness.unwrap_or(0.0),
    ];
    let d = [
        l1.joint.damping.unwrap_or(0.0),
        l2.joint.damping.unwrap_or(0.0),
    ];
    let sp = [
        l1.joint.set_point.unwrap_or(0.0),
        l2.joint.set_point.unwrap_or(0.0),
    ];
    let f = |y: [f64; 4]| -> [f64; 4] {
        let (c2, s2) = (y[1].cos(), y[1].sin());
        let m11 = i1 + i2c + m2 * (a * a + b * b / 4.0 + a * b * c2);
        let m12 = i2c + m2 * (b * b / 4.0 + 0.5 * a * b * c2);
        let m22 = i2c + m2 * b * b / 4.0;
        let hh = m2 * a * 0.5 * b * s2;
        let tau1 = -k[0] * (y[0] - sp[0]) - d[0] * y[2] + hh * (2.0 * y[2] * y[3] + y[3] * y[3]);
        let tau2 = -k[1] * (y[1] - sp[1]) - d[1] * y[3] - hh * y[2] * y[2];
        let det = m11 * m22 - m12 * m12;
        [
            y[2],
            y[3],
            (m22 * tau1 - m12 * tau2) / det,
            (m11 * tau2 - m12 * tau1) / det,
        ]
    };
    let mut y = [
        l1.joint.initial_angle,
        l2.joint.initial_angle,
        l1.joint.initial_rate,
        l2.joint.initial_rate,
    ];
    let mut out = Vec::new();
    let mut t = 0.0;
    let mut next = 0;
    while next < samples.len() && t <= t_end + 1e-12 {
        if (t - samples[next]).abs() < 0.5 * dt {
            out.push([y[0], y[1]]);
            next += 1;
        }
        let k1 = f(y);
        let add = |y: [f64; 4], k: [f64; 4], s: f64| std::array::from_fn(|i| y[i] + s * k[i]);
        let k2 = f(add(y, k1, 0.5 * dt));
        let k3 = f(add(y, k2, 0.5 * dt));
        let k4 = f(add(y, k3, dt));
        y = std::array::from_fn(|i| y[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        t += dt;
    }
    out
}

#[test]
fn dyn_chain_rigid_limit_follows_rigid_two_link_model() {
    // EI × 1e4 (first bending frequency × 100): the joint angles of two-link-free must follow
    // the rigid arm. 11 stations, 0.5 s (the step shrinks 100×).
    let stiff = |sc: &mut data::Scene| {
        for l in &mut sc.planar_chain_mut().unwrap().links {
            l.bending_stiffness *= 1e4;
        }
    };
    let out = run("two-link-free", stiff, &with(11, 0.5));
    assert!(
        matches!(out.verdict, StabilityVerdict::Completed),
        "{:?}",
        out.verdict
    );
    let mut scene = load_scene("two-link-free").unwrap();
    stiff(&mut scene);
    let times = &out.observables.time;
    // RK4 at 1e-4 s: error ≈ (ω dt)⁴ with ω ≈ 10 rad/s ⇒ 1e-12, negligible
    let rigid = rigid_two_link(&scene, 0.5, 1e-4, times);
    assert_eq!(rigid.len(), times.len());
    let th1 = &out.observables.get("joint1.angle").unwrap().values;
    let th2 = &out.observables.get("joint2.angle").unwrap().values;
    let swing = |j: usize| {
        rigid.iter().map(|r| r[j]).fold(f64::NEG_INFINITY, f64::max)
            - rigid.iter().map(|r| r[j]).fold(f64::INFINITY, f64::min)
    };
    let mut worst = [0.0f64; 2];
    for (k, r) in rigid.iter().enumerate() {
        worst[0] = worst[0].max((th1[k] - r[0]).abs() / swing(0));
        worst[1] = worst[1].max((th2[k] - r[1]).abs() / swing(1));
    }
    eprintln!(
        "rigid limit (EI × 1e4, 11 stations): max |Δθ| / swing = {:.3e}, {:.3e}; {} steps, {:.2} s",
        worst[0], worst[1], out.cost.steps, out.cost.wall_time_s
    );
    // Trapezoid lumping misstates each link's inertia by ≈ h²/(2L²) = 0.5 % at 11 stations
    // (plus the O(h³) clamp inertias), residual flexibility ≈ 1e-4: the angle histories
    // agree to ≈ 1 % of their swing over 0.5 s; 2 % bound.
    assert!(worst[0] < 0.02 && worst[1] < 0.02, "{worst:?}");
}

#[test]
fn dyn_chain_two_step_scheme_is_caught_and_velocity_form_is_default() {
    // Damping and the velocity-dependent inertia forces of the free joints grow the two-step
    // scheme's spurious root (|ξ| > 1 for any step): the monitor stops it with a diagnostic,
    // which is why the chain's default (no time.method) is the velocity form.
    let mut s = with(11, 0.5);
    s.time.method = Some("report".parse().expect("a method name"));
    let out = run("two-link-free", |_| {}, &s);
    match &out.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            eprintln!("two-link-free, report: {diagnostic}");
            assert!(diagnostic.what.contains("parasitic"), "{}", diagnostic.what);
        }
        v => panic!("expected the computational mode to be caught: {v:?}"),
    }
    let out = run("two-link-free", |_| {}, &with(11, 0.5));
    assert!(matches!(out.verdict, StabilityVerdict::Completed));
}

#[test]
fn dyn_chain_deflected_beyond_its_length_stops_with_a_diagnostic() {
    // EI 10⁴ times lower: released from 45°/60° against the joint springs, the string-like
    // links swing out of the range of the chain's small-slope chord frames within
    // milliseconds. The clamp-frame tip deflection L·(−ε) passes a link length and the run
    // stops, keeping what it computed up to there. (At 10³ times lower the chain still
    // completes 2 s, link 1's tip deflection peaking at 2.58 of its 3 ft, fem 2.28.)
    let soft = |sc: &mut data::Scene| {
        for l in &mut sc.planar_chain_mut().unwrap().links {
            l.bending_stiffness *= 1e-4;
        }
    };
    let out = run("two-link-free", soft, &with(21, 2.0));
    let scene = load_scene("two-link-free").unwrap();
    match &out.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            assert!(
                diagnostic.what.contains("beyond the link length"),
                "{diagnostic:?}"
            );
            assert!(diagnostic.why.contains("tip chord"), "{diagnostic:?}");
        }
        v => panic!("expected a stop, got {v:?}"),
    }
    for (k, link) in scene.links().iter().enumerate() {
        let tip = &out
            .observables
            .get(&format!("link{}.tip_deflection", k + 1))
            .unwrap()
            .values;
        assert!(!tip.is_empty());
        let peak = tip.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(peak <= link.length, "link {}: {peak}", k + 1);
    }
}

#[test]
fn sys_chain_overextension_is_the_clamp_frame_tip_deflection_past_the_length() {
    // Link 1's station 1 (q-index 2, chord frame) set to −s·h from the undeformed state turns
    // the clamp against the chord by ε (Euler: (v₁ − x)/(2h) with the ghost x left at its rest
    // value 0, so ε = −s/2; Timoshenko: the first segment's slope, ε = −s). The clamp-frame tip
    // deflection L·(−ε) passes L only once |ε| > 1.
    for (name, per_h) in [("two-link-free", 0.5), ("barhorst-case1-timoshenko", 1.0)] {
        let scene = load_scene(name).unwrap();
        let stations = 11;
        let sys =
            TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(stations))
                .unwrap();
        let l1 = scene.links()[0].length;
        let h = l1 / (stations - 1) as f64;
        let (q0, _) = sys.initial_state();
        assert!(sys.overextended(&q0).is_none(), "{name}: at rest");
        let at = |s: f64| {
            let mut q = q0.clone();
            q[2] = -s * h;
            sys.overextended(&q)
        };
        // |ε| = per_h · s: just below and just above 1
        assert!(at(0.95 / per_h).is_none(), "{name}");
        let o = at(1.05 / per_h).unwrap_or_else(|| panic!("{name}: not caught"));
        assert_eq!(o.link, 1, "{name}");
        assert!(
            (o.deflection - 1.05 * l1).abs() < 1e-9 * l1,
            "{name}: {o:?}"
        );
    }
}

#[test]
fn dyn_chain_whip_beyond_the_default_step_stops_when_the_ledger_opens() {
    // EI 1000 times lower: the release whips the soft links faster than the default step (the
    // elastic bound of the chain linearized at t = 0) resolves. The run must not complete as
    // if it were a solution. At the default step (1.35e-3 s) the unresolved whip carries link
    // 1's tip deflection in its clamp-tangent frame, −L₁ψ₁, past the link's length in five
    // steps (14.3 against 3: a clamp slope of 4.8 against the chord), before the ledger watch
    // may judge (`LEDGER_SETTLED_STEPS` = 50): the overextension check stops it. (The check is
    // the chord-frame kinematics' too; there the clamp slope stayed below 1 and the ledger
    // stopped the run at step 50. In the clamp-tangent frames the clamp rotation moves every
    // point, by −s^t ψ̇.) At steps still too long for the whip but whose growth is slower
    // (1e-3, 7e-4 s) the driver stops at step 50 when the ledger's residual passes 5 % of the
    // energy that flowed. At a step that resolves the whip the same run closes its ledger, and
    // the closure falls at second order.
    let soft = |sc: &mut data::Scene| {
        for l in &mut sc.planar_chain_mut().unwrap().links {
            l.bending_stiffness *= 1e-3;
        }
    };
    let out = run("two-link-free", soft, &with(21, 0.1));
    match &out.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            eprintln!(
                "soft chain, default step: {diagnostic} after {} steps",
                out.cost.steps
            );
            assert!(
                diagnostic.what.contains("beyond the link length"),
                "{diagnostic:?}"
            );
        }
        v => panic!("expected a stop, got {v:?}"),
    }
    for dt in [1e-3, 7e-4] {
        let mut s = with(21, 0.1);
        s.time.dt = Some(dt);
        let out = run("two-link-free", soft, &s);
        match &out.verdict {
            StabilityVerdict::Stopped { diagnostic } => {
                eprintln!(
                    "soft chain, dt {dt:e}: {diagnostic} after {} steps",
                    out.cost.steps
                );
                assert!(diagnostic.what.contains("energy ledger"), "{diagnostic:?}");
                assert!(diagnostic.remedy.contains("--dt"), "{diagnostic:?}");
            }
            v => panic!("dt {dt:e}: expected a stop, got {v:?}"),
        }
    }
    let closure = |dt: f64| {
        let mut s = with(21, 0.1);
        s.time.dt = Some(dt);
        let out = run("two-link-free", soft, &s);
        assert!(matches!(out.verdict, StabilityVerdict::Completed));
        out.ledger.relative_closure()
    };
    let (c1, c2) = (closure(2e-5), closure(1e-5));
    eprintln!("soft chain: ledger closure {c1:.2e} at dt 2e-5, {c2:.2e} at 1e-5");
    assert!(c1 < 1e-3, "{c1}");
    let order = (c1 / c2).log2();
    assert!((1.7..2.3).contains(&order), "closure order {order}");
}

#[test]
fn elem_chain_gravity_potential_and_gap_are_those_of_the_lumped_points() {
    // V_g = −g·Σ m r and the gap g = n̂·(r_tip − p₀) of the clamp-tangent-frame positions
    // written independently (`point_positions`); G = ∂g/∂q against a central difference of
    // that tip position; the gravity force against the potential: M a = −∂V/∂q at q̇ = 0
    let scene = load_scene("barhorst-case1").unwrap();
    let pc = scene.planar_chain().unwrap();
    let mut sys = TwoLinkChain::from_planar_chain(&scene, pc, Some(9)).unwrap();
    let n = sys.dofs();
    let (q, _) = common::moving_chain_state(n);
    let gravity = pc.gravity.as_ref().unwrap().vector;
    let data::scene::Surface::Line { point, normal } = pc.contacts[0].surface else {
        panic!("line surface expected")
    };
    let ine = sys.inertia.clone();
    let zeros = vec![0.0; n];
    let energies = |sys: &TwoLinkChain, q: &[f64]| {
        let mut e = [0.0; 4];
        sys.stored_energies(0.0, q, &zeros, &mut e);
        e
    };
    let (pos, _) = point_positions(&ine, &q);
    let vg: f64 = -(0..ine.points())
        .map(|p| ine.point_mass(p) * (gravity[0] * pos[p][0] + gravity[1] * pos[p][1]))
        .sum::<f64>();
    let e = energies(&sys, &q);
    assert!((e[3] - vg).abs() < 1e-12 * vg.abs(), "{} vs {vg}", e[3]);
    let tip_gap = |q: &[f64]| {
        let (pos, _) = point_positions(&ine, q);
        let tip = pos[pos.len() - 1];
        (tip[0] - point[0]) * normal[0] + (tip[1] - point[1]) * normal[1]
    };
    let mut grad = vec![0.0; n];
    let g = sys.gap_gradient(&q, &mut grad);
    assert!(
        (g - tip_gap(&q)).abs() < 1e-13 * 5.0,
        "{g} vs {}",
        tip_gap(&q)
    );
    assert!((sys.gap(&q) - g).abs() == 0.0);
    let eps = 1e-6;
    for i in 0..n {
        let d = central_difference(tip_gap, &q, i, eps);
        // central difference of a smooth position (lengths ≈ 5): O(ε²) truncation,
        // round-off ≈ 1e-16·5/ε
        assert!((grad[i] - d).abs() < 1e-8, "G[{i}] {} vs {d}", grad[i]);
    }
    // M a = −∂V/∂q (strain, springs, gravity) at q̇ = 0: dampers give nothing
    let mut a = vec![0.0; n];
    sys.accel(0.0, &q, &zeros, &mut a);
    let mut ma = vec![0.0; n];
    sys.momenta(&q, &a, &mut ma);
    let potential = |x: &[f64]| {
        let e = energies(&sys, x);
        e[1] + e[2] + e[3]
    };
    assert_inertia_balances_potential(&ma, potential, &q);
}

#[test]
fn sys_chain_corrector_pass_equals_a_fresh_evaluation() {
    // The velocity form's corrector calls accel_split twice at one level; the second call
    // reuses the first pass's forces, Γ at the current drift velocity and M's columns. It must
    // give the bits a fresh evaluation gives, and a call at another state in between must not
    // let stale parts through.
    let scene = load_scene("two-link-free-undamped").unwrap();
    let chain = || {
        TwoLinkChain::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(11)).unwrap()
    };
    let n = chain().dofs();
    let (q, v) = common::moving_chain_state(n);
    let current: Vec<f64> = v.iter().map(|x| 0.9 * x).collect();
    let previous: Vec<f64> = v.iter().map(|x| 1.1 * x + 0.01).collect();
    let next: Vec<f64> = v.iter().map(|x| 0.8 * x - 0.02).collect();
    fn drift<'a>(
        current: &'a [f64],
        previous: &'a [f64],
        w: f64,
        predicted: &'a [f64],
    ) -> fdm::system::DriftVelocities<'a> {
        fdm::system::DriftVelocities {
            current,
            previous,
            w,
            predicted,
        }
    }
    let mut fresh = chain();
    let mut expected = vec![0.0; n];
    fresh.accel_split(0.3, &q, &v, drift(&current, &next, -0.5, &v), &mut expected);
    let mut sys = chain();
    let mut a = vec![0.0; n];
    sys.accel_split(0.3, &q, &v, drift(&current, &previous, 0.5, &v), &mut a);
    sys.accel_split(0.3, &q, &v, drift(&current, &next, -0.5, &v), &mut a);
    assert_eq!(a, expected);
    // another state in between (columns rebuilt at other q): the repeat is evaluated afresh
    let mut sys = chain();
    sys.accel_split(0.3, &q, &v, drift(&current, &previous, 0.5, &v), &mut a);
    let other: Vec<f64> = q.iter().map(|x| x + 1e-3).collect();
    sys.accel(0.3, &other, &v, &mut a);
    sys.accel_split(0.3, &q, &v, drift(&current, &next, -0.5, &v), &mut a);
    assert_eq!(a, expected);
}
