//! `hexadyn._core.run_scenario` and `load_scenario`: scenario files run by the engine, results
//! as numpy arrays with units.

use std::ops::ControlFlow;
use std::path::PathBuf;

use hexadyn::robot::scenario::{run_scenario_until, Scenario, ScenarioError, SummaryValue};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Scenario errors are user errors: one line naming the file, the field, the value and what is
/// allowed.
fn value_error(e: ScenarioError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn load(path: &PathBuf) -> PyResult<Scenario> {
    Scenario::from_file(path).map_err(value_error)
}

/// Reads and validates a scenario file without running it. Returns a dict with "name",
/// "description", "duration_s", "friction", "control", "robot" (`"amru5"` or the robot file),
/// "lifted_legs", "motions" (their count) and "gait" (None, or in gait mode a dict with
/// "pattern", "period_s", "duty_factor", "cycle", "heading", "navigation", "clearance_m",
/// "body_height_m" and "changes", their count). Raises ValueError on an invalid scenario.
#[pyfunction]
pub fn load_scenario<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let s = load(&path)?;
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
/// "robot_source" (`"amru5"` or the robot file).
///
/// The simulation runs without the GIL. About every 1 % of the simulated duration (and at the
/// start and the end) the GIL is taken back to check for signals (Ctrl-C raises
/// KeyboardInterrupt) and to call `progress(t_s, duration_s)` if given; an exception raised by
/// `progress` stops the run and propagates. Raises ValueError with a one-line message for an
/// invalid scenario or a failed simulation.
#[pyfunction]
#[pyo3(signature = (path, progress = None))]
pub fn run_scenario<'py>(py: Python<'py>, path: PathBuf, progress: Option<Py<PyAny>>) -> PyResult<Bound<'py, PyDict>> {
    let scenario = load(&path)?;
    let duration = scenario.duration;
    let step = duration / 100.0;
    let mut next_report = 0.0;
    let mut python_error: Option<PyErr> = None;
    let outcome = py.detach(|| {
        run_scenario_until(&scenario, |t| {
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
