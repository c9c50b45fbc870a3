//! Linearized natural frequencies of the two-link chain (`modes two-link-free`) against the
//! Euler–Bernoulli frequencies of the straight chain, computed here from the scene: the 8×8
//! determinant of two uniform beams with a rotational spring K₁ to the ground at x = 0, a
//! rotational spring K₂ at the elbow and a free end, in the limits K → 0 (pinned / hinged /
//! free), K → ∞ (one clamped-free beam of length L₁ + L₂: 1 + cos βL cosh βL = 0) and at the
//! scene's own springs. Run: cargo test --release -p fdm --test chain_modes -- --nocapture

#![allow(clippy::needless_range_loop)]

use data::{Backend, Scene, Settings, load_scene};
use fdm::FdmBackend;

/// The straight chain's beams: (length, EI, ρA) of links 1 and 2.
fn beams(scene: &Scene) -> [(f64, f64, f64); 2] {
    [0, 1].map(|k| {
        let l = &scene.links()[k];
        (l.length, l.bending_stiffness, l.mass_per_length)
    })
}

/// Determinant of the boundary and joint conditions at angular frequency ω, springs (K₁, K₂)
/// (`None`: rigid joint). w_i = a cos βx + b sin βx + c cosh βx + d sinh βx per link; rows
/// scaled by powers of β so that every entry is O(cosh βL).
fn det(b: [(f64, f64, f64); 2], k: [Option<f64>; 2], omega: f64) -> f64 {
    let beta = b.map(|(_, ei, ra)| (omega * omega * ra / ei).powf(0.25));
    // derivative d (0..=3) of the four basis functions at x, divided by β^d
    let basis = |bt: f64, x: f64, d: usize| -> [f64; 4] {
        let (s, c, sh, ch) = (
            (bt * x).sin(),
            (bt * x).cos(),
            (bt * x).sinh(),
            (bt * x).cosh(),
        );
        match d {
            0 => [c, s, ch, sh],
            1 => [-s, c, sh, ch],
            2 => [-c, -s, ch, sh],
            _ => [s, -c, sh, ch],
        }
    };
    let mut m = [[0.0f64; 8]; 8];
    let put = |row: &mut [f64; 8], link: usize, v: [f64; 4], w: f64| {
        for j in 0..4 {
            row[4 * link + j] += w * v[j];
        }
    };
    let (l1, ei1, _) = b[0];
    let (l2, ei2, _) = b[1];
    let (b1, b2) = (beta[0], beta[1]);
    // ground: w₁(0) = 0; EI w₁''(0) = K₁ w₁'(0)
    put(&mut m[0], 0, basis(b1, 0.0, 0), 1.0);
    match k[0] {
        Some(k1) => {
            put(&mut m[1], 0, basis(b1, 0.0, 2), ei1 * b1);
            put(&mut m[1], 0, basis(b1, 0.0, 1), -k1);
        }
        None => put(&mut m[1], 0, basis(b1, 0.0, 1), 1.0),
    }
    // elbow: w₁(L₁) = w₂(0); EI₁w₁'''(L₁) = EI₂w₂'''(0);
    // EI₁w₁''(L₁) = K₂(w₂'(0) − w₁'(L₁)) = EI₂w₂''(0)
    put(&mut m[2], 0, basis(b1, l1, 0), 1.0);
    put(&mut m[2], 1, basis(b2, 0.0, 0), -1.0);
    put(&mut m[3], 0, basis(b1, l1, 3), ei1 * b1.powi(3));
    put(&mut m[3], 1, basis(b2, 0.0, 3), -ei2 * b2.powi(3));
    put(&mut m[4], 0, basis(b1, l1, 2), ei1 * b1 * b1);
    put(&mut m[4], 1, basis(b2, 0.0, 2), -ei2 * b2 * b2);
    match k[1] {
        Some(k2) => {
            put(&mut m[5], 0, basis(b1, l1, 2), ei1 * b1 * b1);
            put(&mut m[5], 1, basis(b2, 0.0, 1), -k2 * b2);
            put(&mut m[5], 0, basis(b1, l1, 1), k2 * b1);
        }
        None => {
            put(&mut m[5], 1, basis(b2, 0.0, 1), b2);
            put(&mut m[5], 0, basis(b1, l1, 1), -b1);
        }
    }
    // free end: w₂''(L₂) = w₂'''(L₂) = 0
    put(&mut m[6], 1, basis(b2, l2, 2), 1.0);
    put(&mut m[7], 1, basis(b2, l2, 3), 1.0);
    // Gaussian elimination with partial pivoting
    let mut d = 1.0;
    for c in 0..8 {
        let p = (c..8)
            .max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            .unwrap();
        if m[p][c] == 0.0 {
            return 0.0;
        }
        if p != c {
            m.swap(p, c);
            d = -d;
        }
        d *= m[c][c];
        for r in c + 1..8 {
            let f = m[r][c] / m[c][c];
            for j in c..8 {
                m[r][j] -= f * m[c][j];
            }
        }
    }
    d
}

/// The lowest `count` positive roots of `f`, by a scan from `lo` in steps `step` and bisection.
fn roots(f: impl Fn(f64) -> f64, lo: f64, step: f64, count: usize) -> Vec<f64> {
    let mut out = Vec::new();
    let (mut a, mut fa) = (lo, f(lo));
    while out.len() < count {
        let b = a + step;
        let fb = f(b);
        if fa == 0.0 || fa.signum() != fb.signum() {
            let (mut x0, mut x1, mut f0) = (a, b, fa);
            for _ in 0..200 {
                let xm = 0.5 * (x0 + x1);
                let fm = f(xm);
                if f0.signum() == fm.signum() {
                    (x0, f0) = (xm, fm);
                } else {
                    x1 = xm;
                }
            }
            out.push(0.5 * (x0 + x1));
        }
        (a, fa) = (b, fb);
    }
    out
}

/// fdm's lowest non-zero frequencies (rad/time), `count` of them, at `stations` per link.
fn fdm_flexible(scene: &Scene, stations: usize, count: usize) -> (Vec<f64>, usize) {
    let mut s = Settings::default();
    s.discretization.stations = Some(stations);
    let r = FdmBackend.modes(scene, &s, 100).expect("modes");
    let rigid = r.kinds.iter().filter(|k| *k == "rigid").count();
    let w: Vec<f64> = r
        .frequencies_hz
        .iter()
        .zip(&r.kinds)
        .filter(|(_, k)| *k != "rigid")
        .map(|(f, _)| f * 2.0 * std::f64::consts::PI)
        .take(count)
        .collect();
    (w, rigid)
}

/// The straight scene (both joints at angle 0) with springs scaled by `spring`.
fn straight(spring: f64) -> Scene {
    let mut scene = load_scene("two-link-free").unwrap();
    for l in &mut scene.planar_chain_mut().unwrap().links {
        let j = &mut l.joint;
        j.set_point = Some(0.0);
        j.initial_angle = 0.0;
        j.stiffness = j.stiffness.map(|k| k * spring);
    }
    scene
}

/// Errors of the lowest `count` fdm frequencies against `exact` at 21/41/81 stations: asserts
/// an observed order in [`min_order`, 2.3] on each halving (same sign of the error) and returns
/// the relative errors.
fn check_order(
    label: &str,
    scene: &Scene,
    exact: &[f64],
    rigid_expected: usize,
    min_order: f64,
) -> [Vec<f64>; 3] {
    let count = exact.len();
    let errs = [21, 41, 81].map(|n| {
        let (w, rigid) = fdm_flexible(scene, n, count);
        assert_eq!(
            rigid, rigid_expected,
            "{label}: rigid modes at {n} stations"
        );
        let e: Vec<f64> = w.iter().zip(exact).map(|(a, b)| (a - b) / b).collect();
        eprintln!("{label}: {n} stations: ω {w:.6?} exact {exact:.6?} rel. err {e:.3?}");
        e
    });
    for m in 0..count {
        for k in 0..2 {
            let order = (errs[k][m] / errs[k + 1][m]).abs().log2();
            eprintln!("{label}: mode {}: observed order {order:.3}", m + 1);
            assert!(
                (min_order..2.3).contains(&order) && errs[k][m].signum() == errs[k + 1][m].signum(),
                "{label}: mode {} order {order} ({:e} → {:e})",
                m + 1,
                errs[k][m],
                errs[k + 1][m]
            );
        }
    }
    errs
}

#[test]
fn conv_chain_modes_soft_joints_tend_to_the_pinned_hinged_free_chain() {
    // K → 0: no springs; the chain keeps two rigid modes (turning about the pin, folding at the
    // elbow) and its flexible modes are those of the pinned / hinged / free straight chain.
    let scene = straight(0.0);
    let b = beams(&scene);
    let w1 = (b[0].1 / b[0].2).sqrt() / (b[0].0 * b[0].0); // √(EI/ρA L₁⁴)
    let exact = roots(
        |w| det(b, [Some(0.0), Some(0.0)], w),
        0.5 * w1,
        0.05 * w1,
        3,
    );
    let errs = check_order("K → 0", &scene, &exact, 2, 1.8);
    assert!(errs[2].iter().all(|e| e.abs() < 2e-3), "{errs:?}");
}

#[test]
fn conv_chain_modes_stiff_joints_tend_to_the_clamped_free_beam() {
    // K → ∞: one clamped-free beam of length L = L₁ + L₂ (same EI, ρA): β_nL from
    // 1 + cos x cosh x = 0 (x₁ = 1.8751…), ω_n = (β_nL)² √(EI/(ρA L⁴)).
    let b0 = beams(&load_scene("two-link-free").unwrap());
    let (ei, ra) = (b0[0].1, b0[0].2);
    assert_eq!(
        (b0[1].1, b0[1].2),
        (ei, ra),
        "the limit needs equal sections"
    );
    let l = b0[0].0 + b0[1].0;
    let x = roots(|x| 1.0 + x.cos() * x.cosh(), 0.5, 0.01, 3);
    let clamped: Vec<f64> = x
        .iter()
        .map(|x| x * x * (ei / (ra * l.powi(4))).sqrt())
        .collect();
    eprintln!("clamped-free βL: {x:.6?}");
    assert!((x[0] - 1.8751).abs() < 1e-4);
    // the determinant with rigid joints, and with springs × 1e7, gives the same frequencies
    let scene0 = straight(1.0);
    let k_scene = [0, 1].map(|i| scene0.links()[i].joint.stiffness.unwrap());
    let search =
        |k: [Option<f64>; 2]| roots(|w| det(b0, k, w), 0.5 * clamped[0], 0.01 * clamped[0], 3);
    for (a, e) in search([None, None]).iter().zip(&clamped) {
        assert!((a - e).abs() < 1e-9 * e, "rigid joints: {a} vs {e}");
    }
    let huge = search(k_scene.map(|k| Some(k * 1e7)));
    for (a, e) in huge.iter().zip(&clamped) {
        assert!((a - e).abs() < 1e-5 * e, "springs × 1e7: {a} vs {e}");
    }
    // fdm with springs × 1e4 (K₁ = 1.2e6, K₂ = 2e5; stiffer springs put the top eigenvalue,
    // K over the clamp inertia ρAh³/24, where its round-off reaches the low modes) against the
    // exact frequencies of those springs, already within 1.2 % of the clamped limit.
    let spring = 1e4;
    let exact = search(k_scene.map(|k| Some(k * spring)));
    for (a, e) in exact.iter().zip(&clamped) {
        assert!((a - e).abs() < 1.2e-2 * e, "springs × {spring}: {a} vs {e}");
    }
    // The moment-carrying elbow is second order (observed 2.00): link 1's tip ghost carries
    // the trapezoid end term of the bending energy and the central tip slope, so the elbow
    // spring's moment is EIκ(L₁) to O(h²).
    let errs = check_order("K → ∞", &straight(spring), &exact, 0, 1.8);
    assert!(errs[2].iter().all(|e| e.abs() < 1e-2), "{errs:?}");
}

#[test]
fn conv_chain_modes_scene_springs_match_the_spring_jointed_beams() {
    // The scene's own springs (K₁ = 120, K₂ = 20) about the straight set points: the lowest
    // modes are the two spring-dominated joint modes, then the flexible ones.
    let scene = straight(1.0);
    let b = beams(&scene);
    let k = [0, 1].map(|i| scene.links()[i].joint.stiffness);
    let w1 = (b[0].1 / b[0].2).sqrt() / (b[0].0 * b[0].0);
    let exact = roots(|w| det(b, k, w), 0.05 * w1, 0.01 * w1, 4);
    // all four O(h²) (observed 1.89–2.02: joint modes and flexible modes alike)
    let errs = check_order("scene K", &scene, &exact, 0, 1.8);
    assert!(errs[2].iter().all(|e| e.abs() < 2e-3), "{errs:?}");
}

#[test]
fn sys_chain_modes_use_the_run_dofs() {
    // the eigenproblem is the integrated discretization: its size is the run's DOF plan
    let scene = load_scene("two-link-free").unwrap();
    let s = Settings::default();
    let r = FdmBackend.modes(&scene, &s, 6).unwrap();
    let plan = FdmBackend.dof_plan(&scene, &s.discretization).unwrap();
    assert_eq!(r.cost.dofs, plan.total());
    assert_eq!(
        r.cost.dofs,
        2 + 2 * 20 + 1,
        "two chord angles + 20 slots per link at 21 stations + link 1's tip ghost"
    );
    assert_eq!(r.frequencies_hz.len(), 6);
    assert!(
        r.kinds.iter().all(|k| k == "bending"),
        "sprung joints: no rigid mode"
    );
    // a Timoshenko chain is refused with a message, not answered
    let timo = load_scene("barhorst-case1-timoshenko").unwrap();
    assert!(FdmBackend.modes(&timo, &s, 6).is_err());
}
