//! The mobile platform as one composite body ([`Platform::composite`]) against the scene
//! summed wheel by wheel, and the mobile manipulator's channel list
//! ([`channel::mobile_manipulator`]).

use data::catalog_scene;
use data::channel;
use data::scene::{MobileManipulator, Platform, TorqueSchedule};

fn platform(wheel_count: usize, wheelbase: f64, chassis_com_offset: f64) -> Platform {
    Platform {
        chassis_mass: 20.0,
        chassis_yaw_inertia: 1.2,
        chassis_com_offset,
        wheel_count,
        wheel_radius: 0.1,
        wheel_mass: 0.7,
        wheel_spin_inertia: 0.0035,
        wheel_diametral_inertia: 0.0019,
        wheelbase,
        half_track: 0.27,
        driven_axles: vec![1],
        wheel_friction: 0.013,
        drive: TorqueSchedule::Steps {
            times: vec![0.0],
            values: vec![vec![0.0, 0.0]],
        },
    }
}

/// Mass, mass centre (x, y) and yaw inertia about the origin, summed over the chassis and
/// every wheel as a point mass at (x, ±b) with its own diametral inertia; axle k of n at
/// wheelbase·(1/2 − k/(n − 1)), front to rear.
fn summed(p: &Platform) -> (f64, f64, f64, f64) {
    let axles = p.wheel_count / 2;
    let mut m = p.chassis_mass;
    let (mut mx, mut my) = (p.chassis_mass * p.chassis_com_offset, 0.0);
    let mut j_origin = p.chassis_yaw_inertia + p.chassis_mass * p.chassis_com_offset.powi(2);
    for k in 0..axles {
        let x = if axles == 1 {
            0.0
        } else {
            p.wheelbase / 2.0 - p.wheelbase * k as f64 / (axles - 1) as f64
        };
        for y in [p.half_track, -p.half_track] {
            m += p.wheel_mass;
            mx += p.wheel_mass * x;
            my += p.wheel_mass * y;
            j_origin += p.wheel_diametral_inertia + p.wheel_mass * (x * x + y * y);
        }
    }
    (m, mx / m, my / m, j_origin)
}

#[test]
fn sys_platform_composite_is_the_wheel_by_wheel_sum_about_its_mass_centre() {
    for axles in 1..=3 {
        for offset in [0.0, 0.08, -0.13] {
            let wheelbase = if axles == 1 { 0.0 } else { 0.55 };
            let p = platform(2 * axles, wheelbase, offset);
            let c = p.composite();
            let (m, xg, yg, j_origin) = summed(&p);
            assert_eq!(yg, 0.0, "the wheels sit symmetrically across the track");
            // Parallel axes: the inertia about the origin minus M·x̄² is the inertia about the
            // mass centre.
            let j_centre = j_origin - m * xg * xg;
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs().max(1.0);
            let what = format!("{axles} axle(s), chassis offset {offset}: {c:?}");
            assert!(close(c.mass, m), "mass {m}; {what}");
            assert!(close(c.com_offset, xg), "mass centre {xg}; {what}");
            assert!(
                close(c.yaw_inertia, j_centre),
                "yaw inertia {j_centre}; {what}"
            );
            assert_eq!(c.side_spin_inertia, axles as f64 * p.wheel_spin_inertia);
            assert_eq!(c.side_friction, axles as f64 * p.wheel_friction);
            assert_eq!(
                (c.wheel_radius, c.half_track),
                (p.wheel_radius, p.half_track)
            );
        }
    }
}

#[test]
fn sys_platform_composite_of_a_four_wheel_platform_by_hand() {
    // Chassis 2 kg at x = 0.3 (J = 0.5); wheels 1 kg at (±0.3, ±0.2) (J_d = 0.01):
    // M = 6, x̄ = (2·0.3)/6 = 0.1, J_origin = 0.5 + 2·0.09 + 4·(0.01 + 0.13) = 1.24,
    // J = 1.24 − 6·0.1² = 1.18.
    let mut p = platform(4, 0.6, 0.3);
    (p.chassis_mass, p.chassis_yaw_inertia) = (2.0, 0.5);
    (p.wheel_mass, p.wheel_diametral_inertia, p.half_track) = (1.0, 0.01, 0.2);
    let c = p.composite();
    assert_eq!(p.axle_positions(), vec![0.3, -0.3]);
    assert!((c.mass - 6.0).abs() < 1e-15, "{c:?}");
    assert!((c.com_offset - 0.1).abs() < 1e-15, "{c:?}");
    assert!((c.yaw_inertia - 1.18).abs() < 1e-14, "{c:?}");
}

#[test]
fn sys_axles_span_the_wheelbase_front_to_rear() {
    assert_eq!(platform(2, 0.0, 0.0).axle_positions(), vec![0.0]);
    assert_eq!(
        platform(6, 0.5, 0.0).axle_positions(),
        vec![0.25, 0.0, -0.25]
    );
}

fn mobile(name: &str) -> MobileManipulator {
    catalog_scene(name)
        .unwrap()
        .unwrap()
        .mobile_manipulator()
        .cloned()
        .unwrap()
}

fn names(specs: &[channel::Spec]) -> Vec<String> {
    specs.iter().map(|s| s.0.clone()).collect()
}

#[test]
fn sys_mobile_channels_follow_the_parts_of_the_scene() {
    let platform_only = names(&channel::mobile_manipulator(&mobile("mobile-platform")));
    assert_eq!(platform_only.len(), 7 + 1);
    assert_eq!(platform_only[0], channel::PLATFORM_X);
    assert_eq!(platform_only[7], channel::CONSTRAINT_DRIFT);

    let fixed = names(&channel::mobile_manipulator(&mobile(
        "mobile-arm-fixed-base",
    )));
    assert_eq!(fixed.len(), 12 + 3 + 1);
    assert_eq!(fixed[0], channel::joint_angle(1));
    assert!(!fixed.iter().any(|n| n.starts_with("platform.")));

    let rigid = names(&channel::mobile_manipulator(&mobile("mobile-manipulator")));
    assert_eq!(rigid.len(), 7 + 12 + 3 + 1);

    let mm = mobile("mobile-manipulator-flexible");
    let k = mm.flexible_link.as_ref().unwrap().link;
    let flexible = names(&channel::mobile_manipulator(&mm));
    let mut expected = rigid[..rigid.len() - 1].to_vec();
    expected.extend([
        channel::flexible_tip_in_plane(k),
        channel::flexible_tip_out_of_plane(k),
        channel::CONSTRAINT_DRIFT.to_string(),
    ]);
    assert_eq!(flexible, expected);
    // The rigid model of the flexible scene (its EI → ∞ limit) writes no tip deflections.
    assert_eq!(names(&channel::mobile_manipulator_rigid(&mm)), rigid);
}
