//! `hexadyn._core.PantographHexapod`: a pantograph robot description (AMRU5's legs) as the
//! multibody system hexadyn simulates (a [`PyMultibody`]: mass matrix, gravity forces, ...),
//! with its MJCF export (`description::mjcf`: the linkage loops as equality constraints) and
//! the map from its 24 coordinates to MuJoCo's.

use hexadyn::description::mjcf::{pantograph_hexapod_to_mjcf, pantograph_mujoco_state, serial_hexapod_to_mjcf};
use hexadyn::description::Robot;
use hexadyn::hexapod::{LegJoints, Mechanics, MechanicsParameters, DOF};
use hexadyn::mbs::{BodyId, STANDARD_GRAVITY};
use nalgebra::Vector3;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, ToPyArray};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::mbs::PyMultibody;

#[pyclass(extends = PyMultibody, name = "PantographHexapod", module = "hexadyn._core")]
pub struct PyPantographHexapod {
    name: String,
    parameters: MechanicsParameters,
    joints: LegJoints,
    feet: [(BodyId, Vector3<f64>); 6],
}

fn coordinates(q: &PyReadonlyArray1<'_, f64>) -> PyResult<[f64; DOF]> {
    let q = q.as_slice()?;
    q.try_into().map_err(|_| PyValueError::new_err(format!("q has {} entries; allowed: {DOF}", q.len())))
}

#[pymethods]
impl PyPantographHexapod {
    /// PantographHexapod(robot_text, origin="robot description"): the robot of a pantograph
    /// robot description text; ValueError (one line) for an invalid or a serial description.
    #[new]
    #[pyo3(signature = (robot_text, origin = "robot description"))]
    fn new(robot_text: &str, origin: &str) -> PyResult<PyClassInitializer<Self>> {
        let d = crate::schema::pantograph_description(robot_text, origin, "the pantograph model")?;
        let parameters = MechanicsParameters::from_description(&d);
        let mechanics = Mechanics::new(&parameters).map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
        let feet = std::array::from_fn(|leg| (mechanics.legs[leg].links[3], mechanics.foot_local));
        let this = PyPantographHexapod { name: d.name.clone(), parameters, joints: d.joints.names.clone(), feet };
        Ok(PyClassInitializer::from(PyMultibody::of(mechanics.model)).add_subclass(this))
    }

    /// The robot as MuJoCo's MJCF text: the 49 bodies, the pantograph loops as `connect`
    /// equality constraints, the rotors coupled to their joints, the actuated joints named as
    /// hexadyn's columns (`q_r[0]` ...), sites `foot0` ... `foot5`.
    fn to_mjcf(&self) -> String {
        pantograph_hexapod_to_mjcf(&self.parameters, &self.joints, &self.name, 0.0, STANDARD_GRAVITY)
    }

    /// (qpos, G) of MuJoCo's model at hexadyn's coordinates q: qpos the free joint's position
    /// and quaternion then the ten joints of each leg, G (66, 24) with MuJoCo's qvel = G q'.
    /// ValueError when a leg's linkage does not close at q.
    fn mujoco_state<'py>(&self, py: Python<'py>, q: PyReadonlyArray1<'py, f64>) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
        let q = coordinates(&q)?;
        let (qpos, g) = pantograph_mujoco_state(&self.parameters, &q).ok_or_else(|| PyValueError::new_err("q: a leg's pantograph does not close (|A D| outside |c - l1|, c + l1); allowed: q_v, q_h where it closes"))?;
        Ok((qpos.to_pyarray(py), PyArray2::from_vec2(py, &g.row_iter().map(|r| r.iter().copied().collect()).collect::<Vec<Vec<f64>>>())?))
    }

    /// The foot F of each leg in the world frame at q, a (6, 3) array (m).
    fn feet<'py>(mut self_: PyRefMut<'py, Self>, q: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let feet = self_.feet;
        let rows = self_.as_super().points_at(q.as_slice()?, &feet)?;
        Ok(PyArray2::from_vec2(self_.py(), &rows)?)
    }
}

/// The MJCF of a robot description of either leg mechanism (what `hexadyn export-mjcf`
/// writes): a serial robot's links, a pantograph robot's bodies with its loops as equality
/// constraints (`description::mjcf`); `origin` names the description in errors. ValueError (one
/// line) for an invalid description.
#[pyfunction]
#[pyo3(signature = (text, origin = "robot description"))]
pub fn robot_mjcf(text: &str, origin: &str) -> PyResult<String> {
    Ok(match Robot::from_str(text, origin).map_err(|e| PyValueError::new_err(e.to_string()))? {
        Robot::Serial(s) => serial_hexapod_to_mjcf(&s.hexapod, STANDARD_GRAVITY),
        Robot::Pantograph(d) => pantograph_hexapod_to_mjcf(&MechanicsParameters::from_description(&d), &d.joints.names, &d.name, 0.0, STANDARD_GRAVITY),
    })
}
