//! A serial hexapod read from URDF, simulated by the same robot model as AMRU5 (Section 3.5:
//! multibody, Hertz contact at the foot spheres, dry/viscous joint friction, DC motors with
//! H-bridges, the digital PI loops of Eq. 4.18-4.20): it stands on flat ground, its feet carry
//! its weight and the energy account closes.
//!
//! The drives are test values of a small geared servo motor (n k_t = 2 Nm/A at the joint,
//! R = 4 Ω, 12 V), not a shipped robot's.

use std::sync::Arc;

use hexadyn::control::{DigitalPi, JointPiController, JointReferences};
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
    let options = PlantOptions { integrator: NewmarkOptions { tolerance: 1.0, h_max: PERIOD, h_initial: 1e-4, gamma: 0.6, beta: 0.3025, ..Default::default() }, period: PERIOD, encoder_counts: 4096, navigation: false, current_sensing: Default::default() };
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

/// The gait controller of Chapter 7 on the URDF hexapod's own legs: a tripod (T = 2 s, enhanced
/// cycle with 5 % overlap, 2 cm foot lift) from the steady footholds at the workspace centres,
/// at the velocity whose support stroke is 80 % of the smallest workspace diameter. It walks
/// 20 s on at least three feet, with no foot reference out of reach (0 clamped IK
/// references), advances between 80 % and 102 % of the commanded distance and its energy
/// account closes.
#[test]
fn a_urdf_hexapod_walks_a_tripod() {
    use hexadyn::control::gait::controller::{joints_at, steady_footholds, AepMode, GaitController, GaitOptions};
    use hexadyn::control::gait::heading::{Constant, Heading, HeadingSource};
    use hexadyn::control::gait::pattern::{FootCycle, GaitPattern};

    let robot = robot();
    let m = model(&robot);
    let legs = SerialLegKinematics::hexapod(&robot.legs).unwrap();
    let height = -legs.iter().map(|l| l.to_body(&l.foot(&l.limits().middle())).z).sum::<f64>() / 6.0;
    let lift = 0.02;
    let workspaces = std::array::from_fn(|l| legs[l].workspace(-height, -height + lift).unwrap_or_else(|e| panic!("leg {l}: {e}")));
    let (period, cycle) = (2.0, FootCycle::Enhanced { overlap: 0.05 });
    let pattern = GaitPattern::tripod();
    let support = cycle.support_fraction(pattern.beta);
    let radius = workspaces.iter().map(|w| w.radius).fold(f64::INFINITY, f64::min);
    let vx = 0.8 * 2.0 * radius / (support * period);
    let options = GaitOptions { period, pattern, cycle, aep: AepMode::Periodic, lift, dt: PERIOD };
    let mut heading = Constant(Heading::new(vx, 0.0, 0.0));
    let footholds = steady_footholds(&legs, &workspaces, height, &options, &heading.heading(0.0));
    let joints = joints_at(&legs, &footholds).expect("the steady footholds are reachable");
    let q = m.touching_ground(&joints);
    let qd = vec![0.0; q.len()];
    let plant_options = PlantOptions { integrator: NewmarkOptions { tolerance: 1.0, h_max: PERIOD, h_initial: 1e-4, gamma: 0.6, beta: 0.3025, ..Default::default() }, period: PERIOD, encoder_counts: 4096, navigation: false, current_sensing: Default::default() };
    let mut plant = SimulatedRobot::new(m.clone(), &q, &qd, &plant_options).unwrap();
    let pis = std::array::from_fn(|_| DigitalPi::new(PI_GAINS.k, PI_GAINS.t_i, PERIOD));
    let mut controller = GaitController::new(options, legs, workspaces, pis, Box::new(heading));
    let x0 = q[0];
    let mut min_feet = 6;
    run(&mut plant, &mut controller, 20.0, |p, meas, _| {
        if meas.t > 0.5 {
            min_feet = min_feet.min(p.robot.outputs.contact.iter().filter(|c| c.normal_force > 0.0).count());
        }
    })
    .unwrap();
    let advance = plant.state().q[0] - x0;
    let e = &plant.energy;
    let electrical: f64 = e.electrical.iter().sum();
    let error = e.balance_error(&plant.initial_energy);
    println!("v_x {vx:.4} m/s, workspace radius {radius:.4} m, advance {advance:.4} m of {:.4} m, min feet {min_feet}, {:?}, electrical {electrical:.3} J, imbalance {error:.2e} J", vx * 20.0, controller.diagnostics);
    assert_eq!(controller.diagnostics.clamped_references, 0, "{:?}", controller.diagnostics);
    assert!(min_feet >= 3, "{min_feet} feet on the ground");
    // It walks forward at most the commanded distance: 90 % of it on this run (the support legs
    // track their references with the lag of the PI loops under load, and the feet slip).
    assert!(advance > 0.8 * vx * 20.0 && advance < 1.02 * vx * 20.0, "advance {advance} m for {} m", vx * 20.0);
    assert!(error.abs() < 0.01 * electrical, "imbalance {error} J of {electrical} J");
}
