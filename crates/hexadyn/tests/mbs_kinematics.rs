//! Kinematics of the mbs module against closed forms: the slider-crank of Fig. 3.6 with
//! dependent parameters (Eq. 3.42-3.50) and direct vs numerical partial velocities.

use std::sync::Arc;

mod mbs_models;

use approx::assert_relative_eq;
use mbs_models::tree;
use hexadyn::mbs::{kinematics, partial_velocities_numerical, BodySpec, Data, DependentFunction, DualNum, Elementary, Jet, Model, ModelBuilder, ModelError, Var, MAX_INPUTS};
use nalgebra::{Matrix3, Vector3};

const L1: f64 = 0.1;
const L2: f64 = 0.3;

/// p0 = α = asin(l1 sin q0 / l2), p1 = x = l1 cos q0 + l2 cos α (Eq. 3.42-3.43).
#[derive(Debug)]
struct SliderCrank;

impl DependentFunction for SliderCrank {
    fn input_count(&self) -> usize {
        1
    }
    fn output_count(&self) -> usize {
        2
    }
    fn eval(&self, x: &[Jet], p: &mut [Jet]) {
        let alpha = (x[0].sin() * (L1 / L2)).asin();
        p[0] = alpha;
        p[1] = x[0].cos() * L1 + alpha.cos() * L2;
    }
}

fn rod_inertia(m: f64, l: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(1e-6, m * l * l / 12.0, m * l * l / 12.0))
}

/// Crank, connecting rod and slider of Eq. 3.44-3.46.
fn slider_crank() -> Model {
    let mut b = ModelBuilder::new(1);
    let p = b.add_dependent(&[0], Arc::new(SliderCrank)).unwrap();
    b.add_body(BodySpec { name: "crank".into(), parent: None, joint: vec![Elementary::rz(Var::q(0)), Elementary::offset(L1 / 2.0, 0.0, 0.0)], mass: 1.0, inertia: rod_inertia(1.0, L1) }).unwrap();
    b.add_body(BodySpec {
        name: "connrod".into(),
        parent: None,
        joint: vec![Elementary::tx(Var::p(p + 1)), Elementary::rz(Var::p(p).scaled(-1.0)), Elementary::offset(-L2 / 2.0, 0.0, 0.0)],
        mass: 2.0,
        inertia: rod_inertia(2.0, L2),
    })
    .unwrap();
    b.add_body(BodySpec { name: "slider".into(), parent: None, joint: vec![Elementary::tx(Var::p(p + 1))], mass: 0.5, inertia: Matrix3::identity() * 1e-4 }).unwrap();
    b.build()
}

fn analytic(q0: f64) -> (f64, f64) {
    let alpha = (L1 * q0.sin() / L2).asin();
    (alpha, L1 * q0.cos() + L2 * alpha.cos())
}

#[test]
fn slider_crank_positions_velocities_and_accelerations_match_closed_form() {
    let model = slider_crank();
    let mut data = Data::new(&model);
    let rod = model.body_by_name("connrod").unwrap();
    let slider = model.body_by_name("slider").unwrap();
    let crank = model.body_by_name("crank").unwrap();
    for &(q0, w, wd) in &[(0.3, 2.0, -1.0), (1.9, -5.0, 3.0), (-2.5, 0.7, 10.0)] {
        kinematics(&model, &mut data, &[q0], &[w]);
        let (alpha, x) = analytic(q0);
        // Positions.
        assert_relative_eq!(data.position(slider), Vector3::new(x, 0.0, 0.0), epsilon = 1e-14);
        let pin = Vector3::new(L1 * q0.cos(), L1 * q0.sin(), 0.0);
        assert_relative_eq!(data.position(rod), (pin + Vector3::new(x, 0.0, 0.0)) / 2.0, epsilon = 1e-14);
        assert_relative_eq!(data.position(crank), pin / 2.0, epsilon = 1e-14);
        // Dependent rates, Eq. 3.49-3.50 (p0' = l1 q0' cos q0 / (l2 cos α)).
        let p0dot = L1 * w * q0.cos() / (L2 * alpha.cos());
        let p1dot = -L1 * w * q0.sin() - L2 * alpha.sin() * p0dot;
        assert_relative_eq!(data.dependent(0).rate, p0dot, epsilon = 1e-12);
        assert_relative_eq!(data.dependent(1).rate, p1dot, epsilon = 1e-12);
        // Velocity of the rod centre of gravity, Eq. 3.48 (with the rod drawn from the slider).
        let v = Vector3::new(p1dot + L2 * p0dot * alpha.sin() / 2.0, L2 * p0dot * alpha.cos() / 2.0, 0.0);
        assert_relative_eq!(data.velocity(rod), v, epsilon = 1e-12);
        assert_relative_eq!(data.angular_velocity(rod), Vector3::new(0.0, 0.0, -p0dot), epsilon = 1e-12);
        // Accelerations against central differences of the velocity along q(t) = q0 + w t + wd t²/2.
        let acc = data.acceleration(&model, rod, &[wd]);
        let dt = 1e-5;
        let vel = |t: f64| {
            let mut d = Data::new(&model);
            kinematics(&model, &mut d, &[q0 + w * t + 0.5 * wd * t * t], &[w + wd * t]);
            (d.velocity(rod), d.angular_velocity(rod))
        };
        let (vp, wp) = vel(dt);
        let (vm, wm) = vel(-dt);
        assert_relative_eq!(acc, (vp - vm) / (2.0 * dt), epsilon = 1e-6, max_relative = 1e-7);
        assert_relative_eq!(data.angular_acceleration(&model, rod, &[wd]), (wp - wm) / (2.0 * dt), epsilon = 1e-6, max_relative = 1e-7);
    }
}

#[test]
fn direct_partial_velocities_equal_numerical_derivation() {
    let model = tree();
    let mut data = Data::new(&model);
    let q = [0.1, -0.2, 0.3, 0.4, -0.3, 0.2, 0.25, 0.02, -0.6];
    let numeric = partial_velocities_numerical(&model, &mut data, &q);
    kinematics(&model, &mut data, &q, &[0.0; 9]);
    for (i, (js, jw)) in numeric.iter().enumerate() {
        let id = hexadyn::mbs::BodyId(i);
        let mut ds = nalgebra::DMatrix::zeros(3, 9);
        let mut dw = nalgebra::DMatrix::zeros(3, 9);
        for (c, d, delta) in data.partial_velocities(&model, id) {
            ds.set_column(c, &d);
            dw.set_column(c, &delta);
        }
        assert_relative_eq!(ds, js.clone(), epsilon = 1e-6, max_relative = 1e-6);
        assert_relative_eq!(dw, jw.clone(), epsilon = 1e-6, max_relative = 1e-6);
    }
}

/// The partial velocity of a point from the relative ones of the joints on its path
/// (`Data::point_partial_velocity_terms`, after `relative_kinematics` alone) sums, column by
/// column, to the one from the bodies' full partial velocities, on the AMRU5's feet, whose
/// pantograph links share dependent parameters (several terms per column).
#[test]
fn point_partial_velocity_terms_sum_to_the_point_partial_velocity() {
    use hexadyn::hexapod::DOF;
    use hexadyn::mbs::{partial_velocities, relative_kinematics};
    let (mech, q) = mbs_models::amru5();
    let model = &mech.model;
    let mut data = Data::new(model);
    relative_kinematics(model, &mut data, &q, &[0.0; DOF]);
    let mut repeated = 0;
    for bodies in &mech.legs {
        let foot = data.point(bodies.links[3], &mech.foot_local);
        let mut terms = nalgebra::DMatrix::zeros(3, DOF);
        let mut seen = [0; DOF];
        for (c, d) in data.point_partial_velocity_terms(model, bodies.links[3], foot) {
            let mut column = terms.column_mut(c);
            column += d;
            seen[c] += 1;
        }
        repeated += seen.iter().filter(|&&n| n > 1).count();
        partial_velocities(model, &mut data);
        let mut full = nalgebra::DMatrix::zeros(3, DOF);
        for (c, d) in data.point_partial_velocities(model, bodies.links[3], &foot) {
            full.set_column(c, &d);
        }
        assert_relative_eq!(terms, full, epsilon = 1e-14, max_relative = 1e-12);
    }
    assert!(repeated > 0, "the pantograph's columns come in several terms");
}

#[test]
fn velocities_are_partial_velocities_times_qdot() {
    let model = tree();
    let mut data = Data::new(&model);
    let q = [0.1, -0.2, 0.3, 0.4, -0.3, 0.2, 0.25, 0.02, -0.6];
    let qd = [0.3, 0.1, -0.2, 0.5, 0.7, -0.4, 1.2, -0.05, 2.0];
    kinematics(&model, &mut data, &q, &qd);
    for i in 0..model.body_count() {
        let id = hexadyn::mbs::BodyId(i);
        let (mut v, mut w) = (Vector3::zeros(), Vector3::zeros());
        for (c, d, delta) in data.partial_velocities(&model, id) {
            v += d * qd[c];
            w += delta * qd[c];
        }
        assert_relative_eq!(v, data.velocity(id), epsilon = 1e-13);
        assert_relative_eq!(w, data.angular_velocity(id), epsilon = 1e-13);
    }
}

/// A dependent-parameter group takes 1 to MAX_INPUTS inputs: more (or none) is a model error,
/// not a panic.
#[test]
fn dependent_groups_with_too_many_inputs_are_refused() {
    #[derive(Debug)]
    struct Sum(usize);
    impl DependentFunction for Sum {
        fn input_count(&self) -> usize {
            self.0
        }
        fn output_count(&self) -> usize {
            1
        }
        fn eval(&self, x: &[Jet], p: &mut [Jet]) {
            p[0] = x.iter().copied().sum();
        }
    }
    let mut b = ModelBuilder::new(8);
    let inputs: Vec<usize> = (0..=MAX_INPUTS).collect();
    assert_eq!(b.add_dependent(&inputs, Arc::new(Sum(inputs.len()))), Err(ModelError::DependentInputs { inputs: MAX_INPUTS + 1, max: MAX_INPUTS }));
    assert_eq!(b.add_dependent(&[], Arc::new(Sum(0))), Err(ModelError::DependentInputs { inputs: 0, max: MAX_INPUTS }));
    assert_eq!(b.add_dependent(&inputs[..MAX_INPUTS], Arc::new(Sum(MAX_INPUTS))), Ok(0));
}
