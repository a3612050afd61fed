//! Gait benchmark: one controller update (desired body motion, gait phases, inverse kinematics
//! of the 6 legs, 18 PI) in median ns, quoted against the 10 ms control period; the ground
//! detector's update (Section 5.6: torque estimation of Fig. 5.12 and Eq. 5.22 for the 6 legs)
//! on the same measurements, quoted against the controller update and the thesis' 0.1 ms per
//! leg; the free gait controller's update (Section 7.7), alone and at the touchdowns where it
//! solves the posture (Nelder-Mead on Eq. 7.32), against the periodic controller's in the same
//! run; and the thesis'
//! simulation-time case (Section 3.4.1: tripod, T = 15 s, V_x = 2 cm/s, 75 s, LuGre) end to
//! end, quoted as wall time and real-time factor against the thesis' 260 s (Table 3.2).

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use hexadyn::control::gait::controller::{joints_at_workspace_centres, AepMode, GaitController, GaitOptions};
use hexadyn::control::gait::free::{FreeGaitController, FreeGaitOptions, NormalForce, THESIS_CURRENT_THRESHOLD, THESIS_FORCE_THRESHOLD};
use hexadyn::control::gait::heading::{Constant, Heading};
use hexadyn::control::gait::pattern::{FootCycle, GaitPattern};
use hexadyn::control::{joint_pis, Controller, GroundDetector, Measurements};
use hexadyn::hexapod::{LegKinematics, JOINTS};
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, ModelOptions, RobotModel};
use hexadyn::robot::simulation::{run, PlantOptions, SimulatedRobot};
use hexadyn::description::{Robot, RobotDescription};
use nalgebra::Vector3;

const THESIS_WALL_S: f64 = 260.0;
/// Section 5.6.2: "The scheme of Fig. 5.12 takes roughly 0.1 ms of computation time per leg."
const THESIS_ESTIMATION_PER_LEG_NS: f64 = 1e5;

fn controller(d: &RobotDescription, period: f64, vx: f64) -> (GaitController, [f64; JOINTS]) {
    let legs = LegKinematics::hexapod_from_description(d).unwrap();
    let height = -legs[0].foot(&Vector3::new(0.0, 0.06, 0.035)).z;
    let lift = 0.045;
    let workspaces = std::array::from_fn(|l| legs[l].workspace_for_body_height(height, lift).unwrap());
    let joints = joints_at_workspace_centres(&legs, &workspaces, height).unwrap();
    let pis = joint_pis(&d.joint_pi_gains(), d.controller.period_s);
    let options = GaitOptions { period, pattern: GaitPattern::tripod(), cycle: FootCycle::Enhanced { overlap: 0.05 }, aep: AepMode::Omnidirectional, lift, dt: d.controller.period_s };
    (GaitController::new(options, legs, workspaces, pis, Box::new(Constant(Heading::new(vx, 0.0, 0.0)))), joints)
}

fn main() {
    let d = RobotDescription::amru5();
    // One controller update, open loop on measurements that follow the references.
    let (mut c, joints) = controller(&d, 12.0, 0.015);
    let mut m = Measurements { t: 0.0, positions: joints, currents: [0.0; JOINTS], supply_voltage: 12.0, pose: None, foot_normal_forces: None };
    let mut detector = GroundDetector::new(&Robot::Pantograph(d.clone()), LegKinematics::hexapod_from_description(&d).unwrap(), d.controller.period_s, 40.0);
    let (mut samples, mut detector_samples) = (Vec::new(), Vec::new());
    for i in 0..30_000 {
        m.t = i as f64 * 0.01;
        // Currents of the order of a walk's, varying from period to period.
        m.currents = std::array::from_fn(|k| 0.2 * ((k + i) as f64 * 0.37).sin());
        let start = Instant::now();
        let command = black_box(c.update(black_box(&m)));
        samples.push(start.elapsed().as_nanos() as f64);
        let start = Instant::now();
        black_box(detector.update(black_box(&m)));
        detector_samples.push(start.elapsed().as_nanos() as f64);
        m.positions = command.references;
    }
    let median = |s: &mut Vec<f64>| {
        s.sort_by(f64::total_cmp);
        (s[s.len() / 2], s[s.len() * 99 / 100])
    };
    let (controller_ns, controller_p99) = median(&mut samples);
    let (detector_ns, detector_p99) = median(&mut detector_samples);
    println!("hexadyn gait benchmark");
    println!("  controller update (body motion, gait, IK x 6, 18 PI)  median {controller_ns:>8.0} ns, p99 {controller_p99:>8.0} ns = {:.4} % of the 10 ms period", controller_ns / 1e7 * 100.0);
    println!(
        "  ground detector update (Fig. 5.12 + Eq. 5.22, 6 legs)  median {detector_ns:>8.0} ns, p99 {detector_p99:>8.0} ns = {:.2} x the controller update; {:.0} ns per leg, thesis 0.1 ms per leg: {:.0}x faster",
        detector_ns / controller_ns,
        detector_ns / 6.0,
        THESIS_ESTIMATION_PER_LEG_NS * 6.0 / detector_ns
    );

    // The free gait on the ideal plant (joints = references, body = desired pose, flat ground:
    // a foot at z <= 0 carries 100 N), 1 cm/s from the workspace centres.
    let legs = LegKinematics::hexapod_from_description(&d).unwrap();
    let height = -legs[0].foot(&Vector3::new(0.0, 0.06, 0.035)).z;
    let workspaces: [_; 6] = std::array::from_fn(|l| legs[l].workspace_for_body_height(height, 0.045).unwrap());
    let options = FreeGaitOptions { body_height: height, lift: 0.045, takeoff_time: 1.0, swing_time: 3.0, posture_time: 2.0, failed_leg: None, stability_margin: 0.02, energy_margin: 0.0, dt: 0.01, elevator: Some(THESIS_CURRENT_THRESHOLD) };
    let mut free = FreeGaitController::new(options, legs.clone(), workspaces, joint_pis(&d.joint_pi_gains(), 0.01), Box::new(Constant(Heading::new(0.01, 0.0, 0.0))), Box::new(NormalForce { threshold: THESIS_FORCE_THRESHOLD }));
    let mut m = Measurements { t: 0.0, positions: joints_at_workspace_centres(&legs, &workspaces, height).unwrap(), currents: [0.0; JOINTS], supply_voltage: 12.0, pose: None, foot_normal_forces: Some([100.0; 6]) };
    let (mut plain, mut posture) = (Vec::new(), Vec::new());
    for i in 0..30_000 {
        m.t = i as f64 * 0.01;
        let start = Instant::now();
        let command = black_box(free.update(black_box(&m)));
        let elapsed = start.elapsed().as_nanos() as f64;
        if free.state().touchdowns.iter().any(|&t| t) {
            posture.push(elapsed);
        } else {
            plain.push(elapsed);
        }
        m.positions = command.references;
        let body = free.desired_pose().unwrap().htm();
        m.foot_normal_forces = Some(std::array::from_fn(|l| {
            let q = Vector3::new(m.positions[3 * l], m.positions[3 * l + 1], m.positions[3 * l + 2]);
            if body.compose(&legs[l].body_from_leg()).apply(&legs[l].foot(&q)).z <= 1e-9 { 100.0 } else { 0.0 }
        }));
    }
    for v in [&mut plain, &mut posture] {
        v.sort_by(f64::total_cmp);
    }
    let (free_median, posture_median) = (plain[plain.len() / 2], posture[posture.len() / 2]);
    println!("  free gait update (Section 7.7)                        median {free_median:>8.0} ns = {:.2} x the periodic update", free_median / controller_ns);
    println!(
        "  free gait update with the posture solve (Eq. 7.32)   median {posture_median:>8.0} ns = {:.2} x the periodic update, p99 {:>8.0} ns ({} touchdown updates; target: median < 100 us)",
        posture_median / controller_ns,
        posture[posture.len() * 99 / 100],
        posture.len()
    );

    // The simulation-time case of Section 3.4.1.
    let (mut c, joints) = controller(&d, 15.0, 0.02);
    let model = Arc::new(RobotModel::new(&d, ModelOptions::from_description(&d, FrictionModel::LuGre), Arc::new(FlatGround { height: 0.0 })));
    let q = model.touching_ground(&joints);
    let qd = vec![0.0; q.len()];
    let start = Instant::now();
    let options = PlantOptions::new(d.controller.period_s, &model.options);
    let mut plant = SimulatedRobot::new(model, &q, &qd, &options).unwrap();
    run(&mut plant, &mut c, 75.0, |_, _, _| {}).unwrap();
    let wall = start.elapsed().as_secs_f64();
    let s = plant.integrator.stats();
    println!(
        "  75 s tripod walk, T = 15 s, V_x = 2 cm/s, LuGre (Section 3.4.1)   wall {wall:.2} s, real-time factor {:.1}; thesis {THESIS_WALL_S} s: {:.0}x faster ({} steps, {} Jacobians, {} LU)",
        75.0 / wall,
        THESIS_WALL_S / wall,
        s.steps,
        s.jacobian_evaluations,
        s.factorizations
    );
}
