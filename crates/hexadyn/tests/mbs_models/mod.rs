//! Multibody models shared by the integration tests.

use hexadyn::description::RobotDescription;
use hexadyn::hexapod::{joint_index, Mechanics, MechanicsParameters, DOF};
use hexadyn::mbs::{BodySpec, Elementary, Model, ModelBuilder, Var};
use nalgebra::{Matrix3, Vector3};

/// A floating body (Eq. 3.52) carrying a 3-joint leg with a translation and an offset axis:
/// every kind of elementary transform.
pub fn tree() -> Model {
    let mut b = ModelBuilder::new(9);
    let base = b
        .add_body(BodySpec {
            name: "base".into(),
            parent: None,
            joint: Elementary::free_body(0),
            mass: 10.0,
            inertia: Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.25)),
        })
        .unwrap();
    let hip = b
        .add_body(BodySpec { name: "hip".into(), parent: Some(base), joint: vec![Elementary::offset(0.2, 0.1, 0.0), Elementary::rz(Var::q(6).scaled(-1.0)), Elementary::offset(0.05, 0.0, -0.02)], mass: 1.0, inertia: Matrix3::from_diagonal(&Vector3::new(0.01, 0.02, 0.015)) })
        .unwrap();
    let slide = b
        .add_body(BodySpec { name: "slide".into(), parent: Some(hip), joint: vec![Elementary::tz(Var::q(7).plus(0.03)), Elementary::offset(0.0, 0.01, 0.0)], mass: 0.5, inertia: Matrix3::from_diagonal(&Vector3::new(0.002, 0.003, 0.001)) })
        .unwrap();
    b.add_body(BodySpec { name: "rotor".into(), parent: Some(hip), joint: vec![Elementary::offset(-0.03, 0.0, 0.0), Elementary::rx(Var::q(8).scaled(500.0))], mass: 0.2, inertia: Matrix3::from_diagonal(&Vector3::new(6.5e-6, 1.9e-4, 1.9e-4)) }).unwrap();
    b.add_body(BodySpec { name: "shank".into(), parent: Some(slide), joint: vec![Elementary::ry(Var::q(8)), Elementary::offset(0.1, 0.0, -0.15)], mass: 0.3, inertia: Matrix3::from_diagonal(&Vector3::new(0.004, 0.004, 0.0005)) }).unwrap();
    b.build()
}

/// The AMRU5's mechanics (49 bodies, the pantograph's dependent parameters shared by several
/// links, the rotors' spins) at a generic configuration: the body tilted and off the origin,
/// every leg's joints at other values.
pub fn amru5() -> (Mechanics, [f64; DOF]) {
    let mech = Mechanics::new(&MechanicsParameters::from_description(&RobotDescription::amru5())).unwrap();
    let mut q = [0.0; DOF];
    q[..6].copy_from_slice(&[0.1, -0.2, 0.45, 0.3, 0.05, -0.04]);
    for leg in 0..6 {
        q[joint_index(leg, 0)] = 0.1 * leg as f64 - 0.25;
        q[joint_index(leg, 1)] = 0.045 + 0.005 * leg as f64;
        q[joint_index(leg, 2)] = 0.01 + 0.008 * leg as f64;
    }
    (mech, q)
}
