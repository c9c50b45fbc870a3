//! Semantic validation: what TOML syntax and serde types cannot express.
//!
//! Each problem names the field and the form it should take. Limits on sizes are stated here
//! (and in the README) so that absurd inputs fail early with a message instead of exhausting
//! memory.

use crate::locate::FieldPath;
use crate::scene::{
    Contact, InitialShape, Joint, Link, LinkField, LinkInitialShape, MobileManipulator, Model,
    PayloadLink, PlanarChain, PrescribedMotion, RigidBody, Rocket, Scene, SceneFile, Surface,
    TorqueLaw, TorqueSchedule,
};

/// Largest accepted scene file.
pub const MAX_FILE_BYTES: usize = 1 << 20;
/// Largest number of links in a planar chain.
pub const MAX_LINKS: usize = 8;
pub const MAX_CONTACTS: usize = 8;
pub const MAX_STAGES: usize = 4;
pub const MAX_DISCRETE_MASSES: usize = 32;
/// Largest number of field stations sampled per link.
pub const MAX_FIELD_STATIONS: usize = 1001;
/// Largest number of output samples t_end / output_interval.
pub const MAX_OUTPUT_SAMPLES: f64 = 1.0e6;

/// One semantic problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Issue {
    pub path: FieldPath,
    pub message: String,
    pub expected: String,
}

struct Checker {
    issues: Vec<Issue>,
}

impl Checker {
    fn fail(&mut self, path: FieldPath, message: impl Into<String>, expected: impl Into<String>) {
        self.issues.push(Issue {
            path,
            message: message.into(),
            expected: expected.into(),
        });
    }

    fn positive(&mut self, path: FieldPath, v: f64) {
        if !v.is_finite() || v <= 0.0 {
            self.fail(path, format!("{v} is not positive"), "a finite number > 0");
        }
    }

    fn non_negative(&mut self, path: FieldPath, v: f64) {
        if !v.is_finite() || v < 0.0 {
            self.fail(path, format!("{v} is negative"), "a finite number ≥ 0");
        }
    }

    fn finite(&mut self, path: FieldPath, v: f64) {
        if !v.is_finite() {
            self.fail(path, format!("{v} is not finite"), "a finite number");
        }
    }

    fn opt_positive(&mut self, path: FieldPath, v: Option<f64>) {
        if let Some(v) = v {
            self.positive(path, v);
        }
    }
}

/// Problems of the file as a whole, in document order: name, description, simulation, and
/// the model families (exactly one; planar-only tables only with links). A file without such
/// problems converts into a [`Scene`].
pub fn check_file(scene: &SceneFile) -> Vec<Issue> {
    let mut c = Checker { issues: Vec::new() };
    let root = FieldPath::root();

    if scene.name.trim().is_empty()
        || !scene
            .name
            .chars()
            .all(|ch| ch.is_ascii_lowercase() || ch.is_ascii_digit() || ch == '-')
    {
        c.fail(
            root.key("name"),
            format!("`{}` is not a kebab-case identifier", scene.name),
            "lower-case letters, digits and `-`, e.g. \"my-beam\"",
        );
    }
    if scene.description.trim().is_empty() {
        c.fail(
            root.key("description"),
            "is empty",
            "a one-line description",
        );
    }

    let sim = root.key("simulation");
    c.positive(sim.key("t_end"), scene.simulation.t_end);
    c.positive(sim.key("output_interval"), scene.simulation.output_interval);
    if scene.simulation.t_end.is_finite()
        && scene.simulation.output_interval > 0.0
        && scene.simulation.t_end / scene.simulation.output_interval > MAX_OUTPUT_SAMPLES
    {
        c.fail(
            sim.key("output_interval"),
            format!(
                "t_end / output_interval = {:.3e} output samples is above the limit {MAX_OUTPUT_SAMPLES:.0e}",
                scene.simulation.t_end / scene.simulation.output_interval
            ),
            "a larger output_interval",
        );
    }
    let fs = scene.simulation.field_stations;
    if !(2..=MAX_FIELD_STATIONS).contains(&fs) {
        c.fail(
            sim.key("field_stations"),
            format!("{fs} stations is outside the supported range"),
            format!("an integer from 2 to {MAX_FIELD_STATIONS}"),
        );
    }

    let families = [
        ("link", !scene.links.is_empty()),
        ("rocket", scene.rocket.is_some()),
        ("payload_link", scene.payload_link.is_some()),
        ("mobile_manipulator", scene.mobile_manipulator.is_some()),
    ];
    let present: Vec<&str> = families.iter().filter(|f| f.1).map(|f| f.0).collect();
    match present.len() {
        0 => c.fail(
            root,
            "the scene defines no model",
            "one of: [[link]] tables, [rocket], [payload_link] or [mobile_manipulator]",
        ),
        1 => {}
        _ => c.fail(
            root.key(present[1]),
            format!(
                "contradictory model families: {} together",
                present.join(" and ")
            ),
            "exactly one model family per scene file",
        ),
    }
    let planar = present == ["link"];
    if !planar {
        for (key, on) in [
            ("gravity", scene.gravity.is_some()),
            ("contact", !scene.contacts.is_empty()),
            ("statics", scene.statics.is_some()),
            ("studies", scene.studies.is_some()),
        ] {
            if on {
                c.fail(
                    FieldPath::root().key(key),
                    format!("`{key}` applies only to planar link chains"),
                    "remove it, or use the family's own fields (e.g. rocket.gravity)",
                );
            }
        }
    }

    c.issues
}

/// All semantic problems of a scene's model, in document order as far as possible.
pub fn validate(scene: &Scene) -> Vec<Issue> {
    let mut c = Checker { issues: Vec::new() };
    match &scene.model {
        Model::PlanarChain(chain) => check_planar_chain(&mut c, chain),
        Model::Rocket(r) => check_rocket(&mut c, &FieldPath::root().key("rocket"), r),
        Model::PayloadLink(p) => {
            check_payload_link(&mut c, &FieldPath::root().key("payload_link"), p)
        }
        Model::MobileManipulator(m) => check_mobile(&mut c, m),
    }
    c.issues
}

fn check_planar_chain(c: &mut Checker, scene: &PlanarChain) {
    if scene.links.len() > MAX_LINKS {
        c.fail(
            FieldPath::root().key("link"),
            format!("{} links is above the limit", scene.links.len()),
            format!("at most {MAX_LINKS} links"),
        );
    }
    for (i, link) in scene.links.iter().enumerate() {
        let p = FieldPath::root().key("link").index(i);
        if scene.links[..i].iter().any(|l| l.name == link.name) {
            c.fail(
                p.key("name"),
                format!("duplicate link name `{}`", link.name),
                "a unique name per link",
            );
        }
        check_link(c, &p, link);
    }

    if let Some(g) = &scene.gravity {
        c.finite(
            FieldPath::root().key("gravity").key("vector").index(0),
            g.vector[0],
        );
        c.finite(
            FieldPath::root().key("gravity").key("vector").index(1),
            g.vector[1],
        );
    }

    if scene.contacts.len() > MAX_CONTACTS {
        c.fail(
            FieldPath::root().key("contact"),
            format!("{} contacts is above the limit", scene.contacts.len()),
            format!("at most {MAX_CONTACTS} contacts"),
        );
    }
    for (i, contact) in scene.contacts.iter().enumerate() {
        check_contact(
            c,
            &FieldPath::root().key("contact").index(i),
            contact,
            scene,
        );
    }

    if let Some(st) = &scene.statics {
        let p = FieldPath::root().key("statics");
        if let Some(f) = st.tip_force {
            c.finite(p.key("tip_force"), f);
        }
        if let Some(q) = st.distributed_load {
            c.finite(p.key("distributed_load"), q);
        }
        for (k, lp) in st.elastica_load_parameters.iter().enumerate() {
            let pp = p.key("elastica_load_parameters").index(k);
            if !(lp.is_finite() && *lp > 0.0 && *lp <= 100.0) {
                c.fail(
                    pp,
                    format!("{lp} is out of range"),
                    "a load parameter PL²/EI in (0, 100]",
                );
            }
        }
    }
    if let Some(st) = &scene.studies {
        for (k, l) in st.rotation_speeds.iter().enumerate() {
            c.non_negative(
                FieldPath::root()
                    .key("studies")
                    .key("rotation_speeds")
                    .index(k),
                *l,
            );
        }
    }
}

fn check_link(c: &mut Checker, p: &FieldPath, l: &Link) {
    if l.name.trim().is_empty() {
        c.fail(p.key("name"), "is empty", "a non-empty link name");
    }
    c.positive(p.key("length"), l.length);
    c.positive(p.key("mass_per_length"), l.mass_per_length);
    c.positive(p.key("bending_stiffness"), l.bending_stiffness);
    c.opt_positive(p.key("axial_stiffness"), l.axial_stiffness);
    c.opt_positive(p.key("shear_stiffness"), l.shear_stiffness);
    c.opt_positive(
        p.key("rotary_inertia_per_length"),
        l.rotary_inertia_per_length,
    );
    c.opt_positive(p.key("kelvin_voigt"), l.kelvin_voigt);
    c.opt_positive(p.key("tip_mass"), l.tip_mass);
    c.opt_positive(p.key("tip_inertia"), l.tip_inertia);
    if l.axial && l.foreshortening {
        c.fail(
            p.key("foreshortening"),
            "contradictory flags: `axial` (extensible, strain u' + ½v'²) and `foreshortening` \
             (inextensible) are both on",
            "at most one of `axial = true` and `foreshortening = true`",
        );
    }
    if l.axial && l.axial_stiffness.is_none() {
        c.fail(
            p.key("axial_stiffness"),
            "`axial = true` needs the axial stiffness EA, which is missing",
            "axial_stiffness = <EA > 0>",
        );
    }
    if l.shear && l.shear_stiffness.is_none() {
        c.fail(
            p.key("shear_stiffness"),
            "`shear = true` needs the shear stiffness κGA, which is missing",
            "shear_stiffness = <κGA > 0>",
        );
    }
    if l.rotary_inertia && l.rotary_inertia_per_length.is_none() {
        c.fail(
            p.key("rotary_inertia_per_length"),
            "`rotary_inertia = true` needs ρI, which is missing",
            "rotary_inertia_per_length = <ρI > 0>",
        );
    }
    check_joint(c, &p.key("joint"), &l.joint);
}

fn check_payload_link(c: &mut Checker, b: &FieldPath, p: &PayloadLink) {
    for (k, v) in [
        ("length", p.length),
        ("radius", p.radius),
        ("youngs_modulus", p.youngs_modulus),
        ("shear_modulus", p.shear_modulus),
        ("density", p.density),
    ] {
        c.positive(b.key(k), v);
    }
    if p.radius.is_finite() && p.length.is_finite() && p.radius >= 0.1 * p.length {
        c.fail(
            b.key("radius"),
            format!(
                "radius {} is not small against length {}: the rod model neglects shear and \
                 warping",
                p.radius, p.length
            ),
            "a slender rod, radius < length / 10",
        );
    }
    if p.fields.is_empty() {
        c.fail(
            b.key("fields"),
            "no elastic field: the rod would be rigid",
            "a subset of [\"axial\", \"horizontal\", \"vertical\", \"torsion\"], or omit `fields` for all four",
        );
    }
    for (k, f) in p.fields.iter().enumerate() {
        if p.fields[..k].contains(f) {
            c.fail(
                b.key("fields").index(k),
                format!("field `{}` listed twice", f.name()),
                "each field at most once",
            );
        }
    }
    let pl = b.key("payload");
    c.positive(pl.key("mass"), p.payload.mass);
    c.non_negative(pl.key("offset"), p.payload.offset);
    let i = &p.payload.inertia;
    for (r, row) in i.iter().enumerate() {
        for (col, v) in row.iter().enumerate() {
            c.finite(pl.key("inertia").index(r).index(col), *v);
        }
    }
    for (r, col) in [(0, 1), (0, 2), (1, 2)] {
        if i[r][col] != i[col][r] {
            c.fail(
                pl.key("inertia").index(r).index(col),
                format!(
                    "inertia matrix is not symmetric: [{r}][{col}] = {} but [{col}][{r}] = {}",
                    i[r][col], i[col][r]
                ),
                "a symmetric matrix [[I1, I4, I5], [I4, I2, I6], [I5, I6, I3]]",
            );
        }
    }
    if i.iter().flatten().all(|v| v.is_finite()) && is_symmetric(i) {
        // Positive definite, and each principal moment at most the sum of the other two, i.e.
        // (tr I / 2)·1 − I positive semidefinite (Sylvester's criteria on both).
        let tr = i[0][0] + i[1][1] + i[2][2];
        let slack = std::array::from_fn(|r| {
            std::array::from_fn(|col| if r == col { 0.5 * tr } else { 0.0 } - i[r][col])
        });
        if !(leading_minors_positive(i) && principal_minors_nonnegative(&slack, tr.abs())) {
            c.fail(
                pl.key("inertia"),
                "not the inertia matrix of a rigid body: its principal moments must be positive \
                 and each at most the sum of the other two",
                "a symmetric positive definite matrix satisfying the triangle inequality",
            );
        }
    }
    check_joint(c, &b.key("base"), &p.base);
    if let Some(k) = &p.kelvin_voigt {
        let kp = b.key("kelvin_voigt");
        for f in LinkField::ALL {
            let key = f.name();
            if let Some(v) = match f {
                LinkField::Axial => k.axial,
                LinkField::Horizontal => k.horizontal,
                LinkField::Vertical => k.vertical,
                LinkField::Torsion => k.torsion,
            } {
                c.non_negative(kp.key(key), v);
                if v > 0.0 && !p.has(f) {
                    c.fail(
                        kp.key(key),
                        format!("damping on the `{key}` field, which the rod does not carry"),
                        format!("add \"{key}\" to `fields`, or remove `kelvin_voigt.{key}`"),
                    );
                }
            }
        }
    }
    if let Some(g) = p.gravity {
        c.non_negative(b.key("gravity"), g);
        if g > 0.0 && !p.has(LinkField::Vertical) {
            c.fail(
                b.key("gravity"),
                "gravity bends the rod vertically, but the `vertical` field is off",
                "add \"vertical\" to `fields`, or remove `gravity`",
            );
        }
    }
    if p.initial_shape == LinkInitialShape::StaticSag && p.gravity.is_none_or(|g| g == 0.0) {
        c.fail(
            b.key("initial_shape"),
            "a static-sag start without gravity",
            "`gravity = 9.81` (or another g), or `initial_shape = \"undeformed\"`",
        );
    }
}

fn is_symmetric(m: &[[f64; 3]; 3]) -> bool {
    m[0][1] == m[1][0] && m[0][2] == m[2][0] && m[1][2] == m[2][1]
}

fn det2(m: &[[f64; 3]; 3], a: usize, b: usize) -> f64 {
    m[a][a] * m[b][b] - m[a][b] * m[b][a]
}

fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn leading_minors_positive(m: &[[f64; 3]; 3]) -> bool {
    m[0][0] > 0.0 && det2(m, 0, 1) > 0.0 && det3(m) > 0.0
}

/// All principal minors non-negative up to round-off relative to `scale` (an entry's size):
/// positive semidefinite.
fn principal_minors_nonnegative(m: &[[f64; 3]; 3], scale: f64) -> bool {
    let eps = 1e-12;
    (0..3).all(|k| m[k][k] >= -eps * scale)
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| det2(m, a, b) >= -eps * scale * scale)
        && det3(m) >= -eps * scale.powi(3)
}

fn check_joint(c: &mut Checker, p: &FieldPath, j: &Joint) {
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

fn check_contact(c: &mut Checker, p: &FieldPath, ct: &Contact, scene: &PlanarChain) {
    if scene.link_index(&ct.link).is_none() {
        let names: Vec<&str> = scene.links.iter().map(|l| l.name.as_str()).collect();
        c.fail(
            p.key("link"),
            format!("no link is named `{}`", ct.link),
            format!("one of the link names: {}", names.join(", ")),
        );
    }
    c.non_negative(p.key("friction"), ct.friction);
    let sp = p.key("surface");
    match ct.surface {
        Surface::Line { point, normal } => {
            c.finite(sp.key("point").index(0), point[0]);
            c.finite(sp.key("point").index(1), point[1]);
            if !(normal[0].is_finite() && normal[1].is_finite())
                || normal[0].hypot(normal[1]) == 0.0
            {
                c.fail(
                    sp.key("normal"),
                    "the normal is zero or not finite",
                    "a non-zero vector [nx, ny]",
                );
            }
        }
        Surface::Circle { center, radius } => {
            c.finite(sp.key("center").index(0), center[0]);
            c.finite(sp.key("center").index(1), center[1]);
            c.positive(sp.key("radius"), radius);
        }
    }
}

fn check_rocket(c: &mut Checker, p: &FieldPath, r: &Rocket) {
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
        c.non_negative(mp.key("axial_stiffness"), m.axial_stiffness);
        c.non_negative(mp.key("transverse_stiffness"), m.transverse_stiffness);
        c.non_negative(mp.key("axial_damping"), m.axial_damping);
        c.non_negative(mp.key("transverse_damping"), m.transverse_damping);
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
        c.non_negative(sp.key("axial_stiffness"), s.axial_stiffness);
        c.non_negative(sp.key("transverse_stiffness"), s.transverse_stiffness);
        c.non_negative(sp.key("axial_damping"), s.axial_damping);
        c.non_negative(sp.key("transverse_damping"), s.transverse_damping);
    }
    if let InitialShape::Report { a1, a2 } = r.initial_shape {
        c.finite(p.key("initial_shape").key("a1"), a1);
        c.finite(p.key("initial_shape").key("a2"), a2);
    }
}

/// Largest number of wheels of a mobile platform.
pub const MAX_WHEELS: usize = 16;

fn check_mobile(c: &mut Checker, m: &MobileManipulator) {
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
        let axles = p.wheel_count / 2;
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

/// The flexible link is a uniform beam of the link's mass plus a residual rigid inertia
/// J_res = J − diag(0, mL²/12, mL²/12) carried by its frame: its mass centre must be the
/// beam's, (L/2, 0, 0) within 1e-12·L, and J_res must be positive semi-definite.
fn check_flexible_body(c: &mut Checker, p: &FieldPath, l: &crate::scene::ArmLink) {
    if !(l.length > 0.0 && l.mass > 0.0) {
        return; // reported by the link's own checks
    }
    let tol = 1e-12 * l.length;
    let want = [0.5 * l.length, 0.0, 0.0];
    if l.com
        .iter()
        .zip(&want)
        .any(|(a, b)| !a.is_finite() || (a - b).abs() > tol)
    {
        c.fail(
            p.key("com"),
            format!(
                "[{}, {}, {}] is not the middle of a flexible link of length {}",
                l.com[0], l.com[1], l.com[2], l.length
            ),
            format!(
                "[{}, 0.0, 0.0] (the uniform beam's mass centre, within 1e-12·L)",
                want[0]
            ),
        );
        return;
    }
    let rod = l.mass * l.length * l.length / 12.0;
    let mut j = l.inertia;
    j[1][1] -= rod;
    j[2][2] -= rod;
    if !positive_semidefinite(&j) {
        c.fail(
            p.key("inertia"),
            format!(
                "is smaller than the slender rod's (J − diag(0, mL²/12, mL²/12) with mL²/12 = \
                 {rod:e} is not positive semi-definite)"
            ),
            "an inertia of at least the uniform rod's about both transverse axes (the beam \
             carries mL²/12; the rest is a rigid residual)",
        );
    }
}

/// All principal minors of the symmetric 3×3 matrix ≥ −1e-12 · scale^k (round-off of the
/// subtraction above).
fn positive_semidefinite(j: &[[f64; 3]; 3]) -> bool {
    let s = j
        .iter()
        .flatten()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(1e-300);
    let tol = 1e-12;
    let minor2 = |a: usize, b: usize| j[a][a] * j[b][b] - j[a][b] * j[b][a];
    let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
        - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    (0..3).all(|k| j[k][k] >= -tol * s)
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| minor2(a, b) >= -tol * s * s)
        && det >= -tol * s * s * s
}

/// Mass ≥ 0 (> 0 when `massive`), finite centre of mass, and an inertia tensor that is
/// symmetric and positive definite (or all zero, a point mass, when not `massive`) with
/// diagonal moments that satisfy the triangle inequality of a real body.
fn check_body(c: &mut Checker, p: &FieldPath, body: &RigidBody, massive: bool) {
    if massive {
        c.positive(p.key("mass"), body.mass);
    } else {
        c.non_negative(p.key("mass"), body.mass);
    }
    for (k, v) in body.com.iter().enumerate() {
        c.finite(p.key("com").index(k), *v);
    }
    let j = &body.inertia;
    if j.iter().flatten().any(|v| !v.is_finite()) {
        c.fail(p.key("inertia"), "has a non-finite entry", "finite numbers");
        return;
    }
    let scale = j.iter().flatten().fold(0.0f64, |s, v| s.max(v.abs()));
    let asym = (0..3)
        .flat_map(|r| (0..3).map(move |k| (r, k)))
        .fold(0.0f64, |s, (r, k)| s.max((j[r][k] - j[k][r]).abs()));
    if asym > 1e-12 * scale {
        c.fail(
            p.key("inertia"),
            format!("is not symmetric (largest |I_ij − I_ji| = {asym:e})"),
            "a symmetric 3×3 tensor [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]]",
        );
        return;
    }
    // Sylvester's criterion on the leading minors.
    let m1 = j[0][0];
    let m2 = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    let m3 = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
        - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    let definite = m1 > 0.0 && m2 > 0.0 && m3 > 0.0;
    let zero = scale == 0.0;
    if !definite && (massive || !zero) {
        c.fail(
            p.key("inertia"),
            "is not positive definite",
            "principal moments > 0 (a body's inertia tensor about its mass centre)",
        );
        return;
    }
    let (a, bb, cc) = (j[0][0], j[1][1], j[2][2]);
    let slack = 1e-12 * scale;
    if !zero && (a > bb + cc + slack || bb > a + cc + slack || cc > a + bb + slack) {
        c.fail(
            p.key("inertia"),
            format!("diagonal moments {a}, {bb}, {cc} violate the triangle inequality"),
            "each of Ixx, Iyy, Izz at most the sum of the other two (a real body)",
        );
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
