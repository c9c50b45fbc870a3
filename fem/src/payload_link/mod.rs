//! The 3-D flexible link with an offset payload (seed 002, scene family `[payload_link]`):
//! modes, gravity statics and dynamics with 3-D beam elements in the turning frame.
//!
//! ## Model (docs/single-link-3d.md)
//! Base angle θ about Z; the rod along the turning frame's x carries u (axial), v (turning
//! plane), w (vertical) and φ (twist), each only if the scene's `fields` lists it. Element
//! ([`crate::element::beam3d`]): u, φ linear, v, w Hermite cubic; DOFs per node u, v, v′, w, w′, φ;
//! every operator integrated by 4-point Gauss quadrature (exact for all integrands).
//!
//! The kinetic energy truncated at second order in the fields (θ̇ of order zero) is a quadratic
//! form in the velocities whose coefficients are polynomials of degree ≤ 2 in the DOFs d:
//!
//! T = ½J(d)θ̇² + θ̇ b(d)·ḋ + ½ḋᵀMḋ,  J(d) = J₀ + 2j₁·d + dᵀK_c d,  b(d) = b₀ + Gᵀd,
//!
//! with constant band operators ([`model::Model`]) summed from two building blocks:
//! * a point of mass m at reference abscissa a with displacements (u, y, z) — rod sections
//!   (ρA dx at x) and the payload's centre (a = L + c, y = v_L + c v′_L, z = w_L + c w′_L):
//!   ½m[u̇² + ẏ² + ż² + 2θ̇(uẏ − u̇y) + 2θ̇aẏ + θ̇²(a² + 2au + u² + y²)], plus the foreshortening
//!   term −θ̇²m a S (S = s(x), or s_L + ½c(v′_L² + w′_L²) for the payload), which for the rod
//!   integrates to −½θ̇²∫ρA·½(L² − x²)(v′² + w′²) dx (the centrifugal tension);
//! * a rigid body of inertia I in the section axes (ρ dx·diag(J, I, I) for rod sections, I_p
//!   for the payload) with orientation R = R_t(0, −w′, v′)R_x(φ): its body angular velocity
//!   RᵀΩ = θ̇(w′, φ − ½v′w′, 1 − ½(w′² + φ²)) + (φ̇ + ½(w′v̇′ − v′ẇ′), −ẇ′ + φv̇′, v̇′ + φẇ′)
//!   gives ½(RᵀΩ)ᵀI(RᵀΩ) truncated at second order (products of inertia included).
//!
//! V = ½dᵀK_s d + f_g·d + ½K(θ − θ₀)² (K_s from EA u′², EI v″², EI w″², GJ φ′²; f_g from
//! g(ρA∫w + m_p(w_L + c w′_L))); Rayleigh ½b_mθ̇² + ½ḋᵀCḋ with C = Σ C_f, one band per damped
//! field (C_X A u̇′², C_Y I v̇″², C_Z I ẇ″², C_Φ J φ̇′²). Lagrange's equations:
//! * M d̈ + b(d)θ̈ + θ̇(Gᵀ − G)ḋ − θ̇²(j₁ + K_c d) + K_s d + Cḋ + f_g = 0,
//! * J(d)θ̈ + b(d)·d̈ + 2θ̇(j₁ + K_c d)·ḋ + ḋᵀGḋ = T_mot(t) − b_mθ̇ − K(θ − θ₀)
//!   (a prescribed base drops this equation; its left side plus b_mθ̇ + K(θ − θ₀) is the torque
//!   the motion needs, channel `joint1.torque`).
//!
//! Geometric stiffening and softening with θ̇² sit in −θ̇²K_c, the Coriolis/gyroscopic coupling
//! in θ̇(Gᵀ − G), the θ̈ coupling in b(d).
//!
//! ## Modes ([`modes`])
//! Linearized about the undeformed rod at the base's reference rate Ω (0, or the rate of a
//! `constant-rate` base): K = K_s − Ω²K_c, M; a free base adds θ (mass row J₀, b₀; stiffness the
//! joint spring). The generalized symmetric problem is solved densely ([`crate::modes`])
//! ([`link_modes`]). At a prescribed constant rate the gyroscopic term Ω(Gᵀ − G) (it couples u
//! with v and w′ with φ) stays in: the quadratic eigenproblem M q̈ + Ω(Gᵀ − G)q̇ + Kq = 0 in
//! first-order skew form ([`gyroscopic_modes`]). A free base without spring has a rigid rotation,
//! listed first at 0 Hz with kind `rigid`. Kinds: the field holding most of a mode's kinetic
//! energy (`axial`, `bending-horizontal`, `bending-vertical`, `torsion`, `rigid` for θ).
//!
//! ## Statics ([`statics`])
//! K_s d = −f_g: the linear sag of the clamped rod under self-weight, payload weight and the
//! payload's offset moment; `tip_deflection` = w_L, `tip_rotation` = w′_L. The same d is the
//! `static-sag` initial shape.
//!
//! ## Dynamics ([`simulate`])
//! The link is a [`crate::system::System`] ([`system::LinkSystem`]: residual groups, analytic
//! Newton matrix S = c_a ∂R/∂q̈ + c_v ∂R/∂q̇ + c_q ∂R/∂q, energies) stepped by a method of the
//! registry ([`crate::method::stepper`]) on the link's driver path ([`driver`]): fixed steps onto
//! the output times and the motor law's switches, works booked with the midpoint rule,
//! Kelvin–Voigt per damped field. Methods: `implicit-midpoint` (the default), `generalized-alpha`
//! (ρ∞ = 0.9 with the axial field, else 1), `energy-midpoint`, `bathe`, and `central-difference`
//! (its step under 2/ω_max, [`crate::method::central_difference::stability_bound`]: the
//! Kelvin–Voigt damping of the kHz axial and torsion modes is implicit in it). Adaptive
//! steps are refused.
//! Default mesh 16 elements ([`crate::settings::DEFAULT_ELEMENTS`]); default step of the implicit
//! methods [`default_step`]: the largest step (fitted to divide the output interval) whose
//! estimated phase error of the modes the scene's loads excite (gravity against the initial
//! shape, centrifugal load, motor torque and its switches, a prescribed base's acceleration),
//! each damped by its Kelvin–Voigt decay, stays below [`PHASE_ERROR_TOLERANCE`] of the scale of
//! the payload's height, its turning-plane position and the base angle (the estimate is the
//! implicit midpoint rule's phase error). Torsion and axial modes (hundreds of Hz to kHz on the
//! catalog rods) hardly move those observables and are not resolved by that step: the midpoint
//! rule keeps them bounded and undamped, with a phase error in `tip_twist`.

pub mod driver;
pub mod model;
pub mod system;

use std::time::Instant;

use data::scene::{LinkField, LinkInitialShape, PayloadLink};
use data::{
    BackendKind, Cost, DofPlan, EnergyLedger, FemSettings, ModalResult, ModeShape, Observables,
    RunResult, Scene, StabilityVerdict, StaticResult, channel, ledger_term,
};
use faer::prelude::*;
use faer::{Mat, c64};

use crate::band::BorderedBand;
use crate::driver::fixed_steps::QuarterRetries;
use crate::element::beam3d::{PHI, U, V, W};
use crate::error::FemError;
use crate::settings;
use crate::settings::Method;
use crate::system::System;
use driver::LinkDriver;
use model::Model;

/// Default step: the largest h whose estimated phase error of the modes the loads excite stays
/// below this fraction of each observable's scale ([`default_step`]).
pub const PHASE_ERROR_TOLERANCE: f64 = 1e-4;

fn field_dofs(f: LinkField) -> (&'static str, usize) {
    match f {
        LinkField::Axial => ("axial u", 1),
        LinkField::Horizontal => ("horizontal v, v′", 2),
        LinkField::Vertical => ("vertical w, w′", 2),
        LinkField::Torsion => ("torsion φ", 1),
    }
}

/// DOFs and physics built for the payload link `l` with `n_el` elements.
/// Elements of the 3-D link (Hermite cubics only).
pub fn elements(settings: &data::FemSettings) -> Result<usize, FemError> {
    settings::cubic_elements_or(
        settings,
        settings::DEFAULT_ELEMENTS,
        "3-D payload link",
        "the link",
    )
}

pub fn dof_plan(l: &PayloadLink, n_el: usize) -> Result<DofPlan, FemError> {
    let md = Model::assemble(l, n_el)?;
    let mut plan = DofPlan::default();
    if md.free_base() {
        plan.add("joint1 angle", 1);
    }
    for &f in &md.fields {
        let (what, per_node) = field_dofs(f);
        plan.add(format!("link1 {what}"), per_node * n_el);
    }
    let b = &mut plan.builds;
    b.push(format!(
        "link1: 3-D beam elements (linear u, φ; Hermite-cubic v, w), {n_el} elements"
    ));
    b.push("link1: second-order kinematics in the turning frame (foreshortening, centrifugal stiffening, Coriolis and θ̈ couplings, rotary inertia of sections)".into());
    b.push("payload: rigid body at the tip (mass, offset, full inertia matrix)".into());
    for (f, _) in &md.c_field {
        b.push(format!(
            "link1: Kelvin–Voigt damping of the {} field",
            f.name()
        ));
    }
    if md.has_gravity {
        b.push("gravity".into());
    }
    match &md.base {
        model::Base::Free {
            torque, stiffness, ..
        } => {
            if l.base_inertia() > 0.0 {
                b.push("joint1: hub inertia".into());
            }
            if *stiffness > 0.0 {
                b.push("joint1: spring".into());
            }
            if torque.is_some() {
                b.push("joint1: applied torque law".into());
            }
        }
        model::Base::Prescribed(_) => {
            b.push("joint1: prescribed motion (reports required torque)".into())
        }
    }
    if md.motor_friction > 0.0 {
        b.push("joint1: motor friction".into());
    }
    if l.initial_shape == LinkInitialShape::StaticSag {
        b.push("initial static sag".into());
    }
    Ok(plan)
}

/// Hub inertia I_B is part of J₀.
fn build(l: &PayloadLink, n_el: usize) -> Result<Model, FemError> {
    let mut md = Model::assemble(l, n_el)?;
    md.j0 += l.base_inertia();
    Ok(md)
}

/// Reference rate of the eigenproblem.
fn reference_rate(md: &Model) -> f64 {
    match &md.base {
        model::Base::Prescribed(data::scene::PrescribedMotion::ConstantRate { rate }) => *rate,
        _ => 0.0,
    }
}

/// One mode of the linearized link: ω, kind, eigenvector (d first, then θ for a free base).
#[derive(Debug, Clone)]
pub struct Mode3d {
    pub omega: f64,
    pub kind: String,
    pub field: Option<usize>,
    pub vector: Vec<f64>,
}

/// Dense (K, M) of the link linearized about the undeformed rod at the reference rate Ω:
/// K = K_s − Ω²K_c, M; a free base adds θ (mass row J₀, b₀; stiffness the joint spring) last.
fn linearized(md: &Model) -> (Mat<f64>, Mat<f64>) {
    let n = md.n;
    let free = md.free_base();
    let nn = n + usize::from(free);
    let omega_ref = reference_rate(md);
    let mut k = Mat::<f64>::zeros(nn, nn);
    let mut m = Mat::<f64>::zeros(nn, nn);
    for i in 0..n {
        for j in md.m.cols(i) {
            m[(i, j)] = md.m.get(i, j);
            k[(i, j)] = md.ks.get(i, j) - omega_ref * omega_ref * md.kc.get(i, j);
        }
    }
    if free {
        m[(n, n)] = md.j0;
        for i in 0..n {
            m[(i, n)] = md.b0[i];
            m[(n, i)] = md.b0[i];
        }
        k[(n, n)] = md.spring().0;
    }
    (k, m)
}

/// The lowest `count` flexible modes.
pub fn link_modes(md: &Model, count: usize) -> Result<Vec<Mode3d>, FemError> {
    let n = md.n;
    let free = md.free_base();
    let nn = n + usize::from(free);
    let (k, m) = linearized(md);
    // Shift σM (σ > 0) makes K + σM definite with a free base's rigid rotation; λ = μ − σ.
    let tr_k: f64 = (0..nn).map(|i| k[(i, i)].abs()).sum();
    let tr_m: f64 = (0..nn).map(|i| m[(i, i)]).sum();
    let sigma = if free { 1e-8 * tr_k / tr_m } else { 0.0 };
    let mut ks = k.clone();
    for i in 0..nn {
        for j in 0..nn {
            ks[(i, j)] += sigma * m[(i, j)];
        }
    }
    let (lam, x) = crate::modes::generalized_eigen(&ks, &m)?;
    let mut out = Vec::new();
    for (j, &l) in lam.iter().enumerate() {
        if out.len() >= count {
            break;
        }
        let l = l - sigma;
        if free && l.abs() <= 1e-6 * sigma {
            continue; // rigid rotation of the base
        }
        if l < 0.0 {
            return Err(FemError::Numerical {
                t: 0.0,
                message: format!(
                    "mode {} has ω² = {l:.3e} < 0: the linearized link is unstable at the \
                     reference rate",
                    j + 1
                ),
            });
        }
        let v: Vec<f64> = (0..nn).map(|i| x[(i, j)]).collect();
        // Kinetic-energy share per slot (u, v/v′, w/w′, φ) and of θ.
        let mut share = [0.0; 5];
        for a in 0..nn {
            let mv: f64 = (0..nn).map(|b| m[(a, b)] * v[b]).sum();
            let group = if a == n { 4 } else { group_of(md, a) };
            share[group] += v[a] * mv;
        }
        let (kind, field) = kind_of(&share);
        out.push(Mode3d {
            omega: l.sqrt(),
            kind: kind.to_string(),
            field,
            vector: v,
        });
    }
    Ok(out)
}

/// Kind of a mode from the kinetic-energy share of each group (u, v/v′, w/w′, φ, θ).
fn kind_of(share: &[f64; 5]) -> (&'static str, Option<usize>) {
    let (g, _) = share
        .iter()
        .enumerate()
        .fold((0, f64::MIN), |b, (i, &s)| if s > b.1 { (i, s) } else { b });
    match g {
        0 => ("axial", Some(U)),
        1 => ("bending-horizontal", Some(V)),
        2 => ("bending-vertical", Some(W)),
        3 => ("torsion", Some(PHI)),
        _ => ("rigid", None),
    }
}

/// Group (0 u, 1 v/v′, 2 w/w′, 3 φ) of field DOF i.
fn group_of(md: &Model, i: usize) -> usize {
    match slot_of(md, i) {
        U => 0,
        PHI => 3,
        s if s <= 2 => 1,
        _ => 2,
    }
}

/// The lowest `count` modes of a rod turning at the prescribed constant rate Ω with the
/// gyroscopic coupling: M q̈ + Ω(Gᵀ − G) q̇ + (K_s − Ω²K_c) q = 0. With z = (q̇, q),
/// A = diag(M, K) and the skew B = [[Ω(Gᵀ − G), K], [−K, 0]], A ż + B z = 0; for A = LLᵀ the
/// matrix S = L⁻¹BL⁻ᵀ is skew with eigenvalues ±iω: the ω are the positive eigenvalues of the
/// Hermitian iS, and the real and imaginary parts y of an eigenvector span the mode's real
/// plane (z = L⁻ᵀy). Kinds from the kinetic energy ½q̇ᵀMq̇ of both; the shape is the
/// displacement part q of the one with the larger one. (The eigenvalues of the symmetric SᵀS,
/// the ω² twice, are not accurate enough: with ω_max² ~ 1e11 the squared matrix split the
/// horizontal pair of `single-link-3d-constant-rate` by 5e-4 relative and gave one of them as
/// the mode.)
pub fn gyroscopic_modes(md: &Model, count: usize) -> Result<Vec<Mode3d>, FemError> {
    let n = md.n;
    if md.free_base() {
        return Err(FemError::unsupported(
            "fem payload link: gyroscopic modes need a prescribed base",
        ));
    }
    let rate = reference_rate(md);
    let (k, m) = linearized(md);
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    let mut b = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = m[(i, j)];
            a[(n + i, n + j)] = k[(i, j)];
            b[(i, j)] = rate * (md.g.get(j, i) - md.g.get(i, j));
            b[(i, n + j)] = k[(i, j)];
            b[(n + i, j)] = -k[(i, j)];
        }
    }
    let llt = a.llt(faer::Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "K_s − Ω²K_c is not positive definite: the linearized link is unstable at the \
                  reference rate"
            .into(),
    })?;
    let l = llt.L();
    let mut t = b;
    l.solve_lower_triangular_in_place(&mut t);
    let mut sk = t.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut sk);
    // sk = (L⁻¹BL⁻ᵀ)ᵀ = −S, skew up to round-off; i·sk is Hermitian with eigenvalues ∓ω, and
    // its lower triangle (all the eigensolver reads) is that of the skew part.
    let h = Mat::<c64>::from_fn(2 * n, 2 * n, |i, j| {
        c64::new(0.0, 0.5 * (sk[(i, j)] - sk[(j, i)]))
    });
    let ev = h
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| FemError::Numerical {
            t: 0.0,
            message: "eigensolver did not converge".into(),
        })?;
    // Ascending: the n positive eigenvalues are the upper half (A is definite, so none is 0).
    let values = ev.S().column_vector();
    let vectors = ev.U();
    let modes = n.min(count);
    let mut omega = Vec::with_capacity(modes);
    let mut z = Mat::<f64>::zeros(2 * n, 2 * modes);
    for p in 0..modes {
        let j = n + p;
        omega.push(values[j].re.max(0.0));
        for r in 0..2 * n {
            z[(r, 2 * p)] = vectors[(r, j)].re;
            z[(r, 2 * p + 1)] = vectors[(r, j)].im;
        }
    }
    l.transpose().solve_upper_triangular_in_place(&mut z);
    let mut out = Vec::new();
    for p in 0..modes {
        let (j0, j1) = (2 * p, 2 * p + 1);
        let mut share = [0.0; 5];
        let mut best = (f64::MIN, j0);
        for j in [j0, j1] {
            for r in 0..n {
                let mv: f64 = md.m.cols(r).map(|q| m[(r, q)] * z[(q, j)]).sum();
                share[group_of(md, r)] += z[(r, j)] * mv;
            }
            let disp: f64 = (0..n).map(|r| z[(n + r, j)] * z[(n + r, j)]).sum();
            if disp > best.0 {
                best = (disp, j);
            }
        }
        let (kind, field) = kind_of(&share);
        out.push(Mode3d {
            omega: omega[p],
            kind: kind.to_string(),
            field,
            vector: (0..n).map(|r| z[(n + r, best.1)]).collect(),
        });
    }
    Ok(out)
}

/// Slot (U, V, V_SLOPE, W, W_SLOPE, PHI) of field DOF i.
fn slot_of(md: &Model, i: usize) -> usize {
    let node = i / md.layout.per_node + 1;
    (0..6)
        .find(|&s| md.layout.dof(node, s) == Some(i))
        .unwrap_or(U)
}

/// The modes of `l`, the payload link of `scene`.
pub fn modes(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
    count: usize,
) -> Result<ModalResult, FemError> {
    let start = Instant::now();
    let n_el = elements(settings)?;
    let md = build(l, n_el)?;
    // A free base without spring turns rigidly (ω = 0, kind `rigid`), listed first as by the
    // other backends; a base at a prescribed constant rate keeps the gyroscopic coupling.
    let rigid = md.free_base() && md.spring().0 == 0.0 && count > 0;
    let mut modes = Vec::with_capacity(count);
    if rigid {
        modes.push(Mode3d {
            omega: 0.0,
            kind: "rigid".into(),
            field: None,
            vector: vec![0.0; md.n + 1],
        });
    }
    let flexible = count - usize::from(rigid);
    if reference_rate(&md) != 0.0 && !md.free_base() {
        modes.extend(gyroscopic_modes(&md, flexible)?);
    } else {
        modes.extend(link_modes(&md, flexible)?);
    }
    let st = scene.simulation.field_stations.max(2);
    let xs: Vec<f64> = (0..st)
        .map(|k| md.length * k as f64 / (st - 1) as f64)
        .collect();
    let shapes = modes
        .iter()
        .map(|m| {
            let mut y: Vec<f64> = match m.field {
                Some(slot) => xs
                    .iter()
                    .map(|&x| md.field_at(&m.vector[..md.n], slot, x))
                    .collect(),
                None => vec![0.0; st],
            };
            let big = y
                .iter()
                .fold(0.0f64, |a, &b| if b.abs() > a.abs() { b } else { a });
            if big != 0.0 {
                y.iter_mut().for_each(|v| *v /= big);
            }
            ModeShape {
                link: 1,
                x: xs.clone(),
                transverse: y,
            }
        })
        .collect();
    Ok(crate::modes::modal_result(
        scene,
        settings,
        modes.iter().map(|m| (m.omega, m.kind.clone())),
        shapes,
        md.n + usize::from(md.free_base()),
        start,
    ))
}

/// Linear gravity sag K_s d = −f_g (zero without gravity).
pub fn static_sag(md: &Model) -> Result<Vec<f64>, FemError> {
    let n = md.n;
    if !md.has_gravity {
        return Ok(vec![0.0; n]);
    }
    let k = md.ks.to_dense();
    let llt = k.llt(faer::Side::Lower).map_err(|_| FemError::Numerical {
        t: 0.0,
        message: "stiffness matrix of the payload link is not positive definite".into(),
    })?;
    let f = Mat::<f64>::from_fn(n, 1, |i, _| -md.fg[i]);
    let d = llt.solve(&f);
    Ok((0..n).map(|i| d[(i, 0)]).collect())
}

/// The gravity sag of `l`, the payload link of `scene`.
pub fn statics(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
) -> Result<StaticResult, FemError> {
    let start = Instant::now();
    let n_el = elements(settings)?;
    let md = build(l, n_el)?;
    let d = static_sag(&md)?;
    Ok(StaticResult {
        backend: BackendKind::Fem,
        scene: scene.name.clone(),
        settings: data::Settings::from(settings),
        tip_deflection: md.tip.w.dot(&d),
        tip_rotation: md.tip.w_slope.dot(&d),
        cost: Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs: md.n,
            factorizations: 1,
            ..Default::default()
        },
    })
}

/// Everything `simulate` needs, built once (benches reuse it).
pub struct Prepared {
    pub stepper: LinkDriver,
    pub h: f64,
    pub t_end: f64,
    pub output_interval: f64,
    pub stations: usize,
}

/// Largest step ≤ h that divides the output interval evenly.
fn fit(h: f64, out: f64) -> f64 {
    if h >= out {
        out
    } else {
        out / (out / h).ceil()
    }
}

/// Default step from the linearized modes and the scene's loads.
///
/// The implicit midpoint rule turns a mode ω into ω_h = (2/h)·atan(ωh/2) ≈ ω(1 − (ωh)²/12), so
/// after t_end a mode of amplitude A is off by A·min(2, ω³h²t_end/12). Each mode's amplitude is
/// estimated from the loads that start it ringing: the imbalance at t = 0 (gravity against the
/// initial shape, centrifugal load θ̇²(j₁ + K_c d₀), the motor torque or −b₀θ̈ of a prescribed base)
/// plus the largest jump of those loads between samples a quarter output interval apart (a
/// bang-bang switch): A_k = |φ_k·F|/(φ_kᵀMφ_k ω_k²) times the mode's share of three observables:
/// the payload's height z_C, its turning-plane position y_C + (L + c)θ, and θ. The error sums of
/// the payload's position (height and turning plane together) and of θ are held below
/// [`PHASE_ERROR_TOLERANCE`] times their scales: the payload's initial height plus, for a free
/// base, (L + c)·min(Θ, 1), plus Σ A_k; Θ plus Σ A_k (base), with Θ the rigid base excursion
/// over the run (prescribed law, or a rigid-body integration of
/// J₀θ̈ = T(t) − b_mθ̇ − K(θ − θ₀) for a free base). A mode's phase error grows over
/// min(t_end, 1/(eσ)), σ = φᵀCφ/(2φᵀMφ) its Kelvin–Voigt (and motor-friction) decay rate.
/// Torsion and axial modes hardly move these observables and so do not bound the step.
pub fn default_step(md: &Model, d0: &[f64], t_end: f64, out: f64) -> Result<f64, FemError> {
    let n = md.n;
    let free = md.free_base();
    let nn = n + usize::from(free);
    let (_, m) = linearized(md);
    let modes = link_modes(md, nn)?;
    // Load samples F(t) on (d, θ): imbalance and base-driven loads.
    let samples = (4.0 * t_end / out).ceil().max(1.0) as usize;
    let dt_s = t_end / samples as f64;
    let mut ksd0 = vec![0.0; n];
    md.ks.matvec(d0, &mut ksd0);
    let mut kcd0 = vec![0.0; n];
    md.kc.matvec(d0, &mut kcd0);
    // Rigid base: (θ, θ̇, θ̈) at the samples.
    let mut base = Vec::with_capacity(samples + 1);
    match md.prescribed(0.0) {
        Some(_) => {
            for i in 0..=samples {
                base.push(md.prescribed(i as f64 * dt_s).unwrap_or_default());
            }
        }
        None => {
            let (k_spring, set_point) = md.spring();
            let (mut th, mut w) = (md.initial_angle, md.initial_rate);
            let sub = 16;
            let hs = dt_s / sub as f64;
            let acc = |t: f64, th: f64, w: f64| {
                (md.motor_torque(t) - md.motor_friction * w - k_spring * (th - set_point)) / md.j0
            };
            base.push((th, w, acc(0.0, th, w)));
            for i in 0..samples {
                for j in 0..sub {
                    let t = i as f64 * dt_s + j as f64 * hs;
                    w += hs * acc(t, th, w);
                    th += hs * w;
                }
                let t = (i + 1) as f64 * dt_s;
                base.push((th, w, acc(t, th, w)));
            }
        }
    }
    let load = |i: usize, f: &mut [f64]| {
        let t = i as f64 * dt_s;
        let (_, w, a) = base[i];
        for j in 0..n {
            f[j] = -md.fg[j] - ksd0[j] + w * w * (md.j1[j] + kcd0[j]);
            if !free {
                f[j] -= md.b0[j] * a;
            }
        }
        if free {
            f[n] = md.motor_torque(t);
        }
    };
    let theta0 = base[0].0;
    let excursion = base
        .iter()
        .fold(0.0f64, |e, &(th, _, _)| e.max((th - theta0).abs()));
    let arm = md.length + md.offset;
    let mut f0 = vec![0.0; nn];
    let mut fa = vec![0.0; nn];
    let mut fb = vec![0.0; nn];
    load(0, &mut f0);
    // Per mode: excitation e_k = |φ·F(0)| + max_i |φ·(F(t_i) − F(t_{i−1}))|.
    let mut exc: Vec<f64> = modes
        .iter()
        .map(|md_k| crate::linalg::dot(&md_k.vector, &f0).abs())
        .collect();
    let mut jump = vec![0.0f64; modes.len()];
    fa.copy_from_slice(&f0);
    for i in 1..=samples {
        load(i, &mut fb);
        for (k, mk) in modes.iter().enumerate() {
            let dj: f64 = mk
                .vector
                .iter()
                .zip(fb.iter().zip(&fa))
                .map(|(p, (b, a))| p * (b - a))
                .sum();
            jump[k] = jump[k].max(dj.abs());
        }
        std::mem::swap(&mut fa, &mut fb);
    }
    // Amplitudes of (vertical, turning plane, base) per mode.
    let mut amp = Vec::with_capacity(modes.len());
    let mut horizon = Vec::with_capacity(modes.len());
    for (k, mk) in modes.iter().enumerate() {
        exc[k] += jump[k];
        let v = &mk.vector;
        let mut mv = 0.0;
        for a in 0..nn {
            for b in 0..nn {
                mv += v[a] * m[(a, b)] * v[b];
            }
        }
        let q = exc[k] / (mv * mk.omega * mk.omega);
        // Decay rate σ = φᵀCφ/(2φᵀMφ) (Kelvin–Voigt and motor friction): the phase error of a
        // damped mode, A e^(−σt)·ω³h²t/12, peaks at t = 1/σ.
        let mut cv = md.c.form(&v[..n], &v[..n]);
        if free {
            cv += md.motor_friction * v[n] * v[n];
        }
        let sigma = cv / (2.0 * mv);
        horizon.push(if sigma * t_end > 1.0 {
            1.0 / (std::f64::consts::E * sigma)
        } else {
            t_end
        });
        let th = if free { v[n] } else { 0.0 };
        amp.push([
            q * md.tip.z_c.dot(&v[..n]).abs(),
            q * (md.tip.y_c.dot(&v[..n]) + arm * th).abs(),
            q * th.abs(),
        ]);
    }
    // The payload's position (height and turning plane: one vector, so a barely moving
    // component is not held to its own tiny scale) and the base angle. A prescribed rotation
    // is exact and adds nothing to the position's scale.
    let sum = |c: usize| amp.iter().map(|a| a[c]).sum::<f64>();
    let rigid_arc = if free { arm * excursion.min(1.0) } else { 0.0 };
    let scale = [
        md.tip.z_c.dot(d0).abs() + rigid_arc + sum(0) + sum(1),
        if free { excursion + sum(2) } else { 0.0 },
    ];
    let within = |h: f64| {
        (0..2).all(|c| {
            if scale[c] <= 0.0 {
                return true;
            }
            let e: f64 = modes
                .iter()
                .zip(amp.iter().zip(&horizon))
                .map(|(mk, (a, t))| {
                    let a = if c == 0 { a[0] + a[1] } else { a[2] };
                    a * (mk.omega.powi(3) * h * h * t / 12.0).min(2.0)
                })
                .sum();
            e <= PHASE_ERROR_TOLERANCE * scale[c]
        })
    };
    if within(out) {
        return Ok(out);
    }
    // Bisection in log h between a step that resolves the fastest mode to 1e-9 and `out`.
    let fastest = modes.iter().fold(0.0f64, |w, mk| w.max(mk.omega));
    let (mut lo, mut hi) = ((1e-9f64).sqrt() / fastest.max(1.0 / out), out);
    if !within(lo) {
        return Ok(lo);
    }
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if within(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}

/// The stepper, step and output settings of a run of `l`, the payload link of `scene`.
pub fn prepare(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
) -> Result<Prepared, FemError> {
    let n_el = elements(settings)?;
    let method = settings.method.unwrap_or(Method::ImplicitMidpoint);
    if settings.rtol.is_some() || settings.atol.is_some() {
        return Err(FemError::unsupported(
            "fem payload link: adaptive steps (`time.rtol`/`time.atol`); use --dt",
        ));
    }
    let dt_user = settings::positive("time.dt", settings.dt)?;
    let t_end = settings::positive("time.t_end", settings.t_end)?.unwrap_or(scene.simulation.t_end);
    let out = scene.simulation.output_interval;
    let md = build(l, n_el)?;
    let d = if l.initial_shape == LinkInitialShape::StaticSag {
        static_sag(&md)?
    } else {
        vec![0.0; md.n]
    };
    let rho_inf = default_rho_inf(&md);
    match method {
        Method::CentralDifference => {
            // Explicit: the step under its stability bound at the initial state (Kelvin–Voigt
            // damping of the kHz axial and torsion modes included).
            let mut driver = LinkDriver::new(md, &d, method, out, rho_inf)?;
            let mut res = vec![0.0; driver.steps.system.ndof()];
            let (bound, dof) = crate::method::central_difference::stability_bound(
                &mut driver.steps.system,
                &driver.steps.state,
                &mut res,
            )?;
            let h = match dt_user {
                Some(dt) if dt > bound => {
                    return Err(FemError::StabilityBound {
                        dt,
                        bound,
                        bound_kind: crate::method::central_difference::BOUND_KIND.into(),
                        location: describe_dof(&driver.steps.system.model, dof),
                    });
                }
                Some(dt) => dt,
                None => fit(crate::run::DEFAULT_SAFETY * bound, out),
            };
            driver.steps.h_nominal = h;
            Ok(Prepared {
                stepper: driver,
                h,
                t_end,
                output_interval: out,
                stations: scene.simulation.field_stations.max(2),
            })
        }
        _ => {
            let h = match dt_user {
                Some(h) => h,
                None => fit(default_step(&md, &d, t_end, out)?.min(out), out),
            };
            Ok(Prepared {
                stepper: LinkDriver::new(md, &d, method, h, rho_inf)?,
                h,
                t_end,
                output_interval: out,
                stations: scene.simulation.field_stations.max(2),
            })
        }
    }
}

/// Generalized-α's spectral radius for the link: 1 (no numerical damping, as the implicit
/// midpoint rule), or 0.9 when the rod carries the axial field, whose kHz modes the default
/// step does not resolve (the chain's rule, [`crate::run::default_rho_inf`]).
fn default_rho_inf(md: &Model) -> f64 {
    if md.fields.contains(&LinkField::Axial) {
        0.9
    } else {
        1.0
    }
}

/// A DOF of the link by name: the base angle or the slot and node of a field DOF.
fn describe_dof(md: &Model, dof: usize) -> String {
    if dof >= md.n {
        return "joint1 angle".into();
    }
    let node = dof / md.layout.per_node + 1;
    let slot = ["u", "v", "v′", "w", "w′", "φ"][slot_of(md, dof)];
    format!("link1 node {node} {slot}")
}

/// Torque of the base at the driver's state: the motor law of a free base; for a prescribed
/// base, the torque its motion needs, with d̈ from the field equations M d̈ = −R_d(t, d, ḋ, 0)
/// (`mass_lu`: M factorized once; `scratch`: two vectors of n).
fn state_torque(
    st: &mut LinkDriver,
    mass_lu: &mut BorderedBand,
    scratch: &mut [Vec<f64>; 2],
) -> f64 {
    let s = &st.steps.state;
    if st.steps.system.free_base() {
        return st.steps.system.model.motor_torque(s.t);
    }
    let [zero, acc] = scratch;
    st.steps.system.residual(s.t, &s.q, &s.qd, zero, acc);
    acc.iter_mut().for_each(|v| *v = -*v);
    mass_lu.solve_in_place(acc);
    st.steps.system.base_torque(s.t, &s.q, &s.qd, acc)
}

/// Samples the channels of [`channel::payload_link`] (the fields the rod carries) into `buf`.
fn sample(st: &LinkDriver, torque: f64, stations: usize, buf: &mut Vec<f64>) {
    buf.clear();
    let sys = &st.steps.system;
    let md = &sys.model;
    let s = &st.steps.state;
    let d = &s.q[..md.n];
    let (theta, rate, _) = sys.base(s.t, &s.q, &s.qd, &s.qdd);
    let [x, y, z] = md.payload_position(d);
    let (c, sn) = (theta.cos(), theta.sin());
    buf.extend([theta, rate, torque, c * x - sn * y, sn * x + c * y, z]);
    let has = |f| md.fields.contains(&f);
    let t = &md.tip;
    for (j, q) in channel::PAYLOAD_LINK_TIP.iter().enumerate() {
        if !has(q.field) {
            continue;
        }
        // Entries in the registry's order: u, v, w, φ, v′, w′ at the tip.
        let row = [&t.u, &t.v, &t.w, &t.phi, &t.v_slope, &t.w_slope][j];
        buf.push(row.dot(d));
    }
    for p in channel::PAYLOAD_LINK_PROFILES.iter() {
        let component = match p.field {
            LinkField::Horizontal => V,
            LinkField::Vertical => W,
            LinkField::Torsion => PHI,
            LinkField::Axial => continue,
        };
        if !has(p.field) {
            continue;
        }
        for k in 0..stations {
            let xk = md.length * k as f64 / (stations - 1) as f64;
            buf.push(md.field_at(d, component, xk));
        }
    }
}

/// Ledger layout: stored, inputs, dissipation names.
fn ledger_names(md: &Model) -> (Vec<&'static str>, Vec<&'static str>, Vec<&'static str>) {
    let mut stored = vec![ledger_term::KINETIC, ledger_term::STRAIN];
    if md.has_gravity {
        stored.push(ledger_term::GRAVITY);
    }
    if md.spring().0 > 0.0 {
        stored.push(ledger_term::JOINT_SPRING);
    }
    let inputs = if md.free_base() {
        vec![ledger_term::APPLIED_TORQUE]
    } else {
        vec![ledger_term::PRESCRIBED_MOTION]
    };
    let mut diss = Vec::new();
    if md.motor_friction > 0.0 {
        diss.push(ledger_term::JOINT_DAMPER);
    }
    for (f, _) in &md.c_field {
        diss.push(ledger_term::kelvin_voigt_of(*f));
    }
    (stored, inputs, diss)
}

fn push_ledger(st: &LinkDriver, ledger: &mut EnergyLedger) {
    let sys = &st.steps.system;
    let md = &sys.model;
    let s = &st.steps.state;
    let n = md.n;
    let (d, dd) = (&s.q[..n], &s.qd[..n]);
    let (theta, rate, _) = sys.base(s.t, &s.q, &s.qd, &s.qdd);
    let mut stored = [0.0; 4];
    let mut k = 0;
    stored[k] = md.kinetic(d, rate, dd);
    k += 1;
    stored[k] = md.strain(d);
    k += 1;
    if md.has_gravity {
        stored[k] = md.gravity(d);
        k += 1;
    }
    if md.spring().0 > 0.0 {
        stored[k] = md.joint_spring(theta);
        k += 1;
    }
    let w = &st.works;
    let input = [if md.free_base() {
        w.applied_torque
    } else {
        w.prescribed_motion
    }];
    let mut diss = [0.0; 5];
    let mut nd = 0;
    if md.motor_friction > 0.0 {
        diss[nd] = w.joint_damper;
        nd += 1;
    }
    for kv in &w.kelvin_voigt[..md.c_field.len()] {
        diss[nd] = *kv;
        nd += 1;
    }
    ledger.push(s.t, &stored[..k], &input, &diss[..nd]);
}

/// A run of `l`, the payload link of `scene`.
pub fn simulate(
    scene: &Scene,
    l: &PayloadLink,
    settings: &FemSettings,
) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        mut stepper,
        h,
        t_end,
        output_interval,
        stations,
    } = prepare(scene, l, settings)?;
    let md = &stepper.steps.system.model;
    let specs = channel::payload_link(&md.fields, stations);
    let mut obs = Observables::with_channels(&specs);
    let (s, i, d) = ledger_names(md);
    let mut ledger = EnergyLedger::new(&s, &i, &d);
    let n = md.n;
    let free = md.free_base();
    // Mass matrix factorized once: the torque a prescribed base needs at the output samples.
    let mut mass_lu = BorderedBand::new(n, 0, md.layout.half_bandwidth());
    if !free {
        for r in 0..n {
            for c in md.m.cols(r) {
                mass_lu.add(r, c, md.m.get(r, c));
            }
        }
        mass_lu.factorize()?;
    }
    let mut scratch = [vec![0.0; n], vec![0.0; n]];
    let mut buf = Vec::with_capacity(specs.len());
    let torque = state_torque(&mut stepper, &mut mass_lu, &mut scratch);
    sample(&stepper, torque, stations, &mut buf);
    obs.push(0.0, &buf);
    push_ledger(&stepper, &mut ledger);
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut verdict = StabilityVerdict::Completed;
    'outer: for k in 1..=n_out {
        let t_out = (k as f64 * output_interval).min(t_end);
        while stepper.steps.state.t < t_out - 1e-9 * h {
            // Steps of h onto the next output time or motor-law breakpoint (a shorter last
            // step only when h does not divide the stretch); the end is snapped to the stop
            // time against round-off.
            let t_stop = stepper.next_breakpoint().map_or(t_out, |b| b.min(t_out));
            let rest = t_stop - stepper.steps.state.t;
            let hk = if rest < h * (1.0 - 1e-9) { rest } else { h };
            let mut t1 = stepper.steps.state.t + hk;
            if (t1 - t_stop).abs() < 1e-9 * h {
                t1 = t_stop;
            }
            if let Err(e) = stepper.step(hk, t1) {
                verdict = StabilityVerdict::Stopped {
                    diagnostic: e.into_stop_diagnostic()?,
                };
                break 'outer;
            }
        }
        let torque = state_torque(&mut stepper, &mut mass_lu, &mut scratch);
        sample(&stepper, torque, stations, &mut buf);
        if buf.iter().any(|v| !v.is_finite()) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: crate::error::non_finite_state(stepper.steps.state.t),
            };
            break;
        }
        obs.push(stepper.steps.state.t, &buf);
        push_ledger(&stepper, &mut ledger);
    }
    Ok(crate::run::run_result(
        scene,
        settings,
        obs,
        ledger,
        Vec::new(),
        stepper.steps.counters.cost(n + usize::from(free), start),
        verdict,
    ))
}
