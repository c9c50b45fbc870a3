//! One test per error of seed 004's printed equations: the printed and the corrected form
//! disagree on a case where it matters, and the corrected form agrees with the rigid reference
//! (whose equations are checked against the energies in `mobile.rs` and whose energy ledger
//! closes, checked here on the same scene). List: docs/mobile-manipulator.md.

use data::load_scene;
use verify::analytic::rigid::mobile::model::MAX_Q;
use verify::analytic::rigid::mobile::seed::{ClosedFormArm, PlatformClosedForm};
use verify::analytic::rigid::mobile::{Reference, Tolerances};

fn arm() -> (Reference, ClosedFormArm) {
    let scene = load_scene("mobile-arm-fixed-base").unwrap();
    let mm = scene.mobile_manipulator().unwrap();
    (
        Reference::from_scene(mm).unwrap(),
        ClosedFormArm::from_scene(mm).expect("closed form applies"),
    )
}

/// A raised, bent configuration with every joint moving.
const TH: [f64; 4] = [0.4, 0.7, -0.5, 0.9];
const THD: [f64; 4] = [1.2, -0.8, 1.5, 0.6];
/// The arm folded back over the turret: link 1 nearly level, links 2 and 3 turned back, so
/// the mass centres sit close to the yaw axis (small m ρ²) with the links lying flat.
const FOLDED: [f64; 4] = [0.0, 0.1, -3.0, 0.1];
/// A bent elbow (θ₃ far from 0).
const BENT: [f64; 4] = [0.4, 0.3, -1.5, 0.5];
/// A platform heading that is not special.
const HEADING: f64 = 0.6;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The reference's energy ledger closes on the fixed-base arm (what "the corrected form
/// satisfies the energy balance" rests on).
fn assert_reference_ledger_closes(r: &Reference) {
    let h = r.run(2.0, 0.05, Tolerances::default()).unwrap();
    let e0 = h.samples[0].kinetic + h.samples[0].potential;
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for s in &h.samples {
        let res = s.kinetic + s.potential - e0 - s.work[0] - s.work[1] + s.work[2] + s.work[3];
        worst = worst.max(res.abs());
        scale = scale.max(s.kinetic.abs()).max(s.work[1].abs());
    }
    assert!(worst <= 1e-10 * scale, "ledger {worst:e} / {scale:e}");
}

/// Absolute pitch angles β and horizontal radii ρ of the mass centres of links 1-3 and the
/// gripper (the corrected geometry of eqs. 7, 13, 19, 25).
fn pitch_radii(cf: &ClosedFormArm, th: &[f64; 4]) -> ([f64; 4], [f64; 4]) {
    let b1 = th[1];
    let b2 = b1 + th[2];
    let b3 = b2 + th[3];
    let beta = [b1, b2, b3, b3];
    let mut rho = [0.0; 4];
    let mut base = 0.0;
    for k in 0..4 {
        let b = &cf.bodies[k];
        rho[k] = base + b.com * beta[k].cos();
        base += b.length * beta[k].cos();
    }
    (beta, rho)
}

/// The corrected eq. 38 is the reference's M_θ₁θ₁, and B = C = D = 0 (eqs. 39-41) hold for
/// principal axes along the links; every eq. 38 test starts from this.
fn assert_corrected_yaw_inertia(r: &Reference, cf: &ClosedFormArm, th: &[f64; 4]) -> f64 {
    let mut mm = [[0.0; MAX_Q]; MAX_Q];
    r.model.mass_matrix(th, &mut mm);
    let corrected = cf.yaw_inertia_corrected(th);
    assert!(
        rel(corrected, mm[0][0]) < 1e-13,
        "{corrected} vs {}",
        mm[0][0]
    );
    for k in 1..4 {
        assert!(mm[0][k].abs() < 1e-15 * mm[0][0]);
    }
    corrected
}

/// Eq. 38 (and 32): the printed yaw inertia A has w_c = m_c g, the gripper's weight, where its
/// mass m_c belongs. With only that error, A is off by (g − 1) m_c ρ_c², which matters when the
/// gripper is far from the yaw axis (arm stretched out).
#[test]
fn seed_eq38_gripper_weight_in_yaw_inertia() {
    let (r, cf) = arm();
    let corrected = assert_corrected_yaw_inertia(&r, &cf, &TH);
    let (_, rho) = pitch_radii(&cf, &TH);
    let mc = cf.bodies[3].mass;
    let printed = corrected - mc * rho[3] * rho[3] + mc * cf.gravity * rho[3] * rho[3];
    assert!(
        rel(printed, corrected) > 0.5,
        "w_c for m_c: {printed} vs {corrected}"
    );
    // Also the printed eq. 38 as a whole (all its errors together) is far off.
    let whole = cf.yaw_inertia_printed(&TH);
    assert!(
        rel(whole, corrected) > 0.5,
        "printed {whole} vs {corrected}"
    );
    assert_reference_ledger_closes(&r);
}

/// Eq. 38 (and 32): the base disc enters as m_b r², though eq. 6 gives I_b = ½ m_b r². With only
/// that error A is off by J_turret,zz, which matters most with the arm folded close to the yaw
/// axis (A small).
#[test]
fn seed_eq38_base_disc_inertia() {
    let (r, cf) = arm();
    let folded = FOLDED;
    let corrected = assert_corrected_yaw_inertia(&r, &cf, &folded);
    let printed = corrected - cf.turret_jzz + 2.0 * cf.turret_jzz;
    assert!(
        rel(printed, corrected) > 0.1,
        "m_b r²: {printed} vs {corrected}"
    );
    assert_reference_ledger_closes(&r);
}

/// Eq. 38: the m₂ term is printed m₂(l₂ cos θ₂ + 2 l₁ cos θ₂)²/4, i.e. link 2 at the pitch of
/// link 1; eq. 32 has (l₂ cos(θ₂ + θ₃) + 2 l₁ cos θ₂)²/4 = m₂ ρ₂² (uniform rod, centre l₂/2). The
/// two agree at θ₃ = 0 and disagree as soon as the elbow bends.
#[test]
fn seed_eq38_link2_pitch_angle() {
    let (r, cf) = arm();
    let corrected = assert_corrected_yaw_inertia(&r, &cf, &BENT);
    let (l1, l2, m2) = (cf.bodies[0].length, cf.bodies[1].length, cf.bodies[1].mass);
    assert_eq!(
        cf.bodies[1].com,
        0.5 * l2,
        "the seed's lumped rod: centre at mid-length"
    );
    let term = |th: &[f64; 4], elbow: f64| {
        m2 * (l2 * (th[1] + elbow).cos() + 2.0 * l1 * th[1].cos()).powi(2) / 4.0
    };
    let (_, rho) = pitch_radii(&cf, &BENT);
    let corrected_term = term(&BENT, BENT[2]);
    assert!(rel(corrected_term, m2 * rho[1] * rho[1]) < 1e-14);
    let printed = corrected - corrected_term + term(&BENT, 0.0);
    assert!(
        rel(printed, corrected) > 0.1,
        "cos θ₂ for cos(θ₂+θ₃): {printed} vs {corrected}"
    );
    // With a straight elbow the printed term is right.
    let straight = [BENT[0], BENT[1], 0.0, BENT[3]];
    assert_eq!(term(&straight, straight[2]), term(&straight, 0.0));
    assert_reference_ledger_closes(&r);
}

/// Eqs. 32 and 38 carry no rotary inertia of the pitched bodies about the vertical; the
/// corrected A adds J_xx sin²β + J_zz cos²β per body. It matters when the masses sit near the
/// yaw axis (the folded arm), where the point-mass terms m ρ² are small.
#[test]
fn seed_eq38_link_rotary_inertia() {
    let (r, cf) = arm();
    let folded = FOLDED;
    let corrected = assert_corrected_yaw_inertia(&r, &cf, &folded);
    let (beta, _) = pitch_radii(&cf, &folded);
    let rotary: f64 = (0..4)
        .map(|k| {
            let (s, c) = beta[k].sin_cos();
            cf.bodies[k].jxx * s * s + cf.bodies[k].jzz * c * c
        })
        .sum();
    let printed = corrected - rotary;
    assert!(
        rel(printed, corrected) > 0.1,
        "no rotary inertia: {printed} vs {corrected}"
    );
    assert_reference_ledger_closes(&r);
}

/// Eq. 42: Q of joint 1. Printed: cos θ₂ for sin θ₂ in the m₃ term, the m₁ term without its ½
/// (eq. 33 has it), w_c for m_c. Corrected: θ̇₁ Ȧ, equal to the reference's τ₁ at θ̈ = 0.
#[test]
fn seed_eq42_velocity_terms_of_joint1() {
    let (r, cf) = arm();
    let mut h = [0.0; 4];
    r.model.inverse_dynamics(&TH, &THD, &[0.0; 4], true, &mut h);
    let corrected = cf.q_corrected(&TH, &THD);
    assert!(rel(corrected, h[0]) < 1e-12, "{corrected} vs {}", h[0]);
    let printed = cf.q_printed(&TH, &THD);
    assert!(rel(printed, h[0]) > 0.1, "printed {printed} vs {}", h[0]);
    assert_reference_ledger_closes(&r);
}

/// Eq. 30: the gripper's potential p_c = w_c g (…): the weight w_c = m_c g times g again.
/// Corrected m_c g (…) is the gripper's term of the reference's ∂V/∂θ (gravity torque).
#[test]
fn seed_eq30_gripper_weight_for_mass() {
    let (_, cf) = arm();
    let printed = cf.gripper_potential_printed(&TH);
    let corrected = cf.gripper_potential_corrected(&TH);
    assert!(rel(printed, corrected) > 5.0, "{printed} vs {corrected}");
    assert!(rel(printed / corrected, cf.gravity) < 1e-14);
    // The corrected gripper potential is the gripper's part of the reference's V (with its
    // mass centre at the link tip, as the seed has it): V(m_c) − V(0) = m_c g (z_axis + …),
    // z_axis the constant height of the first pitch axis.
    let scene = load_scene("mobile-arm-fixed-base").unwrap();
    let mut with = scene.mobile_manipulator().cloned().unwrap();
    with.arm.as_mut().unwrap().gripper.com = [0.0; 3];
    let mut without = with.clone();
    without.arm.as_mut().unwrap().gripper.mass = 0.0;
    let v = |m: &data::scene::MobileManipulator| {
        Reference::from_scene(m)
            .unwrap()
            .model
            .potential_energy(&TH)
    };
    let a = with.arm.as_ref().unwrap();
    let z_axis = a.mount[2] + a.base_height;
    let mc = a.gripper.mass;
    let mut tip = cf;
    tip.bodies[3].com = 0.0;
    let expected = tip.gripper_potential_corrected(&TH) + mc * cf.gravity * z_axis;
    let dv = v(&with) - v(&without);
    assert!(rel(dv, expected) < 1e-12, "{dv} vs {expected}");
}

/// Eqs. 7-29: link kinetic energy with I = m x² (x the configuration-dependent horizontal
/// coordinate of the mass centre) turning at the relative joint rate. Corrected: the body's
/// central moment about the pitch axis at the absolute pitch rate; equals the reference's T.
#[test]
fn seed_eq11_inertia_m_x_squared() {
    let (r, cf) = arm();
    let scene = load_scene("mobile-arm-fixed-base").unwrap();
    let a = scene.mobile_manipulator().unwrap().arm.as_ref().unwrap();
    let jyy = [
        a.links[0].inertia[1][1],
        a.links[1].inertia[1][1],
        a.links[2].inertia[1][1],
        a.gripper.inertia[1][1],
    ];
    let thd = [0.0, THD[1], THD[2], THD[3]];
    let t_ref = r.model.kinetic_energy(&TH, &thd);
    let corrected = cf.pitch_kinetic_corrected(&TH, &thd, &jyy);
    assert!(rel(corrected, t_ref) < 1e-13, "{corrected} vs {t_ref}");
    let printed = cf.pitch_kinetic_printed(&TH, &thd);
    assert!(rel(printed, t_ref) > 0.05, "printed {printed} vs {t_ref}");
    assert_reference_ledger_closes(&r);
}

/// Eqs. 66-67: platform accelerations. Printed: wheel spin inertia left out of v̇, and ω̇
/// driven by τ_R + τ_L (I/I) instead of b (τ_R − τ_L). Corrected: the reduced model's.
#[test]
fn seed_eq66_67_platform_accelerations() {
    let scene = load_scene("mobile-platform").unwrap();
    let mut mm = scene.mobile_manipulator().cloned().unwrap();
    // The closed forms hold for the mass centre on the middle axle.
    mm.platform.as_mut().unwrap().chassis_com_offset = 0.0;
    let r = Reference::from_scene(&mm).unwrap();
    let p = r.model.platform.clone().unwrap();
    let cf = PlatformClosedForm {
        mass: p.mass,
        yaw_inertia: p.yaw_inertia,
        wheel_radius: p.wheel_radius,
        half_track: p.half_track,
        side_spin_inertia: p.side_spin_inertia,
    };
    // Straight drive at equal torques, then a turn at opposite torques; accelerations from the
    // reduced right-hand side at t = 0 (from rest, so friction plays no part).
    for (tau_r, tau_l) in [(1.0, 1.0), (0.4, -0.4)] {
        let mut local = mm.clone();
        local.platform.as_mut().unwrap().drive = data::scene::TorqueSchedule::Steps {
            times: vec![0.0],
            values: vec![vec![tau_r, tau_l]],
        };
        let rr = Reference::from_scene(&local).unwrap();
        let y = [0.0, 0.0, HEADING, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let mut dy = [0.0; 11];
        let mut qdd = [0.0; MAX_Q];
        rr.reduced_rhs(0.0, &y, &mut dy, &mut qdd).unwrap();
        let (s, c) = HEADING.sin_cos();
        let u_dot = qdd[0] * c + qdd[1] * s;
        let psi_dd = qdd[2];
        let (uc, wc) = cf.accelerations_corrected(tau_r, tau_l);
        let (up, wp) = cf.accelerations_printed(tau_r, tau_l);
        assert!(
            (u_dot - uc).abs() <= 1e-13 * (1.0 + uc.abs()),
            "{u_dot} vs {uc}"
        );
        assert!(
            (psi_dd - wc).abs() <= 1e-13 * (1.0 + wc.abs()),
            "{psi_dd} vs {wc}"
        );
        if tau_r == tau_l {
            assert!(rel(up, uc) > 0.01, "eq. 66 {up} vs {uc}");
            assert!(
                wp.abs() > 1.0 && wc == 0.0,
                "eq. 67 turns a straight drive: {wp}"
            );
        } else {
            assert!(
                wp == 0.0 && wc.abs() > 0.1,
                "eq. 67 cannot turn: {wp} vs {wc}"
            );
        }
    }
    let h = r.run(3.0, 0.05, Tolerances::default()).unwrap();
    let e0 = h.samples[0].kinetic;
    for s in &h.samples {
        let res = s.kinetic - e0 - s.work[0] + s.work[2];
        assert!(res.abs() <= 1e-10 * s.work[0].abs().max(1e-3));
    }
}

/// The seed's decoupling (the arm computed on a fixed base): on the moving platform the
/// accelerating platform changes the arm torques needed for the same joint motion.
#[test]
fn seed_decoupled_arm_and_platform() {
    let full = {
        let s = load_scene("mobile-manipulator").unwrap();
        Reference::from_scene(s.mobile_manipulator().unwrap()).unwrap()
    };
    let (fixed, _) = arm();
    // Platform at rest heading 0, accelerating forward by u̇ = 1 m/s² (φ̈ = u̇/r both sides);
    // joints held still: the fixed-base model needs the gravity torques only.
    let r = full.model.platform.as_ref().unwrap().wheel_radius;
    let mut q = [0.0; MAX_Q];
    q[5..9].copy_from_slice(&TH);
    let qd = [0.0; MAX_Q];
    let mut qdd = [0.0; MAX_Q];
    qdd[0] = 1.0;
    qdd[3] = 1.0 / r;
    qdd[4] = 1.0 / r;
    let coupled = full.inverse_torques(&q, &qd, &qdd);
    let decoupled = fixed.inverse_torques(&TH, &[0.0; 4], &[0.0; 4]);
    let d2 = (coupled[3] - decoupled[1]).abs();
    assert!(
        d2 > 0.05 * decoupled[1].abs(),
        "joint 2: {} vs {}",
        coupled[3],
        decoupled[1]
    );
}
