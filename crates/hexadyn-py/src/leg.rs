//! `hexadyn._core.LegModel`: the joint torques of one leg on a still, level body (Eq. 3.37 on a
//! single leg, `hexadyn::hexapod::LegDynamics::leg_joint_torques`), vectorized over samples, and
//! the constants of each joint, for a robot of either leg mechanism. The friction
//! identification removes the gravity contribution with it (Section 5.2.1).

use hexadyn::description::{Robot, AMRU5_TOML};
use hexadyn::hexapod::{LegDynamics, PantographJoint, LEG_COUNT};
use hexadyn::mbs::Data;
use hexadyn::physics::JointFriction;
use hexadyn::robot::model::{FrictionModel, RobotParts};
use nalgebra::Vector3;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[pyclass(name = "LegModel", module = "hexadyn._core")]
pub struct PyLegModel {
    robot: Robot,
    /// The parts of the robot model with `dry_viscous` friction: the motors, position sensors
    /// and friction laws the simulation uses.
    parts: RobotParts,
    dynamics: LegDynamics,
    data: Data,
}

#[pymethods]
impl PyLegModel {
    /// Builds the mechanics of a robot description of either leg mechanism (TOML text, None
    /// for the embedded AMRU5; `origin` names it in errors).
    #[new]
    #[pyo3(signature = (robot_text = None, origin = "robot description"))]
    fn new(robot_text: Option<&str>, origin: &str) -> PyResult<Self> {
        let robot = Robot::from_str(robot_text.unwrap_or(AMRU5_TOML), origin).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let parts = robot.parts(&robot.model_options(FrictionModel::DryViscous));
        let dynamics = robot.leg_dynamics();
        let data = Data::new(&dynamics.model);
        Ok(PyLegModel { robot, parts, dynamics, data })
    }

    /// The constants of `joint` (one of the robot's joint names: "q_r", "q_v", "q_h" on AMRU5,
    /// "coxa", "femur", "tibia" on the PhantomX) of `leg` the identification needs, SI joint
    /// units: `torque_per_ampere` (n k_t, Eq. 5.17), `encoder_resolution` (rad or m per count
    /// of the position sensor: a motor encoder, or a servo's own sensor), `resistance` (coil
    /// and H-bridge, Ω), `nominal_voltage` (V, the robot's motors'), `lower` and `upper` (the
    /// joint's range), and the friction as the
    /// simulation uses it with `friction = "dry_viscous"` (Eq. 6.1, the description's friction
    /// after the Section 6.1 rules): `tau_f_d_plus`, `tau_f_d_minus`, `f_v_plus`, `f_v_minus`.
    /// A pantograph robot adds `tau_f_s_plus`, `tau_f_s_minus` (Table 5.4) and, for q_h,
    /// `a_2_plus`, `a_1_plus`, `a_2_minus`, `a_1_minus` (Eq. 5.12); a serial drive has one dry
    /// friction and one viscous slope for both senses and neither stiction nor load
    /// dependence.
    fn joint<'py>(&self, py: Python<'py>, leg: usize, joint: &str) -> PyResult<Bound<'py, PyDict>> {
        check_leg(leg)?;
        let names = self.robot.joints();
        let j = names.position(joint).ok_or_else(|| {
            let allowed: Vec<String> = names.names().map(|n| format!("{n:?}")).collect();
            PyValueError::new_err(format!("joint = {joint:?}: allowed {}", allowed.join(", ")))
        })?;
        let k = 3 * leg + j;
        let motor = &self.parts.motors[k];
        let (lower, upper) = self.robot.joint_range(k);
        let JointFriction::DryViscous(law) = &self.parts.friction[k].law else { unreachable!("the parts are built with dry/viscous friction") };
        let out = PyDict::new(py);
        for (name, v) in [
            ("torque_per_ampere", motor.k_t * motor.n),
            ("encoder_resolution", self.parts.encoders[k].resolution()),
            ("resistance", motor.r + motor.r_bridge),
            ("nominal_voltage", self.robot.nominal_voltage()),
            ("lower", lower),
            ("upper", upper),
            ("tau_f_d_plus", law.tau_f_d_plus),
            ("tau_f_d_minus", law.tau_f_d_minus),
            ("f_v_plus", law.f_v_plus),
            ("f_v_minus", law.f_v_minus),
        ] {
            out.set_item(name, v)?;
        }
        if let Robot::Pantograph(d) = &self.robot {
            let f = d.friction(leg, PantographJoint::ALL[j]);
            out.set_item("tau_f_s_plus", f.tau_f_s_plus)?;
            out.set_item("tau_f_s_minus", f.tau_f_s_minus)?;
            if let Some(l) = f.load_dependence {
                for (name, v) in [("a_2_plus", l.a_2_plus), ("a_1_plus", l.a_1_plus), ("a_2_minus", l.a_2_minus), ("a_1_minus", l.a_1_minus)] {
                    out.set_item(name, v)?;
                }
            }
        }
        Ok(out)
    }

    /// τ_grav + τ_iner (N x 3: Nm for a revolute joint, N for a prismatic one) of `leg` for the
    /// joint positions, velocities and accelerations `q`, `qd`, `qdd` (each N x 3, columns the
    /// leg's joints in the order of q: q_r q_v q_h on AMRU5), plus the torques balancing a
    /// constant force `foot_force` (N, global frame) on the foot.
    #[pyo3(signature = (leg, q, qd, qdd, foot_force = [0.0, 0.0, 0.0]))]
    fn joint_torques<'py>(
        &mut self,
        py: Python<'py>,
        leg: usize,
        q: PyReadonlyArray2<'py, f64>,
        qd: PyReadonlyArray2<'py, f64>,
        qdd: PyReadonlyArray2<'py, f64>,
        foot_force: [f64; 3],
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        check_leg(leg)?;
        let (q, qd, qdd) = (q.as_array(), qd.as_array(), qdd.as_array());
        let n = q.nrows();
        for (name, a) in [("q", &q), ("qd", &qd), ("qdd", &qdd)] {
            if a.nrows() != n || a.ncols() != 3 {
                return Err(PyValueError::new_err(format!(
                    "{name} has shape {:?}; expected ({n}, 3): columns {}",
                    a.shape(),
                    self.robot.joints().names().collect::<Vec<_>>().join(", ")
                )));
            }
            if let Some(((i, j), x)) = a.indexed_iter().find(|(_, x)| !x.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "{name}[{i}, {j}] = {x} is not finite"
                )));
            }
        }
        let row =
            |a: &numpy::ndarray::ArrayView2<'_, f64>, i: usize| [a[(i, 0)], a[(i, 1)], a[(i, 2)]];
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            out.push(
                self.dynamics.leg_joint_torques(
                    &mut self.data,
                    leg,
                    row(&q, i),
                    row(&qd, i),
                    row(&qdd, i),
                    Vector3::from(foot_force),
                )
                .to_vec(),
            );
        }
        Ok(PyArray2::from_vec2(py, &out)?)
    }
}

fn check_leg(leg: usize) -> PyResult<()> {
    if leg >= LEG_COUNT {
        return Err(PyValueError::new_err(format!("leg = {leg}: allowed 0..{}", LEG_COUNT - 1)));
    }
    Ok(())
}
