//! Construction of the chain from a planar chain of the scene (the checks of what the model
//! carries, the lumped masses and segment weights, the constant ghost columns of M, the step
//! bound's frequencies at t = 0), its DOF plan and its initial state.

use data::scene::{Link, PlanarChain};
use data::{DofPlan, Scene};

use super::kinetic::{BE, ChainInertia, TH};
use super::kinetic::{Lanes, PointScratch, RateLanes};
use super::model::{JointLaw, LinkProps, SplitReuse, TwoLinkChain};
use super::rates::LinkRates;
use super::rates::MassFactors;
use super::schur::{MAX_SMALL, SmallLu};
use super::surface::{TipConstraint, TipContact};
use super::timoshenko::{self, TimoFields};
use crate::error::FdmError;
use crate::system::System;

/// Default stations per link.
pub const DEFAULT_STATIONS: usize = 21;

fn check_link(name: &str, l: &Link) -> Result<(), FdmError> {
    FdmError::check_switches(
        &format!("`{name}` (link `{}`)", l.name),
        "chain",
        &[
            ("axial", l.axial),
            ("tip_inertia", l.tip_inertia.is_some()),
            ("prescribed joint", l.joint.prescribed.is_some()),
        ],
    )?;
    if !l.foreshortening {
        // Built and tested with foreshortening only. Timoshenko links keep the tip-chord
        // frames (module docs), where a linear model is frame-dependent at second order in the
        // deflection and so not the scene's clamped-frame linear beam (measured on
        // `two-link-free` with both links linear in chord frames: 8.5e-4 of the peak hub angle
        // from fem and modal, which agree). The Euler links' clamp-tangent kinematics without
        // foreshortening do not agree either: `two-link-free` with both links linear, 2 s, the
        // joint-2 angle at 9.6e-4 / 8.9e-4 of the peak from fem (32 elements, dt 1e-4) at 21 / 41
        // stations, where modal lies at 1.5e-4 and fem's default 16 elements at 1.7e-4.
        return Err(FdmError::Unsupported(format!(
            "fdm: `{name}` (link `{}`) is a linear beam (no `foreshortening`): the \
             finite-difference chain supports links with foreshortening only; switch it on, \
             or use the fem or modal backend",
            l.name
        )));
    }
    Ok(())
}

/// Refuses what the chain does not carry: other than two links, a link `check_link` refuses,
/// a mix of Timoshenko and Euler links, section rotary inertia, a joint torque law on
/// Timoshenko links and a rotor inertia at the elbow. Returns whether the links are Timoshenko.
fn check_chain(scene: &Scene, pc: &PlanarChain) -> Result<bool, FdmError> {
    if pc.links.len() != 2 {
        return Err(FdmError::Unsupported(format!(
            "fdm: `{}` has {} links; the finite-difference chain handles exactly two",
            scene.name,
            pc.links.len()
        )));
    }
    for l in &pc.links {
        check_link(&scene.name, l)?;
    }
    let shear = pc.links[0].shear;
    if pc.links[1].shear != shear {
        return Err(FdmError::Unsupported(format!(
            "fdm: `{}` mixes a Timoshenko (`shear`) and an Euler link; the finite-difference \
             chain needs both links of one model",
            scene.name
        )));
    }
    for l in &pc.links {
        if l.rotary_inertia {
            return Err(FdmError::Unsupported(format!(
                "fdm: `{}` (link `{}`) switches on rotary_inertia — the finite-difference \
                 chain has no section inertia: {}",
                scene.name,
                l.name,
                if l.shear {
                    "its Timoshenko ψ is massless and condensed (chain::timoshenko)"
                } else {
                    "Euler links carry only the lumped masses"
                }
            )));
        }
        if l.shear && l.joint.torque.is_some() {
            return Err(FdmError::Unsupported(format!(
                "fdm: `{}` (link `{}`): an applied joint torque law with Timoshenko links \
                 is not implemented (the condensed ψ would follow the torque's rate)",
                scene.name, l.name
            )));
        }
    }
    if pc.links[1].joint.hub_inertia.unwrap_or(0.0) != 0.0 {
        return Err(FdmError::Unsupported(format!(
            "fdm: `{}`: a rotor inertia at the elbow is not implemented",
            scene.name
        )));
    }
    Ok(shear)
}

/// Segments r = n − 1, spacing h = L/r and the lumped masses of stations 1…r: ρAh inside,
/// ρAh/2 plus the tip mass at the tip.
fn lump(l: &Link, n: usize) -> (usize, f64, Vec<f64>) {
    let r = n - 1;
    let h = l.length / r as f64;
    let mut m = vec![l.mass_per_length * h; r];
    m[r - 1] = 0.5 * l.mass_per_length * h + l.tip_mass.unwrap_or(0.0);
    (r, h, m)
}

/// Outboard mass per segment: Σ_{i ≥ seg} mᵢ.
fn outboard(m: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m.len()];
    let mut acc = 0.0;
    for seg in (0..m.len()).rev() {
        acc += m[seg];
        out[seg] = acc;
    }
    out
}

/// Rotary inertia ρA h³/24 of the half cell at each clamp: its section turns with the clamp
/// tangent (module docs). O(h³): the O(h²) convergence is unaffected.
fn clamp_inertia(l: &Link, h: f64) -> f64 {
    l.mass_per_length * h.powi(3) / 24.0
}

/// The condensed Timoshenko fields of both links (segments, spacing, EI, κGA, Kelvin–Voigt)
/// with their joints' springs and dampers.
fn timoshenko_fields(
    scene: &Scene,
    pc: &PlanarChain,
    grids: [(usize, f64); 2],
) -> Result<TimoFields, FdmError> {
    let mut lk = [(0, 0.0, 0.0, 0.0, 0.0); 2];
    for (k, (l, (r, h))) in pc.links.iter().zip(grids).enumerate() {
        lk[k] = (
            r,
            h,
            l.bending_stiffness,
            timoshenko::shear_stiffness(&scene.name, l)?,
            l.kelvin_voigt.unwrap_or(0.0),
        );
    }
    let jt = |l: &Link| {
        (
            l.joint.stiffness.unwrap_or(0.0),
            l.joint.damping.unwrap_or(0.0),
            l.joint.set_point.unwrap_or(0.0),
        )
    };
    TimoFields::new(lk, [jt(&pc.links[0]), jt(&pc.links[1])])
}

/// The chain's mass data from the lumped masses (r, h, m) of both links: outboard moments and
/// masses, Σmx² of link 1, and link 2's mass, first and second moments about the elbow.
fn chain_inertia(pc: &PlanarChain, lumps: [(usize, f64, Vec<f64>); 2]) -> ChainInertia {
    let [(r1, h1, m1), (r2, h2, m2)] = lumps;
    ChainInertia {
        hub: pc.links[0].joint.hub_inertia.unwrap_or(0.0),
        l1: pc.links[0].length,
        h1,
        h2,
        r1,
        r2,
        fs1: pc.links[0].foreshortening,
        fs2: pc.links[1].foreshortening,
        mu2: outboard(&m2),
        // link 2's clamp half cell (mass ρA₂h₂/2 at ξ = 0) rides on the elbow
        mass2: m2.iter().sum::<f64>() + 0.5 * pc.links[1].mass_per_length * h2,
        q2: (0..r2).map(|j| m2[j] * (j + 1) as f64 * h2).sum(),
        elbow_mass: 0.5 * pc.links[1].mass_per_length * h2,
        x1: (0..r1).map(|k| (k + 1) as f64 * h1).collect(),
        x2: (0..r2).map(|j| (j + 1) as f64 * h2).collect(),
        m1,
        m2,
    }
}

fn link_props(l: &Link) -> LinkProps {
    LinkProps {
        length: l.length,
        ei: l.bending_stiffness,
        gamma: l.kelvin_voigt.unwrap_or(0.0),
        rho_a: l.mass_per_length,
    }
}

fn joint_law(l: &Link) -> JointLaw {
    JointLaw {
        stiffness: l.joint.stiffness.unwrap_or(0.0),
        damping: l.joint.damping.unwrap_or(0.0),
        set_point: l.joint.set_point.unwrap_or(0.0),
        law: l.joint.torque.clone(),
    }
}

/// The mass solve's storage: each link's axial masses W (link 1's tip carries the elbow and
/// all of link 2), U and Z of `nd` entries.
fn mass_factors(inertia: &ChainInertia, nd: usize) -> MassFactors {
    let mut w1 = inertia.m1.clone();
    w1[inertia.r1 - 1] += inertia.mass2;
    MassFactors {
        links: [
            LinkRates::new(w1, inertia.fs1),
            LinkRates::new(inertia.m2.clone(), inertia.fs2),
        ],
        u: std::array::from_fn(|_| vec![0.0; nd]),
        nu: 0,
        z: std::array::from_fn(|_| vec![0.0; nd]),
        z_current: false,
        small: SmallLu::default(),
        zb: vec![0.0; nd],
        rz: vec![0.0; nd],
        rows: vec![0.0; nd * MAX_SMALL],
    }
}

/// Mass outboard of each segment of link 1, link 2 (with its clamp half cell) included.
fn link1_outboard_mass(inertia: &ChainInertia) -> Vec<f64> {
    let r1 = inertia.r1;
    let mut acc = inertia.mass2;
    let mut out = vec![0.0; r1];
    for seg in (0..r1).rev() {
        acc += inertia.m1[seg];
        out[seg] = acc;
    }
    out
}

impl TwoLinkChain {
    /// The chain model of `pc`, the planar chain of `scene`.
    pub fn from_planar_chain(
        scene: &Scene,
        pc: &PlanarChain,
        stations: Option<usize>,
    ) -> Result<Self, FdmError> {
        let shear = check_chain(scene, pc)?;
        let n = stations.unwrap_or(DEFAULT_STATIONS);
        let (r1, h1, m1) = lump(&pc.links[0], n);
        let (r2, h2, m2) = lump(&pc.links[1], n);
        // Timoshenko: the clamp section's turn is ψ₀ (massless, condensed), no ghost inertia
        let jc = if shear {
            [0.0; 2]
        } else {
            [
                clamp_inertia(&pc.links[0], h1),
                clamp_inertia(&pc.links[1], h2),
            ]
        };
        let timo = if shear {
            Some(timoshenko_fields(scene, pc, [(r1, h1), (r2, h2)])?)
        } else {
            None
        };
        let inertia = chain_inertia(pc, [(r1, h1, m1), (r2, h2, m2)]);
        // Euler links: link 1's tip ghost y after the inertia's coordinates
        let tip_ghost = (!shear).then(|| inertia.dofs());
        let jt = if shear {
            0.0
        } else {
            clamp_inertia(&pc.links[0], h1)
        };
        let nd = inertia.dofs() + usize::from(tip_ghost.is_some());
        let contact = TipContact::from_planar_chain(&scene.name, pc)?;
        let mu1g = link1_outboard_mass(&inertia);
        let (j1, j2) = (&pc.links[0].joint, &pc.links[1].joint);
        let mut chain = TwoLinkChain {
            links: [link_props(&pc.links[0]), link_props(&pc.links[1])],
            joints: [joint_law(&pc.links[0]), joint_law(&pc.links[1])],
            init: [
                (j1.initial_angle, j1.initial_rate),
                (j2.initial_angle, j2.initial_rate),
            ],
            field_stations: scene.simulation.field_stations.max(2),
            points: PointScratch::new(&inertia),
            obs_points: std::cell::RefCell::new(PointScratch::new(&inertia)),
            factors: mass_factors(&inertia, nd),
            cols: std::array::from_fn(|_| vec![0.0; nd]),
            units: std::array::from_fn(|_| vec![0.0; nd]),
            unit_lanes: RateLanes::default(),
            column_lanes: Lanes::new(&inertia),
            vk2: vec![0.0; nd],
            f2: vec![0.0; nd],
            inertia_lanes: Lanes::new(&inertia),
            drift_lanes: RateLanes::zeroed(r1 + r2),
            drift_slopes: std::array::from_fn(|_| vec![0.0; r1 + r2]),
            drift_slopes_of: vec![0.0; nd],
            drift_slopes_valid: false,
            rhs: vec![0.0; nd],
            split_reuse: SplitReuse::new(nd),
            fv: vec![0.0; r1],
            fw: vec![0.0; r2],
            power: [0.0; 3],
            torques: [0.0; 2],
            omega_max: 0.0,
            omega_max_site: 2,
            kappa_max: 0.0,
            jc,
            tip_ghost,
            jt,
            slots: [1 + r1, 1 + r1 + r2],
            hs: [h1, h2],
            qk: vec![0.0; nd],
            vk: vec![0.0; nd],
            qc: vec![0.0; nd],
            vc: vec![0.0; nd],
            gk: vec![0.0; nd],
            obs_scratch: std::cell::RefCell::new(vec![0.0; nd]),
            obs_scratch_v: std::cell::RefCell::new(vec![0.0; nd]),
            inertia,
            gravity: pc.gravity.as_ref().map(|g| g.vector),
            mu1g,
            contact,
            constraint: TipConstraint {
                constrained: false,
                lambda: 0.0,
                grow: vec![0.0; nd],
                minv_g: vec![0.0; nd],
                last_projection: [0.0; 3],
            },
            implicit: None,
            skip_damping: false,
            closing: None,
            vd: vec![0.0; nd],
            timo,
        };
        chain.set_ghost_columns();
        chain.set_unit_rates();
        chain.set_station_masses();
        (chain.omega_max, chain.omega_max_site) = chain.top_frequency();
        chain.kappa_max = chain.top_damping_rate();
        Ok(chain)
    }

    /// The constant full columns of M: link 1's tip-ghost column J_t e eᵀ (Euler links) and,
    /// Timoshenko, the unused ghost slots (a decoupled unit mass); `build_columns` refreshes
    /// the state-dependent θ, β and (Euler) ψ₁, ψ₂ columns.
    fn set_ghost_columns(&mut self) {
        if self.timo.is_some() {
            for k in 0..2 {
                // unused slot: a decoupled unit mass with no force keeps it at rest at zero
                self.cols[2 + k][self.slots[k]] = 1.0;
            }
        }
        if let Some(y) = self.tip_ghost {
            let mut col = std::mem::take(&mut self.cols[4]);
            self.add_tip(self.jt / (2.0 * self.hs[0]), &mut col);
            debug_assert_eq!(col[y], self.jt / (4.0 * self.hs[0] * self.hs[0]));
            self.cols[4] = col;
        }
    }

    pub fn dof_plan(&self) -> DofPlan {
        let mut plan = DofPlan::default();
        plan.add("link-1 tip-chord angle θ", 1);
        plan.add("link-2 tip-chord angle β", 1);
        if self.timo.is_some() {
            plan.add(
                "unused ghost slots (Timoshenko: held at zero, decoupled unit mass)",
                2,
            );
        } else {
            plan.add(
                "clamp ghost deflections x₁, x₂ (clamp turn against the chord)",
                2,
            );
        }
        if self.tip_ghost.is_some() {
            plan.add(
                "link 1 tip ghost y = v_{r+1} (elbow section turn and moment against the chord)",
                1,
            );
        }
        plan.add(
            "link 1 transverse v at stations 1…r−1 (tip-chord frame: v₀ = v_r = 0)",
            self.inertia.r1 - 1,
        );
        plan.add(
            "link 2 transverse w at stations 1…r−1 (tip-chord frame: w₀ = w_r = 0)",
            self.inertia.r2 - 1,
        );
        if self.inertia.fs1 || self.inertia.fs2 {
            plan.builds
                .push("foreshortening (inertial axial-load) stiffening".into());
        }
        if let Some(t) = &self.timo {
            plan.builds.push(format!(
                "Timoshenko shear ½κGA(Δv/h − ψ̄)² and bending ½EI(Δψ/h)²: {} massless section \
                 rotations ψ condensed on their slow manifold (tridiagonal solve per evaluation)",
                t.nz()
            ));
        }
        if self.any_kv() {
            plan.builds.push("Kelvin–Voigt damping".into());
        }
        if self.any_damper() {
            plan.builds.push("joint dampers".into());
        }
        plan.builds.push(
            "default time method: velocity-form (the hub coupling is velocity dependent)".into(),
        );
        plan
    }

    pub fn initial_state(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.dofs();
        let mut q = vec![0.0; n];
        let mut v = vec![0.0; n];
        // elastic fields at rest and straight: β = θ₁ + θ₂
        q[TH] = self.init[0].0;
        q[BE] = self.init[0].0 + self.init[1].0;
        v[TH] = self.init[0].1;
        v[BE] = self.init[0].1 + self.init[1].1;
        // Timoshenko links too: the centre lines start straight at the scene's angles, and the
        // massless sections (condensed, z₀(q)) take their balance from there, so the joint
        // angles between sections start off the scene's by those sections' turns (data's scene
        // docs; the same initial state in every backend).
        (q, v)
    }
}
