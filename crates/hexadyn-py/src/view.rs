//! `hexadyn._core.Kinematics`: the poses of all bodies of a robot and the points of its legs,
//! from recorded joint coordinates, through the model's own multibody kinematics (Eq.
//! 3.51-3.71), vectorized over frames. The viewer (`hexadyn.view`) draws the robot from these,
//! so the legs move exactly as in the simulation: AMRU5's pantograph linkages, or a serial
//! robot's chain of joints and its foot, on the very multibody model the engine simulates.

use hexadyn::description::{Robot, SerialRobot};
use hexadyn::hexapod::{Mechanics, MechanicsParameters, DOF};
use hexadyn::mbs::{kinematics, BodyId, Data, Model};
use nalgebra::Vector3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Names of the points of one pantograph leg returned by `Kinematics.leg_points`, in order.
const PANTOGRAPH_POINTS: [&str; 8] = ["hip", "crossing", "A", "B", "C", "D", "E", "F"];
/// The last point of a serial leg, after its joints' origins.
const SERIAL_FOOT: &str = "foot";

/// The robot whose legs are drawn.
enum Legs {
    Pantograph(Box<Mechanics>),
    Serial(Box<SerialRobot>),
}

#[pyclass(name = "Kinematics", module = "hexadyn._core")]
pub struct PyKinematics {
    legs: Legs,
    /// The multibody model the engine simulates for this robot.
    model: Model,
    data: Data,
    /// Per leg: (body, point in its frame) of each entry of `point_names`.
    leg_points: Vec<Vec<(BodyId, Vector3<f64>)>>,
    point_names: Vec<String>,
}

/// Runs the kinematics for every row of `q` (N x 24) and calls `visit(model, data)`.
fn each_frame(model: &Model, data: &mut Data, q: &PyReadonlyArray2<'_, f64>, mut visit: impl FnMut(&Model, &Data)) -> PyResult<usize> {
    let q = q.as_array();
    if q.ncols() != DOF {
        return Err(PyValueError::new_err(format!("q has {} columns; the robot has {DOF} coordinates (X Y Z yaw pitch roll, then its three joints per leg)", q.ncols())));
    }
    let zero = [0.0; DOF];
    let mut row = [0.0; DOF];
    for (i, r) in q.rows().into_iter().enumerate() {
        for (dst, src) in row.iter_mut().zip(r.iter()) {
            *dst = *src;
        }
        if let Some(j) = row.iter().position(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!("q[{i}, {j}] = {} is not finite", row[j])));
        }
        kinematics(model, data, &row, &zero);
        visit(model, data);
    }
    Ok(q.nrows())
}

/// The points of a pantograph leg (`PANTOGRAPH_POINTS`).
fn pantograph_points(mechanics: &Mechanics) -> Vec<Vec<(BodyId, Vector3<f64>)>> {
    let p = &mechanics.parameters;
    let pg = p.pantograph;
    let [ag0, _, dg2, _] = p.link_cog;
    mechanics
        .legs
        .iter()
        .map(|leg| {
            let [link0, _, link2, link3] = leg.links;
            vec![
                (leg.chassis, -p.chassis_cog),
                (leg.chassis, p.crossing_point),
                (link0, Vector3::new(-ag0, 0.0, 0.0)),
                (link0, Vector3::new(pg.c - ag0, 0.0, 0.0)),
                (link0, Vector3::new(pg.l0 - ag0, 0.0, 0.0)),
                (link2, Vector3::new(-dg2, 0.0, 0.0)),
                (link2, Vector3::new(pg.l2 - dg2, 0.0, 0.0)),
                (link3, mechanics.foot_local),
            ]
        })
        .collect()
}

/// The points of a serial leg: each joint's origin (the origin of the link frame it moves,
/// which sits at minus the link's centre of mass in the link's body), then the foot centre.
fn serial_points(robot: &SerialRobot, links: &[[BodyId; 3]; 6], feet: &[(BodyId, Vector3<f64>); 6]) -> Vec<Vec<(BodyId, Vector3<f64>)>> {
    robot
        .hexapod
        .legs
        .iter()
        .zip(links.iter().zip(feet))
        .map(|(leg, (bodies, foot))| {
            let mut points: Vec<_> = leg.links.iter().zip(bodies).map(|(link, body)| (*body, -link.com)).collect();
            points.push(*foot);
            points
        })
        .collect()
}

#[pymethods]
impl PyKinematics {
    /// Builds the multibody model of a robot description (TOML text, pantograph or serial legs;
    /// `origin` names it in errors): the model the engine simulates for it.
    #[new]
    #[pyo3(signature = (robot_text, origin = "robot description"))]
    fn new(robot_text: &str, origin: &str) -> PyResult<Self> {
        let robot = Robot::from_str(robot_text, origin).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let (legs, model, leg_points, point_names) = match &robot {
            Robot::Pantograph(description) => {
                let parameters = MechanicsParameters::from_description(description);
                let mechanics = Mechanics::new(&parameters).map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
                let points = pantograph_points(&mechanics);
                let model = mechanics.model.clone();
                (Legs::Pantograph(Box::new(mechanics)), model, points, PANTOGRAPH_POINTS.iter().map(|s| s.to_string()).collect())
            }
            Robot::Serial(serial) => {
                // The model of `SerialRobot::parts`: the links with the motor rotors.
                let mechanics = serial.hexapod.mechanics_with(&serial.rotors()).map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
                let points = serial_points(serial, &mechanics.links, &mechanics.feet);
                let mut names: Vec<String> = serial.joints.names().map(str::to_string).collect();
                names.push(SERIAL_FOOT.to_string());
                (Legs::Serial(Box::new(serial.clone())), mechanics.model, points, names)
            }
        };
        let data = Data::new(&model);
        Ok(PyKinematics { legs, model, data, leg_points, point_names })
    }

    /// "pantograph" (AMRU5's legs) or "serial".
    #[getter]
    fn leg_mechanism(&self) -> &'static str {
        match self.legs {
            Legs::Pantograph(_) => "pantograph",
            Legs::Serial(_) => "serial",
        }
    }

    /// The body names, in the order of the body axis of `poses` ("body", "leg0.chassis", ... on
    /// AMRU5; "base", "leg0.<joint>" per link and "leg0.<joint>.rotor" per motor rotor on a
    /// serial robot, <joint> the description's joint name, e.g. "coxa_lf").
    #[getter]
    fn body_names(&self) -> Vec<String> {
        (0..self.model.body_count()).map(|b| self.model.body_name(BodyId(b)).to_string()).collect()
    }

    /// The names of the points of one leg in `leg_points`. AMRU5: hip (q_r axis at the body),
    /// crossing point C*, then the pantograph joints A, B, C, D, E and the foot F (NOTES.md). A
    /// serial robot: its joint names (the origin of each joint, e.g. "coxa", "femur", "tibia"),
    /// then "foot" (the centre of the foot sphere).
    #[getter]
    fn leg_point_names(&self) -> Vec<String> {
        self.point_names.clone()
    }

    /// Geometry for drawing (SI). Both mechanisms: "leg_mechanism", "mass_kg" (the model's,
    /// which sizes what is drawn at the robot's scale). AMRU5: leg angles, R_rot, pantograph lengths l0
    /// l1 l2 l3 c, link centres of gravity along their axes, chassis offsets. A serial robot:
    /// "mounts" (6 x 3, the first joint's origin of each leg in the frame of the "base" body,
    /// which sits at the base link's centre of mass), "foot_radius", "leg_joint_names" (6 x 3,
    /// the description's names of each leg's joints).
    #[getter]
    fn geometry<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("leg_mechanism", self.leg_mechanism())?;
        d.set_item("mass_kg", self.model.total_mass())?;
        match &self.legs {
            Legs::Pantograph(mechanics) => {
                let p = &mechanics.parameters;
                d.set_item("leg_angles", p.leg_angles.to_vec())?;
                d.set_item("r_rot", p.r_rot)?;
                let pg = p.pantograph;
                d.set_item("l0", pg.l0)?;
                d.set_item("l1", pg.l1)?;
                d.set_item("l2", pg.l2)?;
                d.set_item("l3", pg.l3)?;
                d.set_item("c", pg.c)?;
                d.set_item("link_cog", p.link_cog.to_vec())?;
                d.set_item("chassis_cog", p.chassis_cog.as_slice().to_vec())?;
                d.set_item("crossing_point", p.crossing_point.as_slice().to_vec())?;
                d.set_item("foot_local", mechanics.foot_local.as_slice().to_vec())?;
            }
            Legs::Serial(robot) => {
                let h = &robot.hexapod;
                let mounts: Vec<Vec<f64>> = h.legs.iter().map(|leg| (leg.joints[0].origin.translation - h.base.com).as_slice().to_vec()).collect();
                d.set_item("mounts", mounts)?;
                d.set_item("foot_radius", h.legs[0].foot_radius)?;
                let names: Vec<Vec<String>> = h.legs.iter().map(|leg| leg.joints.iter().map(|j| j.name.clone()).collect()).collect();
                d.set_item("leg_joint_names", names)?;
            }
        }
        Ok(d)
    }

    /// World poses of all bodies for each row of q (N x 24): positions (N, B, 3) and rotation
    /// matrices (N, B, 3, 3), body frame to world.
    fn poses<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let b = self.model.body_count();
        let mut positions = Vec::with_capacity(q.as_array().nrows() * b * 3);
        let mut rotations = Vec::with_capacity(q.as_array().nrows() * b * 9);
        let n = each_frame(&self.model, &mut self.data, &q, |model, data| {
            for body in 0..model.body_count() {
                let pose = data.pose(BodyId(body));
                positions.extend_from_slice(pose.translation.as_slice());
                // nalgebra is column-major: the transpose's storage is the C-ordered (3, 3) block.
                rotations.extend_from_slice(pose.rotation.transpose().as_slice());
            }
        })?;
        let positions = PyArray1::from_vec(py, positions).reshape([n, b, 3])?.into_any();
        let rotations = PyArray1::from_vec(py, rotations).reshape([n, b, 3, 3])?.into_any();
        Ok((positions, rotations))
    }

    /// World positions of the points of every leg for each row of q (N x 24): (N, 6, P, 3), the
    /// P points named by `leg_point_names` (8 on AMRU5, 4 on a serial robot); the foot last.
    fn leg_points<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        let legs = &self.leg_points;
        let per_leg = self.point_names.len();
        let mut out = Vec::with_capacity(q.as_array().nrows() * legs.len() * per_leg * 3);
        let n = each_frame(&self.model, &mut self.data, &q, |_, data| {
            for leg in legs {
                for (body, local) in leg {
                    out.extend_from_slice(data.point(*body, local).as_slice());
                }
            }
        })?;
        Ok(PyArray1::from_vec(py, out).reshape([n, legs.len(), per_leg, 3])?.into_any())
    }
}
