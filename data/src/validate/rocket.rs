//! The variable-mass rocket: material and nozzle values, stages (burning ones with a casing
//! weight), discrete masses on the body and springs between them.

use super::issue::Checker;
use super::limits::{MAX_DISCRETE_MASSES, MAX_STAGES};
use crate::locate::FieldPath;
use crate::scene::{InitialShape, Rocket};

pub(super) fn check_rocket(c: &mut Checker, p: &FieldPath, r: &Rocket) {
    c.positive(p.key("gravity"), r.gravity);
    c.positive(p.key("youngs_modulus"), r.youngs_modulus);
    c.non_negative(p.key("exhaust_velocity"), r.exhaust_velocity);
    c.non_negative(p.key("chamber_pressure"), r.chamber_pressure);
    c.non_negative(p.key("exit_pressure"), r.exit_pressure);
    c.non_negative(p.key("port_area"), r.port_area);
    c.finite(p.key("nozzle_angle_deg"), r.nozzle_angle_deg);
    if !(r.launch_angle_deg.is_finite() && (-180.0..=180.0).contains(&r.launch_angle_deg)) {
        c.fail(
            p.key("launch_angle_deg"),
            format!("{} is not an angle in degrees", r.launch_angle_deg),
            "a number of degrees in [-180, 180]",
        );
    }
    if r.stages.is_empty() || r.stages.len() > MAX_STAGES {
        c.fail(
            p.key("stage"),
            format!("{} stages", r.stages.len()),
            format!("1 to {MAX_STAGES} [[rocket.stage]] tables"),
        );
    }
    for (i, s) in r.stages.iter().enumerate() {
        let sp = p.key("stage").index(i);
        c.positive(sp.key("length"), s.length);
        c.positive(sp.key("area"), s.area);
        c.positive(sp.key("inertia"), s.inertia);
        c.positive(sp.key("weight_per_length"), s.weight_per_length);
        c.non_negative(sp.key("burn_rate"), s.burn_rate);
        if let Some(cw) = s.casing_weight_per_length {
            c.positive(sp.key("casing_weight_per_length"), cw);
            if cw > s.weight_per_length {
                c.fail(
                    sp.key("casing_weight_per_length"),
                    format!(
                        "casing weight {cw} exceeds the total weight {}",
                        s.weight_per_length
                    ),
                    "casing_weight_per_length ≤ weight_per_length",
                );
            }
        }
        if s.burn_rate > 0.0 && s.casing_weight_per_length.is_none() {
            c.fail(
                sp.key("casing_weight_per_length"),
                "a burning stage needs the weight that cannot burn",
                "casing_weight_per_length = <w > 0>",
            );
        }
    }
    let length = r.length();
    if r.discrete_masses.len() > MAX_DISCRETE_MASSES {
        c.fail(
            p.key("discrete_mass"),
            format!("{} discrete masses", r.discrete_masses.len()),
            format!("at most {MAX_DISCRETE_MASSES}"),
        );
    }
    for (i, m) in r.discrete_masses.iter().enumerate() {
        let mp = p.key("discrete_mass").index(i);
        if !(m.position.is_finite() && m.position >= 0.0 && m.position <= length) {
            c.fail(
                mp.key("position"),
                format!("x = {} is outside the body", m.position),
                format!("a station in [0, {length}]"),
            );
        }
        c.positive(mp.key("weight"), m.weight);
        check_coupling(
            c,
            &mp,
            [
                m.axial_stiffness,
                m.transverse_stiffness,
                m.axial_damping,
                m.transverse_damping,
            ],
        );
    }
    for (i, s) in r.springs.iter().enumerate() {
        let sp = p.key("spring").index(i);
        let n = r.discrete_masses.len();
        if s.between[0] >= n || s.between[1] >= n || s.between[0] == s.between[1] {
            c.fail(
                sp.key("between"),
                format!("{:?} does not name two distinct discrete masses", s.between),
                format!("two different indices in 0..{n}"),
            );
        }
        check_coupling(
            c,
            &sp,
            [
                s.axial_stiffness,
                s.transverse_stiffness,
                s.axial_damping,
                s.transverse_damping,
            ],
        );
    }
    if let InitialShape::Report { a1, a2 } = r.initial_shape {
        c.finite(p.key("initial_shape").key("a1"), a1);
        c.finite(p.key("initial_shape").key("a2"), a2);
    }
}

/// The axial and transverse stiffness and damping of a discrete mass's attachment or of a
/// spring, in that order: each finite and ≥ 0.
fn check_coupling(c: &mut Checker, p: &FieldPath, values: [f64; 4]) {
    let keys = [
        "axial_stiffness",
        "transverse_stiffness",
        "axial_damping",
        "transverse_damping",
    ];
    for (key, v) in keys.into_iter().zip(values) {
        c.non_negative(p.key(key), v);
    }
}
