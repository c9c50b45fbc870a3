//! The single link's observables (joint angle/rate/torque, tip position and deflection, the
//! sampled deflection field) and ledger terms.

use data::{channel, ledger_term};

use super::FloatingLink;
use crate::output::{Outputs, sample_field};
use crate::system::Bound;

impl Outputs for FloatingLink {
    fn describe(&self, b: &Bound) -> String {
        let rate = self.bound_rate.get();
        let k = b.site;
        let w2 = rate * rate;
        let tension = if self.foreshortening {
            w2 * self.wseg[k]
        } else {
            0.0
        };
        format!(
            "station {} (x = {:.4}), hub rate {:.4}: ω² = {:.4e} bending + {:.4e} tension (N = {:.4e}) − {:.4e} softening",
            k + 1,
            (k + 1) as f64 * self.h,
            rate,
            self.bend_row[k],
            w2 * self.geo_row[k],
            tension,
            w2
        )
    }

    fn channels(&self) -> Vec<(String, &'static str)> {
        let mut c = vec![
            channel::spec::joint_angle(1),
            channel::spec::joint_rate(1),
            channel::spec::joint_torque(1),
            channel::spec::tip_x(1),
            channel::spec::tip_y(1),
            channel::spec::tip_deflection(1),
        ];
        for k in 0..self.field_stations {
            c.push(channel::spec::field_deflection(1, k));
        }
        c
    }

    fn observe(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        let (th, rate, _) = self.hub_state(t, q, v);
        let vs = &q[self.vrange()];
        let tip = vs[self.r - 1];
        let s_tip = if self.foreshortening {
            (0..self.r)
                .map(|seg| {
                    0.5 * self.h * ((Self::at(vs, seg + 1) - Self::at(vs, seg)) / self.h).powi(2)
                })
                .sum()
        } else {
            0.0
        };
        let (c, s) = (th.cos(), th.sin());
        let xt = self.length - s_tip;
        out[0] = th;
        out[1] = rate;
        // torque of the latest force evaluation (level t_{j+1}; within one step of t)
        out[2] = self.torque;
        out[3] = c * xt - s * tip;
        out[4] = s * xt + c * tip;
        out[5] = tip;
        let nf = self.field_stations;
        sample_field(
            self.length,
            self.h,
            self.r,
            |i| Self::at(vs, i),
            &mut out[6..6 + nf],
        );
    }

    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
        let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
        if self.spring_enabled() {
            stored.push(ledger_term::JOINT_SPRING);
        }
        let mut inputs = Vec::new();
        if self.input_enabled() {
            inputs.push(if self.prescribed() {
                ledger_term::PRESCRIBED_MOTION
            } else {
                ledger_term::APPLIED_TORQUE
            });
        }
        let mut diss = Vec::new();
        if self.damper_enabled() {
            diss.push(ledger_term::JOINT_DAMPER);
        }
        if self.kelvin_voigt_enabled() {
            diss.push(ledger_term::KELVIN_VOIGT);
        }
        (stored, inputs, diss)
    }

    fn dof_name(&self, i: usize) -> String {
        if !self.prescribed() && i == 0 {
            "hub angle θ".into()
        } else {
            let k = i - self.v0() + 1;
            format!("transverse v at station {k} (x = {:.4})", k as f64 * self.h)
        }
    }
}
