//! Analytic reference values by id, computed from the scene's own parameters by
//! [`crate::analytic`] (root finding, series, shooting — never typed-in numbers).
//!
//! Each reference is built from its family's type (`PlanarChain`, `Rocket`, `PayloadLink`);
//! the match on `scene.model` happens here, and a scene of another family gets the reference's
//! own refusal.
//!
//! | id | quantity | reference |
//! |---|---|---|
//! | `clamped-free` | `freqN`, `bending_freqN` | uniform Euler–Bernoulli cantilever, 1 + cos βL cosh βL = 0 |
//! | `tip-mass` | `freqN`, `bending_freqN` | cantilever with the scene's tip mass and tip inertia |
//! | `timoshenko` | `freqN`, `bending_freqN` | clamped-free Timoshenko beam (κGA, ρI) |
//! | `axial-clamped-free` | `axial_freqN` | clamped-free bar (with tip mass when present) |
//! | `rotating-in-plane` | `freqN` | in-plane bending of the cantilever at the scene's hub rate Ω: ω² = ω_flap² − Ω² (Frobenius series) |
//! | `static-linear` | `tip_static` | PL³/3EI + qL⁴/8EI for the scene's `[statics]` loads |
//! | `spring-jointed-chain` | `freqN`, `bending_freqN` | straight chain of Euler–Bernoulli links with the scene's joint springs, hub and tip bodies, linearized about the set points (exact dynamic stiffness, Wittrick–Williams count; `freqN` counts rigid modes as 0) |
//! | `chain-clamped-limit` | `freqN`, `bending_freqN` | that chain with every joint rigid (K → ∞): clamped–free beam of length ΣLᵢ |
//! | `chain-pinned-limit` | `freqN`, `bending_freqN` | root joint free (K₁ → 0), the others rigid: pinned–free beam of length ΣLᵢ, rigid mode first |
//! | `rigid-single-link` | `joint1.angle@T`, `joint1.rate@T` | rigid link + hub + tip mass under the torque law (closed form) |
//! | `rigid-two-link` | `jointI.angle@T`, `jointI.rate@T` | rigid two-link arm with the scene's springs/dampers (tight RK) |
//! | `payload-horizontal` | `bending-horizontal_freqN` | 3-D link: bending in the turning plane with the payload's mass, offset and I₃ (hub-coupled for a free base, rotating at a constant rate) |
//! | `payload-vertical` | `bending-vertical_freqN` | 3-D link: vertical bending with the payload's mass, offset and I₂ (rotating at a constant rate) |
//! | `payload-torsion` | `torsion_freqN` | 3-D link: ζ tan ζ = ρJL/I₁ |
//! | `payload-axial` | `axial_freqN` | 3-D link: ζ tan ζ = ρAL/m, softened by the base rate |
//! | `payload-static-sag` | `tip_static` | 3-D link: linear sag w_L under self-weight, payload weight and its offset moment |
//! | `payload-rigid-base` | `joint1.angle@T`, `joint1.rate@T` | 3-D link, E, G → ∞: (I_B + ρAL³/3 + ρIL + m(L + c)² + I₃) θ̈ = T_mot − b_m θ̇ |
//! | `constrained-rigid-link` | `joint1.angle@T`, `joint1.rate@T`, `contact1.normal_force@T`, `contact1.friction_work@T` | rigid link on the bilateral wall with Coulomb friction |
//! | `tip-mass-momentum-limit` | `impulse_excessN` | 0: the impulse of a point impact on a refined beam tends to m_tip·\|v_n⁻\| |
//! | `rocket-translation` | `rocket.vX@T`, `rocket.vY@T`, `rocket.mass@T` | rocket equation with gravity: material (momentum / mass) velocity |
//! | `rocket-free-free` | `freqN`, `bending_freqN`, `axial_freqN` | rocket at ignition: stepped free-free beam with the spring-mounted, spring-coupled masses (exact dynamic stiffness, Wittrick–Williams count) |
//! | `rocket-free-vibration` | `history:rocket.w@K`, `history:rocket.massJ.w` (and low-passed) | the rocket without mass flow, pressure or dampers, released from its initial shape: superposition of the first 64 exact free-free modes, relative to the mean axis |

use data::Scene;
use data::scene::{Link, Model, PayloadLink, PlanarChain, PrescribedMotion, Rocket};

use super::quantity::Quantity;
use crate::analytic as ana;

/// The planar chain of a scene; for the other families the reference's own refusal `why`.
fn planar_chain(scene: &Scene, why: impl FnOnce() -> String) -> Result<&PlanarChain, String> {
    match &scene.model {
        Model::PlanarChain(c) => Ok(c),
        Model::Rocket(_) | Model::PayloadLink(_) | Model::MobileManipulator(_) => {
            Err(ana::AnalyticError::Unsupported(why()).to_string())
        }
    }
}

/// The rocket of a scene; for the other families the reference's own refusal `why`.
fn rocket(scene: &Scene, why: impl FnOnce() -> String) -> Result<&Rocket, String> {
    match &scene.model {
        Model::Rocket(r) => Ok(r),
        Model::PlanarChain(_) | Model::PayloadLink(_) | Model::MobileManipulator(_) => {
            Err(ana::AnalyticError::Unsupported(why()).to_string())
        }
    }
}

fn not_a_rocket(scene: &Scene) -> String {
    format!("`{}` is not a rocket scene", scene.name)
}

/// The planar chain of a single-link scene and its link.
fn single_link(scene: &Scene) -> Result<(&PlanarChain, &Link), String> {
    let links = match &scene.model {
        Model::PlanarChain(c) => match c.links.as_slice() {
            [l] => return Ok((c, l)),
            links => links.len(),
        },
        Model::Rocket(_) | Model::PayloadLink(_) | Model::MobileManipulator(_) => 0,
    };
    Err(format!(
        "this analytic reference needs a single-link scene; `{}` has {links} links",
        scene.name
    ))
}

fn payload_link(scene: &Scene) -> Result<&PayloadLink, String> {
    match &scene.model {
        Model::PayloadLink(p) => Ok(p),
        Model::PlanarChain(_) | Model::Rocket(_) | Model::MobileManipulator(_) => Err(format!(
            "this analytic reference needs a [payload_link] scene; `{}` is not one",
            scene.name
        )),
    }
}

fn mode_number(q: &Quantity, want_kind: Option<&str>) -> Result<usize, String> {
    match q {
        Quantity::Frequency { n, kind } if kind.as_deref() == want_kind || kind.is_none() => Ok(*n),
        _ => Err(format!(
            "this reference applies to frequencies{}",
            want_kind.map_or(String::new(), |k| format!(" of kind `{k}`"))
        )),
    }
}

/// The channel and time of a `CHANNEL@T` quantity, which reference `id` needs.
fn channel_at<'q>(id: &str, q: &'q Quantity) -> Result<(&'q String, f64), String> {
    match q {
        Quantity::At { channel, t } => Ok((channel, *t)),
        _ => Err(format!("`{id}` applies to CHANNEL@T")),
    }
}

fn nth(v: ana::Result<Vec<f64>>, n: usize) -> Result<f64, String> {
    let v = v.map_err(|e| e.to_string())?;
    v.get(n - 1)
        .copied()
        .ok_or_else(|| format!("the reference has no mode {n}"))
}

/// An analytic reference: the value of a quantity for a scene (`id` names which of a shared
/// family's references is meant).
type Reference = fn(&str, &Scene, &Quantity) -> Result<f64, String>;

/// Every analytic reference by id, in the order an unknown id's message lists them.
const REFERENCES: [(&str, Reference); 21] = [
    ("clamped-free", clamped_free),
    ("tip-mass", tip_mass),
    ("timoshenko", timoshenko),
    ("axial-clamped-free", axial_clamped_free),
    ("rotating-in-plane", rotating_in_plane),
    ("spring-jointed-chain", spring_jointed_chain),
    ("chain-clamped-limit", spring_jointed_chain),
    ("chain-pinned-limit", spring_jointed_chain),
    ("static-linear", static_linear),
    ("rigid-single-link", rigid_single_link),
    ("rigid-two-link", rigid_two_link),
    ("constrained-rigid-link", constrained_rigid_link),
    ("rocket-translation", rocket_translation),
    ("rocket-free-free", rocket_free_free),
    ("tip-mass-momentum-limit", tip_mass_momentum_limit),
    ("payload-horizontal", payload_bending),
    ("payload-vertical", payload_bending),
    ("payload-torsion", payload_torsion),
    ("payload-axial", payload_axial),
    ("payload-static-sag", payload_static_sag),
    ("payload-rigid-base", payload_rigid_base),
];

/// The analytic value of a quantity for a scene.
pub fn analytic_value(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    match REFERENCES.iter().find(|(name, _)| *name == id) {
        Some((_, reference)) => reference(id, scene, q),
        None => Err(format!(
            "unknown analytic reference `{id}`; known: {}",
            REFERENCES.map(|(name, _)| name).join(", ")
        )),
    }
}

/// The impulse of a point impact on a refined beam tends to the tip mass's momentum: its
/// relative excess over m_tip·|v_n⁻| vanishes.
fn tip_mass_momentum_limit(_id: &str, _scene: &Scene, q: &Quantity) -> Result<f64, String> {
    match q {
        Quantity::ImpulseExcess { .. } => Ok(0.0),
        _ => Err("`tip-mass-momentum-limit` is the limit of `impulse_excessN` only".into()),
    }
}

/// Uniform Euler–Bernoulli cantilever.
fn clamped_free(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (_, l) = single_link(scene)?;
    let n = mode_number(q, Some("bending"))?;
    nth(
        ana::bending_frequencies_hz(
            ana::BeamSupport::ClampedFree,
            l.bending_stiffness,
            l.mass_per_length,
            l.length,
            n,
        ),
        n,
    )
}

/// Cantilever with the scene's tip mass and tip inertia.
fn tip_mass(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (_, l) = single_link(scene)?;
    let n = mode_number(q, Some("bending"))?;
    nth(
        ana::cantilever_tip_mass_frequencies_hz(
            l.bending_stiffness,
            l.mass_per_length,
            l.length,
            l.tip_mass.unwrap_or(0.0),
            l.tip_inertia.unwrap_or(0.0),
            n,
        ),
        n,
    )
}

/// Clamped-free Timoshenko beam.
fn timoshenko(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (_, l) = single_link(scene)?;
    let n = mode_number(q, Some("bending"))?;
    let beam = ana::TimoshenkoBeam {
        kappa_ga: l
            .shear_stiffness
            .ok_or("the scene has no shear_stiffness")?,
        ei: l.bending_stiffness,
        rho_a: l.mass_per_length,
        rho_i: if l.rotary_inertia {
            l.rotary_inertia_per_length.unwrap_or(0.0)
        } else {
            0.0
        },
        length: l.length,
    };
    nth(ana::timoshenko_clamped_free_hz(&beam, n), n)
}

/// Clamped-free bar (with the tip mass when present).
fn axial_clamped_free(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (_, l) = single_link(scene)?;
    let n = mode_number(q, Some("axial"))?;
    let ea = l
        .axial_stiffness
        .ok_or("the scene has no axial_stiffness")?;
    match l.tip_mass {
        Some(m) => nth(
            ana::axial_tip_mass_frequencies_hz(ea, l.mass_per_length, l.length, m, n),
            n,
        ),
        None => nth(
            ana::axial_frequencies_hz(ea, l.mass_per_length, l.length, n),
            n,
        ),
    }
}

/// In-plane bending of the cantilever at the hub's constant rate.
fn rotating_in_plane(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (_, l) = single_link(scene)?;
    let n = mode_number(q, Some("bending"))?;
    let omega = match l.joint.prescribed {
        Some(PrescribedMotion::ConstantRate { rate }) => rate,
        Some(PrescribedMotion::Fixed) => 0.0,
        _ => {
            return Err("the rotating-beam reference needs a constant-rate or fixed hub".into());
        }
    };
    if l.tip_mass.is_some() || l.axial {
        return Err("the rotating-beam reference covers the uniform inextensible beam only".into());
    }
    nth(
        ana::rotating_frequencies_hz(
            ana::RotatingPlane::InPlane,
            l.bending_stiffness,
            l.mass_per_length,
            l.length,
            omega,
            n,
        ),
        n,
    )
}

/// The spring-jointed chain and its clamped (K → ∞) and pinned (K₁ → 0) limits.
fn spring_jointed_chain(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let chain = planar_chain(scene, || {
        format!(
            "the spring-jointed chain needs a planar link chain; `{}` has no [[link]]",
            scene.name
        )
    })?;
    let chain = ana::SpringJointedChain::from_chain(chain).map_err(|e| e.to_string())?;
    let (n, bending_only) = match q {
        Quantity::Frequency { n, kind: None } => (*n, false),
        Quantity::Frequency { n, kind: Some(k) } if k == "bending" => (*n, true),
        _ => return Err(format!("`{id}` applies to `freqN` and `bending_freqN`")),
    };
    let rigid = match id {
        "spring-jointed-chain" => chain.rigid_modes(),
        "chain-pinned-limit" => 1,
        _ => 0,
    };
    let count = if bending_only { n + rigid } else { n };
    let all = match id {
        "spring-jointed-chain" => chain.frequencies_hz(count),
        "chain-clamped-limit" => chain.clamped_limit_hz(count),
        _ => chain.pinned_limit_hz(count),
    };
    nth(all, count)
}

/// Linear static tip deflection under the scene's `[statics]` loads.
fn static_linear(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    if !matches!(q, Quantity::StaticTip) {
        return Err("`static-linear` applies to `tip_static`".into());
    }
    let (chain, l) = single_link(scene)?;
    let st = chain
        .statics
        .as_ref()
        .ok_or("the scene has no [statics] loads")?;
    let mut w = 0.0;
    if let Some(p) = st.tip_force {
        w += ana::cantilever_tip_load(p, l.bending_stiffness, l.length)
            .map_err(|e| e.to_string())?
            .deflection;
    }
    if let Some(qd) = st.distributed_load {
        w += ana::cantilever_uniform_load(qd, l.bending_stiffness, l.length)
            .map_err(|e| e.to_string())?
            .deflection;
    }
    Ok(w)
}

/// Rigid link, hub and tip mass under the torque law.
fn rigid_single_link(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (channel, t) = channel_at(id, q)?;
    let chain = planar_chain(scene, || {
        "rigid single-link reference: the scene must have exactly one link".into()
    })?;
    let st = ana::RigidLink::from_chain(chain)
        .and_then(|r| r.state(t))
        .map_err(|e| e.to_string())?;
    offered_channel(
        id,
        channel,
        [
            (data::channel::joint_angle(1), st.angle),
            (data::channel::joint_rate(1), st.rate),
        ],
    )
}

/// Rigid two-link arm with the scene's springs and dampers.
fn rigid_two_link(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (channel, t) = channel_at(id, q)?;
    let chain = planar_chain(scene, || {
        "rigid two-link reference: the scene must have exactly two links".into()
    })?;
    let h = ana::RigidTwoLink::from_chain(chain)
        .and_then(|r| r.simulate(&[0.0, t]))
        .map_err(|e| e.to_string())?;
    let last = |v: &Vec<f64>| v.last().copied().ok_or("empty rigid history".to_string());
    offered_channel(
        id,
        channel,
        [
            (data::channel::joint_angle(1), last(&h.q1)?),
            (data::channel::joint_angle(2), last(&h.q5)?),
        ],
    )
}

/// Rigid link on the bilateral wall with Coulomb friction.
fn constrained_rigid_link(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (channel, t) = channel_at(id, q)?;
    let chain = planar_chain(scene, || {
        "constrained rigid link: the scene must have exactly one link".into()
    })?;
    let st = ana::ConstrainedRigidLink::from_chain(chain)
        .and_then(|r| r.state(t))
        .map_err(|e| e.to_string())?;
    offered_channel(
        id,
        channel,
        [
            (data::channel::joint_angle(1), st.angle),
            (data::channel::joint_rate(1), st.rate),
            (data::channel::contact_normal_force(1), st.normal_force),
            (data::channel::contact_friction_work(1), st.friction_work),
        ],
    )
}

/// Rocket equation with gravity: the material velocity and the mass.
fn rocket_translation(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (channel, t) = channel_at(id, q)?;
    let r = rocket(scene, || {
        "rocket translation: the scene has no [rocket]".into()
    })?;
    let st = ana::RocketTranslation::from_rocket(r)
        .and_then(|r| r.state(t))
        .map_err(|e| e.to_string())?;
    offered_channel(
        id,
        channel,
        [
            (data::channel::ROCKET_VX.to_string(), st.body_vx),
            (data::channel::ROCKET_VY.to_string(), st.body_vy),
            (data::channel::ROCKET_MASS.to_string(), st.mass),
        ],
    )
}

/// Rocket at ignition: stepped free-free beam with its spring-mounted masses.
fn rocket_free_free(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    use ana::rocket_modes::{FreeFreeRocket, Motion};
    let Quantity::Frequency { n, kind } = q else {
        return Err(
            "`rocket-free-free` applies to `freqN`, `bending_freqN` and `axial_freqN`".into(),
        );
    };
    let r = rocket(scene, || not_a_rocket(scene))?;
    let body = FreeFreeRocket::from_rocket(r).map_err(|e| e.to_string())?;
    let of = |m: Motion| body.frequencies_hz(m, *n);
    match kind.as_deref() {
        Some("axial") => nth(of(Motion::Axial), *n),
        Some("bending") => nth(of(Motion::Transverse), *n),
        // both fields merged into one ascending spectrum
        None => {
            let mut all = of(Motion::Axial).map_err(|e| e.to_string())?;
            all.extend(of(Motion::Transverse).map_err(|e| e.to_string())?);
            all.sort_by(f64::total_cmp);
            nth(Ok(all), *n)
        }
        Some(other) => Err(format!(
            "`rocket-free-free` has axial and bending modes, not `{other}`"
        )),
    }
}

/// 3-D link: bending in the turning plane or vertical bending.
fn payload_bending(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let p = payload_link(scene)?;
    let plane_name = id.trim_start_matches("payload-");
    let n = mode_number(q, Some(&format!("bending-{plane_name}")))?;
    let plane = if plane_name == "horizontal" {
        ana::payload_link::BendingPlane::horizontal(p)
    } else {
        ana::payload_link::BendingPlane::vertical(p)
    };
    nth(plane.and_then(|pl| pl.frequencies_hz(n)), n)
}

/// 3-D link: torsion.
fn payload_torsion(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let p = payload_link(scene)?;
    let n = mode_number(q, Some("torsion"))?;
    nth(ana::payload_link::torsion_frequencies_hz(p, n), n)
}

/// 3-D link: axial vibration.
fn payload_axial(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let p = payload_link(scene)?;
    let n = mode_number(q, Some("axial"))?;
    nth(ana::payload_link::axial_frequencies_hz(p, n), n)
}

/// 3-D link: linear sag under self-weight, payload weight and its offset moment.
fn payload_static_sag(_id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    if !matches!(q, Quantity::StaticTip) {
        return Err("`payload-static-sag` applies to `tip_static` (w_L)".into());
    }
    let p = payload_link(scene)?;
    if p.gravity.is_none_or(|g| g == 0.0) {
        return Err("the scene has no gravity: no sag".into());
    }
    Ok(ana::payload_link::linear_sag(p)
        .map_err(|e| e.to_string())?
        .0)
}

/// 3-D link with E, G → ∞: the rigid base motion.
fn payload_rigid_base(id: &str, scene: &Scene, q: &Quantity) -> Result<f64, String> {
    let (channel, t) = channel_at(id, q)?;
    let (angle, rate) = ana::payload_link::RigidPayloadBase::from_link(payload_link(scene)?)
        .and_then(|r| r.state(t))
        .map_err(|e| e.to_string())?;
    offered_channel(
        id,
        channel,
        [
            (data::channel::joint_angle(1), angle),
            (data::channel::joint_rate(1), rate),
        ],
    )
}

/// Expansion length of `rocket-free-vibration`: the initial state's ⟨·⟩-norm residual falls
/// like N^−3.5 (the shape's third derivative does not vanish at the free ends). On the catalog
/// rocket 64 modes leave 2.1e-5 of it, and their histories lie 1.6e-10 (mass 1) and 3e-5 (nose)
/// of peak from 128 modes' (verify/tests/analytic_rocket_free_vibration.rs).
const FREE_VIBRATION_MODES: usize = 64;

/// An analytic reference history of `channel` at `times` (`history:` quantities).
pub fn analytic_history(
    id: &str,
    scene: &Scene,
    channel: &str,
    times: &[f64],
) -> Result<Vec<f64>, String> {
    match id {
        "rocket-free-vibration" => {
            let r = rocket(scene, || not_a_rocket(scene))?;
            let fv = ana::rocket_modes::FreeVibration::from_rocket(r, FREE_VIBRATION_MODES)
                .map_err(|e| e.to_string())?;
            let stations = scene.simulation.field_stations;
            let mass = (1..=r.discrete_masses.len())
                .find(|&j| data::channel::rocket_mass_transverse(j) == channel);
            let station = (0..stations).find(|&k| data::channel::rocket_transverse(k) == channel);
            let at = match (mass, station) {
                (Some(_), _) => vec![],
                (None, Some(k)) => vec![r.length() * k as f64 / (stations - 1).max(1) as f64],
                (None, None) => {
                    return Err(format!(
                        "`rocket-free-vibration` gives `rocket.w@K` and `rocket.massJ.w`, not `{channel}`"
                    ));
                }
            };
            Ok(times
                .iter()
                .map(|&t| {
                    let st = fv.state(t, &at);
                    match mass {
                        Some(j) => st.masses[j - 1],
                        None => st.stations[0],
                    }
                })
                .collect())
        }
        other => Err(format!(
            "`{other}` has no reference history; analytic histories: rocket-free-vibration"
        )),
    }
}

/// The analytic reference that naturally applies to a quantity on a scene, if any.
pub fn default_analytic_id(scene: &Scene, q: &Quantity) -> Option<String> {
    let chain = match &scene.model {
        Model::PlanarChain(c) => c,
        Model::Rocket(_) => return rocket_default_id(q),
        Model::PayloadLink(_) => return payload_link_default_id(q),
        Model::MobileManipulator(_) => return None,
    };
    let [l] = chain.links.as_slice() else {
        return None;
    };
    let clamped = matches!(l.joint.prescribed, Some(PrescribedMotion::Fixed));
    let spinning = matches!(
        l.joint.prescribed,
        Some(PrescribedMotion::ConstantRate { .. })
    );
    let id = match q {
        Quantity::Frequency { kind, .. } if kind.as_deref() == Some("axial") && clamped => {
            "axial-clamped-free"
        }
        Quantity::Frequency { kind, .. } if kind.as_deref() != Some("axial") => {
            if clamped && l.shear {
                "timoshenko"
            } else if clamped && (l.tip_mass.is_some() || l.tip_inertia.is_some()) {
                "tip-mass"
            } else if clamped {
                "clamped-free"
            } else if spinning && !l.axial && l.tip_mass.is_none() {
                "rotating-in-plane"
            } else {
                return None;
            }
        }
        Quantity::StaticTip if clamped => "static-linear",
        _ => return None,
    };
    Some(id.to_string())
}

/// The default reference of a rocket quantity: its free-free spectrum.
fn rocket_default_id(q: &Quantity) -> Option<String> {
    match q {
        Quantity::Frequency { kind, .. }
            if kind
                .as_deref()
                .is_none_or(|k| k == "bending" || k == "axial") =>
        {
            Some("rocket-free-free".to_string())
        }
        _ => None,
    }
}

/// The default reference of a payload-link quantity: the matching 3-D link spectrum or sag.
fn payload_link_default_id(q: &Quantity) -> Option<String> {
    match q {
        Quantity::Frequency {
            kind: Some(kind), ..
        } if ["bending-horizontal", "bending-vertical", "torsion", "axial"]
            .contains(&kind.as_str()) =>
        {
            Some(format!("payload-{}", kind.trim_start_matches("bending-")))
        }
        Quantity::StaticTip => Some("payload-static-sag".to_string()),
        _ => None,
    }
}

/// The value of `channel` among the channels a reference offers, or an error naming them.
fn offered_channel<const N: usize>(
    id: &str,
    channel: &str,
    offered: [(String, f64); N],
) -> Result<f64, String> {
    if let Some((_, v)) = offered.iter().find(|(name, _)| name == channel) {
        return Ok(*v);
    }
    let names: Vec<&str> = offered.iter().map(|(name, _)| name.as_str()).collect();
    Err(format!(
        "`{id}` has no channel `{channel}` ({})",
        names.join(", ")
    ))
}
