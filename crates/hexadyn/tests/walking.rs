//! Walking in the full dynamic model (thesis Chapter 7 and the validation case of Table 6.2).

use std::sync::Arc;

use hexadyn::control::gait::controller::{joints_at_workspace_centres, AepMode, GaitController, GaitOptions};
use hexadyn::control::gait::heading::{Constant, Heading, HeadingSource, Segments, Spline};
use hexadyn::control::gait::pattern::FootPhase;
use hexadyn::control::gait::pattern::{FootCycle, GaitPattern};
use hexadyn::control::{joint_pis, Controller, Measurements, Plant};
use hexadyn::hexapod::{LegKinematics, JOINTS};
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, ModelOptions, RobotModel};
use hexadyn::robot::simulation::{run, PlantOptions, SimulatedRobot};
use hexadyn::description::RobotDescription;
use nalgebra::Vector3;

struct Walk {
    plant: SimulatedRobot,
    controller: GaitController,
}

fn walk(friction: FrictionModel, heading: Box<dyn HeadingSource>, navigation: bool, cycle: FootCycle) -> Walk {
    walk_with(friction, heading, navigation, cycle, AepMode::Periodic, |_| {})
}

fn walk_with(friction: FrictionModel, heading: Box<dyn HeadingSource>, navigation: bool, cycle: FootCycle, aep: AepMode, tweak: impl FnOnce(&mut ModelOptions)) -> Walk {
    walk_lifting(0.045, friction, heading, navigation, cycle, aep, tweak)
}

fn walk_lifting(lift: f64, friction: FrictionModel, heading: Box<dyn HeadingSource>, navigation: bool, cycle: FootCycle, aep: AepMode, tweak: impl FnOnce(&mut ModelOptions)) -> Walk {
    let d = RobotDescription::amru5();
    let legs = LegKinematics::hexapod_from_description(&d).unwrap();
    let height = -legs[0].foot(&Vector3::new(0.0, 0.06, 0.035)).z;
    let workspaces = std::array::from_fn(|l| legs[l].workspace_for_body_height(height, lift).unwrap());
    let joints = joints_at_workspace_centres(&legs, &workspaces, height).unwrap();
    let mut model_options = ModelOptions::from_description(&d, friction);
    tweak(&mut model_options);
    let model = Arc::new(RobotModel::new(&d, model_options, Arc::new(FlatGround { height: 0.0 })));
    let q = model.touching_ground(&joints);
    let qd = vec![0.0; q.len()];
    let mut plant_options = PlantOptions::new(d.controller.period_s, &model.options);
    plant_options.navigation = navigation;
    let plant = SimulatedRobot::new(model, &q, &qd, &plant_options).unwrap();
    let pis = joint_pis(&d.joint_pi_gains(), d.controller.period_s);
    let options = GaitOptions { period: 12.0, pattern: GaitPattern::tripod(), cycle, aep, lift, dt: d.controller.period_s };
    Walk { plant, controller: GaitController::new(options, legs, workspaces, pis, heading) }
}

/// Table 6.2: tripod, T = 12 s, 5 steps, 5 % overlap, enhanced cycle, LuGre friction, at the
/// four velocities: the robot walks its 5 steps on at least three feet, every foot reference
/// is reachable after the first step, and at 1.5 cm/s (the case of Section 6.4) the largest
/// joint tracking errors are of the thesis' magnitude (about 0.5° in rotation, 0.8 mm
/// vertical, 0.5 mm horizontal; asserted within a factor 1.5).
#[test]
fn validation_tripod_walks_five_steps() {
    for vx in [0.01, 0.015, 0.02, 0.025] {
        validation_walk(vx);
    }
}

fn validation_walk(vx: f64) {
    let mut w = walk(FrictionModel::LuGre, Box::new(Constant(Heading::new(vx, 0.0, 0.0))), false, FootCycle::Enhanced { overlap: 0.05 });
    let mut worst = [0.0f64; 3];
    let mut min_feet = 6;
    let x0 = w.plant.state().q[0];
    run(&mut w.plant, &mut w.controller, 60.0, |p, m, c| {
        for k in 0..JOINTS {
            worst[k % 3] = worst[k % 3].max((c.references[k] - p.state().q[6 + k]).abs());
        }
        if m.t > 1.0 {
            min_feet = min_feet.min(p.robot.outputs.contact.iter().filter(|c| c.normal_force > 0.0).count());
        }
    })
    .unwrap();
    let x = w.plant.state().q[0] - x0;
    println!("{:?}", w.plant.integrator.stats());
    println!("V_x {vx}: advance {x:.4} m, worst errors q_r {:.3} deg, q_v {:.3} mm, q_h {:.3} mm, min feet {min_feet}, {:?}", worst[0].to_degrees(), worst[1] * 1e3, worst[2] * 1e3, w.controller.diagnostics);
    assert!((x - vx * 60.0).abs() < 0.05, "advance {x}");
    assert!(min_feet >= 3);
    assert!(w.controller.diagnostics.last_clamped_at.is_none_or(|t| t < 12.0), "{:?}", w.controller.diagnostics);
    if vx == 0.015 {
        assert!(worst[0] < 1.5 * 0.5f64.to_radians(), "q_r error {} deg", worst[0].to_degrees());
        assert!(worst[1] < 1.5 * 0.8e-3, "q_v error {} mm", worst[1] * 1e3);
        assert!(worst[2] < 1.5 * 0.5e-3, "q_h error {} mm", worst[2] * 1e3);
    }
}

/// The control loop of `simulation::run`, with the controller visible to the recorder.
fn drive(w: &mut Walk, duration: f64, mut record: impl FnMut(&SimulatedRobot, &GaitController, &Measurements)) {
    let periods = (duration / w.plant.period()).round() as usize;
    for _ in 0..periods {
        let m = w.plant.measure();
        let command = w.controller.update(&m);
        record(&w.plant, &w.controller, &m);
        w.plant.actuate(&command);
        w.plant.wait_period().unwrap();
    }
}

fn path(name: &str) -> Box<dyn HeadingSource> {
    match name {
        "back and forth" => Box::new(Segments::back_and_forth()),
        "straight lines" => Box::new(Segments::square(0.3, 0.015)),
        _ => Box::new(Spline::section_7_5_3()),
    }
}

/// Section 7.5.3 with a navigation system: on the back-and-forth path, the straight lines with
/// sharp 90° turns and the spline (V_x, V_y, Ω_z all non-zero, yaw tangent), the body's XY
/// tracking error stays at or below 3 mm, and every foot reference stays in its workspace.
#[test]
fn omnidirectional_paths_with_navigation() {
    for (name, duration) in [("back and forth", 200.0), ("straight lines", 80.0), ("spline", 200.0)] {
        let mut w = walk_with(FrictionModel::None, path(name), true, FootCycle::Enhanced { overlap: 0.05 }, AepMode::Omnidirectional, |_| {});
        let workspaces = *w.controller.workspaces();
        let (mut worst_xy, mut worst_outside, mut worst_yaw, mut worst_t) = (0.0f64, 0.0f64, 0.0f64, 0.0);
        drive(&mut w, duration, |p, c, m| {
            let q = &p.state().q;
            if let Some(desired) = c.desired_pose() {
                let e = (desired.position.xy() - Vector3::new(q[0], q[1], 0.0).xy()).norm();
                if m.t > 1.0 && e > worst_xy {
                    worst_xy = e;
                    worst_t = m.t;
                    worst_yaw = worst_yaw.max((desired.angles.x - q[3]).abs());
                }
            }
            for (l, foot) in c.foot_references().iter().enumerate() {
                worst_outside = worst_outside.max(workspaces[l].distance_outside(foot));
            }
        });
        println!("{name}: worst XY error {:.2} mm at {worst_t:.2} s, yaw {:.3} deg, foot outside workspace by {:.2} mm, {:?}", worst_xy * 1e3, worst_yaw.to_degrees(), worst_outside * 1e3, w.controller.diagnostics);
        assert!(worst_xy <= 3e-3, "{name}: XY error {worst_xy}");
        assert!(worst_outside <= 1e-3, "{name}: a foot leaves its workspace by {worst_outside}");
    }
}

/// Section 7.5.2: after the velocity reversal of the back-and-forth path, the strokes re-centre
/// on the workspace centre within 2 steps.
#[test]
fn strokes_recentre_within_two_steps_after_a_velocity_change() {
    let mut w = walk_with(FrictionModel::None, path("back and forth"), true, FootCycle::Enhanced { overlap: 0.05 }, AepMode::Omnidirectional, |_| {});
    let workspaces = *w.controller.workspaces();
    // Per leg and support phase: (start time, first and last foot reference of the support).
    let mut supports: Vec<Vec<(f64, Vector3<f64>, Vector3<f64>)>> = vec![Vec::new(); 6];
    let mut previous = [FootPhase::Support; 6];
    drive(&mut w, 140.0 + 4.0 * 12.0, |_, c, m| {
        for (l, (phase, foot)) in c.phases().iter().zip(c.foot_references()).enumerate() {
            if *phase == FootPhase::Support {
                if previous[l] != FootPhase::Support || supports[l].is_empty() {
                    supports[l].push((m.t, foot, foot));
                } else {
                    supports[l].last_mut().unwrap().2 = foot;
                }
            }
            previous[l] = *phase;
        }
    });
    for l in 0..6 {
        let centre = workspaces[l].centre;
        // Complete supports (the last one may be cut by the end of the run) starting two steps
        // after the reversal.
        let complete = &supports[l][..supports[l].len() - usize::from(previous[l] == FootPhase::Support)];
        for (start, first, last) in complete.iter().filter(|(t, _, _)| *t > 140.0 + 2.0 * 12.0) {
            let middle = ((first + last) / 2.0).xy();
            let offset = (middle - centre).norm();
            assert!(offset < 0.01, "leg {l}: stroke starting at {start:.1} s centred {:.1} mm off C", offset * 1e3);
        }
    }
}

/// Fig. 7.24: on soft ground (K_gnd = 1e4), walking straight at 2 cm/s without navigation, the
/// enhanced foot cycle tracks X at least 3 times better than the plain cycle at the end.
#[test]
fn enhanced_cycle_tracks_better_on_soft_ground() {
    let mut errors = Vec::new();
    for cycle in [FootCycle::Enhanced { overlap: 0.05 }, FootCycle::Plain] {
        // The feet sink about 5 cm: a clearance of 10 cm takes the swinging feet out of the soil.
        let mut w = walk_lifting(0.1, FrictionModel::None, Box::new(Constant(Heading::new(0.02, 0.0, 0.0))), false, cycle, AepMode::Periodic, |o| o.ground.k_gnd = 1e4);
        let mut error = 0.0;
        drive(&mut w, 72.0, |p, c, _| {
            error = c.desired_pose().map_or(0.0, |d| d.position.x - p.state().q[0]);
        });
        println!("{cycle:?}: final X tracking error {:.2} mm, {:?}", error * 1e3, w.controller.diagnostics);
        errors.push(error.abs());
    }
    assert!(errors[0] * 3.0 <= errors[1], "enhanced {} vs plain {}", errors[0], errors[1]);
}

/// A gait change tripod → wave → tripod while walking keeps at least three feet on the ground
/// at every instant (simulated contact forces).
#[test]
fn gait_changes_keep_three_feet_down() {
    let mut w = walk(FrictionModel::None, Box::new(Constant(Heading::new(0.01, 0.0, 0.0))), true, FootCycle::Enhanced { overlap: 0.05 });
    let mut min_feet = 6;
    let mut switched = Vec::new();
    let periods = (80.0 / w.plant.period()).round() as usize;
    for i in 0..periods {
        let t = i as f64 * w.plant.period();
        if i == 2000 {
            w.controller.change_gait(GaitPattern::wave(0.75));
        }
        if i == 5000 {
            w.controller.change_gait(GaitPattern::tripod());
        }
        let m = w.plant.measure();
        let command = w.controller.update(&m);
        w.plant.actuate(&command);
        w.plant.wait_period().unwrap();
        if t > 1.0 {
            min_feet = min_feet.min(w.plant.robot.outputs.contact.iter().filter(|c| c.normal_force > 0.0).count());
        }
        switched.push(w.controller.options.pattern.name.clone());
    }
    println!("gait switches {:?}, minimum feet on the ground {min_feet}", w.controller.diagnostics);
    assert_eq!(w.controller.diagnostics.gait_switches, 2);
    assert!(switched.iter().any(|n| n == "wave"));
    assert_eq!(switched.last().unwrap(), "tripod");
    assert!(min_feet >= 3);
}

