//! Energy-consistent midpoint scheme: ledger closure, conservation, order, agreement.

use data::{Backend, RunResult, Settings};
use fem::FemBackend;

fn run_with(
    name: &str,
    n: Option<usize>,
    dt: Option<f64>,
    t_end: Option<f64>,
    method: Option<&str>,
) -> RunResult {
    let sc = data::load_scene(name).unwrap();
    let mut st = Settings::default();
    st.discretization.elements = n;
    st.time.dt = dt;
    st.time.t_end = t_end;
    st.time.method = method.map(str::to_string);
    FemBackend.simulate(&sc, &st).unwrap()
}

#[test]
#[ignore]
fn explore() {
    for name in ["single-link", "two-link-free", "two-link-free-undamped"] {
        for m in ["energy-midpoint", "generalized-alpha"] {
            let t0 = std::time::Instant::now();
            let r = run_with(name, None, None, None, Some(m));
            eprintln!(
                "{name} {m}: closure {:.3e}, steps {}, newton {}, rhs {}, fact {}, wall {:.2}s verdict {:?}",
                r.ledger.relative_closure(),
                r.cost.steps,
                r.cost.newton_iterations,
                r.cost.rhs_evaluations,
                r.cost.factorizations,
                t0.elapsed().as_secs_f64(),
                r.verdict
            );
        }
    }
}

#[test]
#[ignore]
fn explore_steps() {
    use fem::run::prepare;
    for name in ["single-link", "two-link-free-undamped"] {
        let sc = data::load_scene(name).unwrap();
        let st = Settings::default();
        let mut p = prepare(&sc, &st).unwrap();
        let it = &mut p.integrator;
        let en = |it: &fem::integrator::Integrator| {
            let e = it.chain.energies(it.t, &it.q, &it.qd);
            e.iter().sum::<f64>()
        };
        let e0 = en(it);
        it.set_stop(1e9);
        let mut worst = 0.0f64;
        let mut w_prev = 0.0;
        let mut e_prev = e0;
        for k in 0..400 {
            it.step().unwrap();
            let w = it.works;
            let wt = w.applied_torque + w.applied_load - w.joint_damper - w.kelvin_voigt;
            let e = en(it);
            let d = (e - e_prev) - (wt - w_prev);
            worst = worst.max(d.abs());
            if k < 5 || k % 100 == 0 {
                eprintln!("{name} step {k}: dE {:.3e} dW {:.3e} defect {:.3e} corr {:.3e}", e - e_prev, wt - w_prev, d,
                    it.midpoint.as_ref().map_or(0.0, |m| m.last_correction));
            }
            e_prev = e;
            w_prev = wt;
        }
        eprintln!("{name}: worst per-step defect {worst:.3e}, E {e_prev:.4e}");
    }
}
