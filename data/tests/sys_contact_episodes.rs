//! Contact episodes from a run's switching events (the micro-bounce-independent switching times
//! that verify compares across backends).

use data::Event;
use data::results::contact_episodes;

fn start(t: f64) -> Event {
    Event::ContactStart {
        t,
        contact: 1,
        time_tolerance: 0.0,
    }
}
fn impact(t: f64) -> Event {
    Event::Impact {
        t,
        contact: 1,
        velocity_before: vec![],
        velocity_after: vec![],
        impulse: 1.0,
        momentum_residual: 0.0,
        normal_velocity_before: -1.0,
        normal_velocity_after: 0.0,
        kinetic_energy_lost: 0.0,
    }
}
fn release(t: f64) -> Event {
    Event::Release {
        t,
        contact: 1,
        normal_force: 0.0,
        time_tolerance: 0.0,
    }
}

#[test]
fn sys_micro_bounces_merge_into_one_episode_and_long_flights_separate() {
    let events = vec![
        start(0.28),
        impact(0.28),
        release(0.289),
        // 1 ms flight: a micro-bounce, same episode with min_flight 10 ms.
        impact(0.290),
        release(0.300),
        // Impact immediately followed by free flight (no release recorded), 2 ms later.
        impact(0.302),
        impact(0.304),
        release(0.309),
        // 47 ms flight: a new episode, in contact at the end of the run.
        start(0.356),
        impact(0.356),
    ];
    let e = contact_episodes(&events, 0.01);
    assert_eq!(e, vec![(0.28, Some(0.309)), (0.356, None)]);
    // With a 0.5 ms threshold every flight separates: the silent release gives a zero-length
    // phase at 0.302.
    let e = contact_episodes(&events, 5e-4);
    assert_eq!(
        e,
        vec![
            (0.28, Some(0.289)),
            (0.290, Some(0.300)),
            (0.302, Some(0.302)),
            (0.304, Some(0.309)),
            (0.356, None)
        ]
    );
    assert!(contact_episodes(&[], 0.01).is_empty());
}
