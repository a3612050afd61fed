//! Equations of motion (Eq. 3.37-3.41) against Lagrange's equations built independently from
//! the kinetic and potential energies, and conservation laws under Newmark integration.

mod mbs_models;

use approx::assert_relative_eq;
use hexadyn::mbs::{generalized_forces, kinematics, kinetic_energy, mass_matrix, nonlinear_effects, potential_energy, BodySpec, Data, Elementary, Model, ModelBuilder, MultibodySystem};
use hexadyn::sim::{Newmark, NewmarkOptions};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

const Q: [f64; 9] = [0.1, -0.2, 0.3, 0.4, -0.3, 0.2, 0.25, 0.02, -0.6];
const QD: [f64; 9] = [0.3, 0.1, -0.2, 0.5, 0.7, -0.4, 1.2, -0.05, 2.0];

fn energies(model: &Model, q: &[f64], qd: &[f64]) -> (f64, f64, DMatrix<f64>) {
    let mut data = Data::new(model);
    kinematics(model, &mut data, q, qd);
    let n = model.coordinate_count();
    let mut m = DMatrix::zeros(n, n);
    mass_matrix(model, &data, &mut m);
    (kinetic_energy(model, &data), potential_energy(model, &data), m)
}

/// T = ½ q̇ᵀ M q̇, and h = Ṁ q̇ − ∂T/∂q, g_gravity = −∂V/∂q (Lagrange's equations).
#[test]
fn mass_matrix_and_nonlinear_effects_satisfy_lagrange_equations() {
    let model = mbs_models::tree();
    let n = model.coordinate_count();
    let (t, _, m) = energies(&model, &Q, &QD);
    let qd = DVector::from_column_slice(&QD);
    assert_relative_eq!(t, 0.5 * qd.dot(&(&m * &qd)), max_relative = 1e-13);
    assert!(m.clone().cholesky().is_some(), "M must be symmetric positive definite");

    let mut data = Data::new(&model);
    kinematics(&model, &mut data, &Q, &QD);
    let h = DVector::from_vec(nonlinear_effects(&model, &data));
    let g = DVector::from_vec(generalized_forces(&model, &data));

    let eps = 1e-6;
    let mut mdot = DMatrix::zeros(n, n);
    let mut dtdq = DVector::zeros(n);
    let mut dvdq = DVector::zeros(n);
    for k in 0..n {
        let (mut qp, mut qm) = (Q, Q);
        qp[k] += eps;
        qm[k] -= eps;
        let (tp, vp, mp) = energies(&model, &qp, &QD);
        let (tm, vm, mm) = energies(&model, &qm, &QD);
        mdot += (mp - mm) * (QD[k] / (2.0 * eps));
        dtdq[k] = (tp - tm) / (2.0 * eps);
        dvdq[k] = (vp - vm) / (2.0 * eps);
    }
    let h_lagrange = &mdot * &qd - dtdq;
    assert_relative_eq!(h, h_lagrange, epsilon = 1e-7, max_relative = 1e-6);
    assert_relative_eq!(g, -dvdq, epsilon = 1e-7, max_relative = 1e-6);
}

fn free_body(gravity: bool) -> Model {
    let mut b = ModelBuilder::new(6);
    if !gravity {
        b = b.gravity(Vector3::zeros());
    }
    b.add_body(BodySpec {
        name: "body".into(),
        parent: None,
        joint: Elementary::free_body(0),
        mass: 11.2,
        inertia: Matrix3::from_diagonal(&Vector3::new(0.1063, 0.1198, 0.0843)),
    })
    .unwrap();
    b.build()
}

/// A torque-free asymmetric rigid body tumbling (intermediate-axis spin, the hardest case)
/// conserves kinetic energy and angular momentum within the integrator's tolerance.
#[test]
fn torque_free_rigid_body_conserves_energy_and_angular_momentum() {
    let mut sys = MultibodySystem::new(free_body(false), (), 1e-3);
    let q0 = [0.0, 0.0, 0.0, 0.1, 0.2, -0.1];
    // Yaw-pitch-roll rates giving a mostly intermediate-axis spin with a small perturbation.
    let qd0 = [0.01, -0.02, 0.0, 0.05, 1.0, 0.08];
    let options = NewmarkOptions { tolerance: 1e-7, h_max: 1e-2, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &q0, &qd0, options).unwrap();
    let invariants = |sys: &mut MultibodySystem, q: &[f64], qd: &[f64]| {
        kinematics(&sys.model, &mut sys.data, q, qd);
        let b = hexadyn::mbs::BodyId(0);
        let r = sys.data.rotation(b);
        let phi = r * Matrix3::from_diagonal(&Vector3::new(0.1063, 0.1198, 0.0843)) * r.transpose();
        (kinetic_energy(&sys.model, &sys.data), phi * sys.data.angular_velocity(b), sys.data.velocity(b) * 11.2)
    };
    let (e0, h0, p0) = invariants(&mut sys, &q0, &qd0);
    for k in 1..=20 {
        nm.advance_to(&mut sys, 0.5 * k as f64).unwrap();
        let s = nm.state().clone();
        // Stay clear of the yaw-pitch-roll singularity (pitch = ±90°).
        assert!(s.q[4].cos().abs() > 0.05);
        let (e, h, p) = invariants(&mut sys, s.q.as_slice(), s.qd.as_slice());
        assert_relative_eq!(e, e0, max_relative = 1e-4);
        assert_relative_eq!(h, h0, epsilon = 1e-4 * h0.norm());
        assert_relative_eq!(p, p0, epsilon = 1e-9);
    }
    assert!(nm.stats().steps > 100);
}

/// A free body under gravity falls with g: z(t) = z0 - g t²/2 (Newmark is exact on constant
/// acceleration).
#[test]
fn free_fall() {
    let mut sys = MultibodySystem::new(free_body(true), (), 1e-3);
    let mut nm = Newmark::new(&mut sys, 0.0, &[0.0, 0.0, 1.0, 0.3, 0.0, 0.0], &[0.0; 6], NewmarkOptions::default()).unwrap();
    nm.advance_to(&mut sys, 0.4).unwrap();
    assert_relative_eq!(nm.state().q[2], 1.0 - 0.5 * 9.81 * 0.16, epsilon = 1e-12);
    assert_eq!(nm.state().t, 0.4);
}

/// The mass matrix by composite rigid bodies on the AMRU5 (49 bodies, the pantograph's
/// dependent parameters shared by several links, the rotors' spins) is the kinetic energy's
/// Hessian in q̇, an independent oracle (T from the bodies' velocities, Eq. 3.26, 3.33):
/// M_jk = T(e_j + e_k) − T(e_j) − T(e_k), M_jj = 2 T(e_j).
#[test]
fn amru5_mass_matrix_is_the_hessian_of_the_kinetic_energy() {
    use hexadyn::hexapod::DOF;
    let (mech, q) = mbs_models::amru5();
    let model = &mech.model;
    let (_, _, m) = energies(model, &q, &[0.0; DOF]);
    let t = |j: usize, k: usize| {
        let mut qd = [0.0; DOF];
        qd[j] += 1.0;
        qd[k] += 1.0;
        energies(model, &q, &qd).0
    };
    let scale = m.amax();
    for j in 0..DOF {
        assert!((m[(j, j)] - 2.0 * t(j, j) / 4.0).abs() <= 1e-12 * scale, "M[{j},{j}]");
        for k in 0..j {
            let polarized = t(j, k) - t(j, j) / 4.0 - t(k, k) / 4.0;
            assert!((m[(j, k)] - polarized).abs() <= 1e-12 * scale, "M[{j},{k}] = {} vs {polarized}", m[(j, k)]);
            assert_eq!(m[(j, k)], m[(k, j)]);
        }
    }
}
