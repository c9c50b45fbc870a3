//! Linear statics of a clamped single link: K_b b = P φ(L) + q ∫φ (Ritz; exact tip deflection
//! PL³/3EI is reached as the basis is refined, and the polynomial basis with n ≥ 3 contains the
//! exact cubic tip-load solution).

use data::scene::PlanarChain;
use data::{Cost, ModalSettings, Scene, StaticResult};

use crate::error::ModalError;
use crate::linalg::{cholesky_solve, dot};
use crate::setup::{build_chain, single_clamped_link, transverse_load};

/// The static tip deflection and rotation of `pc`, the chain of `scene`.
pub fn statics(
    scene: &Scene,
    pc: &PlanarChain,
    settings: &ModalSettings,
) -> Result<StaticResult, ModalError> {
    let wall = std::time::Instant::now();
    let Some(loads) = &pc.statics else {
        return Err(ModalError::Unsupported(
            "modal: the scene has no [statics] loads".into(),
        ));
    };
    let Some(link) = single_clamped_link(pc) else {
        return Err(ModalError::Unsupported(
            "modal: statics only for a single link clamped to the ground".into(),
        ));
    };
    let chain = build_chain(pc, settings)?;
    let l = &chain.links[0];
    let nb = l.nb();
    let nbc = l.nbc();
    // Bending block [b, c] (c: Timoshenko section rotations); loads act on v only.
    let mut k = l.section.kbc.clone();
    let p = loads.tip_force.unwrap_or(0.0);
    let q = loads.distributed_load.unwrap_or(0.0);
    let mut b = transverse_load(link, l, p, q);
    b.resize(nbc, 0.0);
    cholesky_solve(&mut k, nbc, &mut b).map_err(|_| ModalError::Numerical {
        t: 0.0,
        message: "bending stiffness matrix not positive definite".into(),
    })?;
    Ok(StaticResult {
        backend: data::BackendKind::Modal,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        tip_deflection: dot(&l.ints.phi_l, &b[..nb]),
        // ψ(L) = r(L)ᵀ[b, c] (= v′(L) for Euler links).
        tip_rotation: dot(&l.section.rot_l[l.na()..], &b),
        cost: Cost {
            wall_time_s: wall.elapsed().as_secs_f64(),
            dofs: nbc,
            ..Cost::default()
        },
    })
}
