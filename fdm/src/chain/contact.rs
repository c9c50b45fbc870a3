//! Unilateral frictionless contact of link 2's tip with a fixed line (`barhorst-case1`,
//! `barhorst-case2`, `barhorst-case1-tipmass`, `barhorst-case1-stiff-elbow`; seed 000).
//!
//! **Gap.** In the tip-chord frames the tip of link 2 sits at
//! r_tip(q) = R(θ)(L₁ − S₁, 0) + R(β)(L₂ − S₂, 0), S_ℓ = ½h Σ_seg g_seg² the foreshortening of
//! link ℓ (0 when it is off) — the positions the kinetic energy uses. With the unit normal n̂ to
//! the free side and p₀ on the line, g(q) = n̂·(r_tip − p₀), and with nc(α) = n̂·(cos α, sin α),
//! ns(α) = n̂·(−sin α, cos α):
//!
//! G = ∂g/∂q: G_θ = ns(θ)(L₁ − S₁), G_β = ns(β)(L₂ − S₂), G_v = −nc(θ) ∂S₁/∂v,
//! G_w = −nc(β) ∂S₂/∂w (the ghost slots move no point: 0);
//! Ġq̇ = Σ_ℓ [−nc(α)α̇²(L − S) − 2ns(α)α̇Ṡ − nc(α) h Σ ġ²] (differentiate g twice, drop G q̈).
//!
//! **Phases** (the velocity form, one step = kick–drift–kick):
//! * free flight: M q̈ = f. When a step ends with g < 0, the crossing is located on the step's own
//!   drift q(s) = q + s q̇ + ½s² q̈ (exact for the velocity form: the positions of a step of
//!   length s need no new force evaluation) by Illinois regula falsi to |g| ≤ 1e-13 L or a
//!   bracket of [`EVENT_TIME_TOLERANCE`]; the step is re-taken with that length, so the state
//!   lands on the event;
//! * impact (positions unchanged): M(q)(q̇⁺ − q̇⁻) = GᵀΛ, G q̇⁺ = 0 ⇒ Λ = −Gq̇⁻/(GM⁻¹Gᵀ),
//!   q̇⁺ = q̇⁻ + M⁻¹GᵀΛ with the chain's own M (lumped diagonal + four full columns, the Schur
//!   solve of [`super`]). The kinetic energy lost, ½(Gq̇⁻)²/(GM⁻¹Gᵀ) ≥ 0, is booked in the
//!   ledger term `impact`. The next phase follows from the sign of the would-be normal force;
//! * constrained sliding: M q̈ = f + Gᵀλ, G q̈ + Ġq̇ = 0 (index 1 at acceleration level), λ =
//!   −(G M⁻¹f + Ġq̇)/(GM⁻¹Gᵀ): one more solve with the same M. Drift control after every step:
//!   q projected onto g = 0 (Newton along M⁻¹Gᵀ, the M⁻¹ metric) *before* the force evaluation
//!   of the step end, q̇ projected onto Gq̇ = 0 along M⁻¹Gᵀ after the final kick. The velocity
//!   projection removes ½(Gq̇)²/(GM⁻¹Gᵀ) of kinetic energy: not booked in the ledger (it is
//!   integration error and shows in the closure), reported in [`ContactReport`];
//! * release when λ crosses zero from above: located by Illinois on λ(s) of the re-taken
//!   constrained step of length s (one force evaluation per trial), then free flight.
//!
//! The step bound of the free chain also covers the constrained phases: adding a constraint
//! can only lower the highest frequency (Rayleigh quotient on a subspace), and located steps are
//! shorter than the bound.
//!
//! Unsupported: friction ≠ 0, circles (any non-line surface), bilateral mode, contact of link
//! 1, more than one contact, the two-step report scheme (its second level cannot be restarted
//! at an event without a start-up step).

// Index loops over parallel buffers (q, v, a, G, M⁻¹Gᵀ) read like the formulas.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use data::scene::{ContactMode, Surface};
use data::{Cost, Diagnostic, Event, RunResult, Scene, Settings, StabilityVerdict};

use super::TwoLinkChain;
use super::kinetic::{BE, TH, seg_energy, seg_grad, seg_rate};
use crate::driver::StepControl;
use crate::error::FdmError;
use crate::method::Levels;
use crate::output::{Outputs, Recorder};
use crate::settings::{FdmSettings, Method};
use crate::system::System;

/// Default safety factor of a Timoshenko chain with contact (an accuracy choice, not a
/// stability one). Impacts excite the condensed operator's shear waves near the step bound,
/// where the velocity-form step is only about first order in energy: at safety 1 the ledger of
/// `barhorst-case1-timoshenko` closes to 1.3e-4 over 0.4 s, at 0.1 to 7.5e-6 (3 s: 3.9e-6,
/// ~9 s wall), inside the 1e-5. `time.safety_factor` overrides it.
pub const TIMOSHENKO_CONTACT_SAFETY: f64 = 0.1;

/// Width of the time bracket at which event location stops (s).
pub const EVENT_TIME_TOLERANCE: f64 = 1e-10;
/// Relative gap (× L₁ + L₂) at which the contact-start location stops, and the tolerance of
/// the position projection.
const GAP_TOLERANCE: f64 = 1e-13;
/// Step factor on the bound, and its number of steps, after a velocity jump (the start from
/// rest with the joint springs off their set-points, every impact): the jump excites the
/// shortest waves and the overdamped clamp-rotation modes, whose transients the velocity form
/// at the bound — and the trapezoidal work of their dampers — resolve poorly. Measured on
/// `barhorst-case2` (2 s): ledger closure 1.7e-5 without, 1.2e-6 to 4e-6 with ¼ of the
/// bound for 0.9–9 ms, for ≈ 10 % more steps.
const REFINE_FACTOR: f64 = 0.25;
const REFINE_STEPS: usize = 2000;
/// Upper bound on contact events (guards a Zeno-like accumulation).
const MAX_CONTACT_EVENTS: usize = 20_000;

/// The tip of link 2 against the line n̂·(p − p₀) = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct TipContact {
    /// unit normal to the free side
    normal: [f64; 2],
    /// n̂·p₀
    offset: f64,
}

impl TipContact {
    /// The scene's contact, if any; `unsupported: …` for what this model does not carry.
    pub fn from_scene(scene: &Scene) -> Result<Option<Self>, FdmError> {
        let Some(c) = scene.contacts.first() else {
            return Ok(None);
        };
        let unsupported = |what: String| {
            Err(FdmError::Unsupported(format!(
                "fdm: `{}`: {what} (the finite-difference chain carries one frictionless \
                 unilateral contact of link 2's tip with a line)",
                scene.name
            )))
        };
        if scene.contacts.len() > 1 {
            return unsupported(format!("{} contacts", scene.contacts.len()));
        }
        if scene.link_index(&c.link) != Some(1) {
            return unsupported(format!("contact of link `{}`", c.link));
        }
        if c.friction != 0.0 {
            return unsupported(format!("friction μ = {}", c.friction));
        }
        if c.mode == ContactMode::Bilateral {
            return unsupported("bilateral contact".into());
        }
        let Surface::Line { point, normal } = c.surface else {
            return unsupported("a non-line contact surface".into());
        };
        let len = normal[0].hypot(normal[1]);
        if !(len > 0.0 && len.is_finite()) {
            return Err(FdmError::invalid("contact.surface.normal", "zero normal"));
        }
        let normal = [normal[0] / len, normal[1] / len];
        Ok(Some(TipContact {
            normal,
            offset: normal[0] * point[0] + normal[1] * point[1],
        }))
    }

    fn nc(&self, a: f64) -> f64 {
        self.normal[0] * a.cos() + self.normal[1] * a.sin()
    }
    fn ns(&self, a: f64) -> f64 {
        -self.normal[0] * a.sin() + self.normal[1] * a.cos()
    }

    /// g(q) from the chord-frame coordinates `qk` (ghost slots zero).
    pub fn gap(&self, chain: &TwoLinkChain, qk: &[f64]) -> f64 {
        let (s1, s2) = chain.shortenings(qk);
        self.nc(qk[TH]) * (chain.links[0].length - s1)
            + self.nc(qk[BE]) * (chain.links[1].length - s2)
            - self.offset
    }
}

/// Diagnostics of a contact run that [`RunResult`] has no field for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactReport {
    /// Largest |g| found at a step end of a constrained phase, before the position projection.
    pub max_gap_violation: f64,
    /// Largest |Gq̇| at a step end of a constrained phase, before the velocity projection.
    pub max_normal_velocity_violation: f64,
    /// Kinetic energy removed by the velocity projections (not booked in the ledger).
    pub projection_energy: f64,
    /// Largest |g| at a located contact start.
    pub max_gap_at_event: f64,
    /// Largest |λ| at a located release.
    pub max_release_force: f64,
    /// Largest time bracket of a located event.
    pub max_time_tolerance: f64,
    /// Smallest and largest step.
    pub tau_min: f64,
    pub tau_max: f64,
}

impl TwoLinkChain {
    /// Whether the scene has a tip contact.
    pub fn has_contact(&self) -> bool {
        self.contact.is_some()
    }

    /// Foreshortenings S₁, S₂ (0 where off) of the chord-frame `qk`.
    fn shortenings(&self, qk: &[f64]) -> (f64, f64) {
        let ine = &self.inertia;
        let s1 = if ine.fs1 {
            seg_energy(&qk[ine.iv()], ine.h1, None)
        } else {
            0.0
        };
        let s2 = if ine.fs2 {
            seg_energy(&qk[ine.iw()], ine.h2, None)
        } else {
            0.0
        };
        (s1, s2)
    }

    /// Fills `grow` with G = ∂g/∂q at `self.qk` and returns g.
    fn gap_row(&mut self) -> f64 {
        let ct = self.contact.clone().expect("contact");
        let ine = &self.inertia;
        let qk = &self.qk;
        let (s1, s2) = self.shortenings(qk);
        let (l1, l2) = (self.links[0].length, self.links[1].length);
        let g = &mut self.grow;
        g.iter_mut().for_each(|x| *x = 0.0);
        g[TH] = ct.ns(qk[TH]) * (l1 - s1);
        g[BE] = ct.ns(qk[BE]) * (l2 - s2);
        if ine.fs1 {
            let (v, c) = (&qk[ine.iv()], ct.nc(qk[TH]));
            for k in 0..ine.r1 - 1 {
                g[2 + k] = -c * seg_grad(v, ine.h1, None, k);
            }
        }
        if ine.fs2 {
            let (w, c) = (&qk[ine.iw()], ct.nc(qk[BE]));
            for j in 0..ine.r2 - 1 {
                g[2 + ine.r1 + j] = -c * seg_grad(w, ine.h2, None, j);
            }
        }
        ct.gap(self, &self.qk)
    }

    /// Ġq̇ at (`self.qk`, `self.vk`) (module docs).
    fn gap_curvature(&self) -> f64 {
        let ct = self.contact.as_ref().expect("contact");
        let ine = &self.inertia;
        let (qk, vk) = (&self.qk, &self.vk);
        let mut out = 0.0;
        for (l, (alpha, range, h, fs)) in [
            (TH, ine.iv(), ine.h1, ine.fs1),
            (BE, ine.iw(), ine.h2, ine.fs2),
        ]
        .into_iter()
        .enumerate()
        {
            let (a, ad) = (qk[alpha], vk[alpha]);
            let (s, sd, sdd) = if fs {
                let (u, ud) = (&qk[range.clone()], &vk[range]);
                (
                    seg_energy(u, h, None),
                    seg_rate(u, ud, h, None),
                    2.0 * seg_energy(ud, h, None),
                )
            } else {
                (0.0, 0.0, 0.0)
            };
            out += -ct.nc(a) * ad * ad * (self.links[l].length - s)
                - 2.0 * ct.ns(a) * ad * sd
                - ct.nc(a) * sdd;
        }
        out
    }

    /// With `qk`, `vk` and the mass columns current: G into `grow`, M⁻¹Gᵀ into `minv_g`;
    /// returns (GM⁻¹Gᵀ, Ġq̇).
    pub(super) fn constraint_solve(&mut self) -> (f64, f64) {
        self.gap_row();
        let grow = std::mem::take(&mut self.grow);
        let mut mg = std::mem::take(&mut self.minv_g);
        self.solve_mass(&grow, &mut mg);
        let gmg: f64 = grow.iter().zip(&mg).map(|(a, b)| a * b).sum();
        self.grow = grow;
        self.minv_g = mg;
        (gmg, self.gap_curvature())
    }

    /// g(q) of full coordinates (uses the chord scratch).
    pub fn gap(&mut self, q: &[f64]) -> f64 {
        self.qk.copy_from_slice(q);
        for s in self.slots {
            self.qk[s] = 0.0;
        }
        let ct = self.contact.clone().expect("contact");
        ct.gap(self, &self.qk)
    }

    /// Projects q onto g = 0 along M⁻¹Gᵀ (Newton, at most 3 passes); returns |g| before.
    fn project_position(&mut self, q: &mut [f64]) -> f64 {
        let tol = GAP_TOLERANCE * (self.links[0].length + self.links[1].length);
        let mut first = None;
        for _ in 0..3 {
            self.qk.copy_from_slice(q);
            for s in self.slots {
                self.qk[s] = 0.0;
            }
            let g = self.gap_row();
            first.get_or_insert(g.abs());
            if g.abs() <= tol {
                break;
            }
            self.build_columns();
            let grow = std::mem::take(&mut self.grow);
            let mut mg = std::mem::take(&mut self.minv_g);
            self.solve_mass(&grow, &mut mg);
            let gmg: f64 = grow.iter().zip(&mg).map(|(a, b)| a * b).sum();
            for i in 0..q.len() {
                q[i] -= mg[i] * g / gmg;
            }
            self.grow = grow;
            self.minv_g = mg;
        }
        first.unwrap_or(0.0)
    }

    /// Projects q̇ onto Gq̇ = 0 along M⁻¹Gᵀ with G, M⁻¹Gᵀ of the last constrained `accel`;
    /// returns (|Gq̇| before, kinetic energy removed).
    fn project_velocity(&self, v: &mut [f64]) -> (f64, f64) {
        let gv: f64 = self.grow.iter().zip(v.iter()).map(|(a, b)| a * b).sum();
        let gmg: f64 = self.grow.iter().zip(&self.minv_g).map(|(a, b)| a * b).sum();
        for i in 0..v.len() {
            v[i] -= self.minv_g[i] * gv / gmg;
        }
        (gv.abs(), 0.5 * gv * gv / gmg)
    }

    fn kinetic_energy(&self, q: &[f64], v: &[f64]) -> f64 {
        let mut e = [0.0; 4];
        let k = self.ledger_names().0.len();
        self.stored_energies(0.0, q, v, &mut e[..k]);
        e[0]
    }

    /// The impact at (q, q̇⁻): q̇ ← q̇⁺. Allocates (once per impact, outside the step loop).
    /// `None` (q̇ untouched) when GM⁻¹Gᵀ is not positive: M lost definiteness.
    fn impact(&mut self, t: f64, q: &[f64], v: &mut [f64]) -> Option<Event> {
        let n = q.len();
        let ke_before = self.kinetic_energy(q, v);
        let before = v.to_vec();
        self.chord(q, v);
        self.build_columns();
        let (gmg, _) = self.constraint_solve();
        if !(gmg > 0.0 && gmg.is_finite()) {
            return None;
        }
        let gv: f64 = (0..n).map(|i| self.grow[i] * v[i]).sum();
        let impulse = -gv / gmg;
        let mut dv = vec![0.0; n];
        for i in 0..n {
            dv[i] = self.minv_g[i] * impulse;
            v[i] += dv[i];
        }
        // ‖M(q̇⁺ − q̇⁻) − GᵀΛ‖ / ‖M(q̇⁺ − q̇⁻)‖ with the product M·Δq̇ formed independently
        let mut mdv = vec![0.0; n];
        self.mass_mul(&dv, &mut mdv);
        let (mut res2, mut mom2) = (0.0, 0.0);
        for i in 0..n {
            res2 += (mdv[i] - self.grow[i] * impulse).powi(2);
            mom2 += mdv[i] * mdv[i];
        }
        let momentum_residual = if mom2 > 0.0 {
            (res2 / mom2).sqrt()
        } else {
            res2.sqrt()
        };
        let normal_velocity_after: f64 = (0..n).map(|i| self.grow[i] * v[i]).sum();
        let kinetic_energy_lost = ke_before - self.kinetic_energy(q, v);

        Some(Event::Impact {
            t,
            contact: 1,
            velocity_before: before,
            velocity_after: v.to_vec(),
            impulse,
            momentum_residual,
            normal_velocity_after,
            kinetic_energy_lost,
        })
    }

    /// Static equilibrium resting on the surface: −∂V/∂q + Gᵀλ = 0, g = 0 (V: strain, joint
    /// springs, gravity), by Newton's method with a central-difference Jacobian from `q_guess`.
    /// Returns (q, λ). Allocates: for checks, not for the step loop.
    pub fn rest_on_surface(&mut self, q_guess: &[f64]) -> Result<(Vec<f64>, f64), FdmError> {
        if self.contact.is_none() {
            return Err(FdmError::Unsupported(
                "fdm: rest on the surface needs a contact".into(),
            ));
        }
        let n = self.dofs();
        let zeros = vec![0.0; n];
        let mut f = vec![0.0; n];
        let mut resid = |sys: &mut Self, x: &[f64], out: &mut [f64]| {
            let q = &x[..n];
            sys.chord(q, &zeros);
            sys.forces(0.0, q, &zeros, &mut f);
            let g = sys.gap_row();
            for i in 0..n {
                out[i] = f[i] + sys.grow[i] * x[n];
            }
            out[n] = g;
        };
        let mut x: Vec<f64> = q_guess.iter().copied().chain([0.0]).collect();
        let m = n + 1;
        let (mut r, mut rp, mut rm) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut jac = vec![vec![0.0; m]; m];
        for _ in 0..50 {
            resid(self, &x, &mut r);
            for j in 0..m {
                let e = 1e-6 * (1.0 + x[j].abs());
                let x0 = x[j];
                x[j] = x0 + e;
                resid(self, &x, &mut rp);
                x[j] = x0 - e;
                resid(self, &x, &mut rm);
                x[j] = x0;
                for i in 0..m {
                    jac[i][j] = (rp[i] - rm[i]) / (2.0 * e);
                }
            }
            let dx = solve_dense(jac.clone(), r.iter().map(|v| -v).collect()).ok_or(
                FdmError::Numerical {
                    t: 0.0,
                    message: "singular Jacobian of the resting equilibrium".into(),
                },
            )?;
            let step = dx.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for i in 0..m {
                x[i] += dx[i];
            }
            if step <= 1e-11 * (1.0 + x[n].abs()) {
                let lam = x[n];
                x.truncate(n);
                return Ok((x, lam));
            }
        }
        Err(FdmError::Numerical {
            t: 0.0,
            message: "Newton on the resting equilibrium did not converge in 50 iterations".into(),
        })
    }
}

/// Gaussian elimination with partial pivoting (small dense systems of the checks).
fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col] == 0.0 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..n {
            let f = a[row][col] / a[col][col];
            for k in col..n {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// Illinois regula falsi on [a, b] with f(a) > 0 ≥ f(b) (or the reverse): stops when the
/// bracket is narrower than `tol_w`, or when |f| ≤ `tol_f` and |f| over the secant slope is
/// below `tol_w`. Returns (point, time tolerance, evaluations): the point is the last evaluated
/// one, the tolerance the bracket width or |f|/|secant slope|.
fn illinois(
    mut f: impl FnMut(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    tol_w: f64,
    tol_f: f64,
) -> (f64, f64, usize) {
    let mut side = 0;
    let mut evals = 0;
    let mut c = b;
    for _ in 0..200 {
        c = if fb != fa {
            (b - fb * (b - a) / (fb - fa)).clamp(a.min(b), a.max(b))
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        evals += 1;
        if fc == 0.0 {
            return (c, 0.0, evals);
        }
        if fc.abs() <= tol_f {
            // |f| small enough; the time is known to |f|/|f'| (grazing: f' small, go on)
            let slope = ((fb - fa) / (b - a)).abs();
            let tol = if slope > 0.0 {
                (fc.abs() / slope).min((b - a).abs())
            } else {
                (b - a).abs()
            };
            if tol <= tol_w {
                return (c, tol, evals);
            }
        }
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if (b - a).abs() <= tol_w {
            break;
        }
    }
    (c, (b - a).abs(), evals)
}

/// Buffers of one velocity-form step.
struct Step {
    vh: Vec<f64>,
    pred: Vec<f64>,
}

impl Step {
    /// One kick–drift–kick step of length τ from (q, v, a) into `next`/`a1`; in the
    /// constrained phase with the position projection before, and the velocity projection
    /// after, the force evaluation of the step end. Returns (|g| before the projection,
    /// |Gq̇| before, energy removed).
    #[allow(clippy::too_many_arguments)]
    fn take(
        &mut self,
        sys: &mut TwoLinkChain,
        t: f64,
        tau: f64,
        cur: &Levels,
        a0: &[f64],
        next: &mut Levels,
        a1: &mut [f64],
    ) -> (f64, f64, f64) {
        let n = a0.len();
        for i in 0..n {
            self.vh[i] = cur.v[i] + 0.5 * tau * a0[i];
            next.q[i] = cur.q[i] + tau * self.vh[i];
            self.pred[i] = self.vh[i] + 0.5 * tau * a0[i];
        }
        let gap = if sys.constrained {
            sys.project_position(&mut next.q)
        } else {
            0.0
        };
        sys.accel(t + tau, &next.q, &self.pred, a1);
        for i in 0..n {
            next.v[i] = self.vh[i] + 0.5 * tau * a1[i];
        }
        if sys.constrained {
            let (gv, de) = sys.project_velocity(&mut next.v);
            (gap, gv, de)
        } else {
            (0.0, 0.0, 0.0)
        }
    }
}

enum Switch {
    Contact { tol: f64 },
    Release { tol: f64 },
}

/// The verdict when the constraint's GM⁻¹Gᵀ is not positive (M lost definiteness).
fn singular(t: f64) -> StabilityVerdict {
    StabilityVerdict::Stopped {
        diagnostic: Diagnostic {
            t,
            what: "the constraint's G M⁻¹ Gᵀ is not positive".into(),
            location: Some("contact1".into()),
            why: "the chain's mass matrix lost positive definiteness (deflections far outside \
                  the second-order kinetic energy's range)"
                .into(),
            remedy: "lower the safety factor or refine the stations".into(),
        },
    }
}

/// Runs a two-link chain with its tip contact (velocity form). Returns the run and the
/// contact diagnostics.
pub fn simulate(
    scene: &Scene,
    settings: &Settings,
    s: &FdmSettings,
) -> Result<(RunResult, ContactReport), FdmError> {
    if settings.time.method.is_some() && s.method != Method::VelocityForm {
        return Err(FdmError::Unsupported(format!(
            "fdm: contact with time.method = {}: only velocity-form restarts at a located \
             event (the two-step scheme needs a second level there)",
            s.method.name()
        )));
    }
    let mut sys = TwoLinkChain::from_scene(scene, s.stations)?;
    let (q0, v0) = sys.initial_state();
    let mut ctl = StepControl::for_scene(scene, s, Method::VelocityForm, false, true);
    if sys.timoshenko().is_some() && settings.time.safety_factor.is_none() {
        ctl.safety = TIMOSHENKO_CONTACT_SAFETY;
    }
    let clock = Instant::now();
    let n = sys.dofs();
    let (_, inp, dis) = sys.ledger_names();
    let np = inp.len() + dis.len();
    let i_impact = np - 1;
    let mut rec = Recorder::new(&sys, ctl.t_end, ctl.output_interval);
    let mut events = Vec::new();
    let mut cost = Cost {
        dofs: n,
        ..Cost::default()
    };
    let mut report = ContactReport::default();
    let mut cur = Levels::new(n);
    let mut next = Levels::new(n);
    let mut acc = vec![0.0; n];
    let mut acc2 = vec![0.0; n];
    let (mut p_cur, mut p_new) = (vec![0.0; np], vec![0.0; np]);
    let (mut w_cur, mut w_new) = (vec![0.0; np], vec![0.0; np]);
    let mut step = Step {
        vh: vec![0.0; n],
        pred: vec![0.0; n],
    };
    let mut trial = vec![0.0; n];
    cur.q.copy_from_slice(&q0);
    cur.v.copy_from_slice(&v0);
    let len = sys.links[0].length + sys.links[1].length;
    let tol_gap = GAP_TOLERANCE * len;

    let mut t = 0.0;
    let mut g_prev = sys.gap(&cur.q);
    if g_prev < 0.0 {
        return Err(FdmError::invalid(
            "contact",
            format!("the tip starts {:.3e} inside the surface", -g_prev),
        ));
    }
    sys.accel(t, &cur.q, &cur.v, &mut acc);
    sys.powers_at(t, &cur.v, &mut p_cur);
    cost.rhs_evaluations += 1;
    let bound = |sys: &TwoLinkChain, t: f64| -> Result<(f64, f64), FdmError> {
        let b = sys.bound(t);
        let limit = b.sigma;
        let tau = match ctl.forced_dt {
            Some(dt) if dt > limit * (1.0 + 1e-12) => {
                return Err(FdmError::StabilityBound {
                    t,
                    dt,
                    bound: limit,
                    kind: b.kind.name().to_string(),
                    location: sys.describe(&b),
                });
            }
            Some(dt) => dt,
            None => ctl.safety * limit,
        };
        Ok((tau, limit))
    };
    let (tau0, limit0) = bound(&sys, t)?;
    report.tau_min = tau0;
    report.tau_max = tau0;
    rec.record(&sys, t, &cur, &w_cur, t, &cur, &w_cur, tau0, limit0);
    let mut lam_prev = 0.0;
    let mut verdict = StabilityVerdict::Completed;
    let mut zero_length = 0usize;
    let window = REFINE_STEPS as f64 * REFINE_FACTOR * tau0;
    let mut refine_until = window;

    while !rec.done() {
        let (mut tau, limit) = bound(&sys, t)?;
        if t < refine_until && ctl.forced_dt.is_none() {
            tau *= REFINE_FACTOR;
        }
        let mut tau_eff = tau;
        let mut proj = step.take(&mut sys, t, tau, &cur, &acc, &mut next, &mut acc2);
        cost.rhs_evaluations += 1;
        if sys.constrained && !sys.lambda.is_finite() {
            verdict = singular(t);
            break;
        }
        if !(next.q.iter().chain(&next.v).all(|x| x.is_finite())) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: Diagnostic {
                    t,
                    what: "non-finite state".into(),
                    location: Some(format!(
                        "{} phase",
                        if sys.constrained {
                            "constrained"
                        } else {
                            "free"
                        }
                    )),
                    why: format!("step {tau:.3e} against the bound {limit:.3e}"),
                    remedy: "lower the safety factor".into(),
                },
            };
            break;
        }
        let mut switch = None;
        if !sys.constrained {
            let g1 = sys.gap(&next.q);
            if g1 < 0.0 && g_prev > 0.0 {
                // drift of a step of length s: q + s v + ½ s² a (exact for the velocity form)
                let slots = sys.slots;
                let mut gap_at = |s: f64| {
                    for i in 0..n {
                        trial[i] = cur.q[i] + s * cur.v[i] + 0.5 * s * s * acc[i];
                    }
                    for k in slots {
                        trial[k] = 0.0;
                    }
                    let ct = sys.contact.clone().expect("contact");
                    ct.gap(&sys, &trial)
                };
                let (s_e, tol, _) = illinois(
                    &mut gap_at,
                    (0.0, g_prev),
                    (tau, g1),
                    EVENT_TIME_TOLERANCE,
                    tol_gap,
                );
                tau_eff = s_e;
                switch = Some(Switch::Contact { tol });
            } else if g1 < -tol_gap.max(1e-9 * len) {
                // left the surface at a release and came back within one step: the contact
                // starts at the step start (tolerance: the step)
                tau_eff = 0.0;
                switch = Some(Switch::Contact { tol: tau });
            }
        } else if sys.lambda <= 0.0 && lam_prev > 0.0 {
            let (l1, cur_ref, acc_ref) = (sys.lambda, &cur, &acc);
            let mut lam_at = |s: f64| {
                step.take(&mut sys, t, s, cur_ref, acc_ref, &mut next, &mut acc2);
                sys.lambda
            };
            let (s_e, tol, evals) = illinois(
                &mut lam_at,
                (0.0, lam_prev),
                (tau, l1),
                EVENT_TIME_TOLERANCE,
                0.0,
            );
            cost.rhs_evaluations += evals;
            tau_eff = s_e;
            switch = Some(Switch::Release { tol });
        }
        if switch.is_some() {
            if tau_eff > 0.0 {
                proj = step.take(&mut sys, t, tau_eff, &cur, &acc, &mut next, &mut acc2);
                cost.rhs_evaluations += 1;
                zero_length = 0;
            } else {
                next.q.copy_from_slice(&cur.q);
                next.v.copy_from_slice(&cur.v);
                acc2.copy_from_slice(&acc);
                zero_length += 1;
            }
        }
        if sys.constrained {
            report.max_gap_violation = report.max_gap_violation.max(proj.0);
            report.max_normal_velocity_violation = report.max_normal_velocity_violation.max(proj.1);
            report.projection_energy += proj.2;
        }
        if tau_eff > 0.0 {
            sys.powers_at(t + tau_eff, &next.v, &mut p_new);
        } else {
            p_new.copy_from_slice(&p_cur);
        }
        for k in 0..np {
            w_new[k] = w_cur[k] + 0.5 * tau_eff * (p_cur[k] + p_new[k]);
        }
        if tau_eff > 0.0 {
            report.tau_min = report.tau_min.min(tau_eff);
            report.tau_max = report.tau_max.max(tau_eff);
            rec.record(
                &sys,
                t,
                &cur,
                &w_cur,
                t + tau_eff,
                &next,
                &w_new,
                tau_eff,
                limit,
            );
            cost.steps += 1;
        }
        std::mem::swap(&mut cur, &mut next);
        std::mem::swap(&mut acc, &mut acc2);
        std::mem::swap(&mut w_cur, &mut w_new);
        std::mem::swap(&mut p_cur, &mut p_new);
        t += tau_eff;
        if let Some(sw) = switch {
            if events.len() >= MAX_CONTACT_EVENTS || zero_length > 3 {
                verdict = StabilityVerdict::Stopped {
                    diagnostic: Diagnostic {
                        t,
                        what: format!("{} contact events", events.len()),
                        location: Some("contact1".into()),
                        why: "impacts/releases accumulate (Zeno-like chattering)".into(),
                        remedy: "shorten t_end or add damping".into(),
                    },
                };
                break;
            }
            report.max_time_tolerance = report.max_time_tolerance.max(match sw {
                Switch::Contact { tol } | Switch::Release { tol } => tol,
            });
            match sw {
                Switch::Contact { tol } => {
                    report.max_gap_at_event = report.max_gap_at_event.max(sys.gap(&cur.q).abs());
                    events.push(Event::ContactStart {
                        t,
                        contact: 1,
                        time_tolerance: tol,
                    });
                    let Some(ev) = sys.impact(t, &cur.q, &mut cur.v) else {
                        verdict = singular(t);
                        break;
                    };
                    refine_until = t + window;
                    if let Event::Impact {
                        kinetic_energy_lost,
                        ..
                    } = &ev
                    {
                        w_cur[i_impact] += kinetic_energy_lost;
                    }
                    events.push(ev);
                    // the phase follows from the sign of the would-be normal force
                    sys.constrained = true;
                    sys.accel(t, &cur.q, &cur.v, &mut acc);
                    cost.rhs_evaluations += 1;
                    if sys.lambda <= 0.0 {
                        sys.constrained = false;
                        sys.accel(t, &cur.q, &cur.v, &mut acc);
                        cost.rhs_evaluations += 1;
                    }
                }
                Switch::Release { tol } => {
                    report.max_release_force = report.max_release_force.max(sys.lambda.abs());
                    events.push(Event::Release {
                        t,
                        contact: 1,
                        normal_force: sys.lambda,
                        time_tolerance: tol,
                    });
                    sys.constrained = false;
                    sys.accel(t, &cur.q, &cur.v, &mut acc);
                    cost.rhs_evaluations += 1;
                }
            }
            sys.powers_at(t, &cur.v, &mut p_cur);
        }
        if sys.constrained {
            lam_prev = sys.lambda;
        } else {
            g_prev = sys.gap(&cur.q);
        }
    }
    cost.wall_time_s = clock.elapsed().as_secs_f64();
    let result = RunResult {
        backend: data::BackendKind::Fdm,
        scene: scene.name.clone(),
        settings: settings.clone(),
        observables: rec.obs,
        ledger: rec.ledger,
        events,
        cost,
        verdict,
    };
    Ok((result, report))
}
