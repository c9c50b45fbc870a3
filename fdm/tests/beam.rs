//! Finite-difference cantilever: ghost-node stencils, frequencies and statics.
//! Run: CARGO_TARGET_DIR=/work/targets/fdm cargo test --release -p fdm --test beam -- --nocapture

use data::{Backend, BackendError, Scene, Settings, load_scene};
use fdm::FdmBackend;
use fdm::beam::Cantilever;

fn settings(stations: usize) -> Settings {
    let mut s = Settings::default();
    s.discretization.stations = Some(stations);
    s
}

/// Bisection to 1e-12 on a bracketing interval.
fn bisect(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let mut fa = f(a);
    assert!(fa * f(b) <= 0.0);
    while b - a > 1e-12 {
        let m = 0.5 * (a + b);
        let fm = f(m);
        if fa * fm <= 0.0 {
            b = m;
        } else {
            a = m;
            fa = fm;
        }
    }
    0.5 * (a + b)
}

/// First `n` roots β of the clamped-free characteristic equation with tip-mass ratio μ:
/// 1 + cos β cosh β + μβ (cos β sinh β − sin β cosh β) = 0 (μ = 0: the plain cantilever).
fn betas(mu: f64, n: usize) -> Vec<f64> {
    let f = |b: f64| 1.0 + b.cos() * b.cosh() + mu * b * (b.cos() * b.sinh() - b.sin() * b.cosh());
    // scale by 1/cosh to keep the scan well conditioned
    let g = |b: f64| f(b) / b.cosh();
    let mut roots = Vec::new();
    let mut a = 0.05;
    while roots.len() < n {
        let b = a + 0.01;
        if g(a) * g(b) <= 0.0 {
            roots.push(bisect(g, a, b));
        }
        a = b;
    }
    roots
}

fn analytic_hz(scene: &Scene, n: usize) -> Vec<f64> {
    let l = &scene.links()[0];
    let mu = l.tip_mass.unwrap_or(0.0) / l.beam_mass();
    betas(mu, n)
        .iter()
        .map(|b| {
            b * b / (2.0 * std::f64::consts::PI * l.length.powi(2))
                * (l.bending_stiffness / l.mass_per_length).sqrt()
        })
        .collect()
}

#[test]
fn sys_cantilever_dof_plan_counts() {
    let scene = load_scene("cantilever").unwrap();
    let plan = FdmBackend
        .dof_plan(&scene, &settings(41).discretization)
        .unwrap();
    // 41 stations, the clamped station is not a DOF; ghost nodes are not DOFs.
    assert_eq!(plan.total(), 40);
    let plan = FdmBackend.dof_plan(&scene, &Default::default()).unwrap();
    assert_eq!(plan.total(), fdm::beam::DEFAULT_STATIONS - 1);
}

#[test]
fn elem_cantilever_rows_equal_ghost_node_stencils() {
    let scene = load_scene("cantilever").unwrap();
    let c = Cantilever::from_planar_chain(&scene, scene.planar_chain().unwrap(), Some(12)).unwrap();
    let k = c.stiffness();
    let m = c.masses();
    let n = c.dofs();
    for i in 0..n {
        for j in 0..n {
            assert_eq!(k[(i, j)], k[(j, i)], "symmetric");
        }
    }
    // w at stations 0..r (w0 = 0), with ghosts: clamped w_{-1} = w_1; free (5.32 mirrored):
    // w_{r+1} = 2w_r − w_{r−1}, w_{r+2} = w_{r−2} − 2w_{r−1} + 2w_{r+1}.
    let w: Vec<f64> = (0..=n)
        .map(|i| {
            if i == 0 {
                0.0
            } else {
                (0.3 * i as f64).sin() + 0.01 * i as f64
            }
        })
        .collect();
    let r = n;
    let at = |i: isize| -> f64 {
        match i {
            -1 => w[1],
            i if i as usize <= r => w[i as usize],
            i if i as usize == r + 1 => 2.0 * w[r] - w[r - 1],
            _ => w[r - 2] - 2.0 * w[r - 1] + 2.0 * (2.0 * w[r] - w[r - 1]),
        }
    };
    let h4 = c.h.powi(4);
    for i in 1..=r {
        let ii = i as isize;
        let d4 =
            (at(ii - 2) - 4.0 * at(ii - 1) + 6.0 * at(ii) - 4.0 * at(ii + 1) + at(ii + 2)) / h4;
        let kw: f64 = (0..n).map(|j| k[(i - 1, j)] * w[j + 1]).sum();
        // lumped length: h inside, h/2 at the free end
        let len = m[i - 1] / c.rho_a;
        let row = kw / len;
        // same arithmetic up to summation order: relative 1e-9
        assert!(
            (row - c.ei * d4).abs() < 1e-9 * (c.ei * d4).abs().max(1.0),
            "station {i}: {row} vs {}",
            c.ei * d4
        );
    }
}

fn observed_orders(name: &str, nmodes: usize) -> Vec<f64> {
    let scene = load_scene(name).unwrap();
    let exact = analytic_hz(&scene, nmodes);
    let ladder = [21usize, 41, 81, 161];
    let errs: Vec<Vec<f64>> = ladder
        .iter()
        .map(|&n| {
            let r = FdmBackend.modes(&scene, &settings(n), nmodes).unwrap();
            r.frequencies_hz
                .iter()
                .zip(&exact)
                .map(|(f, e)| (f - e).abs() / e)
                .collect()
        })
        .collect();
    (0..nmodes)
        .map(|k| {
            let (e1, e2) = (errs[ladder.len() - 2][k], errs[ladder.len() - 1][k]);
            let p = (e1 / e2).ln() / 2.0f64.ln(); // h halves (stations − 1 doubles)
            eprintln!(
                "{name} mode {}: exact {:.6} Hz, rel. errors {:?}, observed order {p:.3}",
                k + 1,
                exact[k],
                errs.iter().map(|e| e[k]).collect::<Vec<_>>()
            );
            p
        })
        .collect()
}

#[test]
fn conv_cantilever_frequencies_converge_at_second_order() {
    for p in observed_orders("cantilever", 3) {
        // central differences: O(h²)
        assert!((p - 2.0).abs() < 0.2, "{p}");
    }
}

#[test]
fn conv_cantilever_tip_mass_frequencies_converge_at_second_order() {
    for p in observed_orders("cantilever-tip-mass", 3) {
        assert!((p - 2.0).abs() < 0.2, "{p}");
    }
}

#[test]
fn sys_cantilever_statics_converge_to_pl3_3ei_plus_ql4_8ei() {
    let scene = load_scene("cantilever").unwrap();
    let l = &scene.links()[0];
    let st = scene.statics().unwrap();
    let (p, q) = (st.tip_force.unwrap(), st.distributed_load.unwrap());
    let ei = l.bending_stiffness;
    let len = l.length;
    let exact = p * len.powi(3) / (3.0 * ei) + q * len.powi(4) / (8.0 * ei);
    let exact_rot = p * len * len / (2.0 * ei) + q * len.powi(3) / (6.0 * ei);
    let e: Vec<(f64, f64)> = [41usize, 81, 161]
        .iter()
        .map(|&n| {
            let r = FdmBackend.statics(&scene, &settings(n)).unwrap();
            (
                (r.tip_deflection - exact).abs() / exact,
                (r.tip_rotation - exact_rot).abs() / exact_rot,
            )
        })
        .collect();
    eprintln!("statics rel. errors (deflection, rotation): {e:?}");
    let pd = (e[1].0 / e[2].0).log2();
    let pr = (e[1].1 / e[2].1).log2();
    eprintln!("observed orders: deflection {pd:.3}, rotation {pr:.3}");
    // clamped ghost node w₋₁ = w₁ is a second-order slope condition
    assert!((pd - 2.0).abs() < 0.2 && (pr - 2.0).abs() < 0.2);
}

#[test]
fn sys_unsupported_scenes_say_what_is_missing() {
    // (two-link-free(-undamped): tests/chain.rs; the barhorst contact scenes: tests/contact.rs;
    // barhorst-case1-timoshenko runs: tests/timoshenko.rs)
    for name in [
        "spin-up-axial",
        "rotating-beam-axial",
        "cantilever",
        "cantilever-axial",
        "cantilever-timoshenko",
        "constrained-arm",
        "mobile-manipulator",
    ] {
        let scene = load_scene(name).unwrap();
        match FdmBackend.simulate(&scene, &Settings::default()) {
            Err(BackendError::Unsupported(msg)) => {
                eprintln!("{name}: {msg}");
                assert!(msg.contains("fdm"), "{msg}");
                assert!(
                    msg.contains(name) || msg.contains("payload") || msg.contains("mobile"),
                    "{msg}"
                );
            }
            other => panic!(
                "{name}: expected Unsupported, got {:?}",
                other.map(|r| r.verdict)
            ),
        }
    }
    let scene = load_scene("cantilever-timoshenko").unwrap();
    match FdmBackend
        .modes(&scene, &Settings::default(), 3)
        .unwrap_err()
    {
        BackendError::Unsupported(msg) => assert!(msg.contains("shear"), "{msg}"),
        e => panic!("{e:?}"),
    }
}

fn rotating_scene(lambda: f64) -> Scene {
    let mut scene = load_scene("rotating-beam").unwrap();
    let l = &scene.links()[0];
    let omega = lambda * (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt();
    scene.planar_chain_mut().unwrap().links[0].joint.prescribed =
        Some(data::scene::PrescribedMotion::ConstantRate { rate: omega });
    scene
}

/// Southwell coefficient α₁ = ∫ T φ'² / (Ω² ∫ ρA φ²) for the first clamped-free mode,
/// T = ρAΩ²(L² − x²)/2 (L = ρA = 1), φ from β₁ (root finding), Simpson quadrature.
fn southwell_alpha() -> f64 {
    let b = betas(0.0, 1)[0];
    let sg = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
    let phi = |x: f64| (b * x).cosh() - (b * x).cos() - sg * ((b * x).sinh() - (b * x).sin());
    let dphi =
        |x: f64| b * ((b * x).sinh() + (b * x).sin() - sg * ((b * x).cosh() - (b * x).cos()));
    let n = 4000;
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..=n {
        let x = i as f64 / n as f64;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        num += w * 0.5 * (1.0 - x * x) * dphi(x).powi(2);
        den += w * phi(x).powi(2);
    }
    num / den
}

#[test]
fn sys_rotating_beam_in_plane_slope_matches_southwell_minus_one() {
    // In-plane: ω² = ω₀² + (α₁ − 1)Ω² + O(Ω⁴) (centrifugal stiffening α₁ minus the rotating
    // frame's softening 1).
    let alpha = southwell_alpha();
    let l = load_scene("rotating-beam").unwrap().links()[0].clone();
    let scale = l.bending_stiffness / (l.mass_per_length * l.length.powi(4));
    let w2 = |lambda: f64| {
        let r = FdmBackend
            .modes(&rotating_scene(lambda), &settings(161), 1)
            .unwrap();
        (2.0 * std::f64::consts::PI * r.frequencies_hz[0]).powi(2) / scale
    };
    let lam = 0.5;
    let slope = (w2(lam) - w2(0.0)) / (lam * lam);
    eprintln!(
        "Southwell α₁ = {alpha:.6}; FD in-plane slope {slope:.6} vs α₁ − 1 = {:.6}",
        alpha - 1.0
    );
    // FD error O(h²) ≈ 3e-5 relative at 161 stations; O(Ω⁴) term ≈ (0.05)²/Δω² ≈ 1e-4 relative
    assert!(
        (slope - (alpha - 1.0)).abs() < 2e-3 * (alpha - 1.0),
        "{slope}"
    );
}

#[test]
fn conv_rotating_beam_frequencies_second_order_by_richardson() {
    for lambda in [4.0, 12.0] {
        let f: Vec<f64> = [41usize, 81, 161]
            .iter()
            .map(|&n| {
                FdmBackend
                    .modes(&rotating_scene(lambda), &settings(n), 1)
                    .unwrap()
                    .frequencies_hz[0]
            })
            .collect();
        let p = ((f[0] - f[1]) / (f[1] - f[2])).abs().log2();
        let l = load_scene("rotating-beam").unwrap().links()[0].clone();
        let nondim = 2.0 * std::f64::consts::PI * f[2]
            / (l.bending_stiffness / (l.mass_per_length * l.length.powi(4))).sqrt();
        eprintln!(
            "rotating beam λ = {lambda}: first in-plane ω√(ρAL⁴/EI) = {nondim:.4}, observed order {p:.3}"
        );
        assert!((p - 2.0).abs() < 0.2, "{p}");
    }
}
