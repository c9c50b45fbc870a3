//! The integrators perform no heap allocation per step (counting global allocator).

use modal::integrate::{Dopri5, OdeRhs, Sdirk, Tolerances};

#[path = "support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

struct Pendulums;
impl OdeRhs for Pendulums {
    fn dim(&self) -> usize {
        6
    }
    fn eval(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
        for k in 0..3 {
            d[2 * k] = y[2 * k + 1];
            d[2 * k + 1] = -(k as f64 + 1.0) * y[2 * k].sin();
        }
    }
}

#[test]
fn ode_steps_do_not_allocate() {
    // Sdirk's dense LU goes through faer; with its default rayon parallelism the worker pool
    // allocates on first use from other threads, which this global counter would see (one
    // flaky failure was observed). Run sequentially, as the CLI does.
    faer::set_global_parallelism(faer::Par::Seq);
    let tol = Tolerances {
        rtol: 1e-9,
        atol: 1e-12,
    };
    let y0 = [1.0, 0.0, 0.5, 0.1, -0.3, 0.2];
    let mut out = [0.0; 6];

    let mut f = Pendulums;
    let mut s = Dopri5::new(6, tol, None, None);
    let (mut t, mut y) = (0.0, y0);
    s.step(&mut f, &mut t, &mut y, 10.0).unwrap(); // warm-up
    let before = allocations();
    while t < 10.0 {
        s.step(&mut f, &mut t, &mut y, 10.0).unwrap();
        s.dense(t, &mut out);
    }
    let after = allocations();
    assert!(s.stats().steps > 50);
    assert_eq!(after - before, 0, "Dopri5 allocated during stepping");

    let mut s = Sdirk::new(6, tol, None, None);
    let (mut t, mut y) = (0.0, y0);
    s.step(&mut f, &mut t, &mut y, 10.0).unwrap();
    let before = allocations();
    while t < 10.0 {
        s.step(&mut f, &mut t, &mut y, 10.0).unwrap();
        s.dense(t, &mut out);
    }
    let after = allocations();
    assert!(s.stats().steps > 50 && s.stats().factorizations > 1);
    assert_eq!(after - before, 0, "Sdirk allocated during stepping");
}
