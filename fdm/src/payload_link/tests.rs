//! The payload link's discrete equations against its energies: the kinetic energy against the
//! kinematics of docs/single-link-3d.md (rotation matrices multiplied out numerically), the
//! equations of motion against Lagrange's equations of that kinetic energy (finite differences),
//! the elastic and gravity forces against the gradient of the discrete potential.

use data::load_scene;
use data::scene::LinkField;
use nalgebra::{Matrix3, Vector3};

use super::{PayloadLinkModel, apply};

fn model(name: &str, payload: bool) -> PayloadLinkModel {
    let mut scene = load_scene(name).unwrap();
    if !payload {
        let p = &mut scene.payload_link_mut().unwrap().payload;
        p.mass = 0.0;
        p.offset = 0.0;
        p.inertia = [[0.0; 3]; 3];
    }
    PayloadLinkModel::from_payload_link(&scene, scene.payload_link().unwrap(), Some(11)).unwrap()
}

/// A smooth field state: each field a different mix of shapes, scaled by `amp`.
fn state(m: &PayloadLinkModel, amp: f64, phase: f64) -> Vec<f64> {
    let mut q = vec![0.0; m.n];
    for (k, f) in LinkField::ALL.iter().enumerate() {
        for i in 1..=m.r {
            if let Some(ix) = m.index(*f, i) {
                let x = i as f64 * m.h / m.length;
                q[ix] = amp
                    * (x * x * (1.0 + k as f64 * 0.3)
                        + 0.4 * (3.0 * x + phase + k as f64).sin() * x);
            }
        }
    }
    q
}

fn kinetic(m: &PayloadLinkModel, q: &[f64], v: &[f64], rate: f64) -> f64 {
    let mut s = vec![0.0; m.n];
    m.kinetic(q, v, rate, &mut s)
}

type V3 = Vector3<f64>;

/// 1 + [a]× + ½[a]×² (second-order rotation)
fn rot2(a: V3) -> Matrix3<f64> {
    let ax = a.cross_matrix();
    Matrix3::identity() + ax + 0.5 * ax * ax
}

/// The doc's kinetic energy evaluated from positions and rotation matrices (no hand expansion):
/// centreline points and payload centre moved along q + t q̇ (velocities by central difference
/// in t, exact for these quadratic positions), payload orientation R = R_t(β)R_x(φ) and angular
/// velocity θ̇e_z + ω, ω from the doc. The rod's rotary terms in the model's quadrature.
fn kinetic_direct(
    m: &PayloadLinkModel,
    p: &data::scene::PayloadLink,
    q: &[f64],
    v: &[f64],
    rate: f64,
) -> f64 {
    let h = m.h;
    let rho = p.density;
    let (i2, jp) = (p.second_moment(), p.polar_moment());
    let mass_at = |i: usize| if i == m.r { 0.5 } else { 1.0 } * rho * p.area() * h;
    let st = |f: LinkField, i: usize, q: &[f64]| m.index(f, i).map_or(0.0, |ix| q[ix]);
    let s_at = |i: usize, q: &[f64]| -> f64 {
        (0..i)
            .map(|s| 0.5 * h * (apply(&m.seg_v[s], q).powi(2) + apply(&m.seg_w[s], q).powi(2)))
            .sum()
    };
    let dt = 1e-3;
    let at = |t: f64| -> Vec<f64> { q.iter().zip(v).map(|(a, b)| a + t * b).collect() };
    let (qp, qm) = (at(dt), at(-dt));
    let inertial_velocity = |pos: &dyn Fn(&[f64]) -> V3| -> V3 {
        let (a, b, c) = (pos(&qp), pos(&qm), pos(q));
        (a - b) / (2.0 * dt) + Vector3::new(0.0, 0.0, rate).cross(&c)
    };
    let mut t = 0.5 * p.base_inertia() * rate * rate;
    use LinkField::*;
    for i in 1..=m.r {
        let x = i as f64 * h;
        let pos = |q: &[f64]| {
            Vector3::new(
                x + st(Axial, i, q) - s_at(i, q),
                st(Horizontal, i, q),
                st(Vertical, i, q),
            )
        };
        let vel = inertial_velocity(&pos);
        t += 0.5 * mass_at(i) * vel.norm_squared();
    }
    // rod rotary inertia in the model's quadrature
    let (ev, gw, gwd): (f64, Vec<f64>, Vec<f64>) = (
        apply(&m.tip[1], v),
        (0..m.r).map(|s| apply(&m.seg_w[s], q)).collect(),
        (0..m.r).map(|s| apply(&m.seg_w[s], v)).collect(),
    );
    for s in 0..m.r {
        let gvd = apply(&m.seg_v[s], v);
        let phibar = 0.5 * (st(Torsion, s, v) + st(Torsion, s + 1, v));
        t += 0.5 * rho * i2 * h * (gvd * gvd + gwd[s] * gwd[s]);
        t += rate * rho * jp * h * gw[s] * phibar;
        t += 0.5 * rate * rate * rho * (jp - i2) * h * gw[s] * gw[s];
    }
    for i in 1..=m.r {
        let w = if i == m.r { 0.5 } else { 1.0 };
        t += 0.5 * rho * jp * w * h * st(Torsion, i, v).powi(2);
    }
    t += rate * rho * i2 * ev + 0.5 * rate * rate * rho * i2 * p.length;
    // payload
    let pl = &p.payload;
    let c = pl.offset;
    let pos_c = |q: &[f64]| {
        let (sv, sw) = (apply(&m.slope_v, q), apply(&m.slope_w, q));
        Vector3::new(
            p.length + apply(&m.tip[0], q) - s_at(m.r, q) + c * (1.0 - 0.5 * (sv * sv + sw * sw)),
            apply(&m.tip[1], q) + c * sv,
            apply(&m.tip[2], q) + c * sw,
        )
    };
    let vc = inertial_velocity(&pos_c);
    t += 0.5 * pl.mass * vc.norm_squared();
    let (sv, sw, phi) = (
        apply(&m.slope_v, q),
        apply(&m.slope_w, q),
        apply(&m.tip[3], q),
    );
    let (svd, swd, phid) = (
        apply(&m.slope_v, v),
        apply(&m.slope_w, v),
        apply(&m.tip[3], v),
    );
    let r = rot2(Vector3::new(0.0, -sw, sv)) * rot2(Vector3::new(phi, 0.0, 0.0));
    let omega = Vector3::new(
        rate * 0.0 + phid + 0.5 * (sv * swd - sw * svd),
        -swd + sv * phid,
        rate + svd + sw * phid,
    );
    let body = r.transpose() * omega;
    let inertia = Matrix3::from(pl.inertia).transpose();
    t += 0.5 * body.dot(&(inertia * body));
    t
}

#[test]
fn elem_payload_kinetic_energy_matches_the_kinematics_to_second_order() {
    let scene = load_scene("single-link-3d").unwrap();
    let p = scene.payload_link().cloned().unwrap();
    let m = model("single-link-3d", true);
    let rate = 1.3;
    let diff = |eps: f64| {
        let (q, v) = (state(&m, eps, 0.2), state(&m, 8.0 * eps, 1.1));
        (
            kinetic(&m, &q, &v, rate) - kinetic_direct(&m, &p, &q, &v, rate),
            kinetic(&m, &q, &v, rate),
        )
    };
    let (d1, t1) = diff(2e-2);
    let (d2, _) = diff(1e-2);
    let ratio = d1 / d2;
    println!("T = {t1:.6e}, T_model − T_direct: {d1:.3e} (ε), {d2:.3e} (ε/2), ratio {ratio:.3}");
    // third order in the fields: halving ε divides the difference by 8
    assert!((ratio - 8.0).abs() < 0.8, "ratio {ratio}");
    assert!(d1.abs() < 1e-3 * t1, "{d1} vs {t1}");
}

#[test]
fn elem_payload_kinetic_energy_second_order_part_is_exact_without_payload_rotation() {
    // With the payload a point mass on the axis (no offset, no inertia) the model's T and the
    // direct T still differ only at third order; the zero-field limit agrees to round-off.
    let mut scene = load_scene("single-link-3d").unwrap();
    {
        let pl = &mut scene.payload_link_mut().unwrap().payload;
        pl.offset = 0.0;
        pl.inertia = [[0.0; 3]; 3];
    }
    let p = scene.payload_link().cloned().unwrap();
    let m = PayloadLinkModel::from_payload_link(&scene, scene.payload_link().unwrap(), Some(11))
        .unwrap();
    let zero = vec![0.0; m.n];
    let (a, b) = (
        kinetic(&m, &zero, &zero, 2.0),
        kinetic_direct(&m, &p, &zero, &zero, 2.0),
    );
    assert!((a - b).abs() < 1e-13 * a, "{a} {b}");
    let q = state(&m, 1e-2, 0.5);
    let v = state(&m, 5e-2, 2.0);
    let q2: Vec<f64> = q.iter().map(|x| 0.5 * x).collect();
    let v2: Vec<f64> = v.iter().map(|x| 0.5 * x).collect();
    let d1 = kinetic(&m, &q, &v, 2.0) - kinetic_direct(&m, &p, &q, &v, 2.0);
    let d2 = kinetic(&m, &q2, &v2, 2.0) - kinetic_direct(&m, &p, &q2, &v2, 2.0);
    assert!((d1 / d2 - 8.0).abs() < 0.8, "{d1} {d2}");
}

#[test]
fn sys_payload_equations_are_lagranges_equations_of_the_kinetic_energy() {
    // d/dt ∂T/∂ż − ∂T/∂z by finite differences of the model's T along a trajectory
    // z(t) = z + tż + ½t²z̈ against the model's inertia terms.
    let m = model("single-link-3d", true);
    let n = m.n;
    let q = state(&m, 0.02, 0.3);
    let v = state(&m, 0.3, 1.7);
    let acc = state(&m, 5.0, 2.9);
    let (rate, thdd) = (1.7, -0.8);
    let traj = |t: f64| {
        let qt: Vec<f64> = (0..n)
            .map(|i| q[i] + t * v[i] + 0.5 * t * t * acc[i])
            .collect();
        let vt: Vec<f64> = (0..n).map(|i| v[i] + t * acc[i]).collect();
        (qt, vt, rate + t * thdd)
    };
    let dv = 1e-3;
    let momentum = |t: f64, i: Option<usize>| {
        let (qt, vt, rt) = traj(t);
        match i {
            Some(i) => {
                let (mut a, mut b) = (vt.clone(), vt.clone());
                a[i] += dv;
                b[i] -= dv;
                (kinetic(&m, &qt, &a, rt) - kinetic(&m, &qt, &b, rt)) / (2.0 * dv)
            }
            None => (kinetic(&m, &qt, &vt, rt + dv) - kinetic(&m, &qt, &vt, rt - dv)) / (2.0 * dv),
        }
    };
    // fourth-order central difference in t (the momenta are polynomials of degree ≤ 5 in t)
    let dt = 1e-3;
    let ddt = |p: &dyn Fn(f64) -> f64| {
        (8.0 * (p(dt) - p(-dt)) - (p(2.0 * dt) - p(-2.0 * dt))) / (12.0 * dt)
    };
    // model side: field equation inertia terms
    let mut f_full = vec![0.0; n];
    let mut f_static = vec![0.0; n];
    m.field_forces(&q, &v, rate, &mut f_full);
    m.field_forces(&q, &v, 0.0, &mut f_static);
    let mut mth = vec![0.0; n];
    m.m_theta(&q, &mut mth);
    let mut mq = vec![0.0; n];
    m.mff.mul_add(&acc, &mut mq);
    let mut scale = 0.0f64;
    let mut worst = 0.0f64;
    for i in 0..n {
        let ddt = ddt(&|t| momentum(t, Some(i)));
        let (mut a, mut b) = (q.clone(), q.clone());
        a[i] += dv;
        b[i] -= dv;
        let dq = (kinetic(&m, &a, &v, rate) - kinetic(&m, &b, &v, rate)) / (2.0 * dv);
        let lagrange = ddt - dq;
        let model_side = mq[i] + mth[i] * thdd - (f_full[i] - f_static[i]);
        scale = scale.max(lagrange.abs());
        worst = worst.max((lagrange - model_side).abs());
    }
    assert!(
        worst < 1e-9 * scale,
        "field equations: {worst:e} of {scale:e}"
    );
    let ddt = ddt(&|t| momentum(t, None));
    let model_theta =
        m.m_thth(&q) * thdd + crate::linalg::dot(&mth, &acc) + m.theta_velocity_terms(&q, &v, rate);
    assert!(
        (ddt - model_theta).abs() < 1e-9 * ddt.abs(),
        "θ equation: {ddt} vs {model_theta}"
    );
}

#[test]
fn elem_payload_elastic_and_gravity_forces_are_the_potential_gradient() {
    let m = model("single-link-3d", true);
    let q = state(&m, 0.01, 0.9);
    let mut f = vec![0.0; m.n];
    m.field_forces(&q, &vec![0.0; m.n], 0.0, &mut f);
    let pot = |q: &[f64]| m.strain(q) + m.gravity_energy(q);
    let d = 1e-6;
    let mut worst = 0.0f64;
    let scale = f.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for i in 0..m.n {
        let (mut a, mut b) = (q.clone(), q.clone());
        a[i] += d;
        b[i] -= d;
        let g = -(pot(&a) - pot(&b)) / (2.0 * d);
        worst = worst.max((g - f[i]).abs());
    }
    assert!(worst < 1e-6 * scale, "{worst:e} of {scale:e}");
}

#[test]
fn elem_payload_step_bounds_are_the_reports_per_field() {
    let scene = load_scene("single-link-3d").unwrap();
    let p = scene.payload_link().cloned().unwrap();
    let m = PayloadLinkModel::from_payload_link(&scene, scene.payload_link().unwrap(), Some(21))
        .unwrap();
    let h = m.h;
    for (f, sigma, station) in m.field_bounds() {
        let report = match f {
            LinkField::Axial => h * (p.mass_per_length() / p.axial_stiffness()).sqrt(),
            LinkField::Torsion => {
                h * (p.density * p.polar_moment() / p.torsional_stiffness()).sqrt()
            }
            _ => h * h * (p.mass_per_length() / (4.0 * p.bending_stiffness())).sqrt(),
        };
        println!(
            "{:?}: σ = {sigma:.4e} at station {station}, report {report:.4e}",
            f
        );
        // the Gershgorin row of the lumped operator is the report's inside the rod, and no
        // station (clamp, free end) binds harder than that
        assert!(
            (sigma - report).abs() <= 1e-12 * report,
            "{f:?}: {sigma} vs {report}"
        );
    }
}
