//! Robot benchmark: wall time for 10 s of the AMRU5 model per friction model, standing on six
//! legs under PI control and with one leg in the air following a sawtooth (Table 5.2), quoted
//! as real-time factor (simulated / wall time). The baseline measured in the same run is the
//! thesis' own figure: 75 s of walking in 260 s (Table 3.2), i.e. a real-time factor of 0.29.

use std::sync::Arc;
use std::time::Instant;

use hexadyn::control::{joint_pis, JointMotion, JointPiController, JointReferences};
use hexadyn::hexapod::JOINTS;
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, ModelOptions, RobotModel};
use hexadyn::robot::simulation::{run, PlantOptions, SimulatedRobot};
use hexadyn::description::RobotDescription;

const THESIS_REAL_TIME_FACTOR: f64 = 75.0 / 260.0;

fn main() {
    let d = RobotDescription::amru5();
    let duration = 10.0;
    println!("hexadyn robot benchmark: {duration} s simulated, digital PI at 100 Hz, 42-DOF model (60 with LuGre bristles + currents off)");
    println!("{:<12} {:<22} {:>9} {:>9} {:>10} {:>7} {:>7} {:>7}", "friction", "case", "wall s", "RTF", "vs thesis", "steps", "jacob.", "LU");
    for friction in [FrictionModel::None, FrictionModel::DryViscous, FrictionModel::LuGre] {
        for case in ["standing, 6 legs", "leg 1 sawtooth in air"] {
            let model = Arc::new(RobotModel::new(&d, ModelOptions::from_description(&d, friction), Arc::new(FlatGround { height: 0.0 })));
            let lifted = case.starts_with("leg");
            let base: [f64; JOINTS] = std::array::from_fn(|k| match k % 3 {
                0 => 0.0,
                1 => if lifted && k / 3 == 1 { 0.045 } else { 0.06 },
                _ => 0.03,
            });
            let q = model.touching_ground(&base);
            let qd = vec![0.0; q.len()];
            let pis = joint_pis(&d.joint_pi_gains(), d.controller.period_s);
            let motions = if lifted {
                vec![(3, JointMotion::Sawtooth { min: -0.35, max: 0.35, speed: 0.15 }), (4, JointMotion::Sawtooth { min: 0.04, max: 0.05, speed: 0.004 }), (5, JointMotion::Sawtooth { min: 0.01, max: 0.05, speed: 0.004 })]
            } else {
                Vec::new()
            };
            let mut controller = JointPiController { pis, references: JointReferences { base, motions } };
            let start = Instant::now();
            let options = PlantOptions::new(d.controller.period_s, &model.options);
            let mut plant = SimulatedRobot::new(model, &q, &qd, &options).expect("initial state");
            run(&mut plant, &mut controller, duration, |_, _, _| {}).expect("simulation");
            let wall = start.elapsed().as_secs_f64();
            let s = plant.integrator.stats();
            let rtf = duration / wall;
            println!(
                "{:<12} {:<22} {:>9.3} {:>9.1} {:>9.0}x {:>7} {:>7} {:>7}",
                format!("{friction:?}"),
                case,
                wall,
                rtf,
                rtf / THESIS_REAL_TIME_FACTOR,
                s.steps,
                s.jacobian_evaluations,
                s.factorizations
            );
        }
    }
}
