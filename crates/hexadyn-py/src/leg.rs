//! `hexadyn._core.LegModel`: the joint torques of one leg on a still, level body (Eq. 3.37 on a
//! single leg, `hexadyn::hexapod::LegDynamics::leg_joint_torques`), vectorized over samples. The friction
//! identification removes the gravity contribution with it (Section 5.2.1).

use hexadyn::description::{RobotDescription, AMRU5_TOML};
use hexadyn::description::Robot;
use hexadyn::hexapod::{LegDynamics, PantographJoint, LEG_COUNT};
use hexadyn::mbs::Data;
use nalgebra::Vector3;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[pyclass(name = "LegModel", module = "hexadyn._core")]
pub struct PyLegModel {
    description: RobotDescription,
    dynamics: LegDynamics,
    data: Data,
}

#[pymethods]
impl PyLegModel {
    /// Builds the mechanics of a robot description (TOML text, None for the embedded AMRU5;
    /// `origin` names it in errors).
    #[new]
    #[pyo3(signature = (robot_text = None, origin = "robot description"))]
    fn new(robot_text: Option<&str>, origin: &str) -> PyResult<Self> {
        let description = crate::schema::pantograph_description(robot_text.unwrap_or(AMRU5_TOML), origin, "friction identification")?;
        let dynamics = Robot::Pantograph(description.clone()).leg_dynamics();
        let data = Data::new(&dynamics.model);
        Ok(PyLegModel {
            description,
            dynamics,
            data,
        })
    }

    /// The constants of `joint` (one of the robot's joint names, "q_r", "q_v" or "q_h" on
    /// AMRU5) the identification needs, and the
    /// friction of `leg` as the simulation uses it (after the Section 6.1 rules), SI joint
    /// units: `torque_per_ampere` (n k_t, Eq. 5.17), `encoder_resolution` (rad or m per
    /// count), `resistance` (coil and H-bridge, Ω), `tau_f_d_plus`, `tau_f_d_minus`, `f_v_plus`, `f_v_minus`, `tau_f_s_plus`,
    /// `tau_f_s_minus` and, for q_h, `a_2_plus`, `a_1_plus`, `a_2_minus`, `a_1_minus`.
    fn joint<'py>(&self, py: Python<'py>, leg: usize, joint: &str) -> PyResult<Bound<'py, PyDict>> {
        if leg >= LEG_COUNT {
            return Err(PyValueError::new_err(format!(
                "leg = {leg}: allowed 0..{}",
                LEG_COUNT - 1
            )));
        }
        let d = &self.description;
        let names = &d.joints.names;
        let j = names.position(joint).map(|j| PantographJoint::ALL[j]).ok_or_else(|| {
            let allowed: Vec<String> = names.names().map(|n| format!("{n:?}")).collect();
            PyValueError::new_err(format!("joint = {joint:?}: allowed {}", allowed.join(", ")))
        })?;
        let f = d.friction(leg, j);
        let out = PyDict::new(py);
        out.set_item("torque_per_ampere", d.joint_torque_per_ampere(j))?;
        out.set_item("encoder_resolution", d.encoder_resolution(j))?;
        out.set_item(
            "resistance",
            d.motor.resistance_ohm + d.driver.series_resistance_ohm(),
        )?;
        for (name, v) in [
            ("tau_f_d_plus", f.tau_f_d_plus),
            ("tau_f_d_minus", f.tau_f_d_minus),
            ("f_v_plus", f.f_v_plus),
            ("f_v_minus", f.f_v_minus),
            ("tau_f_s_plus", f.tau_f_s_plus),
            ("tau_f_s_minus", f.tau_f_s_minus),
        ] {
            out.set_item(name, v)?;
        }
        if let Some(l) = f.load_dependence {
            for (name, v) in [
                ("a_2_plus", l.a_2_plus),
                ("a_1_plus", l.a_1_plus),
                ("a_2_minus", l.a_2_minus),
                ("a_1_minus", l.a_1_minus),
            ] {
                out.set_item(name, v)?;
            }
        }
        Ok(out)
    }

    /// τ_grav + τ_iner (N x 3: Nm for q_r, N for q_v and q_h) of `leg` for the joint positions,
    /// velocities and accelerations `q`, `qd`, `qdd` (each N x 3, columns q_r q_v q_h), plus
    /// the torques balancing a constant force `foot_force` (N, global frame) on the foot.
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
        if leg >= LEG_COUNT {
            return Err(PyValueError::new_err(format!(
                "leg = {leg}: allowed 0..{}",
                LEG_COUNT - 1
            )));
        }
        let (q, qd, qdd) = (q.as_array(), qd.as_array(), qdd.as_array());
        let n = q.nrows();
        for (name, a) in [("q", &q), ("qd", &qd), ("qdd", &qdd)] {
            if a.nrows() != n || a.ncols() != 3 {
                return Err(PyValueError::new_err(format!(
                    "{name} has shape {:?}; expected ({n}, 3): columns q_r, q_v, q_h",
                    a.shape()
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
