//! TR-BDF2 on the modal chain performs no heap allocation per step (counting global
//! allocator; a binary of its own so that no other test allocates meanwhile).

use modal::integrate::{Sdirk, Tolerances};

#[path = "support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

#[test]
fn sys_implicit_chain_steps_do_not_allocate() {
    // TR-BDF2 on the modal chain goes through the factored Newton linear algebra
    // (ChainRhs::newton_linearize / newton_factor / newton_solve): no allocation either.
    faer::set_global_parallelism(faer::Par::Seq);
    let scene = data::load_scene("barhorst-case1-tipmass").unwrap();
    let disc = data::Discretization {
        modes: Some(4),
        ..Default::default()
    };
    let chain =
        modal::setup::build_chain(scene.planar_chain().unwrap(), &disc.modal().unwrap()).unwrap();
    let mut f = modal::simulate::ChainRhs::new(chain);
    let mut y = f.initial_state();
    let dim = y.len();
    let tol = Tolerances {
        rtol: 1e-8,
        atol: 1e-10,
    };
    let mut s = Sdirk::new(dim, tol, None, None);
    let mut out = vec![0.0; dim];
    let mut t = 0.0;
    s.step(&mut f, &mut t, &mut y, 0.2).unwrap();
    let before = allocations();
    while t < 0.2 {
        s.step(&mut f, &mut t, &mut y, 0.2).unwrap();
        s.dense(t, &mut out);
    }
    s.state_changed();
    s.step(&mut f, &mut t, &mut y, 0.25).unwrap();
    let after = allocations();
    let st = *s.stats();
    assert!(
        st.steps > 50 && st.factorizations > 1 && st.jacobian_evals >= 1,
        "{st:?}"
    );
    assert_eq!(
        after - before,
        0,
        "Sdirk on the chain allocated during stepping"
    );
}
