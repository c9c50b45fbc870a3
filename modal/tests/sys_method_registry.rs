//! The integrator registry ([`modal::integrate`]): every registered method builds and steps,
//! spells itself back, and the rocket refuses exactly the fixed-step methods, naming the
//! methods with error-controlled steps.

use data::{BackendError, Settings, StabilityVerdict, load_scene};
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

#[test]
fn sys_registry_methods_build_step_and_spell_themselves() {
    assert!(METHODS.len() >= 4, "{METHODS:?}");
    for &info in METHODS {
        assert!(std::ptr::eq(method_for(info.method), info), "{info:?}");
        let spelled: data::Method = info.name.parse().unwrap();
        assert_eq!(spelled.modal(), Some(info.method), "{info:?}");
        let tol = Tolerances::default();
        let mut stepper = match info.build {
            Build::Adaptive(build) => build(1, tol, None),
            Build::Fixed(build) => build(1, tol, 1e-3),
        };
        assert_eq!(info.is_fixed_step(), matches!(info.build, Build::Fixed(_)));
        // a few steps of the decay stay within the method's accuracy of e^{−t}
        let (mut t, mut y) = (0.0, [1.0]);
        let mut reason = StopReason::InternalStep;
        while reason != StopReason::TstopReached {
            reason = stepper.step(&mut Decay, &mut t, &mut y, 0.05).unwrap();
        }
        assert_eq!(t, 0.05, "{info:?}");
        let err = (y[0] - (-0.05f64).exp()).abs();
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
