//! Engine benchmark: a 24-DOF floating-base tree with six 3-DOF legs (the AMRU5 topology
//! without the pantograph closure). Prints ns per call of residual evaluation, mass matrix,
//! Jacobian assembly and one Newmark step, and the ratio against the baseline measured in the
//! same run: kinematics with partial velocities by numerical derivation (first rows of
//! Table 3.2), versus the direct partial velocities.

use std::hint::black_box;
use std::time::Instant;

use hexadyn::mbs::{kinematics, mass_matrix, partial_velocities_numerical, BodySpec, Data, Elementary, Model, ModelBuilder, MultibodySystem, Var};
use hexadyn::sim::{Jacobian, Newmark, NewmarkOptions, System};
use nalgebra::{DMatrix, Matrix3, Vector3};

fn hexapod_tree() -> Model {
    let mut b = ModelBuilder::new(24);
    let base = b
        .add_body(BodySpec {
            name: "body".into(),
            parent: None,
            joint: Elementary::free_body(0),
            mass: 11.2,
            inertia: Matrix3::from_diagonal(&Vector3::new(0.1063, 0.1198, 0.0843)),
        })
        .unwrap();
    for leg in 0..6 {
        let angle = (30.0 + 60.0 * leg as f64).to_radians();
        let j = 6 + 3 * leg;
        let hip = b
            .add_body(BodySpec {
                name: format!("hip{leg}"),
                parent: Some(base),
                joint: vec![Elementary::rz(Var::q(j).plus(angle)), Elementary::offset(0.175, 0.0, 0.0), Elementary::offset(0.05, 0.0, -0.08)],
                mass: 2.9,
                inertia: Matrix3::from_diagonal(&Vector3::new(0.016, 0.019, 0.0067)),
            })
            .unwrap();
        let thigh = b
            .add_body(BodySpec { name: format!("thigh{leg}"), parent: Some(hip), joint: vec![Elementary::ry(Var::q(j + 1)), Elementary::offset(0.14, 0.0, 0.0)], mass: 0.3, inertia: Matrix3::from_diagonal(&Vector3::new(1e-4, 2e-3, 2e-3)) })
            .unwrap();
        b.add_body(BodySpec { name: format!("shank{leg}"), parent: Some(thigh), joint: vec![Elementary::offset(0.14, 0.0, 0.0), Elementary::ry(Var::q(j + 2)), Elementary::offset(0.0, 0.0, -0.2)], mass: 0.56, inertia: Matrix3::from_diagonal(&Vector3::new(0.012, 0.012, 7e-5)) })
            .unwrap();
    }
    b.build()
}

/// Median ns per call of `f` over `reps` batches of `inner` calls.
fn time_ns(mut f: impl FnMut(), inner: usize, reps: usize) -> f64 {
    let mut samples: Vec<f64> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..inner {
                f();
            }
            t.elapsed().as_nanos() as f64 / inner as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[reps / 2]
}

fn main() {
    let model = hexapod_tree();
    let mut q = vec![0.0; 24];
    q[2] = 0.3;
    for leg in 0..6 {
        q[6 + 3 * leg] = 0.1;
        q[7 + 3 * leg] = -0.3;
        q[8 + 3 * leg] = 0.6;
    }
    let qd: Vec<f64> = (0..24).map(|i| 0.01 * (i as f64 + 1.0).sin()).collect();
    let qdd: Vec<f64> = (0..24).map(|i| 0.1 * (i as f64 * 0.7).cos()).collect();

    // Joint springs and dampers on the leg joints.
    let springs = |_: &Model, data: &mut Data, _: f64, q: &[f64], qd: &[f64]| {
        for j in 6..24 {
            data.add_generalized_force(j, -50.0 * q[j] - 2.0 * qd[j]);
        }
    };
    let mut sys = MultibodySystem::new(model.clone(), springs, 1e-4);
    let mut data = Data::new(&model);
    let mut f = vec![0.0; 24];
    let mut m = DMatrix::zeros(24, 24);

    let kin_direct = time_ns(|| kinematics(black_box(&model), &mut data, black_box(&q), black_box(&qd)), 2000, 21);
    let kin_numerical = time_ns(|| drop(black_box(partial_velocities_numerical(&model, &mut data, black_box(&q)))), 50, 11);
    let residual = time_ns(|| sys.residual(0.0, black_box(&q), &qd, &qdd, &mut f), 2000, 21);
    kinematics(&model, &mut data, &q, &qd);
    let mass = time_ns(|| mass_matrix(&model, black_box(&data), &mut m), 2000, 21);
    let jacobian = time_ns(|| drop(black_box(Jacobian::evaluate(&mut sys, 0.0, &q, &qd, &qdd))), 50, 11);

    let options = NewmarkOptions { adaptive: false, h_max: 1e-3, h_initial: 1e-3, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &q, &qd, options).unwrap();
    let steps = 2000;
    let t = Instant::now();
    nm.advance_to(&mut sys, steps as f64 * 1e-3).unwrap();
    let step = t.elapsed().as_nanos() as f64 / nm.stats().steps as f64;
    let s = nm.stats();

    println!("hexadyn engine benchmark: 24-DOF floating-base tree, six 3-DOF legs, 19 bodies");
    println!("  kinematics, direct partial velocities      {kin_direct:>12.0} ns/call");
    println!("  kinematics, numerical partial velocities   {kin_numerical:>12.0} ns/call   (baseline, Table 3.2 rows 1-2)");
    println!("  ratio numerical / direct                   {:>12.1} x", kin_numerical / kin_direct);
    println!("  residual f(q, q', q'', t)                  {residual:>12.0} ns/call");
    println!("  mass matrix M(q) (Eq. 3.39)                {mass:>12.0} ns/call");
    println!("  Jacobian M exact + CT, KT by differences   {jacobian:>12.0} ns/call   ({:.0} residuals)", jacobian / residual);
    println!("  Newmark step h = 1 ms (fixed)              {step:>12.0} ns/step   ({:.2} Newton it/step, {} Jacobians, {} LU in {} steps)", s.newton_iterations as f64 / s.steps as f64, s.jacobian_evaluations, s.factorizations, s.steps);
}
