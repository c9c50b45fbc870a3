//! The chain as a [`System`] of the integrators: accelerations from the Schur-complement mass
//! solve (with the contact constraint while the tip is held), the split form of the velocity
//! scheme and its implicit damping kick, the drift projections of the constrained phase, the
//! ledger's powers and stored energies, the step bound and the overextension check.

use super::model::TwoLinkChain;
use crate::link::FloatingLink;
use crate::system::{Bound, DeflectionModel, DriftVelocities, Overextension, System, law_jumps};

impl System for TwoLinkChain {
    fn dofs(&self) -> usize {
        self.inertia.dofs() + usize::from(self.tip_ghost.is_some())
    }

    fn jumps(&self) -> Vec<f64> {
        law_jumps(self.joints.iter().filter_map(|j| j.law.as_ref()))
    }

    fn close_stretch_at(&mut self, jump: Option<f64>) {
        self.closing = jump;
    }

    /// The points' positions depend on the frame angles and, through foreshortening and the
    /// clamp-tangent frames, on the deflections.
    fn has_velocity_quadratic_inertia(&self) -> bool {
        true
    }

    fn accel(&mut self, t: f64, q: &[f64], v: &[f64], a: &mut [f64]) {
        let n = self.dofs();
        let mut rhs = std::mem::take(&mut self.rhs);
        self.frames(q, v);
        self.forces(t, q, v, &mut rhs);
        self.add_inertia_terms(1.0, a, &mut rhs);
        self.build_columns();
        self.solve_mass(&rhs, a);
        self.rhs = rhs;
        self.constraint.lambda = 0.0;
        if self.constraint.constrained {
            // M q̈ = f + Gᵀλ with G q̈ + Ġq̇ = 0: q̈ = a_free + M⁻¹Gᵀ λ,
            // λ = −(G a_free + Ġq̇)/(G M⁻¹Gᵀ) — one more solve with the same M.
            let (gmg, curv) = self.constraint_solve();
            let ga: f64 = (0..n).map(|i| self.constraint.grow[i] * a[i]).sum();
            // a GM⁻¹Gᵀ that is not a positive number (a failed mass solve) stops the contact
            // driver through NaN
            let lam = if gmg > 0.0 {
                -(ga + curv) / gmg
            } else {
                f64::NAN
            };
            for i in 0..n {
                a[i] += self.constraint.minv_g[i] * lam;
            }
            self.constraint.lambda = lam;
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
        if self.implicit.is_none() {
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
        if self.constraint.constrained {
            // the constrained phase runs in the contact driver (`accel`): Ġq̇ and Γ at `v`
            self.accel(t, q, v, a);
            return;
        }
        let mut rhs = std::mem::take(&mut self.rhs);
        // −Γ from the drift velocities (integrator docs): (1 + w)Γ[current] − wΓ[previous]
        let reuse = self.split_reuse.matches(t, q, v, inertia.current);
        if reuse {
            // the corrector pass: the same arithmetic as below on the first pass's parts
            rhs.copy_from_slice(&self.split_reuse.rest);
            self.add_scaled_inertia(1.0 + inertia.w, &self.split_reuse.current_forces, &mut rhs);
        } else {
            self.frames(q, v);
            self.forces(t, q, v, &mut rhs);
            self.split_reuse.rest.copy_from_slice(&rhs);
            self.frames_velocity(inertia.current);
            self.add_inertia_terms(1.0 + inertia.w, a, &mut rhs);
            self.split_reuse.current_forces.copy_from_slice(a);
        }
        if inertia.w != 0.0 {
            // the reused pass's q equals the first pass's only as numbers (±0)
            if reuse {
                self.frames(q, inertia.previous);
            } else {
                self.frames_velocity(inertia.previous);
            }
            self.add_inertia_terms(-inertia.w, a, &mut rhs);
        }
        if !reuse {
            self.build_columns();
            let r = &mut self.split_reuse;
            r.valid = true;
            r.t = t;
            r.q.copy_from_slice(q);
            r.v.copy_from_slice(v);
            r.current.copy_from_slice(inertia.current);
        }
        self.solve_mass(&rhs, a);
        self.rhs = rhs;
        self.constraint.lambda = 0.0;
    }

    /// On the surface g = 0 along M⁻¹Gᵀ while the tip is held ([`super::contact`]).
    fn project_position(&mut self, q: &mut [f64]) {
        if self.constraint.constrained {
            self.constraint.last_projection[0] = self.project_onto_surface(q);
        }
    }

    /// Onto Gq̇ = 0 along M⁻¹Gᵀ while the tip is held ([`super::contact`]).
    fn project_velocity(&mut self, v: &mut [f64]) {
        if self.constraint.constrained {
            let (gv, energy) = self.remove_normal_velocity(v);
            self.constraint.last_projection[1] = gv;
            self.constraint.last_projection[2] = energy;
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
        // the bending energy reads the chord-frame deflections (tip on the chord)
        qk.copy_from_slice(q);
        for s in self.ghosts() {
            qk[s] = 0.0;
        }
        let mut strain = FloatingLink::bending_energy(ine.h1, self.links[0].ei, &qk[ine.iv()])
            + FloatingLink::bending_energy(ine.h2, self.links[1].ei, &qk[ine.iw()]);
        // T and V_g: the kernel's coordinates (the clamp-tangent frames, Euler links)
        self.to_kinetic(q, &mut qk);
        self.to_kinetic(v, &mut vk);
        let mut ke = ine.kinetic(&qk, &vk, &mut self.obs_points.borrow_mut());
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
