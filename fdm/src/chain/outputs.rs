//! The chain's observables and ledger terms: joint angles/rates (clamp angles), torques =
//! law + spring + damper, tip positions, deflections in the clamp-tangent frame, the contact
//! channels.

use data::{channel, ledger_term};

use super::kinetic::{BE, TH, seg_energy};
use super::model::{SHEAR_SITE, TIP_SITE, TwoLinkChain};
use crate::output::{Outputs, sample_field};
use crate::system::Bound;

impl Outputs for TwoLinkChain {
    fn describe(&self, b: &Bound) -> String {
        if b.site >= SHEAR_SITE {
            format!(
                "link {} shear sawtooth of the condensed Timoshenko operator (σ = h√(ρA/κGA))",
                b.site - SHEAR_SITE + 1
            )
        } else if b.site == TIP_SITE {
            "tip-rotation mode of link 1 (tip ghost node against J_t)".into()
        } else if b.site >= 3 {
            format!(
                "clamp-rotation mode of link {} (ghost node against J_c)",
                b.site - 2
            )
        } else if b.site == 2 {
            "the coupled chain's highest mode (power iteration at t = 0)".into()
        } else {
            format!("link {} (uniform: every segment)", b.site + 1)
        }
    }

    fn channels(&self) -> Vec<(String, &'static str)> {
        let mut c = Vec::new();
        for j in 1..=2 {
            c.push(channel::spec::joint_angle(j));
            c.push(channel::spec::joint_rate(j));
            c.push(channel::spec::joint_torque(j));
        }
        for l in 1..=2 {
            c.push(channel::spec::tip_x(l));
            c.push(channel::spec::tip_y(l));
            c.push(channel::spec::tip_deflection(l));
            for k in 0..self.field_stations {
                c.push(channel::spec::field_deflection(l, k));
            }
        }
        if self.contact.is_some() {
            c.push(channel::spec::contact_normal_force(1));
            c.push(channel::spec::contact_phase(1));
            // the gap, negative = penetration
            c.push(channel::spec::contact_gap(1));
        }
        c
    }

    fn observe(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let ine = &self.inertia;
        let mut qk = self.obs_scratch.borrow_mut();
        // the kernel's coordinates: Euler links in the clamp-tangent frames (deflections
        // v^t = v − ξψ, tip −Lψ), Timoshenko links in the chord frames (tip on the chord)
        self.to_kinetic(q, &mut qk);
        let (vs, ws) = (&qk[ine.iv()], &qk[ine.iw()]);
        let [th1, th2] = match &self.timo {
            Some(t) => t.joint_angles_with_lag(q, v),
            None => self.joint_angles(q),
        };
        let [th1d, th2d] = self.joint_rates(v);
        let j = &self.joints;
        // joint torques: applied law + spring + damper at this state
        let tau1 =
            j[0].torque(t, None) - j[0].stiffness * (th1 - j[0].set_point) - j[0].damping * th1d;
        let tau2 =
            j[1].torque(t, None) - j[1].stiffness * (th2 - j[1].set_point) - j[1].damping * th2d;
        out[0] = th1;
        out[1] = th1d;
        out[2] = tau1;
        out[3] = th2;
        out[4] = th2d;
        out[5] = tau2;
        // Timoshenko: deflections turned into the clamp section's frame, u − Xε (small angle)
        let turns = match &self.timo {
            Some(_) => self.clamp_frame_turns(q),
            None => [0.0; 2],
        };
        let s1 = if ine.fs1 {
            seg_energy(vs, ine.h1, None)
        } else {
            0.0
        };
        let s2 = if ine.fs2 {
            seg_energy(ws, ine.h2, None)
        } else {
            0.0
        };
        let (c1, n1) = (qk[TH].cos(), qk[TH].sin());
        let (c2, n2) = (qk[BE].cos(), qk[BE].sin());
        let (x1, y1) = (self.links[0].length - s1, vs[ine.r1 - 1]);
        let tip1 = (c1 * x1 - n1 * y1, n1 * x1 + c1 * y1);
        let (x2, y2) = (self.links[1].length - s2, ws[ine.r2 - 1]);
        let tip2 = (tip1.0 + c2 * x2 - n2 * y2, tip1.1 + n2 * x2 + c2 * y2);
        let nf = self.field_stations;
        let mut k = 6;
        for (l, (tip, us, h)) in [(tip1, vs, ine.h1), (tip2, ws, ine.h2)]
            .into_iter()
            .enumerate()
        {
            let turn = turns[l];
            out[k] = tip.0;
            out[k + 1] = tip.1;
            out[k + 2] = us[us.len() - 1] + self.links[l].length * turn;
            k += 3;
            let r = us.len();
            let at = |i: usize| {
                if i == 0 {
                    0.0
                } else {
                    us[i - 1] + i as f64 * h * turn
                }
            };
            sample_field(self.links[l].length, h, r, at, &mut out[k..k + nf]);
            k += nf;
        }
        if let Some(ct) = &self.contact {
            // λ of the last evaluation: the step end of the sampled interval (O(τ) in time)
            out[k] = self.constraint.lambda;
            out[k + 1] = if self.constraint.constrained {
                1.0
            } else {
                0.0
            };
            out[k + 2] = self.gap_on(ct, &qk);
        }
    }

    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        let mut inputs = Vec::new();
        if self.any_law() {
            inputs.push(ledger_term::APPLIED_TORQUE);
        }
        let mut diss = Vec::new();
        if self.any_damper() {
            diss.push(ledger_term::JOINT_DAMPER);
        }
        if self.any_kv() {
            diss.push(ledger_term::KELVIN_VOIGT);
        }
        if self.contact.is_some() {
            diss.push(ledger_term::IMPACT);
        }
        let mut stored = vec![
            ledger_term::KINETIC,
            ledger_term::STRAIN,
            ledger_term::JOINT_SPRING,
        ];
        if self.gravity.is_some() {
            stored.push(ledger_term::GRAVITY);
        }
        (stored, inputs, diss)
    }

    fn dof_name(&self, i: usize) -> String {
        let ine = &self.inertia;
        match i {
            TH => "link-1 tip-chord angle θ".into(),
            BE => "link-2 tip-chord angle β".into(),
            _ if self.timo.is_some() && self.slots.contains(&i) => {
                "unused ghost slot (Timoshenko: the clamp turn is the condensed ψ₀)".into()
            }
            _ if i == self.slots[0] => "link 1 clamp ghost deflection x₁ = v₋₁".into(),
            _ if i == self.slots[1] => "link 2 clamp ghost deflection x₂ = w₋₁".into(),
            _ if Some(i) == self.tip_ghost => "link 1 tip ghost deflection y = v_{r+1}".into(),
            _ if ine.iv().contains(&i) => {
                let k = i - 1;
                format!("link 1 v at station {k} (x = {:.4})", k as f64 * ine.h1)
            }
            _ => {
                let k = i - 1 - ine.r1;
                format!("link 2 w at station {k} (x = {:.4})", k as f64 * ine.h2)
            }
        }
    }
}
