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
//! joint spring). The generalized symmetric problem is solved densely ([`crate::modes`]). The
//! gyroscopic term Ω(Gᵀ − G) is dropped from the eigenproblem (it couples u with v and w′ with φ;
//! the kinds then read e.g. `bending-horizontal (no gyroscopic)`). A free base without spring has
//! a rigid rotation (ω = 0), not reported. Kinds: the field holding most of a mode's kinetic
//! energy (`axial`, `bending-horizontal`, `bending-vertical`, `torsion`, `base`).
//!
//! ## Statics ([`statics`])
//! K_s d = −f_g: the linear sag of the clamped rod under self-weight, payload weight and the
//! payload's offset moment; `tip_deflection` = w_L, `tip_rotation` = w′_L. The same d is the
//! `static-sag` initial shape.
//!
//! ## Dynamics ([`simulate`])
//! Implicit midpoint rule with an analytic Newton matrix ([`step`]); works booked with the
//! scheme's midpoint quadrature. Default mesh 16 elements ([`crate::settings::DEFAULT_ELEMENTS`]);
//! default step min(output interval, T/[`STEPS_PER_PERIOD`]) with T the shorter of the periods of
//! the first horizontal and the first vertical bending mode of [`link_modes`] (the modes the base
//! torque and gravity drive), fitted to divide the output interval. Torsion and axial modes
//! (hundreds of Hz to kHz on the catalog rods, amplitudes 1e-7 rad / 1e-8 m) are not resolved by
//! that step: the midpoint rule keeps them bounded and undamped, with a phase error (tip twist
//! on `single-link-3d`: ≈ 5 % of its peak at the default step, 1.3 % at h = 1.25e-4 s). A stiff
//! rod gets a short default step (`single-link-3d-stiff`: 3.1e-5 s) although its flexible
//! amplitudes are tiny; pass `--dt` there. Only `implicit-midpoint`
//! (the default) is accepted; adaptive steps are refused.

pub mod model;
pub mod step;

use std::time::Instant;

use data::scene::{LinkField, LinkInitialShape, PayloadLink};
use data::{
    BackendKind, Cost, Diagnostic, DofPlan, EnergyLedger, ModalResult, ModeShape, Observables,
    RunResult, Scene, Settings, StabilityVerdict, StaticResult, channel, ledger_term,
};
use faer::Mat;
use faer::prelude::*;

use crate::band::BorderedBand;
use crate::element::beam3d::{PHI, U, V, W};
use crate::error::FemError;
use crate::settings;
use model::Model;
use step::{State, Stepper};

/// Default step: steps per period of the higher of the first bending modes of the two planes.
/// Measured on `single-link-3d` (16 elements, 2 s, against h = 3.125e-5 s; the scheme is second
/// order): the horizontal tip deflection v_L is off by 12 % of its peak at h = 1e-3 s (26 steps per
/// period of the 39 Hz horizontal mode), 3.1 % at 5e-4, 0.18 % at 1.25e-4; the base angle by
/// 3.1e-4, 7.9e-5 and 4.6e-6 of its peak. 80 steps per period gives h = 2.5e-4 s there.
pub const STEPS_PER_PERIOD: f64 = 80.0;

/// The scene's payload link (None for other families).
pub fn link(scene: &Scene) -> Option<&PayloadLink> {
    scene.payload_link.as_ref()
}

fn the_link(scene: &Scene) -> Result<&PayloadLink, FemError> {
    link(scene).ok_or_else(|| FemError::unsupported("fem: not a payload-link scene"))
}

fn field_dofs(f: LinkField) -> (&'static str, usize) {
    match f {
        LinkField::Axial => ("axial u", 1),
        LinkField::Horizontal => ("horizontal v, v′", 2),
        LinkField::Vertical => ("vertical w, w′", 2),
        LinkField::Torsion => ("torsion φ", 1),
    }
}

/// DOFs and physics built for the scene with `n_el` elements.
pub fn dof_plan(scene: &Scene, n_el: usize) -> Result<DofPlan, FemError> {
    let l = the_link(scene)?;
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

/// The lowest `count` flexible modes.
pub fn link_modes(md: &Model, count: usize) -> Result<Vec<Mode3d>, FemError> {
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
    let gyro = if omega_ref != 0.0 {
        " (no gyroscopic)"
    } else {
        ""
    };
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
            let group = if a == n {
                4
            } else {
                match slot_of(md, a) {
                    U => 0,
                    PHI => 3,
                    s if s <= 2 => 1,
                    _ => 2,
                }
            };
            share[group] += v[a] * mv;
        }
        let (g, _) = share
            .iter()
            .enumerate()
            .fold((0, f64::MIN), |b, (i, &s)| if s > b.1 { (i, s) } else { b });
        let (kind, field) = match g {
            0 => ("axial", Some(U)),
            1 => ("bending-horizontal", Some(V)),
            2 => ("bending-vertical", Some(W)),
            3 => ("torsion", Some(PHI)),
            _ => ("base", None),
        };
        out.push(Mode3d {
            omega: l.sqrt(),
            kind: format!("{kind}{gyro}"),
            field,
            vector: v,
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

pub fn modes(scene: &Scene, settings: &Settings, count: usize) -> Result<ModalResult, FemError> {
    let start = Instant::now();
    let l = the_link(scene)?;
    let n_el = settings::elements(&settings.discretization)?;
    let md = build(l, n_el)?;
    let modes = link_modes(&md, count)?;
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
    Ok(ModalResult {
        backend: BackendKind::Fem,
        scene: scene.name.clone(),
        settings: settings.clone(),
        frequencies_hz: modes
            .iter()
            .map(|m| m.omega / (2.0 * std::f64::consts::PI))
            .collect(),
        kinds: modes.iter().map(|m| m.kind.clone()).collect(),
        shapes,
        cost: Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs: md.n + usize::from(md.free_base()),
            factorizations: 1,
            ..Default::default()
        },
    })
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

pub fn statics(scene: &Scene, settings: &Settings) -> Result<StaticResult, FemError> {
    let start = Instant::now();
    let l = the_link(scene)?;
    let n_el = settings::elements(&settings.discretization)?;
    let md = build(l, n_el)?;
    let d = static_sag(&md)?;
    Ok(StaticResult {
        backend: BackendKind::Fem,
        scene: scene.name.clone(),
        settings: settings.clone(),
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
    pub stepper: Stepper,
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

pub fn prepare(scene: &Scene, settings: &Settings) -> Result<Prepared, FemError> {
    let l = the_link(scene)?;
    let n_el = settings::elements(&settings.discretization)?;
    match settings.time.method {
        None | Some(data::Method::ImplicitMidpoint) => {}
        Some(other) => {
            return Err(FemError::unsupported(format!(
                "fem payload link: method `{other}`; only `implicit-midpoint` is implemented \
                 for the 3-D link"
            )));
        }
    }
    if settings.time.rtol.is_some() || settings.time.atol.is_some() {
        return Err(FemError::unsupported(
            "fem payload link: adaptive steps (`time.rtol`/`time.atol`); use --dt",
        ));
    }
    let dt_user = settings::positive("time.dt", settings.time.dt)?;
    let t_end =
        settings::positive("time.t_end", settings.time.t_end)?.unwrap_or(scene.simulation.t_end);
    let out = scene.simulation.output_interval;
    let md = build(l, n_el)?;
    let h = match dt_user {
        Some(h) => h,
        None => {
            // The first bending mode of each carried plane (or the first mode without bending).
            let modes = link_modes(&md, 4 * md.fields.len() + 4)?;
            let first = |kind: &str| {
                modes
                    .iter()
                    .find(|m| m.kind.starts_with(kind))
                    .map(|m| m.omega)
            };
            let omega = match (first("bending-horizontal"), first("bending-vertical")) {
                (None, None) => modes.first().map_or(f64::INFINITY, |m| m.omega),
                (a, b) => a.unwrap_or(0.0).max(b.unwrap_or(0.0)),
            };
            fit(
                (2.0 * std::f64::consts::PI / (STEPS_PER_PERIOD * omega)).min(out),
                out,
            )
        }
    };
    let d = if l.initial_shape == LinkInitialShape::StaticSag {
        static_sag(&md)?
    } else {
        vec![0.0; md.n]
    };
    let (theta, rate) = match md.prescribed(0.0) {
        Some((th, r, _)) => (th, r),
        None => (md.initial_angle, md.initial_rate),
    };
    let n = md.n;
    let state = State {
        t: 0.0,
        d,
        dd: vec![0.0; n],
        theta,
        rate,
    };
    Ok(Prepared {
        stepper: Stepper::new(md, state),
        h,
        t_end,
        output_interval: out,
        stations: scene.simulation.field_stations.max(2),
    })
}

/// Samples the channels of [`channel::payload_link`] (the fields the rod carries) into `buf`.
fn sample(st: &Stepper, torque: f64, stations: usize, buf: &mut Vec<f64>) {
    buf.clear();
    let md = &st.model;
    let s = &st.state;
    let d = &s.d;
    let [x, y, z] = md.payload_position(d);
    let (c, sn) = (s.theta.cos(), s.theta.sin());
    buf.extend([s.theta, s.rate, torque, c * x - sn * y, sn * x + c * y, z]);
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

fn push_ledger(st: &Stepper, ledger: &mut EnergyLedger) {
    let md = &st.model;
    let s = &st.state;
    let mut stored = [0.0; 4];
    let mut k = 0;
    stored[k] = md.kinetic(&s.d, s.rate, &s.dd);
    k += 1;
    stored[k] = md.strain(&s.d);
    k += 1;
    if md.has_gravity {
        stored[k] = md.gravity(&s.d);
        k += 1;
    }
    if md.spring().0 > 0.0 {
        stored[k] = md.joint_spring(s.theta);
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
    for kv in &w.kelvin_voigt {
        diss[nd] = *kv;
        nd += 1;
    }
    ledger.push(s.t, &stored[..k], &input, &diss[..nd]);
}

pub fn simulate(scene: &Scene, settings: &Settings) -> Result<RunResult, FemError> {
    let start = Instant::now();
    let Prepared {
        mut stepper,
        h,
        t_end,
        output_interval,
        stations,
    } = prepare(scene, settings)?;
    let specs = channel::payload_link(&stepper.model.fields, stations);
    let mut obs = Observables::with_channels(&specs);
    let (s, i, d) = ledger_names(&stepper.model);
    let mut ledger = EnergyLedger::new(&s, &i, &d);
    let n = stepper.model.n;
    // Mass matrix factorized once: the torque a prescribed base needs at the output samples.
    let mut mass_lu = BorderedBand::new(n, 0, stepper.model.layout.half_bandwidth());
    if !stepper.model.free_base() {
        for r in 0..n {
            for c in stepper.model.m.cols(r) {
                mass_lu.add(r, c, stepper.model.m.get(r, c));
            }
        }
        mass_lu.factorize()?;
    }
    let mut scratch = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let mut buf = Vec::with_capacity(specs.len());
    let torque = stepper.state_torque(&mut mass_lu, &mut scratch);
    sample(&stepper, torque, stations, &mut buf);
    obs.push(0.0, &buf);
    push_ledger(&stepper, &mut ledger);
    let n_out = (t_end / output_interval - 1e-9).ceil().max(1.0) as usize;
    let mut verdict = StabilityVerdict::Completed;
    'outer: for k in 1..=n_out {
        let t_stop = (k as f64 * output_interval).min(t_end);
        while stepper.state.t < t_stop - 1e-9 * h {
            // Steps of h onto the output time (a shorter last step only when h does not divide
            // the interval); the time is snapped to the output grid against round-off.
            let rest = t_stop - stepper.state.t;
            let hk = if rest < h * (1.0 - 1e-9) { rest } else { h };
            let stepped = stepper.step(hk);
            if (stepper.state.t - t_stop).abs() < 1e-9 * h {
                stepper.state.t = t_stop;
            }
            if let Err(e) = stepped {
                match e {
                    FemError::Runaway {
                        t,
                        what,
                        location,
                        why,
                        remedy,
                    } => {
                        verdict = StabilityVerdict::Stopped {
                            diagnostic: Diagnostic {
                                t,
                                what,
                                location,
                                why,
                                remedy,
                            },
                        };
                        break 'outer;
                    }
                    other => return Err(other),
                }
            }
        }
        let torque = stepper.state_torque(&mut mass_lu, &mut scratch);
        sample(&stepper, torque, stations, &mut buf);
        if buf.iter().any(|v| !v.is_finite()) {
            verdict = StabilityVerdict::Stopped {
                diagnostic: Diagnostic {
                    t: stepper.state.t,
                    what: "non-finite state".into(),
                    location: None,
                    why: "the implicit step diverged".into(),
                    remedy: "reduce --dt".into(),
                },
            };
            break;
        }
        obs.push(stepper.state.t, &buf);
        push_ledger(&stepper, &mut ledger);
    }
    let c = stepper.counters;
    Ok(RunResult {
        backend: BackendKind::Fem,
        scene: scene.name.clone(),
        settings: settings.clone(),
        observables: obs,
        ledger,
        events: Vec::new(),
        cost: Cost {
            wall_time_s: start.elapsed().as_secs_f64(),
            dofs: n + usize::from(stepper.model.free_base()),
            steps: c.steps,
            rejected_steps: 0,
            rhs_evaluations: c.residuals,
            jacobian_evaluations: c.factorizations,
            factorizations: c.factorizations,
            newton_iterations: c.newton,
        },
        verdict,
    })
}
