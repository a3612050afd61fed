//! `hexadyn._core.UrdfHexapod`: a serial hexapod read from URDF (`description::urdf`), as the
//! multibody system hexadyn simulates: a [`PyMultibody`] (mass matrix, nonlinear effects,
//! gravity forces, kinetic energy) with the legs' joint names, feet and foot Jacobians.

use hexadyn::description::mjcf::serial_hexapod_to_mjcf;
use hexadyn::description::Robot;
use hexadyn::description::urdf::{serial_hexapod_from_file, serial_hexapod_from_urdf, UrdfError};
use hexadyn::hexapod::{Leg, LegChain, SerialHexapod, SerialLegKinematics, DOF, LEG_COUNT};
use nalgebra::Vector3;
use numpy::{PyArray1, PyArray2, PyArray3, PyReadonlyArray1, ToPyArray};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::mbs::PyMultibody;

#[pyclass(extends = PyMultibody, name = "UrdfHexapod", module = "hexadyn._core")]
pub struct PyUrdfHexapod {
    robot: SerialHexapod,
    feet: [(hexadyn::mbs::BodyId, Vector3<f64>); 6],
    legs: [SerialLegKinematics; 6],
}

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

impl PyUrdfHexapod {
    fn build(robot: Result<SerialHexapod, UrdfError>, origin: &str) -> PyResult<PyClassInitializer<Self>> {
        let robot = robot.map_err(value_error)?;
        let mechanics = robot.mechanics().map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
        let legs = SerialLegKinematics::hexapod(&robot.legs).map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
        let feet = mechanics.feet;
        Ok(PyClassInitializer::from(PyMultibody::of(mechanics.model)).add_subclass(PyUrdfHexapod { robot, feet, legs }))
    }

    fn leg(&self, leg: usize) -> PyResult<&SerialLegKinematics> {
        self.legs.get(leg).ok_or_else(|| PyValueError::new_err(format!("leg = {leg}: allowed 0..{}", LEG_COUNT - 1)))
    }
}

fn vector3(name: &str, v: &[f64]) -> PyResult<Vector3<f64>> {
    match v {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vector3::new(*x, *y, *z)),
        _ => Err(PyValueError::new_err(format!("{name} = {v:?}: allowed three finite numbers"))),
    }
}

#[pymethods]
impl PyUrdfHexapod {
    /// UrdfHexapod(text, origin="URDF"): the robot of a URDF text (`origin` names it in
    /// errors); ValueError with one line naming the file, the element and what is allowed.
    #[new]
    #[pyo3(signature = (text, origin = "URDF"))]
    fn new(text: &str, origin: &str) -> PyResult<PyClassInitializer<Self>> {
        Self::build(serial_hexapod_from_urdf(text, origin), origin)
    }

    /// UrdfHexapod.from_file(path): the robot of a URDF file.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Py<Self>> {
        let origin = path.display().to_string();
        Py::new(py, Self::build(serial_hexapod_from_file(&path), &origin)?)
    }

    /// Each leg, in the numbering of q: a dict with `joints` (URDF names), `kinds`
    /// ("revolute" or "prismatic"), `lower` and `upper` (rad or m), `link_masses` (kg, each link
    /// with the links fixed to it), `foot_radius` (m) and `body_from_leg` (4 x 4 T_{b,l}: the leg
    /// frame at the first joint with z_l = z_b, Eq. 7.10).
    #[getter]
    fn legs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.robot.legs.iter().zip(&self.legs).map(|(leg, kin)| {
            let d = PyDict::new(py);
            d.set_item("joints", leg.joints.iter().map(|j| j.name.clone()).collect::<Vec<_>>())?;
            d.set_item("kinds", leg.joints.iter().map(|j| j.kind.name()).collect::<Vec<_>>())?;
            d.set_item("lower", leg.joints.iter().map(|j| j.lower).collect::<Vec<_>>())?;
            d.set_item("upper", leg.joints.iter().map(|j| j.upper).collect::<Vec<_>>())?;
            d.set_item("link_masses", leg.links.iter().map(|l| l.mass).collect::<Vec<_>>())?;
            d.set_item("foot_radius", leg.foot_radius)?;
            let t = kin.body_from_leg();
            let rows: Vec<Vec<f64>> = (0..4).map(|r| (0..4).map(|c| match (r, c) { (3, 3) => 1.0, (3, _) => 0.0, (_, 3) => t.translation[r], _ => t.rotation[(r, c)] }).collect()).collect();
            d.set_item("body_from_leg", PyArray2::from_vec2(py, &rows)?)?;
            Ok(d)
        }).collect()
    }

    /// The robot as MuJoCo's MJCF text (`description::mjcf`): the same bodies, joints, ranges,
    /// inertias, foot spheres (sites `foot0` ... `foot5`) and gravity, joints in the order of q.
    fn to_mjcf(&self) -> String {
        serial_hexapod_to_mjcf(&self.robot, hexadyn::mbs::STANDARD_GRAVITY)
    }

    /// A serial robot description of this robot (`docs/robot-format.md`) with the per-leg
    /// joint names `joint_names` and the drives, controller and ground of the serial robot
    /// description `template` (`origin` names it in errors), read back by the engine before it
    /// is returned: what `hexadyn import-urdf` writes. ValueError (one line) for a template that
    /// is not a valid serial description or bad names.
    fn description_toml(&self, joint_names: [String; 3], template: &str, origin: &str) -> PyResult<String> {
        let Robot::Serial(drives) = Robot::from_str(template, origin).map_err(value_error)? else {
            return Err(PyValueError::new_err(format!("{origin}: a pantograph description; allowed: a serial robot description (leg_mechanism = \"serial\") whose drives to use")));
        };
        let robot = drives.with_mechanism(self.robot.clone(), joint_names.clone()).map_err(|e| PyValueError::new_err(format!("joint names {joint_names:?}: {e}; allowed: three distinct identifiers that are not per-leg column names")))?;
        let text = robot.to_toml();
        Robot::from_str(&text, "the imported description").map_err(value_error)?;
        Ok(text)
    }

    /// The base link's mass with the links fixed to it (kg).
    #[getter]
    fn base_mass(&self) -> f64 {
        self.robot.base.mass
    }

    /// k(q) of leg `leg`: its foot centre in the leg frame for its three joints `q`.
    fn foot_in_leg<'py>(&self, py: Python<'py>, leg: usize, q: Vec<f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(self.leg(leg)?.foot(&vector3("q", &q)?).as_slice().to_pyarray(py))
    }

    /// Eq. 7.7 for leg `leg`: joints whose foot is `target` (leg frame) from `start` (default the
    /// middle of the ranges); returns (joints, reached, distance from the target in m).
    #[pyo3(signature = (leg, target, start = None))]
    fn inverse<'py>(&self, py: Python<'py>, leg: usize, target: Vec<f64>, start: Option<Vec<f64>>) -> PyResult<(Bound<'py, PyArray1<f64>>, bool, f64)> {
        let kin = self.leg(leg)?;
        let start = start.map_or(Ok(kin.limits().middle()), |s| vector3("start", &s))?;
        let s = kin.inverse(&vector3("target", &target)?, &start).map_err(value_error)?;
        Ok((s.joints.as_slice().to_pyarray(py), s.is_reached(), s.clamping().map_or(0.0, |c| c.distance)))
    }

    /// The workspace cylinder of leg `leg` for foot heights [z_min, z_max] (leg frame, m,
    /// Section 7.1.1): a dict with `centre` (x, y), `radius`, `z_min`, `z_max`.
    fn workspace<'py>(&self, py: Python<'py>, leg: usize, z_min: f64, z_max: f64) -> PyResult<Bound<'py, PyDict>> {
        let w = self.leg(leg)?.workspace(z_min, z_max).map_err(|e| PyValueError::new_err(format!("leg {leg}: {e}")))?;
        let d = PyDict::new(py);
        d.set_item("centre", (w.centre.x, w.centre.y))?;
        d.set_item("radius", w.radius)?;
        d.set_item("z_min", w.z_min)?;
        d.set_item("z_max", w.z_max)?;
        Ok(d)
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
        let rows = self_.as_super().points_at(q.as_slice()?, &feet)?;
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

/// The text of a shipped robot description (`"amru5"`, `"phantomx"`: the names a scenario's
/// `robot` takes). ValueError for another name.
#[pyfunction]
pub fn shipped_robot_text(name: &str) -> PyResult<&'static str> {
    hexadyn::description::SHIPPED_ROBOTS.iter().find(|(n, _, _)| *n == name).map(|(_, text, _)| *text).ok_or_else(|| {
        let names: Vec<String> = hexadyn::description::SHIPPED_ROBOTS.iter().map(|(n, _, _)| format!("{n:?}")).collect();
        PyValueError::new_err(format!("robot {name:?}: not shipped; allowed: {}", names.join(", ")))
    })
}

/// The URDF of a serial robot description (`SerialRobot::to_urdf`, what `hexadyn export-urdf`
/// writes); `origin` names the description in errors. ValueError (one line) for an invalid or a
/// pantograph description (its closed chains have no URDF form).
#[pyfunction]
#[pyo3(signature = (text, origin = "robot description"))]
pub fn robot_urdf(text: &str, origin: &str) -> PyResult<String> {
    match Robot::from_str(text, origin).map_err(value_error)? {
        Robot::Serial(s) => Ok(s.to_urdf()),
        Robot::Pantograph(d) => Err(PyValueError::new_err(format!("{origin}: robot {:?} has pantograph legs; allowed: a serial robot description (a pantograph's closed chains have no URDF form)", d.name))),
    }
}
