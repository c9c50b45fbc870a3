//! The 3-D payload link (seed 002) at the element and system layers: the truncated kinetic energy
//! of the assembled operators against a direct evaluation of the kinematics of
//! docs/single-link-3d.md, the equations of motion against finite differences of the discrete
//! energies, the analytic Newton matrix against finite differences of the residual, the DOFs and
//! ledger terms built per scene, and the gravity sag against the cantilever formula.

// Energies, gradients and residual rows are indexed by the same generalized coordinate.
#![allow(clippy::needless_range_loop)]

use data::scene::{LinkField, PayloadLink};
use data::{Backend, Discretization, Scene, Settings};
use fem::FemBackend;
use fem::element::beam3d::{bending_element, rows_at};
use fem::element::quadrature::gauss01;
use fem::payload_link::model::Model;
use fem::payload_link::system::LinkSystem;
use fem::system::{NewtonCoefficients, System};

/// The implicit midpoint rule's residual R(q̄, v̄, ā, t₀ + h/2) and its dense Newton matrix
/// S = M + (h/2)C + (h²/4)K of a step of length h from (t₀, d, ḋ, θ, θ̇) at the midpoint
/// acceleration (a_d, a_θ): v̄ = v₀ + (h/2)ā, q̄ = q₀ + (h/2)v̄ (a prescribed base has no θ
/// unknown: its law gives θ at t₀ + h/2).
#[allow(clippy::too_many_arguments)]
fn residual_and_newton(
    sys: &mut LinkSystem,
    t0: f64,
    h: f64,
    (d, dd): (&[f64], &[f64]),
    (theta, rate): (f64, f64),
    a: &[f64],
    a_theta: f64,
) -> (Vec<f64>, faer::Mat<f64>) {
    let mut q0 = d.to_vec();
    let mut v0 = dd.to_vec();
    let mut acc = a.to_vec();
    if sys.free_base() {
        q0.push(theta);
        v0.push(rate);
        acc.push(a_theta);
    }
    let nq = q0.len();
    let vbar: Vec<f64> = (0..nq).map(|i| v0[i] + 0.5 * h * acc[i]).collect();
    let qbar: Vec<f64> = (0..nq).map(|i| q0[i] + 0.5 * h * vbar[i]).collect();
    let mut res = vec![0.0; nq];
    sys.residual(t0 + 0.5 * h, &qbar, &vbar, &acc, &mut res);
    let mut s = sys.new_matrix();
    let c = NewtonCoefficients {
        c_a: 1.0,
        c_v: 0.5 * h,
        c_q: 0.25 * h * h,
    };
    sys.newton_matrix(&qbar, c, &mut s);
    let jac = faer::Mat::from_fn(nq, nq, |i, j| s.get(i, j));
    (res, jac)
}

fn scene(name: &str) -> Scene {
    data::load_scene(name).expect("catalog scene")
}

fn link(sc: &Scene) -> PayloadLink {
    sc.payload_link().cloned().expect("payload link")
}

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn skew(b: [f64; 3]) -> M3 {
    [[0.0, -b[2], b[1]], [b[2], 0.0, -b[0]], [-b[1], b[0], 0.0]]
}

/// 1 + B + ½B² for B = [b]×.
fn second_order_rotation(b: [f64; 3]) -> M3 {
    let s = skew(b);
    let s2 = mul(&s, &s);
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = f64::from(u8::from(i == j)) + s[i][j] + 0.5 * s2[i][j];
        }
    }
    r
}

/// ½ΩᵀR I RᵀΩ with R = R_t(0, −w′, v′) R_x(φ), Ω = θ̇e_z + ω (docs/single-link-3d.md).
fn rotational(i_body: &M3, vs: f64, ws: f64, phi: f64, rates: [f64; 3], theta_dot: f64) -> f64 {
    let [vsd, wsd, phid] = rates;
    let rt = second_order_rotation([0.0, -ws, vs]);
    let rx = second_order_rotation([phi, 0.0, 0.0]);
    let r = mul(&rt, &rx);
    let omega = [
        phid + 0.5 * (vs * wsd - ws * vsd),
        -wsd + vs * phid,
        vsd + ws * phid + theta_dot,
    ];
    // body = Rᵀ Ω
    let body: Vec<f64> = (0..3)
        .map(|j| (0..3).map(|i| r[i][j] * omega[i]).sum())
        .collect();
    let mut t = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            t += 0.5 * body[i] * i_body[i][j] * body[j];
        }
    }
    t
}

/// ½m|ṗ + θ̇e_z × p|² for a point at p with relative velocity ṗ (turning-frame components).
fn translational(m: f64, p: [f64; 3], pd: [f64; 3], theta_dot: f64) -> f64 {
    let v = [pd[0] - theta_dot * p[1], pd[1] + theta_dot * p[0], pd[2]];
    0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
}

/// Kinetic energy of the rod and payload evaluated from the kinematics, without truncation of
/// the products (foreshortening s(x) integrated from the root at every quadrature point).
fn direct_kinetic(l: &PayloadLink, md: &Model, d: &[f64], dd: &[f64], theta_dot: f64) -> f64 {
    let (pts, wts) = gauss01(4);
    let h = md.h;
    let rho_a = l.mass_per_length();
    let i_sec = [
        [l.density * l.polar_moment(), 0.0, 0.0],
        [0.0, l.density * l.second_moment(), 0.0],
        [0.0, 0.0, l.density * l.second_moment()],
    ];
    // s and ṡ at x within element e at ξ: nodal accumulation plus a sub-quadrature.
    let fs = |e: usize, xi: f64| -> (f64, f64) {
        let (mut s, mut sd) = (0.0, 0.0);
        for (k, span) in (0..e).map(|k| (k, 1.0)).chain(std::iter::once((e, xi))) {
            for (&z, &wz) in pts.iter().zip(wts) {
                let r = rows_at(&md.layout, bending_element(), k, h, z * span);
                let (vs, ws) = (r.dv.dot(d), r.dw.dot(d));
                let (vsd, wsd) = (r.dv.dot(dd), r.dw.dot(dd));
                s += 0.5 * (vs * vs + ws * ws) * wz * span * h;
                sd += (vs * vsd + ws * wsd) * wz * span * h;
            }
        }
        (s, sd)
    };
    let mut t = 0.0;
    for e in 0..md.n_el {
        for (&xi, &wq) in pts.iter().zip(wts) {
            let x = (e as f64 + xi) * h;
            let wt = wq * h;
            let r = rows_at(&md.layout, bending_element(), e, h, xi);
            let (s, sd) = fs(e, xi);
            let p = [x + r.u.dot(d) - s, r.v.dot(d), r.w.dot(d)];
            let pd = [r.u.dot(dd) - sd, r.v.dot(dd), r.w.dot(dd)];
            t += translational(rho_a * wt, p, pd, theta_dot);
            let ib = i_sec.map(|row| row.map(|v| v * wt));
            t += rotational(
                &ib,
                r.dv.dot(d),
                r.dw.dot(d),
                r.phi.dot(d),
                [r.dv.dot(dd), r.dw.dot(dd), r.phi.dot(dd)],
                theta_dot,
            );
        }
    }
    let tip = &md.tip;
    let c = l.payload.offset;
    let (s_l, sd_l) = fs(md.n_el - 1, 1.0);
    let (vs, ws) = (tip.v_slope.dot(d), tip.w_slope.dot(d));
    let (vsd, wsd) = (tip.v_slope.dot(dd), tip.w_slope.dot(dd));
    let p = [
        l.length + tip.u.dot(d) - s_l + c * (1.0 - 0.5 * (vs * vs + ws * ws)),
        tip.v.dot(d) + c * vs,
        tip.w.dot(d) + c * ws,
    ];
    let pd = [
        tip.u.dot(dd) - sd_l - c * (vs * vsd + ws * wsd),
        tip.v.dot(dd) + c * vsd,
        tip.w.dot(dd) + c * wsd,
    ];
    t += translational(l.payload.mass, p, pd, theta_dot);
    t += rotational(
        &l.payload.inertia,
        vs,
        ws,
        tip.phi.dot(d),
        [vsd, wsd, tip.phi.dot(dd)],
        theta_dot,
    );
    t
}

/// A smooth deterministic field state of amplitude ε (slopes and twist of order ε).
fn state(md: &Model, eps: f64) -> (Vec<f64>, Vec<f64>) {
    let d = (0..md.n)
        .map(|i| eps * (0.7 * i as f64 + 0.3).sin())
        .collect();
    let dd = (0..md.n)
        .map(|i| eps * 3.0 * (1.3 * i as f64 + 0.1).cos())
        .collect();
    (d, dd)
}

#[test]
fn elem_payload_kinetic_energy_is_the_second_order_truncation_of_the_kinematics() {
    for name in ["single-link-3d", "single-link-3d-constant-rate"] {
        let l = link(&scene(name));
        let md = Model::assemble(&l, 4).unwrap();
        let theta_dot = 2.5;
        let defect = |eps: f64| {
            let (d, dd) = state(&md, eps);
            direct_kinetic(&l, &md, &d, &dd, theta_dot) - md.kinetic(&d, theta_dot, &dd)
        };
        // Zero fields: both are ½J₀θ̇² (rod, sections and payload as a rigid body).
        let z = vec![0.0; md.n];
        let t0 = md.kinetic(&z, theta_dot, &z);
        assert!((direct_kinetic(&l, &md, &z, &z, theta_dot) - t0).abs() < 1e-13 * t0);
        // The truncation drops only terms of third and higher order. The defect is a polynomial
        // in ε: fit c₂ε² + c₃ε³ + c₄ε⁴ + c₅ε⁵ through four amplitudes and require c₂ (a missing
        // or wrong second-order term) to vanish against the energy's field-dependent part at
        // unit amplitude (measured |c₂| ≈ 5e-9 against 167: the ε⁶ remainder and round-off/ε²;
        // a 0.1 % error in the payload's −I₃θ̇²φ² term alone moves c₂ by 5e-7).
        let eps: Vec<f64> = (0..4).map(|k| 4e-3 / f64::from(1u32 << k)).collect();
        let mut a = faer::Mat::<f64>::zeros(4, 4);
        let mut b = faer::Mat::<f64>::zeros(4, 1);
        for (k, &e) in eps.iter().enumerate() {
            for p in 0..4 {
                a[(k, p)] = e.powi(p as i32 + 2);
            }
            b[(k, 0)] = defect(e);
        }
        use faer::prelude::Solve;
        let c = a.partial_piv_lu().solve(&b);
        let (d, dd) = state(&md, 1.0);
        let t2 = md.kinetic(&d, theta_dot, &dd) - t0;
        assert!(
            c[(0, 0)].abs() < 1e-9 * t2.abs(),
            "{name}: second-order defect {:.3e} against {t2:.3e} (c₃ = {:.3e})",
            c[(0, 0)],
            c[(1, 0)]
        );
    }
}

/// Lagrange's equations from finite differences of T, V and the Rayleigh function at the step
/// midpoint, against the stepper's residual.
fn lagrange_check(name: &str) {
    let sc = scene(name);
    let l = link(&sc);
    let md = Model::assemble(&l, 4).unwrap();
    let n = md.n;
    let free = md.free_base();
    let (d, dd) = state(&md, 0.01);
    let (theta0, rate0) = (0.3, 2.0);
    let h = 1e-3;
    let a: Vec<f64> = (0..n).map(|i| 50.0 * (0.9 * i as f64).sin()).collect();
    let a_theta = if free { 1.7 } else { 0.0 };
    let t0 = 0.2;
    let mut sys = LinkSystem::new(md.clone());
    let (res, _) = residual_and_newton(&mut sys, t0, h, (&d, &dd), (theta0, rate0), &a, a_theta);
    // Midpoint state (q̄, v̄) and generalized coordinates q = (d, θ); a prescribed base's θ
    // from its law at the midpoint.
    let vb: Vec<f64> = (0..n).map(|i| dd[i] + 0.5 * h * a[i]).collect();
    let db: Vec<f64> = (0..n).map(|i| d[i] + 0.5 * h * vb[i]).collect();
    let (theta, rate, a_theta) = match md.prescribed(t0 + 0.5 * h) {
        Some(law) => law,
        None => {
            let rate = rate0 + 0.5 * h * a_theta;
            (theta0 + 0.5 * h * rate, rate, a_theta)
        }
    };
    let nq = n + 1;
    let pack = |d: &[f64], th: f64| -> Vec<f64> {
        let mut q = d.to_vec();
        q.push(th);
        q
    };
    let q = pack(&db, theta);
    let v = pack(&vb, rate);
    let mut acc = a.clone();
    acc.push(a_theta);
    let kin = |q: &[f64], v: &[f64]| md.kinetic(&q[..n], v[n], &v[..n]);
    let pot = |q: &[f64]| md.strain(&q[..n]) + md.gravity(&q[..n]) + md.joint_spring(q[n]);
    let rayleigh = |v: &[f64]| {
        0.5 * md.motor_friction * v[n] * v[n]
            + md.c_field
                .iter()
                .map(|(_, c)| 0.5 * c.form(&v[..n], &v[..n]))
                .sum::<f64>()
    };
    let grad = |f: &dyn Fn(&[f64]) -> f64, x: &[f64], k: usize, dx: f64| {
        let (mut p, mut m) = (x.to_vec(), x.to_vec());
        p[k] += dx;
        m[k] -= dx;
        (f(&p) - f(&m)) / (2.0 * dx)
    };
    let (dq, dv, dt) = (1e-6, 1e-4, 1e-5);
    let mut scale = 0.0f64;
    let mut lag = vec![0.0; nq];
    for k in 0..nq {
        // d/dt ∂T/∂v along q(t) = q + t v, v(t) = v + t a.
        let pk = |s: f64| {
            let qs: Vec<f64> = (0..nq).map(|i| q[i] + s * v[i]).collect();
            let vs: Vec<f64> = (0..nq).map(|i| v[i] + s * acc[i]).collect();
            grad(&|x: &[f64]| kin(&qs, x), &vs, k, dv)
        };
        let ddt = (pk(dt) - pk(-dt)) / (2.0 * dt);
        let dtq = grad(&|x: &[f64]| kin(x, &v), &q, k, dq);
        let dvq = grad(&pot, &q, k, dq);
        let dr = grad(&rayleigh, &v, k, dv);
        lag[k] = ddt - dtq + dvq + dr;
        scale = scale.max(ddt.abs()).max(dtq.abs()).max(dvq.abs());
    }
    lag[n] -= md.motor_torque(0.2 + 0.5 * h);
    for i in 0..n {
        assert!(
            (res[i] - lag[i]).abs() < 1e-6 * scale,
            "{name}: field row {i}: stepper {:.9e}, Lagrange {:.9e}",
            res[i],
            lag[i]
        );
    }
    if free {
        assert!(
            (res[n] - lag[n]).abs() < 1e-6 * scale,
            "{name}: θ row: stepper {:.9e}, Lagrange {:.9e}",
            res[n],
            lag[n]
        );
    }
}

#[test]
fn sys_payload_equations_are_lagrange_equations_of_the_discrete_energies() {
    lagrange_check("single-link-3d");
    lagrange_check("single-link-3d-constant-rate");
}

#[test]
fn sys_payload_newton_matrix_is_the_residual_jacobian() {
    for name in ["single-link-3d", "single-link-3d-constant-rate"] {
        let l = link(&scene(name));
        let md = Model::assemble(&l, 3).unwrap();
        let n = md.n;
        let free = md.free_base();
        let (d, dd) = state(&md, 0.01);
        let mut sys = LinkSystem::new(md);
        let (t0, theta0, rate0) = (0.1, 0.2, 3.0);
        let h = 2e-3;
        let a: Vec<f64> = (0..n).map(|i| 20.0 * (0.4 * i as f64).cos()).collect();
        let a_theta = 0.8;
        let mut at = |a: &[f64], a_theta: f64| {
            residual_and_newton(&mut sys, t0, h, (&d, &dd), (theta0, rate0), a, a_theta)
        };
        let (_, jac) = at(&a, a_theta);
        let nn = n + usize::from(free);
        let big = (0..nn)
            .flat_map(|i| (0..nn).map(move |j| (i, j)))
            .fold(0.0f64, |m, (i, j)| m.max(jac[(i, j)].abs()));
        for j in 0..nn {
            let delta = 1e-3;
            let (mut ap, mut am) = (a.clone(), a.clone());
            let (mut tp, mut tm) = (a_theta, a_theta);
            if j < n {
                ap[j] += delta;
                am[j] -= delta;
            } else {
                tp += delta;
                tm -= delta;
            }
            let (rp, _) = at(&ap, tp);
            let (rm, _) = at(&am, tm);
            for i in 0..nn {
                let fd = (rp[i] - rm[i]) / (2.0 * delta);
                assert!(
                    (fd - jac[(i, j)]).abs() < 1e-7 * big,
                    "{name}: ({i}, {j}): analytic {:.9e}, finite difference {fd:.9e}",
                    jac[(i, j)]
                );
            }
        }
    }
}

#[test]
fn sys_payload_dofs_and_terms_follow_the_scene() {
    let fem = FemBackend;
    let disc = Discretization {
        elements: Some(8),
        ..Default::default()
    };
    // Free base: 6 DOFs per node + θ; prescribed: no θ.
    let plan = fem.dof_plan(&scene("single-link-3d"), &disc).unwrap();
    assert_eq!(plan.total(), 6 * 8 + 1);
    let plan = fem
        .dof_plan(&scene("single-link-3d-constant-rate"), &disc)
        .unwrap();
    assert_eq!(plan.total(), 6 * 8);
    // Fields not listed are not built; KV off and gravity off build no operator.
    let mut sc = scene("single-link-3d");
    let pl = sc.payload_link_mut().unwrap();
    pl.fields = vec![LinkField::Vertical, LinkField::Torsion];
    pl.gravity = None;
    pl.kelvin_voigt.as_mut().unwrap().vertical = None;
    let plan = fem.dof_plan(&sc, &disc).unwrap();
    assert_eq!(plan.total(), 3 * 8 + 1);
    let md = Model::assemble(sc.payload_link().unwrap(), 8).unwrap();
    assert_eq!(md.n, 24);
    assert!(!md.has_gravity && md.fg.iter().all(|&f| f == 0.0));
    let damped: Vec<LinkField> = md.c_field.iter().map(|(f, _)| *f).collect();
    assert_eq!(damped, vec![LinkField::Torsion]);
    // The run's ledger books exactly those terms and channels of the carried fields only.
    let mut settings = Settings::default();
    settings.discretization.elements = Some(4);
    settings.time.t_end = Some(0.01);
    let run = fem.simulate(&sc, &settings).unwrap();
    let names = |t: &[data::EnergyTerm]| t.iter().map(|x| x.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&run.ledger.stored), ["kinetic", "strain"]);
    assert_eq!(names(&run.ledger.inputs), ["applied_torque"]);
    assert_eq!(
        names(&run.ledger.dissipation),
        ["joint_damper", "kelvin_voigt_torsion"]
    );
    assert!(run.observables.get("link1.tip_w").is_some());
    assert!(run.observables.get("link1.tip_deflection").is_none());
    assert!(run.observables.get("link1.tip_axial").is_none());
    assert_eq!(run.cost.dofs, 4 * 3 + 1);
}

#[test]
fn sys_payload_gravity_sag_is_the_cantilever_solution() {
    // Hermite cubics are nodally exact for tip loads and consistent uniform loads.
    for name in ["single-link-3d", "single-link-3d-soft-sag"] {
        let sc = scene(name);
        let l = link(&sc);
        let mut settings = Settings::default();
        settings.discretization.elements = Some(5);
        let r = FemBackend.statics(&sc, &settings).unwrap();
        let (ei, len, g) = (l.bending_stiffness(), l.length, l.gravity.unwrap());
        let p = l.payload.mass * g;
        let m = p * l.payload.offset;
        let q = l.mass_per_length() * g;
        let w = -(p * len.powi(3) / (3.0 * ei)
            + m * len * len / (2.0 * ei)
            + q * len.powi(4) / (8.0 * ei));
        let slope = -(p * len * len / (2.0 * ei) + m * len / ei + q * len.powi(3) / (6.0 * ei));
        assert!(
            (r.tip_deflection - w).abs() < 1e-11 * w.abs(),
            "{name}: {} vs {w}",
            r.tip_deflection
        );
        assert!(
            (r.tip_rotation - slope).abs() < 1e-11 * slope.abs(),
            "{name}"
        );
    }
}

#[test]
fn sys_payload_refuses_what_it_does_not_build() {
    let sc = scene("single-link-3d");
    // Central difference runs the rod under its bound 2/ω_max (7.0e-6 s here, set by the
    // kHz axial and torsion modes); a step above it is refused.
    let mut settings = Settings::default();
    settings.time.method = Some("central-difference".parse().expect("a method name"));
    settings.time.dt = Some(sc.simulation.output_interval);
    assert!(matches!(
        FemBackend.simulate(&sc, &settings),
        Err(data::BackendError::StabilityBound { .. })
    ));
    let mut settings = Settings::default();
    settings.time.rtol = Some(1e-6);
    assert!(matches!(
        FemBackend.simulate(&sc, &settings),
        Err(data::BackendError::Unsupported(_))
    ));
}

#[test]
fn sys_payload_link_gyroscopic_modes_reduce_to_the_pencil_without_coupling() {
    // The first-order skew form with G = 0 is the symmetric pencil (K_s − Ω²K_c, M): same ω.
    // With G the Coriolis coupling moves the frequencies, and more at a higher rate.
    use fem::payload_link::{gyroscopic_modes, link_modes};
    let sc = scene("single-link-3d-constant-rate");
    let md = Model::assemble(&link(&sc), 8).unwrap();
    let mut uncoupled = md.clone();
    uncoupled.g.data.iter_mut().for_each(|x| *x = 0.0);
    let pencil = link_modes(&md, 12).unwrap();
    let first_order = gyroscopic_modes(&uncoupled, 12).unwrap();
    for (p, g) in pencil.iter().zip(&first_order) {
        assert!(
            (p.omega - g.omega).abs() <= 1e-9 * p.omega,
            "{} vs {}",
            p.omega,
            g.omega
        );
        assert_eq!(p.kind, g.kind);
    }
    let shift = |md: &Model| {
        let p = link_modes(md, 12).unwrap();
        let g = gyroscopic_modes(md, 12).unwrap();
        p.iter()
            .zip(&g)
            .map(|(a, b)| ((a.omega - b.omega) / a.omega).abs())
            .fold(0.0f64, f64::max)
    };
    let slow = shift(&md);
    let mut fast_link = link(&sc);
    fast_link.base.prescribed = Some(data::scene::PrescribedMotion::ConstantRate { rate: 20.0 });
    let fast = shift(&Model::assemble(&fast_link, 8).unwrap());
    assert!(slow > 1e-9, "Coriolis shift at 2π rad/s: {slow:e}");
    assert!(fast > 5.0 * slow, "shift {fast:e} at 20 rad/s vs {slow:e}");
}

#[test]
fn sys_payload_link_turning_plane_modes_do_not_see_the_vertical_plane_inertia() {
    // The seed's decoupling case: with the payload's principal axes along the tip axes the
    // linearized (u, v) and (w, φ) systems are independent (Coriolis about the spin axis couples
    // u and v only), so the turning-plane frequencies cannot depend on I₂, the payload's inertia
    // about the tip's y axis, which enters the vertical plane only. Up to the eigensolver's
    // round-off (ε‖S‖/ω ~ 1e-12 here).
    use fem::payload_link::gyroscopic_modes;
    let sc = scene("single-link-3d-constant-rate");
    let horizontal = |i2: f64| {
        let mut l = link(&sc);
        l.payload.inertia[1][1] = i2;
        let md = Model::assemble(&l, 16).unwrap();
        gyroscopic_modes(&md, 12)
            .unwrap()
            .into_iter()
            .filter(|m| m.kind == "bending-horizontal" || m.kind == "axial")
            .map(|m| m.omega)
            .collect::<Vec<f64>>()
    };
    let i2 = link(&sc).payload.inertia[1][1];
    // (The lowest 12 modes hold 5 or 6 turning-plane ones, as the vertical ones move with I₂.)
    let (a, b) = (horizontal(i2), horizontal(4.0 / 3.0 * i2));
    assert!(a.len() >= 4 && b.len() >= 4, "{a:?} vs {b:?}");
    for (x, y) in a.iter().zip(&b).take(4) {
        assert!(
            (x - y).abs() <= 1e-9 * x,
            "ω {x} with I₂ = {i2:e}, {y} with 4/3 of it"
        );
    }
}
