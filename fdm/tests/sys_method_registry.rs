//! The method registry ([`fdm::method`]): every registered method builds, spells itself back,
//! and the runs refuse exactly the methods whose capabilities lack what the model needs, naming
//! the methods that have it.

use data::{Backend, BackendError, Settings, StabilityVerdict, load_scene};
use fdm::FdmBackend;
use fdm::method::{Capabilities, METHODS, MethodParams, build, capabilities, names_with};

/// `m` (a registered `data` method) as `time.method`, with a short horizon.
fn settings(m: data::FdmMethod, stations: Option<usize>, t_end: f64) -> Settings {
    let mut s = Settings::default();
    s.discretization.stations = stations;
    s.time.t_end = Some(t_end);
    s.time.method = Some(m.into());
    s
}

#[test]
fn sys_registry_methods_build_and_spell_themselves() {
    assert!(METHODS.len() >= 3, "{METHODS:?}");
    for &(m, caps) in METHODS {
        let method = fdm::Method::from_data(m).unwrap();
        assert_eq!(capabilities(method), caps, "{m}");
        for restartable in [false, true] {
            let stepper = build(MethodParams {
                method,
                restartable,
            });
            let f = stepper.bound_factor();
            assert!(f > 0.0 && f <= 1.0, "{m}: bound factor {f}");
        }
        // the spelling (payload at its checked default) reads back as the same method
        let spelled: data::Method = method.name().parse().unwrap();
        let back = fdm::Method::from_data(spelled.fdm().unwrap()).unwrap();
        assert_eq!(back, method, "{m}");
    }
}

/// The refusal of `m` when the model needs `has`: a typed `Unsupported` naming every method
/// with the capability; a method that has it runs.
fn check_refusal(
    scene: &data::Scene,
    s: &Settings,
    m: data::FdmMethod,
    caps: Capabilities,
    has: fn(&Capabilities) -> bool,
) {
    let capable = names_with("or", has);
    assert!(!capable.is_empty());
    match FdmBackend.simulate(scene, s) {
        Err(BackendError::Unsupported(msg)) if !has(&caps) => {
            assert!(msg.contains(&capable), "{m}: {msg}");
            assert!(msg.contains(&format!("time.method = {m}")), "{msg}");
        }
        Ok(r) if has(&caps) => assert_eq!(r.verdict, StabilityVerdict::Completed, "{m}"),
        other => panic!("{m} ({caps:?}): {other:?}"),
    }
}

#[test]
fn sys_registry_capabilities_match_the_refusals() {
    let contact = load_scene("barhorst-case1").unwrap();
    let payload = load_scene("single-link-3d").unwrap();
    let mut refused = [0, 0];
    for &(m, caps) in METHODS {
        check_refusal(&contact, &settings(m, Some(11), 2e-3), m, caps, |c| {
            c.restarts_at_events
        });
        check_refusal(&payload, &settings(m, None, 2e-3), m, caps, |c| {
            c.implicit_damping
        });
        refused[0] += usize::from(!caps.restarts_at_events);
        refused[1] += usize::from(!caps.implicit_damping);
    }
    // both refusals are exercised by the registered methods
    assert!(refused.iter().all(|&n| n > 0), "{refused:?}");
}
