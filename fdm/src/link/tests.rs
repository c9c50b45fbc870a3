use super::*;
use crate::driver::{StepControl, integrate};
use crate::runs::single_link as simulate;
use data::Settings;

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
    let c = crate::beam::Cantilever::from_scene(&data::load_scene("cantilever").unwrap(), Some(9))
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

/// The link's kinetic energy is the exact kinetic energy of its lumped points at (x − s, v) in
/// the rotating frame (s_i = ½h Σ_{seg<i} g_seg², the foreshortening) truncated to second order
/// in v: the remainder ΔT = ½ Σ m_i [θ̇² s_i² + 2θ̇(v_i ṡ_i − s_i v̇_i) + ṡ_i²] (third and fourth
/// order) is what this model leaves out, and what fem (T = ½Σm|ṙ|²) and modal (its
/// `exact_inextensible_terms`) keep. Checked on a lagging spin-up shape of the size the 20 s run
/// reaches (tip ≈ 0.4 m), where ΔT is 4.9e-3 of the elastic kinetic energy ½Σm(v̇² + θ̇²v²).
#[test]
fn elem_link_kinetic_energy_is_the_exact_one_less_the_inextensible_remainder() {
    let scene = data::load_scene("spin-up").unwrap();
    let link = FloatingLink::from_scene(&scene, Some(21)).unwrap();
    let (r, h) = (link.r, link.h);
    let t = 12.0;
    let n = link.dofs();
    let (q0, v0) = (vec![0.0; n], vec![0.0; n]);
    let (_, rate, _) = link.hub_state(t, &q0, &v0);
    assert!(rate > 2.0, "mid-ramp hub rate {rate}");
    // static-like lagging shape (tip −0.4 m) and a vibration velocity
    let len = link.length;
    let x = |i: usize| i as f64 * h;
    let vs: Vec<f64> = (1..=r)
        .map(|i| {
            let xi = x(i) / len;
            -0.4 * xi * xi * (3.0 - xi) / 2.0
        })
        .collect();
    let vd: Vec<f64> = (1..=r)
        .map(|i| 0.3 * (std::f64::consts::PI * x(i) / (2.0 * len)).sin())
        .collect();
    let mut out = [0.0; 3];
    link.stored_energies(t, &vs, &vd, &mut out);
    let ke_model = out[0];

    // exact kinetic energy of the points (x_i − s_i, v_i) of a frame turning at θ̇
    let (mut s, mut sd) = (0.0, 0.0);
    let mut ke_exact = 0.5 * link.hub * rate * rate;
    let mut remainder = 0.0;
    let mut ke_elastic = 0.0;
    for i in 1..=r {
        let (g, gd) = (
            (vs[i - 1] - FloatingLink::at(&vs, i - 1)) / h,
            (vd[i - 1] - FloatingLink::at(&vd, i - 1)) / h,
        );
        s += 0.5 * h * g * g;
        sd += h * g * gd;
        let m = link.m[i - 1];
        let (v, vdot) = (vs[i - 1], vd[i - 1]);
        let vel = [-sd - rate * v, vdot + rate * (x(i) - s)];
        ke_exact += 0.5 * m * (vel[0] * vel[0] + vel[1] * vel[1]);
        remainder += 0.5 * m * (rate * rate * s * s + 2.0 * rate * (v * sd - s * vdot) + sd * sd);
        ke_elastic += 0.5 * m * (vdot * vdot + (rate * v).powi(2));
    }
    let missing = ke_exact - ke_model;
    assert!(
        (missing - remainder).abs() < 1e-12 * ke_exact,
        "T_exact − T_fdm = {missing:e}, ΔT = {remainder:e}"
    );
    // the identity has power: ΔT is far above the round-off the check allows
    let share = remainder.abs() / ke_elastic;
    assert!(share > 1e-4, "ΔT / elastic kinetic energy = {share:e}");
}
