//! The integrator registry ([`modal::integrate`]): every registered method builds and steps,
//! spells itself back, and the rocket refuses exactly the fixed-step methods, naming the
//! methods with error-controlled steps; the models without linear oscillators refuse exactly
//! the methods that need them.

use data::{Backend, BackendError, Settings, StabilityVerdict, load_scene};
use modal::integrate::{Build, METHODS, OdeRhs, StopReason, Tolerances, method_for, names_with};
use modal::rocket;

/// y' = −y.
struct Decay;

impl OdeRhs for Decay {
    fn dim(&self) -> usize {
        1
    }
    fn eval(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = -y[0];
    }
}

/// q̈ = −4q as (q, q̇), with its oscillator M = 1, K = 4.
struct Spring;

impl OdeRhs for Spring {
    fn dim(&self) -> usize {
        2
    }
    fn eval(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -4.0 * y[0];
    }
    fn second_order_linearization(
        &mut self,
        _t: f64,
        _y: &[f64],
        m: &mut Vec<f64>,
        k: &mut Vec<f64>,
    ) -> Option<usize> {
        *m = vec![1.0];
        *k = vec![4.0];
        Some(1)
    }
}

#[test]
fn sys_registry_methods_build_step_and_spell_themselves() {
    assert!(METHODS.len() >= 4, "{METHODS:?}");
    for &info in METHODS {
        assert!(std::ptr::eq(method_for(info.method), info), "{info:?}");
        let spelled: data::Method = info.name.parse().unwrap();
        assert_eq!(spelled.modal(), Some(info.method), "{info:?}");
        let tol = Tolerances::default();
        // A method that needs oscillators steps the spring (exact: cos 2t), the others the
        // decay (e^{−t}); a few steps stay within the method's accuracy.
        let (rhs, y0, exact): (&mut dyn OdeRhs, &[f64], f64) = if info.needs_oscillators {
            (&mut Spring, &[1.0, 0.0], 0.1f64.cos())
        } else {
            (&mut Decay, &[1.0], (-0.05f64).exp())
        };
        let mut stepper = match info.build {
            Build::Adaptive(build) => build(y0.len(), tol, None),
            Build::Fixed(build) => build(y0.len(), tol, 1e-3),
        };
        assert_eq!(info.is_fixed_step(), matches!(info.build, Build::Fixed(_)));
        let (mut t, mut y) = (0.0, y0.to_vec());
        let mut reason = StopReason::InternalStep;
        while reason != StopReason::TstopReached {
            reason = stepper.step(rhs, &mut t, &mut y, 0.05).unwrap();
        }
        assert_eq!(t, 0.05, "{info:?}");
        let err = (y[0] - exact).abs();
        assert!(err < 1e-6, "{info:?}: error {err:e}");
    }
}

#[test]
fn sys_registry_rocket_refuses_the_fixed_step_methods() {
    let scene = load_scene("rocket").unwrap();
    let adaptive = names_with("or", |m| !m.is_fixed_step());
    let mut refused = 0;
    for &info in METHODS {
        let mut s = Settings::default();
        s.time.method = Some(info.method.into());
        s.time.t_end = Some(1e-3);
        let r = rocket::simulate(&scene, scene.rocket().unwrap(), &s.modal().unwrap());
        match r {
            Err(BackendError::InvalidSettings { field, message }) if info.is_fixed_step() => {
                assert_eq!(field, "time.method");
                assert!(message.contains(&adaptive), "{message}");
                assert!(message.contains(&format!("`{}`", info.name)), "{message}");
                refused += 1;
            }
            Ok(r) if !info.is_fixed_step() => {
                assert_eq!(r.verdict, StabilityVerdict::Completed, "{info:?}")
            }
            other => panic!("{info:?}: {other:?}"),
        }
    }
    assert!(refused > 0);
}

#[test]
fn sys_registry_models_without_oscillators_refuse_the_methods_that_need_them() {
    let others = names_with("or", |m| !m.needs_oscillators);
    let needing: Vec<_> = METHODS.iter().filter(|m| m.needs_oscillators).collect();
    assert!(!needing.is_empty());
    // Kelvin–Voigt and contact chains, the Kelvin–Voigt-damped 3-D payload link and the mobile
    // manipulator.
    for scene_name in [
        "two-link-free",
        "barhorst-case1",
        "single-link-3d",
        "mobile-manipulator",
    ] {
        let scene = load_scene(scene_name).unwrap();
        for &&info in &needing {
            let mut s = Settings::default();
            s.time.method = Some(info.method.into());
            s.time.t_end = Some(1e-3);
            let r = modal::ModalBackend.simulate(&scene, &s);
            match r {
                Err(BackendError::InvalidSettings { field, message }) => {
                    assert_eq!(field, "time.method", "{scene_name}");
                    assert!(message.contains(&others), "{scene_name}: {message}");
                    assert!(message.contains(&format!("`{}`", info.name)), "{message}");
                }
                other => panic!("{scene_name} {info:?}: {other:?}"),
            }
        }
    }
    // An undamped chain without contact and the undamped payload link run them, and refuse a
    // tolerance for them.
    for scene_name in ["two-link-free-undamped", "single-link-3d-stiff"] {
        let scene = load_scene(scene_name).unwrap();
        for &&info in &needing {
            let mut s = Settings::default();
            s.time.method = Some(info.method.into());
            s.time.rtol = Some(1e-6);
            match modal::ModalBackend.simulate(&scene, &s) {
                Err(BackendError::InvalidSettings { field, message }) => {
                    assert_eq!(field, "time.rtol/atol");
                    assert!(message.contains("--dt"), "{message}");
                }
                other => panic!("{scene_name} {info:?} with rtol: {other:?}"),
            }
            let mut s = Settings::default();
            s.time.method = Some(info.method.into());
            s.time.t_end = Some(1e-2);
            let r = modal::ModalBackend.simulate(&scene, &s).unwrap();
            assert_eq!(
                r.verdict,
                StabilityVerdict::Completed,
                "{scene_name} {info:?}"
            );
        }
    }
}
