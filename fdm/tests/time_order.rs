//! Measured temporal orders of the report's unequal-step two-step central difference and its
//! remedies, on the oscillator q̈ = −ω²q − 2ζωq̇ (exact solution known in closed form).
//! Run: CARGO_TARGET_DIR=/work/targets/fdm cargo test --release -p fdm --test time_order -- --nocapture

use data::StabilityVerdict;
use fdm::Method;
use fdm::driver::{StepControl, integrate};
use fdm::method::stepper;
use fdm::output::Outputs;
use fdm::system::{Bound, BoundKind, System};

const OMEGA: f64 = 2.0 * std::f64::consts::PI;
const T_END: f64 = 2.0;

/// How the oscillator's "stability bound" (hence the chosen step) varies.
#[derive(Clone, Copy, Debug)]
enum Schedule {
    /// σ such that the method's step is `base` throughout.
    Constant,
    /// Smooth ±30 % variation over the run (like a slowly burning stage).
    Smooth,
    /// One abrupt halving at T/2.
    Jump,
    /// τ alternating between base and 1.5·base every step (τ_j ≠ τ_{j+1} everywhere).
    Alternating,
}

struct Oscillator {
    zeta: f64,
    base: f64,
    factor: f64,
    schedule: Schedule,
}

impl Oscillator {
    fn step_at(&self, t: f64) -> f64 {
        let b = self.base;
        match self.schedule {
            Schedule::Constant => b,
            Schedule::Smooth => b * (1.0 + 0.3 * (2.0 * std::f64::consts::PI * t / T_END).sin()),
            Schedule::Jump => {
                if t < 0.5 * T_END - 1e-12 {
                    b
                } else {
                    0.5 * b
                }
            }
            Schedule::Alternating => {
                let (a, c) = (b, 1.5 * b);
                let f = (t / (a + c)).fract();
                if f < 0.5 * a / (a + c) || f > 1.0 - 0.5 * c / (a + c) {
                    a
                } else {
                    c
                }
            }
        }
    }

    fn exact(&self, t: f64) -> f64 {
        let wd = OMEGA * (1.0 - self.zeta * self.zeta).sqrt();
        let zw = self.zeta * OMEGA;
        (-zw * t).exp() * ((wd * t).cos() + zw / wd * (wd * t).sin())
    }
}

impl System for Oscillator {
    fn dofs(&self) -> usize {
        1
    }

    fn accel(&mut self, _t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        a[0] = -OMEGA * OMEGA * q[0] - 2.0 * self.zeta * OMEGA * v[0];
    }

    fn powers(&self, _out: &mut [f64]) {}
    fn bound(&self, t: f64) -> Bound {
        Bound {
            sigma: self.step_at(t) / self.factor,
            kind: BoundKind::Axial,
            site: 0,
        }
    }

    fn stored_energies(&self, _t: f64, _q: &[f64], _v: &[f64], _out: &mut [f64]) {}
    fn monitored(&self) -> std::ops::Range<usize> {
        0..1
    }

    fn damped(&self) -> bool {
        self.zeta > 0.0
    }
}

impl Outputs for Oscillator {
    fn describe(&self, _b: &Bound) -> String {
        "oscillator".into()
    }

    fn channels(&self) -> Vec<(String, &'static str)> {
        vec![("q".into(), "1")]
    }

    fn observe(&self, _t: f64, q: &[f64], _v: &[f64], out: &mut [f64]) {
        out[0] = q[0];
    }

    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        (vec![], vec![], vec![])
    }

    fn dof_name(&self, _i: usize) -> String {
        "q".into()
    }
}

/// Max |q − q_exact| over the output samples (every 0.05).
fn error(method: Method, schedule: Schedule, zeta: f64, base: f64) -> (f64, StabilityVerdict) {
    let mut sys = Oscillator {
        zeta,
        base,
        factor: stepper(method).bound_factor(),
        schedule,
    };
    let ctl = StepControl {
        method,
        safety: 1.0,
        forced_dt: None,
        t_end: T_END,
        output_interval: 0.05,
        log_change: 0.01,
        lookahead: false,
        enforce_bound: true,
    };
    let out = integrate(&mut sys, &[1.0], &[0.0], &ctl).expect("runs");
    let q = &out.observables.get("q").unwrap().values;
    let e = out
        .observables
        .time
        .iter()
        .zip(q)
        .map(|(t, q)| (q - sys.exact(*t)).abs())
        .fold(0.0, f64::max);
    (e, out.verdict)
}

/// Least-squares slope of log e against log τ over a halving ladder.
fn observed_order(method: Method, schedule: Schedule, zeta: f64) -> (f64, Vec<f64>) {
    let bases = [1.0 / 400.0, 1.0 / 800.0, 1.0 / 1600.0, 1.0 / 3200.0];
    let errs: Vec<f64> = bases
        .iter()
        .map(|&b| error(method, schedule, zeta, b).0)
        .collect();
    let n = bases.len() as f64;
    let xs: Vec<f64> = bases.iter().map(|b| b.ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let num: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let den: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    (num / den, errs)
}

#[test]
fn conv_two_step_temporal_order_measured_for_equal_and_unequal_steps() {
    let mut table = Vec::new();
    for schedule in [
        Schedule::Constant,
        Schedule::Smooth,
        Schedule::Jump,
        Schedule::Alternating,
    ] {
        for method in [Method::Report, Method::VelocityForm] {
            let (p, errs) = observed_order(method, schedule, 0.0);
            eprintln!(
                "{:>14} {:>12}: observed order {p:.3}  errors {errs:?}",
                method.name(),
                format!("{schedule:?}")
            );
            table.push((schedule, method, p));
        }
    }
    for (schedule, method, p) in table {
        match (schedule, method) {
            // Equal or smoothly varying steps (τ_{j+1} − τ_j = O(τ²)): second order.
            (Schedule::Constant | Schedule::Smooth | Schedule::Jump, _) => {
                assert!((p - 2.0).abs() < 0.2, "{schedule:?} {}: {p}", method.name())
            }
            // Alternating steps: each step of the two-step form leaves (τ_{j+1}² − τ_j²) q''/2,
            // of one sign on the even lattice and the other on the odd one: an O(τ) computational
            // oscillation — first order. The one-step velocity form stays second order.
            (Schedule::Alternating, Method::Report) => {
                assert!((p - 1.0).abs() < 0.2, "alternating report: {p}")
            }
            (Schedule::Alternating, _) => {
                assert!((p - 2.0).abs() < 0.2, "alternating {}: {p}", method.name())
            }
        }
    }
}

#[test]
fn conv_robert_asselin_costs_one_order_of_accuracy() {
    let ra = Method::RobertAsselin { nu: 0.01 };
    let (p_ra, e_ra) = observed_order(ra, Schedule::Constant, 0.0);
    let (p_rep, e_rep) = observed_order(Method::Report, Schedule::Constant, 0.0);
    eprintln!("robert-asselin ν = 0.01: order {p_ra:.3}, errors {e_ra:?}");
    eprintln!("report:                  order {p_rep:.3}, errors {e_rep:?}");
    // The filter damps the physical mode by ≈ ν(ωτ)²/… per step: an O(ντ) amplitude error,
    // first order, against the unfiltered scheme's second order.
    assert!((p_ra - 1.0).abs() < 0.2, "{p_ra}");
    for (a, b) in e_ra.iter().zip(&e_rep) {
        assert!(a > b, "the filter costs accuracy: {a} vs {b}");
    }
}

#[test]
fn dyn_damped_oscillator_parasitic_mode_detected_remedies_complete() {
    // ζ = 0.05: the two-step scheme's spurious root grows like e^{ζωt}; over a long run it
    // dominates. Detection must stop the run; the remedies must complete with small errors.
    let zeta = 0.05;
    let t_long = 60.0;
    let run = |method: Method| {
        let mut sys = Oscillator {
            zeta,
            base: 1.0 / 400.0,
            factor: stepper(method).bound_factor(),
            schedule: Schedule::Constant,
        };
        let ctl = StepControl {
            method,
            safety: 1.0,
            forced_dt: None,
            t_end: t_long,
            output_interval: 0.05,
            log_change: 0.01,
            lookahead: false,
            enforce_bound: true,
        };
        integrate(&mut sys, &[1.0], &[0.0], &ctl).expect("runs")
    };
    let rep = run(Method::Report);
    match &rep.verdict {
        StabilityVerdict::Stopped { diagnostic } => {
            eprintln!("report, damped: {diagnostic}");
            assert!(diagnostic.what.contains("parasitic"));
        }
        v => panic!("expected the parasitic mode to be caught, got {v:?}"),
    }
    for method in [Method::RobertAsselin { nu: 0.01 }, Method::VelocityForm] {
        let out = run(method);
        assert!(
            matches!(out.verdict, StabilityVerdict::Completed),
            "{}",
            method.name()
        );
    }
    // Accuracy of the remedies on the damped problem up to t = 2.
    let (e_ra, _) = error(
        Method::RobertAsselin { nu: 0.01 },
        Schedule::Constant,
        zeta,
        1.0 / 400.0,
    );
    let (e_vf, _) = error(Method::VelocityForm, Schedule::Constant, zeta, 1.0 / 400.0);
    eprintln!("damped, τ = 1/400: robert-asselin error {e_ra:.3e}, velocity-form error {e_vf:.3e}");
    // Both are consistent schemes: at ωτ ≈ 0.016 errors are below 1e-2 of the unit amplitude.
    assert!(e_ra < 1e-2 && e_vf < 1e-2);
}
