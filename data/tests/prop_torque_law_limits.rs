//! The torque laws' one-sided values: `torque` is right-continuous, `torque_before` is its
//! left limit, and the two differ only at the law's breakpoints.

use data::scene::TorqueLaw;

fn laws() -> Vec<TorqueLaw> {
    vec![
        TorqueLaw::Constant {
            value: 2.5,
            until: None,
        },
        TorqueLaw::Constant {
            value: -1.0,
            until: Some(0.3),
        },
        TorqueLaw::BangBang {
            amplitude: 2.0,
            switch: 0.5,
            off: 1.0,
        },
        // a switch at t = 0: the positive stretch is empty
        TorqueLaw::BangBang {
            amplitude: 1.0,
            switch: 0.0,
            off: 0.75,
        },
    ]
}

#[test]
fn prop_torque_before_is_the_left_limit_at_every_breakpoint() {
    for law in laws() {
        for b in law.breakpoints() {
            let eps = 1e-9 * b.abs().max(1.0);
            assert_eq!(law.torque_before(b), law.torque(b - eps), "{law:?} at {b}");
            assert_eq!(law.torque(b), law.torque(b + eps), "{law:?} at {b}");
        }
    }
}

#[test]
fn prop_torque_before_equals_torque_away_from_breakpoints() {
    for law in laws() {
        let breaks = law.breakpoints();
        for k in 0..=2000 {
            let t = -0.1 + 1.5 * f64::from(k) / 2000.0 + 1.234e-7;
            assert!(breaks.iter().all(|b| (t - b).abs() > 1e-8));
            assert_eq!(law.torque_before(t), law.torque(t), "{law:?} at {t}");
        }
    }
}

#[test]
fn prop_bang_bang_jumps_by_twice_the_amplitude_at_its_switch() {
    let law = TorqueLaw::BangBang {
        amplitude: 2.0,
        switch: 0.5,
        off: 1.0,
    };
    assert_eq!(law.torque_before(0.5) - law.torque(0.5), 4.0);
    assert_eq!(law.torque_before(1.0) - law.torque(1.0), -2.0);
}
