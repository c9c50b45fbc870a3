//! The chain's data and its coordinate maps: [`TwoLinkChain`] (links, joints, the lumped
//! inertia, the ghost slots, the tip contact and its constraint state, the implicit damping,
//! scratch), and the angles and inertia directions read off q: clamp tangents, link 1's tip
//! slope ψ and tip-section angle, the elbow angle θ₂, the map P to the kinetic kernel's
//! coordinates (clamp-tangent frames) and its transposes, the chord-frame copies, the lumped diagonal of M (module docs of [`super`]).

use data::scene::TorqueLaw;

use crate::system::law_torque;

use super::damping_matrix::ImplicitDamping;
use super::kinetic::{BE, ChainInertia, TH};
use super::kinetic::{Lanes, PointScratch, RateLanes};
use super::rates::MassFactors;
use super::schur::MAX_FULL;
use super::surface::{TipConstraint, TipContact};
use super::timoshenko::TimoFields;

/// Bound sites ≥ this are the Timoshenko links' shear bounds.
pub(super) const SHEAR_SITE: usize = 10;
/// Bound site of link 1's tip-ghost rotation mode (Euler links).
pub(super) const TIP_SITE: usize = 5;

/// A joint's spring, damper, set point and applied torque law.
#[derive(Debug, Clone, Default)]
pub(super) struct JointLaw {
    pub(super) stiffness: f64,
    pub(super) damping: f64,
    pub(super) set_point: f64,
    pub(super) law: Option<TorqueLaw>,
}

impl JointLaw {
    /// The applied torque at t, or on the stretch being closed
    /// ([`crate::system::System::close_stretch_at`]).
    pub(super) fn torque(&self, t: f64, closing: Option<f64>) -> f64 {
        law_torque(self.law.as_ref(), t, closing)
    }
}

/// A link's length, bending stiffness EI, Kelvin–Voigt coefficient γ and mass per length ρA.
#[derive(Debug, Clone)]
pub(super) struct LinkProps {
    pub(super) length: f64,
    pub(super) ei: f64,
    pub(super) gamma: f64,
    pub(super) rho_a: f64,
}

/// The two-link chain as a [`System`](crate::system::System).
#[derive(Debug, Clone)]
pub struct TwoLinkChain {
    pub inertia: ChainInertia,
    pub(super) links: [LinkProps; 2],
    pub(super) joints: [JointLaw; 2],
    pub(super) init: [(f64, f64); 2],
    pub(super) field_stations: usize,
    /// highest angular frequency of the linearized chain at t = 0 (power iteration)
    pub omega_max: f64,
    /// bound site of that mode (a clamp's or the tip's rotation mode, else the coupled
    /// chain's; `Outputs::describe`)
    pub(super) omega_max_site: usize,
    /// fastest damping rate of the linearized chain at t = 0 (power iteration on −∂a/∂q̇)
    pub kappa_max: f64,
    /// clamp half-cell rotary inertias ρA h³/24 of links 1 and 2
    pub(super) jc: [f64; 2],
    /// Euler links: q-slot of link 1's tip ghost y = v_{r+1} (the elbow section's turn from
    /// the chord, ψ = (y − v_{r−1})/(2h₁)) and the tip half cell's rotary inertia ρA₁h₁³/24;
    /// Timoshenko links: none (link 1's tip section is the condensed ψ)
    pub(super) tip_ghost: Option<usize>,
    pub(super) jt: f64,
    /// q-slots of the clamp ghost deflections x₁, x₂ (station 1 of each link is the chord
    /// frame's zero) and the link steps
    pub(super) slots: [usize; 2],
    pub(super) hs: [f64; 2],
    /// (q, q̇) in the kinetic kernel's coordinates ([`TwoLinkChain::to_kinetic`])
    pub(super) qk: Vec<f64>,
    pub(super) vk: Vec<f64>,
    /// (q, q̇) with the ghost slots zeroed: the chord-frame deflections of the bending energy
    pub(super) qc: Vec<f64>,
    pub(super) vc: Vec<f64>,
    /// gravity-force scratch in the kernel's coordinates
    pub(super) gk: Vec<f64>,
    pub(super) obs_scratch: std::cell::RefCell<Vec<f64>>,
    pub(super) obs_scratch_v: std::cell::RefCell<Vec<f64>>,
    // scratch (allocated once)
    pub(super) points: PointScratch,
    pub(super) obs_points: std::cell::RefCell<PointScratch>,
    /// the factors of the mass solve at the state of the last `build_columns`
    pub(super) factors: MassFactors,
    /// the full columns of M: θ, β, x₁, x₂ and (Euler) the tip ghost y
    pub(super) cols: [Vec<f64>; MAX_FULL],
    /// the kernel's rates at unit rate of each state-dependent full column, and their
    /// deflection rates with their segment slopes lane by lane
    pub(super) units: [Vec<f64>; 4],
    pub(super) unit_lanes: RateLanes<4>,
    /// the per-point scratch of the columns' products, one lane each
    pub(super) column_lanes: Lanes<4>,
    /// the inertia terms at two drift velocities together: the second velocity in the
    /// kernel's coordinates, its forces and the per-point scratch
    pub(super) vk2: Vec<f64>,
    pub(super) f2: Vec<f64>,
    pub(super) inertia_lanes: Lanes<2>,
    /// [`Self::add_inertia_terms_pair`]'s two velocities' rates and slopes, lane by lane.
    pub(super) drift_lanes: RateLanes<2>,
    /// the rate slopes of the inertia terms' pair
    /// ([`super::kinetic::ChainInertia::rate_slopes`]): scratch, then those of the last pair's
    /// current drift velocity in the kernel's coordinates, `drift_slopes_of` (once
    /// `drift_slopes_valid`)
    pub(super) drift_slopes: [Vec<f64>; 2],
    pub(super) drift_slopes_of: Vec<f64>,
    pub(super) drift_slopes_valid: bool,
    pub(super) rhs: Vec<f64>,
    /// what the velocity form's corrector pass may take from the first pass at the same level
    pub(super) split_reuse: SplitReuse,
    pub(super) fv: Vec<f64>,
    pub(super) fw: Vec<f64>,
    pub(super) power: [f64; 3],
    pub(super) torques: [f64; 2],
    /// uniform gravity (inertial gx, gy), if the scene has it
    pub(super) gravity: Option<[f64; 2]>,
    /// gravity weights of link 1's foreshortening: outboard mass of each segment plus the
    /// whole of link 2 (which rides on link 1's tip)
    pub(super) mu1g: Vec<f64>,
    /// the tip contact of link 2, if any ([`super::contact`])
    pub(super) contact: Option<TipContact>,
    /// the state of the contact constraint g = 0: phase, normal force, G and M⁻¹Gᵀ, last
    /// projections
    pub(super) constraint: TipConstraint,
    /// the damping matrix C and the banded factorization of the implicit kick ([`super::implicit`]);
    /// none: damping explicit in the forces
    pub(super) implicit: Option<Box<ImplicitDamping>>,
    /// `forces` leaves the damping out (the implicit kick adds it at the drift velocity)
    pub(super) skip_damping: bool,
    /// the jump the step being closed ends on: the forces and powers take the torque laws'
    /// left limits there ([`crate::system::System::close_stretch_at`])
    pub(super) closing: Option<f64>,
    /// scratch of [`Self::add_damping_forces`] and the implicit kick (length n)
    pub(super) vd: Vec<f64>,
    /// Timoshenko links (`shear` on both): the condensed section rotations ([`super::timoshenko`]);
    /// the ghost slots are then unused (held at zero with a unit dummy mass)
    pub(super) timo: Option<TimoFields>,
}

impl TwoLinkChain {
    pub(super) fn any_law(&self) -> bool {
        self.joints.iter().any(|j| j.law.is_some())
    }

    pub(super) fn any_damper(&self) -> bool {
        self.joints.iter().any(|j| j.damping != 0.0)
    }

    pub(super) fn any_kv(&self) -> bool {
        self.links.iter().any(|l| l.gamma != 0.0)
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
    pub(super) fn slope_stencil(&self) -> [(usize, f64); 2] {
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
    pub(super) fn tip_angle(&self, q: &[f64]) -> f64 {
        let psi: f64 = self.slope_stencil().iter().map(|(i, c)| c * q[*i]).sum();
        q[TH] + psi
    }

    /// Adds J_t e eᵀ·(scale) of link 1's tip-section rotation to a column/momentum vector:
    /// e = ∂(θ + ψ)/∂q (1 at θ, 1/(2h) at y, −1/(2h) at v_{r−1}); nothing without a tip ghost.
    pub(super) fn add_tip(&self, weight: f64, out: &mut [f64]) {
        if self.tip_ghost.is_some() {
            out[TH] += weight;
            for (i, c) in self.slope_stencil() {
                out[i] += weight * c;
            }
        }
    }

    /// q-index of station 1 of link ℓ.
    pub(super) fn first(&self, link: usize) -> usize {
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

    /// Elbow angle θ₂ = (clamp tangent of link 2) − θ − ψ (applied to q or q̇).
    pub fn elbow(&self, q: &[f64]) -> f64 {
        let psi: f64 = self.slope_stencil().iter().map(|(i, c)| c * q[*i]).sum();
        self.clamp_angle(q, 1) - q[TH] - psi
    }

    /// The copies of (q, q̇) the forces read: `qc`, `vc` with the ghost slots zeroed (the
    /// chord-frame deflections of the bending energy, v_r = 0) and `qk`, `vk` in the kinetic
    /// kernel's coordinates ([`Self::to_kinetic`]: the clamp-tangent frames).
    pub(super) fn frames(&mut self, q: &[f64], v: &[f64]) {
        self.qc.copy_from_slice(q);
        for s in self.ghosts() {
            self.qc[s] = 0.0;
        }
        self.set_kinetic_q(q);
        self.frames_velocity(v);
    }

    /// [`Self::frames`] at the q of the last call: only the velocity copies `vc`, `vk` change.
    pub(super) fn frames_velocity(&mut self, v: &[f64]) {
        self.vc.copy_from_slice(v);
        for s in self.ghosts() {
            self.vc[s] = 0.0;
        }
        let mut vk = std::mem::take(&mut self.vk);
        self.to_kinetic(v, &mut vk);
        self.vk = vk;
    }

    /// `qk` ← the kernel's coordinates of q, with their shape in the point scratch (what the
    /// mass columns, M x and the inertia terms read): every write of `qk` goes through here.
    pub(super) fn set_kinetic_q(&mut self, q: &[f64]) {
        let mut qk = std::mem::take(&mut self.qk);
        self.to_kinetic(q, &mut qk);
        self.inertia.set_shape(&qk, &mut self.points);
        self.qk = qk;
    }

    /// The frame-angle slot, the first station, the ghost slot and the step of link ℓ.
    fn link_slots(&self, link: usize) -> (usize, usize, usize, f64) {
        let frame = if link == 0 { TH } else { BE };
        (frame, self.first(link), self.slots[link], self.hs[link])
    }

    /// The abscissae (k+1)h of link ℓ's stations 1…r.
    fn abscissae(&self, link: usize) -> &[f64] {
        if link == 0 {
            &self.inertia.x1
        } else {
            &self.inertia.x2
        }
    }

    /// q (or q̇) → the coordinates of the kinetic kernel ([`super::kinetic`]: frame angles,
    /// deflections of stations 1…r with the tip's in the ghost slot), a constant linear map P.
    /// Euler links: the clamp-tangent frames, α = (chord angle) + ψ, v^t_k = v_k − ξ_kψ (tip
    /// −Lψ), ψ = (v₁ − x)/(2h) the clamp tangent's turn from the chord. Timoshenko links:
    /// the chord frames (ghost slots zeroed, tips on the chord). Link 1's tip ghost is zeroed.
    pub fn to_kinetic(&self, q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(q);
        for s in self.ghosts() {
            out[s] = 0.0;
        }
        if self.timo.is_some() {
            return;
        }
        for link in 0..2 {
            let (frame, first, slot, h) = self.link_slots(link);
            let psi = (q[first] - q[slot]) / (2.0 * h);
            out[frame] += psi;
            for (x, o) in self.abscissae(link).iter().zip(&mut out[first..=slot]) {
                *o -= x * psi;
            }
        }
    }

    /// f ← Pᵀf in place: generalized forces in the kernel's coordinates ([`Self::to_kinetic`])
    /// to forces on q. Zero at link 1's tip ghost (and, Timoshenko, at the ghost slots).
    pub fn kinetic_transpose(&self, f: &mut [f64]) {
        self.kinetic_transpose_z(f);
        self.z_to_q_forces(f);
    }

    /// f ← P_zᵀf: as [`Self::kinetic_transpose`] but onto the mass solve's coordinates z, which
    /// carry ψ (instead of the ghost x) in each ghost slot (Euler links; [`super::mass`]).
    pub(super) fn kinetic_transpose_z(&self, f: &mut [f64]) {
        for s in self.ghosts() {
            if self.timo.is_some() || Some(s) == self.tip_ghost {
                f[s] = 0.0;
            }
        }
        if self.timo.is_some() {
            return;
        }
        for link in 0..2 {
            let (frame, first, slot, _) = self.link_slots(link);
            let mut psi = f[frame];
            for (x, fi) in self.abscissae(link).iter().zip(&f[first..=slot]) {
                psi -= x * fi;
            }
            f[slot] = psi;
        }
    }

    /// [`Self::kinetic_transpose_z`] of `C` vectors at once (their sums over the stations
    /// overlap).
    pub(super) fn kinetic_transpose_z_lanes<const C: usize>(&self, f: &mut [&mut [f64]; C]) {
        for s in self.ghosts() {
            if self.timo.is_some() || Some(s) == self.tip_ghost {
                for fc in f.iter_mut() {
                    fc[s] = 0.0;
                }
            }
        }
        if self.timo.is_some() {
            return;
        }
        for link in 0..2 {
            let (frame, first, slot, _) = self.link_slots(link);
            let mut psi: [f64; C] = std::array::from_fn(|c| f[c][frame]);
            for (&x, i) in self.abscissae(link).iter().zip(first..=slot) {
                for c in 0..C {
                    psi[c] -= x * f[c][i];
                }
            }
            for c in 0..C {
                f[c][slot] = psi[c];
            }
        }
    }

    /// f ← Qᵀf: forces on z (ψ in the ghost slots) to forces on q (x in the ghost slots),
    /// ψ = (v₁ − x)/(2h). Identity for Timoshenko links.
    pub(super) fn z_to_q_forces(&self, f: &mut [f64]) {
        if self.timo.is_some() {
            return;
        }
        for link in 0..2 {
            let (_, first, slot, h) = self.link_slots(link);
            let psi = f[slot];
            f[first] += psi / (2.0 * h);
            f[slot] = -psi / (2.0 * h);
        }
    }

    /// r ← Q⁻ᵀr: a right-hand side on q to one on z (the inverse of [`Self::z_to_q_forces`]).
    pub(super) fn q_to_z_forces(&self, r: &mut [f64]) {
        if self.timo.is_some() {
            return;
        }
        for link in 0..2 {
            let (_, first, slot, h) = self.link_slots(link);
            r[first] += r[slot];
            r[slot] *= -2.0 * h;
        }
    }

    /// a ← Q⁻¹a: velocities/accelerations on z to q (x = v₁ − 2hψ).
    pub(super) fn z_to_q_motion(&self, a: &mut [f64]) {
        if self.timo.is_some() {
            return;
        }
        for link in 0..2 {
            let (_, first, slot, h) = self.link_slots(link);
            a[slot] = a[first] - 2.0 * h * a[slot];
        }
    }

    /// The ghost slots: the clamp ghosts and (Euler) link 1's tip ghost (no chord-frame
    /// deflection; the tip ghost moves no lumped mass).
    pub(super) fn ghosts(&self) -> impl Iterator<Item = usize> + use<> {
        self.slots.into_iter().chain(self.tip_ghost)
    }

    /// Diagonal mass of coordinate i outside the full columns in the mass solve's coordinates
    /// z (the clamp angle is frame + ψ there, so only link 1's tip section adds to a station).
    pub(super) fn diag_mass(&self, i: usize) -> f64 {
        let mut d = self.inertia.diag_mass(i);
        if self.tip_ghost.is_some() && i == self.inertia.i_tip1() - 1 {
            d += self.jt / (4.0 * self.hs[0] * self.hs[0]);
        }
        d
    }

    /// Adds J_c e eᵀ·(scale at `along`) of link ℓ's clamp rotation to a column/momentum vector:
    /// e = ∂(clamp angle)/∂q (1 at the frame, ±1/(2h) at station 1 and the ghost).
    pub(super) fn add_clamp(&self, link: usize, weight: f64, out: &mut [f64]) {
        let frame = if link == 0 { TH } else { BE };
        let a = 1.0 / (2.0 * self.hs[link]);
        out[frame] += weight;
        out[self.first(link)] += weight * a;
        out[self.slots[link]] -= weight * a;
    }

    /// As [`Self::add_clamp`] in the mass solve's coordinates z: e = 1 at the frame and at ψ.
    pub(super) fn add_clamp_z(&self, link: usize, weight: f64, out: &mut [f64]) {
        let frame = if link == 0 { TH } else { BE };
        out[frame] += weight;
        out[self.slots[link]] += weight;
    }
}

/// The velocity form's corrector pass calls `accel_split` a second time at the same level
/// (same t, q, predicted velocity and current drift velocity; only the other drift velocity and
/// the weights change): the forces other than the inertia terms, Γ at the current drift
/// velocity and M's columns are those of the first pass. Valid only while nothing else has
/// evaluated forces or rebuilt the columns since.
#[derive(Debug, Clone)]
pub(super) struct SplitReuse {
    pub(super) valid: bool,
    pub(super) t: f64,
    pub(super) q: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) current: Vec<f64>,
    /// the forces before the inertia terms
    pub(super) rest: Vec<f64>,
    /// the inertia-term forces at the current drift velocity, unscaled
    pub(super) current_forces: Vec<f64>,
}

impl SplitReuse {
    pub(super) fn new(n: usize) -> Self {
        SplitReuse {
            valid: false,
            t: f64::NAN,
            q: vec![0.0; n],
            v: vec![0.0; n],
            current: vec![0.0; n],
            rest: vec![0.0; n],
            current_forces: vec![0.0; n],
        }
    }

    /// Whether a call at (t, q, v, current) repeats the stored first pass.
    pub(super) fn matches(&self, t: f64, q: &[f64], v: &[f64], current: &[f64]) -> bool {
        self.valid && self.t == t && self.q == q && self.v == v && self.current == current
    }
}
