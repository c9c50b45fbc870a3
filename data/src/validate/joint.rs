//! A joint (of a chain's link, or the payload link's base): hub, spring, damper and torque
//! values, and a prescribed motion that excludes the others.

use super::issue::Checker;
use crate::locate::FieldPath;
use crate::scene::{Joint, PrescribedMotion, TorqueLaw};

pub(super) fn check_joint(c: &mut Checker, p: &FieldPath, j: &Joint) {
    c.opt_positive(p.key("hub_inertia"), j.hub_inertia);
    if let Some(k) = j.stiffness {
        c.non_negative(p.key("stiffness"), k);
    }
    if let Some(d) = j.damping {
        c.non_negative(p.key("damping"), d);
    }
    if let Some(s) = j.set_point {
        c.finite(p.key("set_point"), s);
        if j.stiffness.is_none() {
            c.fail(
                p.key("set_point"),
                "a spring set-point without a spring",
                "`stiffness = K` alongside `set_point`, or no `set_point`",
            );
        }
    }
    c.finite(p.key("initial_angle"), j.initial_angle);
    c.finite(p.key("initial_rate"), j.initial_rate);
    if let Some(pm) = &j.prescribed {
        for (key, on) in [
            ("torque", j.torque.is_some()),
            ("stiffness", j.stiffness.is_some()),
            ("damping", j.damping.is_some()),
        ] {
            if on {
                c.fail(
                    p.key(key),
                    format!(
                        "contradictory: the joint motion is prescribed, so `{key}` cannot act on it"
                    ),
                    "either `prescribed` or spring/damper/torque, not both",
                );
            }
        }
        let pp = p.key("prescribed");
        match *pm {
            PrescribedMotion::SpinUp { omega_s, t_s } => {
                c.finite(pp.key("omega_s"), omega_s);
                c.positive(pp.key("t_s"), t_s);
            }
            PrescribedMotion::ConstantRate { rate } => c.finite(pp.key("rate"), rate),
            PrescribedMotion::Fixed => {}
        }
        if j.initial_rate != 0.0 {
            c.fail(
                p.key("initial_rate"),
                "the initial rate of a prescribed joint follows from the law",
                "no `initial_rate` when `prescribed` is set",
            );
        }
    }
    if let Some(t) = &j.torque {
        let tp = p.key("torque");
        match *t {
            TorqueLaw::Constant { value, until } => {
                c.finite(tp.key("value"), value);
                c.opt_positive(tp.key("until"), until);
            }
            TorqueLaw::BangBang {
                amplitude,
                switch,
                off,
            } => {
                c.finite(tp.key("amplitude"), amplitude);
                c.positive(tp.key("switch"), switch);
                if !(off.is_finite() && off > switch) {
                    c.fail(
                        tp.key("off"),
                        format!("off = {off} is not after switch = {switch}"),
                        "a time `off` > `switch`",
                    );
                }
            }
        }
    }
}
