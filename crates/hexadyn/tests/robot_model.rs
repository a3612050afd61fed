//! The complete AMRU5 model: Jacobians, sinkage on three legs (Sections 3.4.2, 7.6) and the
//! unpowered robot of Section 6.2 with the three friction models.

use std::sync::Arc;

use approx::assert_relative_eq;
use hexadyn::control::Command;
use hexadyn::physics::FlatGround;
use hexadyn::robot::model::{FrictionModel, JointControl, ModelOptions, Robot, RobotModel};
use hexadyn::hexapod::JOINTS;
use hexadyn::description::RobotDescription;
use hexadyn::robot::simulation::PlantOptions;
use hexadyn::sim::{finite_difference_jacobian, finite_difference_jacobian_with_steps, static_equilibrium, Jacobian, Newmark, NewmarkOptions, Order, StaticOptions, System};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
        (FrictionModel::Efficiency, false, false, JointControl::Digital),
        (FrictionModel::Efficiency, true, false, JointControl::Digital),
        (FrictionModel::Efficiency, false, false, pid),
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
        // The oracle's own error, seen as its change with ten-times steps: its steps go down to
        // 1e-11 rad on the body angles (1e-6 of their 1e-5 rad scale), where the rounding of the
        // contact and gravity moments, a thousand times f_i, is 3e-4 of KT[3, 5] and KT[4, 5].
        let coarse = finite_difference_jacobian_with_steps(&mut r, 0.0, &q, &qd, &qdd, 1e-5);
        for (name, a, b, c) in [("M", &exact.m, &fd.m, &coarse.m), ("CT", &exact.ct, &fd.ct, &coarse.ct), ("KT", &exact.kt, &fd.kt, &coarse.kt)] {
            for i in 0..n {
                for j in 0..n {
                    let noise = (b[(i, j)] - c[(i, j)]).abs();
                    let tol = 1e-5 * (a[(i, j)].abs() + b[(i, j)].abs()) + 1e-6 * a.row(i).amax().max(1.0) + noise;
                    assert!((a[(i, j)] - b[(i, j)]).abs() <= tol, "{friction:?} inductance {inductance}: {name}[{i}, {j}] exact {} vs FD {}", a[(i, j)], b[(i, j)]);
                }
            }
        }
    }
}

/// The robot's surrogate residual (`System::surrogate_residual`) about an evaluation of the
/// robot on its six feet (sunk 1 mm, the feet sliding within the linear zone of the ground
/// friction, moved in and out of it): at the base's (q, q') it is the residual for any q'' (f is affine in q''
/// through M, Eq. 3.37, and the bristle rates, Eq. 3.85); along a Newmark correction of q''
/// (q by β h² Δq'', q' by γ h Δq'', h = 10 ms) it follows the change of f to within 1e-5 of that
/// change, what it leaves out being the slowly varying inertial terms (the kinematics held at
/// the base). Without a Jacobian (no kept mass matrix) there is no surrogate.
#[test]
fn the_surrogate_is_the_residual_at_its_base_and_follows_its_changes() {
    for friction in [FrictionModel::LuGre, FrictionModel::DryViscous] {
        let mut r = robot(friction, |_| {});
        let mut q = r.model.touching_ground(&joints(&[0, 1, 2, 3, 4, 5]));
        let n = q.len();
        q[2] -= 1e-3;
        let scales = r.layout().scales.clone();
        let size = |i: usize| if i < 24 { 1e-3 } else { 10.0 * scales[i] };
        // The feet slide at some 1e-5 m/s, within the linear zone (v_glim = 1e-4 m/s).
        let qd: Vec<f64> = (0..n).map(|i| 0.02 * size(i) * ((i as f64) * 1.7).sin()).collect();
        let qdd: Vec<f64> = (0..n).map(|i| 10.0 * size(i) * ((i as f64) * 0.9).cos()).collect();
        for k in 0..JOINTS {
            r.set_input(k, 3.0 * (k as f64).cos());
        }
        let mut f0 = vec![0.0; n];
        r.residual(0.0, &q, &qd, &qdd, &mut f0);
        assert!(!r.keep_surrogate_base(&q, &qd, &qdd, &f0), "{friction:?}: no mass matrix kept yet");
        assert!(r.jacobian(0.0, &q, &qd, &qdd, &mut Jacobian::zeros(n)));
        r.residual(0.0, &q, &qd, &qdd, &mut f0);
        assert!(r.keep_surrogate_base(&q, &qd, &qdd, &f0));
        let (mut exact, mut surrogate) = (vec![0.0; n], vec![0.0; n]);
        let scale = f0.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        let other: Vec<f64> = (0..n).map(|i| qdd[i] + 30.0 * size(i) * ((i as f64) * 2.3).sin()).collect();
        r.surrogate_residual(0.0, &q, &qd, &other, &mut surrogate);
        r.residual(0.0, &q, &qd, &other, &mut exact);
        let gap = (0..n).fold(0.0_f64, |a, i| a.max((surrogate[i] - exact[i]).abs()));
        assert!(gap <= 1e-10 * scale, "{friction:?}: surrogate {gap} from f at the base's (q, q'), |f| up to {scale}");
        let options = NewmarkOptions::default();
        let h = 0.01;
        let mut slips = 0;
        for k in 1..=6 {
            let dqdd: Vec<f64> = (0..n).map(|i| 10.0 * size(i) * ((k * i) as f64 * 0.37 + k as f64).cos()).collect();
            let moved = |x: &[f64], factor: f64| -> Vec<f64> { (0..n).map(|i| if i < 24 { x[i] + factor * dqdd[i] } else { x[i] }).collect() };
            let (q1, qd1) = (moved(&q, options.beta * h * h), moved(&qd, options.gamma * h));
            let qdd1: Vec<f64> = (0..n).map(|i| qdd[i] + dqdd[i]).collect();
            r.surrogate_residual(0.0, &q1, &qd1, &qdd1, &mut surrogate);
            r.residual(0.0, &q1, &qd1, &qdd1, &mut exact);
            slips += r.outputs.contact.iter().filter(|c| c.slip_velocity.norm() > r.model.options.ground.v_glim).count();
            // Row by row against the change of the multibody rows (the state rows are exact).
            let change = (0..24).fold(0.0_f64, |a, i| a.max((exact[i] - f0[i]).abs()));
            let gap = (0..n).fold(0.0_f64, |a, i| a.max((surrogate[i] - exact[i]).abs()));
            eprintln!("{friction:?}, move {k}: surrogate {gap:.3e} from f, whose multibody rows changed by up to {change:.3e}; {slips} feet slipping so far");
            assert!(gap <= 1e-5 * change, "{friction:?}, move {k}: surrogate {gap} from f, whose multibody rows changed by up to {change}");
        }
        assert!(slips > 0 && slips < 36, "{friction:?}: feet in and out of the friction's linear zone: {slips} of 36 slipping");
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
    assert_eq!(full.model.multibody.body_count(), 49);
    assert_eq!(robot(FrictionModel::LuGre, |_| {}).model.coordinate_count(), 42);
}

/// The exact change of the residual when the inputs jump (`System::input_change`, Eq. 3.16) is
/// the difference of two residual evaluations at the same random (q, q', q''), for digital
/// voltages without inductance (Eq. 4.4: the joint rows) and with it (Eq. 3.91: the current
/// rows), for the references of continuous PIDs (Eq. 3.97) and on the stand. The commanded
/// voltages reach twice the supply (saturated) and the joints go beyond the ends of their
/// strokes (cut by the limit switches when pushed further out).
#[test]
fn input_change_is_the_difference_of_two_residuals() {
    let pid = JointControl::ContinuousPid { t_d: 0.01, n: 10.0, omega_0: 1000.0 };
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    let (mut saturated, mut cut) = (0, 0);
    for (friction, inductance, control, stand) in [
        (FrictionModel::LuGre, false, JointControl::Digital, false),
        (FrictionModel::DryViscous, false, JointControl::Digital, true),
        (FrictionModel::LuGre, true, JointControl::Digital, false),
        (FrictionModel::None, false, pid, false),
        (FrictionModel::LuGre, true, pid, true),
        (FrictionModel::Efficiency, false, JointControl::Digital, false),
        (FrictionModel::Efficiency, true, JointControl::Digital, true),
    ] {
        let mut r = robot(friction, |o| {
            o.inductance = inductance;
            o.control = control;
            o.stand = stand;
        });
        let supply = r.model.options.supply_voltage;
        let n = r.model.coordinate_count();
        let (mut f_previous, mut f, mut df) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for _ in 0..20 {
            let mut q = r.model.touching_ground(&joints(&[0, 1, 2, 3, 4, 5]));
            q[2] -= rng.random_range(0.0..2e-3);
            for k in 0..JOINTS {
                let stroke = &r.model.strokes[k % 3];
                let margin = 0.2 * (stroke.end() - stroke.start());
                q[6 + k] = rng.random_range(stroke.start() - margin..stroke.end() + margin);
            }
            let size = |i: usize| if i < 24 { 1e-2 } else { 100.0 * r.layout().scales[i] };
            let qd: Vec<f64> = (0..n).map(|i| size(i) * rng.random_range(-1.0..1.0)).collect();
            let qdd: Vec<f64> = (0..n).map(|i| 10.0 * size(i) * rng.random_range(-1.0..1.0)).collect();
            let command = |rng: &mut ChaCha8Rng| Command {
                voltages: std::array::from_fn(|_| rng.random_range(-2.0..2.0) * supply),
                references: std::array::from_fn(|k| q[6 + k] + rng.random_range(-0.01..0.01)),
                goals: None,
            };
            let (first, second) = (command(&mut rng), command(&mut rng));
            r.command(&first, &q);
            let previous: Vec<f64> = (0..JOINTS).map(|k| r.input(k)).collect();
            r.residual(0.0, &q, &qd, &qdd, &mut f_previous);
            r.command(&second, &q);
            r.residual(0.0, &q, &qd, &qdd, &mut f);
            assert!(r.input_change(0.0, &q, &qd, &qdd, &previous, &mut df));
            for i in 0..n {
                let difference = f[i] - f_previous[i];
                let tol = 1e-12 * (f[i].abs() + f_previous[i].abs()) + 1e-12;
                assert!((df[i] - difference).abs() <= tol, "{friction:?} inductance {inductance} {control:?} stand {stand}: row {} Δf {} vs {difference}", r.layout().names[i], df[i]);
            }
            assert!(df.iter().any(|x| *x != 0.0), "the inputs jumped: Δf is not zero");
            if control == JointControl::Digital {
                saturated += second.voltages.iter().filter(|u| u.abs() > supply).count();
                cut += (0..JOINTS).filter(|&k| second.voltages[k] != 0.0 && r.voltages[k] == 0.0).count();
            }
        }
        let zeros = vec![0.0; n];
        assert!(!r.input_change(0.0, &zeros, &zeros, &zeros, &[0.0; 3], &mut df), "inputs of the wrong length");
        assert!(!r.input_change(0.0, &zeros, &zeros, &zeros, &[0.0; JOINTS], &mut [0.0; 3]), "Δf of the wrong length");
    }
    assert!(saturated > 100 && cut > 20, "saturated voltages {saturated}, cut by the limit switches {cut}");
}

/// At every 10 ms control instant of a second of the LuGre robot driven by jumping voltages, the
/// reset after the jump (`Newmark::reset_accelerations_after_input_jump`) evaluates f once (with
/// the robot's surrogate iterations: the surrogate about the last step's evaluation instead) and
/// gives the rates of the first-order states (bristles, currents) of a Newton reset from a fresh
/// mass matrix (a new integrator at the same (t, q, q')) within twice the Newton test of the
/// steps (1 % of q'' plus newton_tolerance · tolerance · scale / (γ h)), and all of q'' (the
/// joint and body accelerations too, β h² for the unit) at the instants where its correction
/// passed the test; the q'' held from the last step is off by more than 100 times that. At the
/// other instants (the second-order coordinates keep the step's accelerations plus the jump) all
/// of q'' is within 10 times twice the test. The voltages swing over the whole supply (±12 V)
/// so that both kinds of instant occur.
#[test]
fn reset_after_an_input_jump_matches_the_newton_reset() {
    let d = RobotDescription::amru5();
    let options = PlantOptions::new(d.controller.period_s, &robot(FrictionModel::LuGre, |_| {}).model.options).integrator;
    assert!(options.surrogate_iterations > 0);
    reset_after_an_input_jump(NewmarkOptions { surrogate_iterations: 0, ..options.clone() });
    reset_after_an_input_jump(options);
}

fn reset_after_an_input_jump(options: NewmarkOptions) {
    let mut r = robot(FrictionModel::LuGre, |_| {});
    let d = RobotDescription::amru5();
    let q = settle(&mut r, &[0, 1, 2, 3, 4, 5]);
    let qd = vec![0.0; q.len()];
    let mut nm = Newmark::new(&mut r, 0.0, &q, &qd, options.clone()).unwrap();
    let layout = r.layout().clone();
    let h = options.h_max;
    let floor = |i: usize| {
        let unit = if layout.orders[i] == Order::Second { options.beta * h * h } else { options.gamma * h };
        options.newton_tolerance * options.tolerance * layout.scales[i] / unit
    };
    let amplitude = d.driver.supply_voltage_v;
    let (mut evaluations, mut surrogate, mut first_order, mut stale, mut consistent, mut others) = (0, 0, 0.0_f64, 0.0_f64, 0, 0.0_f64);
    let instants = 100;
    for k in 1..=instants {
        nm.advance_to(&mut r, 0.01 * k as f64).unwrap();
        let previous = r.voltages;
        let held = nm.state().qdd.clone();
        r.voltages = std::array::from_fn(|j| amplitude * (0.7 * k as f64 + j as f64).sin());
        let counts = |nm: &Newmark| (nm.stats().residual_evaluations, nm.stats().surrogate_evaluations);
        let before = counts(&nm);
        nm.reset_accelerations_after_input_jump(&mut r, &previous).unwrap();
        let after = counts(&nm);
        evaluations += after.0 - before.0;
        surrogate += after.1 - before.1;
        let s = nm.state();
        let newton = Newmark::new(&mut r.clone(), s.t, s.q.as_slice(), s.qd.as_slice(), options.clone()).unwrap();
        let reference = &newton.state().qdd;
        let off = |x: &nalgebra::DVector<f64>, i: usize| (x[i] - reference[i]).abs() / (2.0 * (options.newton_tolerance * reference[i].abs() + floor(i)));
        let first = (0..q.len()).filter(|&i| layout.orders[i] == Order::First);
        first_order = first.map(|i| off(&s.qdd, i)).fold(first_order, f64::max);
        stale = (0..q.len()).map(|i| off(&held, i)).fold(stale, f64::max);
        let largest = (0..q.len()).map(|i| off(&s.qdd, i)).fold(0.0, f64::max);
        if largest <= 1.0 {
            consistent += 1;
        } else {
            others = others.max(largest);
        }
    }
    eprintln!("reset after an input jump, {} surrogate iterations: {evaluations} residual and {surrogate} surrogate evaluations over {instants} instants; first-order rates within {first_order:.2e} of twice the Newton test, all of q'' at {consistent} instants and within {others:.2e} of it at the others (q'' before the reset: {stale:.2e})", options.surrogate_iterations);
    let resets = if options.surrogate_iterations > 0 { surrogate } else { evaluations };
    assert_eq!((resets, evaluations + surrogate), (instants, instants), "one evaluation per reset");
    assert!(stale > 100.0, "the voltage jumps move q'' by {stale} times twice the Newton test only");
    assert!(first_order <= 1.0, "first-order rates off the Newton reset by {first_order} times twice the Newton test");
    assert!(consistent >= instants / 2 && consistent < instants, "all of q'' consistent at {consistent} of {instants} instants");
    assert!(others <= 10.0, "q'' off the Newton reset by {others} times twice the Newton test");
}
