//! The mobile manipulator: the skid-steer platform (wheels, axles, drive schedule), the arm
//! (bodies, three pitch links, torque schedule), the initial state and the flexible link.

use super::body::{check_body, check_flexible_body};
use super::issue::Checker;
use super::limits::MAX_WHEELS;
use crate::locate::FieldPath;
use crate::scene::{MobileManipulator, TorqueSchedule};

pub(super) fn check_mobile(c: &mut Checker, m: &MobileManipulator) {
    let b = FieldPath::root().key("mobile_manipulator");
    c.finite(b.key("gravity"), m.gravity);
    if m.platform.is_none() && m.arm.is_none() {
        c.fail(
            b.clone(),
            "neither a platform nor an arm is defined",
            "a [mobile_manipulator.platform] table, a [mobile_manipulator.arm] table, or both",
        );
    }
    if let Some(p) = &m.platform {
        let pb = b.key("platform");
        for (k, v) in [
            ("chassis_mass", p.chassis_mass),
            ("chassis_yaw_inertia", p.chassis_yaw_inertia),
            ("wheel_radius", p.wheel_radius),
            ("wheel_mass", p.wheel_mass),
            ("wheel_spin_inertia", p.wheel_spin_inertia),
            ("wheel_diametral_inertia", p.wheel_diametral_inertia),
            ("half_track", p.half_track),
        ] {
            c.positive(pb.key(k), v);
        }
        c.non_negative(pb.key("wheelbase"), p.wheelbase);
        c.finite(pb.key("chassis_com_offset"), p.chassis_com_offset);
        c.non_negative(pb.key("wheel_friction"), p.wheel_friction);
        let axles = p.axles();
        if p.wheel_count < 2 || p.wheel_count % 2 != 0 || p.wheel_count > MAX_WHEELS {
            c.fail(
                pb.key("wheel_count"),
                format!("{} wheels cannot form a skid-steer platform", p.wheel_count),
                format!("an even number of wheels from 2 to {MAX_WHEELS}"),
            );
        } else if axles == 1 && p.wheelbase != 0.0 {
            c.fail(
                pb.key("wheelbase"),
                format!("{} with a single axle", p.wheelbase),
                "0 for a two-wheel platform (or more wheels)",
            );
        }
        if p.driven_axles.is_empty() {
            c.fail(
                pb.key("driven_axles"),
                "no driven axle",
                "a list of axle numbers, e.g. [1, 2, 3]",
            );
        }
        for (k, &a) in p.driven_axles.iter().enumerate() {
            if a == 0 || a > axles.max(1) {
                c.fail(
                    pb.key("driven_axles").index(k),
                    format!("axle {a} does not exist"),
                    format!("an axle number from 1 to {}", axles.max(1)),
                );
            } else if p.driven_axles[..k].contains(&a) {
                c.fail(
                    pb.key("driven_axles").index(k),
                    format!("axle {a} is listed twice"),
                    "each driven axle once",
                );
            }
        }
        check_schedule(c, &pb.key("drive"), &p.drive, 2, "[τ_R, τ_L]");
    }
    if let Some(a) = &m.arm {
        let ab = b.key("arm");
        for (k, v) in a.mount.iter().enumerate() {
            c.finite(ab.key("mount").index(k), *v);
        }
        c.non_negative(ab.key("base_height"), a.base_height);
        check_body(c, &ab.key("turret"), &a.turret, true);
        if a.links.len() != 3 {
            c.fail(
                ab.key("links"),
                format!("{} pitch links", a.links.len()),
                "exactly three [[mobile_manipulator.arm.links]] tables (joints θ₂, θ₃, θ₄)",
            );
        }
        for (k, l) in a.links.iter().enumerate() {
            let lb = ab.key("links").index(k);
            c.positive(lb.key("length"), l.length);
            check_body(c, &lb, &l.body(), true);
        }
        check_body(c, &ab.key("gripper"), &a.gripper, false);
        for (k, v) in a.joint_friction.iter().enumerate() {
            c.non_negative(ab.key("joint_friction").index(k), *v);
        }
        check_schedule(c, &ab.key("torques"), &a.torques, 4, "[τ₁, τ₂, τ₃, τ₄]");
    }
    let ib = b.key("initial");
    let i = &m.initial;
    for (k, v) in [("x", i.x), ("y", i.y), ("heading", i.heading)] {
        c.finite(ib.key(k), v);
    }
    for (k, v) in i.joint_angles.iter().enumerate() {
        c.finite(ib.key("joint_angles").index(k), *v);
    }
    for (k, v) in i.joint_rates.iter().enumerate() {
        c.finite(ib.key("joint_rates").index(k), *v);
    }
    for (k, v) in i.wheel_rates.iter().enumerate() {
        c.finite(ib.key("wheel_rates").index(k), *v);
    }
    if let Some(f) = &m.flexible_link {
        let fb = b.key("flexible_link");
        if m.arm.is_none() {
            c.fail(
                fb.clone(),
                "a flexible link without an arm",
                "an [mobile_manipulator.arm] table, or no flexible_link",
            );
        }
        if !(1..=3).contains(&f.link) {
            c.fail(
                fb.key("link"),
                format!("pitch link {} does not exist", f.link),
                "1, 2 or 3 (base to tip)",
            );
        }
        c.positive(
            fb.key("bending_stiffness_in_plane"),
            f.bending_stiffness_in_plane,
        );
        c.positive(
            fb.key("bending_stiffness_out_of_plane"),
            f.bending_stiffness_out_of_plane,
        );
        if let Some(l) = m
            .arm
            .as_ref()
            .and_then(|a| f.link.checked_sub(1).and_then(|k| a.links.get(k)))
        {
            check_flexible_body(c, &b.key("arm").key("links").index(f.link - 1), l);
        }
    }
}

fn check_schedule(c: &mut Checker, p: &FieldPath, s: &TorqueSchedule, width: usize, what: &str) {
    match s {
        TorqueSchedule::Pulses {
            amplitude,
            period,
            bias,
        } => {
            c.positive(p.key("period"), *period);
            if amplitude.len() != width {
                c.fail(
                    p.key("amplitude"),
                    format!("{} entries", amplitude.len()),
                    format!("{width} entries {what}"),
                );
            }
            if !bias.is_empty() && bias.len() != width {
                c.fail(
                    p.key("bias"),
                    format!("{} entries", bias.len()),
                    format!("{width} entries {what}, or none"),
                );
            }
            for (k, v) in amplitude.iter().enumerate() {
                c.finite(p.key("amplitude").index(k), *v);
            }
            for (k, v) in bias.iter().enumerate() {
                c.finite(p.key("bias").index(k), *v);
            }
        }
        TorqueSchedule::Steps { times, values } => {
            if times.is_empty() || times.len() != values.len() {
                c.fail(
                    p.key("values"),
                    format!("{} times and {} rows of values", times.len(), values.len()),
                    "one row of values per time, at least one",
                );
            }
            for (k, &t) in times.iter().enumerate() {
                if !t.is_finite() || t < 0.0 || (k > 0 && t <= times[k - 1]) {
                    c.fail(
                        p.key("times").index(k),
                        format!("{t} is not after the previous time"),
                        "finite times ≥ 0 in increasing order",
                    );
                }
            }
            for (k, row) in values.iter().enumerate() {
                if row.len() != width {
                    c.fail(
                        p.key("values").index(k),
                        format!("{} entries", row.len()),
                        format!("{width} entries {what}"),
                    );
                }
                for v in row {
                    if !v.is_finite() {
                        c.fail(p.key("values").index(k), format!("{v}"), "finite torques");
                    }
                }
            }
        }
    }
}
