//! The 3-D payload link (seed 002) by assumed modes: basis, Ritz matrices against the kinematics
//! of docs/single-link-3d.md, generalized forces against the energies, Jacobian, DOF counts,
//! statics against the beam solution, convergence of the frequencies, ledger closure.

// Dense checks index several arrays with one loop variable on purpose.
#![allow(clippy::needless_range_loop)]

use data::scene::{LinkField, PayloadLink};
use data::{
    Backend, BackendError, Basis, Discretization, Scene, Settings, TimeStepping, load_scene,
};
use modal::ModalBackend;
use modal::basis::quadrature::{Quadrature, gauss_legendre_unit};
use modal::integrate::OdeRhs;
use modal::payload_link::basis::{Clamp, FieldBasis};
use modal::payload_link::dynamics::LinkRhs;
use modal::payload_link::model::{
    BasisChoice, LinkModel, RotationForm, field_index, payload_rotation_energy,
};

fn link(scene: &Scene) -> &PayloadLink {
    scene.payload_link().unwrap()
}

fn settings(modes: usize, basis: Basis) -> Settings {
    Settings {
        discretization: Discretization {
            modes: Some(modes),
            basis: Some(basis),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Deterministic pseudo-random numbers in [−1, 1].
fn noise(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

#[test]
fn elem_payload_link_basis_meets_the_clamped_conditions() {
    for clamp in [Clamp::Value, Clamp::ValueAndSlope] {
        for b in [
            FieldBasis::legendre(1.3, 8, clamp),
            FieldBasis::clamped_free(1.3, 8, clamp).unwrap(),
        ] {
            let mut v = vec![0.0; 8];
            b.eval(0.0, 0, &mut v);
            assert!(v.iter().all(|x| x.abs() < 1e-12), "{v:?}");
            if clamp == Clamp::ValueAndSlope {
                b.eval(0.0, 1, &mut v);
                assert!(v.iter().all(|x| x.abs() < 1e-12), "{v:?}");
            }
            // Derivatives against central differences of the values.
            let (x, h) = (0.77, 1e-6);
            let (mut p, mut m, mut d) = (vec![0.0; 8], vec![0.0; 8], vec![0.0; 8]);
            for deriv in 0..2 {
                b.eval(x + h, deriv, &mut p);
                b.eval(x - h, deriv, &mut m);
                b.eval(x, deriv + 1, &mut d);
                for k in 0..8 {
                    let fd = (p[k] - m[k]) / (2.0 * h);
                    assert!(
                        (fd - d[k]).abs() < 1e-6 * (1.0 + d[k].abs()),
                        "{clamp:?} {deriv} {k}"
                    );
                }
            }
        }
    }
}

#[test]
fn elem_payload_link_legendre_strain_gram_is_diagonal() {
    let l = 0.9;
    let quad = Quadrature::composite(l, 8, 10);
    for (clamp, deriv) in [(Clamp::Value, 1), (Clamp::ValueAndSlope, 2)] {
        let b = FieldBasis::legendre(l, 10, clamp);
        let mut g = [[0.0; 10]; 10];
        let mut v = vec![0.0; 10];
        for (&x, &w) in quad.x.iter().zip(&quad.w) {
            b.eval(x, deriv, &mut v);
            for i in 0..10 {
                for j in 0..10 {
                    g[i][j] += w * v[i] * v[j];
                }
            }
        }
        for i in 0..10 {
            for j in 0..10 {
                if i != j {
                    assert!(
                        g[i][j].abs() < 1e-10 * (g[i][i] * g[j][j]).sqrt(),
                        "{i} {j}"
                    );
                }
            }
        }
    }
}

#[test]
fn elem_payload_rotation_form_reproduces_the_energy() {
    let inertia = [
        [1.0e-4, 1.0e-5, 5.0e-6],
        [1.0e-5, 1.5e-4, 2.0e-6],
        [5.0e-6, 2.0e-6, 1.5e-4],
    ];
    let f = RotationForm::of(&inertia);
    for seed in 0..5 {
        let r = noise(seed, 7);
        let w = 3.0 * r[0];
        let z = [r[1], r[2], r[3]];
        let zd = [r[4], r[5], r[6]];
        let mut t = 0.5 * w * w * f.j0;
        for a in 0..3 {
            t += w * f.b[a] * zd[a] + w * w * f.h[a] * z[a];
            for c in 0..3 {
                t += 0.5 * zd[a] * f.m[a][c] * zd[c]
                    + w * z[a] * f.g[a][c] * zd[c]
                    + 0.5 * w * w * z[a] * f.n[a][c] * z[c];
            }
        }
        let direct = payload_rotation_energy(&inertia, w, z, zd);
        assert!(
            (t - direct).abs() < 1e-15 + 1e-12 * direct.abs(),
            "{t} {direct}"
        );
    }
}

// ---- the kinetic energy straight from the kinematics -------------------------------------

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}
fn mat_t_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}
fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}
/// 1 + [a]× + ½[a]×² (the second-order rotation of docs/single-link-3d.md).
fn rot2(a: [f64; 3]) -> [[f64; 3]; 3] {
    let mut r = [[0.0; 3]; 3];
    for j in 0..3 {
        let mut e = [0.0; 3];
        e[j] = 1.0;
        let c1 = cross(a, e);
        let c2 = cross(a, c1);
        for i in 0..3 {
            r[i][j] = e[i] + c1[i] + 0.5 * c2[i];
        }
    }
    r
}

/// (value, slope, rate, slope rate) of each field at x.
fn fields(model: &LinkModel, x: f64, q: &[f64], qd: &[f64]) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    for b in &model.blocks {
        let k = field_index(b.field);
        let n = b.count();
        let (mut v, mut d) = (vec![0.0; n], vec![0.0; n]);
        b.basis.eval(x, 0, &mut v);
        b.basis.eval(x, 1, &mut d);
        let s = &q[b.offset..b.offset + n];
        let sd = &qd[b.offset..b.offset + n];
        let dp = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(x, y)| x * y).sum::<f64>();
        out[k] = [dp(&v, s), dp(&d, s), dp(&v, sd), dp(&d, sd)];
    }
    out
}

/// s(x) and ṡ(x) by a Gauss rule on [0, x].
fn pull_in(model: &LinkModel, x: f64, q: &[f64], qd: &[f64]) -> (f64, f64) {
    let (gx, gw) = gauss_legendre_unit(30);
    let (mut s, mut sd) = (0.0, 0.0);
    for (&g, &w) in gx.iter().zip(&gw) {
        let f = fields(model, g * x, q, qd);
        s += w * x * 0.5 * (f[1][1] * f[1][1] + f[2][1] * f[2][1]);
        sd += w * x * (f[1][1] * f[1][3] + f[2][1] * f[2][3]);
    }
    (s, sd)
}

/// Section rotation R = R_t(β) R_x(φ) and the angular velocity Ω = W e_z + ω at x.
fn section(f: &[[f64; 4]; 4], w: f64) -> ([[f64; 3]; 3], [f64; 3]) {
    let (vs, ws, phi) = (f[1][1], f[2][1], f[3][0]);
    let (vsd, wsd, phid) = (f[1][3], f[2][3], f[3][2]);
    let r = mat_mul(&rot2([0.0, -ws, vs]), &rot2([phi, 0.0, 0.0]));
    let om = [
        phid + 0.5 * (vs * wsd - ws * vsd),
        -wsd + vs * phid,
        w + vsd + ws * phid,
    ];
    (r, om)
}

fn direct_kinetic(link: &PayloadLink, model: &LinkModel, w: f64, q: &[f64], qd: &[f64]) -> f64 {
    let l = link.length;
    let mu = link.mass_per_length();
    let (ri, rj) = (
        link.density * link.second_moment(),
        link.density * link.polar_moment(),
    );
    let quad = Quadrature::composite(l, 8, 10);
    let ez = [0.0, 0.0, 1.0];
    let mut t = 0.5 * link.base_inertia() * w * w;
    for (&x, &wt) in quad.x.iter().zip(&quad.w) {
        let f = fields(model, x, q, qd);
        let (s, sd) = pull_in(model, x, q, qd);
        let r = [x + f[0][0] - s, f[1][0], f[2][0]];
        let rd = [f[0][2] - sd, f[1][2], f[2][2]];
        let vel = {
            let c = cross(ez, r);
            [rd[0] + w * c[0], rd[1] + w * c[1], rd[2] + w * c[2]]
        };
        let (rot, om) = section(&f, w);
        let a = mat_t_vec(&rot, om);
        t += wt * 0.5 * (mu * dot(vel, vel) + rj * a[0] * a[0] + ri * (a[1] * a[1] + a[2] * a[2]));
    }
    // Payload.
    let p = &link.payload;
    let f = fields(model, l, q, qd);
    let (s, sd) = pull_in(model, l, q, qd);
    let (rot, om) = section(&f, w);
    let axis = mat_vec(&rot, [1.0, 0.0, 0.0]);
    let axis_rate = [-(f[1][1] * f[1][3] + f[2][1] * f[2][3]), f[1][3], f[2][3]];
    let rc = [
        l + f[0][0] - s + p.offset * axis[0],
        f[1][0] + p.offset * axis[1],
        f[2][0] + p.offset * axis[2],
    ];
    let rcd = [
        f[0][2] - sd + p.offset * axis_rate[0],
        f[1][2] + p.offset * axis_rate[1],
        f[2][2] + p.offset * axis_rate[2],
    ];
    let c = cross(ez, rc);
    let vc = [rcd[0] + w * c[0], rcd[1] + w * c[1], rcd[2] + w * c[2]];
    let a = mat_t_vec(&rot, om);
    t + 0.5 * p.mass * dot(vc, vc) + 0.5 * dot(a, mat_vec(&p.inertia, a))
}

#[test]
fn sys_payload_link_kinetic_energy_is_the_second_order_truncation_of_the_kinematics() {
    let scene = load_scene("single-link-3d").unwrap();
    let l = link(&scene);
    let model = LinkModel::build(l, 5, BasisChoice::Legendre, 11).unwrap();
    let n = model.n;
    for seed in 1..4 {
        let r = noise(seed, 2 * n + 1);
        let w = 2.0 * r[0];
        let (q1, qd1) = (&r[1..n + 1], &r[n + 1..]);
        let mut diffs = Vec::new();
        let mut second = 0.0;
        for eps in [1e-2, 5e-3] {
            let q: Vec<f64> = q1.iter().map(|x| eps * x).collect();
            let qd: Vec<f64> = qd1.iter().map(|x| eps * x).collect();
            let tm = model.kinetic(w, &q, &qd);
            let td = direct_kinetic(l, &model, w, &q, &qd);
            if eps == 1e-2 {
                second = (tm - model.kinetic(w, &vec![0.0; n], &vec![0.0; n])).abs();
            }
            diffs.push((td - tm).abs());
        }
        // The remainder is of third order: halving the amplitude divides it by about 8 (a wrong
        // second-order term would leave a remainder that only quarters).
        assert!(
            diffs[0] < 0.05 * second,
            "seed {seed}: {diffs:?} vs {second}"
        );
        assert!(diffs[1] < diffs[0] / 6.0, "seed {seed}: {diffs:?}");
    }
}

#[test]
fn sys_payload_link_strain_and_gravity_match_direct_quadrature() {
    let scene = load_scene("single-link-3d").unwrap();
    let l = link(&scene);
    let model = LinkModel::build(l, 6, BasisChoice::Legendre, 11).unwrap();
    let q = noise(9, model.n);
    let quad = Quadrature::composite(l.length, 8, 10);
    let (mut strain, mut grav) = (0.0, 0.0);
    let g = l.gravity.unwrap();
    for (&x, &wt) in quad.x.iter().zip(&quad.w) {
        let mut d = [0.0; 4];
        let mut w = 0.0;
        for b in &model.blocks {
            let nb = b.count();
            let mut v = vec![0.0; nb];
            let deriv = match b.field {
                LinkField::Horizontal | LinkField::Vertical => 2,
                _ => 1,
            };
            b.basis.eval(x, deriv, &mut v);
            let val: f64 = v
                .iter()
                .zip(&q[b.offset..b.offset + nb])
                .map(|(a, b)| a * b)
                .sum();
            d[field_index(b.field)] = val;
            if b.field == LinkField::Vertical {
                b.basis.eval(x, 0, &mut v);
                w = v
                    .iter()
                    .zip(&q[b.offset..b.offset + nb])
                    .map(|(a, b)| a * b)
                    .sum();
            }
        }
        strain += wt
            * 0.5
            * (l.axial_stiffness() * d[0] * d[0]
                + l.bending_stiffness() * (d[1] * d[1] + d[2] * d[2])
                + l.torsional_stiffness() * d[3] * d[3]);
        grav += wt * g * l.mass_per_length() * w;
    }
    let f = fields(&model, l.length, &q, &q);
    grav += g * l.payload.mass * (f[2][0] + l.payload.offset * f[2][1]);
    assert!((model.strain(&q) - strain).abs() < 1e-12 * strain.abs());
    assert!((model.gravity_energy(&q) - grav).abs() < 1e-12 * grav.abs());
}

/// Central-difference gradient of a function of n variables.
fn gradient(n: usize, x: &[f64], h: f64, f: impl Fn(&[f64]) -> f64) -> Vec<f64> {
    let mut y = x.to_vec();
    (0..n)
        .map(|i| {
            y[i] = x[i] + h;
            let p = f(&y);
            y[i] = x[i] - h;
            let m = f(&y);
            y[i] = x[i];
            (p - m) / (2.0 * h)
        })
        .collect()
}

#[test]
fn sys_payload_link_field_forces_are_lagranges_equations_of_the_energies() {
    // Constant base rate with products of inertia and gravity: M q̈ must equal
    // ∂T/∂q − D_q(∂T/∂q̇)[q̇] − ∂V/∂q − C q̇ (θ̈ = 0), every term by differences of the energies.
    let mut scene = load_scene("single-link-3d-constant-rate").unwrap();
    scene.payload_link_mut().unwrap().payload.inertia = [
        [1.0e-4, 1.0e-5, 5.0e-6],
        [1.0e-5, 1.5e-4, 2.0e-6],
        [5.0e-6, 2.0e-6, 1.5e-4],
    ];
    let l = link(&scene).clone();
    let model = LinkModel::build(&l, 5, BasisChoice::Legendre, 11).unwrap();
    let n = model.n;
    let w = model.base.prescribed_state(0.0).1;
    let r = noise(21, 2 * n);
    let q: Vec<f64> = r[..n].iter().map(|x| 1e-3 * x).collect();
    let qd: Vec<f64> = r[n..].iter().map(|x| 1e-2 * x).collect();
    let mut rhs = LinkRhs::new(model.clone()).unwrap();
    let mut y = rhs.initial_state(&q);
    y[n..2 * n].copy_from_slice(&qd);
    let mut dy = vec![0.0; y.len()];
    rhs.eval(0.3, &y, &mut dy);
    let mut f_rhs = vec![0.0; n];
    for i in 0..n {
        f_rhs[i] = (0..n).map(|j| model.mass[i * n + j] * dy[n + j]).sum();
    }
    let h = 1e-6;
    let dt_dq = gradient(n, &q, h, |x| model.kinetic(w, x, &qd));
    let dv_dq = gradient(n, &q, h, |x| model.strain(x) + model.gravity_energy(x));
    let p_of = |x: &[f64]| gradient(n, &qd, h, |v| model.kinetic(w, x, v));
    let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
    let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
    let (pp, pm) = (p_of(&qp), p_of(&qm));
    let c = model.damping.as_ref().unwrap();
    let scale = f_rhs.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for i in 0..n {
        let cq: f64 = (0..n).map(|j| c[i * n + j] * qd[j]).sum();
        let expected = dt_dq[i] - (pp[i] - pm[i]) / (2.0 * h) - dv_dq[i] - cq;
        assert!(
            (expected - f_rhs[i]).abs() < 1e-6 * scale,
            "{i}: {expected} vs {}",
            f_rhs[i]
        );
    }
}

#[test]
fn sys_payload_link_analytic_jacobian_matches_differences() {
    for name in ["single-link-3d", "single-link-3d-constant-rate"] {
        let scene = load_scene(name).unwrap();
        let model = LinkModel::build(link(&scene), 4, BasisChoice::Legendre, 11).unwrap();
        let mut rhs = LinkRhs::new(model).unwrap();
        let dim = rhs.dim();
        let nd = rhs.nd;
        let r = noise(5, dim);
        let mut y: Vec<f64> = r.iter().map(|x| 1e-3 * x).collect();
        if rhs.model.base.free {
            y[nd] = 1.5;
        }
        let mut jac = vec![0.0; dim * dim];
        assert!(rhs.jacobian(0.2, &y, &mut jac));
        let (mut fp, mut fm) = (vec![0.0; dim], vec![0.0; dim]);
        for c in 0..2 * nd {
            // Accelerations of 1e5 m/s² at these amplitudes: a step large enough to keep
            // their round-off (1e-16 · 1e5 / h) below the tolerance.
            let h = 1e-5 * (1.0 + y[c].abs());
            let y0 = y[c];
            y[c] = y0 + h;
            rhs.eval(0.2, &y, &mut fp);
            y[c] = y0 - h;
            rhs.eval(0.2, &y, &mut fm);
            y[c] = y0;
            let col_scale = (0..2 * nd)
                .map(|i| jac[c * dim + i].abs())
                .fold(1e-300, f64::max);
            for i in 0..2 * nd {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (fd - jac[c * dim + i]).abs() < 1e-5 * col_scale,
                    "{name} ({i}, {c}): {fd} vs {}",
                    jac[c * dim + i]
                );
            }
        }
    }
}

#[test]
fn sys_payload_link_builds_only_what_the_scene_switches_on() {
    let scene = load_scene("single-link-3d").unwrap();
    let disc = Discretization::default();
    let plan = ModalBackend.dof_plan(&scene, &disc).unwrap();
    assert_eq!(plan.total(), 1 + 4 * 6);
    let cr = load_scene("single-link-3d-constant-rate").unwrap();
    assert_eq!(ModalBackend.dof_plan(&cr, &disc).unwrap().total(), 4 * 6);

    let mut s = scene.clone();
    {
        let l = s.payload_link_mut().unwrap();
        l.fields = vec![LinkField::Vertical, LinkField::Torsion];
        l.kelvin_voigt.as_mut().unwrap().vertical = None;
        l.gravity = None;
    }
    let d4 = Discretization {
        modes: Some(4),
        ..Default::default()
    };
    assert_eq!(ModalBackend.dof_plan(&s, &d4).unwrap().total(), 1 + 2 * 4);
    let m = LinkModel::build(link(&s), 4, BasisChoice::Legendre, 11).unwrap();
    assert_eq!(m.n, 8);
    assert!(m.block(LinkField::Axial).is_none() && m.block(LinkField::Horizontal).is_none());
    assert!(m.gravity.is_none());
    assert_eq!(m.damped.len(), 1);
    assert_eq!(m.damped[0].field, LinkField::Torsion);

    let stiff = load_scene("single-link-3d-stiff").unwrap();
    let m = LinkModel::build(link(&stiff), 6, BasisChoice::Legendre, 11).unwrap();
    assert!(m.damping.is_none() && m.damped.is_empty() && m.gravity.is_none());

    // The run writes the channels of the carried fields only (no zeros for u and v).
    let mut settings = Settings {
        discretization: d4,
        ..Default::default()
    };
    settings.time.t_end = Some(0.01);
    let run = ModalBackend.simulate(&s, &settings).unwrap();
    let written: Vec<&str> = run
        .observables
        .channels
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    let stations = s.simulation.field_stations.max(2);
    let expected =
        data::channel::payload_link(&[LinkField::Vertical, LinkField::Torsion], stations);
    let expected: Vec<&str> = expected.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(written, expected);
    for absent in [
        "link1.tip_axial",
        "link1.tip_deflection",
        "link1.tip_slope_v",
        "link1.v@0",
    ] {
        assert!(run.observables.get(absent).is_none(), "{absent}");
    }
    assert!(run.observables.get("link1.tip_w").is_some());
}

#[test]
fn sys_payload_link_refuses_what_it_does_not_offer() {
    let scene = load_scene("single-link-3d").unwrap();
    for (modes, basis) in [
        (0, Basis::Poly),
        (6, Basis::TipMass),
        (6, Basis::FreeFree),
        (500, Basis::Poly),
    ] {
        let e = ModalBackend
            .modes(&scene, &settings(modes, basis), 6)
            .unwrap_err();
        assert!(matches!(e, BackendError::InvalidSettings { .. }), "{e}");
    }
    let mut s = settings(6, Basis::Poly);
    s.time = TimeStepping {
        method: Some(data::Method::GeneralizedAlpha),
        ..Default::default()
    };
    let e = ModalBackend.simulate(&scene, &s).unwrap_err();
    assert!(matches!(e, BackendError::InvalidSettings { .. }), "{e}");
}

#[test]
fn sys_payload_link_static_sag_is_the_beam_solution() {
    // Cantilever under its weight q = ρAg, the payload weight P = m g at the tip and the offset
    // moment P c: w(L) = −(PL³/3 + PcL²/2 + qL⁴/8)/EI, w′(L) = −(PL²/2 + PcL + qL³/6)/EI. The
    // solution is a quartic, inside the span of the Legendre basis from 3 functions on.
    for name in ["single-link-3d", "single-link-3d-soft-sag"] {
        let scene = load_scene(name).unwrap();
        let l = link(&scene);
        let g = l.gravity.unwrap();
        let (len, ei) = (l.length, l.bending_stiffness());
        let p = l.payload.mass * g;
        let q = l.mass_per_length() * g;
        let c = l.payload.offset;
        let w_l = -(p * len.powi(3) / 3.0 + p * c * len * len / 2.0 + q * len.powi(4) / 8.0) / ei;
        let s_l = -(p * len * len / 2.0 + p * c * len + q * len.powi(3) / 6.0) / ei;
        for modes in [3, 6] {
            let r = ModalBackend
                .statics(&scene, &settings(modes, Basis::Poly))
                .unwrap();
            assert!(
                (r.tip_deflection - w_l).abs() < 1e-10 * w_l.abs(),
                "{name} {modes}"
            );
            assert!(
                (r.tip_rotation - s_l).abs() < 1e-10 * s_l.abs(),
                "{name} {modes}"
            );
        }
    }
}

fn freqs(scene: &Scene, modes: usize, basis: Basis, count: usize) -> Vec<f64> {
    ModalBackend
        .modes(scene, &settings(modes, basis), count)
        .unwrap()
        .frequencies_hz
}

/// Frequencies of the symmetric pencil (K, M) without the gyroscopic coupling: the Rayleigh–Ritz
/// problem whose nested spaces give upper bounds (`modes` of a spinning link adds the
/// gyroscopic terms, which are not variational bounds).
fn pencil_freqs(scene: &Scene, modes: usize, count: usize) -> Vec<f64> {
    let s = settings(modes, Basis::Poly);
    let set = modal::payload_link::set_up(
        scene,
        scene.payload_link().unwrap(),
        &s.discretization.modal().unwrap(),
    )
    .unwrap();
    let (k, m, _) = modal::payload_link::analysis::linear_pencil(&set.model);
    let (lambda, _) = modal::modes::generalized_eigen(&k, &m).unwrap();
    lambda
        .iter()
        .take(count)
        .map(|l| l.sqrt() / std::f64::consts::TAU)
        .collect()
}

#[test]
fn conv_payload_link_frequencies_converge_from_above() {
    let scene = load_scene("single-link-3d-constant-rate").unwrap();
    let count = 8;
    let reference = pencil_freqs(&scene, 16, count);
    let mut prev: Option<Vec<f64>> = None;
    for modes in [4, 6, 8, 10, 12] {
        let f = pencil_freqs(&scene, modes, count);
        if let Some(p) = &prev {
            for k in 0..count {
                // Nested Ritz spaces: upper bounds that never rise.
                assert!(
                    f[k] <= p[k] * (1.0 + 1e-10),
                    "{modes} {k}: {} > {}",
                    f[k],
                    p[k]
                );
            }
        }
        if modes >= 10 {
            for k in 0..4 {
                assert!(
                    (f[k] - reference[k]).abs() < 1e-7 * reference[k],
                    "{modes} {k}"
                );
            }
        }
        prev = Some(f);
    }
    // Clamped-free functions carry no tip load: algebraic convergence, with Richardson's
    // extrapolation from the observed order closer to the converged polynomial value than the
    // finest clamped-free result.
    let cf: Vec<Vec<f64>> = [4, 8, 16]
        .iter()
        .map(|&m| freqs(&scene, m, Basis::ClampedFree, 4))
        .collect();
    for k in 0..4 {
        let (a, b, c) = (cf[0][k], cf[1][k], cf[2][k]);
        let order = ((a - b) / (b - c)).log2();
        let richardson = c - (b - c) / (2f64.powf(order) - 1.0);
        assert!(order > 1.0, "mode {k}: observed order {order}");
        assert!(
            (richardson - reference[k]).abs() < (c - reference[k]).abs(),
            "mode {k}: {richardson} {c} {}",
            reference[k]
        );
        // The default basis at 6 functions beats the clamped-free one at 16.
        let poly6 = freqs(&scene, 6, Basis::Poly, 4)[k];
        assert!(
            (poly6 - reference[k]).abs() < (c - reference[k]).abs(),
            "mode {k}"
        );
    }
}

fn run(name: &str, t_end: f64) -> data::RunResult {
    let scene = load_scene(name).unwrap();
    let mut s = Settings::default();
    s.time.t_end = Some(t_end);
    let r = ModalBackend.simulate(&scene, &s).unwrap();
    assert!(
        matches!(r.verdict, data::StabilityVerdict::Completed),
        "{name}: {:?}",
        r.verdict
    );
    r
}

fn names(terms: &[data::EnergyTerm]) -> Vec<&str> {
    terms.iter().map(|t| t.name.as_str()).collect()
}

#[test]
fn dyn_payload_link_ledger_closes_damped_with_torque() {
    // Through the first torque switch at 0.5 s.
    let r = run("single-link-3d", 0.6);
    let l = &r.ledger;
    assert_eq!(names(&l.stored), ["kinetic", "strain", "gravity"]);
    assert_eq!(names(&l.inputs), ["applied_torque"]);
    assert_eq!(
        names(&l.dissipation),
        [
            "joint_damper",
            "kelvin_voigt_axial",
            "kelvin_voigt_horizontal",
            "kelvin_voigt_vertical",
            "kelvin_voigt_torsion"
        ]
    );
    assert!(l.relative_closure() < 1e-5, "{}", l.relative_closure());
    // Started from the static sag: the vertical tip deflection stays at the sag while the base
    // turns slowly (the payload's products of inertia and offset move it only a little).
    let w = r.observables.get("link1.tip_w").unwrap();
    assert!((w.values[0] - w.values[w.values.len() - 1]).abs() < 0.05 * w.values[0].abs());
}

#[test]
fn dyn_payload_link_ledger_closes_undamped_and_prescribed() {
    let r = run("single-link-3d-stiff", 0.3);
    assert!(
        r.ledger
            .dissipation
            .iter()
            .all(|t| t.name == "joint_damper")
    );
    assert!(
        r.ledger.relative_closure() < 1e-5,
        "{}",
        r.ledger.relative_closure()
    );
    let r = run("single-link-3d-constant-rate", 0.3);
    assert_eq!(names(&r.ledger.inputs), ["prescribed_motion"]);
    assert!(
        r.ledger.relative_closure() < 1e-5,
        "{}",
        r.ledger.relative_closure()
    );
}

/// Largest |entry| of a matrix between the coordinates of the pair (u, v) and of (w, φ).
fn cross_pair(model: &LinkModel, m: &[f64]) -> f64 {
    let n = model.n;
    let in_plane = |i: usize| {
        model.blocks.iter().any(|b| {
            matches!(b.field, LinkField::Axial | LinkField::Horizontal)
                && (b.offset..b.offset + b.count()).contains(&i)
        })
    };
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            if in_plane(i) != in_plane(j) {
                worst = worst.max(m[i * n + j].abs());
            }
        }
    }
    worst
}

#[test]
fn sys_payload_link_fields_split_into_u_v_and_w_phi_with_a_diagonal_payload_inertia() {
    // Seed 002's decoupling: with I_p diagonal in the tip axes every matrix of the Lagrangian is
    // block diagonal over (u, v) and (w, φ), exactly; gravity loads only w. The products of
    // inertia I₅ (x–z) and I₆ (y–z) couple v′_L with φ̇_L and ẇ′_L through the payload's
    // rotational energy (tip boundary terms), I₄ (x–y) only w with φ.
    let scene = load_scene("single-link-3d-constant-rate").unwrap();
    let model = LinkModel::build(link(&scene), 6, BasisChoice::Legendre, 11).unwrap();
    for m in [
        &model.mass,
        &model.stiffness,
        &model.gyro,
        &model.centrifugal,
        model.damping.as_ref().unwrap(),
    ] {
        assert_eq!(cross_pair(&model, m), 0.0);
    }
    let fg = model.gravity.as_ref().unwrap();
    for b in &model.blocks {
        if matches!(b.field, LinkField::Axial | LinkField::Horizontal) {
            assert!(fg[b.offset..b.offset + b.count()].iter().all(|f| *f == 0.0));
        }
    }
    let mut products = scene.clone();
    products.payload_link_mut().unwrap().payload.inertia = [
        [1.0e-4, 0.0, 5.0e-6],
        [0.0, 1.5e-4, 0.0],
        [5.0e-6, 0.0, 1.5e-4],
    ];
    let coupled = LinkModel::build(link(&products), 6, BasisChoice::Legendre, 11).unwrap();
    assert!(cross_pair(&coupled, &coupled.mass) > 0.0);
}

#[test]
fn dyn_payload_link_gravity_does_not_move_v_at_constant_rate_with_diagonal_inertia() {
    // A fixed-step run (the same steps with and without gravity): the horizontal history must
    // not see gravity at all, while the vertical one does.
    let scene = load_scene("single-link-3d-constant-rate").unwrap();
    let mut no_gravity = scene.clone();
    no_gravity.payload_link_mut().unwrap().gravity = None;
    let s = Settings {
        time: TimeStepping {
            t_end: Some(0.2),
            method: Some("trapezoid".parse().expect("a method name")),
            dt: Some(2e-4),
            ..Default::default()
        },
        ..Default::default()
    };
    let a = ModalBackend.simulate(&scene, &s).unwrap();
    let b = ModalBackend.simulate(&no_gravity, &s).unwrap();
    let v = |r: &data::RunResult| {
        r.observables
            .get("link1.tip_deflection")
            .unwrap()
            .values
            .clone()
    };
    let w = |r: &data::RunResult| r.observables.get("link1.tip_w").unwrap().values.clone();
    let (va, vb) = (v(&a), v(&b));
    let dv = va
        .iter()
        .zip(&vb)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let vmax = va.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(vmax > 0.0, "the rotation must excite v");
    assert!(dv <= 1e-12 * vmax, "{dv} vs {vmax}");
    let wa = w(&a);
    assert!(wa.iter().any(|x| x.abs() > 1e-4));
    assert!(w(&b).iter().all(|x| x.abs() < 1e-12));
}

#[test]
fn sys_payload_link_gyroscopic_frequencies_reduce_to_the_pencil_at_rest() {
    // At Ω = 0 the gyroscopic analysis is the plain pencil; at the scene's rate (1 rev/s) the
    // Coriolis coupling (u–v, w–φ) moves the first ten frequencies by at most 1.7e-6 (the first
    // in-plane mode, through its coupling with the stretch).
    let scene = load_scene("single-link-3d-constant-rate").unwrap();
    let s = settings(6, Basis::Poly);
    let mut at_rest = scene.clone();
    at_rest.payload_link_mut().unwrap().base.prescribed =
        Some(data::scene::PrescribedMotion::ConstantRate { rate: 0.0 });
    let plain = ModalBackend.modes(&at_rest, &s, 10).unwrap().frequencies_hz;
    let gyro = modal::payload_link::gyroscopic_frequencies(
        &at_rest,
        at_rest.payload_link().unwrap(),
        &s.modal().unwrap(),
        10,
    )
    .unwrap();
    for (p, g) in plain.iter().zip(&gyro) {
        assert!((p - g).abs() < 1e-9 * p, "{p} {g}");
    }
    // At the scene's rate `modes` keeps the coupling; the symmetric pencil drops it.
    let set = modal::payload_link::set_up(
        &scene,
        scene.payload_link().unwrap(),
        &s.discretization.modal().unwrap(),
    )
    .unwrap();
    let (k, m, _) = modal::payload_link::analysis::linear_pencil(&set.model);
    let (lambda, _) = modal::modes::generalized_eigen(&k, &m).unwrap();
    let plain: Vec<f64> = lambda
        .iter()
        .take(10)
        .map(|l| l.sqrt() / std::f64::consts::TAU)
        .collect();
    let gyro = modal::payload_link::gyroscopic_frequencies(
        &scene,
        scene.payload_link().unwrap(),
        &s.modal().unwrap(),
        10,
    )
    .unwrap();
    let reported = ModalBackend.modes(&scene, &s, 10).unwrap().frequencies_hz;
    let mut moved = 0.0f64;
    for ((p, g), r) in plain.iter().zip(&gyro).zip(&reported) {
        assert!((p - g).abs() < 1e-5 * p, "{p} {g}");
        assert!(
            (g - r).abs() <= 1e-12 * g,
            "modes reports {r}, gyroscopic {g}"
        );
        moved = moved.max((p - g).abs() / p);
    }
    assert!(moved > 1e-8, "the coupling moves no frequency: {moved:e}");
}

/// The undamped payload link's default, the exponential method at T₁/128: its oscillators (the
/// undeformed link's M and K) are constant, so every mode, the stiff axial ones included, is
/// carried exactly with one diagonalization, and the hub follows Dormand–Prince (rtol 1e-9,
/// bound by the axial modes' stability: 2e5 steps for the 0.2 s) far inside the trapezoidal
/// rule's error at the same step (measured: 1e-12 rad against 3.8e-6).
#[test]
fn dyn_payload_link_exponential_default_follows_the_resolved_method_on_the_stiff_link() {
    let scene = load_scene("single-link-3d-stiff").unwrap();
    let settings = |method: Option<&str>, rtol: Option<f64>| Settings {
        time: TimeStepping {
            t_end: Some(0.2),
            method: method.map(|m| m.parse().expect("a method name")),
            rtol,
            atol: rtol.map(|r| r * 1e-2),
            ..Default::default()
        },
        ..Default::default()
    };
    let angle = |s: &Settings| {
        let r = ModalBackend.simulate(&scene, s).unwrap();
        assert_eq!(r.verdict, data::StabilityVerdict::Completed);
        let values = r.observables.get("joint1.angle").unwrap().values.clone();
        (values, r.cost.factorizations, r.cost.steps)
    };
    let (reference, _, _) = angle(&settings(Some("dopri5"), Some(1e-9)));
    let distance = |x: &[f64]| {
        x.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let (default, diagonalizations, steps) = angle(&settings(None, None));
    let (trapezoid, _, _) = angle(&settings(Some("trapezoid"), None));
    let (d_default, d_trapezoid) = (distance(&default), distance(&trapezoid));
    println!(
        "exponential {d_default:.3e} rad ({diagonalizations} diagonalizations, {steps} steps), trapezoid {d_trapezoid:.3e}"
    );
    // One for the steps of T₁/128 and at most one for a last step shortened onto t_end.
    assert!(diagonalizations <= 2, "{diagonalizations}");
    assert!(d_default < 1e-8, "{d_default:e}");
    assert!(
        d_default < 1e-3 * d_trapezoid,
        "{d_default:e} vs {d_trapezoid:e}"
    );
}
