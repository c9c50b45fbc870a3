//! Outputs of a chain run: the sampled observables and energy ledger (channel layout chosen
//! from what the scene has), the final state, and the diagnostics of a stopped run.

use data::{Diagnostic, EnergyLedger, Observables, Scene, StabilityVerdict, channel, ledger_term};

use crate::events::ContactReport;
use crate::integrate::Stepper;
use crate::linalg::dot;
use crate::rhs::ChainRhs;

/// Full generalized coordinates q and rates q̇ at the end of a run, plus the contact report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FinalState {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub contact: ContactReport,
}

/// Output layout (channel names and the energy ledger names the scene needs) and the sampling
/// schedule: samples at k·Δt_out, the last one at t_end, taken from the stepper's dense output
/// inside a step.
pub(crate) struct Output {
    pub(crate) obs: Observables,
    pub(crate) ledger: EnergyLedger,
    values: Vec<f64>,
    dt_out: f64,
    t_end: f64,
    n_out: usize,
    /// Index of the next sample time.
    k_out: usize,
    /// The state at a sample time.
    yd: Vec<f64>,
    stations: Vec<Vec<f64>>,
    has_spring: bool,
    has_gravity: bool,
    /// fᵀq₀ of the step load (its work is fᵀq − fᵀq₀), set at the first sample.
    load_origin: Option<f64>,
}

impl Output {
    pub(crate) fn new(rhs: &ChainRhs, scene: &Scene, t_end: f64, dim: usize) -> Self {
        let dt_out = scene.simulation.output_interval;
        let n_samples = (t_end / dt_out - 1e-9).ceil() as usize + 1;
        let chain = &rhs.chain;
        let ns = scene.simulation.field_stations.max(2);
        let mut specs: Vec<(String, &str)> = Vec::new();
        for (i, _) in chain.links.iter().enumerate() {
            let k = i + 1;
            specs.push(channel::spec::joint_angle(k));
            specs.push(channel::spec::joint_rate(k));
            specs.push(channel::spec::joint_torque(k));
            specs.push(channel::spec::tip_x(k));
            specs.push(channel::spec::tip_y(k));
            specs.push(channel::spec::tip_deflection(k));
            for s in 0..ns {
                specs.push(channel::spec::field_deflection(k, s));
            }
        }
        let has_contact = rhs.contact.is_some();
        if has_contact {
            specs.push(channel::spec::contact_normal_force(1));
            specs.push(channel::spec::contact_phase(1));
            // The constraint violation (penetration < 0) at the samples.
            specs.push(channel::spec::contact_gap(1));
        }
        let has_friction = rhs.contact.as_ref().is_some_and(|c| c.has_friction());
        if has_friction {
            // Tangential tip velocity T q̇, friction force along t̂ and the friction work.
            specs.push(channel::spec::contact_slip_velocity(1));
            specs.push(channel::spec::contact_friction_force(1));
            specs.push(channel::spec::contact_friction_work(1));
        }
        let mut obs = Observables::with_channels(&specs);
        obs.time.reserve(n_samples);
        for c in &mut obs.channels {
            c.values.reserve(n_samples);
        }
        let has_spring = chain
            .joints
            .iter()
            .any(|j| j.prescribed.is_none() && j.stiffness > 0.0);
        let has_gravity = chain.gravity.is_some();
        let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
        if has_spring {
            stored.push(ledger_term::JOINT_SPRING);
        }
        if has_gravity {
            stored.push(ledger_term::GRAVITY);
        }
        let mut inputs = Vec::new();
        if rhs.slots.applied.is_some() {
            inputs.push(ledger_term::APPLIED_TORQUE);
        }
        if rhs.slots.prescribed.is_some() {
            inputs.push(ledger_term::PRESCRIBED_MOTION);
        }
        if chain.step_load.is_some() {
            inputs.push(ledger_term::APPLIED_LOAD);
        }
        let mut diss = Vec::new();
        if rhs.slots.joint_damper.is_some() {
            diss.push(ledger_term::JOINT_DAMPER);
        }
        if rhs.slots.kelvin_voigt.is_some() {
            diss.push(ledger_term::KELVIN_VOIGT);
        }
        if rhs.contact.as_ref().is_some_and(|c| !c.bilateral) {
            diss.push(ledger_term::IMPACT);
        }
        if rhs.slots.friction.is_some() {
            diss.push(ledger_term::FRICTION);
        }
        let mut ledger = EnergyLedger::new(&stored, &inputs, &diss);
        ledger.time.reserve(n_samples);
        for term in ledger
            .stored
            .iter_mut()
            .chain(&mut ledger.inputs)
            .chain(&mut ledger.dissipation)
        {
            term.values.reserve(n_samples);
        }
        let stations = chain
            .links
            .iter()
            .map(|l| {
                let len = l.ints.length;
                let mut m = vec![0.0; ns * l.nb()];
                for s in 0..ns {
                    let x = len * s as f64 / (ns - 1) as f64;
                    l.transverse
                        .eval(x, 0, &mut m[s * l.nb()..(s + 1) * l.nb()]);
                }
                m
            })
            .collect();
        Output {
            values: vec![0.0; specs.len()],
            dt_out,
            t_end,
            n_out: n_samples,
            k_out: 0,
            yd: vec![0.0; dim],
            obs,
            ledger,
            stations,
            has_spring,
            has_gravity,
            load_origin: None,
        }
    }

    /// The sample at t = 0 (false: the model failed at the initial state).
    pub(crate) fn sample_initial(&mut self, rhs: &mut ChainRhs, y: &[f64]) -> bool {
        if !self.sample(rhs, 0.0, y) {
            return false;
        }
        self.k_out = self.k_out.max(1);
        true
    }

    /// The samples due in the last accepted step up to `t_limit` (≤ `t`, the step's end, where
    /// the state is `y`). Err: the time of a sample at which the model failed.
    pub(crate) fn sample_through(
        &mut self,
        rhs: &mut ChainRhs,
        stepper: &dyn Stepper,
        t: f64,
        y: &[f64],
        t_limit: f64,
    ) -> Result<(), f64> {
        while self.k_out < self.n_out && self.out_time(self.k_out) <= t_limit {
            let to = self.out_time(self.k_out);
            let mut yd = std::mem::take(&mut self.yd);
            if to == t {
                yd.copy_from_slice(y);
            } else {
                stepper.dense(to, &mut yd);
            }
            let ok = self.sample(rhs, to, &yd);
            self.yd = yd;
            if !ok {
                return Err(to);
            }
            self.k_out += 1;
        }
        Ok(())
    }

    fn out_time(&self, k: usize) -> f64 {
        (k as f64 * self.dt_out).min(self.t_end)
    }

    fn sample(&mut self, rhs: &mut ChainRhs, t: f64, y: &[f64]) -> bool {
        if !rhs.solve(t, y) {
            return false;
        }
        let ns = self
            .stations
            .first()
            .map_or(0, |m| m.len() / rhs.chain.links[0].nb().max(1));
        let mut c = 0;
        for i in 0..rhs.chain.links.len() {
            let l = &rhs.chain.links[i];
            let nb = l.nb();
            let b = &rhs.q[l.b0..l.b0 + nb];
            let tip = rhs.chain.tip_position(i);
            self.values[c] = rhs.chain.joint_angle_with_lag(i, &rhs.q, &rhs.qd);
            self.values[c + 1] = rhs.chain.joint_rate(i, &rhs.qd);
            self.values[c + 2] = rhs.joint_torque(t, i);
            self.values[c + 3] = tip[0];
            self.values[c + 4] = tip[1];
            self.values[c + 5] = dot(&l.ints.phi_l, b);
            c += 6;
            for s in 0..ns {
                self.values[c] = dot(&self.stations[i][s * nb..(s + 1) * nb], b);
                c += 1;
            }
        }
        if let Some(ct) = &rhs.contact {
            self.values[c] = ct.lambda;
            self.values[c + 1] = if ct.sticking {
                2.0
            } else if ct.constrained {
                1.0
            } else {
                0.0
            };
            self.values[c + 2] = ct.gap;
            if ct.has_friction() {
                self.values[c + 3] = ct.slip_velocity;
                self.values[c + 4] = ct.lambda_t;
                self.values[c + 5] = rhs.slots.friction.map_or(0.0, |i| y[i]);
            }
        }
        self.obs.push(t, &self.values);
        let e = rhs.chain.energy(&rhs.q);
        let mut stored = [e.kinetic, e.strain, 0.0, 0.0];
        let mut k = 2;
        if self.has_spring {
            stored[k] = e.joint_spring;
            k += 1;
        }
        if self.has_gravity {
            stored[k] = e.gravity;
            k += 1;
        }
        let s = rhs.slots;
        let (mut inputs, mut ni) = ([0.0; 3], 0);
        for i in [s.applied, s.prescribed].into_iter().flatten() {
            inputs[ni] = y[i];
            ni += 1;
        }
        if let Some(f) = &rhs.chain.step_load {
            let fq = dot(f, &rhs.q);
            inputs[ni] = fq - *self.load_origin.get_or_insert(fq);
            ni += 1;
        }
        let (mut diss, mut nd) = ([0.0; 4], 0);
        for i in [s.joint_damper, s.kelvin_voigt].into_iter().flatten() {
            diss[nd] = y[i];
            nd += 1;
        }
        // Jumps of applied torques behind elbows (crate::model::elbow): their work on the
        // applied input, the section relaxation's loss on the first damper channel.
        let (jump_work, jump_loss) = rhs.chain.torque_step_books(t);
        if jump_work != 0.0 && s.applied.is_some() {
            inputs[0] += jump_work;
        }
        if jump_loss != 0.0 && nd > 0 {
            diss[0] += jump_loss;
        }
        if let Some(ct) = rhs.contact.as_ref().filter(|c| !c.bilateral) {
            diss[nd] = ct.impact_loss;
            nd += 1;
        }
        if let Some(i) = s.friction {
            diss[nd] = y[i];
            nd += 1;
        }
        self.ledger
            .push(t, &stored[..k], &inputs[..ni], &diss[..nd]);
        true
    }
}

/// Links whose transverse tip deflection exceeds their length (runaway growth).
pub(crate) fn runaway(rhs: &ChainRhs, y: &[f64]) -> Option<(usize, f64)> {
    let nf = rhs.nf();
    for (i, l) in rhs.chain.links.iter().enumerate() {
        // b of link i sits in the free part at the positions of its global indices.
        let mut v = 0.0;
        for (k, &g) in rhs.chain.free[..nf].iter().enumerate() {
            if g >= l.b0 && g < l.b0 + l.nb() {
                v += l.ints.phi_l[g - l.b0] * y[k];
            }
        }
        if !v.is_finite() || v.abs() > l.ints.length {
            return Some((i, v));
        }
    }
    None
}

pub(crate) fn stopped(
    rhs: &ChainRhs,
    t: f64,
    integrator: &str,
    runaway: Option<(usize, f64)>,
) -> StabilityVerdict {
    let diagnostic = if let Some((i, v)) = runaway {
        let l = &rhs.chain.links[i];
        let stiffening = l.foreshortening;
        Diagnostic {
            t,
            what: format!(
                "transverse tip deflection {v:.3e} of link {} exceeds its length {}",
                i + 1,
                l.ints.length
            ),
            location: Some(format!("link{} tip", i + 1)),
            why: if stiffening {
                "runaway elastic growth: the small-strain assumed-mode model is no longer valid"
                    .into()
            } else {
                "runaway growth: without geometric stiffening the rotating link softens (ω² M_φ \
                 term) and loses stability once the spin rate exceeds its first bending frequency"
                    .into()
            },
            remedy: if stiffening {
                "reduce the loading or use a geometrically exact backend".into()
            } else {
                "switch on `foreshortening` (or `axial`) for the link to keep centrifugal stiffening".into()
            },
        }
    } else {
        Diagnostic {
            t,
            what: format!("integrator stopped: {integrator}"),
            location: None,
            why: if rhs.painleve {
                "Painlevé's paradox: G M⁻¹Gᵀ ≤ μ|G M⁻¹Tᵀ|, the sliding friction contact has no \
                 unique normal force"
                    .into()
            } else if rhs.singular {
                "the mass matrix lost positive definiteness".into()
            } else {
                "the solution could not be resolved at the requested tolerance (blow-up or a \
                 singular configuration)"
                    .into()
            },
            remedy: "loosen rtol/atol, try `--method trbdf2` for stiff cases, or check the scene \
                     parameters"
                .into(),
        }
    };
    StabilityVerdict::Stopped { diagnostic }
}

/// The stop of a run whose step after a plastic impact at `t` (normal force ≤ 0, so the tip
/// was left free) went `depth` below the surface: the contact would be taken again at `t` with
/// zero impulse and the same decision, without end.
pub(crate) fn unresolved_grazing(t: f64, h: f64, depth: f64, fixed_step: bool) -> StabilityVerdict {
    StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: format!(
                "grazing contact: after the impact at t = {t:.9e} left the tip free (normal \
                 force ≤ 0), the step of {h:.3e} s went {depth:.3e} below the surface"
            ),
            location: Some("contact1".into()),
            why: "the step's own error near a grazing state exceeds the tip's departure from \
                  the surface, so the contact would be taken again at the same instant with \
                  zero impulse"
                .into(),
            remedy: if fixed_step {
                "a smaller --dt, or an adaptive method (trbdf2, dopri5), which shortens the \
                 step there"
                    .into()
            } else {
                "a tighter --rtol/--atol".into()
            },
        },
    }
}

/// The stop of a run whose contact events accumulate (Zeno-like chattering).
pub(crate) fn too_many_events(t: f64, count: usize) -> StabilityVerdict {
    StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: format!("{count} contact events"),
            location: Some("contact1".into()),
            why: "impacts/releases or stick–slip transitions accumulate \
                  (Zeno-like chattering)"
                .into(),
            remedy: "shorten t_end or add damping".into(),
        },
    }
}
