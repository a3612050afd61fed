//! `hexadyn._core.UrdfHexapod`: a serial hexapod read from URDF (`description::urdf`), as the
//! multibody system hexadyn simulates: a [`PyMultibody`] (mass matrix, nonlinear effects,
//! gravity forces, kinetic energy) with the legs' joint names, feet and foot Jacobians.

use hexadyn::description::urdf::serial_hexapod_from_urdf;
use hexadyn::hexapod::{SerialHexapod, DOF};
use numpy::{PyArray2, PyArray3, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::mbs::PyMultibody;

#[pyclass(extends = PyMultibody, name = "UrdfHexapod", module = "hexadyn._core")]
pub struct PyUrdfHexapod {
    robot: SerialHexapod,
    feet: [(hexadyn::mbs::BodyId, nalgebra::Vector3<f64>); 6],
}

#[pymethods]
impl PyUrdfHexapod {
    /// UrdfHexapod(text, origin="URDF"): the robot of a URDF text (`origin` names it in
    /// errors); ValueError with one line naming the file, the element and what is allowed.
    #[new]
    #[pyo3(signature = (text, origin = "URDF"))]
    fn new(text: &str, origin: &str) -> PyResult<PyClassInitializer<Self>> {
        let robot = serial_hexapod_from_urdf(text, origin).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let mechanics = robot.mechanics().map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
        let feet = mechanics.feet;
        Ok(PyClassInitializer::from(PyMultibody::of(mechanics.model)).add_subclass(PyUrdfHexapod { robot, feet }))
    }

    /// The robot's name (`<robot name>`).
    #[getter]
    fn name(&self) -> String {
        self.robot.name.clone()
    }

    /// The URDF names of the 18 actuated joints in the order of q[6:] (leg 0's three, leg 1's, ...).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.robot.legs.iter().flat_map(|l| l.joints.iter().map(|j| j.name.clone())).collect()
    }

    /// The radius of each foot's contact sphere (m).
    #[getter]
    fn foot_radii(&self) -> Vec<f64> {
        self.robot.legs.iter().map(|l| l.foot_radius).collect()
    }

    /// The centre of each foot sphere in the world frame at q, a (6, 3) array (m).
    fn feet<'py>(mut self_: PyRefMut<'py, Self>, q: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let feet = self_.feet;
        let base = self_.as_super();
        base.evaluate(q.as_slice()?, &[0.0; DOF])?;
        let rows: Vec<Vec<f64>> = feet.iter().map(|(b, local)| base.data().point(*b, local).iter().copied().collect()).collect();
        Ok(PyArray2::from_vec2(self_.py(), &rows)?)
    }

    /// ∂p_foot/∂q of each foot centre, a (6, 3, 24) array: the velocity of foot f is
    /// `jacobians[f] @ qd` (the point's partial velocities, Section 3.3.3).
    fn foot_jacobians<'py>(mut self_: PyRefMut<'py, Self>, q: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let feet = self_.feet;
        let base = self_.as_super();
        base.evaluate(q.as_slice()?, &[0.0; DOF])?;
        let mut j = vec![vec![vec![0.0; DOF]; 3]; feet.len()];
        for (f, (b, local)) in feet.iter().enumerate() {
            let p = base.data().point(*b, local);
            for (c, column) in base.data().point_partial_velocities(base.model(), *b, &p) {
                for r in 0..3 {
                    j[f][r][c] += column[r];
                }
            }
        }
        Ok(PyArray3::from_vec3(self_.py(), &j)?)
    }
}
