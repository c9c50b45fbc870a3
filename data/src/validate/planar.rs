//! Planar link chains: the links (sizes, section properties, consistent flags), gravity,
//! contacts naming existing links on valid surfaces, statics loads and study speeds.

use super::issue::Checker;
use super::joint::check_joint;
use super::limits::{MAX_CONTACTS, MAX_LINKS};
use crate::locate::FieldPath;
use crate::scene::{Contact, Link, PlanarChain, Surface};

pub(super) fn check_planar_chain(c: &mut Checker, scene: &PlanarChain) {
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
