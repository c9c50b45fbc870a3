//! Driver outputs: the naming of a model's observables and ledger terms ([`Outputs`]), the
//! sampling of a run at the output times (`Recorder`: the state on the method's continuous
//! extension of the step, the works linear in time; no allocation after construction) and the mapping to `data`'s result types
//! ([`Outcome`]).

use data::{Cost, EnergyLedger, Event, Observables, StabilityVerdict};

use crate::method::{Levels, Stepper};
use crate::system::{Bound, System};

/// How a model's state is named and observed: channels, ledger terms, coordinate names.
pub trait Outputs {
    /// Observable channels (name, unit) sampled by [`Outputs::observe`].
    fn channels(&self) -> Vec<(String, &'static str)>;
    fn observe(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]);
    /// Ledger term names: stored, inputs, dissipation (inputs/dissipation in the order of
    /// [`System::powers`], stored in that of [`System::stored_energies`]).
    fn ledger_names(&self) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>);
    /// Human-readable location of a bound, e.g. "station 0, segment 0 (x = 0–2), stage 1".
    fn describe(&self, b: &Bound) -> String;
    /// Human-readable name of coordinate i (for diagnostics).
    fn dof_name(&self, i: usize) -> String;
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub observables: Observables,
    pub ledger: EnergyLedger,
    pub events: Vec<Event>,
    pub cost: Cost,
    pub verdict: StabilityVerdict,
    /// Smallest and largest step taken.
    pub tau_min: f64,
    pub tau_max: f64,
}

impl Outcome {
    /// Wraps the run as the backend-neutral result of `scene` under the settings `s`.
    pub(crate) fn into_run_result(
        self,
        scene: &data::Scene,
        s: &crate::settings::ValidatedSettings,
    ) -> data::RunResult {
        data::RunResult {
            backend: data::BackendKind::Fdm,
            scene: scene.name.clone(),
            settings: s.request(),
            observables: self.observables,
            ledger: self.ledger,
            events: self.events,
            cost: self.cost,
            verdict: self.verdict,
        }
    }
}

/// One level of a step as the recorder reads it: its time, state, accumulated works and their
/// powers (inputs, then dissipation terms, in the ledger's order).
#[derive(Clone, Copy)]
pub(crate) struct LevelRecord<'a> {
    pub t: f64,
    pub state: &'a Levels,
    pub work: &'a [f64],
    pub power: &'a [f64],
}

/// Output recorder: samples the state at the output times on the method's continuous extension
/// of the step that passes them ([`Stepper::dense`]), the works as integrals of the power
/// interpolated linearly (the trapezoidal rule's own model of it).
pub(crate) struct Recorder {
    times: Vec<f64>,
    next: usize,
    pub(crate) obs: Observables,
    pub(crate) ledger: EnergyLedger,
    row: Vec<f64>,
    stored: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
    work: Vec<f64>,
    n_in: usize,
    /// the ledger's energy scale so far (max |E|, |W_in|, |W_diss| over the samples) and the
    /// relative residual of the last sample
    scale: f64,
    last_closure: f64,
}

impl Recorder {
    /// Samples every `output_interval` from 0 to `t_end` (and at `t_end`).
    pub(crate) fn new<S: System + Outputs + ?Sized>(
        sys: &S,
        t_end: f64,
        output_interval: f64,
    ) -> Self {
        let n_out = (t_end / output_interval - 1e-9).ceil().max(0.0) as usize;
        let mut times: Vec<f64> = (0..=n_out)
            .map(|k| (k as f64 * output_interval).min(t_end))
            .collect();
        times.dedup();
        let mut specs = sys.channels();
        specs.push(data::channel::spec::step_size());
        specs.push(data::channel::spec::stability_bound());
        let mut obs = Observables::with_channels(&specs);
        obs.time.reserve(times.len());
        for c in &mut obs.channels {
            c.values.reserve(times.len());
        }
        let (st, inp, dis) = sys.ledger_names();
        let mut ledger = EnergyLedger::new(&st, &inp, &dis);
        ledger.time.reserve(times.len());
        for term in ledger
            .stored
            .iter_mut()
            .chain(ledger.inputs.iter_mut())
            .chain(ledger.dissipation.iter_mut())
        {
            term.values.reserve(times.len());
        }
        let n = sys.dofs();
        Recorder {
            times,
            next: 0,
            row: vec![0.0; specs.len()],
            stored: vec![0.0; st.len()],
            obs,
            ledger,
            q: vec![0.0; n],
            v: vec![0.0; n],
            work: vec![0.0; inp.len() + dis.len()],
            n_in: inp.len(),
            scale: 0.0,
            last_closure: 0.0,
        }
    }

    /// Records every output time in (t_a, t_b] (and t_a itself if it is the first sample); in
    /// (t_a, t_b) when the step ends on a jump of an applied law (`on_jump`): a sample at the
    /// jump belongs to the stretch it opens (the laws are right-continuous) and is taken at the
    /// start of the next step. Between the levels the state is the method's dense output and
    /// each work the integral of its power interpolated linearly between the levels, the
    /// trapezoidal rule's own model of it, so that a sample's ledger residual is the scheme's
    /// and not the interpolation's (the stored energies of a state leaving rest grow like s²;
    /// a work linear in s would leave a residual of order (1 − s) of the step's energy).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record<S: System + Outputs + ?Sized>(
        &mut self,
        sys: &S,
        method: &dyn Stepper,
        a: LevelRecord<'_>,
        b: LevelRecord<'_>,
        tau: f64,
        bound: f64,
        on_jump: bool,
    ) {
        let (ta, tb) = (a.t, b.t);
        let tol = 1e-12 * tb.abs().max(1e-30);
        while self.next < self.times.len() {
            let t = self.times[self.next];
            if t > tb + tol || (on_jump && t >= tb - tol) {
                break;
            }
            let s = if tb > ta {
                ((t - ta) / (tb - ta)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            method.dense(a.state, b.state, s, &mut self.q, &mut self.v);
            for i in 0..self.work.len() {
                // W_a + ∫ of the linear power: the linear interpolant plus the power's change
                // over the step times ½(s² − s) (exact at both levels, whatever the events
                // booked into W_b)
                let (wa, wb) = (a.work[i], b.work[i]);
                let bend = 0.5 * (tb - ta) * (b.power[i] - a.power[i]) * (s * s - s);
                self.work[i] = wa + s * (wb - wa) + bend;
            }
            let nc = self.row.len();
            sys.observe(t, &self.q, &self.v, &mut self.row[..nc - 2]);
            self.row[nc - 2] = tau;
            self.row[nc - 1] = bound;
            self.obs.push(t, &self.row);
            sys.stored_energies(t, &self.q, &self.v, &mut self.stored);
            self.ledger.push(
                t,
                &self.stored,
                &self.work[..self.n_in],
                &self.work[self.n_in..],
            );
            let k = self.ledger.time.len() - 1;
            let (w_in, w_out): (f64, f64) = (
                self.work[..self.n_in].iter().sum(),
                self.work[self.n_in..].iter().sum(),
            );
            self.scale = self
                .scale
                .max(self.ledger.total(k).abs())
                .max(w_in.abs())
                .max(w_out.abs());
            let residual = self.ledger.residual(k).abs();
            self.last_closure = if self.scale > 0.0 {
                residual / self.scale
            } else {
                residual
            };
            self.next += 1;
        }
    }

    /// The relative ledger residual of the last sample (the measure of
    /// `EnergyLedger::relative_closure`, on the samples so far).
    pub(crate) fn last_closure(&self) -> f64 {
        self.last_closure
    }

    pub(crate) fn done(&self) -> bool {
        self.next >= self.times.len()
    }
}

/// Samples a link's deflection at `out.len()` equally spaced points over its `length`, linearly
/// between the stations 0…r of step `h` (`at(i)`: deflection of station i).
pub(crate) fn sample_field(
    length: f64,
    h: f64,
    r: usize,
    at: impl Fn(usize) -> f64,
    out: &mut [f64],
) {
    let nf = out.len();
    for (k, o) in out.iter_mut().enumerate() {
        let x = k as f64 * length / (nf - 1) as f64;
        let pos = (x / h).clamp(0.0, r as f64);
        let i = (pos.floor() as usize).min(r - 1);
        let al = pos - i as f64;
        *o = at(i) * (1.0 - al) + at(i + 1) * al;
    }
}
