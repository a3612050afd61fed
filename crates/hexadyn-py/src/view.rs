//! `hexadyn._core.Kinematics`: the poses of all bodies of a robot and the points of its
//! pantograph linkages, from recorded joint coordinates, through the model's own multibody
//! kinematics (Eq. 3.51-3.71), vectorized over frames. The viewer (`hexadyn.view`) draws the
//! robot from these, so the legs move exactly as in the simulation.

use hexadyn::hexapod::{Mechanics, MechanicsParameters, DOF};
use hexadyn::mbs::{kinematics, BodyId, Data};
use nalgebra::Vector3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Names of the points of one leg returned by `Kinematics.leg_points`, in order.
const LEG_POINTS: [&str; 8] = ["hip", "crossing", "A", "B", "C", "D", "E", "F"];

#[pyclass(name = "Kinematics", module = "hexadyn._core")]
pub struct PyKinematics {
    mechanics: Mechanics,
    data: Data,
    /// Per leg: (body, point in its frame) of each entry of `LEG_POINTS`.
    leg_points: Vec<[(BodyId, Vector3<f64>); 8]>,
}

impl PyKinematics {
    /// Runs the kinematics for every row of `q` (N x 24) and calls `visit(frame, data)`.
    fn each_frame(&mut self, q: &PyReadonlyArray2<'_, f64>, mut visit: impl FnMut(&Mechanics, &Data)) -> PyResult<usize> {
        let q = q.as_array();
        if q.ncols() != DOF {
            return Err(PyValueError::new_err(format!("q has {} columns; the robot has {DOF} coordinates (X Y Z yaw pitch roll, then q_r q_v q_h per leg)", q.ncols())));
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
            kinematics(&self.mechanics.model, &mut self.data, &row, &zero);
            visit(&self.mechanics, &self.data);
        }
        Ok(q.nrows())
    }
}

#[pymethods]
impl PyKinematics {
    /// Builds the mechanics of a robot description (TOML text; `origin` names it in errors).
    #[new]
    #[pyo3(signature = (robot_text, origin = "robot description"))]
    fn new(robot_text: &str, origin: &str) -> PyResult<Self> {
        let description = crate::schema::pantograph_description(robot_text, origin, "the 3D viewer")?;
        let parameters = MechanicsParameters::from_description(&description);
        let mechanics = Mechanics::new(&parameters).map_err(|e| PyValueError::new_err(format!("{origin}: {e}")))?;
        let p = &mechanics.parameters;
        let pg = p.pantograph;
        let [ag0, _, dg2, _] = p.link_cog;
        let leg_points = mechanics
            .legs
            .iter()
            .map(|leg| {
                let [link0, _, link2, link3] = leg.links;
                [
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
            .collect();
        let data = Data::new(&mechanics.model);
        Ok(PyKinematics { mechanics, data, leg_points })
    }

    /// The body names, in the order of the body axis of `poses` ("body", "leg0.chassis", ...).
    #[getter]
    fn body_names(&self) -> Vec<String> {
        let model = &self.mechanics.model;
        (0..model.body_count()).map(|b| model.body_name(BodyId(b)).to_string()).collect()
    }

    /// The names of the points of one leg in `leg_points`: hip (q_r axis at the body), crossing
    /// point C*, then the pantograph joints A, B, C, D, E and the foot F (NOTES.md).
    #[getter]
    fn leg_point_names(&self) -> Vec<&'static str> {
        LEG_POINTS.to_vec()
    }

    /// Geometry for drawing (SI): leg angles, R_rot, pantograph lengths l0 l1 l2 l3 c, link
    /// centres of gravity along their axes, chassis offsets.
    #[getter]
    fn geometry<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.mechanics.parameters;
        let d = PyDict::new(py);
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
        d.set_item("foot_local", self.mechanics.foot_local.as_slice().to_vec())?;
        Ok(d)
    }

    /// World poses of all bodies for each row of q (N x 24): positions (N, B, 3) and rotation
    /// matrices (N, B, 3, 3), body frame to world.
    fn poses<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let b = self.mechanics.model.body_count();
        let mut positions = Vec::with_capacity(q.as_array().nrows() * b * 3);
        let mut rotations = Vec::with_capacity(q.as_array().nrows() * b * 9);
        let n = self.each_frame(&q, |m, data| {
            for body in 0..m.model.body_count() {
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

    /// World positions of the points of every leg for each row of q (N x 24): (N, 6, 8, 3), the
    /// points named by `leg_point_names`.
    fn leg_points<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        let legs = self.leg_points.clone();
        let mut out = Vec::with_capacity(q.as_array().nrows() * legs.len() * LEG_POINTS.len() * 3);
        let n = self.each_frame(&q, |_, data| {
            for leg in &legs {
                for (body, local) in leg {
                    out.extend_from_slice(data.point(*body, local).as_slice());
                }
            }
        })?;
        Ok(PyArray1::from_vec(py, out).reshape([n, legs.len(), LEG_POINTS.len(), 3])?.into_any())
    }
}
