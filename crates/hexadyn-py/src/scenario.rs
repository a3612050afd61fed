//! `hexadyn._core.run_scenario` and `load_scenario`: scenario files run by the engine, results
//! as numpy arrays with units.

use std::ops::ControlFlow;
use std::path::PathBuf;

use hexadyn::scenario::{run_scenario_until, Override, Record, Scenario, ScenarioError, SummaryValue};
use hexadyn::physics::Extent;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// Scenario errors are user errors: one line naming the file, the field, the value and what is
/// allowed.
fn value_error(e: ScenarioError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

pub(crate) fn load(path: &PathBuf, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Scenario> {
    let overrides = match overrides {
        Some(d) => d.iter().map(|(k, v)| {
            let field: String = k.extract().map_err(|_| PyTypeError::new_err(format!("override names are dotted field strings, not {k:?}")))?;
            let value = toml_value(&field, &v)?;
            Ok(Override { field, value })
        }).collect::<PyResult<Vec<_>>>()?,
        None => Vec::new(),
    };
    Scenario::from_file_with(path, &overrides).map_err(value_error)
}

/// A Python value as a TOML value: bool, int, float, str, and lists/tuples or dicts of those.
fn toml_value(field: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        return v.try_iter()?.map(|item| toml_value(field, &item?)).collect::<PyResult<Vec<_>>>().map(toml::Value::Array);
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, item) in d.iter() {
            let key: String = k.extract()?;
            table.insert(key.clone(), toml_value(&format!("{field}.{key}"), &item)?);
        }
        return Ok(toml::Value::Table(table));
    }
    // numpy scalars and other numbers convert through float.
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(PyTypeError::new_err(format!("override {field}: cannot write a {} into a scenario (allowed: bool, int, float, str, lists and dicts of those)", v.get_type().name()?)))
}

/// Reads and validates a scenario file without running it. Returns a dict with "name",
/// "description", "duration_s", "friction", "control", "robot" (`"amru5"` or the robot file),
/// "lifted_legs", "motions" (their count) and "gait" (None, or in gait mode a dict with
/// "pattern", "period_s", "duty_factor", "cycle", "heading", "navigation", "clearance_m",
/// "body_height_m" and "changes", their count). `overrides` maps dotted scenario fields to
/// values (`{"model.friction": "dry_viscous"}`). Raises ValueError on an invalid scenario.
#[pyfunction]
#[pyo3(signature = (path, overrides = None))]
pub fn load_scenario<'py>(py: Python<'py>, path: PathBuf, overrides: Option<Bound<'py, PyDict>>) -> PyResult<Bound<'py, PyDict>> {
    let s = load(&path, overrides.as_ref())?;
    let d = PyDict::new(py);
    d.set_item("name", &s.name)?;
    d.set_item("description", &s.description)?;
    d.set_item("duration_s", s.duration)?;
    d.set_item("friction", s.model.friction.name())?;
    d.set_item("control", s.control.name())?;
    d.set_item("robot", &s.robot_source)?;
    d.set_item("lifted_legs", s.initial.lifted_legs.clone())?;
    d.set_item("motions", s.motions.len())?;
    match &s.gait {
        None => d.set_item("gait", py.None())?,
        Some(g) => {
            let gd = PyDict::new(py);
            gd.set_item("pattern", &g.options.pattern.name)?;
            gd.set_item("period_s", g.options.period)?;
            gd.set_item("duty_factor", g.options.pattern.beta)?;
            gd.set_item("cycle", match g.options.cycle {
                hexadyn::control::gait::pattern::FootCycle::Plain => "plain",
                hexadyn::control::gait::pattern::FootCycle::Enhanced { .. } => "enhanced",
            })?;
            gd.set_item("heading", g.heading.kind())?;
            gd.set_item("navigation", g.navigation)?;
            gd.set_item("clearance_m", g.options.lift)?;
            gd.set_item("body_height_m", g.body_height)?;
            gd.set_item("changes", g.changes.len())?;
            d.set_item("gait", gd)?;
        }
    }
    Ok(d)
}

/// Runs the scenario file at `path` and returns a dict:
/// "columns" (name -> numpy array, one value per control instant, "t" first), "units"
/// (name -> unit), "descriptions" (name -> one line), "summary" (totals and diagnostics),
/// "scenario" (the scenario TOML text), "robot" (the robot description TOML text),
/// "robot_source" (`"amru5"` or the robot file). `overrides` maps dotted scenario fields to
/// values (see `load_scenario`); the returned "scenario" text is then the effective one. With
/// `timeseries=False` no time series is built and the "columns", "units" and "descriptions" dicts
/// are empty (campaigns that only need the summary).
///
/// The simulation runs without the GIL. About every 1 % of the simulated duration (and at the
/// start and the end) the GIL is taken back to check for signals (Ctrl-C raises
/// KeyboardInterrupt) and to call `progress(t_s, duration_s)` if given; an exception raised by
/// `progress` stops the run and propagates. Raises ValueError with a one-line message for an
/// invalid scenario or a failed simulation.
#[pyfunction]
#[pyo3(signature = (path, progress = None, overrides = None, timeseries = true))]
pub fn run_scenario<'py>(py: Python<'py>, path: PathBuf, progress: Option<Py<PyAny>>, overrides: Option<Bound<'py, PyDict>>, timeseries: bool) -> PyResult<Bound<'py, PyDict>> {
    let scenario = load(&path, overrides.as_ref())?;
    let duration = scenario.duration;
    let step = duration / 100.0;
    let mut next_report = 0.0;
    let mut python_error: Option<PyErr> = None;
    let outcome = py.detach(|| {
        let record = if timeseries { Record::TimeSeries } else { Record::SummaryOnly };
        run_scenario_until(&scenario, record, |t| {
            let last = t >= duration - 0.5 * scenario.period();
            if t < next_report && !last {
                return ControlFlow::Continue(());
            }
            next_report = t + step;
            Python::attach(|py| {
                let called = py.check_signals().and_then(|()| match &progress {
                    Some(f) => f.call1(py, (t, duration)).map(|_| ()),
                    None => Ok(()),
                });
                match called {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(e) => {
                        python_error = Some(e);
                        ControlFlow::Break(())
                    }
                }
            })
        })
    });
    let results = match outcome {
        Ok(r) => r,
        Err(ScenarioError::Stopped { .. }) if python_error.is_some() => return Err(python_error.expect("checked")),
        Err(e) => return Err(value_error(e)),
    };

    let columns = PyDict::new(py);
    let units = PyDict::new(py);
    let descriptions = PyDict::new(py);
    for c in results.series.columns {
        units.set_item(&c.name, c.unit)?;
        descriptions.set_item(&c.name, &c.description)?;
        columns.set_item(&c.name, PyArray1::from_vec(py, c.values))?;
    }
    let summary = PyDict::new(py);
    for (name, value) in results.summary.entries() {
        match value {
            SummaryValue::Text(s) => summary.set_item(name, s)?,
            SummaryValue::Count(n) => summary.set_item(name, n)?,
            SummaryValue::Number(x) => summary.set_item(name, x)?,
        }
    }
    let d = PyDict::new(py);
    d.set_item("columns", columns)?;
    d.set_item("units", units)?;
    d.set_item("descriptions", descriptions)?;
    d.set_item("summary", summary)?;
    d.set_item("scenario", &scenario.text)?;
    d.set_item("robot", &scenario.robot_text)?;
    d.set_item("robot_source", &scenario.robot_source)?;
    Ok(d)
}

/// The ground of a scenario as triangles, for drawing: `(vertices, faces)`, numpy arrays of
/// shape (n, 3) (m, float64) and (m, 3) (vertex indices, uint32, counter-clockwise seen from
/// above). A mesh or heightfield gives its own triangles; a plane or a step the square of side
/// 2 `half_width_m` around (`centre_x_m`, `centre_y_m`). Raises ValueError on an invalid
/// scenario.
#[pyfunction]
#[pyo3(signature = (path, overrides = None, half_width_m = 5.0, centre_x_m = 0.0, centre_y_m = 0.0))]
pub fn terrain_triangles<'py>(
    py: Python<'py>,
    path: PathBuf,
    overrides: Option<Bound<'py, PyDict>>,
    half_width_m: f64,
    centre_x_m: f64,
    centre_y_m: f64,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>)> {
    if !(half_width_m.is_finite() && half_width_m > 0.0 && centre_x_m.is_finite() && centre_y_m.is_finite()) {
        return Err(PyValueError::new_err(format!("terrain_triangles: half_width_m = {half_width_m}, centre = ({centre_x_m}, {centre_y_m}); allowed: a finite half width > 0 and a finite centre (m)")));
    }
    let s = load(&path, overrides.as_ref())?;
    let t = s.terrain.triangles(Extent { centre: [centre_x_m, centre_y_m], half_width: half_width_m });
    let vertices = PyArray2::from_vec2(py, &t.vertices.iter().map(|v| v.to_vec()).collect::<Vec<_>>())?;
    let faces = PyArray2::from_vec2(py, &t.faces.iter().map(|f| f.to_vec()).collect::<Vec<_>>())?;
    Ok((vertices, faces))
}
