//! A serial hexapod read from URDF, simulated by the same robot model as AMRU5 (Section 3.5:
//! multibody, Hertz contact at the foot spheres, dry/viscous joint friction, DC motors with
//! H-bridges, the digital PI loops of Eq. 4.18-4.20): it stands on flat ground, its feet carry
//! its weight and the energy account closes.
//!
//! The drives are test values of a small geared servo motor (n k_t = 2 Nm/A at the joint,
//! R = 4 Ω, 12 V), not a shipped robot's.

use std::sync::Arc;

use hexadyn::control::{DigitalPi, Encoder, JointPiController, JointReferences};
use hexadyn::description::urdf::serial_hexapod_from_urdf;
use hexadyn::description::PiGains;
use hexadyn::hexapod::{JointKind, Leg, LegChain, LegJoints, SerialHexapod, SerialLegKinematics, JOINTS};
use hexadyn::physics::{DcMotor, DryViscous, FlatGround, FrictionElement, GroundContact, JointFriction};
use hexadyn::robot::model::{FrictionModel, JointControl, ModelOptions, RobotModel, RobotParts};
use hexadyn::robot::simulation::{run, PlantOptions, SimulatedRobot};
use hexadyn::sim::NewmarkOptions;

const PERIOD: f64 = 0.01;
const PI_GAINS: PiGains = PiGains { k: 100.0, t_i: 0.5 };

fn robot() -> SerialHexapod {
    serial_hexapod_from_urdf(include_str!("data/random_hexapod.urdf"), "random_hexapod.urdf").unwrap()
}

fn model(robot: &SerialHexapod) -> Arc<RobotModel> {
    let mechanics = robot.mechanics().unwrap();
    let motor = DcMotor { r: 3.4, r_bridge: 0.6, l: 1e-4, k_t: 0.004, n: 500.0, inductance: false };
    let friction = FrictionElement::new(JointFriction::DryViscous(DryViscous { tau_f_d_plus: 0.05, tau_f_d_minus: -0.05, f_v_plus: 0.01, f_v_minus: 0.01, epsilon: 1e-3 }));
    let parts = RobotParts {
        multibody: mechanics.model,
        feet: mechanics.feet,
        joints: LegJoints::new(["coxa", "femur", "tibia"].map(String::from), [JointKind::Revolute; 3]).unwrap(),
        motors: [motor; JOINTS],
        friction: [friction; JOINTS],
        strokes: std::array::from_fn(|k| {
            let j = &robot.legs[k / 3].joints[k % 3];
            j.lower..=j.upper
        }),
        pi_gains: [PI_GAINS; JOINTS],
        encoders: [Encoder { counts_per_rev: 4096, n: motor.n }; JOINTS],
        servos: None,
        series: None,
    };
    let options = ModelOptions {
        friction: FrictionModel::DryViscous,
        load_dependence: false,
        inductance: false,
        // Table 3.3's ground, the foot spheres of the URDF.
        ground: GroundContact { k_gnd: 1e6, d_gnd: 5e4, p_k: 1.5, p_d: 0.5, mu: 0.7, v_glim: 1e-4, foot_radius: robot.legs[0].foot_radius },
        supply_voltage: 12.0,
        control: JointControl::Digital,
        stand: false,
        foot_load: [0.0; 6],
    };
    Arc::new(RobotModel::assemble(parts, options, Arc::new(FlatGround { height: 0.0 })))
}

/// Joints that put every foot on the ground under a level body at the centre of its leg's
/// workspace cylinder (Section 7.1.1), the ground at the mean height of the feet at mid-range
/// (Eq. 7.7 on each leg's chain).
fn standing_joints(robot: &SerialHexapod) -> [f64; JOINTS] {
    let legs = SerialLegKinematics::hexapod(&robot.legs).unwrap();
    let ground = legs.iter().map(|l| l.to_body(&l.foot(&l.limits().middle())).z).sum::<f64>() / 6.0;
    let mut joints = [0.0; JOINTS];
    for (leg, kin) in legs.iter().enumerate() {
        let z = ground - kin.body_from_leg().translation.z;
        let w = kin.workspace(z, z).unwrap_or_else(|e| panic!("leg {leg}: {e}"));
        let s = kin.inverse(&w.centre_at(z), &kin.limits().middle()).unwrap();
        assert!(s.is_reached(), "leg {leg}: {:?}", s.outcome);
        joints[3 * leg..3 * leg + 3].copy_from_slice(s.joints.as_slice());
    }
    joints
}

#[test]
fn a_urdf_hexapod_stands_under_pi_control_and_its_energy_account_closes() {
    let robot = robot();
    let m = model(&robot);
    let base = standing_joints(&robot);
    let q = m.touching_ground(&base);
    let qd = vec![0.0; q.len()];
    let options = PlantOptions { integrator: NewmarkOptions { tolerance: 1.0, h_max: PERIOD, h_initial: 1e-4, gamma: 0.6, beta: 0.3025, ..Default::default() }, period: PERIOD, navigation: false, current_sensing: Default::default() };
    let mut plant = SimulatedRobot::new(m.clone(), &q, &qd, &options).unwrap();
    let mut controller = JointPiController { pis: std::array::from_fn(|_| DigitalPi::new(PI_GAINS.k, PI_GAINS.t_i, PERIOD)), references: JointReferences { base, motions: Vec::new() } };
    let z0 = q[2];
    run(&mut plant, &mut controller, 3.0, |_, _, _| {}).unwrap();

    let s = plant.state();
    let weight = m.multibody.total_mass() * hexadyn::mbs::STANDARD_GRAVITY;
    let carried: f64 = plant.robot.outputs.contact.iter().map(|c| c.force.z).sum();
    assert!((carried - weight).abs() < 1e-3 * weight, "the feet carry {carried} N of {weight} N");
    assert!(plant.robot.outputs.contact.iter().all(|c| c.force.z > 0.02 * weight), "every foot on the ground: {:?}", plant.robot.outputs.contact.iter().map(|c| c.force.z).collect::<Vec<_>>());
    assert!((s.q[2] - z0).abs() < 2e-3 && s.q[4].abs() < 0.02 && s.q[5].abs() < 0.02, "the body sags: dZ {} m, pitch {}, roll {}", s.q[2] - z0, s.q[4], s.q[5]);
    let tracking = (0..JOINTS).map(|k| (s.q[6 + k] - base[k]).abs()).fold(0.0, f64::max);
    assert!(tracking < 3e-3, "joints within {tracking} rad of their references");
    let e = &plant.energy;
    let electrical: f64 = e.electrical.iter().sum();
    let error = e.balance_error(&plant.initial_energy);
    println!("carried {carried:.4} N of {weight:.4} N, dZ {:.2e} m, pitch {:.2e}, roll {:.2e}, tracking {tracking:.2e} rad, electrical {electrical:.4} J, imbalance {error:.2e} J", s.q[2] - z0, s.q[4], s.q[5]);
    assert!(electrical > 0.1 && error.abs() < 1e-3 * electrical, "imbalance {error} J of {electrical} J");
}

/// What a 20 s tripod walk did.
struct Walked {
    vx: f64,
    advance: f64,
    min_feet: usize,
    clamped: usize,
    electrical: f64,
    imbalance: f64,
}

/// The gait controller of Chapter 7 on the robot's own legs: a tripod (T = 2 s, enhanced cycle
/// with 5 % overlap, 2 cm foot lift) at the body height where the feet are at mid-range, from
/// the steady footholds, at the velocity whose support stroke is 80 % of the smallest workspace
/// diameter, for 20 s. Refused with the reason when a workspace is empty at that height or a
/// steady foothold is out of reach.
fn walk_tripod(robot: &SerialHexapod) -> Result<Walked, String> {
    use hexadyn::control::gait::controller::{joints_at, steady_footholds, AepMode, GaitController, GaitOptions};
    use hexadyn::control::gait::heading::{Constant, Heading, HeadingSource};
    use hexadyn::control::gait::pattern::{FootCycle, GaitPattern};

    let m = model(robot);
    let legs = SerialLegKinematics::hexapod(&robot.legs).map_err(|e| e.to_string())?;
    let height = -legs.iter().map(|l| l.to_body(&l.foot(&l.limits().middle())).z).sum::<f64>() / 6.0;
    let lift = 0.02;
    let mut workspaces = Vec::new();
    for (l, leg) in legs.iter().enumerate() {
        workspaces.push(leg.workspace(-height, -height + lift).map_err(|e| format!("leg {l} at body height {height:.4} m: {e}"))?);
    }
    let workspaces: [_; 6] = workspaces.try_into().expect("six legs");
    let (period, cycle) = (2.0, FootCycle::Enhanced { overlap: 0.05 });
    let pattern = GaitPattern::tripod();
    let support = cycle.support_fraction(pattern.beta);
    let radius = workspaces.iter().map(|w| w.radius).fold(f64::INFINITY, f64::min);
    let vx = 0.8 * 2.0 * radius / (support * period);
    let options = GaitOptions { period, pattern, cycle, aep: AepMode::Periodic, lift, dt: PERIOD };
    let mut heading = Constant(Heading::new(vx, 0.0, 0.0));
    let footholds = steady_footholds(&legs, &workspaces, height, &options, &heading.heading(0.0));
    let joints = joints_at(&legs, &footholds).map_err(|l| format!("leg {l}: its steady foothold is out of reach"))?;
    let q = m.touching_ground(&joints);
    let qd = vec![0.0; q.len()];
    let plant_options = PlantOptions { integrator: NewmarkOptions { tolerance: 1.0, h_max: PERIOD, h_initial: 1e-4, gamma: 0.6, beta: 0.3025, ..Default::default() }, period: PERIOD, navigation: false, current_sensing: Default::default() };
    let mut plant = SimulatedRobot::new(m.clone(), &q, &qd, &plant_options).unwrap();
    let pis = std::array::from_fn(|_| DigitalPi::new(PI_GAINS.k, PI_GAINS.t_i, PERIOD));
    let mut controller = GaitController::new(options, legs, workspaces, pis, Box::new(heading));
    let mut min_feet = 6;
    run(&mut plant, &mut controller, 20.0, |p, meas, _| {
        if meas.t > 0.5 {
            min_feet = min_feet.min(p.robot.outputs.contact.iter().filter(|c| c.normal_force > 0.0).count());
        }
    })
    .unwrap();
    let e = &plant.energy;
    Ok(Walked {
        vx,
        advance: plant.state().q[0] - q[0],
        min_feet,
        clamped: controller.diagnostics.clamped_references,
        electrical: e.electrical.iter().sum(),
        imbalance: e.balance_error(&plant.initial_energy),
    })
}

/// A walk on at least three feet with no foot reference out of reach (0 clamped IK
/// references), forward by 85 % to 105 % of the commanded distance (without navigation the
/// body is where its legs put it: the support legs lag their references under load and the feet
/// slip; 90 % for the irregular fixture robot, 97 % to 102.5 % for the random ones), its energy
/// account closed within 0.1 %.
fn assert_walked(w: &Walked, what: &str) {
    let commanded = w.vx * 20.0;
    println!("{what}: v_x {:.4} m/s, advance {:.4} m of {commanded:.4} m, min feet {}, clamped {}, electrical {:.3} J, imbalance {:.2e} J", w.vx, w.advance, w.min_feet, w.clamped, w.electrical, w.imbalance);
    assert_eq!(w.clamped, 0, "{what}: clamped IK references");
    assert!(w.min_feet >= 3, "{what}: {} feet on the ground", w.min_feet);
    assert!(w.advance > 0.85 * commanded && w.advance < 1.05 * commanded, "{what}: advance {} m for {commanded} m", w.advance);
    assert!(w.imbalance.abs() < 1e-3 * w.electrical, "{what}: imbalance {} J of {} J", w.imbalance, w.electrical);
}

/// The URDF hexapod walks its tripod.
#[test]
fn a_urdf_hexapod_walks_a_tripod() {
    assert_walked(&walk_tripod(&robot()).unwrap(), "random_hexapod.urdf");
}

/// A random serial hexapod within a real robot's range: legs mounted around the body at the
/// thesis' angles ± 10°, 8-14 cm from its centre; coxa, femur and tibia 3-6, 6-12 and 10-18 cm
/// long, 30-200 g each, their axes tilted up to 0.1 rad from z, y and y; the femur raised and
/// the tibia lowered at q = 0 (0.2-0.4 and 1.0-1.4 rad), ranges ±0.6-1.0 rad about it; physical
/// inertia tensors in random axes.
fn random_robot(seed: u64) -> SerialHexapod {
    use hexadyn::hexapod::{Link, SerialJoint, SerialLeg};
    use hexadyn::spatial::{rotation_about, yaw_pitch_roll, Htm};
    use nalgebra::{Matrix3, Vector3};
    use rand::{Rng, SeedableRng};

    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let inertia = |r: &mut rand_chacha::ChaCha8Rng, mass: f64, size: f64| {
        let s: [f64; 3] = std::array::from_fn(|_| mass * size * size * r.random_range(0.01..0.1));
        let axis = Vector3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), r.random_range(-1.0..1.0)).normalize();
        let turn = rotation_about(&axis, r.random_range(-1.0..1.0));
        turn * Matrix3::from_diagonal(&Vector3::new(s[1] + s[2], s[0] + s[2], s[0] + s[1])) * turn.transpose()
    };
    let base_mass = r.random_range(1.0..3.0);
    let base = Link { mass: base_mass, com: Vector3::new(r.random_range(-0.01..0.01), r.random_range(-0.01..0.01), 0.0), inertia: inertia(&mut r, base_mass, 0.15) };
    let legs = std::array::from_fn(|leg| {
        let yaw = [30.0f64, -30.0, 90.0, -90.0, 150.0, -150.0][leg].to_radians() + r.random_range(-0.17..0.17);
        let radius = r.random_range(0.08..0.14);
        let tilt = |r: &mut rand_chacha::ChaCha8Rng, v: Vector3<f64>| (v + Vector3::new(r.random_range(-0.1..0.1), r.random_range(-0.1..0.1), r.random_range(-0.1..0.1))).normalize();
        let lengths = [r.random_range(0.03..0.06), r.random_range(0.06..0.12), r.random_range(0.10..0.18)];
        let pitch = [0.0, -r.random_range(0.2..0.4), r.random_range(1.0..1.4)];
        let names = ["coxa", "femur", "tibia"];
        let joints = std::array::from_fn(|k| {
            let origin = if k == 0 {
                Htm { rotation: yaw_pitch_roll(yaw, 0.0, 0.0), translation: Vector3::new(radius * yaw.cos(), radius * yaw.sin(), 0.0) }
            } else {
                Htm { rotation: yaw_pitch_roll(0.0, pitch[k], 0.0), translation: Vector3::new(lengths[k - 1], 0.0, 0.0) }
            };
            let half = r.random_range(0.6..1.0);
            SerialJoint { name: format!("leg{leg}_{}", names[k]), origin, axis: tilt(&mut r, if k == 0 { Vector3::z() } else { Vector3::y() }), kind: JointKind::Revolute, lower: -half, upper: half }
        });
        let links = std::array::from_fn(|k| {
            let mass = r.random_range(0.03..0.2);
            Link { mass, com: Vector3::new(lengths[k] / 2.0, 0.0, 0.0), inertia: inertia(&mut r, mass, lengths[k]) }
        });
        SerialLeg { joints, links, foot: Vector3::new(lengths[2], 0.0, 0.0), foot_radius: 0.01 }
    });
    SerialHexapod { name: format!("random_{seed}"), base, legs }
}

/// Random serial hexapods walk a tripod, or are refused with the reason (a leg whose workspace
/// is empty at the standing height, a foothold out of reach); most of them walk (all 8 do).
#[test]
fn random_serial_hexapods_walk_a_tripod_or_are_refused_with_a_reason() {
    let mut walked = 0;
    for seed in 0..8 {
        match walk_tripod(&random_robot(seed)) {
            Ok(w) => {
                assert_walked(&w, &format!("random robot {seed}"));
                walked += 1;
            }
            Err(reason) => {
                println!("random robot {seed}: refused: {reason}");
                assert!(reason.starts_with("leg ") && (reason.contains("workspace") || reason.contains("out of reach")), "{reason}");
            }
        }
    }
    assert!(walked >= 6, "{walked} of 8 random robots walked");
}
