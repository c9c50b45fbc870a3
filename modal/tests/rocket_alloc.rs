//! The rocket's right-hand side and integration steps perform no heap allocation (counting
//! global allocator; this binary holds only this test so nothing else allocates meanwhile).

use data::{Settings, load_scene};
use modal::integrate::{Dopri5, OdeRhs, Tolerances};
use modal::rocket::RocketOde;

#[path = "support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

#[test]
fn dyn_rocket_rhs_and_steps_do_not_allocate() {
    let scene = load_scene("rocket").unwrap();
    let mut ode = RocketOde::new(
        scene.rocket().unwrap(),
        &Settings::default().modal().unwrap(),
    )
    .unwrap();
    let mut y = ode.initial_state();
    let mut dydt = vec![0.0; ode.dim()];
    let mut s = Dopri5::new(
        ode.dim(),
        Tolerances {
            rtol: 1e-8,
            atol: 1e-10,
        },
        None,
        None,
    );
    let mut t = 0.0;
    s.step(&mut ode, &mut t, &mut y, 0.01).unwrap(); // warm-up
    let before = allocations();
    for k in 0..50 {
        ode.eval(1e-3 * k as f64, &y, &mut dydt);
    }
    for _ in 0..50 {
        s.step(&mut ode, &mut t, &mut y, 0.01).unwrap();
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in the step loop");
    assert!(t > 0.0 && dydt.iter().all(|v| v.is_finite()));
}
