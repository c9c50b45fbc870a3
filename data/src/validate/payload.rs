//! The 3-D payload link: a slender rod, its elastic fields, the payload's mass and inertia,
//! damping and gravity only on fields the rod carries, and its base joint.

use super::inertia::{is_symmetric, leading_minors_positive, principal_minors_nonnegative};
use super::issue::Checker;
use super::joint::check_joint;
use crate::locate::FieldPath;
use crate::scene::{LinkField, LinkInitialShape, PayloadLink};

pub(super) fn check_payload_link(c: &mut Checker, b: &FieldPath, p: &PayloadLink) {
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
