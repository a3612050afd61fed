//! `hexadyn._core.run_scenario` and `load_scenario`: scenario files run by the engine, results
//! as numpy arrays with units.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use std::sync::Mutex;

use std::borrow::Cow;

use hexadyn::robot::recorder::TimeSeries;
use hexadyn::scenario::{run_scenario_chunked, run_scenario_until, HeadingSpec, ModelFlags, Override, Record, Scenario, ScenarioError, Summary, SummaryValue};
use hexadyn::physics::Extent;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// Wall time between two checks for signals during a run: Ctrl-C stops a run within this
/// time plus one control period's computation.
const SIGNAL_CHECK_INTERVAL: Duration = Duration::from_millis(50);

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
        return v.extract().map(toml::Value::Integer).map_err(|_| PyValueError::new_err(format!("override {field} = {v}: out of range; allowed: an integer in [{}, {}] (TOML integers are 64-bit) or a float", i64::MIN, i64::MAX)));
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
/// "description", "text" (the scenario TOML text that would run: the file's, or with overrides
/// the effective text, comments dropped and the overrides listed in a header), "duration_s", "period_s" (the control period), "friction", "model" (a dict: "friction", "load_dependence",
/// "inductance"), "control", "robot" (`"amru5"` or the robot file), "lifted_legs", "motions"
/// (their count) and "gait" (None, or in gait mode a dict with "pattern", "period_s",
/// "duty_factor", "cycle", "heading", "vx_m_s" (the forward velocity of a constant heading,
/// else None), "navigation", "clearance_m",
/// "body_height_m" and "changes", their count). `overrides` maps dotted scenario fields to
/// values (`{"model.friction": "dry_viscous"}`). Raises ValueError on an invalid scenario.
#[pyfunction]
#[pyo3(signature = (path, overrides = None))]
pub fn load_scenario<'py>(py: Python<'py>, path: PathBuf, overrides: Option<Bound<'py, PyDict>>) -> PyResult<Bound<'py, PyDict>> {
    let s = load(&path, overrides.as_ref())?;
    let d = PyDict::new(py);
    d.set_item("name", &s.name)?;
    d.set_item("description", &s.description)?;
    d.set_item("text", &s.text)?;
    d.set_item("duration_s", s.duration)?;
    d.set_item("period_s", s.period())?;
    d.set_item("friction", s.model.friction.name())?;
    d.set_item("model", model_dict(py, &s)?)?;
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
            gd.set_item("vx_m_s", match &g.heading {
                HeadingSpec::Constant(h) => Some(h.velocity.x),
                _ => None,
            })?;
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
/// "robot_source" (`"amru5"` or the robot file), "model" (the engine's parsed `[model]` flags:
/// "friction", "load_dependence", "inductance"). `overrides` maps dotted scenario fields to
/// values (see `load_scenario`); the returned "scenario" text is then the effective one. With
/// `timeseries=False` no time series is built and the "columns", "units" and "descriptions" dicts
/// are empty (campaigns that only need the summary).
///
/// With a `chunk` callable the time series is handed out as the run goes instead of returned:
/// `chunk(columns, units)` receives a dict name -> numpy array with the first row alone, then
/// every `chunk_rows` rows, then the rest, and the units (name -> unit) (the "columns" of the result are then empty); the engine
/// never holds more than one chunk. An exception raised by `chunk` stops the run and
/// propagates.
///
/// The simulation runs without the GIL. Every [`SIGNAL_CHECK_INTERVAL`] of wall time (at the
/// first control instant after it) the GIL is taken back to check for signals (Ctrl-C raises
/// KeyboardInterrupt); about every 1 % of the simulated duration (and at the start and the end)
/// `progress(t_s, duration_s)` is called if given; an exception raised by `progress` stops the
/// run and propagates. Raises ValueError with a one-line message for an invalid scenario or a
/// failed simulation.
#[pyfunction]
#[pyo3(signature = (path, progress = None, overrides = None, timeseries = true, chunk = None, chunk_rows = 10_000))]
#[allow(clippy::too_many_arguments)]
pub fn run_scenario<'py>(
    py: Python<'py>,
    path: PathBuf,
    progress: Option<Py<PyAny>>,
    overrides: Option<Bound<'py, PyDict>>,
    timeseries: bool,
    chunk: Option<Py<PyAny>>,
    chunk_rows: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let scenario = load(&path, overrides.as_ref())?;
    let duration = scenario.duration;
    let step = duration / 100.0;
    let mut next_report = 0.0;
    let mut next_signal_check = Instant::now();
    // The first Python error (signal, progress or chunk) stops the run and is raised.
    let python_error: Mutex<Option<PyErr>> = Mutex::new(None);
    let stop_on = |result: PyResult<()>| match result {
        Ok(()) => ControlFlow::Continue(()),
        Err(e) => {
            python_error.lock().expect("not poisoned").get_or_insert(e);
            ControlFlow::Break(())
        }
    };
    let progress_flow = |t: f64| {
        let last = t >= duration - 0.5 * scenario.period();
        let report = t >= next_report || last;
        let now = Instant::now();
        if !report && now < next_signal_check {
            return ControlFlow::Continue(());
        }
        next_signal_check = now + SIGNAL_CHECK_INTERVAL;
        if report {
            next_report = t + step;
        }
        Python::attach(|py| {
            stop_on(py.check_signals().and_then(|()| match (&progress, report) {
                (Some(f), true) => f.call1(py, (t, duration)).map(|_| ()),
                _ => Ok(()),
            }))
        })
    };
    let mut specs: Vec<(String, &'static str, String)> = Vec::new();
    let outcome = match &chunk {
        Some(sink) => py.detach(|| {
            let hand_out = |series: TimeSeries| {
                if specs.is_empty() {
                    specs = series.columns.iter().map(|c| (c.name.clone(), c.unit, c.description.clone())).collect();
                }
                Python::attach(|py| {
                    stop_on(py.check_signals().and_then(|()| {
                        let units = PyDict::new(py);
                        for (name, unit, _) in &specs {
                            units.set_item(name, unit)?;
                        }
                        sink.call1(py, (columns_dict(py, series)?, units)).map(|_| ())
                    }))
                })
            };
            run_scenario_chunked(&scenario, chunk_rows, hand_out, progress_flow).map(|summary| (TimeSeries::default(), summary))
        }),
        None => py.detach(|| {
            let record = if timeseries { Record::TimeSeries } else { Record::SummaryOnly };
            run_scenario_until(&scenario, record, progress_flow).map(|r| (r.series, r.summary))
        }),
    };
    let (series, summary) = match outcome {
        Ok(r) => r,
        Err(e) => return Err(python_error.into_inner().expect("not poisoned").unwrap_or_else(|| value_error(e))),
    };
    if specs.is_empty() {
        specs = series.columns.iter().map(|c| (c.name.clone(), c.unit, c.description.clone())).collect();
    }

    let units = PyDict::new(py);
    let descriptions = PyDict::new(py);
    for (name, unit, description) in &specs {
        units.set_item(name, unit)?;
        descriptions.set_item(name, description)?;
    }
    let d = PyDict::new(py);
    d.set_item("columns", columns_dict(py, series)?)?;
    d.set_item("units", units)?;
    d.set_item("descriptions", descriptions)?;
    d.set_item("summary", summary_dict(py, &summary)?)?;
    d.set_item("scenario", &scenario.text)?;
    d.set_item("robot", &scenario.robot_text)?;
    d.set_item("robot_source", &scenario.robot_source)?;
    d.set_item("model", model_dict(py, &scenario)?)?;
    Ok(d)
}

/// The columns of a time series as a dict name -> numpy array.
fn columns_dict(py: Python<'_>, series: TimeSeries) -> PyResult<Bound<'_, PyDict>> {
    let columns = PyDict::new(py);
    for c in series.columns {
        columns.set_item(&c.name, PyArray1::from_vec(py, c.values))?;
    }
    Ok(columns)
}

fn summary_dict<'py>(py: Python<'py>, summary: &Summary) -> PyResult<Bound<'py, PyDict>> {
    entries_dict(py, summary.entries())
}

/// The summary entries of a run (a simulation's or the robot link's) as a dict.
pub(crate) fn entries_dict<'py>(py: Python<'py>, entries: Vec<(Cow<'static, str>, SummaryValue)>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, value) in entries {
        let name = name.as_ref();
        match value {
            SummaryValue::Text(s) => d.set_item(name, s)?,
            SummaryValue::Count(n) => d.set_item(name, n)?,
            SummaryValue::Number(x) => d.set_item(name, x)?,
            SummaryValue::Flag(b) => d.set_item(name, b)?,
        }
    }
    Ok(d)
}

/// The `[model]` flags as the engine parsed them (Python reads these, never the TOML text).
fn model_dict<'py>(py: Python<'py>, s: &Scenario) -> PyResult<Bound<'py, PyDict>> {
    flags_dict(py, ModelFlags { friction: s.model.friction, load_dependence: s.model.load_dependence, inductance: s.model.inductance })
}

fn flags_dict(py: Python<'_>, flags: ModelFlags) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("friction", flags.friction.name())?;
    d.set_item("load_dependence", flags.load_dependence)?;
    d.set_item("inductance", flags.inductance)?;
    Ok(d)
}

/// The `[model]` flags ("friction", "load_dependence", "inductance") of a scenario text as the
/// engine parses them, without validating the rest of the scenario (results saved before their
/// metadata held the flags). `origin` names the text in errors; raises ValueError.
#[pyfunction]
pub fn scenario_model<'py>(py: Python<'py>, text: &str, origin: &str) -> PyResult<Bound<'py, PyDict>> {
    flags_dict(py, Scenario::model_flags(text, origin).map_err(value_error)?)
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
