//! The rocket's free-free frequencies (verify::analytic::rocket_modes) against limits whose
//! equations are solved here independently: the uniform free-free beam and bar, a mass on a
//! very stiff spring (rigidly added end mass: its own transcendental equation), a mass on a very
//! soft spring (free beam + the oscillator on the rigid body's reduced mass).

use std::f64::consts::PI;

use verify::analytic as ana;
use verify::analytic::numerics::roots::{RootOptions, first_roots};
use verify::analytic::rocket_modes::{Coupling, FreeFreeRocket, Motion, Segment, SprungMass};

const EA: f64 = 2.0e8;
const EI: f64 = 3.0e9;
const RHO_A: f64 = 0.011;
const LEN: f64 = 150.0;

fn uniform(stages: usize) -> Vec<Segment> {
    (0..stages)
        .map(|_| Segment {
            length: LEN / stages as f64,
            ea: EA,
            ei: EI,
            rho_a: RHO_A,
        })
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn ana_rocket_modes_uniform_free_free_limits() {
    // two stages of identical section, split at (√2 − 1) L: the junction node must not change
    // anything. (At a rational split, e.g. L/2 or 0.4 L, some modes put a clamped–clamped pole
    // of a member exactly on a frequency of the body, where the count is decided next to a pole
    // of K(ω): measured 3e-9 on axial mode 2 at L/2, 4e-10 on axial mode 5 at 0.4 L.)
    let mut stages = uniform(2);
    stages[0].length = (2f64.sqrt() - 1.0) * LEN;
    stages[1].length = LEN - stages[0].length;
    let body = FreeFreeRocket::new(&stages, &[], &[]).unwrap();
    let bend = body.elastic_omegas(Motion::Transverse, 6).unwrap();
    let axial = body.elastic_omegas(Motion::Axial, 6).unwrap();
    for n in 1..=6 {
        let bl = ana::beam_eigenvalue(ana::BeamSupport::FreeFree, n).unwrap();
        let want = bl * bl / (LEN * LEN) * (EI / RHO_A).sqrt();
        let got = bend[n - 1];
        println!("bending {n}: {got:.12e} vs (beta L)^2 law {want:.12e}");
        // the count near a root is decided by the sign of an eigenvalue of K(ω) close to zero,
        // which round-off fixes to ~2e-11 relative (measured 1.7e-11 on mode 1)
        assert!(rel(got, want) < 1e-10, "bending mode {n}: {got} vs {want}");
        let want_ax = n as f64 * PI / LEN * (EA / RHO_A).sqrt();
        assert!(
            rel(axial[n - 1], want_ax) < 1e-10,
            "axial mode {n}: {} vs {want_ax}",
            axial[n - 1]
        );
    }
}

/// Frequencies [rad/s] of a uniform free-free body with a rigid point mass at x = L.
fn end_mass_reference(motion: Motion, mu: f64, n: usize) -> Vec<f64> {
    let opts = RootOptions::default();
    match motion {
        // u = cos kx; EA u'(L) = ω² m u(L)  ⇒  sin kL + μ kL cos kL = 0, μ = m/(ρA L)
        Motion::Axial => first_roots(
            |z| z.sin() + mu * z * z.cos(),
            1e-3,
            0.05,
            200.0,
            n,
            "end-mass bar",
            opts,
        )
        .unwrap()
        .into_iter()
        .map(|z| z / LEN * (EA / RHO_A).sqrt())
        .collect(),
        // w = A(cos + cosh) + B(sin + sinh) (free at 0); at L: w'' = 0, EI w''' + ω² m w = 0;
        // the 2 × 2 determinant scaled by e^{-λ}
        Motion::Transverse => first_roots(
            |z: f64| {
                let (c, s) = (z.cos(), z.sin());
                let e = (-z).exp();
                let (ch, sh) = (0.5 * (1.0 + e * e), 0.5 * (1.0 - e * e)); // cosh·e^{-z}, sinh·e^{-z}
                let a11 = ch - c * e;
                let a12 = sh - s * e;
                let a21 = (s * e + sh) + z * mu * (c * e + ch);
                let a22 = (ch - c * e) + z * mu * (s * e + sh);
                a11 * a22 - a12 * a21
            },
            0.5,
            0.05,
            200.0,
            n,
            "end-mass beam",
            opts,
        )
        .unwrap()
        .into_iter()
        .map(|z| z * z / (LEN * LEN) * (EI / RHO_A).sqrt())
        .collect(),
    }
}

#[test]
fn ana_rocket_modes_stiff_spring_is_a_rigid_end_mass() {
    let m = 0.3 * RHO_A * LEN;
    let mu = m / (RHO_A * LEN);
    for motion in [Motion::Axial, Motion::Transverse] {
        let want = end_mass_reference(motion, mu, 4);
        let mut errors = Vec::new();
        for k_scale in [1e3, 1e5] {
            let k = k_scale * EA / LEN;
            let body = FreeFreeRocket::new(
                &uniform(1),
                &[SprungMass {
                    position: LEN,
                    mass: m,
                    axial_stiffness: k,
                    transverse_stiffness: k,
                }],
                &[],
            )
            .unwrap();
            let got = body.elastic_omegas(motion, 4).unwrap();
            let err = (0..4).map(|i| rel(got[i], want[i])).fold(0.0f64, f64::max);
            println!("{motion:?} k = {k_scale:e} EA/L: max rel error {err:.3e}");
            errors.push(err);
        }
        // the spring's compliance shifts ω by O(m ω²/k): first order in 1/k
        assert!(errors[1] < 1e-4, "{motion:?}: {errors:?}");
        assert!(
            errors[0] / errors[1] > 50.0,
            "{motion:?}: not first order in 1/k: {errors:?}"
        );
    }
}

#[test]
fn ana_rocket_modes_soft_spring_separates_an_oscillator() {
    let m = 0.05 * RHO_A * LEN;
    let x_m = 0.8 * LEN;
    let body_mass = RHO_A * LEN;
    let centroid_inertia = body_mass * LEN * LEN / 12.0;
    let beam_first = {
        let bl = ana::beam_eigenvalue(ana::BeamSupport::FreeFree, 1).unwrap();
        bl * bl / (LEN * LEN) * (EI / RHO_A).sqrt()
    };
    // oscillator well below the first elastic frequency: coupling corrections O((ω/ω₁)²)
    let k = m * (1e-3 * beam_first).powi(2);
    let body = FreeFreeRocket::new(
        &uniform(1),
        &[SprungMass {
            position: x_m,
            mass: m,
            axial_stiffness: k,
            transverse_stiffness: k,
        }],
        &[],
    )
    .unwrap();
    for motion in [Motion::Axial, Motion::Transverse] {
        // the rigid body reacts: 1/m_red = 1/m + 1/M (+ d²/I_c across)
        let d = x_m - 0.5 * LEN;
        let inv = 1.0 / m
            + 1.0 / body_mass
            + match motion {
                Motion::Axial => 0.0,
                Motion::Transverse => d * d / centroid_inertia,
            };
        let osc = (k * inv).sqrt();
        let got = body.elastic_omegas(motion, 4).unwrap();
        println!("{motion:?}: oscillator {:.12e} vs {osc:.12e}", got[0]);
        assert!(rel(got[0], osc) < 1e-5, "{motion:?}: {} vs {osc}", got[0]);
        for (n, &beam_mode) in got.iter().enumerate().skip(1) {
            let want = match motion {
                Motion::Axial => n as f64 * PI / LEN * (EA / RHO_A).sqrt(),
                Motion::Transverse => {
                    let bl = ana::beam_eigenvalue(ana::BeamSupport::FreeFree, n).unwrap();
                    bl * bl / (LEN * LEN) * (EI / RHO_A).sqrt()
                }
            };
            assert!(
                rel(beam_mode, want) < 1e-5,
                "{motion:?} beam mode {n}: {beam_mode} vs {want}"
            );
        }
    }
}

#[test]
fn ana_rocket_modes_coupled_masses_on_a_rigid_body() {
    // Two masses coupled to each other, on soft case springs, on a very stiff short body: the
    // two lowest elastic frequencies are those of the 2-mass chain k_a – m – k_c – m – k_a on a
    // fixed base (body mass ≫ m, so its recoil is negligible at this ratio): ω² = k_a/m and
    // (k_a + 2k_c)/m.
    let seg = [Segment {
        length: 10.0,
        ea: 1e14,
        ei: 1e16,
        rho_a: 1e3,
    }];
    let m = 1e-3;
    let (ka, kc) = (1.0, 0.7);
    let masses = [4.0, 6.0].map(|x| SprungMass {
        position: x,
        mass: m,
        axial_stiffness: ka,
        transverse_stiffness: ka,
    });
    let body = FreeFreeRocket::new(
        &seg,
        &masses,
        &[Coupling {
            between: [0, 1],
            axial_stiffness: kc,
            transverse_stiffness: kc,
        }],
    )
    .unwrap();
    for motion in [Motion::Axial, Motion::Transverse] {
        let got = body.elastic_omegas(motion, 2).unwrap();
        let want = [(ka / m).sqrt(), ((ka + 2.0 * kc) / m).sqrt()];
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(rel(*g, *w) < 1e-4, "{motion:?} {i}: {g} vs {w}");
        }
    }
}

#[test]
fn ana_rocket_modes_catalog() {
    for name in ["rocket", "rocket-case2"] {
        let s = data::load_scene(name).unwrap();
        let body = FreeFreeRocket::from_rocket(s.rocket().unwrap()).unwrap();
        let bend = body.frequencies_hz(Motion::Transverse, 6).unwrap();
        let axial = body.frequencies_hz(Motion::Axial, 6).unwrap();
        println!("{name}: bending {bend:.6?} Hz");
        println!("{name}: axial   {axial:.6?} Hz");
        assert!(bend.windows(2).all(|w| w[1] > w[0]) && bend[0] > 0.0);
        assert!(axial.windows(2).all(|w| w[1] > w[0]) && axial[0] > 0.0);
    }
}

/// Transverse ω² of a rigid body (mass `mb`, rotary inertia `ib` about its centroid `xb`)
/// carrying masses `m` at `x` on case springs `ka` and one spring `kc` between them, by the
/// 4-DOF eigenproblem (translation a and rotation θ of the body, mass displacements q₁, q₂).
/// `body_axes`: the coupling acts on q₁ − q₂ − φ(x₁ − x₂), φ the whole body's mean-axis angle
/// Σ m (x − x_c) y / Σ m (x − x_c)²; otherwise on q₁ − q₂.
fn rigid_body_omegas2(
    (mb, ib, xb): (f64, f64, f64),
    m: [f64; 2],
    x: [f64; 2],
    (ka, kc): (f64, f64),
    body_axes: bool,
) -> Vec<f64> {
    let xc = (mb * xb + m[0] * x[0] + m[1] * x[1]) / (mb + m[0] + m[1]);
    let ic = ib + mb * (xb - xc).powi(2) + m[0] * (x[0] - xc).powi(2) + m[1] * (x[1] - xc).powi(2);
    // ∇φ over (a, θ, q₁, q₂)
    let grad_phi = [
        mb * (xb - xc) / ic,
        ib / ic,
        m[0] * (x[0] - xc) / ic,
        m[1] * (x[1] - xc) / ic,
    ];
    let mut k = [[0.0; 4]; 4];
    let mut add = |g: [f64; 4], s: f64| {
        for i in 0..4 {
            for j in 0..4 {
                k[i][j] += s * g[i] * g[j];
            }
        }
    };
    for j in 0..2 {
        let mut g = [-1.0, -(x[j] - xb), 0.0, 0.0];
        g[2 + j] = 1.0;
        add(g, ka);
    }
    let mut h = [0.0, 0.0, 1.0, -1.0];
    if body_axes {
        for (hi, gi) in h.iter_mut().zip(grad_phi) {
            *hi -= (x[0] - x[1]) * gi;
        }
    }
    add(h, kc);
    let mass = [mb, ib, m[0], m[1]];
    let a = faer::Mat::<f64>::from_fn(4, 4, |i, j| k[i][j] / (mass[i] * mass[j]).sqrt());
    let mut ev: Vec<f64> = a
        .self_adjoint_eigenvalues(faer::Side::Lower)
        .expect("4x4 eigenvalues");
    ev.sort_by(f64::total_cmp);
    ev
}

#[test]
fn ana_rocket_modes_springs_between_masses_ride_with_the_body() {
    // A nearly rigid body as heavy as its two masses: the coupling spring's frame matters. The
    // exact count with body-axis springs must give two rigid modes and the rigid-body model's
    // two elastic frequencies.
    let (len, rho_a) = (10.0, 0.1);
    let seg = [Segment {
        length: len,
        ea: 1e9,
        ei: 1e9,
        rho_a,
    }];
    let (m, x) = ([0.5, 0.3], [2.0, 7.0]);
    let (ka, kc) = (1.0, 0.7);
    let masses = [0, 1].map(|j| SprungMass {
        position: x[j],
        mass: m[j],
        axial_stiffness: ka,
        transverse_stiffness: ka,
    });
    let coupling = [Coupling {
        between: [0, 1],
        axial_stiffness: kc,
        transverse_stiffness: kc,
    }];
    let body = FreeFreeRocket::new(&seg, &masses, &coupling).unwrap();
    let got = body.elastic_omegas(Motion::Transverse, 2).unwrap();
    let mb = rho_a * len;
    let rigid = (mb, mb * len * len / 12.0, len / 2.0);
    let want = rigid_body_omegas2(rigid, m, x, (ka, kc), true);
    assert!(want[0].abs() < 1e-12 && want[1].abs() < 1e-12, "{want:?}");
    // negative control: in fixed axes the rotation stretches the coupling (one rigid mode
    // only) and the elastic frequencies move
    let fixed = rigid_body_omegas2(rigid, m, x, (ka, kc), false);
    assert!(
        fixed[1] > 1e-3 * fixed[3],
        "fixed axes: a soft rotation, {fixed:?}"
    );
    for i in 0..2 {
        let w = want[2 + i].sqrt();
        assert!(rel(got[i], w) < 1e-6, "elastic {i}: {} vs {w}", got[i]);
        let f = fixed[2 + i].sqrt();
        assert!(rel(f, w) > 1e-3, "the frames must differ here: {f} vs {w}");
    }
    // below the first elastic frequency only the two rigid modes are counted
    assert_eq!(
        body.count_below(Motion::Transverse, 0.5 * got[0]).unwrap(),
        2
    );
}
