//! `hexadyn._core.Multibody`: a minimal-coordinates multibody system described from Python,
//! with its mass matrix (Eq. 3.39), nonlinear effects (Eq. 3.40) and gravity forces (Eq. 3.41).

use hexadyn::mbs::{self, BodyId, BodySpec, Data, Elementary, Model, ModelBuilder, Var};
use hexadyn::spatial::Htm;
use nalgebra::{DMatrix, Matrix3, Vector3};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, ToPyArray};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

#[pyclass(subclass, name = "Multibody", module = "hexadyn._core")]
pub struct PyMultibody {
    model: Model,
    data: Data,
}

fn err(body: usize, what: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("bodies[{body}]: {what}"))
}

fn axis_of(name: &str) -> Option<(bool, Vector3<f64>)> {
    let axis = match &name[1..] {
        "x" => Vector3::x(),
        "y" => Vector3::y(),
        "z" => Vector3::z(),
        _ => return None,
    };
    match &name[..1] {
        "r" => Some((true, axis)),
        "t" => Some((false, axis)),
        _ => None,
    }
}

/// One joint element: ("offset", [x, y, z]), ("rotation", [ax, ay, az], angle) or
/// ("rx" | "ry" | "rz" | "tx" | "ty" | "tz", coordinate[, scale[, offset]]).
fn elementary(body: usize, item: &Bound<'_, PyAny>) -> PyResult<Elementary> {
    let t = item.cast::<PyTuple>().map_err(|_| err(body, "each joint element must be a tuple"))?;
    let kind: String = t.get_item(0)?.extract()?;
    match kind.as_str() {
        "offset" => {
            let v: [f64; 3] = t.get_item(1)?.extract()?;
            Ok(Elementary::offset(v[0], v[1], v[2]))
        }
        "rotation" => {
            let a: [f64; 3] = t.get_item(1)?.extract()?;
            let angle: f64 = t.get_item(2)?.extract()?;
            let axis = Vector3::from(a);
            if (axis.norm() - 1.0).abs() > 1e-12 {
                return Err(err(body, format!("rotation axis {a:?} must be a unit vector")));
            }
            Ok(Elementary::Fixed(Htm::rotation(&axis, angle)))
        }
        other => {
            let (rotation, axis) = if other.len() == 2 { axis_of(other) } else { None }
                .ok_or_else(|| err(body, format!("unknown joint element {other:?}; allowed: offset, rotation, rx, ry, rz, tx, ty, tz")))?;
            let j: usize = t.get_item(1)?.extract()?;
            let scale: f64 = if t.len() > 2 { t.get_item(2)?.extract()? } else { 1.0 };
            let offset: f64 = if t.len() > 3 { t.get_item(3)?.extract()? } else { 0.0 };
            let var = Var::q(j).scaled(scale).plus(offset);
            Ok(if rotation { Elementary::Rotation { axis, var } } else { Elementary::Translation { axis, var } })
        }
    }
}

impl PyMultibody {
    /// The Python object of a model built in the engine.
    pub(crate) fn of(model: Model) -> Self {
        let data = Data::new(&model);
        PyMultibody { model, data }
    }
    pub(crate) fn model(&self) -> &Model {
        &self.model
    }
    pub(crate) fn data(&self) -> &Data {
        &self.data
    }

    fn check(&self, name: &str, v: &[f64]) -> PyResult<()> {
        let n = self.model.coordinate_count();
        if v.len() != n {
            return Err(PyValueError::new_err(format!("{name} has {} entries; the model has {n} coordinates", v.len())));
        }
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!("{name}[{i}] = {} is not finite", v[i])));
        }
        Ok(())
    }
    pub(crate) fn evaluate(&mut self, q: &[f64], qd: &[f64]) -> PyResult<()> {
        self.check("q", q)?;
        self.check("qd", qd)?;
        mbs::kinematics(&self.model, &mut self.data, q, qd);
        self.data.clear_forces();
        Ok(())
    }

    /// The world positions at q of the `points` (a body and a point in its frame), one row each.
    pub(crate) fn points_at(&mut self, q: &[f64], points: &[(BodyId, Vector3<f64>)]) -> PyResult<Vec<Vec<f64>>> {
        self.evaluate(q, &vec![0.0; q.len()])?;
        Ok(points.iter().map(|(b, local)| self.data.point(*b, local).iter().copied().collect()).collect())
    }
}

#[pymethods]
impl PyMultibody {
    /// Multibody(coordinates, bodies, gravity=(0, 0, -9.81)); each body is a dict with name,
    /// parent (index or None), joint (list of elements), mass and inertia (3x3, central, body frame).
    #[new]
    #[pyo3(signature = (coordinates, bodies, gravity = [0.0, 0.0, -9.81]))]
    fn new(coordinates: usize, bodies: &Bound<'_, PyList>, gravity: [f64; 3]) -> PyResult<Self> {
        let mut b = ModelBuilder::new(coordinates).gravity(Vector3::from(gravity));
        for (i, item) in bodies.iter().enumerate() {
            let d = item.cast::<PyDict>().map_err(|_| err(i, "must be a dict"))?;
            let get = |key: &str| d.get_item(key)?.ok_or_else(|| err(i, format!("missing key {key:?}")));
            let parent: Option<usize> = get("parent")?.extract()?;
            let joint = get("joint")?.cast::<PyList>().map_err(|_| err(i, "joint must be a list"))?.iter().map(|e| elementary(i, &e)).collect::<PyResult<Vec<_>>>()?;
            let inertia: [[f64; 3]; 3] = get("inertia")?.extract()?;
            let spec = BodySpec {
                name: get("name")?.extract()?,
                parent: parent.map(BodyId),
                joint,
                mass: get("mass")?.extract()?,
                inertia: Matrix3::from_fn(|r, c| inertia[r][c]),
            };
            b.add_body(spec).map_err(|e| err(i, e))?;
        }
        Ok(PyMultibody::of(b.build()))
    }

    #[getter]
    fn coordinates(&self) -> usize {
        self.model.coordinate_count()
    }

    /// M(q), Eq. 3.39.
    fn mass_matrix<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = q.as_slice()?.to_vec();
        let zero = vec![0.0; q.len()];
        self.evaluate(&q, &zero)?;
        let n = self.model.coordinate_count();
        let mut m = DMatrix::zeros(n, n);
        mbs::mass_matrix(&self.model, &self.data, &mut m);
        Ok(PyArray2::from_vec2(py, &(0..n).map(|r| m.row(r).iter().copied().collect()).collect::<Vec<Vec<f64>>>())?)
    }

    /// h(q, q'), Eq. 3.40 (centrifugal and Coriolis terms).
    fn nonlinear_effects<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray1<'py, f64>, qd: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.evaluate(q.as_slice()?, qd.as_slice()?)?;
        Ok(mbs::nonlinear_effects(&self.model, &self.data).to_pyarray(py))
    }

    /// g(q) with gravity as the only applied force, Eq. 3.41.
    fn gravity_forces<'py>(&mut self, py: Python<'py>, q: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = q.as_slice()?.to_vec();
        self.evaluate(&q, &vec![0.0; q.len()])?;
        Ok(mbs::generalized_forces(&self.model, &self.data).to_pyarray(py))
    }

    /// Kinetic energy at (q, q').
    fn kinetic_energy(&mut self, q: PyReadonlyArray1<'_, f64>, qd: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
        self.evaluate(q.as_slice()?, qd.as_slice()?)?;
        Ok(mbs::kinetic_energy(&self.model, &self.data))
    }
}
