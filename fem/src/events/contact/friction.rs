//! Bilateral tip contact with Coulomb friction and stick–slip (seed 001, scene
//! `constrained-arm`) for the midpoint schemes (`energy-midpoint`, the default, whose step the
//! text below describes; `implicit-midpoint` applies the same terms at its midpoint and books
//! the other works by the trapezoidal rule, so its ledger closes to O(h²) only; `bathe` holds it
//! at both sub-step ends; `central-difference` by projection, through the rows and the booking
//! of `projection_rows` and `commit_projection` here).
//!
//! **Constraint.** The tip of the named link stays on the wall ([`crate::events::wall`]) for all time:
//! g(q) = 0 from t = 0 (the scene starts on the wall, checked), never released, multiplier λ
//! (the normal force, positive pushing the tip to the free side) of either sign. The midpoint
//! step carries it exactly as the unilateral constrained phase of [`crate::events::contact`]: force
//! λ̄∇̄g with ∇̄g the Gonzalez discrete gradient of g (metric M(q̄)), and g(q₁) = 0 in the
//! bordered Newton iteration; so Δqᵀ∇̄g = g(q₁) − g(q₀) and the wall does no work. |g| at the
//! step ends is at the Newton tolerance (channel `contact1.gap`, running max
//! `contact1.max_gap`).
//!
//! **Coulomb friction while sliding** in direction s = ±1 (of t̂, counter-clockwise on a
//! circle): generalized force −μ s |λ| Tᵀ, T = t̂ᵀJ. In the step it is −μ s σ λ̄ T(q̄)ᵀ with λ̄
//! the step's multiplier and σ = sign λ fixed for the step (the index-1 sign at the step
//! start). If the converged λ̄ has the other sign the step is re-solved with σ flipped; if that
//! too is inconsistent the discrete problem has no Coulomb solution and the run stops
//! (Painlevé-type diagnostic). With σ fixed the friction force is linear in λ̄, so it simply
//! changes the border of the Newton system to ∇̄g − μ s σ T(q̄). The energy identity of the
//! scheme then gives E₁ − E₀ = W_applied − D with D = μ s σ λ̄ ΔqᵀT(q̄) = −Δqᵀ(friction force
//! of the step), which is exactly what the ledger books as `friction` (channel
//! `contact1.friction_work`): the ledger closes to the Newton tolerance. D approximates
//! ∫μ|λ||v_t| dt to second order (Δq = h v̄).
//!
//! **Index-1 forces at a state** (channels, event functions, phase decisions), from the dense
//! M(q) (the sparse mass matrix, `mass_solve`), R(q, q̇, 0) and the tip's convective acceleration a_c = J̇q̇:
//! * sliding: λ (G M⁻¹Gᵀ − μ s σ G M⁻¹Tᵀ) = G M⁻¹R − n̂·a_c + κ v_t². If
//!   G M⁻¹Gᵀ ≤ μ|G M⁻¹Tᵀ| (Painlevé: no or several λ) the run stops with that diagnosis;
//!   otherwise both brackets are positive and σ = sign of the right-hand side;
//! * tip held (stick, and the cone test): [[GM⁻¹Gᵀ, GM⁻¹Tᵀ], [TM⁻¹Gᵀ, TM⁻¹Tᵀ]] (λ_n, λ_t) =
//!   (G M⁻¹R − n̂·a_c + κ v_t², T M⁻¹R − t̂·a_c), λ_t the tangential force along t̂.
//!
//! **Stick–slip.** While sliding, the event function is s·v_t (v_t = T q̇); its zero is located
//! INSIDE the step by an Illinois secant on the step length (each trial a re-solved midpoint
//! step) to |v_t| ≤ [`VT_TOL`]·L per unit time on the far side, or a bracket below
//! [`crate::events::contact::TIME_TOL`] (trial steps ≥ [`MIN_TRIAL`]·h, rule 4 below). There the
//! Coulomb cone test with the held-tip forces decides:
//! stick if |λ_t| ≤ μ|λ_n|, else slide on in direction s = −sign λ_t (a reversal when s
//! changes; counted, not an event). While sticking, the tip is held at the stick point p_s by
//! the second constraint t̂_s·(r_tip − p_s) = 0, carried like g (discrete gradient, second
//! multiplier, 2 × 2 Schur complement in Newton), so it does no work either; the event function
//! is μ|λ_n| − |λ_t| (held-tip forces at the step end), located the same way; slip resumes in
//! direction −sign λ_t. The same cone test is made at t = 0 (the run starts at rest).
//!
//! **No chattering** (the rules; each switch advances time):
//! 1. A phase entered at a switch keeps its first step whole: that step is never shortened,
//!    and if the event function of the new phase is not positive at its end the switch is made
//!    there. So every switch is followed by at least one full step, and
//!    [`crate::events::contact::MAX_EVENTS`] bounds the count.
//! 2. Discrete consistency of the first slide step: if the tip moved against s over it (the
//!    booked friction work D < 0 — the friction force would have pushed the tip along), that
//!    step is re-solved with the tip held at its start position (a stick event at the step
//!    start; counted in `inconsistent_slides`). Seen at t = 0 on the scene: the index-1 test
//!    at rest says slip, but the first discrete step of the flexible link moves its tip
//!    backwards (non-minimum-phase response to the hub torque).
//! 3. A stop found at the end of a first slide step (not located) with the tip still moving
//!    faster than [`STICK_VT_TOL`]·L per unit time is a reversal: the tip slides on in its
//!    direction of motion (no stick test on a moving tip).
//! 4. Located switches never use trial steps shorter than [`MIN_TRIAL`] of the step: on a
//!    step of length h → 0 the constraint g(q₁) = 0, met only to the Newton tolerance at q₀,
//!    takes a multiplier ~ε/h², whose friction work can come out negative. A root within that first fraction is taken at the step start: the
//!    switch is applied there and the step re-solved in the new phase.
//!
//! Events: `data::Event::StickSlip` (`sticking` true at a stick, false at slip onset,
//! including t = 0); reversals are counted, not recorded (as in `modal`).
//!
//! Channels: `contact1.phase` 1 sliding, 2 sticking (modal's numbering: 0 would be free flight,
//! which a bilateral contact never has), `contact1.normal_force` (index-1 λ_n),
//! `contact1.slip_velocity` (v_t), `contact1.friction_force` (tangential force along t̂:
//! −μ s|λ| sliding, λ_t sticking), `contact1.friction_work` (= ledger `friction`).
//!
//! Measured figures on `constrained-arm` (ledger, gap, switches, θ(2 s) against the step and
//! against modal, the stiff limit against the rigid closed form): docs/contact.md. The wall
//! load is carried by the axial field, so the default step resolves the first axial mode
//! ([`crate::run::axial_wall_step`]).
//!
//! Refused: the inextensible link (no axial field) on the circle of radius L about its own hub
//! (it can stay on that circle only straight: the rigid model, gradient G = 0 and λ undefined).
//! Timoshenko links without rotary inertia are refused here (M is singular in the massless
//! section rotations, and the index-1 forces need M⁻¹).

use data::scene::{ContactMode, Surface};

use crate::chain::{AugmentedLayout, Chain, MAX_LINKS, V2};
use crate::error::FemError;
use crate::events::contact::Contact;
use crate::events::mass_solve::MassSolver;
use crate::events::wall::{Wall, row_along, rows};
use crate::linalg::{dot, solve2};
use crate::method::{ConstraintView, NewtonSystem, ProjectionRows};

/// Slip-velocity tolerance of a located stop, relative to the longest link (per unit time).
pub const VT_TOL: f64 = 1e-10;
/// Largest |v_t| (relative to the longest link, per unit time) at the end of a first step of a
/// slide for the Coulomb stick test; a faster tip slides on in its direction of motion.
pub const STICK_VT_TOL: f64 = 1e-8;
/// Shortest trial step of the event location, relative to the step being located.
pub const MIN_TRIAL: f64 = 1e-3;

/// The `describe` line of a planar chain's bilateral contact (None otherwise).
pub fn describe(contacts: &[data::scene::Contact]) -> Option<String> {
    let c = contacts.first()?;
    if c.mode != ContactMode::Bilateral {
        return None;
    }
    let friction = if c.friction > 0.0 {
        format!(
            "Coulomb friction μ = {} (friction work booked per step), located stick–slip events, \
             tip held by a second discrete-gradient constraint while sticking",
            c.friction
        )
    } else {
        "frictionless".to_string()
    };
    Some(format!(
        "contact1: bilateral tip contact of `{}` on the {} wall (g = 0 for all time in the \
         energy-midpoint step, discrete-gradient constraint force, multiplier λ = normal force); \
         {friction}",
        c.link,
        match c.surface {
            Surface::Circle { .. } => "circular",
            Surface::Line { .. } => "straight",
        }
    ))
}

/// Which event function a step is watched by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Switch {
    /// Sliding: s·v_t reaches zero.
    SlipStop,
    /// Sticking: μ|λ_n| − |λ_t| reaches zero.
    Breakaway,
}

/// Index-1 forces and tip kinematics at a state.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Forces {
    pub(crate) lambda_n: f64,
    /// Tangential force along t̂ (friction force sliding, holding force sticking).
    pub(crate) lambda_t: f64,
    pub(crate) vt: f64,
    pub(crate) vn: f64,
    pub(crate) gap: f64,
    pub(crate) tip: V2,
    pub(crate) tangent: V2,
    /// G M⁻¹Gᵀ ≤ μ|G M⁻¹Tᵀ| (sliding only).
    pub(crate) painleve: bool,
    pub(crate) gmg: f64,
    pub(crate) gmt: f64,
}

/// State of the bilateral (friction) contact; lives in [`Contact::bilateral`]. Parts as in
/// [`Contact`]: the constraint rows a step consumes, the friction phase, the record of the run
/// and the scratch of the index-1 wall forces.
#[derive(Debug, Clone)]
pub struct Bilateral {
    /// The wall, the Coulomb coefficient and the rows and multipliers of a step.
    pub constraint: WallConstraint,
    /// Stick or slide, its direction, the wall forces at the current state and the switch
    /// bookkeeping of the event location.
    pub phase: FrictionPhase,
    /// Friction work, switch counters and stick drift maxima of the run.
    pub record: FrictionRecord,
    /// M(q) factorized and the M⁻¹ products of the index-1 wall forces.
    pub(crate) solve: WallSolve,
}

/// The wall constraint as a step consumes it: normal row G and, while sticking, the
/// tangential row H of t̂_s·(r_tip − p_s) = 0, their discrete gradients and multipliers, and
/// the Coulomb term of a sliding step.
#[derive(Debug, Clone)]
pub struct WallConstraint {
    pub wall: Wall,
    pub mu: f64,
    /// Stick point p_s and tangent t̂_s of the held tip.
    pub stick_point: V2,
    pub stick_tangent: V2,
    /// Tangential multiplier of the last accepted stick step (Newton predictor).
    pub(crate) step_lambda_t: f64,
    /// Tangential multiplier of the current Newton iterate, that of the last residual
    /// evaluation, and the Newton increment not yet applied.
    pub(crate) lt_iter: f64,
    pub(crate) lt_eval: f64,
    pub(crate) dlt_pending: f64,
    /// g(q₁) and h(q₁) of the last residual evaluation.
    pub(crate) g1: f64,
    pub(crate) h1: f64,
    /// Friction work of the step being solved (booked when it is accepted).
    pub(crate) pending_work: f64,
    /// Friction work of the step's earlier sub-steps (a composite method's), which
    /// `pending_work` includes.
    pub(crate) work_before: f64,
    pub(crate) jac: Vec<f64>,
    pub(crate) g_row: Vec<f64>,
    pub(crate) t_row: Vec<f64>,
    pub(crate) h_bar: Vec<f64>,
    pub(crate) h_end: Vec<f64>,
    pub(crate) s_inv_h: Vec<f64>,
}

/// Phase of the Coulomb law: stick or slide, sliding direction, the wall forces at the
/// current state and what the event location carries between trials.
#[derive(Debug, Clone)]
pub struct FrictionPhase {
    pub sticking: bool,
    /// Sliding direction s = ±1 along t̂.
    pub slip_dir: f64,
    /// Sign of λ used in the friction term of the current step.
    pub sigma: f64,
    /// Tangential force along t̂ and slip velocity v_t at the current state.
    pub friction_force: f64,
    pub slip_velocity: f64,
    /// Switch found by the last trial: kind, bracket width, located inside the step.
    pub(crate) pending: Option<(Switch, f64, bool)>,
    /// Event function at the start of the current step.
    pub(crate) e0: f64,
    /// The current step is the first of its phase (not shortened by an event; module docs).
    pub(crate) fresh: bool,
}

/// What the run records of the friction contact.
#[derive(Debug, Clone)]
pub struct FrictionRecord {
    /// Cumulative friction work (ledger `friction`).
    pub friction_work: f64,
    /// Slip reversals (v_t crossed zero and the cone test sent the tip back, no stick).
    pub reversals: usize,
    /// First slide steps re-solved as stick steps (the tip moved against s).
    pub inconsistent_slides: usize,
    /// Largest |t̂_s·(r − p_s)| and |v_t| at the ends of stick steps (tangential drift).
    pub max_stick_offset: f64,
    pub max_stick_velocity: f64,
    /// Smallest (G M⁻¹Gᵀ − μ|G M⁻¹Tᵀ|)/(G M⁻¹Gᵀ) met while sliding (Painlevé margin).
    pub min_painleve_margin: f64,
}

/// Scratch of the index-1 wall forces: M(q) factorized and the products M⁻¹Gᵀ, M⁻¹Tᵀ, M⁻¹R.
#[derive(Debug, Clone)]
pub(crate) struct WallSolve {
    pub(crate) minv_g: Vec<f64>,
    pub(crate) minv_t: Vec<f64>,
    pub(crate) minv_r: Vec<f64>,
    pub(crate) mass: MassSolver,
    pub(crate) zero: Vec<f64>,
}

pub(crate) fn sign(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

impl Bilateral {
    /// The bilateral contact of the scene (None for a unilateral one) on `chain`.
    pub fn from_scene(
        c: &data::scene::Contact,
        chain: &Chain,
    ) -> Result<Option<Box<Self>>, FemError> {
        let n = chain.ndof;
        if c.mode != ContactMode::Bilateral {
            return Ok(None);
        }
        let wall = Wall::from_surface(&c.surface)?;
        let z = vec![0.0; n];
        Ok(Some(Box::new(Bilateral {
            constraint: WallConstraint {
                wall,
                mu: c.friction,
                stick_point: V2::zeros(),
                stick_tangent: V2::zeros(),
                step_lambda_t: 0.0,
                lt_iter: 0.0,
                lt_eval: 0.0,
                dlt_pending: 0.0,
                g1: 0.0,
                h1: 0.0,
                pending_work: 0.0,
                work_before: 0.0,
                jac: vec![0.0; 2 * n],
                g_row: z.clone(),
                t_row: z.clone(),
                h_bar: z.clone(),
                h_end: z.clone(),
                s_inv_h: z.clone(),
            },
            phase: FrictionPhase {
                sticking: false,
                slip_dir: 1.0,
                sigma: 1.0,
                friction_force: 0.0,
                slip_velocity: 0.0,
                pending: None,
                e0: 0.0,
                fresh: true,
            },
            record: FrictionRecord {
                friction_work: 0.0,
                reversals: 0,
                inconsistent_slides: 0,
                max_stick_offset: 0.0,
                max_stick_velocity: 0.0,
                min_painleve_margin: f64::INFINITY,
            },
            solve: WallSolve {
                minv_g: z.clone(),
                minv_t: z.clone(),
                minv_r: z.clone(),
                mass: MassSolver::new(chain, &[]),
                zero: z,
            },
        })))
    }

    /// Whether the contact has Coulomb friction (and hence stick–slip).
    pub fn has_friction(&self) -> bool {
        self.constraint.mu > 0.0
    }

    /// M(q) assembled sparsely and factorized ([`crate::events::mass_solve`]; reused at the
    /// same (t, q)).
    fn factor_mass(&mut self, chain: &mut Chain, t: f64, q: &[f64]) -> Result<(), FemError> {
        self.solve.mass.factor(chain, t, q, 0.0).map(|_| ())
    }

    /// Index-1 forces at (q, q̇) (module docs): the held-tip pair when `held`, else the sliding
    /// normal force with the current s (σ chosen consistently).
    pub(crate) fn forces(
        &mut self,
        chain: &mut Chain,
        link: usize,
        t: f64,
        q: &[f64],
        qd: &[f64],
        held: bool,
    ) -> Result<Forces, FemError> {
        self.factor_mass(chain, t, q)?;
        let r = chain.tip_jacobian(t, link, q, &mut self.constraint.jac);
        let f = self.constraint.wall.frame(r);
        rows(
            &f,
            &self.constraint.jac,
            &mut self.constraint.g_row,
            &mut self.constraint.t_row,
        );
        self.solve.minv_g.copy_from_slice(&self.constraint.g_row);
        self.solve.mass.solve_in_place(&mut self.solve.minv_g);
        self.solve.minv_t.copy_from_slice(&self.constraint.t_row);
        self.solve.mass.solve_in_place(&mut self.solve.minv_t);
        chain.residual(t, q, qd, &self.solve.zero, &mut self.solve.minv_r);
        self.solve.mass.solve_in_place(&mut self.solve.minv_r);
        let [_, v, a] = chain.tip_motion(t, link, q, qd, &self.solve.zero);
        let vt = f.tangent.dot(&v);
        let vn = f.normal.dot(&v);
        let conv_n = f.normal.dot(&a) - f.curvature * vt * vt;
        let conv_t = f.tangent.dot(&a);
        let gmg = dot(&self.constraint.g_row, &self.solve.minv_g);
        let gmt = dot(&self.constraint.g_row, &self.solve.minv_t);
        let tmt = dot(&self.constraint.t_row, &self.solve.minv_t);
        let rn = dot(&self.constraint.g_row, &self.solve.minv_r) - conv_n;
        let rt = dot(&self.constraint.t_row, &self.solve.minv_r) - conv_t;
        let mut out = Forces {
            vt,
            vn,
            gap: f.gap,
            tip: r,
            tangent: f.tangent,
            gmg,
            gmt,
            ..Forces::default()
        };
        if held {
            [out.lambda_n, out.lambda_t] = solve2([[gmg, gmt], [gmt, tmt]], [rn, rt]);
        } else {
            let m = self.constraint.mu * gmt.abs();
            out.painleve = self.constraint.mu > 0.0 && gmg <= m;
            let sigma = if rn == 0.0 {
                self.phase.sigma
            } else {
                sign(rn)
            };
            out.lambda_n = rn / (gmg - self.constraint.mu * self.phase.slip_dir * sigma * gmt);
            out.lambda_t = -self.constraint.mu * self.phase.slip_dir * out.lambda_n.abs();
        }
        if !(out.lambda_n.is_finite() && out.lambda_t.is_finite()) {
            return Err(FemError::Runaway {
                t,
                what: "non-finite contact force".into(),
                location: Some("contact1".into()),
                why: format!(
                    "the constraint rows are degenerate (G M⁻¹Gᵀ = {gmg:.3e}, T M⁻¹Tᵀ = {tmt:.3e})"
                ),
                remedy: "check that the wall is not redundant with the link kinematics".into(),
            });
        }
        Ok(out)
    }
}

/// Friction and stick terms of one midpoint Newton iterate (called from the energy-midpoint
/// step after the normal constraint force; module docs). Sliding: adds the friction force to
/// the residual and folds −μsσT(q̄) into the border ∇̄g. Sticking: adds −λ_t∇̄h of the
/// tangential constraint h = t̂_s·(r − p_s). Returns the constraint value that Newton must drive
/// to tolerance (g(q₁), or the larger of g(q₁), h(q₁) when sticking).
pub(crate) fn midpoint_terms(
    c: &mut Contact,
    chain: &Chain,
    v: &ConstraintView<'_>,
    gap1: f64,
    res: &mut [f64],
) -> f64 {
    let link = c.constraint.link;
    let Some(b) = c.bilateral.as_deref_mut() else {
        return gap1;
    };
    b.constraint.pending_work = b.constraint.work_before;
    if b.constraint.mu == 0.0 {
        return gap1;
    }
    let [t0, t_mid, t1] = v.t;
    let n = res.len();
    let r = chain.tip_jacobian(t_mid, link, v.qbar, &mut b.constraint.jac);
    if !b.phase.sticking {
        let f = b.constraint.wall.frame(r);
        row_along(f.tangent, &b.constraint.jac, &mut b.constraint.t_row);
        let k = b.constraint.mu * b.phase.slip_dir * b.phase.sigma;
        for i in 0..n {
            res[i] += k * v.lambda * b.constraint.t_row[i];
            c.constraint.g_bar[i] -= k * b.constraint.t_row[i];
        }
        b.constraint.pending_work =
            b.constraint.work_before + k * v.lambda * dot(v.dq, &b.constraint.t_row);
        return gap1;
    }
    if v.it == 0 {
        b.constraint.lt_iter = b.constraint.step_lambda_t;
    } else {
        b.constraint.lt_iter -= b.constraint.dlt_pending;
    }
    b.constraint.dlt_pending = 0.0;
    b.constraint.lt_eval = b.constraint.lt_iter;
    let ts = b.constraint.stick_tangent;
    let ps = b.constraint.stick_point;
    row_along(ts, &b.constraint.jac, &mut b.constraint.h_bar);
    let r1 = chain.tip_jacobian(t1, link, v.q1, &mut b.constraint.jac);
    row_along(ts, &b.constraint.jac, &mut b.constraint.h_end);
    let mut tips = [V2::zeros(); MAX_LINKS];
    chain.tip_positions(t0, v.q0, &mut tips[..chain.links.len()]);
    let h0 = ts.dot(&(tips[link] - ps));
    let h1 = ts.dot(&(r1 - ps));
    let corr = if v.denom > 0.0 {
        (h1 - h0 - dot(&b.constraint.h_bar, v.dq)) / v.denom
    } else {
        0.0
    };
    for i in 0..n {
        b.constraint.h_bar[i] += corr * v.w_dq[i];
        res[i] -= b.constraint.lt_iter * b.constraint.h_bar[i];
    }
    b.constraint.g1 = gap1;
    b.constraint.h1 = h1;
    if h1.abs() > gap1.abs() { h1 } else { gap1 }
}

/// The wall's rows for a projection method (central difference), beside the gap row the
/// caller filled: sliding, the normal multiplier's force gains the friction −μsσT; sticking,
/// the second row h = t̂_s·(r_tip − p_s) with its gradient as force direction.
pub(crate) fn projection_rows(
    c: &mut Contact,
    chain: &Chain,
    t: f64,
    q: &[f64],
    rows: &mut ProjectionRows,
) {
    let link = c.constraint.link;
    let Some(b) = c.bilateral.as_deref_mut() else {
        return;
    };
    if b.constraint.mu == 0.0 {
        return;
    }
    let r = chain.tip_jacobian(t, link, q, &mut b.constraint.jac);
    if !b.phase.sticking {
        let f = b.constraint.wall.frame(r);
        row_along(f.tangent, &b.constraint.jac, &mut b.constraint.t_row);
        let k = b.constraint.mu * b.phase.slip_dir * b.phase.sigma;
        for (x, tr) in rows.force[0].iter_mut().zip(&b.constraint.t_row) {
            *x -= k * tr;
        }
        return;
    }
    let ts = b.constraint.stick_tangent;
    row_along(ts, &b.constraint.jac, &mut rows.gradient[1]);
    rows.value[1] = ts.dot(&(r - b.constraint.stick_point));
    let (gradient, force) = (&rows.gradient[1], &mut rows.force[1]);
    force.copy_from_slice(gradient);
    rows.k = 2;
}

/// Books a projection method's converged step q₀ → q₁ on the wall from its start and end
/// multipliers (forces along the rows of [`projection_rows`] at q₀ and at q₁): the step's
/// normal multiplier is their mean (the driver's friction-sign check), the stick multiplier
/// the end one; sliding, the friction work by the trapezoidal rule, as the driver books the
/// other works, D = ½μsσ(μ₀T(q₀) + ν₀T(q₁))·Δq.
pub(crate) fn commit_projection(
    c: &mut Contact,
    chain: &Chain,
    [t0, t1]: [f64; 2],
    [q0, q1]: [&[f64]; 2],
    start: [f64; 2],
    end: [f64; 2],
) {
    c.constraint.step_lambda = 0.5 * (start[0] + end[0]);
    let link = c.constraint.link;
    let Some(b) = c.bilateral.as_deref_mut() else {
        return;
    };
    b.constraint.pending_work = 0.0;
    if b.constraint.mu == 0.0 {
        return;
    }
    if b.phase.sticking {
        b.constraint.lt_eval = end[1];
        return;
    }
    let k = b.constraint.mu * b.phase.slip_dir * b.phase.sigma;
    let mut work = 0.0;
    for (tq, q, lambda) in [(t0, q0, start[0]), (t1, q1, end[0])] {
        let r = chain.tip_jacobian(tq, link, q, &mut b.constraint.jac);
        let f = b.constraint.wall.frame(r);
        row_along(f.tangent, &b.constraint.jac, &mut b.constraint.t_row);
        let slide: f64 = (0..q0.len())
            .map(|i| b.constraint.t_row[i] * (q1[i] - q0[i]))
            .sum();
        work += 0.5 * k * lambda * slide;
    }
    b.constraint.pending_work = work;
}

/// Whether the contact is a sticking friction contact (two multipliers in Newton).
pub(crate) fn sticking(c: &Contact) -> bool {
    c.bilateral.as_deref().is_some_and(|b| b.phase.sticking)
}

/// Phase channel value: 2 sticking, 1 constrained (sliding), 0 free.
pub fn phase(c: &Contact) -> f64 {
    if sticking(c) {
        2.0
    } else if c.phase.constrained {
        1.0
    } else {
        0.0
    }
}

/// Newton update of a stick step: S δa − ∇̄g δλ_n − ∇̄h δλ_t = F with
/// k∇g(q₁)·δa = g(q₁), k∇h(q₁)·δa = h(q₁), k = ∂q₁/∂a (`dq1_da`), by the 2 × 2 Schur
/// complement (three solves of S). Leaves δa in `delta`, stores δλ_t for the next iterate,
/// returns δλ_n.
pub(crate) fn stick_newton_update(
    newton: &mut NewtonSystem<AugmentedLayout>,
    c: &mut Contact,
    res: &[f64],
    dq1_da: f64,
) -> f64 {
    let Some(b) = c.bilateral.as_deref_mut() else {
        return 0.0;
    };
    let n = res.len();
    newton.delta.copy_from_slice(&c.constraint.g_bar);
    newton.solve();
    c.constraint.s_inv_g.copy_from_slice(&newton.delta);
    newton.delta.copy_from_slice(&b.constraint.h_bar);
    newton.solve();
    b.constraint.s_inv_h.copy_from_slice(&newton.delta);
    newton.delta.copy_from_slice(res);
    newton.solve();
    let hh = dq1_da;
    let a11 = hh * dot(&c.constraint.g_end, &c.constraint.s_inv_g);
    let a12 = hh * dot(&c.constraint.g_end, &b.constraint.s_inv_h);
    let a21 = hh * dot(&b.constraint.h_end, &c.constraint.s_inv_g);
    let a22 = hh * dot(&b.constraint.h_end, &b.constraint.s_inv_h);
    let r1 = b.constraint.g1 - hh * dot(&c.constraint.g_end, &newton.delta);
    let r2 = b.constraint.h1 - hh * dot(&b.constraint.h_end, &newton.delta);
    let [dn, dt] = solve2([[a11, a12], [a21, a22]], [r1, r2]);
    for i in 0..n {
        newton.delta[i] += c.constraint.s_inv_g[i] * dn + b.constraint.s_inv_h[i] * dt;
    }
    b.constraint.dlt_pending = dt;
    dn
}
