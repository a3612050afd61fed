//! The complete AMRU5 model: Jacobians, sinkage on three legs (Sections 3.4.2, 7.6) and the
//! unpowered robot of Section 6.2 with the three friction models.

use std::sync::Arc;

use approx::assert_relative_eq;
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, JointControl, ModelOptions, Robot, RobotModel};
use hexadyn::hexapod::JOINTS;
use hexadyn::description::RobotDescription;
use hexadyn::sim::{finite_difference_jacobian, static_equilibrium, Jacobian, Newmark, NewmarkOptions, StaticOptions, System};

/// q_v of the supporting legs and of the lifted ones, q_h of all (m).
const Q_V_DOWN: f64 = 0.06;
const Q_V_UP: f64 = 0.045;
const Q_H: f64 = 0.03;

fn robot(friction: FrictionModel, tweak: impl FnOnce(&mut ModelOptions)) -> Robot {
    let d = RobotDescription::amru5();
    let mut options = ModelOptions::from_description(&d, friction);
    tweak(&mut options);
    Robot::new(Arc::new(RobotModel::new(&d, options, Arc::new(FlatGround { height: 0.0 }))))
}

fn joints(down: &[usize]) -> [f64; JOINTS] {
    std::array::from_fn(|k| match k % 3 {
        0 => 0.0,
        1 => if down.contains(&(k / 3)) { Q_V_DOWN } else { Q_V_UP },
        _ => Q_H,
    })
}

/// Static equilibrium with the joints locked (Section 6.2); returns q.
fn settle(robot: &mut Robot, down: &[usize]) -> Vec<f64> {
    let mut q = robot.model.touching_ground(&joints(down));
    let mut qd = vec![0.0; q.len()];
    let locks = robot.model.standing_locks();
    static_equilibrium(robot, 0.0, &mut q, &mut qd, &locks, &StaticOptions { residual_tolerance: 1e-6, max_iterations: 200 }).unwrap();
    q
}

/// Standing on three legs the feet sink about 2.3 mm with K_gnd = 1e6 (Section 3.4.2) and
/// about 49 mm with K_gnd = 1e4 (Section 7.6), within 10 %.
#[test]
fn sinkage_on_three_legs() {
    for (k_gnd, expected) in [(1e6, 2.3e-3), (1e4, 49e-3)] {
        let mut r = robot(FrictionModel::None, |o| o.ground.k_gnd = k_gnd);
        let q = settle(&mut r, &[0, 3, 4]);
        r.evaluate(&q, &vec![0.0; q.len()], &vec![0.0; q.len()]);
        for leg in [0, 3, 4] {
            let sink = r.outputs.contact[leg].penetration;
            assert!((sink - expected).abs() < 0.1 * expected, "K_gnd = {k_gnd}: leg {leg} sinks {:.3} mm, thesis {:.1} mm", sink * 1e3, expected * 1e3);
        }
        let weight: f64 = r.outputs.contact.iter().map(|c| c.normal_force).sum();
        assert_relative_eq!(weight, 34.447 * 9.81, max_relative = 1e-6);
    }
}

/// The robot's exact Jacobian blocks agree with the finite-difference oracle for every
/// friction model, with and without inductance, in a moving state with feet on the ground.
#[test]
fn analytic_jacobian_matches_finite_differences() {
    let pid = JointControl::ContinuousPid { t_d: 0.01, n: 10.0, omega_0: 1000.0 };
    for (friction, inductance, load, control) in [
        (FrictionModel::None, false, false, JointControl::Digital),
        (FrictionModel::DryViscous, true, true, JointControl::Digital),
        (FrictionModel::LuGre, true, true, JointControl::Digital),
        (FrictionModel::LuGre, false, false, JointControl::Digital),
        (FrictionModel::LuGre, true, false, pid),
        (FrictionModel::None, false, false, pid),
    ] {
        let mut r = robot(friction, |o| {
            o.inductance = inductance;
            o.load_dependence = load;
            o.control = control;
        });
        let mut q = r.model.touching_ground(&joints(&[0, 1, 2, 3, 4, 5]));
        let n = q.len();
        q[2] -= 1e-3;
        // Mechanical velocities of mm/s, bristle states and currents of physical size.
        let size = |i: usize| if i < 24 { 1e-3 } else { 100.0 * r.layout().scales[i] };
        let qd: Vec<f64> = (0..n).map(|i| size(i) * ((i as f64) * 1.7).sin()).collect();
        let qdd: Vec<f64> = (0..n).map(|i| 10.0 * size(i) * ((i as f64) * 0.9).cos()).collect();
        for k in 0..JOINTS {
            let reference = if control == JointControl::Digital { 3.0 * (k as f64).cos() } else { q[6 + k] + 1e-3 * (k as f64).cos() };
            r.set_input(k, reference);
        }
        let mut exact = Jacobian::zeros(n);
        assert!(r.jacobian(0.0, &q, &qd, &qdd, &mut exact));
        let fd = finite_difference_jacobian(&mut r, 0.0, &q, &qd, &qdd);
        // The oracle's rounding noise: a few ulps of f_i over its step in column j (the steps of
        // `finite_difference_jacobian`, down to 1e-12 m on the body position).
        let mut f = vec![0.0; n];
        r.residual(0.0, &q, &qd, &qdd, &mut f);
        let scales = r.layout().scales.clone();
        let step = |x: &[f64], j: usize, floor: f64| 1e-6 * x[j].abs().max(floor);
        for (name, a, b, x) in [("M", &exact.m, &fd.m, &qdd), ("CT", &exact.ct, &fd.ct, &qd), ("KT", &exact.kt, &fd.kt, &q)] {
            for i in 0..n {
                for j in 0..n {
                    let floor = if name == "M" { 1.0 } else { scales[j] };
                    let noise = 8.0 * f64::EPSILON * f[i].abs() / step(x, j, floor);
                    let tol = 1e-5 * (a[(i, j)].abs() + b[(i, j)].abs()) + 1e-6 * a.row(i).amax().max(1.0) + noise;
                    assert!((a[(i, j)] - b[(i, j)]).abs() <= tol, "{friction:?} inductance {inductance}: {name}[{i}, {j}] exact {} vs FD {}", a[(i, j)], b[(i, j)]);
                }
            }
        }
    }
}

/// The mass matrix of the multibody rows in the Jacobian (Eq. 3.39) is kept with the inertial
/// terms while the configuration moves little and re-taken beyond (0.2 rad on a q_r): 0.05 rad
/// later it is still the one of the first configuration, 0.3 rad later the exact one again.
#[test]
fn jacobian_mass_matrix_is_kept_while_the_configuration_moves_little() {
    let mut r = robot(FrictionModel::LuGre, |_| {});
    let q = r.model.touching_ground(&joints(&[0, 1, 2, 3, 4, 5]));
    let n = q.len();
    let (qd, qdd) = (vec![0.0; n], vec![0.0; n]);
    let exact_mass = |r: &mut Robot, q: &[f64]| {
        let mut m = nalgebra::DMatrix::zeros(n, n);
        assert!(r.mass_matrix(0.0, q, &qd, &qdd, &mut m));
        m
    };
    let jacobian_mass = |r: &mut Robot, q: &[f64]| {
        let mut jac = Jacobian::zeros(n);
        assert!(r.jacobian(0.0, q, &qd, &qdd, &mut jac));
        jac.m
    };
    let first = jacobian_mass(&mut r, &q);
    assert_eq!(first, exact_mass(&mut r, &q));
    // q_r of leg 0 (coordinate 6) turned by 0.05 rad: the kept matrix, no longer the exact one.
    let mut near = q.clone();
    near[6] += 0.05;
    let kept = jacobian_mass(&mut r, &near);
    assert_eq!(kept, first);
    assert!((&kept - exact_mass(&mut r, &near)).amax() > 1e-9 * kept.amax(), "M depends on q_r");
    // 0.3 rad: re-taken.
    let mut far = q.clone();
    far[6] += 0.3;
    assert_eq!(jacobian_mass(&mut r, &far), exact_mass(&mut r, &far));
}

/// Section 6.2: the unpowered robot on six legs for 10 s. With LuGre the height changes by less
/// than 0.05 mm; without friction the body sinks steadily (millimetres, slowed by the closed
/// motor circuits); dry/viscous lies in between.
#[test]
fn unpowered_robot_irreversibility() {
    let mut sink = Vec::new();
    for friction in [FrictionModel::LuGre, FrictionModel::DryViscous, FrictionModel::None] {
        let mut r = robot(friction, |_| {});
        let q = settle(&mut r, &[0, 1, 2, 3, 4, 5]);
        let qd = vec![0.0; q.len()];
        let options = NewmarkOptions { tolerance: 1.0, h_max: 1e-2, h_initial: 1e-4, ..Default::default() };
        let mut nm = Newmark::new(&mut r, 0.0, &q, &qd, options).unwrap();
        nm.advance_to(&mut r, 10.0).unwrap();
        let z = nm.state().q[2];
        println!("{friction:?}: body height change {:.4} mm, stats {:?}", (z - q[2]) * 1e3, nm.stats());
        sink.push(q[2] - z);
    }
    let [lugre, dry, none] = [sink[0], sink[1], sink[2]];
    assert!(lugre.abs() < 0.05e-3, "LuGre: {lugre}");
    assert!(none > 1e-3, "no friction sinks millimetres: {none}");
    assert!(lugre.abs() < dry && dry < none, "order LuGre < dry/viscous < none: {sink:?}");
}

/// Table 3.5: 49 bodies and 96 DOF with LuGre friction, motor inductances and continuous PID
/// controllers (24 + 18 + 18 + 36); 42 for the simplified model of Section 4.5.
#[test]
fn coordinate_counts_of_table_3_5_and_section_4_5() {
    let full = robot(FrictionModel::LuGre, |o| {
        o.inductance = true;
        o.control = JointControl::ContinuousPid { t_d: 0.0, n: 10.0, omega_0: 1000.0 };
    });
    assert_eq!(full.model.coordinate_count(), 96);
    assert_eq!(full.model.mechanics.model.body_count(), 49);
    assert_eq!(robot(FrictionModel::LuGre, |_| {}).model.coordinate_count(), 42);
}
