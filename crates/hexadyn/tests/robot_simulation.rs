//! The closed-loop robot: digital PI control at 100 Hz (Section 4.4.5), energy accounting
//! (Section 6.4.5) and the ramp-tracking design case of Section 4.4.4.

use std::sync::Arc;

use hexadyn::control::{joint_pis, DigitalPi, JointMotion, JointPiController, JointReferences, ReferenceFeed};
use hexadyn::hexapod::JOINTS;
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, JointControl, ModelOptions, RobotModel};
use hexadyn::robot::simulation::{run, PlantOptions, SimulatedRobot};
use hexadyn::description::RobotDescription;
use hexadyn::hexapod::PantographJoint;

fn model(friction: FrictionModel, tweak: impl FnOnce(&mut ModelOptions)) -> Arc<RobotModel> {
    let d = RobotDescription::amru5();
    let mut options = ModelOptions::from_description(&d, friction);
    tweak(&mut options);
    Arc::new(RobotModel::new(&d, options, Arc::new(FlatGround { height: 0.0 })))
}

fn pis(d: &RobotDescription) -> [DigitalPi; JOINTS] {
    joint_pis(&d.joint_pi_gains(), d.controller.period_s)
}

/// Legs 0, 3, 4 support the body; legs 1, 2, 5 are lifted.
fn tripod_stance() -> [f64; JOINTS] {
    std::array::from_fn(|k| match k % 3 {
        0 => 0.0,
        1 => if [0, 3, 4].contains(&(k / 3)) { 0.06 } else { 0.045 },
        _ => 0.03,
    })
}

/// Electrical energy in = Δ(kinetic + potential) + Joule + friction + contact work (+ Δ magnetic
/// energy) within 1 %, for every friction model, on a tripod stance with the three lifted legs
/// swinging their three joints.
#[test]
fn energy_balance_closes_for_every_friction_model() {
    let d = RobotDescription::amru5();
    for (friction, inductance) in [(FrictionModel::None, false), (FrictionModel::DryViscous, false), (FrictionModel::LuGre, false), (FrictionModel::LuGre, true)] {
        let m = model(friction, |o| o.inductance = inductance);
        let base = tripod_stance();
        let q = m.touching_ground(&base);
        let qd = vec![0.0; q.len()];
        let mut plant = SimulatedRobot::new(m.clone(), &q, &qd, &PlantOptions::new(d.controller.period_s, &m.options)).unwrap();
        let mut motions = Vec::new();
        for leg in [1, 2, 5] {
            motions.push((3 * leg, JointMotion::Sine { amplitude: 0.1, frequency_hz: 0.5 }));
            motions.push((3 * leg + 1, JointMotion::Sine { amplitude: 0.01, frequency_hz: 0.5 }));
            motions.push((3 * leg + 2, JointMotion::Sine { amplitude: 0.01, frequency_hz: 0.25 }));
        }
        let mut controller = JointPiController { pis: pis(&d), references: JointReferences { base, motions } };
        run(&mut plant, &mut controller, 2.0, |_, _, _| {}).unwrap();
        let e = &plant.energy;
        let electrical: f64 = e.electrical.iter().sum();
        let error = e.balance_error(&plant.initial_energy);
        println!(
            "{friction:?} inductance {inductance}: electrical {electrical:.3} J, imbalance {error:.2e} J, joule {:.3}, friction {:.3}, contact {:.4}, motor work {:.3}, dT {:.4}, dV {:.4}",
            e.joule.iter().sum::<f64>(),
            e.friction_work.iter().sum::<f64>(),
            e.contact_work.iter().sum::<f64>(),
            e.motor_work.iter().sum::<f64>(),
            e.kinetic - plant.initial_energy.kinetic,
            e.potential - plant.initial_energy.potential
        );
        assert!(electrical > 1.0, "the run draws energy");
        assert!(error.abs() < 0.01 * electrical, "{friction:?}: imbalance {error} J of {electrical} J");
    }
}

/// Section 4.4.4: a joint following a ramp at 0.8 × the no-load speed does not saturate, and
/// its tracking error is about 0.1 mm after 0.5 s. Design conditions of Chapter 4: leg in the
/// air, no friction, armature resistance only, saturation at the nominal u_sat = 15 V of
/// Table 3.4.
#[test]
fn ramp_at_80_percent_of_no_load_speed() {
    let d = RobotDescription::amru5();
    let mut m = model(FrictionModel::None, |o| o.supply_voltage = d.motor.nominal_voltage_v);
    // The design model of Chapter 4 has the armature resistance only (Eq. 4.3-4.14).
    for motor in Arc::get_mut(&mut m).expect("unshared").motors.iter_mut() {
        motor.r_bridge = 0.0;
    }
    let leg = 1;
    let k = 3 * leg + PantographJoint::Vertical as usize; // q_v of leg 1 among the 18 joints
    let mut base = tripod_stance();
    base[k] = 0.045;
    let mut q = m.touching_ground(&base);
    q[2] += 0.5; // the whole robot in the air, body held by nothing but its own dynamics for 0.6 s
    let qd = vec![0.0; q.len()];
    let mut plant = SimulatedRobot::new(m.clone(), &q, &qd, &PlantOptions::new(d.controller.period_s, &m.options)).unwrap();
    let rate = 0.8 * d.motor.no_load_speed_rad_per_s() / d.reduction(PantographJoint::Vertical);
    let motions = vec![(k, JointMotion::Ramp { rate, start_s: 0.0, stop_s: 10.0 })];
    let mut controller = JointPiController { pis: pis(&d), references: JointReferences { base, motions } };
    let mut worst_u: f64 = 0.0;
    let mut error_at_half_second = f64::NAN;
    run(&mut plant, &mut controller, 0.6, |p, meas, cmd| {
        worst_u = worst_u.max(cmd.voltages[k].abs());
        if (meas.t - 0.5).abs() < 1e-9 {
            error_at_half_second = cmd.references[k] - p.state().q[6 + k];
        }
    })
    .unwrap();
    println!("ramp {rate:.5} m/s: error at 0.5 s {:.4} mm, max |u| {worst_u:.2} V", error_at_half_second * 1e3);
    assert!(worst_u < d.motor.nominal_voltage_v, "saturates: {worst_u} V");
    assert!(error_at_half_second.abs() > 0.03e-3 && error_at_half_second.abs() < 0.3e-3, "error {error_at_half_second}");
}

/// The 96-DOF model (Table 3.5): continuous PI controllers inside the model (Eq. 3.96-3.97,
/// T_D = 0) with the gains of Table 4.1 track the same tripod-stance motion as the digital ones,
/// and its energy account closes too.
#[test]
fn continuous_pid_model_tracks_like_the_digital_controllers() {
    let d = RobotDescription::amru5();
    let base = tripod_stance();
    let motions = vec![(3 + 1, JointMotion::Sine { amplitude: 0.004, frequency_hz: 0.5 })];
    let mut errors = Vec::new();
    for control in [JointControl::Digital, JointControl::ContinuousPid { t_d: 0.0, n: 10.0, omega_0: 1000.0 }] {
        let m = model(FrictionModel::LuGre, |o| {
            o.control = control;
            o.inductance = control != JointControl::Digital;
        });
        let q = m.touching_ground(&base);
        let qd = vec![0.0; q.len()];
        let mut plant = SimulatedRobot::new(m.clone(), &q, &qd, &PlantOptions::new(d.controller.period_s, &m.options)).unwrap();
        let references = JointReferences { base, motions: motions.clone() };
        let mut worst: f64 = 0.0;
        let mut track = |p: &SimulatedRobot, meas: &hexadyn::control::Measurements, cmd: &hexadyn::control::Command| {
            if meas.t > 0.5 {
                worst = worst.max((cmd.references[4] - p.state().q[6 + 4]).abs());
            }
        };
        match control {
            JointControl::Digital => run(&mut plant, &mut JointPiController { pis: pis(&d), references }, 2.0, &mut track).unwrap(),
            _ => run(&mut plant, &mut ReferenceFeed(references), 2.0, &mut track).unwrap(),
        }
        let electrical: f64 = plant.energy.electrical.iter().sum();
        let imbalance = plant.energy.balance_error(&plant.initial_energy);
        println!("{control:?}: worst q_v[1] error after 0.5 s {:.4} mm, imbalance {imbalance:.2e} of {electrical:.2} J", worst * 1e3);
        assert!(imbalance.abs() < 0.01 * electrical);
        errors.push(worst);
    }
    assert!(errors[1] < 2.0 * errors[0] && errors[0] < 2.0 * errors[1], "{errors:?}");
}
