//! Planar chain + settings → assumed-mode chain model (bases, integrals, joints), and the DOF
//! plan. Every function here takes the scene's [`PlanarChain`] (the backend's entry matches the
//! family once).

use data::scene::{Link, PlanarChain, PrescribedMotion};
use data::{Basis, DofPlan, ModalSettings, Scene};

use crate::basis::ShapeSet;
use crate::error::ModalError;
use crate::model::{Chain, JointModel, LinkIntegrals, LinkModel, Section, SectionParams};

/// Modes per link and field when `--modes` is absent.
pub const DEFAULT_MODES: usize = 6;
/// Largest accepted `--modes` (the eigenfunction bases stay accurate well beyond this; the
/// bound keeps set-up and the dense O(N³) solves small).
pub const MAX_MODES: usize = 40;

/// What a chain model is built for (modes of a spinning extensible link are not supported).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    Dynamics,
    Modes,
}

/// Rejects what this backend does not build for planar chains, with a precise message.
pub fn check_supported(pc: &PlanarChain, purpose: Purpose) -> Result<(), ModalError> {
    if pc.links.is_empty() {
        return Err(ModalError::Unsupported("modal: scene has no links".into()));
    }
    crate::contact::check(pc)?;
    for (i, l) in pc.links.iter().enumerate() {
        if l.shear && l.shear_stiffness.is_none() {
            return Err(ModalError::Unsupported(format!(
                "modal: link {} has `shear` on but no `shear_stiffness`",
                i + 1
            )));
        }
        if l.rotary_inertia && l.rotary_inertia_per_length.is_none() {
            return Err(ModalError::Unsupported(format!(
                "modal: link {} has `rotary_inertia` on but no `rotary_inertia_per_length`",
                i + 1
            )));
        }
        if l.shear && !l.rotary_inertia && l.tip_inertia.is_some_and(|j| j > 0.0) {
            return Err(ModalError::Unsupported(format!(
                "modal: Timoshenko link {} (`{}`) with a tip inertia but without section rotary \
                 inertia: the section rotation ψ would carry inertia only through ψ(L) (singular \
                 ψ mass, not condensable exactly); turn `rotary_inertia` on",
                i + 1,
                l.name
            )));
        }
        let spinning = l
            .joint
            .prescribed
            .as_ref()
            .is_some_and(|p| p.kinematics(0.0).1 != 0.0);
        if l.axial && purpose == Purpose::Modes && spinning {
            return Err(ModalError::Unsupported(format!(
                "modal: modes of the spinning extensible link {} (`{}`) need the centrifugally \
                 stretched steady state and gyroscopic terms, which are not implemented",
                i + 1,
                l.name
            )));
        }
        if l.axial && l.foreshortening {
            return Err(ModalError::Unsupported(format!(
                "modal: link {} has both `axial` and `foreshortening`; choose one",
                i + 1
            )));
        }
        if l.axial && l.axial_stiffness.is_none() {
            return Err(ModalError::Unsupported(format!(
                "modal: link {} has `axial` on but no `axial_stiffness`",
                i + 1
            )));
        }
        if i > 0 && l.joint.prescribed.is_some() {
            return Err(ModalError::Unsupported(format!(
                "modal: prescribed motion of joint {} (only the hub joint may be prescribed)",
                i + 1
            )));
        }
    }
    Ok(())
}

pub fn modes_per_link(settings: &ModalSettings) -> Result<usize, ModalError> {
    let n = settings.modes.unwrap_or(DEFAULT_MODES);
    if n == 0 || n > MAX_MODES {
        return Err(ModalError::invalid(
            "discretization.modes",
            format!("{n} modes per link: must be between 1 and {MAX_MODES}"),
        ));
    }
    Ok(n)
}

/// The default basis: `poly` for a scene whose links carry a tip load — a child link (any
/// chain of more than one link), a tip mass or inertia, or a tip contact — else
/// `clamped-free`. The clamped-free
/// functions all have zero end moment, shear and (axial) end force, so a tip load converges
/// slowly in them. Measured on `two-link-free` (10 s, 20 Hz low-passed joint-1 angle, largest
/// difference; fixed-step TR-BDF2 at h = 2.5e-4, whose own error is 2e-6): against fem
/// (16 elements, energy-midpoint) clamped-free 4 / 6 / 8 modes 4.4e-4 / 2.7e-4 / 2.0e-4 rad,
/// poly 4 / 6 / 8 / 10 / 12 modes 2.9e-4 / 1.5e-5 / 4.0e-5 / 4.0e-6 / 9.5e-6; against poly 12
/// poly 6 / 8 / 10 are 2.5e-5 / 4.9e-5 / 5.5e-6. `single-link` (tip mass, 3 s, Dormand–Prince
/// at the default tolerance) against poly 12: clamped-free 6 / 12 modes 7.7e-3 / 9.4e-4 rad,
/// poly 4 / 6 / 8 modes 1.5e-2 / 3.9e-4 / 5.2e-6. `constrained-arm` θ(2 s) with clamped-free
/// 3 / 6 modes 2.21 / 4.50e-2 rad, with poly 3 / 4 / 6 / 8 modes 1.43e-2 / 1.014e-2 /
/// 9.447e-3 / 9.460e-3 (fem: 9.39e-3); the `barhorst-case1` first impact at 6 modes is 2e-4
/// early with clamped-free, 1e-7 off fem with poly.
pub fn default_basis(pc: &PlanarChain) -> Basis {
    let tip_loaded = pc.links.len() > 1
        || !pc.contacts.is_empty()
        || pc
            .links
            .iter()
            .any(|l| l.tip_mass.is_some_and(|m| m > 0.0) || l.tip_inertia.is_some_and(|j| j > 0.0));
    if !tip_loaded {
        Basis::ClampedFree
    } else {
        Basis::Poly
    }
}

pub fn basis_choice(pc: &PlanarChain, settings: &ModalSettings) -> Result<Basis, ModalError> {
    let basis = settings.basis.unwrap_or_else(|| default_basis(pc));
    match basis {
        Basis::FreeFree => Err(ModalError::invalid(
            "discretization.basis",
            "`free-free` is the rocket's basis; links are clamped to their frames: use \
             `clamped-free`, `tip-mass` or `poly`",
        )),
        Basis::TipMass => {
            if let Some(l) = pc
                .links
                .iter()
                .find(|l| l.tip_mass.is_none() && l.tip_inertia.is_none())
            {
                Err(ModalError::invalid(
                    "discretization.basis",
                    format!(
                        "`tip-mass` needs a tip mass or tip inertia on every link; link `{}` has none",
                        l.name
                    ),
                ))
            } else {
                Ok(basis)
            }
        }
        _ => Ok(basis),
    }
}

fn shapes(link: &Link, index: usize, basis: Basis, n: usize) -> Result<ShapeSet, ModalError> {
    let l = link.length;
    match basis {
        Basis::Poly => Ok(ShapeSet::poly(l, n)),
        Basis::ClampedFree => ShapeSet::clamped_free(l, n).map_err(|source| ModalError::Basis {
            link: index + 1,
            source,
        }),
        Basis::TipMass => {
            let m = link.beam_mass();
            let mu = link.tip_mass.unwrap_or(0.0) / m;
            let j = link.tip_inertia.unwrap_or(0.0) / (m * l * l);
            ShapeSet::tip_mass(l, n, mu, j).map_err(|source| ModalError::Basis {
                link: index + 1,
                source,
            })
        }
        Basis::FreeFree => unreachable!("rejected by basis_choice"),
    }
}

/// Builds the chain model. Everything the scene leaves off is not allocated: no foreshortening
/// integrals without `foreshortening`, no tip terms without a tip mass, no gravity force without
/// `[gravity]`.
pub fn build_chain(pc: &PlanarChain, settings: &ModalSettings) -> Result<Chain, ModalError> {
    build_chain_for(pc, settings, Purpose::Dynamics)
}

/// Whether a Timoshenko link's v basis carries the root shear strain v'(0) (see
/// [`crate::model::section`]): only when the frame rotation cannot be traded for a root shear
/// at zero kinetic energy, i.e. the joint is prescribed or the sections have rotary inertia.
pub fn has_root_shear(link: &Link) -> bool {
    link.joint.prescribed.is_some() || link.rotary_inertia
}

/// The (v, ψ) shapes of a Timoshenko link, n each (see [`crate::model::section`]). With root
/// shear: `poly` → both span{ξ, …, ξⁿ}; eigenfunction bases → v ∈ {ξ, φ₁…φₙ₋₁},
/// ψ ∈ {ξ, φ₁'…φₙ₋₁'}. Without: `poly` → v ∈ span{ξ², …, ξⁿ⁺¹}, ψ ∈ span{ξ, …, ξⁿ};
/// eigenfunction bases → v ∈ {φ₁…φₙ}, ψ ∈ {φ₁'…φₙ'}.
fn timoshenko_shapes(
    link: &Link,
    index: usize,
    basis: Basis,
    n: usize,
) -> Result<(ShapeSet, ShapeSet), ModalError> {
    let root_shear = has_root_shear(link);
    match (basis, root_shear) {
        (Basis::Poly, true) => Ok((
            ShapeSet::axial_poly(link.length, n),
            ShapeSet::axial_poly(link.length, n),
        )),
        (Basis::Poly, false) => Ok((
            ShapeSet::poly(link.length, n),
            ShapeSet::axial_poly(link.length, n),
        )),
        (_, true) => {
            let base = shapes(link, index, basis, n - 1)?;
            Ok(ShapeSet::timoshenko_eigen_pair(base, true))
        }
        (_, false) => {
            let base = shapes(link, index, basis, n)?;
            Ok(ShapeSet::timoshenko_eigen_pair(base, false))
        }
    }
}

/// Axial shapes matching the transverse basis: clamped-free bar modes √2 sin((2k−1)πx/2L)
/// (exact for the bar without tip mass), or ξ·Pₖ(2ξ−1) for `poly`.
fn axial_shapes(link: &Link, basis: Basis, n: usize) -> ShapeSet {
    match basis {
        Basis::Poly => ShapeSet::axial_poly(link.length, n),
        _ => ShapeSet::axial_sine(link.length, n),
    }
}

pub fn build_chain_for(
    pc: &PlanarChain,
    settings: &ModalSettings,
    purpose: Purpose,
) -> Result<Chain, ModalError> {
    check_supported(pc, purpose)?;
    let n = modes_per_link(settings)?;
    let basis = basis_choice(pc, settings)?;
    let mut links = Vec::new();
    let mut joints = Vec::new();
    let mut offset = 0;
    for (i, l) in pc.links.iter().enumerate() {
        let (transverse, rotation) = if l.shear {
            let (v, psi) = timoshenko_shapes(l, i, basis, n)?;
            (v, Some(psi))
        } else {
            (shapes(l, i, basis, n)?, None)
        };
        let axial = l.axial.then(|| axial_shapes(l, basis, n));
        let ints = LinkIntegrals::new(
            l.length,
            l.mass_per_length,
            l.bending_stiffness,
            l.axial_stiffness.unwrap_or(0.0),
            &transverse,
            axial.as_ref(),
            l.foreshortening || l.axial,
        );
        let na = axial.as_ref().map_or(0, |a| a.count());
        let params = SectionParams {
            ei: l.bending_stiffness,
            shear_stiffness: l.shear_stiffness.filter(|_| l.shear),
            rho_i: l.rotary_inertia_per_length.filter(|_| l.rotary_inertia),
            kelvin_voigt: l.kelvin_voigt.filter(|g| *g > 0.0),
        };
        let section = match (&rotation, params.shear_stiffness) {
            (Some(chi), Some(kga)) => {
                Section::timoshenko(na, &transverse, chi, params, kga, params.rho_i.is_none())
                    .map_err(|m| ModalError::Numerical {
                        t: 0.0,
                        message: format!("link {}: {m}", i + 1),
                    })?
            }
            _ => Section::euler(na, &transverse, &ints.kb, params),
        };
        let theta = offset;
        let a0 = offset + 1;
        let b0 = a0 + na;
        offset = b0 + transverse.count() + section.nc;
        links.push(LinkModel {
            name: l.name.clone(),
            transverse,
            axial,
            ints,
            // An axial field is the stretch beside the foreshortening (crate::model::body).
            foreshortening: l.foreshortening || l.axial,
            tip_mass: l.tip_mass.unwrap_or(0.0),
            tip_inertia: l.tip_inertia.unwrap_or(0.0),
            hub_inertia: l.joint.hub_inertia.unwrap_or(0.0),
            section,
            theta,
            a0,
            b0,
        });
        let j = &l.joint;
        joints.push(JointModel {
            initial_angle: j.initial_angle,
            initial_rate: j.initial_rate,
            stiffness: j.stiffness.unwrap_or(0.0),
            set_point: j.set_point.unwrap_or(0.0),
            damping: j.damping.unwrap_or(0.0),
            torque: j.torque.clone(),
            prescribed: j.prescribed.clone(),
        });
    }
    let gravity = pc.gravity.as_ref().map(|g| g.vector);
    let mut chain = Chain::new(links, joints, gravity);
    chain
        .attach_elbows()
        .map_err(|message| ModalError::Numerical { t: 0.0, message })?;
    if purpose == Purpose::Dynamics {
        chain.step_load = step_load(pc, &chain)?;
    }
    Ok(chain)
}

/// The scene's `[statics]` loads as the constant generalized force of a step load (as fem
/// applies them in dynamics): tip force P along the link frame's y and uniform load q per unit
/// length, on the transverse coordinates b of a single clamped link,
/// f_b = P φ(L) + q ∫₀ᴸ φ dx.
fn step_load(pc: &PlanarChain, chain: &Chain) -> Result<Option<Vec<f64>>, ModalError> {
    let Some(st) = &pc.statics else {
        return Ok(None);
    };
    let (p, q) = (
        st.tip_force.unwrap_or(0.0),
        st.distributed_load.unwrap_or(0.0),
    );
    if p == 0.0 && q == 0.0 {
        return Ok(None);
    }
    let Some(link) = single_clamped_link(pc) else {
        return Err(ModalError::Unsupported(
            "modal: the [statics] loads act in dynamics only on a single clamped link".into(),
        ));
    };
    let l = &chain.links[0];
    let mut f = vec![0.0; chain.n];
    f[l.b0..l.b0 + l.nb()].copy_from_slice(&transverse_load(link, l, p, q));
    Ok(Some(f))
}

/// Generalized force of a tip force P and a uniform load q (per unit length) on the transverse
/// coordinates of `l`, the model of the scene's `link`: P φ(L) + q ∫₀ᴸ φ dx.
/// The link of a chain that is one link clamped to the ground (the statics loads' model).
pub(crate) fn single_clamped_link(pc: &PlanarChain) -> Option<&Link> {
    match pc.links.as_slice() {
        [link] if matches!(link.joint.prescribed, Some(PrescribedMotion::Fixed)) => Some(link),
        _ => None,
    }
}

pub(crate) fn transverse_load(link: &Link, l: &LinkModel, p: f64, q: f64) -> Vec<f64> {
    // `phi1` is the mass-weighted ∫ρA φ.
    let q_per_mass = q / link.mass_per_length;
    (0..l.nb())
        .map(|i| p * l.ints.phi_l[i] + q_per_mass * l.ints.phi1[i])
        .collect()
}

/// The DOFs of the model a run integrates (`modes` may refuse a scene a run accepts: the
/// spinning extensible link, [`check_supported`]).
pub fn dof_plan(pc: &PlanarChain, settings: &ModalSettings) -> Result<DofPlan, ModalError> {
    check_supported(pc, Purpose::Dynamics)?;
    let n = modes_per_link(settings)?;
    let basis = basis_choice(pc, settings)?;
    let mut plan = DofPlan::default();
    for (i, l) in pc.links.iter().enumerate() {
        let k = i + 1;
        if l.joint.prescribed.is_none() {
            plan.add(format!("joint{k} angle"), 1);
        }
        if l.axial {
            plan.add(format!("link{k} axial modes"), n);
            plan.builds.push(format!(
                "link{k}: axial stretch field beside the foreshortening (von Kármán strain \
                     u' + ½v'² = stretch')"
            ));
        }
        plan.add(format!("link{k} transverse modes ({})", basis.name()), n);
        if l.shear {
            if l.rotary_inertia {
                plan.add(format!("link{k} section-rotation modes ψ"), n);
                plan.builds.push(format!(
                    "link{k}: Timoshenko shear ½∫κGA(v' − ψ)², bending ½∫EI ψ'², rotary inertia ρI"
                ));
            } else {
                plan.builds.push(format!(
                    "link{k}: Timoshenko shear ½∫κGA(v' − ψ)², bending ½∫EI ψ'²; massless ψ \
                     condensed (ψ = χᵀT b, {n} ψ shapes)"
                ));
            }
        } else if l.rotary_inertia {
            plan.builds.push(format!(
                "link{k}: rotary inertia ρI of the sections (ψ = v')"
            ));
        }
        if l.foreshortening {
            plan.builds
                .push(format!("link{k}: foreshortening (centrifugal) stiffening"));
        }
        if l.tip_mass.is_some() {
            plan.builds.push(format!("link{k}: tip mass"));
        }
        if l.tip_inertia.is_some() {
            plan.builds.push(format!("link{k}: tip inertia"));
        }
        if l.kelvin_voigt.is_some() {
            plan.builds.push(if l.shear {
                format!("link{k}: Kelvin-Voigt damping on ψ' (no shear damping)")
            } else {
                format!("link{k}: Kelvin-Voigt damping")
            });
        }
        let j = &l.joint;
        if j.hub_inertia.is_some() {
            plan.builds.push(format!("joint{k}: hub inertia"));
        }
        if j.stiffness.is_some_and(|v| v > 0.0) {
            plan.builds.push(format!("joint{k}: spring"));
        }
        if j.damping.is_some_and(|v| v > 0.0) {
            plan.builds.push(format!("joint{k}: damper"));
        }
        if j.torque.is_some() {
            plan.builds.push(format!("joint{k}: applied torque"));
        }
        if j.prescribed.is_some() {
            plan.builds
                .push(format!("joint{k}: prescribed motion (torque reported)"));
        }
    }
    if pc.gravity.is_some() {
        plan.builds.push("gravity".into());
    }
    for (c, ct) in pc.contacts.iter().enumerate() {
        if ct.mode == data::scene::ContactMode::Bilateral {
            plan.builds.push(format!(
                "contact{}: bilateral tip contact of `{}` (constraint g = 0 for all time, \
                 multiplier λ = normal force; Coulomb friction μ = {} with located stick–slip \
                 events, tip held by a second constraint while sticking; drift control by \
                 projection)",
                c + 1,
                ct.link,
                ct.friction
            ));
            continue;
        }
        plan.builds.push(format!(
            "contact{}: unilateral frictionless tip contact of `{}` (gap event, plastic impact \
             M(q̇⁺−q̇⁻) = GᵀΛ; while sliding 1 constraint G q̈ = −Ġq̇ with multiplier λ = normal \
             force, i.e. one fewer DOF; drift control by projection)",
            c + 1,
            ct.link
        ));
    }
    Ok(plan)
}

/// The run's end time (settings override the scene), after checking it and any user step.
pub(crate) fn checked_span(
    scene: &Scene,
    settings: &data::ModalSettings,
) -> Result<f64, ModalError> {
    let t_end = settings.t_end.unwrap_or(scene.simulation.t_end);
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(ModalError::invalid(
            "time.t_end",
            format!("{t_end} is not a positive time"),
        ));
    }
    if let Some(dt) = settings.dt
        && !(dt > 0.0 && dt.is_finite())
    {
        return Err(ModalError::invalid(
            "time.dt",
            format!("{dt} is not a positive step"),
        ));
    }
    Ok(t_end)
}
