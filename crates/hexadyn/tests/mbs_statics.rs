//! Static equilibrium (Section 3.3.2) and linearization (Eq. 3.16-3.17) of multibody systems
//! against closed forms: a damped compound pendulum and a vertical spring-mass chain.

use approx::assert_relative_eq;
use hexadyn::mbs::{BodyId, BodySpec, Data, Elementary, Model, ModelBuilder, MultibodySystem, Var};
use hexadyn::sim::{linearize, static_equilibrium, StaticOptions};
use nalgebra::{DMatrix, Matrix3, Vector3};

const M: f64 = 2.0;
const L: f64 = 0.5;
const IYY: f64 = 0.01;
const C: f64 = 0.3;
const G: f64 = 9.81;

fn pendulum() -> Model {
    let mut b = ModelBuilder::new(1);
    b.add_body(BodySpec { name: "pendulum".into(), parent: None, joint: vec![Elementary::ry(Var::q(0)), Elementary::offset(0.0, 0.0, -L)], mass: M, inertia: Matrix3::from_diagonal(&Vector3::new(IYY, IYY, 1e-4)) }).unwrap();
    b.build()
}

/// Viscous damper c q̇ at the pivot.
fn damper(_: &Model, data: &mut Data, _: f64, _: &[f64], qd: &[f64]) {
    data.add_generalized_force(0, -C * qd[0]);
}

#[test]
fn pendulum_equilibrium_and_poles() {
    let mut sys = MultibodySystem::new(pendulum(), damper, 1e-3);
    let (mut q, mut qd) = ([0.8], [0.0]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &StaticOptions::default()).unwrap();
    assert!(q[0].abs() < 1e-9, "pendulum hangs down, got {}", q[0]);

    let lin = linearize(&mut sys, 0.0, &q, &qd, &[0.0]);
    let j = M * L * L + IYY;
    assert_relative_eq!(lin.m[(0, 0)], j, max_relative = 1e-12);
    assert_relative_eq!(lin.ct[(0, 0)], C, max_relative = 1e-6);
    assert_relative_eq!(lin.kt[(0, 0)], M * G * L, max_relative = 1e-6);
    let omega = (M * G * L / j).sqrt();
    let zeta = C / (2.0 * j * omega);
    let poles = lin.poles().unwrap();
    assert_eq!(poles.len(), 2);
    for p in &poles {
        assert_relative_eq!(p.frequency_hz, omega / (2.0 * std::f64::consts::PI), max_relative = 1e-6);
        assert_relative_eq!(p.damping_ratio, zeta, max_relative = 1e-6);
    }
    // Locked: a coordinate held away from equilibrium keeps its value.
    let (mut q, mut qd) = ([0.8], [0.0]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[0], &StaticOptions::default()).unwrap();
    assert_eq!(q[0], 0.8);
}

const MASSES: [f64; 3] = [1.0, 2.0, 1.5];
const K: [f64; 3] = [400.0, 300.0, 250.0];
const REST: f64 = 0.2;

/// Three masses hanging from the ceiling (z = 0) by springs, each on a vertical slider:
/// mass i at height z_i = q_i, spring i between mass i−1 (or the ceiling) and mass i.
fn chain() -> MultibodySystem<impl FnMut(&Model, &mut Data, f64, &[f64], &[f64]) + Send> {
    let mut b = ModelBuilder::new(3);
    for (i, m) in MASSES.iter().enumerate() {
        b.add_body(BodySpec { name: format!("mass{i}"), parent: None, joint: vec![Elementary::tz(Var::q(i))], mass: *m, inertia: Matrix3::identity() * 1e-3 }).unwrap();
    }
    let springs = |_: &Model, data: &mut Data, _: f64, q: &[f64], _: &[f64]| {
        for i in 0..3 {
            let above = if i == 0 { 0.0 } else { q[i - 1] };
            let stretch = above - q[i] - REST;
            let f = Vector3::new(0.0, 0.0, K[i] * stretch);
            let p = data.position(BodyId(i));
            data.add_force(BodyId(i), &p, &f);
            if i > 0 {
                let pa = data.position(BodyId(i - 1));
                data.add_force(BodyId(i - 1), &pa, &-f);
            }
        }
    };
    MultibodySystem::new(b.build(), springs, 1e-3)
}

#[test]
fn spring_mass_chain_equilibrium_and_frequencies() {
    let mut sys = chain();
    let (mut q, mut qd) = ([-0.1, -0.3, -0.5], [0.0; 3]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &StaticOptions::default()).unwrap();
    // Closed form: spring i carries the weight of masses i.. below it.
    let mut z = 0.0;
    for i in 0..3 {
        let carried: f64 = MASSES[i..].iter().sum::<f64>() * G;
        z -= REST + carried / K[i];
        assert_relative_eq!(q[i], z, epsilon = 1e-10);
    }
    let lin = linearize(&mut sys, 0.0, &q, &qd, &[0.0; 3]);
    let kmat = DMatrix::from_row_slice(3, 3, &[K[0] + K[1], -K[1], 0.0, -K[1], K[1] + K[2], -K[2], 0.0, -K[2], K[2]]);
    assert_relative_eq!(lin.kt, kmat, epsilon = 1e-5);
    // ω² are the eigenvalues of M^-1/2 K M^-1/2.
    let mi = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(3, MASSES.iter().map(|m| 1.0 / m.sqrt())));
    let mut w2: Vec<f64> = (&mi * &kmat * &mi).symmetric_eigen().eigenvalues.iter().copied().collect();
    w2.sort_by(f64::total_cmp);
    let poles = lin.poles().unwrap();
    assert_eq!(poles.len(), 6);
    for (k, w) in w2.iter().enumerate() {
        // Undamped: a conjugate pair per mode, damping ratio 0.
        for p in &poles[2 * k..2 * k + 2] {
            assert_relative_eq!(p.frequency_hz, w.sqrt() / (2.0 * std::f64::consts::PI), max_relative = 1e-6);
            assert!(p.damping_ratio.abs() < 1e-6);
        }
    }
}
