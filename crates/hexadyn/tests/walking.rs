//! Walking in the full dynamic model (thesis Chapter 7 and the validation case of Table 6.2).

use std::sync::Arc;

use hexadyn::control::gait::controller::{AepMode, GaitController, GaitOptions};
use hexadyn::control::gait::heading::{Constant, Heading, HeadingSource};
use hexadyn::control::gait::pattern::{FootCycle, GaitPattern};
use hexadyn::control::{DigitalPi, LegKinematics, JOINTS};
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, ModelOptions, RobotModel};
use hexadyn::robot::simulation::{run, PlantOptions, SimulatedRobot};
use hexadyn::robot::{Joint, RobotDescription};
use nalgebra::Vector3;

struct Walk {
    plant: SimulatedRobot,
    controller: GaitController,
}

fn walk(friction: FrictionModel, heading: Box<dyn HeadingSource>, navigation: bool, cycle: FootCycle) -> Walk {
    let d = RobotDescription::amru5();
    let legs = LegKinematics::hexapod_from_description(&d).unwrap();
    let height = -legs[0].foot(&Vector3::new(0.0, 0.06, 0.035)).z;
    let lift = 0.015;
    let workspaces = std::array::from_fn(|l| legs[l].workspace_for_body_height(height, 3.0 * lift).unwrap());
    let mut joints = [0.0; JOINTS];
    for l in 0..6 {
        let c = workspaces[l].centre_at(-height);
        let ik = legs[l].inverse(&c, &Vector3::new(0.0, 0.06, 0.03)).unwrap();
        assert!(ik.is_reached());
        joints[3 * l..3 * l + 3].copy_from_slice(ik.joints.as_slice());
    }
    let model = Arc::new(RobotModel::new(&d, ModelOptions::from_description(&d, friction), Arc::new(FlatGround { height: 0.0 })));
    let q = model.touching_ground(&joints);
    let qd = vec![0.0; q.len()];
    let mut plant_options = PlantOptions::from_description(&d);
    plant_options.navigation = navigation;
    let plant = SimulatedRobot::new(model, &q, &qd, &plant_options).unwrap();
    let pis = std::array::from_fn(|k| {
        let g = d.pi_gains(Joint::ALL[k % 3]);
        DigitalPi::new(g.k, g.t_i, d.controller.period_s)
    });
    let options = GaitOptions { period: 12.0, pattern: GaitPattern::tripod(), cycle, aep: AepMode::Periodic, lift, dt: d.controller.period_s };
    Walk { plant, controller: GaitController::new(options, legs, workspaces, pis, heading) }
}

/// Table 6.2: tripod, T = 12 s, V_x = 1.5 cm/s, 5 steps, 5 % overlap, enhanced cycle.
#[test]
fn validation_tripod_walks_five_steps() {
    let mut w = walk(FrictionModel::None, Box::new(Constant(Heading::new(0.015, 0.0, 0.0))), false, FootCycle::Enhanced { overlap: 0.05 });
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
    println!("advance {x:.4} m, worst errors q_r {:.3} deg, q_v {:.3} mm, q_h {:.3} mm, min feet {min_feet}, {:?}", worst[0].to_degrees(), worst[1] * 1e3, worst[2] * 1e3, w.controller.diagnostics);
    assert!((x - 0.015 * 60.0).abs() < 0.05, "advance {x}");
    assert!(min_feet >= 3);
}
