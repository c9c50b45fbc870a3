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
    let mm = scene.mobile_manipulator.as_ref().unwrap();
    (
        Reference::from_scene(mm).unwrap(),
        ClosedFormArm::from_scene(mm).expect("closed form applies"),
    )
}

/// A raised, bent configuration with every joint moving.
const TH: [f64; 4] = [0.4, 0.7, -0.5, 0.9];
const THD: [f64; 4] = [1.2, -0.8, 1.5, 0.6];
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

/// Eq. 38: yaw inertia A. Printed: w_c for m_c, m_b r² for ½ m_b r², cos θ₂ for cos(θ₂+θ₃) in
/// the m₂ term, no rotary inertia of the links. Corrected: equals M_θ₁θ₁ of the reference.
#[test]
fn seed_eq38_yaw_inertia() {
    let (r, cf) = arm();
    let mut mm = [[0.0; MAX_Q]; MAX_Q];
    r.model.mass_matrix(&TH, &mut mm);
    let corrected = cf.yaw_inertia_corrected(&TH);
    assert!(
        rel(corrected, mm[0][0]) < 1e-13,
        "{corrected} vs {}",
        mm[0][0]
    );
    let printed = cf.yaw_inertia_printed(&TH);
    assert!(
        rel(printed, mm[0][0]) > 0.5,
        "printed {printed} vs {}",
        mm[0][0]
    );
    // B = C = D = 0 (eqs. 39-41) do hold for principal axes along the links.
    for k in 1..4 {
        assert!(mm[0][k].abs() < 1e-15 * mm[0][0]);
    }
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
    let mut with = scene.mobile_manipulator.clone().unwrap();
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
    let a = scene
        .mobile_manipulator
        .as_ref()
        .unwrap()
        .arm
        .as_ref()
        .unwrap();
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
    let mut mm = scene.mobile_manipulator.clone().unwrap();
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
        Reference::from_scene(s.mobile_manipulator.as_ref().unwrap()).unwrap()
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
