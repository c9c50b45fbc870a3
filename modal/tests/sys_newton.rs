//! The chain's structured Newton linear algebra (`sys_` layer): the structured Jacobian against
//! finite differences, the factored solve against the dense system I − cJ, and the implicit
//! run of the contact scene at 12 modes per link against its cost and the explicit method's
//! impulse.

use data::{Discretization, Event, Settings, TimeStepping, load_scene};
use modal::contact::ContactState;
use modal::integrate::OdeRhs;
use modal::setup::build_chain;
use modal::simulate::{ChainRhs, simulate};

/// The tip-mass contact scene without gravity, at rest in its unloaded configuration (both
/// joint angles at 0 = the second joint's spring set point): F(q, 0) = 0 and q̈ = 0, so the
/// terms the structured Jacobian leaves out (∂M/∂q·q̈, the quadratic velocity terms, gravity)
/// all vanish and it must equal the exact Jacobian.
fn rest_rhs(modes: usize, constrained: bool) -> (ChainRhs, Vec<f64>) {
    let mut scene = load_scene("barhorst-case1-tipmass").unwrap();
    scene.planar_chain_mut().unwrap().gravity = None;
    let disc = Discretization {
        modes: Some(modes),
        ..Default::default()
    };
    let chain = build_chain(scene.planar_chain().unwrap(), &disc.modal().unwrap()).unwrap();
    let (n, nf) = (chain.n, chain.free.len());
    let mut rhs = ChainRhs::new(chain);
    let mut contact = ContactState::from_planar_chain(scene.planar_chain().unwrap(), n, nf)
        .unwrap()
        .unwrap();
    contact.constrained = constrained;
    rhs.attach_contact(Some(contact));
    let y = vec![0.0; rhs.dim()];
    (rhs, y)
}

/// The structured Jacobian (`OdeRhs::jacobian`, column-major).
fn structured_jacobian(rhs: &mut ChainRhs, y: &[f64]) -> Vec<f64> {
    let n = y.len();
    let mut jac = vec![0.0; n * n];
    assert!(rhs.jacobian(0.0, y, &mut jac));
    jac
}

/// Central differences, column-major like `OdeRhs::jacobian`.
fn central_jacobian(rhs: &mut ChainRhs, y: &[f64], step: f64) -> Vec<f64> {
    let n = y.len();
    let mut jac = vec![0.0; n * n];
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut yp = y.to_vec();
    for j in 0..n {
        yp[j] = y[j] + step;
        rhs.eval(0.0, &yp, &mut fp);
        yp[j] = y[j] - step;
        rhs.eval(0.0, &yp, &mut fm);
        yp[j] = y[j];
        for i in 0..n {
            jac[j * n + i] = (fp[i] - fm[i]) / (2.0 * step);
        }
    }
    jac
}

/// Largest column error ‖J_a − J_b‖/‖J_b‖ over the columns with a nonzero reference.
fn worst_column_error(a: &[f64], b: &[f64], n: usize) -> f64 {
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let (mut d, mut r) = (0.0, 0.0);
        for i in 0..n {
            d += (a[j * n + i] - b[j * n + i]).powi(2);
            r += b[j * n + i].powi(2);
        }
        if r > 0.0 {
            worst = worst.max((d / r).sqrt());
        } else {
            assert!(
                d == 0.0,
                "column {j}: structured entries where the reference has none"
            );
        }
    }
    worst
}

#[test]
fn sys_structured_jacobian_is_exact_at_rest_free_and_constrained() {
    for constrained in [false, true] {
        let (mut rhs, y) = rest_rhs(4, constrained);
        let n = y.len();
        let js = structured_jacobian(&mut rhs, &y);
        // The right-hand side is quadratic around rest: central differences are exact up to
        // round-off; 1e-6 is well above the noise of f at 4 modes per link.
        let jc = central_jacobian(&mut rhs, &y, 1e-6);
        let err = worst_column_error(&js, &jc, n);
        assert!(
            err < 1e-6,
            "constrained {constrained}: worst column error {err:.3e}"
        );
        if constrained {
            // The contact projection is what makes it right: the free-flight Jacobian misses it.
            let (mut free, _) = rest_rhs(4, false);
            let jf = structured_jacobian(&mut free, &y);
            let err_free = worst_column_error(&jf, &jc, n);
            assert!(err_free > 1e-2, "projection has no effect? {err_free:.3e}");
        }
    }
}

#[test]
fn sys_factored_newton_solve_solves_the_dense_system() {
    // At rest, and at a moving, deflected state (joint rates and modal velocities nonzero:
    // the power rows 2dθ̇ of the joint dampers and the velocity-dependent terms enter both the
    // dense J and the factored path).
    for (constrained, moving) in [(false, false), (true, false), (false, true), (true, true)] {
        let (mut rhs, mut y) = rest_rhs(4, constrained);
        if moving {
            for (i, v) in y.iter_mut().enumerate() {
                *v = 1e-2 * ((i + 1) as f64).sin();
            }
        }
        let n = y.len();
        let j = structured_jacobian(&mut rhs, &y);
        assert!(rhs.newton_linearize(0.0, &y));
        for c in [1e-6, 1e-4, 1e-2] {
            assert!(rhs.newton_factor(c));
            let r: Vec<f64> = (0..n).map(|i| ((i * 7 + 3) % 11) as f64 - 5.0).collect();
            let mut x = r.clone();
            rhs.newton_solve(&mut x);
            // Residual of (I − cJ) x = r with the dense structured Jacobian.
            let mut worst: f64 = 0.0;
            for i in 0..n {
                let ax: f64 = (0..n)
                    .map(|k| (f64::from(u8::from(i == k)) - c * j[k * n + i]) * x[k])
                    .sum();
                worst = worst.max((ax - r[i]).abs());
            }
            let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // The dense J itself carries M⁻¹'s round-off (cond M ~ 1e7 at 4 modes): a wrong
            // formula gives O(1) residuals, round-off ~1e-9 relative.
            assert!(
                worst < 1e-7 * scale,
                "constrained {constrained}, moving {moving}, c {c}: residual {worst:.3e}"
            );
        }
    }
}

/// The implicit run of the contact scene at 12 modes per link: before the structured
/// Jacobian and the projection-preserving restart it took 3189 Jacobians (one per constrained
/// step) and 484 rejections for 5901 steps; now a handful. The first impulse agrees with
/// Dormand–Prince (2.680647262 at its default tolerances).
#[test]
fn sys_trbdf2_contact_run_cost_and_first_impulse() {
    let scene = load_scene("barhorst-case1-tipmass").unwrap();
    let settings = Settings {
        discretization: Discretization {
            modes: Some(12),
            ..Default::default()
        },
        time: TimeStepping {
            method: Some("trbdf2".parse().expect("a method name")),
            rtol: Some(1e-6),
            atol: Some(1e-8),
            t_end: Some(0.29),
            ..Default::default()
        },
    };
    let r = simulate(
        &scene,
        scene.planar_chain().unwrap(),
        &settings.modal().unwrap(),
    )
    .unwrap();
    let c = &r.cost;
    println!("{c:?}");
    assert!(c.jacobian_evaluations <= 40, "{c:?}");
    assert!(c.rejected_steps * 5 <= c.steps, "{c:?}");
    assert!(c.steps < 8000, "{c:?}");
    let impulse = r
        .events
        .iter()
        .find_map(|e| match e {
            Event::Impact { impulse, .. } => Some(*impulse),
            _ => None,
        })
        .expect("an impact");
    let rel = (impulse / 2.680647262 - 1.0).abs();
    assert!(rel < 2e-6, "first impulse {impulse}: {rel:.2e} from dopri5");
}
