//! The methods step any [`System`], not only the chain: a two-DOF spring–mass–damper
//! M q̈ + C q̇ + K q = f(t) (M full and constant, Rayleigh damping C = aM + bK, harmonic load)
//! implemented here, stepped through the [`Stepper`] trait by every method and compared with
//! its exact solution (modal superposition of the damped, harmonically forced oscillators);
//! energy-midpoint closes its energy ledger on the undamped oscillator.

// Index loops mirror the matrix formulas.
#![allow(clippy::needless_range_loop)]

use fem::band::BorderedBand;
use fem::method::central_difference;
use fem::method::{
    Adaptive, Counters, NewtonSystem, StepContext, StepState, Stepper, Trial, Works, start, stepper,
};
use fem::settings::Method;
use fem::system::{NewtonCoefficients, NoAugmentation, Parts, System};

/// M q̈ + C q̇ + K q = f₀ sin(Ωt) with 2 × 2 symmetric M, K and C = aM + bK.
#[derive(Debug, Clone)]
struct Oscillator {
    m: [[f64; 2]; 2],
    k: [[f64; 2]; 2],
    /// Rayleigh coefficients (a, b).
    rayleigh: (f64, f64),
    f0: [f64; 2],
    omega_load: f64,
}

impl Oscillator {
    fn new(rayleigh: (f64, f64)) -> Self {
        Oscillator {
            m: [[2.0, 0.5], [0.5, 1.0]],
            k: [[300.0, -100.0], [-100.0, 100.0]],
            rayleigh,
            f0: [0.0, 1.0],
            omega_load: 7.0,
        }
    }

    fn c(&self) -> [[f64; 2]; 2] {
        let (a, b) = self.rayleigh;
        let mut c = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                c[i][j] = a * self.m[i][j] + b * self.k[i][j];
            }
        }
        c
    }

    fn load(&self, t: f64) -> [f64; 2] {
        let s = (self.omega_load * t).sin();
        [self.f0[0] * s, self.f0[1] * s]
    }

    /// Mass-normalized modes (ω², φ) of K φ = ω² M φ: det(K − λM) = 0 is a quadratic.
    fn modes(&self) -> [(f64, [f64; 2]); 2] {
        let (m, k) = (&self.m, &self.k);
        let a = m[0][0] * m[1][1] - m[0][1] * m[0][1];
        let b = -(k[0][0] * m[1][1] + k[1][1] * m[0][0] - 2.0 * k[0][1] * m[0][1]);
        let c = k[0][0] * k[1][1] - k[0][1] * k[0][1];
        let root = (b * b - 4.0 * a * c).sqrt();
        [(-b - root) / (2.0 * a), (-b + root) / (2.0 * a)].map(|lam| {
            let phi = [k[0][1] - lam * m[0][1], -(k[0][0] - lam * m[0][0])];
            let norm = quad(m, &phi, &phi).sqrt();
            (lam, [phi[0] / norm, phi[1] / norm])
        })
    }

    /// Exact q(t) from (q₀, q̇₀): each modal coordinate η = φᵀMq obeys
    /// η̈ + 2ζω η̇ + ω² η = F sin Ωt, 2ζω = a + bω², F = φᵀf₀.
    fn exact(&self, q0: &[f64; 2], v0: &[f64; 2], t: f64) -> [f64; 2] {
        let (a, b) = self.rayleigh;
        let w = self.omega_load;
        let mut q = [0.0; 2];
        for (lam, phi) in self.modes() {
            let om = lam.sqrt();
            let two_zeta_om = a + b * lam;
            let zeta_om = 0.5 * two_zeta_om;
            let om_d = (lam - zeta_om * zeta_om).sqrt();
            let force = phi[0] * self.f0[0] + phi[1] * self.f0[1];
            let den = (lam - w * w).powi(2) + (two_zeta_om * w).powi(2);
            let (p, c) = (force * (lam - w * w) / den, -force * two_zeta_om * w / den);
            let x0 = quad(&self.m, &phi, q0);
            let xd0 = quad(&self.m, &phi, v0);
            let amp_c = x0 - c;
            let amp_s = (xd0 - p * w + zeta_om * amp_c) / om_d;
            let eta = p * (w * t).sin()
                + c * (w * t).cos()
                + (-zeta_om * t).exp() * (amp_c * (om_d * t).cos() + amp_s * (om_d * t).sin());
            assert!(om > 0.0);
            q[0] += phi[0] * eta;
            q[1] += phi[1] * eta;
        }
        q
    }
}

/// xᵀ A y.
fn quad(a: &[[f64; 2]; 2], x: &[f64], y: &[f64]) -> f64 {
    (0..2)
        .map(|i| (0..2).map(|j| x[i] * a[i][j] * y[j]).sum::<f64>())
        .sum()
}

/// out = A x (overwritten).
fn mat_vec(a: &[[f64; 2]; 2], x: &[f64], out: &mut [f64]) {
    for i in 0..2 {
        out[i] = a[i][0] * x[0] + a[i][1] * x[1];
    }
}

impl System for Oscillator {
    type Augmented = NoAugmentation;

    fn ndof(&self) -> usize {
        2
    }

    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], res: &mut [f64]) {
        self.residual_parts(t, q, qd, qdd, Parts::ALL, res);
    }

    fn residual_parts(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        let mut tmp = [0.0; 2];
        res.iter_mut().for_each(|r| *r = 0.0);
        // Constant M: the inertia group is M q̈ (no velocity terms).
        if parts.inertia {
            mat_vec(&self.m, qdd, &mut tmp);
            res.iter_mut().zip(tmp).for_each(|(r, x)| *r += x);
        }
        if parts.conservative {
            mat_vec(&self.k, q, &mut tmp);
            res.iter_mut().zip(tmp).for_each(|(r, x)| *r += x);
        }
        if parts.nonconservative {
            mat_vec(&self.c(), qd, &mut tmp);
            let f = self.load(t);
            for i in 0..2 {
                res[i] += tmp[i] - f[i];
            }
        }
    }

    fn residual_parts_at_last_q(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        parts: Parts,
        res: &mut [f64],
    ) {
        self.residual_parts(t, q, qd, &[0.0; 2], parts, res);
    }

    fn add_kinetic_gradient(&mut self, _: f64, _: &[f64], _: &[f64], _: f64, _: &mut [f64]) {
        // T = ½q̇ᵀMq̇ with constant M: ∂T/∂q = 0.
    }

    fn energies(&self, _t: f64, q: &[f64], qd: &[f64]) -> [f64; 4] {
        [
            0.5 * quad(&self.m, qd, qd),
            0.5 * quad(&self.k, q, q),
            0.0,
            0.0,
        ]
    }

    fn has_massless_dofs(&self) -> bool {
        false
    }

    fn new_matrix(&self) -> BorderedBand {
        BorderedBand::new(2, 0, 1)
    }

    fn newton_matrix(&self, _q: &[f64], c: NewtonCoefficients, s: &mut BorderedBand) {
        s.clear();
        let damping = self.c();
        for i in 0..2 {
            for j in 0..2 {
                s.add(
                    i,
                    j,
                    c.c_a * self.m[i][j] + c.c_v * damping[i][j] + c.c_q * self.k[i][j],
                );
            }
        }
    }

    /// The load's work f(t_mid)·Δq and the damper's dissipation h v̄ᵀC v̄.
    fn midpoint_works(
        &mut self,
        h: f64,
        t_mid: f64,
        _t_law: f64,
        dq: &[f64],
        vbar: &[f64],
        _minus_q: &[f64],
    ) -> Works {
        let f = self.load(t_mid);
        Works {
            applied_load: f[0] * dq[0] + f[1] * dq[1],
            joint_damper: h * quad(&self.c(), vbar, vbar),
            ..Works::default()
        }
    }
}

const Q0: [f64; 2] = [0.01, -0.02];
const V0: [f64; 2] = [0.0, 0.1];

/// One run of `method` over [0, t_end] in `steps` equal steps from (Q0, V0), through the
/// `Stepper` trait as the driver does it: consistent start, step, commit, accept. Returns the
/// largest error against the exact solution over the steps (relative to the largest |q|), and
/// per step the energy E and the works the method booked (cumulative; `None` where the method
/// leaves the booking to its driver).
fn run(
    sys: &mut Oscillator,
    kind: Method,
    rho_inf: f64,
    t_end: f64,
    steps: usize,
) -> (f64, Vec<(f64, Option<f64>)>) {
    let h = t_end / steps as f64;
    let start = (Q0, V0);
    with_context(sys, kind, rho_inf, h, start, None, |cx, method| {
        errors_and_ledger(cx, method, kind, h, steps)
    })
}

/// Sets up what the driver would — state at (q₀, q̇₀) with the consistent acceleration, Newton
/// system, counters, the `kind` stepper — and hands them to `body`.
fn with_context<R>(
    sys: &mut Oscillator,
    kind: Method,
    rho_inf: f64,
    h: f64,
    (q0, v0): ([f64; 2], [f64; 2]),
    adaptive: Option<Adaptive>,
    body: impl FnOnce(&mut StepContext<'_, Oscillator>, &mut dyn Stepper<Oscillator>) -> R,
) -> R {
    let mut state = StepState::new(2);
    state.q.copy_from_slice(&q0);
    state.qd.copy_from_slice(&v0);
    let mut newton = NewtonSystem::new(&*sys, 1.0);
    let mut counters = Counters::default();
    let mut method = stepper::<Oscillator>(kind, 2, rho_inf);
    let mut cx = StepContext {
        system: sys,
        state: &mut state,
        newton: &mut newton,
        counters: &mut counters,
        adaptive,
        h_nominal: h,
        length_scale: 1.0,
        method_works: true,
    };
    start::consistent_acceleration(&mut cx, h, 0.0).expect("a consistent start");
    body(&mut cx, method.as_mut())
}

/// The body of [`run`].
fn errors_and_ledger(
    cx: &mut StepContext<'_, Oscillator>,
    method: &mut dyn Stepper<Oscillator>,
    kind: Method,
    h: f64,
    steps: usize,
) -> (f64, Vec<(f64, Option<f64>)>) {
    let mut works = Works::default();
    let energy = |s: &Oscillator, st: &StepState| s.energies(st.t, &st.q, &st.qd).iter().sum();
    let mut ledger = vec![(energy(cx.system, cx.state), Some(0.0))];
    let (mut err, mut q_max) = (0.0f64, 0.0f64);
    for k in 0..steps {
        let t1 = (k + 1) as f64 * h;
        let trial = method.step(cx, None, h, t1, t1).expect("a fixed step");
        assert_eq!(
            trial,
            Trial::Converged { error: None },
            "{kind:?}: Newton converged at step {k}"
        );
        let booked = method.commit(h, &mut works);
        cx.state.swap_in(t1);
        let w = works.applied_load - works.joint_damper;
        ledger.push((energy(cx.system, cx.state), booked.then_some(w)));
        let exact = cx.system.exact(&Q0, &V0, t1);
        for i in 0..2 {
            err = err.max((cx.state.q[i] - exact[i]).abs());
            q_max = q_max.max(exact[i].abs());
        }
    }
    (err / q_max, ledger)
}

#[test]
fn sys_every_method_steps_a_system_that_is_not_a_chain_at_second_order() {
    let mut sys = Oscillator::new((0.2, 2e-3));
    // ω ≈ 6.1 and 17.5 rad/s: about one period of the slow mode, three of the fast one.
    let t_end = 1.0;
    for (method, rho) in [
        (Method::ImplicitMidpoint, 1.0),
        (Method::GeneralizedAlpha, 1.0),
        (Method::GeneralizedAlpha, 0.8),
        (Method::EnergyMidpoint, 1.0),
        (Method::CentralDifference, 1.0),
        (Method::Bathe, 1.0),
    ] {
        let errors: Vec<f64> = [100, 200, 400]
            .map(|steps| run(&mut sys, method, rho, t_end, steps).0)
            .to_vec();
        for pair in errors.windows(2) {
            let order = (pair[0] / pair[1]).log2();
            assert!(
                (1.8..=2.2).contains(&order),
                "{method:?} ρ∞ = {rho}: observed order {order:.3} (errors {errors:?})"
            );
        }
    }
}

#[test]
fn sys_every_methods_dense_output_is_no_less_accurate_than_its_step() {
    // One step of length h from (Q0, V0) on the damped, forced oscillator. The continuous
    // extension meets the step's ends exactly, and inside the step its distance to the exact
    // solution is of the order of the step's own local error: the interpolant (third order) adds
    // less than the method (second order) makes, so both fall as h³ under halving.
    let mut sys = Oscillator::new((0.2, 2e-3));
    for (method, rho) in [
        (Method::ImplicitMidpoint, 1.0),
        (Method::GeneralizedAlpha, 0.8),
        (Method::EnergyMidpoint, 1.0),
        (Method::CentralDifference, 1.0),
        (Method::Bathe, 1.0),
    ] {
        let mut previous: Option<(f64, f64)> = None;
        for h in [4e-3, 2e-3, 1e-3] {
            let (end_error, inner_error) =
                with_context(&mut sys, method, rho, h, (Q0, V0), None, |cx, stepper| {
                    let trial = stepper.step(cx, None, h, h, h).expect("a step");
                    assert_eq!(trial, Trial::Converged { error: None }, "{method:?}");
                    let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
                    for (theta, q_end, qd_end) in [
                        (0.0, &cx.state.q, &cx.state.qd),
                        (1.0, &cx.state.q1, &cx.state.qd1),
                    ] {
                        stepper.dense(cx.state, h, theta, &mut q, &mut qd);
                        for i in 0..2 {
                            assert!((q[i] - q_end[i]).abs() <= 1e-15 * q_end[i].abs().max(1e-2));
                            assert!((qd[i] - qd_end[i]).abs() <= 1e-12 * qd_end[i].abs().max(1e-1));
                        }
                    }
                    let exact_end = cx.system.exact(&Q0, &V0, h);
                    let end_error = (0..2)
                        .map(|i| (cx.state.q1[i] - exact_end[i]).abs())
                        .fold(0.0, f64::max);
                    let mut inner_error = 0.0f64;
                    for theta in [0.25, 0.5, 0.75] {
                        stepper.dense(cx.state, h, theta, &mut q, &mut qd);
                        let exact = cx.system.exact(&Q0, &V0, theta * h);
                        for i in 0..2 {
                            inner_error = inner_error.max((q[i] - exact[i]).abs());
                        }
                    }
                    (end_error, inner_error)
                });
            assert!(
                inner_error <= 2.0 * end_error,
                "{method:?}, h = {h}: inside {inner_error:.3e}, at the end {end_error:.3e}"
            );
            if let Some((end_before, inner_before)) = previous {
                let order = (inner_before / inner_error).log2();
                assert!(
                    order >= 2.7,
                    "{method:?}, h = {h}: inner error order {order:.2} \
                     ({inner_before:.3e} → {inner_error:.3e}; end {end_before:.3e} → {end_error:.3e})"
                );
            }
            previous = Some((end_error, inner_error));
        }
    }
}

#[test]
fn sys_energy_midpoint_closes_the_ledger_of_a_system_that_is_not_a_chain() {
    let mut sys = Oscillator::new((0.0, 0.0));
    let steps = 200;
    let (_, ledger) = run(&mut sys, Method::EnergyMidpoint, 1.0, 1.0, steps);
    let (e0, _) = ledger[0];
    let e_scale = ledger.iter().fold(0.0f64, |a, (e, _)| a.max(e.abs()));
    let mut worst = 0.0f64;
    for &(e, w) in &ledger {
        let w = w.expect("energy-midpoint books its own works");
        worst = worst.max((e - e0 - w).abs());
    }
    // The method bounds each step's energy defect at 1e-14 of the step's energy scale (its
    // Newton tolerance, `ENERGY_TOL`): the ledger closes to the sum of those bounds.
    let bound = steps as f64 * 1e-14 * 2.0 * e_scale;
    assert!(
        worst <= bound,
        "ledger closure {worst:.3e} > {bound:.3e} (energy scale {e_scale:.3e})"
    );
    // The load does work: the closure is not that of a constant energy.
    let (e_end, w_end) = ledger[steps];
    assert!(w_end.expect("booked").abs() > 1e-3 * e_scale && (e_end - e0).abs() > 1e-3 * e_scale);
}

/// Two uncoupled undamped, unloaded oscillators q̈ᵢ = −ωᵢ²qᵢ (M = I).
fn uncoupled(omega: [f64; 2]) -> Oscillator {
    Oscillator {
        m: [[1.0, 0.0], [0.0, 1.0]],
        k: [[omega[0] * omega[0], 0.0], [0.0, omega[1] * omega[1]]],
        rayleigh: (0.0, 0.0),
        f0: [0.0, 0.0],
        omega_load: 0.0,
    }
}

/// Bathe's step map of q̈ = −ω²q, (q₀, q̇₀) → (q₁, q̇₁), solved by hand from the two sub-step
/// formulas of the method's docs (a₀ = −ω²q₀; trapezoidal half step; three-point backward
/// difference).
fn bathe_map(omega: f64, h: f64, q0: f64, v0: f64) -> (f64, f64) {
    let w2 = omega * omega;
    let a0 = -w2 * q0;
    let q_m = (q0 * (1.0 - w2 * h * h / 16.0) + 0.5 * h * v0) / (1.0 + w2 * h * h / 16.0);
    let v_m = v0 + 0.25 * h * (a0 - w2 * q_m);
    let q1 = ((4.0 * q_m - q0) / 3.0 + h / 9.0 * (4.0 * v_m - v0)) / (1.0 + w2 * h * h / 9.0);
    let v1 = (4.0 * v_m - v0) / 3.0 - h / 3.0 * w2 * q1;
    (q1, v1)
}

/// Spectral radius of a real 2 × 2 matrix.
fn spectral_radius(a: [[f64; 2]; 2]) -> f64 {
    let (tr, det) = (a[0][0] + a[1][1], a[0][0] * a[1][1] - a[0][1] * a[1][0]);
    let disc = 0.25 * tr * tr - det;
    if disc >= 0.0 {
        (0.5 * tr).abs() + disc.sqrt()
    } else {
        det.sqrt()
    }
}

#[test]
fn sys_bathe_steps_its_amplification_map_which_damps_only_the_unresolved() {
    let h = 1e-2;
    // ωh = 0.1 (resolved) and 1e4 (far beyond the step).
    let omega = [10.0, 1e6];
    let mut sys = uncoupled(omega);
    // Columns of the step map: one step from (q, q̇) = (1, 0) and from (0, 1) in both DOFs.
    let mut map = [[[0.0; 2]; 2]; 2];
    for (col, start) in [([1.0, 1.0], [0.0, 0.0]), ([0.0, 0.0], [1.0, 1.0])]
        .into_iter()
        .enumerate()
    {
        let end = with_context(
            &mut sys,
            Method::Bathe,
            1.0,
            h,
            start,
            None,
            |cx, method| {
                let trial = method.step(cx, None, h, h, h).expect("a step");
                assert!(matches!(trial, Trial::Converged { .. }), "{trial:?}");
                (cx.state.q1.clone(), cx.state.qd1.clone())
            },
        );
        for dof in 0..2 {
            map[dof][0][col] = end.0[dof];
            map[dof][1][col] = end.1[dof];
        }
    }
    for dof in 0..2 {
        for (col, (q0, v0)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
            let (q1, v1) = bathe_map(omega[dof], h, q0, v0);
            // Newton on a linear system: exact after one update, up to its tolerance.
            for (got, want, scale) in [
                (map[dof][0][col], q1, 1.0),
                (map[dof][1][col], v1, omega[dof]),
            ] {
                assert!(
                    (got - want).abs() <= 1e-10 * scale,
                    "ω = {}: step map entry {got:.15e}, by hand {want:.15e}",
                    omega[dof]
                );
            }
        }
    }
    // In the normalized state (q, q̇/ω) the map's spectral radius: near 1 where the step resolves
    // the motion (the loss is O((ωh)⁴)), near 0 where it does not (ρ∞ = 0).
    let radius = |dof: usize| {
        let w = omega[dof];
        let m = map[dof];
        spectral_radius([[m[0][0], m[0][1] * w], [m[1][0] / w, m[1][1]]])
    };
    let (resolved, unresolved) = (radius(0), radius(1));
    assert!(
        1.0 - resolved < 1e-6 && resolved <= 1.0,
        "ωh = 0.1: ρ = {resolved}"
    );
    assert!(unresolved < 1e-3, "ωh = 1e4: ρ = {unresolved}");
}

#[test]
fn sys_bathe_error_estimate_is_its_local_error() {
    // q̈ = f₀ sin Ωt with M = I, no stiffness, from rest: the exact step is
    // q(h) = f₀(h/Ω − sin(Ωh)/Ω²), q⃛(0) = f₀Ω, and the method's local error h³q⃛/24.
    let (f0, big_omega) = (1.0, 7.0);
    let mut sys = Oscillator {
        m: [[1.0, 0.0], [0.0, 1.0]],
        k: [[0.0, 0.0], [0.0, 0.0]],
        rayleigh: (0.0, 0.0),
        f0: [f0, 0.0],
        omega_load: big_omega,
    };
    for h in [1e-2, 1e-3] {
        let tol = Adaptive {
            rtol: 0.0,
            atol: 1.0,
        };
        let (estimate, q1) = with_context(
            &mut sys,
            Method::Bathe,
            1.0,
            h,
            ([0.0; 2], [0.0; 2]),
            Some(tol),
            |cx, method| {
                let trial = method.step(cx, None, h, h, h).expect("a step");
                let Trial::Converged { error: Some(e) } = trial else {
                    panic!("adaptive: an estimate, got {trial:?}");
                };
                (e, cx.state.q1[0])
            },
        );
        let exact = f0 * (h / big_omega - (big_omega * h).sin() / (big_omega * big_omega));
        let error = (q1 - exact).abs();
        // Leading terms agree; the next is O(Ωh) relative.
        let rel = (estimate - error).abs() / error;
        assert!(
            rel <= 2.0 * big_omega * h,
            "h = {h}: estimate {estimate:.4e}, error {error:.4e} (rel. difference {rel:.2e})"
        );
    }
}

#[test]
fn sys_central_difference_keeps_the_undamped_bound_under_damping() {
    // Stiffness-proportional damping b = 0.2: the fast mode (ω ≈ 17.5 rad/s) has κ = bω² ≈ 61,
    // κ/ω ≈ 3.5, so a damping at a predicted velocity would bound the step by
    // 2/(κ + √(κ² + ω²)) ≈ 0.14 × 2/ω_max. With the damping at the end velocity the bound is
    // the undamped 2/ω_max, and the scheme is stable right up to it.
    let mut sys = Oscillator::new((0.0, 0.2));
    let mut state = StepState::new(2);
    state.q.copy_from_slice(&Q0);
    let mut res = [0.0; 2];
    let (bound, _) =
        central_difference::stability_bound(&mut sys, &state, &mut res).expect("a bound");
    let undamped = 2.0 / sys.modes()[1].0.sqrt();
    assert!(
        (bound - undamped).abs() <= 1e-8 * undamped,
        "bound {bound:.10e}, 2/ω_max {undamped:.10e}"
    );
    // Largest |q| over the last quarter of 2000 steps, from (Q0, V0), at step h.
    let mut late_amplitude = |h: f64| {
        let steps = 2000;
        with_context(
            &mut sys,
            Method::CentralDifference,
            1.0,
            h,
            (Q0, V0),
            None,
            |cx, method| {
                let mut late = 0.0f64;
                for k in 0..steps {
                    let t1 = (k + 1) as f64 * h;
                    let trial = method.step(cx, None, h, t1, t1).expect("a step");
                    assert!(matches!(trial, Trial::Converged { .. }), "{trial:?}");
                    cx.state.swap_in(t1);
                    if k >= 3 * steps / 4 {
                        late = late.max(max_abs(&cx.state.q));
                    }
                }
                late
            },
        )
    };
    // The load keeps the forced response at the size of the initial state: below the bound it
    // stays there, above it the fast mode grows without bound.
    let start = max_abs(&Q0);
    let (below, above) = (late_amplitude(0.95 * bound), late_amplitude(1.05 * bound));
    assert!(below < 10.0 * start, "0.95 × bound: late |q| {below:.3e}");
    // (a run that overflowed to ∞ or NaN has grown too)
    let grew = above.is_nan() || above >= 1e6 * start;
    assert!(grew, "1.05 × bound: late |q| {above:.3e}");
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}
