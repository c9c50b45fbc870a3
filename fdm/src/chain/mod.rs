//! Two flexible links in series (`two-link-free`, `two-link-free-undamped`): link 2 is clamped to
//! the tip of link 1 and rotated by the elbow angle θ₂, so its clamp tangent has the angle
//! θ₁ + ψ + θ₂ with ψ = v₁'(L₁) (scenes.md; Barhorst's q₁, q₅).
//!
//! **Frames.** Each link's floating frame is its *tip chord* (v₀ = v_r = 0): θ and β are the
//! chord angles of links 1 and 2. The clamp condition is the report's ghost node, kept as an
//! unknown x = v₋₁: the clamp tangent turns by (v₁ − x)/(2h) from the chord and κ₀ =
//! (v₁ + x)/h². Why not the clamp-tangent frame of the single link? With zero hub inertia (both
//! joints here) a tangent-frame rotation against the opposite linear deflection moves no lumped
//! mass, and the second-order kinetic energy (exact value ½Σm s² ≥ 0) becomes *indefinite* in
//! that direction for deflections of a few mm (measured: M loses definiteness, the run blows up
//! at any step). Pinning the tip to the chord makes every frame rotation move the link's mass.
//! The clamp section's own rotation carries the half-cell rotary inertia J_c = ρA h³/24
//! (O(h³), exact positive term ½J_c(clamp angle rate)²).
//!
//! **Equations.** Lagrange's equations of L = T − V with the dissipation function D:
//! * T: [`kinetic`] (second order in the deflections, exact in the angles: the single link's
//!   order) + Σ ½J_c,ℓ (clamp angle rate)²;
//! * V = Σ_ℓ ½ Σᵢ cᵢ h EI κᵢ² (the single link's ghost-node bending energy, [`crate::link`],
//!   with κ₀ from the clamp ghost) plus ½K₁(θ₁ − θ₁⁰)² + ½K₂(θ₂ − θ₂⁰)², θ₁ the clamp angle of
//!   link 1, θ₂ = (clamp angle of link 2) − θ − ψ, ψ = (y − v_{r−1})/(2h₁) the central tip
//!   slope of link 1 with its **tip ghost** y = v_{r+1} (v_r = 0). Link 1's sum runs to the
//!   elbow station with the trapezoid end weight c_r = ½ and κ_r = (y + v_{r−1})/h², so ∂V/∂y
//!   = 0 reads EI κ_r = K₂(θ₂ − θ₂⁰) + O(h²): the elbow moment is a second-order boundary
//!   condition (as the clamp ghost's κ₀ at each root), and the shear is the reaction of v_r = 0
//!   in the frame equations. (Treating link 1's tip as a free end, κ_r = 0 in the energy with
//!   a one-sided slope, is O(h) wherever the elbow carries a moment.) The tip section turns
//!   with θ + ψ and carries its half cell's rotary inertia J_t = ρA₁h₁³/24 (O(h³), as J_c);
//! * D = Σ_ℓ ½ Σᵢ cᵢ h γ κ̇ᵢ² + ½D₁θ̇₁² + ½D₂θ̇₂² (link 1's sum with the same tip term);
//!   applied torque laws τⱼ(t) do the work ∫τⱼ θ̇ⱼ.
//!
//! M(q) q̈ = Q − ∂V/∂q − ∂D/∂q̇ + ∂T/∂q − (∂p/∂q) q̇, with p = ∂T/∂q̇ = M q̇. The last term is one
//! forward-mode dual-number pass over p ([`dual`]); the columns of M for θ, β, x₁, x₂ (and y)
//! are p at unit velocities plus J_c e eᵀ (J_t e eᵀ); the rest of M is the diagonal of lumped
//! masses, so the solve is a 5×5 Schur complement: O(n) per force evaluation, no allocation in
//! the step loop.
//!
//! **Step.** Velocity form by default (free joints: velocity-dependent inertia forces; damping
//! on). Without contact the damping (constant C) is implicit in the closing kick ([`implicit`]:
//! Crank–Nicolson in the damping, banded solve) and the bound is the undamped one below (ζ = 0);
//! with contact (restartable steps) it is explicit and the bound carries the damping.
//! Bound: 0.9 · 2/ω_max with ω_max from a power iteration on the linearized chain at t = 0
//! (once per run, O(n²)), with ζ = max(Kelvin–Voigt ζ of that frequency, κ_max/(2ω_max)) —
//! κ_max the fastest damping rate, a power iteration on −∂a/∂q̇ (the joint dampers act on the
//! clamp half-cell inertia: overdamped modes, velocity-form limit τ → 1/κ) — and the
//! clamp-rotation modes and link 1's tip-rotation mode with their joint-damper ratios. Gravity: V_g of the lumped masses
//! ([`TwoLinkChain`]'s `gravity_potential`). Tip contact: [`contact`]. Observables: joint angles/rates (clamp angles),
//! torques = law + spring + damper, tip positions, and deflections in the clamp-tangent frame.
//!
//! **Timoshenko links** (`shear` on both links): [`timoshenko`] — ψ at the stations replaces the
//! clamp ghost (the clamp section's turn from the chord is ψ₀), ψ is massless in the chord
//! frames and condensed; the clamp ghost slots of q stay in place, unused (zero force, a
//! decoupled unit mass), so the mass solve and the contact code are shared unchanged; there is
//! no tip ghost (link 1's tip section is the condensed ψ).

// Index loops over parallel buffers (q, v, a, columns of M) read like the formulas.
#![allow(clippy::needless_range_loop)]

mod bound;
pub mod contact;
pub mod dual;
pub mod implicit;
pub mod kinetic;
mod mass;
pub mod modes;
mod outputs;
pub mod timoshenko;

use data::scene::{Link, PlanarChain, TorqueLaw};
use data::{DofPlan, Scene};

use crate::error::FdmError;
use crate::link::FloatingLink;
use crate::output::Outputs;
use crate::system::{Bound, DeflectionModel, DriftVelocities, Overextension, System};
use contact::TipContact;
use dual::Dual;
use kinetic::{BE, ChainInertia, TH, seg_energy, seg_grad};
use timoshenko::TimoFields;

/// Bound sites ≥ this are the Timoshenko links' shear bounds.
const SHEAR_SITE: usize = 10;
/// Bound site of link 1's tip-ghost rotation mode (Euler links).
const TIP_SITE: usize = 5;

/// Default stations per link.
pub const DEFAULT_STATIONS: usize = 21;

#[derive(Debug, Clone, Default)]
struct JointLaw {
    stiffness: f64,
    damping: f64,
    set_point: f64,
    law: Option<TorqueLaw>,
}

impl JointLaw {
    fn torque(&self, t: f64) -> f64 {
        self.law.as_ref().map_or(0.0, |l| l.torque(t))
    }
}

#[derive(Debug, Clone)]
struct LinkProps {
    length: f64,
    ei: f64,
    gamma: f64,
    rho_a: f64,
}

/// The two-link chain as a [`System`].
#[derive(Debug, Clone)]
pub struct TwoLinkChain {
    pub inertia: ChainInertia,
    links: [LinkProps; 2],
    joints: [JointLaw; 2],
    init: [(f64, f64); 2],
    field_stations: usize,
    /// highest angular frequency of the linearized chain at t = 0 (power iteration)
    pub omega_max: f64,
    /// fastest damping rate of the linearized chain at t = 0 (power iteration on −∂a/∂q̇)
    pub kappa_max: f64,
    /// clamp half-cell rotary inertias ρA h³/24 of links 1 and 2
    jc: [f64; 2],
    /// Euler links: q-slot of link 1's tip ghost y = v_{r+1} (the elbow section's turn from
    /// the chord, ψ = (y − v_{r−1})/(2h₁)) and the tip half cell's rotary inertia ρA₁h₁³/24;
    /// Timoshenko links: none (link 1's tip section is the condensed ψ)
    tip_ghost: Option<usize>,
    jt: f64,
    /// q-slots of the clamp ghost deflections x₁, x₂ (station 1 of each link is the chord
    /// frame's zero) and the link steps
    slots: [usize; 2],
    hs: [f64; 2],
    qk: Vec<f64>,
    vk: Vec<f64>,
    obs_scratch: std::cell::RefCell<Vec<f64>>,
    obs_scratch_v: std::cell::RefCell<Vec<f64>>,
    // scratch (allocated once)
    p: Vec<Dual>,
    /// the full columns of M: θ, β, x₁, x₂ and (Euler) the tip ghost y
    cols: [Vec<f64>; 5],
    unit: Vec<f64>,
    rhs: Vec<f64>,
    fv: Vec<f64>,
    fw: Vec<f64>,
    power: [f64; 3],
    torques: [f64; 2],
    /// uniform gravity (inertial gx, gy), if the scene has it
    gravity: Option<[f64; 2]>,
    /// gravity weights of link 1's foreshortening: outboard mass of each segment plus the
    /// whole of link 2 (which rides on link 1's tip)
    mu1g: Vec<f64>,
    /// the tip contact of link 2, if any ([`contact`])
    contact: Option<TipContact>,
    /// whether the tip is held on the surface (constrained phase)
    constrained: bool,
    /// normal force λ of the last constrained `accel` (0 in free flight)
    lambda: f64,
    /// scratch of the constraint: G = ∂g/∂q and M⁻¹Gᵀ
    grow: Vec<f64>,
    minv_g: Vec<f64>,
    /// (|g|, |Gq̇|, energy removed) of the last constrained step's projections
    last_projection: [f64; 3],
    /// the damping matrix C and the banded factorization of the implicit kick ([`implicit`]);
    /// none: damping explicit in the forces
    implicit: Option<Box<implicit::ImplicitDamping>>,
    /// `forces` leaves the damping out (the implicit kick adds it at the drift velocity)
    skip_damping: bool,
    /// scratch of [`Self::add_damping_forces`] and the implicit kick (length n)
    vd: Vec<f64>,
    /// Timoshenko links (`shear` on both): the condensed section rotations ([`timoshenko`]);
    /// the ghost slots are then unused (held at zero with a unit dummy mass)
    timo: Option<TimoFields>,
}

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
        // The chain's floating frames are the links' tip chords (module docs). With
        // foreshortening the kinematics are those of the clamped frame to the order kept; the
        // linear model without it is frame-dependent at second order in the deflection, so it
        // would not be the scene's clamped-frame linear beam (measured on `two-link-free` with
        // both links linear: 8.5e-4 of the peak hub angle from fem and modal, which agree).
        return Err(FdmError::Unsupported(format!(
            "fdm: `{name}` (link `{}`) is a linear beam (no `foreshortening`): the \
             finite-difference chain measures deflections from the link's tip chord, which \
             matches the clamped frame of the scene only with foreshortening; switch it on, \
             or use the fem or modal backend",
            l.name
        )));
    }
    Ok(())
}

impl TwoLinkChain {
    /// The chain model of `pc`, the planar chain of `scene`.
    pub fn from_planar_chain(
        scene: &Scene,
        pc: &PlanarChain,
        stations: Option<usize>,
    ) -> Result<Self, FdmError> {
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
        let n = stations.unwrap_or(DEFAULT_STATIONS);
        let lump = |l: &Link| -> (usize, f64, Vec<f64>) {
            let r = n - 1;
            let h = l.length / r as f64;
            let mut m = vec![l.mass_per_length * h; r];
            m[r - 1] = 0.5 * l.mass_per_length * h + l.tip_mass.unwrap_or(0.0);
            (r, h, m)
        };
        let (r1, h1, m1) = lump(&pc.links[0]);
        let (r2, h2, m2) = lump(&pc.links[1]);
        // outboard sums per segment: Σ_{i > seg} mᵢ xᵢ and Σ_{i > seg} mᵢ
        let outboard = |m: &[f64], h: f64, moment: bool| -> Vec<f64> {
            let mut out = vec![0.0; m.len()];
            let mut acc = 0.0;
            for seg in (0..m.len()).rev() {
                acc += m[seg] * if moment { (seg + 1) as f64 * h } else { 1.0 };
                out[seg] = acc;
            }
            out
        };
        // Rotary inertia ρA h³/24 of the half cell at each clamp: its section turns with the
        // clamp tangent (module docs). O(h³): the O(h²) convergence is unaffected.
        let clamp = |l: &Link, h: f64| l.mass_per_length * h.powi(3) / 24.0;
        // Timoshenko: the clamp section's turn is ψ₀ (massless, condensed), no ghost inertia
        let jc = if shear {
            [0.0; 2]
        } else {
            [clamp(&pc.links[0], h1), clamp(&pc.links[1], h2)]
        };
        let timo = if shear {
            let mut lk = [(0, 0.0, 0.0, 0.0, 0.0); 2];
            for (k, (l, (r, h))) in pc.links.iter().zip([(r1, h1), (r2, h2)]).enumerate() {
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
            Some(TimoFields::new(lk, [jt(&pc.links[0]), jt(&pc.links[1])])?)
        } else {
            None
        };
        let inertia = ChainInertia {
            hub: pc.links[0].joint.hub_inertia.unwrap_or(0.0),
            l1: pc.links[0].length,
            h1,
            h2,
            r1,
            r2,
            fs1: pc.links[0].foreshortening,
            fs2: pc.links[1].foreshortening,
            w1: outboard(&m1, h1, true),
            w2: outboard(&m2, h2, true),
            mu2: outboard(&m2, h2, false),
            sum_mx2_1: (0..r1).map(|k| m1[k] * ((k + 1) as f64 * h1).powi(2)).sum(),
            // link 2's clamp half cell (mass ρA₂h₂/2 at ξ = 0) rides on the elbow
            mass2: m2.iter().sum::<f64>() + 0.5 * pc.links[1].mass_per_length * h2,
            q2: (0..r2).map(|j| m2[j] * (j + 1) as f64 * h2).sum(),
            i2: (0..r2).map(|j| m2[j] * ((j + 1) as f64 * h2).powi(2)).sum(),
            m1,
            m2,
        };
        let props = |l: &Link| LinkProps {
            length: l.length,
            ei: l.bending_stiffness,
            gamma: l.kelvin_voigt.unwrap_or(0.0),
            rho_a: l.mass_per_length,
        };
        let joint = |l: &Link| JointLaw {
            stiffness: l.joint.stiffness.unwrap_or(0.0),
            damping: l.joint.damping.unwrap_or(0.0),
            set_point: l.joint.set_point.unwrap_or(0.0),
            law: l.joint.torque.clone(),
        };
        // Euler links: link 1's tip ghost y after the inertia's coordinates
        let tip_ghost = (!shear).then(|| inertia.dofs());
        let jt = if shear { 0.0 } else { clamp(&pc.links[0], h1) };
        let nd = inertia.dofs() + usize::from(tip_ghost.is_some());
        let contact = TipContact::from_planar_chain(&scene.name, pc)?;
        let mu1g = {
            let mut acc = inertia.mass2;
            let mut out = vec![0.0; r1];
            for seg in (0..r1).rev() {
                acc += inertia.m1[seg];
                out[seg] = acc;
            }
            out
        };
        let (j1, j2) = (&pc.links[0].joint, &pc.links[1].joint);
        let mut chain = TwoLinkChain {
            links: [props(&pc.links[0]), props(&pc.links[1])],
            joints: [joint(&pc.links[0]), joint(&pc.links[1])],
            init: [
                (j1.initial_angle, j1.initial_rate),
                (j2.initial_angle, j2.initial_rate),
            ],
            field_stations: scene.simulation.field_stations.max(2),
            p: vec![Dual::default(); nd],
            cols: std::array::from_fn(|_| vec![0.0; nd]),
            unit: vec![0.0; nd],
            rhs: vec![0.0; nd],
            fv: vec![0.0; r1],
            fw: vec![0.0; r2],
            power: [0.0; 3],
            torques: [0.0; 2],
            omega_max: 0.0,
            kappa_max: 0.0,
            jc,
            tip_ghost,
            jt,
            slots: [1 + r1, 1 + r1 + r2],
            hs: [h1, h2],
            qk: vec![0.0; nd],
            vk: vec![0.0; nd],
            obs_scratch: std::cell::RefCell::new(vec![0.0; nd]),
            obs_scratch_v: std::cell::RefCell::new(vec![0.0; nd]),
            inertia,
            gravity: pc.gravity.as_ref().map(|g| g.vector),
            mu1g,
            contact,
            constrained: false,
            lambda: 0.0,
            grow: vec![0.0; nd],
            minv_g: vec![0.0; nd],
            last_projection: [0.0; 3],
            implicit: None,
            skip_damping: false,
            vd: vec![0.0; nd],
            timo,
        };
        // The ghost columns of M (J_c e eᵀ at the ghost slots) do not depend on the state:
        // built once here, `accel` refreshes only the θ and β columns.
        for k in 0..2 {
            let mut col = std::mem::take(&mut chain.cols[2 + k]);
            if chain.timo.is_some() {
                // unused slot: a decoupled unit mass with no force keeps it at rest at zero
                col[chain.slots[k]] = 1.0;
            } else {
                chain.add_clamp(k, -chain.jc[k] / (2.0 * chain.hs[k]), &mut col);
            }
            chain.cols[2 + k] = col;
        }
        if let Some(y) = chain.tip_ghost {
            let mut col = std::mem::take(&mut chain.cols[4]);
            chain.add_tip(chain.jt / (2.0 * chain.hs[0]), &mut col);
            debug_assert_eq!(col[y], chain.jt / (4.0 * chain.hs[0] * chain.hs[0]));
            chain.cols[4] = col;
        }
        chain.omega_max = chain.top_frequency();
        chain.kappa_max = chain.top_damping_rate();
        Ok(chain)
    }

    fn any_law(&self) -> bool {
        self.joints.iter().any(|j| j.law.is_some())
    }
    fn any_damper(&self) -> bool {
        self.joints.iter().any(|j| j.damping != 0.0)
    }
    fn any_kv(&self) -> bool {
        self.links.iter().any(|l| l.gamma != 0.0)
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
        // elastic fields at rest and straight: ψ = 0, β = θ₁ + θ₂
        q[TH] = self.init[0].0;
        q[BE] = self.init[0].0 + self.init[1].0;
        v[TH] = self.init[0].1;
        v[BE] = self.init[0].1 + self.init[1].1;
        if let Some(t) = &self.timo {
            // The condensed sections turn with the elbow spring's load: set the chord angles
            // so that the joint angles Θ₁ = θ + ψ¹₀, Θ₂ = β + ψ²₀ − θ − ψ¹_r (and their rates)
            // are the scene's. ∂Θ/∂(θ, β) is 1 up to the ψ response (≪ 1): fixed point.
            for (x, rate) in [(&mut q, false), (&mut v, true)] {
                let want = [
                    if rate { self.init[0].1 } else { self.init[0].0 },
                    if rate { self.init[1].1 } else { self.init[1].0 },
                ];
                for _ in 0..50 {
                    let th = t.joint_angles(x, rate);
                    let d = [want[0] - th[0], want[1] - th[1]];
                    x[TH] += d[0];
                    x[BE] += d[0] + d[1];
                    if d[0].abs().max(d[1].abs()) <= 1e-16 * (1.0 + want[0].abs()) {
                        break;
                    }
                }
            }
        }
        (q, v)
    }

    /// Joint angles (θ₁, θ₂) at q: the clamp angle of link 1 and the elbow (Euler: clamp
    /// tangents and the tip slope; Timoshenko: clamp sections and link 1's tip section on the
    /// condensed ψ).
    pub fn joint_angles(&self, q: &[f64]) -> [f64; 2] {
        match &self.timo {
            Some(t) => t.joint_angles(q, false),
            None => [self.clamp_angle(q, 0), self.elbow(q)],
        }
    }

    /// Joint rates (θ̇₁, θ̇₂) at q̇ (both models: linear in q̇ alone).
    pub fn joint_rates(&self, v: &[f64]) -> [f64; 2] {
        match &self.timo {
            Some(t) => t.joint_angles(v, true),
            None => [self.clamp_angle(v, 0), self.elbow(v)],
        }
    }

    /// The condensed Timoshenko fields, if the links are Timoshenko links.
    pub fn timoshenko(&self) -> Option<&TimoFields> {
        self.timo.as_ref()
    }

    /// Tip slope ψ of link 1 and the stencil (indices into q, weights).
    fn slope_stencil(&self) -> [(usize, f64); 2] {
        let i = self.inertia.i_tip1();
        let h = self.inertia.h1;
        match self.tip_ghost {
            // central (y − v_{r−1})/(2h) with the tip ghost y = v_{r+1}
            Some(y) => [(y, 1.0 / (2.0 * h)), (i - 1, -1.0 / (2.0 * h))],
            // Timoshenko (joint angles from the condensed ψ; unused): one-sided
            // (3v_r − 4v_{r−1} + v_{r−2})/(2h) with v_r = 0 in the chord frame
            None => [(i - 1, -4.0 / (2.0 * h)), (i - 2, 1.0 / (2.0 * h))],
        }
    }

    /// Link 1's tip-section angle θ + ψ (applied to q or q̇; Euler links).
    fn tip_angle(&self, q: &[f64]) -> f64 {
        let psi: f64 = self.slope_stencil().iter().map(|(i, c)| c * q[*i]).sum();
        q[TH] + psi
    }

    /// Adds J_t e eᵀ·(scale) of link 1's tip-section rotation to a column/momentum vector:
    /// e = ∂(θ + ψ)/∂q (1 at θ, 1/(2h) at y, −1/(2h) at v_{r−1}); nothing without a tip ghost.
    fn add_tip(&self, weight: f64, out: &mut [f64]) {
        if self.tip_ghost.is_some() {
            out[TH] += weight;
            for (i, c) in self.slope_stencil() {
                out[i] += weight * c;
            }
        }
    }

    /// Link 1's tip term of the trapezoid bending energy, ¼h c κ_r² with κ_r = (y + u)/h²
    /// (u = v_{r−1}, v_r = 0, y = v_{r+1}): (energy, ∂/∂y = ∂/∂u).
    fn tip_bending(h: f64, c: f64, u: f64, y: f64) -> (f64, f64) {
        let h3 = h * h * h;
        (c * (y + u).powi(2) / (4.0 * h3), c * (y + u) / (2.0 * h3))
    }

    /// q-index of station 1 of link ℓ.
    fn first(&self, link: usize) -> usize {
        if link == 0 { 2 } else { 2 + self.inertia.r1 }
    }

    /// Clamp tangent angle of link ℓ: chord angle + (v₁ − x)/(2h) (applied to q or q̇).
    pub fn clamp_angle(&self, q: &[f64], link: usize) -> f64 {
        let frame = if link == 0 { q[TH] } else { q[BE] };
        frame + (q[self.first(link)] - q[self.slots[link]]) / (2.0 * self.hs[link])
    }

    /// The turn −ε of each link's chord against its clamp tangent, ε = (v₁ − x)/(2h) the clamp
    /// slope in the chord frame (Timoshenko: −ψ₀, the clamp section's rotation): deflections
    /// in the clamp-tangent frame are u − Xε (small angle).
    pub(super) fn clamp_frame_turns(&self, q: &[f64]) -> [f64; 2] {
        match &self.timo {
            Some(t) => t.clamp_turns(q).map(|z| -z),
            None => [0, 1].map(|l| -(q[self.first(l)] - q[self.slots[l]]) / (2.0 * self.hs[l])),
        }
    }

    /// Bending energy of one link in the tip-chord frame with the clamp ghost x: the
    /// single-link energy on u (u_r = 0) with κ₀ = 2u₁/h² replaced by (u₁ + x)/h². Adds −∂/∂u
    /// into f (its tip entry left untouched) and returns (energy, −∂/∂x).
    fn ghost_bending(h: f64, c: f64, u: &[f64], x: f64, f: &mut [f64]) -> (f64, f64) {
        let r = u.len();
        let tip = f[r - 1];
        let e = FloatingLink::add_bending(h, c, u, f);
        f[r - 1] = tip;
        let h3 = h * h * h;
        f[0] += 2.0 * c * u[0] / h3;
        let g = c * (u[0] + x) / (2.0 * h3);
        f[0] -= g;
        (
            e - c * u[0] * u[0] / h3 + c * (u[0] + x).powi(2) / (4.0 * h3),
            -g,
        )
    }

    /// Elbow angle θ₂ = (clamp tangent of link 2) − θ − ψ (applied to q or q̇).
    pub fn elbow(&self, q: &[f64]) -> f64 {
        let psi: f64 = self.slope_stencil().iter().map(|(i, c)| c * q[*i]).sum();
        self.clamp_angle(q, 1) - q[TH] - psi
    }

    /// Copies of (q, q̇) with the ghost slots zeroed: the chord-frame deflections (v₁ = 0).
    fn chord(&mut self, q: &[f64], v: &[f64]) {
        self.qk.copy_from_slice(q);
        self.vk.copy_from_slice(v);
        for s in self.ghosts() {
            self.qk[s] = 0.0;
            self.vk[s] = 0.0;
        }
    }

    /// The q-slots that move no lumped mass: the clamp ghosts and (Euler) link 1's tip ghost.
    fn ghosts(&self) -> impl Iterator<Item = usize> + use<> {
        self.slots.into_iter().chain(self.tip_ghost)
    }

    /// Diagonal mass of coordinate i outside the full columns θ, β, x₁, x₂.
    fn diag_mass(&self, i: usize) -> f64 {
        let mut d = self.inertia.diag_mass(i);
        for k in 0..2 {
            if i == self.first(k) {
                d += self.jc[k] / (4.0 * self.hs[k] * self.hs[k]);
            }
        }
        if self.tip_ghost.is_some() && i == self.inertia.i_tip1() - 1 {
            d += self.jt / (4.0 * self.hs[0] * self.hs[0]);
        }
        d
    }

    /// Adds J_c e eᵀ·(scale at `along`) of link ℓ's clamp rotation to a column/momentum vector:
    /// e = ∂(clamp angle)/∂q (1 at the frame, ±1/(2h) at station 1 and the ghost).
    fn add_clamp(&self, link: usize, weight: f64, out: &mut [f64]) {
        let frame = if link == 0 { TH } else { BE };
        let a = 1.0 / (2.0 * self.hs[link]);
        out[frame] += weight;
        out[self.first(link)] += weight * a;
        out[self.slots[link]] -= weight * a;
    }

    /// Generalized momenta p = M(q) q̇ of the whole chain (chord-frame kinetic energy plus the
    /// clamp rotary inertias).
    pub fn momenta(&mut self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.chord(q, qd);
        out.iter_mut().for_each(|x| *x = 0.0);
        self.inertia.momenta_values(&self.qk, &self.vk, out);
        for s in self.ghosts() {
            out[s] = 0.0;
        }
        for k in 0..2 {
            let w = self.jc[k] * self.clamp_angle(qd, k);
            self.add_clamp(k, w, out);
        }
        if self.tip_ghost.is_some() {
            self.add_tip(self.jt * self.tip_angle(qd), out);
        }
    }

    pub fn total_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let mut e = [0.0; 4];
        let k = self.ledger_names().0.len();
        self.stored_energies(0.0, q, v, &mut e[..k]);
        e.iter().sum()
    }

    /// Gravity potential V_g = −g·Σ m r of the lumped masses, from the chord-frame coordinates
    /// `qk` (ghost slots zero); adds −∂V_g/∂q into `out` when given (not at the ghost slots:
    /// the ghosts move no mass). With A(α) = g·(cos α, sin α), B(α) = g·(−sin α, cos α),
    /// ∂A/∂α = B, ∂B/∂α = −A:
    /// V_g = −[A(θ)X₁ + B(θ)Y₁ + A(β)X₂ + B(β)Y₂], X₁ = Σm₁x + M₂L₁ − Σ_seg c₁ ½h g²
    /// (foreshortening; c₁ = outboard mass of link 1 + M₂), Y₁ = Σm₁v, X₂ = Q₂ − Ψ, Y₂ = Σm₂w:
    /// the positions the kinetic energy uses, so the gravity work is exactly −ΔV_g.
    fn gravity_potential(&self, qk: &[f64], out: Option<&mut [f64]>) -> f64 {
        let Some([gx, gy]) = self.gravity else {
            return 0.0;
        };
        let ine = &self.inertia;
        let (v, w) = (&qk[ine.iv()], &qk[ine.iw()]);
        let ab = |a: f64| {
            let (s, c) = a.sin_cos();
            (gx * c + gy * s, -gx * s + gy * c)
        };
        let (a1, b1) = ab(qk[TH]);
        let (a2, b2) = ab(qk[BE]);
        let mut x1 = ine.mass2 * ine.l1;
        let mut y1 = 0.0;
        for k in 0..ine.r1 {
            x1 += ine.m1[k] * (k + 1) as f64 * ine.h1;
            y1 += ine.m1[k] * v[k];
        }
        if ine.fs1 {
            x1 -= seg_energy(v, ine.h1, Some(&self.mu1g));
        }
        let mut x2 = ine.q2;
        let y2: f64 = (0..ine.r2).map(|j| ine.m2[j] * w[j]).sum();
        if ine.fs2 {
            x2 -= seg_energy(w, ine.h2, Some(&ine.mu2));
        }
        if let Some(out) = out {
            out[TH] += b1 * x1 - a1 * y1;
            out[BE] += b2 * x2 - a2 * y2;
            // the tip entries (k = r − 1) are the ghost slots: no mass moves with them
            for k in 0..ine.r1 - 1 {
                let mut f = b1 * ine.m1[k];
                if ine.fs1 {
                    f -= a1 * seg_grad(v, ine.h1, Some(&self.mu1g), k);
                }
                out[2 + k] += f;
            }
            for j in 0..ine.r2 - 1 {
                let mut f = b2 * ine.m2[j];
                if ine.fs2 {
                    f -= a2 * seg_grad(w, ine.h2, Some(&ine.mu2), j);
                }
                out[2 + ine.r1 + j] += f;
            }
        }
        -(a1 * x1 + b1 * y1 + a2 * x2 + b2 * y2)
    }

    /// Stores the input/dissipation powers at (q, q̇) — without the force evaluation — and
    /// writes them as [`System::powers`] does. The velocity form evaluates the forces of a step
    /// end at the *predicted* velocity; its ledger takes the powers at the final one (the
    /// overdamped clamp-rotation modes make the two differ at O(1) near the step bound).
    pub(crate) fn powers_at(&mut self, t: f64, v: &[f64], out: &mut [f64]) {
        if let Some(tf) = &self.timo {
            let pw = tf.powers(v);
            self.power = [0.0, pw[0], pw[1]];
            self.powers(out);
            return;
        }
        self.vk.copy_from_slice(v);
        for s in self.ghosts() {
            self.vk[s] = 0.0;
        }
        let (iv, iw) = (self.inertia.iv(), self.inertia.iw());
        let mut p_kv = 0.0;
        if let Some(y) = self.tip_ghost {
            let u = v[self.inertia.i_tip1() - 1];
            p_kv += 2.0 * Self::tip_bending(self.hs[0], self.links[0].gamma, u, v[y]).0;
        }
        for (link, (range, f)) in [(iv, &mut self.fv), (iw, &mut self.fw)]
            .into_iter()
            .enumerate()
        {
            let lp = &self.links[link];
            if lp.gamma == 0.0 {
                continue;
            }
            f.iter_mut().for_each(|x| *x = 0.0);
            let (d2, _) = Self::ghost_bending(
                self.hs[link],
                lp.gamma,
                &self.vk[range],
                v[self.slots[link]],
                f,
            );
            p_kv += 2.0 * d2;
        }
        let (th1d, th2d) = (self.clamp_angle(v, 0), self.elbow(v));
        let j = &self.joints;
        self.power = [
            j[0].torque(t) * th1d + j[1].torque(t) * th2d,
            j[0].damping * th1d * th1d + j[1].damping * th2d * th2d,
            p_kv,
        ];
        self.powers(out);
    }

    /// rhs += scale·(∂T/∂q − (∂p/∂q)q̇) at the chord copies (`qk`, `vk`) of the last
    /// [`Self::chord`]; `scratch` (length n) is overwritten. The clamp inertias are constant
    /// and the chord-frame T does not see the ghost slots.
    fn add_inertia_terms(&mut self, scale: f64, scratch: &mut [f64], rhs: &mut [f64]) {
        self.inertia.grad_q(&self.qk, &self.vk, scratch);
        self.inertia
            .momenta(&self.qk, &self.vk, &self.vk, &mut self.p);
        for s in self.ghosts() {
            scratch[s] = 0.0;
            self.p[s] = Dual::default();
        }
        for i in 0..rhs.len() {
            rhs[i] += scale * (scratch[i] - self.p[i].du);
        }
    }

    /// Generalized forces Q − ∂V/∂q − ∂D/∂q̇ into `out`; sets the powers.
    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        if let Some(tf) = &self.timo {
            // condensed ψ (chain::timoshenko): −∂U_c/∂q − ∂D_c/∂q̇, no torque laws (refused)
            let (pw, [th, thd]) = tf.forces(q, v, out);
            let j = &self.joints;
            self.torques =
                [0, 1].map(|k| -j[k].stiffness * (th[k] - j[k].set_point) - j[k].damping * thd[k]);
            self.power = [0.0, pw[0], pw[1]];
            let qk = std::mem::take(&mut self.qk);
            self.gravity_potential(&qk, Some(out));
            self.qk = qk;
            return;
        }
        // the implicit kick (`implicit`) takes the damping forces separately
        let damp = !self.skip_damping;
        let (iv, iw) = (self.inertia.iv(), self.inertia.iw());
        let mut p_kv = 0.0;
        for (link, (range, f)) in [(iv, &mut self.fv), (iw, &mut self.fw)]
            .into_iter()
            .enumerate()
        {
            f.iter_mut().for_each(|x| *x = 0.0);
            let h = if link == 0 {
                self.inertia.h1
            } else {
                self.inertia.h2
            };
            let lp = &self.links[link];
            let slot = self.slots[link];
            let (_, gx) = Self::ghost_bending(h, lp.ei, &self.qk[range.clone()], q[slot], f);
            let mut fx = gx;
            if lp.gamma != 0.0 && damp {
                let (d2, gv) =
                    Self::ghost_bending(h, lp.gamma, &self.vk[range.clone()], v[slot], f);
                p_kv += 2.0 * d2;
                fx += gv;
            }
            let r = f.len();
            f[r - 1] = fx; // the tip entry carries the ghost's force
            out[range].copy_from_slice(f);
        }
        if let Some(y) = self.tip_ghost {
            // link 1's tip term of the bending energy (elbow moment EIκ_r) and its Kelvin–Voigt
            // dissipation
            let (h, lp, u) = (self.hs[0], &self.links[0], self.inertia.i_tip1() - 1);
            let (_, g) = Self::tip_bending(h, lp.ei, q[u], q[y]);
            let (mut fy, mut fu) = (-g, -g);
            if lp.gamma != 0.0 && damp {
                let (d2, gv) = Self::tip_bending(h, lp.gamma, v[u], v[y]);
                p_kv += 2.0 * d2;
                fy -= gv;
                fu -= gv;
            }
            out[y] = fy;
            out[u] += fu;
        }
        let th2 = self.elbow(q);
        let th2d = self.elbow(v);
        let j = &self.joints;
        let ext = [j[0].torque(t), j[1].torque(t)];
        let th1 = self.clamp_angle(q, 0);
        let th1d = self.clamp_angle(v, 0);
        let dj = if damp {
            [j[0].damping, j[1].damping]
        } else {
            [0.0; 2]
        };
        let tau1 = ext[0] - j[0].stiffness * (th1 - j[0].set_point) - dj[0] * th1d;
        let tau2 = ext[1] - j[1].stiffness * (th2 - j[1].set_point) - dj[1] * th2d;
        // τ₁ on θ₁ (clamp angle of link 1); τ₂ on θ₂ = clamp angle of link 2 − θ − ψ(v)
        self.add_clamp(0, tau1, out);
        self.add_clamp(1, tau2, out);
        out[TH] -= tau2;
        for (i, c) in self.slope_stencil() {
            out[i] -= tau2 * c;
        }
        self.torques = [tau1, tau2];
        let qk = std::mem::take(&mut self.qk);
        self.gravity_potential(&qk, Some(out));
        self.qk = qk;
        self.power = [
            ext[0] * th1d + ext[1] * th2d,
            j[0].damping * th1d * th1d + j[1].damping * th2d * th2d,
            p_kv,
        ];
    }
}

impl TwoLinkChain {
    /// Adds the damping forces −∂D/∂q̇ = −C q̇ at `v` into `out`: Kelvin–Voigt (the ghost-node
    /// bending stencil on the rates, link 1's tip term) and the joint dampers (Euler links;
    /// the same terms as [`Self::forces`]). Linear in `v` with constant C.
    pub(crate) fn add_damping_forces(&mut self, v: &[f64], out: &mut [f64]) {
        let mut vd = std::mem::take(&mut self.vd);
        vd.copy_from_slice(v);
        for s in self.ghosts() {
            vd[s] = 0.0;
        }
        let (iv, iw) = (self.inertia.iv(), self.inertia.iw());
        for (link, (range, f)) in [(iv, &mut self.fv), (iw, &mut self.fw)]
            .into_iter()
            .enumerate()
        {
            let lp = &self.links[link];
            if lp.gamma == 0.0 {
                continue;
            }
            f.iter_mut().for_each(|x| *x = 0.0);
            let slot = self.slots[link];
            let (_, gv) =
                Self::ghost_bending(self.hs[link], lp.gamma, &vd[range.clone()], v[slot], f);
            let r = f.len();
            f[r - 1] = gv;
            for (o, x) in out[range].iter_mut().zip(f.iter()) {
                *o += x;
            }
        }
        if let Some(y) = self.tip_ghost {
            let (h, lp, u) = (self.hs[0], &self.links[0], self.inertia.i_tip1() - 1);
            if lp.gamma != 0.0 {
                let (_, g) = Self::tip_bending(h, lp.gamma, v[u], v[y]);
                out[y] -= g;
                out[u] -= g;
            }
        }
        let tau1 = -self.joints[0].damping * self.clamp_angle(v, 0);
        let tau2 = -self.joints[1].damping * self.elbow(v);
        self.add_clamp(0, tau1, out);
        self.add_clamp(1, tau2, out);
        out[TH] -= tau2;
        for (i, c) in self.slope_stencil() {
            out[i] -= tau2 * c;
        }
        self.vd = vd;
    }
}

impl System for TwoLinkChain {
    fn dofs(&self) -> usize {
        self.inertia.dofs() + usize::from(self.tip_ghost.is_some())
    }

    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        let n = self.dofs();
        let mut rhs = std::mem::take(&mut self.rhs);
        self.chord(q, v);
        self.forces(t, q, v, &mut rhs);
        self.add_inertia_terms(1.0, a, &mut rhs);
        self.build_columns();
        self.solve_mass(&rhs, a);
        self.rhs = rhs;
        self.lambda = 0.0;
        if self.constrained {
            // M q̈ = f + Gᵀλ with G q̈ + Ġq̇ = 0: q̈ = a_free + M⁻¹Gᵀ λ,
            // λ = −(G a_free + Ġq̇)/(G M⁻¹Gᵀ) — one more solve with the same M.
            let (gmg, curv) = self.constraint_solve();
            let ga: f64 = (0..n).map(|i| self.grow[i] * a[i]).sum();
            // a non-positive GM⁻¹Gᵀ means M lost definiteness: NaN stops the contact driver
            let lam = if gmg > 0.0 {
                -(ga + curv) / gmg
            } else {
                f64::NAN
            };
            for i in 0..n {
                a[i] += self.minv_g[i] * lam;
            }
            self.lambda = lam;
        }
    }

    fn implicit_kick(
        &mut self,
        t: f64,
        q: &[f64],
        inertia: DriftVelocities,
        tau: f64,
        a: &mut [f64],
    ) -> bool {
        if self.implicit.is_none() || self.constrained {
            return false;
        }
        self.implicit_kick_solve(t, q, inertia, tau, a);
        true
    }

    fn accel_split(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        inertia: DriftVelocities,
        a: &mut [f64],
    ) {
        if self.constrained {
            // the constrained phase runs in the contact driver (`accel`): Ġq̇ and Γ at `v`
            self.accel(t, q, v, a);
            return;
        }
        let mut rhs = std::mem::take(&mut self.rhs);
        self.chord(q, v);
        self.forces(t, q, v, &mut rhs);
        // −Γ from the drift velocities (integrator docs): (1 + w)Γ[v_{j+½}] − wΓ[v_{j−½}]
        self.chord(q, inertia.current);
        self.add_inertia_terms(1.0 + inertia.w, a, &mut rhs);
        if inertia.w != 0.0 {
            self.chord(q, inertia.previous);
            self.add_inertia_terms(-inertia.w, a, &mut rhs);
        }
        self.build_columns();
        self.solve_mass(&rhs, a);
        self.rhs = rhs;
        self.lambda = 0.0;
    }

    /// On the surface g = 0 along M⁻¹Gᵀ while the tip is held ([`contact`]).
    fn project_position(&mut self, q: &mut [f64]) {
        if self.constrained {
            self.last_projection[0] = self.project_onto_surface(q);
        }
    }

    /// Onto Gq̇ = 0 along M⁻¹Gᵀ while the tip is held ([`contact`]).
    fn project_velocity(&mut self, v: &mut [f64]) {
        if self.constrained {
            let (gv, energy) = self.remove_normal_velocity(v);
            self.last_projection[1] = gv;
            self.last_projection[2] = energy;
        }
    }

    fn powers(&self, out: &mut [f64]) {
        let mut k = 0;
        if self.any_law() {
            out[k] = self.power[0];
            k += 1;
        }
        if self.any_damper() {
            out[k] = self.power[1];
            k += 1;
        }
        if self.any_kv() {
            out[k] = self.power[2];
            k += 1;
        }
        if self.contact.is_some() {
            // the impact loss is a jump booked by the contact driver; the frictionless fixed
            // surface does no work while the tip slides (λ Gq̇ = 0)
            out[k] = 0.0;
        }
    }

    fn bound(&self, _t: f64) -> Bound {
        self.step_bound()
    }

    fn stored_energies(&self, _t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let ine = &self.inertia;
        let mut qk = self.obs_scratch.borrow_mut();
        let mut vk = self.obs_scratch_v.borrow_mut();
        qk.copy_from_slice(q);
        vk.copy_from_slice(v);
        for s in self.ghosts() {
            qk[s] = 0.0;
            vk[s] = 0.0;
        }
        let mut ke = ine.kinetic(&qk, &vk);
        let mut strain = FloatingLink::bending_energy(ine.h1, self.links[0].ei, &qk[ine.iv()])
            + FloatingLink::bending_energy(ine.h2, self.links[1].ei, &qk[ine.iw()]);
        for k in 0..2 {
            let (h, c) = (self.hs[k], self.links[k].ei);
            let (u1, x) = (q[self.first(k)], q[self.slots[k]]);
            ke += 0.5 * self.jc[k] * self.clamp_angle(v, k).powi(2);
            // κ₀ = (u₁ + x)/h² instead of the single link's 2u₁/h²
            strain += c * ((u1 + x).powi(2) / 4.0 - u1 * u1) / (h * h * h);
        }
        if let Some(y) = self.tip_ghost {
            ke += 0.5 * self.jt * self.tip_angle(v).powi(2);
            let u = q[ine.i_tip1() - 1];
            strain += Self::tip_bending(self.hs[0], self.links[0].ei, u, q[y]).0;
        }
        let j = &self.joints;
        let mut spring = 0.5 * j[0].stiffness * (self.clamp_angle(q, 0) - j[0].set_point).powi(2)
            + 0.5 * j[1].stiffness * (self.elbow(q) - j[1].set_point).powi(2);
        if let Some(t) = &self.timo {
            // condensed U(y, z₀(y)): strain (bending + shear) and joint springs
            let parts = t.energies(q);
            strain = parts.links;
            spring = parts.joints;
        }
        out[..3].copy_from_slice(&[ke, strain, spring]);
        if self.gravity.is_some() {
            out[3] = self.gravity_potential(&qk, None);
        }
    }

    fn monitored(&self) -> std::ops::Range<usize> {
        2..self.dofs()
    }

    /// The tip sits on the chord (v_r = 0), so its deflection in the clamp-tangent frame — the
    /// `tip_deflection` channel, fem's and modal's coordinate — is L·(−ε): beyond L once the
    /// clamp slope against the chord passes 1, where no small-slope beam model holds.
    /// Timoshenko links take the first segment's slope v₁/h for ε (it differs from the clamp
    /// section's rotation by the shear angle): the section rotation needs the condensation
    /// solve, too much for a check made at every step.
    fn overextended(&self, q: &[f64]) -> Option<Overextension> {
        let turns = match &self.timo {
            Some(_) => [0, 1].map(|l| -q[self.first(l)] / self.hs[l]),
            None => self.clamp_frame_turns(q),
        };
        (0..2).find_map(|l| {
            let length = self.links[l].length;
            let deflection = length * turns[l];
            (deflection.abs() > length).then_some(Overextension {
                link: l + 1,
                deflection,
                length,
                model: DeflectionModel::ChordFrames,
            })
        })
    }

    fn damped(&self) -> bool {
        // free joints: velocity-coupled (gyroscopic) inertia forces, as the torque-driven link
        true
    }
}
