//! Integration checks of the analytic references on the catalog scenes: every reference a scene
//! asks for is computed from the scene's own parameters, is finite, and has the qualitative
//! properties physics demands. Run with `--nocapture` to see the values.

use verify::analytic as ana;

#[test]
fn ana_catalog_cantilever_family() {
    let scene = data::load_scene("cantilever").unwrap();
    let l = &scene.links()[0];
    let (ei, ra, len) = (l.bending_stiffness, l.mass_per_length, l.length);
    for kind in [
        ana::BeamSupport::ClampedFree,
        ana::BeamSupport::FreeFree,
        ana::BeamSupport::PinnedFree,
        ana::BeamSupport::ClampedPinned,
    ] {
        let f = ana::bending_frequencies_hz(kind, ei, ra, len, 5).unwrap();
        println!("{kind:?}: {f:?} Hz");
        assert!(f.windows(2).all(|w| w[1] > w[0]));
    }
    // Elastica for every load parameter the scene lists: transverse tip deflection below the
    // linear value α/3 (the tip rotates away from the load) and rising with α.
    let statics = scene.statics().cloned().unwrap_or_default();
    let mut last = 0.0;
    for &alpha in &statics.elastica_load_parameters {
        let e = ana::cantilever_elastica(alpha).unwrap();
        println!(
            "elastica alpha = {alpha}: y/L = {:.10}, u/L = {:.10}, tip angle = {:.10}",
            e.tip_transverse, e.tip_axial, e.tip_rotation
        );
        assert!(e.tip_transverse < alpha / 3.0 && e.tip_transverse > last);
        last = e.tip_transverse;
    }

    let tm = data::load_scene("cantilever-tip-mass").unwrap();
    let l = &tm.links()[0];
    let f = ana::cantilever_tip_mass_frequencies_hz(
        l.bending_stiffness,
        l.mass_per_length,
        l.length,
        l.tip_mass.unwrap_or(0.0),
        l.tip_inertia.unwrap_or(0.0),
        5,
    )
    .unwrap();
    println!("tip mass: {f:?} Hz");

    let ts = data::load_scene("cantilever-timoshenko").unwrap();
    let beam = ana::TimoshenkoBeam::from_link(&ts.links()[0]).unwrap();
    let f = ana::timoshenko_clamped_free_hz(&beam, 5).unwrap();
    let eb = ana::bending_frequencies_hz(
        ana::BeamSupport::ClampedFree,
        beam.ei,
        beam.rho_a,
        beam.length,
        5,
    )
    .unwrap();
    println!("timoshenko: {f:?} Hz (Euler-Bernoulli {eb:?})");
    assert!(f.iter().zip(&eb).all(|(t, e)| t < e));

    let ax = data::load_scene("cantilever-axial").unwrap();
    let l = &ax.links()[0];
    let f = ana::axial_frequencies_hz(l.axial_stiffness.unwrap(), l.mass_per_length, l.length, 3)
        .unwrap();
    println!("axial: {f:?} Hz");
}

#[test]
fn ana_catalog_rotating_beam_speeds() {
    let scene = data::load_scene("rotating-beam").unwrap();
    let speeds = scene
        .studies()
        .map(|s| s.rotation_speeds.clone())
        .unwrap_or_default();
    assert!(!speeds.is_empty(), "rotating-beam lists its speeds");
    let mut prev_out: Option<Vec<f64>> = None;
    for &lambda in &speeds {
        let out = ana::rotating_frequencies(ana::RotatingPlane::Flapwise, lambda, 5).unwrap();
        let inp = ana::rotating_frequencies(ana::RotatingPlane::InPlane, lambda, 5).unwrap();
        println!("lambda = {lambda:>4}: flapwise {out:.8?}\n              in-plane {inp:.8?}");
        if let Some(p) = &prev_out {
            assert!(
                out.iter().zip(p).all(|(a, b)| a > b),
                "flapwise rises with speed"
            );
        }
        prev_out = Some(out);
    }
}

#[test]
fn ana_catalog_rigid_limits() {
    let s = data::load_scene("single-link").unwrap();
    let r = ana::RigidLink::from_chain(s.planar_chain().unwrap()).unwrap();
    let end = r.state(s.simulation.t_end).unwrap();
    println!("single-link rigid: theta(t_end) = {:.12}", end.angle);

    let s = data::load_scene("constrained-arm").unwrap();
    let c = ana::ConstrainedRigidLink::from_chain(s.planar_chain().unwrap()).unwrap();
    let end = c.state(s.simulation.t_end).unwrap();
    println!(
        "constrained-arm rigid: theta = {:.12}, rate = {:.12} (terminal {:.12}), N = {:.10}, W_f = {:.10}",
        end.angle,
        end.rate,
        c.terminal_rate(2.0),
        end.normal_force,
        end.friction_work
    );
    assert!(end.friction_work > 0.0 && end.friction_work < end.input_work);

    let s = data::load_scene("two-link-free").unwrap();
    let arm = ana::RigidTwoLink::from_chain(s.planar_chain().unwrap()).unwrap();
    let t0 = std::time::Instant::now();
    let h = arm
        .simulate(&ana::output_times(
            s.simulation.t_end,
            s.simulation.output_interval,
        ))
        .unwrap();
    println!(
        "two-link-free rigid: q1(t_end) = {:.10}, q5(t_end) = {:.10}, {} steps, {:.1} ms",
        h.q1.last().unwrap(),
        h.q5.last().unwrap(),
        h.stats.accepted_steps,
        t0.elapsed().as_secs_f64() * 1e3
    );

    let s = data::load_scene("barhorst-case1-stiff-elbow").unwrap();
    let rest = ana::resting_from_chain(s.planar_chain().unwrap()).unwrap();
    println!(
        "stiff-elbow at rest: straight N = {:.10}, with elbow spring N = {:.10} (q5 = {:.3e})",
        rest.straight.normal_force,
        rest.elbow_spring.unwrap().normal_force,
        rest.elbow_spring.unwrap().q5
    );
}

#[test]
fn ana_catalog_rocket_translation() {
    for name in [
        "rocket",
        "rocket-case2",
        "rocket-launch-60",
        "rocket-launch-75",
    ] {
        let s = data::load_scene(name).unwrap();
        let r = ana::RocketTranslation::from_rocket(s.rocket().unwrap()).unwrap();
        let st = r.state(s.simulation.t_end).unwrap();
        println!(
            "{name}: t = {}, m = {:.10}, v_axis = {:.10}, s_axis = {:.10}, cg = ({:.10}, {:.10})",
            st.time, st.mass, st.axial_velocity, st.axial_displacement, st.cg_x, st.cg_y
        );
        assert!(st.axial_velocity > 0.0 && st.mass < r.initial_mass);
    }
}

#[test]
fn ana_high_modes_are_robust() {
    // High modes: the scaled equations neither overflow nor lose the roots.
    let x = ana::beam_eigenvalues(ana::BeamSupport::ClampedFree, 100).unwrap();
    // Beyond n = 10 (x > 30) the e^{-x} corrections are < 1e-12: spacing π to round-off of x.
    assert!(
        x[10..]
            .windows(2)
            .all(|w| (w[1] - w[0] - std::f64::consts::PI).abs() < 1e-11)
    );
    let mu = ana::rotating_frequencies(ana::RotatingPlane::Flapwise, 12.0, 10).unwrap();
    println!("flapwise lambda = 12, 10 modes: {mu:.6?}");
    assert!(mu.windows(2).all(|w| w[1] > w[0]));
    // At λ = 0 the 10th root must still equal the closed form (double-double series).
    let mu0 = ana::rotating_frequencies(ana::RotatingPlane::Flapwise, 0.0, 10).unwrap();
    let x = ana::beam_eigenvalues(ana::BeamSupport::ClampedFree, 10).unwrap();
    for (m, xk) in mu0.iter().zip(&x) {
        // Brent 1e-14 on both sides; the series is summed in double-double.
        assert!((m - xk * xk).abs() < 1e-12 * m, "{m} vs {}", xk * xk);
    }
    // Far beyond the scenes' λ ≤ 12: tension dominates and every flapwise frequency exceeds
    // the spin rate (the centrifugal field alone gives ω ≥ Ω for a clamped root).
    let fast = ana::rotating_frequencies(ana::RotatingPlane::Flapwise, 100.0, 4).unwrap();
    println!("flapwise lambda = 100: {fast:.6?}");
    assert!(fast[0] > 100.0 && fast.windows(2).all(|w| w[1] > w[0]));
    let ts = data::load_scene("cantilever-timoshenko").unwrap();
    let beam = ana::TimoshenkoBeam::from_link(&ts.links()[0]).unwrap();
    let f = ana::timoshenko_clamped_free_hz(&beam, 12).unwrap();
    println!(
        "timoshenko 12 modes: {f:.3?} Hz, cut-off {:.3} Hz",
        beam.cutoff_rad_s() / (2.0 * std::f64::consts::PI)
    );
    assert!(f.windows(2).all(|w| w[1] > w[0]));
}
