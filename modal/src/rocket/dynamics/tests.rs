use super::*;
use crate::integrate::{Dopri5, OdeRhs, Tolerances};
use crate::rocket::basis::Basis;
use crate::rocket::integrals::QuadTable;

fn rocket_body() -> Body {
    Body::from_rocket(data::load_scene("rocket").unwrap().rocket().unwrap()).unwrap()
}

/// Deterministic pseudo-random numbers in [-1, 1].
fn pseudo(i: usize) -> f64 {
    ((i as f64 * 12.9898).sin() * 43758.5453).fract() * 2.0 - 1.0
}

struct F<'a> {
    model: &'a Model,
    ws: Workspace,
}
impl OdeRhs for F<'_> {
    fn dim(&self) -> usize {
        self.model.layout.state_len()
    }
    fn eval(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        rhs(self.model, &mut self.ws, t, y, dydt);
    }
}

/// Integrates to t_end and returns the states at every accepted step.
fn integrate(model: &Model, y0: &[f64], t_end: f64, rtol: f64) -> Vec<(f64, Vec<f64>)> {
    let mut f = F {
        model,
        ws: Workspace::new(model.layout),
    };
    let mut y = y0.to_vec();
    let mut t = 0.0;
    let mut dp = Dopri5::new(
        y.len(),
        Tolerances {
            rtol,
            atol: rtol * 1e-3,
        },
        None,
        None,
    );
    let mut out = vec![(0.0, y.clone())];
    while t < t_end {
        dp.step(&mut f, &mut t, &mut y, t_end).unwrap();
        out.push((t, y.clone()));
    }
    out
}

/// A general state: spinning, translating, deformed, everything moving.
fn busy_state(model: &Model, spin: f64) -> Vec<f64> {
    let l = model.layout;
    let mut y = vec![0.0; l.state_len()];
    y[0] = 3.0;
    y[1] = -2.0;
    y[2] = 0.4;
    // elastic motion large enough that its inertia coupling terms matter at 1e-8
    for i in 3..l.dofs() {
        y[i] = 0.05 * pseudo(i);
        y[l.dofs() + i] = 50.0 * pseudo(100 + i);
    }
    y[l.dofs()] = 5.0;
    y[l.dofs() + 1] = -2.0;
    y[l.dofs() + 2] = spin;
    y
}

#[test]
fn elem_strain_gradient_matches_finite_difference() {
    let body = rocket_body();
    let basis = Basis::new(&body, 5).unwrap();
    let model = Model::new(body, &basis);
    let n = 5;
    // large displacements so that the cubic coupling ½∫EA u'w'² matters
    let a: Vec<f64> = (0..n).map(|k| 0.5 * pseudo(k)).collect();
    let b: Vec<f64> = (0..n).map(|k| 0.8 * pseudo(10 + k)).collect();
    let mut g = vec![0.0; 2 * n];
    strain_energy(&model, &a, &b, Some(&mut g));
    for i in 0..2 * n {
        let h = 1e-5;
        let mut ap = a.clone();
        let mut bp = b.clone();
        let mut am = a.clone();
        let mut bm = b.clone();
        if i < n {
            ap[i] += h;
            am[i] -= h;
        } else {
            bp[i - n] += h;
            bm[i - n] -= h;
        }
        let fd = (strain_energy(&model, &ap, &bp, None) - strain_energy(&model, &am, &bm, None))
            / (2.0 * h);
        // central difference of a cubic polynomial: truncation h²·V''' ~ 1e-10 relative,
        // round-off eps·V/h ~ 1e-9 relative to the gradient scale
        let scale = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            (fd - g[i]).abs() < 1e-7 * scale,
            "component {i}: fd {fd} vs {}",
            g[i]
        );
    }
    // the coupling term is really there: gradient differs from K q alone
    let lin = dot(&model.kb[..n], &b[..n]);
    assert!((g[n] - lin).abs() > 1e-9 * g[n].abs());
}

#[test]
fn elem_coupling_tensor_matches_pointwise_quadrature() {
    // ½ Σ G_klm a_k b_l b_m against ½∫EA u'w'² summed point by point (5 Gauss points per
    // element, exact for the degree-5 integrand as is the tensor's 3-point rule)
    let body = rocket_body();
    let basis = Basis::new(&body, 5).unwrap();
    let model = Model::new(body, &basis);
    let n = 5;
    let a: Vec<f64> = (0..n).map(pseudo).collect();
    let b: Vec<f64> = (0..n).map(|k| pseudo(20 + k)).collect();
    let zero = vec![0.0; n];
    let coupled = strain_energy(&model, &a, &b, None)
        - strain_energy(&model, &a, &zero, None)
        - strain_energy(&model, &zero, &b, None);
    let t5 = QuadTable::new(&basis, 5);
    let mut direct = 0.0;
    for p in 0..t5.points() {
        let ea = basis.mesh.elements[t5.element[p]].ea;
        let up = dot(&t5.du[p * n..(p + 1) * n], &a);
        let wp = dot(&t5.dw[p * n..(p + 1) * n], &b);
        direct += 0.5 * ea * t5.weight[p] * up * wp * wp;
    }
    // two exact quadratures of the same polynomial: round-off only
    assert!(
        (coupled - direct).abs() < 1e-10 * direct.abs(),
        "{coupled} vs {direct}"
    );
}

#[test]
fn elem_mass_matrix_matches_kinetic_energy_quadrature() {
    // ½vᵀM v against an independent pointwise quadrature of ½∫m|ṙ_b|² + ½ΣM_j|ṙ_j|²
    let body = rocket_body();
    let basis = Basis::new(&body, 4).unwrap();
    let model = Model::new(body, &basis);
    let l = model.layout;
    let nd = l.dofs();
    let t = 0.7; // mid-burn: the affine mass update is exercised
    let y = busy_state(&model, 1.7);
    let (q, v) = (&y[..nd], &y[nd..2 * nd]);
    let mut ws = Workspace::new(l);
    let snap = snapshot(&model, &mut ws, t, &y);

    let table = QuadTable::new(&basis, 4);
    let n = l.n;
    let burnt = model.burnt_per_length(t);
    let (om, vx, vy) = (v[2], v[0], v[1]);
    let mut kin = 0.0;
    let mut mass = 0.0;
    for g in 0..table.points() {
        let el = &basis.mesh.elements[table.element[g]];
        let m = el.mass0 - if el.burning { burnt } else { 0.0 };
        let x = table.x[g];
        let uk = &table.u[g * n..(g + 1) * n];
        let wk = &table.w[g * n..(g + 1) * n];
        let u = dot(uk, &q[l.a()..l.a() + n]);
        let w = dot(wk, &q[l.b()..l.b() + n]);
        let ud = dot(uk, &v[l.a()..l.a() + n]);
        let wd = dot(wk, &v[l.b()..l.b() + n]);
        let px = vx - om * w + ud;
        let py = vy + om * (x + u) + wd;
        kin += 0.5 * m * table.weight[g] * (px * px + py * py);
        mass += m * table.weight[g];
    }
    for (j, pm) in model.body.masses.iter().enumerate() {
        let (uj, wj) = (q[l.mu() + j], q[l.mw() + j]);
        let (udj, wdj) = (v[l.mu() + j], v[l.mw() + j]);
        let px = vx - om * wj + udj;
        let py = vy + om * (pm.x + uj) + wdj;
        kin += 0.5 * pm.mass * (px * px + py * py);
        mass += pm.mass;
    }
    // same quadrature, different algebra: round-off only
    assert!(
        (snap.kinetic - kin).abs() < 1e-12 * kin,
        "{} vs {kin}",
        snap.kinetic
    );
    assert!((snap.total_mass - mass).abs() < 1e-13 * mass);
}

/// Angular momentum about the inertial origin: R_O × P + (M v)_θ.
fn angular_momentum(model: &Model, ws: &mut Workspace, t: f64, y: &[f64]) -> f64 {
    let nd = model.layout.dofs();
    let snap = snapshot(model, ws, t, y);
    // snapshot leaves M v in ws.tmp
    y[0] * snap.momentum.1 - y[1] * snap.momentum.0 + ws.tmp[2] + 0.0 * nd as f64
}

#[test]
fn dyn_spinning_free_body_conserves_energy_and_momenta() {
    // No burn, no gravity: a free elastic body. Energy, linear and angular momentum are
    // invariants; the gyroscopic/Coriolis terms h(q, v) are fully exercised by the spin.
    let mut body = rocket_body();
    body.burn = None;
    body.gravity = 0.0;
    let basis = Basis::new(&body, 4).unwrap();
    let model = Model::new(body, &basis);
    let y0 = busy_state(&model, 3.0);
    let run = integrate(&model, &y0, 0.02, 1e-11);
    let mut ws = Workspace::new(model.layout);
    let e = |ws: &mut Workspace, y: &[f64]| {
        let s = snapshot(&model, ws, 0.0, y);
        s.kinetic + s.strain + s.springs
    };
    let e0 = e(&mut ws, &y0);
    let p0 = snapshot(&model, &mut ws, 0.0, &y0).momentum;
    let h0 = angular_momentum(&model, &mut ws, 0.0, &y0);
    let (mut de, mut dp, mut dh) = (0.0f64, 0.0f64, 0.0f64);
    for (t, y) in &run {
        de = de.max((e(&mut ws, y) - e0).abs() / e0);
        let p = snapshot(&model, &mut ws, *t, y).momentum;
        dp = dp.max(((p.0 - p0.0).powi(2) + (p.1 - p0.1).powi(2)).sqrt() / p0.0.hypot(p0.1));
        dh = dh.max((angular_momentum(&model, &mut ws, *t, y) - h0).abs() / h0.abs());
    }
    // rtol 1e-11 over ~1000 steps: drift ≲ 1e-8 relative
    assert!(de < 1e-8, "energy drift {de:e}");
    assert!(dp < 1e-8, "momentum drift {dp:e}");
    assert!(dh < 1e-8, "angular momentum drift {dh:e}");
}

#[test]
fn dyn_burning_spinning_body_balances_close() {
    // Full loads (thrust, pressure, jet Coriolis, gravity, mass loss) on a spinning body:
    // the momentum balance and the energy ledger are identities of the model.
    let body = rocket_body();
    let basis = Basis::new(&body, 4).unwrap();
    let model = Model::new(body, &basis);
    let l = model.layout;
    let y0 = busy_state(&model, 2.0);
    let run = integrate(&model, &y0, 0.02, 1e-11);
    let mut ws = Workspace::new(l);
    let s0 = snapshot(&model, &mut ws, 0.0, &y0);
    let e0 = s0.kinetic + s0.strain + s0.gravity + s0.springs;
    let (mut worst_e, mut worst_p, mut scale_e, mut scale_p) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (t, y) in &run {
        let s = snapshot(&model, &mut ws, *t, y);
        let qd = &y[l.quad()..];
        let e = s.kinetic + s.strain + s.gravity + s.springs;
        let w_in =
            qd[quad::W_THRUST] + qd[quad::W_PRESSURE] + qd[quad::W_CORIOLIS] + qd[quad::E_OUTFLOW];
        worst_e = worst_e.max((e - e0 - w_in + qd[quad::W_DAMPING]).abs());
        scale_e = scale_e.max(e.abs()).max(w_in.abs());
        for c in 0..2 {
            let p = if c == 0 { s.momentum.0 } else { s.momentum.1 };
            let p0 = if c == 0 { s0.momentum.0 } else { s0.momentum.1 };
            let imp = qd[quad::IMP_THRUST + c]
                + qd[quad::IMP_PRESSURE + c]
                + qd[quad::IMP_CORIOLIS + c]
                + qd[quad::IMP_GRAVITY + c]
                + qd[quad::MOM_OUTFLOW + c];
            worst_p = worst_p.max((p - p0 - imp).abs());
            scale_p = scale_p.max(p.abs());
        }
    }
    // integrator tolerance 1e-11: both balances close to ~1e-9 of their scale
    assert!(
        worst_e < 1e-9 * scale_e,
        "energy ledger residual {:e}",
        worst_e / scale_e
    );
    assert!(
        worst_p < 1e-9 * scale_p,
        "momentum residual {:e}",
        worst_p / scale_p
    );
    // the Coriolis impulse is non-zero with spin (the term is really exercised)
    let last = &run.last().unwrap().1[l.quad()..];
    assert!(last[quad::IMP_CORIOLIS].hypot(last[quad::IMP_CORIOLIS + 1]) > 1e-3);
}
